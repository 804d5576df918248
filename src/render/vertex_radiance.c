/*
 * vertex_radiance.c - the radiance at a solution's display vertices from the light
 * computed there (vertex_radiance.h).
 */
#include "render/vertex_radiance.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "parallel/ranks.h"
#include "render/vertex_light.h"

bool vertex_radiance_applies(const rad_scene *scene)
{
    return scene && (rad_scene_has_emitter(scene) || scene->light_count > 0);
}

double vertex_radiance_leave(const rad_mesh *mesh)
{
    if (mesh->vertex_count == 0)
        return RAD_SURFACE_LEAVE_DIAGONAL;
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    double diagonal = v3_length(v3_sub(hi, lo));
    double largest = fmax(fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fabs(lo.y), fabs(hi.y))),
                          fmax(fabs(lo.z), fabs(hi.z)));
    return RAD_SURFACE_LEAVE_DIAGONAL * diagonal + RAD_SURFACE_LEAVE_COORDINATE * largest;
}

bool vertex_radiance_reflected(const rad_mesh *mesh, const display_mesh *display,
                               const rad_rgb *B, const rad_rgb *exitance,
                               const uint8_t *hidden, rad_rgb *reflected)
{
    rad_rgb *outgoing = rad_alloc_array(mesh->patch_count ? mesh->patch_count : 1,
                                        sizeof(*outgoing));
    if (!outgoing)
        return false;
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        outgoing[p] = rgb_max0(rgb_add(B[p], rgb_scale(exitance[p], -1)));
    bool made = display_mesh_radiance_weighted(mesh, display, outgoing, hidden, reflected);
    free(outgoing);
    return made;
}

rad_status vertex_radiance(const vertex_radiance_job *job, rad_rgb *radiance,
                           rad_rgb *irradiance, rad_error *error)
{
    const rad_mesh *mesh = job->mesh;
    const display_mesh *display = job->display;
    uint32_t n = mesh->patch_count ? mesh->patch_count : 1;
    size_t vertices = display->vertex_count ? display->vertex_count : 1;
    rad_rgb *factor = rad_alloc_array(n, sizeof(*factor));
    rad_rgb *emission = rad_alloc_array(n, sizeof(*emission));
    rad_rgb *vertex_factor = rad_alloc_array(vertices, sizeof(*vertex_factor));
    rad_rgb *vertex_emission = rad_alloc_array(vertices, sizeof(*vertex_emission));
    rad_rgb *direct = rad_alloc_array(vertices, sizeof(*direct));
    rad_rgb *gathered = rad_alloc_array(vertices, sizeof(*gathered));
    rad_status status = RAD_OK;
    if (!factor || !emission || !vertex_factor || !vertex_emission || !direct || !gathered) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
        goto agree;
    }
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        bool holds_irradiance =
            job->irradiance || patch_material_textured(job->lookup, mesh->patches[p].material);
        factor[p] = holds_irradiance ? (rad_rgb){1, 1, 1} : job->inputs->albedo[p];
        emission[p] = holds_irradiance ? (rad_rgb){0, 0, 0} : job->inputs->exitance[p];
    }
    if (!display_mesh_radiance_weighted(mesh, NULL, factor, job->hidden, vertex_factor) ||
        !display_mesh_radiance_weighted(mesh, NULL, emission, job->hidden, vertex_emission))
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
agree: /* over ranks every rank goes on to the (collective) light at the vertices, or none */
    if (job->over_ranks)
        status = ranks_agree(status, "render", error);
    if (status != RAD_OK)
        goto done;
    const emitter_set none = {0};
    status = vertex_light(job->gathered_only ? &none : job->emitters, job->scene, mesh,
                          job->scene_tracer, job->view, job->sharp, job->hidden, job->leave,
                          job->seed, job->threads, job->over_ranks, direct, gathered, error);
    if (status != RAD_OK)
        goto done;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        rad_rgb incident = rgb_add(direct[v], gathered[v]);
        radiance[v] = rgb_add(vertex_emission[v], rgb_mul(vertex_factor[v], incident));
        if (irradiance)
            irradiance[v] = incident;
    }
    display_mesh_constrain(mesh, display, radiance);
    if (irradiance)
        display_mesh_constrain(mesh, display, irradiance);
done:
    free(factor);
    free(emission);
    free(vertex_factor);
    free(vertex_emission);
    free(direct);
    free(gathered);
    return status;
}

rad_status vertex_radiance_of_solution(const rad_mesh *mesh, const display_mesh *display,
                                       const rad_rgb *B, const rad_scene *scene,
                                       const rad_patch_inputs *inputs, uint64_t seed,
                                       int threads, rad_rgb *radiance, rad_rgb *irradiance,
                                       rad_error *error)
{
    uint32_t n = mesh->patch_count ? mesh->patch_count : 1;
    size_t vertices = display->vertex_count ? display->vertex_count : 1;
    rad_vec3 *positions = rad_alloc_array(vertices, sizeof(*positions));
    uint8_t *hidden = rad_alloc_array(n, sizeof(*hidden));
    rad_rgb *reflected = rad_alloc_array(vertices, sizeof(*reflected));
    rad_tracer *tracer = NULL, *scene_tracer = NULL;
    emitter_set emitters = {0};
    light_set lights;
    rad_status status = RAD_OK;
    if (!positions || !hidden || !reflected) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
        goto done;
    }
    double leave = vertex_radiance_leave(mesh);
    display_mesh_positions(mesh, display, positions);
    /* the tracer sees the front patches (their twins' display triangles come after) */
    status = rad_tracer_create(RAD_TRACER_EMBREE, positions, display->vertex_count,
                               (const uint32_t(*)[3])display->triangles,
                               display_mesh_front_triangles(mesh, display), &tracer, error);
    if (status == RAD_OK)
        status = emitters_build(scene, &emitters, error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &scene_tracer, error);
    if (status != RAD_OK)
        goto done;
    /* what the gather rays meet: the reflected light (B - E) / pi at the vertices */
    display_hidden_patches(mesh, tracer, leave, hidden, NULL, 0);
    if (!vertex_radiance_reflected(mesh, display, B, inputs->exitance, hidden, reflected)) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
        goto done;
    }
    light_set_init(&lights, scene);
    bool any_lights = scene->light_count > 0;
    gather_view view = {mesh,      (const uint32_t(*)[3])display->triangles,
                        display->patch_of, reflected,
                        B,         inputs->exitance,
                        any_lights ? &lights : NULL, tracer};
    vertex_radiance_job job = {
        .mesh = mesh,
        .display = display,
        .scene = scene,
        .inputs = inputs,
        .emitters = &emitters,
        .scene_tracer = scene_tracer,
        .view = &view,
        .sharp = any_lights && lights.sharp_count > 0 ? &lights : NULL,
        .hidden = hidden,
        .leave = leave,
        .seed = seed,
        .threads = threads,
    };
    status = vertex_radiance(&job, radiance, irradiance, error);
done:
    rad_tracer_destroy(tracer);
    rad_tracer_destroy(scene_tracer);
    emitters_free(&emitters);
    free(positions);
    free(hidden);
    free(reflected);
    return status;
}
