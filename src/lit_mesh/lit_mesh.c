/*
 * lit_mesh.c - rad_lit_mesh_write: the solution as a mesh with per-vertex radiance and
 * display colour, in .ply, .glb or .obj (the encoders are lit_mesh_ply.c, lit_mesh_glb.c
 * and lit_mesh_obj.c; see lit_mesh.h for why they are ours).
 *
 * Given the patch inputs, every vertex also carries the illuminance a lighting designer
 * reads. B_i = E_i + rho_i (H_i + sum_j F_ij B_j) makes the light arriving at patch i,
 * direct and interreflected, (B_i - E_i) / rho_i per channel; where rho_i = 0 the patch
 * reflects nothing and only its direct light H_i is known. That per-patch irradiance goes
 * through the radiance's own reconstruction (display_mesh_radiance gives value / pi per
 * vertex, so the result is multiplied by pi): one code path for both quantities.
 *
 * A two-sided surface needs nothing here: the mesh gives each side its own patches and
 * vertices (rad_patch.twin), wound to face their side, so the file holds both sides as
 * ordinary faces, each with its own colours and normals (a viewer that culls back faces
 * shows the side it faces; the .glb's material is single-sided, glTF's default).
 *
 * Everything that can fail without touching the disk is settled first; then the file is
 * written under a temporary name and renamed, so a failed write leaves nothing.
 */
#include "lit_mesh/lit_mesh.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/alloc.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "image/tonemap.h"
#include "reconstruct/display_mesh.h"
#include "render/light_refine.h"
#include "render/vertex_radiance.h"

typedef enum lit_mesh_format { FORMAT_UNKNOWN, FORMAT_PLY, FORMAT_GLB, FORMAT_OBJ } lit_mesh_format;

static lit_mesh_format format_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (!dot)
        return FORMAT_UNKNOWN;
    if (strcasecmp(dot, ".ply") == 0)
        return FORMAT_PLY;
    if (strcasecmp(dot, ".glb") == 0)
        return FORMAT_GLB;
    if (strcasecmp(dot, ".obj") == 0)
        return FORMAT_OBJ;
    return FORMAT_UNKNOWN;
}

void lit_mesh_describe_colour(const lit_mesh *mesh, char *text, size_t size)
{
    snprintf(text, size, "radiance x %.9g (%s), clamped to [0,1]", mesh->scale,
             mesh->automatic ? "automatic exposure: the 95th percentile of the lit vertices' "
                               "luminance at 0.9"
                             : "fixed exposure");
}

/* Vertex normals: each vertex lies in one smooth region, whose patches' normals differ by
 * under a degree, so their area-weighted mean is a sound unit normal. */
static void vertex_normals(const rad_mesh *mesh, rad_vec3 *normal)
{
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_vec3 *n = &normal[patch->vertex[k]];
            *n = v3_add(*n, v3_scale(patch->normal, patch->area));
        }
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        normal[v] = v3_length(normal[v]) > 0 ? v3_normalize(normal[v]) : v3(0, 0, 1);
}

/* One channel's irradiance of a patch: (B - E) / rho where rho > 0 (a negative value is
 * a rounding residue of B = E, written as 0), else the direct light H. NaN when an input
 * is not finite, so the caller refuses it. */
static double channel_irradiance(double B, double E, double rho, double H)
{
    if (!isfinite(rho))
        return NAN;
    double value = rho > 0 ? (B - E) / rho : H;
    return isfinite(value) ? fmax(value, 0) : NAN;
}

/* The per-patch irradiance (see the top of this file); RAD_ERR_INVALID naming the first
 * patch whose value is not finite. */
static rad_status patch_irradiance(const rad_mesh *mesh, const rad_rgb *B,
                                   const rad_patch_inputs *inputs, const char *path,
                                   rad_rgb *irradiance, rad_error *error)
{
    for (uint32_t i = 0; i < mesh->patch_count; i++) {
        rad_rgb E = inputs->exitance[i], rho = inputs->albedo[i], H = inputs->direct[i];
        rad_rgb value = {channel_irradiance(B[i].r, E.r, rho.r, H.r),
                         channel_irradiance(B[i].g, E.g, rho.g, H.g),
                         channel_irradiance(B[i].b, E.b, rho.b, H.b)};
        if (!(isfinite(value.r) && isfinite(value.g) && isfinite(value.b)))
            return rad_fail(error, RAD_ERR_INVALID,
                            "%s: patch %u has an irradiance that is not finite (its albedo, "
                            "exitance or direct light in the patch inputs); nothing was "
                            "written",
                            path, i);
        irradiance[i] = value;
    }
    return RAD_OK;
}

/* Writes the validated solution: `inputs` (NULL: built where needed) are the patch inputs
 * the light is computed with, `illuminance_wanted` whether the vertices carry it, `parent`
 * (NULL: the mesh is the solution's) the solution's patch of each of mesh's, `parents`
 * (NULL: every vertex gathers) where each vertex's gathered light comes from. */
static rad_status write_lit_mesh(const rad_mesh *mesh, const rad_rgb *B, const char *path,
                                 const rad_lit_mesh_options *options,
                                 const rad_patch_inputs *inputs, bool illuminance_wanted,
                                 const uint32_t *parent, const vertex_parents *parents,
                                 lit_mesh_format format, rad_error *error)
{
    /* the light computed at the vertices, as the default render shows it */
    bool vertex_light = options && options->direct_light != RAD_DIRECT_SOLUTION &&
                        vertex_radiance_applies(options->scene);
    rad_patch_inputs *built = NULL;
    rad_status status = RAD_OK;
    rad_vec3 *position = NULL, *normal = NULL;
    rad_rgb *radiance = NULL, *display = NULL, *irradiance = NULL, *illuminance = NULL;
    double *luminance = NULL;
    display_mesh shown = {0};
    status = display_mesh_build(mesh, true, &shown, error);
    if (status != RAD_OK)
        goto done;
    uint32_t n = shown.vertex_count; /* the mesh's vertices and the added ones */
    position = rad_alloc_array(n, sizeof(*position));
    normal = rad_alloc_array(n, sizeof(*normal));
    radiance = rad_alloc_array(n, sizeof(*radiance));
    display = rad_alloc_array(n, sizeof(*display));
    luminance = rad_alloc_array(n, sizeof(*luminance));
    if (!position || !normal || !radiance || !display || !luminance) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %u vertices", path, n);
        goto done;
    }
    display_mesh_positions(mesh, &shown, position);
    if (vertex_light) {
        if (illuminance_wanted)
            illuminance = rad_alloc_array(n, sizeof(*illuminance));
        const rad_patch_inputs *used = inputs;
        if (!used)
            status = rad_patch_inputs_build(options->scene, mesh, &built, error);
        if (status == RAD_OK && illuminance_wanted && !illuminance)
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the illuminance of "
                              "%u vertices", path, n);
        if (status == RAD_OK)
            status = vertex_radiance_of_solution(
                mesh, &shown, B, options->scene, used ? used : built, parents, options->seed,
                options->threads > 0 ? options->threads : omp_get_max_threads(), radiance,
                illuminance, error);
        if (status != RAD_OK)
            goto done;
        for (uint32_t v = 0; v < n; v++)
            if (!(isfinite(radiance[v].r) && isfinite(radiance[v].g) && isfinite(radiance[v].b)) ||
                (illuminance && !(isfinite(illuminance[v].r) && isfinite(illuminance[v].g) &&
                                  isfinite(illuminance[v].b)))) {
                status = rad_fail(error, RAD_ERR_INVALID,
                                  "%s: vertex %u has a radiance that is not finite; nothing "
                                  "was written",
                                  path, v);
                goto done;
            }
    } else if (!display_mesh_radiance(mesh, &shown, B, radiance)) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %u vertices", path, n);
        goto done;
    }
    if (illuminance_wanted && !vertex_light) {
        irradiance = rad_alloc_array(mesh->patch_count, sizeof(*irradiance));
        illuminance = rad_alloc_array(n, sizeof(*illuminance));
        if (!irradiance || !illuminance) {
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the illuminance of "
                              "%u vertices", path, n);
            goto done;
        }
        status = patch_irradiance(mesh, B, inputs, path, irradiance, error);
        if (status != RAD_OK)
            goto done;
        if (!display_mesh_radiance(mesh, &shown, irradiance, illuminance)) {
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %u vertices", path,
                              n);
            goto done;
        }
        for (uint32_t v = 0; v < n; v++) /* display_mesh_radiance divides by pi */
            illuminance[v] = rgb_scale(illuminance[v], RAD_PI);
    }
    vertex_normals(mesh, normal);
    for (uint32_t k = 0; k < shown.extra_count; k++) { /* along their edge, as the values */
        const display_extra *x = &shown.extras[k];
        rad_vec3 along = v3_add(v3_scale(normal[x->from], 1 - x->t), v3_scale(normal[x->to], x->t));
        normal[mesh->vertex_count + k] =
            v3_length(along) > 0 ? v3_normalize(along) : normal[x->from];
    }
    lit_mesh lit = {
        .vertex_count = n,
        .position = position,
        .normal = normal,
        .radiance = radiance,
        .illuminance = illuminance,
        .display = display,
        .triangles = (const uint32_t(*)[3])shown.triangles,
        .triangle_count = shown.triangle_count,
        .automatic = !options || !options->fixed_exposure,
    };
    if (lit.automatic) {
        for (uint32_t v = 0; v < n; v++)
            luminance[v] = rgb_luminance(radiance[v]);
        lit.scale = rad_tonemap_auto_scale(luminance, n);
    } else {
        lit.scale = exp2(options->exposure);
    }
    for (uint32_t v = 0; v < n; v++) {
        rad_rgb d = rgb_scale(radiance[v], lit.scale);
        display[v] = (rad_rgb){fmin(fmax(d.r, 0), 1), fmin(fmax(d.g, 0), 1),
                               fmin(fmax(d.b, 0), 1)};
    }

    rad_atomic_file file;
    status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        goto done;
    uint32_t *triangle_patch = NULL;
    if (options && options->triangle_patches) {
        /* the solution's patch of each triangle written (the pieces' parents) */
        triangle_patch = rad_alloc_array(shown.triangle_count ? shown.triangle_count : 1,
                                         sizeof(*triangle_patch));
        if (!triangle_patch) {
            rad_atomic_abort(&file);
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the patches of %u "
                              "triangles", path, shown.triangle_count);
            goto done;
        }
        for (uint32_t t = 0; t < shown.triangle_count; t++)
            triangle_patch[t] = parent ? parent[shown.patch_of[t]] : shown.patch_of[t];
    }
    switch (format) {
    case FORMAT_PLY: status = lit_mesh_write_ply(&lit, file.stream, path, error); break;
    case FORMAT_GLB: status = lit_mesh_write_glb(&lit, file.stream, path, error); break;
    case FORMAT_OBJ: status = lit_mesh_write_obj(&lit, file.stream, path, error); break;
    case FORMAT_UNKNOWN: status = rad_fail(error, RAD_ERR_INTERNAL, "%s: no writer", path);
    }
    if (status == RAD_OK)
        status = rad_atomic_commit(&file, error);
    else
        rad_atomic_abort(&file);
    if (status == RAD_OK && triangle_patch) {
        *options->triangle_patches = triangle_patch;
        *options->triangle_patch_count = shown.triangle_count;
    } else
        free(triangle_patch);
done:
    free(position);
    free(normal);
    free(radiance);
    free(display);
    free(luminance);
    free(irradiance);
    free(illuminance);
    rad_patch_inputs_destroy(built);
    display_mesh_free(&shown);
    return status;
}

rad_status rad_lit_mesh_write(const rad_mesh *mesh, const rad_rgb *B, const char *path,
                              const rad_lit_mesh_options *options, rad_error *error)
{
    if (!path || !*path)
        return rad_fail(error, RAD_ERR_INVALID, "rad_lit_mesh_write: no path");
    lit_mesh_format format = format_of(path);
    if (format == FORMAT_UNKNOWN)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: unknown mesh format (use .ply, .glb or .obj)", path);
    if (options && options->fixed_exposure && !isfinite(options->exposure))
        return rad_fail(error, RAD_ERR_INVALID, "%s: exposure %g is not a finite number", path,
                        options->exposure);
    /* a NaN or infinite radiosity is never written as a result */
    for (uint32_t i = 0; i < mesh->patch_count; i++)
        if (!(isfinite(B[i].r) && isfinite(B[i].g) && isfinite(B[i].b)))
            return rad_fail(error, RAD_ERR_INVALID,
                            "%s: patch %u has a radiosity that is not finite; nothing was "
                            "written",
                            path, i);
    const rad_patch_inputs *inputs = options ? options->inputs : NULL;
    if (inputs && inputs->n != mesh->patch_count)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: the patch inputs have %u patches, the mesh %u; nothing was "
                        "written",
                        path, inputs->n, mesh->patch_count);

    if (options && options->threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: thread count %d is negative", path,
                        options->threads);
    /* the light computed at the vertices, as the default render shows it, on a finer mesh
     * where the emitters' shadows bend it (light_refine.h) */
    bool vertex_light = options && options->direct_light != RAD_DIRECT_SOLUTION &&
                        vertex_radiance_applies(options->scene);
    if (!vertex_light)
        return write_lit_mesh(mesh, B, path, options, inputs, inputs != NULL, NULL, NULL,
                              format, error);
    light_refined refined;
    rad_status status = light_refine(options->scene, mesh, B, inputs,
                                     options->threads > 0 ? options->threads
                                                          : omp_get_max_threads(),
                                     &refined, error);
    if (status == RAD_OK)
        status = refined.mesh ? write_lit_mesh(refined.mesh, refined.B, path, options,
                                               refined.inputs, inputs != NULL, refined.parent,
                                               refined.parents, format, error)
                              : write_lit_mesh(mesh, B, path, options, inputs, inputs != NULL,
                                               NULL, NULL, format, error);
    light_refined_free(&refined);
    return status;
}
