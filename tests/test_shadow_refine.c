/*
 * test_shadow_refine.c - patches split where a sharp light's shadow edge crosses them
 * (rad_mesh_options.shadow_levels), checked against the exact shadow.
 *
 * A black unit box stands on a grey floor under a sun of 1000 lux with no disk, 40 degrees
 * up, its light travelling at 30 degrees from -x in plan: the box's shadow on the floor is
 * exactly the footprint swept along the offset o = -cot(40 deg) (cos 30, sin 30) (the
 * top face's shadow), and the floor gets E = 1000 sin 40 deg everywhere else. The box
 * is black and the floor flat, so nothing reflects light onto the floor: every solver's
 * answer there is B = rho H, H the patch's direct light, and the error of a patch's
 * one value against the exact, discontinuous H(x) is all at the shadow's edge. Its
 * integral over the floor, divided by E and by the edge's length, is the width over which
 * the mesh smears the edge: about a quarter of a patch for an edge across a grid of
 * patches of size h, so each level of refinement should halve it. Checked:
 *   - that width for levels 0 (none) to 3, from the patch inputs and from the gather,
 *     Gauss-Seidel, shooting, direct (LU) and hierarchical solutions (the hierarchical solver's leaves are the refined
 *     patches), falling by at least 35 % a level; the area of the shadow (outside the
 *     footprint) stays right at every level;
 *   - that a point light without anything in its way splits nothing (smooth fall-off), and
 *     that the budget stops the splits, saying so;
 *   - the CLI: --shadow-levels in the --stats, and a bad value refused.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846

static const double sun_elevation = 40 * PI / 180, sun_azimuth = 30 * PI / 180;
static const double sun_lux = 1000, floor_albedo = 0.5;

static rad_scene *box_scene(void)
{
    test_write_file("shadow.mtl", "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl black\nKd 0 0 0\n");
    const char *path = test_write_file(
        "shadow.obj",
        "mtllib shadow.mtl\n"
        "o floor\nusemtl grey\n"
        "v -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\nf 1 2 3 4\n"
        "o box\nusemtl black\n"
        "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n"
        "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
        "f 5 9 10 6\nf 6 10 11 7\nf 7 11 12 8\nf 8 12 9 5\nf 9 12 11 10\n");
    rad_scene *scene = NULL;
    rad_error error;
    if (rad_scene_load(path, NULL, &scene, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "load: %s", error.message);
        exit(1);
    }
    rad_light sun = {.type = RAD_LIGHT_DIRECTIONAL,
                     .direction = {-cos(sun_azimuth) * cos(sun_elevation), -sin(sun_elevation),
                                   -sin(sun_azimuth) * cos(sun_elevation)},
                     .intensity = {sun_lux, sun_lux, sun_lux}};
    if (rad_scene_add_light(scene, &sun, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "add light: %s", error.message);
        exit(1);
    }
    return scene;
}

/* The exact direct light at floor point (x, z): 0 in the footprint swept along o. */
static double exact_floor_light(double x, double z)
{
    double cot = cos(sun_elevation) / sin(sun_elevation);
    double ox = -cot * cos(sun_azimuth), oz = -cot * sin(sun_azimuth);
    /* s in [0, 1] with |x - s ox| <= 0.5 and |z - s oz| <= 0.5 */
    double low = 0, high = 1;
    double p[2] = {x, z}, o[2] = {ox, oz};
    for (int k = 0; k < 2; k++) {
        double a = (p[k] - 0.5) / o[k], b = (p[k] + 0.5) / o[k];
        low = fmax(low, fmin(a, b));
        high = fmin(high, fmax(a, b));
    }
    return low <= high ? 0 : sun_lux * sin(sun_elevation);
}

/* The shadow's outline: the footprint swept along o is a hexagon whose perimeter is the
 * square's 4 plus twice |o|'s extent across... measured directly: the perimeter of the
 * convex hull of the footprint and its copy moved by o. */
static double shadow_perimeter(void)
{
    double cot = cos(sun_elevation) / sin(sun_elevation);
    double ox = -cot * cos(sun_azimuth), oz = -cot * sin(sun_azimuth);
    /* o points into the -x, -z quadrant: the sweep adds the two edges from the corners
     * (+0.5, -0.5) and (-0.5, +0.5) and drops nothing of the square's outline but the
     * two sides it sweeps over, which the moved square's two sides replace */
    return 4 + 2 * sqrt(ox * ox + oz * oz);
}

/* Integral over the floor of |value of the patch under (x, z) - exact|, by a 1 cm grid over
 * [-2.5, 1] x [-2, 1] (the shadow and a margin), each point assigned to the floor patch
 * containing it. `value` is per patch (direct light, or B / rho). */
static double edge_error(const rad_mesh *mesh, uint32_t floor_surface, const double *value,
                         double *shadow_area)
{
    const double x0 = -2.5, x1 = 1, z0 = -2, z1 = 1, step = 0.01;
    const int nx = (int)lround((x1 - x0) / step), nz = (int)lround((z1 - z0) / step);
    double error = 0, shadow = 0;
    int assigned = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (patch->surface != floor_surface)
            continue;
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_vec3 v = mesh->vertices[patch->vertex[k]];
            lo[0] = fmin(lo[0], v.x);
            hi[0] = fmax(hi[0], v.x);
            lo[1] = fmin(lo[1], v.z);
            hi[1] = fmax(hi[1], v.z);
        }
        /* the floor's patches are axis-aligned squares: a grid point belongs to the patch
         * whose half-open box [lo, hi) holds it */
        for (int i = (int)fmax(0, ceil((lo[0] - x0) / step - 0.5)); i < nx; i++) {
            double x = x0 + (i + 0.5) * step;
            if (x < lo[0])
                continue;
            if (x >= hi[0])
                break;
            for (int j = (int)fmax(0, ceil((lo[1] - z0) / step - 0.5)); j < nz; j++) {
                double z = z0 + (j + 0.5) * step;
                if (z < lo[1])
                    continue;
                if (z >= hi[1])
                    break;
                double exact = exact_floor_light(x, z);
                error += fabs(value[p] - exact) * step * step;
                bool footprint = fabs(x) < 0.5 && fabs(z) < 0.5;
                if (!footprint)
                    shadow += (1 - value[p] / (sun_lux * sin(sun_elevation))) * step * step;
                assigned++;
            }
        }
    }
    CHECK(assigned == nx * nz);
    *shadow_area = shadow;
    return error;
}

static void test_edge_widths(void)
{
    rad_scene *scene = box_scene();
    const double patch_size = 0.25;
    const double open = sun_lux * sin(sun_elevation), perimeter = shadow_perimeter();
    double cot = cos(sun_elevation) / sin(sun_elevation);
    /* the shadow outside the footprint: the swept area |o| x (the footprint's width across
     * o), the square's extent across the unit vector perpendicular to o */
    double across = fabs(cos(sun_azimuth)) + fabs(sin(sun_azimuth));
    double exact_shadow = cot * across;
    const rad_solver solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT,
                                  RAD_SOLVER_DIRECT, RAD_SOLVER_HIERARCHICAL};
    const int solver_count = (int)(sizeof(solvers) / sizeof(solvers[0]));
    double previous[4] = {0};
    for (int levels = 0; levels <= 3; levels++) {
        rad_mesh_options options = {.patch_size = patch_size,
                                    .shadow_levels = levels == 0 ? -1 : levels};
        rad_mesh *mesh = NULL;
        rad_patch_inputs *inputs = NULL;
        rad_error error;
        CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_OK);
        CHECK(rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK);
        if (!mesh || !inputs)
            break;
        if (levels == 0)
            CHECK(mesh->shadow_splits == 0);
        else
            CHECK(mesh->shadow_splits > 0 && !mesh->shadow_budget_reached);
        uint32_t n = mesh->patch_count;
        double *value = calloc(n, sizeof(*value));
        rad_rgb *B = calloc(n, sizeof(*B));
        for (uint32_t p = 0; p < n; p++)
            value[p] = inputs->direct[p].g;
        double shadow;
        double width = edge_error(mesh, 0, value, &shadow) / (open * perimeter);
        printf("levels %d: %u patches (%u splits): patch inputs smear the edge over %.4f m "
               "(patch %.4f m); shadow %.4f m^2 (exact %.4f)\n",
               levels, n, mesh->shadow_splits, width, patch_size / (1 << levels), shadow,
               exact_shadow);
        CHECK_NEAR(shadow, exact_shadow, 0.01);
        if (levels > 0)
            CHECK(width < 0.65 * previous[0]);
        previous[0] = width;
        for (int s = 0; s < solver_count; s++) {
            rad_scene_solve_options solve = {.solver = solvers[s], .inputs = inputs};
            rad_scene_solve_report report;
            CHECK(rad_solve_scene(scene, mesh, &solve, B, &report, &error) == RAD_OK);
            if (solvers[s] == RAD_SOLVER_HIERARCHICAL)
                CHECK(report.hierarchy.leaves == n);
            for (uint32_t p = 0; p < n; p++)
                value[p] = B[p].g / floor_albedo;
            double solved = edge_error(mesh, 0, value, &shadow) / (open * perimeter);
            printf("          %s: %.4f m; shadow %.4f m^2\n", rad_solver_name(solvers[s]),
                   solved, shadow);
            /* nothing reflects onto the floor: the solvers give the inputs back, up to
             * their tolerance */
            CHECK_NEAR(solved, width, 0.03);
            CHECK_NEAR(shadow, exact_shadow, 0.01);
        }
        free(value);
        free(B);
        rad_patch_inputs_destroy(inputs);
        rad_mesh_destroy(mesh);
    }
    rad_scene_destroy(scene);
}

static void test_no_shadow_no_split(void)
{
    /* the floor alone under a point light 1 m up: the fall-off is steep but smooth */
    const char *path =
        test_write_file("plain.obj", "o floor\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\nf 1 2 3 4\n");
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (!scene)
        return;
    rad_light point = {.type = RAD_LIGHT_POINT, .position = {0.1, 1, 0.2},
                       .intensity = {100, 100, 100}};
    CHECK(rad_scene_add_light(scene, &point, &error) == RAD_OK);
    rad_mesh *mesh = NULL;
    rad_mesh_options options = {.patch_size = 0.25, .shadow_levels = 4};
    CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_OK);
    if (mesh) {
        CHECK(mesh->shadow_splits == 0);
        CHECK(mesh->patch_count == 24 * 24);
    }
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);

    /* the budget: splits stop when they have added that many patches */
    scene = box_scene();
    options = (rad_mesh_options){.patch_size = 0.25, .shadow_levels = 3, .max_added_patches = 30};
    CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_OK);
    if (mesh) {
        printf("budget of 30 added patches: %u splits, %u patches\n", mesh->shadow_splits,
               mesh->patch_count);
        CHECK(mesh->shadow_budget_reached);
        CHECK(mesh->shadow_splits == 10);
        CHECK(mesh->patch_count == 24 * 24 + 5 * 16 + 30);
    }
    rad_mesh_destroy(mesh);
    options = (rad_mesh_options){.patch_size = 0.25, .shadow_levels = 7};
    CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_ERR_INVALID);
    rad_scene_destroy(scene);
}

static void test_cli(void)
{
    rad_scene_destroy(box_scene()); /* writes shadow.obj */
    char command[2048];
    const char *stats = test_path("shadow-stats.json");
    snprintf(command, sizeof(command),
             "solve '%s' --sun 1,1,0.3:1000:0 --patch-size 0.25 --shadow-levels 3 -o '%s' "
             "--stats '%s' --quiet",
             test_path("shadow.obj"), test_path("shadow.ply"), stats);
    CHECK(test_run_tool(command) == 0);
    const char *text = test_read_text(stats);
    CHECK(text && strstr(text, "\"shadow_splits\"") && !strstr(text, "\"shadow_splits\": 0,"));
    snprintf(command, sizeof(command),
             "solve '%s' --sun 1,1,0.3:1000 --shadow-levels 9 -o '%s' --quiet",
             test_path("shadow.obj"), test_path("never.ply"));
    CHECK(test_run_tool(command) == 2);
    CHECK(!test_file_exists(test_path("never.ply")));
}

int main(void)
{
    test_edge_widths();
    test_no_shadow_no_split();
    test_cli();
    return test_finish("test_shadow_refine");
}
