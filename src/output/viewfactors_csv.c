/*
 * viewfactors_csv.c - the surface view-factor matrix as CSV.
 *
 * First row "surface,NAME1,...,NAMEn", then "NAMEi,F_i1,...,F_in". Names containing a
 * comma, quote or newline are quoted per RFC 4180. Written atomically.
 */
#include <errno.h>
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

static void write_matrix(const rad_scene *scene, const double *matrix, FILE *stream)
{
    size_t S = scene->surface_count;
    fputs("surface", stream);
    for (size_t J = 0; J < S; J++) {
        fputc(',', stream);
        write_name(stream, scene->surfaces[J].name);
    }
    fputc('\n', stream);
    for (size_t I = 0; I < S; I++) {
        write_name(stream, scene->surfaces[I].name);
        for (size_t J = 0; J < S; J++)
            fprintf(stream, ",%.9g", matrix[I * S + J]);
        fputc('\n', stream);
    }
}

rad_status rad_viewfactors_write_csv(const rad_scene *scene, const double *matrix,
                                     const char *path, rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    write_matrix(scene, matrix, file.stream);
    return rad_atomic_commit(&file, error);
}

rad_status rad_viewfactors_print_csv(const rad_scene *scene, const double *matrix, FILE *stream,
                                     rad_error *error)
{
    write_matrix(scene, matrix, stream);
    if (fflush(stream) != 0 || ferror(stream))
        return rad_fail(error, RAD_ERR_IO, "cannot write the view factors: %s", strerror(errno));
    return RAD_OK;
}
