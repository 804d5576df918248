/*
 * test_hierarchical.c - the hierarchical solver against the dense one on the Cornell box
 * and on a furnished room (~2000 patches each): area-weighted mean radiance per surface
 * within 1 %, image RMSE within 2 % of the mean; bitwise the same for 1 and 2 threads; a
 * small --max-memory budget caps refinement, says so, and stays within 5 %.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

typedef struct dense_reference {
    rad_rgb *B;
} dense_reference;

static void fail_on(rad_status status, const rad_error *error, const char *what)
{
    if (status != RAD_OK) {
        fprintf(stderr, "%s: %s\n", what, error->message);
        exit(1);
    }
}

/* Area-weighted mean of B's luminance-free channel sum per surface. */
static void surface_means(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                          double *mean)
{
    double *area = calloc(scene->surface_count, sizeof(double));
    for (uint32_t s = 0; s < scene->surface_count; s++)
        mean[s] = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        mean[patch->surface] += patch->area * (B[p].r + B[p].g + B[p].b) / 3;
        area[patch->surface] += patch->area;
    }
    for (uint32_t s = 0; s < scene->surface_count; s++)
        mean[s] = area[s] > 0 ? mean[s] / area[s] : 0;
    free(area);
}

static double image_rmse_relative(const rad_mesh *mesh, const rad_rgb *a, const rad_rgb *b,
                                  const rad_camera *camera)
{
    rad_error error;
    rad_image *ia = test_new_image(128, 128), *ib = test_new_image(128, 128);
    rad_render_options options = {.samples_per_pixel = 4, .edge_samples = 4, .seed = 1};
    fail_on(rad_render(mesh, a, camera, &options, ia, &error), &error, "render");
    fail_on(rad_render(mesh, b, camera, &options, ib, &error), &error, "render");
    rad_image_difference d;
    fail_on(rad_image_compare(ia, ib, NULL, &d, NULL, &error), &error, "compare");
    double mean = (d.mean_b.r + d.mean_b.g + d.mean_b.b) / 3;
    rad_image_destroy(ia);
    rad_image_destroy(ib);
    return d.rmse / mean;
}

/* Quads of an axis-aligned box, facing out (or in, for a room). */
static void box(FILE *f, int *vertices, const double lo[3], const double hi[3], bool inward)
{
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int k = 0; k < 8; k++)
        fprintf(f, "v %g %g %g\n", k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                k & 4 ? hi[2] : lo[2]);
    for (int face = 0; face < 6; face++) {
        const int *q = faces[face];
        if (!inward) /* the corners as listed face into the box */
            fprintf(f, "f %d %d %d %d\n", *vertices + q[3] + 1, *vertices + q[2] + 1,
                    *vertices + q[1] + 1, *vertices + q[0] + 1);
        else
            fprintf(f, "f %d %d %d %d\n", *vertices + q[0] + 1, *vertices + q[1] + 1,
                    *vertices + q[2] + 1, *vertices + q[3] + 1);
    }
    *vertices += 8;
}

/* A furnished room: walls, a table on four legs, a cupboard, a bed, a ceiling lamp. */
static const char *write_furnished_room(void)
{
    const char *path = test_path("furnished.obj");
    FILE *f = fopen(path, "w");
    int v = 0;
    fprintf(f, "mtllib furnished.mtl\no room\nusemtl white\n");
    box(f, &v, (double[3]){0, 0, 0}, (double[3]){4, 2.6, 5}, true);
    fprintf(f, "o table\nusemtl wood\n");
    box(f, &v, (double[3]){1.4, 0.72, 1.6}, (double[3]){2.6, 0.78, 2.4}, false);
    for (int leg = 0; leg < 4; leg++) {
        double x = leg & 1 ? 2.5 : 1.45, z = leg & 2 ? 2.3 : 1.65;
        box(f, &v, (double[3]){x, 0, z}, (double[3]){x + 0.05, 0.72, z + 0.05}, false);
    }
    fprintf(f, "o cupboard\nusemtl blue\n");
    box(f, &v, (double[3]){0, 0, 3.8}, (double[3]){0.6, 2, 4.9}, false);
    fprintf(f, "o bed\nusemtl red\n");
    box(f, &v, (double[3]){2.4, 0, 3.2}, (double[3]){3.9, 0.5, 4.9}, false);
    fprintf(f, "o lamp\nusemtl lamp\n"); /* faces down, just below the ceiling */
    fprintf(f, "v 1.6 2.55 2.2\nv 2.4 2.55 2.2\nv 2.4 2.55 2.8\nv 1.6 2.55 2.8\n");
    fprintf(f, "f %d %d %d %d\n", v + 1, v + 2, v + 3, v + 4);
    fclose(f);
    test_write_file("furnished.mtl", "newmtl white\nKd 0.75 0.75 0.72\nnewmtl wood\n"
                                     "Kd 0.5 0.35 0.2\nnewmtl blue\nKd 0.2 0.3 0.6\n"
                                     "newmtl red\nKd 0.6 0.15 0.1\nnewmtl lamp\n"
                                     "Kd 0.5 0.5 0.5\nKe 8 8 7\n");
    return path;
}

/* The dense reference (every F_ij, Gauss-Seidel to 1e-7) and the hierarchical solution on
 * the same 2000 to 3000 patches (the shadow refinement adds some): area-weighted mean per
 * surface within 1 %, image RMSE within 2 % of the mean. */
static void compare_with_dense(const char *label, const rad_scene *scene, const rad_mesh *mesh,
                               const rad_tracer *tracer, const rad_camera *camera,
                               rad_rgb *dense, rad_rgb *hier, rad_hierarchy_report *report)
{
    rad_error error;
    printf("%s: %u patches\n", label, mesh->patch_count);
    CHECK(mesh->patch_count > 1500 && mesh->patch_count < 3000);
    /* the patch inputs first: the rows are made with their open areas (the floor's patches
     * that run under the blocks), as rad_solve_scene makes them */
    rad_patch_inputs *inputs = NULL;
    fail_on(rad_patch_inputs_build(scene, mesh, &inputs, &error), &error, "inputs");
    /* 4 x 4 points a patch: the single point (before the far pairs' expansion) put the rows
     * up to 1.0058 (the furnished room) and the surfaces about 0.1 % brighter */
    rad_formfactor_options ff_options = {.seed = 1, .quadrature = 4, .area = inputs->area};
    rad_formfactors *ff = NULL;
    rad_formfactor_report ff_report;
    fail_on(rad_formfactors_compute(mesh, tracer, &ff_options, &ff, &ff_report, &error), &error,
            "ff");
    /* the dense reference's rows are right before trimming (the furnished room's reached
     * 1.025 when a first pass of four segments decided which pairs were clear), but for
     * the patches partly buried in a closed object, whose rows are divided by their open
     * share: a sliver of wall 9 mm tall above the cupboard pressed against it, the rest
     * of its patch inside the cupboard, sums to 1.17 here (its 16 segments resolve a
     * sliver so far; trimmed: a known limit, docs/DESIGN.md). Before the segments' buried
     * ends were told apart, buried parts inside one closed region (a floor under the bed
     * and the wall behind it) saw each other, and rows reached 3.4 */
    uint32_t partly = 0;
    for (uint32_t i = 0; i < mesh->patch_count; i++)
        partly += inputs->area[i] < mesh->patches[i].area * (1 - 1e-12);
    uint32_t worst = ff_report.largest_row;
    bool worst_partly = inputs->area[worst] < mesh->patches[worst].area * (1 - 1e-12);
    printf("dense rows: largest %.5f before trimming (patch %u, %s), %u trimmed; %u patches "
           "partly buried\n",
           ff_report.largest_row_sum, worst, worst_partly ? "partly buried" : "open",
           ff_report.rows_trimmed, partly);
    CHECK(ff_report.largest_row_sum <= 1 + RAD_ROW_SUM_SLACK || worst_partly);
    CHECK(ff_report.rows_trimmed <= partly / 2);
    rad_system system = rad_system_of(inputs, ff);
    rad_solve_options solve = {.solver = RAD_SOLVER_GAUSS_SEIDEL, .tolerance = 1e-7};
    fail_on(rad_solve(&system, &solve, dense, NULL, &error), &error, "solve");
    rad_formfactors_destroy(ff);

    rad_hierarchy_options options = {.seed = 1, .threads = 2};
    fail_on(rad_solve_hierarchical(mesh, inputs, tracer, &options, hier, report, &error), &error,
            "hierarchical");
    rad_patch_inputs_destroy(inputs);
    printf("elements %llu clusters %llu links %llu partial %llu rays %llu passes %u sweeps %u "
           "change %.3g residual %.3g\n",
           (unsigned long long)report->elements, (unsigned long long)report->clusters,
           (unsigned long long)report->links, (unsigned long long)report->links_partial,
           (unsigned long long)report->rays, report->passes, report->iterations, report->change,
           report->residual);
    CHECK(report->converged);
    CHECK(!report->memory_capped);
    CHECK(report->leaves == mesh->patch_count);
    CHECK(report->links < (uint64_t)mesh->patch_count * mesh->patch_count / 4);

    double *mean_dense = calloc(scene->surface_count, sizeof(double));
    double *mean_hier = calloc(scene->surface_count, sizeof(double));
    surface_means(scene, mesh, dense, mean_dense);
    surface_means(scene, mesh, hier, mean_hier);
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        printf("%-12s dense %10.4f hierarchical %10.4f (%+.2f %%)\n", scene->surfaces[s].name,
               mean_dense[s], mean_hier[s], 100 * (mean_hier[s] / mean_dense[s] - 1));
        CHECK_NEAR(mean_hier[s], mean_dense[s], 0.01);
    }
    double rmse = image_rmse_relative(mesh, hier, dense, camera);
    printf("image rmse / mean: %.4f\n", rmse);
    CHECK(rmse < 0.02);
    free(mean_dense);
    free(mean_hier);
}

/* About 2000 patches of the scene, and a tracer over it. */
static void prepare(const rad_scene *scene, rad_mesh **mesh, rad_tracer **tracer)
{
    rad_error error;
    fail_on(rad_mesh_build(scene, rad_mesh_default_patch_size(scene, 2000), mesh, &error),
            &error, "mesh");
    fail_on(rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, tracer, &error), &error,
            "tracer");
}

static void furnished_room(void)
{
    rad_error error;
    rad_scene *scene = NULL;
    fail_on(rad_scene_load(write_furnished_room(), NULL, &scene, &error), &error, "room");
    rad_mesh *mesh = NULL;
    rad_tracer *tracer = NULL;
    prepare(scene, &mesh, &tracer);
    rad_rgb *dense = calloc(mesh->patch_count, sizeof(rad_rgb));
    rad_rgb *hier = calloc(mesh->patch_count, sizeof(rad_rgb));
    rad_camera camera = {{3.6, 1.8, 0.3}, {1.5, 0.6, 3.5}, {0, 1, 0}, 70};
    rad_hierarchy_report report;
    compare_with_dense("furnished room", scene, mesh, tracer, &camera, dense, hier, &report);
    free(dense);
    free(hier);
    rad_tracer_destroy(tracer);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

int main(void)
{
    rad_error error;
    test_tmpdir();
    furnished_room();

    rad_scene *scene = NULL;
    fail_on(rad_scene_cornell_box(&scene, &error), &error, "cornell");
    rad_mesh *mesh = NULL;
    rad_tracer *tracer = NULL;
    prepare(scene, &mesh, &tracer);
    rad_rgb *dense = calloc(mesh->patch_count, sizeof(rad_rgb));
    rad_rgb *hier = calloc(mesh->patch_count, sizeof(rad_rgb));
    rad_rgb *hier1 = calloc(mesh->patch_count, sizeof(rad_rgb));
    rad_hierarchy_report report;
    compare_with_dense("Cornell box", scene, mesh, tracer, &scene->camera, dense, hier, &report);
    rad_hierarchy_options options = {.seed = 1, .threads = 2};
    double *mean_dense = calloc(scene->surface_count, sizeof(double));
    double *mean_hier = calloc(scene->surface_count, sizeof(double));
    surface_means(scene, mesh, dense, mean_dense);

    /* the same bits for one thread */
    options.threads = 1;
    rad_hierarchy_report report1;
    fail_on(test_solve_hierarchical(scene, mesh, tracer, &options, hier1, &report1, &error),
            &error, "hierarchical 1 thread");
    CHECK(memcmp(hier, hier1, mesh->patch_count * sizeof(rad_rgb)) == 0);
    CHECK(report1.links == report.links && report1.rays == report.rays);

    /* a budget a third of what the links want: capped, reported, still within 5 % */
    options.threads = 2;
    options.max_memory = report.link_bytes / 3;
    fail_on(test_solve_hierarchical(scene, mesh, tracer, &options, hier1, &report1, &error),
            &error, "hierarchical capped");
    printf("capped: links %llu, link bytes %llu of %llu\n", (unsigned long long)report1.links,
           (unsigned long long)report1.link_bytes, (unsigned long long)options.max_memory);
    CHECK(report1.memory_capped);
    CHECK(report1.link_bytes <= options.max_memory);
    surface_means(scene, mesh, hier1, mean_hier);
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        printf("%-12s capped %+.2f %%\n", scene->surfaces[s].name,
               100 * (mean_hier[s] / mean_dense[s] - 1));
        CHECK_NEAR(mean_hier[s], mean_dense[s], 0.05);
    }

    /* a raised stop flag (Ctrl-C in the tool): a clean return with a usable solution */
    volatile int stop = 1;
    options.max_memory = 0;
    options.stop = &stop;
    /* poison B: a solver that returned without writing it must not pass as "usable" on
     * the previous call's answer */
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        hier1[p] = (rad_rgb){NAN, NAN, NAN};
    fail_on(test_solve_hierarchical(scene, mesh, tracer, &options, hier1, &report1, &error),
            &error, "hierarchical stopped");
    CHECK(report1.interrupted && !report1.converged);
    bool usable = true;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        usable = usable && isfinite(hier1[p].r) && isfinite(hier1[p].g) &&
                 isfinite(hier1[p].b) && hier1[p].r >= 0 && hier1[p].g >= 0 && hier1[p].b >= 0;
    CHECK(usable);

    free(mean_dense);
    free(mean_hier);
    free(dense);
    free(hier);
    free(hier1);
    rad_tracer_destroy(tracer);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return test_finish("test_hierarchical");
}
