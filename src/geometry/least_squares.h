/*
 * least_squares.h - weights that predict a function's value from samples by the
 * least-squares fit of a few basis terms (the normal equations, factored by Cholesky).
 *
 * The integrals' edge checks (polygon_integral.c, parallelogram_integral.c) compare f at
 * points no rule point is near with what the rule points predict there.
 */
#ifndef RAD_GEOMETRY_LEAST_SQUARES_H
#define RAD_GEOMETRY_LEAST_SQUARES_H

#define LEAST_SQUARES_MAX_TERMS 15

/* design[r * terms + i]: term i at sample r (rows samples, terms <= LEAST_SQUARES_MAX_TERMS
 * and <= rows, the terms independent on the samples); at[p * terms + i]: term i at point
 * p. Fills weights[p * rows + r] so that sum over r of weights[p * rows + r] y_r is the fit
 * to the samples y at point p. */
void least_squares_predictor(const double *design, int rows, int terms, const double *at,
                             int points, double *weights);

#endif
