/*
 * sky_model.c - sky luminance distributions relative to the zenith (uniform, CIE standard
 * overcast, CIE standard clear), their horizontal illuminance, and the angles of a world
 * direction on the sky. See sky_model.h and radiosity.h.
 *
 * The clear sky is the CIE standard general sky (CIE S 011/E:2003, ISO 15469:2004) of
 * type 12, "CIE standard clear sky, low luminance turbidity":
 *     L / L_z = f(chi) phi(Z) / (f(Z_s) phi(0)),
 *     phi(Z) = 1 + a exp(b / cos Z)  (1 at the horizon),   the gradation,
 *     f(chi) = 1 + c (exp(d chi) - exp(d pi / 2)) + e cos^2 chi,   the indicatrix,
 * Z the zenith angle of the direction, Z_s that of the sun, chi the angle between them,
 * with a = -1, b = -0.32, c = 10, d = -3, e = 0.45.
 */
#include "lights/sky_model.h"

#include <math.h>

#include "core/vec3.h"

/* CIE S 011 type 12: gradation group 5 (a, b), indicatrix group 4 (c, d, e) */
static const double clear_a = -1, clear_b = -0.32;
static const double clear_c = 10, clear_d = -3, clear_e = 0.45;

static double clamp(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

/* phi as a function of the elevation h = pi/2 - Z: cos Z = sin h */
static double clear_gradation(double elevation)
{
    double cos_zenith = sin(elevation);
    if (!(cos_zenith > 0))
        return 1;
    return 1 + clear_a * exp(clear_b / cos_zenith);
}

static double clear_indicatrix(double chi)
{
    double cos_chi = cos(chi);
    return 1 + clear_c * (exp(clear_d * chi) - exp(clear_d * RAD_PI / 2)) +
           clear_e * cos_chi * cos_chi;
}

double rad_sky_relative_luminance(rad_sky_model sky, double elevation, double gamma,
                                  double sun_elevation)
{
    if (!(elevation >= 0))
        return 0; /* below the horizon, or NaN */
    elevation = fmin(elevation, RAD_PI / 2);
    switch (sky) {
    case RAD_SKY_UNIFORM:
        return 1;
    case RAD_SKY_CIE_OVERCAST:
        return (1 + 2 * sin(elevation)) / 3;
    case RAD_SKY_CIE_CLEAR: {
        if (!isfinite(gamma) || !isfinite(sun_elevation))
            return 0;
        /* The formula holds for the sun above the horizon; below it, it is evaluated as
         * it stands (f stays above 1.3 for every angle, so the ratio stays finite). */
        double sun_zenith = RAD_PI / 2 - clamp(sun_elevation, -RAD_PI / 2, RAD_PI / 2);
        double chi = clamp(gamma, 0, RAD_PI);
        return clear_indicatrix(chi) * clear_gradation(elevation) /
               (clear_indicatrix(sun_zenith) * clear_gradation(RAD_PI / 2));
    }
    }
    return 0;
}

/* ---- the hemisphere integral ---------------------------------------------------------- */

enum {
    GAUSS_ORDER = 16, /* nodes per panel */
    PANELS = 12,      /* panels per graded interval */
    INTERVAL_NODES = GAUSS_ORDER * PANELS
};

/* Gauss-Legendre nodes and weights on [-1, 1]: the roots of P_n by Newton's method from
 * the Chebyshev-like guess cos(pi (i + 3/4) / (n + 1/2)) (Abramowitz and Stegun 25.4.29:
 * w = 2 / ((1 - x^2) P_n'(x)^2)). */
static void gauss_legendre(double x[GAUSS_ORDER], double w[GAUSS_ORDER])
{
    const int n = GAUSS_ORDER;
    for (int i = 0; i < n; i++) {
        double root = cos(RAD_PI * (i + 0.75) / (n + 0.5)), derivative = 1;
        for (int iteration = 0; iteration < 100; iteration++) {
            double p0 = 1, p1 = root; /* P_0, P_1, then the recurrence up to P_n */
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * root * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            derivative = n * (root * p1 - p0) / (root * root - 1);
            double step = p1 / derivative;
            root -= step;
            if (fabs(step) < 1e-16)
                break;
        }
        x[i] = root;
        w[i] = 2 / ((1 - root * root) * derivative * derivative);
    }
}

/* Nodes and weights of a composite rule over [from, to] (either order: the nodes crowd
 * toward `from`): t in [0, 1] in PANELS Gauss panels, x = from + (to - from) t^2, which
 * smooths a kink at `from` (the sun) by the Jacobian 2 t. */
static void graded_rule(double from, double to, const double gx[GAUSS_ORDER],
                        const double gw[GAUSS_ORDER], double x[INTERVAL_NODES],
                        double w[INTERVAL_NODES])
{
    double span = to - from;
    for (int p = 0; p < PANELS; p++)
        for (int i = 0; i < GAUSS_ORDER; i++) {
            double t = (p + 0.5 + 0.5 * gx[i]) / PANELS;
            double dt = 0.5 * gw[i] / PANELS;
            x[p * GAUSS_ORDER + i] = from + span * t * t;
            w[p * GAUSS_ORDER + i] = fabs(span) * 2 * t * dt;
        }
}

double sky_horizontal_illuminance_quadrature(rad_sky_model sky, double sun_elevation)
{
    if (!isfinite(sun_elevation))
        return 0;
    double gx[GAUSS_ORDER], gw[GAUSS_ORDER];
    gauss_legendre(gx, gw);

    /* elevation: [0, h_s] and [h_s, pi/2] (one of them empty when the sun is not strictly
     * above the horizon or is at the zenith), both graded toward the sun */
    double sun_h = clamp(sun_elevation, 0, RAD_PI / 2);
    double hx[2][INTERVAL_NODES], hw[2][INTERVAL_NODES];
    graded_rule(sun_h, 0, gx, gw, hx[0], hw[0]);
    graded_rule(sun_h, RAD_PI / 2, gx, gw, hx[1], hw[1]);

    /* azimuth from the sun's vertical plane: [0, pi], doubled (the sky is symmetric) */
    double ax[INTERVAL_NODES], aw[INTERVAL_NODES];
    graded_rule(0, RAD_PI, gx, gw, ax, aw);

    double sin_hs = sin(sun_elevation), cos_hs = cos(sun_elevation), sum = 0;
    for (int part = 0; part < 2; part++)
        for (int i = 0; i < INTERVAL_NODES; i++) {
            double h = hx[part][i];
            double sin_h = sin(h), cos_h = cos(h), ring = 0;
            for (int j = 0; j < INTERVAL_NODES; j++) {
                double cos_chi = sin_h * sin_hs + cos_h * cos_hs * cos(ax[j]);
                double chi = acos(clamp(cos_chi, -1, 1));
                ring += aw[j] * rad_sky_relative_luminance(sky, h, chi, sun_elevation);
            }
            /* dOmega = cos h dh dazimuth, times the cosine sin h of the horizontal plane */
            sum += hw[part][i] * 2 * ring * sin_h * cos_h;
        }
    return sum;
}

double sky_horizontal_illuminance_factor(rad_sky_model sky, double sun_elevation)
{
    switch (sky) {
    case RAD_SKY_UNIFORM:
        return RAD_PI; /* integral of sin h cos h dh dazimuth */
    case RAD_SKY_CIE_OVERCAST:
        return 7 * RAD_PI / 9; /* pi / 3 + (2 / 3) (2 pi / 3) */
    case RAD_SKY_CIE_CLEAR:
        return sky_horizontal_illuminance_quadrature(sky, sun_elevation);
    }
    return 0;
}

/* ---- angles on the sky ---------------------------------------------------------------- */

void sky_angles(rad_vec3 direction, rad_vec3 up, rad_vec3 north, double rotate_degrees,
                double *azimuth, double *elevation)
{
    rad_vec3 east = v3_cross(north, up);
    double x = v3_dot(direction, east), y = v3_dot(direction, north);
    double z = v3_dot(direction, up);
    double a = atan2(x, y) - rotate_degrees * (RAD_PI / 180);
    a = fmod(a, 2 * RAD_PI);
    if (a < 0)
        a += 2 * RAD_PI;
    if (!(a < 2 * RAD_PI))
        a = 0; /* -tiny + 2 pi rounds to 2 pi */
    *azimuth = a;
    *elevation = atan2(z, hypot(x, y));
}

rad_vec3 sky_direction(double azimuth, double elevation, rad_vec3 up, rad_vec3 north)
{
    rad_vec3 east = v3_cross(north, up);
    double horizontal = cos(elevation);
    return v3_add(v3_add(v3_scale(north, horizontal * cos(azimuth)),
                         v3_scale(east, horizontal * sin(azimuth))),
                  v3_scale(up, sin(elevation)));
}

double rad_sky_horizontal_factor(rad_sky_model sky, double sun_elevation)
{
    return sky_horizontal_illuminance_factor(sky, sun_elevation);
}
