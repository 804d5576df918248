/*
 * row_repair.c - trimming the rows of a view-factor matrix that sum above 1 while keeping
 * reciprocity, for open and closed scenes alike; see radiosity.h.
 *
 * With the symmetric transfers G_IJ = A_I F_IJ (the mean of A_I F_IJ and A_J F_JI where
 * they differ) every surface gets a scale s_I in (0, 1] and the repaired transfers are
 * G'_IJ = s_I s_J G_IJ, symmetric by construction, so A_I F'_IJ = A_J F'_JI holds to
 * rounding. The scales are the fixed point of s_I = min(1, root of
 * s_I^2 G_II + s_I sum_{J != I} s_J G_IJ = A_I), found by Gauss-Seidel sweeps in row order
 * (deterministic): a row above 1 is brought to 1, a row below 1 keeps s = 1 unless its
 * neighbours' trimming let it rise back. Rows never gain exchange: 0 < s <= 1. Rows below
 * 1 are left as they are (the rest of their hemisphere is sky, or an error this cannot
 * see); closing a closed enclosure's rows is rad_viewfactor_matrix_close_enclosure's job.
 *
 * Not here: deciding whether a change is acceptable beyond the limits the caller gives.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "surface_viewfactors/matrix_entry.h"

/* The sweeps stop when no scale moved by more than this (relative). */
#define REPAIR_TOLERANCE 1e-15
enum { REPAIR_MAX_SWEEPS = 100000 };

static bool skipped(const rad_scene *scene, uint32_t I)
{
    return scene && (scene->surfaces[I].flags & RAD_SURFACE_OBSTRUCTION);
}

/* g[k]: the symmetric transfer of stored entry k. False when F_IJ is stored without F_JI. */
static bool symmetric_transfers(const rad_viewfactor_matrix *m, double *g, uint64_t *missing)
{
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            if (J == I) {
                g[k] = m->area[I] * m->value[k];
                continue;
            }
            uint64_t t = vf_matrix_entry(m, J, I);
            if (t == UINT64_MAX) {
                if (m->value[k] == 0) {
                    g[k] = 0;
                    continue;
                }
                *missing = k;
                return false;
            }
            g[k] = 0.5 * (m->area[I] * m->value[k] + m->area[J] * m->value[t]);
        }
    return true;
}

/* The scale that brings row I to 1 given the others', at most 1. */
static double row_scale(const rad_viewfactor_matrix *m, const double *g, const double *s,
                        uint32_t I)
{
    double self = 0, others = 0;
    for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
        uint32_t J = m->column[k];
        if (J == I)
            self += g[k];
        else
            others += s[J] * g[k];
    }
    double a = self / m->area[I], b = others / m->area[I];
    if (a + b <= 1) /* s = 1 keeps the row at or below 1 */
        return 1;
    /* the positive root of a s^2 + b s = 1, written without cancellation */
    return 2 / (b + sqrt(b * b + 4 * a));
}

rad_status rad_viewfactor_matrix_repair_rows(rad_viewfactor_matrix *matrix,
                                             const rad_scene *scene,
                                             const rad_row_repair_limits *limits,
                                             rad_row_repair_report *report, rad_error *error)
{
    const rad_viewfactor_matrix *m = matrix;
    const char *source = scene ? scene->source : "view factors";
    memset(report, 0, sizeof(*report));
    uint64_t total = m->row_start[m->n];
    double *g = rad_alloc_array(total ? total : 1, sizeof(double));
    double *s = rad_alloc_array(m->n ? m->n : 1, sizeof(double));
    if (!g || !s) {
        free(g);
        free(s);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the row repair", source);
    }
    uint64_t missing = 0;
    if (!symmetric_transfers(m, g, &missing)) {
        uint32_t I = 0;
        while (m->row_start[I + 1] <= missing)
            I++;
        free(g);
        free(s);
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: row repair: F from surface %u to %u is stored without its "
                        "reciprocal",
                        source, I, m->column[missing]);
    }
    double exchange = 0;
    for (uint32_t I = 0; I < m->n; I++) {
        s[I] = 1;
        double sum = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            sum += m->value[k];
            exchange += g[k];
        }
        if (skipped(scene, I) || !(m->area[I] > 0))
            continue;
        report->largest_row_sum_before = fmax(report->largest_row_sum_before, sum);
        report->rows_above_one += sum > 1;
    }
    /* Gauss-Seidel sweeps until the scales settle */
    uint32_t sweep = 0;
    for (; sweep < REPAIR_MAX_SWEEPS; sweep++) {
        double moved = 0;
        for (uint32_t I = 0; I < m->n; I++) {
            if (skipped(scene, I) || !(m->area[I] > 0))
                continue;
            double next = row_scale(m, g, s, I);
            moved = fmax(moved, fabs(next - s[I]) / next);
            s[I] = next;
        }
        if (moved <= REPAIR_TOLERANCE)
            break;
    }
    report->sweeps = sweep + 1;
    /* what the repair would do, measured entry by entry before anything changes */
    double removed = 0;
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            double repaired = s[I] * s[J] * g[k] / m->area[I];
            double change = fabs(repaired - m->value[k]);
            removed += (1 - s[I] * s[J]) * g[k];
            if (change > report->largest_change) {
                report->largest_change = change;
                report->largest_change_row = I;
                report->largest_change_column = J;
                report->largest_change_before = m->value[k];
                report->largest_change_after = repaired;
            }
            if (m->value[k] > 0 && change / m->value[k] > report->largest_relative_change) {
                report->largest_relative_change = change / m->value[k];
                report->largest_relative_row = I;
                report->largest_relative_column = J;
            }
        }
    report->removed_share = exchange > 0 ? removed / exchange : 0;
    double max_change = limits && limits->max_relative_change > 0 ? limits->max_relative_change
                                                                  : INFINITY;
    double max_removed = limits && limits->max_removed_share > 0 ? limits->max_removed_share
                                                                 : INFINITY;
    if (report->largest_relative_change > max_change) {
        report->refused = RAD_ROW_REPAIR_REFUSED_CHANGE;
        free(g);
        free(s);
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: row repair refused: a factor would change by %.3g of its value "
                        "(more than the limit %.3g)",
                        source, report->largest_relative_change, max_change);
    }
    if (report->removed_share > max_removed) {
        report->refused = RAD_ROW_REPAIR_REFUSED_REMOVED;
        free(g);
        free(s);
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: row repair refused: it would remove %.3g of the exchange (more "
                        "than the limit %.3g)",
                        source, report->removed_share, max_removed);
    }
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
            matrix->value[k] = fmin(s[I] * s[m->column[k]] * g[k] / m->area[I], 1.0);
    for (uint32_t I = 0; I < m->n; I++) {
        double sum = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            sum += m->value[k];
            uint32_t J = m->column[k];
            if (J == I || m->value[k] == 0)
                continue;
            double a = m->area[I] * m->value[k];
            double b = m->area[J] * rad_viewfactor_matrix_get(m, J, I);
            report->reciprocity_after = fmax(report->reciprocity_after, fabs(a - b) / fmax(a, b));
        }
        report->rows_trimmed += s[I] < 1;
        if (!skipped(scene, I) && m->area[I] > 0)
            report->largest_row_sum_after = fmax(report->largest_row_sum_after, sum);
    }
    free(g);
    free(s);
    return RAD_OK;
}
