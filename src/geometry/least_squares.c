/*
 * least_squares.c - least-squares prediction weights, see least_squares.h.
 */
#include "geometry/least_squares.h"

#include <math.h>

void least_squares_predictor(const double *design, int rows, int terms, const double *at,
                             int points, double *weights)
{
    /* the normal equations' matrix A^T A, factored L L^T (Cholesky) */
    double normal[LEAST_SQUARES_MAX_TERMS][LEAST_SQUARES_MAX_TERMS];
    for (int i = 0; i < terms; i++)
        for (int j = 0; j < terms; j++) {
            normal[i][j] = 0;
            for (int r = 0; r < rows; r++)
                normal[i][j] += design[r * terms + i] * design[r * terms + j];
        }
    for (int j = 0; j < terms; j++) {
        for (int k = 0; k < j; k++)
            normal[j][j] -= normal[j][k] * normal[j][k];
        normal[j][j] = sqrt(normal[j][j]);
        for (int i = j + 1; i < terms; i++) {
            for (int k = 0; k < j; k++)
                normal[i][j] -= normal[i][k] * normal[j][k];
            normal[i][j] /= normal[j][j];
        }
    }
    for (int p = 0; p < points; p++) {
        /* x = (A^T A)^-1 terms(p); the prediction's weights are A x */
        double x[LEAST_SQUARES_MAX_TERMS];
        for (int i = 0; i < terms; i++)
            x[i] = at[p * terms + i];
        for (int i = 0; i < terms; i++) {
            for (int k = 0; k < i; k++)
                x[i] -= normal[i][k] * x[k];
            x[i] /= normal[i][i];
        }
        for (int i = terms - 1; i >= 0; i--) {
            for (int k = i + 1; k < terms; k++)
                x[i] -= normal[k][i] * x[k];
            x[i] /= normal[i][i];
        }
        for (int r = 0; r < rows; r++) {
            weights[p * rows + r] = 0;
            for (int i = 0; i < terms; i++)
                weights[p * rows + r] += design[r * terms + i] * x[i];
        }
    }
}
