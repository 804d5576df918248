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
    "which the vertices run counter-clockwise; a surface need not be flat (a cylinder\n"
    "given as a mesh is one surface and may see itself). Unobstructed polygon pairs are\n"
    "integrated analytically to --accuracy; pairs with something in between sample\n"
    "visibility until their error bound meets it (or --max-rays). Output: CSV, first row\n"
    "'surface,NAME1,...,NAMEn', then one row per surface; to stdout without -o.\n"
    "A summary (the invariants: range, reciprocity, row sums; error bounds) goes to stderr.\n"
    "\n"
    "  -o, --output FILE    write the CSV here (atomically)\n"
    "  --accuracy E         relative error target of each factor (default 1e-4)\n"
    "  --max-rays N         visibility rays per sampled polygon pair at most\n"
    "                       (default 1024)\n"
    CLI_SCENE_HELP
    "  --threads N          worker threads (default: all cores)\n"
    "  --seed N             seed of the sample points (default 1)\n"
    "  --stats FILE.json    write counts, times, invariants and error bounds\n"
    "  -h, --help           this text\n";

enum { OPT_ACCURACY = OPT_OWN, OPT_MAX_RAYS, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS, CLI_SCENE_OPTIONS, [OPT_ACCURACY] = {"accuracy", 0, true},
    [OPT_MAX_RAYS] = {"max-rays", 0, true}};

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
    rad_viewfactor_options vf = {.seed = shared.seed, .threads = shared.threads,
                                 .progress = cli_progress};
    if (args.value[OPT_ACCURACY]) {
        if (!cli_parse_double("accuracy", args.value[OPT_ACCURACY], &vf.accuracy))
            return EXIT_USAGE;
        if (!(vf.accuracy >= 1e-9 && vf.accuracy <= 0.5)) {
            cli_error("--accuracy: must be between 1e-9 and 0.5");
            return EXIT_USAGE;
        }
    }
    if (args.value[OPT_MAX_RAYS]) {
        unsigned long value;
        if (!cli_parse_uint("max-rays", args.value[OPT_MAX_RAYS], 1u << 24, &value))
            return EXIT_USAGE;
        if (value < 64) {
            cli_error("--max-rays: must be at least 64");
            return EXIT_USAGE;
        }
        vf.max_rays = (uint32_t)value;
    }
    const char *output = shared.output, *stats_path = shared.stats_path;
    if ((output && !cli_output_writable(output)) ||
        (stats_path && !cli_output_writable(stats_path)))
        return EXIT_ERROR;

    int exit_code = EXIT_OK;
    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL;
    double *dense = NULL;
    rad_viewfactor_report report = {0};
    double t0 = cli_now();
    rad_status status = cli_load_scene(args.positional[0], &scene, &error);
    if (status == RAD_OK)
        status = rad_viewfactor_matrix_compute(scene, &vf, &matrix, &report, &error);
    if (status != RAD_OK)
        goto fail;
    cli_progress_end();

    rad_viewfactor_check check;
    rad_viewfactor_matrix_check(matrix, scene, &check);
    size_t S = scene->surface_count;
    fprintf(stderr,
            "radiosity: %zu surfaces, %llu polygon pairs (%llu hidden, %llu obstructed, %llu "
            "of them sampled), %llu rays, %llu non-zero factors, %.2f s\n"
            "radiosity: F in [%.6g, %.6g]; reciprocity residual %.2e; planar F_ii %.2g; "
            "largest row sum %.6f",
            S, (unsigned long long)report.polygon_pairs, (unsigned long long)report.hidden_pairs,
            (unsigned long long)report.obstructed_pairs,
            (unsigned long long)report.sampled_pairs, (unsigned long long)report.rays,
            (unsigned long long)report.nonzeros, cli_now() - t0, check.smallest, check.largest,
            check.reciprocity, check.largest_planar_self, check.largest_row_sum);
    if (check.closed)
        fprintf(stderr, "; closed enclosure: largest |row sum - 1| %.3g", check.row_sum_deviation);
    fprintf(stderr, "\nradiosity: largest error bound of a factor %.3g (absolute)", report.largest_error_bound);
    if (report.capped_pairs)
        fprintf(stderr, " (%llu sampled pairs reached --max-rays first)",
                (unsigned long long)report.capped_pairs);
    fputc('\n', stderr);
    if (check.largest > 1 || check.smallest < 0 || check.largest_planar_self > 0) {
        snprintf(error.message, sizeof(error.message),
                 "%s: internal error: a view factor outside [0, 1] or a planar F_ii > 0",
                 scene->source);
        goto fail;
    }

    dense = calloc(S ? S * S : 1, sizeof(*dense));
    if (!dense) {
        snprintf(error.message, sizeof(error.message), "out of memory for %zu surfaces", S);
        goto fail;
    }
    for (size_t I = 0; I < S; I++)
        for (uint64_t k = matrix->row_start[I]; k < matrix->row_start[I + 1]; k++)
            dense[I * S + matrix->column[k]] = matrix->value[k];
    if (output) {
        status = rad_viewfactors_write_csv(scene, dense, output, &error);
        if (status != RAD_OK)
            goto fail;
    } else {
        status = rad_viewfactors_print_csv(scene, dense, stdout, &error);
        if (status != RAD_OK)
            goto fail;
    }
    if (stats_path) {
        cli_stats stats;
        stats_begin(&stats);
        stats_string(&stats, "scene", scene->source);
        stats_integer(&stats, "surfaces", S);
        stats_integer(&stats, "surface_pairs", report.surface_pairs);
        stats_integer(&stats, "polygon_pairs", report.polygon_pairs);
        stats_integer(&stats, "hidden_pairs", report.hidden_pairs);
        stats_integer(&stats, "obstructed_pairs", report.obstructed_pairs);
        stats_integer(&stats, "sampled_pairs", report.sampled_pairs);
        stats_integer(&stats, "capped_pairs", report.capped_pairs);
        stats_integer(&stats, "rays_cast", report.rays);
        stats_integer(&stats, "nonzeros", report.nonzeros);
        stats_integer(&stats, "threads", (uint64_t)report.threads);
        stats_number(&stats, "seconds_view_factors", report.seconds);
        stats_number(&stats, "seconds_total", cli_now() - t0);
        stats_number(&stats, "largest_error_bound", report.largest_error_bound);
        stats_number(&stats, "reciprocity_residual", check.reciprocity);
        stats_number(&stats, "largest_row_sum", check.largest_row_sum);
        stats_number(&stats, "row_sum_deviation", check.row_sum_deviation);
        stats_integer(&stats, "closed_enclosure", check.closed);
        stats_integer(&stats, "peak_memory_bytes", rad_peak_memory_bytes());
        if (!stats_write(&stats, stats_path))
            exit_code = EXIT_ERROR;
    }
    goto done;
fail:
    cli_error("%s", error.message);
    exit_code = EXIT_ERROR;
done:
    free(dense);
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return exit_code;
}
