/*
 * fuzz_ies.c - libFuzzer target: IES LM-63 photometric files (src/lights/ies_read.c) and
 * the candela look-up (src/lights/photometry.c). The reader takes a path, so the input is
 * written to a temporary file first (fuzz_target.h).
 *
 * Besides the refusal's contract (one line starting with the file), a web that loads must
 * keep what radiosity.h and ies_read.c promise: a photometric type in 1..3, counts in
 * 1..100000, strictly ascending angles in their type's range, horizontal angles that are
 * one of the symmetric variants, candela values finite and not negative, a finite flux
 * that is not negative; every warning one line naming the file. The look-up must give each
 * listed value back exactly at its angles, and anywhere else a finite value between 0 and
 * the table's largest.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_target.h"

static void broken(const char *what, const char *path)
{
    fprintf(stderr, "fuzz contract broken: %s: %s\n", what, path);
    abort();
}

static const char *warning_path;

static void check_warning(void *user, const char *message)
{
    (void)user;
    if (getenv("RAD_FUZZ_VERBOSE"))
        fprintf(stderr, "warning: %s\n", message);
    if (strncmp(message, warning_path, strlen(warning_path)) != 0)
        broken("a warning does not start with the file", message);
    if (strchr(message, '\n') || strchr(message, '\r'))
        broken("a warning is more than one line", message);
}

static bool legal_horizontal(const rad_photometry *ph)
{
    const double *h = ph->horizontal_degrees;
    uint32_t n = ph->horizontal_count;
    double first = h[0], last = h[n - 1];
    if (n == 1)
        return first == 0;
    if (ph->photometric_type == 1)
        return (first == 0 && (last == 90 || last == 180 || last == 360)) ||
               (first == 90 && last == 270);
    return (first == 0 || first == -90) && last == 90;
}

static void check_angles(const double *a, uint32_t n, double least, double most,
                         const char *path)
{
    for (uint32_t k = 0; k < n; k++) {
        if (!(a[k] >= least && a[k] <= most))
            broken("an angle is out of its range", path);
        if (k > 0 && !(a[k] > a[k - 1]))
            broken("the angles are not ascending", path);
    }
}

static void check_web(const rad_photometry *ph, const char *path)
{
    uint32_t type = ph->photometric_type, nv = ph->vertical_count, nh = ph->horizontal_count;
    if (type < 1 || type > 3)
        broken("the photometric type is not 1..3", path);
    if (nv < 1 || nv > 100000 || nh < 1 || nh > 100000)
        broken("a count is out of 1..100000", path);
    if (!ph->vertical_degrees || !ph->horizontal_degrees || !ph->candela)
        broken("an array is missing", path);
    if (strncmp(ph->source, path, sizeof(ph->source) - 1) != 0)
        broken("the source is not the file", path);
    check_angles(ph->vertical_degrees, nv, type == 1 ? 0 : -90, type == 1 ? 180 : 90, path);
    check_angles(ph->horizontal_degrees, nh, type == 1 ? 0 : -90, type == 1 ? 360 : 90, path);
    if (!legal_horizontal(ph))
        broken("the horizontal angles are not a symmetric variant", path);
    double largest = 0;
    for (uint64_t k = 0; k < (uint64_t)nv * nh; k++) {
        double c = ph->candela[k];
        if (!(c >= 0) || !isfinite(c))
            broken("a candela value is negative or not finite", path);
        if (c > largest)
            largest = c;
    }
    if (!(ph->lumens >= 0) || !isfinite(ph->lumens))
        broken("the flux is negative or not finite", path);
    /* the listed values come back exactly (the 360 column of a 0..360 web reads as 0) */
    for (uint32_t j = 0; j < nh && j < 64; j++) {
        double h = ph->horizontal_degrees[j];
        if (type == 1 && h >= 360)
            continue;
        for (uint32_t k = 0; k < nv && k < 64; k++)
            if (rad_photometry_candela(ph, ph->vertical_degrees[k], h) !=
                ph->candela[(size_t)j * nv + k])
                broken("a listed value does not come back at its angles", path);
    }
    /* anywhere: finite, between 0 and the largest */
    static const double angles[] = {-720.5, -180, -90, -45.25, -1e-300, 0, 1e-300, 0.5, 5,
                                    33.3,   89.9, 90,  90.1,   135,     179.99, 180, 200,
                                    270,    359.999999, 360, 1e9};
    size_t count = sizeof(angles) / sizeof(angles[0]);
    for (size_t a = 0; a < count; a++)
        for (size_t b = 0; b < count; b++) {
            double c = rad_photometry_candela(ph, angles[a], angles[b]);
            if (!(c >= 0 && c <= largest))
                broken("a look-up is outside [0, the largest value]", path);
        }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_file("input.ies", data, size);
    warning_path = path;
    rad_photometry *ph = NULL;
    rad_error error = {0};
    rad_status status = rad_photometry_read(path, check_warning, NULL, &ph, &error);
    fuzz_check_refusal(status, &error, path);
    if (status == RAD_OK) {
        if (!ph)
            broken("RAD_OK without a web", path);
        check_web(ph, path);
    } else if (ph) {
        broken("a refusal handed back a web", path);
    }
    rad_photometry_destroy(ph);
    return 0;
}
