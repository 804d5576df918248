/*
 * cmd_view.c - `radiosity view [SCENE|LIT.glb] [-o PAGE.html] [--open]`: one self-contained
 * HTML page that shows the lit mesh in a browser (orbit and walk, exposure, tone mapping,
 * false colour with a legend, picking). The page holds three blocks: a JSON block (the
 * source, the camera, units and, for a SCENE, each surface's name, material, area and
 * mean radiance), the lit mesh as base64 of the .glb `solve` writes, and for a SCENE the
 * surface of each of its triangles (base64 of uint32 little-endian); then the viewer's
 * script (viewer/, three.js bundled, compiled in with -DRAD_VIEWER=ON). It loads nothing
 * else: it opens from disk with no server and no network.
 *
 * A SCENE's page also holds the patch of each triangle (for the patch edges); with
 * --viewfactors the surface view-factor matrix (rad_viewfactor_matrix_compute, sparse rows);
 * with --compare B.glb a second lit mesh of the same geometry (the viewer shows A - B); with
 * --grid FILE.csv the points and lux of an `illuminance` table.
 *
 * Not the viewer (viewer/src) and not the lit mesh (rad_lit_mesh_write): this file
 * solves a SCENE as `solve` does, or checks a LIT.glb, and assembles the page.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cli.h"

#ifdef RAD_VIEWER_SCRIPT
extern const unsigned char rad_viewer_script[];
extern const size_t rad_viewer_script_size;
#endif

static const char usage[] =
    "usage: radiosity view [SCENE|LIT.glb] [-o PAGE.html] [--open] [options]\n"
    "\n"
    "Writes one HTML page that shows the lit mesh in a web browser, opened from disk with\n"
    "no server and no network: drag to orbit, W A S D to walk, an exposure slider, tone\n"
    "mapping, false colour of radiance (cd/m^2) or illuminance (lux) with its legend, and\n"
    "a click shows the surface picked (name, area, material, mean radiance). SCENE is\n"
    "solved first, as `radiosity solve` does, with the same options (none = the built-in\n"
    "Cornell box); a LIT.glb written by `radiosity solve -o LIT.glb` is shown as it is\n"
    "(no surface names). With --record FILE the page also plays the solve back: a step\n"
    "slider, play, the shooting patch outlined, the step's unshot energy and residual.\n"
    "\n"
    "  -o, --output FILE    the page (default: SCENE's base name + .html in the current\n"
    "                       folder; cornell_box.html for the built-in box)\n"
    "  --open               print the page's file:// address to open in a browser\n"
    "  --viewfactors        SCENE's surface view factors too: click surface i, see F_ij\n"
    "  --compare B.glb      a lit mesh of the same geometry (`solve -o B.glb`): shows\n"
    "                       A - B in false colour, and B\n"
    "  --grid FILE.csv      an `illuminance` table: its points' lux in false colour\n"
    CLI_TWO_SIDED_HELP
    CLI_SOLVE_HELP
    "\n"
    "Needs a build with -DRAD_VIEWER=ON (node and npm: scripts/install-deps --viewer).\n";

enum { OPT_TWO_SIDED = OPT_OWN, OPT_OPEN, OPT_VIEWFACTORS, OPT_COMPARE, OPT_GRID, OPT_COUNT };

static const cli_option options[OPT_COUNT] = {
    CLI_BASE_OPTIONS,
    CLI_FORMFACTOR_OPTIONS,
    CLI_SOLVE_OPTIONS,
    CLI_SCENE_OPTIONS,
    [OPT_TWO_SIDED] = {"two-sided", 0, true},
    [OPT_OPEN] = {"open", 0, false},
    [OPT_VIEWFACTORS] = {"viewfactors", 0, false},
    [OPT_COMPARE] = {"compare", 0, true},
    [OPT_GRID] = {"grid", 0, true},
};

#ifdef RAD_VIEWER_SCRIPT
/* ---- the page, built in memory and written at once ---------------------------------- */

typedef struct page {
    char *data;
    size_t length, capacity;
    bool failed; /* out of memory: everything after is dropped */
} page;

static void page_append(page *p, const void *bytes, size_t count)
{
    if (p->failed)
        return;
    if (p->length + count + 1 > p->capacity) {
        size_t capacity = p->capacity ? p->capacity : 1 << 16;
        while (capacity < p->length + count + 1)
            capacity *= 2;
        char *grown = rad_resize_array(p->data, capacity, 1);
        if (!grown) {
            p->failed = true;
            return;
        }
        p->data = grown;
        p->capacity = capacity;
    }
    memcpy(p->data + p->length, bytes, count);
    p->length += count;
    p->data[p->length] = '\0';
}

static void page_text(page *p, const char *text) { page_append(p, text, strlen(text)); }

static void page_printf(page *p, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void page_printf(page *p, const char *format, ...)
{
    char text[512];
    va_list args;
    va_start(args, format);
    int n = vsnprintf(text, sizeof(text), format, args);
    va_end(args);
    if (n > 0)
        page_append(p, text, (size_t)n < sizeof(text) ? (size_t)n : sizeof(text) - 1);
}

static void page_base64(page *p, const unsigned char *bytes, size_t count)
{
    static const char alphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char chunk[4096];
    size_t used = 0;
    for (size_t i = 0; i < count; i += 3) {
        uint32_t triple = (uint32_t)bytes[i] << 16;
        if (i + 1 < count)
            triple |= (uint32_t)bytes[i + 1] << 8;
        if (i + 2 < count)
            triple |= bytes[i + 2];
        chunk[used++] = alphabet[(triple >> 18) & 63];
        chunk[used++] = alphabet[(triple >> 12) & 63];
        chunk[used++] = i + 1 < count ? alphabet[(triple >> 6) & 63] : '=';
        chunk[used++] = i + 2 < count ? alphabet[triple & 63] : '=';
        if (used + 4 > sizeof(chunk)) {
            page_append(p, chunk, used);
            used = 0;
        }
    }
    page_append(p, chunk, used);
}

/* A JSON string; '<', '>' and '&' escaped too, so no text can close the script block. */
static void page_json_string(page *p, const char *text)
{
    page_text(p, "\"");
    for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
        if (*c < 0x20 || *c == '"' || *c == '\\' || *c == '<' || *c == '>' || *c == '&')
            page_printf(p, "\\u%04x", *c);
        else
            page_append(p, c, 1);
    }
    page_text(p, "\"");
}

/* Text inside an HTML element (the title). */
static void page_html_text(page *p, const char *text)
{
    for (const char *c = text; *c; c++) {
        if (*c == '<')
            page_text(p, "&lt;");
        else if (*c == '>')
            page_text(p, "&gt;");
        else if (*c == '&')
            page_text(p, "&amp;");
        else
            page_append(p, c, 1);
    }
}

static void page_vec3(page *p, rad_vec3 v)
{
    page_printf(p, "[%.9g,%.9g,%.9g]", v.x, v.y, v.z);
}

/* ---- the input ------------------------------------------------------------------------ */

/* Reads a whole file; false after printing a one-line error naming it. */
static bool read_whole_file(const char *path, unsigned char **bytes, size_t *size)
{
    *bytes = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        cli_error("%s: cannot open: %s", path, strerror(errno));
        return false;
    }
    size_t capacity = 1 << 16, length = 0;
    unsigned char *data = rad_alloc_array(capacity, 1);
    while (data) {
        size_t got = fread(data + length, 1, capacity - length, f);
        length += got;
        if (length < capacity)
            break;
        unsigned char *grown = capacity <= SIZE_MAX / 2 ? rad_resize_array(data, capacity * 2, 1) : NULL;
        if (!grown) {
            free(data);
            data = NULL;
            break;
        }
        data = grown;
        capacity *= 2;
    }
    bool ok = data && !ferror(f);
    fclose(f);
    if (!ok) {
        cli_error("%s: cannot read%s", path, data ? "" : ": out of memory");
        free(data);
        return false;
    }
    *bytes = data;
    *size = length;
    return true;
}

static uint32_t get_u32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static bool has_glb_extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    return dot && strcasecmp(dot, ".glb") == 0;
}

/* True when the .glb's JSON chunk names a _RADIANCE attribute: a lit mesh, not a scene. */
static bool glb_is_lit_mesh(const unsigned char *bytes, size_t size)
{
    if (size < 20 || get_u32(bytes) != 0x46546C67u || get_u32(bytes + 16) != 0x4E4F534Au)
        return false;
    uint32_t json_length = get_u32(bytes + 12);
    if (json_length > size - 20)
        return false;
    const char needle[] = "\"_RADIANCE\"";
    for (size_t i = 20; i + sizeof(needle) - 1 <= 20 + (size_t)json_length; i++)
        if (memcmp(bytes + i, needle, sizeof(needle) - 1) == 0)
            return true;
    return false;
}

/* The accessor `index` of a float VEC3 or uint32 SCALAR lies inside the binary chunk and
 * has `count` elements (count 0: take its own); returns its data, or NULL. */
static const unsigned char *glb_accessor(const cJSON *root, const cJSON *index_item,
                                         int component, const char *type, size_t bin_length,
                                         const unsigned char *bin, uint32_t *count)
{
    if (!cJSON_IsNumber(index_item))
        return NULL;
    const cJSON *accessor =
        cJSON_GetArrayItem(cJSON_GetObjectItem(root, "accessors"), index_item->valueint);
    const cJSON *view_item = cJSON_GetObjectItem(accessor, "bufferView");
    const cJSON *n = cJSON_GetObjectItem(accessor, "count");
    const cJSON *kind = cJSON_GetObjectItem(accessor, "type");
    if (!cJSON_IsNumber(view_item) || !cJSON_IsNumber(n) || n->valuedouble < 1 ||
        n->valuedouble > UINT32_MAX || !cJSON_IsString(kind) ||
        strcmp(kind->valuestring, type) != 0 ||
        cJSON_GetNumberValue(cJSON_GetObjectItem(accessor, "componentType")) != component ||
        cJSON_GetObjectItem(accessor, "byteOffset"))
        return NULL;
    const cJSON *view =
        cJSON_GetArrayItem(cJSON_GetObjectItem(root, "bufferViews"), view_item->valueint);
    double offset = cJSON_GetNumberValue(cJSON_GetObjectItem(view, "byteOffset"));
    if (isnan(offset))
        offset = 0;
    double length = cJSON_GetNumberValue(cJSON_GetObjectItem(view, "byteLength"));
    double need = n->valuedouble * (strcmp(type, "VEC3") == 0 ? 12 : 4);
    if (!view || offset < 0 || fmod(offset, 4) != 0 || !(length >= need) ||
        offset + need > (double)bin_length || (*count && (uint32_t)n->valuedouble != *count))
        return NULL;
    *count = (uint32_t)n->valuedouble;
    return bin + (size_t)offset;
}

/* Checks a lit mesh .glb as the viewer reads it (glb.js): the chunks, the attributes'
 * accessors, every float finite and every index in range. False after printing one line
 * naming the file. */
static bool check_lit_mesh(const char *path, const unsigned char *bytes, size_t size,
                           uint32_t *triangles)
{
    if (size < 28 || get_u32(bytes + 8) != size) {
        cli_error("%s: a truncated .glb: its header says %u bytes, the file has %zu", path,
                  size >= 12 ? get_u32(bytes + 8) : 0, size);
        return false;
    }
    uint32_t json_length = get_u32(bytes + 12);
    size_t bin_at = 20 + (size_t)json_length;
    if (bin_at + 8 > size || get_u32(bytes + bin_at + 4) != 0x004E4942u ||
        get_u32(bytes + bin_at) > size - bin_at - 8) {
        cli_error("%s: a .glb without its binary chunk", path);
        return false;
    }
    size_t bin_length = get_u32(bytes + bin_at);
    const unsigned char *bin = bytes + bin_at + 8;
    cJSON *root = cJSON_ParseWithLength((const char *)bytes + 20, json_length);
    const cJSON *primitive = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(root, "meshes"), 0),
                            "primitives"),
        0);
    const cJSON *attributes = cJSON_GetObjectItem(primitive, "attributes");
    const char *problem = NULL;
    uint32_t vertices = 0, indices = 0;
    const char *names[] = {"POSITION", "_RADIANCE", "NORMAL", "_ILLUMINANCE"};
    if (!root || !attributes)
        problem = "no mesh in its JSON";
    for (int k = 0; !problem && k < 4; k++) {
        const cJSON *item = cJSON_GetObjectItem(attributes, names[k]);
        if (!item && k >= 2)
            continue; /* NORMAL and _ILLUMINANCE are optional */
        const unsigned char *data = glb_accessor(root, item, 5126, "VEC3", bin_length, bin,
                                                 &vertices);
        if (!data) {
            problem = names[k];
            break;
        }
        for (size_t i = 0; i < (size_t)vertices * 3; i++) {
            uint32_t u = get_u32(data + 4 * i);
            float value;
            memcpy(&value, &u, sizeof(value));
            if (!isfinite(value)) {
                cli_error("%s: %s of vertex %zu is not a finite number", path, names[k], i / 3);
                cJSON_Delete(root);
                return false;
            }
        }
    }
    const unsigned char *index_data = NULL;
    if (!problem) {
        index_data = glb_accessor(root, cJSON_GetObjectItem(primitive, "indices"), 5125,
                                  "SCALAR", bin_length, bin, &indices);
        if (!index_data || indices % 3 != 0)
            problem = "triangle indices";
    }
    cJSON_Delete(root);
    if (problem) {
        cli_error("%s: not a lit mesh of `radiosity solve`: its %s %s", path, problem,
                  strchr(problem, ' ') ? "are missing or malformed" : "is missing or malformed");
        return false;
    }
    for (uint32_t i = 0; i < indices; i++)
        if (get_u32(index_data + 4 * (size_t)i) >= vertices) {
            cli_error("%s: triangle index %u is %u, past the %u vertices", path, i,
                      get_u32(index_data + 4 * (size_t)i), vertices);
            return false;
        }
    *triangles = indices / 3;
    return true;
}

/* ---- a scene, solved ------------------------------------------------------------------ */

/* The lit mesh of the solution as .glb bytes (written to a temporary folder, read back),
 * and the solution's patch of each of its triangles (*patch_of, malloc'ed). */
static bool lit_mesh_bytes(const cli_solved *solved, const cli_shared *shared,
                           unsigned char **bytes, size_t *size, uint32_t **patch_of,
                           uint32_t *patch_count)
{
    const char *tmp = getenv("TMPDIR");
    char folder[4096], file[4200];
    snprintf(folder, sizeof(folder), "%s/radiosity-view-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(folder)) {
        cli_error("%s: cannot make a temporary folder: %s", folder, strerror(errno));
        return false;
    }
    snprintf(file, sizeof(file), "%s/lit.glb", folder);
    /* the light computed at the vertices, as `solve` and `render` take it by default */
    rad_lit_mesh_options write = {.inputs = solved->inputs,
                                  .scene = solved->scene,
                                  .seed = shared->seed,
                                  .threads = shared->threads,
                                  .triangle_patches = patch_of,
                                  .triangle_patch_count = patch_count};
    rad_error error = {0};
    bool ok = rad_lit_mesh_write(solved->mesh, solved->B, file, &write, &error) == RAD_OK;
    if (!ok)
        cli_error("%s", error.message);
    ok = ok && read_whole_file(file, bytes, size);
    remove(file);
    rmdir(folder);
    return ok;
}

/* The JSON of each surface: name, its materials, area (front patches: a two-sided
 * surface's cells once) and the area-weighted mean radiance B / pi over all its patches. */
static bool page_surfaces(page *p, const rad_scene *scene, const rad_mesh *mesh,
                          const rad_rgb *B)
{
    const double pi = 3.14159265358979323846;
    uint32_t n = scene->surface_count;
    double *area = rad_alloc_array(n ? n : 1, sizeof(*area));
    double *weight = rad_alloc_array(n ? n : 1, sizeof(*weight));
    rad_rgb *sum = rad_alloc_array(n ? n : 1, sizeof(*sum));
    uint32_t *material = rad_alloc_array(n ? n : 1, sizeof(*material)); /* 1 + first */
    bool *several = rad_alloc_array(n ? n : 1, sizeof(*several));
    bool ok = area && weight && sum && material && several;
    for (uint32_t i = 0; ok && i < mesh->patch_count; i++) {
        const rad_patch *patch = &mesh->patches[i];
        uint32_t s = patch->surface;
        if (patch->twin == 0 || i < patch->twin - 1)
            area[s] += patch->area;
        weight[s] += patch->area;
        sum[s].r += patch->area * B[i].r / pi;
        sum[s].g += patch->area * B[i].g / pi;
        sum[s].b += patch->area * B[i].b / pi;
        if (material[s] == 0)
            material[s] = patch->material + 1;
        else if (material[s] != patch->material + 1)
            several[s] = true;
    }
    page_text(p, "\"surfaces\":[");
    for (uint32_t s = 0; ok && s < n; s++) {
        double w = weight[s] > 0 ? weight[s] : 1;
        page_text(p, s ? ",{\"name\":" : "{\"name\":");
        page_json_string(p, scene->surfaces[s].name);
        page_text(p, ",\"material\":");
        char names[300] = "";
        if (material[s])
            snprintf(names, sizeof(names), "%s%s", scene->materials[material[s] - 1].name,
                     several[s] ? " and others" : "");
        page_json_string(p, names);
        page_printf(p, ",\"area\":%.9g,\"radiance\":[%.9g,%.9g,%.9g]}", area[s], sum[s].r / w,
                    sum[s].g / w, sum[s].b / w);
    }
    page_text(p, "],");
    free(area);
    free(weight);
    free(sum);
    free(material);
    free(several);
    if (!ok)
        cli_error("view: out of memory for the surface table");
    return ok;
}

/* The surface of each lit-mesh triangle, base64 of uint32 little-endian, from the patch of
 * each (patch_of, count of them, as the lit mesh's writer gave them). */
static bool page_triangle_surfaces(page *p, const rad_mesh *mesh, const uint32_t *patch_of,
                                   uint32_t count, uint32_t triangles)
{
    if (count != triangles) {
        cli_error("view: the lit mesh has %u triangles, its patch table %u", triangles, count);
        return false;
    }
    unsigned char *bytes = rad_alloc_array(count ? count : 1, 4);
    if (!bytes) {
        cli_error("view: out of memory for the surfaces of %u triangles", count);
        return false;
    }
    for (uint32_t t = 0; t < count; t++) {
        uint32_t s = mesh->patches[patch_of[t]].surface;
        for (int k = 0; k < 4; k++)
            bytes[4 * (size_t)t + k] = (unsigned char)(s >> (8 * k));
    }
    page_text(p, "<script type=\"application/octet-stream\" id=\"radiosity-triangle-surface\">");
    page_base64(p, bytes, 4 * (size_t)count);
    page_text(p, "</script>\n");
    /* the patch of each triangle: the viewer draws lines where it changes */
    for (uint32_t t = 0; t < count; t++)
        for (int k = 0; k < 4; k++)
            bytes[4 * (size_t)t + k] = (unsigned char)(patch_of[t] >> (8 * k));
    page_text(p, "<script type=\"application/octet-stream\" id=\"radiosity-triangle-patch\">");
    page_base64(p, bytes, 4 * (size_t)count);
    page_text(p, "</script>\n");
    free(bytes);
    return true;
}

/* `--record FILE` (written by this run's solve): the record's JSON, checked against the
 * mesh, embedded for the viewer's playback (viewer/src/playback.js) with "</" written as
 * "<\/" so that no text ends the script element early (the patch of each triangle, which
 * playback colours by, is page_triangle_surfaces' block). */
static bool page_record(page *p, const char *path, const rad_mesh *mesh)
{
    unsigned char *text = NULL;
    size_t size = 0;
    if (!read_whole_file(path, &text, &size))
        return false;
    cJSON *root = cJSON_ParseWithLength((const char *)text, size);
    const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(root, "snapshots");
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(root, "format");
    size_t expected = 4 * ((12 * (size_t)mesh->patch_count + 2) / 3);
    bool ok = cJSON_IsString(format) && strcmp(format->valuestring, "radiosity-record") == 0 &&
              cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(root, "patches")) ==
                  mesh->patch_count &&
              cJSON_GetArraySize(snapshots) > 0;
    const cJSON *snapshot;
    cJSON_ArrayForEach(snapshot, snapshots)
    {
        const cJSON *radiosity = cJSON_GetObjectItemCaseSensitive(snapshot, "radiosity");
        if (!cJSON_IsString(radiosity) || strlen(radiosity->valuestring) != expected)
            ok = false;
    }
    cJSON_Delete(root);
    if (!ok) {
        free(text);
        cli_error("%s: not a record of this scene's %u patches", path, mesh->patch_count);
        return false;
    }
    page_text(p, "<script type=\"application/json\" id=\"radiosity-record\">");
    size_t from = 0;
    for (size_t i = 1; i < size; i++)
        if (text[i] == '/' && text[i - 1] == '<') {
            page_append(p, text + from, i - from);
            page_text(p, "\\");
            from = i;
        }
    page_append(p, text + from, size - from);
    page_text(p, "</script>\n");
    free(text);
    return true;
}

/* ---- view factors, a second solution, an illuminance grid ------------------------------ */

static void put_u32(unsigned char *b, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        b[k] = (unsigned char)(v >> (8 * k));
}

/* The surface view-factor matrix of the solved scene, as a block the viewer reads
 * (viewfactor_row.js): uint32 n and nonzeros, uint32 row_start[n + 1], uint32
 * column[nonzeros], zero padding to a multiple of 8 bytes, float64 value[nonzeros], all
 * little-endian. */
static bool page_viewfactors(page *p, const rad_scene *scene, const cli_shared *shared)
{
    rad_viewfactor_options vf = {0};
    CLI_SET_RUN_OPTIONS(vf, *shared);
    rad_viewfactor_matrix *matrix = NULL;
    rad_viewfactor_report report = {0};
    rad_error error = {0};
    cli_progress_mark();
    if (rad_viewfactor_matrix_compute(scene, &vf, &matrix, &report, &error) != RAD_OK) {
        cli_progress_end();
        cli_error("%s", error.message);
        return false;
    }
    cli_progress_end();
    uint64_t nonzeros = matrix->row_start[matrix->n];
    if (nonzeros > UINT32_MAX / 16 || matrix->n > UINT32_MAX / 8) {
        cli_error("%s: %llu view factors are too many for a page", scene->source,
                  (unsigned long long)nonzeros);
        rad_viewfactor_matrix_destroy(matrix);
        return false;
    }
    size_t integers = 2 + (size_t)matrix->n + 1 + (size_t)nonzeros;
    size_t values_at = (4 * integers + 7) / 8 * 8;
    size_t size = values_at + 8 * (size_t)nonzeros;
    unsigned char *bytes = rad_alloc_array(size, 1); /* zeroed: the padding */
    if (!bytes) {
        cli_error("view: out of memory for %llu view factors", (unsigned long long)nonzeros);
        rad_viewfactor_matrix_destroy(matrix);
        return false;
    }
    put_u32(bytes, matrix->n);
    put_u32(bytes + 4, (uint32_t)nonzeros);
    for (uint32_t i = 0; i <= matrix->n; i++)
        put_u32(bytes + 8 + 4 * (size_t)i, (uint32_t)matrix->row_start[i]);
    unsigned char *columns = bytes + 8 + 4 * ((size_t)matrix->n + 1);
    for (uint64_t k = 0; k < nonzeros; k++) {
        put_u32(columns + 4 * k, matrix->column[k]);
        uint64_t bits;
        memcpy(&bits, &matrix->value[k], sizeof(bits));
        for (int b = 0; b < 8; b++)
            bytes[values_at + 8 * k + b] = (unsigned char)(bits >> (8 * b));
    }
    page_text(p, "<script type=\"application/octet-stream\" id=\"radiosity-viewfactors\">");
    page_base64(p, bytes, size);
    page_text(p, "</script>\n");
    free(bytes);
    rad_viewfactor_matrix_destroy(matrix);
    return true;
}

/* The positions and triangle indices of a lit mesh check_lit_mesh accepted. */
static void lit_mesh_geometry(const unsigned char *bytes, const unsigned char **position,
                              uint32_t *vertices, const unsigned char **index, uint32_t *indices)
{
    uint32_t json_length = get_u32(bytes + 12);
    size_t bin_at = 20 + (size_t)json_length;
    cJSON *root = cJSON_ParseWithLength((const char *)bytes + 20, json_length);
    const cJSON *primitive = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(root, "meshes"), 0),
                            "primitives"),
        0);
    *vertices = *indices = 0;
    *position = glb_accessor(root, cJSON_GetObjectItem(cJSON_GetObjectItem(primitive, "attributes"), "POSITION"),
                             5126, "VEC3", get_u32(bytes + bin_at), bytes + bin_at + 8, vertices);
    *index = glb_accessor(root, cJSON_GetObjectItem(primitive, "indices"), 5125, "SCALAR",
                          get_u32(bytes + bin_at), bytes + bin_at + 8, indices);
    cJSON_Delete(root);
}

/* B (a lit mesh, checked) has A's vertices and triangles, bit for bit; else one line. */
static bool same_geometry(const char *path_b, const unsigned char *a, const unsigned char *b)
{
    const unsigned char *position_a, *position_b, *index_a, *index_b;
    uint32_t vertices_a, vertices_b, indices_a, indices_b;
    lit_mesh_geometry(a, &position_a, &vertices_a, &index_a, &indices_a);
    lit_mesh_geometry(b, &position_b, &vertices_b, &index_b, &indices_b);
    if (vertices_a != vertices_b || indices_a != indices_b) {
        cli_error("%s: --compare: %u vertices and %u triangles, the first mesh %u and %u: "
                  "solve both with the same scene, patch size and lights",
                  path_b, vertices_b, indices_b / 3, vertices_a, indices_a / 3);
        return false;
    }
    if (memcmp(position_a, position_b, 12 * (size_t)vertices_a) != 0 ||
        memcmp(index_a, index_b, 4 * (size_t)indices_a) != 0) {
        cli_error("%s: --compare: the same counts but other vertices or triangles than the "
                  "first mesh: solve both with the same scene, patch size and lights",
                  path_b);
        return false;
    }
    return true;
}

/* The table `radiosity illuminance` writes (header x,y,z,nx,ny,nz,E_r,E_g,E_b,E[,...],
 * then a row per point) as the info block's "grid": its file, the points, normals and E
 * in lux. False after one line naming the file (and line). */
static bool page_grid(page *p, const char *path)
{
    unsigned char *bytes = NULL;
    size_t size = 0;
    if (!read_whole_file(path, &bytes, &size))
        return false;
    char *text = rad_resize_array(bytes, size + 1, 1);
    if (!text) {
        free(bytes);
        cli_error("%s: out of memory", path);
        return false;
    }
    text[size] = '\0';
    static const char header[] = "x,y,z,nx,ny,nz,E_r,E_g,E_b,E";
    bool ok = strncmp(text, header, sizeof(header) - 1) == 0;
    if (!ok)
        cli_error("%s:1: not a table of `radiosity illuminance` (its first line is %s...)",
                  path, header);
    page points = {0}, normals = {0}, lux = {0};
    uint32_t line_number = 1, count = 0;
    char *line = strchr(text, '\n');
    line = line ? line + 1 : text + size;
    while (ok && *line) {
        line_number++;
        char *end = strchr(line, '\n');
        char *next = end ? end + 1 : line + strlen(line);
        if (end)
            *end = '\0';
        if (*line == '\0' || *line == '\r') {
            line = next;
            continue;
        }
        double v[10];
        char *c = line;
        for (int k = 0; ok && k < 10; k++) {
            char *after;
            errno = 0;
            v[k] = strtod(c, &after);
            if (after == c || errno == ERANGE || !isfinite(v[k]) ||
                (k < 9 && *after != ',') ||
                (k == 9 && *after != ',' && *after != '\0' && *after != '\r'))
                ok = false;
            c = after + 1;
        }
        if (!ok || v[9] < 0 || (v[3] == 0 && v[4] == 0 && v[5] == 0)) {
            ok = false;
            cli_error("%s:%u: not a row x,y,z,nx,ny,nz,E_r,E_g,E_b,E of finite numbers (a "
                      "non-zero normal, E >= 0)",
                      path, line_number);
            break;
        }
        page_printf(&points, "%s%.9g,%.9g,%.9g", count ? "," : "", v[0], v[1], v[2]);
        page_printf(&normals, "%s%.6g,%.6g,%.6g", count ? "," : "", v[3], v[4], v[5]);
        page_printf(&lux, "%s%.9g", count ? "," : "", v[9]);
        count++;
        line = next;
    }
    if (ok && count == 0) {
        ok = false;
        cli_error("%s: the table has no points", path);
    }
    if (ok && (points.failed || normals.failed || lux.failed)) {
        ok = false;
        cli_error("%s: out of memory for %u points", path, count);
    }
    if (ok) {
        page_text(p, "\"grid\":{\"source\":");
        page_json_string(p, path);
        page_text(p, ",\"points\":[");
        page_append(p, points.data, points.length);
        page_text(p, "],\"normals\":[");
        page_append(p, normals.data, normals.length);
        page_text(p, "],\"lux\":[");
        page_append(p, lux.data, lux.length);
        page_text(p, "]},");
    }
    free(points.data);
    free(normals.data);
    free(lux.data);
    free(text);
    return ok;
}

/* ---- the command ---------------------------------------------------------------------- */

/* The units of the shown values, by `render --false-colour`'s rule (README, "Units."):
 * cd/m^2 and lux when every light of the scene is photometric; "relative" with emitting
 * surfaces alone (Ke in the file's own unit), a light in no known unit or an environment
 * map. A lit .glb does not say: "relative". */
static void page_units(page *p, const rad_scene *scene)
{
    bool photometric = scene && scene->light_count > 0;
    for (uint32_t l = 0; scene && l < scene->light_count; l++)
        photometric = photometric && !scene->lights[l].unit_unknown &&
                      scene->lights[l].type != RAD_LIGHT_ENVIRONMENT;
    page_text(p, photometric ? ",\"radiance_unit\":\"cd/m\\u00b2\",\"illuminance_unit\":\"lux\","
                             : ",\"radiance_unit\":\"relative\",\"illuminance_unit\":\"relative\",");
}

/* SCENE's base name + .html, or cornell_box.html. */
static void default_output(const char *input, char *out, size_t size)
{
    if (!input) {
        snprintf(out, size, "cornell_box.html");
        return;
    }
    const char *slash = strrchr(input, '/');
    const char *base = slash ? slash + 1 : input;
    const char *dot = strrchr(base, '.');
    int length = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, size, "%.*s.html", length, base);
}

/* A lit mesh is shown as it is: the options that make one do nothing (a warning each). */
static void warn_ignored(const cli_args *args, const char *input)
{
    for (int k = OPT_PATCH_SIZE; k < OPT_COUNT; k++)
        if (args->value[k] && options[k].name && k != OPT_OPEN && k != OPT_COMPARE &&
            k != OPT_GRID && (k < OPT_EYE || k > OPT_EXR_FLOAT))
            cli_warn("%s: a lit mesh, shown as it is: --%s is ignored", input, options[k].name);
}
#endif

int command_view(int argc, char **argv)
{
    cli_args args;
    cli_shared shared;
    cli_solve solve;
    const char *input = NULL;
    int exit_code;
    if (!cli_begin("view", usage, argc, argv, options, OPT_COUNT, &args, &shared, &exit_code))
        return exit_code;
    if (!cli_scene_argument("view", &args, &input) || !cli_parse_solve(&args, &shared, &solve))
        return EXIT_USAGE;
    cli_parse_two_sided(&args, OPT_TWO_SIDED, &solve.two_sided);
#ifndef RAD_VIEWER_SCRIPT
    cli_error("view: this build has no viewer: configure with -DRAD_VIEWER=ON (needs node "
              "and npm: scripts/install-deps --viewer) and build again");
    return EXIT_ERROR;
#else
    char default_path[4096];
    default_output(input, default_path, sizeof(default_path));
    const char *output = shared.output ? shared.output : default_path;
    const char *slash = strrchr(output, '/');
    const char *dot = strrchr(slash ? slash + 1 : output, '.');
    if (!dot || (strcasecmp(dot, ".html") != 0 && strcasecmp(dot, ".htm") != 0)) {
        cli_error("%s: the page is HTML: give -o PAGE.html", output);
        return EXIT_USAGE;
    }
    const char *outputs[] = {output, shared.stats_path, solve.save_solution_path};
    if (!cli_outputs_writable(outputs, 3))
        return EXIT_ERROR;

    double t0 = rad_clock_seconds();
    unsigned char *glb = NULL;
    size_t glb_size = 0;
    bool lit_input = false;
    if (input && has_glb_extension(input)) {
        if (!read_whole_file(input, &glb, &glb_size))
            return EXIT_ERROR;
        lit_input = glb_is_lit_mesh(glb, glb_size);
        if (!lit_input) {
            free(glb);
            glb = NULL;
        }
    }
    if (lit_input && args.value[OPT_VIEWFACTORS]) {
        cli_error("%s: --viewfactors needs the SCENE (a lit mesh has no surfaces)", input);
        free(glb);
        return EXIT_USAGE;
    }
    uint32_t triangles = 0, compare_triangles = 0;
    uint32_t *patch_of = NULL, patch_count = 0; /* the solution's patch of each triangle */
    const char *compare_path = args.value[OPT_COMPARE];
    unsigned char *compare_glb = NULL;
    size_t compare_size = 0;
    page html = {0};
    cli_solved solved;
    memset(&solved, 0, sizeof(solved));
    exit_code = EXIT_ERROR;
    if (lit_input) {
        if (!check_lit_mesh(input, glb, glb_size, &triangles))
            goto done;
        warn_ignored(&args, input);
    } else {
        rad_error error = {0};
        if (cli_solve_scene(input, &shared, &solve, &solved, &error) != RAD_OK) {
            exit_code = cli_failed(&error);
            goto done;
        }
        cli_progress_end();
        if (!lit_mesh_bytes(&solved, &shared, &glb, &glb_size, &patch_of, &patch_count) ||
            !check_lit_mesh("the lit mesh", glb, glb_size, &triangles))
            goto done;
    }
    if (compare_path) {
        if (!read_whole_file(compare_path, &compare_glb, &compare_size))
            goto done;
        if (!glb_is_lit_mesh(compare_glb, compare_size)) {
            cli_error("%s: --compare: not a lit mesh of `radiosity solve -o B.glb`", compare_path);
            goto done;
        }
        if (!check_lit_mesh(compare_path, compare_glb, compare_size, &compare_triangles) ||
            !same_geometry(compare_path, glb, compare_glb))
            goto done;
    }

    const char *source = lit_input ? input : solved.scene->source;
    page_text(&html, "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                     "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                     "<title>radiosity: ");
    page_html_text(&html, source);
    page_text(&html, "</title>\n</head>\n<body>\n"
                     "<script type=\"application/json\" id=\"radiosity-info\">{\"source\":");
    page_json_string(&html, source);
    page_units(&html, lit_input ? NULL : solved.scene);
    if (!lit_input) {
        const rad_scene *scene = solved.scene;
        page_printf(&html, "\"unit_metres\":%.9g,", scene->unit_metres);
        if (scene->has_camera) {
            page_text(&html, "\"camera\":{\"eye\":");
            page_vec3(&html, scene->camera.eye);
            page_text(&html, ",\"target\":");
            page_vec3(&html, scene->camera.target);
            page_text(&html, ",\"up\":");
            page_vec3(&html, scene->camera.up);
            page_printf(&html, ",\"fov\":%.9g},", scene->camera.fov_degrees);
        }
        if (!page_surfaces(&html, scene, solved.mesh, solved.B))
            goto done;
    }
    if (args.value[OPT_GRID] && !page_grid(&html, args.value[OPT_GRID]))
        goto done;
    if (compare_path) {
        page_text(&html, "\"compare_source\":");
        page_json_string(&html, compare_path);
        page_text(&html, ",");
    }
    page_printf(&html, "\"triangles\":%u}</script>\n", triangles);
    page_text(&html, "<script type=\"application/octet-stream\" id=\"radiosity-glb\">");
    page_base64(&html, glb, glb_size);
    page_text(&html, "</script>\n");
    if (!lit_input &&
        !page_triangle_surfaces(&html, solved.mesh, patch_of, patch_count, triangles))
        goto done;
    if (!lit_input && solve.record_path &&
        !page_record(&html, solve.record_path, solved.mesh))
        goto done;
    if (compare_path) {
        page_text(&html, "<script type=\"application/octet-stream\" id=\"radiosity-compare-glb\">");
        page_base64(&html, compare_glb, compare_size);
        page_text(&html, "</script>\n");
    }
    if (args.value[OPT_VIEWFACTORS] && !page_viewfactors(&html, solved.scene, &shared))
        goto done;
    page_text(&html, "<script>");
    page_append(&html, rad_viewer_script, rad_viewer_script_size);
    page_text(&html, "</script>\n</body>\n</html>\n");
    if (html.failed) {
        cli_error("%s: out of memory for the page", output);
        goto done;
    }
    rad_error error = {0};
    if (rad_write_file_atomic(output, html.data, html.length, &error) != RAD_OK) {
        exit_code = cli_failed(&error);
        goto done;
    }
    double t1 = rad_clock_seconds();
    if (args.value[OPT_OPEN]) {
        char folder[4096];
        if (output[0] != '/' && getcwd(folder, sizeof(folder)))
            printf("file://%s/%s\n", folder, output);
        else
            printf("file://%s\n", output);
    }
    cli_stats stats;
    stats_begin(&stats);
    if (!lit_input)
        cli_solved_stats(&solved, &solve, &stats);
    stats_integer(&stats, "triangles_shown", triangles);
    stats_integer(&stats, "page_bytes", html.length);
    stats_number(&stats, "seconds_total", t1 - t0);
    exit_code = cli_finish(&stats, shared.stats_path, "view: %u triangles, %.1f MB, %.2f s: wrote %s",
                           triangles, (double)html.length / 1e6, t1 - t0, output);
done:
    cli_progress_end();
    free(html.data);
    free(glb);
    free(patch_of);
    free(compare_glb);
    if (!lit_input)
        cli_solved_free(&solved);
    return exit_code;
#endif
}
