/*
 * scene_files.c - several mesh files as one scene, each file one surface; and setting a
 * surface's flags by name afterwards (the command line's --obstruction, --two-sided).
 *
 * Each file is loaded on its own (so every format check of rad_scene_load applies), then
 * its triangles are handed to one scene builder under the file's base name.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "scene/scene_builder.h"

/* "dir/north.wall.stl" -> "north.wall" */
static void base_name(const char *path, char *name, size_t size)
{
    const char *slash = strrchr(path, '/');
    const char *start = slash ? slash + 1 : path;
    const char *dot = strrchr(start, '.');
    size_t n = dot && dot != start ? (size_t)(dot - start) : strlen(start);
    if (n >= size)
        n = size - 1;
    memcpy(name, start, n);
    name[n] = 0;
}

/* The builder surface for a name no earlier file used; UINT32_MAX with *error set. */
static uint32_t new_surface(scene_builder *builder, const char *path, const char *name,
                            rad_status *status, rad_error *error)
{
    if (scene_builder_find_surface(builder, name) != UINT32_MAX) {
        *status = rad_fail(error, RAD_ERR_INVALID,
                           "%s: surface name '%s' is also used by an earlier file (a file "
                           "given whole is named after its base name)",
                           path, name);
        return UINT32_MAX;
    }
    uint32_t surface = scene_builder_surface(builder, name);
    if (surface == UINT32_MAX)
        *status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    return surface;
}

static rad_status append_file(scene_builder *builder, const rad_scene_file *file,
                              const rad_load_options *options, rad_error *error)
{
    char name[sizeof(((rad_surface *)0)->name)];
    base_name(file->path, name, sizeof(name));
    if (!name[0])
        return rad_fail(error, RAD_ERR_INVALID, "%s: no file name to name the surface after",
                        file->path);
    rad_status status = RAD_OK;
    if (!file->keep_surfaces && scene_builder_find_surface(builder, name) != UINT32_MAX)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: surface name '%s' is also used by an earlier file (a file "
                        "given whole is named after its base name)",
                        file->path, name);
    rad_scene *part = NULL;
    status = rad_scene_load(file->path, options, &part, error);
    if (status != RAD_OK)
        return status;
    uint32_t *surface = rad_alloc_array(part->surface_count, sizeof(*surface));
    uint32_t first_material = UINT32_MAX;
    if (!surface)
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", file->path);
    for (uint32_t m = 0; m < part->material_count && status == RAD_OK; m++) {
        rad_material material = part->materials[m];
        material.albedo_texture = 0; /* textures are not carried over (see radiosity.h) */
        material.emission_texture = 0;
        uint32_t index = scene_builder_material(builder, &material);
        if (m == 0)
            first_material = index;
        if (index == UINT32_MAX)
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", file->path);
    }
    uint32_t whole = UINT32_MAX;
    if (status == RAD_OK && !file->keep_surfaces)
        whole = new_surface(builder, file->path, name, &status, error);
    for (uint32_t s = 0; s < part->surface_count && status == RAD_OK; s++) {
        const rad_surface *own = &part->surfaces[s];
        surface[s] = whole;
        if (file->keep_surfaces) {
            surface[s] = new_surface(builder, file->path, own->name, &status, error);
            scene_builder_set_surface_flags(builder, surface[s], own->flags | file->flags);
            scene_builder_set_surface_emissivity(builder, surface[s], own->emissivity);
        }
    }
    double area = 0, weighted = 0;
    for (uint32_t t = 0; t < part->triangle_count && status == RAD_OK; t++) {
        const rad_triangle *tri = &part->triangles[t];
        rad_vec3 a = part->positions[tri->vertex[0]], b = part->positions[tri->vertex[1]],
                 c = part->positions[tri->vertex[2]];
        double twice = v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        area += twice;
        weighted += twice * part->surfaces[tri->surface].emissivity;
        status = scene_builder_triangle(builder, surface[tri->surface],
                                        first_material + tri->material, a, b, c, error);
    }
    if (status == RAD_OK && !file->keep_surfaces) {
        scene_builder_set_surface_flags(builder, whole, file->flags);
        if (area > 0)
            scene_builder_set_surface_emissivity(builder, whole, weighted / area);
    }
    free(surface);
    rad_scene_destroy(part);
    return status;
}

rad_status rad_scene_load_files(const rad_scene_file *files, uint32_t count,
                                const rad_load_options *options, rad_scene **out,
                                rad_error *error)
{
    *out = NULL;
    if (count == 0)
        return rad_fail(error, RAD_ERR_INVALID, "no scene files given");
    scene_builder *builder = NULL;
    rad_status status = scene_builder_create(files[0].path, options, &builder, error);
    for (uint32_t f = 0; f < count && status == RAD_OK; f++)
        status = append_file(builder, &files[f], options, error);
    if (status != RAD_OK) {
        scene_builder_destroy(builder);
        return status;
    }
    return scene_builder_finish(builder, out, error);
}
