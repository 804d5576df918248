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

/* The planes of the last proof for polygon p: tried first, with no probe, for p's next
 * pair (the walls that hide one building from p often hide its neighbours too). Owned by
 * one thread; zero-initialise. Which pairs came before changes how much work a proof
 * takes, never what it proves right. */
typedef struct pair_hidden_memory {
    const vf_polygon *p;
    pair_hidden_planes planes;
} pair_hidden_memory;

/* True when every segment between p and q is proven blocked (see above). `memory` may be
 * NULL. */
bool pair_proven_hidden(const pair_hidden_context *context, pair_hidden_memory *memory,
                        const vf_polygon *p, const vf_polygon *q, pair_hidden_work *work);

#endif
