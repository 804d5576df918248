/*
 * cmd_raytrace.c - `radiosity raytrace`: Whitted ray tracing with the Phong model (being written).
 */
#include "cli.h"

int command_raytrace(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    cli_error("raytrace: not available yet");
    return EXIT_ERROR;
}
