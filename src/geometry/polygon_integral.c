/*
 * polygon_integral.c - adaptive degree-5 integration over a polygon, see polygon_integral.h.
 */
#include "geometry/polygon_integral.h"

#include <math.h>

#include "core/vec3.h"

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

static inline bool stopped(const polygon_integral *c) { return c->failed && *c->failed; }

/* Whether f is smooth on the triangle, whose points come next (polygon_integral.cell). */
static inline bool enter(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                         int level, int slot, int parent_slot)
{
    return c->cell ? c->cell(c->context, a, b, d, level, slot, parent_slot)
                   : c->min_depth == 0;
}

/* The 7-point rule times the area; *centre receives the 1-point (centroid) rule. */
static double rule7(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                    double area, double *centre)
{
    double f0 = c->f(c->context, barycentric(a, b, d, 1.0 / 3, 1.0 / 3, 1.0 / 3));
    double s1 = c->f(c->context, barycentric(a, b, d, rule_a1, rule_b1, rule_b1)) +
                c->f(c->context, barycentric(a, b, d, rule_b1, rule_a1, rule_b1)) +
                c->f(c->context, barycentric(a, b, d, rule_b1, rule_b1, rule_a1));
    double s2 = c->f(c->context, barycentric(a, b, d, rule_a2, rule_b2, rule_b2)) +
                c->f(c->context, barycentric(a, b, d, rule_b2, rule_a2, rule_b2)) +
                c->f(c->context, barycentric(a, b, d, rule_b2, rule_b2, rule_a2));
    *centre = f0 * area;
    return (rule_w0 * f0 + rule_w1 * s1 + rule_w2 * s2) * area;
}

/* Integral over triangle (a, b, d), child `slot` at level depth - 1, whose rule7 value
 * is `whole`; *error accumulates the estimated error of what is returned. */
static double adapt(const polygon_integral *c, rad_vec3 a, rad_vec3 b, rad_vec3 d,
                    double area, double whole, double tolerance, int depth, int slot,
                    bool smooth, double *error)
{
    rad_vec3 ab = v3_scale(v3_add(a, b), 0.5), bd = v3_scale(v3_add(b, d), 0.5),
             da = v3_scale(v3_add(d, a), 0.5);
    double quarter = 0.25 * area, unused;
    rad_vec3 child[4][3] = {{a, ab, da}, {ab, b, bd}, {da, bd, d}, {ab, bd, da}};
    double part[4];
    bool part_smooth[4];
    for (int k = 0; k < 4; k++) {
        part_smooth[k] = enter(c, child[k][0], child[k][1], child[k][2], depth, k, slot);
        part[k] = rule7(c, child[k][0], child[k][1], child[k][2], quarter, &unused);
    }
    double sum = part[0] + part[1] + part[2] + part[3];
    double difference = fabs(sum - whole);
    if ((difference <= tolerance && (smooth || depth >= c->min_depth)) ||
        depth >= c->max_depth || stopped(c)) {
        *error += difference;
        return sum;
    }
    double t = 0.5 * tolerance;
    return adapt(c, a, ab, da, quarter, part[0], t, depth + 1, 0, part_smooth[0], error) +
           adapt(c, ab, b, bd, quarter, part[1], t, depth + 1, 1, part_smooth[1], error) +
           adapt(c, da, bd, d, quarter, part[2], t, depth + 1, 2, part_smooth[2], error) +
           adapt(c, ab, bd, da, quarter, part[3], t, depth + 1, 3, part_smooth[3], error);
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
    double centre;
    bool smooth = enter(c, a, b, d, 0, 0, 0);
    double whole = rule7(c, a, b, d, area, &centre);
    /* the floor keeps a pair that transfers (almost) nothing from refining forever */
    double tolerance = fmax(fmax(accuracy * fabs(whole), absolute), 1e-15 * area);
    if ((smooth || c->min_depth == 0) && fabs(whole - centre) <= tolerance) {
        /* the 1-point rule already agrees: the degree-5 value is far better than that */
        *error += fabs(whole - centre);
        return whole;
    }
    return adapt(c, a, b, d, area, whole, tolerance, 1, 0, smooth, error);
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
