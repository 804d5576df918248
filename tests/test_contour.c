/*
 * test_contour.c - Lambert's contour formula against closed forms (VALIDATION.md
 * section 2): a point under the corner of a parallel rectangle, a point under the centre
 * of a polygonal disk, clipping by the point's tangent plane, and one-sidedness; the same
 * formula in a plane's own frame against them.
 */
#include <math.h>

#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/flat_pieces.h"
#include "testlib.h"

static const double pi = 3.14159265358979323846;

/* F from a point whose normal passes through one corner of a parallel a x b rectangle. */
static double corner_rectangle(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    return 1 / (2 * pi) *
           (X / sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) +
            Y / sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)));
}

int main(void)
{
    rad_vec3 up = {0, 0, 1}, down = {0, 0, -1};

    /* the edge angles span (0, pi) over a wide range of shapes: very thin, very wide and
     * very close rectangles, seen from under a corner and from under the centre */
    const double extents[] = {0.001, 0.01, 0.1, 0.5, 1, 3, 10, 100, 1000};
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++) {
            double a = extents[i], b = extents[j];
            rad_vec3 corner[4] = {{0, 0, 1}, {0, b, 1}, {a, b, 1}, {a, 0, 1}};
            rad_vec3 centred[4] = {{-a, -b, 1}, {-a, b, 1}, {a, b, 1}, {a, -b, 1}};
            CHECK_NEAR(contour_point_to_polygon((rad_vec3){0, 0, 0}, up, corner, 4, down, 0),
                       corner_rectangle(a, b, 1), 1e-8);
            CHECK_NEAR(contour_point_to_polygon((rad_vec3){0, 0, 0}, up, centred, 4, down, 0),
                       4 * corner_rectangle(a, b, 1), 1e-8);
        }

    /* the catalogue value: X = 2, Y = 3 gives 0.2175752 */
    CHECK_NEAR(corner_rectangle(2, 3, 1), 0.2175752, 1e-6);

    double sizes[][3] = {{2, 3, 1}, {1, 1, 1}, {0.1, 0.3, 2}, {5, 0.5, 0.7}};
    for (int k = 0; k < 4; k++) {
        double a = sizes[k][0], b = sizes[k][1], c = sizes[k][2];
        /* the rectangle faces down, towards the point: counter-clockwise seen from below */
        rad_vec3 rect[4] = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
        double F = contour_point_to_polygon((rad_vec3){0, 0, 0}, up, rect, 4, down, 0);
        CHECK_NEAR(F, corner_rectangle(a, b, c), 1e-9);
        /* reversed winding: the point is behind the polygon, so nothing is seen */
        rad_vec3 back[4] = {rect[3], rect[2], rect[1], rect[0]};
        CHECK(contour_point_to_polygon((rad_vec3){0, 0, 0}, up, back, 4, up, 0) == 0);
    }

    /* superposition: a regular 7-gon (the most corners a polygon may have before clipping)
     * seen from below its centre equals the sum of its 7 fan triangles */
    double R = 1.5, H = 0.8;
    rad_vec3 heptagon[7];
    for (int k = 0; k < 7; k++)
        heptagon[k] = (rad_vec3){R * cos(-2 * pi * k / 7), R * sin(-2 * pi * k / 7), H};
    double whole = contour_point_to_polygon((rad_vec3){0, 0, 0}, up, heptagon, 7, down, 0);
    double fan = 0;
    for (int k = 0; k < 7; k++) {
        rad_vec3 tri[3] = {{0, 0, H}, heptagon[k], heptagon[(k + 1) % 7]};
        fan += contour_point_to_polygon((rad_vec3){0, 0, 0}, up, tri, 3, down, 0);
    }
    CHECK_NEAR(whole, fan, 1e-12);
    /* and it lies between the inscribed and circumscribed disks' values */
    double r_in = R * cos(pi / 7);
    CHECK(whole < R * R / (H * H + R * R));
    CHECK(whole > r_in * r_in / (H * H + r_in * r_in));

    /* a point under the centre of a square: 4 x the corner value */
    rad_vec3 square[4] = {{-1, -1, 2}, {-1, 1, 2}, {1, 1, 2}, {1, -1, 2}};
    CHECK_NEAR(contour_point_to_polygon((rad_vec3){0, 0, 0}, up, square, 4, down, 0),
               4 * corner_rectangle(1, 1, 2), 1e-9);

    /* clipping: a tilted point sees only the part of an infinite-like plate in front of it.
     * A huge plate perpendicular to the point's tangent plane, touching it: F -> 1/2 as the
     * plate grows (the plate fills half the hemisphere, weighted by cosine). */
    double L = 1e4;
    rad_vec3 wall[4] = {{-L, 1e-3, -L}, {-L, 1e-3, L}, {L, 1e-3, L}, {L, 1e-3, -L}};
    rad_vec3 wall_normal = {0, -1, 0};
    /* wall at y = 0.001 facing -y; point at origin with normal +z: half the wall is behind */
    double half = contour_point_to_polygon((rad_vec3){0, 0, 0}, up, wall, 4, wall_normal, 0);
    CHECK_NEAR(half, 0.5, 1e-3);

    /* an infinite parallel plane in front: F -> 1 */
    rad_vec3 ceiling[4] = {{-L, -L, 1}, {-L, L, 1}, {L, L, 1}, {L, -L, 1}};
    CHECK_NEAR(contour_point_to_polygon((rad_vec3){0, 0, 0}, up, ceiling, 4, down, 0), 1.0, 1e-3);

    /* the coaxial disk closed form R^2 / (H^2 + R^2), by a 360-triangle fan */
    double disk = 0;
    for (int k = 0; k < 360; k++) {
        double a0 = -2 * pi * k / 360, a1 = -2 * pi * (k + 1) / 360;
        rad_vec3 tri[3] = {{0, 0, H}, {R * cos(a0), R * sin(a0), H}, {R * cos(a1), R * sin(a1), H}};
        disk += contour_point_to_polygon((rad_vec3){0, 0, 0}, up, tri, 3, down, 0);
    }
    /* polygon area / disk area = sin(2pi/n) n / (2 pi); compare with the disk of equal area */
    double equal_area_R = R * sqrt(360 * sin(2 * pi / 360) / (2 * pi));
    CHECK_NEAR(disk, equal_area_R * equal_area_R / (H * H + equal_area_R * equal_area_R), 1e-4);
    /* the same in the receiving plane's own frame (contour_point_to_flat_polygon, what
     * the shadow clipping uses): the corner rectangle's closed form, and the 3-D formula
     * for normals tilted far enough that the tangent plane clips the rectangle */
    for (int k = 0; k < 4; k++) {
        double a = sizes[k][0], b = sizes[k][1], c = sizes[k][2];
        rad_vec3 rect[4] = {{0, 0, c}, {0, b, c}, {a, b, c}, {a, 0, c}};
        plane_frame frame = plane_frame_make(rect[0], down);
        flat_point flat[4];
        for (int m = 0; m < 4; m++)
            flat[m] = plane_frame_flat(&frame, rect[m]);
        double height = -frame.normal.z * c; /* N . (x - origin), x at the origin */
        flat_point x = plane_frame_flat(&frame, (rad_vec3){0, 0, 0});
        rad_vec3 n_up = {v3_dot(up, frame.u), v3_dot(up, frame.v), v3_dot(up, frame.normal)};
        CHECK_NEAR(contour_point_to_flat_polygon(x, height, n_up, flat, 4),
                   corner_rectangle(a, b, c), 1e-9);
        for (int t = 0; t < 12; t++) {
            double tilt = 0.25 * t, turn = 0.9 * t;
            rad_vec3 n = {sin(tilt) * cos(turn), sin(tilt) * sin(turn), cos(tilt)};
            rad_vec3 n_local = {v3_dot(n, frame.u), v3_dot(n, frame.v), v3_dot(n, frame.normal)};
            double want = contour_point_to_polygon((rad_vec3){0, 0, 0}, n, rect, 4, down, 0);
            CHECK_NEAR(contour_point_to_flat_polygon(x, height, n_local, flat, 4), want,
                       1e-12 + 1e-12 * want);
        }
    }
    return test_finish("test_contour");
}
