/*
 * scene_builder.c - see scene_builder.h.
 *
 * Triangles are collected with their three raw corners; positions are welded only in
 * finish(), by exact equality, so that importers which de-index faces (Assimp's OBJ reader)
 * still give the mesh stage shared vertices to find quads and shared edges with.
 */
#include "scene/scene_builder.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "core/weld.h"

typedef struct raw_triangle {
    rad_vec3 corner[3];
    float uv[3][2];
    bool has_uv;
    uint32_t material, surface;
    uint32_t order; /* position in the input: keeps the sort by surface stable */
} raw_triangle;

struct scene_builder {
    char source[512];
    rad_load_options options;
    raw_triangle *triangles;
    size_t triangle_count, triangle_capacity;
    rad_material *materials;
    size_t material_count, material_capacity;
    rad_surface *surfaces;
    size_t surface_count, surface_capacity;
    uint32_t *surface_slots; /* name hash table: surface index + 1, 0 = empty */
    size_t surface_slot_count;
    rad_texture *textures;
    size_t texture_count, texture_capacity;
    bool any_uv;
    bool has_camera;
    rad_camera camera;
    rad_vec3 up;
    double unit_metres;
};

rad_status scene_builder_create(const char *source, const rad_load_options *options,
                                scene_builder **out, rad_error *error)
{
    scene_builder *b = rad_alloc_array(1, sizeof(*b));
    if (!b)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", source);
    snprintf(b->source, sizeof(b->source), "%s", source);
    if (options)
        b->options = *options;
    b->up = (rad_vec3){0, 1, 0};
    *out = b;
    return RAD_OK;
}

void scene_builder_destroy(scene_builder *b)
{
    if (!b)
        return;
    free(b->triangles);
    free(b->materials);
    free(b->surfaces);
    free(b->surface_slots);
    for (size_t t = 0; t < b->texture_count; t++)
        free(b->textures[t].rgb);
    free(b->textures);
    free(b);
}

uint32_t scene_builder_material(scene_builder *b, const rad_material *material)
{
    if (b->material_count >= UINT32_MAX - 1 ||
        !rad_grow_array((void **)&b->materials, &b->material_capacity, b->material_count + 1,
                        sizeof(*b->materials)))
        return UINT32_MAX;
    b->materials[b->material_count] = *material;
    b->materials[b->material_count].name[sizeof(material->name) - 1] = 0;
    return (uint32_t)b->material_count++;
}

static uint64_t hash_name(const char *name)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a */
    for (; *name; name++)
        h = (h ^ (unsigned char)*name) * 1099511628211ull;
    return h;
}

static int grow_surface_slots(scene_builder *b)
{
    size_t count = b->surface_slot_count ? b->surface_slot_count * 2 : 64;
    uint32_t *slots = rad_alloc_array(count, sizeof(*slots));
    if (!slots)
        return 0;
    for (size_t i = 0; i < b->surface_count; i++) {
        size_t s = hash_name(b->surfaces[i].name) & (count - 1);
        while (slots[s])
            s = (s + 1) & (count - 1);
        slots[s] = (uint32_t)i + 1;
    }
    free(b->surface_slots);
    b->surface_slots = slots;
    b->surface_slot_count = count;
    return 1;
}

uint32_t scene_builder_surface(scene_builder *b, const char *name)
{
    char clipped[sizeof(b->surfaces[0].name)];
    snprintf(clipped, sizeof(clipped), "%s", name);
    if ((b->surface_count + 1) * 2 > b->surface_slot_count && !grow_surface_slots(b))
        return UINT32_MAX;
    size_t mask = b->surface_slot_count - 1;
    size_t s = hash_name(clipped) & mask;
    for (; b->surface_slots[s]; s = (s + 1) & mask)
        if (strcmp(b->surfaces[b->surface_slots[s] - 1].name, clipped) == 0)
            return b->surface_slots[s] - 1;
    if (b->surface_count >= UINT32_MAX - 1 ||
        !rad_grow_array((void **)&b->surfaces, &b->surface_capacity, b->surface_count + 1,
                        sizeof(*b->surfaces)))
        return UINT32_MAX;
    rad_surface *surface = &b->surfaces[b->surface_count];
    memset(surface, 0, sizeof(*surface));
    surface->emissivity = RAD_DEFAULT_EMISSIVITY;
    memcpy(surface->name, clipped, sizeof(clipped));
    b->surface_slots[s] = (uint32_t)b->surface_count + 1;
    return (uint32_t)b->surface_count++;
}

uint32_t scene_builder_find_surface(const scene_builder *b, const char *name)
{
    if (!b->surface_slot_count)
        return UINT32_MAX;
    char clipped[sizeof(b->surfaces[0].name)];
    snprintf(clipped, sizeof(clipped), "%s", name);
    size_t mask = b->surface_slot_count - 1;
    for (size_t s = hash_name(clipped) & mask; b->surface_slots[s]; s = (s + 1) & mask)
        if (strcmp(b->surfaces[b->surface_slots[s] - 1].name, clipped) == 0)
            return b->surface_slots[s] - 1;
    return UINT32_MAX;
}

void scene_builder_set_surface_flags(scene_builder *b, uint32_t surface, uint32_t flags)
{
    if (surface < b->surface_count)
        b->surfaces[surface].flags = flags;
}

void scene_builder_set_surface_emissivity(scene_builder *b, uint32_t surface, double emissivity)
{
    if (surface < b->surface_count)
        b->surfaces[surface].emissivity = emissivity;
}

rad_status scene_builder_triangle(scene_builder *b, uint32_t surface, uint32_t material,
                                  rad_vec3 a, rad_vec3 c1, rad_vec3 c2, rad_error *error)
{
    if (b->triangle_count >= UINT32_MAX - 1 ||
        !rad_grow_array((void **)&b->triangles, &b->triangle_capacity, b->triangle_count + 1,
                        sizeof(*b->triangles)))
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", b->source);
    raw_triangle *t = &b->triangles[b->triangle_count++];
    t->corner[0] = a;
    t->corner[1] = c1;
    t->corner[2] = c2;
    t->material = material;
    t->surface = surface;
    t->order = (uint32_t)(b->triangle_count - 1);
    t->has_uv = false;
    memset(t->uv, 0, sizeof(t->uv));
    return RAD_OK;
}

rad_status scene_builder_triangle_uv(scene_builder *b, uint32_t surface, uint32_t material,
                                     const rad_vec3 corner[3], const float uv[3][2],
                                     rad_error *error)
{
    rad_status status =
        scene_builder_triangle(b, surface, material, corner[0], corner[1], corner[2], error);
    if (status == RAD_OK) {
        raw_triangle *t = &b->triangles[b->triangle_count - 1];
        memcpy(t->uv, uv, sizeof(t->uv));
        t->has_uv = true;
        b->any_uv = true;
    }
    return status;
}

uint32_t scene_builder_texture(scene_builder *b, rad_texture *texture)
{
    if (b->texture_count >= UINT32_MAX - 1 ||
        !rad_grow_array((void **)&b->textures, &b->texture_capacity, b->texture_count + 1,
                        sizeof(*b->textures))) {
        free(texture->rgb);
        texture->rgb = NULL;
        return 0;
    }
    b->textures[b->texture_count++] = *texture;
    texture->rgb = NULL;
    return (uint32_t)b->texture_count;
}

void scene_builder_set_camera(scene_builder *b, const rad_camera *camera)
{
    b->has_camera = true;
    b->camera = *camera;
}

void scene_builder_set_frame(scene_builder *b, rad_vec3 up, double unit_metres)
{
    double length = v3_length(up);
    if (length > 0 && isfinite(length))
        b->up = v3_scale(up, 1 / length);
    b->unit_metres = unit_metres > 0 && isfinite(unit_metres) ? unit_metres : 0;
}

/* True when the triangle has no area relative to its size (collinear or repeated corners). */
static bool is_degenerate(const raw_triangle *t)
{
    rad_vec3 e0 = v3_sub(t->corner[1], t->corner[0]);
    rad_vec3 e1 = v3_sub(t->corner[2], t->corner[0]);
    rad_vec3 e2 = v3_sub(t->corner[2], t->corner[1]);
    double longest = fmax(v3_dot(e0, e0), fmax(v3_dot(e1, e1), v3_dot(e2, e2)));
    double twice_area = v3_length(v3_cross(e0, e1));
    return !(longest > 0) || twice_area <= RAD_DEGENERATE_RELATIVE_AREA * longest;
}

static int compare_surface(const void *a, const void *b)
{
    const raw_triangle *x = a, *y = b;
    if (x->surface != y->surface)
        return x->surface < y->surface ? -1 : 1;
    return (x->order > y->order) - (x->order < y->order);
}

/* Clamps *value into [0,1]; true when it had to. */
static bool clamp_unit(double *value)
{
    if (*value >= 0 && *value <= 1)
        return false;
    *value = *value > 1 ? 1 : 0; /* NaN becomes 0 */
    return true;
}

static void check_material(scene_builder *b, rad_material *m)
{
    double *albedo[3] = {&m->albedo.r, &m->albedo.g, &m->albedo.b};
    double *specular[3] = {&m->specular.r, &m->specular.g, &m->specular.b};
    double *emission[3] = {&m->emission.r, &m->emission.g, &m->emission.b};
    bool clamped = false, negative = false, clamped_specular = false;
    for (int c = 0; c < 3; c++) {
        clamped |= clamp_unit(albedo[c]);
        clamped_specular |= clamp_unit(specular[c]);
        if (!(*emission[c] >= 0 && *emission[c] <= FLT_MAX)) { /* powers stay finite */
            *emission[c] = 0;
            negative = true;
        }
    }
    if (!(m->shininess >= 0) || !isfinite(m->shininess))
        m->shininess = 0;
    if (clamped)
        rad_warn(b->options.log, b->options.log_user,
                 "%s: material '%s': albedo outside [0,1] clamped", b->source, m->name);
    if (clamped_specular)
        rad_warn(b->options.log, b->options.log_user,
                 "%s: material '%s': specular reflectance outside [0,1] clamped", b->source,
                 m->name);
    if (negative)
        rad_warn(b->options.log, b->options.log_user,
                 "%s: material '%s': negative or invalid emission set to 0", b->source,
                 m->name);
}

rad_status scene_builder_finish(scene_builder *b, rad_scene **out, rad_error *error)
{
    rad_status status = RAD_OK;
    rad_scene *scene = NULL;
    uint32_t *skipped = NULL;
    rad_weld weld = {0};
    *out = NULL;

    for (size_t t = 0; t < b->triangle_count; t++)
        for (int k = 0; k < 3; k++)
            if (!v3_is_finite(b->triangles[t].corner[k])) {
                status = rad_fail(error, RAD_ERR_PARSE,
                                  "%s: surface '%s': a vertex has a non-finite coordinate",
                                  b->source, b->surfaces[b->triangles[t].surface].name);
                goto done;
            }
    /* Rays are traced in single precision: squared lengths must neither underflow nor
     * overflow. */
    double largest = 0, lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < b->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            const double *c = &b->triangles[t].corner[k].x;
            for (int a = 0; a < 3; a++) {
                largest = fmax(largest, fabs(c[a]));
                lo[a] = fmin(lo[a], c[a]);
                hi[a] = fmax(hi[a], c[a]);
            }
        }
    double extent = b->triangle_count ? fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2])) : 1;
    if (largest > RAD_LARGEST_COORDINATE || extent < RAD_SMALLEST_EXTENT) {
        status = rad_fail(error, RAD_ERR_INVALID,
                          "%s: the scene spans %g units with coordinates up to %g: beyond what "
                          "single-precision ray tracing resolves (extent at least %g, "
                          "coordinates at most %g); rescale it",
                          b->source, extent, largest, RAD_SMALLEST_EXTENT, RAD_LARGEST_COORDINATE);
        goto done;
    }
    for (size_t m = 0; m < b->material_count; m++)
        check_material(b, &b->materials[m]);

    skipped = rad_alloc_array(b->surface_count, sizeof(*skipped));
    scene = rad_alloc_array(1, sizeof(*scene));
    if (!skipped || !scene || !rad_weld_init(&weld, (uint32_t)(b->triangle_count < UINT32_MAX / 4 ? b->triangle_count : UINT32_MAX / 4)))
        goto nomem;

    /* drop degenerate triangles, then order by surface */
    size_t kept = 0;
    for (size_t t = 0; t < b->triangle_count; t++) {
        if (is_degenerate(&b->triangles[t]))
            skipped[b->triangles[t].surface]++;
        else
            b->triangles[kept++] = b->triangles[t];
    }
    if (kept == 0) {
        size_t degenerate = b->triangle_count;
        status = degenerate ? rad_fail(error, RAD_ERR_PARSE,
                                       "%s: the scene has no usable triangles (%zu degenerate "
                                       "triangle%s skipped)",
                                       b->source, degenerate, degenerate == 1 ? "" : "s")
                            : rad_fail(error, RAD_ERR_PARSE,
                                       "%s: the scene has no triangles (is it a scene file?)",
                                       b->source);
        goto done;
    }
    qsort(b->triangles, kept, sizeof(*b->triangles), compare_surface);

    scene->triangles = rad_alloc_array(kept, sizeof(*scene->triangles));
    scene->surfaces = rad_alloc_array(b->surface_count, sizeof(*scene->surfaces));
    if (!scene->triangles || !scene->surfaces)
        goto nomem;
    if (b->any_uv) {
        scene->uv = rad_alloc_array(kept, sizeof(*scene->uv));
        if (!scene->uv)
            goto nomem;
        for (size_t t = 0; t < kept; t++)
            memcpy(scene->uv[t], b->triangles[t].uv, sizeof(scene->uv[t]));
    }
    /* a texture index out of range (a bug of a source) becomes no texture */
    for (size_t m = 0; m < b->material_count; m++) {
        if (b->materials[m].albedo_texture > b->texture_count)
            b->materials[m].albedo_texture = 0;
        if (b->materials[m].emission_texture > b->texture_count)
            b->materials[m].emission_texture = 0;
    }

    /* surfaces that kept triangles, renumbered in order of first appearance */
    uint32_t *surface_map = skipped; /* reuse after warning */
    for (size_t s = 0; s < b->surface_count; s++)
        if (skipped[s])
            rad_warn(b->options.log, b->options.log_user,
                     "%s: surface '%s': %u degenerate triangle%s skipped", b->source,
                     b->surfaces[s].name, skipped[s], skipped[s] == 1 ? "" : "s");
    for (size_t s = 0; s < b->surface_count; s++)
        surface_map[s] = UINT32_MAX;
    for (size_t t = 0; t < kept; t++) {
        raw_triangle *raw = &b->triangles[t];
        if (surface_map[raw->surface] == UINT32_MAX) {
            surface_map[raw->surface] = scene->surface_count;
            rad_surface *surface = &scene->surfaces[scene->surface_count++];
            *surface = b->surfaces[raw->surface];
            surface->first_triangle = (uint32_t)t;
            surface->triangle_count = 0;
        }
        rad_triangle *tri = &scene->triangles[t];
        tri->surface = surface_map[raw->surface];
        tri->material = raw->material;
        scene->surfaces[tri->surface].triangle_count++;
        for (int k = 0; k < 3; k++) {
            tri->vertex[k] = rad_weld_insert(&weld, 0, raw->corner[k]);
            if (tri->vertex[k] == UINT32_MAX)
                goto nomem;
        }
    }
    scene->triangle_count = (uint32_t)kept;
    scene->position_count = weld.count;
    scene->positions = rad_weld_take_positions(&weld);
    if (!scene->positions && kept)
        goto nomem;
    scene->materials = b->materials;
    scene->material_count = (uint32_t)b->material_count;
    b->materials = NULL;
    scene->textures = b->textures;
    scene->texture_count = (uint32_t)b->texture_count;
    b->textures = NULL;
    b->texture_count = 0;
    scene->has_camera = b->has_camera;
    scene->camera = b->camera;
    scene->up = b->up;
    scene->unit_metres = b->unit_metres;
    snprintf(scene->source, sizeof(scene->source), "%s", b->source);

    *out = scene;
    scene = NULL;
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", b->source);
done:
    rad_weld_free(&weld);
    free(skipped);
    rad_scene_destroy(scene);
    scene_builder_destroy(b);
    return status;
}
