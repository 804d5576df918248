/*
 * obj_check.h - the OBJ checks Assimp does not make, makes without a line number, or gets
 * wrong, and the copy of the file Assimp reads instead of it where it would misread it.
 * See obj_check.c.
 */
#ifndef RAD_SCENE_OBJ_CHECK_H
#define RAD_SCENE_OBJ_CHECK_H

#include <stdbool.h>
#include <stdio.h>

#include "radiosity.h"

/* The numbered lists of an OBJ file a face corner refers to (v/vt/vn). */
enum { OBJ_VERTEX, OBJ_UV, OBJ_NORMAL, OBJ_LISTS };

/* A set of material names, "\nNAME\n" each (a usemtl line names a material by the rest
 * of its line, spaces included). */
typedef struct obj_names {
    char *text;
    size_t length, capacity;
    char last[256]; /* the name found last (files repeat usemtl lines) */
    bool with_lines; /* "\nNAME\tLINE\n" each */
} obj_names;

/* What the OBJ check has seen, and the copy of the file Assimp reads instead of it when
 * the file must be told differently. */
typedef struct obj_check {
    const char *path;
    const rad_load_options *options;
    char folder[4096];
    unsigned long line;
    unsigned long defined[OBJ_LISTS];     /* v, vt, vn lines so far */
    long long largest[OBJ_LISTS];         /* the largest absolute index of each list */
    unsigned long largest_line[OBJ_LISTS];
    char *copy;                           /* the file as Assimp is to read it */
    size_t copy_length, copy_capacity;
    bool copy_differs;                    /* Assimp must read `copy`, not the file */
    obj_names materials_defined;          /* newmtl names of the file's libraries */
    obj_names materials_used;             /* usemtl names, each once, with its first line */
    obj_names materials_undefined;        /* used but not defined: the default albedo */
} obj_check;

/* Reads `file` (at its start) of OBJ scene `path`: face indices name entries of their
 * v/vt/vn list (compared without overflow, INT64_MIN included), v/vt/vn lines hold enough
 * finite numbers within single precision, material libraries exist (beside the OBJ, or
 * by their base name beside it: a warning). RAD_OK, or "PATH:LINE: what is wrong" in
 * error. Fills c->copy with the file as Assimp is to read it; c->copy_differs says when
 * that is not the file itself: numbers written ".5", a comment after a face, several
 * libraries on one mtllib line, a library found by its base name. Usemtl names no
 * library defines are warned about (at their first use) and kept in
 * c->materials_undefined. Free with obj_check_free, whatever the result. */
rad_status obj_check_read(const char *path, const rad_load_options *options, FILE *file,
                          obj_check *c, rad_error *error);

/* True when `name` is in the set. */
bool obj_names_has(obj_names *set, const char *name);

/* Frees what obj_check_read kept (the copy, the name sets). */
void obj_check_free(obj_check *c);

#endif
