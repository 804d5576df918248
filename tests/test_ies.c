/*
 * test_ies.c - the IES LM-63 reader (rad_photometry_read) and the candela look-up
 * (rad_photometry_candela), on files written here with known tables: an isotropic web, a
 * cosine downlight, each symmetric variant of the horizontal angles with an asymmetric
 * table (mirrored look-ups, the flux against a quadrature of the look-up), the multiplier
 * and ballast factors, the 1986 to 2019 headers, TILT=INCLUDE and TILT=<file>, commas and
 * numbers spread over lines, types A and B, a manufacturer-like 2002 file, every malformed
 * case refused with the file and the line, and allocation failures.
 */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "testlib.h"

#define PI 3.14159265358979323846

/* ------------------------------------------------------------------------------------ */
/* Helpers                                                                              */

/* The warnings of one read. */
typedef struct warnings {
    int count;
    char last[RAD_ERROR_MESSAGE_MAX];
} warnings;

static void collect(void *user, const char *message)
{
    warnings *w = user;
    w->count++;
    snprintf(w->last, sizeof(w->last), "%s", message);
    if (strchr(message, '\n'))
        test_fail(__FILE__, __LINE__, "a warning of more than one line: %s", message);
}

/* A growing string. */
typedef struct text {
    char *s;
    size_t length, capacity;
} text;

__attribute__((format(printf, 2, 3))) static void add(text *t, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    int n = vsnprintf(NULL, 0, format, args);
    va_end(args);
    if (n < 0)
        exit(1);
    if (t->length + (size_t)n + 1 > t->capacity) {
        size_t capacity = 2 * (t->length + (size_t)n + 1);
        char *bigger = realloc(t->s, capacity);
        if (!bigger)
            exit(1);
        t->s = bigger;
        t->capacity = capacity;
    }
    va_start(args, format);
    vsnprintf(t->s + t->length, t->capacity - t->length, format, args);
    va_end(args);
    t->length += (size_t)n;
}

/* Reads `path`, which must load; NULL (a failure recorded) when it does not. */
static rad_photometry *read_ok(const char *path, warnings *w)
{
    rad_photometry *ph = NULL;
    rad_error error = {0};
    if (w)
        memset(w, 0, sizeof(*w));
    rad_status status = rad_photometry_read(path, w ? collect : NULL, w, &ph, &error);
    if (status != RAD_OK)
        fprintf(stderr, "unexpected refusal: %s\n", error.message);
    CHECK(status == RAD_OK);
    CHECK((status == RAD_OK) == (ph != NULL));
    return ph;
}

static rad_photometry *write_and_read(const char *name, const char *content, warnings *w)
{
    return read_ok(test_write_file(name, content), w);
}

/* Writes `content` as `name`, reads it, and requires a refusal with `status` whose message
 * starts with "PATH:LINE: " (line 0: "PATH: ") and holds `fragment`. */
static void expect_refused_at(const char *name, const char *content, size_t size,
                              rad_status expected, unsigned line, const char *fragment)
{
    const char *path = test_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || (size && fwrite(content, 1, size, f) != size) || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    char start[4200];
    if (line)
        snprintf(start, sizeof(start), "%s:%u: ", path, line);
    else
        snprintf(start, sizeof(start), "%s: ", path);
    rad_photometry *ph = (rad_photometry *)1;
    rad_error error = {0};
    rad_status status = rad_photometry_read(path, NULL, NULL, &ph, &error);
    bool good = status == expected && error.status == expected && ph == NULL &&
                strncmp(error.message, start, strlen(start)) == 0 &&
                strstr(error.message, fragment) != NULL && !strchr(error.message, '\n');
    if (!good)
        fprintf(stderr, "[%s] status %s, message: %s (expected %s at line %u with '%s')\n", name,
                rad_status_name(status), error.message, rad_status_name(expected), line,
                fragment);
    CHECK(good);
    if (status == RAD_OK)
        rad_photometry_destroy(ph);
}

static void expect_refused(const char *name, const char *content, unsigned line,
                           const char *fragment)
{
    expect_refused_at(name, content, strlen(content), RAD_ERR_PARSE, line, fragment);
}

/* A web to write: the file's header line (NULL: 1986), its factors and its table. */
typedef struct web {
    const char *format_line;
    const char *tilt; /* the TILT line's value, and for INCLUDE the block after it */
    double multiplier, ballast, twelfth;
    unsigned type;
    unsigned nv, nh;
    const double *vertical, *horizontal;
    double (*candela)(double h, double v); /* the file's value */
} web;

/* The text of an IES file for w: numbers spread over short lines. */
static char *ies_text(const web *w)
{
    text t = {0};
    if (w->format_line)
        add(&t, "%s\n[TEST] test_ies\n[MANUFAC] nobody\n", w->format_line);
    else
        add(&t, "a 1986 header: free text\nanother line of it\n");
    add(&t, "TILT=%s\n", w->tilt ? w->tilt : "NONE");
    add(&t, "1 -1 %.17g %u %u %u 2 0.5 0.5 0.1\n", w->multiplier, w->nv, w->nh, w->type);
    add(&t, "%.17g %.17g 20\n", w->ballast, w->twelfth);
    for (unsigned k = 0; k < w->nv; k++)
        add(&t, "%.17g%s", w->vertical[k], k % 8 == 7 || k + 1 == w->nv ? "\n" : " ");
    for (unsigned j = 0; j < w->nh; j++)
        add(&t, "%.17g%s", w->horizontal[j], j % 8 == 7 || j + 1 == w->nh ? "\n" : " ");
    for (unsigned j = 0; j < w->nh; j++)
        for (unsigned k = 0; k < w->nv; k++)
            add(&t, "%.17g%s", w->candela(w->horizontal[j], w->vertical[k]),
                k % 8 == 7 || k + 1 == w->nv ? "\n" : " ");
    return t.s;
}

static rad_photometry *read_web(const char *name, const web *w, warnings *warned)
{
    char *content = ies_text(w);
    rad_photometry *ph = write_and_read(name, content, warned);
    free(content);
    return ph;
}

/* Evenly spaced angles first, first + step, ..., last. */
static unsigned spaced(double *angles, double first, double last, double step)
{
    unsigned n = (unsigned)lround((last - first) / step) + 1;
    for (unsigned k = 0; k < n; k++)
        angles[k] = first + step * k;
    return n;
}

/* The flux of the look-up by the midpoint rule: type C over the sphere (sin of the
 * vertical angle), types A and B over -90..90 x -90..90 (cos of the horizontal angle). */
static double quadrature(const rad_photometry *ph, int n)
{
    double sum = 0;
    if (ph->photometric_type == 1) {
        double dv = PI / n, dh = 2 * PI / (2 * n);
        for (int i = 0; i < n; i++) {
            double v = (i + 0.5) * 180.0 / n;
            for (int j = 0; j < 2 * n; j++) {
                double h = (j + 0.5) * 360.0 / (2 * n);
                sum += rad_photometry_candela(ph, v, h) * sin(v * PI / 180) * dv * dh;
            }
        }
    } else {
        double d = PI / n;
        for (int i = 0; i < n; i++) {
            double v = -90 + (i + 0.5) * 180.0 / n;
            for (int j = 0; j < n; j++) {
                double h = -90 + (j + 0.5) * 180.0 / n;
                sum += rad_photometry_candela(ph, v, h) * cos(h * PI / 180) * d * d;
            }
        }
    }
    return sum;
}

static double constant_100(double h, double v)
{
    (void)h;
    (void)v;
    return 100;
}

/* ------------------------------------------------------------------------------------ */
/* Known webs                                                                           */

static void test_isotropic(void)
{
    double v[13], h[1] = {0};
    web w = {"IESNA:LM-63-2002", NULL, 1, 1, 1, 1, 0, 1, v, h, constant_100};
    w.nv = spaced(v, 0, 180, 15);
    rad_photometry *ph = read_web("isotropic.ies", &w, NULL);
    if (!ph)
        return;
    CHECK(ph->photometric_type == 1 && ph->vertical_count == 13 && ph->horizontal_count == 1);
    CHECK(strstr(ph->source, "isotropic.ies") != NULL);
    CHECK_NEAR(ph->lumens, 4 * PI * 100, 1e-3);
    CHECK_NEAR(ph->lumens, 4 * PI * 100, 1e-12); /* exact for a piecewise linear web */
    const double angles[] = {0, 7.5, 15, 33.3, 90, 144.4, 179.9, 180};
    const double around[] = {0, 45, 90, 181, 359.9, -30, 720.5, 1e6};
    for (size_t a = 0; a < sizeof(angles) / sizeof(angles[0]); a++)
        for (size_t b = 0; b < sizeof(around) / sizeof(around[0]); b++)
            CHECK_NEAR(rad_photometry_candela(ph, angles[a], around[b]), 100, 1e-12);
    CHECK(rad_photometry_candela(ph, -0.1, 0) == 0);
    CHECK(rad_photometry_candela(ph, 180.1, 0) == 0);
    CHECK(rad_photometry_candela(ph, NAN, 0) == 0);
    CHECK(rad_photometry_candela(ph, 10, INFINITY) == 0);
    CHECK(rad_photometry_candela(NULL, 10, 0) == 0);
    rad_photometry_destroy(ph);
    rad_photometry_destroy(NULL);
}

static double cosine_1000(double h, double v)
{
    (void)h;
    return 1000 * cos(v * PI / 180);
}

static void test_cosine_downlight(void)
{
    double v[19], h[1] = {0};
    web w = {"IESNA:LM-63-1995", NULL, 1, 1, 1, 1, 0, 1, v, h, cosine_1000};
    w.nv = spaced(v, 0, 90, 5);
    rad_photometry *ph = read_web("cosine.ies", &w, NULL);
    if (!ph)
        return;
    CHECK_NEAR(ph->lumens, PI * 1000, 5e-3);
    /* linear interpolation of cos over 5 degrees: at most (5 deg)^2 / 8 = 0.00095 of I0 */
    double half_step = 0.5 * 5 * PI / 180;
    CHECK_ABS(rad_photometry_candela(ph, 37.5, 0), 1000 * cos(37.5 * PI / 180),
              1000 * half_step * half_step / 2);
    CHECK_ABS(rad_photometry_candela(ph, 37.5, 123), 1000 * cos(37.5 * PI / 180),
              1000 * half_step * half_step / 2);
    CHECK(rad_photometry_candela(ph, 37.5, 0) < 1000 * cos(37.5 * PI / 180)); /* a chord */
    CHECK_NEAR(rad_photometry_candela(ph, 35, 0), 1000 * cos(35 * PI / 180), 1e-12);
    CHECK_ABS(rad_photometry_candela(ph, 90, 0), 0, 1e-9);
    CHECK(rad_photometry_candela(ph, 95, 0) == 0); /* nothing above the horizontal */
    CHECK(rad_photometry_candela(ph, 135, 0) == 0);
    CHECK_NEAR(quadrature(ph, 720), ph->lumens, 1e-4);
    rad_photometry_destroy(ph);
}

/* An asymmetric table: it changes with both angles, and differently at 0 and 360. */
static double asymmetric(double h, double v)
{
    return 200 + 150 * sin(v * PI / 180) * (1 + h / 360) + 40 * cos(v * PI / 180) +
           0.3 * h;
}

static void test_symmetric_variants(void)
{
    static const struct {
        const char *name;
        double first, last, step;
    } variants[] = {
        {"quadrant.ies", 0, 90, 30},
        {"bilateral.ies", 0, 180, 45},
        {"bilateral_90_270.ies", 90, 270, 45},
        {"full.ies", 0, 360, 45},
    };
    const double probe_v[] = {0, 12.5, 45, 100, 167};
    for (size_t n = 0; n < sizeof(variants) / sizeof(variants[0]); n++) {
        double v[13], h[9];
        web w = {"IESNA:LM-63-2002", NULL, 1, 1, 1, 1, 0, 0, v, h, asymmetric};
        w.nv = spaced(v, 0, 180, 15);
        w.nh = spaced(h, variants[n].first, variants[n].last, variants[n].step);
        rad_photometry *ph = read_web(variants[n].name, &w, NULL);
        if (!ph)
            continue;
        /* the listed values, exactly */
        for (unsigned j = 0; j < w.nh; j++)
            for (unsigned k = 0; k < w.nv; k++)
                if (h[j] < 360)
                    CHECK(rad_photometry_candela(ph, v[k], h[j]) == asymmetric(h[j], v[k]));
        /* the middle of a cell: the mean of its corners */
        double middle = rad_photometry_candela(ph, 0.5 * (v[2] + v[3]), 0.5 * (h[1] + h[2]));
        double corners = 0.25 * (asymmetric(h[1], v[2]) + asymmetric(h[1], v[3]) +
                                 asymmetric(h[2], v[2]) + asymmetric(h[2], v[3]));
        CHECK_NEAR(middle, corners, 1e-12);
        for (size_t a = 0; a < sizeof(probe_v) / sizeof(probe_v[0]); a++) {
            double pv = probe_v[a];
            if (n == 0) { /* 0..90: the four quadrants alike */
                const double hs[] = {10, 37.5, 80};
                for (size_t b = 0; b < 3; b++) {
                    double c = rad_photometry_candela(ph, pv, hs[b]);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, -hs[b]), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 180 - hs[b]), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 180 + hs[b]), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 360 - hs[b]), c, 1e-12);
                }
            } else if (n == 1) { /* 0..180: mirrored about the 0-180 plane */
                const double hs[] = {10, 80, 100, 170};
                for (size_t b = 0; b < 4; b++) {
                    double c = rad_photometry_candela(ph, pv, hs[b]);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 360 - hs[b]), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, -hs[b]), c, 1e-12);
                }
            } else if (n == 2) { /* 90..270: mirrored about the 90-270 plane */
                const double hs[] = {100, 170, 200, 260};
                for (size_t b = 0; b < 4; b++) {
                    double c = rad_photometry_candela(ph, pv, hs[b]);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 180 - hs[b]), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, 540 - hs[b]), c, 1e-12);
                }
                CHECK_NEAR(rad_photometry_candela(ph, pv, 300), rad_photometry_candela(ph, pv, 240),
                           1e-12);
                CHECK_NEAR(rad_photometry_candela(ph, pv, 30), rad_photometry_candela(ph, pv, 150),
                           1e-12);
            } else { /* 0..360: wrapped, and not symmetric */
                const double hs[] = {10, 100, 200, 350};
                for (size_t b = 0; b < 4; b++) {
                    double c = rad_photometry_candela(ph, pv, hs[b]);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, hs[b] + 360), c, 1e-12);
                    CHECK_NEAR(rad_photometry_candela(ph, pv, hs[b] - 360), c, 1e-12);
                }
                if (pv > 0)
                    CHECK(fabs(rad_photometry_candela(ph, pv, 10) -
                               rad_photometry_candela(ph, pv, 350)) > 1);
                /* between 315 and 360: interpolated toward the 360 column */
                CHECK_NEAR(rad_photometry_candela(ph, 45, 337.5),
                           0.5 * (asymmetric(315, 45) + asymmetric(360, 45)), 1e-12);
            }
        }
        /* the flux: the look-up integrated over the whole sphere */
        CHECK_NEAR(ph->lumens, quadrature(ph, 720), 1e-4);
        rad_photometry_destroy(ph);

        /* an isotropic web in this variant: 4 pi I */
        w.candela = constant_100;
        ph = read_web(variants[n].name, &w, NULL);
        if (ph)
            CHECK_NEAR(ph->lumens, 4 * PI * 100, 1e-12);
        rad_photometry_destroy(ph);
    }
}

static void test_types_a_and_b(void)
{
    double v[7], h[4], one[1] = {0};
    /* type B, laterally symmetric (0..90) */
    web w = {"IESNA:LM-63-2002", NULL, 1, 1, 1, 2, 0, 0, v, h, asymmetric};
    w.nv = spaced(v, -90, 90, 30);
    w.nh = spaced(h, 0, 90, 30);
    rad_photometry *ph = read_web("type_b.ies", &w, NULL);
    if (ph) {
        CHECK(ph->photometric_type == 2);
        for (unsigned j = 0; j < w.nh; j++)
            for (unsigned k = 0; k < w.nv; k++)
                CHECK(rad_photometry_candela(ph, v[k], h[j]) == asymmetric(h[j], v[k]));
        CHECK_NEAR(rad_photometry_candela(ph, 20, -50), rad_photometry_candela(ph, 20, 50), 1e-12);
        CHECK(rad_photometry_candela(ph, 20, 95) == 0);
        CHECK(rad_photometry_candela(ph, 95, 20) == 0);
        CHECK(fabs(rad_photometry_candela(ph, -60, 20) - rad_photometry_candela(ph, 60, 20)) > 1);
        CHECK_NEAR(ph->lumens, quadrature(ph, 720), 1e-4);
    }
    rad_photometry_destroy(ph);
    /* type B over -90..90 and uniform: the front hemisphere, 2 pi I */
    double full[7];
    w.horizontal = full;
    w.nh = spaced(full, -90, 90, 30);
    w.candela = constant_100;
    ph = read_web("type_b_full.ies", &w, NULL);
    if (ph) {
        CHECK_NEAR(ph->lumens, 2 * PI * 100, 1e-12);
        CHECK_NEAR(rad_photometry_candela(ph, -45, -80), 100, 1e-12);
    }
    rad_photometry_destroy(ph);
    /* type A with a single horizontal angle and uniform: 2 pi I too */
    w.type = 3;
    w.horizontal = one;
    w.nh = 1;
    ph = read_web("type_a.ies", &w, NULL);
    if (ph) {
        CHECK(ph->photometric_type == 3);
        CHECK_NEAR(ph->lumens, 2 * PI * 100, 1e-12);
        CHECK_NEAR(rad_photometry_candela(ph, 10, -70), 100, 1e-12);
        CHECK_NEAR(quadrature(ph, 360), ph->lumens, 1e-4);
    }
    rad_photometry_destroy(ph);
}

/* ------------------------------------------------------------------------------------ */
/* Headers, factors, tilt, separators                                                   */

static double small_table(double h, double v) { return 10 + v + 0.1 * h; }

static void test_formats_and_factors(void)
{
    static const struct {
        const char *line; /* NULL: 1986 */
        bool twelfth_applied;
    } formats[] = {
        {NULL, true},
        {"IESNA91", true},
        {"IESNA:LM-63-1995", true},
        {"IESNA:LM-63-2002", false},
        {"IES:LM-63:2019", false},
    };
    double v[5] = {0, 22.5, 45, 67.5, 90}, h[3] = {0, 45, 90};
    for (size_t n = 0; n < sizeof(formats) / sizeof(formats[0]); n++) {
        web w = {formats[n].line, NULL, 2.5, 0.9, 0.8, 1, 5, 3, v, h, small_table};
        char name[64];
        snprintf(name, sizeof(name), "format_%zu.ies", n);
        warnings warned;
        rad_photometry *ph = read_web(name, &w, &warned);
        if (!ph)
            continue;
        CHECK(warned.count == 0);
        double factor = 2.5 * 0.9 * (formats[n].twelfth_applied ? 0.8 : 1);
        for (unsigned j = 0; j < 3; j++)
            for (unsigned k = 0; k < 5; k++)
                CHECK_NEAR(rad_photometry_candela(ph, v[k], h[j]), small_table(h[j], v[k]) * factor,
                           1e-12);
        /* the flux scales with the factors */
        web unit = w;
        unit.multiplier = unit.ballast = unit.twelfth = 1;
        snprintf(name, sizeof(name), "format_%zu_unit.ies", n);
        rad_photometry *plain = read_web(name, &unit, NULL);
        if (plain)
            CHECK_NEAR(ph->lumens, plain->lumens * factor, 1e-12);
        rad_photometry_destroy(plain);
        rad_photometry_destroy(ph);
    }
    /* an unknown IESNA line: read as 2002, with a warning */
    web w = {"IESNA:LM-63-2030", NULL, 1, 1, 0.5, 1, 5, 3, v, h, small_table};
    warnings warned;
    rad_photometry *ph = read_web("format_unknown.ies", &w, &warned);
    if (ph) {
        CHECK(warned.count == 1 && strstr(warned.last, "format_unknown.ies:1: unknown format"));
        CHECK_NEAR(rad_photometry_candela(ph, 45, 45), small_table(45, 45), 1e-12);
    }
    rad_photometry_destroy(ph);
}

static void test_tilt(void)
{
    double v[5] = {0, 22.5, 45, 67.5, 90}, h[3] = {0, 45, 90};
    web w = {"IESNA:LM-63-2002",
             "INCLUDE\n1\n7\n0 15 30 45\n60 75 90\n1.0 .95 .94 .90\n.88 .87 .94",
             1, 1, 1, 1, 5, 3, v, h, small_table};
    warnings warned;
    rad_photometry *ph = read_web("tilt_include.ies", &w, &warned);
    if (ph) {
        CHECK(warned.count == 1);
        CHECK(strstr(warned.last, "tilt_include.ies:4: TILT=INCLUDE") != NULL);
        CHECK(ph->vertical_count == 5 && ph->horizontal_count == 3);
        CHECK(rad_photometry_candela(ph, 45, 45) == small_table(45, 45)); /* not tilted */
    }
    rad_photometry_destroy(ph);
    w.tilt = "lamp_tilt.dat";
    ph = read_web("tilt_file.ies", &w, &warned);
    if (ph) {
        CHECK(warned.count == 1);
        CHECK(strstr(warned.last, "tilt_file.ies:4: TILT=lamp_tilt.dat: the tilt file is ignored"));
        CHECK(rad_photometry_candela(ph, 90, 90) == small_table(90, 90));
    }
    rad_photometry_destroy(ph);
    /* a 1986 file whose first line is TILT= (no header text at all), lower case */
    ph = write_and_read("tilt_first.ies",
                        "tilt = none\n1 -1 1 2 1 1 1 0 0 0 1 1 0\n0 90\n0\n5 6\n", &warned);
    if (ph) {
        CHECK(warned.count == 0);
        CHECK(rad_photometry_candela(ph, 90, 0) == 6 * 1.0);
    }
    rad_photometry_destroy(ph);
}

static void test_separators(void)
{
    /* commas, numbers split over lines anyhow, CR LF line ends, a byte order mark, tabs */
    const char *content = "\xEF\xBB\xBFIESNA:LM-63-2002\r\n"
                          "[TEST] commas\r\n"
                          "TILT=NONE\r\n"
                          "1,-1,2\r\n"
                          "3\r\n"
                          "2,1,2,0.1,0.2,0.0,1.0\t1.0\r\n"
                          "30\r\n"
                          "0,45\r\n"
                          ",90,0,\r\n"
                          "90\r\n"
                          "10, 20,\r\n"
                          "30\r\n"
                          "40,50,60\r\n";
    rad_photometry *ph = write_and_read("commas.ies", content, NULL);
    if (ph) {
        CHECK(ph->vertical_count == 3 && ph->horizontal_count == 2);
        CHECK(rad_photometry_candela(ph, 45, 0) == 40);
        CHECK(rad_photometry_candela(ph, 90, 90) == 120);
        CHECK(rad_photometry_candela(ph, 90, 270) == 120);
    }
    rad_photometry_destroy(ph);
    /* CR line ends only (an old Mac file), and its line numbers in a refusal */
    ph = write_and_read("cr.ies",
                        "IESNA91\r[TEST] cr\rTILT=NONE\r1 -1 1 2 1 1 1 0 0 0\r1 1 0\r0 90\r0\r"
                        "7 8\r",
                        NULL);
    if (ph)
        CHECK(rad_photometry_candela(ph, 0, 0) == 7);
    rad_photometry_destroy(ph);
    expect_refused("cr_bad.ies",
                   "IESNA91\r[TEST] cr\rTILT=NONE\r1 -1 1 2 1 1 1 0 0 0\r1 1 0\r0 90\r0\r7 x\r",
                   8, "'x' is not a number");
    /* text after the table: a warning naming its line */
    warnings warned;
    ph = write_and_read("trailing.ies",
                        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 1 0 0 0\n1 1 0\n0 90\n0\n7 8\n"
                        "\n\x1a\n",
                        &warned);
    if (ph)
        CHECK(warned.count == 1 && strstr(warned.last, "trailing.ies:9: text after the candela"));
    rad_photometry_destroy(ph);
}

/* ------------------------------------------------------------------------------------ */
/* A manufacturer's file                                                                */

static const char troffer_ies[] =
    "IESNA:LM-63-2002\n"
    "[TEST] 24561-LT\n"
    "[TESTLAB] PHOTOMETRIC TESTING LABORATORY\n"
    "[ISSUEDATE] 03-MAR-2021\n"
    "[MANUFAC] NORTHLIGHT LUMINAIRES\n"
    "[LUMCAT] NL-TRF22-40K-DIM\n"
    "[LUMINAIRE] 2X2 LED TROFFER, WHITE STEEL HOUSING, FROSTED ACRYLIC LENS\n"
    "[MORE] RECESSED IN A 24 INCH GRID CEILING\n"
    "[LAMPCAT] LED-3400-40K\n"
    "[LAMP] LED ARRAY, 4000K, CRI 82\n"
    "[BALLAST] 0-10V DIMMING DRIVER\n"
    "[BALLASTCAT] DRV-40W-010\n"
    "[OTHER] ABSOLUTE PHOTOMETRY: CANDELA VALUES FOR THE LUMINAIRE AS TESTED\n"
    "[SEARCH] TROFFER LED 2X2\n"
    "TILT=NONE\n"
    "1 -1 1.0 37 5 1 2 0.597 0.597 0.089\n"
    "1.0 1.0 32.5\n"
    "    0.0    5.0   10.0   15.0   20.0   25.0   30.0   35.0   40.0   45.0\n"
    "   50.0   55.0   60.0   65.0   70.0   75.0   80.0   85.0   90.0   95.0\n"
    "  100.0  105.0  110.0  115.0  120.0  125.0  130.0  135.0  140.0  145.0\n"
    "  150.0  155.0  160.0  165.0  170.0  175.0  180.0\n"
    "    0.0   22.5   45.0   67.5   90.0\n"
    " 1300.0 1300.2 1289.4 1267.6 1234.8 1191.3 1137.5 1073.8 1000.8  919.3\n"
    "  830.1  734.2  632.7  526.9  418.2  308.1  198.8   93.2    2.1    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    " 1300.0 1298.5 1286.1 1262.8 1228.7 1184.1 1129.4 1065.0  991.7  910.1\n"
    "  821.2  725.8  625.0  520.2  412.7  304.0  196.1   91.9    2.1    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    " 1300.0 1294.6 1278.3 1251.4 1214.0 1166.7 1109.8 1043.9  969.7  887.9\n"
    "  799.5  705.3  606.5  504.1  399.4  293.9  189.5   88.8    2.1    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    " 1300.0 1290.6 1270.4 1239.9 1199.3 1149.2 1090.1 1022.7  947.6  865.7\n"
    "  777.8  684.9  587.9  487.9  386.1  283.9  182.9   85.6    2.1    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    " 1300.0 1288.9 1267.2 1235.2 1193.3 1142.0 1082.0 1013.9  938.5  856.5\n"
    "  768.9  676.4  580.2  481.2  380.6  279.7  180.2   84.3    2.1    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n"
    "    0.0    0.0    0.0    0.0    0.0    0.0    0.0\n";

/* Its flux: the bilinear web integrated independently (2000 midpoints per 5 degrees in
 * the vertical angle, trapezoid in the horizontal one), lm. */
#define TROFFER_LUMENS 3890.124915466131

static void test_manufacturer_file(void)
{
    rad_photometry *ph = write_and_read("NL-TRF22-40K-DIM.ies", troffer_ies, NULL);
    if (!ph)
        return;
    CHECK(ph->photometric_type == 1);
    CHECK(ph->vertical_count == 37 && ph->horizontal_count == 5);
    CHECK(ph->vertical_degrees[36] == 180 && ph->horizontal_degrees[4] == 90);
    CHECK(rad_photometry_candela(ph, 0, 0) == 1300.0);
    CHECK(rad_photometry_candela(ph, 45, 0) == 919.3);
    CHECK(rad_photometry_candela(ph, 45, 90) == 856.5);
    CHECK(rad_photometry_candela(ph, 45, 270) == 856.5); /* the quadrant mirrored */
    CHECK(rad_photometry_candela(ph, 45, 180) == 919.3);
    CHECK_NEAR(rad_photometry_candela(ph, 42.5, 11.25),
               0.25 * (1000.8 + 919.3 + 991.7 + 910.1), 1e-12);
    CHECK(rad_photometry_candela(ph, 90, 45) == 2.1);
    CHECK(rad_photometry_candela(ph, 120, 10) == 0);
    CHECK_NEAR(ph->lumens, TROFFER_LUMENS, 1e-8);
    CHECK_NEAR(ph->lumens, quadrature(ph, 720), 1e-4);
    /* a coarser, different rule (trapezoid in cos of the vertical angle) agrees to 1 % */
    double trapezoid = 0;
    for (uint32_t j = 0; j + 1 < 5; j++)
        for (uint32_t k = 0; k + 1 < 37; k++) {
            const double *c0 = ph->candela + j * 37, *c1 = ph->candela + (j + 1) * 37;
            double mean = 0.25 * (c0[k] + c0[k + 1] + c1[k] + c1[k + 1]);
            double dcos = cos(ph->vertical_degrees[k] * PI / 180) -
                          cos(ph->vertical_degrees[k + 1] * PI / 180);
            trapezoid += 4 * mean * dcos * 22.5 * PI / 180;
        }
    CHECK_NEAR(ph->lumens, trapezoid, 1e-2);
    rad_photometry_destroy(ph);
}

/* ------------------------------------------------------------------------------------ */
/* Refusals                                                                             */

/* A small valid file of eight lines; lines 4 to 8 replaced by the arguments that are not
 * NULL. */
static const char *mini(const char *l4, const char *l5, const char *l6, const char *l7,
                        const char *l8)
{
    static char buffer[4096];
    snprintf(buffer, sizeof(buffer),
             "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n%s\n%s\n%s\n%s\n%s\n",
             l4 ? l4 : "1 -1 1 3 1 1 2 0 0 0", l5 ? l5 : "1 1 100", l6 ? l6 : "0 45 90",
             l7 ? l7 : "0", l8 ? l8 : "100 80 50");
    return buffer;
}

static void test_refusals(void)
{
    /* the base is valid */
    rad_photometry *ph = write_and_read("mini.ies", mini(NULL, NULL, NULL, NULL, NULL), NULL);
    rad_photometry_destroy(ph);

    expect_refused("no_tilt.ies", "IESNA:LM-63-2002\n[TEST] x\n1 -1 1 3 1 1 2 0 0 0\n", 3,
                   "no TILT= line");
    expect_refused("no_tilt_empty.ies", "", 1, "no TILT= line");
    expect_refused("tilt_empty.ies", "IESNA:LM-63-2002\n[TEST] x\nTILT=  \n", 3,
                   "TILT= without a value");
    expect_refused("tilt_short.ies", "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n4\n0 30\n60 90\n1 1\n",
                   7, "the file ends after 2 of 4 tilt multiplying factors");
    expect_refused("tilt_count.ies", "IESNA:LM-63-2002\nTILT=INCLUDE\n1\nfour\n0 30 60 90\n", 4,
                   "number of tilt angles 'four' is not a number");
    expect_refused("tilt_angle.ies", "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n2\n0\n3O\n", 6,
                   "tilt angles 2: '3O' is not a number");

    expect_refused("v_count_zero.ies", mini("1 -1 1 0 1 1 2 0 0 0", NULL, NULL, NULL, NULL), 4,
                   "number of vertical angles '0' is not a positive integer");
    expect_refused("v_count_fraction.ies", mini("1 -1 1 2.5 1 1 2 0 0 0", NULL, NULL, NULL, NULL),
                   4, "number of vertical angles '2.5' is not a positive integer");
    expect_refused("v_count_absurd.ies", mini("1 -1 1 100001 1 1 2 0 0 0", NULL, NULL, NULL, NULL),
                   4, "number of vertical angles 100001 is more than this reader takes");
    expect_refused("h_count_negative.ies", mini("1 -1 1 3 -1 1 2 0 0 0", NULL, NULL, NULL, NULL),
                   4, "number of horizontal angles '-1' is not a positive integer");
    expect_refused("h_count_huge.ies",
                   mini("1 -1 1 3 4294967297 1 2 0 0 0", NULL, NULL, NULL, NULL), 4,
                   "is more than this reader takes");
    expect_refused("type_4.ies", mini("1 -1 1 3 1 4 2 0 0 0", NULL, NULL, NULL, NULL), 4,
                   "photometric type '4' is not 1 (C), 2 (B) or 3 (A)");
    expect_refused("type_0.ies", mini("1 -1 1 3 1 0 2 0 0 0", NULL, NULL, NULL, NULL), 4,
                   "photometric type '0'");
    expect_refused("not_number_header.ies", mini("1 -1 1 3 1 1 2 0 1e 0", NULL, NULL, NULL, NULL),
                   4, "the length '1e' is not a number");
    expect_refused("multiplier_negative.ies", mini("1 -1 -2 3 1 1 2 0 0 0", NULL, NULL, NULL, NULL),
                   4, "the candela multiplier -2 is negative");
    expect_refused("multiplier_inf.ies", mini("1 -1 inf 3 1 1 2 0 0 0", NULL, NULL, NULL, NULL), 4,
                   "the candela multiplier 'inf' is not a number");
    expect_refused("multiplier_huge.ies", mini("1 -1 1e999 3 1 1 2 0 0 0", NULL, NULL, NULL, NULL),
                   4, "the candela multiplier '1e999' is out of range");
    expect_refused("ballast_negative.ies", mini(NULL, "-1 1 100", NULL, NULL, NULL), 5,
                   "the ballast factor -1 is negative");
    expect_refused("header_short.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1", 5,
                   "the file ends before the input watts");
    /* 1995: the twelfth number is a factor, and may not be negative; 2002: not read as one */
    expect_refused("lamp_factor_negative.ies",
                   "IESNA:LM-63-1995\n[TEST] bad\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 -0.5 100\n"
                   "0 45 90\n0\n100 80 50\n",
                   5, "the ballast-lamp photometric factor -0.5 is negative");
    expect_refused("factors_overflow.ies",
                   "IESNA:LM-63-1995\n[TEST] bad\nTILT=NONE\n1 -1 1e300 3 1 1 2 0 0 0\n"
                   "1e300\n1e-300 100\n0 45 90\n0\n100 80 50\n",
                   6, "multiply to more than double's range");
    ph = write_and_read("future_negative.ies", mini(NULL, "1 -0.5 100", NULL, NULL, NULL), NULL);
    if (ph)
        CHECK(rad_photometry_candela(ph, 0, 0) == 100);
    rad_photometry_destroy(ph);

    expect_refused("v_not_ascending.ies", mini(NULL, NULL, "0 90 45", NULL, NULL), 6,
                   "vertical angle 3 is 45, not above the one before (90): not ascending");
    expect_refused("v_repeated.ies", mini(NULL, NULL, "0 45 45", NULL, NULL), 6,
                   "not ascending");
    expect_refused("v_above_180.ies", mini(NULL, NULL, "0 90 190", NULL, NULL), 6,
                   "vertical angle 3 is 190, outside [0, 180]");
    expect_refused("v_negative_c.ies", mini(NULL, NULL, "-5 45 90", NULL, NULL), 6,
                   "vertical angle 1 is -5, outside [0, 180]");
    expect_refused("v_type_b.ies", mini("1 -1 1 3 1 2 2 0 0 0", NULL, "-95 0 90", NULL, NULL), 6,
                   "vertical angle 1 is -95, outside [-90, 90]");
    expect_refused("v_type_a.ies", mini("1 -1 1 3 1 3 2 0 0 0", NULL, "0 45 100", NULL, NULL), 6,
                   "vertical angle 3 is 100, outside [-90, 90]");
    expect_refused("v_nan.ies", mini(NULL, NULL, "0 nan 90", NULL, NULL), 6,
                   "vertical angle 2: 'nan' is not a number");
    expect_refused("v_short.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 100\n"
                   "0 45\n",
                   6, "the file ends after 2 of 3 vertical angles");

    /* horizontal sets: one line each for the first and the last angle */
    const char *bad_sets[][3] = {
        /* count, angles, what */
        {"2", "0\n270", "8:the horizontal angles run 0..270"},
        {"2", "45\n90", "7:the horizontal angles start at 45"},
        {"1", "10", "7:the single horizontal angle is 10, not 0"},
        {"2", "90\n180", "8:the horizontal angles run 90..180"},
        {"3", "0\n90\n45", "9:horizontal angle 3 is 45, not above the one before (90)"},
        {"2", "0\n400", "8:horizontal angle 2 is 400, outside [0, 360]"},
    };
    for (size_t n = 0; n < sizeof(bad_sets) / sizeof(bad_sets[0]); n++) {
        char content[1024], name[64];
        unsigned nh = (unsigned)atoi(bad_sets[n][0]);
        text table = {0};
        for (unsigned k = 0; k < 3 * nh; k++)
            add(&table, "%u ", 10 + k);
        snprintf(content, sizeof(content),
                 "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 %u 1 2 0 0 0\n1 1 100\n"
                 "0 45 90\n%s\n%s\n",
                 nh, bad_sets[n][1], table.s);
        free(table.s);
        snprintf(name, sizeof(name), "h_set_%zu.ies", n);
        unsigned line = (unsigned)atoi(bad_sets[n][2]);
        expect_refused(name, content, line, strchr(bad_sets[n][2], ':') + 1);
    }
    expect_refused("h_type_b.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 2 2 2 0 0 0\n1 1 100\n"
                   "-90 0 90\n0\n45\n1 2 3 4 5 6\n",
                   8, "the horizontal angles run 0..45 (types A and B");
    expect_refused("h_type_a_start.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 2 3 2 0 0 0\n1 1 100\n"
                   "-90 0 90\n-45\n90\n1 2 3 4 5 6\n",
                   7, "the horizontal angles start at -45");

    expect_refused("short_table.ies", mini(NULL, NULL, NULL, NULL, "100 80"), 8,
                   "the file ends after 2 of 3 candela values");
    expect_refused("short_table_blank_lines.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 2 1 2 0 0 0\n1 1 100\n"
                   "0 45 90\n0 90\n100 80 50\n40\n\n\n",
                   11, "the file ends after 4 of 6 candela values");
    /* 100000 x 100000 angles: a table of 1e10 values the file cannot hold */
    {
        text big = {0};
        add(&big, "IESNA:LM-63-2002\n[TEST] big\nTILT=NONE\n1 -1 1 100000 100000 1 2 0 0 0\n"
                  "1 1 100\n");
        for (int k = 0; k < 100000; k++)
            add(&big, "%.17g%s", 180.0 * k / 99999, k % 10 == 9 ? "\n" : " ");
        for (int k = 0; k < 100000; k++)
            add(&big, "%.17g%s", 360.0 * k / 99999, k % 10 == 9 ? "\n" : " ");
        add(&big, "100 80\n");
        expect_refused("short_table_big.ies", big.s, 20006,
                       "the file ends after 2 of 10000000000 candela values");
        free(big.s);
    }
    expect_refused("candela_word.ies", mini(NULL, NULL, NULL, NULL, "100 abc 50"), 8,
                   "candela value at horizontal 0, vertical 45: 'abc' is not a number");
    expect_refused("candela_hex.ies", mini(NULL, NULL, NULL, NULL, "100 0x10 50"), 8,
                   "'0x10' is not a number");
    expect_refused("candela_negative.ies", mini(NULL, NULL, NULL, NULL, "100 80 -50"), 8,
                   "candela value at horizontal 0, vertical 90 is negative (-50)");
    expect_refused("candela_infinite.ies", mini(NULL, NULL, NULL, NULL, "100 1e400 50"), 8,
                   "'1e400' is out of range");
    expect_refused("candela_overflow.ies", mini("1 -1 1e200 3 1 1 2 0 0 0", NULL, NULL, NULL,
                   "100 80 50"), 8, "more than 1e+30 cd");
    /* spread over lines: the line of the offending token, not of the row's start */
    expect_refused("candela_spread.ies",
                   "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1,-1,1,3,2,1,2,0,0,0\n1,1,100\n"
                   "0,45,90\n0,\n180\n100,\n80,\n50,\n10,\n-3,\n1\n",
                   13, "candela value at horizontal 180, vertical 45 is negative (-3)");
    /* NUL bytes: the line of the first */
    static const char with_nul[] =
        "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n1 -1 1 3 1\0 1 2 0 0 0\n";
    expect_refused_at("nul.ies", with_nul, sizeof(with_nul) - 1, RAD_ERR_PARSE, 4,
                      "holds a NUL byte");
    /* no file, a folder */
    {
        rad_photometry *none = (rad_photometry *)1;
        rad_error error = {0};
        const char *missing = test_path("not_there.ies");
        CHECK(rad_photometry_read(missing, NULL, NULL, &none, &error) == RAD_ERR_IO);
        CHECK(none == NULL && error.status == RAD_ERR_IO);
        CHECK(strncmp(error.message, missing, strlen(missing)) == 0);
        CHECK(rad_photometry_read(test_tmpdir(), NULL, NULL, &none, &error) == RAD_ERR_IO);
        CHECK(rad_photometry_read(missing, NULL, NULL, NULL, NULL) == RAD_ERR_INVALID);
    }
    /* larger than 16 MiB: a valid file padded with blank lines */
    {
        size_t size = ((size_t)16 << 20) + 1;
        char *big = malloc(size);
        if (big) {
            const char *start = mini(NULL, NULL, NULL, NULL, NULL);
            memset(big, '\n', size);
            memcpy(big, start, strlen(start));
            expect_refused_at("big.ies", big, size, RAD_ERR_PARSE, 0, "larger than 16 MiB");
            /* one byte less is read */
            const char *path = test_path("big.ies");
            FILE *f = fopen(path, "wb");
            if (f) {
                fwrite(big, 1, size - 1, f);
                fclose(f);
            }
            rad_photometry_destroy(read_ok(path, NULL));
            free(big);
        }
    }
}

/* Every allocation of a read may fail: RAD_ERR_NOMEM each time, nothing left behind. */
static void test_allocation_failures(void)
{
    const char *path = test_write_file("alloc.ies", troffer_ies);
    int failures = 0;
    for (uint64_t n = 1; n < 100; n++) {
        rad_photometry *ph = NULL;
        rad_error error = {0};
        rad_alloc_fail_nth(n);
        rad_status status = rad_photometry_read(path, NULL, NULL, &ph, &error);
        bool injected = rad_alloc_failure_injected();
        rad_alloc_fail_nth(0);
        if (!injected) {
            CHECK(status == RAD_OK);
            rad_photometry_destroy(ph);
            break;
        }
        failures++;
        CHECK(status == RAD_ERR_NOMEM && ph == NULL && strstr(error.message, "alloc.ies"));
    }
    CHECK(failures >= 4);
}

int main(void)
{
    test_isotropic();
    test_cosine_downlight();
    test_symmetric_variants();
    test_types_a_and_b();
    test_formats_and_factors();
    test_tilt();
    test_separators();
    test_manufacturer_file();
    test_refusals();
    test_allocation_failures();
    return test_finish("test_ies");
}
