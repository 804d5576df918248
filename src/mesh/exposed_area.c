/*
 * exposed_area.c - the share of each patch's area not buried in a closed object, see
 * exposed_area.h.
 */
#include "mesh/exposed_area.h"

#include <math.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"
#include "trace/ray.h"

#define SIDE 8u        /* points per side of a patch: 64 cells */
#define FINE_SIDE EXPOSED_FINE_SIDE /* the same for a patch partly buried */
#define DIRECTIONS 8u  /* rays per point */
#define BURIED_BACKS 7u /* a point whose rays meet this many backs first is buried */
#define LIFT 1e-6      /* off the surface, times the scene's diagonal (and past a fold) */

/* The point of patch p at the centre of cell (a, b) of its side x side split of the unit
 * square (s, t), mapped as the form factors' segments are (pair_engine.c): bilinear for a
 * quad, c0 + sqrt(s) (c1 - c0 + t (c2 - c1)) for a triangle (uniform in area). */
static rad_vec3 cell_centre(const rad_mesh *mesh, const rad_patch *p, unsigned side,
                            unsigned a, unsigned b)
{
    double s = (a + 0.5) / side, t = (b + 0.5) / side;
    const rad_vec3 *v = mesh->vertices;
    rad_vec3 c0 = v[p->vertex[0]], c1 = v[p->vertex[1]], c2 = v[p->vertex[2]];
    if (p->vertex_count == 4)
        return v3_lerp(v3_lerp(c0, c1, s), v3_lerp(v[p->vertex[3]], c2, s), t);
    return v3_add(c0, v3_scale(v3_add(v3_sub(c1, c0), v3_scale(v3_sub(c2, c1), t)), sqrt(s)));
}

/* The hemisphere's directions in a patch's frame (normal, u, w): two rings. */
static void hemisphere_directions(double (*along)[3])
{
    for (unsigned d = 0; d < DIRECTIONS; d++) {
        double phi = 2 * RAD_PI * (d + 0.5) / DIRECTIONS, cosine = d % 2 ? 0.5 : 0.8660254;
        double sine = sqrt(1 - cosine * cosine);
        along[d][0] = cosine;
        along[d][1] = sine * cos(phi);
        along[d][2] = sine * sin(phi);
    }
}

/* Rays from a point are traced in two rounds: FIRST_DIRECTIONS of them, then the rest
 * only where those found a back. A point whose first rays all meet fronts (or nothing)
 * cannot reach BURIED_BACKS and is open: the same answer as tracing all of them, in
 * about a third of the rays where most points are open. */
#define FIRST_DIRECTIONS (DIRECTIONS - BURIED_BACKS + 1u)

/* The points of patch p's side x side split that are not buried, traced a row of points
 * at a time; `along` holds the hemisphere's directions in the patch's frame. With `bits`,
 * cell (a, b)'s bit a * side + b is set when its point is open. */
static unsigned open_points(const rad_tracer *tracer, const rad_mesh *mesh, const rad_patch *p,
                            unsigned side, double lift, double (*along)[3], uint8_t *bits)
{
    rad_vec3 normal = p->normal;
    rad_vec3 t = fabs(normal.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
    rad_vec3 u = v3_normalize(v3_cross(t, normal)), w = v3_cross(normal, u);
    rad_vec3 direction[DIRECTIONS];
    for (unsigned d = 0; d < DIRECTIONS; d++)
        direction[d] = v3_add(v3_scale(normal, along[d][0]),
                              v3_add(v3_scale(u, along[d][1]), v3_scale(w, along[d][2])));
    rad_ray rays[FINE_SIDE * DIRECTIONS];
    rad_hit hits[FINE_SIDE * DIRECTIONS];
    rad_vec3 x[FINE_SIDE];
    unsigned backs[FINE_SIDE], again[FINE_SIDE];
    unsigned open = 0;
    for (unsigned a = 0; a < side; a++) {
        unsigned r = 0;
        for (unsigned b = 0; b < side; b++) {
            x[b] = v3_add(cell_centre(mesh, p, side, a, b), v3_scale(normal, lift + 2 * p->behind));
            for (unsigned d = 0; d < FIRST_DIRECTIONS; d++)
                ray_set(&rays[r++], x[b], direction[d], 0, INFINITY);
        }
        rad_tracer_intersect(tracer, rays, r, hits);
        unsigned more = 0; /* points whose first rays met a back: the rest of theirs */
        for (unsigned b = 0; b < side; b++) {
            backs[b] = 0;
            for (unsigned d = 0; d < FIRST_DIRECTIONS; d++) {
                const rad_hit *h = &hits[b * FIRST_DIRECTIONS + d];
                backs[b] += h->triangle != RAD_NO_HIT && !h->front;
            }
            if (backs[b] > 0)
                again[more++] = b;
        }
        r = 0;
        for (unsigned k = 0; k < more; k++)
            for (unsigned d = FIRST_DIRECTIONS; d < DIRECTIONS; d++)
                ray_set(&rays[r++], x[again[k]], direction[d], 0, INFINITY);
        if (r)
            rad_tracer_intersect(tracer, rays, r, hits);
        for (unsigned k = 0; k < more; k++)
            for (unsigned d = 0; d < DIRECTIONS - FIRST_DIRECTIONS; d++) {
                const rad_hit *h = &hits[k * (DIRECTIONS - FIRST_DIRECTIONS) + d];
                backs[again[k]] += h->triangle != RAD_NO_HIT && !h->front;
            }
        for (unsigned b = 0; b < side; b++) {
            open += backs[b] < BURIED_BACKS;
            if (bits && backs[b] < BURIED_BACKS)
                bits[(a * side + b) / 8] |= (uint8_t)(1u << ((a * side + b) % 8));
        }
    }
    return open;
}

double exposed_lift(const rad_mesh *mesh)
{
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    return LIFT * v3_length(v3_sub(hi, lo));
}

unsigned patch_open_cells(const rad_tracer *tracer, const rad_mesh *mesh, uint32_t patch,
                          double lift, uint8_t bits[EXPOSED_CELL_BYTES])
{
    double along[DIRECTIONS][3];
    hemisphere_directions(along);
    for (unsigned k = 0; k < EXPOSED_CELL_BYTES; k++)
        bits[k] = 0;
    return open_points(tracer, mesh, &mesh->patches[patch], FINE_SIDE, lift, along, bits);
}

rad_status patch_exposed_shares(const rad_scene *scene, const rad_mesh *mesh, double *share,
                                rad_error *error)
{
    const uint32_t n = mesh->patch_count;
    for (uint32_t i = 0; i < n; i++)
        share[i] = 1;
    if (n == 0 || scene->triangle_count == 0)
        return RAD_OK;
    rad_tracer *tracer = NULL;
    rad_status status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &tracer,
                                                    error);
    if (status != RAD_OK)
        return status;
    const double lift = exposed_lift(mesh);
    double along[DIRECTIONS][3];
    hemisphere_directions(along);
#pragma omp parallel for schedule(dynamic, 16)
    for (int64_t k = 0; k < (int64_t)n; k++) {
        const rad_patch *p = &mesh->patches[k];
        unsigned open = open_points(tracer, mesh, p, SIDE, lift, along, NULL);
        if (open == 0 || open == SIDE * SIDE)
            continue; /* all open, or all buried (it sees nothing): 1 */
        /* partly buried: its share is the area's, finer */
        open = open_points(tracer, mesh, p, FINE_SIDE, lift, along, NULL);
        if (open)
            share[k] = (double)open / (FINE_SIDE * FINE_SIDE);
    }
    rad_tracer_destroy(tracer);
    return RAD_OK;
}
