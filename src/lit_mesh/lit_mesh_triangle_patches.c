/*
 * lit_mesh_triangle_patches.c - rad_lit_mesh_triangle_patches: which patch each triangle of
 * the lit mesh comes from, so a viewer can tell the surface, material and area under a
 * picked triangle. Not the lit mesh itself (lit_mesh.c writes it): both take their
 * triangles from the same display mesh (display_mesh_build), so the order is the file's.
 */
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "reconstruct/display_mesh.h"

rad_status rad_lit_mesh_triangle_patches(const rad_mesh *mesh, uint32_t **patch_of,
                                         uint32_t *triangle_count, rad_error *error)
{
    *patch_of = NULL;
    *triangle_count = 0;
    display_mesh shown = {0};
    rad_status status = display_mesh_build(mesh, true, &shown, error);
    if (status != RAD_OK)
        return status;
    uint32_t *out = rad_alloc_array(shown.triangle_count ? shown.triangle_count : 1, sizeof(*out));
    if (!out) {
        status = rad_fail(error, RAD_ERR_NOMEM, "out of memory for the patches of %u lit-mesh "
                                                "triangles",
                          shown.triangle_count);
    } else {
        memcpy(out, shown.patch_of, (size_t)shown.triangle_count * sizeof(*out));
        *patch_of = out;
        *triangle_count = shown.triangle_count;
    }
    display_mesh_free(&shown);
    return status;
}
