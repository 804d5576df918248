/*
 * ply_check.h - a PLY check Assimp does not make: the body holds every row the header
 * declares (ASCII or binary, lists included), and no face has an empty vertex list.
 * Assimp 5.2 reads short files past their data and aborts or crashes in its
 * triangulation, and aborts on an empty face; this check refuses them first.
 */
#ifndef RAD_SCENE_PLY_CHECK_H
#define RAD_SCENE_PLY_CHECK_H

#include <stdio.h>

#include "radiosity.h"

/* Reads `file` (at its start) of scene `path`: RAD_OK, or RAD_ERR_PARSE with
 * "PATH[:LINE]: what is wrong" in error (a header line, or the element whose rows the file
 * ends in). */
rad_status ply_check(const char *path, FILE *file, rad_error *error);

#endif
