/*
 * pair_hidden.h - proves two polygons wholly hidden from each other, exactly.
 *
 * A plane with polygon p strictly on one side and q strictly on the other is crossed by
 * every segment between them, inside the window where it cuts their convex hull (the
 * convex hull of the points where the segments between their corners cross it). When the
 * scene's shapes lying in that plane (coplanar_polygons.h) cover the whole window (up to
 * slivers of 1e-12 of its area: rounding where their edges meet), every segment is blocked
 * and the pair is hidden, with no error.
 *
 * The planes tried are those of the triangles that 8 probe segments between p and q cross
 * (2 points of each, both ways, the first 3 triangles along each): the blockers, found by
 * the tracer, not a shaft's whole contents; the most often crossed first. When no plane
 * covers its window, the uncovered pieces of the two planes that leave least are proven
 * hidden from q or from p (the same test on the pair (piece, q) or (p, piece)); failing
 * that, the polygon that widens the window more is halved and both halves are proven.
 * Each sub-pair probes for its own planes; PAIR_HIDDEN_MAX_DEPTH levels and
 * PAIR_HIDDEN_MAX_PROOFS sub-pairs at most. A probe segment that gets through ends the
 * attempt. It is a proof, not an estimate: false means "not proven", never "visible"; the
 * caller then integrates or samples the pair. Probes and memory only choose which planes
 * are tried: they change what is proven, never whether a proof is right.
 */
#ifndef RAD_VIEWFACTOR_PAIR_HIDDEN_H
#define RAD_VIEWFACTOR_PAIR_HIDDEN_H

#include "radiosity.h"
#include "surface_viewfactors/coplanar_polygons.h"
#include "surface_viewfactors/vf_geometry.h"

/* Levels of pieces or halves, and sub-pairs looked at, at most per attempt; levels with
 * the remembered planes. */
#define PAIR_HIDDEN_MAX_DEPTH 3u
#define PAIR_HIDDEN_MAX_PROOFS 8u
#define PAIR_HIDDEN_REMEMBERED_DEPTH 1u

/* Probe segments per (sub-)pair and way: 2 points of each polygon, every pairing. */
#define PAIR_HIDDEN_PROBES 4u

typedef struct pair_hidden_context {
    const coplanar_polygons *planes;  /* what blocks, grouped by plane */
    const rad_tracer *tracer;         /* the same triangles */
    double plane_epsilon;             /* as in vf_geometry */
} pair_hidden_context;

/* What the attempts did: probe segments cast, sub-pairs looked at, pairs proven with the
 * planes remembered from the polygon's last proof. */
typedef struct pair_hidden_work {
    uint64_t rays, proofs, remembered;
} pair_hidden_work;

/* Distinct planes a probe keeps at most. */
#define PAIR_HIDDEN_MAX_PLANES 32u

typedef struct pair_hidden_planes {
    uint32_t group[PAIR_HIDDEN_MAX_PLANES]; /* coplanar_polygons groups */
    unsigned count;
} pair_hidden_planes;

/* Shapes remembered per polygon (pair_hidden_memory). */
#define PAIR_HIDDEN_SHAPES 8u

/* What hid polygon p's earlier pairs, tried for its next: the last PAIR_HIDDEN_SHAPES
 * single shapes that alone covered a whole window, most recently useful first (tried
 * first), and the planes the last probed proof used (the top plane and those that settled
 * its pieces or halves; tried next, with no probe: the walls that hide one building from
 * p often hide its neighbours too). Every plane that proof's probes found is tried last,
 * when the pair's own probes found no proof. One shape hides q from p when p and q lie
 * strictly on either side of its plane and every segment between their corners crosses
 * it inside the shape (then, by convexity, every segment between p and q does): a few
 * dozen dot products, no ray. Owned by one thread; zero-initialise. Which pairs came
 * before changes how much work a proof takes, never what it proves right. */
typedef struct pair_hidden_memory {
    const vf_polygon *p;
    pair_hidden_planes planes;              /* the planes the last proof used */
    pair_hidden_planes probed;              /* every plane its probes found */
    const vf_polygon *shapes_of;            /* the polygon the shapes hid pairs from */
    uint32_t shape[PAIR_HIDDEN_SHAPES];     /* coplanar_polygons shapes */
    uint32_t shape_group[PAIR_HIDDEN_SHAPES];
    unsigned shape_count;
    uint64_t shape_proofs;                  /* pairs proven by a remembered shape */
} pair_hidden_memory;

/* True when every segment between p and q is proven blocked (see above): by a remembered
 * shape, the planes the last proof used, the pair's own probes, or every plane the last
 * proof's probes found, in that order. `memory` may be NULL. */
bool pair_proven_hidden(const pair_hidden_context *context, pair_hidden_memory *memory,
                        const vf_polygon *p, const vf_polygon *q, pair_hidden_work *work);

/* Only the first of those tests: true when one shape remembered for p hides q from it (the
 * same exact test, no ray cast). For a caller that tries it before anything else. */
bool pair_hidden_by_remembered_shape(const pair_hidden_context *context,
                                     pair_hidden_memory *memory, const vf_polygon *p,
                                     const vf_polygon *q);

#endif
