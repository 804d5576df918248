/*
 * city.c - writes a generated city block as OBJ for the view-factor benchmark.
 *
 * usage: city SURFACES OUT.obj
 *
 * A square grid of box buildings (10 m footprint, 8 m streets, heights 6-30 m from a fixed
 * hash) on ground tiles, y up, metres. Every building has four walls (each two storeys,
 * four triangles) and a roof; every grid cell has a ground tile: six surfaces per
 * building, each an OBJ object, all facing outwards or up. The grid is the smallest
 * square with at least SURFACES surfaces.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static FILE *out;
static long vertices;

static void vertex(double x, double y, double z)
{
    fprintf(out, "v %.6f %.6f %.6f\n", x, y, z);
    vertices++;
}

/* A quad a b c d, counter-clockwise seen from its front. */
static void quad(const double p[4][3])
{
    for (int k = 0; k < 4; k++)
        vertex(p[k][0], p[k][1], p[k][2]);
    fprintf(out, "f %ld %ld %ld %ld\n", vertices - 3, vertices - 2, vertices - 1, vertices);
}

/* A wall from (x0, z0) to (x1, z1) at ground level, height h, facing to the right of the
 * direction of travel seen from above; two storeys. */
static void wall(const char *name, double x0, double z0, double x1, double z1, double h)
{
    fprintf(out, "o %s\n", name);
    for (int storey = 0; storey < 2; storey++) {
        double y0 = h * storey / 2, y1 = h * (storey + 1) / 2;
        const double p[4][3] = {{x0, y0, z0}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z0}};
        quad(p);
    }
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fputs("usage: city SURFACES OUT.obj\n", stderr);
        return 2;
    }
    long target = strtol(argv[1], NULL, 10);
    int grid = (int)ceil(sqrt((double)target / 6));
    out = fopen(argv[2], "w");
    if (!out || grid < 1) {
        fprintf(stderr, "city: cannot write %s\n", argv[2]);
        return 1;
    }
    const double footprint = 10, street = 8, cell = footprint + street;
    fprintf(out, "# generated city: %d x %d buildings, %d surfaces\n", grid, grid,
            6 * grid * grid);
    char name[64];
    for (int i = 0; i < grid; i++)
        for (int j = 0; j < grid; j++) {
            uint64_t hash = (uint64_t)(i * 7919 + j * 104729 + 1) * 0x9E3779B97F4A7C15ull;
            double h = 6 + 24 * (double)(hash >> 40) / (double)(1ull << 24);
            double x0 = i * cell + street / 2, x1 = x0 + footprint;
            double z0 = j * cell + street / 2, z1 = z0 + footprint;
            /* walls facing -z, +x, +z, -x (counter-clockwise seen from outside) */
            snprintf(name, sizeof(name), "b%d_%d_south", i, j);
            wall(name, x1, z0, x0, z0, h);
            snprintf(name, sizeof(name), "b%d_%d_east", i, j);
            wall(name, x1, z1, x1, z0, h);
            snprintf(name, sizeof(name), "b%d_%d_north", i, j);
            wall(name, x0, z1, x1, z1, h);
            snprintf(name, sizeof(name), "b%d_%d_west", i, j);
            wall(name, x0, z0, x0, z1, h);
            snprintf(name, sizeof(name), "b%d_%d_roof", i, j);
            fprintf(out, "o %s\n", name);
            const double roof[4][3] = {{x0, h, z0}, {x0, h, z1}, {x1, h, z1}, {x1, h, z0}};
            quad(roof);
            snprintf(name, sizeof(name), "g%d_%d_ground", i, j);
            fprintf(out, "o %s\n", name);
            const double ground[4][3] = {{i * cell, 0, j * cell},
                                         {i * cell, 0, (j + 1) * cell},
                                         {(i + 1) * cell, 0, (j + 1) * cell},
                                         {(i + 1) * cell, 0, j * cell}};
            quad(ground);
        }
    if (fclose(out) != 0) {
        fprintf(stderr, "city: cannot write %s\n", argv[2]);
        return 1;
    }
    return 0;
}
