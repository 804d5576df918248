/*
 * seen_pairs.c - the surface pairs some ray found in sight of each other, see seen_pairs.h.
 */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/hemisphere.h"
#include "core/random.h"
#include "core/vec3.h"
#include "parallel/ranks.h"
#include "surface_viewfactors/seen_pairs.h"
#include "trace/ray.h"

/* Rays per tracer call. */
#define SEEN_BATCH 1024u

/* Rays start this far above their point along the polygon's normal, as a fraction of the
 * scene's diagonal, and at least SEEN_RAY_ULPS float steps of its largest coordinate: above
 * the float rounding of the tracer's coordinates, also for a model placed far from the
 * origin (a ray that started under its own surface would meet it and be lost). */
#define SEEN_RAY_OFFSET 1e-6
#define SEEN_RAY_ULPS 8.0

/* Salt of the rays' random streams (no other stream of the view factors uses it). */
#define SEEN_SALT 0x7365656eu

typedef struct hit_list {
    uint32_t *surfaces; /* ascending */
    uint32_t count;
} hit_list;

/* One thread's scratch space. */
typedef struct seen_workspace {
    rad_ray rays[SEEN_BATCH];
    rad_hit hits[SEEN_BATCH];
    uint32_t *stamp;      /* per surface: the last surface whose rays met it */
    uint32_t *met;        /* per surface: how many of that one's rays met it */
    uint32_t *found;      /* the surfaces the current one's rays met */
    double *cumulative;   /* the current surface's polygon areas, summed */
    rad_vec3 *frame;      /* the current surface's polygons' tangents, two each */
    uint32_t found_capacity, cumulative_capacity;
} seen_workspace;

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static bool grow_u32(uint32_t **array, uint32_t *capacity)
{
    uint32_t grown_capacity = *capacity ? 2 * *capacity : 256;
    uint32_t *grown = rad_resize_array(*array, grown_capacity, sizeof(uint32_t));
    if (!grown)
        return false;
    *array = grown;
    *capacity = grown_capacity;
    return true;
}

typedef struct seen_job {
    const rad_scene *scene;
    const vf_geometry *geometry;
    const rad_tracer *tracer;
    uint32_t rays;
    uint64_t seed;
    double offset; /* scene units */
} seen_job;

/* The polygon of the surface whose share of the area holds u in [0, total). */
static uint32_t polygon_at(const double *cumulative, uint32_t count, double u)
{
    uint32_t low = 0, high = count - 1;
    while (low < high) {
        uint32_t middle = low + (high - low) / 2;
        if (u < cumulative[middle])
            high = middle;
        else
            low = middle + 1;
    }
    return low;
}

/* Surface I's rays: the distinct other surfaces (with polygons) they met first on a
 * radiating side, ascending, into *out, and *missed the share of I's view the surfaces
 * none met hold, by Good and Turing's estimate: the surfaces met exactly once over the
 * rays. False when out of memory. */
static bool cast_surface(const seen_job *job, uint32_t I, seen_workspace *w, hit_list *out,
                         uint64_t *cast, float *missed)
{
    *missed = 0;
    const vf_geometry *g = job->geometry;
    const vf_surface *s = &g->surfaces[I];
    *out = (hit_list){NULL, 0};
    if (s->polygon_count == 0)
        return true;
    while (w->cumulative_capacity < s->polygon_count) {
        uint32_t capacity = w->cumulative_capacity ? 2 * w->cumulative_capacity : 64;
        double *grown = rad_resize_array(w->cumulative, capacity, sizeof(double));
        if (!grown)
            return false;
        w->cumulative = grown;
        rad_vec3 *frames = rad_resize_array(w->frame, 2 * (size_t)capacity, sizeof(rad_vec3));
        if (!frames)
            return false;
        w->frame = frames;
        w->cumulative_capacity = capacity;
    }
    double total = 0;
    for (uint32_t k = 0; k < s->polygon_count; k++) {
        const vf_polygon *p = &g->polygons[s->first_polygon + k];
        w->cumulative[k] = total += p->area;
        hemisphere_frame(p->normal, &w->frame[2 * k], &w->frame[2 * k + 1]);
    }
    if (!(total > 0))
        return true;
    uint32_t found = 0;
    rad_rng rng = rad_rng_seed(job->seed ^ SEEN_SALT, I, 0);
    for (uint32_t done = 0; done < job->rays;) {
        uint32_t batch = job->rays - done < SEEN_BATCH ? job->rays - done : SEEN_BATCH;
        for (uint32_t k = 0; k < batch; k++) {
            uint32_t pk = polygon_at(w->cumulative, s->polygon_count,
                                     rad_rng_uniform(&rng) * total);
            const vf_polygon *p = &g->polygons[s->first_polygon + pk];
            double u1 = rad_rng_uniform(&rng), u2 = rad_rng_uniform(&rng);
            rad_vec3 x = vf_polygon_sample(p, u1, u2);
            /* cosine-distributed (Malley): a uniform point of the unit disc, by rejection
             * from its square (no trigonometry), lifted onto the hemisphere */
            double dx, dy, r2;
            do {
                dx = 2 * rad_rng_uniform(&rng) - 1;
                dy = 2 * rad_rng_uniform(&rng) - 1;
                r2 = dx * dx + dy * dy;
            } while (r2 > 1);
            rad_vec3 d = v3_add(v3_scale(p->normal, sqrt(1 - r2)),
                                v3_add(v3_scale(w->frame[2 * pk], dx),
                                       v3_scale(w->frame[2 * pk + 1], dy)));
            /* lifted off p along its normal, not along the ray: a point closer to a wall
             * than the offset must not start beyond it */
            ray_set(&w->rays[k], v3_add(x, v3_scale(p->normal, job->offset)), d, 0, INFINITY);
        }
        rad_tracer_intersect(job->tracer, w->rays, batch, w->hits);
        *cast += batch;
        done += batch;
        for (uint32_t k = 0; k < batch; k++) {
            const rad_hit *h = &w->hits[k];
            if (h->triangle == RAD_NO_HIT)
                continue;
            uint32_t J = job->scene->triangles[h->triangle].surface;
            if (J == I || g->surfaces[J].polygon_count == 0 ||
                (!h->front && !(job->scene->surfaces[J].flags & RAD_SURFACE_TWO_SIDED)))
                continue;
            if (w->stamp[J] == I) {
                w->met[J]++;
                continue;
            }
            w->stamp[J] = I;
            w->met[J] = 1;
            if (found == w->found_capacity && !grow_u32(&w->found, &w->found_capacity))
                return false;
            w->found[found++] = J;
        }
    }
    if (found == 0)
        return true;
    uint32_t once = 0;
    for (uint32_t k = 0; k < found; k++)
        once += w->met[w->found[k]] == 1;
    *missed = (float)((double)once / job->rays);
    qsort(w->found, found, sizeof(uint32_t), compare_u32);
    out->surfaces = rad_alloc_array(found, sizeof(uint32_t));
    if (!out->surfaces)
        return false;
    memcpy(out->surfaces, w->found, found * sizeof(uint32_t));
    out->count = found;
    return true;
}

/* This rank's surfaces' lists, by threads. False when out of memory. */
static bool cast_all(const seen_job *job, int threads, hit_list *lists, uint64_t *cast,
                     float *missed)
{
    uint32_t n = job->geometry->surface_count;
    int rank = ranks_rank(), ranks = ranks_count();
    bool failed = false;
    uint64_t total = 0;
#pragma omp parallel num_threads(threads) reduction(+ : total)
    {
        seen_workspace w = {0};
        w.stamp = rad_alloc_array(n ? n : 1, sizeof(uint32_t));
        w.met = rad_alloc_array(n ? n : 1, sizeof(uint32_t));
        if (!w.stamp || !w.met) {
#pragma omp atomic write
            failed = true;
        } else
            for (uint32_t J = 0; J < n; J++)
                w.stamp[J] = UINT32_MAX;
#pragma omp for schedule(dynamic, 4)
        for (uint32_t I = 0; I < n; I++) {
            bool stop;
#pragma omp atomic read
            stop = failed;
            if (stop || I % (uint32_t)ranks != (uint32_t)rank)
                continue;
            if (!cast_surface(job, I, &w, &lists[I], &total, &missed[I])) {
#pragma omp atomic write
                failed = true;
            }
        }
        free(w.stamp);
        free(w.met);
        free(w.found);
        free(w.cumulative);
        free(w.frame);
    }
    *cast = total;
    return !failed;
}

/* Over ranks: every rank's lists to all (rank 0 gathers, then broadcasts them). */
static rad_status share_lists(hit_list *lists, uint32_t n, rad_error *error)
{
    int rank = ranks_rank(), ranks = ranks_count();
    uint64_t size = 0;
    for (uint32_t I = 0; I < n; I++)
        if (I % (uint32_t)ranks == (uint32_t)rank)
            size += 2 + (uint64_t)lists[I].count;
    uint32_t *mine = rad_alloc_array(size ? size : 1, sizeof(uint32_t));
    uint64_t *sizes = rad_alloc_array((size_t)ranks, sizeof(uint64_t));
    bool failed = !mine || !sizes;
    if (ranks_failures(failed)) {
        free(mine);
        free(sizes);
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing the seen pairs");
    }
    uint64_t at = 0;
    for (uint32_t I = 0; I < n; I++)
        if (I % (uint32_t)ranks == (uint32_t)rank) {
            mine[at++] = I;
            mine[at++] = lists[I].count;
            if (lists[I].count)
                memcpy(mine + at, lists[I].surfaces, lists[I].count * sizeof(uint32_t));
            at += lists[I].count;
        }
    void *gathered = NULL;
    rad_status status = ranks_gather(mine, size * sizeof(uint32_t), &gathered, sizes, error);
    free(mine);
    uint64_t total = 0;
    for (int r = 0; status == RAD_OK && rank == 0 && r < ranks; r++)
        total += sizes[r] / sizeof(uint32_t);
    free(sizes);
    if (status == RAD_OK)
        ranks_broadcast(&total, sizeof(total));
    uint32_t *all = NULL;
    if (status == RAD_OK) {
        all = rank == 0 ? gathered : rad_alloc_array(total ? total : 1, sizeof(uint32_t));
        if (ranks_failures(!all)) {
            if (rank != 0)
                free(all);
            free(gathered);
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing the seen pairs");
        }
        ranks_broadcast(all, total * sizeof(uint32_t));
    }
    bool bad = false;
    for (uint64_t k = 0; status == RAD_OK && !bad && k < total;) {
        if (total - k < 2 || all[k] >= n || total - k - 2 < all[k + 1]) {
            bad = true;
            break;
        }
        uint32_t I = all[k], count = all[k + 1];
        k += 2;
        if (I % (uint32_t)ranks != (uint32_t)rank && count) {
            lists[I].surfaces = rad_alloc_array(count, sizeof(uint32_t));
            if (!lists[I].surfaces) {
                bad = true;
                break;
            }
            memcpy(lists[I].surfaces, all + k, count * sizeof(uint32_t));
            lists[I].count = count;
        }
        k += count;
    }
    if (all != gathered)
        free(all);
    free(gathered);
    if (status == RAD_OK && ranks_failures(bad))
        status = rad_fail(error, RAD_ERR_NOMEM,
                          "out of memory (or a malformed message) sharing the seen pairs");
    return status;
}

/* The rows: for each pair met from either side, min(I, J) holds max(I, J), once. */
static bool build_rows(const hit_list *lists, uint32_t n, seen_pairs *out)
{
    out->row_start = rad_alloc_array((size_t)n + 1, sizeof(uint64_t));
    if (!out->row_start)
        return false;
    memset(out->row_start, 0, ((size_t)n + 1) * sizeof(uint64_t));
    for (uint32_t I = 0; I < n; I++)
        for (uint32_t k = 0; k < lists[I].count; k++) {
            uint32_t J = lists[I].surfaces[k];
            out->row_start[(I < J ? I : J) + 1]++;
        }
    for (uint32_t I = 0; I < n; I++)
        out->row_start[I + 1] += out->row_start[I];
    uint64_t total = out->row_start[n];
    out->column = rad_alloc_array(total ? total : 1, sizeof(uint32_t));
    uint64_t *cursor = rad_alloc_array((size_t)n + 1, sizeof(uint64_t));
    if (!out->column || !cursor) {
        free(cursor);
        return false;
    }
    memcpy(cursor, out->row_start, ((size_t)n + 1) * sizeof(uint64_t));
    for (uint32_t I = 0; I < n; I++)
        for (uint32_t k = 0; k < lists[I].count; k++) {
            uint32_t J = lists[I].surfaces[k];
            out->column[cursor[I < J ? I : J]++] = I < J ? J : I;
        }
    /* each row sorted, its repeats (met from both sides) dropped, packed */
    uint64_t kept = 0;
    for (uint32_t I = 0; I < n; I++) {
        uint64_t first = out->row_start[I], end = out->row_start[I + 1];
        qsort(out->column + first, end - first, sizeof(uint32_t), compare_u32);
        out->row_start[I] = kept;
        for (uint64_t k = first; k < end; k++)
            if (k == first || out->column[k] != out->column[k - 1])
                out->column[kept++] = out->column[k];
    }
    out->row_start[n] = kept;
    free(cursor);
    return true;
}

rad_status seen_pairs_build(const rad_scene *scene, const vf_geometry *geometry,
                            const rad_tracer *tracer, uint32_t rays, uint64_t seed, int threads,
                            seen_pairs *out, rad_error *error)
{
    memset(out, 0, sizeof(*out));
    uint32_t n = geometry->surface_count;
    out->surface_count = n;
    out->rays = rays;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double largest = 0;
    for (uint32_t v = 0; v < scene->position_count; v++) {
        const double c[3] = {scene->positions[v].x, scene->positions[v].y, scene->positions[v].z};
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], c[k]), hi[k] = fmax(hi[k], c[k]);
            largest = fmax(largest, fabs(c[k]));
        }
    }
    double diagonal = scene->position_count
                          ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                 (hi[2] - lo[2]) * (hi[2] - lo[2]))
                          : 1;
    seen_job job = {scene, geometry, tracer, rays, seed,
                    fmax(SEEN_RAY_OFFSET * diagonal, SEEN_RAY_ULPS * FLT_EPSILON * largest)};
    hit_list *lists = rad_alloc_array(n ? n : 1, sizeof(hit_list));
    if (lists)
        memset(lists, 0, (n ? n : 1) * sizeof(hit_list));
    out->missed = rad_alloc_array(n ? n : 1, sizeof(float));
    if (out->missed)
        memset(out->missed, 0, (n ? n : 1) * sizeof(float));
    bool failed = !lists || !out->missed ||
                  !cast_all(&job, threads, lists, &out->rays_cast, out->missed);
    rad_status status = RAD_OK;
    if (ranks_failures(failed))
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory casting the sight rays of %u "
                                                "surfaces", n);
    if (status == RAD_OK && ranks_count() > 1) {
        status = share_lists(lists, n, error);
        /* each surface's estimate was made on one rank, the others hold 0 */
        if (status == RAD_OK)
            ranks_sum_floats(out->missed, n);
    }
    if (status == RAD_OK && !build_rows(lists, n, out))
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the seen pairs of %u "
                                                "surfaces", n);
    for (uint32_t I = 0; lists && I < n; I++)
        free(lists[I].surfaces);
    free(lists);
    if (status != RAD_OK)
        seen_pairs_free(out);
    return status;
}

void seen_pairs_free(seen_pairs *s)
{
    free(s->row_start);
    free(s->column);
    free(s->missed);
    s->row_start = NULL;
    s->column = NULL;
    s->missed = NULL;
}
