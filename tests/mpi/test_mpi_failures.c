/*
 * test_mpi_failures.c - a rank that fails ends the whole job: non-zero exit, a clear
 * message, no output file. Rank 1 reads a malformed scene while rank 0 reads a good one
 * (mpirun's "A : B" form makes that deterministic): rank 1's message names itself, the
 * file and the line. Rank 1 killed (SIGKILL) a moment after its start, while rank 0 works:
 * mpirun reports the signal. Rank 1 killed mid-run after the first checkpoint of a
 * checkpointed run: non-zero, no output, and the checkpoint resumes to the serial matrix.
 * Every rank reading the same bad file: one message (rank 0's), exit 1.
 */
#include <string.h>

#include "mpi_run.h"

/* the city behind at most 4 occluders exactly (the default clips every pair: about 8 times
 * longer) */
#define VIEWFACTORS "viewfactors city.obj --exact-occluders 4"

int main(void)
{
    test_write_city(1000, "city.obj");
    test_write_file("bad.obj", "o wall\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");

    /* bad input on rank 1 only */
    char other[4200];
    snprintf(other, sizeof(other), "'%s' viewfactors bad.obj -o out.mtx", RAD_TOOL);
    CHECK(test_run_mpi(1, VIEWFACTORS " -o out.mtx", 1, other) != 0);
    const char *err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "radiosity: rank 1 of 2: bad.obj:5: ") != NULL);
    CHECK(!test_file_exists(test_path("out.mtx")));
    CHECK(test_count_files("out") == 0);

    /* the same bad input on every rank: one message, from rank 0 */
    CHECK(test_run_mpi(3, "viewfactors bad.obj -o out.mtx", 0, NULL) == 1);
    err = test_read_text(test_path("stderr.txt"));
    const char *message = "radiosity: bad.obj:5: ";
    const char *first = strstr(err, message);
    CHECK(first != NULL);
    CHECK(first && strstr(first + strlen(message), "bad.obj:5") == NULL);
    CHECK(strstr(err, "rank 1 of") == NULL);
    CHECK(!test_file_exists(test_path("out.mtx")));

    /* rank 1 killed early in a run that takes seconds: the city's 1014 surfaces, one
     * thread per rank */
    snprintf(other, sizeof(other), "timeout -s KILL 0.5 '%s' " VIEWFACTORS " -o out.mtx "
             "--threads 1", RAD_TOOL);
    CHECK(test_run_mpi(1, VIEWFACTORS " -o out.mtx --threads 1", 1, other) != 0);
    err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "signal 9") != NULL);
    CHECK(!test_file_exists(test_path("out.mtx")));
    CHECK(test_count_files("out") == 0);

    /* rank 1 killed mid-run at a known point: its shell waits for the job's first
     * checkpoint (a 64th of the rows done and gathered; the rest takes seconds), then
     * kills it. The job ends non-zero, mpirun names the rank and its status (128 + 9), no
     * output is written, and the checkpoint left behind resumes to the serial matrix. */
    const char *checkpointed = VIEWFACTORS " -o out.mtx --threads 1 --checkpoint "
                               "ck.bin --checkpoint-interval 0";
    snprintf(other, sizeof(other),
             "sh -c \"'%s' %s & pid=\\$!; while [ ! -e ck.bin ]; do sleep 0.01; done; "
             "kill -KILL \\$pid; wait \\$pid\"",
             RAD_TOOL, checkpointed);
    CHECK(test_run_mpi(1, checkpointed, 1, other) != 0);
    err = test_read_text(test_path("stderr.txt"));
    CHECK(strstr(err, "Process name: [[") != NULL && strstr(err, "],1]") != NULL);
    CHECK(strstr(err, "Exit code:    137") != NULL);
    CHECK(!test_file_exists(test_path("out.mtx")));
    CHECK(test_count_files("out") == 0);
    CHECK(test_count_files("ck.bin.tmp-") == 0);
    CHECK(test_run_tool(VIEWFACTORS " -o serial.mtx --threads 2 --quiet") == 0);
    CHECK(test_run_tool(VIEWFACTORS " -o resumed.mtx --threads 2 --resume ck.bin") == 0);
    const char *resumed = strstr(test_read_text(test_path("stderr.txt")), "resumed from ck.bin: ");
    CHECK(resumed != NULL);
    CHECK(resumed && strtol(resumed + strlen("resumed from ck.bin: "), NULL, 10) > 0);
    size_t a_size, b_size;
    uint8_t *a = test_read_bytes(test_path("serial.mtx"), &a_size);
    uint8_t *b = test_read_bytes(test_path("resumed.mtx"), &b_size);
    CHECK(a && b && a_size == b_size && a_size > 0 && memcmp(a, b, a_size) == 0);
    free(a);
    free(b);
    return test_finish("test_mpi_failures");
}
