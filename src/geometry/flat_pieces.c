/*
 * flat_pieces.c - convex pieces of a plane and their subtraction, see flat_pieces.h.
 */
#include "geometry/flat_pieces.h"

#include <math.h>

#include "core/hemisphere.h"
#include "core/minmax.h"

plane_frame plane_frame_make(rad_vec3 origin, rad_vec3 n)
{
    plane_frame frame = {.origin = origin, .normal = n};
    hemisphere_frame(n, &frame.u, &frame.v);
    return frame;
}

double flat_piece_area(const flat_piece *p)
{
    double sum = 0;
    for (unsigned k = 0; k < p->count; k++) {
        flat_point a = p->vertex[k], b = p->vertex[k + 1 == p->count ? 0 : k + 1];
        sum += a.u * b.v - a.v * b.u;
    }
    return 0.5 * sum;
}

static inline double extent_of(flat_point a, flat_point b)
{
    return max_d(fabs(a.u - b.u), fabs(a.v - b.v));
}

void flat_piece_drop_repeated(flat_piece *p)
{
    if (p->count < 2)
        return;
    double extent = 0;
    for (unsigned k = 1; k < p->count; k++)
        extent = max_d(extent, extent_of(p->vertex[k], p->vertex[0]));
    double tiny = 1e-12 * extent;
    unsigned kept = 1;
    for (unsigned k = 1; k < p->count; k++)
        if (extent_of(p->vertex[k], p->vertex[kept - 1]) > tiny)
            p->vertex[kept++] = p->vertex[k];
    while (kept > 1 && !(extent_of(p->vertex[kept - 1], p->vertex[0]) > tiny))
        kept--;
    p->count = kept;
}

/* An edge's line: inward . q - offset > 0 on the inner side of a counter-clockwise
 * polygon's edge from p0 to p1 (inward is the edge turned a quarter left). */
typedef struct flat_line {
    double nu, nv, offset;
} flat_line;

static inline flat_line edge_line(flat_point p0, flat_point p1)
{
    flat_line line = {-(p1.v - p0.v), p1.u - p0.u, 0};
    line.offset = line.nu * p0.u + line.nv * p0.v;
    return line;
}

static inline double side_of(flat_line line, flat_point q)
{
    return line.nu * q.u + line.nv * q.v - line.offset;
}

static inline bool no_line(flat_line line) { return line.nu == 0 && line.nv == 0; }

/* Whether `points` lie wholly on the outer side of the line (or on it). */
static bool all_outside(flat_line line, const flat_piece *points)
{
    for (unsigned m = 0; m < points->count; m++)
        if (side_of(line, points->vertex[m]) > 0)
            return false;
    return true;
}

/* True when the convex pieces a and b cannot overlap: an edge line of either has the
 * other wholly outside (b's lines given). */
static bool separated(const flat_piece *a, const flat_piece *b, const flat_line *b_lines)
{
    for (unsigned k = 0; k < a->count; k++) {
        flat_line line = edge_line(a->vertex[k], a->vertex[k + 1 == a->count ? 0 : k + 1]);
        if (!no_line(line) && all_outside(line, b))
            return true;
    }
    for (unsigned k = 0; k < b->count; k++)
        if (!no_line(b_lines[k]) && all_outside(b_lines[k], a))
            return true;
    return false;
}

/* Whether flat_piece_drop_repeated may drop a corner of p, given `reach` at least the
 * largest coordinate difference between p's corners: some corner (the last with the
 * first too) within 2e-12 of reach of the one before it. When not, no corner is within
 * the function's own 1e-12 of p's extent of the one before it, and it would change
 * nothing: most cuts are spared its two passes. (The factor 2 is slack: a wrong yes
 * costs only the pass.) */
static bool may_repeat(const flat_piece *p, double reach)
{
    double tiny = 2e-12 * reach;
    for (unsigned k = 0; k < p->count; k++)
        if (!(extent_of(p->vertex[k], p->vertex[k + 1 == p->count ? 0 : k + 1]) > tiny))
            return true;
    return false;
}

/* Splits `in` (no repeated corners) along the line into the part on its inner side and
 * the part outside, each with its repeated corners dropped (`reach`: at least the largest
 * coordinate difference between in's corners); false when either would have more than
 * FLAT_PIECE_MAX_VERTICES corners. */
static bool split_by_line(const flat_piece *in, flat_line line, double reach,
                          flat_piece *inside, flat_piece *outside)
{
    double d[FLAT_PIECE_MAX_VERTICES];
    for (unsigned k = 0; k < in->count; k++)
        d[k] = side_of(line, in->vertex[k]);
    inside->count = outside->count = 0;
    bool crossed = false;
    for (unsigned k = 0; k < in->count; k++) {
        unsigned next = k + 1 == in->count ? 0 : k + 1;
        flat_point a = in->vertex[k], b = in->vertex[next];
        double da = d[k], db = d[next];
        bool crosses = (da > 0 && db < 0) || (da < 0 && db > 0);
        if (inside->count + (da >= 0) + crosses > FLAT_PIECE_MAX_VERTICES ||
            outside->count + (da <= 0) + crosses > FLAT_PIECE_MAX_VERTICES)
            return false;
        if (da >= 0)
            inside->vertex[inside->count++] = a;
        if (da <= 0)
            outside->vertex[outside->count++] = a;
        if (crosses) {
            double t = da / (da - db);
            flat_point x = {a.u + (b.u - a.u) * t, a.v + (b.v - a.v) * t};
            inside->vertex[inside->count++] = x;
            outside->vertex[outside->count++] = x;
            crossed = true;
        }
    }
    /* only a crossing point can repeat a corner: without one, each side keeps corners of
     * the piece in order */
    if (crossed) {
        if (may_repeat(inside, reach))
            flat_piece_drop_repeated(inside);
        if (may_repeat(outside, reach))
            flat_piece_drop_repeated(outside);
    }
    return true;
}

/* The box of a piece's corners. */
typedef struct flat_box {
    double u0, u1, v0, v1;
} flat_box;

static flat_box box_of(const flat_piece *p)
{
    flat_box box = {p->vertex[0].u, p->vertex[0].u, p->vertex[0].v, p->vertex[0].v};
    for (unsigned k = 1; k < p->count; k++) {
        box.u0 = min_d(box.u0, p->vertex[k].u);
        box.u1 = max_d(box.u1, p->vertex[k].u);
        box.v0 = min_d(box.v0, p->vertex[k].v);
        box.v1 = max_d(box.v1, p->vertex[k].v);
    }
    return box;
}

/* Boxes apart, or touching: the pieces are separated (by a line along the frame's axes);
 * most pieces and shadows are told apart so, cheaply. */
static inline bool boxes_apart(flat_box a, flat_box b)
{
    return a.u1 <= b.u0 || b.u1 <= a.u0 || a.v1 <= b.v0 || b.v1 <= a.v0;
}

/* Copies a piece's corners only (a piece holds room for many more than it uses). */
static inline void piece_copy(flat_piece *to, const flat_piece *from)
{
    to->count = from->count;
    for (unsigned k = 0; k < from->count; k++)
        to->vertex[k] = from->vertex[k];
}

/* A slot for one more piece: past the last while there is room, else a hole (a piece that
 * vanished) before `before`; -1 when there is neither. */
static int free_slot(flat_piece *pieces, unsigned *made, unsigned max_pieces, unsigned *holes,
                     unsigned *hole_from, unsigned before)
{
    if (*made < max_pieces)
        return (int)(*made)++;
    for (; *holes > 0 && *hole_from < before; (*hole_from)++)
        if (pieces[*hole_from].count == 0) {
            (*holes)--;
            return (int)(*hole_from)++;
        }
    return -1;
}

int flat_subtract(flat_piece *pieces, unsigned count, const flat_piece *shape, double tiny,
                  unsigned max_pieces)
{
    flat_line lines[FLAT_PIECE_MAX_VERTICES];
    for (unsigned e = 0; e < shape->count; e++)
        lines[e] = edge_line(shape->vertex[e], shape->vertex[e + 1 == shape->count ? 0 : e + 1]);
    flat_box shape_box = box_of(shape);
    unsigned made = count, holes = 0, hole_from = 0, waiting = 0;
    flat_piece wait[FLAT_SUBTRACT_WAITING]; /* parts with no room yet */
    for (unsigned k = 0; k < count; k++) {
        if (pieces[k].count == 0) {
            holes++;
            continue;
        }
        flat_box box = box_of(&pieces[k]);
        if (boxes_apart(box, shape_box))
            continue; /* stays as it is */
        /* every part of the piece lies in its box, but for a crossing point rounded a
         * few units in the last place of its coordinates outside it */
        double reach = max_d(box.u1 - box.u0, box.v1 - box.v0) +
                       1e-14 * max_d(max_d(fabs(box.u0), fabs(box.u1)),
                                     max_d(fabs(box.v0), fabs(box.v1)));
        /* the parts outside the shape's edges in turn, kept aside until what is left
         * inside every edge shows that the shape overlaps the piece at all (else the piece
         * stays as it is: a separating line, found on the way, costs no more) */
        flat_piece buffer[2], parts[FLAT_PIECE_MAX_VERTICES];
        unsigned part_count = 0;
        bool missed = false;
        const flat_piece *remaining = &pieces[k];
        for (unsigned e = 0; e < shape->count && remaining->count >= 3; e++) {
            if (no_line(lines[e]))
                continue;
            /* most lines leave the rest wholly on one side: nothing to cut */
            bool some_in = false, some_out = false;
            for (unsigned m = 0; m < remaining->count; m++) {
                double d = side_of(lines[e], remaining->vertex[m]);
                some_in = some_in || d > 0;
                some_out = some_out || d < 0;
            }
            if (!some_out)
                continue; /* inside this edge: all of it goes on to the next */
            if (!some_in) {
                missed = true; /* wholly outside: the shape misses the piece */
                break;
            }
            flat_piece *inside = remaining == &buffer[0] ? &buffer[1] : &buffer[0];
            flat_piece *outside = &parts[part_count];
            if (!split_by_line(remaining, lines[e], reach, inside, outside)) {
                /* a part of too many corners: an error only where the shape meets the
                 * piece (a 15-gon the shape misses lost a corner to an edge's line) */
                if (separated(&pieces[k], shape, lines)) {
                    missed = true;
                    break;
                }
                return -1;
            }
            remaining = inside;
            if (outside->count >= 3 && flat_piece_area(outside) > tiny)
                part_count++;
        }
        if (missed || !(remaining->count >= 3 && flat_piece_area(remaining) > tiny))
            continue; /* no overlap (or none above tiny): the piece stays as it is */
        /* the first part takes the piece's own slot, the others go past the last, or
         * into a hole an earlier piece left, or else wait for one a later piece leaves */
        if (part_count == 0) {
            pieces[k].count = 0;
            holes++;
            continue;
        }
        piece_copy(&pieces[k], &parts[0]);
        for (unsigned m = 1; m < part_count; m++) {
            int slot = free_slot(pieces, &made, max_pieces, &holes, &hole_from, k);
            if (slot >= 0)
                piece_copy(&pieces[slot], &parts[m]);
            else if (waiting < FLAT_SUBTRACT_WAITING)
                piece_copy(&wait[waiting++], &parts[m]);
            else
                return -1;
        }
    }
    unsigned kept = 0; /* the holes closed up */
    for (unsigned k = 0; k < made; k++)
        if (pieces[k].count > 0) {
            if (kept != k)
                piece_copy(&pieces[kept], &pieces[k]);
            kept++;
        }
    if (kept + waiting > max_pieces)
        return -1;
    for (unsigned k = 0; k < waiting; k++)
        piece_copy(&pieces[kept++], &wait[k]);
    return (int)kept;
}
