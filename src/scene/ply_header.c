/*
 * ply_header.c - the one parser of a PLY header. See ply_header.h; the format is Greg
 * Turk's "The PLY Polygon File Format" (1994): "ply", a format line, then elements, each
 * with a row count and its properties in the order of a row, up to "end_header".
 */
#include "ply_header.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* A PLY scalar type by name (the 1994 names and the sized ones of later writers);
 * false if unknown. */
static bool type_named(const char *name, ply_type *type)
{
    static const struct {
        const char *name;
        ply_type type;
    } types[] = {{"char", {1, true, false}},     {"uchar", {1, false, false}},
                 {"int8", {1, true, false}},     {"uint8", {1, false, false}},
                 {"short", {2, true, false}},    {"ushort", {2, false, false}},
                 {"int16", {2, true, false}},    {"uint16", {2, false, false}},
                 {"int", {4, true, false}},      {"uint", {4, false, false}},
                 {"int32", {4, true, false}},    {"uint32", {4, false, false}},
                 {"float", {4, true, true}},     {"float32", {4, true, true}},
                 {"double", {8, true, true}},    {"float64", {8, true, true}}};
    for (size_t k = 0; k < sizeof(types) / sizeof(types[0]); k++)
        if (strcmp(name, types[k].name) == 0) {
            *type = types[k].type;
            return true;
        }
    return false;
}

const ply_element *ply_header_element(const ply_header *header, const char *name)
{
    for (int e = 0; e < header->element_count; e++)
        if (strcmp(header->elements[e].name, name) == 0)
            return &header->elements[e];
    return NULL;
}

int ply_element_property(const ply_element *element, const char *name)
{
    for (int p = 0; p < element->property_count; p++)
        if (strcmp(element->properties[p].name, name) == 0)
            return p;
    return -1;
}

/* One "property" line (its words after the keyword: a, b, c, d; n words in all). */
static rad_status read_property(const char *path, unsigned long line, ply_element *element,
                                int n, const char *a, const char *b, const char *c,
                                const char *d, rad_error *error)
{
    bool list = strcmp(a, "list") == 0;
    const char *type = list ? c : a, *name = list ? d : b;
    ply_property property = {.is_list = list};
    bool known = type_named(type, &property.type) &&
                 (!list || type_named(b, &property.count_type));
    /* a property without a name made Assimp 5.2 abort in its triangulation */
    bool named = n >= (list ? 5 : 3);
    if (!element || element->property_count == PLY_MAX_PROPERTIES || !known || !named)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: bad property line", path, line);
    if (list && property.count_type.is_float)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: property '%s': a list's length is of type '%s', not a whole "
                        "number",
                        path, line, name, b);
    snprintf(property.name, sizeof(property.name), "%s", name);
    element->properties[element->property_count++] = property;
    return RAD_OK;
}

/* One "element" line: its name `a` and row count `b`. */
static rad_status read_element(const char *path, unsigned long line, ply_header *header, int n,
                               const char *a, const char *b, rad_error *error)
{
    char *end;
    errno = 0;
    unsigned long long rows = strtoull(b, &end, 10);
    if (n < 3 || *end || end == b || b[0] == '-')
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: element '%s' has no row count", path,
                        line, a);
    if (errno == ERANGE)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: element '%s': row count %s is out of range",
                        path, line, a, b);
    if (header->element_count == PLY_MAX_ELEMENTS)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: more than %d elements", path, line,
                        PLY_MAX_ELEMENTS);
    ply_element *element = &header->elements[header->element_count++];
    snprintf(element->name, sizeof(element->name), "%s", a);
    element->rows = rows;
    element->property_count = 0;
    return RAD_OK;
}

/* One "format" line: the format `a` and version `b`. */
static rad_status read_format(const char *path, unsigned long line, ply_header *header,
                              const char *a, const char *b, rad_error *error)
{
    if (strcmp(a, "ascii") == 0)
        header->format = PLY_ASCII;
    else if (strcmp(a, "binary_little_endian") == 0)
        header->format = PLY_LITTLE;
    else if (strcmp(a, "binary_big_endian") == 0)
        header->format = PLY_BIG;
    else
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unknown PLY format '%s'", path, line, a);
    if (strcmp(b, "1.0") != 0)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: PLY version '%s' (1.0 expected)", path,
                        line, b);
    return RAD_OK;
}

rad_status ply_header_read(const char *path, FILE *file, ply_header *header, rad_error *error)
{
    char line_text[1024];
    unsigned long line = 0;
    bool has_format = false, ended = false;
    rad_status status = RAD_OK;
    header->format = PLY_ASCII;
    header->element_count = 0;
    while (status == RAD_OK && !ended && fgets(line_text, sizeof(line_text), file)) {
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
        if (!whole) /* fgets stopped short: a NUL byte, or a line too long */
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s:%lu: header line holds a NUL byte or is longer than %zu bytes",
                              path, line, sizeof(line_text) - 2);
        else if (strcmp(word, "end_header") == 0)
            ended = true;
        else if (strcmp(word, "format") == 0) {
            has_format = true;
            status = read_format(path, line, header, a, b, error);
        } else if (strcmp(word, "element") == 0)
            status = read_element(path, line, header, n, a, b, error);
        else if (strcmp(word, "property") == 0)
            status = read_property(path, line,
                                   header->element_count
                                       ? &header->elements[header->element_count - 1]
                                       : NULL,
                                   n, a, b, c, d, error);
        else /* Assimp 5.2 skipped other words and could corrupt its heap (found by fuzz_ply) */
            status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unknown header line '%.40s'", path,
                              line, word);
    }
    header->lines = line;
    if (status != RAD_OK)
        return status;
    if (!has_format || !ended)
        return rad_fail(error, RAD_ERR_PARSE, "%s: not a PLY file (no %s)", path,
                        has_format ? "end_header" : "format line");
    const ply_element *vertex = ply_header_element(header, "vertex");
    if (!vertex || vertex->rows == 0) /* Assimp 5.2 crashed on one (found by fuzz_ply) */
        return rad_fail(error, RAD_ERR_PARSE, "%s: no vertex element with rows", path);
    for (int e = 0; e < header->element_count; e++) {
        const ply_element *element = &header->elements[e];
        if (element->property_count == 0 && element->rows > 0) /* rows of nothing */
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: element '%s' declares %llu rows but no properties", path,
                            element->name, element->rows);
    }
    return RAD_OK;
}
