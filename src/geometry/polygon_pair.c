/*
 * polygon_pair.c - the double contour integral between two polygons, see polygon_pair.h.
 */
#include "geometry/polygon_pair.h"

#include <math.h>

#include "core/vec3.h"

/* Edges closer to parallel than this (the sine of their angle) are taken as parallel:
 * over an edge of length L the distance between their lines then changes by under 1e-9 L. */
#define PARALLEL_SINE 1e-9
/* Halvings of an edge's outer integral, at most (2^-40 of it: far below any tolerance). */
#define MAX_HALVINGS 40

/* Gauss-Kronrod 7-15 on [-1, 1]: the Kronrod nodes (the Gauss ones are the odd-numbered,
 * and 0) and weights, and the 7-point Gauss weights (Kronrod 1965; QUADPACK's qk15). */
static const double kronrod_node[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
static const double kronrod_weight[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double gauss_weight[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

/* u ln u, 0 at u = 0. */
static inline double u_log_u(double u) { return u > 0 ? u * log(u) : 0; }

/* int ln sqrt(x^2 + d^2) dx = x ln sqrt(x^2 + d^2) - x + d atan(x / d), d >= 0. */
static inline double line_antiderivative(double x, double d)
{
    double u = x * x + d * d;
    double log_term = u > 0 ? 0.5 * x * log(u) : 0;
    return log_term - x + (d > 0 ? d * atan2(x, d) : 0);
}

/* Its antiderivative again (up to a linear term): K'' = ln sqrt(x^2 + d^2). */
static inline double line_second_antiderivative(double x, double d)
{
    double u = x * x + d * d;
    double log_u = u > 0 ? log(u) : 0;
    return 0.25 * u_log_u(u) - 0.75 * x * x + (d > 0 ? d * x * atan2(x, d) : 0) -
           0.5 * d * d * log_u;
}

/* An edge f from b along unit v, length Lb: int over f of ln |x - y| dy for a point x. */
typedef struct inner_edge {
    rad_vec3 b, v;
    double length;
} inner_edge;

static inline double inner_integral(const inner_edge *f, rad_vec3 x)
{
    rad_vec3 w = v3_sub(x, f->b);
    double along = v3_dot(w, f->v);
    double d = v3_length(v3_cross(w, f->v));
    return line_antiderivative(f->length - along, d) - line_antiderivative(-along, d);
}

/* Gauss-Kronrod 7-15 of the inner integral along a + s u, s in [s0, s1]; *error is
 * |Kronrod - Gauss|. */
static double kronrod(const inner_edge *f, rad_vec3 a, rad_vec3 u, double s0, double s1,
                      double *error)
{
    double centre = 0.5 * (s0 + s1), half = 0.5 * (s1 - s0);
    double value = inner_integral(f, v3_add(a, v3_scale(u, centre)));
    double k = kronrod_weight[7] * value, g = gauss_weight[3] * value;
    for (int i = 0; i < 7; i++) {
        double ds = half * kronrod_node[i];
        double sum = inner_integral(f, v3_add(a, v3_scale(u, centre - ds))) +
                     inner_integral(f, v3_add(a, v3_scale(u, centre + ds)));
        k += kronrod_weight[i] * sum;
        if (i % 2 == 1)
            g += gauss_weight[i / 2] * sum;
    }
    *error = fabs(k - g) * half;
    return k * half;
}

static double adapt(const inner_edge *f, rad_vec3 a, rad_vec3 u, double s0, double s1,
                    double whole, double tolerance, int depth)
{
    double mid = 0.5 * (s0 + s1), e0, e1;
    double left = kronrod(f, a, u, s0, mid, &e0), right = kronrod(f, a, u, mid, s1, &e1);
    double halves = left + right;
    if (depth >= MAX_HALVINGS || !isfinite(halves) || fabs(halves - whole) <= tolerance)
        return halves; /* (a value that is not finite would split both halves 40 deep) */
    return adapt(f, a, u, s0, mid, left, 0.5 * tolerance, depth + 1) +
           adapt(f, a, u, mid, s1, right, 0.5 * tolerance, depth + 1);
}

/* (e^ . f^) int over e int over f of ln r, for edge e from a to a + ea and f from b to
 * b + eb. */
static double edge_pair(rad_vec3 a, rad_vec3 ea, rad_vec3 b, rad_vec3 eb, double accuracy)
{
    double la = v3_length(ea), lb = v3_length(eb);
    if (!(la > 0) || !(lb > 0))
        return 0;
    rad_vec3 u = v3_scale(ea, 1 / la), v = v3_scale(eb, 1 / lb);
    double cosine = v3_dot(u, v);
    if (cosine == 0)
        return 0;
    double sine = v3_length(v3_cross(u, v));
    if (sine <= PARALLEL_SINE) {
        /* both along v: e covers [lo, hi] of f's line coordinate, at distance d from it;
         * int over [lo, hi] of int over [0, lb] of ln sqrt((x - t)^2 + d^2) dt dx
         * = -(K(hi - lb) - K(hi) - K(lo - lb) + K(lo)) */
        rad_vec3 w = v3_sub(a, b);
        double start = v3_dot(w, v), d = v3_length(v3_cross(w, v));
        double end = start + (cosine > 0 ? la : -la);
        double lo = start < end ? start : end, hi = start < end ? end : start;
        double value = -(line_second_antiderivative(hi - lb, d) -
                         line_second_antiderivative(hi, d) -
                         line_second_antiderivative(lo - lb, d) +
                         line_second_antiderivative(lo, d));
        return cosine > 0 ? value : -value;
    }
    inner_edge f = {b, v, lb};
    double error;
    double whole = kronrod(&f, a, u, 0, la, &error);
    double tolerance = accuracy * la * lb;
    if (error > tolerance)
        whole = adapt(&f, a, u, 0, la, whole, tolerance, 1);
    return cosine * whole;
}

/* Clips polygon (count corners) to the half-space n . (x - origin) >= 0, corners within
 * epsilon of the plane taken as on it; returns the corners kept in out. */
static unsigned clip_to_front(const rad_vec3 *polygon, unsigned count, rad_vec3 n,
                              rad_vec3 origin, double epsilon, rad_vec3 *out)
{
    double h[POLYGON_PAIR_MAX_VERTICES];
    unsigned in_front = 0, behind = 0;
    for (unsigned k = 0; k < count; k++) {
        h[k] = v3_dot(n, v3_sub(polygon[k], origin));
        if (fabs(h[k]) <= epsilon)
            h[k] = 0;
        in_front += h[k] > 0;
        behind += h[k] < 0;
    }
    if (in_front == 0)
        return 0; /* wholly behind or in the plane: no exchange */
    if (behind == 0) {
        for (unsigned k = 0; k < count; k++)
            out[k] = polygon[k];
        return count;
    }
    unsigned kept = 0;
    for (unsigned k = 0; k < count; k++) {
        unsigned next = k + 1 == count ? 0 : k + 1;
        if (h[k] >= 0)
            out[kept++] = polygon[k];
        if ((h[k] > 0 && h[next] < 0) || (h[k] < 0 && h[next] > 0))
            out[kept++] = v3_lerp(polygon[k], polygon[next], h[k] / (h[k] - h[next]));
    }
    return kept;
}

/* +1 when the corners run counter-clockwise about n, else -1. */
static double winding(const rad_vec3 *polygon, unsigned count, rad_vec3 n)
{
    rad_vec3 area = v3(0, 0, 0);
    for (unsigned k = 0; k < count; k++)
        area = v3_add(area, v3_cross(polygon[k], polygon[k + 1 == count ? 0 : k + 1]));
    return v3_dot(area, n) >= 0 ? 1 : -1;
}

double polygon_pair_transfer(const rad_vec3 *p, unsigned np, rad_vec3 p_normal,
                             const rad_vec3 *q, unsigned nq, rad_vec3 q_normal,
                             double plane_epsilon, double accuracy)
{
    rad_vec3 cp[POLYGON_PAIR_MAX_VERTICES], cq[POLYGON_PAIR_MAX_VERTICES];
    unsigned kp = clip_to_front(p, np, q_normal, q[0], plane_epsilon, cp);
    unsigned kq = clip_to_front(q, nq, p_normal, p[0], plane_epsilon, cq);
    if (kp < 3 || kq < 3)
        return 0;
    /* ln r is measured from an origin inside the pair: the sum is the same for any unit
     * of length (each contour closes), and its terms stay small */
    rad_vec3 origin = cp[0];
    for (unsigned k = 0; k < kp; k++)
        cp[k] = v3_sub(cp[k], origin);
    for (unsigned k = 0; k < kq; k++)
        cq[k] = v3_sub(cq[k], origin);
    double sign = winding(cp, kp, p_normal) * winding(cq, kq, q_normal);
    double sum = 0;
    for (unsigned i = 0; i < kp; i++) {
        rad_vec3 a = cp[i], ea = v3_sub(cp[i + 1 == kp ? 0 : i + 1], a);
        for (unsigned j = 0; j < kq; j++) {
            rad_vec3 b = cq[j], eb = v3_sub(cq[j + 1 == kq ? 0 : j + 1], b);
            sum += edge_pair(a, ea, b, eb, accuracy);
        }
    }
    double G = sign * sum / (2 * RAD_PI);
    return G > 0 ? G : 0;
}

void polygon_second_moment(const rad_vec3 *corner, unsigned count, rad_vec3 centroid,
                           double m[6])
{
    for (int k = 0; k < 6; k++)
        m[k] = 0;
    for (unsigned t = 0; t + 2 < count; t++) {
        rad_vec3 v[3] = {corner[0], corner[t + 1], corner[t + 2]};
        double area = 0.5 * v3_length(v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0])));
        rad_vec3 centre = v3_scale(v3_add(v3_add(v[0], v[1]), v[2]), 1.0 / 3);
        rad_vec3 d[4] = {v3_sub(v[0], centre), v3_sub(v[1], centre), v3_sub(v[2], centre),
                         v3_sub(centre, centroid)};
        for (int k = 0; k < 4; k++) {
            double w = k < 3 ? area / 12 : area;
            m[0] += w * d[k].x * d[k].x;
            m[1] += w * d[k].y * d[k].y;
            m[2] += w * d[k].z * d[k].z;
            m[3] += w * d[k].x * d[k].y;
            m[4] += w * d[k].x * d[k].z;
            m[5] += w * d[k].y * d[k].z;
        }
    }
}

void polygon_moments_of(const rad_vec3 *corner, unsigned count, rad_vec3 normal,
                        polygon_moments *out)
{
    rad_vec3 weighted = v3(0, 0, 0);
    double area = 0;
    for (unsigned t = 0; t + 2 < count; t++) {
        rad_vec3 a = corner[0], b = corner[t + 1], c = corner[t + 2];
        double piece = 0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a)));
        weighted = v3_add(weighted, v3_scale(v3_add(v3_add(a, b), c), piece / 3));
        area += piece;
    }
    out->area = area;
    out->normal = normal;
    out->centroid = area > 0 ? v3_scale(weighted, 1 / area) : corner[0];
    polygon_second_moment(corner, count, out->centroid, out->moment);
}

/* W v for the symmetric W given as (xx, yy, zz, xy, xz, yz). */
static inline rad_vec3 symmetric_times(const double w[6], rad_vec3 v)
{
    return v3(w[0] * v.x + w[3] * v.y + w[4] * v.z, w[3] * v.x + w[1] * v.y + w[5] * v.z,
              w[4] * v.x + w[5] * v.y + w[2] * v.z);
}

double polygon_pair_expansion(const polygon_moments *p, const polygon_moments *q)
{
    rad_vec3 d = v3_sub(q->centroid, p->centroid);
    double a = v3_dot(p->normal, d), b = v3_dot(q->normal, d);
    double rho2 = v3_dot(d, d), inverse2 = 1 / rho2;
    double g = inverse2 * inverse2;
    /* W = A_q M_p + A_p M_q: the second-order term is 1/2 W : grad^2 k for the kernel
     * k(d) = -(n_p . d)(n_q . d) / (pi rho^4) */
    double w[6];
    for (int k = 0; k < 6; k++)
        w[k] = q->area * p->moment[k] + p->area * q->moment[k];
    rad_vec3 wd = symmetric_times(w, d), wnq = symmetric_times(w, q->normal);
    double trace = w[0] + w[1] + w[2];
    double second = 2 * g * v3_dot(p->normal, wnq) -
                    8 * g * inverse2 * (b * v3_dot(p->normal, wd) + a * v3_dot(q->normal, wd)) +
                    a * b * g * inverse2 * (-4 * trace + 24 * inverse2 * v3_dot(d, wd));
    return (-p->area * q->area * a * b * g - 0.5 * second) / RAD_PI;
}
