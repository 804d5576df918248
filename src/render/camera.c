/*
 * camera.c - see camera.h.
 */
#include "render/camera.h"

#include <math.h>

#include "core/error.h"
#include "core/vec3.h"

rad_status camera_frame_make(const rad_camera *camera, uint32_t width, uint32_t height,
                             camera_frame *frame, rad_error *error)
{
    rad_vec3 forward = v3_sub(camera->target, camera->eye);
    if (!(v3_length(forward) > 0) || !v3_is_finite(forward))
        return rad_fail(error, RAD_ERR_INVALID, "camera: eye and target must differ");
    forward = v3_normalize(forward);
    rad_vec3 right = v3_cross(forward, camera->up);
    if (!(v3_length(right) > 1e-9 * v3_length(camera->up)))
        return rad_fail(error, RAD_ERR_INVALID, "camera: up must not be parallel to the view");
    if (!(camera->fov_degrees > 0 && camera->fov_degrees < 180))
        return rad_fail(error, RAD_ERR_INVALID,
                        "camera: field of view must be between 0 and 180 degrees");
    if (width == 0 || height == 0)
        return rad_fail(error, RAD_ERR_INVALID, "camera: image size must be positive");
    frame->eye = camera->eye;
    frame->forward = forward;
    frame->right = v3_normalize(right);
    frame->up = v3_cross(frame->right, forward);
    frame->tan_half_fov = tan(camera->fov_degrees * RAD_PI / 360.0);
    frame->aspect = (double)width / height;
    return RAD_OK;
}

rad_vec3 camera_direction(const camera_frame *frame, double x, double y, uint32_t width,
                          uint32_t height)
{
    double sx = (2.0 * x / width - 1.0) * frame->tan_half_fov * frame->aspect;
    double sy = (1.0 - 2.0 * y / height) * frame->tan_half_fov;
    return v3_add(frame->forward, v3_add(v3_scale(frame->right, sx), v3_scale(frame->up, sy)));
}
