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
 */
#include <math.h>
#include <stdbool.h>

#include "core/vec3.h"
#include "formfactor/contour.h"
#include "hierarchy/hierarchy.h"

#define CLUSTER_MEAN_COSINE 0.25
#define NEAR_DISTANCE 3.0     /* patch pairs closer than this x (sum of radii): 2 x 2 points */
#define TOUCHING_DISTANCE 1.0 /* and closer than this: 4 x 4 points */
#define OPEN_RATIO 5.0        /* a node seen from this many of its radii or more is a disk */
#define MAX_RECEIVER_POINTS 16u
#define MAX_SOURCE_OPENINGS 64

/* Largest signed distance of the box's corners from the plane through c with normal n. */
static double box_front(rad_vec3 lo, rad_vec3 hi, rad_vec3 c, rad_vec3 n)
{
    double best = -INFINITY;
    for (int k = 0; k < 8; k++) {
        rad_vec3 corner = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        best = fmax(best, v3_dot(n, v3_sub(corner, c)));
    }
    return best;
}

static double patch_to_patch(const rad_mesh *mesh, const hnode *p, const hnode *q)
{
    const rad_patch *rp = &mesh->patches[p->patch], *rq = &mesh->patches[q->patch];
    rad_vec3 polygon[4];
    for (uint32_t k = 0; k < rq->vertex_count; k++)
        polygon[k] = mesh->vertices[rq->vertex[k]];
    double distance = v3_length(v3_sub(q->centroid, p->centroid));
    double epsilon = 1e-7 * (p->radius + q->radius);
    if (distance >= NEAR_DISTANCE * (p->radius + q->radius))
        return contour_point_to_polygon(p->centroid, p->normal, polygon, rq->vertex_count,
                                        rq->normal, epsilon);
    rad_vec3 c[4];
    for (uint32_t k = 0; k < rp->vertex_count; k++)
        c[k] = mesh->vertices[rp->vertex[k]];
    /* the midpoint rule on m x m cells of the receiver (m^2 similar sub-triangles of a
     * triangle), finer for the closest pairs, where the kernel varies fastest */
    unsigned m = distance < TOUCHING_DISTANCE * (p->radius + q->radius) ? 4 : 2;
    double sum = 0;
    unsigned count = 0;
    for (unsigned j = 0; j < m; j++)
        for (unsigned i = 0; i < m; i++) {
            if (rp->vertex_count == 4) {
                double s = (i + 0.5) / m, t = (j + 0.5) / m;
                rad_vec3 point = v3_lerp(v3_lerp(c[0], c[1], s), v3_lerp(c[3], c[2], s), t);
                sum += contour_point_to_polygon(point, p->normal, polygon, rq->vertex_count,
                                                rq->normal, epsilon);
                count++;
                continue;
            }
            if (i + j >= m)
                continue;
            for (int flip = 0; flip < 2; flip++) {
                if (flip && i + j + 1 >= m)
                    continue;
                double u = (i + (flip ? 2.0 : 1.0) / 3) / m, v = (j + (flip ? 2.0 : 1.0) / 3) / m;
                rad_vec3 point = v3_add(c[0], v3_add(v3_scale(v3_sub(c[1], c[0]), u),
                                                     v3_scale(v3_sub(c[2], c[0]), v)));
                sum += contour_point_to_polygon(point, p->normal, polygon, rq->vertex_count,
                                                rq->normal, epsilon);
                count++;
            }
        }
    return sum / count;
}

/* F from a point to one node seen as a disk facing along its normal (a cluster: the mean
 * cosine). */
static double disk_factor(rad_vec3 x, rad_vec3 nx, const hnode *q)
{
    rad_vec3 d = v3_sub(q->centroid, x);
    double r2 = v3_dot(d, d), r = sqrt(r2);
    if (!(r > 0))
        return 0;
    double cos_x = fmax(0, v3_dot(nx, d) / r);
    double cos_q = q->planar ? fmax(0, -v3_dot(q->normal, d) / r) : CLUSTER_MEAN_COSINE;
    return q->area * cos_x * cos_q / (RAD_PI * r2 + q->area);
}

/* F from the point x (unit normal nx) to the patches below node q, unoccluded: the contour
 * formula for patches, a disk for nodes seen from OPEN_RATIO of their radii or more
 * (Barnes-Hut style), else the sum over the children; at most *budget nodes are opened. */
static double point_to_node(const rad_mesh *mesh, const hier_tree *tree, rad_vec3 x,
                            rad_vec3 nx, uint32_t index, int *budget)
{
    const hnode *q = &tree->nodes[index];
    if (box_front(q->lo, q->hi, x, nx) <= tree->plane_epsilon)
        return 0; /* wholly behind x's plane */
    if (q->planar && v3_dot(q->normal, v3_sub(x, q->centroid)) <= tree->plane_epsilon)
        return 0; /* x behind q's plane */
    if (q->patch != HNODE_NONE) {
        const rad_patch *rq = &mesh->patches[q->patch];
        rad_vec3 polygon[4];
        for (uint32_t k = 0; k < rq->vertex_count; k++)
            polygon[k] = mesh->vertices[rq->vertex[k]];
        return contour_point_to_polygon(x, nx, polygon, rq->vertex_count, rq->normal,
                                        1e-7 * q->radius);
    }
    rad_vec3 d = v3_sub(q->centroid, x);
    if (*budget <= 0 || (q->planar && v3_dot(d, d) >= OPEN_RATIO * OPEN_RATIO * q->radius * q->radius))
        return disk_factor(x, nx, q);
    (*budget)--;
    return point_to_node(mesh, tree, x, nx, q->child[0], budget) +
           point_to_node(mesh, tree, x, nx, q->child[1], budget);
}

/* F(p <- q) for a planar receiver node: the area-weighted mean of point_to_node over the
 * centroids of nodes below p small enough to be seen from q as points (largest first, at
 * most MAX_RECEIVER_POINTS). */
static double plane_to_node(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                            uint32_t source)
{
    const hnode *q = &tree->nodes[source];
    uint32_t points[MAX_RECEIVER_POINTS];
    unsigned count = 1;
    points[0] = receiver;
    for (;;) { /* split the point whose node is largest for its distance to q */
        unsigned widest = count;
        double worst = 1.0 / OPEN_RATIO;
        for (unsigned k = 0; k < count; k++) {
            const hnode *n = &tree->nodes[points[k]];
            if (n->child[0] == HNODE_NONE)
                continue;
            double gap = v3_length(v3_sub(n->centroid, q->centroid)) - q->radius;
            double ratio = gap > 0 ? n->radius / gap : INFINITY;
            if (ratio > worst) {
                worst = ratio;
                widest = k;
            }
        }
        if (widest == count || count == MAX_RECEIVER_POINTS)
            break;
        const hnode *n = &tree->nodes[points[widest]];
        points[widest] = n->child[0];
        points[count++] = n->child[1];
    }
    double sum = 0, area = 0;
    for (unsigned k = 0; k < count; k++) {
        const hnode *n = &tree->nodes[points[k]];
        int budget = MAX_SOURCE_OPENINGS;
        sum += n->area * point_to_node(mesh, tree, n->centroid, n->normal, source, &budget);
        area += n->area;
    }
    return area > 0 ? sum / area : 0;
}

/* The factor estimate and, when bound is set, the bound on A_p F. */
static link_estimate estimate(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                              uint32_t source, bool factor)
{
    const hnode *p = &tree->nodes[receiver], *q = &tree->nodes[source];
    link_estimate e = {0, 0};
    /* wholly behind a plane: nothing passes, exactly */
    if (p->planar && box_front(q->lo, q->hi, p->centroid, p->normal) <= tree->plane_epsilon)
        return e;
    if (q->planar && box_front(p->lo, p->hi, q->centroid, q->normal) <= tree->plane_epsilon)
        return e;
    if (p->patch != HNODE_NONE && q->patch != HNODE_NONE) {
        e.factor = factor ? patch_to_patch(mesh, p, q) : 0;
        e.factor_bound = factor ? e.factor * p->area : 0; /* leaves never split */
        return e;
    }
    rad_vec3 d = v3_sub(q->centroid, p->centroid);
    double r2 = v3_dot(d, d), r = sqrt(r2);
    double smaller = fmin(p->area, q->area);
    double spread = r > 0 ? (p->radius + q->radius) / r : INFINITY;
    double cos_p = CLUSTER_MEAN_COSINE, cos_q = CLUSTER_MEAN_COSINE;
    double bound_p = 1, bound_q = 1;
    if (r > 0 && p->planar) {
        cos_p = fmax(0, v3_dot(p->normal, d) / r);
        bound_p = fmin(1, cos_p + spread);
    }
    if (r > 0 && q->planar) {
        cos_q = fmax(0, -v3_dot(q->normal, d) / r);
        bound_q = fmin(1, cos_q + spread);
    }
    double gap = r - p->radius - q->radius;
    e.factor_bound = smaller;
    if (gap > 0)
        e.factor_bound = fmin(smaller, p->area * q->area * bound_p * bound_q / (RAD_PI * gap * gap));
    if (factor)
        e.factor = p->planar && q->planar ? plane_to_node(mesh, tree, receiver, source)
                                          : q->area * cos_p * cos_q / (RAD_PI * r2 + q->area);
    return e;
}

link_estimate hier_estimate(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                            uint32_t source)
{
    return estimate(mesh, tree, receiver, source, true);
}

double hier_error_bound(const rad_mesh *mesh, const hier_tree *tree, uint32_t receiver,
                        uint32_t source)
{
    return estimate(mesh, tree, receiver, source, false).factor_bound;
}

double hier_point_factor(const rad_mesh *mesh, const hier_tree *tree, rad_vec3 x, rad_vec3 nx,
                         uint32_t source)
{
    int budget = MAX_SOURCE_OPENINGS;
    return point_to_node(mesh, tree, x, nx, source, &budget);
}

rad_vec3 hier_sample_point(const rad_mesh *mesh, const hier_tree *tree, uint32_t node,
                           double u1, double u2, double u3, rad_vec3 *normal)
{
    const hnode *n = &tree->nodes[node];
    double base = n->first > 0 ? tree->cumulative[n->first - 1] : 0;
    double target = base + u1 * n->area;
    uint32_t lo = n->first, hi = n->first + n->count - 1;
    while (lo < hi) { /* first k with cumulative[k] > target */
        uint32_t mid = lo + (hi - lo) / 2;
        if (tree->cumulative[mid] > target)
            hi = mid;
        else
            lo = mid + 1;
    }
    const rad_patch *p = &mesh->patches[tree->order[lo]];
    double before = lo > 0 ? tree->cumulative[lo - 1] : 0;
    double within = p->area > 0 ? (target - before) / p->area : 0; /* in [0, 1) */
    rad_vec3 a = mesh->vertices[p->vertex[0]], b = mesh->vertices[p->vertex[1]],
             c = mesh->vertices[p->vertex[2]];
    if (p->vertex_count == 4) { /* triangle (0,1,2) or (0,2,3) by area */
        rad_vec3 dd = mesh->vertices[p->vertex[3]];
        double a0 = v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        double a1 = v3_length(v3_cross(v3_sub(c, a), v3_sub(dd, a)));
        if (within * (a0 + a1) >= a0) {
            b = c;
            c = dd;
        }
    }
    *normal = p->normal;
    double s = sqrt(u2);
    rad_vec3 point = v3_add(a, v3_add(v3_scale(v3_sub(b, a), s * (1 - u3)),
                                      v3_scale(v3_sub(c, a), s * u3)));
    return v3_add(point, v3_scale(p->normal, 2 * p->bulge));
}
