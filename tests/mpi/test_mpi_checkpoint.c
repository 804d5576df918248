/*
 * test_mpi_checkpoint.c - `mpirun -np N radiosity viewfactors --checkpoint` stopped part
 * way, then `--resume`, writes the bytes of the uninterrupted serial run: under 1 and 3
 * ranks, and across rank counts (a 3-rank checkpoint resumed by 2 ranks, then by a plain
 * serial run). The stop comes after a known number of checkpoints
 * (RADIOSITY_STOP_AFTER_CHECKPOINTS, which acts as SIGTERM there), so no timing is
 * involved. A real SIGTERM after the first checkpoint, to the serial tool and to mpirun,
 * stops the run with a checkpoint that resumes the same way. A refused checkpoint (another
 * --accuracy) under 3 ranks prints its one line once, naming the file, and writes nothing.
 */
#include <string.h>

#include "mpi_run.h"

/* the command's start: behind at most 4 occluders exactly, the rest sampled (the sampled
 * pairs' random numbers are what ranks must share; the default clips them all) */
#define VIEWFACTORS "viewfactors city.obj --exact-occluders 4"

/* The K of "FILE holds K of N rows" in the last run's stderr; -1 when missing. */
static long rows_held(const char *file)
{
    char key[128];
    snprintf(key, sizeof(key), "%s holds ", file);
    const char *at = strstr(test_read_text(test_path("stderr.txt")), key);
    return at ? strtol(at + strlen(key), NULL, 10) : -1;
}

static int count_lines_with(const char *text, const char *what)
{
    int count = 0;
    for (const char *at = text; (at = strstr(at, what)); at += strlen(what))
        count++;
    return count;
}

int main(void)
{
    test_write_city(300, "city.obj"); /* 384 surfaces */
    CHECK(test_run_tool(VIEWFACTORS " -o serial.mtx --threads 2") == 0);

    for (int ranks = 1; ranks <= 3; ranks += 2) {
        char arguments[256], name[32], checkpoint[32];
        snprintf(name, sizeof(name), "ranks%d.mtx", ranks);
        snprintf(checkpoint, sizeof(checkpoint), "ck%d.bin", ranks);
        setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "4", 1);
        snprintf(arguments, sizeof(arguments),
                 VIEWFACTORS " -o %s --threads 1 --checkpoint %s "
                 "--checkpoint-interval 0",
                 name, checkpoint);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) != 0);
        unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
        CHECK(!test_file_exists(test_path(name)));
        long held = rows_held(checkpoint);
        CHECK(held > 0 && held < 384);
        snprintf(arguments, sizeof(arguments), VIEWFACTORS " -o %s --threads 1 --resume %s",
                 name, checkpoint);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.mtx"), test_path(name)));
    }

    /* a 3-rank checkpoint, continued by 2 ranks (stopped again further on), then serially */
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "2", 1);
    CHECK(test_run_mpi(3, VIEWFACTORS " -o mixed.mtx --threads 1 --checkpoint mixed.bin "
                          "--checkpoint-interval 0",
                       0, NULL) != 0);
    long first = rows_held("mixed.bin");
    CHECK(test_run_mpi(2, VIEWFACTORS " -o mixed.mtx --threads 1 --resume mixed.bin "
                          "--checkpoint-interval 0",
                       0, NULL) != 0);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    long second = rows_held("mixed.bin");
    CHECK(first > 0 && second > first && second < 384);
    CHECK(!test_file_exists(test_path("mixed.mtx")));
    CHECK(test_run_tool(VIEWFACTORS " -o mixed.mtx --threads 2 --resume mixed.bin") == 0);
    CHECK(test_same_bytes(test_path("serial.mtx"), test_path("mixed.mtx")));

    /* a real SIGTERM once the first checkpoint exists (a 64th of the rows done; the run
     * waits there for it: RADIOSITY_WAIT_AFTER_CHECKPOINTS): to the serial tool, which
     * stops with status 130, and to mpirun, which passes it to its 3 ranks (mpirun
     * itself then ends non-zero); either checkpoint resumes to the serial matrix */
    for (int ranks = 0; ranks <= 3; ranks += 3) {
        char command[8000];
        snprintf(command, sizeof(command),
                 "cd '%s' && RADIOSITY_WAIT_AFTER_CHECKPOINTS=1 sh -c \"%s%s%s '%s' " VIEWFACTORS
                 " -o term.mtx --threads %d "
                 "--checkpoint term.bin --checkpoint-interval 0 & pid=\\$!; "
                 "while [ ! -e term.bin ]; do sleep 0.01; done; kill -TERM \\$pid; "
                 "wait \\$pid\" >'%s' 2>'%s' </dev/null",
                 test_tmpdir(), ranks ? RAD_MPIEXEC : "",
                 ranks ? " --oversubscribe --allow-run-as-root -np 3" : "", ranks ? "" : "exec",
                 RAD_TOOL, ranks ? 1 : 2, test_path("stdout.txt"), test_path("stderr.txt"));
        int status = system(command);
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == (ranks ? 1 : 130));
        long held = rows_held("term.bin");
        CHECK(held > 0 && held < 384);
        CHECK(!test_file_exists(test_path("term.mtx")));
        CHECK(test_run_tool(VIEWFACTORS " -o term.mtx --threads 2 --resume term.bin") ==
              0);
        CHECK(test_same_bytes(test_path("serial.mtx"), test_path("term.mtx")));
        remove(test_path("term.mtx"));
        remove(test_path("term.bin"));
    }

    /* another job's checkpoint: refused by every rank, said once, nothing written */
    CHECK(test_run_mpi(3, VIEWFACTORS " -o refused.mtx --resume ck3.bin --accuracy 3e-4",
                       0, NULL) == 1);
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(count_lines_with(err, "ck3.bin: a checkpoint made with other options") == 1);
    CHECK(!test_file_exists(test_path("refused.mtx")));
    return test_finish("test_mpi_checkpoint");
}
