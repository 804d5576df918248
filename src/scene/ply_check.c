/*
 * ply_check.c - a PLY file holds every row its header declares. See ply_check.h.
 */
#include "ply_check.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"

enum { PLY_MAX_ELEMENTS = 16, PLY_MAX_PROPERTIES = 64 };

typedef enum ply_format { PLY_ASCII, PLY_LITTLE, PLY_BIG } ply_format;

typedef struct ply_property {
    int size;       /* bytes of a scalar, or of the list's items */
    int count_size; /* bytes of a list's count; 0 = a scalar */
    bool item_signed, item_float;
    bool vertex_indices; /* a face's vertex_indices (or vertex_index) */
} ply_property;

typedef struct ply_element {
    char name[64];
    unsigned long long rows;
    int property_count;
    ply_property properties[PLY_MAX_PROPERTIES];
} ply_element;

static bool type_is_float(const char *type)
{
    return strncmp(type, "float", 5) == 0 || strcmp(type, "double") == 0;
}

static bool type_is_signed(const char *type)
{
    return type[0] != 'u';
}

/* Bytes of a PLY scalar type, 0 if unknown. */
static int type_size(const char *type)
{
    static const struct {
        const char *name;
        int size;
    } types[] = {{"char", 1},  {"uchar", 1},  {"int8", 1},   {"uint8", 1},   {"short", 2},
                 {"ushort", 2}, {"int16", 2},  {"uint16", 2}, {"int", 4},     {"uint", 4},
                 {"int32", 4},  {"uint32", 4}, {"float", 4},  {"float32", 4}, {"double", 8},
                 {"float64", 8}};
    for (size_t k = 0; k < sizeof(types) / sizeof(types[0]); k++)
        if (strcmp(type, types[k].name) == 0)
            return types[k].size;
    return 0;
}

/* A list item or count of `size` bytes, in the file's byte order, as a signed value when
 * `is_signed` (a count is never: PLY counts are unsigned in practice, uchar or int). */
static unsigned long long binary_count(const unsigned char *bytes, int size, ply_format format)
{
    unsigned long long value = 0;
    for (int k = 0; k < size; k++)
        value = value << 8 | bytes[format == PLY_BIG ? k : size - 1 - k];
    return value;
}

/* The next whitespace-separated token of an ASCII body, counting lines; false at the end. */
static bool next_token(FILE *file, char *token, size_t size, unsigned long *line)
{
    int c;
    while ((c = getc(file)) != EOF && isspace(c))
        *line += c == '\n';
    if (c == EOF)
        return false;
    size_t n = 0;
    for (; c != EOF && !isspace(c); c = getc(file))
        if (n + 1 < size)
            token[n++] = c ? (char)c : '?'; /* a NUL byte makes the token no number */
    token[n] = 0;
    if (c == '\n')
        ungetc(c, file);
    return true;
}

/* An ASCII value of its property's type: a whole number (optionally signed) or a real
 * one, written whole (Assimp 5.2 reads a prefix of "0-" or "25z" and can then abort). */
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

/* After an ASCII row: only blanks (and a '\r') up to the end of the line or the file.
 * Assimp 5.2 reads rows line by line, and aborts on a row that runs over into the next
 * line or shares one with it (found by fuzz_ply). */
static bool row_ends_line(FILE *file)
{
    int c;
    while ((c = getc(file)) == ' ' || c == '\t' || c == '\r')
        ;
    if (c == '\n') {
        ungetc(c, file); /* next_token counts it */
        return true;
    }
    return c == EOF;
}

/* A face's vertex index (`text` as written, or `value` read from a binary file) names one
 * of the file's `vertices` (PLY counts from 0): Assimp 5.2 keeps only the low 32 bits, so
 * 4294967296 would be vertex 0 without a word. */
static rad_status check_vertex_index(const char *path, unsigned long line, const char *text,
                                     long long value, unsigned long long row,
                                     unsigned long long vertices, rad_error *error)
{
    char where[32] = "";
    if (line)
        snprintf(where, sizeof(where), ":%lu", line);
    char written[64];
    if (text) {
        char *end;
        errno = 0;
        value = strtoll(text, &end, 10);
        if (end == text || *end)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s%s: face %llu: vertex index '%s' is not a whole number", path,
                            where, row, text);
        snprintf(written, sizeof(written), "%s", text);
        if (errno == ERANGE)
            value = -1; /* out of any range: refused below, as written */
    } else {
        snprintf(written, sizeof(written), "%lld", value);
    }
    if (value < 0 || (unsigned long long)value >= vertices)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s%s: face %llu refers to vertex %s but only %llu %s defined (PLY "
                        "counts from 0)",
                        path, where, row, written, vertices, vertices == 1 ? "is" : "are");
    return RAD_OK;
}

static rad_status check_body(const char *path, FILE *file, ply_format format,
                             const ply_element *elements, int element_count,
                             unsigned long line, rad_error *error)
{
    unsigned long long vertices = 0;
    for (int e = 0; e < element_count; e++)
        if (strcmp(elements[e].name, "vertex") == 0)
            vertices = elements[e].rows;
    for (int e = 0; e < element_count; e++) {
        const ply_element *element = &elements[e];
        if (element->property_count == 0 && element->rows > 0) /* Assimp 5.2 spins on them */
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: element '%s' declares %llu rows but no properties", path,
                            element->name, element->rows);
        for (unsigned long long row = 0; row < element->rows; row++) {
            for (int p = 0; p < element->property_count; p++) {
                const ply_property *property = &element->properties[p];
                unsigned long long items = 1;
                bool ended = false;
                if (format == PLY_ASCII) {
                    char token[64];
                    ended = !next_token(file, token, sizeof(token), &line);
                    if (!ended && property->count_size) {
                        char *end;
                        errno = 0;
                        items = strtoull(token, &end, 10);
                        if (*end || end == token || token[0] == '-' || errno == ERANGE)
                            return rad_fail(error, RAD_ERR_PARSE,
                                            "%s:%lu: %s %llu: list length '%s' is not a count",
                                            path, line, element->name, row, token);
                    } else {
                        items = 0;
                        if (!ended && !is_number(token, property->item_float))
                            return rad_fail(error, RAD_ERR_PARSE,
                                            "%s:%lu: %s %llu: '%s' is not a number", path, line,
                                            element->name, row, token);
                    }
                    if (!ended && property->vertex_indices && items == 0)
                        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: face %llu has no vertices",
                                        path, line, row);
                    for (unsigned long long k = 0; k < items && !ended; k++) {
                        ended = !next_token(file, token, sizeof(token), &line);
                        if (!ended && !property->vertex_indices &&
                            !is_number(token, property->item_float))
                            return rad_fail(error, RAD_ERR_PARSE,
                                            "%s:%lu: %s %llu: '%s' is not a number", path, line,
                                            element->name, row, token);
                        if (!ended && property->vertex_indices) {
                            rad_status status = check_vertex_index(path, line, token, 0, row,
                                                                   vertices, error);
                            if (status != RAD_OK)
                                return status;
                        }
                    }
                } else {
                    unsigned char bytes[8];
                    if (property->count_size) {
                        ended = fread(bytes, 1, (size_t)property->count_size, file) !=
                                (size_t)property->count_size;
                        items = ended ? 0 : binary_count(bytes, property->count_size, format);
                        if (!ended && property->vertex_indices && items == 0)
                            return rad_fail(error, RAD_ERR_PARSE, "%s: face %llu has no vertices",
                                            path, row);
                    }
                    if (property->vertex_indices && !property->item_float) {
                        /* read each index (a face has a handful) */
                        for (unsigned long long k = 0; k < items && !ended; k++) {
                            ended = fread(bytes, 1, (size_t)property->size, file) !=
                                    (size_t)property->size;
                            if (ended)
                                break;
                            unsigned long long bits =
                                binary_count(bytes, property->size, format);
                            long long value = (long long)bits;
                            if (property->item_signed && property->size < 8 &&
                                bits >> (8 * property->size - 1))
                                value = (long long)bits - (1ll << (8 * property->size));
                            rad_status status = check_vertex_index(path, 0, NULL, value, row,
                                                                   vertices, error);
                            if (status != RAD_OK)
                                return status;
                        }
                        items = 0;
                    }
                    /* skip the items, then read their last byte: fseek passes the end */
                    ended = ended || items > (unsigned long long)LONG_MAX / 8 ||
                            fseek(file, (long)(items * (unsigned)property->size), SEEK_CUR) != 0 ||
                            (items && (fseek(file, -1, SEEK_CUR) != 0 ||
                                       fread(bytes, 1, 1, file) != 1));
                }
                if (ended)
                    return rad_fail(error, RAD_ERR_PARSE,
                                    "%s: truncated: the header declares %llu rows of element '%s', "
                                    "the file holds %llu",
                                    path, element->rows, element->name, row);
            }
            /* Assimp 5.2 reads an ASCII body line by line (it aborted on rows run together
             * by a form feed; found by fuzz_ply) */
            if (format == PLY_ASCII && element->property_count > 0 && !row_ends_line(file))
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: row %llu of element '%s' does not end its line (one "
                                "row per line; or the file holds fewer rows than its header "
                                "declares)",
                                path, line, row, element->name);
        }
    }
    return RAD_OK;
}

rad_status ply_check(const char *path, FILE *file, rad_error *error)
{
    ply_element *element_list = rad_alloc_array(PLY_MAX_ELEMENTS, sizeof(*element_list));
    if (!element_list)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    char line_text[1024];
    unsigned long line = 0;
    int element_count = 0;
    ply_format format = PLY_ASCII;
    bool has_format = false, ended = false;
    rad_status status = RAD_OK;
    while (status == RAD_OK && fgets(line_text, sizeof(line_text), file)) {
        line++;
        bool whole = strchr(line_text, '\n') != NULL || feof(file);
        if (!whole) { /* the rest of a long line: only comments may be that long */
            int ch;
            while ((ch = fgetc(file)) != EOF && ch != '\n')
                ;
        }
        char word[64] = "", a[64] = "", b[64] = "", c[64] = "", d[64] = "";
        int n = sscanf(line_text, "%63s %63s %63s %63s %63s", word, a, b, c, d);
        if ((n < 1 && whole) || strcmp(word, "ply") == 0 || strcmp(word, "comment") == 0 ||
            strcmp(word, "obj_info") == 0)
            continue;
        if (!whole) { /* fgets stopped short: a NUL byte, or a line too long */
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s:%lu: header line holds a NUL byte or is longer than %zu bytes",
                              path, line, sizeof(line_text) - 2);
            break;
        }
        /* the header has these keywords only; Assimp 5.2 skips others and can corrupt its
         * heap on what follows (found by fuzz_ply) */
        if (strcmp(word, "end_header") != 0 && strcmp(word, "format") != 0 &&
            strcmp(word, "element") != 0 && strcmp(word, "property") != 0) {
            status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unknown header line '%.40s'", path,
                              line, word);
            break;
        }
        if (strcmp(word, "end_header") == 0) {
            ended = true;
            break;
        }
        if (strcmp(word, "format") == 0) {
            has_format = true;
            if (strcmp(a, "ascii") == 0)
                format = PLY_ASCII;
            else if (strcmp(a, "binary_little_endian") == 0)
                format = PLY_LITTLE;
            else if (strcmp(a, "binary_big_endian") == 0)
                format = PLY_BIG;
            else
                status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unknown PLY format '%s'", path,
                                  line, a);
            if (status == RAD_OK && strcmp(b, "1.0") != 0)
                status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: PLY version '%s' (1.0 expected)",
                                  path, line, b);
        } else if (strcmp(word, "element") == 0) {
            char *end;
            errno = 0;
            unsigned long long rows = strtoull(b, &end, 10);
            if (n < 3 || *end || end == b || b[0] == '-')
                status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: element '%s' has no row count",
                                  path, line, a);
            else if (errno == ERANGE)
                status = rad_fail(error, RAD_ERR_PARSE,
                                  "%s:%lu: element '%s': row count %s is out of range", path,
                                  line, a, b);
            else if (element_count == PLY_MAX_ELEMENTS)
                status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: more than %d elements", path,
                                  line, PLY_MAX_ELEMENTS);
            else {
                ply_element *e = &element_list[element_count++];
                snprintf(e->name, sizeof(e->name), "%s", a);
                e->rows = rows;
            }
        } else if (strcmp(word, "property") == 0) {
            ply_element *e = element_count ? &element_list[element_count - 1] : NULL;
            bool list = strcmp(a, "list") == 0;
            const char *type = list ? c : a, *name = list ? d : b;
            int size = type_size(type), count_size = list ? type_size(b) : 0;
            /* a property without a name makes Assimp 5.2 abort in its triangulation */
            bool named = n >= (list ? 5 : 3);
            if (!e || e->property_count == PLY_MAX_PROPERTIES || !size || (list && !count_size) ||
                !named)
                status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: bad property line", path, line);
            else if (list && type_is_float(b))
                status = rad_fail(error, RAD_ERR_PARSE,
                                  "%s:%lu: property '%s': a list's length is of type '%s', not "
                                  "a whole number",
                                  path, line, name, b);
            else
                e->properties[e->property_count++] = (ply_property){
                    size, count_size, type_is_signed(type), type_is_float(type),
                    list && strcmp(e->name, "face") == 0 &&
                        (strcmp(name, "vertex_indices") == 0 || strcmp(name, "vertex_index") == 0)};
        }
    }
    if (status == RAD_OK && (!has_format || !ended))
        status = rad_fail(error, RAD_ERR_PARSE, "%s: not a PLY file (no %s)", path,
                          has_format ? "end_header" : "format line");
    bool has_vertices = false;
    for (int e = 0; e < element_count; e++)
        has_vertices = has_vertices || (strcmp(element_list[e].name, "vertex") == 0 &&
                                        element_list[e].rows > 0);
    if (status == RAD_OK && !has_vertices) /* Assimp 5.2 crashed on one (found by fuzz_ply) */
        status = rad_fail(error, RAD_ERR_PARSE, "%s: no vertex element with rows", path);
    if (status == RAD_OK)
        status = check_body(path, file, format, element_list, element_count, line + 1, error);
    free(element_list);
    return status;
}
