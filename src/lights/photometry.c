/*
 * photometry.c - a photometric web (IES LM-63): freeing it. The reader and the candela
 * look-up come with the IES reader.
 */
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
