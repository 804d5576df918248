/*
 * ply_header.h - the one parser of a PLY 1.0 header (ASCII, binary little- and big-endian):
 * its format, and each element with its row count and properties (name, type, and for a
 * list the type of its count). The body is import_ply.c's. What the header parser refuses,
 * with the header line: an unknown keyword (only ply, format, comment, obj_info, element,
 * property, end_header), a NUL byte or a line over 1022 bytes (comments may be longer), a
 * format other than the three or a version other than 1.0, a row count that is not a whole
 * number of 64 bits, a property of unknown type or without a name, a list whose count is
 * of a floating type; then a header without format or end_header, without a vertex element
 * with rows, or with an element of rows but no properties.
 */
#ifndef RAD_SCENE_PLY_HEADER_H
#define RAD_SCENE_PLY_HEADER_H

#include <stdbool.h>
#include <stdio.h>

#include "radiosity.h"

enum { PLY_MAX_ELEMENTS = 16, PLY_MAX_PROPERTIES = 64, PLY_NAME_SIZE = 64 };

typedef enum ply_format { PLY_ASCII, PLY_LITTLE, PLY_BIG } ply_format;

/* A scalar type of PLY: its size in bytes (1, 2, 4 or 8), and how its bits read. */
typedef struct ply_type {
    int size;
    bool is_signed, is_float;
} ply_type;

typedef struct ply_property {
    char name[PLY_NAME_SIZE];
    ply_type type;       /* a scalar's type, or a list's items' */
    bool is_list;
    ply_type count_type; /* a list's count (a whole number), else unused */
} ply_property;

typedef struct ply_element {
    char name[PLY_NAME_SIZE];
    unsigned long long rows;
    int property_count;
    ply_property properties[PLY_MAX_PROPERTIES];
} ply_element;

typedef struct ply_header {
    ply_format format;
    int element_count;
    ply_element elements[PLY_MAX_ELEMENTS];
    unsigned long lines; /* lines of the header, end_header's included */
} ply_header;

/* Reads the header of scene `path` from `file` (at its start), leaving `file` at the first
 * byte of the body: RAD_OK, or RAD_ERR_PARSE with "PATH[:LINE]: what is wrong" in error. */
rad_status ply_header_read(const char *path, FILE *file, ply_header *header, rad_error *error);

/* The first element of this name, or NULL. */
const ply_element *ply_header_element(const ply_header *header, const char *name);

/* Index of the element's first property of this name, or -1. */
int ply_element_property(const ply_element *element, const char *name);

#endif
