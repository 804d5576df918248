/*
 * test_convex_solids.c - convex solids among a scene's triangles (convex_solids_find,
 * src/surface_viewfactors/convex_solids.c) and the occluders a pair's view leaves out
 * behind them (occluder_tree_collect).
 *
 * Found: a closed box; a building with walls of two storeys and a roof but no floor (open,
 * the missing face's plane outward down); a tetrahedron; a closed box with one wall split
 * where its neighbours are not (a T-junction: open along that wall). Not found: walls
 * alone (two open faces), an L-shaped prism (not convex), a box turned inside out, the
 * T-junction with the floor missing too, a flat sheet, a box with a face given twice.
 *
 * The exact transfer between a floor and a ceiling square is the same with the faces left
 * out as with every triangle, and both match brute-force ray casting against every
 * triangle (an independent code path): behind three boxes (closed; open below, its missing
 * face turned to the floor; open above), over a box standing on the floor (the floor lies
 * on it) and from inside a closed box. A wrong face left out lets light through a box.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec3.h"
#include "surface_viewfactors/convex_solids.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/pair_transfer.h"
#include "surface_viewfactors/vf_geometry.h"
#include "testlib.h"

/* The scene being written (testlib's OBJ text), loaded and emptied by load(). */
static test_obj obj;

enum { WALLS = 1, ROOF = 2, FLOOR = 4, STOREYS = 8, INSIDE_OUT = 16, SPLIT_ONE_WALL = 32 };

/* The box [x0, x1] x [y0, y1] x [z0, z1] facing out (in with INSIDE_OUT), of the parts
 * `parts` names; each face of its own vertices. STOREYS: walls in two storeys;
 * SPLIT_ONE_WALL: the -z wall alone in two. */
static void box(double x0, double x1, double y0, double y1, double z0, double z1, int parts)
{
    const int out = (parts & INSIDE_OUT) ? -1 : 1;
    for (int w = 0; (parts & WALLS) && w < 4; w++) { /* -z, +x, +z, -x */
        int storeys = (parts & STOREYS) || ((parts & SPLIT_ONE_WALL) && w == 0) ? 2 : 1;
        for (int k = 0; k < storeys; k++) {
            double ya = y0 + (y1 - y0) * k / storeys, yb = y0 + (y1 - y0) * (k + 1) / storeys;
            if (w % 2 == 0) /* in a z plane: (x, y) */
                test_obj_rectangle(&obj, 2, w == 0 ? z0 : z1, x0, ya, x1, yb, w == 0 ? -out : out);
            else /* in an x plane: (y, z) */
                test_obj_rectangle(&obj, 0, w == 1 ? x1 : x0, ya, z0, yb, z1, w == 1 ? out : -out);
        }
    }
    if (parts & ROOF) /* in a y plane: (z, x) */
        test_obj_rectangle(&obj, 1, y1, z0, x0, z1, x1, out);
    if (parts & FLOOR)
        test_obj_rectangle(&obj, 1, y0, z0, x0, z1, x1, -out);
}

static rad_scene *load(const char *name, uint32_t flags)
{
    test_obj_add(&obj, "%s", ""); /* (an empty scene is text too) */
    rad_scene_file file = {test_write_file(name, obj.data), flags, true};
    /* (the OBJ's objects are its surfaces) */
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_files(&file, 1, NULL, &scene, &error) == RAD_OK);
    obj.length = 0;
    obj.vertices = 0;
    return scene;
}

/* The solids of the scene written so far: how many, and the first's openness. */
static uint32_t solids_of(const char *name, convex_solids *out)
{
    rad_scene *scene = load(name, 0);
    *out = (convex_solids){0};
    rad_error error = {0};
    if (scene)
        CHECK(convex_solids_find(scene, out, &error) == RAD_OK);
    rad_scene_destroy(scene);
    return out->count;
}

static void check_found(void)
{
    convex_solids s;
    box(0, 1, 0, 2, 0, 3, WALLS | ROOF | FLOOR);
    CHECK(solids_of("closed.obj", &s) == 1);
    CHECK(s.count == 1 && !s.solids[0].open && s.solids[0].plane_count == 6);
    convex_solids_free(&s);

    box(0, 10, 0, 22, 0, 10, WALLS | ROOF | STOREYS);
    CHECK(solids_of("building.obj", &s) == 1);
    if (s.count == 1) {
        const convex_solid *b = &s.solids[0];
        CHECK(b->open && b->plane_count == 5);
        CHECK_ABS(b->open_normal.y, -1, 1e-12);
        CHECK_ABS(b->open_offset, 0, 1e-12);
    }
    convex_solids_free(&s);

    /* two buildings side by side, apart: two solids */
    box(0, 10, 0, 22, 0, 10, WALLS | ROOF | STOREYS);
    box(18, 28, 0, 9, 0, 10, WALLS | ROOF);
    CHECK(solids_of("two.obj", &s) == 2);
    convex_solids_free(&s);

    test_obj_add(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    CHECK(solids_of("tetrahedron.obj", &s) == 1);
    convex_solids_free(&s);

    box(0, 1, 0, 2, 0, 3, WALLS);
    CHECK(solids_of("walls.obj", &s) == 0);
    convex_solids_free(&s);

    box(0, 1, 0, 2, 0, 3, WALLS | ROOF | FLOOR | INSIDE_OUT);
    CHECK(solids_of("inside_out.obj", &s) == 0);
    convex_solids_free(&s);

    /* one wall in two storeys, its neighbours whole: the edges along the T-junctions lie in
     * that wall's plane, which is then taken for a missing face (safe: only the faces seen
     * from its inner side are left out); with the floor missing too, no solid */
    box(0, 1, 0, 2, 0, 3, WALLS | ROOF | FLOOR | SPLIT_ONE_WALL);
    CHECK(solids_of("t_junction.obj", &s) == 1);
    if (s.count == 1) {
        CHECK(s.solids[0].open);
        CHECK_ABS(s.solids[0].open_normal.z, -1, 1e-12);
    }
    convex_solids_free(&s);
    box(0, 1, 0, 2, 0, 3, WALLS | ROOF | SPLIT_ONE_WALL);
    CHECK(solids_of("t_junction_open.obj", &s) == 0);
    convex_solids_free(&s);

    test_obj_rectangle(&obj, 1, 0, -1, 0, 0, 1, 1);
    CHECK(solids_of("sheet.obj", &s) == 0);
    convex_solids_free(&s);

    box(0, 1, 0, 2, 0, 3, WALLS | ROOF | FLOOR);
    box(0, 1, 0, 2, 0, 3, ROOF);
    CHECK(solids_of("twice.obj", &s) == 0);
    convex_solids_free(&s);

    /* an L-shaped prism: an outline of six corners, extruded; its reflex edge breaks it */
    const double L[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
    for (int y = 0; y < 2; y++)
        for (int k = 0; k < 6; k++)
            test_obj_add(&obj, "v %g %d %g\n", L[k][0], y, -L[k][1]);
    for (int k = 0; k < 6; k++) {
        int a = k + 1, b = (k + 1) % 6 + 1;
        test_obj_add(&obj, "f %d %d %d %d\n", a, b, b + 6, a + 6);
    }
    test_obj_add(&obj, "f 7 8 9 10\nf 7 10 11 12\nf 1 4 3 2\nf 1 6 5 4\n");
    CHECK(solids_of("ell.obj", &s) == 0);
    convex_solids_free(&s);
}

static double uniform(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*state >> 11) * 0x1.0p-53;
}

/* The share of cosine rays from uniform points of polygon `from` (a parallel-axis square
 * facing -y) whose first hit is a triangle of surface `to`: brute-force ray casting. */
static double monte_carlo(const rad_scene *scene, const vf_polygon *from, uint32_t to,
                          uint32_t rays, double *standard_error)
{
    rad_error error = {0};
    rad_tracer *tracer = NULL;
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_BRUTE_FORCE, scene, &tracer, &error) == RAD_OK);
    if (!tracer)
        return 0;
    uint64_t state = 12345, reached = 0;
    rad_ray batch[1024];
    rad_hit hits[1024];
    rad_vec3 lo = from->vertex[0], hi = from->vertex[0];
    for (unsigned k = 1; k < from->count; k++) {
        lo = v3(fmin(lo.x, from->vertex[k].x), lo.y, fmin(lo.z, from->vertex[k].z));
        hi = v3(fmax(hi.x, from->vertex[k].x), hi.y, fmax(hi.z, from->vertex[k].z));
    }
    for (uint32_t done = 0; done < rays; done += 1024) {
        for (int k = 0; k < 1024; k++) {
            double x = lo.x + (hi.x - lo.x) * uniform(&state);
            double z = lo.z + (hi.z - lo.z) * uniform(&state);
            double q = uniform(&state), phi = 2 * 3.14159265358979323846 * uniform(&state);
            double r = sqrt(q);
            batch[k] = (rad_ray){{(float)x, (float)lo.y, (float)z},
                                 1e-5f,
                                 {(float)(r * cos(phi)), (float)-sqrt(1 - q),
                                  (float)(r * sin(phi))},
                                 INFINITY};
        }
        rad_tracer_intersect(tracer, batch, 1024, hits);
        for (int k = 0; k < 1024; k++)
            reached += hits[k].triangle != RAD_NO_HIT &&
                       scene->triangles[hits[k].triangle].surface == to;
    }
    rad_tracer_destroy(tracer);
    uint32_t n = (rays + 1023) / 1024 * 1024;
    double share = (double)reached / n;
    *standard_error = sqrt(share * (1 - share) / n);
    return share;
}

/* The floor (facing up) and the ceiling (an axis-aligned square facing down) of the scene
 * written so far, whose boxes are obstructions: the occluders between them with and without
 * the faces left out (expected counts), the exact transfer behind each, against brute-force
 * ray casting from the ceiling; `blocked`: the boxes must take a good share of the light. */
static void check_exact(const char *name, uint32_t solids_expected, uint32_t all_expected,
                        uint32_t kept_expected, bool blocked)
{
    rad_scene *scene = load(name, 0);
    if (!scene)
        return;
    vf_geometry geometry;
    rad_error error = {0};
    occluder_tree *tree = NULL;
    CHECK(vf_geometry_build(scene, &geometry, &error) == RAD_OK);
    CHECK(occluder_tree_build(scene, geometry.triangle_source, true, &tree, &error) == RAD_OK);
    convex_solids solids;
    CHECK(convex_solids_find(scene, &solids, &error) == RAD_OK);
    CHECK(solids.count == solids_expected);
    convex_solids_free(&solids);
    const vf_polygon *floor_p = NULL, *ceiling_p = NULL;
    for (uint32_t k = 0; k < geometry.polygon_count; k++) {
        const vf_polygon *p = &geometry.polygons[k];
        if (strcmp(scene->surfaces[p->surface].name, "floor") == 0)
            floor_p = p;
        if (strcmp(scene->surfaces[p->surface].name, "ceiling") == 0)
            ceiling_p = p;
    }
    CHECK(floor_p && ceiling_p && tree);
    if (floor_p && ceiling_p && tree) {
        static shadow_occluder all[256], kept[256];
        const double eps = geometry.plane_epsilon;
        occluder_tree_use_solids(tree, false);
        uint32_t n_all = occluder_tree_collect(tree, floor_p, ceiling_p, eps, all, 256);
        occluder_tree_use_solids(tree, true);
        uint32_t n_kept = occluder_tree_collect(tree, floor_p, ceiling_p, eps, kept, 256);
        printf("%s: occluders between floor and ceiling: %u triangles, %u kept\n", name, n_all,
               n_kept);
        CHECK(n_all == all_expected);
        CHECK(n_kept == kept_expected);
        double g_all, b_all, g_kept, b_kept, open, b_open;
        CHECK(pair_obstructed_exact_within(floor_p, ceiling_p, all, n_all, 1e-6, 0, eps,
                                           UINT64_MAX, &g_all, &b_all));
        CHECK(pair_obstructed_exact_within(floor_p, ceiling_p, kept, n_kept, 1e-6, 0, eps,
                                           UINT64_MAX, &g_kept, &b_kept));
        CHECK(pair_obstructed_exact_within(floor_p, ceiling_p, all, 0, 1e-6, 0, eps, UINT64_MAX,
                                           &open, &b_open));
        double A = ceiling_p->area, F_all = g_all / A, F_kept = g_kept / A;
        double se, reference = monte_carlo(scene, ceiling_p, floor_p->surface, 4u << 20, &se);
        printf("  F(ceiling -> floor): unobstructed %.7f, behind every triangle %.7f, faces "
               "left out %.7f, brute force %.5f +- %.5f\n",
               open / A, F_all, F_kept, reference, se);
        CHECK_ABS(F_kept, F_all, 1e-6 * F_all + (b_all + b_kept) / A + 1e-12);
        CHECK_ABS(F_kept, reference, 3 * se + b_kept / A + 1e-12);
        if (blocked) /* a box seen through would show */
            CHECK(open / A - F_kept > 20 * se);
    }
    occluder_tree_destroy(tree);
    vf_geometry_free(&geometry);
    rad_scene_destroy(scene);
}

/* The floor [x0, x1] x [z0, z1] at y = 0 facing up, the ceiling over it shifted by
 * `shift` along x at y = height facing down. */
/* The floor [x0, x1] x [z0, z1] at y = 0 facing up, the ceiling over it shifted by
 * `shift` along x at y = height facing down, then the boxes' object. */
static void floor_and_ceiling(double x0, double x1, double z0, double z1, double shift,
                              double height)
{
    test_obj_add(&obj, "o floor\n");
    test_obj_rectangle(&obj, 1, 0, z0, x0, z1, x1, 1);
    test_obj_add(&obj, "o ceiling\n");
    test_obj_rectangle(&obj, 1, height, z0, x0 + shift, z1, x1 + shift, -1);
    test_obj_add(&obj, "o boxes\n");
}

static void check_exact_behind_solids(void)
{
    /* the floor [0, 4] x [-4, 0] at y = 0, the ceiling [3, 7] x [-4, 0] at y = 5; boxes
     * between: closed; open below, its missing face turned to the floor (seen from the
     * ceiling, which no face of it is turned away from); open above (seen from the floor,
     * which straddles every wall plane). 32 triangles cut the hull; the closed box's roof
     * and +x wall face away from the whole floor (2 triangles each) */
    floor_and_ceiling(0, 4, -4, 0, 3, 5);
    box(4.2, 5.2, 1.5, 2.5, -2, -1, WALLS | ROOF | FLOOR);
    box(4.2, 5.2, 3, 4, -3.5, -2.2, WALLS | ROOF);
    box(2.5, 3.5, 1.5, 2.5, -1.5, -0.5, WALLS | FLOOR);
    check_exact("behind.obj", 3, 32, 28, true);

    /* a closed box standing on the floor: the floor lies in the box's floor plane, and its
     * part under the box is on the box's surface, where a segment enters through no face:
     * the floor cannot see the box so (its roof would go), the ceiling, 3 along x, can:
     * the box's -x wall faces away from it (of 10 triangles that cut the hull) */
    floor_and_ceiling(0, 4, -4, 0, 3, 3);
    box(1, 3, 0, 1, -3, -1, WALLS | ROOF | FLOOR);
    check_exact("under.obj", 1, 10, 8, true);

    /* the floor inside a closed box that the ceiling is outside of: all of it hidden. The
     * floor is no place to see the box from (its roof would go) */
    floor_and_ceiling(1, 3, -3, -1, 0, 4);
    box(0, 4, -0.5, 2, -4, 0, WALLS | ROOF | FLOOR);
    check_exact("inside.obj", 1, 2, 2, true);
}

int main(void)
{
    check_found();
    check_exact_behind_solids();
    free(obj.data);
    return test_finish("test_convex_solids");
}
