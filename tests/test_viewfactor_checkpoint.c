/*
 * test_viewfactor_checkpoint.c - `viewfactors --checkpoint` then `--resume` (one process;
 * tests/mpi/test_mpi_checkpoint.c does it over ranks).
 *
 * A block of 4 x 4 boxes (each wall and roof its own surface, on ground tiles: rows
 * obstructed by the neighbouring boxes) is computed once whole. Then a checkpointed run is
 * stopped after its third checkpoint (RADIOSITY_STOP_AFTER_CHECKPOINTS, which acts as
 * SIGTERM at a known point, without timing): it must exit 130, write no output and leave
 * a checkpoint holding some but not all rows. Resumed with another thread count, it must
 * write exactly the bytes of the uninterrupted run. A checkpoint of another scene (one
 * vertex moved), of other options (--accuracy, --seed, --sight-rays, --exact-occluders), a
 * damaged one and a file that is no checkpoint are refused with one line naming the file, exit 1 and no output.
 * The runs clip behind at most 4 occluders, sampling the rest (the default clips them all,
 * ten times slower here: what is checked is the checkpoint, the same for both).
 */
#include <stdlib.h>
#include <string.h>

#include "core/bytes.h"
#include "core/hash.h"
#include "testlib.h"

/* the command's start: behind at most 4 occluders exactly, the rest sampled */
#define BLOCKS "viewfactors blocks.obj --exact-occluders 4"
#define MOVED "viewfactors moved.obj --exact-occluders 4"

/* 4 x 4 boxes of 2 x 2 x (2..5) on a 4-unit grid, each side its own OBJ object, and one
 * ground tile per box; `shift` moves the first box's first corner (another scene). */
static void write_blocks(const char *name, double shift)
{
    static char text[1 << 16];
    size_t at = 0;
    int vertices = 0;
    for (int bx = 0; bx < 4; bx++)
        for (int bz = 0; bz < 4; bz++) {
            double x0 = 4.0 * bx, z0 = 4.0 * bz, x1 = x0 + 2, z1 = z0 + 2;
            double h = 2 + (bx * 7 + bz * 3) % 4;
            double c[8][3] = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1},
                              {x0, h, z0}, {x1, h, z0}, {x1, h, z1}, {x0, h, z1}};
            if (bx == 0 && bz == 0)
                c[4][1] += shift;
            for (int k = 0; k < 8; k++)
                at += (size_t)snprintf(text + at, sizeof(text) - at, "v %g %g %g\n", c[k][0],
                                       c[k][1], c[k][2]);
            int v = vertices + 1;
            /* outward faces, counter-clockwise from outside */
            const int faces[5][4] = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6},
                                     {3, 0, 4, 7}, {4, 5, 6, 7}};
            for (int f = 0; f < 5; f++) {
                const int *q = faces[f];
                at += (size_t)snprintf(text + at, sizeof(text) - at,
                                       "o box%d%d_side%d\nf %d %d %d %d\n", bx, bz, f,
                                       v + q[0], v + q[1], v + q[2], v + q[3]);
            }
            vertices += 8;
            /* the ground tile around the box, facing up */
            double g0x = x0 - 1, g0z = z0 - 1, g1x = x0 + 3, g1z = z0 + 3;
            at += (size_t)snprintf(text + at, sizeof(text) - at,
                                   "v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\n"
                                   "o ground%d%d\nf %d %d %d %d\n",
                                   g0x, g0z, g0x, g1z, g1x, g1z, g1x, g0z, bx, bz,
                                   vertices + 1, vertices + 2, vertices + 3, vertices + 4);
            vertices += 4;
        }
    test_write_file(name, text);
}

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

int main(void)
{
    write_blocks("blocks.obj", 0);
    CHECK(test_run_tool(BLOCKS " -o full.mtx --threads 2 --stats full.json") ==
          0);
    CHECK(strstr(test_read_text(test_path("full.json")), "\"surfaces\": 96") != NULL ||
          strstr(test_read_text(test_path("full.json")), "\"surfaces\":96") != NULL);
    CHECK(strstr(test_read_text(test_path("full.json")), "\"obstructed_pairs\": 0") == NULL);

    /* stopped after the third checkpoint: status 130, no output, some rows saved */
    setenv("RADIOSITY_STOP_AFTER_CHECKPOINTS", "3", 1);
    CHECK(test_run_tool(BLOCKS " -o part.mtx --threads 2 --checkpoint ck.bin "
                        "--checkpoint-interval 0") == 130);
    unsetenv("RADIOSITY_STOP_AFTER_CHECKPOINTS");
    CHECK(!test_file_exists(test_path("part.mtx")));
    CHECK(test_file_exists(test_path("ck.bin")));
    const char *err = test_read_text(test_path("stderr.txt"));
    const char *holds = strstr(err, "ck.bin holds ");
    CHECK(holds != NULL);
    long done = holds ? strtol(holds + strlen("ck.bin holds "), NULL, 10) : 0;
    CHECK(done > 0 && done < 96);
    CHECK(test_count_files("ck.bin.tmp-") == 0);

    /* resumed with one thread: the bytes of the uninterrupted run */
    CHECK(test_run_tool(BLOCKS " -o part.mtx --threads 1 --resume ck.bin") == 0);
    CHECK(test_same_bytes(test_path("full.mtx"), test_path("part.mtx")));
    char resumed[64];
    snprintf(resumed, sizeof(resumed), "%ld of 96 rows were done", done);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), resumed) != NULL);

    /* refusals: one line naming the file, exit 1, no output */
    write_blocks("moved.obj", 0.25);
    CHECK(test_run_tool(MOVED " -o other.mtx --resume ck.bin") == 1);
    check_refusal("another scene", "ck.bin");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume ck.bin --accuracy 2e-4") ==
          1);
    check_refusal("other options", "ck.bin");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume ck.bin --seed 7") == 1);
    check_refusal("other options", "ck.bin");
    /* its rows visit only the pairs its sight rays met: not a job without them */
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume ck.bin --sight-rays none") ==
          1);
    check_refusal("--sight-rays 29958, --exact-occluders 4; this run: 0.0001, 1024, 1, 0, 4",
                  "ck.bin");
    /* its obstructed pairs were clipped exactly behind at most 4 triangles, not 64 */
    CHECK(test_run_tool("viewfactors blocks.obj -o other.mtx --resume ck.bin "
                        "--exact-occluders 64") == 1);
    check_refusal("--exact-occluders 4; this run: 0.0001, 1024, 1, 29958, 64", "ck.bin");
    size_t size;
    uint8_t *bytes = test_read_bytes(test_path("ck.bin"), &size);
    CHECK(bytes && size > 100);
    if (bytes && size > 100) {
        FILE *f = fopen(test_path("damaged.bin"), "wb");
        bytes[size / 2] ^= 0x10; /* one bit of a row */
        CHECK(f && fwrite(bytes, 1, size, f) == size);
        if (f)
            fclose(f);
        f = fopen(test_path("short.bin"), "wb");
        CHECK(f && fwrite(bytes, 1, size - 5, f) == size - 5);
        if (f)
            fclose(f);
    }
    free(bytes);
    /* a whole checkpoint of format version 3 (before the exact quadrature's edge check):
     * refused, saying why */
    bytes = test_read_bytes(test_path("ck.bin"), &size);
    if (bytes && size > 100) {
        bytes_put_u32(bytes + 8, 3);
        bytes_put_u64(bytes + size - 8, hash_bytes(RAD_HASH_START, bytes, size - 8));
        FILE *f = fopen(test_path("version3.bin"), "wb");
        CHECK(f && fwrite(bytes, 1, size, f) == size);
        if (f)
            fclose(f);
    }
    free(bytes);
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume version3.bin") == 1);
    check_refusal("an earlier build (format version 3), whose exact clipping could miss light",
                  "version3.bin");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume damaged.bin") == 1);
    check_refusal("corrupted", "damaged.bin");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume short.bin") == 1);
    check_refusal("checkpoint", "short.bin");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume full.mtx") == 1);
    check_refusal("not a view-factor checkpoint", "full.mtx");
    CHECK(test_run_tool(BLOCKS " -o other.mtx --resume missing.bin") == 1);
    check_refusal("cannot open", "missing.bin");
    CHECK(!test_file_exists(test_path("other.mtx")));
    /* the refused runs left the checkpoint as it was: it still resumes */
    CHECK(test_run_tool(BLOCKS " -o again.mtx --resume ck.bin --quiet") == 0);
    CHECK(test_same_bytes(test_path("full.mtx"), test_path("again.mtx")));

    CHECK(test_run_tool("viewfactors blocks.obj --checkpoint-interval 5") == 2);
    CHECK(test_run_tool("viewfactors blocks.obj --checkpoint ck2.bin --checkpoint-interval -1") ==
          2);
    return test_finish("test_viewfactor_checkpoint");
}
