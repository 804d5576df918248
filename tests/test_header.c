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
    for (int s = RAD_OK; s <= RAD_ERR_INTERNAL; s++)
        CHECK(strlen(rad_status_name((rad_status)s)) > 0);
    CHECK(strcmp(rad_status_name(RAD_OK), "success") == 0);
    /* destroying NULL is harmless for every object */
    rad_scene_destroy(NULL);
    rad_mesh_destroy(NULL);
    rad_tracer_destroy(NULL);
    rad_formfactors_destroy(NULL);
    rad_image_destroy(NULL);
    CHECK(rad_peak_memory_bytes() > 0);
    return test_finish("test_header");
}
