/*
 * cmd_pathtrace.c - `radiosity pathtrace`: the Monte-Carlo path tracer (being written).
 */
#include "cli.h"

int command_pathtrace(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    cli_error("pathtrace: not available yet");
    return EXIT_ERROR;
}
