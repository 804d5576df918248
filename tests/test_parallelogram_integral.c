/*
 * test_parallelogram_integral.c - the adaptive integral over a parallelogram (src/geometry/
 * parallelogram_integral.c) against integrals worked out by hand: which polygons are
 * parallelograms; a polynomial of degree 5 in each direction is exact on the first rule; a
 * kink along a line parallel to an edge (what a rectilinear scene's shadows make) reaches
 * its tolerance with a small part of the points the triangle splitting of
 * polygon_integral.c takes; a thin wedge of light along an edge, which no rule point sees
 * at the first splits, is found by the edge check, and so is a sliver at a corner; a ridge
 * parallel to an edge, between the lines of every rule point, is missed with no forced
 * splits and found whole by the probes; a floor seen through a slit parallel to its edge
 * (the view factors' path, with probes and no forced splits) agrees with the same floor
 * by triangles; and the cell callback's protocol holds, with and without the probes:
 * every point lies in the cell told last (or selected again), and every cell in the one
 * its level and parent slot name.
 */
#include <math.h>
#include <stdio.h>

#include "core/vec3.h"
#include "geometry/parallelogram_integral.h"
#include "geometry/polygon_integral.h"
#include "surface_viewfactors/pair_transfer.h"
#include "testlib.h"

typedef struct counted {
    double (*f)(rad_vec3 x, const double *parameter);
    const double *parameter;
    unsigned long points;
} counted;

static double counted_f(void *context, rad_vec3 x)
{
    counted *c = context;
    c->points++;
    return c->f(x, c->parameter);
}

/* f = x^5 + 3 x^2 y^3 - 2 y + 1 */
static double quintic(rad_vec3 x, const double *parameter)
{
    (void)parameter;
    return pow(x.x, 5) + 3 * x.x * x.x * pow(x.y, 3) - 2 * x.y + 1;
}

/* f = |x - c| (1 + y): a kink along the line x = c */
static double kink(rad_vec3 x, const double *c) { return fabs(x.x - *c) * (1 + x.y); }

/* f = max(0, 1 - x / w): a wedge of width w along the edge x = 0 */
static double wedge(rad_vec3 x, const double *w) { return fmax(0, 1 - x.x / *w); }

/* The cell protocol: cells told per level and slot, and the one told last. */
typedef struct protocol {
    rad_vec3 cell[PARALLELOGRAM_MAX_LEVELS][4][4];
    bool told[PARALLELOGRAM_MAX_LEVELS][4];
    rad_vec3 now[4];
    unsigned long points, cells, selected, outside_now, outside_parent;
    unsigned long root_visits; /* the whole told or selected: 3 or more when a second pass
                                  ran (told, its edge midpoints, then the second pass) */
    bool cross;                /* f: two ridges crossing instead of the wedge */
} protocol;

/* whether x lies in the rectangle cell (axis-aligned in x, y here), by 1e-12 */
static bool in_cell(const rad_vec3 *corner, rad_vec3 x)
{
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < 4; k++) {
        x0 = fmin(x0, corner[k].x);
        x1 = fmax(x1, corner[k].x);
        y0 = fmin(y0, corner[k].y);
        y1 = fmax(y1, corner[k].y);
    }
    return x.x >= x0 - 1e-12 && x.x <= x1 + 1e-12 && x.y >= y0 - 1e-12 && x.y <= y1 + 1e-12;
}

static bool protocol_cell(void *context, const rad_vec3 corner[4], int level, int slot,
                          int parent_slot)
{
    protocol *p = context;
    p->cells++;
    if (level > 0) {
        bool inside = p->told[level - 1][parent_slot];
        for (int k = 0; k < 4 && inside; k++)
            inside = in_cell(p->cell[level - 1][parent_slot], corner[k]);
        p->outside_parent += !inside;
    }
    for (int k = 0; k < 4; k++)
        p->cell[level][slot][k] = p->now[k] = corner[k];
    p->told[level][slot] = true;
    p->root_visits += level == 0;
    return false; /* as where shadows may fall: split to min_splits, edge check on */
}

static void protocol_select(void *context, int level, int slot)
{
    protocol *p = context;
    p->selected++;
    p->root_visits += level == 0;
    for (int k = 0; k < 4; k++)
        p->now[k] = p->cell[level][slot][k];
}

static double protocol_f(void *context, rad_vec3 x)
{
    protocol *p = context;
    p->points++;
    p->outside_now += !in_cell(p->now, x);
    if (p->cross) /* 1 + y, a ridge 0.08 wide across x = 0.72, one 0.02 wide across y = 0.7 */
        return 1 + x.y + 10 * fmax(0, 1 - fabs(x.x - 0.72) / 0.04) +
               10 * fmax(0, 1 - fabs(x.y - 0.7) / 0.01);
    double w = 0.02;
    return wedge(x, &w) + 0.25 * x.y;
}

/* f = 1 + y + 10 max(0, 1 - |x - 0.36| / 0.02): a ridge 0.04 wide across x = 0.36 on a
 * slope, int over [0, 2] x [0, 1] = 2 + 1 + 10 x 0.02 = 3.2 */
static double ridge(rad_vec3 x, const double *parameter)
{
    (void)parameter;
    return 1 + x.y + 10 * fmax(0, 1 - fabs(x.x - 0.36) / 0.02);
}

/* f = 1 + 0.3 x + 0.2 y + 5 [0.055 <= y < 0.077]: int over the unit square 1.25 + 0.11 */
static double band(rad_vec3 x, const double *parameter)
{
    (void)parameter;
    return 1 + 0.3 * x.x + 0.2 * x.y + (x.y >= 0.055 && x.y < 0.077 ? 5 : 0);
}

/* f = a band 0.03 wide along y at x in [0.301, 0.331), 1 but 0.05 where |y - 0.518| <
 * 0.1: int over the unit square 0.03 (0.8 + 0.2 x 0.05) = 0.0243. Of the lattice's probes
 * only (0.318, 0.518) lies in it, where it is dim. */
static double dim_band(rad_vec3 x, const double *parameter)
{
    (void)parameter;
    if (!(x.x >= 0.301 && x.x < 0.331))
        return 0;
    return fabs(x.y - 0.518) < 0.1 ? 0.05 : 1;
}

/* As where shadows may fall: f not smooth anywhere, so the probes look everywhere. */
static bool rough_cell(void *context, const rad_vec3 corner[4], int level, int slot,
                       int parent_slot)
{
    (void)context, (void)corner, (void)level, (void)slot, (void)parent_slot;
    return false;
}

/* f = (x / 2)^4 + max(0, 1 - (x + y) / w): a sliver of light at the corner (0, 0) */
static double corner_sliver(rad_vec3 x, const double *w)
{
    return pow(0.5 * x.x, 4) + fmax(0, 1 - (x.x + x.y) / *w);
}

/* a convex polygon in z = height from its corners' (x, y) (counter-clockwise seen from
 * `up`) */
static vf_polygon flat_polygon(const double *corner, unsigned count, double height,
                               double up)
{
    vf_polygon polygon = {0};
    for (unsigned k = 0; k < count; k++)
        polygon.vertex[k] = v3(corner[2 * k], corner[2 * k + 1], height);
    polygon.count = count;
    polygon.normal = v3(0, 0, up);
    vf_polygon_finish(&polygon);
    return polygon;
}

/* the rectangle [x0, x1] x [y0, y1] at height z as two occluder triangles */
static void occluder_rectangle(double x0, double x1, double y0, double y1, double z,
                               shadow_occluder *out)
{
    out[0] = (shadow_occluder){{v3(x0, y0, z), v3(x1, y0, z), v3(x1, y1, z)}};
    out[1] = (shadow_occluder){{v3(x0, y0, z), v3(x1, y1, z), v3(x0, y1, z)}};
}

/* The transfer from `floor` (a parallelogram: strips) to `ceiling` behind the 6 lid
 * triangles, checked against the same floor given with a fifth corner (triangles), 250
 * times finer; returns the reference. */
static double floor_through_slit(const char *what, const vf_polygon *floor,
                                 const vf_polygon *floor_five, const vf_polygon *ceiling,
                                 const shadow_occluder *lid)
{
    double value = 0, bound = 0, reference = 0, reference_bound = 0;
    CHECK(pair_obstructed_exact_within(floor, ceiling, lid, 6, 2.5e-5, 0, 1e-9,
                                       PAIR_EXACT_WORK_BUDGET, &value, &bound));
    CHECK(pair_obstructed_exact_within(floor_five, ceiling, lid, 6, 1e-7, 0, 1e-9, UINT64_MAX,
                                       &reference, &reference_bound));
    printf("%s: strips %.9g (bound %.2g), triangles %.9g (bound %.2g)\n", what, value, bound,
           reference, reference_bound);
    CHECK(fabs(value - reference) <= bound + reference_bound);
    return reference;
}

int main(void)
{
    double value;
    rad_vec3 origin, a, b;
    const rad_vec3 rectangle[4] = {v3(0, 0, 0), v3(2, 0, 0), v3(2, 1, 0), v3(0, 1, 0)};
    const rad_vec3 sheared[4] = {v3(1, 1, 1), v3(3, 1, 1), v3(3.5, 2, 2), v3(1.5, 2, 2)};
    const rad_vec3 trapezoid[4] = {v3(0, 0, 0), v3(2, 0, 0), v3(1.5, 1, 0), v3(0.5, 1, 0)};
    CHECK(parallelogram_of(rectangle, 4, &origin, &a, &b));
    CHECK(v3_length(v3_sub(a, v3(2, 0, 0))) == 0 && v3_length(v3_sub(b, v3(0, 1, 0))) == 0);
    CHECK(parallelogram_of(sheared, 4, &origin, &a, &b));
    CHECK(!parallelogram_of(trapezoid, 4, &origin, &a, &b));
    CHECK(!parallelogram_of(rectangle, 3, &origin, &a, &b));

    /* the rectangle [0, 2] x [0, 1]: int x^5 = 32 / 3, int 3 x^2 y^3 = 3 (8 / 3) (1 / 4) = 2,
     * int -2 y = -2, int 1 = 2 */
    double exact = 32.0 / 3 + 2 - 2 + 2, bound;
    for (int check = 0; check < 2; check++) {
        counted c = {quintic, NULL, 0};
        parallelogram_integral integral = {counted_f, &c, 8, NULL, NULL, check ? 2 : 0,
                                           check == 1, NULL, false};
        value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(2, 0, 0),
                                                      v3(0, 1, 0), 1e-12, 0, &bound);
        printf("quintic (edge check %s): %.17g, exact %.17g, bound %.2g, %lu points\n",
               check ? "on" : "off", value, exact, bound, c.points);
        CHECK_NEAR(value, exact, 1e-13 * exact);
        CHECK(bound <= (check ? 1e-11 * exact : 1e-14 * exact));
    }

    /* the kink at x = c: int |x - c| over [0, 2] = (c^2 + (2 - c)^2) / 2, int (1 + y) = 3/2 */
    double c_line = 0.7310585786;
    double kink_exact = 0.75 * (c_line * c_line + (2 - c_line) * (2 - c_line));
    counted strips_count = {kink, &c_line, 0}, triangles_count = {kink, &c_line, 0};
    parallelogram_integral strips = {counted_f, &strips_count, 8, NULL, NULL, 2, true, NULL,
                                     false};
    polygon_integral triangles = {counted_f, &triangles_count, 8, NULL, NULL, 2, true};
    double strips_bound, triangles_bound;
    double by_strips = parallelogram_integrate_within(&strips, v3(0, 0, 0), v3(2, 0, 0),
                                                      v3(0, 1, 0), 1e-5, 0, &strips_bound);
    double by_triangles =
        polygon_integrate_within(&triangles, rectangle, 4, 1e-5, 0, &triangles_bound);
    printf("kink along x = %.10g: strips %.12g (bound %.2g, %lu points), triangles %.12g "
           "(bound %.2g, %lu points), exact %.12g\n",
           c_line, by_strips, strips_bound, strips_count.points, by_triangles, triangles_bound,
           triangles_count.points, kink_exact);
    CHECK(fabs(by_strips - kink_exact) <= strips_bound);
    CHECK(fabs(by_triangles - kink_exact) <= triangles_bound);
    CHECK(strips_bound <= 4e-5 * kink_exact);
    /* what the strips are for: the same accuracy from a few cells a level along the line,
     * where triangles need 2^depth */
    CHECK(strips_count.points * 4 < triangles_count.points);

    /* a wedge of width 0.02 along x = 0: int = w / 2 over y in [0, 1]. After two splits
     * each way the cells along the edge are 0.5 wide, their rule points 0.056 from it; the
     * narrowest strip (8 splits) is 2 / 256 wide. */
    double w = 0.02, wedge_exact = w / 2;
    for (int check = 0; check < 2; check++) {
        counted c = {wedge, &w, 0};
        parallelogram_integral integral = {counted_f, &c,       8,   NULL, NULL, 2,
                                           check == 1, NULL, false};
        value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(2, 0, 0),
                                                      v3(0, 1, 0), 1e-3, 1e-9, &bound);
        printf("wedge of width %g on an edge (edge check %s): %.9g, exact %.9g, bound %.2g\n",
               w, check ? "on" : "off", value, wedge_exact, bound);
        if (!check) {
            CHECK(value == 0); /* every rule point missed it, and the bound says nothing */
            CHECK(bound == 0);
        } else {
            CHECK(fabs(value - wedge_exact) <= bound);
            CHECK(fabs(value - wedge_exact) <= 0.02 * wedge_exact);
        }
    }

    /* a sliver of light at a corner on a smooth slope: f = x^4 + max(0, 1 - (x + y) / w).
     * The quartered cell's check sees it at its corner; the child that holds that corner
     * must not be cut into strips, which check their centre lines only (it was lost with
     * a bound of 1e-16). */
    double sliver_w = 0.01, sliver_exact = 0.4 + sliver_w * sliver_w / 6;
    counted sliver = {corner_sliver, &sliver_w, 0};
    parallelogram_integral at_corner = {counted_f, &sliver, 8, NULL, NULL, 2, true, NULL,
                                        false};
    value = parallelogram_integrate_within(&at_corner, v3(0, 0, 0), v3(2, 0, 0), v3(0, 1, 0),
                                           1e-6, 0, &bound);
    printf("sliver of width %g at a corner: %.12g, exact %.12g, bound %.2g, %lu points\n",
           sliver_w, value, sliver_exact, bound, sliver.points);
    CHECK(fabs(value - sliver_exact) <= bound);
    CHECK(fabs(value - sliver_exact) <= 0.02 * sliver_w * sliver_w / 6);

    /* A ridge parallel to an edge, between the lines of every rule point and edge-check
     * point of the first splits (x = 0.225, 0.5, 0.775, ... of the unit square's 0.18):
     * with no forced splits the rules agree on the slope and miss it, and the bound says
     * nothing; the probes (one at x = 0.1727 of the square) find it. */
    for (int probing = 0; probing < 2; probing++) {
        counted c = {ridge, NULL, 0};
        parallelogram_integral integral = {counted_f, &c, 8, NULL, rough_cell, 0, true, NULL,
                                           probing == 1};
        value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(2, 0, 0),
                                               v3(0, 1, 0), 1e-5, 0, &bound);
        printf("ridge of width 0.04 across x = 0.36 (probes %s): %.9g, exact 3.2, bound %.2g, "
               "%lu points\n",
               probing ? "on" : "off", value, bound, c.points);
        if (!probing) {
            CHECK(fabs(value - 3) < 1e-12);
            CHECK(bound < 1e-12);
        } else {
            CHECK(fabs(value - 3.2) <= bound);
            CHECK(fabs(value - 3.2) <= 1e-4 * 3.2);
        }
    }

    /* A band 0.022 wide along x on a plane, found by a quartered cell's rule points on one
     * side of the square and missed on the other by strips that rounding noise in two
     * fourth differences chose (both ~1e-16 where f is linear at every point of the cell):
     * half the band lost, error 0.054 with a bound of 0.0057, before flat differences
     * made a cell quarter. */
    {
        counted c = {band, NULL, 0};
        parallelogram_integral integral = {counted_f, &c, 8, NULL, rough_cell, 0, true, NULL,
                                           true};
        value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(1, 0, 0),
                                               v3(0, 1, 0), 1e-5, 0, &bound);
        printf("band y in [0.055, 0.077) on a plane (probes): %.9g, exact 1.36, bound %.2g, "
               "%lu points\n",
               value, bound, c.points);
        CHECK(fabs(value - 1.36) <= bound);
    }

    /* A band wider than the lattice's spacing that no rule point of the first splits sees,
     * to a tolerance above what it holds: one probe finds it dim, and the second pass's
     * probes along that probe's line find it bright elsewhere. Weighed as a band no wider
     * than the lattice's spacing (1/55 of a strip each), they made a bound of 0.016 for an
     * error of 0.024, and the band was accepted unseen; weighed as filling their cells
     * across, they make the cells split until rule points see it. */
    {
        counted c = {dim_band, NULL, 0};
        parallelogram_integral integral = {counted_f, &c, 8, NULL, rough_cell, 0, true, NULL,
                                           true};
        value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(1, 0, 0),
                                               v3(0, 1, 0), 0, 0.02, &bound);
        printf("band 0.03 wide, dim at its probe (probes): %.9g, exact 0.0243, bound %.2g, "
               "%lu points\n",
               value, bound, c.points);
        CHECK(fabs(value - 0.0243) <= bound);
    }

    /* A floor seen through a slit: the unit floor (up) under a 3 x 3 ceiling 1 above it
     * (down), with a lid 0.01 above the floor open only along x in [0.17, 0.19] and a gap
     * along two of its edges. The light reaches the floor in a band 0.02 wide parallel to
     * one edge of it, which after two splits each way falls between the lines every point
     * of the strips lies on: half the transfer was lost, with a bound of 7e-6. The
     * reference is the same floor given with a fifth corner (mid-edge), so the triangles
     * integrate it, to a tighter tolerance. */
    const double floor_corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const double floor_five[5][2] = {{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}};
    const double ceiling_corner[4][2] = {{-1, -1}, {-1, 2}, {2, 2}, {2, -1}};
    vf_polygon floor_p = flat_polygon(&floor_corner[0][0], 4, 0, 1);
    vf_polygon floor_five_p = flat_polygon(&floor_five[0][0], 5, 0, 1);
    vf_polygon ceiling_p = flat_polygon(&ceiling_corner[0][0], 4, 1, -1);
    shadow_occluder lid[6];
    occluder_rectangle(0.19, 2, -1, 2, 0.01, &lid[0]);
    occluder_rectangle(0.02, 0.17, -1, 2, 0.01, &lid[2]);
    occluder_rectangle(-1, 0.02, 0.02, 2, 0.01, &lid[4]);
    double slit = floor_through_slit("floor through a slit", &floor_p, &floor_five_p,
                                     &ceiling_p, lid);
    CHECK(slit > 0.0145 && slit < 0.0147);
    /* the same under a hexagonal ceiling: a 4-corner cell and a 6-corner polygon have 20
     * hull sides (room was made for a triangle cell's 18; AddressSanitizer saw the rest
     * written past it) */
    double hexagon[6][2];
    for (int k = 0; k < 6; k++) {
        double angle = -RAD_PI / 3 * k; /* clockwise seen from above: counter-clockwise
                                            from below, where it faces */
        hexagon[k][0] = 0.5 + 2 * cos(angle);
        hexagon[k][1] = 0.5 + 2 * sin(angle);
    }
    vf_polygon hexagon_p = flat_polygon(&hexagon[0][0], 6, 1, -1);
    CHECK(floor_through_slit("the same under a hexagon", &floor_p, &floor_five_p, &hexagon_p,
                             lid) > 0);

    /* the protocol, on the wedge over a slope (so that cells split both ways and in
     * strips): with every cell told again before its own points come back, and with the
     * one told last at its level and slot selected instead (as the view factors do) */
    for (int variant = 0; variant < 6; variant++) {
        bool selecting = variant % 2, probing = variant >= 2, cross = variant >= 4;
        static protocol p;
        p = (protocol){0};
        p.cross = cross;
        /* with the probes, no forced splits (as the view factors take them) */
        parallelogram_integral told = {
            protocol_f,  &p, 8, NULL, protocol_cell, probing ? 0 : 2, true,
            selecting ? protocol_select : NULL, probing};
        value = parallelogram_integrate_within(&told, v3(0, 0, 0), v3(2, 0, 0), v3(0, 1, 0),
                                               1e-6, 0, &bound);
        /* the wedge: 0.01 + 0.25 y over [0, 2] x [0, 1]; the cross: 3 + 10 x 0.04 + 20 x 0.01 */
        double expected = cross ? 3.6 : 0.26;
        printf("protocol (%s%s%s): %lu cells told, %lu selected, %lu points, %lu outside the "
               "cell told last, %lu cells outside their parent, the whole visited %lu times; "
               "value %.9g, exact %.9g, bound %.2g\n",
               selecting ? "selected" : "told again", probing ? ", probes" : "",
               cross ? ", two ridges crossing" : "", p.cells, p.selected, p.points,
               p.outside_now, p.outside_parent, p.root_visits, value, expected, bound);
        CHECK(p.cells > 16);
        CHECK(selecting ? p.selected > 0 : p.selected == 0);
        CHECK(p.outside_now == 0);
        CHECK(p.outside_parent == 0);
        CHECK(fabs(value - expected) <= bound);
        if (cross) { /* an outlier on a ridge: the second pass ran, under the same protocol */
            CHECK(p.root_visits >= 3);
            /* and resolved both ridges: strips split to the deepest across one, tall across
             * the other, were left with a bound of 0.17 */
            CHECK(bound <= 3e-3 * expected);
        }
    }
    return test_finish("test_parallelogram_integral");
}
