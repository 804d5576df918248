/*
 * test_polygon_pair.c - the double contour integral between two polygons
 * (geometry/polygon_pair.h) against the catalogue's closed forms (VALIDATION.md section 1)
 * and against an independent integral: perpendicular rectangles sharing an edge (aspect
 * ratios 0.05 to 20), directly opposed parallel rectangles, the same pairs turned and
 * wound either way, a rectangle partly behind the other's plane (clipped), two triangles
 * meeting at a corner at an odd angle (no parallel edges: every edge pair integrated
 * numerically) against the point-to-polygon contour formula integrated over a fine
 * triangle lattice, and reciprocity.
 */
#include <math.h>
#include <stdio.h>

#include "closed_forms.h"
#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/polygon_pair.h"
#include "testlib.h"

#define ACCURACY 1e-9

/* An arbitrary rotation and shift, so that no edge lies along an axis. */
static rad_vec3 moved(rad_vec3 x)
{
    const double a = 0.7, b = -0.4;
    rad_vec3 y = {cos(a) * x.x - sin(a) * x.y, sin(a) * x.x + cos(a) * x.y, x.z};
    rad_vec3 z = {y.x, cos(b) * y.y - sin(b) * y.z, sin(b) * y.y + cos(b) * y.z};
    return v3_add(z, (rad_vec3){3.1, -2.2, 17.5});
}

static rad_vec3 moved_direction(rad_vec3 n)
{
    return v3_sub(moved(n), moved((rad_vec3){0, 0, 0}));
}

static double transfer(const rad_vec3 *p, unsigned np, rad_vec3 pn, const rad_vec3 *q,
                       unsigned nq, rad_vec3 qn, int turned)
{
    if (!turned)
        return polygon_pair_transfer(p, np, pn, q, nq, qn, 0, ACCURACY);
    rad_vec3 mp[8], mq[8];
    for (unsigned k = 0; k < np; k++)
        mp[k] = moved(p[k]);
    for (unsigned k = 0; k < nq; k++)
        mq[k] = moved(q[k]);
    return polygon_pair_transfer(mp, np, moved_direction(pn), mq, nq, moved_direction(qn), 0,
                                 ACCURACY);
}

/* The point-to-polygon factor from q's points, integrated over triangle p (n x n similar
 * sub-triangles, Richardson-extrapolated between n and 2n: the integrand is smooth away
 * from p's corner that q touches, where it is bounded). */
static double lattice_transfer(const rad_vec3 *p, rad_vec3 pn, const rad_vec3 *q, unsigned nq,
                               rad_vec3 qn, unsigned n)
{
    double sums[2];
    for (int level = 0; level < 2; level++) {
        unsigned m = n << level;
        rad_vec3 a = p[0], ab = v3_sub(p[1], a), ac = v3_sub(p[2], a);
        double area = 0.5 * v3_length(v3_cross(ab, ac)), sum = 0;
        for (unsigned j = 0; j < m; j++)
            for (unsigned i = 0; i + j < m; i++) {
                double u = (i + 1.0 / 3) / m, v = (j + 1.0 / 3) / m;
                sum += contour_point_to_polygon(
                    v3_add(a, v3_add(v3_scale(ab, u), v3_scale(ac, v))), pn, q, nq, qn, 0);
                if (i + j + 1 < m) {
                    u = (i + 2.0 / 3) / m;
                    v = (j + 2.0 / 3) / m;
                    sum += contour_point_to_polygon(
                        v3_add(a, v3_add(v3_scale(ab, u), v3_scale(ac, v))), pn, q, nq, qn, 0);
                }
            }
        sums[level] = area * sum / ((double)m * m);
    }
    return sums[1] + (sums[1] - sums[0]) / 3; /* the midpoint rule's error falls as 1/m^2 */
}

int main(void)
{
    const rad_vec3 up = {0, 0, 1}, down = {0, 0, -1}, along_y = {0, 1, 0};

    /* perpendicular rectangles sharing the edge l along x: floor w x l (normal +z) and wall
     * h x l (normal +y) at y = 0, both ways round, wound either way, turned */
    const double ratios[] = {0.05, 0.2, 1, 3, 20};
    double worst = 0;
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 5; b++)
            for (int turned = 0; turned < 2; turned++) {
                double l = 1.3, w = ratios[a] * l, h = ratios[b] * l;
                rad_vec3 floor_ccw[4] = {{0, 0, 0}, {l, 0, 0}, {l, w, 0}, {0, w, 0}};
                rad_vec3 floor_cw[4] = {{0, 0, 0}, {0, w, 0}, {l, w, 0}, {l, 0, 0}};
                rad_vec3 wall[4] = {{0, 0, 0}, {0, 0, h}, {l, 0, h}, {l, 0, 0}};
                double expected = w * l * perpendicular_rectangles(w, h, l);
                double g1 = transfer(floor_ccw, 4, up, wall, 4, along_y, turned);
                double g2 = transfer(floor_cw, 4, up, wall, 4, along_y, turned);
                double g3 = transfer(wall, 4, along_y, floor_ccw, 4, up, turned);
                CHECK_NEAR(g1 / expected, 1, 1e-7);
                CHECK_NEAR(g2 / expected, 1, 1e-7);
                CHECK_NEAR(g3 / expected, 1, 1e-7);
                worst = fmax(worst, fabs(g1 / expected - 1));
            }
    printf("perpendicular rectangles sharing an edge: worst relative error %.2e\n", worst);

    /* directly opposed parallel rectangles a x b at distance c */
    const double sizes[] = {0.1, 1, 2, 7};
    worst = 0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            for (int turned = 0; turned < 2; turned++) {
                double a = sizes[i], b = sizes[j], c = 1.7;
                rad_vec3 lower[4] = {{0, 0, 0}, {a, 0, 0}, {a, b, 0}, {0, b, 0}};
                rad_vec3 upper[4] = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
                double expected = a * b * parallel_rectangles(a, b, c);
                double g = transfer(lower, 4, up, upper, 4, down, turned);
                CHECK_NEAR(g / expected, 1, 1e-7);
                worst = fmax(worst, fabs(g / expected - 1));
            }
    printf("parallel opposed rectangles: worst relative error %.2e\n", worst);

    /* a wall reaching below the floor's plane: only its part above counts (clipped), and a
     * wall wholly behind the floor sees nothing */
    {
        double l = 2, w = 1.5, h = 0.8;
        rad_vec3 floor[4] = {{0, 0, 0}, {l, 0, 0}, {l, w, 0}, {0, w, 0}};
        rad_vec3 deep_wall[4] = {{0, 0, -0.6}, {0, 0, h}, {l, 0, h}, {l, 0, -0.6}};
        rad_vec3 buried[4] = {{0, 0, -1.6}, {0, 0, -0.1}, {l, 0, -0.1}, {l, 0, -1.6}};
        double expected = w * l * perpendicular_rectangles(w, h, l);
        CHECK_NEAR(polygon_pair_transfer(floor, 4, up, deep_wall, 4, along_y, 0, ACCURACY) /
                       expected,
                   1, 1e-7);
        CHECK(polygon_pair_transfer(floor, 4, up, buried, 4, along_y, 0, ACCURACY) == 0);
    }

    /* two triangles meeting at a corner at an odd angle, no two edges parallel: against
     * the contour formula integrated over a fine lattice, and reciprocity */
    {
        rad_vec3 p[3] = {{0, 0, 0}, {1.2, 0.1, 0}, {0.3, 0.9, 0}};
        rad_vec3 q[3] = {{0, 0, 0}, {0.2, 1.1, 0.7}, {-0.9, 0.4, 0.5}};
        rad_vec3 qn = v3_normalize(v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0])));
        if (v3_dot(qn, (rad_vec3){0.4, 0.1, 0}) < 0) /* facing p's points */
            qn = v3_scale(qn, -1);
        double g = polygon_pair_transfer(p, 3, up, q, 3, qn, 0, ACCURACY);
        double back = polygon_pair_transfer(q, 3, qn, p, 3, up, 0, ACCURACY);
        double lattice = lattice_transfer(p, up, q, 3, qn, 256);
        printf("triangles at a corner: %.9f, reversed %.9f, lattice %.9f\n", g, back, lattice);
        CHECK(g > 0);
        CHECK_NEAR(back / g, 1, 1e-9);
        CHECK_NEAR(lattice / g, 1, 2e-4);
    }
    return test_finish("test_polygon_pair");
}
