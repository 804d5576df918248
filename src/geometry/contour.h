/*
 * contour.h - the analytic point-to-polygon form factor (Lambert's contour formula).
 *
 * For a differential area at p with unit normal n and a planar polygon seen unoccluded:
 *   F = 1/(2 pi) * | sum_k beta_k (n . g_k) |
 * with r_k = v_k - p, beta_k the angle between r_k and r_k+1, g_k the unit vector along
 * r_k x r_k+1 (shared/docs/VALIDATION.md section 2). The polygon is first clipped to the
 * half-space in front of p. One-sided: when p is not in front of the polygon's plane (its
 * counter-clockwise side), the factor is 0. No visibility here.
 */
#ifndef RAD_FORMFACTOR_CONTOUR_H
#define RAD_FORMFACTOR_CONTOUR_H

#include "geometry/flat_pieces.h"
#include "radiosity.h"

/* Most vertices a polygon may have (clipping adds one). */
#define CONTOUR_MAX_VERTICES 16

/* polygon: count vertices (count <= CONTOUR_MAX_VERTICES - 1), counter-clockwise seen
 * from its front, with unit front normal polygon_normal. plane_epsilon (scene units): p
 * counts as in front of the polygon only beyond this distance. */
double contour_point_to_polygon(rad_vec3 p, rad_vec3 n, const rad_vec3 *polygon,
                                unsigned count, rad_vec3 polygon_normal, double plane_epsilon);

/* The same for a polygon given in a plane's own frame (plane_frame: axes u, v, normal N,
 * counter-clockwise in (u, v)) and a point at `height` (> 0) above the plane over x, whose
 * unit normal n has components n_local = (n . u, n . v, n . N): no mapping to 3-D, fewer
 * products (the shadow clipping's pieces). count <= CONTOUR_MAX_VERTICES - 1. */
double contour_point_to_flat_polygon(flat_point x, double height, rad_vec3 n_local,
                                     const flat_point *polygon, unsigned count);

#endif
