/*
 * polygon_integral.c - adaptive degree-5 integration over a polygon, see polygon_integral.h.
 */
#include "geometry/polygon_integral.h"

#include <math.h>
#include <pthread.h>

#include "core/vec3.h"
#include "geometry/least_squares.h"

/* The 7-point degree-5 rule on a triangle (Radon; Strang and Fix): barycentric points. */
static const double rule_a1 = 0.059715871789769820, rule_b1 = 0.470142064105115090;
static const double rule_a2 = 0.797426985353087322, rule_b2 = 0.101286507323456338;
static const double rule_w0 = 0.225, rule_w1 = 0.132394152788506181,
                    rule_w2 = 0.125939180544827153;

static inline rad_vec3 barycentric(rad_vec3 a, rad_vec3 b, rad_vec3 c, double u, double v,
                                   double w)
{
    return v3(u * a.x + v * b.x + w * c.x, u * a.y + v * b.y + w * c.y,
              u * a.z + v * b.z + w * c.z);
}

/* The 7 points' barycentric coordinates, in rule7's order. */
static const double rule_point[7][3] = {
    {1.0 / 3, 1.0 / 3, 1.0 / 3},      {rule_a1, rule_b1, rule_b1}, {rule_b1, rule_a1, rule_b1},
    {rule_b1, rule_b1, rule_a1},      {rule_a2, rule_b2, rule_b2}, {rule_b2, rule_a2, rule_b2},
    {rule_b2, rule_b2, rule_a2}};

/*
 * The edge check (polygon_integral.edge_check). A triangle's 4 children hold 28 rule
 * points; the polynomial of degree EDGE_FIT_DEGREE nearest them (least squares) predicts f
 * at the triangle's corners and edge midpoints, and those 6 points (the children's corners)
 * are compared with the prediction. Where f is smooth the prediction is good to h^5 and the
 * check costs no split; a sliver of light or shadow at a corner or along an edge, which no
 * rule point sees, shows. The prediction is linear in the 28 values: edge_predict[p][i] is
 * the weight of child point i (child i / 7, point i % 7) in f at point p (corners a, b, d,
 * then midpoints ab, bd, da), computed once.
 */
#define EDGE_FIT_DEGREE 4
#define EDGE_FIT_TERMS ((EDGE_FIT_DEGREE + 1) * (EDGE_FIT_DEGREE + 2) / 2)
#define CHILD_POINTS 28
_Static_assert(EDGE_FIT_TERMS <= LEAST_SQUARES_MAX_TERMS, "the fit's terms fit");

static const double edge_point[6][3] = {{1, 0, 0},     {0, 1, 0},     {0, 0, 1},
                                        {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
/* each child's corners as points of the parent, in adapt's order */
static const int child_corner[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
/* What a miss at a check point may weigh, as a share of the triangle: EDGE_SHARE_MARGIN
 * times the part of it nearer that point than any other of the 34 (the 28 rule points and
 * the 6 check points), where a sliver no rule point sees lies. About 0.018 at a corner and
 * 0.049 at a midpoint. Measured on the 1k city behind 256 occluders against brute force:
 * a factor 11 % low (within its bound, which is sized by the unobstructed factor) stays so
 * with 2 or 6 times and comes to 1.4 % with 16 times (about the degree-3 rule's weights),
 * but 16 times takes 1.7 times as long. 2 times already brings the tube's rim (test
 * _viewfactor_obstructed) within its bound; 6 is for a margin, at about 10 % more time. */
static double edge_point_share[6];
#define EDGE_SHARE_LATTICE 120
#define EDGE_SHARE_MARGIN 6.0

static double edge_predict[6][CHILD_POINTS];
static pthread_once_t edge_predict_once = PTHREAD_ONCE_INIT;

/* the monomials s^i t^j, i + j <= EDGE_FIT_DEGREE, at barycentric (., s, t) */
static void edge_fit_terms(double s, double t, double *term)
{
    unsigned n = 0;
    for (int i = 0; i <= EDGE_FIT_DEGREE; i++)
        for (int j = 0; i + j <= EDGE_FIT_DEGREE; j++)
            term[n++] = pow(s, i) * pow(t, j);
}

/* barycentric (., s, t) on the equilateral triangle of unit side */
static void equilateral(double s, double t, double *x, double *y)
{
    *x = s + 0.5 * t;
    *y = 0.8660254037844386 * t;
}

static void edge_predict_compute(void)
{
    double design[CHILD_POINTS][EDGE_FIT_TERMS];
    double site[6 + CHILD_POINTS][2];
    for (int p = 0; p < 6; p++)
        equilateral(edge_point[p][1], edge_point[p][2], &site[p][0], &site[p][1]);
    for (int k = 0; k < 4; k++)
        for (int r = 0; r < 7; r++) {
            double bary[3] = {0, 0, 0};
            for (int v = 0; v < 3; v++)
                for (int e = 0; e < 3; e++)
                    bary[e] += rule_point[r][v] * edge_point[child_corner[k][v]][e];
            edge_fit_terms(bary[1], bary[2], design[7 * k + r]);
            equilateral(bary[1], bary[2], &site[6 + 7 * k + r][0], &site[6 + 7 * k + r][1]);
        }
    /* the shares: a lattice of the triangle, each lattice point to its nearest site */
    unsigned nearest_count[6] = {0}, lattice = 0;
    for (int i = 0; i <= EDGE_SHARE_LATTICE; i++)
        for (int j = 0; i + j <= EDGE_SHARE_LATTICE; j++, lattice++) {
            double x, y, best = INFINITY;
            int nearest = 0;
            equilateral((double)i / EDGE_SHARE_LATTICE, (double)j / EDGE_SHARE_LATTICE, &x, &y);
            for (int m = 0; m < 6 + CHILD_POINTS; m++) {
                double dx = site[m][0] - x, dy = site[m][1] - y, d = dx * dx + dy * dy;
                if (d < best)
                    best = d, nearest = m;
            }
            if (nearest < 6)
                nearest_count[nearest]++;
        }
    for (int p = 0; p < 6; p++)
        edge_point_share[p] = EDGE_SHARE_MARGIN * nearest_count[p] / lattice;
    double at[6][EDGE_FIT_TERMS];
    for (int p = 0; p < 6; p++)
        edge_fit_terms(edge_point[p][1], edge_point[p][2], at[p]);
    least_squares_predictor(&design[0][0], CHILD_POINTS, EDGE_FIT_TERMS, &at[0][0], 6,
                            &edge_predict[0][0]);
}

static inline bool stopped(const polygon_integral *c) { return c->failed && *c->failed; }

/* Whether f is smooth on the triangle, whose points come next (polygon_integral.cell). */
static inline bool enter(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                         int level, int slot, int parent_slot)
{
    return c->cell ? c->cell(c->context, a, b, d, level, slot, parent_slot)
                   : c->min_depth == 0;
}

/* The 7-point rule times the area; *centre receives the 1-point (centroid) rule and
 * value[0 .. 7) f at the points. */
static double rule7(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                    double area, double *centre, double *value)
{
    for (int k = 0; k < 7; k++)
        value[k] = c->f(c->context, barycentric(a, b, d, rule_point[k][0], rule_point[k][1],
                                                rule_point[k][2]));
    *centre = value[0] * area;
    return (rule_w0 * value[0] + rule_w1 * (value[1] + value[2] + value[3]) +
            rule_w2 * (value[4] + value[5] + value[6])) *
           area;
}

/* Integral over triangle (a, b, d), child `slot` at level depth - 1, whose rule7 value
 * is `whole`; *error accumulates the estimated error of what is returned. corner[3]: f at
 * a, b and d when the edge check is on there. It is on in a triangle only where it was in
 * the triangle's parent: f is smooth in the children of a triangle where it is (the cell
 * callback's lists of what may shade only shrink a level down; without the callback,
 * smoothness is the same everywhere), so the parent always hands its corners down. */
static double adapt(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                    double area, double whole, double tolerance, int depth, int slot,
                    bool smooth, const double *corner, double *error)
{
    rad_vec3 ab = v3_scale(v3_add(a, b), 0.5), bd = v3_scale(v3_add(b, d), 0.5),
             da = v3_scale(v3_add(d, a), 0.5);
    double quarter = 0.25 * area, unused;
    rad_vec3 child[4][3] = {{a, ab, da}, {ab, b, bd}, {da, bd, d}, {ab, bd, da}};
    double part[4], value[CHILD_POINTS], at[6];
    bool part_smooth[4];
    bool check = c->edge_check && !smooth;
    for (int k = 0; k < 4; k++) {
        part_smooth[k] = enter(c, child[k][0], child[k][1], child[k][2], depth, k, slot);
        part[k] = rule7(c, child[k][0], child[k][1], child[k][2], quarter, &unused,
                        &value[7 * k]);
    }
    double sum = part[0] + part[1] + part[2] + part[3];
    double difference = fabs(sum - whole);
    if (check) {
        /* the midpoints are child 3's corners: f there under its cell, the last entered */
        at[0] = corner[0];
        at[1] = corner[1];
        at[2] = corner[2];
        at[3] = c->f(c->context, ab);
        at[4] = c->f(c->context, bd);
        at[5] = c->f(c->context, da);
        double miss = 0;
        for (int p = 0; p < 6; p++) {
            double predicted = 0;
            for (int i = 0; i < CHILD_POINTS; i++)
                predicted += edge_predict[p][i] * value[i];
            miss += edge_point_share[p] * fabs(at[p] - predicted);
        }
        difference = fmax(difference, miss * area);
    }
    if ((difference <= tolerance && (smooth || depth >= c->min_depth)) ||
        depth >= c->max_depth || stopped(c)) {
        *error += difference;
        return sum;
    }
    double t = 0.5 * tolerance, total = 0;
    for (int k = 0; k < 4; k++) {
        double child_corner_value[3];
        if (check)
            for (int v = 0; v < 3; v++)
                child_corner_value[v] = at[child_corner[k][v]];
        total += adapt(c, child[k][0], child[k][1], child[k][2], quarter, part[k], t, depth + 1,
                       k, part_smooth[k], check ? child_corner_value : NULL, error);
    }
    return total;
}

static double triangle_area(rad_vec3 a, rad_vec3 b, rad_vec3 d)
{
    return 0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(d, a)));
}

/* One fan triangle to max(accuracy |its value|, absolute): absolute is its share of the
 * polygon's absolute tolerance. */
static double integrate_triangle(const polygon_integral *c, rad_vec3 a, rad_vec3 b,
                                 rad_vec3 d, double accuracy, double absolute, double *error)
{
    double area = triangle_area(a, b, d);
    double centre, value[7];
    bool smooth = enter(c, a, b, d, 0, 0, 0);
    double whole = rule7(c, a, b, d, area, &centre, value);
    /* the floor keeps a pair that transfers (almost) nothing from refining forever */
    double tolerance = fmax(fmax(accuracy * fabs(whole), absolute), 1e-15 * area);
    bool check = c->edge_check && !smooth;
    if ((smooth || c->min_depth == 0) && !check && fabs(whole - centre) <= tolerance) {
        /* the 1-point rule already agrees: the degree-5 value is far better than that */
        *error += fabs(whole - centre);
        return whole;
    }
    double corner[3];
    if (check) {
        pthread_once(&edge_predict_once, edge_predict_compute);
        corner[0] = c->f(c->context, a);
        corner[1] = c->f(c->context, b);
        corner[2] = c->f(c->context, d);
    }
    return adapt(c, a, b, d, area, whole, tolerance, 1, 0, smooth, check ? corner : NULL,
                 error);
}

double polygon_integrate(const polygon_integral *integral, const rad_vec3 *polygon,
                         unsigned count, double accuracy, double *bound)
{
    return polygon_integrate_within(integral, polygon, count, accuracy, 0, bound);
}

double polygon_integrate_within(const polygon_integral *integral, const rad_vec3 *polygon,
                                unsigned count, double accuracy, double absolute, double *bound)
{
    double error = 0, sum = 0, area = 0;
    for (unsigned k = 1; k + 1 < count && absolute > 0; k++)
        area += triangle_area(polygon[0], polygon[k], polygon[k + 1]);
    /* each fan triangle to the relative accuracy, or its share by area of the absolute
     * tolerance: so is their sum */
    for (unsigned k = 1; k + 1 < count; k++) {
        double share = area > 0 ? absolute * triangle_area(polygon[0], polygon[k],
                                                           polygon[k + 1]) / area
                                : 0;
        sum += integrate_triangle(integral, polygon[0], polygon[k], polygon[k + 1], accuracy,
                                  share, &error);
    }
    *bound = error;
    return sum;
}
