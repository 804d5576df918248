/*
 * camera.h - primary rays of a pinhole camera.
 *
 * The image plane spans [-1,1] vertically at tan(fov/2), x to the right of the view,
 * y up; pixel (0,0) is the top-left corner. right = forward x up, so a camera looking
 * along +z with +y up has +x on the image's LEFT (the Cornell box's red wall).
 */
#ifndef RAD_RENDER_CAMERA_H
#define RAD_RENDER_CAMERA_H

#include "radiosity.h"

typedef struct camera_frame {
    rad_vec3 eye, forward, right, up; /* orthonormal */
    double tan_half_fov, aspect;
} camera_frame;

/* RAD_ERR_INVALID when eye == target, up is parallel to the view, or fov not in (0,180). */
rad_status camera_frame_make(const rad_camera *camera, uint32_t width, uint32_t height,
                             camera_frame *frame, rad_error *error);

/* Direction (not unit) through image point (x, y) in pixels, x right, y down. */
rad_vec3 camera_direction(const camera_frame *frame, double x, double y, uint32_t width,
                          uint32_t height);

#endif
