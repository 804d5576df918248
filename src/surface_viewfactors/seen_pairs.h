/*
 * seen_pairs.h - which surface pairs can see each other at all, found by rays, before any
 * pair is integrated.
 *
 * Each surface I casts `rays` cosine-distributed rays from uniform points of its polygons
 * (area-weighted, both sides of a two-sided surface) and notes the surface each one first
 * meets on its radiating side. A ray from a uniform point of I, cosine-distributed, meets
 * J first with probability exactly F_IJ (the definition of the view factor), so the
 * chance that none of I's N_I rays and none of J's N_J rays meets the other is
 * exp(-N_I F_IJ - N_J F_JI) at most, which is 5 % when the transfer G = A_I F_IJ = A_J F_JI
 * is SEEN_PAIRS_BOUND / (N_I / A_I + N_J / A_J):
 *
 *     G <= -ln(0.05) / (N_I / A_I + N_J / A_J)   (95 %), so F_IJ <= 3.0 / N_I.
 *
 * A pair neither side's rays met is taken as 0 with that bound, without a first look or a
 * proof: in a city most facing pairs are hidden (84 % of the 20k city's), and proving them
 * cost most of the matrix's time. With N = ceil(-ln 0.05 / accuracy) each such factor is
 * within `accuracy` absolute at 95 % (a per-pair statement: a pair whose factor is at the
 * bound goes unmet one time in 20, so among many such pairs some do), the floor of the
 * relative accuracy the integrated pairs meet.
 * Many such pairs in one row add up (a roof sees thousands of distant surfaces at 1e-6
 * each): the share of each surface's view its rays missed is estimated too (`missed`),
 * so that a run can say how much its rows may lack.
 *
 * Over MPI ranks every rank casts the rays of a share of the surfaces and all of them get
 * every surface's list, so any rank can decide any pair; the lists depend only on the seed
 * and the surface, so the pairs are the same for any thread or rank count.
 */
#ifndef RAD_VIEWFACTOR_SEEN_PAIRS_H
#define RAD_VIEWFACTOR_SEEN_PAIRS_H

#include "radiosity.h"
#include "surface_viewfactors/vf_geometry.h"

/* -ln(0.05): no ray of either side met the other with 95 % confidence when the transfer is
 * below this over (N_I / A_I + N_J / A_J). */
#define SEEN_PAIRS_BOUND 2.995732

typedef struct seen_pairs {
    uint32_t surface_count;
    uint64_t *row_start; /* surface_count + 1 */
    uint32_t *column;    /* row I: the J > I that a ray of I or of J met, ascending */
    float *missed;       /* per surface I: the share of its view held by surfaces none of
                            its rays met (Good and Turing: the surfaces met by exactly one
                            ray, over the rays), an estimate of what its row loses */
    uint32_t rays;       /* rays per surface with polygons */
    uint64_t rays_cast;  /* by this process */
} seen_pairs;

/* Casts the rays (threads OpenMP threads; over ranks, each its share) and builds the pairs.
 * `tracer` holds every triangle of `scene` in scene order. Collective over MPI ranks. */
rad_status seen_pairs_build(const rad_scene *scene, const vf_geometry *geometry,
                            const rad_tracer *tracer, uint32_t rays, uint64_t seed, int threads,
                            seen_pairs *out, rad_error *error);

/* The 95 % bound on the transfer G_IJ of a pair no ray met (surfaces I and J with polygons). */
static inline double seen_pairs_unseen_bound(const seen_pairs *s, double area_i, double area_j)
{
    return SEEN_PAIRS_BOUND / ((double)s->rays / area_i + (double)s->rays / area_j);
}

void seen_pairs_free(seen_pairs *s);

#endif
