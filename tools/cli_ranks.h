/*
 * cli_ranks.h - the tool's side of a run over MPI ranks (`mpirun -np N radiosity ...`):
 * join the job, let the ranks agree on a failure before a collective step, print the
 * per-rank summary on rank 0, leave the job. Outside a job (or in a build without MPI) each
 * of these is what a serial run does. The work itself is shared by the library.
 */
#ifndef RAD_TOOLS_CLI_RANKS_H
#define RAD_TOOLS_CLI_RANKS_H

#include <stdbool.h>

#include "cli.h"

/* Joins the job when launched by mpirun or srun; returns the rank count. */
int cli_ranks_begin(void);

/* Collective: true when status is RAD_OK on every rank. When every rank failed, returns
 * false (the caller reports `error` on rank 0 only: see cli_ranks_failed). When only some
 * failed, does not return: those print their error naming their rank and end the job
 * (MPI_Abort), the others leave it and exit with EXIT_ERROR. */
bool cli_ranks_ok(rad_status status, const rad_error *error);

/* The exit code of a failed run: rank 0 prints the error (cli_failed); the other ranks,
 * which failed the same way, stay silent. */
int cli_ranks_failed(const rad_error *error);

/* Collective: gathers every rank's report (its work and seconds; the peak memory and bytes
 * communicated are filled here); rank 0 prints one summary line per rank and the load
 * imbalance, the slowest rank's time over the mean (*imbalance: 1 with one rank, and on
 * the other ranks). Nothing with one rank. `unit` names the work ("rows"). False (error
 * filled) when out of memory. */
bool cli_ranks_summary(const rad_rank_report *mine, const char *unit, double *imbalance,
                       rad_error *error);

/* `solve` and `render` over ranks: ranks other than 0 show no progress and no warnings
 * and do not write --save-solution (rank 0 does). Call after cli_ranks_begin. */
void cli_ranks_solve_quiet(cli_solve *solve);

/* Collective, after cli_solve_scene: the per-rank summary of the solve (cli_ranks_summary
 * with the dense form-factor rows each rank computed, and its time on them plus the
 * solve's; hierarchical: the links each rank held at the end and its solve time less its
 * waiting, and on rank 0 a line with the links in all and those every rank holds). */
bool cli_ranks_solve_summary(const cli_solved *solved, double *imbalance, rad_error *error);

/* Leaves the job; returns exit_code. */
int cli_ranks_end(int exit_code);

#endif
