/*
 * vf_geometry.c - polygons and surfaces for the view-factor engine, see vf_geometry.h.
 */
#include "viewfactor/vf_geometry.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/vec3.h"

/* Two triangles form one flat quad when the fourth corner lies within this fraction of the
 * quad's diagonal from the first triangle's plane (dimensionless): input read as floats
 * (Assimp) rounds a flat quad's corners by about 1e-7. */
#define QUAD_FLATNESS 1e-6

typedef struct edge_use {
    uint32_t low, high; /* vertex indices, low < high */
    uint32_t triangle;
} edge_use;

static int compare_edges(const void *a, const void *b)
{
    const edge_use *x = a, *y = b;
    if (x->low != y->low)
        return x->low < y->low ? -1 : 1;
    if (x->high != y->high)
        return x->high < y->high ? -1 : 1;
    return x->triangle < y->triangle ? -1 : x->triangle > y->triangle;
}

static void finish_polygon(vf_polygon *polygon)
{
    rad_vec3 sum = {0, 0, 0}, cross = {0, 0, 0};
    for (unsigned k = 0; k < polygon->count; k++) {
        sum = v3_add(sum, polygon->vertex[k]);
        cross = v3_add(cross, v3_cross(polygon->vertex[k],
                                       polygon->vertex[(k + 1) % polygon->count]));
    }
    polygon->area = 0.5 * v3_length(cross);
    polygon->normal = v3_normalize(cross);
    polygon->centroid = v3_scale(sum, 1.0 / polygon->count);
    polygon->radius = 0;
    for (unsigned k = 0; k < polygon->count; k++)
        polygon->radius =
            fmax(polygon->radius, v3_length(v3_sub(polygon->vertex[k], polygon->centroid)));
}

/* The quad a, b, d, c when triangle t = (a, b, c) and its neighbour across edge b-c, with
 * third corner d, are coplanar and their union is convex. */
static bool try_quad(const rad_scene *scene, uint32_t t, uint32_t u, vf_polygon *quad)
{
    const uint32_t *tv = scene->triangles[t].vertex, *uv = scene->triangles[u].vertex;
    for (unsigned k = 0; k < 3; k++) {
        uint32_t a = tv[k], b = tv[(k + 1) % 3], c = tv[(k + 2) % 3];
        for (unsigned m = 0; m < 3; m++) {
            if (uv[m] != c || uv[(m + 1) % 3] != b)
                continue;
            uint32_t d = uv[(m + 2) % 3];
            rad_vec3 corner[4] = {scene->positions[a], scene->positions[b],
                                  scene->positions[d], scene->positions[c]};
            rad_vec3 n = v3_normalize(
                v3_cross(v3_sub(corner[1], corner[0]), v3_sub(corner[3], corner[0])));
            double diagonal = v3_length(v3_sub(corner[2], corner[0]));
            if (fabs(v3_dot(n, v3_sub(corner[2], corner[0]))) > QUAD_FLATNESS * diagonal)
                return false;
            for (unsigned e = 0; e < 4; e++) {
                rad_vec3 edge = v3_sub(corner[(e + 1) % 4], corner[e]);
                rad_vec3 next = v3_sub(corner[(e + 2) % 4], corner[(e + 1) % 4]);
                if (v3_dot(n, v3_cross(edge, next)) <= 0)
                    return false; /* not strictly convex */
            }
            memcpy(quad->vertex, corner, sizeof(corner));
            quad->count = 4;
            quad->triangle[0] = t;
            quad->triangle[1] = u;
            return true;
        }
    }
    return false;
}

/* Polygons of one surface: triangles paired into quads where they can be. */
static uint32_t surface_polygons(const rad_scene *scene, const rad_surface *surface,
                                 uint32_t index, edge_use *edges, uint8_t *used,
                                 vf_polygon *out)
{
    uint32_t first = surface->first_triangle, count = surface->triangle_count, made = 0;
    size_t edge_count = 0;
    for (uint32_t t = first; t < first + count; t++) {
        used[t - first] = 0;
        for (unsigned k = 0; k < 3; k++) {
            uint32_t a = scene->triangles[t].vertex[k], b = scene->triangles[t].vertex[(k + 1) % 3];
            edges[edge_count++] = (edge_use){a < b ? a : b, a < b ? b : a, t};
        }
    }
    qsort(edges, edge_count, sizeof(*edges), compare_edges);
    for (size_t e = 0; e + 1 < edge_count; e++) {
        /* an edge used by exactly two triangles of this surface */
        if (edges[e].low != edges[e + 1].low || edges[e].high != edges[e + 1].high)
            continue;
        if (e + 2 < edge_count && edges[e + 2].low == edges[e].low &&
            edges[e + 2].high == edges[e].high)
            continue;
        if (e > 0 && edges[e - 1].low == edges[e].low && edges[e - 1].high == edges[e].high)
            continue;
        uint32_t t = edges[e].triangle, u = edges[e + 1].triangle;
        if (used[t - first] || used[u - first])
            continue;
        vf_polygon quad = {0};
        if (!try_quad(scene, t, u, &quad))
            continue;
        used[t - first] = used[u - first] = 1;
        quad.surface = index;
        finish_polygon(&quad);
        out[made++] = quad;
    }
    for (uint32_t t = first; t < first + count; t++) {
        if (used[t - first])
            continue;
        vf_polygon triangle = {0};
        for (unsigned k = 0; k < 3; k++)
            triangle.vertex[k] = scene->positions[scene->triangles[t].vertex[k]];
        triangle.count = 3;
        triangle.triangle[0] = t;
        triangle.triangle[1] = UINT32_MAX;
        triangle.surface = index;
        finish_polygon(&triangle);
        out[made++] = triangle;
    }
    return made;
}

static void reverse_polygon(vf_polygon *polygon)
{
    for (unsigned k = 0; k < polygon->count / 2; k++) {
        rad_vec3 swap = polygon->vertex[k];
        polygon->vertex[k] = polygon->vertex[polygon->count - 1 - k];
        polygon->vertex[polygon->count - 1 - k] = swap;
    }
    polygon->normal = v3_scale(polygon->normal, -1);
}

static void finish_surface(vf_surface *surface, const vf_polygon *polygons, double epsilon)
{
    const vf_polygon *first = &polygons[surface->first_polygon];
    rad_vec3 lo = first->vertex[0], hi = lo;
    surface->area = 0;
    surface->planar = true;
    surface->normal = first->normal;
    surface->offset = v3_dot(first->normal, first->vertex[0]);
    for (uint32_t k = 0; k < surface->polygon_count; k++) {
        const vf_polygon *polygon = &first[k];
        surface->area += polygon->area;
        if (v3_dot(polygon->normal, surface->normal) < 1 - 1e-12)
            surface->planar = false;
        for (unsigned c = 0; c < polygon->count; c++) {
            rad_vec3 v = polygon->vertex[c];
            lo = v3(fmin(lo.x, v.x), fmin(lo.y, v.y), fmin(lo.z, v.z));
            hi = v3(fmax(hi.x, v.x), fmax(hi.y, v.y), fmax(hi.z, v.z));
            if (fabs(v3_dot(surface->normal, v) - surface->offset) > epsilon)
                surface->planar = false;
        }
    }
    surface->center = v3_scale(v3_add(lo, hi), 0.5);
    surface->radius = 0;
    for (uint32_t k = 0; k < surface->polygon_count; k++)
        for (unsigned c = 0; c < first[k].count; c++)
            surface->radius =
                fmax(surface->radius, v3_length(v3_sub(first[k].vertex[c], surface->center)));
}

rad_status vf_geometry_build(const rad_scene *scene, vf_geometry *geometry, rad_error *error)
{
    memset(geometry, 0, sizeof(*geometry));
    rad_vec3 lo, hi;
    rad_scene_bounds(scene, &lo, &hi);
    geometry->plane_epsilon = RAD_PLANE_EPSILON * v3_length(v3_sub(hi, lo));

    size_t polygon_capacity = 0, largest = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        if (surface->flags & RAD_SURFACE_OBSTRUCTION)
            continue;
        size_t copies = surface->flags & RAD_SURFACE_TWO_SIDED ? 2 : 1;
        polygon_capacity += copies * surface->triangle_count;
        if (surface->triangle_count > largest)
            largest = surface->triangle_count;
    }
    geometry->surface_count = scene->surface_count;
    geometry->surfaces = rad_alloc_array(scene->surface_count ? scene->surface_count : 1,
                                         sizeof(vf_surface));
    geometry->polygons = rad_alloc_array(polygon_capacity ? polygon_capacity : 1,
                                         sizeof(vf_polygon));
    edge_use *edges = rad_alloc_array(3 * largest + 1, sizeof(edge_use));
    uint8_t *used = rad_alloc_array(largest + 1, 1);
    if (!geometry->surfaces || !geometry->polygons || !edges || !used) {
        free(edges);
        free(used);
        vf_geometry_free(geometry);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %zu view-factor polygons",
                        polygon_capacity);
    }
    uint32_t made = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        vf_surface *out = &geometry->surfaces[s];
        memset(out, 0, sizeof(*out));
        out->first_polygon = made;
        if (surface->flags & RAD_SURFACE_OBSTRUCTION || surface->triangle_count == 0)
            continue;
        uint32_t count = surface_polygons(scene, surface, s, edges, used,
                                          geometry->polygons + made);
        if (surface->flags & RAD_SURFACE_TWO_SIDED)
            for (uint32_t k = 0; k < count; k++) {
                geometry->polygons[made + count + k] = geometry->polygons[made + k];
                reverse_polygon(&geometry->polygons[made + count + k]);
            }
        out->polygon_count = surface->flags & RAD_SURFACE_TWO_SIDED ? 2 * count : count;
        made += out->polygon_count;
        finish_surface(out, geometry->polygons, geometry->plane_epsilon);
    }
    geometry->polygon_count = made;
    free(edges);
    free(used);
    return RAD_OK;
}

void vf_geometry_free(vf_geometry *geometry)
{
    free(geometry->polygons);
    free(geometry->surfaces);
    memset(geometry, 0, sizeof(*geometry));
}
