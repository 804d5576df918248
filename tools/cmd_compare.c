/*
 * cmd_compare.c - `radiosity compare`: comparing two HDR images (being written).
 */
#include "cli.h"

int command_compare(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    cli_error("compare: not available yet");
    return EXIT_ERROR;
}
