/*
 * sky_viewfactor_writer.c - the sky view factors as a file, see radiosity.h: CSV
 * ("index,surface,sky_view_factor,error_bound") or, for a name ending in .mtx, a Matrix
 * Market column vector, the companion of a .mtx matrix. Both number the surfaces as the
 * matrix writers do (obstructions left out, 1-based), so index K is row K of the .mtx
 * matrix. Written atomically (core/atomic_file.h). Not here: computing them
 * (sky_viewfactor.c).
 */
#include <string.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "surface_viewfactors/surface_names.h"

static void write_csv(const rad_scene *scene, const double *sky, const double *bound, FILE *f)
{
    fputs("index,surface,sky_view_factor,error_bound\n", f);
    uint32_t number = 0;
    for (uint32_t I = 0; I < scene->surface_count; I++) {
        if (!vf_surface_listed(scene, I))
            continue;
        fprintf(f, "%u,", ++number);
        vf_write_csv_name(f, scene->surfaces[I].name);
        fprintf(f, ",%.9g,%.3g\n", sky[I], bound[I]);
    }
}

static void write_matrix_market(const rad_scene *scene, const double *sky, const double *bound,
                                FILE *f)
{
    uint32_t count = 0;
    for (uint32_t I = 0; I < scene->surface_count; I++)
        count += vf_surface_listed(scene, I);
    fputs("%%MatrixMarket matrix array real general\n", f);
    fputs("% sky view factors from radiosity viewfactors: row K is surface K of the view-factor "
          "matrix\n",
          f);
    fputs("% sky K ERROR_BOUND NAME\n", f);
    uint32_t number = 0;
    for (uint32_t I = 0; I < scene->surface_count; I++)
        if (vf_surface_listed(scene, I))
            fprintf(f, "%% sky %u %.3g %s\n", ++number, bound[I], scene->surfaces[I].name);
    fprintf(f, "%u 1\n", count);
    for (uint32_t I = 0; I < scene->surface_count; I++)
        if (vf_surface_listed(scene, I))
            fprintf(f, "%.17g\n", sky[I]);
}

rad_status rad_sky_viewfactors_write(const rad_scene *scene, const double *sky,
                                     const double *bound, const char *path, rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    if (rad_viewfactor_format_for_path(path) == RAD_VIEWFACTOR_MATRIX_MARKET)
        write_matrix_market(scene, sky, bound, file.stream);
    else
        write_csv(scene, sky, bound, file.stream);
    return rad_atomic_commit(&file, error);
}
