/*
 * render.c - images of a radiosity solution.
 *
 * The patches are split into triangles (quads along their first diagonal) and handed to a
 * tracer; each pixel averages k x k jittered stratified primary rays (box filter). A hit
 * on a front face takes the radiance interpolated from the vertex values with the hit's
 * barycentrics; a back face or a miss is black. Random numbers come from (seed, pixel).
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "render/camera.h"

#define MAX_STRATA 16u

rad_status rad_render(const rad_mesh *mesh, const rad_rgb *B, const rad_camera *camera,
                      const rad_render_options *options, rad_image *image, rad_error *error)
{
    rad_render_options defaults = {0};
    if (!options)
        options = &defaults;
    uint32_t W = image->width, H = image->height;
    camera_frame frame;
    rad_status status = camera_frame_make(camera, W, H, &frame, error);
    if (status != RAD_OK)
        return status;
    unsigned spp = options->samples_per_pixel ? options->samples_per_pixel : 4;
    unsigned k = (unsigned)lround(sqrt((double)spp));
    k = k < 1 ? 1 : k > MAX_STRATA ? MAX_STRATA : k;
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();

    /* triangles of the patches, and the radiance at each vertex */
    size_t triangle_count = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        triangle_count += mesh->patches[p].vertex_count - 2;
    uint32_t (*triangles)[3] = rad_alloc_array(triangle_count, sizeof(*triangles));
    uint32_t *patch_of = rad_alloc_array(triangle_count, sizeof(*patch_of));
    rad_rgb *radiance = rad_alloc_array(mesh->vertex_count, sizeof(*radiance));
    rad_tracer *tracer = NULL;
    rad_ray *rays = NULL;
    rad_hit *hits = NULL;
    if (!triangles || !patch_of || !radiance || triangle_count > UINT32_MAX)
        goto nomem;
    size_t t = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        for (uint32_t s = 0; s + 2 < patch->vertex_count + 0u; s++) {
            triangles[t][0] = patch->vertex[0];
            triangles[t][1] = patch->vertex[s + 1];
            triangles[t][2] = patch->vertex[s + 2];
            patch_of[t++] = p;
        }
    }
    rad_reconstruct_vertices(mesh, B, radiance);
    status = rad_tracer_create(RAD_TRACER_EMBREE, mesh->vertices, mesh->vertex_count,
                               (const uint32_t(*)[3])triangles, (uint32_t)triangle_count,
                               &tracer, error);
    if (status != RAD_OK)
        goto done;

    rad_vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        rad_vec3 q = mesh->vertices[v];
        lo = v3(fmin(lo.x, q.x), fmin(lo.y, q.y), fmin(lo.z, q.z));
        hi = v3(fmax(hi.x, q.x), fmax(hi.y, q.y), fmax(hi.z, q.z));
    }
    double diagonal = mesh->vertex_count ? v3_length(v3_sub(hi, lo)) : 1;
    float t_near = (float)(RAD_CAMERA_NEAR * diagonal);

    size_t per_row = (size_t)W * k * k;
    rays = rad_alloc_array((size_t)threads * per_row, sizeof(*rays));
    hits = rad_alloc_array((size_t)threads * per_row, sizeof(*hits));
    if (!rays || !hits)
        goto nomem;

    uint32_t rows_done = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (uint32_t y = 0; y < H; y++) {
        int thread = omp_get_thread_num();
        rad_ray *row_rays = rays + (size_t)thread * per_row;
        rad_hit *row_hits = hits + (size_t)thread * per_row;
        for (uint32_t x = 0; x < W; x++) {
            rad_rng rng = rad_rng_seed(options->seed, y, x);
            for (unsigned s = 0; s < k * k; s++) {
                double px = x + ((s % k) + rad_rng_uniform(&rng)) / k;
                double py = y + ((s / k) + rad_rng_uniform(&rng)) / k;
                rad_vec3 d = v3_normalize(camera_direction(&frame, px, py, W, H));
                rad_ray *ray = &row_rays[(size_t)x * k * k + s];
                ray->origin[0] = (float)frame.eye.x;
                ray->origin[1] = (float)frame.eye.y;
                ray->origin[2] = (float)frame.eye.z;
                ray->direction[0] = (float)d.x;
                ray->direction[1] = (float)d.y;
                ray->direction[2] = (float)d.z;
                ray->t_near = t_near;
                ray->t_far = INFINITY;
            }
        }
        rad_tracer_intersect(tracer, row_rays, (uint32_t)per_row, row_hits);
        for (uint32_t x = 0; x < W; x++) {
            double sum[3] = {0, 0, 0};
            for (unsigned s = 0; s < k * k; s++) {
                const rad_hit *hit = &row_hits[(size_t)x * k * k + s];
                if (hit->triangle == RAD_NO_HIT || !hit->front)
                    continue;
                const uint32_t *v = triangles[hit->triangle];
                double w0 = 1.0 - hit->u - hit->v, w1 = hit->u, w2 = hit->v;
                sum[0] += w0 * radiance[v[0]].r + w1 * radiance[v[1]].r + w2 * radiance[v[2]].r;
                sum[1] += w0 * radiance[v[0]].g + w1 * radiance[v[1]].g + w2 * radiance[v[2]].g;
                sum[2] += w0 * radiance[v[0]].b + w1 * radiance[v[1]].b + w2 * radiance[v[2]].b;
            }
            float *pixel = &image->rgb[((size_t)y * W + x) * 3];
            for (int c = 0; c < 3; c++)
                pixel[c] = (float)(sum[c] / (k * k));
        }
        uint32_t done;
#pragma omp atomic capture
        done = ++rows_done;
        if (thread == 0 && options->progress)
            options->progress(options->progress_user, "render", (double)done / H);
    }
    if (options->progress)
        options->progress(options->progress_user, "render", 1);
    goto done;
nomem:
    status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for rendering");
done:
    rad_tracer_destroy(tracer);
    free(triangles);
    free(patch_of);
    free(radiance);
    free(rays);
    free(hits);
    return status;
}
