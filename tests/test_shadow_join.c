/*
 * test_shadow_join.c - occluding triangles joined into polygons (shadow_join_occluders,
 * src/surface_viewfactors/shadow_clip.c) and the exact point factor behind them: a square
 * given as 4 triangles in two strips becomes one quadrilateral, and the factor behind it
 * from a point above a square receiver matches the closed form (the receiver less the
 * shadow, both rectangles seen from above their centre) as the triangles' own does;
 * triangles in two planes, meeting at a corner only, or whose union is not convex (an L)
 * are not joined, and the factor behind whatever is left is the triangles'; a 2 x 2 grid of
 * squares in 20 shuffled orders joins into at most 4 polygons (into 1 in some order) that
 * cast the triangles' shadow. Not here: the
 * pair integrals built on it (test_viewfactor_obstructed).
 */
#include <math.h>
#include <stdio.h>

#include "closed_forms.h"
#include "core/random.h"
#include "core/vec3.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"
#include "testlib.h"

/* F from a point at height h above a corner of a parallel a x b rectangle, facing it
 * (Howell's catalogue, differential element to a parallel rectangle). */
static double corner_factor(double a, double b, double h)
{
    double A = a / h, B = b / h;
    double sa = sqrt(1 + A * A), sb = sqrt(1 + B * B);
    return (A / sa * atan(B / sa) + B / sb * atan(A / sb)) / (2 * pi);
}

/* The square [x0, x1] x [y0, y1] at height z as two triangles, counter-clockwise about +z. */
static void square(double x0, double x1, double y0, double y1, double z, shadow_occluder *out)
{
    out[0] = (shadow_occluder){{v3(x0, y0, z), v3(x1, y0, z), v3(x1, y1, z)}};
    out[1] = (shadow_occluder){{v3(x0, y0, z), v3(x1, y1, z), v3(x0, y1, z)}};
}

static vf_polygon receiver_square(void)
{
    vf_polygon r = {0};
    r.count = 4;
    r.vertex[0] = v3(0, 0, 0);
    r.vertex[1] = v3(2, 0, 0);
    r.vertex[2] = v3(2, 2, 0);
    r.vertex[3] = v3(0, 2, 0);
    r.normal = v3(0, 0, 1);
    vf_polygon_finish(&r);
    return r;
}

/* The factor behind the triangles and behind what they join into agree at random points
 * above the receiver, looking down at it (to 1e-9: the contour formula's arc tangent is
 * good to 2e-10 per edge, and the triangles' shadows leave more edges). */
static void check_same_factor(const char *what, const shadow_occluder *triangles,
                              uint32_t count, const shadow_polygon *joined, uint32_t joined_count)
{
    vf_polygon r = receiver_square();
    rad_rng rng = rad_rng_seed(7, count, joined_count);
    double worst = 0;
    for (int k = 0; k < 200; k++) {
        rad_vec3 x = v3(-1 + 4 * rad_rng_uniform(&rng), -1 + 4 * rad_rng_uniform(&rng),
                        1.5 + 3 * rad_rng_uniform(&rng));
        rad_vec3 n = v3_normalize(v3(0.3 * (rad_rng_uniform(&rng) - 0.5),
                                     0.3 * (rad_rng_uniform(&rng) - 0.5), -1));
        double a = shadow_visible_factor(x, n, &r, triangles, count, 1e-9);
        double b = shadow_visible_factor_polygons(x, n, &r, joined, joined_count, 1e-9);
        CHECK(a >= 0 && b >= 0);
        worst = fmax(worst, fabs(a - b));
    }
    printf("%s: %u triangles joined into %u; largest difference of 200 point factors %.3g\n",
           what, count, joined_count, worst);
    CHECK(worst <= 1e-9);
}

int main(void)
{
    /* a square occluder [0.5, 1.5]^2 at z = 1 as two strips of two triangles (the strips'
     * corners repeated, as an OBJ with its own corners per quad gives them) */
    shadow_occluder wall[4];
    square(0.5, 1.5, 0.5, 1, 1, &wall[0]);
    square(0.5, 1.5, 1, 1.5, 1, &wall[2]);
    shadow_polygon joined[6]; /* room for the most triangles below */
    uint32_t count = shadow_join_occluders(wall, 4, joined);
    CHECK(count == 1);
    CHECK(count == 1 && joined[0].count == 4);
    check_same_factor("square in two strips", wall, 4, joined, count);
    /* from (1, 1, 3) looking down: the shadow is the square scaled by 3 / 2 about the centre,
     * [0.25, 1.75]^2; visible = the receiver [0, 2]^2 less it */
    vf_polygon r = receiver_square();
    double expected = 4 * corner_factor(1, 1, 3) - 4 * corner_factor(0.75, 0.75, 3);
    double by_polygon =
        shadow_visible_factor_polygons(v3(1, 1, 3), v3(0, 0, -1), &r, joined, count, 1e-9);
    double by_triangles = shadow_visible_factor(v3(1, 1, 3), v3(0, 0, -1), &r, wall, 4, 1e-9);
    printf("behind the square from above its centre: joined %.15f, triangles %.15f, closed "
           "form %.15f\n",
           by_polygon, by_triangles, expected);
    CHECK_NEAR(by_polygon, expected, 1e-9);
    CHECK_NEAR(by_triangles, expected, 1e-9);

    /* two triangles folded along their shared edge: two planes, not joined */
    shadow_occluder fold[2];
    square(0.5, 1.5, 0.5, 1.5, 1, fold);
    fold[1].corner[2].z = 1.2;
    count = shadow_join_occluders(fold, 2, joined);
    CHECK(count == 2);
    check_same_factor("folded pair", fold, 2, joined, count);

    /* two triangles meeting at a corner only */
    shadow_occluder touching[2] = {
        {{v3(0.2, 0.2, 1), v3(1, 0.2, 1), v3(1, 1, 1)}},
        {{v3(1, 1, 1), v3(1.8, 1, 1), v3(1.8, 1.8, 1)}}};
    count = shadow_join_occluders(touching, 2, joined);
    CHECK(count == 2);
    check_same_factor("corner only", touching, 2, joined, count);

    /* an L of three unit squares (six triangles): its union is not convex */
    shadow_occluder l_shape[6];
    square(0.2, 0.8, 0.2, 0.8, 1, &l_shape[0]);
    square(0.8, 1.4, 0.2, 0.8, 1, &l_shape[2]);
    square(0.2, 0.8, 0.8, 1.4, 1, &l_shape[4]);
    count = shadow_join_occluders(l_shape, 6, joined);
    CHECK(count == 2);
    check_same_factor("L of three squares", l_shape, 6, joined, count);

    /* a 2 x 2 grid of squares as 8 triangles in shuffled orders: a join can make an
     * earlier polygon joinable (the search goes back for it); whatever joins, the shadow
     * covers the same points, and two triangles of one square that meet first always join */
    shadow_occluder grid[8], shuffled[8];
    square(0.4, 1.0, 0.4, 1.0, 1, &grid[0]);
    square(1.0, 1.6, 0.4, 1.0, 1, &grid[2]);
    square(0.4, 1.0, 1.0, 1.6, 1, &grid[4]);
    square(1.0, 1.6, 1.0, 1.6, 1, &grid[6]);
    shadow_polygon grid_joined[8];
    rad_rng order = rad_rng_seed(11, 8, 0);
    uint32_t fewest = 8, most = 0;
    for (int trial = 0; trial < 20; trial++) {
        for (int k = 0; k < 8; k++)
            shuffled[k] = grid[k];
        for (int k = 7; k > 0; k--) {
            int swap = (int)(rad_rng_uniform(&order) * (k + 1));
            shadow_occluder keep = shuffled[k];
            shuffled[k] = shuffled[swap];
            shuffled[swap] = keep;
        }
        count = shadow_join_occluders(shuffled, 8, grid_joined);
        CHECK(count >= 1 && count <= 4);
        fewest = count < fewest ? count : fewest;
        most = count > most ? count : most;
        check_same_factor("2 x 2 grid, shuffled", shuffled, 8, grid_joined, count);
    }
    printf("2 x 2 grid in 20 orders: %u to %u polygons\n", fewest, most);
    CHECK(fewest == 1);
    return test_finish("test_shadow_join");
}
