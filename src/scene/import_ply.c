/*
 * import_ply.c - reading a PLY 1.0 file (ASCII, binary little- and big-endian) into a
 * scene through the scene builder, without Assimp (whose 5.2 reader aborted on malformed
 * ASCII bodies; tests/fuzz).
 *
 * The header is ply_header.c's. The body is read row by row, every element in the header's
 * order, lists included, so an element this reader does not use (edge, anything) is
 * skipped by its properties' sizes. What it keeps:
 * - the first `vertex` element: its scalar properties x, y, z, of any numeric type (z may
 *   be absent: 0, a flat file, as Assimp read it). Normals, texture coordinates and
 *   per-vertex colours are read past and dropped: Assimp 5.2 did not turn colours into
 *   albedo either (the scene's albedo is per material; a coloured PLY is grey).
 * - the first `face` element's list `vertex_indices` (or `vertex_index`), any count and
 *   index type: each polygon is fanned from its first corner, (0,k,k+1), convex assumed;
 *   Assimp's triangulation gives the same fan for a convex quad and, for larger convex
 *   polygons, another set of n - 2 triangles of the same area. A face of 1 or 2 corners
 *   has no area: skipped, with one warning for the file. A face's own material_index is
 *   not used (Assimp 5.2 did not either).
 * - the first row of a `material` element: diffuse_red/green/blue as albedo,
 *   specular_red/green/blue as specular reflectance, specular_power as the Phong exponent,
 *   ambient_* only for the warning every importer gives (an ambient colour above 1 and no
 *   emission); a whole-number colour is divided by its type's largest value (uchar 255).
 *   The material is named "material0", as the Assimp-based import named it; a file
 *   without one gets "default", RAD_DEFAULT_ALBEDO.
 * All the triangles form one surface named after the file (no folder, no extension).
 *
 * Refused, with the line (ASCII) or the element and row (binary): a body shorter than its
 * header declares; an ASCII row that does not end its line, or rows after the last one
 * declared; a value that is not a number of its type; a list length that is not a count;
 * a face without vertices or with an index outside the vertex list (PLY counts from 0);
 * a coordinate that is not a finite number of its type (ASCII: written as a decimal
 * number, not "nan", "inf" or hexadecimal). Bytes after a binary body are a warning.
 */
#include "scene/import_ply.h"

#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "scene/ply_header.h"
#include "scene/scene_builder.h"

enum { TOKEN_SIZE = 64 };

/* One value as read: the token (ASCII) and the number it is. */
typedef struct ply_value {
    char text[TOKEN_SIZE]; /* ASCII: as written; binary: empty */
    double real;           /* the value (a whole number's too) */
    long long whole;       /* a whole-number type's value */
} ply_value;

typedef struct ply_reader {
    const char *path;
    FILE *file;
    const ply_header *header;
    const rad_load_options *options;
    unsigned long line;          /* ASCII: the line being read, 1 = the file's first */
    const ply_element *vertex;   /* the vertex element (the header makes sure of one) */
    const ply_element *face;     /* the face element, or NULL */
    const ply_element *material; /* the material element, or NULL */
    int face_list;               /* index of the face's vertex list, or -1 */
    int axis[3];                 /* property index of x, y, z in a vertex row; -1 = none */
    rad_vec3 *positions;         /* vertex rows read so far */
    size_t position_count, position_capacity;
    uint64_t *corners;           /* 3 vertex indices per triangle, in file order */
    size_t corner_count, corner_capacity;
    unsigned long long short_faces, first_short_face; /* faces of 1 or 2 corners */
    bool has_material;           /* the material element has a row */
    rad_material first_material; /* its first row's values */
    double ambient[3];           /* and its ambient colour (for a warning only) */
} ply_reader;

/* ------------------------------------------------------------------ reading values */

/* The next whitespace-separated token of an ASCII body, counting lines; false at the end. */
static bool next_token(ply_reader *r, char *token)
{
    int c;
    while ((c = getc(r->file)) != EOF && (c == ' ' || (c >= '\t' && c <= '\r')))
        r->line += c == '\n';
    if (c == EOF)
        return false;
    size_t n = 0;
    for (; c != EOF && !(c == ' ' || (c >= '\t' && c <= '\r')); c = getc(r->file))
        if (n + 1 < TOKEN_SIZE)
            token[n++] = c ? (char)c : '?'; /* a NUL byte makes the token no number */
    token[n] = 0;
    if (c == '\n')
        ungetc(c, r->file); /* counted by the next call */
    return true;
}

/* After an ASCII row: only blanks (and a '\r') up to the end of the line or the file.
 * PLY writes one row per line; a row that runs over into the next line, or shares one
 * with it, is a file whose counts and rows disagree. */
static bool row_ends_line(ply_reader *r)
{
    int c;
    while ((c = getc(r->file)) == ' ' || c == '\t' || c == '\r')
        ;
    if (c == '\n') {
        ungetc(c, r->file);
        return true;
    }
    return c == EOF;
}

/* The whole token is a number of its type: a whole number (base 10, optionally signed)
 * or anything strtod reads (other values than coordinates may be "nan"). */
static bool is_number(const char *token, bool real)
{
    char *end;
    errno = 0;
    if (real)
        (void)strtod(token, &end);
    else
        (void)strtoll(token, &end, 10);
    return end != token && *end == 0;
}

/* A decimal number as PLY writers print one: [+-] digits [. digits] [e [+-] digits],
 * with a digit before or after the point. */
static bool is_decimal(const char *text)
{
    const char *p = text + (*text == '+' || *text == '-');
    size_t digits = strspn(p, "0123456789");
    p += digits;
    if (*p == '.') {
        size_t fraction = strspn(p + 1, "0123456789");
        digits += fraction;
        p += 1 + fraction;
    }
    if (digits == 0)
        return false;
    if (*p == 'e' || *p == 'E') {
        p += 1 + (p[1] == '+' || p[1] == '-');
        size_t exponent = strspn(p, "0123456789");
        if (exponent == 0)
            return false;
        p += exponent;
    }
    return *p == 0;
}

/* A value of `type` from a binary body, in the file's byte order; false at the end. */
static bool read_binary(ply_reader *r, ply_type type, ply_value *out)
{
    unsigned char bytes[8];
    size_t size = (size_t)type.size;
    if (fread(bytes, 1, size, r->file) != size)
        return false;
    uint64_t bits = 0;
    for (size_t k = 0; k < size; k++)
        bits = bits << 8 | bytes[r->header->format == PLY_BIG ? k : size - 1 - k];
    out->text[0] = 0;
    if (type.is_float && size == 4) {
        uint32_t bits32 = (uint32_t)bits;
        float value;
        memcpy(&value, &bits32, sizeof(value));
        out->real = value;
        out->whole = 0;
    } else if (type.is_float) {
        double value;
        memcpy(&value, &bits, sizeof(value));
        out->real = value;
        out->whole = 0;
    } else {
        /* whole types have 1 to 4 bytes: their values fit a long long */
        out->whole = (long long)bits;
        if (type.is_signed && bits >> (8 * size - 1))
            out->whole -= 1ll << (8 * size);
        out->real = (double)out->whole;
    }
    return true;
}

/* The end of the body in the middle of `element`'s row `row`. */
static rad_status truncated(const ply_reader *r, const ply_element *element,
                            unsigned long long row, rad_error *error)
{
    return rad_fail(error, RAD_ERR_PARSE,
                    "%s: truncated: the header declares %llu rows of element '%s', the file "
                    "holds %llu",
                    r->path, element->rows, element->name, row);
}

/* One scalar value of `type` of `element`'s row `row`: RAD_OK, or refused (truncated, or
 * an ASCII token that is no number of its type). */
static rad_status read_value(ply_reader *r, ply_type type, const ply_element *element,
                             unsigned long long row, ply_value *out, rad_error *error)
{
    if (r->header->format != PLY_ASCII)
        return read_binary(r, type, out) ? RAD_OK : truncated(r, element, row, error);
    if (!next_token(r, out->text))
        return truncated(r, element, row, error);
    if (!is_number(out->text, type.is_float))
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: %s %llu: '%s' is not a number", r->path,
                        r->line, element->name, row, out->text);
    out->real = strtod(out->text, NULL);
    out->whole = type.is_float ? 0 : strtoll(out->text, NULL, 10);
    return RAD_OK;
}

/* A list's length: RAD_OK with *items, or refused (truncated, not a count). */
static rad_status read_count(ply_reader *r, const ply_property *property,
                             const ply_element *element, unsigned long long row,
                             unsigned long long *items, rad_error *error)
{
    if (r->header->format != PLY_ASCII) {
        ply_value value;
        if (!read_binary(r, property->count_type, &value))
            return truncated(r, element, row, error);
        if (value.whole < 0)
            return rad_fail(error, RAD_ERR_PARSE, "%s: %s %llu: list length %lld is not a count",
                            r->path, element->name, row, value.whole);
        *items = (unsigned long long)value.whole;
        return RAD_OK;
    }
    char token[TOKEN_SIZE];
    if (!next_token(r, token))
        return truncated(r, element, row, error);
    char *end;
    errno = 0;
    *items = strtoull(token, &end, 10);
    if (*end || end == token || token[0] == '-' || errno == ERANGE)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: %s %llu: list length '%s' is not a count",
                        r->path, r->line, element->name, row, token);
    return RAD_OK;
}

/* Reads past `items` values of a list that is not kept. */
static rad_status skip_items(ply_reader *r, const ply_property *property,
                             const ply_element *element, unsigned long long row,
                             unsigned long long items, rad_error *error)
{
    if (r->header->format == PLY_ASCII) {
        for (unsigned long long k = 0; k < items; k++) {
            ply_value value;
            rad_status status = read_value(r, property->type, element, row, &value, error);
            if (status != RAD_OK)
                return status;
        }
        return RAD_OK;
    }
    /* skip them, then read their last byte: fseek alone may pass the end */
    unsigned char last;
    bool ended = items > (unsigned long long)LONG_MAX / 8 ||
                 fseek(r->file, (long)(items * (unsigned)property->type.size), SEEK_CUR) != 0 ||
                 (items && (fseek(r->file, -1, SEEK_CUR) != 0 || fread(&last, 1, 1, r->file) != 1));
    return ended ? truncated(r, element, row, error) : RAD_OK;
}

/* ------------------------------------------------------------------ what is kept */

/* A face's vertex index (as written in ASCII, or read from a binary file) names one of
 * the file's vertex rows, PLY counting from 0. The index is checked whole: Assimp 5.2 kept
 * its low 32 bits, so 4294967296 was vertex 0 without a word. */
static rad_status vertex_index(const ply_reader *r, const ply_property *property,
                               const ply_value *value, unsigned long long row, uint64_t *index,
                               rad_error *error)
{
    unsigned long long vertices = r->vertex->rows;
    char where[32] = "", written[TOKEN_SIZE + 8];
    long long whole = value->whole;
    if (r->header->format == PLY_ASCII) {
        snprintf(where, sizeof(where), ":%lu", r->line);
        char *end;
        errno = 0;
        whole = strtoll(value->text, &end, 10);
        if (end == value->text || *end)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s%s: face %llu: vertex index '%s' is not a whole number", r->path,
                            where, row, value->text);
        if (errno == ERANGE)
            whole = -1; /* out of any range: refused below, as written */
        snprintf(written, sizeof(written), "%s", value->text);
    } else if (property->type.is_float) {
        if (!(value->real >= 0 && value->real < (double)vertices &&
              value->real == floor(value->real)))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: face %llu refers to vertex %g, not a vertex of the %llu "
                            "defined (PLY counts from 0)",
                            r->path, row, value->real, vertices);
        whole = (long long)value->real;
        snprintf(written, sizeof(written), "%lld", whole);
    } else {
        snprintf(written, sizeof(written), "%lld", whole);
    }
    if (whole < 0 || (unsigned long long)whole >= vertices)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s%s: face %llu refers to vertex %s but only %llu %s defined (PLY "
                        "counts from 0)",
                        r->path, where, row, written, vertices, vertices == 1 ? "is" : "are");
    *index = (uint64_t)whole;
    return RAD_OK;
}

static bool add_triangle(ply_reader *r, uint64_t a, uint64_t b, uint64_t c)
{
    if (!rad_grow_array((void **)&r->corners, &r->corner_capacity, r->corner_count + 3,
                        sizeof(*r->corners)))
        return false;
    r->corners[r->corner_count++] = a;
    r->corners[r->corner_count++] = b;
    r->corners[r->corner_count++] = c;
    return true;
}

/* A face's vertex list: its indices, fanned from the first, (0,k,k+1). */
static rad_status read_face(ply_reader *r, const ply_property *property,
                            unsigned long long row, rad_error *error)
{
    unsigned long long items = 0;
    rad_status status = read_count(r, property, r->face, row, &items, error);
    if (status != RAD_OK)
        return status;
    if (items == 0) {
        if (r->header->format == PLY_ASCII)
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: face %llu has no vertices", r->path,
                            r->line, row);
        return rad_fail(error, RAD_ERR_PARSE, "%s: face %llu has no vertices", r->path, row);
    }
    uint64_t first = 0, previous = 0;
    for (unsigned long long k = 0; k < items; k++) {
        ply_value value;
        uint64_t index = 0;
        /* an ASCII index is parsed whole by vertex_index, for its own message */
        if (r->header->format == PLY_ASCII)
            status = next_token(r, value.text) ? RAD_OK : truncated(r, r->face, row, error);
        else
            status = read_value(r, property->type, r->face, row, &value, error);
        if (status == RAD_OK)
            status = vertex_index(r, property, &value, row, &index, error);
        if (status != RAD_OK)
            return status;
        if (k == 0)
            first = index;
        else if (k >= 2 && !add_triangle(r, first, previous, index))
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        previous = index;
    }
    if (items < 3 && r->short_faces++ == 0)
        r->first_short_face = row;
    return RAD_OK;
}

/* A coordinate: a finite number of its type (ASCII: written as a decimal number). */
static rad_status coordinate(const ply_reader *r, const ply_property *property,
                             const ply_value *value, unsigned long long row, double *out,
                             rad_error *error)
{
    if (r->header->format == PLY_ASCII) {
        if (property->type.is_float && !is_decimal(value->text))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: vertex %llu: coordinate %s '%s' is not a finite decimal "
                            "number",
                            r->path, r->line, row, property->name, value->text);
        /* strtof and strtod round to the type (3.4028235e38 is FLT_MAX) and overflow to
         * an infinity */
        double rounded = property->type.is_float && property->type.size == 4
                             ? (double)strtof(value->text, NULL)
                             : strtod(value->text, NULL);
        if (!isfinite(rounded))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: vertex %llu: coordinate %s '%s' is beyond the range of %s",
                            r->path, r->line, row, property->name, value->text,
                            property->type.is_float && property->type.size == 4 ? "float"
                                                                                 : "double");
        *out = rounded;
        return RAD_OK;
    } else if (!isfinite(value->real)) {
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: vertex %llu: coordinate %s is not a finite number", r->path, row,
                        property->name);
    }
    *out = value->real;
    return RAD_OK;
}

/* A colour channel of the material: a whole number over its type's largest value. */
static double colour_value(const ply_property *property, const ply_value *value)
{
    if (property->type.is_float)
        return value->real;
    int bits = 8 * property->type.size - (property->type.is_signed ? 1 : 0);
    return value->real / (double)((1ull << bits) - 1);
}

/* A value of the material element's first row: the channels the reader keeps. */
static void material_value(ply_reader *r, const ply_property *property, const ply_value *value)
{
    static const char *const kinds[3] = {"diffuse_", "specular_", "ambient_"};
    static const char *const channels[3] = {"red", "green", "blue"};
    rad_material *m = &r->first_material;
    double *targets[3][3] = {{&m->albedo.r, &m->albedo.g, &m->albedo.b},
                             {&m->specular.r, &m->specular.g, &m->specular.b},
                             {&r->ambient[0], &r->ambient[1], &r->ambient[2]}};
    for (int kind = 0; kind < 3; kind++)
        for (int c = 0; c < 3; c++) {
            size_t n = strlen(kinds[kind]);
            if (strncmp(property->name, kinds[kind], n) == 0 &&
                strcmp(property->name + n, channels[c]) == 0)
                *targets[kind][c] = colour_value(property, value);
        }
    if (strcmp(property->name, "specular_power") == 0)
        m->shininess = value->real;
}

/* ------------------------------------------------------------------ the body */

static rad_status read_element(ply_reader *r, const ply_element *element, rad_error *error)
{
    bool is_vertex = element == r->vertex, is_face = element == r->face,
         is_material = element == r->material;
    for (unsigned long long row = 0; row < element->rows; row++) {
        rad_vec3 position = {0, 0, 0};
        double *axes[3] = {&position.x, &position.y, &position.z};
        for (int p = 0; p < element->property_count; p++) {
            const ply_property *property = &element->properties[p];
            rad_status status = RAD_OK;
            if (property->is_list && is_face && p == r->face_list) {
                status = read_face(r, property, row, error);
            } else if (property->is_list) {
                unsigned long long items = 0;
                status = read_count(r, property, element, row, &items, error);
                if (status == RAD_OK)
                    status = skip_items(r, property, element, row, items, error);
            } else {
                ply_value value;
                status = read_value(r, property->type, element, row, &value, error);
                for (int a = 0; a < 3 && status == RAD_OK && is_vertex; a++)
                    if (p == r->axis[a])
                        status = coordinate(r, property, &value, row, axes[a], error);
                if (status == RAD_OK && is_material && row == 0)
                    material_value(r, property, &value);
            }
            if (status != RAD_OK)
                return status;
        }
        if (r->header->format == PLY_ASCII && !row_ends_line(r))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: row %llu of element '%s' does not end its line (one row "
                            "per line; or the file holds fewer rows than its header declares)",
                            r->path, r->line, row, element->name);
        if (is_vertex) {
            if (!rad_grow_array((void **)&r->positions, &r->position_capacity,
                                r->position_count + 1, sizeof(*r->positions)))
                return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
            r->positions[r->position_count++] = position;
        }
    }
    if (is_material && element->rows > 0) {
        r->has_material = true;
        /* files in the wild put a light's power in the ambient colour, which no
         * reflectance can exceed: say so, as the other importers do */
        const rad_material *m = &r->first_material;
        if (fmax(r->ambient[0], fmax(r->ambient[1], r->ambient[2])) > 1)
            rad_warn(r->options ? r->options->log : NULL,
                     r->options ? r->options->log_user : NULL,
                     "%s: material '%s' has an ambient colour Ka (%g, %g, %g) above 1 but no "
                     "Ke: it does not emit (--emit %s=R,G,B makes it a light)",
                     r->path, m->name, r->ambient[0], r->ambient[1], r->ambient[2], m->name);
    }
    return RAD_OK;
}

/* After the last row: nothing but blanks (ASCII: more rows than declared are refused;
 * binary: trailing bytes are a warning). */
static rad_status read_end(ply_reader *r, rad_error *error)
{
    if (r->header->format == PLY_ASCII) {
        char token[TOKEN_SIZE];
        if (next_token(r, token))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: '%s' after the last row the header declares (more rows "
                            "than declared?)",
                            r->path, r->line, token);
        return RAD_OK;
    }
    unsigned long long extra = 0;
    while (getc(r->file) != EOF)
        extra++;
    if (extra)
        rad_warn(r->options ? r->options->log : NULL, r->options ? r->options->log_user : NULL,
                 "%s: %llu byte%s after the last row the header declares: ignored", r->path,
                 extra, extra == 1 ? "" : "s");
    return RAD_OK;
}

/* The elements and properties the reader keeps, found in the header. */
static rad_status find_parts(ply_reader *r, rad_error *error)
{
    r->vertex = ply_header_element(r->header, "vertex");
    r->face = ply_header_element(r->header, "face");
    r->material = ply_header_element(r->header, "material");
    static const char *const axes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; a++) {
        r->axis[a] = ply_element_property(r->vertex, axes[a]);
        if (r->axis[a] >= 0 && r->vertex->properties[r->axis[a]].is_list)
            r->axis[a] = -1;
    }
    if (r->axis[0] < 0 || r->axis[1] < 0)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: element 'vertex' has no property %s (a number, not a list)",
                        r->path, r->axis[0] < 0 ? "x" : "y");
    r->face_list = -1;
    for (int p = 0; r->face && p < r->face->property_count && r->face_list < 0; p++) {
        const ply_property *property = &r->face->properties[p];
        if (property->is_list && (strcmp(property->name, "vertex_indices") == 0 ||
                                  strcmp(property->name, "vertex_index") == 0))
            r->face_list = p;
    }
    return RAD_OK;
}

/* The surface's name, as the Assimp-based import named it: the file's name without
 * folder and extension (up to 127 bytes). */
static void surface_name(const char *path, char name[128])
{
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    snprintf(name, 128, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot && dot != name)
        *dot = 0;
}

static rad_status build(ply_reader *r, rad_scene **out, rad_error *error)
{
    scene_builder *builder = NULL;
    rad_status status = scene_builder_create(r->path, r->options, &builder, error);
    if (status != RAD_OK)
        return status;
    char name[128];
    surface_name(r->path, name);
    uint32_t surface = scene_builder_surface(builder, name);
    rad_material material = r->first_material;
    if (!r->has_material) {
        material = (rad_material){0};
        snprintf(material.name, sizeof(material.name), "default");
        material.albedo = (rad_rgb){RAD_DEFAULT_ALBEDO, RAD_DEFAULT_ALBEDO, RAD_DEFAULT_ALBEDO};
    }
    uint32_t index = scene_builder_material(builder, &material);
    if (surface == UINT32_MAX || index == UINT32_MAX) {
        scene_builder_destroy(builder);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
    }
    for (size_t c = 0; c + 2 < r->corner_count; c += 3) {
        status = scene_builder_triangle(builder, surface, index, r->positions[r->corners[c]],
                                        r->positions[r->corners[c + 1]],
                                        r->positions[r->corners[c + 2]], error);
        if (status != RAD_OK) {
            scene_builder_destroy(builder);
            return status;
        }
    }
    if (r->short_faces)
        rad_warn(r->options ? r->options->log : NULL, r->options ? r->options->log_user : NULL,
                 "%s: %llu face%s of 1 or 2 vertices (the first: face %llu) %s no area: "
                 "skipped",
                 r->path, r->short_faces, r->short_faces == 1 ? "" : "s", r->first_short_face,
                 r->short_faces == 1 ? "has" : "have");
    return scene_builder_finish(builder, out, error);
}

rad_status ply_scene_read(const char *path, FILE *file, const rad_load_options *options,
                          rad_scene **out, rad_error *error)
{
    *out = NULL;
    ply_header *header = rad_alloc_array(1, sizeof(*header));
    if (!header)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    ply_reader r = {.path = path, .file = file, .header = header, .options = options};
    snprintf(r.first_material.name, sizeof(r.first_material.name), "material0");
    rad_status status = ply_header_read(path, file, header, error);
    if (status == RAD_OK)
        status = find_parts(&r, error);
    r.line = header->lines + 1;
    for (int e = 0; status == RAD_OK && e < header->element_count; e++)
        status = read_element(&r, &header->elements[e], error);
    if (status == RAD_OK)
        status = read_end(&r, error);
    if (status == RAD_OK)
        status = build(&r, out, error);
    free(r.positions);
    free(r.corners);
    free(header);
    return status;
}

rad_status ply_scene_load(const char *path, const rad_load_options *options, rad_scene **out,
                          rad_error *error)
{
    *out = NULL;
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    rad_status status = ply_scene_read(path, file, options, out, error);
    fclose(file);
    return status;
}

bool ply_stream_is_ply(FILE *file)
{
    char magic[5] = "";
    size_t n = fread(magic, 1, 4, file);
    return n == 4 && memcmp(magic, "ply", 3) == 0 && (magic[3] == '\n' || magic[3] == '\r');
}
