/*
 * test_mpi_solve_checkpoint.c - `mpirun -np N radiosity solve --checkpoint` stopped part
 * way, then `--resume`, writes the solution file of the uninterrupted serial run, bitwise:
 * every solver under 2 and 3 ranks (the built-in Cornell box, 411 patches). The stop comes
 * after a known number of checkpoints (RADIOSITY_STOP_AFTER_CHECKPOINTS, which acts as
 * SIGTERM there), so no timing is involved: in the dense solvers' form-factor rows (each
 * rank's rows, gathered at rank 0) and in their iterate, and during the last sweep (the
 * direct solver: during its last round of rows, F written before its LU); in the
 * hierarchical solver's
 * refinement and between its final gather's rounds (each rank's links, and its leaves'
 * corrections, gathered at rank 0 and dealt out again on resuming). Across rank counts: a
 * 3-rank hierarchical checkpoint continued by 2 ranks (stopped again), then serially; one
 * in the final gather's rounds under 3 ranks resumed by 2; a 2-rank checkpoint of
 * form-factor rows resumed by 3 ranks. A refused checkpoint (another --seed) under 3 ranks prints its one line once,
 * naming the file, and writes nothing.
 */
#include <string.h>

#include "mpi_run.h"

#define SCENE "--patch-size 100"

static int count_lines_with(const char *text, const char *what)
{
    int count = 0;
    for (const char *at = text; (at = strstr(at, what)); at += strlen(what))
        count++;
    return count;
}

/* Under `ranks` ranks: stopped after k checkpoints (nothing written), then resumed under
 * `resume_ranks` (0: the plain serial tool) to the bytes of serial-SOLVER.sol. */
static void stop_and_resume(const char *solver, int ranks, long k, int resume_ranks)
{
    char arguments[512], count[32], reference[64];
    snprintf(reference, sizeof(reference), "serial-%s.sol", solver);
    remove(test_path("part.sol"));
    remove(test_path("ck.bin"));
    snprintf(count, sizeof(count), "%ld", k);
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", count, 1);
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 1 --checkpoint ck.bin "
             "--checkpoint-interval 0 --save-solution part.sol",
             solver);
    CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 130);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(count_lines_with(test_read_text(test_path("stderr.txt")), "--resume ck.bin") == 1);
    CHECK(!test_file_exists(test_path("part.sol")));
    CHECK(test_file_exists(test_path("ck.bin")));
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 1 --resume ck.bin --save-solution part.sol "
             "--quiet",
             solver);
    CHECK((resume_ranks ? test_run_mpi(resume_ranks, arguments, 0, NULL)
                        : test_run_tool(arguments)) == 0);
    bool same = test_same_bytes(test_path(reference), test_path("part.sol"));
    CHECK(same);
    if (!same)
        fprintf(stderr, "%s under %d ranks stopped after %ld, resumed under %d: other bytes\n",
                solver, ranks, k, resume_ranks);
}

int main(void)
{
    const char *solvers[] = {"gather", "gauss-seidel", "shoot", "hierarchical", "direct"};
    for (int s = 0; s < 5; s++) {
        char arguments[256];
        snprintf(arguments, sizeof(arguments),
                 "solve --solver %s " SCENE " --threads 2 --save-solution serial-%s.sol "
                 "--quiet",
                 solvers[s], solvers[s]);
        CHECK(test_run_tool(arguments) == 0);
    }
    /* the hierarchical solver's steps (one checkpoint each), counted serially */
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --checkpoint count.bin "
                        "--checkpoint-interval 0 --stats count.json --save-solution count.sol "
                        "--quiet") == 0);
    const char *at = strstr(test_read_text(test_path("count.json")), "\"checkpoints_written\":");
    long steps = at ? strtol(at + strlen("\"checkpoints_written\":"), NULL, 10) : 0;
    CHECK(steps > 10);
    /* the gather solver's: 63 between its rows' rounds, then one before each sweep */
    CHECK(test_run_tool("solve --solver gather " SCENE " --checkpoint count.bin "
                        "--checkpoint-interval 0 --stats count.json --save-solution count.sol "
                        "--quiet") == 0);
    at = strstr(test_read_text(test_path("count.json")), "\"checkpoints_written\":");
    long sweeps_steps = at ? strtol(at + strlen("\"checkpoints_written\":"), NULL, 10) : 0;
    CHECK(sweeps_steps > 66);

    /* dense: 63 checkpoints between the 64 rounds of each rank's rows, then the iterate;
     * hierarchical: its refinement, and the last of those between the final gather's 16
     * rounds (15, the last `steps`) */
    stop_and_resume("gather", 2, 3, 2);
    stop_and_resume("gauss-seidel", 2, 66, 2);
    stop_and_resume("hierarchical", 2, 3, 2);
    stop_and_resume("gather", 3, 66, 3);
    stop_and_resume("shoot", 3, 70, 3);
    stop_and_resume("hierarchical", 3, steps, 3);
    /* a stop during the last sweep, honoured after it; the direct solver's during its
     * rows' last round, honoured before its LU (F alone in the checkpoint) */
    stop_and_resume("gather", 2, sweeps_steps, 2);
    stop_and_resume("direct", 2, 63, 3);

    /* across rank counts */
    stop_and_resume("gather", 2, 5, 3);
    stop_and_resume("hierarchical", 3, steps - 7, 2); /* half way through the final gather */
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "4", 1);
    CHECK(test_run_mpi(3, "solve --solver hierarchical " SCENE " --threads 1 --checkpoint "
                          "mixed.bin --checkpoint-interval 0 --save-solution mixed.sol",
                       0, NULL) == 130);
    CHECK(test_run_mpi(2, "solve --solver hierarchical " SCENE " --threads 1 --resume "
                          "mixed.bin --checkpoint-interval 0 --save-solution mixed.sol",
                       0, NULL) == 130);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(!test_file_exists(test_path("mixed.sol")));
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --resume mixed.bin "
                        "--save-solution mixed.sol --quiet") == 0);
    CHECK(test_same_bytes(test_path("serial-hierarchical.sol"), test_path("mixed.sol")));

    /* another job's checkpoint: refused by every rank, said once, nothing written */
    CHECK(test_run_mpi(3, "solve --solver hierarchical " SCENE " --seed 9 --resume mixed.bin "
                          "--save-solution refused.sol",
                       0, NULL) == 1);
    CHECK(count_lines_with(test_read_text(test_path("stderr.txt")),
                           "mixed.bin: a checkpoint made with other options") == 1);
    CHECK(!test_file_exists(test_path("refused.sol")));
    return test_finish("test_mpi_solve_checkpoint");
}
