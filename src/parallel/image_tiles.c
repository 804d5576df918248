/*
 * image_tiles.c - tiles of images computed on several ranks, gathered on rank 0
 * (image_tiles.h). A rank packs its tiles' pixels, tile by tile in tile order and image by
 * image, so rank 0 can unpack them from the owner table alone. Not a renderer.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "parallel/image_tiles.h"
#include "parallel/ranks.h"

typedef struct tile_box {
    uint32_t x0, y0, width, height;
} tile_box;

static tile_box tile_at(const rad_image *image, uint32_t tile, uint64_t k)
{
    uint32_t tiles_x = (image->width - 1) / tile + 1;
    tile_box b = {(uint32_t)(k % tiles_x) * tile, (uint32_t)(k / tiles_x) * tile, 0, 0};
    b.width = image->width - b.x0 < tile ? image->width - b.x0 : tile;
    b.height = image->height - b.y0 < tile ? image->height - b.y0 : tile;
    return b;
}

/* Floats of every image over the tiles rank owns. */
static uint64_t tile_floats(const rad_image *image, uint32_t tile, const uint32_t *owner,
                            int rank, int count)
{
    uint64_t tiles = (uint64_t)((image->width - 1) / tile + 1) * ((image->height - 1) / tile + 1);
    uint64_t floats = 0;
    for (uint64_t k = 0; k < tiles; k++)
        if (owner[k] == (uint32_t)rank) {
            tile_box b = tile_at(image, tile, k);
            floats += (uint64_t)b.width * b.height * 3 * (uint64_t)count;
        }
    return floats;
}

/* Copies the tile's pixels of every image to `at` (to_image false) or from it; returns
 * the position after them. */
static float *copy_tile(rad_image *const *images, int count, tile_box b, float *at,
                        bool to_image)
{
    for (int i = 0; i < count; i++)
        for (uint32_t y = b.y0; y < b.y0 + b.height; y++) {
            float *row = images[i]->rgb + ((size_t)y * images[i]->width + b.x0) * 3;
            size_t floats = (size_t)b.width * 3;
            if (to_image)
                memcpy(row, at, floats * sizeof(float));
            else
                memcpy(at, row, floats * sizeof(float));
            at += floats;
        }
    return at;
}

rad_status ranks_gather_tiles(rad_image *const *images, int count, uint32_t tile,
                              const uint32_t *owner, rad_error *error)
{
    int rank = ranks_rank(), ranks = ranks_count();
    if (ranks == 1)
        return RAD_OK;
    const rad_image *image = images[0];
    uint64_t tiles = (uint64_t)((image->width - 1) / tile + 1) * ((image->height - 1) / tile + 1);
    uint64_t floats = rank == 0 ? 0 : tile_floats(image, tile, owner, rank, count);
    float *mine = rad_alloc_array(floats ? floats : 1, sizeof(float));
    uint64_t *sizes = rad_alloc_array((size_t)ranks, sizeof(uint64_t));
    bool failed = !mine || !sizes;
    if (ranks_failures(failed)) {
        free(mine);
        free(sizes);
        return rad_fail(error, RAD_ERR_NOMEM, failed ? "out of memory packing image tiles"
                                                     : "another rank ran out of memory");
    }
    float *at = mine;
    for (uint64_t k = 0; k < tiles; k++)
        if (owner[k] == (uint32_t)rank && rank != 0) /* rank 0's tiles are in place */
            at = copy_tile(images, count, tile_at(image, tile, k), at, false);
    void *gathered = NULL;
    rad_status status = ranks_gather(mine, floats * sizeof(float), &gathered, sizes, error);
    free(mine);
    for (int r = 1; status == RAD_OK && rank == 0 && r < ranks; r++)
        if (sizes[r] != tile_floats(image, tile, owner, r, count) * sizeof(float))
            status = rad_fail(error, RAD_ERR_INTERNAL,
                              "rank %d sent %llu bytes of image tiles, not the tiles it owns", r,
                              (unsigned long long)sizes[r]);
    if (status == RAD_OK && rank == 0) {
        at = gathered; /* rank 0 sent nothing: its tiles are in place */
        for (int r = 1; r < ranks; r++)
            for (uint64_t k = 0; k < tiles; k++)
                if (owner[k] == (uint32_t)r)
                    at = copy_tile(images, count, tile_at(image, tile, k), at, true);
    }
    free(gathered);
    free(sizes);
    return status;
}
