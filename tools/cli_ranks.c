/*
 * cli_ranks.c - the tool's side of a run over MPI ranks (cli_ranks.h): agreement on
 * failure, the per-rank summary. It does not share work (the library does) and never
 * calls MPI itself (the rad_ranks_* functions of radiosity.h do).
 */
#include <stdlib.h>

#include "cli_ranks.h"

int cli_ranks_begin(void) { return rad_ranks_begin(); }

bool cli_ranks_ok(rad_status status, const rad_error *error)
{
    int failures = rad_ranks_failures(status != RAD_OK);
    if (failures == 0)
        return true;
    if (failures == rad_rank_count())
        return false;
    if (status != RAD_OK) {
        cli_error("rank %d of %d: %s", rad_rank(), rad_rank_count(), error->message);
        rad_ranks_abort(EXIT_ERROR);
    }
    rad_ranks_end(); /* MPI_Abort of the failed rank ends this one here or in there */
    exit(EXIT_ERROR);
}

int cli_ranks_failed(const rad_error *error)
{
    return rad_rank() == 0 ? cli_failed(error) : EXIT_ERROR;
}

static void megabytes(char *text, size_t size, uint64_t bytes)
{
    snprintf(text, size, "%.1f MB", (double)bytes / 1e6);
}

bool cli_ranks_summary(const rad_rank_report *mine, const char *unit, double *imbalance,
                       rad_error *error)
{
    int count = rad_rank_count();
    *imbalance = 1;
    if (count == 1)
        return true;
    rad_rank_report *all = rad_alloc_array((size_t)count, sizeof(*all));
    bool ok = all != NULL;
    if (cli_ranks_ok(ok ? RAD_OK : RAD_ERR_NOMEM, error) && ok) {
        rad_rank_report report = *mine;
        report.peak_memory = rad_peak_memory_bytes();
        report.bytes_communicated = rad_ranks_bytes_communicated();
        ok = rad_ranks_gather_reports(&report, all, error) == RAD_OK;
    } else {
        ok = false;
    }
    if (ok && rad_rank() == 0) {
        double total = 0, slowest = 0;
        for (int r = 0; r < count; r++) {
            char peak[32], sent[32];
            megabytes(peak, sizeof(peak), all[r].peak_memory);
            megabytes(sent, sizeof(sent), all[r].bytes_communicated);
            cli_summary("rank %d of %d: %llu %s, %.2f s, peak memory %s, communicated %s", r,
                        count, (unsigned long long)all[r].work, unit, all[r].seconds, peak,
                        sent);
            total += all[r].seconds;
            slowest = all[r].seconds > slowest ? all[r].seconds : slowest;
        }
        *imbalance = total > 0 ? slowest / (total / count) : 1;
        cli_summary("%d ranks: load imbalance %.3f (the slowest rank's time over the mean)",
                    count, *imbalance);
    }
    free(all);
    return ok;
}

void cli_ranks_solve_quiet(cli_solve *solve)
{
    if (rad_rank() == 0)
        return;
    solve->options.progress = NULL;
    solve->options.log = NULL;
    solve->save_solution_path = NULL;
}

/* Collective: rank 0 prints every rank's peak link-store bytes on one line. */
static bool link_store_summary(uint64_t bytes, rad_error *error)
{
    int count = rad_rank_count();
    rad_rank_report *all = rad_alloc_array((size_t)count, sizeof(*all));
    bool ok = all != NULL;
    if (!cli_ranks_ok(ok ? RAD_OK : RAD_ERR_NOMEM, error) || !ok) {
        free(all);
        return false;
    }
    rad_rank_report mine = {bytes, 0, 0, 0};
    ok = rad_ranks_gather_reports(&mine, all, error) == RAD_OK;
    if (ok && rad_rank() == 0) {
        char line[4096];
        size_t at = 0;
        for (int r = 0; r < count && at < sizeof(line); r++)
            at += (size_t)snprintf(line + at, sizeof(line) - at, "%s%.1f", r ? ", " : "",
                                   (double)all[r].work / 1e6);
        cli_summary("link store per rank (peak, MB, rank 0 first): %s", line);
    }
    free(all);
    return ok;
}

bool cli_ranks_solve_summary(const cli_solved *solved, double *imbalance, rad_error *error)
{
    const rad_scene_solve_report *r = &solved->report;
    bool dense = !solved->from_file && r->solver != RAD_SOLVER_HIERARCHICAL;
    if (solved->from_file || dense) {
        rad_rank_report mine = {dense ? r->formfactors.rank_rows : 0,
                                dense ? r->formfactors.rank_seconds + r->seconds_solve
                                      : r->seconds_solve,
                                0, 0};
        return cli_ranks_summary(&mine, "form-factor rows", imbalance, error);
    }
    const rad_hierarchy_report *h = &r->hierarchy;
    if (rad_rank_count() > 1 && rad_rank() == 0)
        cli_summary("links: %llu in all; each rank holds its receivers' and the %llu received "
                    "above the cut into subtrees",
                    (unsigned long long)h->links, (unsigned long long)h->shared_links);
    rad_rank_report mine = {h->rank_links, h->rank_seconds, 0, 0};
    if (!cli_ranks_summary(&mine, "links held", imbalance, error))
        return false;
    return rad_rank_count() == 1 || link_store_summary(h->link_bytes, error);
}

int cli_ranks_end(int exit_code)
{
    rad_ranks_end();
    return exit_code;
}
