/*
 * test_tracer.c - the ray queries: a hand-built square with known answers, then the Embree
 * backend against the brute-force oracle on a random triangle soup, then argument checks,
 * the empty scene, and several threads querying one tracer at once.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const rad_tracer_backend backends[2] = {RAD_TRACER_EMBREE, RAD_TRACER_BRUTE_FORCE};
static const char *const backend_names[2] = {"embree", "brute force"};

/* Rays grazing an edge may legitimately disagree between float BVH and double oracle. */
enum { MAX_GRAZING_MISMATCHES = 2 };
#define T_RELATIVE 1e-4  /* t agreement between the backends, relative ... */
#define T_FLOOR 1e-2     /* ... to max(t, T_FLOOR): near the origin float error is absolute */
#define UV_ABSOLUTE 1e-3 /* barycentric agreement between the backends */
/* Below this |cos(ray, triangle normal)| the hit is too ill-conditioned in float for t, u, v
 * to be compared (the error grows as 1 / |cos|); only the triangle is compared. */
#define GRAZING_COS 1e-2

/* xorshift64*: a fixed, portable random sequence for the test data. */
static uint64_t rng_next(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *state = x;
    return x * 0x2545F4914F6CDD1Dull;
}

static double rng_uniform(uint64_t *state, double lo, double hi)
{
    return lo + (hi - lo) * (double)(rng_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

static rad_ray make_ray(double ox, double oy, double oz, double dx, double dy, double dz,
                        double t_near, double t_far)
{
    rad_ray ray = {{(float)ox, (float)oy, (float)oz}, (float)t_near,
                   {(float)dx, (float)dy, (float)dz}, (float)t_far};
    return ray;
}

/* ------------------------------------------------------------------------------------ */
/* A unit square at z = 1 made of two triangles, both facing +z (counter-clockwise seen
 * from above). The origin projects strictly inside triangle 0, away from every edge. */

static const rad_vec3 square_positions[4] = {
    {-0.75, -0.25, 1.0}, {0.25, -0.25, 1.0}, {0.25, 0.75, 1.0}, {-0.75, 0.75, 1.0}};
static const uint32_t square_triangles[2][3] = {{0, 1, 2}, {0, 2, 3}};

static void check_hit_point(const rad_hit *hit, const rad_ray *ray)
{
    const uint32_t *tri = square_triangles[hit->triangle < 2 ? hit->triangle : 0];
    rad_vec3 p0 = square_positions[tri[0]], p1 = square_positions[tri[1]],
             p2 = square_positions[tri[2]];
    double w = 1.0 - hit->u - hit->v;
    double px = w * p0.x + hit->u * p1.x + hit->v * p2.x;
    double py = w * p0.y + hit->u * p1.y + hit->v * p2.y;
    double pz = w * p0.z + hit->u * p1.z + hit->v * p2.z;
    CHECK_ABS(px, ray->origin[0] + hit->t * ray->direction[0], 1e-6);
    CHECK_ABS(py, ray->origin[1] + hit->t * ray->direction[1], 1e-6);
    CHECK_ABS(pz, ray->origin[2] + hit->t * ray->direction[2], 1e-6);
}

static void test_square(rad_tracer_backend backend)
{
    rad_tracer *tracer = NULL;
    rad_error error = {0};
    CHECK(rad_tracer_create(backend, square_positions, 4, square_triangles, 2, &tracer,
                            &error) == RAD_OK);
    if (!tracer)
        return;

    enum { N = 9 };
    rad_ray rays[N] = {
        /* 0: from the origin up +z: back of triangle 0 at t = 1 */
        make_ray(0, 0, 0, 0, 0, 1, 0, INFINITY),
        /* 1: from above, down, direction of length 2: front of triangle 1 at t = 1 */
        make_ray(-0.5, 0.5, 3, 0, 0, -2, 0, INFINITY),
        /* 2: a segment stopping short of the square */
        make_ray(0, 0, 0, 0, 0, 1, 0, 0.99),
        /* 3: a segment reaching just past it */
        make_ray(0, 0, 0, 0, 0, 1, 0, 1.01),
        /* 4: a segment starting past it */
        make_ray(0, 0, 0, 0, 0, 1, 1.01, INFINITY),
        /* 5: pointing away */
        make_ray(0, 0, 0, 0, 0, -1, 0, INFINITY),
        /* 6: beside the square */
        make_ray(2, 0, 0, 0, 0, 1, 0, INFINITY),
        /* 7: a long direction: t is in its units (hits at t = 0.25) */
        make_ray(0, 0, 0, 0, 0, 4, 0, INFINITY),
        /* 8: oblique, from below, into triangle 1 at (-0.5, 0.5, 1) */
        make_ray(-1, 0, 0, 0.5, 0.5, 1, 0, INFINITY),
    };
    static const uint8_t expect_occluded[N] = {1, 1, 0, 1, 0, 0, 0, 1, 1};
    static const uint32_t expect_triangle[N] = {0, 1, RAD_NO_HIT, 0, RAD_NO_HIT, RAD_NO_HIT,
                                                RAD_NO_HIT, 0, 1};
    static const float expect_t[N] = {1, 1, 0, 1, 0, 0, 0, 0.25f, 1};
    static const bool expect_front[N] = {false, true, false, false, false,
                                         false, false, false, false};

    uint8_t occluded[N];
    rad_hit hits[N];
    memset(occluded, 7, sizeof(occluded));
    rad_tracer_occluded(tracer, rays, N, occluded);
    rad_tracer_intersect(tracer, rays, N, hits);
    for (int k = 0; k < N; k++) {
        CHECK(occluded[k] == expect_occluded[k]);
        CHECK(hits[k].triangle == expect_triangle[k]);
        if (expect_triangle[k] == RAD_NO_HIT) {
            CHECK(isinf(hits[k].t) && hits[k].t > 0);
            continue;
        }
        CHECK_NEAR(hits[k].t, expect_t[k], 1e-6);
        CHECK(hits[k].front == expect_front[k]);
        check_hit_point(&hits[k], &rays[k]);
    }
    /* Barycentrics by hand: (0,0) = p0 + 0.5 (p1 - p0) + 0.25 (p2 - p0) in triangle 0, and
     * (-0.5, 0.5) = p0 + 0.25 (p2 - p0) + 0.5 (p3 - p0) in triangle 1. */
    CHECK_ABS(hits[0].u, 0.5, 1e-6);
    CHECK_ABS(hits[0].v, 0.25, 1e-6);
    CHECK_ABS(hits[1].u, 0.25, 1e-6);
    CHECK_ABS(hits[1].v, 0.5, 1e-6);

    /* No crack along the shared diagonal: rays aimed at points of it, from both sides and
     * at several slants, are all blocked (the seam between two patches must not leak). */
    enum { SEAM = 200 };
    rad_ray seam[SEAM];
    for (int k = 0; k < SEAM; k++) {
        double s = (k + 0.5) / SEAM; /* along p0 -> p2 */
        double x = -0.75 + s, y = -0.25 + s;
        double ox = x + 0.3 * ((k % 7) - 3), oy = y - 0.2 * ((k % 5) - 2);
        double oz = k % 2 ? -1.0 - 0.01 * k : 3.0 + 0.01 * k;
        seam[k] = make_ray(ox, oy, oz, x - ox, y - oy, 1 - oz, 0, INFINITY);
    }
    uint8_t seam_occluded[SEAM];
    rad_tracer_occluded(tracer, seam, SEAM, seam_occluded);
    int leaks = 0;
    for (int k = 0; k < SEAM; k++)
        leaks += !seam_occluded[k];
    CHECK(leaks == 0);
    rad_tracer_destroy(tracer);
}

/* ------------------------------------------------------------------------------------ */
/* Random soup: Embree against the oracle. */

enum { SOUP_TRIANGLES = 500, SOUP_RAYS = 6000 };

static void make_soup(uint64_t *rng, rad_vec3 *positions, uint32_t (*triangles)[3])
{
    for (uint32_t t = 0; t < SOUP_TRIANGLES; t++) {
        double cx = rng_uniform(rng, 0, 1), cy = rng_uniform(rng, 0, 1),
               cz = rng_uniform(rng, 0, 1);
        for (int k = 0; k < 3; k++) {
            /* One draw per statement: argument order is unspecified, the data must not be. */
            rad_vec3 *p = &positions[3 * t + (uint32_t)k];
            p->x = cx + rng_uniform(rng, -0.12, 0.12);
            p->y = cy + rng_uniform(rng, -0.12, 0.12);
            p->z = cz + rng_uniform(rng, -0.12, 0.12);
            triangles[t][k] = 3 * t + (uint32_t)k;
        }
    }
}

/* Thirds: segments between random points (t in [0,1]); infinite rays in random
 * directions; segments with t_near > 0 aimed through a point of a random triangle. */
static void make_rays(uint64_t *rng, const rad_vec3 *positions, rad_ray *rays)
{
    for (uint32_t i = 0; i < SOUP_RAYS; i++) {
        double ox = rng_uniform(rng, -0.2, 1.2), oy = rng_uniform(rng, -0.2, 1.2),
               oz = rng_uniform(rng, -0.2, 1.2);
        if (i % 3 == 0) {
            double bx = rng_uniform(rng, -0.2, 1.2), by = rng_uniform(rng, -0.2, 1.2),
                   bz = rng_uniform(rng, -0.2, 1.2);
            rays[i] = make_ray(ox, oy, oz, bx - ox, by - oy, bz - oz, 0, 1);
        } else if (i % 3 == 1) {
            double dx = rng_uniform(rng, -1, 1), dy = rng_uniform(rng, -1, 1),
                   dz = rng_uniform(rng, -1, 1);
            rays[i] = make_ray(ox, oy, oz, dx, dy, dz, 0, INFINITY);
        } else {
            uint32_t t = (uint32_t)(rng_next(rng) % SOUP_TRIANGLES);
            double a = rng_uniform(rng, 0, 1), b = rng_uniform(rng, 0, 1);
            if (a + b > 1) {
                a = 1 - a;
                b = 1 - b;
            }
            rad_vec3 p0 = positions[3 * t], p1 = positions[3 * t + 1], p2 = positions[3 * t + 2];
            double tx = p0.x + a * (p1.x - p0.x) + b * (p2.x - p0.x);
            double ty = p0.y + a * (p1.y - p0.y) + b * (p2.y - p0.y);
            double tz = p0.z + a * (p1.z - p0.z) + b * (p2.z - p0.z);
            double t_near = rng_uniform(rng, 0, 0.5);
            double t_far = t_near + rng_uniform(rng, 0, 1.5);
            rays[i] = make_ray(ox, oy, oz, tx - ox, ty - oy, tz - oz, t_near, t_far);
        }
    }
}

/* |cos| of the angle between a ray and a triangle's normal. */
static double ray_cosine(const rad_ray *ray, const rad_vec3 *positions, const uint32_t *tri)
{
    rad_vec3 p0 = positions[tri[0]], p1 = positions[tri[1]], p2 = positions[tri[2]];
    double a[3] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
    double b[3] = {p2.x - p0.x, p2.y - p0.y, p2.z - p0.z};
    double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    const float *d = ray->direction;
    double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double dd = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
    return fabs(nd) / (nn * dd);
}

static void test_soup(void)
{
    uint64_t rng = 0x9E3779B97F4A7C15ull;
    rad_vec3 *positions = calloc(3 * SOUP_TRIANGLES, sizeof(*positions));
    uint32_t(*triangles)[3] = calloc(SOUP_TRIANGLES, sizeof(*triangles));
    rad_ray *rays = calloc(SOUP_RAYS, sizeof(*rays));
    uint8_t *occluded[2] = {calloc(SOUP_RAYS, 1), calloc(SOUP_RAYS, 1)};
    rad_hit *hits[2] = {calloc(SOUP_RAYS, sizeof(rad_hit)), calloc(SOUP_RAYS, sizeof(rad_hit))};
    rad_tracer *tracers[2] = {NULL, NULL};
    CHECK(positions && triangles && rays && occluded[0] && occluded[1] && hits[0] && hits[1]);
    if (!(positions && triangles && rays && occluded[0] && occluded[1] && hits[0] && hits[1]))
        goto done;
    make_soup(&rng, positions, triangles);
    make_rays(&rng, positions, rays);

    for (int b = 0; b < 2; b++) {
        rad_error error = {0};
        rad_status status = rad_tracer_create(backends[b], positions, 3 * SOUP_TRIANGLES,
                                              (const uint32_t(*)[3])triangles, SOUP_TRIANGLES,
                                              &tracers[b], &error);
        CHECK(status == RAD_OK);
        if (status != RAD_OK) {
            fprintf(stderr, "%s: %s\n", backend_names[b], error.message);
            goto done;
        }
        rad_tracer_occluded(tracers[b], rays, SOUP_RAYS, occluded[b]);
        rad_tracer_intersect(tracers[b], rays, SOUP_RAYS, hits[b]);
    }

    int occluded_count = 0, flag_mismatches = 0, hit_mismatches = 0, ties = 0, grazing = 0;
    int consistency_errors = 0;
    for (uint32_t i = 0; i < SOUP_RAYS; i++) {
        occluded_count += occluded[1][i];
        flag_mismatches += occluded[0][i] != occluded[1][i];
        /* Within one backend, occluded and intersect must agree exactly. */
        for (int b = 0; b < 2; b++)
            consistency_errors += occluded[b][i] != (hits[b][i].triangle != RAD_NO_HIT);
        const rad_hit *e = &hits[0][i], *o = &hits[1][i];
        if ((e->triangle == RAD_NO_HIT) != (o->triangle == RAD_NO_HIT)) {
            hit_mismatches++;
            continue;
        }
        if (o->triangle == RAD_NO_HIT)
            continue;
        if (ray_cosine(&rays[i], positions, triangles[o->triangle]) < GRAZING_COS) {
            grazing++;
            continue;
        }
        CHECK_ABS(e->t, o->t, T_RELATIVE * fmax(o->t, T_FLOOR));
        if (e->triangle != o->triangle) {
            ties++; /* two hits equally near: only t must agree (checked above) */
            continue;
        }
        CHECK_ABS(e->u, o->u, UV_ABSOLUTE);
        CHECK_ABS(e->v, o->v, UV_ABSOLUTE);
        CHECK(e->front == o->front);
    }
    printf("soup: %d rays, %d occluded, %d flag and %d hit mismatches, %d ties, %d grazing\n",
           SOUP_RAYS, occluded_count, flag_mismatches, hit_mismatches, ties, grazing);
    CHECK(flag_mismatches <= MAX_GRAZING_MISMATCHES);
    CHECK(hit_mismatches <= MAX_GRAZING_MISMATCHES);
    CHECK(ties <= MAX_GRAZING_MISMATCHES);
    CHECK(grazing <= SOUP_RAYS / 100);
    CHECK(consistency_errors <= MAX_GRAZING_MISMATCHES);
    /* Not vacuous: a good share of the rays hit, a good share miss. */
    CHECK(occluded_count > SOUP_RAYS / 5 && occluded_count < SOUP_RAYS * 4 / 5);

    /* Several threads on one tracer, each calling with chunks the serial call also made
     * (same rays grouped the same way): answers must be identical. */
    enum { BLOCK = 256 };
    uint8_t *parallel_occluded = calloc(SOUP_RAYS, 1);
    rad_hit *parallel_hits = calloc(SOUP_RAYS, sizeof(rad_hit));
    CHECK(parallel_occluded && parallel_hits);
    if (parallel_occluded && parallel_hits) {
        int blocks = (SOUP_RAYS + BLOCK - 1) / BLOCK;
        uint8_t *serial_occluded = calloc(SOUP_RAYS, 1);
        rad_hit *serial_hits = calloc(SOUP_RAYS, sizeof(rad_hit));
        CHECK(serial_occluded && serial_hits);
        if (serial_occluded && serial_hits) {
            for (int k = 0; k < blocks; k++) {
                uint32_t first = (uint32_t)k * BLOCK;
                uint32_t n = SOUP_RAYS - first < BLOCK ? SOUP_RAYS - first : BLOCK;
                rad_tracer_occluded(tracers[0], rays + first, n, serial_occluded + first);
                rad_tracer_intersect(tracers[0], rays + first, n, serial_hits + first);
            }
#pragma omp parallel for num_threads(4) schedule(dynamic, 1)
            for (int k = 0; k < blocks; k++) {
                uint32_t first = (uint32_t)k * BLOCK;
                uint32_t n = SOUP_RAYS - first < BLOCK ? SOUP_RAYS - first : BLOCK;
                rad_tracer_occluded(tracers[0], rays + first, n, parallel_occluded + first);
                rad_tracer_intersect(tracers[0], rays + first, n, parallel_hits + first);
            }
            int differ = 0;
            for (uint32_t i = 0; i < SOUP_RAYS; i++) {
                differ += parallel_occluded[i] != serial_occluded[i];
                differ += parallel_hits[i].triangle != serial_hits[i].triangle;
                differ += memcmp(&parallel_hits[i].t, &serial_hits[i].t, sizeof(float)) != 0;
            }
            CHECK(differ == 0);
        }
        free(serial_occluded);
        free(serial_hits);
    }
    free(parallel_occluded);
    free(parallel_hits);

done:
    for (int b = 0; b < 2; b++) {
        rad_tracer_destroy(tracers[b]);
        free(occluded[b]);
        free(hits[b]);
    }
    free(positions);
    free(triangles);
    free(rays);
}

/* ------------------------------------------------------------------------------------ */
/* Arguments and the empty scene. */

static void test_invalid(rad_tracer_backend backend)
{
    static const uint32_t bad_index[2][3] = {{0, 1, 2}, {0, 2, 4}};
    rad_tracer *tracer = (rad_tracer *)&tracer; /* must be reset to NULL on failure */
    rad_error error = {0};
    CHECK(rad_tracer_create(backend, square_positions, 4, bad_index, 2, &tracer, &error) ==
          RAD_ERR_INVALID);
    CHECK(tracer == NULL);
    CHECK(error.status == RAD_ERR_INVALID);
    CHECK(strstr(error.message, "triangle 1") != NULL);

    rad_vec3 nan_positions[4];
    memcpy(nan_positions, square_positions, sizeof(nan_positions));
    nan_positions[2].y = NAN;
    CHECK(rad_tracer_create(backend, nan_positions, 4, square_triangles, 2, &tracer,
                            &error) == RAD_ERR_INVALID);
    nan_positions[2].y = 1e300; /* finite, but not in float range */
    CHECK(rad_tracer_create(backend, nan_positions, 4, square_triangles, 2, &tracer,
                            &error) == RAD_ERR_INVALID);
    CHECK(rad_tracer_create(backend, NULL, 4, square_triangles, 2, &tracer, &error) ==
          RAD_ERR_INVALID);
    CHECK(rad_tracer_create(backend, square_positions, 4, NULL, 2, &tracer, &error) ==
          RAD_ERR_INVALID);
    CHECK(rad_tracer_create(backend, square_positions, 4, square_triangles, 2, NULL, NULL) ==
          RAD_ERR_INVALID);
    CHECK(rad_tracer_create((rad_tracer_backend)7, square_positions, 4, square_triangles, 2,
                            &tracer, NULL) == RAD_ERR_INVALID);
    CHECK(tracer == NULL);
    rad_tracer_destroy(NULL); /* harmless */
}

static void test_empty(rad_tracer_backend backend)
{
    /* No triangles at all, and triangles' positions without triangles: every ray misses. */
    for (int with_positions = 0; with_positions < 2; with_positions++) {
        rad_tracer *tracer = NULL;
        rad_error error = {0};
        rad_status status =
            rad_tracer_create(backend, with_positions ? square_positions : NULL,
                              with_positions ? 4 : 0, NULL, 0, &tracer, &error);
        CHECK(status == RAD_OK);
        if (status != RAD_OK) {
            fprintf(stderr, "%s\n", error.message);
            continue;
        }
        rad_ray rays[300];
        for (int k = 0; k < 300; k++)
            rays[k] = make_ray(0, 0, 0, 0.01 * k - 1, 0.5, 1, 0, INFINITY);
        uint8_t occluded[300];
        rad_hit hits[300];
        memset(occluded, 1, sizeof(occluded));
        rad_tracer_occluded(tracer, rays, 300, occluded);
        rad_tracer_intersect(tracer, rays, 300, hits);
        int hit_count = 0;
        for (int k = 0; k < 300; k++)
            hit_count += occluded[k] + (hits[k].triangle != RAD_NO_HIT);
        CHECK(hit_count == 0);
        rad_tracer_occluded(tracer, NULL, 0, NULL); /* nothing to do */
        rad_tracer_destroy(tracer);
    }
}

int main(void)
{
    for (int b = 0; b < 2; b++) {
        test_square(backends[b]);
        test_invalid(backends[b]);
        test_empty(backends[b]);
    }
    test_soup();
    return test_finish("test_tracer");
}
