/*
 * test_shadow_clip.c - the exact point factor behind many occluders
 * (src/surface_viewfactors/shadow_clip.c) where their shadows share edges and corners: a
 * wall of a generated city block looking at a wall of another block past three buildings
 * (ten faces, the geometry of a pair that came out 5.8 % visible where brute force finds
 * 0.005 %). At a grid of points on the first wall the factor must not exceed the factor
 * behind any one of the faces (more occluders never show more), must be 0 wherever one
 * face alone covers the receiver, and must match the test's own Monte-Carlo integral over
 * the receiver (segments tested against every face by the test's own code). A receiver
 * given with a corner twice (as the part of a polygon in front of a plane through its
 * corner comes) behind a face covering it: 0. The part in front of a plane
 * (vf_polygon_clip_front): a corner on the plane kept once. Not here: the joining of
 * triangles (test_shadow_join) and the pair integrals (test_viewfactor_obstructed).
 */
#include <math.h>
#include <stdio.h>

#include "core/random.h"
#include "core/vec3.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"
#include "testlib.h"

static const double pi = 3.14159265358979323846;

#define FACES 10

/* The faces of the three buildings in between, as the occluder tree collected them (a roof
 * triangle of the first building is all of its roof that cuts the pair's hull). */
static const shadow_polygon faces[FACES] = {
    {{{202, 0, 122}, {212, 0, 122}, {212, 16.3298, 122}, {202, 16.3298, 122}}, 4},
    {{{202, 16.3298, 112}, {202, 16.3298, 122}, {212, 16.3298, 122}, {212, 16.3298, 112}}, 4},
    {{{194, 0, 94}, {184, 0, 94}, {184, 9.30341, 94}, {194, 9.30341, 94}}, 4},
    {{{212, 0, 122}, {212, 0, 112}, {212, 16.3298, 112}, {212, 16.3298, 122}}, 4},
    {{{184, 9.30341, 94}, {194, 9.30341, 104}, {194, 9.30341, 94}}, 3},
    {{{194, 0, 104}, {194, 0, 94}, {194, 9.30341, 94}, {194, 9.30341, 104}}, 4},
    {{{202, 0, 94}, {202, 0, 104}, {202, 14.3712, 104}, {202, 14.3712, 94}}, 4},
    {{{202, 0, 112}, {202, 0, 122}, {202, 16.3298, 122}, {202, 16.3298, 112}}, 4},
    {{{202, 0, 104}, {212, 0, 104}, {212, 14.3712, 104}, {202, 14.3712, 104}}, 4},
    {{{212, 0, 112}, {202, 0, 112}, {202, 16.3298, 112}, {212, 16.3298, 112}}, 4},
};

/* Where the segment from x to y crosses the convex flat face strictly between its ends. */
static bool segment_blocked(rad_vec3 x, rad_vec3 y, const shadow_polygon *face)
{
    rad_vec3 n = v3_cross(v3_sub(face->vertex[1], face->vertex[0]),
                          v3_sub(face->vertex[2], face->vertex[0]));
    double dx = v3_dot(n, v3_sub(x, face->vertex[0])), dy = v3_dot(n, v3_sub(y, face->vertex[0]));
    if ((dx > 0) == (dy > 0) || dx == dy)
        return false;
    double t = dx / (dx - dy);
    if (t <= 1e-9 || t >= 1 - 1e-9)
        return false;
    rad_vec3 c = v3_lerp(x, y, t);
    for (unsigned k = 0; k < face->count; k++) {
        rad_vec3 a = face->vertex[k], b = face->vertex[(k + 1) % face->count];
        if (v3_dot(n, v3_cross(v3_sub(b, a), v3_sub(c, a))) < 0)
            return false;
    }
    return true;
}

/* F from x (normal n) to the receiver past every face: uniform points of the receiver,
 * the kernel cos cos / (pi r^2) of those whose segment no face blocks. */
static double monte_carlo(rad_vec3 x, rad_vec3 n, const vf_polygon *receiver, unsigned samples,
                          double *standard_error)
{
    rad_rng rng = rad_rng_seed(11, (uint64_t)(x.x * 1000), (uint64_t)(x.y * 1000));
    double sum = 0, squares = 0;
    rad_vec3 o = receiver->vertex[0], u = v3_sub(receiver->vertex[1], o),
             v = v3_sub(receiver->vertex[3], o);
    for (unsigned k = 0; k < samples; k++) {
        rad_vec3 y = v3_add(o, v3_add(v3_scale(u, rad_rng_uniform(&rng)),
                                      v3_scale(v, rad_rng_uniform(&rng))));
        rad_vec3 d = v3_sub(y, x);
        double r2 = v3_dot(d, d), cx = v3_dot(n, d), cy = -v3_dot(receiver->normal, d);
        double value = cx > 0 && cy > 0 ? receiver->area * cx * cy / (pi * r2 * r2) : 0;
        for (unsigned f = 0; f < FACES && value > 0; f++)
            if (segment_blocked(x, y, &faces[f]))
                value = 0;
        sum += value;
        squares += value * value;
    }
    double mean = sum / samples;
    *standard_error = sqrt(fmax(squares / samples - mean * mean, 0) / samples);
    return mean;
}

/* The convex polygon a b c d with its front normal. */
static vf_polygon quad(rad_vec3 a, rad_vec3 b, rad_vec3 c, rad_vec3 d, rad_vec3 normal)
{
    vf_polygon polygon = {0};
    polygon.count = 4;
    polygon.vertex[0] = a;
    polygon.vertex[1] = b;
    polygon.vertex[2] = c;
    polygon.vertex[3] = d;
    polygon.normal = normal;
    vf_polygon_finish(&polygon);
    return polygon;
}

/* The part of a polygon in front of a plane through one of its corners keeps that corner
 * once; a part with more corners than a polygon holds is the whole polygon. */
static void check_clip_front(void)
{
    vf_polygon diamond =
        quad(v3(3, 0.5, 0), v3(3, 0, 0.5), v3(3, 0.5, 1), v3(3, 1, 0.5), v3(-1, 0, 0));
    vf_polygon part;
    CHECK(vf_polygon_clip_front(&diamond, v3(0, 0, 1), 0, &part));
    CHECK(part.count == 4);
    CHECK(fabs(part.area - diamond.area) <= 1e-15);
    /* the same a hair behind the plane: still 4 corners, not a pair 1e-16 apart */
    CHECK(vf_polygon_clip_front(&diamond, v3(0, 0, 1), 1e-16, &part));
    CHECK(part.count == 4);
    /* a hexagon with one corner cut off would have 7: the whole hexagon comes back */
    vf_polygon hexagon = {0};
    hexagon.count = 6;
    for (unsigned k = 0; k < 6; k++)
        hexagon.vertex[k] = v3(cos(k * pi / 3), sin(k * pi / 3), 0);
    hexagon.normal = v3(0, 0, 1);
    vf_polygon_finish(&hexagon);
    CHECK(vf_polygon_clip_front(&hexagon, v3(-1, 0, 0), -0.9, &part));
    CHECK(part.count == 6 && part.area == hexagon.area);
    /* wholly behind: nothing */
    CHECK(!vf_polygon_clip_front(&hexagon, v3(1, 0, 0), 2, &part));
}

/* A receiver with a corner given twice (exactly, or 3e-16 apart) behind a face that covers
 * it: the factor is 0, as without the repeat (the repeated corner is an edge with no
 * direction, which `separated` once took for a side with the shadow outside). */
static void check_repeated_corner(void)
{
    const shadow_polygon cover = {{{-1, -1, 1}, {2, -1, 1}, {2, 2, 1}, {-1, 2, 1}}, 4};
    for (int variant = 0; variant < 3; variant++) {
        vf_polygon receiver =
            quad(v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0), v3(0, 1, 0), v3(0, 0, 1));
        receiver.vertex[receiver.count++] =
            variant == 0 ? v3(0, 1, 0) : v3(0, 1 - 3e-16 * variant, 0);
        vf_polygon_finish(&receiver);
        rad_rng rng = rad_rng_seed(3, (uint64_t)variant, 0);
        double largest = 0;
        for (int k = 0; k < 100; k++) {
            rad_vec3 x = v3(-0.5 + 2 * rad_rng_uniform(&rng), -0.5 + 2 * rad_rng_uniform(&rng),
                            1.5 + rad_rng_uniform(&rng));
            largest = fmax(largest, shadow_visible_factor_polygons(x, v3(0, 0, -1), &receiver,
                                                                   &cover, 1, 1e-9));
        }
        printf("receiver with a repeated corner (%s) behind a face covering it: largest of 100 "
               "point factors %.3g\n",
               variant == 0 ? "exactly" : variant == 1 ? "3e-16 apart" : "6e-16 apart", largest);
        CHECK(largest == 0);
    }
}

int main(void)
{
    check_clip_front();
    check_repeated_corner();
    /* the receiver: a wall at x = 220 facing -x; the points: a wall at z = 86 facing +z */
    vf_polygon receiver = quad(v3(220, 0, 130), v3(220, 0, 140), v3(220, 23.3561, 140),
                               v3(220, 23.3561, 130), v3(-1, 0, 0));
    rad_vec3 n = v3(0, 0, 1);
    double worst_excess = 0, worst_covered = 0, worst_z = 0, largest = 0;
    unsigned covered = 0;
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++) {
            rad_vec3 x = v3(184 + (i + 0.5), 7.34482 * (j + 0.5) / 10, 86);
            double all = shadow_visible_factor_polygons(x, n, &receiver, faces, FACES, 1e-9);
            CHECK(all >= 0);
            double least = INFINITY;
            for (unsigned f = 0; f < FACES; f++)
                least = fmin(least, shadow_visible_factor_polygons(x, n, &receiver, &faces[f], 1,
                                                                   1e-9));
            worst_excess = fmax(worst_excess, all - least);
            if (least == 0) {
                covered++;
                worst_covered = fmax(worst_covered, all);
            }
            double standard_error, reference = monte_carlo(x, n, &receiver, 4096, &standard_error);
            worst_z = fmax(worst_z, fabs(all - reference) / (standard_error + 1e-7));
            largest = fmax(largest, all);
        }
    printf("wall past three buildings, 100 points: largest factor %.3g; largest excess over "
           "one face's %.3g; %u points covered by one face, largest factor there %.3g; "
           "largest |exact - Monte Carlo| %.2f standard errors\n",
           largest, worst_excess, covered, worst_covered, worst_z);
    CHECK(worst_excess <= 1e-12);
    CHECK(covered > 50);
    CHECK(worst_covered == 0);
    CHECK(worst_z < 5);
    return test_finish("test_shadow_clip");
}
