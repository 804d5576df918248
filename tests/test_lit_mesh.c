/*
 * test_lit_mesh.c - `radiosity solve -o OUT`: the lit mesh in .glb, .ply and .obj.
 *
 * References, each independent of the writers under test:
 *   - the vertex radiances the library computes in this process (scene, mesh, form
 *     factors, solve, rad_reconstruct_vertices, with the tool's default settings): every
 *     file must carry them, and the geometry must be the mesh's, read back through this
 *     test's own .glb parser (cJSON and the binary chunk), its own PLY and OBJ readers, and
 *     Assimp (rad_scene_load);
 *   - the display colour recomputed here from the PNG rule (95th percentile of the lit
 *     vertices' luminance to 0.9, clamp, the sRGB curve written out below);
 *   - the glTF rules a validator checks: 4-byte alignment, chunk and buffer lengths,
 *     POSITION min/max equal to the data, unit normals, colours in [0,1];
 *   - physics: in the furnace (every face Kd 0.5, Ke 1) every vertex radiance is
 *     Le / (1 - rho) = 2 within 0.5 %;
 *   - creases: vertices at one position on two walls keep different radiances;
 *   - illuminance (the CLI passes the patch inputs): in the furnace every vertex has
 *     pi x 2 (the radiance 2 arriving from the whole hemisphere) within 0.5 %; in the
 *     Cornell box the per-patch irradiance (B - E) / rho computed here from the patch
 *     inputs, through rad_reconstruct_vertices, times pi; a floor under a point light
 *     (library calls) against E = I h / (h^2 + r^2)^(3/2), and radiance = rho / pi x
 *     illuminance on its grey floor; files written without inputs hold no illuminance
 *     and keep today's exact layout; a wrong patch count and non-finite inputs refused.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "testlib.h"

#define PI 3.14159265358979323846
#define CORNELL_PATCH_SIZE 100.0
#define FLOAT_RELATIVE 1e-6 /* a double stored as float, or printed with 9 digits */

/* What the library computes for a scene: the tool's defaults, in this process. */
typedef struct reference {
    rad_scene *scene;
    rad_mesh *mesh;
    rad_rgb *radiance; /* per mesh vertex */
    rad_rgb *illuminance; /* per mesh vertex: the irradiance from the patch inputs */
    rad_patch_inputs *inputs;
    rad_rgb *B;
    uint32_t (*triangles)[3];
    uint32_t triangle_count;
    double scale; /* the automatic exposure, recomputed here */
} reference;

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double luminance(rad_rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

/* IEC 61966-2-1, on [0,1]. */
static double srgb(double linear)
{
    linear = fmin(fmax(linear, 0), 1);
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
}

static double display(double radiance, double scale) { return fmin(fmax(radiance * scale, 0), 1); }

static void compute_reference(const char *scene_path, double patch_size, reference *ref)
{
    rad_error error;
    memset(ref, 0, sizeof(*ref));
    rad_status status = scene_path ? rad_scene_load(scene_path, NULL, &ref->scene, &error)
                                   : rad_scene_cornell_box(&ref->scene, &error);
    /* no shadow refinement: every cell a quad or triangle of the uniform split, so the
     * expected vertex and triangle counts below are the mesh's own (the T-vertices a
     * refined mesh makes are test_seams' subject) */
    if (status == RAD_OK)
        status = test_mesh_uniform(ref->scene, patch_size, &ref->mesh, &error);
    rad_rgb *B = calloc(ref->mesh ? ref->mesh->patch_count : 1, sizeof(*B));
    rad_scene_solve_options solve = {.solver = RAD_SOLVER_JACOBI, .seed = 1};
    if (status == RAD_OK)
        status = rad_solve_scene(ref->scene, ref->mesh, &solve, B, NULL, &error);
    if (status != RAD_OK) {
        fprintf(stderr, "reference: %s\n", error.message);
        exit(1);
    }
    if (rad_patch_inputs_build(ref->scene, ref->mesh, &ref->inputs, &error) != RAD_OK) {
        fprintf(stderr, "reference inputs: %s\n", error.message);
        exit(1);
    }
    uint32_t n = ref->mesh->vertex_count;
    ref->radiance = calloc(n, sizeof(*ref->radiance));
    rad_reconstruct_vertices(ref->mesh, B, ref->radiance);
    /* the light arriving at each patch: B = E + rho x (incident), per channel */
    rad_rgb *irradiance = calloc(ref->mesh->patch_count, sizeof(*irradiance));
    for (uint32_t p = 0; p < ref->mesh->patch_count; p++) {
        const double b[3] = {B[p].r, B[p].g, B[p].b};
        const rad_rgb *in_E = &ref->inputs->exitance[p], *in_rho = &ref->inputs->albedo[p],
                      *in_H = &ref->inputs->direct[p];
        const double e[3] = {in_E->r, in_E->g, in_E->b}, rho[3] = {in_rho->r, in_rho->g, in_rho->b},
                     h[3] = {in_H->r, in_H->g, in_H->b};
        double out[3];
        for (int k = 0; k < 3; k++)
            out[k] = rho[k] > 0 ? fmax((b[k] - e[k]) / rho[k], 0) : h[k];
        irradiance[p] = (rad_rgb){out[0], out[1], out[2]};
    }
    ref->illuminance = calloc(n, sizeof(*ref->illuminance));
    rad_reconstruct_vertices(ref->mesh, irradiance, ref->illuminance);
    for (uint32_t v = 0; v < n; v++) /* rad_reconstruct_vertices gives value / pi */
        ref->illuminance[v] = (rad_rgb){PI * ref->illuminance[v].r,
                                        PI * ref->illuminance[v].g,
                                        PI * ref->illuminance[v].b};
    free(irradiance);
    ref->triangles = calloc(2 * (size_t)ref->mesh->patch_count, sizeof(*ref->triangles));
    for (uint32_t p = 0; p < ref->mesh->patch_count; p++) {
        const rad_patch *patch = &ref->mesh->patches[p];
        uint32_t *t = ref->triangles[ref->triangle_count++];
        t[0] = patch->vertex[0], t[1] = patch->vertex[1], t[2] = patch->vertex[2];
        if (patch->vertex_count == 4) {
            t = ref->triangles[ref->triangle_count++];
            t[0] = patch->vertex[0], t[1] = patch->vertex[2], t[2] = patch->vertex[3];
        }
    }
    double *lit = calloc(n, sizeof(*lit));
    size_t count = 0;
    for (uint32_t v = 0; v < n; v++)
        if (luminance(ref->radiance[v]) > 0)
            lit[count++] = luminance(ref->radiance[v]);
    qsort(lit, count, sizeof(*lit), compare_doubles);
    double position = 0.95 * (double)(count - 1);
    size_t below = (size_t)position;
    double quantile = lit[below];
    if (below + 1 < count)
        quantile += (position - (double)below) * (lit[below + 1] - lit[below]);
    ref->scale = 0.9 / quantile;
    free(lit);
    ref->B = B;
}

static void free_reference(reference *ref)
{
    free(ref->radiance);
    free(ref->illuminance);
    free(ref->B);
    rad_patch_inputs_destroy(ref->inputs);
    free(ref->triangles);
    rad_mesh_destroy(ref->mesh);
    rad_scene_destroy(ref->scene);
}

/* |a - b| within FLOAT_RELATIVE of the larger magnitude (or of 1e-30 near zero). */
static bool same_float(double a, double b)
{
    return fabs(a - b) <= FLOAT_RELATIVE * fmax(fmax(fabs(a), fabs(b)), 1e-30);
}

static bool same_rgb(const float *f, rad_rgb c)
{
    return same_float(f[0], c.r) && same_float(f[1], c.g) && same_float(f[2], c.b);
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float get_f32(const uint8_t *p)
{
    uint32_t bits = get_u32(p);
    float v;
    memcpy(&v, &bits, sizeof(v));
    return v;
}

static int json_int(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(item) ? item->valueint : -1;
}

/* The accessor `index` of a float VEC3 or uint SCALAR: its data in BIN, checked. */
static const uint8_t *accessor_data(const cJSON *json, int index, const uint8_t *bin,
                                    size_t bin_length, uint32_t *count, int component,
                                    const char *type)
{
    const cJSON *accessor = cJSON_GetArrayItem(cJSON_GetObjectItem(json, "accessors"), index);
    CHECK(accessor != NULL);
    if (!accessor)
        return NULL;
    CHECK(json_int(accessor, "componentType") == component);
    const cJSON *type_item = cJSON_GetObjectItem(accessor, "type");
    CHECK(cJSON_IsString(type_item) && strcmp(type_item->valuestring, type) == 0);
    *count = (uint32_t)json_int(accessor, "count");
    const cJSON *view = cJSON_GetArrayItem(cJSON_GetObjectItem(json, "bufferViews"),
                                           json_int(accessor, "bufferView"));
    CHECK(view != NULL);
    if (!view)
        return NULL;
    int offset = json_int(view, "byteOffset"), length = json_int(view, "byteLength");
    int element = strcmp(type, "VEC3") == 0 ? 12 : 4;
    CHECK(offset >= 0 && offset % 4 == 0);
    CHECK(length == element * (int)*count);
    CHECK((size_t)offset + (size_t)length <= bin_length);
    if (offset < 0 || (size_t)offset + (size_t)length > bin_length)
        return NULL;
    return bin + offset;
}

/* Reads x.glb back by hand and checks it against the reference and the glTF rules;
 * `illuminance`: whether it must have _ILLUMINANCE (the reference's), or must not. */
static void check_glb(const char *name, const reference *ref, bool illuminance)
{
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    CHECK(bytes != NULL && size >= 28);
    if (!bytes || size < 28)
        return;
    CHECK(memcmp(bytes, "glTF", 4) == 0);
    CHECK(get_u32(bytes + 4) == 2);
    CHECK(get_u32(bytes + 8) == size);
    uint32_t json_length = get_u32(bytes + 12);
    CHECK(memcmp(bytes + 16, "JSON", 4) == 0);
    CHECK(json_length % 4 == 0 && 20 + json_length + 8 <= size);
    const uint8_t *bin_header = bytes + 20 + json_length;
    uint32_t bin_length = get_u32(bin_header);
    CHECK(memcmp(bin_header + 4, "BIN\0", 4) == 0);
    CHECK(bin_length % 4 == 0 && 20 + json_length + 8 + bin_length == size);
    const uint8_t *bin = bin_header + 8;
    cJSON *json = cJSON_ParseWithLength((const char *)bytes + 20, json_length);
    CHECK(json != NULL);
    if (!json) {
        free(bytes);
        return;
    }
    const cJSON *asset = cJSON_GetObjectItem(json, "asset");
    CHECK(cJSON_IsString(cJSON_GetObjectItem(asset, "version")) &&
          strcmp(cJSON_GetObjectItem(asset, "version")->valuestring, "2.0") == 0);
    const cJSON *buffer = cJSON_GetArrayItem(cJSON_GetObjectItem(json, "buffers"), 0);
    CHECK(json_int(buffer, "byteLength") == (int)bin_length);
    const cJSON *primitive = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(json, "meshes"), 0),
                            "primitives"),
        0);
    const cJSON *attributes = cJSON_GetObjectItem(primitive, "attributes");
    CHECK(json_int(primitive, "mode") == 4 || cJSON_GetObjectItem(primitive, "mode") == NULL);
    const cJSON *used = cJSON_GetObjectItem(json, "extensionsUsed");
    CHECK(cJSON_IsArray(used) &&
          strcmp(cJSON_GetArrayItem(used, 0)->valuestring, "KHR_materials_unlit") == 0);

    uint32_t n = ref->mesh->vertex_count, count;
    const uint8_t *position = accessor_data(json, json_int(attributes, "POSITION"), bin,
                                            bin_length, &count, 5126, "VEC3");
    CHECK(count == n);
    const uint8_t *normal = accessor_data(json, json_int(attributes, "NORMAL"), bin, bin_length,
                                          &count, 5126, "VEC3");
    CHECK(count == n);
    const uint8_t *colour = accessor_data(json, json_int(attributes, "COLOR_0"), bin,
                                          bin_length, &count, 5126, "VEC3");
    CHECK(count == n);
    const uint8_t *radiance = accessor_data(json, json_int(attributes, "_RADIANCE"), bin,
                                            bin_length, &count, 5126, "VEC3");
    CHECK(count == n);
    const uint8_t *illuminance_data = NULL;
    CHECK((cJSON_GetObjectItem(attributes, "_ILLUMINANCE") != NULL) == illuminance);
    if (illuminance) {
        illuminance_data = accessor_data(json, json_int(attributes, "_ILLUMINANCE"), bin,
                                         bin_length, &count, 5126, "VEC3");
        CHECK(count == n && illuminance_data != NULL);
        /* five vertex views and the indices: the buffer holds all of them, nothing else */
        CHECK(bin_length == 5 * 12 * n + 12 * ref->triangle_count);
    } else {
        CHECK(bin_length == 4 * 12 * n + 12 * ref->triangle_count);
    }
    const uint8_t *indices = accessor_data(json, json_int(primitive, "indices"), bin,
                                           bin_length, &count, 5125, "SCALAR");
    CHECK(count == 3 * ref->triangle_count);
    if (!position || !normal || !colour || !radiance || !indices ||
        count != 3 * ref->triangle_count || (illuminance && !illuminance_data)) {
        cJSON_Delete(json);
        free(bytes);
        return;
    }

    /* POSITION: the mesh's vertices, and min/max exactly those of the data */
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t bad_position = 0, bad_normal = 0, bad_colour = 0, bad_radiance = 0;
    uint32_t bad_illuminance = 0;
    for (uint32_t v = 0; v < n; v++) {
        float p[3], nn[3], c[3], L[3], E[3];
        for (int k = 0; k < 3; k++) {
            p[k] = get_f32(position + 12 * v + 4 * k);
            nn[k] = get_f32(normal + 12 * v + 4 * k);
            c[k] = get_f32(colour + 12 * v + 4 * k);
            L[k] = get_f32(radiance + 12 * v + 4 * k);
            E[k] = illuminance ? get_f32(illuminance_data + 12 * v + 4 * k) : 0;
            lo[k] = fminf(lo[k], p[k]);
            hi[k] = fmaxf(hi[k], p[k]);
        }
        rad_vec3 q = ref->mesh->vertices[v];
        bad_position += !(p[0] == (float)q.x && p[1] == (float)q.y && p[2] == (float)q.z);
        bad_normal += fabs(sqrt((double)nn[0] * nn[0] + (double)nn[1] * nn[1] +
                                (double)nn[2] * nn[2]) - 1) > 1e-6;
        rad_rgb Lr = ref->radiance[v];
        bad_radiance += !same_rgb(L, Lr);
        bad_illuminance += illuminance && !same_rgb(E, ref->illuminance[v]);
        rad_rgb d = {display(Lr.r, ref->scale), display(Lr.g, ref->scale),
                     display(Lr.b, ref->scale)};
        bad_colour += !same_rgb(c, d) || c[0] < 0 || c[0] > 1 || c[1] < 0 || c[1] > 1 ||
                      c[2] < 0 || c[2] > 1;
    }
    printf("%s: %u vertices, %u triangles; mismatches: position %u, normal %u, colour %u, "
           "radiance %u, illuminance %u%s\n",
           name, n, ref->triangle_count, bad_position, bad_normal, bad_colour, bad_radiance,
           bad_illuminance, illuminance ? "" : " (none written)");
    CHECK(bad_illuminance == 0);
    CHECK(bad_position == 0);
    CHECK(bad_normal == 0);
    CHECK(bad_colour == 0);
    CHECK(bad_radiance == 0);
    const cJSON *accessor = cJSON_GetArrayItem(cJSON_GetObjectItem(json, "accessors"),
                                               json_int(attributes, "POSITION"));
    const cJSON *min = cJSON_GetObjectItem(accessor, "min"), *max = cJSON_GetObjectItem(accessor, "max");
    CHECK(cJSON_GetArraySize(min) == 3 && cJSON_GetArraySize(max) == 3);
    for (int k = 0; k < 3; k++) {
        CHECK((float)cJSON_GetArrayItem(min, k)->valuedouble == lo[k]);
        CHECK((float)cJSON_GetArrayItem(max, k)->valuedouble == hi[k]);
    }
    /* triangles: the renderer's, in patch order */
    uint32_t bad_index = 0;
    for (uint32_t t = 0; t < ref->triangle_count; t++)
        for (int k = 0; k < 3; k++)
            bad_index += get_u32(indices + 12 * t + 4 * k) != ref->triangles[t][k];
    CHECK(bad_index == 0);

    /* creases stay sharp: some vertices share a position with another vertex (two walls
     * meet there) yet keep a clearly different radiance */
    uint32_t sharp = 0;
    for (uint32_t a = 0; a < n && sharp == 0; a++)
        for (uint32_t b = a + 1; b < n; b++)
            if (memcmp(position + 12 * a, position + 12 * b, 12) == 0) {
                double la = luminance(ref->radiance[a]), lb = luminance(ref->radiance[b]);
                if (fabs(la - lb) > 0.2 * fmax(la, lb))
                    sharp++;
            }
    CHECK(sharp > 0);
    cJSON_Delete(json);
    free(bytes);
}

/* Assimp (rad_scene_load) reads the file: same triangles at the same places, within
 * `tolerance` scene units of the mesh's points rounded to float (0: exactly those). */
static void check_geometry_through_assimp(const char *name, const reference *ref,
                                          double tolerance)
{
    rad_scene *scene = NULL;
    rad_error error;
    CHECK(rad_scene_load(test_path(name), NULL, &scene, &error) == RAD_OK);
    if (!scene) {
        fprintf(stderr, "%s: %s\n", name, error.message);
        return;
    }
    CHECK(scene->triangle_count == ref->triangle_count);
    /* each loaded triangle is one of the reference's, corner for corner (the loader may
     * order triangles by surface; here there is one surface, so the order is kept) */
    uint32_t matched = 0;
    for (uint32_t t = 0; t < scene->triangle_count && t < ref->triangle_count; t++) {
        bool same = true;
        for (int k = 0; k < 3; k++) {
            rad_vec3 a = scene->positions[scene->triangles[t].vertex[k]];
            rad_vec3 b = ref->mesh->vertices[ref->triangles[t][k]];
            same = same && fabs(a.x - (float)b.x) <= tolerance &&
                   fabs(a.y - (float)b.y) <= tolerance && fabs(a.z - (float)b.z) <= tolerance;
        }
        matched += same;
    }
    printf("%s through Assimp: %u of %u triangles match\n", name, matched, ref->triangle_count);
    CHECK(matched == ref->triangle_count);
    rad_scene_destroy(scene);
}

/* A PLY as this writer makes it: the header line by line, then the binary records;
 * `illuminance`: whether the records end with the reference's illuminance, or have none. */
static void check_ply(const char *name, const reference *ref, bool furnace, bool illuminance)
{
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    CHECK(bytes != NULL);
    if (!bytes)
        return;
    const char *end = strstr((const char *)bytes, "end_header\n");
    CHECK(end != NULL);
    if (!end) {
        free(bytes);
        return;
    }
    size_t header = (size_t)(end - (const char *)bytes) + strlen("end_header\n");
    char expected_elements[512];
    snprintf(expected_elements, sizeof(expected_elements),
             "element vertex %u\n"
             "property float x\nproperty float y\nproperty float z\n"
             "property float nx\nproperty float ny\nproperty float nz\n"
             "property uchar red\nproperty uchar green\nproperty uchar blue\n"
             "property float radiance_r\nproperty float radiance_g\nproperty float radiance_b\n"
             "%s"
             "element face %u\nproperty list uchar int vertex_indices\n",
             ref->mesh->vertex_count,
             illuminance ? "property float illuminance_r\nproperty float illuminance_g\n"
                           "property float illuminance_b\n"
                         : "",
             ref->triangle_count);
    CHECK(strncmp((const char *)bytes, "ply\nformat binary_little_endian 1.0\n", 36) == 0);
    CHECK(strstr((const char *)bytes, expected_elements) != NULL);
    uint32_t n = ref->mesh->vertex_count;
    size_t vertex_bytes = illuminance ? 51 : 39, face_bytes = 13;
    CHECK((strstr((const char *)bytes, "illuminance") != NULL) == illuminance);
    CHECK(size == header + n * vertex_bytes + ref->triangle_count * face_bytes);
    if (size != header + n * vertex_bytes + ref->triangle_count * face_bytes) {
        free(bytes);
        return;
    }
    uint32_t bad_position = 0, bad_colour = 0, bad_radiance = 0, bad_face = 0, off_furnace = 0;
    uint32_t bad_illuminance = 0, off_furnace_illuminance = 0;
    double worst = 0; /* largest |L - 2| / 2 in the furnace */
    double worst_illuminance = 0; /* largest |E - 2 pi| / (2 pi) in the furnace */
    for (uint32_t v = 0; v < n; v++) {
        const uint8_t *r = bytes + header + v * vertex_bytes;
        rad_vec3 q = ref->mesh->vertices[v];
        bad_position += !(get_f32(r) == (float)q.x && get_f32(r + 4) == (float)q.y &&
                          get_f32(r + 8) == (float)q.z);
        rad_rgb L = ref->radiance[v];
        float stored[3] = {get_f32(r + 27), get_f32(r + 31), get_f32(r + 35)};
        bad_radiance += !same_rgb(stored, L);
        if (illuminance) {
            float E[3] = {get_f32(r + 39), get_f32(r + 43), get_f32(r + 47)};
            bad_illuminance += !same_rgb(E, ref->illuminance[v]);
            /* (B - E) / rho turns B's error dB into dB / (B - E) relative: here B - E = B / 2,
             * so twice B's relative error, and twice its 0.5 % bound */
            for (int k = 0; k < 3; k++) {
                off_furnace_illuminance += furnace && fabs(E[k] - 2 * PI) > 0.01 * 2 * PI;
                worst_illuminance = fmax(worst_illuminance, fabs(E[k] - 2 * PI) / (2 * PI));
            }
        }
        double channel[3] = {L.r, L.g, L.b};
        for (int k = 0; k < 3; k++) {
            int expected = (int)lround(255 * srgb(display(channel[k], ref->scale)));
            bad_colour += abs((int)r[24 + k] - expected) > 0; /* the same rounding */
            off_furnace += furnace && fabs(stored[k] - 2.0) > 0.005 * 2.0;
            worst = fmax(worst, fabs(stored[k] - 2.0) / 2.0);
        }
    }
    for (uint32_t t = 0; t < ref->triangle_count; t++) {
        const uint8_t *f = bytes + header + n * vertex_bytes + t * face_bytes;
        bad_face += f[0] != 3;
        for (int k = 0; k < 3; k++)
            bad_face += get_u32(f + 1 + 4 * k) != ref->triangles[t][k];
    }
    printf("%s: %u vertices; mismatches: position %u, colour %u, radiance %u, illuminance "
           "%u%s, face %u%s\n",
           name, n, bad_position, bad_colour, bad_radiance, bad_illuminance,
           illuminance ? "" : " (none written)", bad_face, furnace ? "" : " (not the furnace)");
    CHECK(bad_illuminance == 0);
    CHECK(bad_position == 0);
    CHECK(bad_colour == 0);
    CHECK(bad_radiance == 0);
    CHECK(bad_face == 0);
    if (furnace) {
        printf("%s: %u channels off Le / (1 - rho) = 2 by over 0.5 %%, %u illuminance "
               "channels off pi x 2 by over 1 %%; largest deviation %.2e relative "
               "(illuminance %.2e)\n",
               name, off_furnace, off_furnace_illuminance, worst, worst_illuminance);
        CHECK(off_furnace_illuminance == 0);
        CHECK(off_furnace == 0);
    }
    free(bytes);
}

/* The OBJ: `v x y z r g b`, then `#radiance R G B` per vertex in the same order, each
 * followed by `#illuminance R G B` when `illuminance` (the reference's), else none. */
static void check_obj(const char *name, const reference *ref, double scale, bool illuminance)
{
    FILE *f = fopen(test_path(name), "r");
    CHECK(f != NULL);
    if (!f)
        return;
    char line[512];
    uint32_t v = 0, radiance_lines = 0, faces = 0, bad_colour = 0, bad_radiance = 0;
    uint32_t illuminance_lines = 0, bad_illuminance = 0;
    bool described = false, after_radiance = false;
    while (fgets(line, sizeof(line), f)) {
        double x, y, z, r, g, b;
        if (strncmp(line, "# v x y z r g b:", 16) == 0)
            described = true;
        if (sscanf(line, "v %lf %lf %lf %lf %lf %lf", &x, &y, &z, &r, &g, &b) == 6) {
            if (v < ref->mesh->vertex_count) {
                rad_rgb L = ref->radiance[v];
                bad_colour += fabs(r - srgb(display(L.r, scale))) > 1e-6 ||
                              fabs(g - srgb(display(L.g, scale))) > 1e-6 ||
                              fabs(b - srgb(display(L.b, scale))) > 1e-6;
            }
            v++;
        } else if (sscanf(line, "#radiance %lf %lf %lf", &r, &g, &b) == 3) {
            if (radiance_lines < ref->mesh->vertex_count) {
                float stored[3] = {(float)r, (float)g, (float)b};
                bad_radiance += !same_rgb(stored, ref->radiance[radiance_lines]);
            }
            radiance_lines++;
            after_radiance = true;
            continue;
        } else if (sscanf(line, "#illuminance %lf %lf %lf", &r, &g, &b) == 3) {
            /* right after its vertex's #radiance line */
            bad_illuminance += !after_radiance || illuminance_lines + 1 != radiance_lines;
            if (illuminance_lines < ref->mesh->vertex_count) {
                float stored[3] = {(float)r, (float)g, (float)b};
                bad_illuminance += !same_rgb(stored, ref->illuminance[illuminance_lines]);
            }
            illuminance_lines++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            faces++;
        }
        after_radiance = false;
    }
    fclose(f);
    printf("%s: %u v lines, %u #radiance lines, %u #illuminance lines, %u faces; mismatches: "
           "colour %u, radiance %u, illuminance %u\n",
           name, v, radiance_lines, illuminance_lines, faces, bad_colour, bad_radiance,
           bad_illuminance);
    CHECK(illuminance_lines == (illuminance ? ref->mesh->vertex_count : 0));
    CHECK(bad_illuminance == 0);
    CHECK(described);
    CHECK(v == ref->mesh->vertex_count);
    CHECK(radiance_lines == ref->mesh->vertex_count);
    CHECK(faces == ref->triangle_count);
    CHECK(bad_colour == 0);
    CHECK(bad_radiance == 0);
}

/* ---- illuminance through the library: files read back by name, not by this writer's layout */

/* A float VEC3 attribute of a .glb's first primitive, malloc'd; NULL when it has none. */
static float *glb_attribute(const char *name, const char *attribute, uint32_t *count)
{
    *count = 0;
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    if (!bytes || size < 28) {
        free(bytes);
        return NULL;
    }
    uint32_t json_length = get_u32(bytes + 12);
    const uint8_t *bin_header = bytes + 20 + json_length;
    cJSON *json = 20 + (size_t)json_length + 8 <= size
                      ? cJSON_ParseWithLength((const char *)bytes + 20, json_length)
                      : NULL;
    float *values = NULL;
    const cJSON *attributes = cJSON_GetObjectItem(
        cJSON_GetArrayItem(
            cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(json, "meshes"), 0),
                                "primitives"),
            0),
        "attributes");
    if (cJSON_GetObjectItem(attributes, attribute)) {
        uint32_t n = 0;
        const uint8_t *data = accessor_data(json, json_int(attributes, attribute), bin_header + 8,
                                            get_u32(bin_header), &n, 5126, "VEC3");
        if (data) {
            values = calloc(3 * (size_t)n + 1, sizeof(*values));
            for (size_t k = 0; k < 3 * (size_t)n; k++)
                values[k] = get_f32(data + 4 * k);
            *count = n;
        }
    }
    cJSON_Delete(json);
    free(bytes);
    return values;
}

/* The numbers of every OBJ comment line `TAG R G B` (tag with its '#'), malloc'd. */
static float *obj_comments(const char *name, const char *tag, uint32_t *count)
{
    *count = 0;
    FILE *f = fopen(test_path(name), "r");
    if (!f)
        return NULL;
    size_t capacity = 1024;
    float *values = calloc(3 * capacity, sizeof(*values));
    char line[512];
    float r, g, b;
    size_t tag_length = strlen(tag);
    while (fgets(line, sizeof(line), f))
        if (strncmp(line, tag, tag_length) == 0 && line[tag_length] == ' ' &&
            sscanf(line + tag_length, "%f %f %f", &r, &g, &b) == 3) {
            if (*count == capacity) {
                capacity *= 2;
                values = realloc(values, 3 * capacity * sizeof(*values));
            }
            values[3 * *count] = r, values[3 * *count + 1] = g, values[3 * *count + 2] = b;
            (*count)++;
        }
    fclose(f);
    return values;
}

#define FLOOR_HALF 3.0        /* the floor: [-3, 3] x [-3, 3] at y = 0, facing +y */
#define FLOOR_PATCH 0.1       /* 60 x 60 square patches */
#define FLOOR_INNER 2.0       /* vertices checked: |x|, |z| <= 2, a metre from every edge */
#define LAMP_HEIGHT 2.0       /* a 100 cd point light at (0, 2, 0) */
#define LAMP_CANDELA 100.0
#define FLOOR_ALBEDO 0.5      /* the default material: grey */
/* A vertex holds the area-weighted mean of its four patches' mean irradiance, i.e. the mean
 * of E over the square of side 2a (a = FLOOR_PATCH) around it: E + a^2/6 lap E + O(a^4).
 * For E = I h / (h^2 + r^2)^(3/2), lap E / E = (9 r^2 - 6 h^2) / (h^2 + r^2)^2, largest in
 * size at r = 0: -6 / h^2, so the vertex is low by a^2 / h^2 = 0.25 % at most; each
 * patch's H itself is an 8 x 8 point mean (under 0.1 % here). 2 % leaves room for both and
 * still fails for any wrong factor (pi, rho, a missing bounce weight). */
#define FLOOR_BOUND 0.02

/* E = I h / (h^2 + r^2)^(3/2) below the lamp. */
static double floor_illuminance(rad_vec3 p)
{
    double r2 = p.x * p.x + p.z * p.z;
    return LAMP_CANDELA * LAMP_HEIGHT / pow(LAMP_HEIGHT * LAMP_HEIGHT + r2, 1.5);
}

/* Checks a floor file's vertex values: illuminance against the closed form inside, and
 * radiance = rho / pi x illuminance at every vertex; returns the worst relative error. */
static double check_floor_values(const char *label, const rad_mesh *mesh, const float *radiance,
                                 uint32_t radiance_count, const float *illuminance,
                                 uint32_t illuminance_count)
{
    CHECK(radiance != NULL && illuminance != NULL);
    CHECK(radiance_count == mesh->vertex_count && illuminance_count == mesh->vertex_count);
    if (!radiance || !illuminance || radiance_count != mesh->vertex_count ||
        illuminance_count != mesh->vertex_count)
        return HUGE_VAL;
    double worst = 0, worst_ratio = 0;
    uint32_t checked = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        rad_vec3 p = mesh->vertices[v];
        for (int k = 0; k < 3; k++) {
            double E = illuminance[3 * v + k], L = radiance[3 * v + k];
            double expected_L = FLOOR_ALBEDO / PI * E;
            worst_ratio = fmax(worst_ratio, fabs(L - expected_L) / fmax(expected_L, 1e-30));
            if (fabs(p.x) <= FLOOR_INNER && fabs(p.z) <= FLOOR_INNER)
                worst = fmax(worst, fabs(E - floor_illuminance(p)) / floor_illuminance(p));
        }
        checked += fabs(p.x) <= FLOOR_INNER && fabs(p.z) <= FLOOR_INNER;
    }
    printf("%s: %u inner vertices, illuminance worst %.2e relative to I h / (h^2 + r^2)^1.5; "
           "radiance vs rho / pi x illuminance worst %.2e relative\n",
           label, checked, worst, worst_ratio);
    CHECK(checked >= 41 * 41);
    CHECK(worst < FLOOR_BOUND);
    CHECK(worst_ratio < FLOAT_RELATIVE);
    return worst;
}

static void write_ok(const rad_mesh *mesh, const rad_rgb *B, const char *name,
                     const rad_lit_mesh_options *options)
{
    rad_error error = {0};
    rad_status status = rad_lit_mesh_write(mesh, B, test_path(name), options, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK)
        fprintf(stderr, "%s: %s\n", name, error.message);
}

/* A lone floor under a point light, written with the patch inputs in all three formats. */
static void test_floor_under_point_light(void)
{
    char text[256];
    snprintf(text, sizeof(text), "o floor\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nf 1 2 3 4\n",
             -FLOOR_HALF, FLOOR_HALF, FLOOR_HALF, FLOOR_HALF, FLOOR_HALF, -FLOOR_HALF,
             -FLOOR_HALF, -FLOOR_HALF);
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_error error = {0};
    rad_light lamp = {.type = RAD_LIGHT_POINT, .position = {0, LAMP_HEIGHT, 0},
                      .intensity = {LAMP_CANDELA, LAMP_CANDELA, LAMP_CANDELA}};
    rad_status status = rad_scene_load(test_write_file("floor.obj", text), NULL, &scene, &error);
    if (status == RAD_OK)
        status = rad_scene_add_light(scene, &lamp, &error);
    if (status == RAD_OK)
        status = rad_mesh_build(scene, FLOOR_PATCH, &mesh, &error);
    if (status == RAD_OK)
        status = rad_patch_inputs_build(scene, mesh, &inputs, &error);
    rad_rgb *B = calloc(mesh ? mesh->patch_count : 1, sizeof(*B));
    rad_scene_solve_options solve = {.solver = RAD_SOLVER_JACOBI, .threads = 2, .inputs = inputs};
    if (status == RAD_OK)
        status = rad_solve_scene(scene, mesh, &solve, B, NULL, &error);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "floor: %s\n", error.message);
        exit(1);
    }
    uint32_t grey = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        grey += inputs->albedo[p].r == FLOOR_ALBEDO && inputs->albedo[p].g == FLOOR_ALBEDO &&
                inputs->albedo[p].b == FLOOR_ALBEDO;
    CHECK(grey == mesh->patch_count);
    printf("floor: %u patches, %u vertices\n", mesh->patch_count, mesh->vertex_count);

    rad_lit_mesh_options options = {.inputs = inputs};
    write_ok(mesh, B, "floor.ply", &options);
    write_ok(mesh, B, "floor.glb", &options);
    write_ok(mesh, B, "floor.obj.obj", &options);
    static const char *const radiance_names[3] = {"radiance_r", "radiance_g", "radiance_b"};
    static const char *const illuminance_names[3] = {"illuminance_r", "illuminance_g",
                                                     "illuminance_b"};
    uint32_t nL, nE;
    float *L = test_ply_vertex_floats("floor.ply", radiance_names, &nL);
    float *E = test_ply_vertex_floats("floor.ply", illuminance_names, &nE);
    check_floor_values("floor.ply", mesh, L, nL, E, nE);
    free(L);
    free(E);
    L = glb_attribute("floor.glb", "_RADIANCE", &nL);
    E = glb_attribute("floor.glb", "_ILLUMINANCE", &nE);
    check_floor_values("floor.glb", mesh, L, nL, E, nE);
    free(L);
    free(E);
    L = obj_comments("floor.obj.obj", "#radiance", &nL);
    E = obj_comments("floor.obj.obj", "#illuminance", &nE);
    check_floor_values("floor.obj", mesh, L, nL, E, nE);
    free(L);
    free(E);

    /* the light computed at the vertices (the scene given): the lamp by a shadow ray at a
     * point a tenth of the way to the vertex's patches' mean centre, which for an inner
     * vertex (four patches around it) is the vertex itself; nothing gathered (a lone floor
     * sees nothing): the closed form to float rounding (measured 5.4e-8), where the patch
     * means are 2.5e-3 off */
    rad_lit_mesh_options at_vertices = {.inputs = inputs, .scene = scene, .threads = 2};
    write_ok(mesh, B, "floor_vertex.ply", &at_vertices);
    L = test_ply_vertex_floats("floor_vertex.ply", radiance_names, &nL);
    E = test_ply_vertex_floats("floor_vertex.ply", illuminance_names, &nE);
    CHECK(check_floor_values("floor_vertex.ply", mesh, L, nL, E, nE) < 1e-6);
    free(L);
    free(E);

    /* a black floor reflects nothing (B = 0): its vertices show the lamp's direct light
     * alone, which on a lone floor is all the light there is */
    rad_rgb *black = calloc(mesh->patch_count, sizeof(*black));
    rad_patch_inputs dark = *inputs;
    dark.albedo = black;
    rad_lit_mesh_options dark_options = {.inputs = &dark};
    write_ok(mesh, black, "black.ply", &dark_options);
    E = test_ply_vertex_floats("black.ply", illuminance_names, &nE);
    CHECK(E != NULL && nE == mesh->vertex_count);
    double worst_black = 0;
    for (uint32_t v = 0; E && v < nE && v < mesh->vertex_count; v++)
        if (fabs(mesh->vertices[v].x) <= FLOOR_INNER && fabs(mesh->vertices[v].z) <= FLOOR_INNER)
            worst_black = fmax(worst_black, fabs(E[3 * v + 1] - floor_illuminance(mesh->vertices[v])) /
                                                floor_illuminance(mesh->vertices[v]));
    printf("black.ply: illuminance (H alone) worst %.2e relative to the closed form\n",
           worst_black);
    CHECK(worst_black < FLOOR_BOUND);
    free(E);

    /* without inputs: no illuminance in any format */
    write_ok(mesh, B, "plain.ply", NULL);
    write_ok(mesh, B, "plain.glb", &(rad_lit_mesh_options){0});
    write_ok(mesh, B, "plain.obj", NULL);
    E = test_ply_vertex_floats("plain.ply", illuminance_names, &nE);
    CHECK(E == NULL);
    free(E);
    E = glb_attribute("plain.glb", "_ILLUMINANCE", &nE);
    CHECK(E == NULL);
    free(E);
    E = obj_comments("plain.obj", "#illuminance", &nE);
    CHECK(nE == 0);
    free(E);
    CHECK(!strstr(test_read_text(test_path("plain.obj")), "illuminance"));

    free(black);
    free(B);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

/* The Cornell box through the library without inputs: today's exact files; with inputs
 * of the wrong size, or non-finite ones, refused and nothing written. */
static void test_library_cornell(const reference *ref)
{
    write_ok(ref->mesh, ref->B, "plain_cornell.ply", NULL);
    write_ok(ref->mesh, ref->B, "plain_cornell.glb", NULL);
    write_ok(ref->mesh, ref->B, "plain_cornell.obj", NULL);
    check_ply("plain_cornell.ply", ref, false, false);
    check_glb("plain_cornell.glb", ref, false);
    check_obj("plain_cornell.obj", ref, ref->scale, false);
    rad_lit_mesh_options with = {.inputs = ref->inputs};
    write_ok(ref->mesh, ref->B, "with_cornell.ply", &with);
    check_ply("with_cornell.ply", ref, false, true);

    const char *names[3] = {"refused.ply", "refused.glb", "refused.obj"};
    uint32_t n = ref->mesh->patch_count, k = n / 3;
    rad_rgb *albedo = calloc(n, sizeof(*albedo)), *exitance = calloc(n, sizeof(*exitance)),
            *direct = calloc(n, sizeof(*direct));
    for (int f = 0; f < 3; f++) {
        const char *path = test_path(names[f]);
        rad_error error = {0};
        char expected[64];
        /* a patch count other than the mesh's */
        rad_patch_inputs wrong = *ref->inputs;
        wrong.n = n - 1;
        rad_lit_mesh_options options = {.inputs = &wrong};
        CHECK(rad_lit_mesh_write(ref->mesh, ref->B, path, &options, &error) == RAD_ERR_INVALID);
        snprintf(expected, sizeof(expected), "have %u patches, the mesh %u", n - 1, n);
        printf("%s\n", error.message);
        CHECK(strstr(error.message, path) != NULL && strstr(error.message, expected) != NULL);
        CHECK(!test_file_exists(path));

        /* a NaN exitance on a patch that reflects: its irradiance is not finite */
        memcpy(albedo, ref->inputs->albedo, n * sizeof(*albedo));
        memcpy(exitance, ref->inputs->exitance, n * sizeof(*exitance));
        memcpy(direct, ref->inputs->direct, n * sizeof(*direct));
        CHECK(albedo[k].g > 0);
        exitance[k].g = NAN;
        rad_patch_inputs bad = *ref->inputs;
        bad.albedo = albedo, bad.exitance = exitance, bad.direct = direct;
        options.inputs = &bad;
        memset(&error, 0, sizeof(error));
        CHECK(rad_lit_mesh_write(ref->mesh, ref->B, path, &options, &error) == RAD_ERR_INVALID);
        snprintf(expected, sizeof(expected), "patch %u has an irradiance", k);
        printf("%s\n", error.message);
        CHECK(strstr(error.message, path) != NULL && strstr(error.message, expected) != NULL);
        CHECK(!test_file_exists(path));
        /* a black patch whose direct light is infinite */
        exitance[k].g = ref->inputs->exitance[k].g;
        albedo[k].b = 0;
        direct[k].b = INFINITY;
        memset(&error, 0, sizeof(error));
        CHECK(rad_lit_mesh_write(ref->mesh, ref->B, path, &options, &error) == RAD_ERR_INVALID);
        CHECK(strstr(error.message, expected) != NULL);
        CHECK(!test_file_exists(path));
        /* and a finite one is written */
        direct[k].b = 1;
        CHECK(rad_lit_mesh_write(ref->mesh, ref->B, path, &options, &error) == RAD_OK);
        CHECK(test_file_exists(path));
    }
    free(albedo);
    free(exitance);
    free(direct);
}

static void run_ok(const char *arguments)
{
    int code = test_run_tool(arguments);
    CHECK(code == 0);
    if (code != 0)
        fprintf(stderr, "radiosity %s: exit %d: %s", arguments, code,
                test_read_text(test_path("stderr.txt")));
}

/* The default lit mesh: the light computed at every vertex (as the default render does),
 * in the furnace: the emitters' direct light from the whole hemisphere, pi x Le = pi, and
 * the gathered reflected light, pi x (2 - 1) = pi, so every vertex has the radiance
 * Le + rho / pi x 2 pi = 2 and the illuminance 2 pi, up to the Monte-Carlo estimates'
 * noise (1024 light samples MIS with 512 cosine rays, 1024 gather rays; measured
 * 2026-12-02, the worst of 3 x 486 vertex channels: radiance within 0.50 %, illuminance
 * within 1.01 %; a wrong factor, a missing bounce or the sharp-light path counting the
 * emitters twice would be off by 25 % or more). */
static void check_furnace_vertex_light(const reference *furnace)
{
    run_ok("solve furnace.obj -o furnace_vertex.ply --patch-size 0.125 --shadow-levels 0");
    static const char *const radiance_names[3] = {"radiance_r", "radiance_g", "radiance_b"};
    static const char *const illuminance_names[3] = {"illuminance_r", "illuminance_g",
                                                     "illuminance_b"};
    uint32_t nL = 0, nE = 0;
    float *L = test_ply_vertex_floats("furnace_vertex.ply", radiance_names, &nL);
    float *E = test_ply_vertex_floats("furnace_vertex.ply", illuminance_names, &nE);
    /* the box's creases split its patches next to them for display (light_refine.h): the
     * mesh's own vertices come first, then the pieces' */
    CHECK(L != NULL && E != NULL && nL >= furnace->mesh->vertex_count && nE == nL);
    double worst_L = 0, worst_E = 0, differ = 0;
    for (uint32_t v = 0; L && E && v < nL && v < nE; v++)
        for (int k = 0; k < 3; k++) {
            worst_L = fmax(worst_L, fabs(L[3 * v + k] - 2.0) / 2.0);
            worst_E = fmax(worst_E, fabs(E[3 * v + k] - 2 * PI) / (2 * PI));
            /* computed at the vertex, not the patches' mean: not the same numbers */
            if (v < furnace->mesh->vertex_count)
                differ = fmax(differ, fabs(L[3 * v + k] - (&furnace->radiance[v].r)[k]));
        }
    printf("furnace_vertex.ply (the light at the vertices): radiance within %.2e of 2, "
           "illuminance within %.2e of 2 pi (relative); largest difference from the patch "
           "means %.2e\n",
           worst_L, worst_E, differ);
    CHECK(worst_L < 0.01);
    CHECK(worst_E < 0.02);
    CHECK(differ > 0);
    free(L);
    free(E);
}

int main(void)
{
    /* the Cornell box: three formats, one solution */
    reference cornell;
    compute_reference(NULL, CORNELL_PATCH_SIZE, &cornell);
    run_ok("solve -o cornell.glb --patch-size 100 --shadow-levels 0 --direct solution");
    run_ok("solve -o cornell.ply --patch-size 100 --shadow-levels 0 --direct solution");
    run_ok("solve -o cornell.obj --patch-size 100 --shadow-levels 0 --direct solution");
    check_glb("cornell.glb", &cornell, true);
    check_geometry_through_assimp("cornell.glb", &cornell, 0);
    check_ply("cornell.ply", &cornell, false, true);
    check_geometry_through_assimp("cornell.ply", &cornell, 0);
    check_obj("cornell.obj", &cornell, cornell.scale, true);
    /* 9 significant digits of coordinates up to 560 mm */
    check_geometry_through_assimp("cornell.obj", &cornell, 1e-6 * 560);
    test_library_cornell(&cornell);
    free_reference(&cornell);

    /* the furnace: radiance 2 everywhere; a uniform mesh exposes to 0.9 exactly */
    test_write_furnace("furnace.obj");
    reference furnace;
    compute_reference(test_path("furnace.obj"), 0.125, &furnace);
    run_ok("solve furnace.obj -o furnace.ply --patch-size 0.125 --shadow-levels 0 --direct solution");
    check_ply("furnace.ply", &furnace, true, true);
    run_ok("solve furnace.obj -o furnace.obj.obj --patch-size 0.125 --exposure -3 --shadow-levels 0 --direct solution");
    check_obj("furnace.obj.obj", &furnace, 0.125, true); /* 2^-3 */
    check_furnace_vertex_light(&furnace);
    free_reference(&furnace);

    test_floor_under_point_light();

    /* refusals: a usage error, no file left */
    CHECK(test_run_tool("solve -o out.stl") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "out.stl: unknown mesh format"));
    CHECK(test_run_tool("solve") == 2);
    CHECK(test_run_tool("solve -o nowhere/out.glb") == 1);
    CHECK(test_count_files("out") == 0);
    return test_finish("test_lit_mesh");
}
