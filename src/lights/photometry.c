/*
 * photometry.c - a photometric web (IES LM-63, read by ies_read.c): the candela look-up
 * and freeing it.
 *
 * rad_photometry_candela interpolates bilinearly in (horizontal, vertical) degrees between
 * the table's angles, after reducing the horizontal angle by the file's symmetry:
 *   type C (vertical 0 = nadir .. 180 = zenith, horizontal counter-clockwise from above):
 *     a single 0    symmetric about the vertical axis: any horizontal angle;
 *     0..90         symmetric about the 0-180 and the 90-270 planes: mirrored into the first
 *                   quadrant;
 *     0..180        symmetric about the 0-180 plane: h and 360 - h alike;
 *     90..270       symmetric about the 90-270 plane: h and 180 - h alike;
 *     0..360        none: the angle wrapped into [0, 360) (so 360 reads the 0 column).
 *   types A and B: the file's own angles, vertical V in [-90, 90] (the angle about the
 *     polar axis) and horizontal H in [-90, 90] (the angle from the equator toward the
 *     polar axis); a single 0 holds for every H, 0..90 is laterally symmetric (H and -H
 *     alike); |H| > 90 is not a direction of these systems: 0.
 * A vertical angle outside the table's range gives 0 (a downlight listed 0..90 sends
 * nothing above the horizontal), as does a non-finite angle. A web whose horizontal angles
 * are none of these variants (not one rad_photometry_read makes) is read as listed, 0
 * outside its range.
 */
#include <math.h>
#include <stdlib.h>

#include "radiosity.h"

void rad_photometry_destroy(rad_photometry *photometry)
{
    if (!photometry)
        return;
    free(photometry->vertical_degrees);
    free(photometry->horizontal_degrees);
    free(photometry->candela);
    free(photometry);
}

/* The interval of ascending `angles` (count >= 2) holding x, angles[0] <= x <=
 * angles[count - 1]: index k with angles[k] <= x <= angles[k + 1], and the fraction t of
 * the way from angles[k] to angles[k + 1] (exactly 0 or 1 on a listed angle). */
static uint32_t locate(const double *angles, uint32_t count, double x, double *t)
{
    uint32_t low = 0, high = count - 1; /* angles[low] <= x <= angles[high] */
    while (high - low > 1) {
        uint32_t middle = low + (high - low) / 2;
        if (angles[middle] <= x)
            low = middle;
        else
            high = middle;
    }
    double span = angles[low + 1] - angles[low];
    double f = span > 0 ? (x - angles[low]) / span : 0;
    *t = f < 0 ? 0 : f > 1 ? 1 : f;
    return low;
}

/* From a (t = 0) to b (t = 1), exactly a and b at the ends and never outside [a, b] (the
 * rounding of (1 - t) a + t b could step an ulp beyond). */
static double lerp(double a, double b, double t)
{
    double value = (1 - t) * a + t * b, low = a < b ? a : b, high = a < b ? b : a;
    return value < low ? low : value > high ? high : value;
}

/* Linear along the vertical angles of one horizontal column. */
static double column_value(const rad_photometry *ph, uint32_t column, uint32_t k, double t)
{
    const double *c = ph->candela + (size_t)column * ph->vertical_count;
    if (ph->vertical_count == 1)
        return c[0];
    return lerp(c[k], c[k + 1], t);
}

/* The horizontal angle reduced by the symmetry of a type C web (degrees, [0, 360)). */
static double type_c_horizontal(double h, double first, double last, uint32_t count)
{
    h = fmod(h, 360.0);
    if (h < 0)
        h += 360.0;
    if (h >= 360.0)
        h = 0; /* -1e-20 + 360 */
    if (count == 1)
        return first;
    if (first == 0 && last == 90) {
        if (h > 180)
            h = 360 - h;
        if (h > 90)
            h = 180 - h;
    } else if (first == 0 && last == 180) {
        if (h > 180)
            h = 360 - h;
    } else if (first == 90 && last == 270) {
        if (h < 90)
            h = 180 - h;
        else if (h > 270)
            h = 540 - h;
    }
    return h;
}

double rad_photometry_candela(const rad_photometry *photometry, double vertical_degrees,
                              double horizontal_degrees)
{
    const rad_photometry *ph = photometry;
    if (!ph || !ph->vertical_count || !ph->horizontal_count || !ph->vertical_degrees ||
        !ph->horizontal_degrees || !ph->candela || !isfinite(vertical_degrees) ||
        !isfinite(horizontal_degrees))
        return 0;
    uint32_t nv = ph->vertical_count, nh = ph->horizontal_count;
    const double *v = ph->vertical_degrees, *hd = ph->horizontal_degrees;
    if (vertical_degrees < v[0] || vertical_degrees > v[nv - 1])
        return 0;
    double first = hd[0], last = hd[nh - 1], h = horizontal_degrees;
    if (ph->photometric_type == 1) {
        h = type_c_horizontal(h, first, last, nh);
    } else {
        if (fabs(h) > 90)
            return 0;
        if (nh == 1)
            h = first;
        else if (first == 0 && last == 90)
            h = fabs(h);
    }
    if (h < first || h > last)
        return 0;
    double tv = 0;
    uint32_t kv = nv > 1 ? locate(v, nv, vertical_degrees, &tv) : 0;
    if (nh == 1)
        return column_value(ph, 0, kv, tv);
    double th;
    uint32_t kh = locate(hd, nh, h, &th);
    return lerp(column_value(ph, kh, kv, tv), column_value(ph, kh + 1, kv, tv), th);
}
