/*
 * photometry.c - a photometric web (IES LM-63): freeing it. The reader and the candela
 * look-up come with the IES reader.
 */
#include <stdio.h>
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

/* PLACEHOLDER until the IES reader lands. */
double rad_photometry_candela(const rad_photometry *photometry, double vertical_degrees,
                              double horizontal_degrees)
{
    (void)photometry;
    (void)vertical_degrees;
    (void)horizontal_degrees;
    return 0;
}

/* PLACEHOLDER until the IES reader lands. */
rad_status rad_photometry_read(const char *path, rad_log_fn log, void *log_user,
                               rad_photometry **out, rad_error *error)
{
    (void)log;
    (void)log_user;
    *out = NULL;
    if (error) {
        error->status = RAD_ERR_UNSUPPORTED;
        snprintf(error->message, sizeof(error->message), "%s: IES files cannot be read yet",
                 path);
    }
    return RAD_ERR_UNSUPPORTED;
}
