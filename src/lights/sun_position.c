/*
 * sun_position.c - where the sun is seen from a place at a local date and time: NOAA's
 * solar position algorithm, the one of NOAA's Solar Calculator spreadsheet (after Meeus,
 * "Astronomical Algorithms", 2nd ed., chapters 7, 22, 25 and 28).
 *
 * The one idea: the sun's apparent ecliptic longitude and the obliquity give its
 * declination and the equation of time; the true solar time then gives the hour angle,
 * and the place's latitude turns (declination, hour angle) into elevation and azimuth. Time
 * is UT throughout (the spreadsheet ignores Delta T, some 70 s today: 0.001 degree of the
 * sun's longitude). Accuracy: about 0.01 degree for years 1900..2100, worse far from 2000.
 */
#include "lights/sun_position.h"

#include <math.h>
#include <stdbool.h>

#include "core/error.h"
#include "radiosity.h"

#define DEGREES (180.0 / 3.14159265358979323846)
#define RADIANS (3.14159265358979323846 / 180.0)

/* x modulo m in [0, m). */
static double wrap(double x, double m)
{
    double r = fmod(x, m);
    return r < 0 ? r + m : r;
}

double sun_julian_day(int year, int month, int day, double hour_ut)
{
    /* Meeus 7.1: January and February count as months 13 and 14 of the previous year;
     * B is the Gregorian calendar's correction */
    double y = year, m = month;
    if (month <= 2) {
        y -= 1;
        m += 12;
    }
    double a = floor(y / 100);
    double b = 2 - a + floor(a / 4);
    return floor(365.25 * (y + 4716)) + floor(30.6001 * (m + 1)) + day + b - 1524.5 +
           hour_ut / 24;
}

sun_ephemeris sun_ephemeris_at(double julian_day)
{
    /* Julian centuries from J2000.0 */
    double t = (julian_day - 2451545.0) / 36525;

    /* Meeus 25.2-25.4: geometric mean longitude, mean anomaly, eccentricity */
    double mean_longitude = wrap(280.46646 + t * (36000.76983 + t * 0.0003032), 360);
    double mean_anomaly = 357.52911 + t * (35999.05029 - 0.0001537 * t);
    double e = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    double m = mean_anomaly * RADIANS;

    /* the equation of centre, then the true longitude and anomaly (Meeus ch. 25) */
    double centre = sin(m) * (1.914602 - t * (0.004817 + 0.000014 * t)) +
                    sin(2 * m) * (0.019993 - 0.000101 * t) + sin(3 * m) * 0.000289;
    double true_longitude = mean_longitude + centre;
    double true_anomaly = (mean_anomaly + centre) * RADIANS;
    double radius = 1.000001018 * (1 - e * e) / (1 + e * cos(true_anomaly));

    /* nutation and aberration through the longitude of the Moon's ascending node */
    double node = (125.04 - 1934.136 * t) * RADIANS;
    double apparent_longitude = true_longitude - 0.00569 - 0.00478 * sin(node);

    /* Meeus 22.2, the mean obliquity (arcseconds after 23 deg 26'), and its correction */
    double mean_obliquity = 23 + (26 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) /
                                           60) / 60;
    double obliquity = mean_obliquity + 0.00256 * cos(node);

    double lambda = apparent_longitude * RADIANS, epsilon = obliquity * RADIANS;
    double declination = asin(sin(epsilon) * sin(lambda)) * DEGREES;

    /* Meeus 28.3 (after Smart): the equation of time in radians, times 4 minutes/degree */
    double y = tan(epsilon / 2) * tan(epsilon / 2);
    double l0 = mean_longitude * RADIANS;
    double equation = y * sin(2 * l0) - 2 * e * sin(m) + 4 * e * y * sin(m) * cos(2 * l0) -
                      0.5 * y * y * sin(4 * l0) - 1.25 * e * e * sin(2 * m);

    return (sun_ephemeris){.true_longitude = wrap(true_longitude, 360),
                           .apparent_longitude = wrap(apparent_longitude, 360),
                           .obliquity = obliquity,
                           .declination = declination,
                           .radius_au = radius,
                           .equation_of_time = 4 * equation * DEGREES};
}

double sun_refraction_degrees(double h)
{
    double arcseconds;
    if (h > 85) {
        arcseconds = 0;
    } else if (h > 5) {
        double t = tan(h * RADIANS);
        arcseconds = 58.1 / t - 0.07 / (t * t * t) + 0.000086 / (t * t * t * t * t);
    } else if (h > -0.575) {
        arcseconds = 1735 + h * (-518.2 + h * (103.4 + h * (-12.79 + h * 0.711)));
    } else {
        arcseconds = -20.772 / tan(h * RADIANS);
    }
    return arcseconds / 3600;
}

static bool is_leap_year(int year)
{
    return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
}

static int days_in_month(int year, int month)
{
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return month == 2 && is_leap_year(year) ? 29 : days[month - 1];
}

/* Each field in its range (NaN fails every comparison, so it is refused too). */
static rad_status check_place_time(const rad_place_time *when, rad_error *error)
{
    if (!when)
        return rad_fail(error, RAD_ERR_INVALID, "sun position: no place and time given");
    if (!(when->latitude >= -90 && when->latitude <= 90))
        return rad_fail(error, RAD_ERR_INVALID,
                        "sun position: latitude %g outside [-90, 90] degrees", when->latitude);
    if (!(when->longitude >= -180 && when->longitude <= 180))
        return rad_fail(error, RAD_ERR_INVALID,
                        "sun position: longitude %g outside [-180, 180] degrees",
                        when->longitude);
    if (when->year < 1900 || when->year > 2200)
        return rad_fail(error, RAD_ERR_INVALID, "sun position: year %d outside 1900..2200",
                        when->year);
    if (when->month < 1 || when->month > 12)
        return rad_fail(error, RAD_ERR_INVALID, "sun position: month %d outside 1..12",
                        when->month);
    int last_day = days_in_month(when->year, when->month);
    if (when->day < 1 || when->day > last_day)
        return rad_fail(error, RAD_ERR_INVALID,
                        "sun position: day %d outside 1..%d for month %d of %d", when->day,
                        last_day, when->month, when->year);
    if (!(when->hour >= 0 && when->hour <= 24))
        return rad_fail(error, RAD_ERR_INVALID, "sun position: hour %g outside [0, 24]",
                        when->hour);
    if (!(when->utc_offset_hours >= -14 && when->utc_offset_hours <= 14))
        return rad_fail(error, RAD_ERR_INVALID,
                        "sun position: UTC offset %g outside [-14, 14] hours",
                        when->utc_offset_hours);
    return RAD_OK;
}

rad_status rad_sun_position(const rad_place_time *when, double *azimuth_degrees,
                            double *elevation_degrees, rad_error *error)
{
    rad_status status = check_place_time(when, error);
    if (status != RAD_OK)
        return status;

    double jd = sun_julian_day(when->year, when->month, when->day,
                               when->hour - when->utc_offset_hours);
    sun_ephemeris sun = sun_ephemeris_at(jd);

    /* true solar time (minutes) and the hour angle: 0 at solar noon, positive afternoon */
    double solar_minutes = wrap(when->hour * 60 + sun.equation_of_time +
                                    4 * when->longitude - 60 * when->utc_offset_hours,
                                1440);
    double hour_angle = (solar_minutes / 4 - 180) * RADIANS;

    /* The sun's direction in the local frame (east, north, up). The spreadsheet's
     * zenith = acos(sin phi sin delta + cos phi cos delta cos H) and its azimuth by acos
     * are the same angles; atan2 stays exact at the poles (cos phi = 0) and near the
     * zenith, where the acos form divides by zero. */
    double phi = when->latitude * RADIANS, delta = sun.declination * RADIANS;
    double east = -cos(delta) * sin(hour_angle);
    double north = sin(delta) * cos(phi) - cos(delta) * cos(hour_angle) * sin(phi);
    double up = sin(delta) * sin(phi) + cos(delta) * cos(hour_angle) * cos(phi);

    double elevation = atan2(up, hypot(east, north)) * DEGREES;
    double azimuth = wrap(atan2(east, north) * DEGREES, 360);
    if (azimuth_degrees)
        *azimuth_degrees = azimuth;
    if (elevation_degrees)
        *elevation_degrees = elevation + sun_refraction_degrees(elevation);
    return RAD_OK;
}
