/*
 * tracer_scene.c - a tracer over a scene's triangles.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"

rad_status rad_tracer_create_for_scene(rad_tracer_backend backend, const rad_scene *scene,
                                       rad_tracer **out, rad_error *error)
{
    uint32_t (*triangles)[3] = rad_alloc_array(scene->triangle_count, sizeof(*triangles));
    if (!triangles)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %u triangles",
                        scene->triangle_count);
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        memcpy(triangles[t], scene->triangles[t].vertex, sizeof(triangles[t]));
    rad_status status = rad_tracer_create(backend, scene->positions, scene->position_count,
                                          (const uint32_t(*)[3])triangles,
                                          scene->triangle_count, out, error);
    free(triangles);
    return status;
}
