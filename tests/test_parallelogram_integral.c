/*
 * test_parallelogram_integral.c - the adaptive integral over a parallelogram (src/geometry/
 * parallelogram_integral.c) against integrals worked out by hand: which polygons are
 * parallelograms; a polynomial of degree 5 in each direction is exact on the first rule; a
 * kink along a line parallel to an edge (what a rectilinear scene's shadows make) reaches
 * its tolerance with a small part of the points the triangle splitting of
 * polygon_integral.c takes; a thin wedge of light along an edge, which no rule point sees
 * at the first splits, is found by the edge check; and the cell callback's protocol holds:
 * every point lies in the cell told last, and every cell in the one its level and parent
 * slot name.
 */
#include <math.h>
#include <stdio.h>

#include "core/vec3.h"
#include "geometry/parallelogram_integral.h"
#include "geometry/polygon_integral.h"
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
    unsigned long points, cells, outside_now, outside_parent;
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
    return false; /* as where shadows may fall: split to min_splits, edge check on */
}

static double protocol_f(void *context, rad_vec3 x)
{
    protocol *p = context;
    p->points++;
    p->outside_now += !in_cell(p->now, x);
    double w = 0.02;
    return wedge(x, &w) + 0.25 * x.y;
}

int main(void)
{
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
                                           check == 1};
        double value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(2, 0, 0),
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
    parallelogram_integral strips = {counted_f, &strips_count, 8, NULL, NULL, 2, true};
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
        parallelogram_integral integral = {counted_f, &c, 8, NULL, NULL, 2, check == 1};
        double value = parallelogram_integrate_within(&integral, v3(0, 0, 0), v3(2, 0, 0),
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

    /* the protocol, on the wedge over a slope (so that cells split both ways and in
     * strips) */
    static protocol p;
    parallelogram_integral told = {protocol_f, &p, 8, NULL, protocol_cell, 2, true};
    double value = parallelogram_integrate_within(&told, v3(0, 0, 0), v3(2, 0, 0), v3(0, 1, 0),
                                                  1e-6, 0, &bound);
    printf("protocol: %lu cells told, %lu points, %lu outside the cell told last, %lu cells "
           "outside their parent; value %.9g, exact %.9g\n",
           p.cells, p.points, p.outside_now, p.outside_parent, value, 0.01 + 0.25);
    CHECK(p.cells > 16);
    CHECK(p.outside_now == 0);
    CHECK(p.outside_parent == 0);
    CHECK(fabs(value - 0.26) <= bound);
    return test_finish("test_parallelogram_integral");
}
