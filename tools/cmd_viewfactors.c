/*
 * cmd_viewfactors.c - `radiosity viewfactors SCENE [-o OUT.csv]`: the surface-to-surface
 * view-factor matrix, a surface being an OBJ object or group.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity viewfactors SCENE [-o OUT.csv] [options]\n"
    "\n"
    "Computes the view factor F_ij between every pair of surfaces of SCENE (an OBJ object\n"
    "or group is a surface): the fraction of the energy leaving surface i that reaches\n"
    "surface j, with obstructions. Surfaces are one-sided: the front is the side from\n"
    "which the vertices run counter-clockwise. Output: CSV, first row\n"
    "'surface,NAME1,...,NAMEn', then one row per surface; to stdout without -o.\n"
    "A summary (reciprocity and row sums) goes to stderr.\n"
    "\n"
    "  -o, --output FILE    write the CSV here (atomically)\n"
    "  --patch-size L       longest patch edge in scene units (default: about 1500 patches)\n"
    "  --visibility-rays N  occlusion rays per patch pair (default 16)\n"
    "  --quadrature M       M x M points per patch for the analytic part (default 3)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  --seed N             seed of the sample points (default 1)\n"
    "  --stats FILE.json    write counts, times and residuals\n"
    "  -h, --help           this text\n";

enum { OPT_COUNT = OPT_OWN };

static const cli_option options[OPT_COUNT] = {CLI_BASE_OPTIONS, CLI_FORMFACTOR_OPTIONS};

#define DEFAULT_TARGET_PATCHES 1500u
#define DEFAULT_QUADRATURE 3u

int command_viewfactors(int argc, char **argv)
{
    cli_args args;
    if (!cli_parse("viewfactors", argc, argv, options, OPT_COUNT, &args))
        return EXIT_USAGE;
    if (args.value[OPT_HELP]) {
        fputs(usage, stdout);
        return EXIT_OK;
    }
    if (args.positional_count != 1) {
        cli_error("viewfactors: give exactly one SCENE (see 'radiosity viewfactors --help')");
        return EXIT_USAGE;
    }
    cli_shared shared;
    if (!cli_parse_shared(&args, &shared))
        return EXIT_USAGE;
    rad_formfactor_options ff = shared.formfactor;
    if (!args.value[OPT_QUADRATURE])
        ff.quadrature = DEFAULT_QUADRATURE;
    double patch_size = shared.patch_size;
    const char *output = shared.output, *stats_path = shared.stats_path;
    if ((output && !cli_output_writable(output)) ||
        (stats_path && !cli_output_writable(stats_path)))
        return EXIT_ERROR;

    int exit_code = EXIT_OK;
    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_tracer *occluders = NULL;
    double *matrix = NULL, *areas = NULL;
    rad_formfactor_report report = {0};
    double t0 = cli_now();
    rad_status status = cli_load_scene(args.positional[0], &scene, &error);
    if (status != RAD_OK)
        goto fail;
    if (patch_size <= 0)
        patch_size = rad_mesh_default_patch_size(scene, DEFAULT_TARGET_PATCHES);
    status = rad_mesh_build(scene, patch_size, &mesh, &error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &occluders, &error);
    if (status != RAD_OK)
        goto fail;
    size_t S = scene->surface_count;
    matrix = calloc(S * S, sizeof(*matrix));
    areas = calloc(S, sizeof(*areas));
    if (!matrix || !areas) {
        snprintf(error.message, sizeof(error.message), "out of memory for %zu surfaces", S);
        goto fail;
    }
    status = rad_viewfactors_compute(scene, mesh, occluders, &ff, matrix, areas, &report, &error);
    if (status != RAD_OK)
        goto fail;
    cli_progress_end();

    /* the invariants, reported on every run */
    double reciprocity = 0, row_deviation = 0, largest = 0;
    for (size_t i = 0; i < S; i++) {
        double row = 0;
        for (size_t j = 0; j < S; j++) {
            row += matrix[i * S + j];
            largest = fmax(largest, matrix[i * S + j]);
            double a = areas[i] * matrix[i * S + j], b = areas[j] * matrix[j * S + i];
            if (fmax(a, b) > 0)
                reciprocity = fmax(reciprocity, fabs(a - b) / fmax(a, b));
        }
        row_deviation = fmax(row_deviation, fabs(row - 1));
    }
    fprintf(stderr,
            "radiosity: %zu surfaces, %u patches, %llu rays, %.2f s; largest F %.6g, "
            "reciprocity residual %.2e, largest |row sum - 1| %.4g (0 only for closed "
            "enclosures)\n",
            S, mesh->patch_count, (unsigned long long)report.rays, cli_now() - t0, largest,
            reciprocity, row_deviation);

    if (output) {
        status = rad_viewfactors_write_csv(scene, matrix, output, &error);
        if (status != RAD_OK)
            goto fail;
    } else {
        status = rad_viewfactors_print_csv(scene, matrix, stdout, &error);
        if (status != RAD_OK)
            goto fail;
    }
    if (stats_path) {
        cli_stats stats;
        stats_begin(&stats);
        stats_string(&stats, "scene", scene->source);
        stats_integer(&stats, "surfaces", S);
        stats_integer(&stats, "patches", mesh->patch_count);
        stats_integer(&stats, "rays_cast", report.rays);
        stats_number(&stats, "seconds_form_factors", report.seconds);
        stats_number(&stats, "seconds_total", cli_now() - t0);
        stats_number(&stats, "reciprocity_residual", reciprocity);
        stats_number(&stats, "row_sum_deviation", row_deviation);
        stats_integer(&stats, "peak_memory_bytes", rad_peak_memory_bytes());
        if (!stats_write(&stats, stats_path))
            exit_code = EXIT_ERROR;
    }
    goto done;
fail:
    cli_error("%s", error.message);
    exit_code = EXIT_ERROR;
done:
    free(matrix);
    free(areas);
    rad_tracer_destroy(occluders);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return exit_code;
}
