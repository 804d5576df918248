/*
 * pair_transfer.h - the transfer G_pq = A_p F_pq between two convex polygons.
 *
 * Unobstructed: the outer integral of Lambert's contour formula (exact point-to-polygon
 * factor) over the smaller polygon by adaptive quadrature: a 7-point degree-5 rule on each
 * triangle, compared with its 4 children, split further where they disagree, to a
 * relative tolerance. Obstructed by up to a set number of triangles: the same integral of
 * the exact factor to the part left visible by their shadows (shadow_clip.h), each
 * triangle of the splitting clipped by the occluders that can shade it only. By more, or when
 * the visible part breaks into too many pieces: the unobstructed value times the visible
 * fraction, estimated from replicated stratified segments between the polygons, weighted
 * by the kernel cos cos / r^2; rounds of 4x more segments until the estimate's error bound
 * meets the target or the ray budget is spent. Only segments of weight > 0 count. The
 * bound is the replicates' spread (Student t), and at least what the rarer outcome's count
 * allows (a Poisson limit: m of n segments visible, or blocked, are consistent with a
 * share up to about (m + 1.6 sqrt(m) + 2) / n, 3 / n for m = 0): when every segment of a
 * round agreed, the binomial PAIR_UNSEEN_BOUND / n on what they could all have missed, so
 * a pair whose segments were all blocked still carries the error it may have; when a few
 * got through a street among many blocked, more than their spread. The caller passes only
 * the parts of the polygons in front of each other's planes, where the kernel is not 0.
 * The result never exceeds the unobstructed value.
 */
#ifndef RAD_VIEWFACTOR_PAIR_TRANSFER_H
#define RAD_VIEWFACTOR_PAIR_TRANSFER_H

#include "radiosity.h"
#include "surface_viewfactors/shadow_clip.h"
#include "surface_viewfactors/vf_geometry.h"

/* Replicates of the visibility estimate; its spread gives the error bound. */
#define PAIR_REPLICATES 8u

/* Two-sided 95 % Student t for PAIR_REPLICATES - 1 = 7 degrees of freedom. */
#define PAIR_STUDENT_T 2.365

/* -ln(0.05): when all n segments of a round agree (all blocked, or all free), the other
 * outcome's share is below PAIR_UNSEEN_BOUND / n with 95 % confidence (binomial: a share f
 * passes n stratified segments unseen with probability at most (1 - f)^n <= exp(-n f)). */
#define PAIR_UNSEEN_BOUND 2.995732

/* One-sided 95 % normal quantile (the rarer outcome's Poisson limit, pair_transfer.c). */
#define PAIR_ONE_SIDED_Z 1.644854

/* The one-sided 95 % upper limit of a Poisson mean when m events were seen: m = 0 gives
 * PAIR_UNSEEN_BOUND, more Wilson and Hilferty's cube-root approximation (within 1 % of
 * the exact limit). A sampled share's bound is at least (limit - m) / n for the rarer
 * outcome's count m among n: the replicates' spread says little when one outcome is rare. */
double pair_poisson_upper(uint64_t m);

/* The unobstructed transfer, to relative tolerance `accuracy` (and *bound receives the
 * estimated absolute error). plane_epsilon as in vf_geometry. */
double pair_unobstructed(const vf_polygon *p, const vf_polygon *q, double accuracy,
                         double plane_epsilon, double *bound);

/* The obstructed transfer by exact shadow clipping at every quadrature point
 * (shadow_clip.h), with the occluders that can shade the part of the outer polygon the
 * point is in (the hull of that triangle of its splitting and the inner polygon), to
 * relative tolerance `accuracy`; false when the visible part broke into
 * too many pieces, more than about a millisecond of clipping was needed or there are more
 * than PAIR_EXACT_MAX_OCCLUDERS occluders (sample instead). */
bool pair_obstructed_exact(const vf_polygon *p, const vf_polygon *q,
                           const shadow_occluder *occluders, uint32_t occluder_count,
                           double accuracy, double plane_epsilon, double *value, double *bound);

/* The same to the looser of the relative `accuracy` and the absolute tolerance `absolute`
 * on the transfer, with at most `work_budget` (point, occluder) clippings, and the occluders
 * (at most PAIR_EXACT_MAX_OCCLUDERS of them) first joined where they share an edge in one
 * plane (shadow_join_occluders: a wall's triangles cast one shadow, not one each; the same
 * visible part, in fewer pieces). An outer polygon that is a parallelogram is integrated in
 * cells split into strips where the shadows' kinks run along its edges
 * (parallelogram_integral.h), any other by triangles. */
bool pair_obstructed_exact_within(const vf_polygon *p, const vf_polygon *q,
                                  const shadow_occluder *occluders, uint32_t occluder_count,
                                  double accuracy, double absolute, double plane_epsilon,
                                  uint64_t work_budget, double *value, double *bound);

/* The clippings the surface view factors allow one pair's first try: some 50 ms at most. A
 * slot 1/50 as wide as two unit plates, behind 4 triangles, needs more than 65536 (the
 * kinks where its image leaves the receiver refine to the deepest level). A second try
 * (pair_obstructed_exact_roomy) gets a multiple of it, and with up to PAIR_ROOMY_PIECES
 * pieces a clipping may cost up to 20 times one of the first try's: such pairs are few
 * (56 of the 22k city's 1.07 M, none taking 50 ms given the room from the start), but
 * their time is bounded only by that. */
#define PAIR_EXACT_WORK_BUDGET 262144u

/* The most triangles in between that a pair can get exact shadow clipping behind (the
 * surface view factors take rad_viewfactor_options.exact_occluders of them at most, the
 * patches' form factors EXACT_PAIRS_MAX_OCCLUDERS). */
#define PAIR_EXACT_MAX_OCCLUDERS ((uint32_t)RAD_MAX_EXACT_OCCLUDERS)

/* Rounds of pair_sample_visibility at most (k = 1, 2, 4, ... 32 strata a side). */
#define PAIR_MAX_ROUNDS 6u

/* What one round found: the visible fraction, its bound, whether every segment agreed,
 * whether they were all blocked, and its segments. */
typedef struct pair_round {
    double fraction, bound;
    bool all_same, unseen;
    uint32_t rays;
} pair_round;

/* Visible pieces a point of pair_obstructed_exact_roomy may break its receiver into: a
 * ground tile behind some 300 triangles of the 22k-surface generated city breaks into
 * more than SHADOW_MAX_PIECES at some points. */
#define PAIR_ROOMY_PIECES 1024u

/* Scratch space of one thread: the occluders of a pair, its sampled visibility, and room
 * for the visible pieces of pair_obstructed_exact_roomy. */
typedef struct pair_workspace {
    shadow_occluder occluders[PAIR_EXACT_MAX_OCCLUDERS];
    rad_ray *rays;
    uint8_t *occluded;
    double *weight;
    uint32_t capacity; /* rays */
    /* the rounds of the last pair_sample_visibility, for pair_sample_visibility_resume */
    const vf_polygon *last_p, *last_q;
    const rad_tracer *last_occluders;
    uint64_t last_stream;
    unsigned last_rounds;
    pair_round last_round[PAIR_MAX_ROUNDS];
    flat_piece *pieces; /* room for PAIR_ROOMY_PIECES */
} pair_workspace;

bool pair_workspace_init(pair_workspace *workspace, uint32_t max_rays);
void pair_workspace_free(pair_workspace *workspace);

/* pair_obstructed_exact_within with room for PAIR_ROOMY_PIECES visible pieces a point (the
 * workspace's) rather than SHADOW_MAX_PIECES: the try after that gave up on a pair behind
 * hundreds of triangles. */
bool pair_obstructed_exact_roomy(const vf_polygon *p, const vf_polygon *q,
                                 const shadow_occluder *occluders, uint32_t occluder_count,
                                 double accuracy, double absolute, double plane_epsilon,
                                 uint64_t work_budget, pair_workspace *workspace, double *value,
                                 double *bound);

typedef struct pair_visibility {
    double fraction; /* visible fraction in [0, 1] */
    double bound;    /* its error bound (about 95 %), absolute, as a fraction */
    uint32_t rays;
    bool capped;     /* the ray budget ran out before the bound met the target */
    bool unseen;     /* every segment of the last round was blocked */
} pair_visibility;

/* Samples visibility between p and q through `occluders` until bound <= accuracy or
 * max_rays; `stream` seeds the random numbers (the same for any thread). */
void pair_sample_visibility(const vf_polygon *p, const vf_polygon *q,
                            const rad_tracer *occluders, double accuracy, uint32_t max_rays,
                            uint64_t stream, pair_workspace *workspace,
                            pair_visibility *out);

/* The same as pair_sample_visibility with these arguments, when the last call on this
 * workspace was for the same p, q, occluders and stream (another target or budget): its
 * rounds are taken as they came out rather than cast again (their segments and outcomes
 * would be the same), so the result is the same bit for bit, and out->rays counts only
 * the segments cast now. Any other last call: a fresh pair_sample_visibility. */
void pair_sample_visibility_resume(const vf_polygon *p, const vf_polygon *q,
                                   const rad_tracer *occluders, double accuracy,
                                   uint32_t max_rays, uint64_t stream, pair_workspace *workspace,
                                   pair_visibility *out);

#endif
