/*
 * test_solve_checkpoint.c - `solve --checkpoint` and `render --checkpoint` stopped part
 * way, then `--resume`, write the bytes of the uninterrupted run (one process;
 * tests/mpi/test_mpi_solve_checkpoint.c does it over ranks).
 *
 * The built-in Cornell box at a coarse patch size (411 patches). For each solver (gather,
 * gauss-seidel, shoot, hierarchical) the run is made once whole, then once with a
 * checkpoint at every step (--checkpoint-interval 0), which must not change a byte and
 * tells how many steps there are (N, --stats). Runs stopped after K checkpoints
 * (RADIOSITY_STOP_AFTER_CHECKPOINTS, which acts as SIGTERM at a known point, without
 * timing) must exit 130 and write neither the solution nor the lit mesh; resumed with
 * another thread count, they must write exactly the uninterrupted run's bytes. K = 3 is in
 * the dense solvers' form-factor rows (64 rounds), K = N - 1 in their iterate, K = N
 * during their last sweep (the direct solver: K = 63, during the last round of rows,
 * honoured before its LU); for the
 * hierarchical solver K runs from the first refinement passes through the checkpoint before
 * the final gather to those between the final gather's 16 rounds of leaves (15, the last
 * N - 14 .. N). `render` does the same for its .pfm. A real SIGINT (to the
 * hierarchical solver, which without --checkpoint would go on with the solution so far)
 * and a real SIGTERM stop with status 130 and a checkpoint that resumes the same way.
 * A checkpoint of another scene (--albedo), mesh (--patch-size), solver or options
 * (--seed, --tolerance), a damaged or truncated one and a file that is no checkpoint are
 * refused with one line naming the file, exit 1 and no output.
 */
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "testlib.h"

#define SCENE "--patch-size 100"

/* The hierarchical solver's checkpoints between the final gather's 16 rounds of leaves. */
#define FINAL_GATHER_CHECKPOINTS 15

/* stderr is one line that contains `path` and `what`. */
static void check_refusal(const char *what, const char *path)
{
    const char *err = test_read_text(test_path("stderr.txt"));
    const char *newline = strchr(err, '\n');
    CHECK(strstr(err, path) != NULL);
    CHECK(strstr(err, what) != NULL);
    CHECK(newline != NULL && newline[1] == 0);
    if (!strstr(err, what))
        fprintf(stderr, "expected '%s' in: %s", what, err);
}

/* The "checkpoints_written" of a --stats file; -1 when missing. */
static long checkpoints_written(const char *stats)
{
    const char *at = strstr(test_read_text(test_path(stats)), "\"checkpoints_written\":");
    return at ? strtol(at + strlen("\"checkpoints_written\":"), NULL, 10) : -1;
}

/* A run of `solver` stopped after k checkpoints, then resumed with one thread: status 130
 * and nothing written, then the bytes of full.sol and full.ply. */
static void stop_and_resume(const char *solver, long k)
{
    char arguments[512], count[32];
    remove(test_path("part.sol"));
    remove(test_path("part.ply"));
    remove(test_path("ck.bin"));
    snprintf(count, sizeof(count), "%ld", k);
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", count, 1);
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 2 --checkpoint ck.bin "
             "--checkpoint-interval 0 --save-solution part.sol -o part.ply",
             solver);
    int stopped = test_run_tool(arguments);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(stopped == 130);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--resume ck.bin") != NULL);
    CHECK(!test_file_exists(test_path("part.sol")));
    CHECK(!test_file_exists(test_path("part.ply")));
    CHECK(test_file_exists(test_path("ck.bin")));
    CHECK(test_count_files("ck.bin.tmp-") == 0);
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 1 --resume ck.bin --save-solution part.sol "
             "-o part.ply --stats part.json",
             solver);
    CHECK(test_run_tool(arguments) == 0);
    CHECK(strstr(test_read_text(test_path("part.json")), "\"resumed\": true") != NULL);
    bool same = test_same_bytes(test_path("full.sol"), test_path("part.sol")) &&
                test_same_bytes(test_path("full.ply"), test_path("part.ply"));
    CHECK(same);
    if (!same)
        fprintf(stderr, "%s stopped after %ld checkpoints: resumed to other bytes\n", solver,
                k);
}

/* A real signal once `k` checkpoints are written (the run waits there for it:
 * RADIOSITY_WAIT_AFTER_CHECKPOINTS): status 130, no output, and the checkpoint resumes to
 * full.sol. */
static void signal_and_resume(const char *solver, const char *signal_name, int k)
{
    char command[8192], arguments[512];
    remove(test_path("sig.bin"));
    snprintf(command, sizeof(command),
             "cd '%s' && RADIOSITY_WAIT_AFTER_CHECKPOINTS=%d sh -c \"exec '%s' solve --solver "
             "%s " SCENE " --threads 2 --checkpoint sig.bin --checkpoint-interval 0 "
             "--save-solution sig.sol & pid=\\$!; while [ ! -e sig.bin ]; do sleep 0.01; "
             "done; kill -%s \\$pid; wait \\$pid\" >'%s' 2>'%s' </dev/null",
             test_tmpdir(), k, RAD_TOOL, solver, signal_name, test_path("stdout.txt"),
             test_path("stderr.txt"));
    int status = system(command);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 130);
    CHECK(!test_file_exists(test_path("sig.sol")));
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --resume sig.bin --save-solution sig.sol --quiet",
             solver);
    CHECK(test_run_tool(arguments) == 0);
    CHECK(test_same_bytes(test_path("full.sol"), test_path("sig.sol")));
    remove(test_path("sig.sol"));
}

static void solver_checkpoints(const char *solver)
{
    char arguments[512];
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 2 --save-solution full.sol -o full.ply "
             "--quiet",
             solver);
    CHECK(test_run_tool(arguments) == 0);
    /* a checkpoint at every step changes nothing, and counts the steps */
    snprintf(arguments, sizeof(arguments),
             "solve --solver %s " SCENE " --threads 2 --checkpoint all.bin "
             "--checkpoint-interval 0 --save-solution all.sol --stats all.json --quiet",
             solver);
    CHECK(test_run_tool(arguments) == 0);
    CHECK(test_same_bytes(test_path("full.sol"), test_path("all.sol")));
    long n = checkpoints_written("all.json");
    bool hierarchical = strcmp(solver, "hierarchical") == 0;
    /* dense: 63 between the 64 rounds of rows, then one per sweep (shooting: n / 16 shots) */
    CHECK(hierarchical ? n > 10 + FINAL_GATHER_CHECKPOINTS : n > 66);
    if (n <= 10 + FINAL_GATHER_CHECKPOINTS)
        return;
    if (hierarchical) {
        long before_final = n - FINAL_GATHER_CHECKPOINTS;
        stop_and_resume(solver, 3);                /* the first passes */
        stop_and_resume(solver, before_final / 2);
        stop_and_resume(solver, before_final - 1); /* a sweep to the tolerance, the last */
        stop_and_resume(solver, before_final);     /* before the final gather */
        stop_and_resume(solver, before_final + 1); /* after its first round */
        stop_and_resume(solver, n - 7);            /* half way through it */
        stop_and_resume(solver, n);                /* before its last round */
    } else {
        stop_and_resume(solver, 3);     /* form-factor rows */
        stop_and_resume(solver, n - 1); /* the iterate */
        stop_and_resume(solver, n);     /* during the last sweep (shots): honoured after it */
    }
}

/* The direct solver checkpoints only between its 64 rounds of form-factor rows (63), none
 * in its LU: a stop in the rows, and one during the last round, which is honoured before
 * the LU (F alone is written; the resumed run factors it again). */
static void direct_checkpoints(void)
{
    CHECK(test_run_tool("solve --solver direct " SCENE " --threads 2 --save-solution full.sol "
                        "-o full.ply --quiet") == 0);
    CHECK(test_run_tool("solve --solver direct " SCENE " --threads 2 --checkpoint all.bin "
                        "--checkpoint-interval 0 --save-solution all.sol --stats all.json "
                        "--quiet") == 0);
    CHECK(test_same_bytes(test_path("full.sol"), test_path("all.sol")));
    long n = checkpoints_written("all.json");
    CHECK(n == 63);
    stop_and_resume("direct", 3);
    stop_and_resume("direct", n);
}

int main(void)
{
    const char *solvers[] = {"gather", "gauss-seidel", "shoot", "hierarchical"};
    direct_checkpoints();
    for (int s = 0; s < 4; s++)
        solver_checkpoints(solvers[s]);
    /* full.sol is the hierarchical solver's now */
    signal_and_resume("hierarchical", "INT", 3);
    CHECK(test_run_tool("solve --solver gather " SCENE " --save-solution full.sol --quiet") ==
          0);
    signal_and_resume("gather", "TERM", 70); /* in the iterate */

    /* render: the image of the resumed solve, bitwise */
    CHECK(test_run_tool("render --solver gather " SCENE " --size 48x48 -o full.pfm --quiet") ==
          0);
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "5", 1);
    CHECK(test_run_tool("render --solver gather " SCENE " --size 48x48 -o part.pfm "
                        "--checkpoint render.bin --checkpoint-interval 0") == 130);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(!test_file_exists(test_path("part.pfm")));
    CHECK(test_run_tool("render --solver gather " SCENE " --size 48x48 -o part.pfm "
                        "--resume render.bin --quiet") == 0);
    CHECK(test_same_bytes(test_path("full.pfm"), test_path("part.pfm")));

    /* refusals: one line naming the file, exit 1, no output (ck.bin: the hierarchical
     * solver's, all.bin: its every-step run's) */
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "3", 1);
    CHECK(test_run_tool("solve --solver gather " SCENE " --checkpoint dense.bin "
                        "--checkpoint-interval 0 --save-solution dense.sol") == 130);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(test_run_tool("solve --solver gather " SCENE " --albedo white=0.5,0.5,0.5 "
                        "--resume dense.bin -o other.ply") == 1);
    check_refusal("another scene or mesh", "dense.bin");
    CHECK(test_run_tool("solve --solver gather --patch-size 90 --resume dense.bin "
                        "-o other.ply") == 1);
    check_refusal("another scene or mesh", "dense.bin");
    CHECK(test_run_tool("solve --solver shoot " SCENE " --resume dense.bin -o other.ply") == 1);
    check_refusal("a checkpoint of the gather solver", "dense.bin");
    CHECK(test_run_tool("solve --solver gather " SCENE " --seed 7 --resume dense.bin "
                        "-o other.ply") == 1);
    check_refusal("other options: --seed 1 (this run: 7)", "dense.bin");
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --tolerance 1e-3 "
                        "--resume all.bin -o other.ply") == 1);
    check_refusal("other options: --tolerance", "all.bin");
    size_t size;
    uint8_t *bytes = test_read_bytes(test_path("ck.bin"), &size);
    CHECK(bytes && size > 100);
    if (bytes && size > 100) {
        FILE *f = fopen(test_path("damaged.bin"), "wb");
        bytes[size / 2] ^= 0x10; /* one bit of the state */
        CHECK(f && fwrite(bytes, 1, size, f) == size);
        if (f)
            fclose(f);
        f = fopen(test_path("short.bin"), "wb");
        CHECK(f && fwrite(bytes, 1, size - 5, f) == size - 5);
        if (f)
            fclose(f);
    }
    free(bytes);
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --resume damaged.bin "
                        "-o other.ply") == 1);
    check_refusal("corrupted", "damaged.bin");
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --resume short.bin "
                        "-o other.ply") == 1);
    check_refusal("checkpoint", "short.bin");
    CHECK(test_run_tool("solve --solver hierarchical " SCENE " --resume full.sol "
                        "-o other.ply") == 1);
    check_refusal("not a solve checkpoint", "full.sol");
    CHECK(test_run_tool("solve " SCENE " --resume missing.bin -o other.ply") == 1);
    check_refusal("cannot open", "missing.bin");
    CHECK(!test_file_exists(test_path("other.ply")));
    /* the refused runs left the checkpoint as it was: it still resumes */
    CHECK(test_run_tool("solve --solver gather " SCENE " --resume dense.bin "
                        "--save-solution again.sol --quiet") == 0);
    CHECK(test_same_bytes(test_path("full.sol"), test_path("again.sol")));

    CHECK(test_run_tool("solve " SCENE " -o x.ply --checkpoint-interval 5") == 2);
    CHECK(test_run_tool("solve " SCENE " -o x.ply --checkpoint c.bin --checkpoint-interval -1") ==
          2);
    CHECK(test_run_tool("solve " SCENE " --solution full.sol --resume dense.bin -o x.ply") ==
          2);
    return test_finish("test_solve_checkpoint");
}
