/*
 * vf_geometry.c - polygons and surfaces for the view-factor engine, see vf_geometry.h.
 */
#include "surface_viewfactors/vf_geometry.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/vec3.h"

/* A polygon joins a neighbour when the neighbour's corners lie within this fraction of
 * the union's size from its plane and the normals agree as closely (dimensionless): input
 * read as floats (Assimp) rounds a flat face's corners by about 1e-7. */
#define MERGE_FLATNESS 1e-6

/* A corner is dropped as collinear when the turn there is below this (sine of the angle). */
#define COLLINEAR_SINE 1e-9

typedef struct edge_use {
    uint32_t low, high; /* vertex indices, low < high */
    uint32_t polygon;
} edge_use;

static int compare_edges(const void *a, const void *b)
{
    const edge_use *x = a, *y = b;
    if (x->low != y->low)
        return x->low < y->low ? -1 : 1;
    if (x->high != y->high)
        return x->high < y->high ? -1 : 1;
    return x->polygon < y->polygon ? -1 : x->polygon > y->polygon;
}

/* A polygon under construction: scene vertex indices, counter-clockwise. */
typedef struct draft {
    uint32_t corner[VF_MAX_VERTICES];
    unsigned count;
    rad_vec3 normal;
    uint32_t merged_into; /* itself while alive */
} draft;

static uint32_t find_alive(draft *drafts, uint32_t d)
{
    while (drafts[d].merged_into != d) {
        drafts[d].merged_into = drafts[drafts[d].merged_into].merged_into;
        d = drafts[d].merged_into;
    }
    return d;
}

static rad_vec3 draft_normal(const rad_scene *scene, const uint32_t *corner, unsigned count)
{
    rad_vec3 sum = {0, 0, 0};
    for (unsigned k = 0; k < count; k++)
        sum = v3_add(sum, v3_cross(scene->positions[corner[k]],
                                   scene->positions[corner[(k + 1) % count]]));
    return v3_normalize(sum);
}

/* Joins b into a across their shared edge when the result is flat, convex and small enough. */
static bool try_merge(const rad_scene *scene, draft *a, const draft *b)
{
    if (v3_dot(a->normal, b->normal) < 1 - MERGE_FLATNESS)
        return false;
    /* find the edge a[i] -> a[i+1] that b runs as b[j+1] -> b[j] */
    for (unsigned i = 0; i < a->count; i++) {
        uint32_t u = a->corner[i], v = a->corner[(i + 1) % a->count];
        for (unsigned j = 0; j < b->count; j++) {
            if (b->corner[j] != v || b->corner[(j + 1) % b->count] != u)
                continue;
            uint32_t joined[2 * VF_MAX_VERTICES];
            unsigned n = 0;
            for (unsigned k = 0; k <= i; k++)
                joined[n++] = a->corner[k];
            /* b's corners from after u round to before v */
            for (unsigned k = 2; k < b->count; k++)
                joined[n++] = b->corner[(j + k) % b->count];
            for (unsigned k = i + 1; k < a->count; k++)
                joined[n++] = a->corner[k];
            /* flatness of the union, convexity, and collinear corners dropped */
            rad_vec3 origin = scene->positions[joined[0]];
            double size = 0;
            for (unsigned k = 0; k < n; k++)
                size = fmax(size, v3_length(v3_sub(scene->positions[joined[k]], origin)));
            for (unsigned k = 0; k < n; k++)
                if (fabs(v3_dot(a->normal, v3_sub(scene->positions[joined[k]], origin))) >
                    MERGE_FLATNESS * size)
                    return false;
            uint32_t kept[2 * VF_MAX_VERTICES];
            unsigned m = 0;
            for (unsigned k = 0; k < n; k++) {
                rad_vec3 prev = scene->positions[joined[(k + n - 1) % n]];
                rad_vec3 here = scene->positions[joined[k]];
                rad_vec3 next = scene->positions[joined[(k + 1) % n]];
                rad_vec3 in = v3_sub(here, prev), out = v3_sub(next, here);
                double turn = v3_dot(a->normal, v3_cross(in, out));
                double scale = v3_length(in) * v3_length(out);
                if (turn < -COLLINEAR_SINE * scale)
                    return false; /* reflex: not convex */
                if (turn > COLLINEAR_SINE * scale)
                    kept[m++] = joined[k];
            }
            if (m < 3 || m > VF_MAX_VERTICES)
                return false;
            memcpy(a->corner, kept, m * sizeof(uint32_t));
            a->count = m;
            return true;
        }
    }
    return false;
}

void vf_polygon_finish(vf_polygon *polygon)
{
    rad_vec3 sum = {0, 0, 0}, cross = {0, 0, 0};
    for (unsigned k = 0; k < polygon->count; k++) {
        sum = v3_add(sum, polygon->vertex[k]);
        cross = v3_add(cross, v3_cross(polygon->vertex[k],
                                       polygon->vertex[(k + 1) % polygon->count]));
    }
    polygon->area = 0.5 * fabs(v3_dot(cross, polygon->normal));
    polygon->centroid = v3_scale(sum, 1.0 / polygon->count);
    polygon->radius = 0;
    for (unsigned k = 0; k < polygon->count; k++)
        polygon->radius =
            fmax(polygon->radius, v3_length(v3_sub(polygon->vertex[k], polygon->centroid)));
    double running = 0;
    rad_vec3 a = polygon->vertex[0];
    for (unsigned k = 1; k + 1 < polygon->count; k++) {
        running += 0.5 * v3_length(v3_cross(v3_sub(polygon->vertex[k], a),
                                            v3_sub(polygon->vertex[k + 1], a)));
        polygon->fan[k - 1] = polygon->area > 0 ? fmin(running / polygon->area, 1) : 1;
    }
    polygon->fan[polygon->count - 3] = 1;
}

bool vf_polygon_clip_front(const vf_polygon *polygon, rad_vec3 n, double offset,
                           vf_polygon *out)
{
    double height[VF_MAX_VERTICES];
    bool all_front = true, any_front = false;
    for (unsigned k = 0; k < polygon->count; k++) {
        height[k] = v3_dot(n, polygon->vertex[k]) - offset;
        all_front = all_front && height[k] > 0;
        any_front = any_front || height[k] > 0;
    }
    if (!any_front)
        return false;
    if (out != polygon)
        *out = *polygon;
    if (all_front)
        return true;
    rad_vec3 kept[VF_MAX_VERTICES + 1];
    unsigned count = 0;
    for (unsigned k = 0; k < polygon->count; k++) {
        unsigned next = (k + 1) % polygon->count;
        double a = height[k], b = height[next];
        if (a > 0)
            kept[count++] = polygon->vertex[k];
        if ((a > 0 && b <= 0) || (a <= 0 && b > 0)) /* the edge crosses the plane */
            kept[count++] = v3_lerp(polygon->vertex[k], polygon->vertex[next], a / (a - b));
    }
    /* a corner on the plane between two in front comes out twice (as the end of one
     * crossing edge and the start of the next), or twice a hair apart: once only, as a
     * repeated corner is an edge with no direction */
    count = v3_drop_repeated(kept, count, 1e-12);
    if (count > VF_MAX_VERTICES)
        return true; /* the whole polygon, as said */
    if (count < 3)
        return false;
    memcpy(out->vertex, kept, count * sizeof(rad_vec3));
    out->count = count;
    vf_polygon_finish(out);
    return out->area > 0;
}

/* The normal from the corners' winding, then the rest (vf_polygon_finish). */
static void finish_polygon(vf_polygon *polygon)
{
    rad_vec3 cross = {0, 0, 0};
    for (unsigned k = 0; k < polygon->count; k++)
        cross = v3_add(cross, v3_cross(polygon->vertex[k],
                                       polygon->vertex[(k + 1) % polygon->count]));
    polygon->normal = v3_normalize(cross);
    vf_polygon_finish(polygon);
}

/* Polygons of one surface: its triangles merged greedily across shared edges. */
static uint32_t surface_polygons(const rad_scene *scene, const rad_surface *surface,
                                 uint32_t index, uint32_t first_source, edge_use *edges,
                                 draft *drafts, uint32_t *triangle_source, vf_polygon *out)
{
    uint32_t first = surface->first_triangle, count = surface->triangle_count, made = 0;
    size_t edge_count = 0;
    for (uint32_t t = 0; t < count; t++) {
        draft *d = &drafts[t];
        memcpy(d->corner, scene->triangles[first + t].vertex, 3 * sizeof(uint32_t));
        d->count = 3;
        d->normal = draft_normal(scene, d->corner, 3);
        d->merged_into = t;
        for (unsigned k = 0; k < 3; k++) {
            uint32_t a = d->corner[k], b = d->corner[(k + 1) % 3];
            edges[edge_count++] = (edge_use){a < b ? a : b, a < b ? b : a, t};
        }
    }
    qsort(edges, edge_count, sizeof(*edges), compare_edges);
    for (size_t e = 0; e + 1 < edge_count; e++) {
        /* an edge used by exactly two triangles of this surface */
        if (edges[e].low != edges[e + 1].low || edges[e].high != edges[e + 1].high)
            continue;
        if ((e + 2 < edge_count && edges[e + 2].low == edges[e].low &&
             edges[e + 2].high == edges[e].high) ||
            (e > 0 && edges[e - 1].low == edges[e].low && edges[e - 1].high == edges[e].high))
            continue;
        uint32_t a = find_alive(drafts, edges[e].polygon);
        uint32_t b = find_alive(drafts, edges[e + 1].polygon);
        if (a == b)
            continue;
        if (try_merge(scene, &drafts[a], &drafts[b]))
            drafts[b].merged_into = a;
    }
    for (uint32_t t = 0; t < count; t++) {
        if (drafts[t].merged_into != t)
            continue; /* merged into another */
        vf_polygon polygon = {0};
        polygon.count = drafts[t].count;
        for (unsigned k = 0; k < polygon.count; k++)
            polygon.vertex[k] = scene->positions[drafts[t].corner[k]];
        polygon.surface = index;
        polygon.source = first_source + made;
        finish_polygon(&polygon);
        drafts[t].merged_into = UINT32_MAX - made; /* remember which polygon it became */
        out[made++] = polygon;
    }
    for (uint32_t t = 0; t < count; t++) {
        uint32_t d = t;
        while (drafts[d].merged_into < count && drafts[d].merged_into != d)
            d = drafts[d].merged_into;
        uint32_t polygon = UINT32_MAX - drafts[d].merged_into;
        triangle_source[first + t] = first_source + polygon;
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
    finish_polygon(polygon);
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
    draft *drafts = rad_alloc_array(largest + 1, sizeof(draft));
    geometry->triangle_source = rad_alloc_array(scene->triangle_count ? scene->triangle_count : 1,
                                                sizeof(uint32_t));
    if (!geometry->surfaces || !geometry->polygons || !edges || !drafts ||
        !geometry->triangle_source) {
        free(edges);
        free(drafts);
        vf_geometry_free(geometry);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for %zu view-factor polygons",
                        polygon_capacity);
    }
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        geometry->triangle_source[t] = UINT32_MAX;
    uint32_t made = 0, sources = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        vf_surface *out = &geometry->surfaces[s];
        memset(out, 0, sizeof(*out));
        out->first_polygon = made;
        if (surface->flags & RAD_SURFACE_OBSTRUCTION || surface->triangle_count == 0)
            continue;
        uint32_t count = surface_polygons(scene, surface, s, sources, edges, drafts,
                                          geometry->triangle_source, geometry->polygons + made);
        sources += count;
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
    free(drafts);
    return RAD_OK;
}

void vf_geometry_free(vf_geometry *geometry)
{
    free(geometry->polygons);
    free(geometry->surfaces);
    free(geometry->triangle_source);
    memset(geometry, 0, sizeof(*geometry));
}
