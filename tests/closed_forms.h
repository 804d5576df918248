/*
 * closed_forms.h - view factors from the catalogue (Howell; VALIDATION.md) that more than
 * one test holds the engine to. Test code only: static inline, no library names.
 */
#ifndef RAD_TEST_CLOSED_FORMS_H
#define RAD_TEST_CLOSED_FORMS_H

#include <math.h>

static const double pi = 3.14159265358979323846;

/* Between two directly opposed a x b rectangles at distance c. */
static inline double parallel_rectangles(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    return 2 / (pi * X * Y) *
           (log(sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) +
            X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

/* From the w x l rectangle to the h x l one, sharing the edge l, at right angles. */
static inline double perpendicular_rectangles(double w, double h, double l)
{
    double W = w / l, H = h / l, W2 = W * W, H2 = H * H;
    double a = (1 + W2) * (1 + H2) / (1 + W2 + H2);
    double b = pow(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2)), W2);
    double c = pow(H2 * (1 + W2 + H2) / ((1 + H2) * (W2 + H2)), H2);
    return 1 / (pi * W) *
           (W * atan(1 / W) + H * atan(1 / H) - sqrt(H2 + W2) * atan(1 / sqrt(H2 + W2)) +
            0.25 * log(a * b * c));
}

#endif
