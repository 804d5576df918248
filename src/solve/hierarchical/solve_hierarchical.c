/*
 * solve_hierarchical.c - rad_solve_hierarchical: refinement alternating with Jacobi
 * gathering over links and push-pull between levels.
 *
 * A sweep: every node gathers H = sum over its links of transfer x B(source) (parallel over
 * nodes, links sorted by receiver); push adds each node's H to everything below it
 * (preorder: one forward loop); every patch takes B = E + rho H; pull makes every node's B
 * the area-weighted mean of its children's (one backward loop). The outer loop refines the
 * links one level with the newest B and sweeps twice, until nothing splits; then it sweeps
 * to the tolerance and checks refinement once more with the converged B.
 *
 * Over MPI ranks (rank_share.h) every rank builds the same tree; the links are shared by
 * receiver subtree, each held by its owner only (those of the few nodes above the cut by
 * every rank), and each rank refines, gathers and final-gathers its own receivers. After a
 * sweep the leaves' new B go to every rank, which then measures the change and pulls over
 * the whole tree exactly as one process does: each rank's links and sums are the serial
 * run's, so the solution is bitwise the serial one for any rank count.
 *
 * With a checkpoint (solve/solve_checkpoint.h) the state is written at the top of the loop
 * and between the sweeps to the tolerance when one is due, always before the final gather,
 * and between the final gather's FINAL_ROUNDS rounds of leaves when one is due (with the
 * corrections of the rounds done; a stop inside a round leaves the last checkpoint
 * standing): the links of every rank gathered at rank 0, each once. A resumed run rebuilds
 * the tree, keeps the links it receives and goes on from the same point
 * (hierarchy_checkpoint.h).
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "core/clock.h"

#include "core/alloc.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/minmax.h"
#include "core/rgb.h"
#include "core/vec3.h"
#include "solve/hierarchical/final_gather.h"
#include "solve/hierarchical/hierarchy.h"
#include "solve/hierarchical/hierarchy_checkpoint.h"
#include "solve/hierarchical/rank_share.h"
#include "parallel/ranks.h"

#define DEFAULT_THRESHOLD RAD_DEFAULT_REFINE_THRESHOLD
#define DEFAULT_TOLERANCE RAD_DEFAULT_TOLERANCE
#define DEFAULT_MAX_ITERATIONS RAD_DEFAULT_HIERARCHY_SWEEPS
#define DEFAULT_VISIBILITY_RAYS RAD_DEFAULT_LINK_VISIBILITY_RAYS
#define SWEEPS_PER_PASS 1u
#define MAX_CORRECTION_FACTOR 1.0
#define FULL_CHECK_EVERY 8u /* passes; the others look only at links not settled */
#define MAX_PASSES 256u
/* The final gather goes in this many rounds of nodes (equal index ranges), between which a
 * checkpoint may be written. */
#define FINAL_ROUNDS 16u

typedef struct hsolver {
    const rad_mesh *mesh;
    hier_tree tree;
    const rad_rgb *emission, *albedo; /* per patch: the patch inputs' E and rho */
    const double *open_area;    /* per patch: the inputs' area, the part not buried in a
                                   closed object (mesh/exposed_area.h) */
    double *node_open;          /* per node: its leaves' open area */
    rad_rgb *node_B, *gathered, *down;
    rad_rgb *correction, *scale; /* per node (leaves only): the final gather's, or NULL:
                                    a leaf gathers down x scale + correction */
    rad_rgb *patch_B;           /* per patch */
    float *brightness;          /* B.r + B.g + B.b by leaf-order position */
    size_t *offsets;            /* links by receiver: node k's are [offsets[k], offsets[k+1]) */
    link_store store;
    double emitted;             /* sum A |E|_1 */
    int threads;
    bool diverged;              /* a sweep changed B by more than HIER_DIVERGED_CHANGE */
    uint32_t changed_most;      /* the patch whose B changed the most in the last sweep */
    rad_rgb *observed;          /* per patch: the observer's copy of B, or NULL */
    rank_share share;           /* over MPI ranks: who holds which receivers' links */
    bool over_ranks;            /* more than one rank: each holds its receivers' links and
                                   the shared ones, and the steps here are collective */
    rad_rgb *fresh;             /* over ranks: a sweep's new B by leaf-order position */
    bool stop_seen;             /* over ranks: every rank saw the stop */
    double seconds_waiting;     /* over ranks: in the collective steps here (the exchanges
                                   of B are timed by rank_share) */
} hsolver;

/* A sweep whose change (relative to the emitted power) is not finite or above this has
 * diverged: with links that send out no more than they receive, a sweep moves B by at
 * most the light still bouncing, which is below the emitted power times the albedo
 * series and far below this. */
#define HIER_DIVERGED_CHANGE 1e3

static double now_seconds(void) { return rad_clock_seconds(); }

static void pull(hsolver *s)
{
    const hier_tree *t = &s->tree;
    for (uint32_t k = t->node_count; k-- > 0;) {
        const hnode *n = &t->nodes[k];
        if (n->patch != HNODE_NONE) {
            s->node_B[k] = s->patch_B[n->patch];
            continue;
        }
        /* weighted by the open areas: a leaf's B is its open part's (leaf_radiosity), and
         * what a node sends is what those parts send */
        double total = s->node_open[k], oa = s->node_open[n->child[0]],
               ob = s->node_open[n->child[1]];
        double wa = total > 0 ? oa / total : 0.5, wb = total > 0 ? ob / total : 0.5;
        s->node_B[k] = rgb_add(rgb_scale(s->node_B[n->child[0]], wa),
                               rgb_scale(s->node_B[n->child[1]], wb));
    }
}

/* Stable counting sort of the links by receiver into the spare buffer, then swap. */
static void sort_by_receiver(hsolver *s)
{
    link_store *st = &s->store;
    uint32_t nodes = s->tree.node_count;
    memset(s->offsets, 0, ((size_t)nodes + 1) * sizeof(size_t));
    for (size_t l = 0; l < st->count; l++)
        s->offsets[st->links[l].receiver + 1]++;
    for (uint32_t k = 0; k < nodes; k++)
        s->offsets[k + 1] += s->offsets[k];
    for (size_t l = 0; l < st->count; l++)
        st->spare[s->offsets[st->links[l].receiver]++] = st->links[l];
    for (uint32_t k = nodes; k > 0; k--)
        s->offsets[k] = s->offsets[k - 1];
    s->offsets[0] = 0;
    hlink *swap = st->links;
    st->links = st->spare;
    st->spare = swap;
}

/* Leaf node k's new B from what comes down to it (and the final gather's correction). */
static rad_rgb leaf_radiosity(const hsolver *s, uint32_t k)
{
    uint32_t p = s->tree.nodes[k].patch;
    rad_rgb h = s->down[k];
    if (s->correction) /* irradiance is never negative, however corrected */
        h = rgb_max0(rgb_add(rgb_mul(h, s->scale[k]), s->correction[k]));
    /* a leaf part of which lies buried gathers over its whole area, the buried part
     * nothing: its open part's irradiance is the mean over that part */
    double area = s->tree.nodes[k].area, open = s->open_area[p];
    if (open > 0 && open < area)
        h = rgb_scale(h, area / open);
    return rgb_add(s->emission[p], rgb_mul(s->albedo[p], h));
}

/* One Jacobi sweep with push-pull; returns the relative change. Collective over ranks. */
static double sweep(hsolver *s)
{
    const hier_tree *t = &s->tree;
    const hlink *links = s->store.links;
    int64_t nodes = t->node_count;
#pragma omp parallel for num_threads(s->threads) schedule(dynamic, 256)
    for (int64_t k = 0; k < nodes; k++) {
        rad_rgb sum = {0, 0, 0};
        for (size_t l = s->offsets[k]; l < s->offsets[k + 1]; l++)
            rgb_add_to(&sum, rgb_scale(s->node_B[links[l].source], links[l].transfer));
        s->gathered[k] = sum;
    }
    double change = 0, most = -1;
    if (s->over_ranks) { /* this rank's leaves, then every rank's from their owners */
        for (uint32_t k = 0; k < t->node_count; k++) {
            const hnode *n = &t->nodes[k];
            s->down[k] = n->parent == HNODE_NONE ? s->gathered[k]
                                                 : rgb_add(s->down[n->parent], s->gathered[k]);
            if (n->patch != HNODE_NONE && s->share.role[k] == RECEIVER_OWN)
                s->fresh[n->first] = leaf_radiosity(s, k);
        }
        rank_share_exchange(&s->share, s->mesh->patch_count, s->fresh);
    }
    for (uint32_t k = 0; k < t->node_count; k++) {
        const hnode *n = &t->nodes[k];
        if (!s->over_ranks)
            s->down[k] = n->parent == HNODE_NONE ? s->gathered[k]
                                                 : rgb_add(s->down[n->parent], s->gathered[k]);
        if (n->patch != HNODE_NONE) {
            uint32_t p = n->patch;
            rad_rgb b = s->over_ranks ? s->fresh[n->first] : leaf_radiosity(s, k);
            double moved = n->area * (fabs(b.r - s->patch_B[p].r) + fabs(b.g - s->patch_B[p].g) +
                                      fabs(b.b - s->patch_B[p].b));
            change += moved;
            if (!(moved <= most)) {
                most = moved;
                s->changed_most = p;
            }
            s->patch_B[p] = b;
        }
    }
    pull(s);
    double relative = s->emitted > 0 ? change / s->emitted : 0;
    if (!(relative <= HIER_DIVERGED_CHANGE))
        s->diverged = true;
    return relative;
}

/* One channel of the final gather's correction c to what comes down d: as a factor where d
 * is positive (the correction then moves with B), at most MAX_CORRECTION_FACTOR = 1 (a
 * factor above 1 raises the sweeps' operator, which can then diverge in a bright
 * enclosure); the rest is added, a constant that cannot. */
static void as_scale(double d, double *c, double *factor)
{
    *factor = 1;
    if (d > 0 && d + *c >= 0) {
        *factor = min_d((d + *c) / d, MAX_CORRECTION_FACTOR);
        *c = d + *c - *factor * d;
    }
}

static void update_brightness(hsolver *s)
{
    for (uint32_t k = 0; k < s->mesh->patch_count; k++) {
        rad_rgb b = s->patch_B[s->tree.order[k]];
        s->brightness[k] = (float)(b.r + b.g + b.b);
    }
}

static void hsolver_free(hsolver *s)
{
    hier_tree_free(&s->tree);
    free(s->node_B);
    free(s->node_open);
    free(s->gathered);
    free(s->down);
    free(s->correction);
    free(s->scale);
    free(s->patch_B);
    free(s->brightness);
    free(s->offsets);
    free(s->store.links);
    free(s->store.spare);
    free(s->observed);
    free(s->fresh);
    rank_share_free(&s->share);
}

/* The observer (rad_solve_step): B_k is handed over after sweep k + 1, whose change is
 * B_k's residual (the same measure as rad_hierarchy_report.residual), from a copy made
 * before that sweep. */
typedef struct hobserver {
    rad_solve_observer_fn fn; /* NULL: none, and nothing else is used */
    void *user;
    rad_rgb *before;          /* B_k */
    rad_solve_step pending;   /* B_k's step, all but its residual */
    double start, spent;      /* the solver's start; time spent observing */
} hobserver;

static double observed_seconds(const hobserver *ob)
{
    return now_seconds() - ob->start - ob->spent;
}

/* sweep(), and the observer's call for the B before it; `phase` names what this sweep
 * follows ("refine", "gather", "final gather"). */
static double sweep_observed(hsolver *s, hobserver *ob, const char *phase)
{
    if (!ob->fn)
        return sweep(s);
    double t = now_seconds();
    memcpy(ob->before, s->patch_B, (size_t)s->mesh->patch_count * sizeof(rad_rgb));
    ob->spent += now_seconds() - t;
    double change = sweep(s);
    t = now_seconds();
    double seconds = observed_seconds(ob);
    ob->pending.residual = change;
    ob->pending.B = ob->before;
    ob->fn(ob->user, &ob->pending);
    ob->pending.step++;
    ob->pending.phase = phase;
    ob->pending.seconds = seconds;
    ob->pending.criterion = change;
    ob->spent += now_seconds() - t;
    return change;
}

/* Whether the solve is to stop; over ranks collective, true on every rank once any saw the
 * stop (and from then on without asking again). */
static bool stopped(hsolver *s, const rad_hierarchy_options *o)
{
    bool here = s->stop_seen || (o->stop && *o->stop);
    if (s->over_ranks && !s->stop_seen) {
        double t = now_seconds();
        here = ranks_failures(here) > 0;
        s->seconds_waiting += now_seconds() - t;
    }
    s->stop_seen = s->stop_seen || (s->over_ranks && here);
    return here;
}

/* Over ranks: assigns the receiver subtrees by their leaf counts (measured on two scenes,
 * a better predictor of the links each will receive than the links the first passes put
 * there). 0 when out of memory. */
static int assign_by_leaves(hsolver *s)
{
    rank_share *share = &s->share;
    double *cost = rad_alloc_array(share->subtrees, sizeof(double));
    if (!cost)
        return 0;
    for (uint32_t k = 0; k < s->tree.node_count; k++)
        if (s->tree.nodes[k].patch != HNODE_NONE)
            cost[share->subtree_of[k]] += 1;
    int ok = rank_share_assign(share, &s->tree, cost);
    free(cost);
    return ok;
}

/* Whether any rank holds a link (collective over ranks). */
static bool links_anywhere(hsolver *s)
{
    uint64_t count = s->store.count;
    double t = now_seconds();
    if (s->over_ranks)
        ranks_sum(&count, 1);
    s->seconds_waiting += now_seconds() - t;
    return count > 0;
}

/* Of this rank's links: those it alone counts in the whole (its own receivers', and on rank
 * 0 those every rank holds), how many of those are partly visible, and those every rank
 * holds (over ranks: those received above the cut). */
static void count_links(const hsolver *s, uint64_t *counted, uint64_t *partial,
                        uint64_t *shared)
{
    *counted = *partial = *shared = 0;
    for (size_t l = 0; l < s->store.count; l++) {
        const hlink *link = &s->store.links[l];
        bool is_shared = s->over_ranks && s->share.role[link->receiver] == RECEIVER_SHARED;
        bool counts = !is_shared || s->share.rank == 0;
        *shared += is_shared;
        *counted += counts;
        *partial += counts && link->visible < LINK_VISIBLE;
    }
}

/* Progress of refinement after `passes` passes: about 4 passes per level of the tree
 * (measured: 87 at 1M leaves' 21 levels), linear up to 90 % of that; past it the fraction
 * keeps creeping towards 1 (each pass a tenth of the way), never stuck at one value. */
static double refine_fraction(uint32_t passes, uint32_t nodes)
{
    double expected = 4.0 * log2((double)nodes + 2) + 8;
    double linear = passes / expected;
    if (linear <= 0.9)
        return linear;
    return 1 - 0.1 * pow(0.9, passes - 0.9 * expected);
}

/* ---- checkpoints (hierarchy_checkpoint.h) ---- */

/* Every leaf's value[] (per node: `down`, the final gather's correction) by leaf-order
 * position, from its owner over ranks. Collective. */
static void leaves_by_position(hsolver *s, const rad_rgb *value, rad_rgb *by_position)
{
    const hier_tree *t = &s->tree;
    for (uint32_t k = 0; k < t->node_count; k++)
        if (t->nodes[k].patch != HNODE_NONE &&
            (!s->over_ranks || s->share.role[k] == RECEIVER_OWN))
            by_position[t->nodes[k].first] = value[k];
    if (s->over_ranks)
        rank_share_exchange(&s->share, s->mesh->patch_count, by_position);
}

/* Collective: writes the state as a HIERARCHY checkpoint: the links of every rank at rank 0
 * (those every rank holds from rank 0 only); in phase HIER_IN_FINAL s->correction too. */
static rad_status write_state(hsolver *s, solve_checkpoint *cp, hier_loop_state *state,
                              rad_error *error)
{
    uint32_t n = s->mesh->patch_count;
    bool in_final = state->phase == HIER_IN_FINAL;
    rad_rgb *down = rad_alloc_array(in_final ? 2 * (size_t)n : n, sizeof(rad_rgb));
    rad_rgb *correction = in_final && down ? down + n : NULL;
    hlink *mine = s->store.links;
    size_t count = s->store.count;
    rad_status status = down ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "out of memory");
    if (s->over_ranks && status == RAD_OK && s->share.rank != 0) {
        mine = rad_alloc_array(count ? count : 1, sizeof(hlink));
        if (!mine)
            status = rad_fail(error, RAD_ERR_NOMEM, "out of memory");
        size_t kept = 0;
        for (size_t l = 0; mine && l < count; l++)
            if (s->share.role[s->store.links[l].receiver] != RECEIVER_SHARED)
                mine[kept++] = s->store.links[l];
        count = kept;
    }
    if (s->over_ranks)
        status = ranks_agree(status, "writing a checkpoint", error);
    if (status == RAD_OK)
        leaves_by_position(s, s->down, down);
    if (status == RAD_OK && correction)
        leaves_by_position(s, s->correction, correction);
    state->capacity = s->store.capacity;
    state->peak_bytes = s->store.peak_bytes;
    if (s->over_ranks) /* the rays every rank traced on its own, in one count */
        ranks_sum(&state->rays, 1);
    void *gathered = NULL;
    uint64_t *sizes = NULL;
    if (status == RAD_OK && s->over_ranks) {
        sizes = rad_alloc_array((size_t)ranks_count(), sizeof(uint64_t));
        status = ranks_agree(sizes ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "out of memory"),
                             "writing a checkpoint", error);
        if (status == RAD_OK)
            status = ranks_gather(mine, count * sizeof(hlink), &gathered, sizes, error);
        if (status == RAD_OK && ranks_rank() == 0) {
            count = 0;
            for (int r = 0; r < ranks_count(); r++)
                count += sizes[r] / sizeof(hlink);
        }
    }
    byte_sink body = {0};
    body.off = ranks_rank() != 0;
    if (status == RAD_OK)
        hier_checkpoint_put(&body, state, n, gathered ? gathered : mine, count, s->patch_B,
                            down, correction);
    if (status == RAD_OK)
        status = solve_checkpoint_write(cp, SOLVE_CHECKPOINT_HIERARCHY, &body, 1, error);
    sink_free(&body);
    free(gathered);
    free(sizes);
    if (mine != s->store.links)
        free(mine);
    free(down);
    return status;
}

/* Collective, between sweeps: writes the state when a checkpoint is due (or always);
 * true when the solver is to stop here (cp->interrupted) or the write failed (*status). */
static bool checkpoint_step(hsolver *s, solve_checkpoint *cp, hier_loop_state *state,
                            bool always, rad_status *status, rad_error *error)
{
    bool stop = false;
    bool due = solve_checkpoint_due(cp, &stop);
    if (!due && !(always && cp->path))
        return false;
    *status = write_state(s, cp, state, error);
    if (*status != RAD_OK)
        return true;
    cp->interrupted = stop;
    return stop;
}

/* The resumed state: this rank's links, B and the leaves' down; false (error set) for a
 * state that does not fit this tree. */
static bool resume_state(hsolver *s, solve_checkpoint *cp, hier_loop_state *state,
                         rad_error *error)
{
    byte_source source;
    if (!solve_checkpoint_resuming(cp, SOLVE_CHECKPOINT_HIERARCHY, &source))
        return true;
    uint32_t n = s->mesh->patch_count;
    rad_rgb *down = rad_alloc_array(2 * (size_t)n, sizeof(rad_rgb));
    rad_rgb *correction = down ? down + n : NULL;
    uint8_t *keep = NULL;
    if (s->over_ranks && (keep = rad_alloc_array(s->tree.node_count, 1)))
        for (uint32_t k = 0; k < s->tree.node_count; k++)
            keep[k] = s->share.role[k] != RECEIVER_ELSEWHERE;
    hlink *links = NULL;
    size_t count = 0, capacity = 0;
    bool ok = down && (!s->over_ranks || keep);
    if (!ok)
        rad_fail(error, RAD_ERR_NOMEM, "out of memory resuming from %s", cp->resume_path);
    else
        ok = hier_checkpoint_get(&source, cp->resume_path, &s->tree, n, keep, state, &links,
                                 &count, &capacity, s->patch_B, down, correction, error);
    if (ok && state->phase == HIER_IN_FINAL && state->final_rounds >= FINAL_ROUNDS) {
        ok = false;
        rad_fail(error, RAD_ERR_PARSE, "%s: %u of the final gather's %u rounds done",
                 cp->resume_path, state->final_rounds, FINAL_ROUNDS);
    }
    if (ok && state->phase == HIER_IN_FINAL) { /* the corrections of the rounds done */
        s->correction = rad_alloc_array(s->tree.node_count, sizeof(rad_rgb));
        ok = s->correction != NULL;
        if (!ok)
            rad_fail(error, RAD_ERR_NOMEM, "out of memory resuming from %s", cp->resume_path);
        for (uint32_t k = 0; ok && k < s->tree.node_count; k++)
            if (s->tree.nodes[k].patch != HNODE_NONE)
                s->correction[k] = correction[s->tree.nodes[k].first];
    }
    hlink *spare = NULL;
    if (ok) {
        if (s->over_ranks) /* this rank's share of the links: its store from them alone */
            capacity = count ? count : 1;
        spare = rad_alloc_array(capacity, sizeof(hlink));
        ok = spare != NULL;
        if (!ok)
            rad_fail(error, RAD_ERR_NOMEM, "out of memory for the links of %s",
                     cp->resume_path);
    }
    if (ok) {
        free(s->store.links);
        free(s->store.spare);
        s->store.links = links;
        s->store.spare = spare;
        s->store.count = count;
        s->store.capacity = capacity;
        s->store.peak_bytes = s->over_ranks ? (uint64_t)capacity * 2 * sizeof(hlink)
                                            : state->peak_bytes;
        for (uint32_t k = 0; k < s->tree.node_count; k++)
            if (s->tree.nodes[k].patch != HNODE_NONE)
                s->down[k] = down[s->tree.nodes[k].first];
        pull(s);
        links = NULL;
        solve_checkpoint_resumed(cp);
    }
    free(links);
    free(down);
    free(keep);
    return ok;
}

rad_status rad_solve_hierarchical(const rad_mesh *mesh, const rad_patch_inputs *inputs,
                                  const rad_tracer *occluders,
                                  const rad_hierarchy_options *options, rad_rgb *B,
                                  rad_hierarchy_report *report, rad_error *error)
{
    return solve_hierarchical_checkpointed(mesh, inputs, occluders, options, NULL, B, report,
                                           error);
}

rad_status solve_hierarchical_checkpointed(const rad_mesh *mesh,
                                           const rad_patch_inputs *inputs,
                                           const rad_tracer *occluders,
                                           const rad_hierarchy_options *options,
                                           solve_checkpoint *cp, rad_rgb *B,
                                           rad_hierarchy_report *report, rad_error *error)
{
    rad_hierarchy_options o = {0};
    if (options)
        o = *options;
    rad_hierarchy_report rep = {0};
    rep.patch = UINT32_MAX;
    if (o.threads < 0)
        return rad_fail(error, RAD_ERR_INVALID, "threads must be 0 (all cores) or positive");
    if (!(o.refine_threshold >= 0) || !isfinite(o.refine_threshold))
        return rad_fail(error, RAD_ERR_INVALID, "the refinement threshold must be >= 0");
    if (!(o.tolerance >= 0))
        return rad_fail(error, RAD_ERR_INVALID, "the tolerance must be >= 0");
    if (!inputs || inputs->n != mesh->patch_count)
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve_hierarchical: the patch inputs are for %u patches, the mesh "
                        "has %u",
                        inputs ? inputs->n : 0, mesh->patch_count);
    double threshold = o.refine_threshold > 0 ? o.refine_threshold : DEFAULT_THRESHOLD;
    double tolerance = o.tolerance > 0 ? o.tolerance : DEFAULT_TOLERANCE;
    uint32_t max_sweeps = o.max_iterations ? o.max_iterations : DEFAULT_MAX_ITERATIONS;
    unsigned rays = o.visibility_rays ? o.visibility_rays : DEFAULT_VISIBILITY_RAYS;
    uint64_t budget = o.max_memory;
    if (budget == 0)
        budget = rad_physical_memory_bytes() / 2;
    if (budget == 0)
        budget = UINT64_MAX;

    hsolver s;
    memset(&s, 0, sizeof(s));
    s.mesh = mesh;
    s.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
    rep.threads = s.threads;
    uint32_t n = mesh->patch_count;
    double t0 = now_seconds();
    hobserver ob = {o.observer, o.observer_user, NULL, {0}, t0, 0};
    ob.pending = (rad_solve_step){0, "start", 0, NAN, NAN, NAN, UINT32_MAX, false, n, NULL};
    if (n == 0) {
        if (report)
            *report = rep;
        return RAD_OK;
    }
    /* over ranks every rank builds the same tree, then they agree before working together */
    s.over_ranks = ranks_count() > 1;
    rad_status setup = RAD_OK;
    if (!hier_tree_build(mesh, &s.tree))
        setup = rad_fail(error, RAD_ERR_NOMEM, "out of memory building the element tree");
    if (setup == RAD_OK && s.over_ranks &&
        (!rank_share_build(&s.tree, ranks_count(), ranks_rank(), &s.share) ||
         !assign_by_leaves(&s) || !(s.fresh = rad_alloc_array(n, sizeof(rad_rgb)))))
        setup = rad_fail(error, RAD_ERR_NOMEM, "out of memory sharing the hierarchy over %d "
                         "ranks", ranks_count());
    if (s.over_ranks)
        setup = ranks_agree(setup, "the hierarchical solver", error);
    if (setup != RAD_OK) {
        hsolver_free(&s);
        return setup;
    }
    uint32_t nodes = s.tree.node_count;
    s.emission = inputs->source; /* E + rho H: the light sources' first bounce */
    s.albedo = inputs->albedo;
    s.open_area = inputs->area;
    s.node_open = rad_alloc_array(nodes, sizeof(double));
    for (uint32_t k = nodes; s.node_open && k-- > 0;) {
        const hnode *node = &s.tree.nodes[k];
        s.node_open[k] = node->patch != HNODE_NONE
                             ? inputs->area[node->patch]
                             : s.node_open[node->child[0]] + s.node_open[node->child[1]];
    }
    s.patch_B = rad_alloc_array(n, sizeof(rad_rgb));
    s.brightness = rad_alloc_array(n, sizeof(float));
    s.node_B = rad_alloc_array(nodes, sizeof(rad_rgb));
    s.gathered = rad_alloc_array(nodes, sizeof(rad_rgb));
    s.down = rad_alloc_array(nodes, sizeof(rad_rgb));
    s.offsets = rad_alloc_array((size_t)nodes + 1, sizeof(size_t));
    if (ob.fn)
        ob.before = s.observed = rad_alloc_array(n, sizeof(rad_rgb));
    setup = !s.node_open || !s.patch_B || !s.node_B || !s.gathered || !s.down || !s.offsets ||
                    !s.brightness || (ob.fn && !ob.before)
                ? rad_fail(error, RAD_ERR_NOMEM, "out of memory for the hierarchy")
                : RAD_OK;
    if (s.over_ranks)
        setup = ranks_agree(setup, "the hierarchical solver", error);
    if (setup != RAD_OK) {
        hsolver_free(&s);
        return setup;
    }
    double brightest_total = 0;
    for (uint32_t p = 0; p < n; p++) {
        s.patch_B[p] = s.emission[p];
        double a = mesh->patches[p].area;
        s.emitted += a * (s.emission[p].r + s.emission[p].g + s.emission[p].b);
        brightest_total += a * fmax(s.emission[p].r, fmax(s.emission[p].g, s.emission[p].b));
    }
    pull(&s);
    rep.leaves = n;
    rep.elements = s.tree.planar_count;
    rep.clusters = s.tree.cluster_count;
    rep.seconds_build = now_seconds() - t0;

    s.store.max_bytes = budget;
    bool root_cluster = !s.tree.nodes[0].planar;
    if (root_cluster && s.emitted > 0 &&
        !(s.over_ranks && s.share.role[0] == RECEIVER_ELSEWHERE)) {
        if (2 * sizeof(hlink) > budget) {
            hsolver_free(&s);
            return rad_fail(error, RAD_ERR_NOMEM, "--max-memory: %llu bytes cannot hold a link",
                            (unsigned long long)budget);
        }
        s.store.links = rad_alloc_array(1, sizeof(hlink));
        s.store.spare = rad_alloc_array(1, sizeof(hlink));
        if (!s.store.links || !s.store.spare) {
            hsolver_free(&s);
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the links");
        }
        s.store.capacity = 1;
        s.store.count = 1;
        s.store.links[0] = (hlink){0, 0, 0, INFINITY, (uint16_t)LINK_VISIBLE, 0};
        s.store.peak_bytes = 2 * sizeof(hlink);
    }
    refine_context rc = {mesh,
                         &s.tree,
                         occluders,
                         s.node_B,
                         s.brightness,
                         threshold * brightest_total / n,
                         true,
                         rays,
                         o.seed,
                         s.threads,
                         s.over_ranks ? s.share.role : NULL};

    double sweep_change = s.emitted > 0 ? 1 : 0;
    uint64_t rays_shared = 0; /* over ranks: traced alike on every rank, counted once */
    bool refining = links_anywhere(&s), converged = false;
    uint32_t quiet_passes = 0;
    /* a checkpoint: the state at its points (loop_state), resumed or written */
    hier_loop_state resumed = {0};
    rad_status checkpointed = RAD_OK;
    bool halt = false; /* a checkpoint's stop, or its failure */
    if (cp) {
        rad_status status = resume_state(&s, cp, &resumed, error) ? RAD_OK : RAD_ERR_PARSE;
        if (s.over_ranks)
            status = ranks_agree(status, "resuming the hierarchical solver", error);
        if (status != RAD_OK) {
            hsolver_free(&s);
            return status == RAD_ERR_PARSE && error ? error->status : status;
        }
        if (resumed.phase) {
            rep.iterations = resumed.iterations;
            rep.passes = resumed.passes;
            rep.rays = s.over_ranks && s.share.rank != 0 ? 0 : resumed.rays;
            rep.memory_capped = resumed.memory_capped;
            rays_shared = resumed.rays_shared;
            quiet_passes = resumed.quiet_passes;
            refining = resumed.refining;
            converged = resumed.converged;
            sweep_change = resumed.sweep_change;
        }
    }
#define LOOP_STATE_AT(at, first_change, rounds)                                              \
    (hier_loop_state)                                                                      \
    {                                                                                      \
        (at), rep.iterations, rep.passes, quiet_passes, rep.rays, rays_shared,             \
            rep.memory_capped, refining, converged, sweep_change, (first_change), 0, 0,    \
            (rounds)                                                                       \
    }
#define LOOP_STATE(at, first_change) LOOP_STATE_AT(at, first_change, 0)
    bool resume_gather = resumed.phase == HIER_IN_GATHER;
    bool resume_final = resumed.phase == HIER_IN_FINAL;
    bool skip_loop = resumed.phase == HIER_BEFORE_FINAL || resume_final;
    while (!skip_loop &&
           !(cp && !resume_gather &&
             (halt = checkpoint_step(&s, cp, &LOOP_STATE(HIER_AT_PASS, 0), false,
                                     &checkpointed, error))) &&
           !stopped(&s, &o) && rep.iterations < max_sweeps && !s.diverged) {
        size_t split = 0;
        if (resume_gather) { /* straight back to the sweeps to the tolerance */
        } else if (refining && !rep.memory_capped && rep.passes < MAX_PASSES) {
            double tr = now_seconds();
            refine_result rr;
            update_brightness(&s);
            rc.full_check = quiet_passes > 0 || rep.passes % FULL_CHECK_EVERY == 0;
            rad_status refined =
                hier_refine_pass(&rc, &s.store, &rr)
                    ? RAD_OK
                    : rad_fail(error, RAD_ERR_NOMEM, "out of memory refining the links");
            double tw = now_seconds(); /* the ranks wait here for the slowest */
            if (s.over_ranks)
                refined = ranks_agree(refined, "refining the links", error);
            s.seconds_waiting += now_seconds() - tw;
            if (refined != RAD_OK) {
                hsolver_free(&s);
                return refined;
            }
            rep.passes++;
            rep.rays += rr.rays - rr.rays_shared;
            rays_shared += rr.rays_shared;
            split = rr.split;
            if (s.over_ranks) { /* whether any rank split, or stopped at its budget */
                uint64_t any[2] = {split, rr.capped};
                ranks_sum(any, 2);
                split = (size_t)any[0];
                rr.capped = any[1] > 0;
            }
            if (rr.capped)
                rep.memory_capped = true;
            rep.seconds_refine += now_seconds() - tr;
            if (o.progress)
                o.progress(o.progress_user, "refine", refine_fraction(rep.passes, nodes));
        }
        double tg = now_seconds();
        sort_by_receiver(&s);
        if (split > 0) {
            quiet_passes = 0;
            for (unsigned k = 0; k < SWEEPS_PER_PASS && rep.iterations < max_sweeps && !s.diverged;
                 k++) {
                sweep_change = sweep_observed(&s, &ob, "refine");
                rep.iterations++;
            }
            rep.seconds_gather += now_seconds() - tg;
            continue;
        }
        /* nothing split: sweep to the tolerance, then look once more */
        double first = resume_gather ? resumed.first : sweep_change;
        resume_gather = false;
        while (sweep_change > tolerance && rep.iterations < max_sweeps &&
               !(cp && (halt = checkpoint_step(&s, cp, &LOOP_STATE(HIER_IN_GATHER, first),
                                               false, &checkpointed, error))) &&
               !stopped(&s, &o) && !s.diverged) {
            sweep_change = sweep_observed(&s, &ob, "gather");
            rep.iterations++;
            if (o.progress && first > tolerance && sweep_change > 0)
                o.progress(o.progress_user, "gather",
                           fmin(0.99, fmax(0, log(first / sweep_change) /
                                                  log(first / tolerance))));
        }
        rep.seconds_gather += now_seconds() - tg;
        if (halt)
            break;
        if (sweep_change <= tolerance && (quiet_passes > 0 || !refining ||
                                          rep.memory_capped || rep.passes >= MAX_PASSES)) {
            converged = true;
            break;
        }
        quiet_passes++;
        refining = links_anywhere(&s);
    }
    if (checkpointed != RAD_OK) {
        hsolver_free(&s);
        return checkpointed;
    }
    if (o.progress)
        o.progress(o.progress_user, "gather", 1);
    if (!halt && !stopped(&s, &o) && links_anywhere(&s) && !s.diverged) {
        sort_by_receiver(&s); /* as it is after any sweep (and resumed links) */
        if (cp && cp->path && !resume_final) { /* a stop in the final gather's first round
                                                  goes back to here */
            checkpoint_step(&s, cp, &LOOP_STATE(HIER_BEFORE_FINAL, 0), true, &checkpointed,
                            error);
            if (checkpointed != RAD_OK) {
                hsolver_free(&s);
                return checkpointed;
            }
        }
        if (cp && cp->interrupted)
            goto final_done;
        double tf = now_seconds();
        if (!s.correction) /* (resumed in the final gather: the rounds done) */
            s.correction = rad_alloc_array(nodes, sizeof(rad_rgb));
        s.scale = rad_alloc_array(nodes, sizeof(rad_rgb));
        update_brightness(&s);
        final_gather_context fg = {mesh,       &s.tree,    occluders,  s.store.links,
                                   s.offsets,  s.node_B,   s.brightness, rays,
                                   o.seed + 2, s.threads,  o.progress, o.progress_user,
                                   o.stop,     s.over_ranks ? s.share.role : NULL, 0, 0};
        int gathered = s.correction && s.scale ? 1 : 0;
        if (s.over_ranks && ranks_failures(gathered == 0) > 0)
            gathered = 0;
        /* in rounds of nodes, each round's corrections depending on the node, the seed and
         * B only: a checkpoint between two holds those done, and resuming goes on bitwise */
        for (uint32_t round = resume_final ? resumed.final_rounds : 0;
             gathered > 0 && round < FINAL_ROUNDS; round++) {
            fg.first_node = (uint32_t)((uint64_t)nodes * round / FINAL_ROUNDS);
            fg.end_node = (uint32_t)((uint64_t)nodes * (round + 1) / FINAL_ROUNDS);
            gathered = hier_final_gather(&fg, s.correction, &rep.rays);
            double tw = now_seconds(); /* the ranks wait here for the slowest */
            if (s.over_ranks) { /* out of memory anywhere fails all; a stop anywhere stops
                                   all */
                if (ranks_failures(gathered == 0) > 0)
                    gathered = 0;
                else if (ranks_failures(gathered < 0) > 0)
                    gathered = -1;
            }
            s.seconds_waiting += now_seconds() - tw;
            if (gathered > 0 && cp && cp->path && round + 1 < FINAL_ROUNDS &&
                checkpoint_step(&s, cp, &LOOP_STATE_AT(HIER_IN_FINAL, 0, round + 1), false,
                                &checkpointed, error)) {
                if (checkpointed != RAD_OK) {
                    hsolver_free(&s);
                    return checkpointed;
                }
                gathered = -1; /* stopped: the checkpoint holds the rounds done */
            }
        }
        if (gathered == 0) {
            hsolver_free(&s);
            return rad_fail(error, RAD_ERR_NOMEM, "out of memory in the final gather");
        }
        if (gathered < 0) { /* stopped: the solution without it stands */
            free(s.correction);
            free(s.scale);
            s.correction = s.scale = NULL;
        }
        /* as a factor on what comes down where that is not 0, so that the correction moves
         * with B */
        for (uint32_t k = 0; s.correction && k < nodes; k++) {
            as_scale(s.down[k].r, &s.correction[k].r, &s.scale[k].r);
            as_scale(s.down[k].g, &s.correction[k].g, &s.scale[k].g);
            as_scale(s.down[k].b, &s.correction[k].b, &s.scale[k].b);
        }
        double change = s.correction ? 1 : 0;
        while (change > tolerance && rep.iterations < max_sweeps && !stopped(&s, &o) &&
               !s.diverged) {
            sweep_change = change = sweep_observed(&s, &ob, "final gather");
            rep.iterations++;
        }
        converged = converged && change <= tolerance;
        if (o.progress)
            o.progress(o.progress_user, "final gather", 1);
        rep.seconds_final = now_seconds() - tf;
    }
final_done:
#undef LOOP_STATE
#undef LOOP_STATE_AT
    rep.interrupted = stopped(&s, &o);
    if (cp && cp->path && rep.interrupted)
        cp->interrupted = true; /* the last checkpoint written stands for this point */
    rep.converged = converged && !rep.interrupted;
    rep.change = sweep_change;
    /* the sweep_change of the B handed out: one more sweep, measured and not applied */
    memcpy(B, s.patch_B, (size_t)n * sizeof(rad_rgb));
    rep.residual = sweep(&s);
    if (ob.fn && !s.diverged && isfinite(sweep_change) && isfinite(rep.residual)) {
        ob.pending.residual = rep.residual;
        ob.pending.B = B;
        ob.pending.final = true;
        ob.fn(ob.user, &ob.pending);
    }
    uint64_t counts[3] = {0, 0, rep.rays}; /* links, partial, rays: every one once */
    count_links(&s, &counts[0], &counts[1], &rep.shared_links);
    rep.rank_links = s.store.count;
    if (s.over_ranks)
        ranks_sum(counts, 3);
    rep.links = counts[0];
    rep.links_partial = counts[1];
    rep.rays = counts[2] + rays_shared;
    rep.link_bytes = s.store.peak_bytes;
    rep.rank_seconds = now_seconds() - t0 - s.share.seconds_exchanging - s.seconds_waiting;
    if (s.diverged || !isfinite(sweep_change) || !isfinite(rep.residual)) {
        /* never hand out a diverged answer as a solution */
        rep.patch = s.changed_most;
        if (report)
            *report = rep;
        hsolver_free(&s);
        return rad_fail(error, RAD_ERR_INVALID,
                        "rad_solve: the hierarchical solver diverges: after %u sweeps a sweep "
                        "changed the radiosity by %.3g times the emitted power; patch %u "
                        "changes the most",
                        rep.iterations, sweep_change, rep.patch);
    }
    hsolver_free(&s);
    if (report)
        *report = rep;
    return RAD_OK;
}
