/*
 * test_sun_sky.c - the sun's position against published values (Meeus's worked examples,
 * NREL's SPA example, the equation of time's known extremes, equinox and solstice
 * geometry), the sky models against their closed forms and the CIE formula, and the
 * environment map's convention.
 */
#include <math.h>
#include <string.h>

#include "core/random.h"
#include "core/vec3.h"
#include "lights/environment_map.h"
#include "lights/sky_model.h"
#include "lights/sun_position.h"
#include "testlib.h"

static const double pi = 3.14159265358979323846;
static const double degree = 3.14159265358979323846 / 180;

static rad_status sun_at(double latitude, double longitude, int year, int month, int day,
                         double hour, double utc_offset, double *azimuth, double *elevation,
                         rad_error *error)
{
    rad_place_time when = {latitude, longitude, year, month, day, hour, utc_offset};
    return rad_sun_position(&when, azimuth, elevation, error);
}

static void test_julian_day(void)
{
    /* Meeus, "Astronomical Algorithms", 2nd ed., chapter 7 (examples 7.a, 7.b and the
     * table after them) */
    CHECK_ABS(sun_julian_day(2000, 1, 1, 12), 2451545.0, 1e-9);
    CHECK_ABS(sun_julian_day(1957, 10, 4, 0.81 * 24), 2436116.31, 1e-6);
    CHECK_ABS(sun_julian_day(1987, 1, 27, 0), 2446822.5, 1e-9);
    CHECK_ABS(sun_julian_day(1988, 6, 19, 12), 2447332.0, 1e-9);
    CHECK_ABS(sun_julian_day(1900, 1, 1, 0), 2415020.5, 1e-9);
    CHECK_ABS(sun_julian_day(1600, 12, 31, 0), 2305812.5, 1e-9);
}

static void test_meeus_example(void)
{
    /* Meeus example 25.a: 1992 October 13.0 TD = JDE 2448908.5. The book gives the true
     * longitude 199.90988, R = 0.99766, the apparent longitude 199.90895, the corrected
     * obliquity 23.43999 and the apparent declination -7.78507 degrees */
    sun_ephemeris sun = sun_ephemeris_at(2448908.5);
    CHECK_ABS(sun.true_longitude, 199.90988, 1e-4);
    CHECK_ABS(sun.apparent_longitude, 199.90895, 1e-4);
    CHECK_ABS(sun.radius_au, 0.99766, 1e-5);
    CHECK_ABS(sun.obliquity, 23.43999, 1e-4);
    CHECK_ABS(sun.declination, -7.78507, 1e-4);
    /* Meeus example 28.b, same instant, Smart's formula: E = +13 min 42.7 s (the exact
     * value of example 28.a is 13 min 42.6 s) */
    CHECK_ABS(sun.equation_of_time, 13 + 42.7 / 60, 0.01);
}

static void test_equation_of_time_extremes(void)
{
    /* the equation of time over 2024 (daily at 12 UT): its minimum about -14.2 min near
     * 11-12 February, its maximum about +16.4 min near 3 November (almanac values) */
    double lowest = INFINITY, highest = -INFINITY;
    double lowest_day = 0, highest_day = 0;
    double january_1 = sun_julian_day(2024, 1, 1, 12);
    for (int d = 0; d < 366; d++) {
        double e = sun_ephemeris_at(january_1 + d).equation_of_time;
        if (e < lowest) {
            lowest = e;
            lowest_day = d + 1; /* day of the year */
        }
        if (e > highest) {
            highest = e;
            highest_day = d + 1;
        }
    }
    CHECK_ABS(lowest, -14.2, 0.2);
    CHECK_ABS(highest, 16.4, 0.2);
    CHECK(lowest_day >= 31 + 10 && lowest_day <= 31 + 13);              /* Feb 10..13 */
    CHECK(highest_day >= 305 + 2 && highest_day <= 305 + 5);            /* Nov 2..5 (leap) */
}

static void test_solstices_and_equinox(void)
{
    /* June solstice 2024: 20 June 20:51 UT; December: 21 December 09:21 UT. The
     * declination is then +-epsilon, 23.436 degrees in 2024 (Meeus 22.2) */
    double june = sun_julian_day(2024, 6, 20, 20 + 51.0 / 60);
    double december = sun_julian_day(2024, 12, 21, 9 + 21.0 / 60);
    CHECK_ABS(sun_ephemeris_at(june).declination, 23.44, 0.05);
    CHECK_ABS(sun_ephemeris_at(december).declination, -23.44, 0.05);
    CHECK_ABS(sun_ephemeris_at(june).apparent_longitude, 90, 0.01);
    CHECK_ABS(sun_ephemeris_at(december).apparent_longitude, 270, 0.01);

    /* March equinox 2024: 20 March 03:06 UT: apparent longitude 0 */
    double equinox = sun_julian_day(2024, 3, 20, 3 + 6.0 / 60);
    double longitude = sun_ephemeris_at(equinox).apparent_longitude;
    CHECK_ABS(longitude > 180 ? longitude - 360 : longitude, 0, 0.01);
    CHECK_ABS(sun_ephemeris_at(equinox).declination, 0, 0.005);

    /* solar noon at (0, 0) on the equinox day: the sun in the zenith within that day's
     * declination (0.15 degree nine hours after the equinox), refraction 0 above 85 */
    double e = sun_ephemeris_at(sun_julian_day(2024, 3, 20, 12)).equation_of_time;
    double azimuth, elevation;
    rad_error error;
    CHECK(sun_at(0, 0, 2024, 3, 20, 12 - e / 60, 0, &azimuth, &elevation, &error) == RAD_OK);
    CHECK_ABS(elevation, 90, 0.25);

    /* at the north pole the sun's elevation is its declination (plus refraction) at any
     * hour: 23.44 + 58.1"/tan(23.44) - ... = 23.44 + 0.037 degrees on the solstice */
    for (double hour = 0; hour <= 24; hour += 3) {
        CHECK(sun_at(90, 0, 2024, 6, 20, hour, 0, &azimuth, &elevation, &error) == RAD_OK);
        CHECK_ABS(elevation, 23.44 + 0.037, 0.05);
    }
}

static void test_noon_geometry(void)
{
    /* at local solar noon the sun is due south from northern mid-latitudes and due north
     * from southern ones, at elevation 90 - |latitude - declination| */
    const double latitudes[] = {51.5, 40, 23, -33.9, -45};
    for (int i = 0; i < 5; i++) {
        double longitude = 15 * (i - 2) + 7.5; /* off the zone's meridian on purpose */
        double offset = i - 2;
        double jd_noon = sun_julian_day(2024, 8, 14, 12 - longitude / 15);
        sun_ephemeris sun = sun_ephemeris_at(jd_noon);
        double local_noon = 12 - longitude / 15 + offset - sun.equation_of_time / 60;
        double azimuth, elevation;
        rad_error error;
        CHECK(sun_at(latitudes[i], longitude, 2024, 8, 14, local_noon, offset, &azimuth,
                     &elevation, &error) == RAD_OK);
        double geometric = 90 - fabs(latitudes[i] - sun.declination);
        CHECK_ABS(elevation, geometric + sun_refraction_degrees(geometric), 0.01);
        if (latitudes[i] > sun.declination)
            CHECK_ABS(azimuth, 180, 0.05);
        else
            CHECK(azimuth < 0.05 || azimuth > 359.95);
    }
}

static void test_nrel_example(void)
{
    /* Reda and Andreas, "Solar Position Algorithm for Solar Radiation Applications",
     * NREL/TP-560-34302 (2004), the example of its appendix: 2003 October 17, 12:30:30
     * local time, UTC-7, latitude 39.742476, longitude -105.1786: topocentric zenith
     * 50.11162 and azimuth 194.34024 degrees. SPA refracts for 820 mbar and 11 C (0.0037
     * degree less than NOAA's standard atmosphere here) and adds parallax (0.0016): NOAA
     * agrees within about 0.01 degree */
    double azimuth, elevation;
    rad_error error;
    CHECK(sun_at(39.742476, -105.1786, 2003, 10, 17, 12 + 30.5 / 60, -7, &azimuth, &elevation,
                 &error) == RAD_OK);
    CHECK_ABS(90 - elevation, 50.11162, 0.01);
    CHECK_ABS(azimuth, 194.34024, 0.01);

    /* morning and evening: east of south before noon, west after, mirror images about
     * solar noon within the declination's change */
    double morning_azimuth, morning_elevation, evening_azimuth, evening_elevation;
    CHECK(sun_at(39.742476, -105.1786, 2003, 10, 17, 8, -7, &morning_azimuth,
                 &morning_elevation, &error) == RAD_OK);
    CHECK(sun_at(39.742476, -105.1786, 2003, 10, 17, 17, -7, &evening_azimuth,
                 &evening_elevation, &error) == RAD_OK);
    CHECK(morning_azimuth > 90 && morning_azimuth < 180);
    CHECK(evening_azimuth > 180 && evening_azimuth < 270);
}

static void test_refraction(void)
{
    /* the spreadsheet's pieces meet within 2" (1.7" at 5 degrees), and it is about 58.1"
     * / tan h high up (Saemundsson and Bennett agree within 1" above 15 degrees) */
    CHECK_ABS(sun_refraction_degrees(5 + 1e-9), sun_refraction_degrees(5 - 1e-9), 2.0 / 3600);
    CHECK_ABS(sun_refraction_degrees(-0.575 + 1e-9), sun_refraction_degrees(-0.575 - 1e-9),
              2e-4);
    CHECK_ABS(sun_refraction_degrees(45), 58.1 / 3600, 1.0 / 3600);
    CHECK_ABS(sun_refraction_degrees(0), 1735.0 / 3600, 1e-12);
    CHECK(sun_refraction_degrees(86) == 0);
}

static void test_sun_refusals(void)
{
    struct {
        rad_place_time when;
        const char *names;
    } bad[] = {
        {{91, 0, 2024, 6, 1, 12, 0}, "latitude 91"},
        {{NAN, 0, 2024, 6, 1, 12, 0}, "latitude nan"},
        {{0, -181, 2024, 6, 1, 12, 0}, "longitude -181"},
        {{0, 0, 1899, 6, 1, 12, 0}, "year 1899"},
        {{0, 0, 2201, 6, 1, 12, 0}, "year 2201"},
        {{0, 0, 2024, 13, 1, 12, 0}, "month 13"},
        {{0, 0, 2024, 0, 1, 12, 0}, "month 0"},
        {{0, 0, 2023, 2, 29, 12, 0}, "day 29"},
        {{0, 0, 2100, 2, 29, 12, 0}, "day 29"},
        {{0, 0, 2024, 4, 31, 12, 0}, "day 31"},
        {{0, 0, 2024, 4, 0, 12, 0}, "day 0"},
        {{0, 0, 2024, 4, 1, 24.5, 0}, "hour 24.5"},
        {{0, 0, 2024, 4, 1, -1, 0}, "hour -1"},
        {{0, 0, 2024, 4, 1, 12, 14.5}, "offset 14.5"},
    };
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        rad_error error = {0};
        double azimuth = -1, elevation = -1;
        CHECK(rad_sun_position(&bad[i].when, &azimuth, &elevation, &error) ==
              RAD_ERR_INVALID);
        CHECK(error.status == RAD_ERR_INVALID);
        if (!strstr(error.message, bad[i].names))
            test_fail(__FILE__, __LINE__, "'%s' does not name '%s'", error.message,
                      bad[i].names);
    }
    /* the valid edges */
    double azimuth, elevation;
    rad_error error;
    CHECK(sun_at(0, 0, 2000, 2, 29, 24, 14, &azimuth, &elevation, &error) == RAD_OK);
    CHECK(sun_at(-90, 180, 2024, 2, 29, 0, -14, &azimuth, &elevation, &error) == RAD_OK);
    CHECK(isfinite(azimuth) && isfinite(elevation) && azimuth >= 0 && azimuth < 360);
    CHECK(rad_sun_position(NULL, &azimuth, &elevation, &error) == RAD_ERR_INVALID);
}

static void test_sky_integrals(void)
{
    /* the quadrature against the closed forms: a uniform sky pi, the overcast one
     * 7 pi / 9 (pi/3 + (2/3)(2 pi/3)), for any sun */
    const double suns[] = {-0.2, 0, 0.05, 0.5, 1.0, pi / 2};
    for (int i = 0; i < 6; i++) {
        CHECK_NEAR(sky_horizontal_illuminance_quadrature(RAD_SKY_UNIFORM, suns[i]), pi, 1e-9);
        CHECK_NEAR(sky_horizontal_illuminance_quadrature(RAD_SKY_CIE_OVERCAST, suns[i]),
                   7 * pi / 9, 1e-9);
    }
    CHECK_NEAR(sky_horizontal_illuminance_factor(RAD_SKY_UNIFORM, 0.3), pi, 1e-15);
    CHECK_NEAR(sky_horizontal_illuminance_factor(RAD_SKY_CIE_OVERCAST, 0.3), 7 * pi / 9, 1e-15);
    CHECK(sky_horizontal_illuminance_factor((rad_sky_model)99, 0.3) == 0);

    /* the clear sky against an independent integration: the midpoint rule in (elevation,
     * azimuth) on n x 2n and 2n x 4n cells, Richardson-extrapolated (error order 2) */
    const double clear_suns[] = {0.1, 0.6, 1.3};
    for (int s = 0; s < 3; s++) {
        double sun = clear_suns[s], estimate[2];
        for (int level = 0; level < 2; level++) {
            int n = 600 << level;
            double dh = (pi / 2) / n, da = 2 * pi / (2 * n), sum = 0;
            for (int i = 0; i < n; i++) {
                double h = (i + 0.5) * dh;
                for (int j = 0; j < 2 * n; j++) {
                    double a = -pi + (j + 0.5) * da;
                    double cos_chi = sin(h) * sin(sun) + cos(h) * cos(sun) * cos(a);
                    double chi = acos(fmax(-1, fmin(1, cos_chi)));
                    sum += rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, h, chi, sun) *
                           sin(h) * cos(h);
                }
            }
            estimate[level] = sum * dh * da;
        }
        double reference = (4 * estimate[1] - estimate[0]) / 3;
        CHECK_NEAR(sky_horizontal_illuminance_factor(RAD_SKY_CIE_CLEAR, sun), reference, 1e-6);
    }
}

static void test_sky_luminance(void)
{
    /* overcast: 1/3 at the horizon, 1 at the zenith; nothing below the horizon */
    CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_OVERCAST, 0, 0, 0), 1.0 / 3, 1e-15);
    CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_OVERCAST, pi / 2, 0, 0), 1, 1e-15);
    CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_OVERCAST, pi / 6, 0, 0), 2.0 / 3, 1e-15);
    CHECK(rad_sky_relative_luminance(RAD_SKY_CIE_OVERCAST, -0.01, 0, 0) == 0);
    CHECK(rad_sky_relative_luminance(RAD_SKY_UNIFORM, -0.01, 0, 0) == 0);
    CHECK(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, -0.01, 0.3, 0.3) == 0);
    CHECK(rad_sky_relative_luminance(RAD_SKY_UNIFORM, 0.2, 0, 0) == 1);
    CHECK(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, NAN, 0.3, 0.3) == 0);
    CHECK(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, 0.3, NAN, 0.3) == 0);

    /* clear: 1 at the zenith whatever the sun's height */
    for (double sun = 0; sun <= pi / 2; sun += 0.1)
        CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, pi / 2, pi / 2 - sun, sun), 1,
                   1e-12);

    /* the CIE S 011 formula worked by hand (a = -1, b = -0.32, c = 10, d = -3, e = 0.45):
     * sun 30 degrees high; a direction 45 degrees high 90 degrees round from it
     * (chi = 1.2094292 rad): f = 1.2320, phi = 0.3640; f(Z_s) = 1.4548, phi(0) = 0.2739:
     * 1.1256362; and 10 degrees high opposite the sun (chi = 140 degrees): 2.4944435 */
    double chi = acos(sin(45 * degree) * sin(30 * degree));
    CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, 45 * degree, chi, 30 * degree),
               1.1256362392620811, 1e-9);
    CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, 10 * degree, 140 * degree,
                                          30 * degree),
               2.4944434588774915, 1e-9);

    /* brightest at the sun, symmetric about the sun's vertical plane (directions built
     * from angles, chi from their dot product) */
    rad_vec3 up = {0, 0, 1}, north = {0, 1, 0};
    const double sun_heights[] = {10, 30, 60};
    for (int s = 0; s < 3; s++) {
        double sun_h = sun_heights[s] * degree, sun_azimuth = 2.0;
        rad_vec3 sun = sky_direction(sun_azimuth, sun_h, up, north);
        double best = -1, best_h = 0, best_a = 0;
        for (int i = 0; i <= 90; i++)
            for (int j = 0; j < 360; j++) {
                double h = i * degree, a = sun_azimuth + j * degree;
                rad_vec3 d = sky_direction(a, h, up, north);
                double gamma = acos(fmax(-1, fmin(1, v3_dot(d, sun))));
                double l = rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, h, gamma, sun_h);
                if (l > best) {
                    best = l;
                    best_h = h;
                    best_a = j * degree;
                }
                rad_vec3 mirror = sky_direction(sun_azimuth - j * degree, h, up, north);
                double mirror_gamma = acos(fmax(-1, fmin(1, v3_dot(mirror, sun))));
                CHECK_NEAR(rad_sky_relative_luminance(RAD_SKY_CIE_CLEAR, h, mirror_gamma,
                                                      sun_h),
                           l, 1e-9);
            }
        CHECK_ABS(best_h, sun_h, 1 * degree);
        CHECK(best_a <= 1 * degree || best_a >= 359 * degree);
    }
}

/* A 2:1 map whose pixels hold their own centre's (azimuth, elevation), by the convention
 * of the brief: column x at 2 pi ((x + 0.5) / W - 0.5), row y at pi (0.5 - (y + 0.5) / H). */
static rad_image *angle_map(uint32_t height)
{
    rad_image *map = test_new_image(2 * height, height);
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < 2 * height; x++)
            test_set_pixel(map, x, y, 2 * pi * ((x + 0.5) / (2 * height) - 0.5),
                           pi * (0.5 - (y + 0.5) / height), 1);
    return map;
}

static void test_environment(void)
{
    const uint32_t height = 16, width = 32;
    rad_image *map = angle_map(height);

    /* the pixel centres give back their own angles, also a turn away in azimuth */
    for (uint32_t y = 0; y < height; y++)
        for (uint32_t x = 0; x < width; x++) {
            double a = 2 * pi * ((x + 0.5) / width - 0.5), h = pi * (0.5 - (y + 0.5) / height);
            for (int turn = -1; turn <= 1; turn++) {
                rad_rgb c = environment_radiance(map, a + 2 * pi * turn, h);
                CHECK_ABS(c.r, a, 1e-6);
                CHECK_ABS(c.g, h, 1e-6);
                CHECK_ABS(c.b, 1, 1e-6);
            }
        }
    /* bilinear between centres: the angles are linear in x and y away from the seam */
    rad_rgb c = environment_radiance(map, 0.3, 0.2);
    CHECK_ABS(c.r, 0.3, 1e-6);
    CHECK_ABS(c.g, 0.2, 1e-6);
    /* clamped beyond the first and last rows' centres: the poles read rows 0 and H-1 */
    CHECK_ABS(environment_radiance(map, 0.3, pi / 2).g, pi * (0.5 - 0.5 / height), 1e-6);
    CHECK_ABS(environment_radiance(map, 0.3, -pi / 2).g, -pi * (0.5 - 0.5 / height), 1e-6);
    CHECK_ABS(environment_radiance(map, 0.3, 7.0).g, pi * (0.5 - 0.5 / height), 1e-6);
    rad_rgb nothing = environment_radiance(map, NAN, 0);
    CHECK(nothing.r == 0 && nothing.g == 0 && nothing.b == 0);
    rad_image_destroy(map);

    /* the seam: azimuth pi lies halfway between the last column and the first */
    rad_image *seam = test_new_image(width, height);
    for (uint32_t y = 0; y < height; y++) {
        test_set_pixel(seam, 0, y, 1, 1, 1);
        test_set_pixel(seam, width - 1, y, 3, 3, 3);
    }
    CHECK_ABS(environment_radiance(seam, pi, 0.1).r, 2, 1e-6);
    CHECK_ABS(environment_radiance(seam, -pi, 0.1).g, 2, 1e-6);
    CHECK_ABS(environment_radiance(seam, pi - pi / width, 0.1).b, 3, 1e-6);
    CHECK_ABS(environment_radiance(seam, -pi + pi / width, 0.1).b, 1, 1e-6);
    rad_image_destroy(seam);
}

static void test_sky_angles(void)
{
    /* a y-up scene: north -z, east = north x up = +x */
    rad_vec3 up = {0, 1, 0}, north = {0, 0, -1};
    double a, h;
    sky_angles((rad_vec3){0, 0, -1}, up, north, 0, &a, &h); /* north */
    CHECK_ABS(a, 0, 1e-12);
    CHECK_ABS(h, 0, 1e-12);
    sky_angles((rad_vec3){1, 0, 0}, up, north, 0, &a, &h); /* east */
    CHECK_ABS(a, pi / 2, 1e-12);
    sky_angles((rad_vec3){0, 0, 1}, up, north, 0, &a, &h); /* south */
    CHECK_ABS(a, pi, 1e-12);
    sky_angles((rad_vec3){-1, 0, 0}, up, north, 0, &a, &h); /* west */
    CHECK_ABS(a, 3 * pi / 2, 1e-12);
    sky_angles((rad_vec3){0, 5, 0}, up, north, 0, &a, &h); /* up, any length */
    CHECK_ABS(h, pi / 2, 1e-12);
    sky_angles((rad_vec3){0, -1, 0}, up, north, 0, &a, &h);
    CHECK_ABS(h, -pi / 2, 1e-12);
    sky_angles((rad_vec3){1, 1, 0}, up, north, 0, &a, &h);
    CHECK_ABS(h, pi / 4, 1e-12);

    /* rotated by 90 degrees, the map's north is seen in the east */
    sky_angles((rad_vec3){1, 0, 0}, up, north, 90, &a, &h);
    CHECK_ABS(a, 0, 1e-12);
    sky_angles((rad_vec3){0, 0, -1}, up, north, 90, &a, &h);
    CHECK_ABS(a, 3 * pi / 2, 1e-12);

    /* through a map: north is the middle column, east a quarter further right, up the top
     * row, down the bottom one */
    rad_image *map = angle_map(16);
    sky_angles((rad_vec3){0, 0, -1}, up, north, 0, &a, &h);
    CHECK_ABS(environment_radiance(map, a, h).r, 0, 1e-6);
    sky_angles((rad_vec3){1, 0.0, 0}, up, north, 0, &a, &h);
    CHECK_ABS(environment_radiance(map, a, h).r, pi / 2, 1e-6);
    sky_angles((rad_vec3){-1, 0.0, 0}, up, north, 0, &a, &h);
    CHECK_ABS(environment_radiance(map, a, h).r, -pi / 2, 1e-6);
    sky_angles((rad_vec3){0, 1, 0}, up, north, 0, &a, &h);
    CHECK_ABS(environment_radiance(map, a, h).g, pi * (0.5 - 0.5 / 16), 1e-6);
    sky_angles((rad_vec3){0, -1, 0}, up, north, 0, &a, &h);
    CHECK_ABS(environment_radiance(map, a, h).g, -pi * (0.5 - 0.5 / 16), 1e-6);
    rad_image_destroy(map);

    /* sky_direction inverts sky_angles, in a z-up frame and in a tilted one */
    rad_vec3 frames[2][2] = {{{0, 0, 1}, {0, 1, 0}},
                             {v3_normalize(v3(1, 2, 3)), v3_normalize(v3(3, 0, -1))}};
    rad_rng rng = rad_rng_seed(7, 11, 13);
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < 1000; k++) {
            rad_vec3 d;
            do {
                d = v3((rad_rng_next(&rng) >> 11) * 0x1p-52 - 1,
                       (rad_rng_next(&rng) >> 11) * 0x1p-52 - 1,
                       (rad_rng_next(&rng) >> 11) * 0x1p-52 - 1);
            } while (v3_length(d) < 0.1 || v3_length(d) > 1);
            d = v3_normalize(d);
            sky_angles(d, frames[f][0], frames[f][1], 0, &a, &h);
            CHECK(a >= 0 && a < 2 * pi && h >= -pi / 2 && h <= pi / 2);
            rad_vec3 back = sky_direction(a, h, frames[f][0], frames[f][1]);
            CHECK_ABS(v3_length(v3_sub(back, d)), 0, 1e-12);
            double a2, h2;
            sky_angles(back, frames[f][0], frames[f][1], 0, &a2, &h2);
            CHECK_ABS(h2, h, 1e-12);
        }
}

int main(void)
{
    test_julian_day();
    test_meeus_example();
    test_equation_of_time_extremes();
    test_solstices_and_equinox();
    test_noon_geometry();
    test_nrel_example();
    test_refraction();
    test_sun_refusals();
    test_sky_integrals();
    test_sky_luminance();
    test_environment();
    test_sky_angles();
    return test_finish("test_sun_sky");
}
