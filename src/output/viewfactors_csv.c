/*
 * viewfactors_csv.c - the surface view-factor matrix as CSV.
 *
 * First row "surface,NAME1,...,NAMEn", then "NAMEi,F_i1,...,F_in". Names containing a
 * comma, quote or newline are quoted per RFC 4180. Written atomically.
 */
#include <string.h>

#include "core/atomic_file.h"
#include "core/error.h"

static void write_name(FILE *f, const char *name)
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

rad_status rad_viewfactors_write_csv(const rad_scene *scene, const double *matrix,
                                     const char *path, rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    size_t S = scene->surface_count;
    fputs("surface", file.stream);
    for (size_t J = 0; J < S; J++) {
        fputc(',', file.stream);
        write_name(file.stream, scene->surfaces[J].name);
    }
    fputc('\n', file.stream);
    for (size_t I = 0; I < S; I++) {
        write_name(file.stream, scene->surfaces[I].name);
        for (size_t J = 0; J < S; J++)
            fprintf(file.stream, ",%.9g", matrix[I * S + J]);
        fputc('\n', file.stream);
    }
    return rad_atomic_commit(&file, error);
}
