/*
 * import_ply.h - the project's own PLY 1.0 reader (ASCII, binary little- and big-endian),
 * so that Assimp never reads a PLY file. See import_ply.c for what it keeps of a file.
 */
#ifndef RAD_SCENE_IMPORT_PLY_H
#define RAD_SCENE_IMPORT_PLY_H

#include <stdbool.h>
#include <stdio.h>

#include "radiosity.h"

/* Reads the PLY file at `path` into a new scene (rad_scene_load's contract): RAD_OK, or
 * RAD_ERR_IO / RAD_ERR_PARSE / RAD_ERR_NOMEM with "PATH[:LINE]: message" in error. */
rad_status ply_scene_load(const char *path, const rad_load_options *options, rad_scene **out,
                          rad_error *error);

/* The same from an open stream at its start (the fuzz target reads from memory); `path`
 * names it in messages and, without folder and extension, names its surface. */
rad_status ply_scene_read(const char *path, FILE *file, const rad_load_options *options,
                          rad_scene **out, rad_error *error);

/* True when the stream (at its start; it is left anywhere) begins with PLY's magic line,
 * "ply" then a line ending: PLY content whatever the file's extension. */
bool ply_stream_is_ply(FILE *file);

#endif
