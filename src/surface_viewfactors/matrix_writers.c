/*
 * matrix_writers.c - a sparse surface view-factor matrix as a file: CSV (dense
 * rows), Matrix Market (coordinate, the stored factors only) or View3D's text layout.
 *
 * Obstruction surfaces have no factors and are left out of every layout; the others keep
 * the scene's order. Files are written through core/atomic_file.h.
 */
#include <errno.h>
#include <string.h>
#include <strings.h>

#include "core/alloc.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "surface_viewfactors/surface_names.h"

/* The version View3D's header names: the layout matches its 3.3 text output (SaveF0). */
#define VIEW3D_VERSION "3.3"
/* View3D pads its header line to this many characters before the newline. */
enum { VIEW3D_HEADER_WIDTH = 30 };

rad_viewfactor_format rad_viewfactor_format_for_path(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcasecmp(path + n - 4, ".mtx") == 0 ? RAD_VIEWFACTOR_MATRIX_MARKET
                                                           : RAD_VIEWFACTOR_CSV;
}

/* Row I expanded into `dense` (n values). */
static void expand_row(const rad_viewfactor_matrix *m, uint32_t I, double *dense)
{
    memset(dense, 0, m->n * sizeof(*dense));
    for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
        dense[m->column[k]] = m->value[k];
}

static void write_csv(const rad_scene *scene, const rad_viewfactor_matrix *m, double *dense,
                      FILE *f)
{
    fputs("surface", f);
    for (uint32_t J = 0; J < m->n; J++)
        if (vf_surface_listed(scene, J)) {
            fputc(',', f);
            vf_write_csv_name(f, scene->surfaces[J].name);
        }
    fputc('\n', f);
    for (uint32_t I = 0; I < m->n; I++) {
        if (!vf_surface_listed(scene, I))
            continue;
        expand_row(m, I, dense);
        vf_write_csv_name(f, scene->surfaces[I].name);
        for (uint32_t J = 0; J < m->n; J++)
            if (vf_surface_listed(scene, J))
                fprintf(f, ",%.9g", dense[J]);
        fputc('\n', f);
    }
}

static void write_matrix_market(const rad_scene *scene, const rad_viewfactor_matrix *m,
                                bool error_bounds, uint32_t *number, FILE *f)
{
    uint32_t count = 0;
    uint64_t nonzeros = 0;
    for (uint32_t I = 0; I < m->n; I++)
        number[I] = vf_surface_listed(scene, I) ? ++count : 0;
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; number[I] && k < m->row_start[I + 1]; k++)
            nonzeros += number[m->column[k]] && m->value[k] != 0;
    fputs("%%MatrixMarket matrix coordinate real general\n", f);
    fputs(error_bounds ? "% error bounds of the surface view factors F_IJ (absolute; row I, "
                         "column J) from radiosity viewfactors\n"
                       : "% surface view factors F_IJ (row I, column J) from radiosity "
                         "viewfactors\n",
          f);
    fputs("% surface K AREA NAME\n", f);
    for (uint32_t I = 0; I < m->n; I++)
        if (number[I])
            fprintf(f, "%% surface %u %.17g %s\n", number[I], m->area[I], scene->surfaces[I].name);
    fprintf(f, "%u %u %llu\n", count, count, (unsigned long long)nonzeros);
    for (uint32_t I = 0; I < m->n; I++)
        for (uint64_t k = m->row_start[I]; number[I] && k < m->row_start[I + 1]; k++)
            if (number[m->column[k]] && m->value[k] != 0)
                fprintf(f, "%u %u %.17g\n", number[I], number[m->column[k]], m->value[k]);
}

static void write_view3d(const rad_scene *scene, const rad_viewfactor_matrix *m,
                         const rad_viewfactor_write_options *options, double *dense, FILE *f)
{
    uint32_t count = 0;
    for (uint32_t I = 0; I < m->n; I++)
        count += vf_surface_listed(scene, I);
    char header[64];
    int length = snprintf(header, sizeof(header), "View3D %s 0 %d %d %u", VIEW3D_VERSION,
                          options->enclosure ? 1 : 0, options->script_f ? 1 : 0, count);
    fprintf(f, "%s%*s\n", header, length < VIEW3D_HEADER_WIDTH ? VIEW3D_HEADER_WIDTH - length : 0,
            "");
    const char *separator = "";
    for (uint32_t I = 0; I < m->n; I++)
        if (vf_surface_listed(scene, I)) {
            fprintf(f, "%s%g", separator, m->area[I]);
            separator = " ";
        }
    fputc('\n', f);
    for (uint32_t I = 0; I < m->n; I++) {
        if (!vf_surface_listed(scene, I))
            continue;
        expand_row(m, I, dense);
        separator = "";
        for (uint32_t J = 0; J < m->n; J++)
            if (vf_surface_listed(scene, J)) {
                fprintf(f, "%s%.6f", separator, dense[J]);
                separator = " ";
            }
        fputc('\n', f);
    }
    separator = "";
    for (uint32_t I = 0; I < m->n; I++)
        if (vf_surface_listed(scene, I)) {
            fprintf(f, "%s%.3f", separator, scene->surfaces[I].emissivity);
            separator = " ";
        }
    fputc('\n', f);
}

static rad_status write_any(const rad_scene *scene, const rad_viewfactor_matrix *m, FILE *f,
                            const rad_viewfactor_write_options *options, rad_error *error)
{
    rad_viewfactor_write_options defaults = {RAD_VIEWFACTOR_CSV, false, false, false};
    if (!options)
        options = &defaults;
    if (m->n != scene->surface_count)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: the view-factor matrix has %u surfaces, the scene %u",
                        scene->source, m->n, scene->surface_count);
    void *buffer = rad_alloc_array(m->n, sizeof(double));
    if (!buffer)
        return rad_fail(error, RAD_ERR_NOMEM, "out of memory for the view-factor output");
    switch (options->format) {
    case RAD_VIEWFACTOR_MATRIX_MARKET:
        /* n uint32_t fit in n doubles */
        write_matrix_market(scene, m, options->error_bounds, buffer, f);
        break;
    case RAD_VIEWFACTOR_VIEW3D:
        write_view3d(scene, m, options, buffer, f);
        break;
    default:
        write_csv(scene, m, buffer, f);
        break;
    }
    free(buffer);
    return RAD_OK;
}

rad_status rad_viewfactor_matrix_write(const rad_scene *scene,
                                       const rad_viewfactor_matrix *matrix, const char *path,
                                       const rad_viewfactor_write_options *options,
                                       rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    status = write_any(scene, matrix, file.stream, options, error);
    if (status != RAD_OK) {
        rad_atomic_abort(&file);
        return status;
    }
    return rad_atomic_commit(&file, error);
}

rad_status rad_viewfactor_matrix_print(const rad_scene *scene,
                                       const rad_viewfactor_matrix *matrix, FILE *stream,
                                       const rad_viewfactor_write_options *options,
                                       rad_error *error)
{
    rad_status status = write_any(scene, matrix, stream, options, error);
    if (status != RAD_OK)
        return status;
    if (fflush(stream) != 0 || ferror(stream))
        return rad_fail(error, RAD_ERR_IO, "cannot write the view factors: %s", strerror(errno));
    return RAD_OK;
}
