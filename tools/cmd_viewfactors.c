/*
 * cmd_viewfactors.c - `radiosity viewfactors SCENE... [-o OUT]`: the surface-to-surface
 * view-factor matrix, a surface being an OBJ object or group, a View3D surface, or a whole
 * mesh file when several are given; then the optional enclosure correction and script-F
 * factors, written as CSV, Matrix Market or View3D's text layout. Under mpirun the ranks
 * share the rows (the library does) and rank 0 alone does the rest and writes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_ranks.h"

static const char usage[] =
    "usage: radiosity viewfactors SCENE [MESH...] [-o OUT.csv|OUT.mtx] [options]\n"
    "\n"
    "Computes the view factor F_ij between every pair of surfaces: the fraction of the\n"
    "energy leaving surface i that reaches surface j, with obstructions. One SCENE: its\n"
    "surfaces are its OBJ objects or groups, or the surfaces of a View3D input file (.vs3,\n"
    "F 3 geometry; its control line's encl=1 and emit=1 act as --enclosure and\n"
    "--script-f). Several files (OBJ, STL, PLY, ...): each file is one surface, named after\n"
    "the file without its extension. Surfaces are one-sided: the front is the side from\n"
    "which the vertices run counter-clockwise; a surface need not be flat (a cylinder\n"
    "given as a mesh is one surface and may see itself). Unobstructed polygon pairs are\n"
    "integrated analytically to --accuracy; pairs with something in between to an\n"
    "absolute error of F of --accuracy x sqrt(F unobstructed): behind at most\n"
    "--exact-occluders triangles by the same integral of the part left visible, behind\n"
    "more by sampled visibility (up to --max-rays). Output by the extension\n"
    "of -o: .mtx is Matrix Market (sparse coordinates), anything else CSV (first row\n"
    "'surface,NAME1,...,NAMEn', then one row per surface), or --format; CSV to stdout\n"
    "without -o. Obstruction surfaces have no row or column. The invariants (range,\n"
    "reciprocity, row sums; error bounds) and a summary line go to stderr (not with\n"
    "--quiet).\n"
    "\n"
    "  -o, --output FILE    write the matrix here (atomically)\n"
    "  --format F           csv, mtx or view3d (View3D's text output: header, areas,\n"
    "                       rows, emissivities); default: by the extension of -o\n"
    "  --obstruction FILE   a mesh that only blocks (one surface, no row); repeatable\n"
    "  --two-sided NAME     surface NAME radiates from both sides; repeatable\n"
    "  --enclosure          close the enclosure: rows sum to 1, reciprocity kept\n"
    "                       (least-squares correction; its size is reported)\n"
    "  --script-f           grey-body total exchange factors (Hottel's script-F) with\n"
    "                       the surfaces' emissivities (View3D emit field; default "
    CLI_STR(RAD_DEFAULT_EMISSIVITY) ")\n"
    "  --accuracy E         relative error target of each factor (default "
    CLI_STR(RAD_DEFAULT_ACCURACY) ")\n"
    "  --max-rays N         visibility rays per sampled polygon pair at most\n"
    "                       (default " CLI_STR(RAD_DEFAULT_MAX_RAYS) ")\n"
    "  --exact-occluders N  pairs behind at most N triangles are clipped exactly, not\n"
    "                       sampled (default and most " CLI_STR(RAD_MAX_EXACT_OCCLUDERS) ",\n"
    "                       the accuracy for every pair behind that many; 4 is 8-10x\n"
    "                       faster on cities, with sampled bounds far above it)\n"
    CLI_BASE_HELP("counts, times, invariants and error bounds");

/* The rest of the help (one string may hold 4095 characters in C17), after the scene's. */
static const char usage_more[] =
    "\nPairs that cannot see each other, sky, repair, memory and long runs:\n"
    "  --sight-rays N|none  cosine-distributed rays from each surface that find the pairs\n"
    "                       that see each other at all (default -ln 0.05 / --accuracy,\n"
    "                       about 3 / --accuracy); a pair no ray of either side met is\n"
    "                       F = 0, within 3 / N (95 % for each pair), and the run\n"
    "                       prints what such pairs hold of a row (estimated). none:\n"
    "                       every pair is integrated or proven hidden (exact zeros, far\n"
    "                       slower on large open scenes)\n"
    "  --sky-view-factor FILE  each surface's sky view factor (the share of its\n"
    "                       hemisphere that sees no surface, integrated like the factors)\n"
    "                       and its error bound: CSV, or a Matrix Market column for a\n"
    "                       .mtx name; prints the largest |row sum + SVF - 1|\n"
    "  --sky-exact          clip the sky seen past more than 16 triangles exactly (up\n"
    "                       to --exact-occluders): bounds at about --accuracy (up to\n"
    "                       1.3x where many shadows cross), about 13x the matrix's\n"
    "                       time on a city (default: sampled, seconds, bounds about\n"
    "                       1e-2 there)\n"
    "  --error-bounds FILE  each stored factor's error bound (absolute, in units of F),\n"
    "                       as -o writes the factors: Matrix Market for a .mtx name,\n"
    "                       else CSV (the pairs no sight ray met are within 3 / N)\n"
    "  --repair-rows        trim rows that sum above 1 keeping reciprocity (symmetric\n"
    "                       scaling of A_i F_ij); reports the largest change, the share\n"
    "                       of exchange removed and the reciprocity residual\n"
    "  --repair-max-change R   refuse the repair (no output) when a factor would change\n"
    "                       by more than R of its value (default 0.05)\n"
    "  --repair-max-removed S  refuse it when it would remove more than S of the\n"
    "                       exchange sum A_i F_ij (default 0.01)\n"
    "  --max-memory SIZE    bytes the whole run may hold (K, M, G): scene, occluders,\n"
    "                       per-thread buffers, matrix. Refused before any row when the\n"
    "                       matrix's bound cannot fit (24 bytes per pair the sight rays\n"
    "                       met, or with --sight-rays none per pair of surfaces that do\n"
    "                       not face away, plus 20 per factor); anything else that would\n"
    "                       exceed it ends the run with an error (default: no budget)\n"
    "  --checkpoint FILE    write the rows done so far to FILE (atomically) every\n"
    "                       --checkpoint-interval seconds, and on SIGINT or SIGTERM, which\n"
    "                       then end the run (status 130, no output)\n"
    "  --checkpoint-interval S  seconds between checkpoints (default 600; 0: after each\n"
    "                       1/64 of the rows)\n"
    "  --resume FILE        continue the job of this checkpoint (same scene, --accuracy,\n"
    "                       --max-rays, --sight-rays, --exact-occluders, --seed; others\n"
    "                       are refused): the output is the one an uninterrupted run\n"
    "                       writes. Checkpoints go on to FILE unless --checkpoint names\n"
    "                       another\n"
    "  --plot FILE.svg      the fraction of polygon pairs left against time (log scale):\n"
    "                       the computation's progress; it has no iteration to converge\n";

enum {
    OPT_ACCURACY = OPT_OWN, OPT_MAX_RAYS, OPT_FORMAT, OPT_ENCLOSURE, OPT_SCRIPT_F,
    OPT_OBSTRUCTION, OPT_TWO_SIDED, OPT_CHECKPOINT, OPT_CHECKPOINT_INTERVAL, OPT_RESUME,
    OPT_SKY_VIEW_FACTOR, OPT_REPAIR_ROWS, OPT_REPAIR_MAX_CHANGE, OPT_REPAIR_MAX_REMOVED,
    OPT_SIGHT_RAYS, OPT_EXACT_OCCLUDERS, OPT_SKY_EXACT, OPT_ERROR_BOUNDS, OPT_COUNT
};

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS, CLI_SCENE_OPTIONS, [OPT_ACCURACY] = {"accuracy", 0, true},
    [OPT_MAX_RAYS] = {"max-rays", 0, true},   [OPT_FORMAT] = {"format", 0, true},
    [OPT_ENCLOSURE] = {"enclosure", 0, false}, [OPT_SCRIPT_F] = {"script-f", 0, false},
    [OPT_OBSTRUCTION] = {"obstruction", 0, true}, [OPT_TWO_SIDED] = {"two-sided", 0, true},
    [OPT_MAX_MEMORY] = {"max-memory", 0, true}, [OPT_CHECKPOINT] = {"checkpoint", 0, true},
    [OPT_CHECKPOINT_INTERVAL] = {"checkpoint-interval", 0, true},
    [OPT_RESUME] = {"resume", 0, true}, [OPT_PLOT] = {"plot", 0, true},
    [OPT_SKY_VIEW_FACTOR] = {"sky-view-factor", 0, true},
    [OPT_REPAIR_ROWS] = {"repair-rows", 0, false},
    [OPT_REPAIR_MAX_CHANGE] = {"repair-max-change", 0, true},
    [OPT_REPAIR_MAX_REMOVED] = {"repair-max-removed", 0, true},
    [OPT_SIGHT_RAYS] = {"sight-rays", 0, true},
    [OPT_EXACT_OCCLUDERS] = {"exact-occluders", 0, true},
    [OPT_SKY_EXACT] = {"sky-exact", 0, false},
    [OPT_ERROR_BOUNDS] = {"error-bounds", 0, true}};

/* --repair-rows' default limits (relative change of a factor, share of exchange). */
#define REPAIR_MAX_CHANGE 0.05
#define REPAIR_MAX_REMOVED 0.01

/* --obstruction files at most; as many SCENE files (cli_args.positional). */
#define MAX_FILES 256

/* The scene: one SCENE with its own surfaces (a View3D file with its control line), or
 * several files, each one surface, plus the obstruction meshes. */
static rad_status load_surfaces(const cli_args *args, rad_scene **scene,
                                rad_vs3_control *control, bool *is_vs3, rad_error *error)
{
    rad_load_options load = {cli_log, NULL};
    int obstructions = cli_value_count(args, OPT_OBSTRUCTION), cursor = 0;
    *is_vs3 = false;
    if (args->positional_count == 1 && obstructions == 0) {
        if (rad_scene_is_vs3(args->positional[0])) {
            *is_vs3 = true;
            return rad_scene_load_vs3(args->positional[0], &load, scene, control, error);
        }
        return cli_load_scene(args->positional[0], scene, error);
    }
    rad_scene_file files[2 * MAX_FILES];
    uint32_t count = 0;
    for (int k = 0; k < args->positional_count; k++)
        files[count++] = (rad_scene_file){args->positional[k], 0, args->positional_count == 1};
    for (const char *path; (path = cli_next_value(args, OPT_OBSTRUCTION, &cursor));)
        files[count++] = (rad_scene_file){path, RAD_SURFACE_OBSTRUCTION, false};
    return rad_scene_load_files(files, count, &load, scene, error);
}

/* --repair-rows and its limits; false (after a message) on a usage error. */
static bool parse_repair_options(const cli_args *args, rad_row_repair_limits *limits)
{
    const int limit_options[2] = {OPT_REPAIR_MAX_CHANGE, OPT_REPAIR_MAX_REMOVED};
    double *limit_values[2] = {&limits->max_relative_change, &limits->max_removed_share};
    for (int k = 0; k < 2; k++) {
        const char *text = args->value[limit_options[k]], *name = options[limit_options[k]].name;
        if (!text)
            continue;
        if (!args->value[OPT_REPAIR_ROWS]) {
            cli_error("--%s: applies to --repair-rows only", name);
            return false;
        }
        if (!cli_parse_double(name, text, limit_values[k]))
            return false;
        if (!(*limit_values[k] > 0 && *limit_values[k] <= 1)) {
            cli_error("--%s: must be in (0, 1]", name);
            return false;
        }
    }
    if (args->value[OPT_REPAIR_ROWS] && args->value[OPT_ENCLOSURE]) {
        cli_error("viewfactors: --repair-rows and --enclosure: choose one (--enclosure closes "
                  "every row to 1, --repair-rows only trims rows above 1)");
        return false;
    }
    return true;
}

/* The sky view factors (*sky: S values, then their S bounds) and the check row sum + SVF
 * = 1, printed. False with *error set. */
static bool sky_view_factors(const rad_scene *scene, const rad_viewfactor_options *vf,
                             const rad_viewfactor_matrix *matrix, double **sky,
                             rad_sky_report *report, rad_sky_check *check, rad_error *error)
{
    size_t S = scene->surface_count;
    *sky = rad_alloc_array(S ? 2 * S : 1, sizeof(double));
    if (!*sky) {
        snprintf(error->message, sizeof(error->message), "%s: out of memory for %zu surfaces",
                 scene->source, S);
        return false;
    }
    rad_viewfactor_options sky_options = *vf;
    sky_options.progress = NULL;
    if (rad_sky_viewfactors_compute(scene, &sky_options, *sky, *sky + S, report, error) != RAD_OK)
        return false;
    rad_sky_viewfactor_check(matrix, scene, *sky, *sky + S, check);
    double accuracy = vf->accuracy > 0 ? vf->accuracy : RAD_DEFAULT_ACCURACY;
    cli_summary("sky view factors: %llu polygon-sky pairs (%llu obstructed: %llu exact, %llu "
                "sampled; %llu polygons reached 16 x --max-rays), largest bound %.3g, %.2f s",
                (unsigned long long)report->polygon_pairs,
                (unsigned long long)report->obstructed_pairs,
                (unsigned long long)report->exact_pairs,
                (unsigned long long)report->sampled_pairs,
                (unsigned long long)report->capped_pairs, report->largest_error_bound,
                report->seconds);
    if (report->short_surfaces)
        cli_summary("sky view factors: %u of %u short of --accuracy %g (their bound above it, "
                    "absolute): %s",
                    report->short_surfaces, report->surfaces, accuracy,
                    vf->sky_exact ? "where shadows crowd, the quadrature's deepest split "
                                    "leaves more (a smaller --accuracy narrows it), or their "
                                    "sky is sampled past more than --exact-occluders triangles"
                                  : "the sky seen past more than 16 triangles is sampled, "
                                    "and a sampled bound falls only as 1 / sqrt(--max-rays); "
                                    "--sky-exact clips it (slower)");
    else if (report->surfaces)
        cli_summary("sky view factors: every one within --accuracy %g (absolute)", accuracy);
    if (check->worst_surface != UINT32_MAX)
        cli_summary("sky view factors: largest |row sum + SVF - 1| %.3g (accuracy %.3g) at "
                    "'%s': row sum %.9f (bound %.3g), SVF %.9f (bound %.3g)",
                    check->largest_deviation, accuracy,
                    scene->surfaces[check->worst_surface].name, check->worst_row_sum,
                    check->worst_row_bound, (*sky)[check->worst_surface], check->worst_sky_bound);
    return true;
}

/* --repair-rows: the repair and its report, or its refusal naming the limit's option. */
static bool repair_rows(const rad_scene *scene, rad_viewfactor_matrix *matrix,
                        const rad_row_repair_limits *limits, rad_row_repair_report *repair,
                        rad_error *error)
{
    rad_status status = rad_viewfactor_matrix_repair_rows(matrix, scene, limits, repair, error);
    if (status == RAD_OK) {
        cli_summary("row repair: %u rows above 1 (largest sum %.9f, %.9f after), %u rows "
                    "scaled; largest change of a factor %.3g ('%s' to '%s', %.9g to %.9g; "
                    "largest relative %.3g); exchange removed %.3g; reciprocity residual %.2g",
                    repair->rows_above_one, repair->largest_row_sum_before,
                    repair->largest_row_sum_after, repair->rows_trimmed, repair->largest_change,
                    scene->surfaces[repair->largest_change_row].name,
                    scene->surfaces[repair->largest_change_column].name,
                    repair->largest_change_before, repair->largest_change_after,
                    repair->largest_relative_change, repair->removed_share,
                    repair->reciprocity_after);
        return true;
    }
    if (repair->refused == RAD_ROW_REPAIR_REFUSED_CHANGE)
        snprintf(error->message, sizeof(error->message),
                 "%s: --repair-rows refused: F from '%s' to '%s' would change by %.3g of its "
                 "value, more than --repair-max-change %g; nothing written",
                 scene->source, scene->surfaces[repair->largest_relative_row].name,
                 scene->surfaces[repair->largest_relative_column].name,
                 repair->largest_relative_change, limits->max_relative_change);
    else if (repair->refused == RAD_ROW_REPAIR_REFUSED_REMOVED)
        snprintf(error->message, sizeof(error->message),
                 "%s: --repair-rows refused: it would remove %.3g of the exchange, more than "
                 "--repair-max-removed %g; nothing written",
                 scene->source, repair->removed_share, limits->max_removed_share);
    return false;
}

int command_viewfactors(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    int exit_code;
    if (!cli_begin("viewfactors", usage, argc, argv, options, OPT_COUNT, &args, &shared,
                   &exit_code)) {
        if (exit_code == EXIT_OK && args.value[OPT_HELP])
            fputs(usage_more, stdout);
        return exit_code;
    }
    if (args.positional_count < 1) {
        cli_error("viewfactors: give a SCENE or mesh files (see 'radiosity viewfactors --help')");
        return EXIT_USAGE;
    }
    if (cli_value_count(&args, OPT_OBSTRUCTION) > MAX_FILES) {
        cli_error("viewfactors: --obstruction given more than %d times", MAX_FILES);
        return EXIT_USAGE;
    }
    if ((args.value[OPT_EMIT] || args.value[OPT_ALBEDO]) &&
        (args.positional_count > 1 || args.value[OPT_OBSTRUCTION] ||
         rad_scene_is_vs3(args.positional[0]))) {
        cli_error("viewfactors: --emit and --albedo apply to one OBJ (or other mesh) scene "
                  "only; they do not change view factors");
        return EXIT_USAGE;
    }
    rad_viewfactor_options vf = {0};
    CLI_SET_RUN_OPTIONS(vf, shared);
    if (args.value[OPT_ACCURACY]) {
        if (!cli_parse_double("accuracy", args.value[OPT_ACCURACY], &vf.accuracy))
            return EXIT_USAGE;
        if (!(vf.accuracy >= 1e-9 && vf.accuracy <= 0.5)) {
            cli_error("--accuracy: must be between 1e-9 and 0.5");
            return EXIT_USAGE;
        }
    }
    if (!cli_parse_count("max-rays", args.value[OPT_MAX_RAYS], 64, 1u << 24, &vf.max_rays))
        return EXIT_USAGE;
    if (!cli_parse_count("exact-occluders", args.value[OPT_EXACT_OCCLUDERS], 1,
                         RAD_MAX_EXACT_OCCLUDERS, &vf.exact_occluders))
        return EXIT_USAGE;
    if (args.value[OPT_SIGHT_RAYS] && strcmp(args.value[OPT_SIGHT_RAYS], "none") == 0)
        vf.sight_rays = RAD_SIGHT_RAYS_NONE;
    else if (!cli_parse_count("sight-rays", args.value[OPT_SIGHT_RAYS], 64, 1u << 26,
                              &vf.sight_rays))
        return EXIT_USAGE;
    uint64_t max_memory = 0;
    if (args.value[OPT_MAX_MEMORY] &&
        !cli_parse_bytes("max-memory", args.value[OPT_MAX_MEMORY], &max_memory))
        return EXIT_USAGE;
    cli_memory_budget(max_memory);
    vf.resume = args.value[OPT_RESUME];
    vf.checkpoint = args.value[OPT_CHECKPOINT] ? args.value[OPT_CHECKPOINT] : vf.resume;
    vf.checkpoint_interval = CLI_CHECKPOINT_INTERVAL;
    if (args.value[OPT_CHECKPOINT_INTERVAL]) {
        if (!vf.checkpoint) {
            cli_error("--checkpoint-interval: give --checkpoint FILE (or --resume FILE) too");
            return EXIT_USAGE;
        }
        if (!cli_parse_checkpoint_interval(args.value[OPT_CHECKPOINT_INTERVAL],
                                           &vf.checkpoint_interval))
            return EXIT_USAGE;
    }
    const char *output = shared.output, *stats_path = shared.stats_path;
    rad_viewfactor_write_options write = {RAD_VIEWFACTOR_CSV, false, false, false};
    if (output)
        write.format = rad_viewfactor_format_for_path(output);
    if (args.value[OPT_FORMAT]) {
        const char *format = args.value[OPT_FORMAT];
        if (strcmp(format, "csv") == 0)
            write.format = RAD_VIEWFACTOR_CSV;
        else if (strcmp(format, "mtx") == 0)
            write.format = RAD_VIEWFACTOR_MATRIX_MARKET;
        else if (strcmp(format, "view3d") == 0)
            write.format = RAD_VIEWFACTOR_VIEW3D;
        else {
            cli_error("--format: '%s' is not csv, mtx or view3d", format);
            return EXIT_USAGE;
        }
    }
    const char *plot_path = args.value[OPT_PLOT];
    if (!cli_convergence_paths_ok(plot_path, NULL))
        return EXIT_USAGE;
    const char *sky_path = args.value[OPT_SKY_VIEW_FACTOR];
    if (args.value[OPT_SKY_EXACT] && !sky_path) {
        cli_error("--sky-exact: applies to --sky-view-factor FILE only");
        return EXIT_USAGE;
    }
    vf.sky_exact = args.value[OPT_SKY_EXACT] != NULL;
    rad_row_repair_limits repair_limits = {REPAIR_MAX_CHANGE, REPAIR_MAX_REMOVED};
    if (!parse_repair_options(&args, &repair_limits))
        return EXIT_USAGE;
    const char *bounds_path = args.value[OPT_ERROR_BOUNDS];
    if (!cli_outputs_writable(
            (const char *[]){output, stats_path, vf.checkpoint, plot_path, sky_path, bounds_path},
            6))
        return EXIT_ERROR;

    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL;
    double *emissivity = NULL;
    rad_viewfactor_report report = {0};
    rad_enclosure_report enclosure = {0};
    rad_row_repair_report repair = {0};
    double *sky = NULL;
    rad_sky_report sky_report = {0};
    rad_sky_check sky_check = {0};
    rad_vs3_control control = {0};
    bool is_vs3 = false;
    double t0 = rad_clock_seconds();
    if (cli_ranks_begin() > 1 && rad_rank() != 0)
        vf.progress = NULL; /* rank 0 shows its own rows' progress */
    cli_viewfactor_plot plot;
    cli_viewfactor_plot_begin(&plot, plot_path, &vf);
    rad_status status = load_surfaces(&args, &scene, &control, &is_vs3, &error);
    int cursor = 0;
    for (const char *name; status == RAD_OK && (name = cli_next_value(&args, OPT_TWO_SIDED, &cursor));)
        status = rad_scene_set_surface_flags(scene, name, RAD_SURFACE_TWO_SIDED, &error);
    if (status == RAD_OK && is_vs3 && (control.row || control.col) && rad_rank() == 0)
        cli_warn("%s: the control line's row/col are ignored: every factor is computed",
                 scene->source);
    write.enclosure = args.value[OPT_ENCLOSURE] || (is_vs3 && control.enclosure);
    write.script_f = args.value[OPT_SCRIPT_F] || (is_vs3 && control.emit);
    if (status == RAD_OK && write.script_f && scene->surface_count > RAD_SCRIPT_F_MAX_SURFACES) {
        snprintf(error.message, sizeof(error.message),
                 "%s: --script-f: script-F factors are computed densely, for at most %u "
                 "surfaces (this scene has %u)",
                 scene->source, RAD_SCRIPT_F_MAX_SURFACES, scene->surface_count);
        status = RAD_ERR_UNSUPPORTED;
    }
    if (!cli_ranks_ok(status, &error))
        goto fail;
    cli_progress_mark();
    cli_checkpoints checkpoints;
    if (vf.checkpoint) /* SIGINT and SIGTERM stop at the next round, with a checkpoint */
        vf.stop = cli_checkpoints_begin(&checkpoints, &vf.progress, &vf.progress_user);
    status = rad_viewfactor_matrix_compute(scene, &vf, &matrix, &report, &error);
    if (vf.checkpoint)
        cli_checkpoints_end(&checkpoints);
    if (!cli_ranks_ok(status, &error))
        goto fail;
    cli_progress_end();
    if (report.resumed_rows && rad_rank() == 0)
        cli_summary("resumed from %s: %u of %u rows were done", vf.resume, report.resumed_rows,
                    scene->surface_count);
    if (report.interrupted) {
        if (rad_rank() == 0)
            cli_error("viewfactors: interrupted: %s holds %u of %u rows; continue with "
                      "--resume %s",
                      vf.checkpoint, report.checkpoint_rows, scene->surface_count,
                      vf.checkpoint);
        exit_code = EXIT_INTERRUPTED;
        goto done;
    }
    rad_rank_report rank_report = {report.rank_rows, report.rank_seconds, 0, 0};
    double imbalance = 1;
    if (!cli_ranks_summary(&rank_report, "rows", &imbalance, &error))
        goto fail;
    if (rad_rank() != 0) /* rank 0 has the matrix and does the rest */
        goto done;

    rad_viewfactor_check check;
    rad_viewfactor_matrix_check(matrix, scene, &check);
    size_t S = scene->surface_count;
    char closed[96] = "", capped[96] = "";
    if (check.closed)
        snprintf(closed, sizeof(closed), "; closed enclosure: largest |row sum - 1| %.3g",
                 check.row_sum_deviation);
    if (report.capped_pairs)
        snprintf(capped, sizeof(capped), " (%llu sampled pairs reached --max-rays first)",
                 (unsigned long long)report.capped_pairs);
    cli_summary("F in [%.6g, %.6g]; reciprocity residual %.2e; planar F_ii %.2g; largest row "
                "sum %.6f%s",
                check.smallest, check.largest, check.reciprocity, check.largest_planar_self,
                check.largest_row_sum, closed);
    cli_summary("largest error bound of a factor %.3g (absolute)%s", report.largest_error_bound,
                capped);
    const double accuracy_asked = vf.accuracy > 0 ? vf.accuracy : RAD_DEFAULT_ACCURACY;
    /* the counts are those of the rows this run computed, not of rows read from a
     * checkpoint */
    const char *rows_counted = report.resumed_rows ? " in the rows computed by this run" : "";
    if (report.short_pairs)
        cli_summary("%llu of %llu polygon pairs%s short of --accuracy %g (their bound above "
                    "accuracy x sqrt(F unobstructed)): %s",
                    (unsigned long long)report.short_pairs,
                    (unsigned long long)report.polygon_pairs, rows_counted, accuracy_asked,
                    report.exact_occluders < RAD_MAX_EXACT_OCCLUDERS
                        ? "a larger --exact-occluders clips more of them exactly"
                        : "they are sampled behind more occluders than --exact-occluders");
    else
        cli_summary("every factor%s within --accuracy %g (obstructed: accuracy x sqrt(F "
                    "unobstructed), absolute)",
                    rows_counted, accuracy_asked);
    if (report.sight_rays)
        cli_summary("pairs no sight ray met (%u a surface): F = 0, each within %.1e (95 %%); "
                    "what they hold of a row, estimated: %.2g on average, %.2g at most",
                    report.sight_rays, report.unmet_bound, report.missed_mean,
                    report.missed_largest);
    if (check.largest > 1 || check.smallest < 0 || check.largest_planar_self > 0) {
        snprintf(error.message, sizeof(error.message),
                 "%s: internal error: a view factor outside [0, 1] or a planar F_ii > 0",
                 scene->source);
        goto fail;
    }

    if (sky_path && !sky_view_factors(scene, &vf, matrix, &sky, &sky_report, &sky_check, &error))
        goto fail;
    if (is_vs3) {
        status = rad_viewfactor_matrix_apply_vs3_masks(args.positional[0], scene, &matrix, &error);
        if (status != RAD_OK)
            goto fail;
    }
    if (write.enclosure) {
        if (!check.closed)
            cli_warn("%s: --enclosure: the surfaces' triangles do not share every edge; the "
                     "rows are closed anyway",
                     scene->source);
        status = rad_viewfactor_matrix_close_enclosure(matrix, scene, &enclosure, &error);
        if (status != RAD_OK)
            goto fail;
        cli_summary("enclosure correction: largest relative change of a factor %.3g; largest "
                    "|row sum - 1| %.3g before, %.2g after; reciprocity residual %.2g",
                    enclosure.largest_relative_change, enclosure.row_deviation_before,
                enclosure.row_deviation_after, enclosure.reciprocity_after);
    }
    if (args.value[OPT_REPAIR_ROWS] && !repair_rows(scene, matrix, &repair_limits, &repair, &error))
        goto fail;
    if (write.script_f) {
        emissivity = rad_alloc_array(S ? S : 1, sizeof(*emissivity));
        if (!emissivity) {
            snprintf(error.message, sizeof(error.message), "%s: out of memory for %zu surfaces",
                     scene->source, S);
            goto fail;
        }
        for (size_t I = 0; I < S; I++)
            emissivity[I] = scene->surfaces[I].emissivity;
        rad_viewfactor_matrix *exchange = NULL;
        status = rad_viewfactor_matrix_script_f(matrix, emissivity, &exchange, &error);
        if (status != RAD_OK)
            goto fail;
        rad_viewfactor_matrix_destroy(matrix);
        matrix = exchange;
        cli_summary("script-F total exchange factors with the surfaces' emissivities");
    }
    if (sky_path &&
        rad_sky_viewfactors_write(scene, sky, sky + S, sky_path, &error) != RAD_OK)
        goto fail;
    status = output ? rad_viewfactor_matrix_write(scene, matrix, output, &write, &error)
                    : rad_viewfactor_matrix_print(scene, matrix, stdout, &write, &error);
    if (status == RAD_OK && bounds_path) {
        /* the same pattern with the bounds for values (a bound of 0 is not written, as a
         * factor of 0 is not) */
        rad_viewfactor_matrix bounds = *matrix;
        bounds.value = matrix->error_bound;
        rad_viewfactor_write_options layout = {rad_viewfactor_format_for_path(bounds_path), false,
                                               false, true};
        status = rad_viewfactor_matrix_write(scene, &bounds, bounds_path, &layout, &error);
    }
    if (status == RAD_OK)
        status = cli_viewfactor_plot_end(&plot, scene->source, (uint32_t)S, &error);
    if (status != RAD_OK)
        goto fail;
    double seconds = rad_clock_seconds() - t0;
    cli_stats stats;
    stats_begin(&stats);
    stats_string(&stats, "scene", scene->source);
    stats_integer(&stats, "surfaces", S);
    stats_integer(&stats, "surface_pairs", report.surface_pairs);
    stats_integer(&stats, "polygon_pairs", report.polygon_pairs);
    stats_integer(&stats, "unobstructed_pairs", report.unobstructed_pairs);
    stats_integer(&stats, "hidden_pairs", report.hidden_pairs);
    stats_integer(&stats, "obstructed_pairs", report.obstructed_pairs);
    stats_integer(&stats, "exact_pairs", report.exact_pairs);
    stats_integer(&stats, "sampled_pairs", report.sampled_pairs);
    stats_integer(&stats, "unseen_pairs", report.unseen_pairs);
    stats_integer(&stats, "capped_pairs", report.capped_pairs);
    stats_integer(&stats, "short_pairs", report.short_pairs);
    stats_integer(&stats, "roomy_pairs", report.roomy_pairs);
    stats_integer(&stats, "exact_occluders", report.exact_occluders);
    stats_integer(&stats, "rays_cast", report.rays);
    stats_integer(&stats, "unmet_pairs", report.unmet_pairs);
    stats_integer(&stats, "sight_rays_a_surface", report.sight_rays);
    stats_integer(&stats, "sight_rays_cast", report.sight_rays_cast);
    stats_number(&stats, "unmet_bound", report.unmet_bound);
    stats_number(&stats, "sight_seconds", report.sight_seconds);
    stats_number(&stats, "missed_share_largest", report.missed_largest);
    stats_number(&stats, "missed_share_mean", report.missed_mean);
    stats_integer(&stats, "nonzeros", report.nonzeros);
    stats_integer(&stats, "threads", (uint64_t)report.threads);
    stats_number(&stats, "seconds_view_factors", report.seconds);
    stats_number(&stats, "seconds_total", seconds);
    stats_number(&stats, "largest_error_bound", report.largest_error_bound);
    stats_number(&stats, "reciprocity_residual", check.reciprocity);
    stats_number(&stats, "largest_row_sum", check.largest_row_sum);
    stats_number(&stats, "row_sum_deviation", check.row_sum_deviation);
    stats_integer(&stats, "closed_enclosure", check.closed);
    stats_bool(&stats, "enclosure_corrected", write.enclosure);
    if (write.enclosure) {
        stats_number(&stats, "enclosure_largest_relative_change",
                     enclosure.largest_relative_change);
        stats_number(&stats, "enclosure_row_sum_deviation_before",
                     enclosure.row_deviation_before);
        stats_number(&stats, "enclosure_row_sum_deviation_after",
                     enclosure.row_deviation_after);
    }
    stats_bool(&stats, "script_f", write.script_f);
    if (sky_path) {
        stats_number(&stats, "sky_seconds", sky_report.seconds);
        stats_number(&stats, "sky_largest_error_bound", sky_report.largest_error_bound);
        stats_number(&stats, "sky_row_sum_deviation", sky_check.largest_deviation);
        stats_integer(&stats, "sky_sampled_pairs", sky_report.sampled_pairs);
        stats_integer(&stats, "sky_short_surfaces", sky_report.short_surfaces);
    }
    if (args.value[OPT_REPAIR_ROWS]) {
        stats_number(&stats, "repair_largest_change", repair.largest_change);
        stats_number(&stats, "repair_largest_relative_change", repair.largest_relative_change);
        stats_number(&stats, "repair_removed_share", repair.removed_share);
        stats_number(&stats, "repair_reciprocity_after", repair.reciprocity_after);
        stats_integer(&stats, "repair_rows_trimmed", repair.rows_trimmed);
    }
    if (rad_rank_count() > 1) {
        stats_integer(&stats, "ranks", (unsigned long long)rad_rank_count());
        stats_number(&stats, "load_imbalance", imbalance);
    }
    char unmet[96] = "", sight[64] = "";
    if (report.sight_rays) {
        snprintf(unmet, sizeof(unmet), "%llu surface pairs no sight ray met (F = 0, within %.1e), ",
                 (unsigned long long)report.unmet_pairs, report.unmet_bound);
        snprintf(sight, sizeof(sight), " (and %llu sight rays)",
                 (unsigned long long)report.sight_rays_cast);
    }
    exit_code = cli_finish(&stats, stats_path,
                           "%zu surfaces, %s%llu polygon pairs (%llu unobstructed exact, "
                           "%llu obstructed exact (%llu on a second try), %llu sampled of which "
                           "%llu saw nothing, "
                           "%llu proven hidden), %llu rays%s, %llu non-zero factors, %.2f s: "
                           "wrote %s",
                           S, unmet, (unsigned long long)report.polygon_pairs,
                           (unsigned long long)report.unobstructed_pairs,
                           (unsigned long long)report.exact_pairs,
                           (unsigned long long)report.roomy_pairs,
                           (unsigned long long)report.sampled_pairs,
                           (unsigned long long)report.unseen_pairs,
                           (unsigned long long)report.hidden_pairs,
                           (unsigned long long)report.rays, sight,
                           (unsigned long long)report.nonzeros,
                           seconds, output ? output : "standard output");
    goto done;
fail:
    exit_code = cli_ranks_failed(&error);
done:
    rad_convergence_free(&plot.history);
    free(sky);
    free(emissivity);
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return cli_ranks_end(exit_code);
}
