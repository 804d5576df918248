/*
 * test_polygon_integral.c - the adaptive integral over a polygon (src/geometry/
 * polygon_integral.c) against integrals worked out by hand: a polynomial of degree 5 is
 * exact on the first rule; a smooth bump reaches its tolerance; and a narrow cone of light
 * standing on a corner of the triangle, which no 7-point rule point sees at the splits the
 * integral makes, comes out 0 with a bound of 0 without the edge check (what made obstructed
 * view factors err beyond their bounds: a tube's rim seen from just below it) and within
 * its bound, near the exact value, with it.
 */
#include <math.h>
#include <stdio.h>

#include "core/vec3.h"
#include "geometry/polygon_integral.h"
#include "testlib.h"

/* f = x^5 + 3 x^2 y^3 - 2 y + 1 */
static double quintic(void *context, rad_vec3 x)
{
    (void)context;
    return pow(x.x, 5) + 3 * x.x * x.x * pow(x.y, 3) - 2 * x.y + 1;
}

/* f = exp(-((x - 0.3)^2 + (y - 0.2)^2) / 0.02), smooth with a scale well inside the
 * triangle */
static double bump(void *context, rad_vec3 x)
{
    (void)context;
    return exp(-((x.x - 0.3) * (x.x - 0.3) + (x.y - 0.2) * (x.y - 0.2)) / 0.02);
}

/* a cone of height 1 and radius `radius` on the origin: max(0, 1 - |x| / radius) */
static double cone(void *context, rad_vec3 x)
{
    double radius = *(const double *)context;
    return fmax(0, 1 - sqrt(x.x * x.x + x.y * x.y) / radius);
}

int main(void)
{
    /* the unit right triangle (0,0), (1,0), (0,1), counter-clockwise */
    const rad_vec3 triangle[3] = {v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
    double bound;

    /* int x^5 = 1/42, int x^2 y^3 = 2! 3! / 7! = 1/420, int y = 1/6, area 1/2 */
    double exact = 1.0 / 42 + 3.0 / 420 - 2.0 / 6 + 0.5;
    for (int check = 0; check < 2; check++) {
        polygon_integral integral = {quintic, NULL, 12, NULL, NULL, 2, check == 1};
        double value = polygon_integrate(&integral, triangle, 3, 1e-12, &bound);
        printf("quintic (edge check %s): %.17g, exact %.17g, bound %.2g\n",
               check ? "on" : "off", value, exact, bound);
        CHECK_NEAR(value, exact, 1e-14);
        /* off: the 7-point rule is exact; on: the degree-4 fit's misses at the corners
         * and midpoints are split down to the tolerance */
        CHECK(bound <= (check ? 8e-12 * exact : 1e-15));
    }

    /* the bump: int over the plane is 0.02 pi, and the triangle holds all of it but
     * e^(-0.2^2 / 0.02) = e^-2 of a tail past y = 0 (and less past the others): against a
     * fine split (depth 10, by the same rule) */
    polygon_integral fine = {bump, NULL, 10, NULL, NULL, 10, false};
    double reference = polygon_integrate(&fine, triangle, 3, 0, &bound);
    CHECK(reference > 0.02 * RAD_PI * 0.9 && reference < 0.02 * RAD_PI);
    for (int check = 0; check < 2; check++) {
        polygon_integral integral = {bump, NULL, 10, NULL, NULL, 2, check == 1};
        double value = polygon_integrate(&integral, triangle, 3, 1e-7, &bound);
        printf("bump (edge check %s): %.12g, fine split %.12g, bound %.2g\n",
               check ? "on" : "off", value, reference, bound);
        CHECK(fabs(value - reference) <= bound + 1e-12);
        /* each cell meets its share of the tolerance: the sum of the cells' estimates
         * stays within a few times it */
        CHECK(bound <= 8 * 1e-7 * reference);
    }

    /* the cone on the corner (0, 0): a quarter of a cone's volume pi r^2 / 3. At depth 2
     * the corner's cell is 1/4 wide and its children's rule points nearest the corner are
     * 0.0127 from it, farther than the cone reaches. */
    double radius = 0.01, quarter_cone = RAD_PI * radius * radius / 12;
    for (int check = 0; check < 2; check++) {
        polygon_integral integral = {cone, &radius, 8, NULL, NULL, 2, check == 1};
        double value = polygon_integrate_within(&integral, triangle, 3, 1e-3, 1e-9, &bound);
        printf("cone of radius %g on a corner (edge check %s): %.9g, exact %.9g, bound %.2g\n",
               radius, check ? "on" : "off", value, quarter_cone, bound);
        if (!check) {
            /* what the check is for: every point missed it, and the bound says nothing */
            CHECK(value == 0);
            CHECK(bound == 0);
        } else {
            CHECK(fabs(value - quarter_cone) <= bound);
            CHECK(fabs(value - quarter_cone) <= 0.02 * quarter_cone);
        }
    }
    return test_finish("test_polygon_integral");
}
