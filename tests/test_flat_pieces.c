/*
 * test_flat_pieces.c - convex pieces of a plane and their subtraction
 * (src/geometry/flat_pieces.c), against areas worked out by hand: a plane's frame maps its
 * points to (u, v) and back and keeps counter-clockwise counter-clockwise; a square less
 * a square over one of its corners leaves 3/4 of it in 2 pieces, less one in its middle a
 * frame of 4 pieces, less a covering one nothing; a shape whose box is apart, that only
 * touches along an edge, that lies apart only across the piece's own edge, or that
 * overlaps it by a sliver of at most tiny, leaves the piece as it was, as does a 15-gon
 * the shape misses though its edge's line cuts a corner off (16 corners); of 2 triangles
 * that cover it together, the first leaves the corner the second then covers; more pieces
 * than there is room for fail (-1); in place, a piece the shape misses stays as it was, one it covers vanishes and the
 * next piece's parts may take its slot, or wait for it when it comes later;
 * corners repeated a hair apart are dropped, distinct ones kept, also beside a crossing
 * point rounded outside the piece's box. Not here: the shadows
 * cut with it (test_shadow_clip, test_shadow_join).
 */
#include <math.h>
#include <stdio.h>

#include "core/vec3.h"
#include "geometry/flat_pieces.h"
#include "testlib.h"

static flat_piece square(double u0, double u1, double v0, double v1)
{
    return (flat_piece){{{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}}, 4};
}

static double total_area(const flat_piece *pieces, int count)
{
    double sum = 0;
    for (int k = 0; k < count; k++) {
        double area = flat_piece_area(&pieces[k]);
        CHECK(area > 0); /* counter-clockwise, not degenerate */
        sum += area;
    }
    return sum;
}

/* The pieces `start` less `shape`, into `pieces` (room for max). */
static int subtract_from(const flat_piece *start, const flat_piece *shape, flat_piece *pieces,
                         unsigned max)
{
    pieces[0] = *start;
    return flat_subtract(pieces, 1, shape, 1e-12, max);
}

int main(void)
{
    /* the frame of a tilted plane: axes unit and orthogonal, u x v = n, points back */
    rad_vec3 n = v3_normalize(v3(0.3, -0.5, 0.8));
    plane_frame frame = plane_frame_make(v3(1, 2, 3), n);
    CHECK_NEAR(v3_length(frame.u), 1, 1e-15);
    CHECK_NEAR(v3_length(frame.v), 1, 1e-15);
    CHECK(fabs(v3_dot(frame.u, frame.v)) < 1e-15);
    CHECK(v3_length(v3_sub(v3_cross(frame.u, frame.v), n)) < 1e-15);
    rad_vec3 p = v3_add(v3(1, 2, 3), v3_add(v3_scale(frame.u, 0.7), v3_scale(frame.v, -1.3)));
    flat_point q = plane_frame_flat(&frame, p);
    CHECK_NEAR(q.u, 0.7, 1e-14);
    CHECK_NEAR(q.v, -1.3, 1e-14);
    CHECK(v3_length(v3_sub(plane_frame_point(&frame, q), p)) < 1e-14);

    flat_piece unit = square(0, 1, 0, 1), next[8];
    CHECK_NEAR(flat_piece_area(&unit), 1, 1e-15);

    /* a square over the corner (1, 1): the L left is 3/4, in 2 convex pieces */
    flat_piece corner = square(0.5, 1.5, 0.5, 1.5);
    int made = subtract_from(&unit, &corner, next, 8);
    printf("unit square less the square over its corner: %d pieces, area %.17g\n", made,
           made > 0 ? total_area(next, made) : -1.0);
    CHECK(made == 2);
    CHECK_NEAR(total_area(next, made), 0.75, 1e-15);

    /* a square in its middle: a frame of 4 pieces, 1 - 0.25 */
    flat_piece middle = square(0.25, 0.75, 0.25, 0.75);
    made = subtract_from(&unit, &middle, next, 8);
    CHECK(made == 4);
    CHECK_NEAR(total_area(next, made), 0.75, 1e-15);
    /* ... with room for 3 only: fails */
    CHECK(subtract_from(&unit, &middle, next, 3) == -1);

    /* a covering square: nothing left */
    flat_piece cover = square(-1, 2, -1, 2);
    CHECK(subtract_from(&unit, &cover, next, 8) == 0);

    /* apart, and touching along an edge: the piece as it was */
    flat_piece apart = square(2, 3, 0, 1), touching = square(1, 2, 0.2, 0.8);
    made = subtract_from(&unit, &apart, next, 8);
    CHECK(made == 1 && next[0].count == 4);
    CHECK_NEAR(total_area(next, made), 1, 0);
    made = subtract_from(&unit, &touching, next, 8);
    CHECK(made == 1 && next[0].count == 4);
    CHECK_NEAR(total_area(next, made), 1, 0);
    /* apart only across the piece's own edge (the triangle's long side), every edge of
     * the shape crossing the piece: the triangle as it was, not cut into parts */
    flat_piece triangle = {{{0, 0}, {1, 0}, {0, 1}}, 3};
    flat_piece beyond = square(0.7, 0.9, 0.7, 0.9);
    made = subtract_from(&triangle, &beyond, next, 8);
    CHECK(made == 1 && next[0].count == 3 && next[0].vertex[1].u == 1);
    CHECK_NEAR(total_area(next, made), 0.5, 0);
    /* a 15-gon the shape misses, though the line of the shape's first edge cuts a corner
     * off it (16 corners, more than a piece holds): the piece as it was, not a failure */
    flat_piece fifteen = {.count = 15};
    for (int k = 0; k < 15; k++)
        fifteen.vertex[k] = (flat_point){cos(2 * RAD_PI * k / 15), sin(2 * RAD_PI * k / 15)};
    flat_piece off_corner = {{{0.99, 0.9}, {0.99, 1.0}, {0.9, 0.95}}, 3};
    made = subtract_from(&fifteen, &off_corner, next, 4);
    CHECK(made == 1 && next[0].count == 15 && next[0].vertex[0].u == 1);
    /* a cut whose crossing point rounds a unit in the last place outside the piece's box,
     * beside a corner 1e-12 of the piece's extent from the one before it: that corner is
     * dropped, as flat_piece_drop_repeated drops it (the check before the pass that
     * spares most cuts allows for such a crossing point) */
    {
        double A = -231.0248902154305, au = -123.85412263141437, B = 2.2943922411537523e-05;
        double W = B - A, e = 1e-12 * ((au + (B - au)) - A), H = 0.3 * W;
        flat_piece window = {
            {{A, 0}, {au, -0.1 * W}, {B, 0}, {B, 0.6 * H}, {A + 0.5 * W, H}, {A, e}}, 6};
        double at = nextafter(B, -INFINITY);
        flat_piece band = {{{at, -2 * H}, {at, 2 * H}, {at - 0.4 * W, 2 * H},
                            {at - 0.4 * W, -2 * H}},
                           4};
        made = subtract_from(&window, &band, next, 4);
        CHECK(made == 1 && next[0].count == 5);
    }
    /* overlapping by a sliver (1e-14 of the area, at most tiny): the piece as it was */
    flat_piece sliver = square(1 - 1e-14, 2, 0.2, 0.8);
    made = subtract_from(&unit, &sliver, next, 8);
    CHECK(made == 1 && next[0].count == 4);
    CHECK_NEAR(total_area(next, made), 1, 0);

    /* a triangle over the square's part below y = x + 0.1, then one over its part above
     * y = x - 0.1: 0.9^2 / 2 left after the first, nothing after both */
    flat_piece lower = {{{-0.3, -0.2}, {1.2, -0.2}, {1.2, 1.3}}, 3};
    flat_piece upper = {{{-0.2, -0.3}, {1.3, 1.2}, {-0.2, 1.2}}, 3};
    flat_piece after[8];
    made = subtract_from(&unit, &lower, next, 8);
    CHECK(made >= 1);
    CHECK_NEAR(total_area(next, made), 0.405, 1e-14);
    for (int k = 0; k < made; k++)
        after[k] = next[k];
    made = flat_subtract(after, (unsigned)(made > 0 ? made : 0), &upper, 1e-12, 8);
    CHECK(made == 0);

    /* in place: a piece the shape misses stays where it was; one it covers vanishes and
     * its slot is taken by the next piece's parts when the list is full. The wedge covers
     * the unit square and pokes into [2, 3] x [0, 1] to (2.5, 0.5) from its left side:
     * 1 - 1/3 of that square is left, in 2 pieces, in a list of room for 2. */
    flat_piece wedge = {{{-1, -1}, {1.5, -1}, {2.5, 0.5}, {1.5, 2}, {-1, 2}}, 5};
    flat_piece list[4] = {unit, square(2, 3, 0, 1), square(5, 6, 0, 1)};
    made = flat_subtract(list, 2, &wedge, 1e-12, 2);
    CHECK(made == 2);
    CHECK_NEAR(total_area(list, made), 2.0 / 3, 1e-14);
    list[0] = unit, list[1] = square(5, 6, 0, 1), list[2] = square(2, 3, 0, 1);
    made = flat_subtract(list, 3, &wedge, 1e-12, 4);
    CHECK(made == 3);
    CHECK(made == 3 && list[0].count == 4 && list[0].vertex[0].u == 5); /* moved up, whole */
    CHECK_NEAR(total_area(list, made), 1 + 2.0 / 3, 1e-14);
    /* the square cut first, before the covered one vanishes: its second part waits for
     * that room */
    list[0] = square(2, 3, 0, 1), list[1] = unit;
    made = flat_subtract(list, 2, &wedge, 1e-12, 2);
    CHECK(made == 2);
    CHECK_NEAR(total_area(list, made), 2.0 / 3, 1e-14);

    /* corners repeated 1e-15 apart dropped, 1e-6 apart kept */
    flat_piece repeated = {{{0, 0}, {1, 0}, {1, 1e-15}, {1, 1}, {0, 1}, {1e-16, 1}}, 6};
    flat_piece_drop_repeated(&repeated);
    CHECK(repeated.count == 4);
    flat_piece distinct = {{{0, 0}, {1, 0}, {1, 1e-6}, {1, 1}}, 4};
    flat_piece_drop_repeated(&distinct);
    CHECK(distinct.count == 4);
    return test_finish("test_flat_pieces");
}
