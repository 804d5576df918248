/*
 * cli_checkpoint.c - what the commands that write checkpoints share (viewfactors, solve,
 * render): the stop flag that SIGINT and SIGTERM raise, and the progress wrapper that
 * counts the library's "checkpoint" reports for the tests' RADIOSITY_STOP_AFTER_CHECKPOINTS
 * and RADIOSITY_WAIT_AFTER_CHECKPOINTS. It does not write checkpoints (the library does).
 * See cli.h.
 */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"

/* SIGINT or SIGTERM with --checkpoint: stop at the next step. */
static volatile sig_atomic_t stop_requested;

static void on_stop_signal(int signal_number)
{
    stop_requested = 1;
    signal(signal_number, SIG_DFL); /* a second one ends the run at once */
}

static void progress_with_checkpoints(void *user, const char *phase, double fraction)
{
    cli_checkpoints *c = user;
    if (strcmp(phase, "checkpoint") != 0) {
        if (c->next)
            c->next(c->next_user, phase, fraction);
        return;
    }
    c->written++;
    if (c->stop_after > 0 && c->written >= c->stop_after)
        stop_requested = 1;
    if (c->wait_after > 0 && c->written == c->wait_after)
        for (int k = 0; k < 6000 && !stop_requested; k++)
            nanosleep(&(struct timespec){0, 10000000}, NULL);
}

const volatile int *cli_checkpoints_begin(cli_checkpoints *c, rad_progress_fn *progress,
                                          void **progress_user)
{
    memset(c, 0, sizeof(*c));
    const char *stop_after = getenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    if (stop_after)
        c->stop_after = strtol(stop_after, NULL, 10);
    const char *wait_after = getenv("RADIOSITY_WAIT_AFTER_CHECKPOINTS");
    if (wait_after)
        c->wait_after = strtol(wait_after, NULL, 10);
    c->next = *progress;
    c->next_user = *progress_user;
    if (rad_rank() == 0) { /* the library tells rank 0 alone of checkpoints */
        *progress = progress_with_checkpoints;
        *progress_user = c;
    }
    stop_requested = 0;
    c->previous_int = signal(SIGINT, on_stop_signal);
    c->previous_term = signal(SIGTERM, on_stop_signal);
    return (const volatile int *)&stop_requested;
}

void cli_checkpoints_end(cli_checkpoints *c)
{
    signal(SIGINT, c->previous_int == SIG_ERR ? SIG_DFL : c->previous_int);
    signal(SIGTERM, c->previous_term == SIG_ERR ? SIG_DFL : c->previous_term);
}

bool cli_parse_checkpoint_interval(const char *value, double *seconds)
{
    if (!cli_parse_double("checkpoint-interval", value, seconds))
        return false;
    if (!(*seconds >= 0 && *seconds <= 1e9)) {
        cli_error("--checkpoint-interval: must be between 0 and 1e9 seconds");
        return false;
    }
    return true;
}
