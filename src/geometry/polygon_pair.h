/*
 * polygon_pair.h - the unoccluded transfer between two planar polygons, G = A_p F_pq =
 * A_q F_qp, by the double contour integral (Stokes' theorem applied twice to the area
 * integral of cos cos / (pi r^2); Sparrow 1963, Siegel & Howell):
 *
 *   G = 1/(2 pi) sum over edges e of p and f of q of (e^ . f^) int_e int_f ln r ds dt
 *
 * with both contours counter-clockwise seen from their fronts. Each polygon is first
 * clipped to the front half-space of the other's plane, where the kernel's two cosines
 * are both positive, so the formula holds for polygons that touch, share an edge or run
 * partly behind each other. Pairs of parallel edges (a shared edge among them, where
 * ln r is singular along the whole edge) are integrated in closed form; for the others
 * the inner integral is in closed form and the outer one adaptive (Gauss-Kronrod 7-15
 * points, halves until they agree). No visibility here.
 */
#ifndef RAD_GEOMETRY_POLYGON_PAIR_H
#define RAD_GEOMETRY_POLYGON_PAIR_H

#include "radiosity.h"

/* Most corners a polygon may have (clipping adds one). */
#define POLYGON_PAIR_MAX_VERTICES 16

/* p: np corners with unit front normal p_normal, q likewise (either winding: each is
 * traversed counter-clockwise about its own normal); np, nq <= POLYGON_PAIR_MAX_VERTICES
 * - 1. plane_epsilon (scene units): corners within it of the other's plane count as on
 * it. accuracy: the adaptive edge integrals' absolute tolerance, relative to the product
 * of the two edges' lengths (1e-9 gives G to about 1e-7 relative on touching patches). */
double polygon_pair_transfer(const rad_vec3 *p, unsigned np, rad_vec3 p_normal,
                             const rad_vec3 *q, unsigned nq, rad_vec3 q_normal,
                             double plane_epsilon, double accuracy);

/* The second moment of a planar polygon's area about a point (its centroid), as (xx, yy,
 * zz, xy, xz, yz). */
void polygon_second_moment(const rad_vec3 *corner, unsigned count, rad_vec3 centroid,
                           double m[6]);

/* A polygon as the expansion sees it. */
typedef struct polygon_moments {
    rad_vec3 centroid, normal;
    double area;
    double moment[6]; /* polygon_second_moment about the centroid */
} polygon_moments;

/* A polygon's area, area centroid, second moment about it, and the given unit normal. */
void polygon_moments_of(const rad_vec3 *corner, unsigned count, rad_vec3 normal,
                        polygon_moments *out);

/* G for two planar polygons far apart, each wholly in front of the other: the kernel
 * cos cos / (pi r^2) expanded to second order about both centroids (the first-order
 * terms vanish there), G = A_p A_q k(D) + 1/2 (A_q M_p + A_p M_q) : grad^2 k(D). Its
 * error falls as (radius / distance)^4. */
double polygon_pair_expansion(const polygon_moments *p, const polygon_moments *q);

#endif
