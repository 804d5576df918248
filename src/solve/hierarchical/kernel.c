/*
 * kernel.c - a link's form-factor estimate and its bound, and sample points on a node.
 *
 * F(p <- q), the fraction of what leaves p that reaches q (the irradiance p gathers per unit
 * radiosity of q), between centres at distance r along unit direction d:
 *   F ~ A_q cos_p cos_q / (pi r^2 + A_q)       (point to coaxial disk, exact on axis)
 * with cos of a plane's normal with d, and 1/4 for a cluster (Sillion 1995: a cluster
 * seen as an isotropic volume; 1/4 is the mean of max(0, cos) over the sphere). Between
 * two mesh patches the estimate is Lambert's contour formula from the receiver's centre,
 * or from four points of it when the two are close. The bound on A_p F used by refinement
 * takes cosines at their largest over the nodes' bounding spheres and the gap between the
 * spheres as the distance, and never exceeds min(A_p, A_q) (reciprocity with F <= 1).
 *
 * The final gather needs the irradiance on a leaf from a node (hier_leaf_gather):
 * the contour formula over the node's patches times their B, with planar subtrees seen
 * from OPEN_RATIO of their radii or more taken whole with their mean B (Barnes and Hut's
 * opening rule), by the kernel's expansion to second order about their centroid
 * (hier_planar_node_factor). The disk A cos cos / (pi r^2 + A) it replaced is exact only
 * on the axis and low seen obliquely: the Cornell box's solution came out 0.4 % dark.
 */
#include <math.h>

#include "core/minmax.h"
#include "core/random.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "geometry/contour.h"
#include "geometry/polygon_pair.h"
#include "solve/hierarchical/hierarchy.h"
#include "trace/ray.h"

#define CLUSTER_MEAN_COSINE 0.25
#define NEAR_DISTANCE 3.0     /* patch pairs closer than this x (sum of radii): 2 x 2 points */
#define TOUCHING_DISTANCE 1.0 /* and closer than this: 4 x 4 points */
#define OPEN_RATIO 6.0 /* a planar node seen from this many of its radii or more is taken whole */
#define MAX_SOURCE_OPENINGS 64
/* Two planar nodes at least this many times the sum of their radii apart, each wholly in
 * front of the other, take the kernel's second-order expansion (polygon_pair_expansion)
 * for their link's factor, not the disk A cos cos / (pi r^2 + A), low seen obliquely. */
#define EXPANSION_DISTANCE 3.0

/* Largest signed distance of the box's corners from the plane through c with normal n. */
static double box_front(rad_vec3 lo, rad_vec3 hi, rad_vec3 c, rad_vec3 n)
{
    double best = -INFINITY;
    for (int k = 0; k < 8; k++) {
        rad_vec3 corner = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        best = max_d(best, v3_dot(n, v3_sub(corner, c)));
    }
    return best;
}

/* The midpoints of m x m cells of patch p (m^2 similar sub-triangles of a triangle), lifted
 * by lift along its normal; returns how many (at most 16 for m <= 4). */
static unsigned patch_points(const rad_mesh *mesh, const rad_patch *p, unsigned m, double lift,
                             rad_vec3 *points)
{
    rad_vec3 c[4];
    for (uint32_t k = 0; k < p->vertex_count; k++)
        c[k] = v3_add(mesh->vertices[p->vertex[k]], v3_scale(p->normal, lift));
    unsigned count = 0;
    for (unsigned j = 0; j < m; j++)
        for (unsigned i = 0; i < m; i++) {
            if (p->vertex_count == 4) {
                double s = (i + 0.5) / m, t = (j + 0.5) / m;
                points[count++] = v3_lerp(v3_lerp(c[0], c[1], s), v3_lerp(c[3], c[2], s), t);
                continue;
            }
            for (int flip = 0; flip < 2; flip++) {
                if (i + j + (unsigned)flip >= m)
                    continue;
                double u = (i + (flip ? 2.0 : 1.0) / 3) / m, v = (j + (flip ? 2.0 : 1.0) / 3) / m;
                points[count++] = v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), u),
                                                      v3_scale(v3_sub(c[2], c[0]), v)));
            }
        }
    return count;
}

/* Points per side for the midpoint rule on a receiver patch of radius r at distance gap from
 * what it sees: finer for the closest, where the kernel varies fastest. */
static unsigned cells_for(double gap, double r)
{
    return gap < TOUCHING_DISTANCE * r ? 4 : gap < NEAR_DISTANCE * r ? 2 : 1;
}

static double patch_to_patch(const rad_mesh *mesh, const hnode *p, const hnode *q)
{
    const rad_patch *rp = &mesh->patches[p->patch], *rq = &mesh->patches[q->patch];
    rad_vec3 polygon[4];
    for (uint32_t k = 0; k < rq->vertex_count; k++)
        polygon[k] = mesh->vertices[rq->vertex[k]];
    double distance = v3_length(v3_sub(q->centroid, p->centroid));
    double epsilon = 1e-7 * (p->radius + q->radius);
    unsigned m = cells_for(distance, p->radius + q->radius);
    if (m == 1)
        return contour_point_to_polygon(p->centroid, p->normal, polygon, rq->vertex_count,
                                        rq->normal, epsilon);
    rad_vec3 points[16];
    unsigned count = patch_points(mesh, rp, m, 0, points);
    double sum = 0;
    for (unsigned k = 0; k < count; k++)
        sum += contour_point_to_polygon(points[k], p->normal, polygon, rq->vertex_count,
                                        rq->normal, epsilon);
    return sum / count;
}

/* F from a point x (unit normal nx) to a planar node from the second-order expansion of
 * the kernel cos_x cos_q / (pi r^2) about the node's centroid c (a multipole expansion:
 * exact to the node's second moment M, the error falling as (radius / r)^4). With
 * d = c - x, rho = |d|, h = -n_q.d (x's height over the node's plane), a = nx.d, and
 * cos_q / r^2 = h / r^3 exact on the plane, integrating over s = y - c:
 *   F = h / (pi rho^4) [a A - 2 a tr M / rho^2 + 12 a d.M d / rho^4 - 4 nx.M d / rho^2].
 * Checked on the axis of a disk of radius R: A / (pi rho^2) (1 - R^2 / rho^2), the
 * expansion of the exact R^2 / (rho^2 + R^2). Valid where the node lies wholly in front
 * of x's plane (a > radius); NAN otherwise, for the caller's fallback. */
double hier_planar_node_factor(rad_vec3 x, rad_vec3 nx, const hnode *q)
{
    rad_vec3 d = v3_sub(q->centroid, x);
    double a = v3_dot(nx, d), h = -v3_dot(q->normal, d);
    if (!(a > q->radius) || !(h > 0))
        return NAN;
    double m[6];
    for (int k = 0; k < 6; k++)
        m[k] = q->moment[k];
    rad_vec3 md = v3(m[0] * d.x + m[3] * d.y + m[4] * d.z, m[3] * d.x + m[1] * d.y + m[5] * d.z,
                     m[4] * d.x + m[5] * d.y + m[2] * d.z);
    double rho2 = v3_dot(d, d), inverse2 = 1 / rho2;
    double trace = m[0] + m[1] + m[2];
    double second = -2 * a * trace - 4 * v3_dot(nx, md) + 12 * a * v3_dot(d, md) * inverse2;
    double sum = a * q->area + inverse2 * second;
    return max_d(0, h * inverse2 * inverse2 * sum / RAD_PI);
}

/* F from a point to one node taken whole: a planar node wholly in front of the point by
 * its expansion, else as a disk facing along its normal (a cluster: the mean cosine). */
static double whole_node_factor(rad_vec3 x, rad_vec3 nx, const hnode *q)
{
    if (q->planar) {
        double f = hier_planar_node_factor(x, nx, q);
        if (!isnan(f))
            return f;
    }
    rad_vec3 d = v3_sub(q->centroid, x);
    double r2 = v3_dot(d, d), r = sqrt(r2);
    if (!(r > 0))
        return 0;
    double cos_x = max_d(0, v3_dot(nx, d) / r);
    double cos_q = q->planar ? max_d(0, -v3_dot(q->normal, d) / r) : CLUSTER_MEAN_COSINE;
    return q->area * cos_x * cos_q / (RAD_PI * r2 + q->area);
}

/* The irradiance at the point x (unit normal nx) from the patches below node q, per unit of
 * their radiosity B (sum of F x B), unoccluded: the contour formula for patches, a disk
 * with the node's pulled B for nodes seen from OPEN_RATIO of their radii or more (Barnes
 * and Hut), else the sum over the children; at most *budget nodes are opened. */
static rad_rgb point_to_node(const rad_mesh *mesh, const hier_tree *tree, const rad_rgb *B,
                             rad_vec3 x, rad_vec3 nx, uint32_t index, int *budget)
{
    const hnode *q = &tree->nodes[index];
    rad_rgb none = {0, 0, 0};
    if (box_front(q->lo, q->hi, x, nx) <= tree->plane_epsilon)
        return none; /* wholly behind x's plane */
    if (q->planar && v3_dot(q->normal, v3_sub(x, q->centroid)) <= tree->plane_epsilon)
        return none; /* x behind q's plane */
    double f;
    rad_vec3 d = v3_sub(q->centroid, x);
    if (q->patch != HNODE_NONE) {
        const rad_patch *rq = &mesh->patches[q->patch];
        rad_vec3 polygon[4];
        for (uint32_t k = 0; k < rq->vertex_count; k++)
            polygon[k] = mesh->vertices[rq->vertex[k]];
        f = contour_point_to_polygon(x, nx, polygon, rq->vertex_count, rq->normal,
                                     1e-7 * q->radius);
    } else if (*budget <= 0 ||
               (q->planar && v3_dot(d, d) >= OPEN_RATIO * OPEN_RATIO * q->radius * q->radius)) {
        f = whole_node_factor(x, nx, q);
    } else {
        (*budget)--;
        rad_rgb a = point_to_node(mesh, tree, B, x, nx, q->child[0], budget);
        rad_rgb b = point_to_node(mesh, tree, B, x, nx, q->child[1], budget);
        return (rad_rgb){a.r + b.r, a.g + b.g, a.b + b.b};
    }
    return (rad_rgb){f * B[index].r, f * B[index].g, f * B[index].b};
}

link_estimate hier_estimate(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                            uint32_t source)
{
    const hnode *p = &tree->nodes[receiver], *q = &tree->nodes[source];
    link_estimate e = {0, 0};
    /* wholly behind a plane: nothing passes, exactly */
    if (p->planar && box_front(q->lo, q->hi, p->centroid, p->normal) <= tree->plane_epsilon)
        return e;
    if (q->planar && box_front(p->lo, p->hi, q->centroid, q->normal) <= tree->plane_epsilon)
        return e;
    if (p->patch != HNODE_NONE && q->patch != HNODE_NONE) {
        e.factor = patch_to_patch(mesh, p, q);
        e.factor_bound = e.factor * p->area;
        return e;
    }
    rad_vec3 d = v3_sub(q->centroid, p->centroid);
    double r2 = v3_dot(d, d), r = sqrt(r2);
    double smaller = min_d(p->area, q->area);
    double spread = r > 0 ? (p->radius + q->radius) / r : INFINITY;
    double cos_p = CLUSTER_MEAN_COSINE, cos_q = CLUSTER_MEAN_COSINE;
    double bound_p = 1, bound_q = 1;
    if (r > 0 && p->planar) {
        cos_p = max_d(0, v3_dot(p->normal, d) / r);
        bound_p = min_d(1, cos_p + spread);
    }
    if (r > 0 && q->planar) {
        cos_q = max_d(0, -v3_dot(q->normal, d) / r);
        bound_q = min_d(1, cos_q + spread);
    }
    double gap = r - p->radius - q->radius;
    e.factor_bound = smaller;
    if (gap > 0)
        e.factor_bound = min_d(smaller, p->area * q->area * bound_p * bound_q / (RAD_PI * gap * gap));
    e.factor = q->area * cos_p * cos_q / (RAD_PI * r2 + q->area);
    if (p->planar && q->planar && r >= EXPANSION_DISTANCE * (p->radius + q->radius) &&
        v3_dot(p->normal, d) > q->radius && -v3_dot(q->normal, d) > p->radius) {
        /* far apart, each wholly in front of the other: the kernel's expansion to second
         * order about both centroids, as the dense form factors' far pairs */
        polygon_moments mp = {p->centroid, p->normal, p->area, {0}};
        polygon_moments mq = {q->centroid, q->normal, q->area, {0}};
        for (int k = 0; k < 6; k++) {
            mp.moment[k] = p->moment[k];
            mq.moment[k] = q->moment[k];
        }
        double G = polygon_pair_expansion(&mp, &mq);
        if (G > 0)
            e.factor = G / p->area;
    }
    return e;
}

rad_rgb hier_leaf_gather(const rad_mesh *mesh, const hier_tree *tree, const rad_rgb *B,
                         uint32_t leaf, uint32_t source)
{
    const hnode *p = &tree->nodes[leaf], *q = &tree->nodes[source];
    const rad_patch *patch = &mesh->patches[p->patch];
    double gap = v3_length(v3_sub(q->centroid, p->centroid)) - q->radius;
    rad_vec3 points[16];
    unsigned count = patch_points(mesh, patch, cells_for(gap, p->radius), 2 * patch->behind,
                                  points);
    if (count == 1)
        points[0] = v3_add(patch->centroid, v3_scale(patch->normal, 2 * patch->behind));
    rad_rgb sum = {0, 0, 0};
    for (unsigned k = 0; k < count; k++) {
        int budget = MAX_SOURCE_OPENINGS;
        rad_rgb h = point_to_node(mesh, tree, B, points[k], patch->normal, source, &budget);
        sum = (rad_rgb){sum.r + h.r, sum.g + h.g, sum.b + h.b};
    }
    return (rad_rgb){sum.r / count, sum.g / count, sum.b / count};
}

rad_vec3 hier_sample_point(const hier_tree *tree, uint32_t node, double u1, double u2,
                           double u3, rad_vec3 *normal, uint32_t *position)
{
    const hnode *n = &tree->nodes[node];
    uint32_t lo = n->first, length = n->count;
    double before = lo > 0 ? tree->cumulative[lo - 1] : 0;
    double target = before + u1 * n->area;
    /* the first k with cumulative[k] > target lies in [lo, lo + length): halve without
     * branches (the comparison becomes a conditional move) */
    while (length > 1) {
        uint32_t half = length / 2;
        lo = tree->cumulative[lo + half - 1] <= target ? lo + half : lo;
        length -= half;
    }
    if (lo > n->first)
        before = tree->cumulative[lo - 1];
    const leaf_shape *shape = &tree->shapes[lo];
    *position = lo;
    double area = tree->cumulative[lo] - before;
    double within = area > 0 ? (target - before) / area : 0; /* in [0, 1) */
    const float *e1 = shape->ab, *e2 = shape->ac;
    if (within >= shape->first_share) { /* triangle (a, c, d) of a quad */
        e1 = shape->ac;
        e2 = shape->ad;
    }
    *normal = v3(shape->normal[0], shape->normal[1], shape->normal[2]);
    double s = sqrt(u2), w1 = s * (1 - u3), w2 = s * u3;
    return v3(shape->a[0] + w1 * e1[0] + w2 * e2[0], shape->a[1] + w1 * e1[1] + w2 * e2[1],
              shape->a[2] + w1 * e1[2] + w2 * e2[2]);
}

static unsigned greatest_divisor(unsigned a, unsigned b)
{
    while (b) {
        unsigned t = a % b;
        a = b;
        b = t;
    }
    return a;
}

void hier_segments(const hier_tree *tree, uint64_t seed, uint32_t receiver, uint32_t source,
                   unsigned count, rad_ray *rays, double *kernel, const float *leaf_weight,
                   float *weight, uint8_t *blocked)
{
    double area = tree->nodes[source].area;
    rad_rng rng = rad_rng_seed(seed, receiver, source);
    /* stratified along each node's leaf order (spatially coherent), strata of the source
     * paired with the receiver's by a random stride prime to their count */
    unsigned stride = 1 + (unsigned)(rad_rng_next(&rng) % count);
    while (greatest_divisor(stride, count) != 1)
        stride--;
    unsigned offset = (unsigned)(rad_rng_next(&rng) % count);
    for (unsigned k = 0; k < count; k++) {
        double u[6];
        for (int m = 0; m < 6; m++)
            u[m] = rad_rng_uniform(&rng);
        u[0] = (k + u[0]) / count;
        u[3] = ((k * stride + offset) % count + u[3]) / count;
        rad_vec3 na, nb;
        uint32_t at_a, at_b;
        rad_vec3 a = hier_sample_point(tree, receiver, u[0], u[1], u[2], &na, &at_a);
        rad_vec3 b = hier_sample_point(tree, source, u[3], u[4], u[5], &nb, &at_b);
        rad_vec3 d = v3_sub(b, a);
        double r2 = v3_dot(d, d), r = sqrt(r2);
        double cos_a = r > 0 ? max_d(0, v3_dot(na, d) / r) : 0;
        double cos_b = r > 0 ? max_d(0, -v3_dot(nb, d) / r) : 0;
        if (kernel)
            kernel[k] = area * cos_a * cos_b / (RAD_PI * r2 + 0.25 * area);
        if (weight)
            weight[k] = leaf_weight[at_b];
        ray_segment(&rays[k], a, b);
        uint32_t from = tree->order[at_a], to = tree->order[at_b];
        blocked[k] = (near_contacts_any(&tree->contacts, from) ||
                      near_contacts_any(&tree->contacts, to)) &&
                     near_contacts_pair_may_block(&tree->contacts, from, to) &&
                     near_contacts_block(&tree->contacts, from, to, a, b);
    }
}

void hier_occluded(const rad_tracer *occluders, const rad_ray *rays, uint32_t count,
                   const uint8_t *blocked, uint8_t *occluded)
{
    rad_tracer_occluded(occluders, rays, count, occluded);
    for (uint32_t k = 0; k < count; k++)
        occluded[k] |= blocked[k];
}

double hier_visible_share(const double *kernel, const float *weight, const uint8_t *occluded,
                          unsigned count, double fallback)
{
    double open = 0, all = 0;
    for (unsigned k = 0; k < count; k++) {
        double w = weight ? kernel[k] * weight[k] : kernel[k];
        all += w;
        open += occluded[k] ? 0 : w;
    }
    return all > 0 ? open / all : fallback;
}
