/*
 * image_tiles.h - an image computed tile by tile over several ranks, put together on rank 0:
 * every rank sends the pixels of the tiles it owns, rank 0 copies them into its image.
 * Only the gathering: which rank owns which tile is its caller's choice (partition.h).
 */
#ifndef RAD_PARALLEL_IMAGE_TILES_H
#define RAD_PARALLEL_IMAGE_TILES_H

#include <stdint.h>

#include "radiosity.h"

/* Collective. The image is cut into tile x tile squares (the last row and column
 * narrower), numbered row by row; owner[k] is the rank that computed tile k into its own
 * `images` (count of them, all the same size: say the image and its standard error). On
 * rank 0 every tile of every image then holds its owner's pixels; the other ranks' images
 * are not changed. Fails on every rank when out of memory. */
rad_status ranks_gather_tiles(rad_image *const *images, int count, uint32_t tile,
                              const uint32_t *owner, rad_error *error);

#endif
