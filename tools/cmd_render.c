/*
 * cmd_render.c - `radiosity render [SCENE] -o OUT [options]`: the whole pipeline, from a
 * scene (or the built-in Cornell box) to an image.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity render [SCENE] -o OUT [options]\n"
    "\n"
    "Solves the radiosity of SCENE (an OBJ+MTL or any file Assimp reads; none = the\n"
    "built-in Cornell box with its official camera) and renders it to OUT. OUT's extension\n"
    "picks the format: .png (exposure, tone map, sRGB 8-bit), .hdr (Radiance RGBE), .pfm\n"
    "(portable float map) or .exr (OpenEXR, half float); .hdr, .pfm and .exr hold linear\n"
    "radiance.\n"
    "\n"
    "Camera (default: the scene's camera, or a view of the whole scene from -z):\n"
    "  --eye X,Y,Z  --target X,Y,Z  --up X,Y,Z  --fov DEG (vertical)   --size WxH (512x512)\n"
    "  --spp N              samples per pixel, stratified, box filter (default 16, at\n"
    "                       most 256;\n"
    "                       pixels on an edge get 64 more)\n"
    "  --exposure EV        PNG: scale radiance by 2^EV (default: automatic)\n"
    "  --specular           the two-pass method: surfaces with Ks > 0 (MTL) also show\n"
    "                       mirror reflections of the radiosity-lit scene\n"
    "  --max-depth N        mirror reflections followed with --specular (default 5)\n"
    "Solution:\n"
    "  --solver NAME        gather (Jacobi, default), gauss-seidel, shoot, or direct (LU,\n"
    "                       small scenes only)\n"
    "  --tolerance X        relative residual, or unshot fraction for shoot (default 1e-4)\n"
    "  --max-iterations N   sweeps, or shots for shoot (default: until the tolerance)\n"
    "  --patch-size L       longest patch edge in scene units (default: about 3000 patches)\n"
    "  --visibility-rays N  most occlusion rays per patch pair (default 16; 4 first,\n"
    "                       all N only where those 4 disagree)\n"
    "  --quadrature M       M x M points per patch for the analytic form factor (default 1)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  --seed N             seed of every random choice (default 1)\n"
    "  --stats FILE.json    write counts, times, residuals and peak memory\n"
    "  -h, --help           this text\n";

enum {
    OPT_SOLVER = OPT_OWN, OPT_TOLERANCE, OPT_MAX_ITERATIONS, OPT_SPECULAR, OPT_MAX_DEPTH,
    OPT_COUNT
};

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_FORMFACTOR_OPTIONS,
    CLI_VIEW_OPTIONS,
    [OPT_SOLVER] = {"solver", 0, true},
    [OPT_TOLERANCE] = {"tolerance", 0, true},
    [OPT_MAX_ITERATIONS] = {"max-iterations", 0, true},
    [OPT_SPECULAR] = {"specular", 0, false},
    [OPT_MAX_DEPTH] = {"max-depth", 0, true},
};

/* Patches the default patch size aims at. */
#define DEFAULT_TARGET_PATCHES 3000u
#define RENDER_MAX_SPP 256u

typedef struct render_settings {
    const char *scene_path, *output, *stats_path;
    cli_shared shared;
    cli_view view;
    rad_render_options render;
    rad_solve_options solve;
    bool specular; /* the two-pass method */
} render_settings;

static bool parse_settings(int argc, char **argv, render_settings *s, int *exit_code)
{
    cli_args args;
    memset(s, 0, sizeof(*s));
    if (!cli_parse_image_command("render", usage, argc, argv, options, OPT_COUNT, &args,
                                 &s->shared, &s->view, &s->scene_path, exit_code))
        return false;
    s->output = s->shared.output;
    s->stats_path = s->shared.stats_path;
    s->render.samples_per_pixel = s->view.samples_per_pixel;
    if (s->view.samples_per_pixel > RENDER_MAX_SPP) {
        cli_error("--spp: at most %u for render (16 x 16 strata; the radiosity image has no "
                  "noise to average away)",
                  RENDER_MAX_SPP);
        return false;
    }
    s->specular = args.value[OPT_SPECULAR] != NULL;
    unsigned long value;
    double number;
    if (args.value[OPT_MAX_DEPTH]) {
        if (!cli_parse_uint("max-depth", args.value[OPT_MAX_DEPTH], 64, &value))
            return false;
        if (value == 0) {
            cli_error("--max-depth: must be at least 1");
            return false;
        }
        s->render.max_depth = (uint32_t)value;
    }
    const char *solver = args.value[OPT_SOLVER] ? args.value[OPT_SOLVER] : "gather";
    if (strcmp(solver, "gather") == 0 || strcmp(solver, "jacobi") == 0)
        s->solve.solver = RAD_SOLVER_JACOBI;
    else if (strcmp(solver, "gauss-seidel") == 0)
        s->solve.solver = RAD_SOLVER_GAUSS_SEIDEL;
    else if (strcmp(solver, "shoot") == 0)
        s->solve.solver = RAD_SOLVER_SHOOT;
    else if (strcmp(solver, "direct") == 0)
        s->solve.solver = RAD_SOLVER_DIRECT;
    else {
        cli_error("--solver: '%s' is not gather, gauss-seidel, shoot or direct", solver);
        return false;
    }
    s->solve.ambient = true;
    if (args.value[OPT_TOLERANCE]) {
        if (!cli_parse_double("tolerance", args.value[OPT_TOLERANCE], &number))
            return false;
        if (!(number > 0)) {
            cli_error("--tolerance: must be positive");
            return false;
        }
        s->solve.tolerance = number;
    }
    if (args.value[OPT_MAX_ITERATIONS]) {
        if (!cli_parse_uint("max-iterations", args.value[OPT_MAX_ITERATIONS], UINT32_MAX, &value))
            return false;
        s->solve.max_iterations = (uint32_t)value;
    }
    s->solve.threads = s->render.threads = s->shared.threads;
    s->render.seed = s->shared.seed;
    s->solve.progress = s->render.progress = cli_progress;
    s->render.width = s->view.width;
    s->render.height = s->view.height;
    *exit_code = EXIT_OK;
    return true;
}

int command_render(int argc, char **argv)
{
    render_settings s;
    int exit_code;
    if (!parse_settings(argc, argv, &s, &exit_code))
        return exit_code;
    if (!cli_output_writable(s.output) || (s.stats_path && !cli_output_writable(s.stats_path)))
        return EXIT_ERROR;

    rad_error error = {0};
    rad_status status;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_tracer *occluders = NULL;
    rad_formfactors *ff = NULL;
    rad_system system = {0};
    rad_rgb *B = NULL;
    rad_image *image = NULL;
    rad_formfactor_report ff_report = {0};
    rad_solve_report solve_report = {0};
    rad_formfactor_check check = {0};
    double t_check = 0;
    double t0 = cli_now(), t_load, t_mesh, t_ff, t_solve, t_render, t_write;

    status = cli_load_scene(s.scene_path, &scene, &error);
    if (status != RAD_OK)
        goto fail;
    t_load = cli_now();
    if (!rad_scene_has_emitter(scene))
        cli_warn("%s: no surface emits light (no material with non-zero Ke): the image will "
                 "be black",
                 scene->source);

    rad_camera camera = cli_view_camera(&s.view, scene);

    double patch_size = s.shared.patch_size > 0 ? s.shared.patch_size
                                         : rad_mesh_default_patch_size(scene, DEFAULT_TARGET_PATCHES);
    status = rad_mesh_build(scene, patch_size, &mesh, &error);
    if (status != RAD_OK)
        goto fail;
    t_mesh = cli_now();

    status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &occluders, &error);
    if (status != RAD_OK)
        goto fail;
    status = rad_formfactors_compute(mesh, occluders, &s.shared.formfactor, &ff, &ff_report, &error);
    if (status != RAD_OK)
        goto fail;
    t_ff = cli_now();
    rad_formfactors_check(ff, mesh, &check);
    t_check = cli_now() - t_ff;

    status = rad_system_from_mesh(scene, mesh, ff, &system, &error);
    if (status != RAD_OK)
        goto fail;
    B = calloc(mesh->patch_count, sizeof(*B));
    if (!B) {
        status = RAD_ERR_NOMEM;
        snprintf(error.message, sizeof(error.message), "out of memory");
        goto fail;
    }
    status = rad_solve(&system, &s.solve, B, &solve_report, &error);
    if (status != RAD_OK)
        goto fail;
    cli_progress_end();
    if (!solve_report.converged)
        cli_warn("the solver stopped at its iteration limit (%u) with residual %.3g, above the "
                 "tolerance",
                 solve_report.iterations, solve_report.criterion);
    t_solve = cli_now();

    if (s.specular)
        s.render.materials = scene->materials;
    status = rad_image_create(s.view.width, s.view.height, &image, &error);
    if (status == RAD_OK)
        status = rad_render(mesh, B, &camera, &s.render, image, &error);
    if (status != RAD_OK)
        goto fail;
    t_render = cli_now();
    status = rad_image_write(image, s.output, &s.view.write, &error);
    if (status != RAD_OK)
        goto fail;
    t_write = cli_now();
    if (cli_progress_enabled()) { /* a summary for a person watching; quiet in scripts */
        char solved[64];
        if (s.solve.solver == RAD_SOLVER_DIRECT)
            snprintf(solved, sizeof(solved), "direct solve");
        else
            snprintf(solved, sizeof(solved), "%u %s", solve_report.iterations,
                     s.solve.solver == RAD_SOLVER_SHOOT ? "shots" : "sweeps");
        fprintf(stderr, "radiosity: %u patches, %.1f M rays, %s (residual %.2g), %.2f s: wrote %s\n",
                mesh->patch_count, ff_report.rays / 1e6, solved, solve_report.residual,
                t_write - t0, s.output);
    }

    if (s.stats_path) {
        cli_stats stats;
        stats_begin(&stats);
        stats_string(&stats, "scene", scene->source);
        stats_integer(&stats, "triangles", scene->triangle_count);
        stats_integer(&stats, "patches", mesh->patch_count);
        stats_number(&stats, "patch_size", mesh->patch_size);
        stats_integer(&stats, "patch_pairs", ff_report.pairs);
        stats_integer(&stats, "patch_pairs_facing", ff_report.pairs_facing);
        stats_integer(&stats, "patch_pairs_refined", ff_report.pairs_refined);
        stats_integer(&stats, "rays_cast", ff_report.rays);
        stats_number(&stats, "rays_per_second",
                     ff_report.seconds > 0 ? ff_report.rays / ff_report.seconds : 0);
        /* the tracer's own rate: rays per second of tracing per thread, times threads */
        stats_integer(&stats, "threads", (unsigned long long)ff_report.threads);
        stats_number(&stats, "tracing_rays_per_second",
                     ff_report.tracing_seconds > 0
                         ? ff_report.rays / (ff_report.tracing_seconds / ff_report.threads)
                         : 0);
        stats_number(&stats, "seconds_load", t_load - t0);
        stats_number(&stats, "seconds_mesh", t_mesh - t_load);
        stats_number(&stats, "seconds_form_factors", t_ff - t_mesh);
        stats_number(&stats, "seconds_solve", t_solve - t_ff - t_check);
        stats_number(&stats, "seconds_render", t_render - t_solve);
        stats_number(&stats, "seconds_write", t_write - t_render);
        stats_number(&stats, "seconds_total", t_write - t0);
        stats_string(&stats, "solver", s.solve.solver == RAD_SOLVER_JACOBI ? "gather"
                                       : s.solve.solver == RAD_SOLVER_GAUSS_SEIDEL ? "gauss-seidel"
                                       : s.solve.solver == RAD_SOLVER_SHOOT ? "shoot" : "direct");
        stats_integer(&stats, "iterations", solve_report.iterations);
        stats_number(&stats, "solver_criterion", solve_report.criterion);
        stats_number(&stats, "final_residual", solve_report.residual);
        stats_bool(&stats, "converged", solve_report.converged);
        stats_number(&stats, "seconds_check", t_check);
        stats_number(&stats, "reciprocity_residual", check.reciprocity);
        stats_number(&stats, "largest_row_sum", check.largest_row_sum);
        stats_number(&stats, "closure_residual", check.closure);
        stats_number(&stats, "largest_form_factor", check.largest_factor);
        stats_integer(&stats, "patches_seeing_nothing", check.empty_rows);
        stats_integer(&stats, "peak_memory_bytes", rad_peak_memory_bytes());
        stats_integer(&stats, "width", s.view.width);
        stats_integer(&stats, "height", s.view.height);
        if (!stats_write(&stats, s.stats_path))
            exit_code = EXIT_ERROR;
    }
    goto done;
fail:
    cli_error("%s", error.message);
    exit_code = EXIT_ERROR;
done:
    cli_progress_end();
    rad_image_destroy(image);
    free(B);
    rad_system_free_arrays(&system);
    rad_formfactors_destroy(ff);
    rad_tracer_destroy(occluders);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return exit_code;
}
