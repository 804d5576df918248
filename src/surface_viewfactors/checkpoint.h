/*
 * checkpoint.h - the restart file of a long view-factor run: the rows done so far, with
 * what identifies the job (a fingerprint of the scene's geometry and surfaces, the
 * accuracy, the ray caps and the seed), so that a resumed run continues the same job and
 * ends with the matrix an uninterrupted run gives, bitwise. Reading refuses, naming the
 * file, a checkpoint of another scene or other options and a damaged one. It does not
 * decide when to write (viewfactor_matrix.c does) and knows nothing of MPI.
 */
#ifndef RAD_VIEWFACTOR_CHECKPOINT_H
#define RAD_VIEWFACTOR_CHECKPOINT_H

#include <stdint.h>

#include "radiosity.h"
#include "surface_viewfactors/pending_row.h"

/* What a checkpoint belongs to: the rows are valid only for the same values. */
typedef struct vf_checkpoint_job {
    uint64_t fingerprint; /* vf_checkpoint_fingerprint of the scene */
    uint32_t rows;        /* surface count */
    double accuracy;      /* as used (defaults applied) */
    uint32_t max_rays;
    uint64_t seed;
    uint32_t sight_rays;  /* 0: none */
    uint32_t exact_occluders;
} vf_checkpoint_job;

/* A hash of what the view factors depend on: positions, triangles (corners and surface),
 * the surfaces' triangle ranges and flags (obstruction, two-sided). Not names, materials
 * or emissivities, which do not change F. */
uint64_t vf_checkpoint_fingerprint(const rad_scene *scene);

/* Writes, atomically, every row I with done[I] (rows[I] its entries, sorted by column). */
rad_status vf_checkpoint_write(const char *path, const vf_checkpoint_job *job,
                               const pending_row *rows, const uint8_t *done, rad_error *error);

/* Reads the rows of a checkpoint of `job` into rows[] (which must be empty) and sets
 * done[I] for each; *count receives how many. RAD_ERR_IO when it cannot be read,
 * RAD_ERR_PARSE for a file that is not a whole checkpoint, RAD_ERR_INVALID for one of
 * another scene or other options; every message names the file. On failure rows[] is left
 * empty. */
rad_status vf_checkpoint_read(const char *path, const vf_checkpoint_job *job,
                              pending_row *rows, uint8_t *done, uint32_t *count,
                              rad_error *error);

#endif
