/*
 * test_polygon_pair.c - the double contour integral between two polygons
 * (geometry/polygon_pair.h) against the catalogue's closed forms (VALIDATION.md section 1)
 * and against an independent integral: perpendicular rectangles sharing an edge (aspect
 * ratios 0.05 to 20), directly opposed parallel rectangles, the same pairs turned and
 * wound either way, a rectangle partly behind the other's plane (clipped), two triangles
 * meeting at a corner at an odd angle (no parallel edges: every edge pair integrated
 * numerically) against the point-to-polygon contour formula integrated over a fine
 * triangle lattice, and reciprocity; far apart, the kernel's second-order expansion about
 * both centroids against the exact transfer.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
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

/* A rectangle (count 4, half-sides a, b) or a triangle (count 3) centred at c in the plane
 * with unit normal n, counter-clockwise about n. */
static void test_polygon_in_plane(rad_vec3 c, rad_vec3 n, double a, double b, unsigned count,
                                  rad_vec3 *out)
{
    rad_vec3 t = fabs(n.x) < 0.9 ? (rad_vec3){1, 0, 0} : (rad_vec3){0, 1, 0};
    rad_vec3 u = v3_normalize(v3_cross(t, n)), v = v3_cross(n, u);
    if (count == 4) {
        const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int k = 0; k < 4; k++)
            out[k] = v3_add(c, v3_add(v3_scale(u, s[k][0] * a), v3_scale(v, s[k][1] * b)));
        return;
    }
    out[0] = v3_add(c, v3_add(v3_scale(u, -a), v3_scale(v, -b)));
    out[1] = v3_add(c, v3_add(v3_scale(u, a), v3_scale(v, -0.3 * b)));
    out[2] = v3_add(c, v3_add(v3_scale(u, -0.2 * a), v3_scale(v, b)));
}

/* The largest distance from the polygon's area centroid to a corner. */
static double test_polygon_radius(const rad_vec3 *corner, unsigned count)
{
    polygon_moments m;
    polygon_moments_of(corner, count, (rad_vec3){0, 0, 1}, &m);
    double r = 0;
    for (unsigned k = 0; k < count; k++)
        r = fmax(r, v3_length(v3_sub(corner[k], m.centroid)));
    return r;
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
        /* the form factors' tolerance (pair_engine.c) */
        CHECK_NEAR(polygon_pair_transfer(p, 3, up, q, 3, qn, 0, 1e-7) / g, 1, 1e-6);
    }
    /* far apart: the second-order expansion about both centroids against the exact
     * transfer, rectangles and triangles turned at random, 3 to 12 times the sum of their
     * radii apart (farther, the exact transfer's own cancellation shows), each wholly in
     * front of the other; its error falls as (R / D)^4 and the one-point rule's as
     * (R / D)^2 */
    {
        uint64_t state = 12345;
        double worst_expansion = 0, worst_point = 0;
        unsigned cases = 0;
        for (int trial = 0; trial < 3000; trial++) {
            double r[8];
            for (int k = 0; k < 8; k++) {
                state = state * 6364136223846793005u + 1442695040888963407u;
                r[k] = (double)(state >> 11) * 0x1p-53;
            }
            rad_vec3 pn = v3_normalize((rad_vec3){r[0] - 0.5, r[1] - 0.5, 1});
            rad_vec3 qn_hint = v3_normalize((rad_vec3){r[2] - 0.5, r[3] - 0.5, r[4] - 0.5});
            rad_vec3 p[4], q[4];
            unsigned np = trial % 3 == 0 ? 3 : 4, nq = trial % 5 == 0 ? 3 : 4;
            test_polygon_in_plane((rad_vec3){0, 0, 0}, pn, 0.5, 0.2 + 0.6 * r[5], np, p);
            double distance_share = 3 + 9 * r[6] * r[6];
            rad_vec3 direction = v3_normalize((rad_vec3){r[7] - 0.5, r[5] - 0.5, 1.2});
            double rp = test_polygon_radius(p, np);
            double rq_guess = 0.6;
            rad_vec3 centre = v3_scale(direction, distance_share * (rp + rq_guess));
            rad_vec3 qn = v3_normalize(v3_sub(qn_hint, direction));
            test_polygon_in_plane(centre, qn, 0.4 + 0.3 * r[0], 0.35, nq, q);
            polygon_moments mp, mq;
            polygon_moments_of(p, np, pn, &mp);
            polygon_moments_of(q, nq, qn, &mq);
            double R = test_polygon_radius(p, np) + test_polygon_radius(q, nq);
            double D = v3_length(v3_sub(mq.centroid, mp.centroid));
            bool in_front = true;
            for (unsigned k = 0; k < nq; k++)
                in_front = in_front && v3_dot(pn, v3_sub(q[k], mp.centroid)) >= 0;
            for (unsigned k = 0; k < np; k++)
                in_front = in_front && v3_dot(qn, v3_sub(p[k], mq.centroid)) >= 0;
            if (!in_front || D < 3 * R)
                continue;
            double exact = polygon_pair_transfer(p, np, pn, q, nq, qn, 0, 1e-12);
            if (!(exact > 0))
                continue;
            double expanded = polygon_pair_expansion(&mp, &mq);
            double point = mp.area * contour_point_to_polygon(mp.centroid, pn, q, nq, qn, 0);
            /* errors on the scale of the pair's transfer seen head-on, A_p A_q / (pi D^2):
             * relative to the value itself they grow without bound as a cosine nears 0 */
            double head_on = mp.area * mq.area / (3.14159265358979 * D * D);
            double scale2 = (D / R) * (D / R);
            worst_expansion = fmax(worst_expansion,
                                   fabs(expanded - exact) / head_on * scale2 * scale2);
            worst_point = fmax(worst_point, fabs(point - exact) / head_on * scale2);
            cases++;
        }
        printf("far pairs (%u): expansion within %.3f (R/D)^4, one point within %.3f (R/D)^2\n",
               cases, worst_expansion, worst_point);
        CHECK(cases > 1000);
        CHECK(worst_expansion < 0.3);
        CHECK(worst_point > 0.05); /* the expansion's reason to be: the rule it replaces errs */
    }
    return test_finish("test_polygon_pair");
}
