/*
 * radiosity.c - the command-line tool's entry point: picks the subcommand.
 */
#include <string.h>

#include "cli.h"

static const char usage[] =
    "usage: radiosity COMMAND [options]\n"
    "\n"
    "Diffuse global illumination by the radiosity method.\n"
    "\n"
    "commands:\n"
    "  render [SCENE] -o OUT     solve and render an image (.png, .hdr, .pfm, .exr); no\n"
    "                            SCENE renders the built-in Cornell box\n"
    "  solve [SCENE] -o OUT      solve and write the lit mesh (.ply, .glb, .obj: vertex\n"
    "                            radiance and colour) or a solution file for render\n"
    "  viewfactors SCENE         the surface-to-surface view-factor matrix as CSV\n"
    "  raytrace SCENE -o OUT     Whitted ray tracing with the Phong model\n"
    "  pathtrace SCENE -o OUT    a Monte-Carlo path tracer: the reference for radiosity\n"
    "  illuminance [SCENE] --plane H -o OUT.csv  illuminance (lux) on a work plane, or\n"
    "                            at --points FILE: E_min, E_avg, E_max, uniformity\n"
    "  compare A B [-o DIFF]     differences between two HDR images (.pfm, .hdr, .exr)\n"
    "  info [SCENE]              what was read: surfaces, materials, emitters, camera\n"
    "  view [SCENE|LIT.glb]      an HTML page showing the lit mesh in a browser (a build\n"
    "                            with -DRAD_VIEWER=ON)\n"
    "  plot RECORD.json...       the recorded solves' convergence on one plot (SVG)\n"
    "  help [COMMAND]            this text, or a command's\n"
    "\n"
    "'radiosity COMMAND --help' tells a command's options.\n";

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
} command;

static const command commands[] = {
    {"render", command_render},     {"solve", command_solve},
    {"viewfactors", command_viewfactors},
    {"raytrace", command_raytrace}, {"pathtrace", command_pathtrace},
    {"compare", command_compare},   {"info", command_info},
    {"illuminance", command_illuminance}, {"view", command_view},
    {"plot", command_plot},
};

static const command *find_command(const char *name)
{
    for (size_t k = 0; k < sizeof(commands) / sizeof(commands[0]); k++)
        if (strcmp(commands[k].name, name) == 0)
            return &commands[k];
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(usage, stderr);
        return EXIT_USAGE;
    }
    const char *name = argv[1];
    const command *found = find_command(name);
    if (found)
        return found->run(argc - 2, argv + 2);
    if (strcmp(name, "help") == 0 || strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0) {
        found = argc > 2 && strcmp(name, "help") == 0 ? find_command(argv[2]) : NULL;
        if (found) {
            char help[] = "--help";
            char *help_argv[] = {help};
            return found->run(1, help_argv);
        }
        fputs(usage, stdout);
        return EXIT_OK;
    }
    cli_error("unknown command '%s' (see 'radiosity --help')", name);
    return EXIT_USAGE;
}
