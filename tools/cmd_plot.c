/*
 * cmd_plot.c - `radiosity plot RECORD.json... -o PLOT.svg`: the convergence of several
 * recorded solves (`solve --record`, `render --record`) on the same axes, one curve of
 * relative residual per run, named by its solver: the solvers compared.
 *
 * Reads the records' step numbers, not their radiosity; draws with
 * rad_convergence_plot_compare. Not the plot of one run (`--plot` on solve, render and
 * viewfactors) and not the record writer (src/solution/solve_record.c).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity plot RECORD.json... -o PLOT.svg [options]\n"
    "\n"
    "Draws the relative residual of each recorded solve (written by `radiosity solve\n"
    "--record` or `render --record`) against the iterations and against the solver's time,\n"
    "one curve per record, named by its solver (and its file when two share a solver), on\n"
    "log axes in one standalone SVG: the solvers compared on one scene. Up to 16 records.\n"
    "\n"
    "  -o, --output FILE    the plot (required; a name ending in .svg), written atomically\n"
    "  --title TEXT         the plot's title (default: 'convergence: ' and the first\n"
    "                       record's scene)\n"
    CLI_QUIET_HELP;

enum { OPT_TITLE = OPT_OWN, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    [OPT_TITLE] = {"title", 0, true},
};

#define MAX_RECORDS 16

/* A record's steps into *history and its solver's name into solver; false after one line
 * naming the file. */
static bool read_record(const char *path, rad_convergence *history, char *solver,
                        size_t solver_size, char *scene, size_t scene_size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        cli_error("%s: cannot open: %s", path, strerror(errno));
        return false;
    }
    char *text = NULL;
    size_t length = 0, capacity = 0;
    bool ok = true;
    for (;;) {
        if (length + 65536 + 1 > capacity) {
            size_t grown = capacity ? 2 * capacity : 1 << 20;
            char *bigger = rad_resize_array(text, grown, 1);
            if (!bigger) {
                cli_error("%s: out of memory", path);
                ok = false;
                break;
            }
            text = bigger;
            capacity = grown;
        }
        size_t got = fread(text + length, 1, capacity - length - 1, f);
        length += got;
        if (got == 0)
            break;
    }
    if (ok && ferror(f)) {
        cli_error("%s: read failed", path);
        ok = false;
    }
    fclose(f);
    cJSON *root = ok ? cJSON_ParseWithLength(text, length) : NULL;
    free(text);
    if (!ok)
        return false;
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(root, "format");
    const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(root, "snapshots");
    if (!cJSON_IsString(format) || strcmp(format->valuestring, "radiosity-record") != 0 ||
        !cJSON_IsArray(snapshots)) {
        cli_error("%s: not a record of `radiosity solve --record`", path);
        cJSON_Delete(root);
        return false;
    }
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "solver");
    const cJSON *where = cJSON_GetObjectItemCaseSensitive(root, "scene");
    snprintf(solver, solver_size, "%s", cJSON_IsString(name) ? name->valuestring : "?");
    snprintf(scene, scene_size, "%s", cJSON_IsString(where) ? where->valuestring : "");
    int index = 0;
    const cJSON *snapshot;
    cJSON_ArrayForEach(snapshot, snapshots)
    {
        index++;
        const cJSON *step = cJSON_GetObjectItemCaseSensitive(snapshot, "step");
        const cJSON *seconds = cJSON_GetObjectItemCaseSensitive(snapshot, "seconds");
        const cJSON *residual = cJSON_GetObjectItemCaseSensitive(snapshot, "residual");
        const cJSON *criterion = cJSON_GetObjectItemCaseSensitive(snapshot, "criterion");
        if (!cJSON_IsNumber(step) || !(step->valuedouble >= 0) ||
            step->valuedouble > UINT32_MAX || (!cJSON_IsNumber(seconds) && !cJSON_IsNull(seconds)) ||
            (!cJSON_IsNumber(residual) && !cJSON_IsNull(residual))) {
            cli_error("%s: snapshot %d has no step number, or seconds or residual that are "
                      "not numbers",
                      path, index);
            cJSON_Delete(root);
            return false;
        }
        rad_solve_step s = {0};
        s.step = (uint32_t)step->valuedouble;
        s.seconds = cJSON_IsNumber(seconds) ? seconds->valuedouble : NAN;
        s.residual = cJSON_IsNumber(residual) ? residual->valuedouble : NAN;
        s.criterion = cJSON_IsNumber(criterion) ? criterion->valuedouble : NAN;
        s.unshot = NAN;
        rad_error error = {0};
        if (rad_convergence_add(history, &s, &error) != RAD_OK) {
            cli_error("%s: %s", path, error.message);
            cJSON_Delete(root);
            return false;
        }
    }
    cJSON_Delete(root);
    if (history->count == 0) {
        cli_error("%s: the record has no snapshots", path);
        return false;
    }
    return true;
}

int command_plot(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    int exit_code;
    if (!cli_begin("plot", usage, argc, argv, options, OPT_COUNT, &args, &shared, &exit_code))
        return exit_code;
    const char *output = shared.output;
    if (args.positional_count < 1 || args.positional_count > MAX_RECORDS || !output) {
        cli_error("plot: give 1 to %d records and -o PLOT.svg (see 'radiosity plot --help')",
                  MAX_RECORDS);
        return EXIT_USAGE;
    }
    if (!cli_convergence_paths_ok(output, NULL))
        return EXIT_USAGE;
    if (!cli_outputs_writable((const char *[]){output}, 1))
        return EXIT_ERROR;
    size_t runs = (size_t)args.positional_count;
    rad_convergence histories[MAX_RECORDS] = {{0}};
    char solver[MAX_RECORDS][64], label[MAX_RECORDS][320], scene[512] = "";
    const char *names[MAX_RECORDS];
    exit_code = EXIT_ERROR;
    for (size_t r = 0; r < runs; r++) {
        char this_scene[512];
        if (!read_record(args.positional[r], &histories[r], solver[r], sizeof(solver[r]),
                         this_scene, sizeof(this_scene)))
            goto done;
        if (r == 0)
            snprintf(scene, sizeof(scene), "%s", this_scene);
    }
    for (size_t r = 0; r < runs; r++) {
        bool shared_name = false;
        for (size_t k = 0; k < runs; k++)
            shared_name = shared_name || (k != r && strcmp(solver[k], solver[r]) == 0);
        if (shared_name)
            snprintf(label[r], sizeof(label[r]), "%s (%s)", solver[r], args.positional[r]);
        else
            snprintf(label[r], sizeof(label[r]), "%s", solver[r]);
        names[r] = label[r];
    }
    char title[600];
    snprintf(title, sizeof(title), "convergence: %s", scene[0] ? scene : "(no scene named)");
    rad_convergence_plot_options plot = {
        .title = args.value[OPT_TITLE] ? args.value[OPT_TITLE] : title,
        .step_label = "iterations (sweeps, shots or passes)",
        .residual = true,
        .y_label = "relative residual, to the emitted power sum A |E| (1)"};
    rad_error error = {0};
    if (rad_convergence_plot_compare(histories, names, runs, output, &plot, &error) != RAD_OK) {
        cli_error("%s", error.message);
        goto done;
    }
    cli_summary("%zu records: wrote %s", runs, output);
    exit_code = EXIT_OK;
done:
    for (size_t r = 0; r < runs; r++)
        rad_convergence_free(&histories[r]);
    return exit_code;
}
