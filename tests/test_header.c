/*
 * test_header.c - the public header stands alone: this file includes nothing before it,
 * and the library's documented no-op and naming contracts hold.
 */
#include "radiosity.h"

#include <string.h>

#include "testlib.h"

int main(void)
{
    /* every status has a name, and unknown ones do not crash */
    for (int s = RAD_OK; s <= RAD_ERR_INTERNAL; s++) {
        CHECK(strlen(rad_status_name((rad_status)s)) > 0);
        /* each known status has its own name, not the fallback for unknown ones */
        for (int t = RAD_OK; t < s; t++)
            CHECK(strcmp(rad_status_name((rad_status)s), rad_status_name((rad_status)t)) != 0);
    }
    CHECK(strcmp(rad_status_name(RAD_OK), "success") == 0);
    /* values outside the enum (a status from a newer library, memory garbage): a name,
     * never NULL, never one of the real statuses' names */
    const int unknown[] = {RAD_ERR_INTERNAL + 1, 999, -1};
    for (size_t k = 0; k < sizeof(unknown) / sizeof(unknown[0]); k++) {
        const char *name = rad_status_name((rad_status)unknown[k]);
        CHECK(name != NULL && strlen(name) > 0);
        for (int t = RAD_OK; name && t <= RAD_ERR_INTERNAL; t++)
            CHECK(strcmp(name, rad_status_name((rad_status)t)) != 0);
    }
    /* destroying NULL is harmless for every object */
    rad_scene_destroy(NULL);
    rad_mesh_destroy(NULL);
    rad_tracer_destroy(NULL);
    rad_formfactors_destroy(NULL);
    rad_image_destroy(NULL);
    rad_solution_destroy(NULL);
    rad_viewfactor_matrix_destroy(NULL);
    rad_patch_inputs_destroy(NULL);
    /* every solver's name reads back as that solver; an unknown value still has a name */
    for (int k = RAD_SOLVER_AUTO; k <= RAD_SOLVER_HIERARCHICAL; k++) {
        rad_solver back = (rad_solver)-1;
        const char *name = rad_solver_name((rad_solver)k);
        CHECK(name != NULL && rad_solver_from_name(name, &back) && back == (rad_solver)k);
    }
    rad_solver jacobi = RAD_SOLVER_AUTO;
    CHECK(rad_solver_from_name("jacobi", &jacobi) && jacobi == RAD_SOLVER_JACOBI);
    CHECK(!rad_solver_from_name("nonsense", &jacobi));
    CHECK(rad_solver_name((rad_solver)999) != NULL);
    CHECK(rad_peak_memory_bytes() > 0);
    return test_finish("test_header");
}
