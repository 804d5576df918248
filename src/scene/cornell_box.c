/*
 * cornell_box.c - the built-in Cornell box.
 *
 * Geometry: the Cornell University Program of Computer Graphics' published "Cornell Box
 * Data" (millimetres, y up), the same as shared/scenes/cornell-box.obj, with the light
 * 0.1 mm below the ceiling. Materials: the common RGB approximation of the measured
 * spectra (Kd albedo, Ke emitted radiance). Camera: the official one, eye (278, 273, -800)
 * looking along +z, vertical field of view 2 atan(12.5 / 35).
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "core/error.h"
#include "core/vec3.h"
#include "scene/scene_builder.h"

enum { WHITE, RED, GREEN, LIGHT, MATERIAL_COUNT };

static const struct {
    const char *name;
    rad_rgb albedo, emission;
} materials[MATERIAL_COUNT] = {
    [WHITE] = {"white", {0.725, 0.71, 0.68}, {0, 0, 0}},
    [RED] = {"red", {0.63, 0.065, 0.05}, {0, 0, 0}},
    [GREEN] = {"green", {0.14, 0.45, 0.091}, {0, 0, 0}},
    [LIGHT] = {"light", {0.78, 0.78, 0.78}, {17, 12, 4}},
};

/* Each quad is split like the OBJ: triangles (0,1,2) and (0,2,3). */
typedef struct quad {
    const char *surface;
    int material;
    double v[4][3];
} quad;

static const quad quads[] = {
    {"floor", WHITE, {{552.8, 0, 0}, {0, 0, 0}, {0, 0, 559.2}, {549.6, 0, 559.2}}},
    {"ceiling", WHITE, {{556, 548.8, 0}, {556, 548.8, 559.2}, {0, 548.8, 559.2}, {0, 548.8, 0}}},
    {"back_wall", WHITE, {{549.6, 0, 559.2}, {0, 0, 559.2}, {0, 548.8, 559.2}, {556, 548.8, 559.2}}},
    {"right_wall", GREEN, {{0, 0, 559.2}, {0, 0, 0}, {0, 548.8, 0}, {0, 548.8, 559.2}}},
    {"left_wall", RED, {{552.8, 0, 0}, {549.6, 0, 559.2}, {556, 548.8, 559.2}, {556, 548.8, 0}}},
    {"short_block", WHITE, {{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}}},
    {"short_block", WHITE, {{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}}},
    {"short_block", WHITE, {{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}}},
    {"short_block", WHITE, {{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}}},
    {"short_block", WHITE, {{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}},
    {"tall_block", WHITE, {{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}}},
    {"tall_block", WHITE, {{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}}},
    {"tall_block", WHITE, {{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}}},
    {"tall_block", WHITE, {{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}}},
    {"tall_block", WHITE, {{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}},
    {"light", LIGHT, {{343, 548.7, 227}, {343, 548.7, 332}, {213, 548.7, 332}, {213, 548.7, 227}}},
};

rad_status rad_scene_cornell_box(rad_scene **out, rad_error *error)
{
    scene_builder *builder;
    rad_status status = scene_builder_create("(built-in Cornell box)", NULL, &builder, error);
    if (status != RAD_OK)
        return status;
    uint32_t material[MATERIAL_COUNT];
    for (int m = 0; m < MATERIAL_COUNT; m++) {
        rad_material description = {0};
        snprintf(description.name, sizeof(description.name), "%s", materials[m].name);
        description.albedo = materials[m].albedo;
        description.emission = materials[m].emission;
        material[m] = scene_builder_material(builder, &description);
        if (material[m] == UINT32_MAX)
            goto nomem;
    }
    for (size_t q = 0; q < sizeof(quads) / sizeof(quads[0]); q++) {
        uint32_t surface = scene_builder_surface(builder, quads[q].surface);
        if (surface == UINT32_MAX)
            goto nomem;
        rad_vec3 p[4];
        for (int k = 0; k < 4; k++)
            p[k] = v3(quads[q].v[k][0], quads[q].v[k][1], quads[q].v[k][2]);
        status = scene_builder_triangle(builder, surface, material[quads[q].material], p[0],
                                        p[1], p[2], error);
        if (status == RAD_OK)
            status = scene_builder_triangle(builder, surface, material[quads[q].material],
                                            p[0], p[2], p[3], error);
        if (status != RAD_OK) {
            scene_builder_destroy(builder);
            return status;
        }
    }
    rad_camera camera = {v3(278, 273, -800), v3(278, 273, 0), v3(0, 1, 0),
                         2.0 * atan(12.5 / 35.0) * 180.0 / RAD_PI};
    scene_builder_set_camera(builder, &camera);
    return scene_builder_finish(builder, out, error);
nomem:
    scene_builder_destroy(builder);
    return rad_fail(error, RAD_ERR_NOMEM, "(built-in Cornell box): out of memory");
}
