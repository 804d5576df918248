/*
 * test_sine_cosine.c - the sampling code's own sin and cos (core/sine_cosine.h) against
 * libm's in long double, and the base-2 radical inverse's bit reversal (core/random.h)
 * against the digit sum it stands for.
 *
 * sine_cosine: 2 million angles spread over [-1e5, 1e5] and 2 million over the azimuths
 * the cosine-weighted rays use, [0, 4 pi), plus the multiples of pi/4 and their
 * neighbours (where the reduction changes quadrant): every value within 3e-16 of sinl
 * and cosl, and sin^2 + cos^2 within 5e-16 of 1. With the degree-15 term of sin left
 * out, the error reaches 2.1e-14 and the test fails.
 */
#include <math.h>
#include <stdio.h>

#include "core/random.h"
#include "core/sine_cosine.h"
#include "core/vec3.h"
#include "testlib.h"

static double worst = 0;

static void check_angle(double x)
{
    double s, c;
    sine_cosine(x, &s, &c);
    double es = fabs((double)((long double)s - sinl((long double)x)));
    double ec = fabs((double)((long double)c - cosl((long double)x)));
    double e = es > ec ? es : ec;
    if (e > worst)
        worst = e;
    CHECK(e <= 3e-16);
    CHECK(fabs(s * s + c * c - 1) <= 5e-16);
}

/* The radical inverse in base 2 as the digit sum: digit k of j times 2^-(k+1). */
static double digit_sum(uint32_t j)
{
    double value = 0, scale = 0.5;
    for (; j > 0; j /= 2, scale *= 0.5)
        value += (j % 2) * scale;
    return value;
}

int main(void)
{
    rad_rng rng = rad_rng_seed(3, 1, 4);
    for (int k = 0; k < 2000000; k++)
        check_angle(-1e5 + 2e5 * rad_rng_uniform(&rng));
    for (int k = 0; k < 2000000; k++)
        check_angle(4 * RAD_PI * rad_rng_uniform(&rng));
    for (int k = -4000; k <= 4000; k++) {
        double x = k * (RAD_PI / 4);
        check_angle(x);
        check_angle(nextafter(x, INFINITY));
        check_angle(nextafter(x, -INFINITY));
    }
    check_angle(0);
    check_angle(-0.0);
    check_angle(1e-300);
    printf("sine_cosine: largest error %.3g\n", worst);

    /* bit for bit the digit sum, over the first 2^20 and over the top of the range */
    for (uint32_t j = 0; j < (1u << 20); j++)
        CHECK(rad_radical_inverse(j, 2) == digit_sum(j));
    for (uint32_t j = UINT32_MAX; j > UINT32_MAX - 100000u; j--)
        CHECK(rad_radical_inverse(j, 2) == digit_sum(j));
    CHECK(rad_radical_inverse(1, 2) == 0.5);
    CHECK(rad_radical_inverse(6, 2) == 0.375);
    CHECK_ABS(rad_radical_inverse(5, 3), 7.0 / 9, 1e-15);
    return test_finish("test_sine_cosine");
}
