/*
 * coplanar_polygons.c - the scene's blocking shapes grouped by plane, see
 * coplanar_polygons.h.
 *
 * Sorted once by (normal rounded to 1e-9, offset); a run with the same rounded normal and
 * offsets within plane_epsilon of its first shape's is a group. Degenerate shapes join no
 * group. Not here: whether the shapes block anything.
 */
#include "surface_viewfactors/coplanar_polygons.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/vec3.h"

#define NORMAL_QUANTUM 1e9

typedef struct keyed_shape {
    long long key[3]; /* the normal, rounded */
    double offset;
    rad_vec3 normal;
    uint32_t shape; /* index into the unsorted shapes */
} keyed_shape;

static int by_plane(const void *a, const void *b)
{
    const keyed_shape *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->key[k] != y->key[k])
            return x->key[k] < y->key[k] ? -1 : 1;
    if (x->offset != y->offset)
        return x->offset < y->offset ? -1 : 1;
    return (x->shape > y->shape) - (x->shape < y->shape);
}

static double coordinate(rad_vec3 v, unsigned axis)
{
    return axis == 0 ? v.x : axis == 1 ? v.y : v.z;
}

typedef struct sorted_shape {
    double low;
    uint32_t shape;
} sorted_shape;

static int by_low(const void *a, const void *b)
{
    const sorted_shape *x = a, *y = b;
    if (x->low != y->low)
        return x->low < y->low ? -1 : 1;
    return (x->shape > y->shape) - (x->shape < y->shape);
}

/* The plane of a shape with its largest normal component positive; false when degenerate. */
static bool shape_plane(const shadow_polygon *s, rad_vec3 *normal, double *offset)
{
    rad_vec3 sum = {0, 0, 0};
    for (unsigned k = 0; k < s->count; k++)
        sum = v3_add(sum, v3_cross(s->vertex[k], s->vertex[(k + 1) % s->count]));
    double length = v3_length(sum);
    if (!(length > 0) || !isfinite(length))
        return false;
    rad_vec3 n = v3_scale(sum, 1 / length);
    double largest = fabs(n.x) >= fabs(n.y) && fabs(n.x) >= fabs(n.z) ? n.x
                     : fabs(n.y) >= fabs(n.z)                        ? n.y
                                                                     : n.z;
    *normal = largest < 0 ? v3_scale(n, -1) : n;
    *offset = v3_dot(*normal, s->vertex[0]);
    return true;
}

rad_status coplanar_polygons_build(const rad_scene *scene, const vf_geometry *geometry,
                                   coplanar_polygons *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    uint32_t n = scene->triangle_count, polygons = geometry->polygon_count;
    uint64_t most = (uint64_t)n + polygons + 1;
    shadow_polygon *shapes = rad_alloc_array(most, sizeof(*shapes));
    keyed_shape *keyed = rad_alloc_array(most, sizeof(*keyed));
    sorted_shape *sorted = rad_alloc_array(most, sizeof(*sorted));
    uint32_t *shape_of_source = rad_alloc_array(polygons + 1, sizeof(*shape_of_source));
    uint32_t *group_of_shape = rad_alloc_array(most, sizeof(*group_of_shape));
    out->group_of = rad_alloc_array(n ? n : 1, sizeof(*out->group_of));
    out->shape = rad_alloc_array(most, sizeof(*out->shape));
    out->low = rad_alloc_array(most, sizeof(*out->low));
    out->box = rad_alloc_array(most, sizeof(*out->box));
    out->groups = rad_alloc_array(most, sizeof(*out->groups));
    rad_status status = RAD_OK;
    if (!shapes || !keyed || !sorted || !shape_of_source || !group_of_shape || !out->group_of ||
        !out->shape || !out->low || !out->box || !out->groups) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the planes of %u triangles",
                          n);
        goto done;
    }
    /* the shapes: each merged polygon once, each obstruction triangle */
    uint32_t count = 0;
    for (uint32_t s = 0; s <= polygons; s++)
        shape_of_source[s] = UINT32_MAX;
    for (uint32_t k = 0; k < polygons; k++) {
        const vf_polygon *p = &geometry->polygons[k];
        if (p->source >= polygons || shape_of_source[p->source] != UINT32_MAX)
            continue;
        shape_of_source[p->source] = count;
        shapes[count].count = p->count;
        memcpy(shapes[count].vertex, p->vertex, p->count * sizeof(rad_vec3));
        count++;
    }
    uint32_t first_obstruction = count;
    for (uint32_t t = 0; t < n; t++) {
        if (geometry->triangle_source[t] != UINT32_MAX)
            continue;
        shapes[count].count = 3;
        for (int c = 0; c < 3; c++)
            shapes[count].vertex[c] = scene->positions[scene->triangles[t].vertex[c]];
        count++;
    }
    uint32_t kept = 0;
    for (uint32_t s = 0; s < count; s++) {
        group_of_shape[s] = UINT32_MAX;
        rad_vec3 normal;
        double offset;
        if (!shape_plane(&shapes[s], &normal, &offset))
            continue;
        keyed[kept++] = (keyed_shape){{llround(normal.x * NORMAL_QUANTUM),
                                       llround(normal.y * NORMAL_QUANTUM),
                                       llround(normal.z * NORMAL_QUANTUM)},
                                      offset, normal, s};
    }
    qsort(keyed, kept, sizeof(*keyed), by_plane);
    for (uint32_t k = 0; k < kept;) {
        uint32_t first = k;
        while (k < kept && !memcmp(keyed[k].key, keyed[first].key, sizeof(keyed[k].key)) &&
               keyed[k].offset - keyed[first].offset <= geometry->plane_epsilon)
            k++;
        coplanar_group *g = &out->groups[out->group_count];
        *g = (coplanar_group){keyed[first].normal, keyed[first].offset, first, k - first, 0, 0};
        /* sorted along the coordinate in which the group's corners spread widest */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t m = first; m < k; m++) {
            const shadow_polygon *s = &shapes[keyed[m].shape];
            for (unsigned c = 0; c < s->count; c++)
                for (unsigned a = 0; a < 3; a++) {
                    lo[a] = fmin(lo[a], coordinate(s->vertex[c], a));
                    hi[a] = fmax(hi[a], coordinate(s->vertex[c], a));
                }
        }
        for (unsigned a = 1; a < 3; a++)
            if (hi[a] - lo[a] > hi[g->axis] - lo[g->axis])
                g->axis = a;
        for (uint32_t m = first; m < k; m++) {
            const shadow_polygon *s = &shapes[keyed[m].shape];
            double low = INFINITY, high = -INFINITY;
            for (unsigned c = 0; c < s->count; c++) {
                low = fmin(low, coordinate(s->vertex[c], g->axis));
                high = fmax(high, coordinate(s->vertex[c], g->axis));
            }
            sorted[m] = (sorted_shape){low, keyed[m].shape};
            g->widest = fmax(g->widest, high - low);
            group_of_shape[keyed[m].shape] = out->group_count;
        }
        qsort(&sorted[first], k - first, sizeof(*sorted), by_low);
        for (uint32_t m = first; m < k; m++) {
            const shadow_polygon *s = &shapes[sorted[m].shape];
            coplanar_box *box = &out->box[m];
            out->shape[m] = *s;
            out->low[m] = sorted[m].low;
            box->flat = true;
            for (unsigned a = 0; a < 3; a++) {
                box->lo[a] = INFINITY;
                box->hi[a] = -INFINITY;
            }
            for (unsigned c = 0; c < s->count; c++) {
                for (unsigned a = 0; a < 3; a++) {
                    box->lo[a] = fmin(box->lo[a], coordinate(s->vertex[c], a));
                    box->hi[a] = fmax(box->hi[a], coordinate(s->vertex[c], a));
                }
                box->flat = box->flat && fabs(v3_dot(g->normal, s->vertex[c]) - g->offset) <=
                                             geometry->plane_epsilon;
            }
        }
        out->group_count++;
    }
    /* each scene triangle's group: its polygon's, or its own (an obstruction's) */
    for (uint32_t t = 0, obstruction = first_obstruction; t < n; t++) {
        uint32_t source = geometry->triangle_source[t];
        uint32_t s = source == UINT32_MAX ? obstruction++
                     : source < polygons  ? shape_of_source[source]
                                          : UINT32_MAX;
        out->group_of[t] = s == UINT32_MAX ? UINT32_MAX : group_of_shape[s];
    }
done:
    free(shapes);
    free(keyed);
    free(sorted);
    free(shape_of_source);
    free(group_of_shape);
    if (status != RAD_OK)
        coplanar_polygons_free(out);
    return status;
}

void coplanar_polygons_free(coplanar_polygons *planes)
{
    free(planes->groups);
    free(planes->group_of);
    free(planes->shape);
    free(planes->low);
    free(planes->box);
    memset(planes, 0, sizeof(*planes));
}

/* The first of the `count` lows from `first` on that is >= x (> x when `after`). */
static uint32_t bisect(const double *low, uint32_t first, uint32_t count, double x, bool after)
{
    uint32_t lo = first, hi = first + count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (after ? low[mid] <= x : low[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

void coplanar_polygons_range(const coplanar_polygons *planes, uint32_t g, double from,
                             double to, uint32_t *begin, uint32_t *end)
{
    const coplanar_group *group = &planes->groups[g];
    *begin = bisect(planes->low, group->first, group->count, from - group->widest, false);
    *end = bisect(planes->low, group->first, group->count, to, true);
    if (*end < *begin)
        *end = *begin;
}
