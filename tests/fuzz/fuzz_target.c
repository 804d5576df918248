/*
 * fuzz_target.c - see fuzz_target.h.
 */
#include "fuzz_target.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { MOST_NAMES = 8 };

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz contract broken: %s: %s\n", what, detail);
    abort();
}

static char folder[4096];
static char file_path[4096 + 256];
static char written[MOST_NAMES][256]; /* names written so far, removed at exit */
static int written_count;

static void remove_folder(void)
{
    for (int k = 0; k < written_count; k++) {
        snprintf(file_path, sizeof(file_path), "%s/%s", folder, written[k]);
        unlink(file_path);
    }
    rmdir(folder);
}

static void remember(const char *name)
{
    for (int k = 0; k < written_count; k++)
        if (strcmp(written[k], name) == 0)
            return;
    if (written_count == MOST_NAMES || strlen(name) >= sizeof(written[0]))
        fail("too many or too long temporary file names", name);
    snprintf(written[written_count++], sizeof(written[0]), "%s", name);
}

const char *fuzz_write_file(const char *name, const uint8_t *data, size_t size)
{
    if (!folder[0]) {
        /* memory-backed /dev/shm when there is one: a file per input on a disk is ten
         * times slower */
        const char *tmp = getenv("TMPDIR");
        if (!tmp || !tmp[0])
            tmp = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
        snprintf(folder, sizeof(folder), "%s/rad-fuzz-XXXXXX", tmp);
        if (!mkdtemp(folder))
            fail("cannot make a temporary folder", folder);
        atexit(remove_folder);
    }
    remember(name);
    snprintf(file_path, sizeof(file_path), "%s/%s", folder, name);
    FILE *file = fopen(file_path, "wb");
    if (!file || (size && fwrite(data, 1, size, file) != size) || fclose(file) != 0)
        fail("cannot write the input", file_path);
    return file_path;
}

static void ignore_warning(void *user, const char *message)
{
    (void)user;
    (void)message;
}

const rad_load_options *fuzz_quiet_options(void)
{
    static const rad_load_options quiet = {ignore_warning, NULL};
    return &quiet;
}

void fuzz_check_refusal(rad_status status, const rad_error *error, const char *path)
{
    if (getenv("RAD_FUZZ_VERBOSE"))
        fprintf(stderr, "%s\n", status == RAD_OK ? "loaded" : error->message);
    if (status == RAD_OK)
        return;
    if (error->status != status)
        fail("the error record's status is not the one returned", error->message);
    if (strncmp(error->message, path, strlen(path)) != 0)
        fail("the message does not start with the file", error->message);
    if (strchr(error->message, '\n') || strchr(error->message, '\r'))
        fail("the message is more than one line", error->message);
}

static bool finite_vec3(rad_vec3 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static bool unit_rgb(rad_rgb c)
{
    return c.r >= 0 && c.r <= 1 && c.g >= 0 && c.g <= 1 && c.b >= 0 && c.b <= 1;
}

static bool emission_rgb(rad_rgb c)
{
    return c.r >= 0 && c.g >= 0 && c.b >= 0 && isfinite(c.r) && isfinite(c.g) && isfinite(c.b);
}

void fuzz_check_scene(const rad_scene *scene)
{
    for (uint32_t v = 0; v < scene->position_count; v++)
        if (!finite_vec3(scene->positions[v]))
            fail("a position is not finite", scene->source);
    for (uint32_t m = 0; m < scene->material_count; m++) {
        const rad_material *material = &scene->materials[m];
        if (!unit_rgb(material->albedo))
            fail("an albedo is outside [0,1]", material->name);
        if (!emission_rgb(material->emission))
            fail("an emission is negative or not finite", material->name);
        if (material->albedo_texture > scene->texture_count ||
            material->emission_texture > scene->texture_count)
            fail("a texture index is out of range", material->name);
    }
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const rad_triangle *tri = &scene->triangles[t];
        if (tri->vertex[0] >= scene->position_count || tri->vertex[1] >= scene->position_count ||
            tri->vertex[2] >= scene->position_count)
            fail("a vertex index is out of range", scene->source);
        if (tri->material >= scene->material_count || tri->surface >= scene->surface_count)
            fail("a material or surface index is out of range", scene->source);
        rad_vec3 a = scene->positions[tri->vertex[0]], b = scene->positions[tri->vertex[1]],
                 c = scene->positions[tri->vertex[2]];
        rad_vec3 e1 = {b.x - a.x, b.y - a.y, b.z - a.z}, e2 = {c.x - a.x, c.y - a.y, c.z - a.z};
        rad_vec3 n = {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z,
                      e1.x * e2.y - e1.y * e2.x};
        double twice_area = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
        if (!(twice_area > 0) || !isfinite(twice_area))
            fail("a triangle is degenerate or its area is not finite", scene->source);
    }
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        const rad_surface *surface = &scene->surfaces[s];
        if (surface->first_triangle > scene->triangle_count ||
            surface->triangle_count > scene->triangle_count - surface->first_triangle)
            fail("a surface's triangle range is out of range", surface->name);
        if (!(surface->emissivity > 0 && surface->emissivity <= 1))
            fail("an emissivity is outside (0,1]", surface->name);
    }
}
