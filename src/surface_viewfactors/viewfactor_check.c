/*
 * viewfactor_check.c - the invariants of a view-factor matrix, measured; see radiosity.h.
 */
#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/vec3.h"

typedef struct edge_key {
    uint32_t low, high;
} edge_key;

static int compare_edge_keys(const void *a, const void *b)
{
    const edge_key *x = a, *y = b;
    if (x->low != y->low)
        return x->low < y->low ? -1 : 1;
    return x->high < y->high ? -1 : x->high > y->high;
}

/* Every edge of the radiating surfaces' triangles used by exactly two of them. */
static bool scene_is_closed(const rad_scene *scene)
{
    size_t count = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (!(scene->surfaces[s].flags & RAD_SURFACE_OBSTRUCTION))
            count += 3 * (size_t)scene->surfaces[s].triangle_count;
    if (count == 0)
        return false;
    edge_key *edges = rad_alloc_array(count, sizeof(*edges));
    if (!edges)
        return false;
    size_t n = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        if (surface->flags & RAD_SURFACE_OBSTRUCTION)
            continue;
        for (uint32_t t = surface->first_triangle;
             t < surface->first_triangle + surface->triangle_count; t++)
            for (int k = 0; k < 3; k++) {
                uint32_t a = scene->triangles[t].vertex[k];
                uint32_t b = scene->triangles[t].vertex[(k + 1) % 3];
                edges[n++] = (edge_key){a < b ? a : b, a < b ? b : a};
            }
    }
    qsort(edges, n, sizeof(*edges), compare_edge_keys);
    bool closed = true;
    for (size_t k = 0; k < n && closed;) {
        size_t same = 1;
        while (k + same < n && edges[k + same].low == edges[k].low &&
               edges[k + same].high == edges[k].high)
            same++;
        closed = same == 2;
        k += same;
    }
    free(edges);
    return closed;
}

static bool surface_is_planar(const rad_scene *scene, const rad_surface *surface)
{
    if (surface->triangle_count == 0)
        return true;
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    double epsilon = 1e-7 * v3_length(v3_sub(hi, lo));
    const uint32_t *first = scene->triangles[surface->first_triangle].vertex;
    rad_vec3 origin = scene->positions[first[0]];
    rad_vec3 normal = v3_normalize(v3_cross(v3_sub(scene->positions[first[1]], origin),
                                            v3_sub(scene->positions[first[2]], origin)));
    for (uint32_t t = surface->first_triangle;
         t < surface->first_triangle + surface->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        rad_vec3 a = scene->positions[v[0]];
        rad_vec3 n = v3_normalize(v3_cross(v3_sub(scene->positions[v[1]], a),
                                           v3_sub(scene->positions[v[2]], a)));
        if (v3_dot(n, normal) < 1 - 1e-9)
            return false;
        for (int k = 0; k < 3; k++)
            if (fabs(v3_dot(normal, v3_sub(scene->positions[v[k]], origin))) > epsilon)
                return false;
    }
    return true;
}

void rad_viewfactor_matrix_check(const rad_viewfactor_matrix *matrix, const rad_scene *scene,
                                 rad_viewfactor_check *check)
{
    check->smallest = INFINITY;
    check->largest = 0;
    check->reciprocity = 0;
    check->largest_planar_self = 0;
    check->largest_row_sum = 0;
    check->row_sum_deviation = 0;
    check->closed = scene_is_closed(scene);
    for (uint32_t I = 0; I < matrix->n; I++) {
        double sum = 0;
        for (uint64_t k = matrix->row_start[I]; k < matrix->row_start[I + 1]; k++) {
            uint32_t J = matrix->column[k];
            double F = matrix->value[k];
            sum += F;
            check->smallest = fmin(check->smallest, F);
            check->largest = fmax(check->largest, F);
            if (J == I) {
                if (surface_is_planar(scene, &scene->surfaces[I]))
                    check->largest_planar_self = fmax(check->largest_planar_self, F);
                continue;
            }
            double a = matrix->area[I] * F;
            double b = matrix->area[J] * rad_viewfactor_matrix_get(matrix, J, I);
            check->reciprocity = fmax(check->reciprocity, fabs(a - b) / fmax(a, b));
        }
        check->largest_row_sum = fmax(check->largest_row_sum, sum);
        if (!(scene->surfaces[I].flags & RAD_SURFACE_OBSTRUCTION) && matrix->area[I] > 0)
            check->row_sum_deviation = fmax(check->row_sum_deviation, fabs(sum - 1));
    }
    if (check->smallest == INFINITY)
        check->smallest = 0;
}
