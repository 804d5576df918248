/*
 * sky_viewfactor.c - the sky view factor of each surface, see radiosity.h: the fraction of
 * its hemisphere (cosine-weighted) from which a ray leaves the scene without meeting any
 * triangle, integrated directly, not taken as 1 - row sum.
 *
 * The sky is an inward-facing box around the whole scene (every triangle, obstructions
 * included) that blocks nothing. A ray from a point of the scene leaves the scene exactly
 * when its segment to the box is unblocked, because nothing lies beyond the box: the
 * factor from x to the visible part of the box is the sky fraction of x's hemisphere for
 * any box that encloses the scene, so its size adds no error (there is no
 * finite-distance term to bound).
 *
 * For each polygon p of a surface, the box's faces are tiles, split in four (a quadtree,
 * SKY_MAX_LEVEL levels) while the occluder tree finds more than SKY_EXACT_MAX_OCCLUDERS
 * triangles in the hull of p and the tile. The tiles with few enough are integrated
 * together, as one point function over p (the sky fraction seen from x through them,
 * each tile's part exact by shadow clipping, shadow_clip.h), so that the kinks where one
 * tile's shadows cross its edge, which the neighbouring tile's cancel, do not make the
 * quadrature refine; a long polygon is cut into strips of aspect about 2 first. The
 * tiles with too many occluders at the last level (and a polygon's obstructed tiles when
 * its exact integral does not settle within its work budget) are counted by
 * cosine-distributed rays from the polygon (sample_sky). With sky_exact
 * (rad_viewfactor_options, --sky-exact) a polygon with such a tile takes every tile of
 * the last level as its own pair, clipped exactly behind up to exact_occluders triangles
 * as the matrix's pairs are (pair_tile), and samples only those that do not settle. No
 * shortcut drops anything as hidden. Error bounds add in quadrature, as in the matrix's
 * rows.
 *
 * Not here: the matrix (viewfactor_matrix.c); the writer (sky_viewfactor_writer.c).
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/random.h"
#include "core/vec3.h"
#include "geometry/polygon_integral.h"
#include "surface_viewfactors/occluder_tree.h"
#include "surface_viewfactors/pair_transfer.h"
#include "surface_viewfactors/vf_geometry.h"
#include "trace/ray.h"

/* A tile is clipped exactly when its hull with the polygon holds at most this many
 * triangles (a closed room's floor sees 10 others); otherwise it is split, down to
 * SKY_MAX_LEVEL (8 x 8 tiles a face), and sampled there. */
#define SKY_EXACT_MAX_OCCLUDERS 16u
#define SKY_MAX_LEVEL 3u
#define SKY_MAX_TILES (6u * 64u)

/* Occluder clippings one strip's exact integrand may spend (a few milliseconds) before
 * the polygon's obstructed tiles are sampled instead: where many shadows cross, the
 * quadrature chases their edges and sampling is cheaper; and the deepest split of its
 * quadrature (4^8 cells of each fan triangle). */
#define SKY_WORK_BUDGET (1u << 16)
#define SKY_MAX_DEPTH 8

/* The clippings a TILE_PAIR tile may spend (pair_tile): four times a pair of the
 * matrix's (with one, 1,129 tiles of the 486-surface generated city ran out and were
 * sampled, leaving 201 of its sky view factors short of the accuracy; with four, none and
 * 16). */
#define SKY_PAIR_WORK_BUDGET (4u * PAIR_EXACT_WORK_BUDGET)

/* The work of a tile's second try (pair_obstructed_exact_roomy), as a multiple of the
 * first's. */
#define SKY_ROOMY_WORK 4u

/* Occluders are cut this far (times the polygon's size) above its plane (lift_occluders). */
#define SKY_LIFT 1e-6

/* The integrand is the sky fraction plus this constant, subtracted again: the quadrature's
 * relative tolerance then has an absolute floor of accuracy x SKY_FLOOR / 4, so a polygon
 * that sees (almost) no sky, where clipping leaves slivers of 1e-12, does not refine
 * forever. */
#define SKY_FLOOR 0.01

/* A polygon longer than twice its mean width is cut into strips of aspect about 2, at most
 * this many. */
#define SKY_MAX_STRIPS 64u

/* Sampled sky: independent replicates, rays per polygon at most this many times max_rays,
 * and how far above its point (along the polygon's normal) each ray starts, as a fraction
 * of the box's diagonal (above the float rounding of the tracer's coordinates). */
#define SKY_REPLICATES 8u
#define SKY_RAY_FACTOR 16u
#define SKY_RAY_OFFSET 1e-6

/* The tiles' `source`: no scene triangle has it (obstructions have UINT32_MAX), so none is
 * excluded from the tiles' hulls. */
#define SKY_SOURCE (UINT32_MAX - 1u)

/* The box: the scene's bounds grown by this fraction of their diagonal (any margin is
 * exact; a small one keeps the sampled segments short, so their end offsets stay small). */
#define SKY_MARGIN 0.05

typedef struct sky_counts {
    uint64_t polygon_pairs, obstructed_pairs, exact_pairs, sampled_pairs, capped_pairs, rays;
} sky_counts;

/* TILE_EXACT: in the polygon's one integrand (sky_point); TILE_PAIR: a tile of the last
 * level with more occluders, integrated as its own pair (pair_tile); TILE_SAMPLED: by rays
 * (sample_sky). */
enum { TILE_EXACT = 1, TILE_SAMPLED, TILE_PAIR };

typedef struct sky_tile {
    vf_polygon polygon;
    uint32_t id; /* (face, level, i, j): its random stream */
    uint32_t occluder_count;
    uint8_t state;
    shadow_occluder occluders[2 * SKY_EXACT_MAX_OCCLUDERS]; /* lifted: 2 triangles each */
} sky_tile;

/* Per thread: the tiles for the polygon at hand. */
typedef struct sky_workspace {
    pair_workspace pair;
    sky_tile tiles[SKY_MAX_TILES];
    uint32_t tile_count;
    /* a TILE_PAIR tile's occluders (pair_tile): as collected, then lifted */
    shadow_occluder collected[RAD_MAX_EXACT_OCCLUDERS];
    shadow_occluder lifted[2 * RAD_MAX_EXACT_OCCLUDERS];
} sky_workspace;

typedef struct sky_box {
    double lo[3], hi[3];
} sky_box;

/* Tile (i, j) of level `level` of face `face` (axis face / 2, high side when odd), facing
 * into the box. */
static void make_tile(const sky_box *box, unsigned face, unsigned level, unsigned i,
                      unsigned j, vf_polygon *t)
{
    unsigned axis = face / 2, side = face % 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
    double cells = (double)(1u << level);
    double u0 = box->lo[u] + (box->hi[u] - box->lo[u]) * i / cells;
    double u1 = box->lo[u] + (box->hi[u] - box->lo[u]) * (i + 1) / cells;
    double v0 = box->lo[v] + (box->hi[v] - box->lo[v]) * j / cells;
    double v1 = box->lo[v] + (box->hi[v] - box->lo[v]) * (j + 1) / cells;
    double corner[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
    memset(t, 0, sizeof(*t));
    t->count = 4;
    for (int k = 0; k < 4; k++) {
        /* (u, v, axis) is right-handed: counter-clockwise about +axis as listed, so the
         * high face (normal -axis) runs them backwards */
        int c = side ? 3 - k : k;
        double x[3];
        x[axis] = side ? box->hi[axis] : box->lo[axis];
        x[u] = corner[c][0];
        x[v] = corner[c][1];
        t->vertex[k] = v3(x[0], x[1], x[2]);
    }
    double n[3] = {0, 0, 0};
    n[axis] = side ? -1 : 1;
    t->normal = v3(n[0], n[1], n[2]);
    t->surface = SKY_SOURCE;
    t->source = SKY_SOURCE;
    vf_polygon_finish(t);
}

typedef struct sky_context {
    const sky_box *box;
    const occluder_tree *tree;
    const rad_tracer *tracer;
    double accuracy, eps;
    double ray_offset; /* sampled rays start this far above their point (scene units) */
    uint32_t max_rays;
    uint32_t exact_occluders; /* a TILE_PAIR tile is clipped behind this many at most
                                 (SKY_EXACT_MAX_OCCLUDERS: there is none; sky_exact) */
    uint64_t seed;
} sky_context;

/* Cuts away the part of each occluder within SKY_LIFT sqrt(A_p) of p's plane, in place
 * (each becomes 0, 1 or 2 triangles); returns the new count. An occluder that touches p's
 * plane (a wall standing on a floor) would otherwise reach the point's own height above a
 * tile parallel to p and cast a shadow out to 1e9 times the scene, whose corners ruin the
 * clipping's arithmetic (the quadrature then never settles). What is cut away blocks only
 * rays that leave p at elevations below SKY_LIFT sqrt(A_p) / d from points at distance d
 * from it: about SKY_LIFT / 2 of the SVF (the cosine-weighted share (e^2 / 2) averaged over
 * p). */
static uint32_t lift_occluders_to(const vf_polygon *p, const shadow_occluder *occluders,
                                  uint32_t count, shadow_occluder *kept)
{
    double offset = v3_dot(p->normal, p->vertex[0]) + SKY_LIFT * sqrt(p->area);
    uint32_t made = 0;
    for (uint32_t o = 0; o < count; o++) {
        rad_vec3 out[4];
        unsigned n = 0;
        for (unsigned k = 0; k < 3; k++) {
            rad_vec3 a = occluders[o].corner[k], b = occluders[o].corner[(k + 1) % 3];
            double da = v3_dot(p->normal, a) - offset, db = v3_dot(p->normal, b) - offset;
            if (da >= 0)
                out[n++] = a;
            if ((da > 0 && db < 0) || (da < 0 && db > 0))
                out[n++] = v3_lerp(a, b, da / (da - db));
        }
        if (n >= 3)
            kept[made++] = (shadow_occluder){{out[0], out[1], out[2]}};
        if (n == 4)
            kept[made++] = (shadow_occluder){{out[0], out[2], out[3]}};
    }
    return made;
}

/* lift_occluders_to in place, for at most SKY_EXACT_MAX_OCCLUDERS occluders. */
static uint32_t lift_occluders(const vf_polygon *p, shadow_occluder *occluders, uint32_t count)
{
    shadow_occluder kept[2 * SKY_EXACT_MAX_OCCLUDERS];
    uint32_t made = lift_occluders_to(p, occluders, count, kept);
    memcpy(occluders, kept, made * sizeof(*kept));
    return made;
}

/* Whether p and tile t face each other (each in front of the other's plane). */
static bool tile_faces(const sky_context *c, const vf_polygon *p, const vf_polygon *t)
{
    return vf_polygon_in_front(t, p->normal, v3_dot(p->normal, p->vertex[0]), c->eps) &&
           vf_polygon_in_front(p, t->normal, v3_dot(t->normal, t->vertex[0]), c->eps);
}

/* The tiles of face `face` under (level, i, j) that p faces, split while they have too
 * many occluders for the polygon's integrand; at the last level such a tile is its own
 * pair (TILE_PAIR) when the run clips more than SKY_EXACT_MAX_OCCLUDERS triangles
 * (exact_occluders), else sampled, and a tile whose children would all be sampled is
 * sampled whole instead (sampling cost grows with the pairs, not with their size).
 * Returns false when the subtree holds a tile to clip exactly. */
static bool add_tiles(const sky_context *c, const vf_polygon *p, sky_workspace *w,
                      unsigned face, unsigned level, unsigned i, unsigned j)
{
    uint32_t first = w->tile_count;
    sky_tile *tile = &w->tiles[first];
    make_tile(c->box, face, level, i, j, &tile->polygon);
    const vf_polygon *t = &tile->polygon;
    if (!tile_faces(c, p, t))
        return true;
    uint32_t count = occluder_tree_collect(c->tree, p, t, c->eps, tile->occluders,
                                           SKY_EXACT_MAX_OCCLUDERS);
    tile->occluder_count = count;
    tile->id = (face << 24) | (level << 20) | (i << 10) | j;
    if (count <= SKY_EXACT_MAX_OCCLUDERS) {
        tile->occluder_count = lift_occluders(p, tile->occluders, count);
        tile->state = TILE_EXACT;
        w->tile_count++;
        return false;
    }
    if (level < SKY_MAX_LEVEL) {
        bool sampled = true;
        for (unsigned k = 0; k < 4; k++)
            sampled = add_tiles(c, p, w, face, level + 1, 2 * i + k % 2, 2 * j + k / 2) &&
                      sampled;
        if (!sampled)
            return false;
        /* none of them exact: this tile, sampled whole (rebuilt: the children overwrote
         * its slot) */
        w->tile_count = first;
        make_tile(c->box, face, level, i, j, &tile->polygon);
        tile->occluder_count = count;
        tile->id = (face << 24) | (level << 20) | (i << 10) | j;
    }
    w->tile_count++;
    if (level == SKY_MAX_LEVEL && c->exact_occluders > SKY_EXACT_MAX_OCCLUDERS) {
        tile->state = TILE_PAIR;
        return false;
    }
    tile->state = TILE_SAMPLED;
    return true;
}

/* The exact integrand: x on a strip of the polygon (normal n) to every TILE_EXACT tile, as
 * far as its occluders leave it visible. */
typedef struct sky_integrand {
    sky_workspace *w;
    rad_vec3 normal;
    double plane_epsilon;
    uint64_t work_left;   /* occluder clippings left */
    uint32_t failed_tile; /* the tile whose visible part broke into too many pieces, or
                             UINT32_MAX when the work ran out */
    bool failed;
} sky_integrand;

static double sky_point(void *context, rad_vec3 x)
{
    sky_integrand *c = context;
    double sum = 0;
    for (uint32_t k = 0; k < c->w->tile_count && !c->failed; k++) {
        const sky_tile *tile = &c->w->tiles[k];
        if (tile->state != TILE_EXACT)
            continue;
        uint32_t count = tile->occluder_count;
        if (c->work_left < count) {
            c->failed = true;
            c->failed_tile = UINT32_MAX;
            break;
        }
        c->work_left -= count;
        double f = shadow_visible_factor(x, c->normal, &tile->polygon, tile->occluders, count,
                                         c->plane_epsilon);
        if (f < 0) {
            c->failed = true;
            c->failed_tile = k;
            break;
        }
        sum += f;
    }
    return sum + SKY_FLOOR;
}

/* The convex polygon p cut into strips across its longest extent, each of aspect about 2:
 * strips[] receives them (room for SKY_MAX_STRIPS); returns how many. */
static unsigned cut_strips(const vf_polygon *p, vf_polygon *strips)
{
    rad_vec3 a = p->vertex[0], b = p->vertex[0];
    double longest = 0;
    for (unsigned i = 0; i < p->count; i++)
        for (unsigned j = i + 1; j < p->count; j++) {
            double d = v3_length(v3_sub(p->vertex[i], p->vertex[j]));
            if (d > longest)
                longest = d, a = p->vertex[i], b = p->vertex[j];
        }
    double width = longest > 0 ? p->area / longest : 0;
    unsigned n = width > 0 ? (unsigned)fmin(ceil(0.5 * longest / width - 1e-9), SKY_MAX_STRIPS) : 1;
    if (n <= 1) {
        strips[0] = *p;
        return 1;
    }
    rad_vec3 axis = v3_scale(v3_sub(b, a), 1 / longest);
    double start = v3_dot(axis, a);
    unsigned made = 0;
    for (unsigned s = 0; s < n; s++) {
        double from = start + longest * s / n, to = start + longest * (s + 1) / n;
        /* the part of p with from <= axis . x <= to */
        rad_vec3 out[VF_MAX_VERTICES + 2];
        unsigned count = 0;
        for (unsigned k = 0; k < p->count; k++) {
            rad_vec3 x = p->vertex[k], y = p->vertex[(k + 1) % p->count];
            double dx = v3_dot(axis, x), dy = v3_dot(axis, y);
            double lo[2] = {from, to};
            if (dx >= from && dx <= to && count < VF_MAX_VERTICES + 2)
                out[count++] = x;
            /* crossings of the two cut planes along x -> y, in order */
            double t0 = dy != dx ? (lo[0] - dx) / (dy - dx) : -1;
            double t1 = dy != dx ? (lo[1] - dx) / (dy - dx) : -1;
            double first = fmin(t0, t1), second = fmax(t0, t1);
            if (first > 0 && first < 1 && count < VF_MAX_VERTICES + 2)
                out[count++] = v3_lerp(x, y, first);
            if (second > 0 && second < 1 && count < VF_MAX_VERTICES + 2)
                out[count++] = v3_lerp(x, y, second);
        }
        if (count < 3 || count > VF_MAX_VERTICES) {
            /* a slab of a convex hexagon has at most 8 corners: keep p whole then */
            strips[0] = *p;
            return 1;
        }
        vf_polygon *strip = &strips[made];
        *strip = *p;
        strip->count = count;
        memcpy(strip->vertex, out, count * sizeof(rad_vec3));
        vf_polygon_finish(strip);
        if (strip->area > 0)
            made++;
    }
    return made;
}

/* The sampled tile the ray from x along d leaves the box through, or false. */
static bool lands_on_sampled(const sky_context *c, const sky_workspace *w, rad_vec3 x,
                             rad_vec3 d, rad_vec3 *exit)
{
    double o[3] = {x.x, x.y, x.z}, v[3] = {d.x, d.y, d.z}, t = INFINITY;
    int axis = 0;
    for (int a = 0; a < 3; a++) {
        if (v[a] == 0)
            continue;
        double ta = ((v[a] > 0 ? c->box->hi[a] : c->box->lo[a]) - o[a]) / v[a];
        if (ta < t)
            t = ta, axis = a;
    }
    unsigned face = 2u * (unsigned)axis + (v[axis] > 0);
    *exit = v3_add(x, v3_scale(d, t));
    double y[3] = {exit->x, exit->y, exit->z};
    int u = (axis + 1) % 3, vv = (axis + 2) % 3;
    for (uint32_t k = 0; k < w->tile_count; k++) {
        const sky_tile *tile = &w->tiles[k];
        if (tile->state != TILE_SAMPLED || tile->id >> 24 != face)
            continue;
        unsigned level = (tile->id >> 20) & 15u, i = (tile->id >> 10) & 1023u, j = tile->id & 1023u;
        double cells = (double)(1u << level);
        double u0 = c->box->lo[u] + (c->box->hi[u] - c->box->lo[u]) * i / cells;
        double u1 = c->box->lo[u] + (c->box->hi[u] - c->box->lo[u]) * (i + 1) / cells;
        double v0 = c->box->lo[vv] + (c->box->hi[vv] - c->box->lo[vv]) * j / cells;
        double v1 = c->box->lo[vv] + (c->box->hi[vv] - c->box->lo[vv]) * (j + 1) / cells;
        if (y[u] >= u0 && y[u] <= u1 && y[vv] >= v0 && y[vv] <= v1)
            return true;
    }
    return false;
}

/* The part of p's sky seen through its sampled tiles (share: their unobstructed F), by
 * cosine-distributed rays from uniform points of p: a ray counts when it leaves the box
 * through a sampled tile with nothing in its way. Sampling directions, not tile points,
 * keeps the estimate's spread that of a coin toss however large the tiles are. The
 * estimate is the mean of SKY_REPLICATES independent ones; its bound a 95 % Student t of
 * their spread (at least the Poisson limit of the rarer outcome's count over the rays
 * cast, pair_poisson_upper), or, when no ray escaped, the rule of three (3 / rays that
 * landed, times the share). Rounds of twice the rays until the bound is accuracy x sqrt(share) or
 * SKY_RAY_FACTOR x max_rays were cast. */
static double sample_sky(const sky_context *c, const vf_polygon *p, uint32_t pi,
                         sky_workspace *w, double share, sky_counts *counts, double *bound)
{
    rad_vec3 n = p->normal;
    rad_vec3 t1 = v3_normalize(v3_cross(n, fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0)));
    rad_vec3 t2 = v3_cross(n, t1);
    uint64_t escaped[SKY_REPLICATES] = {0}, cast[SKY_REPLICATES] = {0}, landed = 0;
    uint64_t budget = (uint64_t)SKY_RAY_FACTOR * c->max_rays, total = 0;
    double target = c->accuracy * sqrt(share), mean = 0;
    uint32_t per_replicate = 16;
    rad_vec3 exit;
    for (unsigned round = 0;; round++, per_replicate *= 2) {
        for (unsigned r = 0; r < SKY_REPLICATES; r++) {
            rad_rng rng = rad_rng_seed(c->seed ^ 0x736b79u, ((uint64_t)pi << 8) | round, r);
            for (uint32_t done = 0; done < per_replicate;) {
                uint32_t batch = 0;
                for (; done < per_replicate && batch < w->pair.capacity; done++) {
                    rad_vec3 x = vf_polygon_sample(p, rad_rng_uniform(&rng), rad_rng_uniform(&rng));
                    double q = rad_rng_uniform(&rng), phi = 2 * RAD_PI * rad_rng_uniform(&rng);
                    double radius = sqrt(q);
                    rad_vec3 d = v3_add(v3_add(v3_scale(t1, radius * cos(phi)),
                                               v3_scale(t2, radius * sin(phi))),
                                        v3_scale(n, sqrt(1 - q)));
                    cast[r]++;
                    if (!lands_on_sampled(c, w, x, d, &exit))
                        continue;
                    /* lifted off p along its normal, not along the ray: a point
                     * closer to a wall than the offset must not start beyond it */
                    rad_vec3 start = v3_add(x, v3_scale(n, c->ray_offset));
                    ray_set(&w->pair.rays[batch++], start, v3_sub(exit, start), 0, 1.0);
                }
                if (batch == 0)
                    continue;
                rad_tracer_occluded(c->tracer, w->pair.rays, batch, w->pair.occluded);
                landed += batch;
                for (uint32_t k = 0; k < batch; k++)
                    escaped[r] += !w->pair.occluded[k];
            }
        }
        total += (uint64_t)SKY_REPLICATES * per_replicate;
        double estimate[SKY_REPLICATES], spread = 0;
        uint64_t any = 0;
        mean = 0;
        for (unsigned r = 0; r < SKY_REPLICATES; r++) {
            estimate[r] = (double)escaped[r] / (double)cast[r];
            mean += estimate[r] / SKY_REPLICATES;
            any += escaped[r];
        }
        for (unsigned r = 0; r < SKY_REPLICATES; r++)
            spread += (estimate[r] - mean) * (estimate[r] - mean);
        /* a few rays blocked among many escaping, or the other way round: their spread
         * says little, their count does (pair_poisson_upper) */
        uint64_t rarer = any < landed - any ? any : landed - any;
        double rare = (pair_poisson_upper(rarer) - (double)rarer) / (double)total;
        *bound = any ? fmax(PAIR_STUDENT_T * sqrt(spread / (SKY_REPLICATES - 1) / SKY_REPLICATES),
                            rare)
                     : share * fmin(3.0 / (double)(landed ? landed : 1), 1);
        if (*bound <= target)
            break;
        if (total + 2 * (uint64_t)SKY_REPLICATES * per_replicate > budget) {
            counts->capped_pairs++;
            break;
        }
    }
    counts->rays += landed;
    return fmin(mean, share);
}

/* The transfer from p to a TILE_PAIR tile as far as the triangles in their hull leave it
 * visible, clipped exactly as a pair of the matrix is (pair_obstructed_exact_within:
 * joined where they share an edge, culled per cell of p's splitting), to the looser of
 * the relative accuracy and `absolute`; false when more than exact_occluders triangles
 * (after lifting) stand in the hull, or when the visible part breaks into too many pieces
 * or the clipping needs more than SKY_PAIR_WORK_BUDGET, and again with room for
 * PAIR_ROOMY_PIECES pieces and SKY_ROOMY_WORK times the work: the tile is then sampled. */
static bool pair_tile(const sky_context *c, const vf_polygon *p, sky_workspace *w,
                      const vf_polygon *tile, double absolute, uint32_t *collected,
                      double *value, double *bound)
{
    uint32_t count = occluder_tree_collect(c->tree, p, tile, c->eps, w->collected,
                                           c->exact_occluders);
    *collected = count;
    if (count > c->exact_occluders)
        return false;
    count = lift_occluders_to(p, w->collected, count, w->lifted);
    if (count > c->exact_occluders)
        return false;
    if (count == 0) {
        *value = pair_unobstructed(p, tile, 0.25 * c->accuracy, c->eps, bound);
        return true;
    }
    if (pair_obstructed_exact_within(p, tile, w->lifted, count, c->accuracy, absolute, c->eps,
                                     SKY_PAIR_WORK_BUDGET, value, bound))
        return true;
    /* too many visible pieces at a point, or out of work: once more with room for more
     * (as the matrix's pairs) */
    return pair_obstructed_exact_roomy(p, tile, w->lifted, count, c->accuracy, absolute, c->eps,
                                       SKY_ROOMY_WORK * SKY_PAIR_WORK_BUDGET, &w->pair, value,
                                       bound);
}

/* The transfer from polygon p (index pi) to the sky, with its error bound in *bound. */
static double sky_polygon(const sky_context *c, const vf_polygon *p, uint32_t pi,
                          sky_workspace *w, vf_polygon *strips, sky_counts *counts,
                          double *bound)
{
    w->tile_count = 0;
    for (unsigned face = 0; face < 6; face++)
        add_tiles(c, p, w, face, 0, 0, 0);
    /* a polygon with a tile of many occluders (in a city, most) takes every tile of the
     * last level as its own pair: in the one integrand their shadows' kinks would refine
     * it for all of them, and its clipping budget run out, mostly after spending it; and a
     * large tile's shadows refine its pair to the deepest level, leaving their error in
     * its bound */
    bool busy = false;
    for (uint32_t k = 0; k < w->tile_count; k++)
        busy = busy || w->tiles[k].state == TILE_PAIR;
    if (busy) {
        w->tile_count = 0;
        for (unsigned face = 0; face < 6; face++)
            for (unsigned i = 0; i < 1u << SKY_MAX_LEVEL; i++)
                for (unsigned j = 0; j < 1u << SKY_MAX_LEVEL; j++) {
                    sky_tile *tile = &w->tiles[w->tile_count];
                    make_tile(c->box, face, SKY_MAX_LEVEL, i, j, &tile->polygon);
                    if (!tile_faces(c, p, &tile->polygon))
                        continue;
                    tile->id = (face << 24) | (SKY_MAX_LEVEL << 20) | (i << 10) | j;
                    tile->state = TILE_PAIR;
                    tile->occluder_count = 0; /* pair_tile's count */
                    w->tile_count++;
                }
    }
    bool any_exact = false;
    for (uint32_t k = 0; k < w->tile_count; k++)
        any_exact = any_exact || w->tiles[k].state == TILE_EXACT;
    double transfer = 0, variance = 0;
    unsigned strip_count = any_exact ? cut_strips(p, strips) : 0;
    while (any_exact) {
        double value = 0, error2 = 0;
        sky_integrand integrand = {w, p->normal, c->eps, 0, 0, false};
        for (unsigned s = 0; s < strip_count && !integrand.failed; s++) {
            integrand.work_left = SKY_WORK_BUDGET;
            polygon_integral integral = {sky_point, &integrand, SKY_MAX_DEPTH,
                                         &integrand.failed, NULL, 0, false};
            double error;
            value += polygon_integrate(&integral, strips[s].vertex, strips[s].count,
                                       0.25 * c->accuracy, &error) -
                     SKY_FLOOR * strips[s].area;
            error2 += error * error;
        }
        if (!integrand.failed) {
            transfer += fmax(value, 0);
            variance += error2;
            break;
        }
        /* too many pieces behind one tile: that tile on its own; out of work: every
         * obstructed tile (each its own pair when the run clips more occluders than the
         * integrand takes, else sampled) */
        any_exact = false;
        for (uint32_t k = 0; k < w->tile_count; k++) {
            sky_tile *tile = &w->tiles[k];
            if (tile->state == TILE_EXACT &&
                (k == integrand.failed_tile ||
                 (integrand.failed_tile == UINT32_MAX && tile->occluder_count)))
                tile->state = c->exact_occluders > SKY_EXACT_MAX_OCCLUDERS ? TILE_PAIR
                                                                           : TILE_SAMPLED;
            any_exact = any_exact || tile->state == TILE_EXACT;
        }
    }
    /* the tiles with many occluders, each its own pair: their bounds add in quadrature to
     * half the accuracy at most (of the transfer A_p SVF, absolute); those that do not
     * settle are sampled */
    uint32_t pairs = 0;
    for (uint32_t k = 0; k < w->tile_count; k++)
        pairs += w->tiles[k].state == TILE_PAIR;
    for (uint32_t k = 0; pairs && k < w->tile_count; k++) {
        sky_tile *tile = &w->tiles[k];
        double value, b;
        if (tile->state != TILE_PAIR)
            continue;
        if (pair_tile(c, p, w, &tile->polygon, 0.5 * c->accuracy * p->area / sqrt(pairs),
                      &tile->occluder_count, &value, &b)) {
            transfer += value;
            variance += b * b;
        } else
            tile->state = TILE_SAMPLED;
    }
    double sampled_share = 0, share_error = 0; /* unobstructed F to the sampled tiles */
    for (uint32_t k = 0; k < w->tile_count; k++) {
        const sky_tile *tile = &w->tiles[k];
        counts->polygon_pairs++;
        counts->obstructed_pairs += tile->occluder_count > 0;
        if (tile->state == TILE_EXACT || tile->state == TILE_PAIR) {
            counts->exact_pairs += tile->occluder_count > 0;
            continue;
        }
        counts->sampled_pairs++;
        double quadrature_error;
        sampled_share += pair_unobstructed(p, &tile->polygon, 0.25 * c->accuracy, c->eps,
                                           &quadrature_error) / p->area;
        share_error += quadrature_error / p->area;
    }
    if (sampled_share > 0) {
        double sampled_bound;
        double sampled = sample_sky(c, p, pi, w, fmin(sampled_share, 1), counts, &sampled_bound);
        transfer += sampled * p->area;
        variance += (sampled_bound + share_error) * p->area * (sampled_bound + share_error) *
                    p->area;
    }
    *bound = sqrt(variance);
    return transfer;
}

/* The box around every triangle of the scene, grown by SKY_MARGIN. */
static void scene_box(const rad_scene *scene, sky_box *box)
{
    for (int a = 0; a < 3; a++)
        box->lo[a] = INFINITY, box->hi[a] = -INFINITY;
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            rad_vec3 x = scene->positions[scene->triangles[t].vertex[k]];
            double c[3] = {x.x, x.y, x.z};
            for (int a = 0; a < 3; a++) {
                box->lo[a] = fmin(box->lo[a], c[a]);
                box->hi[a] = fmax(box->hi[a], c[a]);
            }
        }
    double d2 = 0;
    for (int a = 0; a < 3; a++)
        d2 += (box->hi[a] - box->lo[a]) * (box->hi[a] - box->lo[a]);
    /* uneven margins: no tile corner in a plane of symmetry of the scene, where a shadow's
     * edge would pass exactly through it (shadow clipping can leave a sliver there) */
    static const double unevenness[6] = {0.1458980, 0.3819660, 0.0901699,
                                         0.2360680, 0.4721360, 0.0557281};
    double margin = SKY_MARGIN * sqrt(d2) + 1e-9;
    for (int a = 0; a < 3; a++) {
        box->lo[a] -= margin * (1 + unevenness[2 * a]);
        box->hi[a] += margin * (1 + unevenness[2 * a + 1]);
    }
}

rad_status rad_sky_viewfactors_compute(const rad_scene *scene,
                                       const rad_viewfactor_options *options, double *sky,
                                       double *bound, rad_sky_report *report, rad_error *error)
{
    rad_viewfactor_options defaults = {0};
    if (!options)
        options = &defaults;
    if (options->threads < 0 || !(options->accuracy >= 0) || options->accuracy >= 1)
        return rad_fail(error, RAD_ERR_INVALID,
                        "sky view factors: threads must be >= 0 and accuracy in [0, 1)");
    double start = rad_clock_seconds();
    uint32_t n = scene->surface_count;
    for (uint32_t I = 0; I < n; I++)
        sky[I] = bound[I] = 0;
    if (report)
        memset(report, 0, sizeof(*report));
    if (scene->triangle_count == 0)
        return RAD_OK;
    int threads = options->threads > 0 ? options->threads : omp_get_max_threads();
    uint32_t max_rays = options->max_rays ? options->max_rays : RAD_DEFAULT_MAX_RAYS;
    sky_box box;
    scene_box(scene, &box);
    sky_context c = {&box,
                     NULL,
                     NULL,
                     options->accuracy > 0 ? options->accuracy : RAD_DEFAULT_ACCURACY,
                     0,
                     0,
                     max_rays < 64 ? 64 : max_rays,
                     !options->sky_exact         ? SKY_EXACT_MAX_OCCLUDERS
                     : options->exact_occluders ? options->exact_occluders
                                                : RAD_DEFAULT_EXACT_OCCLUDERS,
                     options->seed};
    vf_geometry geometry;
    occluder_tree *tree = NULL;
    rad_tracer *tracer = NULL;
    rad_status status = vf_geometry_build(scene, &geometry, error);
    if (status != RAD_OK)
        return status;
    /* every face of a convex solid stays: the sky lifts its occluders off p's plane
     * (lift_occluders_to), and where a ray enters a solid through the part cut away, a face
     * turned away from p is what stops it */
    status = occluder_tree_build(scene, geometry.triangle_source, false, &tree, error);
    if (status == RAD_OK)
        status = rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, error);
    if (status != RAD_OK) {
        occluder_tree_destroy(tree);
        vf_geometry_free(&geometry);
        return status;
    }
    c.tree = tree;
    c.tracer = tracer;
    c.eps = geometry.plane_epsilon;
    c.ray_offset = SKY_RAY_OFFSET * sqrt((box.hi[0] - box.lo[0]) * (box.hi[0] - box.lo[0]) +
                                         (box.hi[1] - box.lo[1]) * (box.hi[1] - box.lo[1]) +
                                         (box.hi[2] - box.lo[2]) * (box.hi[2] - box.lo[2]));
    sky_counts totals = {0};
    bool out_of_memory = false;
#pragma omp parallel num_threads(threads)
    {
        sky_counts counts = {0};
        sky_workspace *w = rad_alloc_array(1, sizeof(*w));
        vf_polygon *strips = rad_alloc_array(SKY_MAX_STRIPS, sizeof(*strips));
        bool ready = w && strips && pair_workspace_init(&w->pair, c.max_rays);
        if (!ready) {
#pragma omp atomic write
            out_of_memory = true;
        }
#pragma omp for schedule(dynamic, 1)
        for (uint32_t I = 0; I < n; I++) {
            const vf_surface *s = &geometry.surfaces[I];
            if (!ready || s->polygon_count == 0 || !(s->area > 0))
                continue;
            double transfer = 0, variance = 0;
            for (uint32_t k = 0; k < s->polygon_count; k++) {
                uint32_t pi = s->first_polygon + k;
                double b;
                transfer += sky_polygon(&c, &geometry.polygons[pi], pi, w, strips, &counts, &b);
                variance += b * b;
            }
            sky[I] = fmin(fmax(transfer / s->area, 0), 1);
            bound[I] = sqrt(variance) / s->area;
        }
        if (w)
            pair_workspace_free(&w->pair);
        free(w);
        free(strips);
#pragma omp critical
        {
            totals.polygon_pairs += counts.polygon_pairs;
            totals.obstructed_pairs += counts.obstructed_pairs;
            totals.exact_pairs += counts.exact_pairs;
            totals.sampled_pairs += counts.sampled_pairs;
            totals.capped_pairs += counts.capped_pairs;
            totals.rays += counts.rays;
        }
    }
    /* the surfaces given a factor, and those whose bound is above the accuracy */
    uint32_t given = 0, short_of = 0;
    for (uint32_t I = 0; I < n; I++) {
        const vf_surface *s = &geometry.surfaces[I];
        if (s->polygon_count == 0 || !(s->area > 0))
            continue;
        given++;
        short_of += bound[I] > c.accuracy;
    }
    rad_tracer_destroy(tracer);
    occluder_tree_destroy(tree);
    vf_geometry_free(&geometry);
    if (out_of_memory)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the sky view factors");
    if (report) {
        report->polygon_pairs = totals.polygon_pairs;
        report->obstructed_pairs = totals.obstructed_pairs;
        report->exact_pairs = totals.exact_pairs;
        report->sampled_pairs = totals.sampled_pairs;
        report->capped_pairs = totals.capped_pairs;
        report->rays = totals.rays;
        report->surfaces = given;
        report->short_surfaces = short_of;
        for (uint32_t I = 0; I < n; I++)
            report->largest_error_bound = fmax(report->largest_error_bound, bound[I]);
        report->seconds = rad_clock_seconds() - start;
        report->threads = threads;
    }
    return RAD_OK;
}

void rad_sky_viewfactor_check(const rad_viewfactor_matrix *matrix, const rad_scene *scene,
                              const double *sky, const double *bound, rad_sky_check *check)
{
    memset(check, 0, sizeof(*check));
    check->worst_surface = UINT32_MAX;
    for (uint32_t I = 0; I < matrix->n; I++) {
        if ((scene->surfaces[I].flags & RAD_SURFACE_OBSTRUCTION) || !(matrix->area[I] > 0))
            continue;
        double sum = 0, variance = 0;
        for (uint64_t k = matrix->row_start[I]; k < matrix->row_start[I + 1]; k++) {
            sum += matrix->value[k];
            variance += matrix->error_bound[k] * matrix->error_bound[k];
        }
        double deviation = fabs(sum + sky[I] - 1);
        if (check->worst_surface == UINT32_MAX || deviation > check->largest_deviation) {
            check->largest_deviation = deviation;
            check->worst_surface = I;
            check->worst_row_sum = sum;
            check->worst_row_bound = sqrt(variance);
            check->worst_sky_bound = bound[I];
        }
    }
}
