/*
 * enclosure.c - the least-squares closure of an enclosure's view-factor matrix.
 *
 * Unknowns are the changes dG of the symmetric transfers G_IJ = A_I F_IJ over the stored
 * entries; minimising sum dG_IJ^2 / w_IJ (w = G^2: relative changes) under the row
 * constraints sum_J (G_IJ + dG_IJ) = A_I gives dG_IJ = w_IJ (mu_I + mu_J) with one
 * multiplier per row, and the rows give the system (D + W) mu = r, D_II = sum_J w_IJ, r_I
 * = A_I - sum_J G_IJ. Its quadratic form is (1/2) sum_IJ w_IJ (mu_I + mu_J)^2: positive
 * definite unless a connected group of surfaces splits into two sets that see only the
 * other set (no odd cycle, no surface seeing itself), which is checked before solving.
 * Solved by conjugate gradients with the diagonal as preconditioner, plus a refinement
 * pass on the rows' remaining residual.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "surface_viewfactors/matrix_entry.h"

/* Conjugate gradients stop at this residual relative to the right-hand side (double
 * precision's floor for these well-scaled systems). */
#define ENCLOSURE_CG_TOLERANCE 1e-14
/* Rows whose sum is this close to 1 (relative) need no refinement pass. */
#define ENCLOSURE_ROW_TOLERANCE 1e-13
enum { ENCLOSURE_REFINEMENTS = 3 };

typedef struct enclosure_system {
    const rad_viewfactor_matrix *m;
    const bool *active;
    const double *w; /* per stored entry, 0 for entries left out */
    double *diagonal;
} enclosure_system;

/* y = (D + W) x */
static void apply(const enclosure_system *s, const double *x, double *y)
{
    const rad_viewfactor_matrix *m = s->m;
    for (uint32_t I = 0; I < m->n; I++) {
        double sum = 0;
        if (s->active[I])
            for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
                sum += s->w[k] * (x[I] + x[m->column[k]]);
        y[I] = sum;
    }
}

/* Solves (D + W) x = b by preconditioned conjugate gradients; returns iterations. */
static uint32_t solve_cg(const enclosure_system *s, const double *b, double *x, double *work)
{
    uint32_t n = s->m->n;
    double *r = work, *z = work + n, *p = work + 2 * (size_t)n, *q = work + 3 * (size_t)n;
    double bnorm = 0;
    for (uint32_t i = 0; i < n; i++) {
        x[i] = 0;
        r[i] = b[i];
        bnorm += b[i] * b[i];
    }
    bnorm = sqrt(bnorm);
    if (bnorm == 0)
        return 0;
    double rz = 0;
    for (uint32_t i = 0; i < n; i++) {
        z[i] = s->diagonal[i] > 0 ? r[i] / s->diagonal[i] : 0;
        p[i] = z[i];
        rz += r[i] * z[i];
    }
    uint32_t limit = 10 * n + 100, it = 0;
    for (; it < limit; it++) {
        apply(s, p, q);
        double pq = 0;
        for (uint32_t i = 0; i < n; i++)
            pq += p[i] * q[i];
        if (!(pq > 0))
            break;
        double alpha = rz / pq, rnorm = 0;
        for (uint32_t i = 0; i < n; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            rnorm += r[i] * r[i];
        }
        if (sqrt(rnorm) <= ENCLOSURE_CG_TOLERANCE * bnorm)
            return it + 1;
        double rz_next = 0;
        for (uint32_t i = 0; i < n; i++) {
            z[i] = s->diagonal[i] > 0 ? r[i] / s->diagonal[i] : 0;
            rz_next += r[i] * z[i];
        }
        double beta = rz_next / rz;
        rz = rz_next;
        for (uint32_t i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i];
    }
    return it;
}

static const char *surface_name(const rad_scene *scene, uint32_t I, char *buffer, size_t size)
{
    if (scene && I < scene->surface_count)
        snprintf(buffer, size, "surface '%s'", scene->surfaces[I].name);
    else
        snprintf(buffer, size, "surface %u", I + 1);
    return buffer;
}

/* 0 when every connected group of active surfaces has an odd cycle or a surface that sees
 * itself (the system is then positive definite); else 1 + a surface of a group that does
 * not. */
static uint32_t find_singular_group(const rad_viewfactor_matrix *m, const bool *active,
                                    const double *w, uint32_t *colour, uint32_t *queue)
{
    for (uint32_t I = 0; I < m->n; I++)
        colour[I] = 0;
    for (uint32_t start = 0; start < m->n; start++) {
        if (!active[start] || colour[start])
            continue;
        bool definite = false;
        uint32_t head = 0, tail = 0;
        queue[tail++] = start;
        colour[start] = 1;
        while (head < tail) {
            uint32_t I = queue[head++];
            for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
                uint32_t J = m->column[k];
                if (!(w[k] > 0))
                    continue;
                if (J == I || colour[J] == colour[I])
                    definite = true;
                else if (!colour[J]) {
                    colour[J] = 3 - colour[I];
                    queue[tail++] = J;
                }
            }
        }
        if (!definite)
            return start + 1;
    }
    return 0;
}

rad_status rad_viewfactor_matrix_close_enclosure(rad_viewfactor_matrix *m,
                                                 const rad_scene *scene,
                                                 rad_enclosure_report *report,
                                                 rad_error *error)
{
    rad_enclosure_report local;
    if (!report)
        report = &local;
    memset(report, 0, sizeof(*report));
    uint32_t n = m->n;
    uint64_t nz = m->row_start[n];
    /* every failure names the scene's file: the user's handle on what to fix */
    const char *source = scene ? scene->source : "view-factor matrix";
    if (scene && scene->surface_count != n)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: the enclosure correction: the matrix has %u surfaces, the scene %u",
                        source, n, scene->surface_count);
    rad_status status = RAD_OK;
    char name[160];
    bool *active = rad_alloc_array(n, sizeof(*active));
    double *G = rad_alloc_array(nz, sizeof(*G));
    double *w = rad_alloc_array(nz, sizeof(*w));
    double *diagonal = rad_alloc_array(n, sizeof(*diagonal));
    double *rhs = rad_alloc_array(n, sizeof(*rhs));
    double *mu = rad_alloc_array(n, sizeof(*mu));
    double *work = rad_alloc_array(n, 4 * sizeof(*work));
    uint32_t *colour = rad_alloc_array(n, sizeof(*colour));
    uint32_t *queue = rad_alloc_array(n, sizeof(*queue));
    if (!active || !G || !w || !diagonal || !rhs || !mu || !work || !colour || !queue) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for the enclosure correction",
                          source);
        goto done;
    }
    for (uint32_t I = 0; I < n; I++)
        active[I] = !(scene && (scene->surfaces[I].flags & RAD_SURFACE_OBSTRUCTION));

    /* symmetric transfers and weights; the constant part of each row */
    for (uint32_t I = 0; I < n; I++) {
        if (!active[I])
            continue;
        if (!(m->area[I] > 0) || !isfinite(m->area[I])) {
            status = rad_fail(error, RAD_ERR_INVALID,
                              "%s: the enclosure correction: %s has area %g", source,
                              surface_name(scene, I, name, sizeof(name)), m->area[I]);
            goto done;
        }
        double row = 0, fixed = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            if (!(m->value[k] >= 0) || !isfinite(m->value[k])) {
                status = rad_fail(error, RAD_ERR_INVALID,
                                  "%s: the enclosure correction: F from %s to surface %u is %g, "
                                  "not a view factor",
                                  source, surface_name(scene, I, name, sizeof(name)), J + 1,
                                  m->value[k]);
                goto done;
            }
            row += m->value[k];
            if (!active[J] || m->value[k] == 0) {
                fixed += m->area[I] * m->value[k];
                continue;
            }
            uint64_t t = vf_matrix_entry(m, J, I);
            if (t == UINT64_MAX) {
                status = rad_fail(error, RAD_ERR_INVALID,
                                  "%s: the enclosure correction: F from %s to surface %u is "
                                  "stored without its reciprocal",
                                  source, surface_name(scene, I, name, sizeof(name)), J + 1);
                goto done;
            }
            G[k] = 0.5 * (m->area[I] * m->value[k] + m->area[J] * m->value[t]);
            w[k] = G[k] * G[k];
        }
        report->row_deviation_before = fmax(report->row_deviation_before, fabs(row - 1));
        rhs[I] = m->area[I] - fixed;
    }
    for (uint32_t I = 0; I < n; I++) {
        if (!active[I])
            continue;
        double weight = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            weight += w[k];
            if (m->column[k] == I)
                weight += w[k];
        }
        diagonal[I] = weight;
        if (!(weight > 0)) {
            status = rad_fail(error, RAD_ERR_INVALID,
                              "%s: the enclosure correction: %s sees nothing (an empty row): "
                              "it cannot be part of a closed enclosure",
                              source, surface_name(scene, I, name, sizeof(name)));
            goto done;
        }
    }
    uint32_t singular = find_singular_group(m, active, w, colour, queue);
    if (singular) {
        status = rad_fail(error, RAD_ERR_INVALID,
                          "%s: the enclosure correction is singular: %s and the surfaces it "
                          "sees split into two sets that see only each other",
                          source, surface_name(scene, singular - 1, name, sizeof(name)));
        goto done;
    }

    /* solve, then refine on what the rows still miss */
    enclosure_system system = {m, active, w, diagonal};
    double *delta = G; /* G + dG accumulates in place */
    for (int pass = 0; pass <= ENCLOSURE_REFINEMENTS; pass++) {
        double worst = 0;
        for (uint32_t I = 0; I < n; I++) {
            if (!active[I]) {
                rhs[I] = 0;
                continue;
            }
            double sum = 0, fixed = 0;
            for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
                if (active[m->column[k]] && m->value[k] != 0)
                    sum += delta[k];
                else
                    fixed += m->area[I] * m->value[k];
            }
            rhs[I] = m->area[I] - fixed - sum;
            worst = fmax(worst, fabs(rhs[I]) / m->area[I]);
        }
        if (worst <= ENCLOSURE_ROW_TOLERANCE)
            break;
        report->iterations += solve_cg(&system, rhs, mu, work);
        for (uint32_t I = 0; I < n; I++)
            for (uint64_t k = m->row_start[I]; active[I] && k < m->row_start[I + 1]; k++)
                delta[k] += w[k] * (mu[I] + mu[m->column[k]]);
    }
    for (uint32_t I = 0; I < n; I++)
        for (uint64_t k = m->row_start[I]; active[I] && k < m->row_start[I + 1]; k++)
            if (w[k] > 0 && !(delta[k] > 0)) {
                char other[160];
                status = rad_fail(error, RAD_ERR_INVALID,
                                  "%s: the enclosure correction would make the view factor from "
                                  "%s to %s negative: the matrix is too far from closed "
                                  "(largest row-sum deviation %g)",
                                  source, surface_name(scene, I, name, sizeof(name)),
                                  surface_name(scene, m->column[k], other, sizeof(other)),
                                  report->row_deviation_before);
                goto done;
            }

    /* write back */
    for (uint32_t I = 0; I < n; I++)
        for (uint64_t k = m->row_start[I]; active[I] && k < m->row_start[I + 1]; k++) {
            if (!(w[k] > 0))
                continue;
            double F = delta[k] / m->area[I];
            report->largest_relative_change =
                fmax(report->largest_relative_change, fabs(F - m->value[k]) / m->value[k]);
            m->value[k] = F;
        }
    for (uint32_t I = 0; I < n; I++) {
        if (!active[I])
            continue;
        double row = 0;
        for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++) {
            uint32_t J = m->column[k];
            row += m->value[k];
            double a = m->area[I] * m->value[k];
            double b = m->area[J] * rad_viewfactor_matrix_get(m, J, I);
            if (fmax(a, b) > 0)
                report->reciprocity_after =
                    fmax(report->reciprocity_after, fabs(a - b) / fmax(a, b));
        }
        report->row_deviation_after = fmax(report->row_deviation_after, fabs(row - 1));
    }
done:
    free(active);
    free(G);
    free(w);
    free(diagonal);
    free(rhs);
    free(mu);
    free(work);
    free(colour);
    free(queue);
    return status;
}
