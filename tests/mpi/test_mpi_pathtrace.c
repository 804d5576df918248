/*
 * test_mpi_pathtrace.c - `mpirun -np N radiosity pathtrace` for N = 1 to 4 writes the same
 * image and standard-error image, byte for byte, as the serial run: the built-in Cornell
 * box at 70 x 45 (partial tiles at the right and bottom edges), 8 samples per pixel; and
 * rank 0's summary accounts for every 16 x 16 tile once (5 x 3 = 15).
 */
#include <string.h>

#include "mpi_run.h"

int main(void)
{
    const char *options = "--size 70x45 --spp 8";
    char arguments[512];
    snprintf(arguments, sizeof(arguments),
             "pathtrace -o serial.pfm --standard-error serial-se.pfm --threads 2 %s", options);
    CHECK(test_run_tool(arguments) == 0);
    for (int ranks = 1; ranks <= 4; ranks++) {
        char image[32], error[32];
        snprintf(image, sizeof(image), "ranks%d.pfm", ranks);
        snprintf(error, sizeof(error), "ranks%d-se.pfm", ranks);
        snprintf(arguments, sizeof(arguments),
                 "pathtrace -o %s --standard-error %s --threads 1 %s", image, error, options);
        CHECK(test_run_mpi(ranks, arguments, 0, NULL) == 0);
        CHECK(test_same_bytes(test_path("serial.pfm"), test_path(image)));
        CHECK(test_same_bytes(test_path("serial-se.pfm"), test_path(error)));
        const char *err = test_read_text(test_path("stderr.txt"));
        long long tiles = ranks > 1 ? test_rank_work(err, ranks) : 0;
        CHECK(ranks == 1 || tiles == 15);
    }
    return test_finish("test_mpi_pathtrace");
}
