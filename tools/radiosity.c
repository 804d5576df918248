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
    "  render [SCENE] -o OUT     solve and render an image (.png, .hdr, .pfm); no SCENE\n"
    "                            renders the built-in Cornell box\n"
    "  viewfactors SCENE         the surface-to-surface view-factor matrix as CSV\n"
    "  help [COMMAND]            this text, or a command's\n"
    "\n"
    "'radiosity COMMAND --help' tells a command's options.\n";

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(usage, stderr);
        return EXIT_USAGE;
    }
    const char *command = argv[1];
    if (strcmp(command, "render") == 0)
        return command_render(argc - 2, argv + 2);
    if (strcmp(command, "viewfactors") == 0)
        return command_viewfactors(argc - 2, argv + 2);
    if (strcmp(command, "help") == 0 || strcmp(command, "--help") == 0 ||
        strcmp(command, "-h") == 0) {
        if (argc > 2 && strcmp(command, "help") == 0) {
            char help[] = "--help";
            char *help_argv[] = {help};
            if (strcmp(argv[2], "render") == 0)
                return command_render(1, help_argv);
            if (strcmp(argv[2], "viewfactors") == 0)
                return command_viewfactors(1, help_argv);
        }
        fputs(usage, stdout);
        return EXIT_OK;
    }
    cli_error("unknown command '%s' (see 'radiosity --help')", command);
    return EXIT_USAGE;
}
