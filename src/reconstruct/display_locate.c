/*
 * display_locate.c - where a hit on a scene triangle lies in the display mesh
 * (display_locate.h).
 */
#include "reconstruct/display_locate.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "trace/ray.h"

/* Probe points per display triangle: its centroid and a point 9/10 of the way to each
 * corner; each may find a different scene triangle (a quad's cell across its diagonal). */
#define PROBES 4u
/* Display triangles probed per batch of rays (per thread). */
#define PROBE_BATCH 256u
/* A grid over a scene triangle has about this many display triangles a cell, and at most
 * MAX_SIDE cells along either side. On the Cornell box's default render, tests a hit (its
 * cell's triangles tried, most covering first): 2.92 at 2 a cell, 2.10 at 1, 1.66 at
 * 0.5, 1.45 at 0.25; at 0.5 the render took 4 % less CPU time than at 2 (perf stat
 * task-clock, 2 runs each), its peak memory the same. */
#define PER_CELL 0.5
#define MAX_SIDE 256u
/* A display triangle whose box meets more cells than this is not listed (its hits are
 * traced on the display mesh): the listings stay about PER_CELL a cell. */
#define MAX_CELLS_PER_TRIANGLE 64u
/* A point this far outside a display triangle, in its own barycentrics, still counts as
 * on it (the scene hit's u, v are floats), its barycentrics clamped onto it. */
#define ON_EDGE 1e-3
/* Same side: the display triangle's normal and the scene triangle's within ~8 degrees. */
#define SAME_SIDE 0.99

/* One display triangle in one scene triangle's cell: (b1, b2) = m ((u, v) - q0). */
typedef struct located {
    float q0[2]; /* the display triangle's corner 0 in (u, v) */
    float m[4];
    uint32_t triangle;
} located;

/* A display triangle on a scene triangle: its map from the scene triangle's (u, v) and
 * its box in the triangle's grid (grid_frame). */
typedef struct placement {
    double m[4], q0[2];
    double lo[2], hi[2];
} placement;

/* A display triangle found on a scene triangle, before the cells are made. */
typedef struct found {
    uint32_t scene_triangle, triangle;
} found;

/* A scene triangle's grid: (x, y) = (f[0] + f[1] u + f[2] v, f[3] + f[4] u + f[5] v) is
 * the point's place in the triangle's bounding rectangle, 0 to 1 along its longest edge
 * and across it (square cells on a long thin triangle, where the (u, v) square would
 * stretch each display triangle's box over many cells); nx x ny cells. */
typedef struct grid_frame {
    double f[6];
    uint32_t nx, ny; /* 0: no display triangle */
} grid_frame;

struct display_locator {
    uint32_t scene_triangles;
    uint32_t *first_cell; /* per scene triangle, and one past the last */
    grid_frame *grid;     /* per scene triangle: where its cells lie */
    uint32_t *cell_start; /* per cell, and one past the last: into items */
    uint32_t *items;      /* per cell, its display triangles: indices into placed, 4 bytes
                             each so that a cell's list shares a cache line (the maps
                             themselves, repeated in every cell, made the listings 3.6 MB
                             on the Cornell box; with `placed` they and the maps take
                             1.1 MB) */
    located *placed;      /* per (scene triangle, display triangle) pair found */
    uint32_t placed_count;
};

/* The scene triangle's corner and edges, as (u, v) measure them. */
typedef struct triangle_frame {
    rad_vec3 p0, e1, e2;
    double a, b, c, det; /* e1.e1, e1.e2, e2.e2 and the Gram determinant */
} triangle_frame;

static triangle_frame frame_of(const rad_scene *scene, uint32_t t)
{
    const uint32_t *v = scene->triangles[t].vertex;
    triangle_frame f;
    f.p0 = scene->positions[v[0]];
    f.e1 = v3_sub(scene->positions[v[1]], f.p0);
    f.e2 = v3_sub(scene->positions[v[2]], f.p0);
    f.a = v3_dot(f.e1, f.e1);
    f.b = v3_dot(f.e1, f.e2);
    f.c = v3_dot(f.e2, f.e2);
    f.det = f.a * f.c - f.b * f.b;
    return f;
}

/* The point's (u, v) in the scene triangle, projected onto its plane. */
static void uv_of(const triangle_frame *f, rad_vec3 x, double uv[2])
{
    rad_vec3 r = v3_sub(x, f->p0);
    double s1 = v3_dot(f->e1, r), s2 = v3_dot(f->e2, r);
    uv[0] = (f->c * s1 - f->b * s2) / f->det;
    uv[1] = (f->a * s2 - f->b * s1) / f->det;
}

static void grid_point(const grid_frame *g, double u, double v, double *x, double *y);

/* The display triangle d's map from the scene triangle's (u, v) to its barycentrics, and
 * its box in the grid; false when it is edge-on in that plane. */
static bool map_onto(const triangle_frame *f, const rad_vec3 corner[3], const grid_frame *g,
                     placement *out)
{
    double q[3][2], x[3][2];
    for (int k = 0; k < 3; k++) {
        uv_of(f, corner[k], q[k]);
        grid_point(g, q[k][0], q[k][1], &x[k][0], &x[k][1]);
    }
    double a00 = q[1][0] - q[0][0], a01 = q[2][0] - q[0][0];
    double a10 = q[1][1] - q[0][1], a11 = q[2][1] - q[0][1];
    double det = a00 * a11 - a01 * a10;
    if (!(fabs(det) > 1e-14 * (fabs(a00 * a11) + fabs(a01 * a10))) || !isfinite(det))
        return false;
    out->m[0] = a11 / det;
    out->m[1] = -a01 / det;
    out->m[2] = -a10 / det;
    out->m[3] = a00 / det;
    out->q0[0] = q[0][0];
    out->q0[1] = q[0][1];
    for (int a = 0; a < 2; a++) {
        out->lo[a] = fmin(x[0][a], fmin(x[1][a], x[2][a]));
        out->hi[a] = fmax(x[0][a], fmax(x[1][a], x[2][a]));
    }
    return true;
}

static uint32_t cell_index(double x, uint32_t side)
{
    double at = floor(x * side);
    return !(at >= 0) ? 0 : at >= side ? side - 1 : (uint32_t)at;
}

/* The frame of scene triangle t's grid, for `count` display triangles on it. */
static grid_frame grid_of(const rad_scene *scene, uint32_t t, uint32_t count)
{
    grid_frame g = {{0, 0, 0, 0, 0, 0}, 0, 0};
    if (count == 0)
        return g;
    const uint32_t *v = scene->triangles[t].vertex;
    rad_vec3 p0 = scene->positions[v[0]];
    rad_vec3 e1 = v3_sub(scene->positions[v[1]], p0), e2 = v3_sub(scene->positions[v[2]], p0);
    rad_vec3 e3 = v3_sub(e2, e1);
    rad_vec3 along = v3_dot(e1, e1) >= v3_dot(e2, e2) ? e1 : e2;
    along = v3_dot(e3, e3) > v3_dot(along, along) ? e3 : along;
    rad_vec3 n = v3_cross(e1, e2);
    if (!(v3_length(n) > 0) || !(v3_length(along) > 0))
        return g;
    along = v3_normalize(along);
    rad_vec3 across = v3_normalize(v3_cross(v3_normalize(n), along));
    /* the corners in (along, across), from p0: (0, 0), e1's, e2's */
    double x[3] = {0, v3_dot(along, e1), v3_dot(along, e2)};
    double y[3] = {0, v3_dot(across, e1), v3_dot(across, e2)};
    double x0 = fmin(x[0], fmin(x[1], x[2])), sx = fmax(x[0], fmax(x[1], x[2])) - x0;
    double y0 = fmin(y[0], fmin(y[1], y[2])), sy = fmax(y[0], fmax(y[1], y[2])) - y0;
    if (!(sx > 0) || !(sy > 0))
        return g;
    g.f[0] = -x0 / sx;
    g.f[1] = x[1] / sx;
    g.f[2] = x[2] / sx;
    g.f[3] = -y0 / sy;
    g.f[4] = y[1] / sy;
    g.f[5] = y[2] / sy;
    double cells = count / PER_CELL, nx = round(sqrt(cells * sx / sy));
    nx = nx < 1 ? 1 : nx > MAX_SIDE ? MAX_SIDE : nx;
    double ny = round(cells / nx);
    ny = ny < 1 ? 1 : ny > MAX_SIDE ? MAX_SIDE : ny;
    g.nx = (uint32_t)nx;
    g.ny = (uint32_t)ny;
    return g;
}

static void grid_point(const grid_frame *g, double u, double v, double *x, double *y)
{
    *x = g->f[0] + g->f[1] * u + g->f[2] * v;
    *y = g->f[3] + g->f[4] * u + g->f[5] * v;
}

/* How far above display triangle d its probes start (a hundredth of its longest edge past
 * a folded cell's stray), and in *slack how far from there the surface under it may lie:
 * the stray, and a fifth of that hundredth (not a parallel layer of the same surface a
 * little above or below). */
static double probe_lift(const rad_mesh *mesh, const display_mesh *display,
                         const rad_vec3 *positions, uint32_t d, double *slack)
{
    const uint32_t *v = display->triangles[d];
    rad_vec3 a = positions[v[0]], b = positions[v[1]], c = positions[v[2]];
    const rad_patch *patch = &mesh->patches[display->patch_of[d]];
    double edge = fmax(v3_length(v3_sub(b, a)), fmax(v3_length(v3_sub(c, b)),
                                                     v3_length(v3_sub(a, c))));
    double stray = 2 * (patch->behind + patch->bulge);
    *slack = stray + 0.002 * edge;
    return 0.01 * edge + stray;
}

/* The scene triangles under display triangle d (up to PROBES, UINT32_MAX for none), by
 * short rays onto it from just in front, kept when the triangle hit is of d's patch's
 * surface and material and faces the same way. */
static void probe_rays(const rad_mesh *mesh, const display_mesh *display,
                       const rad_vec3 *positions, uint32_t d, rad_ray *rays, bool *valid)
{
    const uint32_t *v = display->triangles[d];
    rad_vec3 a = positions[v[0]], b = positions[v[1]], c = positions[v[2]];
    rad_vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    double length = v3_length(n);
    *valid = length > 0 && isfinite(length);
    if (!*valid) { /* nothing to find: empty rays */
        for (unsigned k = 0; k < PROBES; k++)
            ray_set(&rays[k], a, v3(1, 0, 0), 1, 0);
        return;
    }
    n = v3_scale(n, 1 / length);
    double slack, lift = probe_lift(mesh, display, positions, d, &slack);
    rad_vec3 centre = v3_scale(v3_add(v3_add(a, b), c), 1.0 / 3.0);
    rad_vec3 point[PROBES] = {centre, v3_lerp(centre, a, 0.9), v3_lerp(centre, b, 0.9),
                              v3_lerp(centre, c, 0.9)};
    for (unsigned k = 0; k < PROBES; k++)
        ray_set(&rays[k], v3_add(point[k], v3_scale(n, lift)), v3_scale(n, -1), 0, 2 * lift);
}

rad_status display_locator_build(const rad_scene *scene, const rad_tracer *scene_tracer,
                                 const rad_mesh *mesh, const display_mesh *display,
                                 const rad_vec3 *positions, uint32_t front, uint64_t keep,
                                 int threads, display_locator **out, rad_error *error)
{
    *out = NULL;
    if (!scene || !scene_tracer || scene->triangle_count == 0 || front == 0)
        return RAD_OK;
    threads = threads < 1 ? 1 : threads;
    uint64_t left = rad_memory_budget_left();
    if (left != UINT64_MAX && (left < keep || (left - keep) / DISPLAY_LOCATE_BYTES_PER_TRIANGLE <
                                                  (uint64_t)front + PROBE_BATCH * threads))
        return RAD_OK;
    const uint32_t T = scene->triangle_count;
    display_locator *l = rad_alloc_array(1, sizeof(*l));
    uint32_t (*under)[PROBES] = rad_alloc_array(front, sizeof(*under));
    rad_ray *rays = rad_alloc_array((size_t)threads * PROBE_BATCH * PROBES, sizeof(*rays));
    rad_hit *hits = rad_alloc_array((size_t)threads * PROBE_BATCH * PROBES, sizeof(*hits));
    bool *valid = rad_alloc_array((size_t)threads * PROBE_BATCH, sizeof(*valid));
    uint32_t *count = rad_alloc_array((size_t)T + 1, sizeof(*count));
    found *pairs = NULL;
    uint32_t *cursor = NULL;
    float *cover = NULL; /* per listing while the cells are made */
    rad_status status = RAD_OK;
    if (!l || !under || !rays || !hits || !valid || !count)
        goto fail;
    l->scene_triangles = T;

    /* 1. the scene triangles under each display triangle */
    const uint32_t batches = (front + PROBE_BATCH - 1) / PROBE_BATCH;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int64_t batch = 0; batch < (int64_t)batches; batch++) {
        const int thread = omp_get_thread_num();
        rad_ray *r = &rays[(size_t)thread * PROBE_BATCH * PROBES];
        rad_hit *h = &hits[(size_t)thread * PROBE_BATCH * PROBES];
        bool *ok = &valid[(size_t)thread * PROBE_BATCH];
        const uint32_t first = (uint32_t)batch * PROBE_BATCH;
        const uint32_t n = front - first < PROBE_BATCH ? front - first : PROBE_BATCH;
        for (uint32_t k = 0; k < n; k++)
            probe_rays(mesh, display, positions, first + k, &r[k * PROBES], &ok[k]);
        rad_tracer_intersect(scene_tracer, r, n * PROBES, h);
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t d = first + k;
            const rad_patch *patch = &mesh->patches[display->patch_of[d]];
            double slack, lift = probe_lift(mesh, display, positions, d, &slack);
            unsigned kept = 0;
            for (unsigned p = 0; p < PROBES; p++) {
                uint32_t t = h[k * PROBES + p].triangle;
                bool again = t == RAD_NO_HIT || !ok[k] ||
                             !(fabs(h[k * PROBES + p].t - lift) <= slack);
                for (unsigned q = 0; !again && q < kept; q++)
                    again = under[d][q] == t;
                if (again || scene->triangles[t].surface != patch->surface ||
                    scene->triangles[t].material != patch->material)
                    continue;
                const uint32_t *sv = scene->triangles[t].vertex;
                rad_vec3 tn = v3_cross(v3_sub(scene->positions[sv[1]], scene->positions[sv[0]]),
                                       v3_sub(scene->positions[sv[2]], scene->positions[sv[0]]));
                double tl = v3_length(tn);
                if (!(tl > 0) || v3_dot(tn, patch->normal) < SAME_SIDE * tl)
                    continue;
                under[d][kept++] = t;
            }
            for (unsigned p = kept; p < PROBES; p++)
                under[d][p] = UINT32_MAX;
        }
    }
    free(rays);
    free(hits);
    free(valid);
    rays = NULL;
    hits = NULL;
    valid = NULL;

    /* 2. the (scene triangle, display triangle) pairs in scene-triangle order, and each
     * scene triangle's grid: about PER_CELL display triangles a cell */
    size_t pair_count = 0;
    for (uint32_t d = 0; d < front; d++)
        for (unsigned p = 0; p < PROBES && under[d][p] != UINT32_MAX; p++) {
            count[under[d][p]]++;
            pair_count++;
        }
    pairs = rad_alloc_array(pair_count ? pair_count : 1, sizeof(*pairs));
    cursor = rad_alloc_array((size_t)T + 1, sizeof(*cursor));
    l->first_cell = rad_alloc_array((size_t)T + 1, sizeof(*l->first_cell));
    l->grid = rad_alloc_array(T, sizeof(*l->grid));
    if (!pairs || !cursor || !l->first_cell || !l->grid)
        goto fail;
    for (uint32_t t = 0, at = 0; t < T; t++) {
        cursor[t] = at;
        at += count[t];
    }
    size_t cells = 0;
    for (uint32_t t = 0; t < T; t++) {
        l->first_cell[t] = (uint32_t)cells;
        l->grid[t] = grid_of(scene, t, count[t]);
        cells += (size_t)l->grid[t].nx * l->grid[t].ny;
        if (cells > UINT32_MAX / 2)
            goto decline;
    }
    l->first_cell[T] = (uint32_t)cells;
    for (uint32_t d = 0; d < front; d++)
        for (unsigned p = 0; p < PROBES && under[d][p] != UINT32_MAX; p++) {
            uint32_t t = under[d][p];
            pairs[cursor[t]++] = (found){t, d};
        }
    free(under);
    under = NULL;

    /* 3. the cells: each display triangle in every cell its (u, v) box meets */
    l->cell_start = rad_alloc_array(cells + 1, sizeof(*l->cell_start));
    if (!l->cell_start)
        goto fail;
    size_t items = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t k = 0; k < pair_count; k++) {
            const uint32_t t = pairs[k].scene_triangle, *v = display->triangles[pairs[k].triangle];
            const rad_vec3 corner[3] = {positions[v[0]], positions[v[1]], positions[v[2]]};
            triangle_frame frame = frame_of(scene, t);
            placement at, *f = &at;
            const grid_frame *g = &l->grid[t];
            if (g->nx == 0 || !(frame.det > 0) || !map_onto(&frame, corner, g, f) ||
                f->hi[0] < 0 || f->hi[1] < 0 || f->lo[0] > 1 || f->lo[1] > 1)
                continue; /* edge-on or outside: never located there */
            uint32_t u0 = cell_index(f->lo[0], g->nx), u1 = cell_index(f->hi[0], g->nx);
            uint32_t v0 = cell_index(f->lo[1], g->ny), v1 = cell_index(f->hi[1], g->ny);
            if ((uint64_t)(u1 - u0 + 1) * (v1 - v0 + 1) > MAX_CELLS_PER_TRIANGLE)
                continue; /* larger than its cells: its hits are traced on the display */
            if (pass == 1) {
                located *item = &l->placed[k];
                for (int m = 0; m < 4; m++)
                    item->m[m] = (float)f->m[m];
                item->q0[0] = (float)f->q0[0];
                item->q0[1] = (float)f->q0[1];
                item->triangle = pairs[k].triangle;
            }
            for (uint32_t cv = v0; cv <= v1; cv++)
                for (uint32_t cu = u0; cu <= u1; cu++) {
                    size_t cell = l->first_cell[t] + (size_t)cv * g->nx + cu;
                    if (pass == 0) {
                        l->cell_start[cell + 1]++;
                        items++;
                    } else {
                        /* how much of the cell its box covers: the likelier first */
                        double du = fmin(f->hi[0], (cu + 1.0) / g->nx) -
                                    fmax(f->lo[0], (double)cu / g->nx);
                        double dv = fmin(f->hi[1], (cv + 1.0) / g->ny) -
                                    fmax(f->lo[1], (double)cv / g->ny);
                        cover[l->cell_start[cell]] = (float)(fmax(du, 0) * fmax(dv, 0));
                        l->items[l->cell_start[cell]++] = (uint32_t)k;
                    }
                }
        }
        if (pass == 0) {
            /* the listings counted: under a budget that cannot hold them beside `keep`, no
             * locator (the estimate above was made before their number was known) */
            uint64_t need = (uint64_t)items * (sizeof(*l->items) + sizeof(float)) +
                            (uint64_t)pair_count * sizeof(located);
            left = rad_memory_budget_left();
            if (items > UINT32_MAX || (left != UINT64_MAX && (left < keep || left - keep < need)))
                goto decline;
            for (size_t c = 0; c < cells; c++) /* starts; pass 1 moves each to its end */
                l->cell_start[c + 1] += l->cell_start[c];
            l->items = rad_alloc_array(items ? items : 1, sizeof(*l->items));
            l->placed = rad_alloc_array(pair_count ? pair_count : 1, sizeof(*l->placed));
            l->placed_count = (uint32_t)pair_count;
            cover = rad_alloc_array(items ? items : 1, sizeof(*cover));
            if (!l->items || !l->placed || !cover)
                goto fail;
        }
    }
    for (size_t c = cells; c > 0; c--) /* each end back to its start */
        l->cell_start[c] = l->cell_start[c - 1];
    l->cell_start[0] = 0;
    /* each cell's display triangles by how much of it they cover, most first: a hit is
     * found after fewer tests (on the Cornell box 6.9 a hit in arrival order) */
    for (size_t c = 0; c < cells; c++)
        for (uint32_t k = l->cell_start[c] + 1; k < l->cell_start[c + 1]; k++) {
            uint32_t item = l->items[k];
            float key = cover[k];
            uint32_t at = k;
            for (; at > l->cell_start[c] && cover[at - 1] < key; at--) {
                l->items[at] = l->items[at - 1];
                cover[at] = cover[at - 1];
            }
            l->items[at] = item;
            cover[at] = key;
        }
    free(cover);
    free(pairs);
    free(cursor);
    free(count);
    *out = l;
    return RAD_OK;
fail:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for placing the gather's hits");
decline: /* no locator: RAD_OK, or the failure above */
    free(cover);
    free(under);
    free(rays);
    free(hits);
    free(valid);
    free(count);
    free(pairs);
    free(cursor);
    display_locator_destroy(l);
    return status;
}

/* The barycentrics of (u, v) in the item's display triangle; the least of the three. */
static double weights_in(const located *item, double u, double v, double *b1, double *b2)
{
    double du = u - item->q0[0], dv = v - item->q0[1];
    *b1 = item->m[0] * du + item->m[1] * dv;
    *b2 = item->m[2] * du + item->m[3] * dv;
    double b0 = 1 - *b1 - *b2, least = *b1 < *b2 ? *b1 : *b2;
    return b0 < least ? b0 : least;
}

bool display_locate(const display_locator *l, rad_hit *hit)
{
    if (hit->triangle == RAD_NO_HIT)
        return true;
    const uint32_t t = hit->triangle;
    const grid_frame *g = &l->grid[t];
    if (g->nx == 0)
        return false;
    const double u = hit->u, v = hit->v;
    double best = -INFINITY, b1 = 0, b2 = 0;
    uint32_t chosen = RAD_NO_HIT;
    double x, y;
    grid_point(g, u, v, &x, &y);
    const uint32_t cell = l->first_cell[t] + cell_index(y, g->ny) * g->nx + cell_index(x, g->nx);
    for (uint32_t k = l->cell_start[cell]; k < l->cell_start[cell + 1]; k++) {
        const located *item = &l->placed[l->items[k]];
        double x1, x2, least = weights_in(item, u, v, &x1, &x2);
        if (least > best) {
            best = least;
            b1 = x1;
            b2 = x2;
            chosen = item->triangle;
            if (least >= 0)
                break;
        }
    }
    if (!(best >= -ON_EDGE))
        return false;
    if (best < 0) { /* just outside: onto the triangle */
        b1 = fmax(b1, 0);
        b2 = fmax(b2, 0);
        double sum = b1 + b2;
        if (sum > 1) {
            b1 /= sum;
            b2 /= sum;
        }
    }
    hit->triangle = chosen;
    hit->u = (float)b1;
    hit->v = (float)b2;
    return true;
}

uint64_t display_locator_bytes(const display_locator *l)
{
    const uint64_t cells = l->first_cell[l->scene_triangles];
    const uint64_t items = l->cell_start[cells];
    return sizeof(*l) + (uint64_t)l->scene_triangles * (sizeof(uint32_t) + sizeof(grid_frame)) +
           (cells + 1) * sizeof(uint32_t) + items * sizeof(*l->items) +
           (uint64_t)l->placed_count * sizeof(located);
}

void display_locator_destroy(display_locator *l)
{
    if (!l)
        return;
    free(l->first_cell);
    free(l->grid);
    free(l->cell_start);
    free(l->items);
    free(l->placed);
    free(l);
}
