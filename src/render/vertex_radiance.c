/*
 * vertex_radiance.c - the radiance at a solution's display vertices from the light
 * computed there (vertex_radiance.h).
 */
#include "render/vertex_radiance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/rgb.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "parallel/ranks.h"
#include "render/vertex_light.h"

#define CORRECTION_RAYS 128u                /* the second gather's rays per vertex */
#define CORRECTION_STREAM 0xC0EEEC7ull      /* keeps its random numbers apart */

bool vertex_radiance_applies(const rad_scene *scene)
{
    return scene && (rad_scene_has_emitter(scene) || scene->light_count > 0);
}

uint64_t rad_vertex_light_bytes(const rad_scene *scene, const rad_mesh *mesh)
{
    if (!mesh || !vertex_radiance_applies(scene))
        return 0;
    return (uint64_t)VERTEX_LIGHT_BYTES_PER_PATCH * mesh->patch_count;
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

/* The second gather (vertex_radiance.h): gathered[v] += what the change from the view's
 * reflected light to f_rho (direct + sharp + gathered) at the vertices brings. Collective
 * over ranks with job->over_ranks. */
static rad_status gather_correction(const vertex_radiance_job *job, const rad_rgb *direct,
                                    const rad_rgb *sharp, rad_rgb *gathered,
                                    rad_error *error)
{
    const rad_mesh *mesh = job->mesh;
    const display_mesh *display = job->display;
    size_t vertices = display->vertex_count ? display->vertex_count : 1;
    rad_rgb *change = rad_alloc_array(vertices, sizeof(*change));
    rad_rgb *added = rad_alloc_array(vertices, sizeof(*added));
    rad_status status = RAD_OK;
    if (!change || !added ||
        !display_mesh_radiance_weighted(mesh, NULL, job->inputs->albedo, job->hidden, change))
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
    if (job->over_ranks) /* every rank goes on to the (collective) gather, or none */
        status = ranks_agree(status, "render", error);
    if (status == RAD_OK) {
        for (uint32_t v = 0; v < mesh->vertex_count; v++) /* rho / pi x H, then the change */
            change[v] = rgb_mul(change[v], rgb_add(rgb_add(direct[v], sharp[v]), gathered[v]));
        display_mesh_constrain(mesh, display, change);
        for (uint32_t v = 0; v < display->vertex_count; v++)
            change[v] = rgb_add(change[v], rgb_scale(job->view->reflected[v], -1));
        gather_view view = *job->view;
        view.reflected = change;
        view.B = NULL;      /* the twins' backs: unchanged */
        view.lights = NULL; /* the sky: unchanged */
        const emitter_set none = {0};
        vertex_light_job light = {
            .emitters = &none,
            .scene = job->scene,
            .mesh = mesh,
            .occluders = job->scene_tracer,
            .view = &view,
            .gather_rays = CORRECTION_RAYS,
            .shown = job->shown,
            .unshown_part = 0, /* its light is shown by no pixel */
            .hidden = job->hidden,
            .parents = job->parents,
            .leave = job->leave,
            .seed = job->seed ^ CORRECTION_STREAM,
            .threads = job->threads,
            .over_ranks = job->over_ranks,
        };
        status = vertex_light(&light, NULL, NULL, added, error);
    }
    if (status == RAD_OK)
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            rgb_add_to(&gathered[v], added[v]);
    free(change);
    free(added);
    return status;
}

rad_status vertex_radiance(const vertex_radiance_job *job, rad_rgb *radiance,
                           rad_rgb *irradiance, rad_error *error)
{
    const rad_mesh *mesh = job->mesh;
    const display_mesh *display = job->display;
    size_t vertices = display->vertex_count ? display->vertex_count : 1;
    /* the light first, then what the vertices show: the fewest arrays held at a time */
    rad_rgb *direct = rad_alloc_array(vertices, sizeof(*direct));
    rad_rgb *sharp = rad_alloc_array(vertices, sizeof(*sharp));
    rad_rgb *incident = rad_alloc_array(vertices, sizeof(*incident));
    rad_rgb *vertex_factor = NULL, *vertex_emission = NULL;
    rad_status status = RAD_OK;
    if (!direct || !sharp || !incident)
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
    if (job->over_ranks) /* every rank goes on to the (collective) light, or none */
        status = ranks_agree(status, "render", error);
    if (status != RAD_OK)
        goto done;
    vertex_light_job light = {
        .emitters = job->emitters,
        .shadows = job->shadows,
        .sharp = job->sharp,
        .scene = job->scene,
        .mesh = mesh,
        .occluders = job->scene_tracer,
        .view = job->view,
        .gather_rays = VERTEX_GATHER_RAYS,
        .shown = job->shown,
        .unshown_part = VERTEX_UNSHOWN_PART,
        .hidden = job->hidden,
        .parents = job->parents,
        .sees = job->sees,
        .penumbra_at_pixels = job->penumbra_at_pixels && job->sees,
        .leave = job->leave,
        .seed = job->seed,
        .threads = job->threads,
        .over_ranks = job->over_ranks,
    };
    status = vertex_light(&light, direct, sharp, incident, error);
    if (status == RAD_OK)
        status = gather_correction(job, direct, sharp, incident, error);
    if (status != RAD_OK)
        goto done;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) { /* gathered, then the rest */
        if (!job->sharp_at_hits)
            rgb_add_to(&incident[v], sharp[v]);
        if (job->without_emitters)
            job->without_emitters[v] = incident[v];
        if (!job->emitters_at_hits)
            rgb_add_to(&incident[v], direct[v]);
    }
    free(direct);
    free(sharp);
    direct = sharp = NULL;

    /* per patch, what multiplies the incident light and what is added: rho / pi and E / pi,
     * or 1 / pi and 0 where the vertex holds irradiance; at the vertices their means */
    uint32_t n = mesh->patch_count ? mesh->patch_count : 1;
    rad_rgb *factor = rad_alloc_array(n, sizeof(*factor));
    rad_rgb *emission = rad_alloc_array(n, sizeof(*emission));
    vertex_factor = rad_alloc_array(vertices, sizeof(*vertex_factor));
    vertex_emission = rad_alloc_array(vertices, sizeof(*vertex_emission));
    bool made = factor && emission && vertex_factor && vertex_emission;
    for (uint32_t p = 0; made && p < mesh->patch_count; p++) {
        bool holds_irradiance =
            job->irradiance || patch_material_textured(job->lookup, mesh->patches[p].material);
        factor[p] = holds_irradiance ? (rad_rgb){1, 1, 1} : job->inputs->albedo[p];
        emission[p] = holds_irradiance ? (rad_rgb){0, 0, 0} : job->inputs->exitance[p];
    }
    made = made &&
           display_mesh_radiance_weighted(mesh, NULL, factor, job->hidden, vertex_factor) &&
           display_mesh_radiance_weighted(mesh, NULL, emission, job->hidden, vertex_emission);
    free(factor);
    free(emission);
    if (!made) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the light at the vertices");
        goto done;
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        radiance[v] = rgb_add(vertex_emission[v], rgb_mul(vertex_factor[v], incident[v]));
    display_mesh_constrain(mesh, display, radiance);
    if (job->without_emitters) {
        rad_rgb *without = job->without_emitters;
        for (uint32_t v = 0; v < mesh->vertex_count; v++)
            without[v] = rgb_add(vertex_emission[v], rgb_mul(vertex_factor[v], without[v]));
        display_mesh_constrain(mesh, display, without);
    }
    if (irradiance) {
        memcpy(irradiance, incident, display->vertex_count * sizeof(*irradiance));
        display_mesh_constrain(mesh, display, irradiance);
    }
done:
    free(direct);
    free(sharp);
    free(incident);
    free(vertex_factor);
    free(vertex_emission);
    return status;
}

rad_status vertex_radiance_of_solution(const rad_mesh *mesh, const display_mesh *display,
                                       const rad_rgb *B, const rad_scene *scene,
                                       const rad_patch_inputs *inputs,
                                       const vertex_parents *parents, uint64_t seed,
                                       int threads, rad_rgb *radiance, rad_rgb *irradiance,
                                       rad_error *error)
{
    uint32_t n = mesh->patch_count ? mesh->patch_count : 1;
    size_t vertices = display->vertex_count ? display->vertex_count : 1;
    rad_vec3 *positions = rad_alloc_array(vertices, sizeof(*positions));
    uint8_t *hidden = rad_alloc_array(n, sizeof(*hidden));
    rad_rgb *reflected = rad_alloc_array(vertices, sizeof(*reflected));
    rad_tracer *tracer = NULL, *scene_tracer = NULL;
    display_locator *locator = NULL;
    emitter_set emitters = {0};
    emitter_shadows *shadows = NULL;
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
        status = emitter_shadows_build(scene, &emitters, &shadows, error);
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
    /* the gather's rays against the scene's triangles, placed in the display mesh */
    status = display_locator_build(scene, scene_tracer, mesh, display, positions,
                                   display_mesh_front_triangles(mesh, display),
                                   (uint64_t)VERTEX_LIGHT_BYTES_PER_PATCH * mesh->patch_count,
                                   threads, &locator, error);
    if (status != RAD_OK)
        goto done;
    gather_view view = {mesh,      (const uint32_t(*)[3])display->triangles,
                        display->patch_of, reflected,
                        B,         inputs->exitance,
                        any_lights ? &lights : NULL, tracer, scene_tracer, locator};
    vertex_radiance_job job = {
        .mesh = mesh,
        .display = display,
        .scene = scene,
        .inputs = inputs,
        .emitters = &emitters,
        .shadows = shadows,
        .scene_tracer = scene_tracer,
        .view = &view,
        .sharp = any_lights && lights.sharp_count > 0 ? &lights : NULL,
        .hidden = hidden,
        .parents = parents,
        .leave = leave,
        .seed = seed,
        .threads = threads,
    };
    status = vertex_radiance(&job, radiance, irradiance, error);
done:
    rad_tracer_destroy(tracer);
    rad_tracer_destroy(scene_tracer);
    display_locator_destroy(locator);
    emitter_shadows_destroy(shadows);
    emitters_free(&emitters);
    free(positions);
    free(hidden);
    free(reflected);
    return status;
}
