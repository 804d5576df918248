/*
 * tolerance.h - every tolerance of the library, named once with its unit and reason.
 */
#ifndef RAD_CORE_TOLERANCE_H
#define RAD_CORE_TOLERANCE_H

/* A triangle is degenerate when twice its area is at most this times its longest edge
 * squared (dimensionless): collinear or repeated corners, whatever the scene's unit. */
#define RAD_DEGENERATE_RELATIVE_AREA 1e-9

/* Scenes are traced in single precision: the scene must span at least this many units
 * (squared distances of 1e-20 and below underflow) and no coordinate may exceed this. */
#define RAD_SMALLEST_EXTENT 1e-9
#define RAD_LARGEST_COORDINATE 1e15

/* Two triangles sharing an edge belong to one smooth region when their unit normals differ
 * by less than this (dimensionless: 2 sin(0.5 deg), a 1 degree crease). Real data is not
 * exactly planar: the Cornell box's left wall folds by 0.47 degrees along its diagonal. */
#define RAD_REGION_NORMAL 0.01745

/* A quad is flat when its fourth corner lies within this fraction of the diagonal from the
 * first triangle's plane (dimensionless: float-rounded input data of a flat quad passes);
 * a folded one records its bulge for the visibility rays. */
#define RAD_QUAD_FLATNESS 1e-5

/* Occlusion segments between two patches stop this far (as a fraction of the segment)
 * from each end, so that the patches' own triangles never count as occluders. */
#define RAD_SEGMENT_END_EPSILON 1e-4f

/* A point is in front of a plane when its signed distance exceeds this times the scene's
 * bounding-box diagonal (scene units; guards coplanar and touching patches). */
#define RAD_PLANE_EPSILON 1e-7

/* Secondary rays (mirror rays of the two-pass method) leave a surface this far along its
 * normal: a fraction of the scene diagonal plus a fraction of the largest coordinate, since
 * a float hit point's error grows with its distance from the origin. */
#define RAD_SURFACE_LEAVE_DIAGONAL 1e-5
#define RAD_SURFACE_LEAVE_COORDINATE 1e-6

/* Camera rays start this far from the eye, as a fraction of the scene diagonal. */
#define RAD_CAMERA_NEAR 1e-6

#endif
