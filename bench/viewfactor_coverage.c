/*
 * viewfactor_coverage.c - do the view factors' error bounds cover their errors? Computes a
 * scene's matrix with the library, then checks surface pairs against brute force: uniform
 * points of both surfaces, the kernel cos cos / (pi r^2), each segment tested against every
 * triangle of the scene by this program's own ray-triangle test (no tracer, no polygons,
 * no occluder tree, no proofs). G_IJ = A_I A_J mean(kernel x visible); F_IJ = G_IJ / A_I.
 *
 * usage: viewfactor_coverage SCENE [RANDOM_PAIRS [LARGEST_BOUNDS [SEGMENTS [EXACT_OCCLUDERS
 *        [SKY_RAYS [SKY_SURFACES [SKY_EXACT]]]]]]]
 *   RANDOM_PAIRS stored factors F_IJ (I < J) drawn at random (default 150), LARGEST_BOUNDS
 *   more with the largest error bounds (default 50), SEGMENTS per pair (default 40000);
 *   and as many pairs drawn at random among those not stored (F = 0: proven hidden,
 *   facing away, or met by no sight ray, whose F_IJ is then within 3 / (N (1 + A_I / A_J))
 *   for N sight rays a surface, 95 %), which brute force must find within that bound
 *   + 3 s.e.; and the sky
 *   view factors of RANDOM_PAIRS surfaces drawn at random (rad_sky_viewfactors_compute)
 *   against the share of cosine-distributed rays from uniform points that nothing stops
 *   (SEGMENTS / 2 rays). EXACT_OCCLUDERS: the library's --exact-occluders (0: its
 *   default); SKY_RAYS and SKY_SURFACES: the sky's rays a surface and surfaces (default
 *   SEGMENTS / 2 and RANDOM_PAIRS); SKY_EXACT 1: the sky as with --sky-exact.
 * Prints one line per pair whose brute-force value lies outside bound + 3 standard errors,
 * then a summary: how many lie within bound + 3 s.e., within 2 bound + 3 s.e., the largest
 * |F - reference| / (bound + 3 s.e.), and the median bound and standard error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "radiosity.h"

typedef struct checked {
    uint32_t I, J;
    double F, bound, reference, standard_error;
} checked;

/* xorshift64* */
static double uniform(uint64_t *s)
{
    *s ^= *s >> 12, *s ^= *s << 25, *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static rad_vec3 sub(rad_vec3 a, rad_vec3 b) { return (rad_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double dot(rad_vec3 a, rad_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static rad_vec3 cross(rad_vec3 a, rad_vec3 b)
{
    return (rad_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

static double triangle_area(const rad_scene *s, uint32_t t, rad_vec3 *normal)
{
    const rad_triangle *tri = &s->triangles[t];
    rad_vec3 n = cross(sub(s->positions[tri->vertex[1]], s->positions[tri->vertex[0]]),
                       sub(s->positions[tri->vertex[2]], s->positions[tri->vertex[0]]));
    double length = sqrt(dot(n, n));
    if (normal)
        *normal = length > 0 ? (rad_vec3){n.x / length, n.y / length, n.z / length} : n;
    return 0.5 * length;
}

/* A uniform point of surface I (its triangles by area; cumulative[] their running areas)
 * and the unit normal there. */
static rad_vec3 surface_point(const rad_scene *s, uint32_t I, const double *cumulative,
                              uint64_t *rng, rad_vec3 *normal)
{
    const rad_surface *surface = &s->surfaces[I];
    double pick = uniform(rng) * cumulative[surface->triangle_count - 1];
    uint32_t lo = 0, hi = surface->triangle_count - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (cumulative[mid] < pick)
            lo = mid + 1;
        else
            hi = mid;
    }
    uint32_t t = surface->first_triangle + lo;
    triangle_area(s, t, normal);
    const rad_triangle *tri = &s->triangles[t];
    rad_vec3 a = s->positions[tri->vertex[0]], b = s->positions[tri->vertex[1]],
             c = s->positions[tri->vertex[2]];
    double r1 = sqrt(uniform(rng)), r2 = uniform(rng);
    double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2;
    return (rad_vec3){wa * a.x + wb * b.x + wc * c.x, wa * a.y + wb * b.y + wc * c.y,
                      wa * a.z + wb * b.z + wc * c.z};
}

/* Some triangle of the scene crosses the segment x -> x + d strictly inside it (far: or
 * anywhere beyond its start, for a ray). */
static bool crossed(const rad_scene *s, rad_vec3 x, rad_vec3 d, double far)
{
    for (uint32_t t = 0; t < s->triangle_count; t++) {
        const rad_triangle *tri = &s->triangles[t];
        rad_vec3 a = s->positions[tri->vertex[0]];
        rad_vec3 e1 = sub(s->positions[tri->vertex[1]], a);
        rad_vec3 e2 = sub(s->positions[tri->vertex[2]], a);
        rad_vec3 h = cross(d, e2);
        double det = dot(e1, h);
        if (fabs(det) < 1e-300)
            continue;
        double f = 1 / det;
        rad_vec3 o = sub(x, a);
        double u = f * dot(o, h);
        if (u < 0 || u > 1)
            continue;
        rad_vec3 q = cross(o, e1);
        double v = f * dot(d, q);
        if (v < 0 || u + v > 1)
            continue;
        double along = f * dot(e2, q);
        if (along > 1e-6 && along < far)
            return true;
    }
    return false;
}

static bool blocked(const rad_scene *s, rad_vec3 x, rad_vec3 d)
{
    return crossed(s, x, d, 1 - 1e-6);
}

/* Surface I's sky view factor by brute force: cosine-distributed rays from uniform points
 * of I that no triangle stops. */
static void brute_force_sky(const rad_scene *s, uint32_t I, const double *cumulative,
                            uint32_t rays, double *share, double *standard_error)
{
    uint64_t rng = 0xD1B54A32D192ED03ull ^ I;
    uint32_t escaped = 0;
    for (uint32_t k = 0; k < rays; k++) {
        rad_vec3 n;
        rad_vec3 x = surface_point(s, I, cumulative, &rng, &n);
        rad_vec3 h = fabs(n.x) > 0.5 ? (rad_vec3){0, 1, 0} : (rad_vec3){1, 0, 0};
        rad_vec3 t1 = cross(n, h);
        double l = sqrt(dot(t1, t1));
        t1 = (rad_vec3){t1.x / l, t1.y / l, t1.z / l};
        rad_vec3 t2 = cross(n, t1);
        double q = uniform(&rng), phi = 2 * 3.14159265358979323846 * uniform(&rng);
        double r = sqrt(q), a = r * cos(phi), b = r * sin(phi), c = sqrt(fmax(0, 1 - q));
        rad_vec3 d = {a * t1.x + b * t2.x + c * n.x, a * t1.y + b * t2.y + c * n.y,
                      a * t1.z + b * t2.z + c * n.z};
        escaped += !crossed(s, x, d, INFINITY);
    }
    *share = (double)escaped / rays;
    *standard_error = sqrt(*share * (1 - *share) / rays);
}

static void brute_force(const rad_scene *s, checked *c, double *const *cumulative,
                        double area_I, double area_J, uint32_t segments)
{
    uint64_t rng = 0x9E3779B97F4A7C15ull ^ ((uint64_t)c->I << 32 | c->J);
    double sum = 0, squares = 0;
    for (uint32_t k = 0; k < segments; k++) {
        rad_vec3 nx, ny;
        rad_vec3 x = surface_point(s, c->I, cumulative[c->I], &rng, &nx);
        rad_vec3 y = surface_point(s, c->J, cumulative[c->J], &rng, &ny);
        rad_vec3 d = sub(y, x);
        double r2 = dot(d, d), cx = dot(nx, d), cy = -dot(ny, d);
        double value = cx > 0 && cy > 0 && r2 > 0 ? cx * cy / (r2 * r2) : 0;
        if (value > 0 && blocked(s, x, d))
            value = 0;
        sum += value;
        squares += value * value;
    }
    double mean = sum / segments, var = fmax(squares / segments - mean * mean, 0) / segments;
    double scale = area_J / 3.14159265358979323846; /* F_IJ = A_J mean / pi */
    c->reference = scale * mean;
    c->standard_error = scale * sqrt(var);
    (void)area_I;
}

static int by_bound(const void *a, const void *b)
{
    double x = ((const checked *)a)->bound, y = ((const checked *)b)->bound;
    return (x < y) - (x > y);
}

static int by_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs("usage: viewfactor_coverage SCENE [RANDOM_PAIRS [LARGEST_BOUNDS [SEGMENTS "
              "[EXACT_OCCLUDERS [SKY_RAYS [SKY_SURFACES [SKY_EXACT]]]]]]]\n",
              stderr);
        return 2;
    }
    uint32_t random_pairs = argc > 2 ? (uint32_t)atoi(argv[2]) : 150;
    uint32_t largest = argc > 3 ? (uint32_t)atoi(argv[3]) : 50;
    uint32_t segments = argc > 4 ? (uint32_t)atoi(argv[4]) : 40000;
    uint32_t exact_occluders = argc > 5 ? (uint32_t)atoi(argv[5]) : 0;
    /* the sky view factors' brute force: rays a surface, and how many surfaces */
    uint32_t sky_rays = argc > 6 ? (uint32_t)atoi(argv[6]) : segments / 2;
    uint32_t sky_surfaces = argc > 7 ? (uint32_t)atoi(argv[7]) : random_pairs;
    bool sky_exact = argc > 8 && atoi(argv[8]) != 0; /* --sky-exact */
    rad_scene *scene = NULL;
    rad_error error = {0};
    if (rad_scene_load(argv[1], NULL, &scene, &error) != RAD_OK) {
        fprintf(stderr, "viewfactor_coverage: %s\n", error.message);
        return 1;
    }
    rad_viewfactor_matrix *m = NULL;
    rad_viewfactor_report report;
    /* the command line's defaults (seed 1), so that its figures are `radiosity viewfactors`' */
    rad_viewfactor_options options = {.seed = 1, .exact_occluders = exact_occluders,
                                      .sky_exact = sky_exact};
    if (rad_viewfactor_matrix_compute(scene, &options, &m, &report, &error) != RAD_OK) {
        fprintf(stderr, "viewfactor_coverage: %s\n", error.message);
        return 1;
    }
    /* the stored factors above the diagonal */
    uint64_t stored = 0;
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
            stored += m->column[k] > I;
    checked *all = malloc((stored ? stored : 1) * sizeof(*all));
    uint64_t n = 0;
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
            if (m->column[k] > I)
                all[n++] = (checked){I, m->column[k], m->value[k], m->error_bound[k], 0, 0};
    qsort(all, n, sizeof(*all), by_bound);
    uint32_t count = 0;
    checked *pick = malloc((random_pairs + largest) * sizeof(*pick));
    for (uint32_t k = 0; k < largest && k < n; k++)
        pick[count++] = all[k];
    uint64_t rng = 12345;
    for (uint32_t k = 0; k < random_pairs && n > largest; k++) {
        uint64_t at = largest + (uint64_t)(uniform(&rng) * (double)(n - largest));
        pick[count++] = all[at];
    }
    /* pairs not stored: F = 0, bound 0 (proven hidden or facing away) or what no sight ray
     * met: G_IJ <= 3 / (N / A_I + N / A_J), 95 % (seen_pairs.h); set below */
    uint32_t stored_count = count;
    checked *grown = realloc(pick, (2 * (size_t)count + 1) * sizeof(*pick));
    if (!grown)
        return 1;
    pick = grown;
    for (uint32_t tries = 0; count < 2 * stored_count && tries < 100 * stored_count; tries++) {
        uint32_t I = (uint32_t)(uniform(&rng) * m->n), J = (uint32_t)(uniform(&rng) * m->n);
        if (I >= J || scene->surfaces[I].flags || scene->surfaces[J].flags)
            continue;
        bool found = false;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1] && !found; k++)
            found = m->column[k] == J;
        if (!found)
            pick[count++] = (checked){I, J, 0, 0, 0, 0};
    }
    double **cumulative = calloc(scene->surface_count, sizeof(*cumulative));
    double *areas = calloc(scene->surface_count, sizeof(double));
    for (uint32_t I = 0; I < scene->surface_count; I++) {
        const rad_surface *surface = &scene->surfaces[I];
        cumulative[I] = malloc((surface->triangle_count ? surface->triangle_count : 1) *
                               sizeof(double));
        double running = 0;
        for (uint32_t t = 0; t < surface->triangle_count; t++)
            cumulative[I][t] = running += triangle_area(scene, surface->first_triangle + t, NULL);
        areas[I] = running;
    }
#pragma omp parallel for schedule(dynamic, 1)
    for (uint32_t k = 0; k < count; k++)
        brute_force(scene, &pick[k], cumulative, areas[pick[k].I], areas[pick[k].J], segments);
    uint32_t within = 0, within_twice = 0, zero_seen = 0, zero_outside = 0;
    double zero_largest = 0;
    for (uint32_t k = stored_count; k < count; k++) {
        checked *c = &pick[k];
        if (report.sight_rays)
            c->bound = 2.995732 / ((double)report.sight_rays / areas[c->I] +
                                   (double)report.sight_rays / areas[c->J]) / areas[c->I];
        zero_seen += c->reference > 3 * c->standard_error;
        zero_outside += c->reference > c->bound + 3 * c->standard_error;
        zero_largest = fmax(zero_largest, c->reference);
        if (c->reference > c->bound + 3 * c->standard_error)
            printf("not stored: F(%s -> %s) 0 within %.2g; brute force %.6g +- %.2g\n",
                   scene->surfaces[c->I].name, scene->surfaces[c->J].name, c->bound,
                   c->reference, c->standard_error);
    }
    uint32_t unstored_count = count - stored_count;
    count = stored_count;
    double worst = 0;
    double *bounds = malloc(count * sizeof(double)), *errors = malloc(count * sizeof(double));
    for (uint32_t k = 0; k < count; k++) {
        const checked *c = &pick[k];
        double miss = fabs(c->F - c->reference);
        within += miss <= c->bound + 3 * c->standard_error;
        within_twice += miss <= 2 * c->bound + 3 * c->standard_error;
        worst = fmax(worst, miss / (c->bound + 3 * c->standard_error));
        bounds[k] = c->bound;
        errors[k] = c->standard_error;
        if (miss > c->bound + 3 * c->standard_error)
            printf("outside: F(%s -> %s) %.6g bound %.3g; brute force %.6g +- %.2g (%s)\n",
                   scene->surfaces[c->I].name, scene->surfaces[c->J].name, c->F, c->bound,
                   c->reference, c->standard_error, k < largest ? "largest bounds" : "random");
    }
    /* sky view factors of surfaces drawn at random */
    double *sky = calloc(scene->surface_count, sizeof(double));
    double *sky_bound = calloc(scene->surface_count, sizeof(double));
    rad_sky_report sky_report;
    if (rad_sky_viewfactors_compute(scene, &options, sky, sky_bound, &sky_report, &error) !=
        RAD_OK) {
        fprintf(stderr, "viewfactor_coverage: %s\n", error.message);
        return 1;
    }
    uint32_t sky_count = sky_surfaces < scene->surface_count ? sky_surfaces : scene->surface_count;
    uint32_t *sky_pick = malloc((sky_count ? sky_count : 1) * sizeof(uint32_t));
    double *sky_reference = malloc((sky_count ? sky_count : 1) * sizeof(double));
    double *sky_error = malloc((sky_count ? sky_count : 1) * sizeof(double));
    for (uint32_t k = 0; k < sky_count; k++) {
        uint32_t I;
        do
            I = (uint32_t)(uniform(&rng) * scene->surface_count);
        while (scene->surfaces[I].flags || areas[I] <= 0);
        sky_pick[k] = I;
    }
#pragma omp parallel for schedule(dynamic, 1)
    for (uint32_t k = 0; k < sky_count; k++)
        brute_force_sky(scene, sky_pick[k], cumulative[sky_pick[k]], sky_rays,
                        &sky_reference[k], &sky_error[k]);
    uint32_t sky_within = 0, sky_within_twice = 0;
    double sky_worst = 0;
    for (uint32_t k = 0; k < sky_count; k++) {
        uint32_t I = sky_pick[k];
        double miss = fabs(sky[I] - sky_reference[k]);
        sky_within += miss <= sky_bound[I] + 3 * sky_error[k];
        sky_within_twice += miss <= 2 * sky_bound[I] + 3 * sky_error[k];
        sky_worst = fmax(sky_worst, miss / (sky_bound[I] + 3 * sky_error[k]));
        if (miss > sky_bound[I] + 3 * sky_error[k])
            printf("outside: sky view factor of %s %.6g bound %.3g; brute force %.6g +- %.2g\n",
                   scene->surfaces[I].name, sky[I], sky_bound[I], sky_reference[k],
                   sky_error[k]);
    }
    uint32_t top = largest < n ? largest : (uint32_t)n;
    qsort(bounds, count, sizeof(double), by_double);
    qsort(errors, count, sizeof(double), by_double);
    printf("%s: %u stored factors checked (%u with the largest bounds, %u at random), %u "
           "segments each: %u within bound + 3 s.e., %u within 2 bound + 3 s.e.; largest "
           "|F - brute force| / (bound + 3 s.e.) %.2f; median bound %.3g, median s.e. %.3g; "
           "largest bound of the run %.3g\n"
           "%u pairs not stored (F = 0, within %.2g with %u sight rays a surface): %u where "
           "brute force sees more than 3 s.e., %u more than the bound + 3 s.e.; largest "
           "brute-force value %.3g\n"
           "%u sky view factors (%u rays each): %u within bound + 3 s.e., %u within 2 bound + "
           "3 s.e.; largest miss / (bound + 3 s.e.) %.2f; largest bound of the run %.3g\n",
           argv[1], count, top, count - top,
           segments, within, within_twice, worst, count ? bounds[count / 2] : 0,
           count ? errors[count / 2] : 0, report.largest_error_bound, unstored_count,
           report.unmet_bound, report.sight_rays, zero_seen, zero_outside, zero_largest, sky_count, sky_rays, sky_within, sky_within_twice, sky_worst,
           sky_report.largest_error_bound);
    return 0;
}
