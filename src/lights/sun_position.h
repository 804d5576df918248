/*
 * sun_position.h - the steps of NOAA's solar position algorithm (internal), exposed so the
 * tests can check them against Meeus's worked examples; rad_sun_position (radiosity.h)
 * strings them together for a place and time.
 *
 * Angles in degrees, times in minutes, as in NOAA's Solar Calculator spreadsheet.
 */
#ifndef RAD_LIGHTS_SUN_POSITION_H
#define RAD_LIGHTS_SUN_POSITION_H

/* The Julian day of a Gregorian calendar date at `hour_ut` hours (Universal Time), by
 * Meeus, "Astronomical Algorithms" (2nd ed.), formula 7.1: 2000 January 1, 12h is 2451545.0.
 * For dates from 1582 October 15 on; month 1..12. */
double sun_julian_day(int year, int month, int day, double hour_ut);

/* Where the sun is on the celestial sphere at a Julian day (NOAA's spreadsheet, Meeus
 * chapters 25 and 28, the "low accuracy" series: about 0.01 degree). */
typedef struct sun_ephemeris {
    double true_longitude;       /* degrees, geometric, mean equinox of the date */
    double apparent_longitude;   /* degrees, nutation and aberration included */
    double obliquity;            /* degrees, the corrected obliquity of the ecliptic */
    double declination;          /* degrees, apparent */
    double radius_au;            /* the distance to the sun, astronomical units */
    double equation_of_time;     /* minutes, apparent minus mean solar time */
} sun_ephemeris;

sun_ephemeris sun_ephemeris_at(double julian_day);

/* The spreadsheet's atmospheric refraction correction (degrees) for a geometric elevation
 * in degrees: 0 above 85 degrees, a series in tan(h) above 5 degrees, a polynomial down to
 * -0.575 degrees, -20.772" / tan(h) below (the spreadsheet's fit for a standard
 * atmosphere; about 0.48 degree at the horizon). */
double sun_refraction_degrees(double elevation_degrees);

#endif
