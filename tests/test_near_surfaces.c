/*
 * test_near_surfaces.c - surfaces a hair apart: the form-factor invariants and every
 * solver's answer where the tracer alone cannot tell the surfaces apart.
 *
 * Scenes:
 *   - a box inside a box, 1e-6 and 1e-4 apart: the room's ceiling is a light (Kd 0), every
 *     other face white (rho 0.7). Each room face sees only the inner face in front of it,
 *     so in the closed form the inner box's top has radiance rho Le and everything else
 *     is dark (light reaches the rest only through the gap, a share of order gap / size);
 *     rows of F sum to 1.
 *   - a floor under a square light one unit above (unit squares: the parallel-squares
 *     factor F = 0.19982 of VALIDATION.md), with a copy of the floor facing down: at the
 *     same height (a coincident back face) and 1e-6 below it (a thin slab) the floor
 *     still sees the light; 1e-6 above it (facing the floor: a closed cavity) it sees only
 *     the copy and stays dark.
 *   - boxes that pierce the floor and each other in a closed room: no F negative or a row
 *     above 1 + RAD_ROW_SUM_SLACK, the ceiling's rows sum to 1 (it sees a closed room),
 *     every solver agrees with the direct one, and the face of the sunk box below the
 *     floor, outside the room, gets no light;
 *   - a system whose row of F sums to 2: rad_solve refuses it and names the patch.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846
#define RHO 0.7
#define LE 10.0

static void write_materials(FILE *f)
{
    fprintf(f, "newmtl white\nKd %g %g %g\nnewmtl light\nKd 0 0 0\nKe %g %g %g\n", RHO, RHO,
            RHO, LE, LE, LE);
}

/* An axis-aligned box's six faces, facing out (or in), one OBJ object per face. */
static void write_box(FILE *f, unsigned *vertices, const char *name, const double lo[3],
                      const double hi[3], bool inward, const char *top_material)
{
    static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    static const int face[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                   {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
    static const char *face_name[6] = {"bottom", "top", "front", "back", "right", "left"};
    for (int k = 0; k < 8; k++)
        fprintf(f, "v %.12g %.12g %.12g\n", corner[k][0] ? hi[0] : lo[0],
                corner[k][1] ? hi[1] : lo[1], corner[k][2] ? hi[2] : lo[2]);
    for (int q = 0; q < 6; q++) {
        fprintf(f, "o %s_%s\nusemtl %s\nf", name, face_name[q],
                q == 1 && top_material ? top_material : "white");
        for (int k = 0; k < 4; k++)
            fprintf(f, " %u", *vertices + 1 + (unsigned)face[q][inward ? 3 - k : k]);
        fprintf(f, "\n");
    }
    *vertices += 8;
}

static const char *write_box_in_box(double gap)
{
    static char path[512];
    snprintf(path, sizeof(path), "%s", test_path(gap < 1e-5 ? "box_in_box_1e-6.obj"
                                                            : "box_in_box_1e-4.obj"));
    FILE *m = fopen(test_path("near.mtl"), "w");
    FILE *f = fopen(path, "w");
    CHECK(m && f);
    if (!m || !f)
        exit(1);
    write_materials(m);
    fclose(m);
    fprintf(f, "mtllib near.mtl\n");
    unsigned vertices = 0;
    const double room_lo[3] = {0, 0, 0}, room_hi[3] = {1, 1, 1};
    const double inner_lo[3] = {gap, gap, gap}, inner_hi[3] = {1 - gap, 1 - gap, 1 - gap};
    write_box(f, &vertices, "room", room_lo, room_hi, true, "light");
    write_box(f, &vertices, "inner", inner_lo, inner_hi, false, NULL);
    fclose(f);
    return path;
}

/* Floor (unit square at z = 0, facing up), light (unit square at z = 1, facing down) and
 * a copy of the floor facing down at z = copy_z. */
static const char *write_floor_with_copy(const char *name, double copy_z)
{
    static char path[512];
    snprintf(path, sizeof(path), "%s", test_path(name));
    FILE *m = fopen(test_path("near.mtl"), "w");
    FILE *f = fopen(path, "w");
    CHECK(m && f);
    if (!m || !f)
        exit(1);
    write_materials(m);
    fclose(m);
    fprintf(f, "mtllib near.mtl\n"
               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
               "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n");
    fprintf(f, "v 0 0 %.12g\nv 1 0 %.12g\nv 1 1 %.12g\nv 0 1 %.12g\n", copy_z, copy_z, copy_z,
            copy_z);
    fprintf(f, "o floor\nusemtl white\nf 1 2 3 4\n"
               "o light\nusemtl light\nf 5 8 7 6\n"
               "o copy\nusemtl white\nf 9 12 11 10\n");
    fclose(f);
    return path;
}

static rad_scene *load(const char *path)
{
    rad_scene *scene = NULL;
    rad_error error = {0};
    if (rad_scene_load(path, NULL, &scene, &error) != RAD_OK) {
        fprintf(stderr, "%s\n", error.message);
        CHECK(false);
        exit(1);
    }
    return scene;
}

static int surface_index(const rad_scene *scene, const char *name)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, name) == 0)
            return (int)s;
    fprintf(stderr, "no surface %s\n", name);
    CHECK(false);
    return -1;
}

/* Area-weighted mean radiance (B / pi, green channel) of a surface's patches. */
static double mean_radiance(const rad_mesh *mesh, const rad_rgb *B, int surface)
{
    double sum = 0, area = 0;
    for (uint32_t i = 0; i < mesh->patch_count; i++)
        if ((int)mesh->patches[i].surface == surface) {
            sum += mesh->patches[i].area * B[i].g;
            area += mesh->patches[i].area;
        }
    return area > 0 ? sum / area / PI : NAN;
}

static bool all_finite(const rad_rgb *B, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (!(isfinite(B[i].r) && isfinite(B[i].g) && isfinite(B[i].b)))
            return false;
    return true;
}

static const rad_solver solvers[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_GAUSS_SEIDEL,
                                     RAD_SOLVER_SHOOT, RAD_SOLVER_DIRECT,
                                     RAD_SOLVER_HIERARCHICAL};

/* Solves with one solver; B is mesh->patch_count long. */
static bool solve(const rad_scene *scene, const rad_mesh *mesh, rad_solver solver, rad_rgb *B)
{
    rad_scene_solve_options o = {0};
    o.solver = solver;
    o.seed = 5;
    rad_scene_solve_report report;
    rad_error error = {0};
    rad_status status = rad_solve_scene(scene, mesh, &o, B, &report, &error);
    if (status != RAD_OK)
        fprintf(stderr, "%s: %s\n", rad_solver_name(solver), error.message);
    CHECK(status == RAD_OK);
    return status == RAD_OK;
}

/* The mesh's form factors with the scene's triangles as occluders (exits on failure). */
static rad_formfactors *formfactors_of(const rad_scene *scene, const rad_mesh *mesh,
                                       rad_formfactor_report *report)
{
    rad_tracer *tracer = NULL;
    rad_formfactors *ff = NULL;
    rad_error error = {0};
    rad_status status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error);
    if (status == RAD_OK)
        status = rad_formfactors_compute(mesh, tracer, NULL, &ff, report, &error);
    rad_tracer_destroy(tracer);
    if (status != RAD_OK) {
        fprintf(stderr, "form factors: %s\n", error.message);
        CHECK(false);
        exit(1);
    }
    return ff;
}

/* The share of cosine-distributed rays from patch i that first meet the front of some
 * face: what sum_j F_ij must be, found without the form-factor engine. */
static double traced_row(const rad_tracer *tracer, const rad_mesh *mesh, uint32_t i,
                         uint32_t rays)
{
    const rad_patch *p = &mesh->patches[i];
    rad_vec3 n = p->normal;
    rad_vec3 a = fabs(n.x) > 0.5 ? (rad_vec3){0, 1, 0} : (rad_vec3){1, 0, 0};
    rad_vec3 t1 = {a.y * n.z - a.z * n.y, a.z * n.x - a.x * n.z, a.x * n.y - a.y * n.x};
    double l = sqrt(t1.x * t1.x + t1.y * t1.y + t1.z * t1.z);
    t1 = (rad_vec3){t1.x / l, t1.y / l, t1.z / l};
    rad_vec3 t2 = {n.y * t1.z - n.z * t1.y, n.z * t1.x - n.x * t1.z, n.x * t1.y - n.y * t1.x};
    const rad_vec3 *c[4];
    for (unsigned k = 0; k < p->vertex_count; k++)
        c[k] = &mesh->vertices[p->vertex[k]];
    rad_ray *ray = malloc(sizeof(rad_ray) * rays);
    rad_hit *hit = malloc(sizeof(rad_hit) * rays);
    uint32_t side = (uint32_t)sqrt((double)rays);
    uint64_t state = 0x1234567 + i;
    for (uint32_t k = 0; k < rays; k++) {
        double u[4];
        for (int d = 0; d < 4; d++) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            u[d] = (double)(state >> 11) / 9007199254740992.0;
        }
        /* a bilinear point of the (quad) patch, stratified */
        double s = (k % side + u[0]) / side, t = (k / side % side + u[1]) / side;
        rad_vec3 x = {0, 0, 0};
        double w[4] = {(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t};
        for (int m = 0; m < 4; m++) {
            x.x += w[m] * c[m]->x;
            x.y += w[m] * c[m]->y;
            x.z += w[m] * c[m]->z;
        }
        double r = sqrt(u[2]), phi = 2 * PI * u[3], z = sqrt(1 - u[2]);
        double dx = r * cos(phi), dy = r * sin(phi);
        ray[k] = (rad_ray){{(float)(x.x + 2e-6 * n.x), (float)(x.y + 2e-6 * n.y),
                            (float)(x.z + 2e-6 * n.z)},
                           0,
                           {(float)(dx * t1.x + dy * t2.x + z * n.x),
                            (float)(dx * t1.y + dy * t2.y + z * n.y),
                            (float)(dx * t1.z + dy * t2.z + z * n.z)},
                           INFINITY};
    }
    rad_tracer_intersect(tracer, ray, rays, hit);
    uint32_t front = 0;
    for (uint32_t k = 0; k < rays; k++)
        front += hit[k].triangle != RAD_NO_HIT && hit[k].front;
    free(ray);
    free(hit);
    return (double)front / rays;
}

/* Rows of patches that a box's wall cuts or encloses (the floor inside the sunk box, the
 * crossing box's bottom) against traced_row: within RAD_ROW_SUM_SLACK. */
static void check_split_rows(const rad_scene *scene, const rad_mesh *mesh,
                             const rad_formfactors *ff)
{
    rad_tracer *tracer = NULL;
    rad_error error = {0};
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error) == RAD_OK);
    int floor = surface_index(scene, "room_bottom"), bottom = surface_index(scene, "cross_bottom");
    uint32_t n = mesh->patch_count, checked = 0;
    double worst = 0;
    for (uint32_t i = 0; tracer && i < n; i++) {
        const rad_patch *p = &mesh->patches[i];
        bool under_sunk = (int)p->surface == floor && p->centroid.x > 0.3 && p->centroid.x < 0.6 &&
                          p->centroid.y > 0.3 && p->centroid.y < 0.6;
        if (!under_sunk && (int)p->surface != bottom)
            continue;
        double row = 0;
        for (uint32_t j = 0; j < n; j++)
            row += ff->F[(size_t)i * n + j];
        double traced = traced_row(tracer, mesh, i, 1u << 16);
        CHECK_ABS(row, traced, RAD_ROW_SUM_SLACK);
        worst = fmax(worst, fabs(row - traced));
        checked++;
    }
    printf("  %u rows cut or enclosed by a box: largest |row - traced| %.4f\n", checked, worst);
    CHECK(checked == 21);
    rad_tracer_destroy(tracer);
}

static void check_box_in_box(double gap)
{
    rad_scene *scene = load(write_box_in_box(gap));
    rad_mesh *mesh = NULL;
    rad_error error = {0};
    CHECK(test_mesh_uniform(scene, 0.125, &mesh, &error) == RAD_OK);
    uint32_t n = mesh->patch_count;

    /* rows of F: a closed scene, so every row sums to 1 */
    rad_formfactor_report ff_report;
    rad_formfactors *ff = formfactors_of(scene, mesh, &ff_report);
    double lowest = INFINITY, highest = 0;
    for (uint32_t i = 0; i < n; i++) {
        double row = 0;
        for (uint32_t j = 0; j < n; j++)
            row += ff->F[(size_t)i * n + j];
        lowest = fmin(lowest, row);
        highest = fmax(highest, row);
    }
    printf("box in box, gap %g: %u patches, rows of F in [%.6f, %.6f] (before trimming the "
           "largest was %.6f)\n",
           gap, n, lowest, highest, ff_report.largest_row_sum);
    CHECK(highest <= 1 + RAD_ROW_SUM_SLACK);
    CHECK(ff_report.largest_row_sum <= 1 + 1e-3); /* not only trimmed: right */
    CHECK(lowest >= 1 - 2e-3);
    rad_formfactors_destroy(ff);

    int inner_top = surface_index(scene, "inner_top");
    int room_floor = surface_index(scene, "room_bottom");
    int inner_side = surface_index(scene, "inner_left");
    rad_rgb *B = malloc(sizeof(rad_rgb) * n);
    for (size_t s = 0; s < sizeof(solvers) / sizeof(solvers[0]); s++) {
        if (!solve(scene, mesh, solvers[s], B))
            continue;
        CHECK(all_finite(B, n));
        double top = mean_radiance(mesh, B, inner_top);
        double floor = mean_radiance(mesh, B, room_floor);
        double side = mean_radiance(mesh, B, inner_side);
        printf("  %-12s inner top %.5f (closed form %.5f), room floor %.2e, inner side %.2e\n",
               rad_solver_name(solvers[s]), top, RHO * LE, floor, side);
        CHECK_NEAR(top, RHO * LE, 5e-3);
        /* without the near contacts the floor sees the light through the inner bottom:
         * about rho Le F(floor -> ceiling) = 1.4 */
        CHECK(floor < 2e-3 * LE);
        CHECK(side < 2e-3 * LE);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* The parallel-squares factor of VALIDATION.md for unit squares one unit apart. */
static double parallel_unit_squares(void)
{
    double x = 1, y = 1;
    double a = sqrt(1 + x * x), b = sqrt(1 + y * y);
    return 2 / (PI * x * y) *
           (log(sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y))) + x * b * atan(x / b) +
            y * a * atan(y / a) - x * atan(x) - y * atan(y));
}

static void check_floor_copy(const char *name, double copy_z, bool sees_light)
{
    rad_scene *scene = load(write_floor_with_copy(name, copy_z));
    rad_mesh *mesh = NULL;
    rad_error error = {0};
    CHECK(test_mesh_uniform(scene, 0.125, &mesh, &error) == RAD_OK);
    int floor = surface_index(scene, "floor");
    double expected = sees_light ? RHO * LE * parallel_unit_squares() : 0;
    rad_rgb *B = malloc(sizeof(rad_rgb) * mesh->patch_count);
    for (size_t s = 0; s < sizeof(solvers) / sizeof(solvers[0]); s++) {
        if (!solve(scene, mesh, solvers[s], B))
            continue;
        CHECK(all_finite(B, mesh->patch_count));
        double L = mean_radiance(mesh, B, floor);
        printf("  %-12s %s: floor %.5f (closed form %.5f)\n", rad_solver_name(solvers[s]), name,
               L, expected);
        if (sees_light)
            CHECK_NEAR(L, expected, 1e-2);
        else
            CHECK(L < 1e-3 * LE);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

static void check_interpenetrating(void)
{
    const char *path = test_path("interpenetrating.obj");
    FILE *m = fopen(test_path("near.mtl"), "w");
    FILE *f = fopen(path, "w");
    CHECK(m && f);
    if (!m || !f)
        exit(1);
    write_materials(m);
    fclose(m);
    fprintf(f, "mtllib near.mtl\n");
    unsigned vertices = 0;
    const double room_lo[3] = {0, 0, 0}, room_hi[3] = {1, 1, 1};
    const double sunk_lo[3] = {0.3, 0.3, -0.1}, sunk_hi[3] = {0.6, 0.6, 0.2};
    const double cross_lo[3] = {0.5, 0.4, 0.05}, cross_hi[3] = {0.8, 0.7, 0.35};
    write_box(f, &vertices, "room", room_lo, room_hi, true, "light");
    write_box(f, &vertices, "sunk", sunk_lo, sunk_hi, false, NULL);
    write_box(f, &vertices, "cross", cross_lo, cross_hi, false, NULL);
    fclose(f);

    rad_scene *scene = load(path);
    rad_mesh *mesh = NULL;
    rad_error error = {0};
    CHECK(test_mesh_uniform(scene, 0.1, &mesh, &error) == RAD_OK);
    uint32_t n = mesh->patch_count;
    rad_formfactor_report ff_report;
    rad_formfactors *ff = formfactors_of(scene, mesh, &ff_report);
    int ceiling = surface_index(scene, "room_top");
    double smallest = INFINITY, highest = 0, ceiling_low = INFINITY, ceiling_high = 0;
    for (uint32_t i = 0; i < n; i++) {
        double row = 0;
        for (uint32_t j = 0; j < n; j++) {
            double F = ff->F[(size_t)i * n + j];
            smallest = fmin(smallest, F);
            row += F;
        }
        highest = fmax(highest, row);
        if ((int)mesh->patches[i].surface == ceiling) {
            ceiling_low = fmin(ceiling_low, row);
            ceiling_high = fmax(ceiling_high, row);
        }
    }
    printf("interpenetrating boxes: %u patches, smallest F %g, largest row %.5f (before "
           "trimming %.5f, %u trimmed), ceiling rows in [%.5f, %.5f]\n",
           n, smallest, highest, ff_report.largest_row_sum, ff_report.rows_trimmed, ceiling_low,
           ceiling_high);
    CHECK(smallest >= 0);
    /* right before any trimming, which stays a last guard: nothing was scaled back */
    CHECK(ff_report.largest_row_sum <= 1 + RAD_ROW_SUM_SLACK);
    CHECK(ff_report.rows_trimmed == 0);
    CHECK(highest <= 1 + RAD_ROW_SUM_SLACK);
    CHECK(fabs(ceiling_low - 1) <= RAD_ROW_SUM_SLACK && fabs(ceiling_high - 1) <= RAD_ROW_SUM_SLACK);
    /* a floor patch wholly inside the sunk box sees only the crossing box's faces inside
     * it; cut by the sunk box's wall, those faces used to be credited with what lies
     * outside the wall (row 0.555 where 0.505 is right) */
    check_split_rows(scene, mesh, ff);
    rad_formfactors_destroy(ff);

    const char *shown[] = {"room_bottom", "room_left", "sunk_top", "cross_top", "cross_left"};
    int below = surface_index(scene, "sunk_bottom");
    double direct[5] = {0};
    rad_rgb *B = malloc(sizeof(rad_rgb) * n);
    const rad_solver direct_first[] = {RAD_SOLVER_DIRECT, RAD_SOLVER_JACOBI,
                                       RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT,
                                       RAD_SOLVER_HIERARCHICAL};
    for (size_t s = 0; s < sizeof(direct_first) / sizeof(direct_first[0]); s++) {
        rad_solver solver = direct_first[s];
        if (!solve(scene, mesh, solver, B))
            continue;
        CHECK(all_finite(B, n));
        printf("  %-12s", rad_solver_name(solver));
        for (int k = 0; k < 5; k++) {
            double L = mean_radiance(mesh, B, surface_index(scene, shown[k]));
            printf(" %s %.5f", shown[k], L);
            /* the hierarchical solver's links are coarser where a face runs into another
             * box: 6 %, a known limit. Since the patches take the area of their part
             * outside any closed object (mesh/exposed_area.h), the crossing box's left
             * face, mostly inside the sunk box, is 5 % bright there (1.717 against 1.634:
             * its leaves' links that no segment tests, divided by their open share); the
             * sunk box's top 1.4 %. Before, both solvers took those faces' buried parts as
             * gathering nothing, and agreed to 2 % on a value 19 % low (cross_left) */
            if (solver == RAD_SOLVER_DIRECT)
                direct[k] = L;
            else
                CHECK_NEAR(L, direct[k], solver == RAD_SOLVER_HIERARCHICAL ? 6e-2 : 1e-2);
        }
        double outside = mean_radiance(mesh, B, below);
        printf(", below the floor %.2e\n", outside);
        /* nothing reaches it; shooting's ambient term spreads its unshot remainder over
         * every patch, seen or not */
        CHECK(solver == RAD_SOLVER_SHOOT ? outside <= 1e-4 * LE : outside == 0);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* A 3-patch system whose second row sums to 2: refused, naming patch 1. */
static void check_energy_refused(void)
{
    float F[9] = {0, 0.5f, 0.5f, 1.0f, 0, 1.0f, 0.5f, 0.5f, 0};
    double area[3] = {1, 1, 1};
    rad_rgb albedo[3] = {{0.5, 0.5, 0.5}, {0.9, 0.9, 0.9}, {0.5, 0.5, 0.5}};
    rad_rgb exitance[3] = {{1, 1, 1}, {0, 0, 0}, {0, 0, 0}};
    rad_system system = {3, F, area, albedo, exitance};
    rad_rgb B[3];
    const rad_solver dense[] = {RAD_SOLVER_JACOBI, RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT,
                                RAD_SOLVER_DIRECT};
    for (size_t s = 0; s < 4; s++) {
        rad_solve_options o = {0};
        o.solver = dense[s];
        rad_solve_report report;
        rad_error error = {0};
        rad_status status = rad_solve(&system, &o, B, &report, &error);
        printf("  %-12s row sum 2: %s\n", rad_solver_name(dense[s]), error.message);
        CHECK(status == RAD_ERR_INVALID);
        CHECK(report.patch == 1);
        CHECK(strstr(error.message, "patch 1") != NULL);
        CHECK(strstr(error.message, "creates energy") != NULL);
    }
}

int main(void)
{
    check_box_in_box(1e-6);
    check_box_in_box(1e-4);
    check_floor_copy("copy_coincident.obj", 0, true);
    check_floor_copy("copy_below.obj", -1e-6, true);
    check_floor_copy("copy_above.obj", 1e-6, false);
    check_interpenetrating();
    check_energy_refused();
    return test_finish("test_near_surfaces");
}
