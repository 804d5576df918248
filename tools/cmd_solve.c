/*
 * cmd_solve.c - `radiosity solve [SCENE] -o OUT [options]`: the radiosity solution as a
 * lit mesh (.ply, .glb, .obj) other tools can show from any side, and/or a solution file
 * for `render --solution`.
 */
#include <string.h>
#include <strings.h>

#include "cli.h"
#include "cli_ranks.h"

static const char usage[] =
    "usage: radiosity solve [SCENE] [-o OUT] [--save-solution FILE] [options]\n"
    "\n"
    "Solves the radiosity of SCENE (an OBJ+MTL or any file Assimp reads; none = the\n"
    "built-in Cornell box) and writes the lit mesh to OUT, view-independent: every vertex\n"
    "has its linear radiance (what `render` shows there), its illuminance, direct and\n"
    "interreflected (lux with lights in candela and lux), and a display colour (radiance\n"
    "times the exposure, clamped to [0,1], sRGB; automatic: the 95th percentile of the\n"
    "lit vertices' luminance to 0.9). Creases stay sharp. OUT's extension picks the format:\n"
    "  .ply  binary PLY: float nx ny nz, uchar red green blue (sRGB), float radiance_r\n"
    "        radiance_g radiance_b (linear), float illuminance_r illuminance_g illuminance_b\n"
    "  .glb  binary glTF 2.0: COLOR_0 (linear), _RADIANCE, _ILLUMINANCE,\n"
    "        NORMAL, an unlit material\n"
    "  .obj  'v x y z r g b' (sRGB), then per vertex '#radiance R G B' and\n"
    "        '#illuminance R G B' comment lines (linear)\n"
    "\n"
    "  -o, --output FILE    the lit mesh (.ply, .glb or .obj)\n"
    "  --exposure EV        display colour: radiance times 2^EV (default: automatic)\n"
    "  --direct MODE        vertex (default): the light computed at each vertex, as\n"
    "                       `render` does (about 2600 rays a vertex); solution: the\n"
    "                       patches' mean radiosity (always, with no emitter or light)\n"
    CLI_TWO_SIDED_HELP
    CLI_SOLVE_HELP;

enum { OPT_TWO_SIDED = OPT_OWN, OPT_DIRECT, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_FORMFACTOR_OPTIONS,
    CLI_SOLVE_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_EXPOSURE] = {"exposure", 0, true},
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
    [OPT_DIRECT] = {"direct", 0, true},
};

static bool mesh_output_ok(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (dot && (strcasecmp(dot, ".ply") == 0 || strcasecmp(dot, ".glb") == 0 ||
                strcasecmp(dot, ".obj") == 0))
        return true;
    cli_error("%s: unknown mesh format (use .ply, .glb or .obj)", path);
    return false;
}

int command_solve(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    cli_solve solve;
    rad_lit_mesh_options write = {0};
    const char *scene_path = NULL;
    int exit_code;
    if (!cli_begin("solve", usage, argc, argv, options, OPT_COUNT, &args, &shared, &exit_code))
        return exit_code;
    if (args.value[OPT_EXPOSURE]) {
        if (!cli_parse_double("exposure", args.value[OPT_EXPOSURE], &write.exposure))
            return EXIT_USAGE;
        write.fixed_exposure = true;
    }
    const char *direct = args.value[OPT_DIRECT];
    if (direct && strcmp(direct, "vertex") != 0 && strcmp(direct, "solution") != 0) {
        cli_error("--direct: '%s' is not vertex or solution (pixel is render's)", direct);
        return EXIT_USAGE;
    }
    write.direct_light = direct && strcmp(direct, "solution") == 0 ? RAD_DIRECT_SOLUTION
                                                                    : RAD_DIRECT_VERTEX;
    if (!cli_scene_argument("solve", &args, &scene_path))
        return EXIT_USAGE;
    if (!shared.output && !args.value[OPT_SAVE_SOLUTION]) {
        cli_error("solve: nothing to write: give -o OUT.ply, .glb or .obj, or "
                  "--save-solution FILE");
        return EXIT_USAGE;
    }
    if (shared.output && !mesh_output_ok(shared.output))
        return EXIT_USAGE;
    if (!cli_parse_solve(&args, &shared, &solve))
        return EXIT_USAGE;
    solve.light_at_vertices = shared.output && write.direct_light == RAD_DIRECT_VERTEX;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &solve.two_sided);
    if (!cli_solve_outputs_writable(&shared, &solve))
        return EXIT_ERROR;

    rad_error error = {0};
    cli_solved solved;
    double t0 = rad_clock_seconds();
    cli_ranks_begin(); /* under mpirun: the ranks share the form factors and sweeps */
    cli_ranks_solve_quiet(&solve);
    rad_status status = cli_solve_scene(scene_path, &shared, &solve, &solved, &error);
    double t_solved = rad_clock_seconds(), imbalance = 1;
    if (!cli_ranks_ok(status, &error) ||
        !cli_ranks_solve_summary(&solved, &imbalance, &error)) {
        exit_code = cli_ranks_failed(&error);
        goto done;
    }
    if (solved.checkpoint_stop) { /* the checkpoint holds it: no output */
        exit_code = cli_checkpoint_stop("solve", &solve);
        goto done;
    }
    if (rad_rank() != 0) { /* rank 0 writes */
        exit_code = EXIT_OK;
        goto done;
    }
    if (status == RAD_OK && shared.output) {
        write.inputs = solved.inputs; /* the vertices' illuminance */
        write.scene = solved.scene;   /* the light at the vertices */
        write.seed = shared.seed;
        write.threads = shared.threads;
        status = rad_lit_mesh_write(solved.mesh, solved.B, shared.output, &write, &error);
    }
    double t_write = rad_clock_seconds();
    if (status != RAD_OK) {
        exit_code = cli_failed(&error);
        goto done;
    }
    cli_stats stats;
    stats_begin(&stats);
    cli_solved_stats(&solved, &solve, &stats);
    stats_integer(&stats, "vertices", solved.mesh->vertex_count);
    if (rad_rank_count() > 1) {
        stats_integer(&stats, "ranks", (unsigned long long)rad_rank_count());
        stats_number(&stats, "load_imbalance", imbalance);
    }
    stats_number(&stats, "seconds_write", t_write - t_solved);
    stats_number(&stats, "seconds_total", t_write - t0);
    char summary[384];
    cli_solved_summary(&solved, &solve, summary, sizeof(summary));
    exit_code = cli_finish(&stats, shared.stats_path, "%s, %.2f s: wrote %s", summary,
                           t_write - t0, shared.output ? shared.output : solve.save_solution_path);
    if (exit_code == EXIT_OK && solved.report.interrupted)
        exit_code = EXIT_INTERRUPTED; /* the files are complete, of the solution so far */
done:
    cli_progress_end();
    cli_solved_free(&solved);
    return cli_ranks_end(exit_code);
}
