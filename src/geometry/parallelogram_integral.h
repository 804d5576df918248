/*
 * parallelogram_integral.h - the adaptive integral of a point function over a
 * parallelogram, split along the direction in which the function changes fast.
 *
 * The same outer integral as polygon_integral.h, for an outer polygon that is a
 * parallelogram (a rectangle: walls, roofs, floors). Shadows of a rectilinear scene kink
 * the integrand along lines parallel to the polygon's edges (an occluder's edge parallel
 * to an edge of the other polygon, seen from a point in their common plane): a triangle
 * splitting needs 2^d cells along such a line at depth d, strips across it a few a level.
 * Each cell gets the 3 x 3 Gauss-Legendre rule (degree 5 in each direction); the fourth
 * differences along its two centre lines (the rule's 3 points there and the two edge
 * midpoints) say which way f changes fast: a cell is halved across that direction only
 * when the other is at least STRIP_RATIO times smoother, else quartered. The children are
 * compared with the cell as in polygon_integral.c; with the edge check, f at a quartered
 * cell's corners, edge midpoints and centre, and at a strip's two midpoints across its
 * cut, must also agree with what its children's rule points predict. A cell split to
 * max_splits either way is not split the other way: halves along a kink agree on what
 * neither resolves, so it stops there with its disagreement as its error.
 * With `probes`, 55 points of a lattice over the whole parallelogram, with 55 distinct
 * values along either direction, check each cell about to be accepted: f at the probes in
 * it against its rule points' biquadratic, the misses counted as error. A probe far
 * outside its cell's range marks a feature the rule points did not see (light through a
 * slit), and the integral is made again with 64 more probes along each of that probe's
 * two lines, which a band through it along either edge holds (cells across the lines are
 * quartered rather than halved down to 1/32, and split only where f misses them). This
 * takes the place of forced splits (min_splits), which only narrowed the gaps between the
 * lines all rule points lie on, at the price of every cell.
 */
#ifndef RAD_GEOMETRY_PARALLELOGRAM_INTEGRAL_H
#define RAD_GEOMETRY_PARALLELOGRAM_INTEGRAL_H

#include <stdbool.h>

#include "geometry/polygon_integral.h"
#include "radiosity.h"

/* Splits of a parallelogram's cells in either direction, at most: the cull callback's
 * levels run to twice this. */
#define PARALLELOGRAM_MAX_SPLITS 10
#define PARALLELOGRAM_MAX_LEVELS (2 * PARALLELOGRAM_MAX_SPLITS + 1)

/* As polygon_integral.cell, for the cell with corners corner[0 .. 4) (a parallelogram,
 * counter-clockwise like the whole), child `slot` (0 to 3) of the one told last at level -
 * 1 with slot `parent_slot`. */
typedef bool (*parallelogram_cell_fn)(void *context, const rad_vec3 corner[4], int level,
                                      int slot, int parent_slot);

/* Makes the cell told last at (level, slot) the one the next points belong to again, as
 * its telling did (its children have been told since, at level + 1). */
typedef void (*parallelogram_select_fn)(void *context, int level, int slot);

typedef struct parallelogram_integral {
    polygon_point_fn f;
    void *context;
    int max_splits;     /* in either direction, 1 to PARALLELOGRAM_MAX_SPLITS */
    const bool *failed; /* as polygon_integral.failed */
    parallelogram_cell_fn cell; /* NULL or as polygon_integral.cell */
    int min_splits;     /* where f is not smooth, splits in each direction before the
                           rules' agreement is believed */
    bool edge_check;
    /* NULL: a cell whose own points come again after its children's is told again */
    parallelogram_select_fn select;
    /* where f is not smooth, cells are accepted only where f at the lattice probes inside
     * them follows their rule points (above) */
    bool probes;
} parallelogram_integral;

/* Whether the convex polygon (count corners) is a parallelogram: corner 0 at *origin, the
 * others origin + *a, origin + *a + *b, origin + *b (to 1e-9 of its extent). */
bool parallelogram_of(const rad_vec3 *polygon, unsigned count, rad_vec3 *origin, rad_vec3 *a,
                      rad_vec3 *b);

/* int over the parallelogram origin + s a + t b, (s, t) in [0, 1]^2, of f, to the looser
 * of the relative `accuracy` and the absolute tolerance `absolute`; *bound receives the
 * estimated absolute error. */
double parallelogram_integrate_within(const parallelogram_integral *integral, rad_vec3 origin,
                                      rad_vec3 a, rad_vec3 b, double accuracy,
                                      double absolute, double *bound);

#endif
