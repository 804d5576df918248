/*
 * test_scrambled_sobol.c - the Owen-scrambled Sobol points (core/scrambled_sobol.h) and
 * the cosine-weighted rays made from them (emitter_cosine_rays).
 *
 * - Net: for m = 0..12 and 50 seeds each, the first 2^m points put exactly one point in
 *   every cell of every 2^a x 2^(m - a) grid (Sobol's first two dimensions are a
 *   (0, m, 2)-net in base 2, and Owen's scrambling keeps that). A wrong direction number
 *   in the second dimension, or a scramble that lets a digit depend on the digits below
 *   it, fails here.
 * - The Gray-code walk (sobol_walk, what the rays use): its first 2^m points are the
 *   sequence's first 2^m, for m = 0..12 and 10 seeds each.
 * - Uniform: each point, over 40,000 seeds, is uniform on the square (its mean and its
 *   quarter fractions within 4.5 sigma): an unscrambled or half-scrambled digit fails.
 * - Integration: 1024 points, 400 seeds, of f(x, y) = exp(x) y^2 (exactly (e - 1) / 3):
 *   unbiased within 4.5 sigma, and the RMS error below 2.5e-4 relative (measured 7.6e-5;
 *   a jittered 32 x 32 grid gives 1.1e-3, the sequence unscrambled but shifted at random
 *   modulo 1 1.9e-3, independent uniform points 2.8e-2).
 * - The rays: for 1, 2, 8, 512, 1024 and 2048 rays every slot is written once (their
 *   cells' slots are a permutation), for 1600 in sequence order; the directions have
 *   unit length, lie in the hemisphere, cos_x is their cosine to n, and the mean cosine
 *   over 4096 rays is 2/3 (the cosine-weighted density's) to 2e-4.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/random.h"
#include "core/scrambled_sobol.h"
#include "core/vec3.h"
#include "render/emitter_light.h"
#include "testlib.h"
#include "trace/ray.h"

static void check_nets(void)
{
    static uint32_t count[1u << 12];
    rad_rng rng = rad_rng_seed(7, 7, 7);
    int broken = 0;
    for (unsigned m = 0; m <= 12; m++)
        for (int trial = 0; trial < 50; trial++) {
            uint32_t seed1 = (uint32_t)rad_rng_next(&rng), seed2 = (uint32_t)rad_rng_next(&rng);
            if (trial == 0)
                seed1 = seed2 = 0;
            for (unsigned a = 0; a <= m; a++) {
                const unsigned b = m - a;
                memset(count, 0, sizeof(count));
                for (uint32_t k = 0; k < (1u << m); k++) {
                    uint32_t x1, x2;
                    sobol_scrambled_bits(k, seed1, seed2, &x1, &x2);
                    uint32_t cx = a ? x1 >> (32 - a) : 0, cy = b ? x2 >> (32 - b) : 0;
                    count[(cy << a) | cx]++;
                }
                for (uint32_t c = 0; c < (1u << m); c++)
                    broken += count[c] != 1;
            }
        }
    printf("nets: %d cells without exactly one point\n", broken);
    CHECK(broken == 0);
}

static int compare_points(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The Gray-code walk's first 2^m points are the sequence's first 2^m, as a set. */
static void check_walk(void)
{
    static uint64_t by_index[1u << 12], walked[1u << 12];
    rad_rng rng = rad_rng_seed(9, 9, 9);
    int differ = 0;
    for (unsigned m = 0; m <= 12; m++)
        for (int trial = 0; trial < 10; trial++) {
            uint32_t seed1 = (uint32_t)rad_rng_next(&rng), seed2 = (uint32_t)rad_rng_next(&rng);
            sobol_walk walk = sobol_walk_start(seed1, seed2);
            for (uint32_t k = 0; k < (1u << m); k++) {
                uint32_t x1, x2;
                sobol_scrambled_bits(k, seed1, seed2, &x1, &x2);
                by_index[k] = (uint64_t)x1 << 32 | x2;
                sobol_walk_next(&walk, &x1, &x2);
                walked[k] = (uint64_t)x1 << 32 | x2;
            }
            qsort(by_index, 1u << m, sizeof(uint64_t), compare_points);
            qsort(walked, 1u << m, sizeof(uint64_t), compare_points);
            differ += memcmp(by_index, walked, (1u << m) * sizeof(uint64_t)) != 0;
        }
    CHECK(differ == 0);
}

static void check_uniform(void)
{
    const int seeds = 40000;
    const uint32_t points[] = {0, 1, 5, 100, 1023};
    rad_rng rng = rad_rng_seed(11, 2, 3);
    for (size_t p = 0; p < sizeof(points) / sizeof(points[0]); p++) {
        double mean[2] = {0, 0}, low[2] = {0, 0};
        for (int s = 0; s < seeds; s++) {
            uint32_t x[2];
            sobol_scrambled_bits(points[p], (uint32_t)rad_rng_next(&rng),
                                 (uint32_t)rad_rng_next(&rng), &x[0], &x[1]);
            for (int d = 0; d < 2; d++) {
                double u = x[d] / 4294967296.0;
                mean[d] += u / seeds;
                low[d] += (u < 0.25) / (double)seeds;
            }
        }
        for (int d = 0; d < 2; d++) {
            CHECK(fabs(mean[d] - 0.5) <= 4.5 * sqrt(1.0 / 12 / seeds));
            CHECK(fabs(low[d] - 0.25) <= 4.5 * sqrt(0.25 * 0.75 / seeds));
        }
    }
}

static void check_integration(void)
{
    const int seeds = 400;
    const uint32_t n = 1024;
    const double exact = (exp(1.0) - 1) / 3;
    rad_rng rng = rad_rng_seed(5, 5, 5);
    double sum = 0, squares = 0;
    for (int s = 0; s < seeds; s++) {
        uint32_t seed1 = (uint32_t)rad_rng_next(&rng), seed2 = (uint32_t)rad_rng_next(&rng);
        double estimate = 0;
        for (uint32_t k = 0; k < n; k++) {
            uint32_t x1, x2;
            sobol_scrambled_bits(k, seed1, seed2, &x1, &x2);
            double x = x1 / 4294967296.0, y = x2 / 4294967296.0;
            estimate += exp(x) * y * y;
        }
        double error = estimate / n / exact - 1;
        sum += error;
        squares += error * error;
    }
    double rms = sqrt(squares / seeds), bias = sum / seeds;
    printf("integration: relative RMS error %.3g, mean error %.3g\n", rms, bias);
    CHECK(rms < 2.5e-4);
    CHECK(fabs(bias) <= 4.5 * rms / sqrt(seeds));
}

static void check_rays(void)
{
    const uint32_t counts[] = {1, 2, 8, 512, 1024, 1600, 2048, 4096};
    rad_ray *rays = malloc(4096 * sizeof(*rays));
    double *cosines = malloc(4096 * sizeof(*cosines));
    if (!rays || !cosines) {
        CHECK(!"out of memory");
        free(rays);
        free(cosines);
        return;
    }
    rad_vec3 n = v3_normalize(v3(0.3, -0.5, 0.8)), x = v3(1, 2, 3);
    rad_rng rng = rad_rng_seed(1, 2, 3);
    for (size_t c = 0; c < sizeof(counts) / sizeof(counts[0]); c++) {
        const uint32_t count = counts[c];
        for (uint32_t k = 0; k < count; k++)
            cosines[k] = NAN;
        emitter_cosine_rays(x, n, 0.01, count, &rng, rays, cosines);
        double mean = 0;
        int bad = 0;
        for (uint32_t k = 0; k < count; k++) {
            rad_vec3 d = v3(rays[k].direction[0], rays[k].direction[1], rays[k].direction[2]);
            bad += !isfinite(cosines[k]);
            bad += !(fabs(v3_length(d) - 1) < 1e-6);
            bad += !(fabs(v3_dot(d, n) - cosines[k]) < 1e-6) || !(cosines[k] >= 0);
            mean += cosines[k] / count;
        }
        CHECK(bad == 0);
        if (count == 4096)
            CHECK_ABS(mean, 2.0 / 3, 2e-4);
    }
    free(rays);
    free(cosines);
}

int main(void)
{
    check_nets();
    check_walk();
    check_uniform();
    check_integration();
    check_rays();
    return test_finish("test_scrambled_sobol");
}
