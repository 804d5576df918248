/*
 * surface_names.h - what the view-factor files share about surfaces: which surfaces get
 * a row (obstructions do not) and a surface's name as a CSV field. Used by the matrix
 * writers and the sky view factor's writer, which number and name surfaces alike.
 */
#ifndef RAD_VIEWFACTOR_SURFACE_NAMES_H
#define RAD_VIEWFACTOR_SURFACE_NAMES_H

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "radiosity.h"

/* True for a surface with a row and a column in the files: every one but obstructions. */
static inline bool vf_surface_listed(const rad_scene *scene, uint32_t surface)
{
    return !(scene->surfaces[surface].flags & RAD_SURFACE_OBSTRUCTION);
}

/* The name as a CSV field: quoted (and its quotes doubled) when it holds a comma, a quote
 * or a line end. */
static inline void vf_write_csv_name(FILE *f, const char *name)
{
    if (strpbrk(name, ",\"\n\r") == NULL) {
        fputs(name, f);
        return;
    }
    fputc('"', f);
    for (; *name; name++) {
        if (*name == '"')
            fputc('"', f);
        fputc(*name, f);
    }
    fputc('"', f);
}

#endif
