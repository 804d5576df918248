/*
 * hierarchy.h - the element and cluster tree, links, and their estimates (internal).
 *
 * One binary tree over the mesh's patches, stored in preorder (a parent before its
 * children), so push (top-down) is a forward loop and pull (bottom-up) a backward one:
 *   - leaves are the mesh patches;
 *   - "planar" nodes group patches of one plane (a run of consecutive coplanar patches of
 *     one surface and material: an input polygon's cells, or a flat region);
 *   - clusters are the nodes above the planes (a bounding-volume tree, median splits).
 * A link (receiver <- source) carries the irradiance the receiver gets per unit radiosity
 * of the source: the form-factor estimate F times the visible fraction.
 */
#ifndef RAD_HIERARCHY_HIERARCHY_H
#define RAD_HIERARCHY_HIERARCHY_H

#include <stdbool.h>
#include <stdint.h>

#include "mesh/near_contacts.h"
#include "radiosity.h"

#define HNODE_NONE UINT32_MAX

typedef struct hnode {
    rad_vec3 centroid; /* area-weighted */
    rad_vec3 normal;   /* unit, area-weighted mean; meaningful for planar nodes */
    rad_vec3 lo, hi;   /* bounding box */
    double area;
    double radius;     /* bounding sphere about the centroid */
    /* the second moment of area about the centroid, the integral of s s^T over the
     * patches (s = point - centroid): xx, yy, zz, xy, xz, yz (floats: it enters only
     * the far nodes' second-order term, and a node stays 168 bytes) */
    float moment[6];
    uint32_t first, count; /* range of hier_tree.order (patches below) */
    uint32_t child[2];     /* HNODE_NONE for a leaf */
    uint32_t parent;       /* HNODE_NONE for the root */
    uint32_t patch;        /* the mesh patch of a leaf, else HNODE_NONE */
    bool planar;
} hnode;

/* A patch for sampling, compact and in leaf order (a node's patches are contiguous): the
 * corner a (lifted off a folded quad by twice its `behind`), the edges to the other corners
 * (ad zero for a triangle), the normal, and the share of the area in triangle (a, b, c). */
typedef struct leaf_shape {
    float a[3], ab[3], ac[3], ad[3];
    float normal[3];
    float first_share;
} leaf_shape;

typedef struct hier_tree {
    hnode *nodes;
    uint32_t node_count;
    uint32_t *order;      /* patches in leaf order */
    double *cumulative;   /* cumulative[k] = area of order[0..k], for sampling */
    struct leaf_shape *shapes; /* per leaf, in leaf order: what sampling needs */
    uint32_t planar_count, cluster_count;
    double plane_epsilon; /* scene units: the front-of-plane guard */
    near_contacts contacts; /* what segments' left-out ends could miss (near_contacts.h) */
} hier_tree;

/* Builds the tree over every patch of the mesh. 0 on allocation failure. */
int hier_tree_build(const rad_mesh *mesh, hier_tree *tree);
void hier_tree_free(hier_tree *tree);

/* F from the point x (unit normal nx) to the planar node q taken whole, by the kernel's
 * second-order expansion about q's centroid (its second moment of area): the error falls
 * as (q's radius / distance)^4. NAN where q is not wholly in front of x's plane (its
 * centroid less than its radius above it) or x is behind q. */
double hier_planar_node_factor(rad_vec3 x, rad_vec3 nx, const hnode *q);

typedef struct hlink {
    uint32_t receiver, source;
    float transfer;   /* F(receiver <- source) x visible share */
    float bound;      /* bound on A_receiver F: B(source) x bound is refinement's error; 0
                         for two patches (they never split) */
    uint16_t visible; /* visible share x LINK_VISIBLE: LINK_VISIBLE full, 0 hidden */
    uint16_t flags;   /* LINK_SETTLED */
} hlink;

#define LINK_VISIBLE 65535u
/* Its error was far under the threshold when last looked at: only a full check (every few
 * passes, and before the solver stops) looks at it again. */
#define LINK_SETTLED 1u

static inline double link_visibility(const hlink *link)
{
    return link->visible * (1.0 / LINK_VISIBLE);
}

/* The share in [0, 1], with (0, 1) kept strictly partial. */
static inline uint16_t link_visible_code(double share)
{
    if (!(share > 0))
        return 0;
    if (share >= 1)
        return (uint16_t)LINK_VISIBLE;
    double code = share * LINK_VISIBLE + 0.5;
    return (uint16_t)(code < 1 ? 1 : code > LINK_VISIBLE - 1 ? LINK_VISIBLE - 1 : code);
}

/* What refinement needs to know about a link, computed from geometry alone. */
typedef struct link_estimate {
    double factor;      /* form-factor estimate F(receiver <- source), unoccluded */
    double factor_bound; /* an upper bound of F times A_receiver (the transfer area) */
} link_estimate;

/* Geometry of a link between two distinct nodes (contour formula for two patches). */
link_estimate hier_estimate(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                            uint32_t source);

/* The irradiance on leaf node `leaf` from the patches below source with radiosity B (per
 * node), unoccluded: sum of F x B over the leaf's area (the midpoint rule, on 1, 2 x 2 or
 * 4 x 4 cells by how close the source is), the contour formula for source patches, nodes
 * far enough away as disks with their mean B. */
rad_rgb hier_leaf_gather(const rad_mesh *mesh, const hier_tree *tree, const rad_rgb *B,
                         uint32_t leaf, uint32_t source);

/* A point uniform in area on the patches below node, lifted off folded quads, and the
 * normal of its patch; u1..u3 in [0,1). */
rad_vec3 hier_sample_point(const hier_tree *tree, uint32_t node, double u1, double u2,
                           double u3, rad_vec3 *normal, uint32_t *position);

/* count segments between area-uniform points of receiver and source (stratified along
 * both nodes' leaf order; random numbers from (seed, receiver, source)); when kernel is
 * not NULL, the transfer kernel A_source cos cos / (pi r^2 + A_source / 4) at each (their
 * mean is a Monte Carlo estimate of F(receiver <- source)); when weight is not NULL,
 * leaf_weight of the source leaf each ends on (by leaf-order position). */
void hier_segments(const hier_tree *tree, uint64_t seed, uint32_t receiver, uint32_t source,
                   unsigned count, rad_ray *rays, double *kernel, const float *leaf_weight,
                   float *weight, uint8_t *blocked);

/* rad_tracer_occluded, then the segments hier_segments found blocked by a near contact
 * (`blocked`) counted as occluded too. */
void hier_occluded(const rad_tracer *occluders, const rad_ray *rays, uint32_t count,
                   const uint8_t *blocked, uint8_t *occluded);

/* The visible share of a link from its segments: the open ones' kernel x weight over all
 * of it (weight NULL: 1), or `fallback` when all of it is 0 (every segment ended on a face
 * of the source turned away from its start: counting those as the plain open fraction
 * would say the source's own solid hides it). Weighting by the kernel and by the source's
 * radiosity where each segment ends keeps F x share unbiased when the shadowed part of a
 * node is nearer, farther, brighter or darker than the rest. */
double hier_visible_share(const double *kernel, const float *weight, const uint8_t *occluded,
                          unsigned count, double fallback);

/* The links, in two buffers of `capacity` (the second is scratch for refinement and for
 * sorting by receiver). */
typedef struct link_store {
    hlink *links, *spare;
    size_t count, capacity;
    uint64_t max_bytes;  /* budget for both buffers */
    uint64_t peak_bytes; /* the most both buffers held */
} link_store;

/* Over MPI ranks (rank_share.h), a node's role as a receiver on this rank: its links are
 * held here only (OWN), on every rank (SHARED: the few nodes above the cut), or on another
 * rank only (ELSEWHERE). */
enum { RECEIVER_ELSEWHERE = 0, RECEIVER_OWN = 1, RECEIVER_SHARED = 2 };

typedef struct refine_context {
    const rad_mesh *mesh;
    const hier_tree *tree;
    const rad_tracer *occluders;
    const rad_rgb *node_radiosity; /* pulled B of every node */
    const float *leaf_brightness;  /* B.r + B.g + B.b by leaf-order position */
    double epsilon;                /* absolute BFA threshold (power) */
    bool full_check;               /* look at settled links too */
    unsigned visibility_rays;      /* segments for a link the first 4 did not find all
                                      open */
    uint64_t seed;
    int threads;
    const uint8_t *receiver_role;  /* per node, over MPI ranks: children received ELSEWHERE
                                      are dropped unestimated; NULL: every receiver here */
} refine_context;

typedef struct refine_result {
    size_t split;  /* links replaced by their children */
    bool capped;   /* some links wanted to split but the budget said no */
    uint64_t rays;
    uint64_t rays_shared; /* of which for links received by a SHARED node (every rank
                             traces those) */
} refine_result;

/* One refinement pass: every link whose BFA bound exceeds epsilon (a quarter of it for
 * partly visible links) is replaced by its children one level down: the larger node
 * split, and a cluster's link to itself by its children's four pairs. Children get a
 * form-factor estimate and a visibility fraction; hidden and facing-away children are
 * dropped. Deterministic: the output order is fixed by the input order. 0 when memory
 * could not be allocated (the store is left as it was). */
int hier_refine_pass(const refine_context *context, link_store *store, refine_result *result);

#endif
