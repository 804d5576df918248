/*
 * import_vs3.c - reading View3D 3.x input files (`F 3` geometry) into a rad_scene.
 *
 * Three steps, as the header describes the format: (1) parse every line into vertices
 * (by number) and polygons (kind S/O/M/N, four vertex numbers, base, cmb, emissivity,
 * name, line number); (2) resolve the references and check each polygon (planar convex
 * quadrilateral, area, subsurfaces inside their base); (3) hand triangles to the scene
 * builder. A polygon with subsurfaces or null surfaces (`base` pointing at it) is cut
 * into convex pieces around them: each hole is convex, so the base minus the hole is,
 * edge by edge of the hole, "outside this edge and inside the previous ones", a convex
 * piece each. That is what View3D's post-processing computes with view-factor algebra
 * (the base's factors and area less the subsurface's). Masks are cut out the same way and
 * kept as obstructions; rad_viewfactor_matrix_apply_vs3_masks then gives them View3D's
 * factors after the computation.
 */
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/alloc.h"
#include "core/error.h"
#include "core/tolerance.h"
#include "core/vec3.h"
#include "scene/scene_builder.h"

/* A convex piece of a polygon cut around holes has at most 4 + (number of hole edges
 * applied) corners; this bounds it (a wall with a dozen windows fits). */
enum { VS3_PIECE_CORNERS = 64 };

/* The largest vertex or surface number read: the reader keeps tables indexed by number,
 * so a larger one would cost memory for numbers no file uses. */
enum { VS3_LARGEST_NUMBER = 1 << 24 };

/* Coordinates are at most single precision's largest in magnitude: the ray tracer holds
 * them in floats. */
#define VS3_LARGEST_COORDINATE FLT_MAX

typedef enum vs3_kind { VS3_SURFACE, VS3_OBSTRUCTION, VS3_MASK, VS3_NULL } vs3_kind;

typedef struct vs3_polygon {
    unsigned long line;
    uint32_t number;      /* the surface number of the file */
    vs3_kind kind;
    uint32_t vertex[4];   /* vertex numbers of the file; vertex[3] = 0 for a triangle */
    uint32_t corner_count;
    uint32_t base, cmb;   /* surface numbers of the file, 0 = none */
    double emissivity;
    char name[128];
    /* resolved */
    rad_vec3 corner[4];
    rad_vec3 normal;      /* unit, right-hand rule */
    double area;
    uint32_t base_index;  /* index into the polygon list, UINT32_MAX = none */
    uint32_t root;        /* index of the polygon whose surface it joins (itself if none) */
} vs3_polygon;

typedef struct vs3_reader {
    const char *path;
    rad_load_options options;
    rad_vs3_control control;
    rad_vec3 *vertex;       /* by vertex number */
    unsigned long *vertex_line; /* 0 = undefined */
    size_t vertex_capacity;
    vs3_polygon *polygon;
    size_t polygon_count, polygon_capacity;
    uint32_t *polygon_by_number; /* surface number -> index + 1 */
    size_t number_capacity;
} vs3_reader;

static void reader_free(vs3_reader *r)
{
    free(r->vertex);
    free(r->vertex_line);
    free(r->polygon);
    free(r->polygon_by_number);
}

/* Splits a line into whitespace-separated tokens, stopping at a token that starts a
 * comment. Returns the count (at most max). */
static int tokenize(char *line, char **token, int max)
{
    int n = 0;
    char *p = line;
    while (n < max) {
        while (*p && isspace((unsigned char)*p))
            p++;
        if (!*p || *p == '!' || *p == '/')
            break;
        token[n++] = p;
        while (*p && !isspace((unsigned char)*p))
            p++;
        if (*p)
            *p++ = 0;
    }
    return n;
}

static bool parse_double(const char *text, double *out)
{
    char *end;
    errno = 0;
    double value = strtod(text, &end);
    /* an underflow (1e-400) is the nearest double, near 0; an overflow is refused */
    if (end == text || *end || (errno == ERANGE && fabs(value) >= 1) || !isfinite(value))
        return false;
    *out = value;
    return true;
}

static bool parse_count(const char *text, uint32_t *out)
{
    char *end;
    if (!isdigit((unsigned char)text[0]))
        return false;
    errno = 0;
    unsigned long value = strtoul(text, &end, 10);
    if (*end || errno == ERANGE || value > UINT32_MAX - 1)
        return false;
    *out = (uint32_t)value;
    return true;
}

/* A vertex or surface number written as digits but beyond VS3_LARGEST_NUMBER: refused in
 * those words (not as a malformed line). */
static rad_status check_number_size(vs3_reader *r, const char *text, const char *what,
                                    unsigned long line, rad_error *error)
{
    uint32_t number;
    if (text[strspn(text, "0123456789")] || (parse_count(text, &number) &&
                                              number <= VS3_LARGEST_NUMBER))
        return RAD_OK;
    return rad_fail(error, RAD_ERR_UNSUPPORTED,
                    "%s:%lu: %s number %s is larger than this reader supports (%d)", r->path,
                    line, what, text, VS3_LARGEST_NUMBER);
}

static rad_status parse_control(vs3_reader *r, char **token, int count, unsigned long line,
                                rad_error *error)
{
    for (int k = 1; k < count; k++) {
        char name[64], value_text[128];
        char *equals = strchr(token[k], '=');
        if (equals) {
            snprintf(name, sizeof(name), "%.*s", (int)(equals - token[k]), token[k]);
            if (equals[1])
                snprintf(value_text, sizeof(value_text), "%s", equals + 1);
            else if (k + 1 < count)
                snprintf(value_text, sizeof(value_text), "%s", token[++k]);
            else
                value_text[0] = 0;
        } else if (k + 2 < count && strcmp(token[k + 1], "=") == 0) {
            snprintf(name, sizeof(name), "%s", token[k]);
            snprintf(value_text, sizeof(value_text), "%s", token[k + 2]);
            k += 2;
        } else {
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: control value '%s' is not of the form name=value", r->path,
                            line, token[k]);
        }
        rad_vs3_control *c = &r->control;
        struct {
            const char *name;
            uint32_t *value;
        } counts[] = {{"maxU", &c->max_u}, {"maxO", &c->max_o}, {"minO", &c->min_o},
                      {"row", &c->row},    {"col", &c->col},    {"out", &c->out},
                      {"list", &c->list}};
        bool known = false;
        if (strcasecmp(name, "eps") == 0) {
            known = true;
            if (!parse_double(value_text, &c->eps) || !(c->eps > 0) || c->eps >= 1)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: eps must be a number in (0,1), not '%s'", r->path,
                                line, value_text);
        } else if (strcasecmp(name, "encl") == 0 || strcasecmp(name, "emit") == 0) {
            known = true;
            uint32_t flag;
            if (!parse_count(value_text, &flag) || flag > 1)
                return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: %s must be 0 or 1, not '%s'",
                                r->path, line, name, value_text);
            if (strcasecmp(name, "encl") == 0)
                c->enclosure = flag;
            else
                c->emit = flag;
        }
        for (size_t i = 0; !known && i < sizeof(counts) / sizeof(counts[0]); i++)
            if (strcasecmp(name, counts[i].name) == 0) {
                known = true;
                if (!parse_count(value_text, counts[i].value))
                    return rad_fail(error, RAD_ERR_PARSE,
                                    value_text[0] && !value_text[strspn(value_text, "0123456789")]
                                        ? "%s:%lu: %s must be at most 4294967294, not '%s'"
                                        : "%s:%lu: %s must be a whole number, not '%s'",
                                    r->path, line, name, value_text);
            }
        if (!known)
            rad_warn(r->options.log, r->options.log_user,
                     "%s:%lu: unknown control value '%s' ignored", r->path, line, name);
    }
    return RAD_OK;
}

static rad_status parse_vertex(vs3_reader *r, char **token, int count, unsigned long line,
                               rad_error *error)
{
    uint32_t number;
    double x[3];
    if (count >= 2 && check_number_size(r, token[1], "vertex", line, error) != RAD_OK)
        return RAD_ERR_UNSUPPORTED;
    for (int k = 2; k < 5 && k < count; k++) {
        char *end;
        double value = strtod(token[k], &end);
        if (end != token[k] && !*end && isfinite(value) && fabs(value) > VS3_LARGEST_COORDINATE)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: vertex %s: coordinate %s is out of the supported range "
                            "(magnitude at most %g)",
                            r->path, line, token[1], token[k], VS3_LARGEST_COORDINATE);
    }
    if (count < 5 || !parse_count(token[1], &number) || number == 0 ||
        !parse_double(token[2], &x[0]) || !parse_double(token[3], &x[1]) ||
        !parse_double(token[4], &x[2]))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: expected 'V number x y z' with a vertex number from 1 and "
                        "finite coordinates",
                        r->path, line);
    if (count > 5)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unexpected '%s' after the vertex",
                        r->path, line, token[5]);
    if (number > VS3_LARGEST_NUMBER)
        return rad_fail(error, RAD_ERR_UNSUPPORTED, "%s:%lu: vertex number %u is above %d",
                        r->path, line, number, VS3_LARGEST_NUMBER);
    size_t old = r->vertex_capacity;
    if (number >= old) {
        size_t capacity = old;
        if (!rad_grow_array((void **)&r->vertex, &capacity, (size_t)number + 1,
                            sizeof(*r->vertex)))
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        capacity = old;
        if (!rad_grow_array((void **)&r->vertex_line, &capacity, (size_t)number + 1,
                            sizeof(*r->vertex_line)))
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        memset(r->vertex_line + old, 0, (capacity - old) * sizeof(*r->vertex_line));
        r->vertex_capacity = capacity;
    }
    if (r->vertex_line[number])
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: vertex %u is already defined on line %lu",
                        r->path, line, number, r->vertex_line[number]);
    r->vertex[number] = v3(x[0], x[1], x[2]);
    r->vertex_line[number] = line;
    return RAD_OK;
}

static rad_status parse_surface(vs3_reader *r, vs3_kind kind, char **token, int count,
                                unsigned long line, rad_error *error)
{
    vs3_polygon p;
    memset(&p, 0, sizeof(p));
    if (count >= 2 && check_number_size(r, token[1], "surface", line, error) != RAD_OK)
        return RAD_ERR_UNSUPPORTED;
    p.line = line;
    p.kind = kind;
    /* a reference (vertex, base, cmb) written as digits beyond any number read: to none */
    static const char *const field[6] = {"vertex", "vertex", "vertex", "vertex", "base",
                                         "cmb"};
    for (int k = 2; k < 8 && k < count; k++)
        if (!token[k][strspn(token[k], "0123456789")] &&
            !(parse_count(token[k], &p.base) && p.base <= VS3_LARGEST_NUMBER))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: surface %s: %s %s is not %s (numbers go up to %d)", r->path,
                            line, token[1], field[k - 2], token[k],
                            k < 6 ? "a vertex of the file" : "a surface of the file",
                            VS3_LARGEST_NUMBER);
    p.base = 0;
    bool ok = count >= 9 && parse_count(token[1], &p.number) && p.number > 0;
    for (int k = 0; ok && k < 4; k++)
        ok = parse_count(token[2 + k], &p.vertex[k]);
    ok = ok && parse_count(token[6], &p.base) && parse_count(token[7], &p.cmb) &&
         parse_double(token[8], &p.emissivity);
    if (!ok)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: expected '%c number v1 v2 v3 v4 base cmb emit name' (v4 = 0 "
                        "for a triangle)",
                        r->path, line, token[0][0]);
    if (count > 10)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: unexpected '%s' after the surface name",
                        r->path, line, token[10]);
    if (p.number > VS3_LARGEST_NUMBER)
        return rad_fail(error, RAD_ERR_UNSUPPORTED, "%s:%lu: surface number %u is above %d",
                        r->path, line, p.number, VS3_LARGEST_NUMBER);
    if (!(p.emissivity > 0 && p.emissivity <= 1))
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: surface %u: emissivity %g is outside (0,1]", r->path, line,
                        p.number, p.emissivity);
    if (count == 10) {
        if (strlen(token[9]) >= sizeof(p.name))
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: surface name longer than %zu bytes",
                            r->path, line, sizeof(p.name) - 1);
        snprintf(p.name, sizeof(p.name), "%s", token[9]);
    } else {
        snprintf(p.name, sizeof(p.name), "%u", p.number);
    }
    p.corner_count = p.vertex[3] ? 4 : 3;
    if (p.number >= r->number_capacity) {
        size_t old = r->number_capacity, capacity = old;
        if (!rad_grow_array((void **)&r->polygon_by_number, &capacity, (size_t)p.number + 1,
                            sizeof(*r->polygon_by_number)))
            return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        memset(r->polygon_by_number + old, 0, (capacity - old) * sizeof(uint32_t));
        r->number_capacity = capacity;
    }
    if (r->polygon_by_number[p.number])
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: surface %u is already defined on line %lu",
                        r->path, line, p.number,
                        r->polygon[r->polygon_by_number[p.number] - 1].line);
    if (!rad_grow_array((void **)&r->polygon, &r->polygon_capacity, r->polygon_count + 1,
                        sizeof(*r->polygon)))
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
    r->polygon[r->polygon_count++] = p;
    r->polygon_by_number[p.number] = (uint32_t)r->polygon_count;
    return RAD_OK;
}

/* Step 1: every line. */
static rad_status parse_file(vs3_reader *r, FILE *file, rad_error *error)
{
    char line[4096];
    unsigned long number = 0;
    while (fgets(line, sizeof(line), file)) {
        number++;
        if (!strchr(line, '\n') && !feof(file))
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: line longer than %zu characters",
                            r->path, number, sizeof(line) - 2);
        char *p = line;
        while (*p && isspace((unsigned char)*p))
            p++;
        char kind = *p;
        if (!kind || kind == '!' || kind == '/')
            continue;
        if (kind == '*' || kind == 'E' || kind == 'e')
            break; /* End of data */
        if (kind == 'T' || kind == 't') {
            char *title = p + 1;
            while (*title && isspace((unsigned char)*title))
                title++;
            size_t n = strlen(title);
            while (n && isspace((unsigned char)title[n - 1]))
                n--;
            snprintf(r->control.title, sizeof(r->control.title), "%.*s", (int)n, title);
            continue;
        }
        char *token[16];
        int count = tokenize(p, token, 16);
        if (strlen(token[0]) != 1)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: '%s' is not a View3D line (T, C, F, V, S, O, M, N, ! or "
                            "End of data)",
                            r->path, number, token[0]);
        rad_status status = RAD_OK;
        switch (toupper((unsigned char)kind)) {
        case 'C':
            status = parse_control(r, token, count, number, error);
            break;
        case 'F':
            if (count < 2 || strcmp(token[1], "3") != 0)
                return rad_fail(error, RAD_ERR_UNSUPPORTED,
                                "%s:%lu: geometry 'F %s' is not supported (only F 3: vertices "
                                "and surfaces given separately)",
                                r->path, number, count < 2 ? "" : token[1]);
            break;
        case 'V':
            status = parse_vertex(r, token, count, number, error);
            break;
        case 'S':
            status = parse_surface(r, VS3_SURFACE, token, count, number, error);
            break;
        case 'O':
            status = parse_surface(r, VS3_OBSTRUCTION, token, count, number, error);
            break;
        case 'N':
            status = parse_surface(r, VS3_NULL, token, count, number, error);
            break;
        case 'M':
            status = parse_surface(r, VS3_MASK, token, count, number, error);
            break;
        default:
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: '%c' is not a View3D line (T, C, F, V, S, O, M, N, ! or "
                            "End of data)",
                            r->path, number, kind);
        }
        if (status != RAD_OK)
            return status;
    }
    if (ferror(file))
        return rad_fail(error, RAD_ERR_IO, "%s: cannot read: %s", r->path, strerror(errno));
    if (r->polygon_count == 0)
        return rad_fail(error, RAD_ERR_PARSE, "%s: no surfaces (S or O lines)", r->path);
    return RAD_OK;
}

/* Newell's normal (not normalised: its length is twice the polygon's area). */
static rad_vec3 newell_normal(const rad_vec3 *c, uint32_t n)
{
    rad_vec3 normal = v3(0, 0, 0);
    for (uint32_t k = 0; k < n; k++)
        normal = v3_add(normal, v3_cross(c[k], c[(k + 1) % n]));
    return normal;
}

static double longest_extent(const rad_vec3 *c, uint32_t n)
{
    double longest = 0;
    for (uint32_t a = 0; a < n; a++)
        for (uint32_t b = a + 1; b < n; b++)
            longest = fmax(longest, v3_length(v3_sub(c[a], c[b])));
    return longest;
}

/* Step 2a: corners, normal, area, convexity of one polygon. */
static rad_status resolve_geometry(vs3_reader *r, vs3_polygon *p, rad_error *error)
{
    for (uint32_t k = 0; k < p->corner_count; k++) {
        uint32_t v = p->vertex[k];
        if (v == 0 || v >= r->vertex_capacity || !r->vertex_line[v])
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: surface %u uses undefined vertex %u",
                            r->path, p->line, p->number, v);
        for (uint32_t j = 0; j < k; j++)
            if (p->vertex[j] == v)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u uses vertex %u twice", r->path, p->line,
                                p->number, v);
        p->corner[k] = r->vertex[v];
    }
    double size = longest_extent(p->corner, p->corner_count);
    rad_vec3 normal = newell_normal(p->corner, p->corner_count);
    double twice_area = v3_length(normal);
    if (!(size > 0) || twice_area <= RAD_DEGENERATE_RELATIVE_AREA * size * size)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: surface %u has zero area", r->path,
                        p->line, p->number);
    p->area = 0.5 * twice_area;
    p->normal = v3_scale(normal, 1 / twice_area);
    if (p->corner_count == 4) {
        double off = fabs(v3_dot(v3_sub(p->corner[3], p->corner[0]), p->normal));
        for (uint32_t k = 1; k < 3; k++)
            off = fmax(off, fabs(v3_dot(v3_sub(p->corner[k], p->corner[0]), p->normal)));
        if (off > RAD_QUAD_FLATNESS * size)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: surface %u is not planar: a corner lies %g from the "
                            "plane of the others (size %g)",
                            r->path, p->line, p->number, off, size);
        for (uint32_t k = 0; k < 4; k++) {
            rad_vec3 a = v3_sub(p->corner[(k + 1) % 4], p->corner[k]);
            rad_vec3 b = v3_sub(p->corner[(k + 2) % 4], p->corner[(k + 1) % 4]);
            if (v3_dot(v3_cross(a, b), p->normal) < -RAD_DEGENERATE_RELATIVE_AREA * size * size)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u is not convex (the corner at vertex %u "
                                "turns the wrong way): split it into convex parts joined "
                                "with cmb",
                                r->path, p->line, p->number, p->vertex[(k + 1) % 4]);
        }
    }
    return RAD_OK;
}

/* Signed distance of point x from the plane through a, b containing direction n, positive
 * on the side of `inside`'s left (the polygon's interior for counter-clockwise edges). */
static double edge_side(rad_vec3 a, rad_vec3 b, rad_vec3 normal, rad_vec3 x)
{
    rad_vec3 inward = v3_cross(normal, v3_sub(b, a));
    return v3_dot(v3_sub(x, a), inward) / v3_length(inward);
}

/* Step 2b: a subsurface or null surface lies in its base's plane, inside it, facing the
 * same way (null: the opposite way). */
static rad_status check_inside_base(vs3_reader *r, const vs3_polygon *p, const vs3_polygon *base,
                                    rad_error *error)
{
    double size = longest_extent(base->corner, base->corner_count);
    double tolerance = RAD_QUAD_FLATNESS * size;
    for (uint32_t k = 0; k < p->corner_count; k++) {
        if (fabs(v3_dot(v3_sub(p->corner[k], base->corner[0]), base->normal)) > tolerance)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: surface %u is not in the plane of its base surface %u",
                            r->path, p->line, p->number, base->number);
    }
    double facing = v3_dot(p->normal, base->normal);
    bool opposite = p->kind == VS3_NULL || p->kind == VS3_MASK;
    if (opposite ? facing > -1 + RAD_REGION_NORMAL : facing < 1 - RAD_REGION_NORMAL)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: surface %u must face %s its base surface %u", r->path, p->line,
                        p->number, opposite ? "opposite to" : "the same way as", base->number);
    for (uint32_t k = 0; k < p->corner_count; k++) {
        for (uint32_t e = 0; e < base->corner_count; e++)
            if (edge_side(base->corner[e], base->corner[(e + 1) % base->corner_count],
                          base->normal, p->corner[k]) < -tolerance)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u is not inside its base surface %u", r->path,
                                p->line, p->number, base->number);
    }
    return RAD_OK;
}

static rad_status check_holes(vs3_reader *r, rad_error *error);

/* Step 2: references and checks. */
static rad_status resolve(vs3_reader *r, rad_error *error)
{
    for (size_t i = 0; i < r->polygon_count; i++) {
        rad_status status = resolve_geometry(r, &r->polygon[i], error);
        if (status != RAD_OK)
            return status;
    }
    for (size_t i = 0; i < r->polygon_count; i++) {
        vs3_polygon *p = &r->polygon[i];
        p->base_index = UINT32_MAX;
        p->root = (uint32_t)i;
        uint32_t refs[2] = {p->base, p->cmb};
        const char *what[2] = {"base", "cmb"};
        for (int k = 0; k < 2; k++) {
            if (!refs[k])
                continue;
            uint32_t index = refs[k] < r->number_capacity ? r->polygon_by_number[refs[k]] : 0;
            if (!index || index - 1 >= i)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u: %s %u is not a surface defined before it",
                                r->path, p->line, p->number, what[k], refs[k]);
        }
        if (p->base) {
            p->base_index = r->polygon_by_number[p->base] - 1;
            const vs3_polygon *base = &r->polygon[p->base_index];
            if (base->kind == VS3_NULL || base->kind == VS3_MASK)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u: base %u is a %s surface", r->path, p->line,
                                p->number, p->base, base->kind == VS3_NULL ? "null" : "mask");
            if ((p->kind == VS3_MASK || p->kind == VS3_NULL) && base->kind != VS3_SURFACE)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u: the base of a mask or null surface must be "
                                "a radiating surface (S)",
                                r->path, p->line, p->number);
            if (p->kind == VS3_OBSTRUCTION)
                return rad_fail(error, RAD_ERR_UNSUPPORTED,
                                "%s:%lu: obstruction surface %u with a base is not supported",
                                r->path, p->line, p->number);
            rad_status status = check_inside_base(r, p, base, error);
            if (status != RAD_OK)
                return status;
        } else if (p->kind == VS3_NULL || p->kind == VS3_MASK) {
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: %s surface %u needs a base surface",
                            r->path, p->line, p->kind == VS3_NULL ? "null" : "mask", p->number);
        }
        if (p->cmb) {
            vs3_polygon *target = &r->polygon[r->polygon_by_number[p->cmb] - 1];
            p->root = target->root; /* a chain of combinations ends at its first surface */
            const vs3_polygon *root = &r->polygon[p->root];
            if (p->kind == VS3_NULL || p->kind == VS3_MASK || root->kind != p->kind)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: surface %u combines with surface %u of another kind",
                                r->path, p->line, p->number, p->cmb);
        }
    }
    return check_holes(r, error);
}

/* Clips a convex polygon (in place) to the side of the plane where side() >= 0. */
static uint32_t clip(rad_vec3 *c, uint32_t n, rad_vec3 a, rad_vec3 b, rad_vec3 normal,
                     double sign)
{
    rad_vec3 out[VS3_PIECE_CORNERS];
    double d[VS3_PIECE_CORNERS];
    uint32_t m = 0;
    for (uint32_t k = 0; k < n; k++)
        d[k] = sign * edge_side(a, b, normal, c[k]);
    for (uint32_t k = 0; k < n && m + 2 <= VS3_PIECE_CORNERS; k++) {
        uint32_t next = (k + 1) % n;
        if (d[k] >= 0)
            out[m++] = c[k];
        if ((d[k] > 0 && d[next] < 0) || (d[k] < 0 && d[next] > 0))
            out[m++] = v3_lerp(c[k], c[next], d[k] / (d[k] - d[next]));
    }
    memcpy(c, out, m * sizeof(*c));
    return m;
}

typedef struct vs3_piece {
    rad_vec3 corner[VS3_PIECE_CORNERS];
    uint32_t count;
} vs3_piece;

static double piece_area(const vs3_piece *p)
{
    return p->count < 3 ? 0 : 0.5 * v3_length(newell_normal(p->corner, p->count));
}

/* The corners of hole h counter-clockwise about its base's normal (a null surface or mask
 * faces the other way). */
static vs3_piece hole_piece(const vs3_polygon *h)
{
    vs3_piece piece;
    piece.count = h->corner_count;
    for (uint32_t k = 0; k < h->corner_count; k++)
        piece.corner[k] = h->kind == VS3_SURFACE ? h->corner[k]
                                                 : h->corner[h->corner_count - 1 - k];
    return piece;
}

/* Step 2c: the holes of a base (its subsurfaces, null surfaces and masks, all cut out of
 * it) do not overlap, which would count the overlap twice (in two surfaces, and out of the
 * base twice); and they leave some of the base: a base covered entirely would have no
 * area, so no view factors, and vanish from the matrix. Both are refused. Each hole is
 * convex, so the overlap of two is one hole clipped by the other's edges. */
static rad_status check_holes(vs3_reader *r, rad_error *error)
{
    size_t n = r->polygon_count;
    uint32_t *first = rad_alloc_array(n, sizeof(*first)); /* per base: its first hole + 1 */
    uint32_t *next = rad_alloc_array(n, sizeof(*next));   /* per hole: the next one + 1 */
    double *covered = rad_alloc_array(n, sizeof(*covered));
    rad_status status = RAD_OK;
    if (!first || !next || !covered) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        goto done;
    }
    for (size_t i = n; i-- > 0;) {
        uint32_t base = r->polygon[i].base_index;
        if (base == UINT32_MAX)
            continue;
        next[i] = first[base];
        first[base] = (uint32_t)i + 1;
        covered[base] += r->polygon[i].area;
    }
    for (size_t b = 0; b < n && status == RAD_OK; b++) {
        const vs3_polygon *base = &r->polygon[b];
        for (uint32_t i = first[b]; i && status == RAD_OK; i = next[i - 1]) {
            const vs3_polygon *one = &r->polygon[i - 1];
            vs3_piece edges = hole_piece(one);
            for (uint32_t j = next[i - 1]; j; j = next[j - 1]) {
                const vs3_polygon *other = &r->polygon[j - 1];
                vs3_piece overlap = hole_piece(other);
                for (uint32_t e = 0; e < edges.count && overlap.count >= 3; e++)
                    overlap.count = clip(overlap.corner, overlap.count, edges.corner[e],
                                         edges.corner[(e + 1) % edges.count], base->normal, 1);
                double area = piece_area(&overlap);
                if (area > RAD_QUAD_FLATNESS * fmin(one->area, other->area)) {
                    status = rad_fail(error, RAD_ERR_PARSE,
                                      "%s:%lu: surface %u '%s' overlaps surface %u '%s' (line "
                                      "%lu) by area %g, both cut out of base surface %u: the "
                                      "overlap would be counted twice",
                                      r->path, other->line, other->number, other->name,
                                      one->number, one->name, one->line, area, base->number);
                    break;
                }
            }
        }
        if (status == RAD_OK && first[b] &&
            base->area - covered[b] <= RAD_QUAD_FLATNESS * base->area) {
            const vs3_polygon *hole = &r->polygon[first[b] - 1];
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s:%lu: surface %u '%s' is covered entirely by what is cut out "
                              "of it (surface %u '%s', line %lu%s): nothing of it would be "
                              "left to have view factors; remove it, and give what covers it "
                              "base 0",
                              r->path, base->line, base->number, base->name, hole->number,
                              hole->name, hole->line, next[first[b] - 1] ? ", and more" : "");
        }
    }
done:
    free(first);
    free(next);
    free(covered);
    return status;
}

/* Adds a convex polygon as a fan of triangles, skipping slivers left by clipping. */
static rad_status add_fan(scene_builder *builder, uint32_t surface, uint32_t material,
                          const vs3_piece *piece, double smallest_area, rad_error *error)
{
    for (uint32_t k = 1; k + 1 < piece->count; k++) {
        rad_vec3 a = piece->corner[0], b = piece->corner[k], c = piece->corner[k + 1];
        if (0.5 * v3_length(v3_cross(v3_sub(b, a), v3_sub(c, a))) <= smallest_area)
            continue;
        rad_status status = scene_builder_triangle(builder, surface, material, a, b, c, error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

/* Step 3 for one polygon: cut out its holes (the polygons whose base it is), then
 * triangles. */
static rad_status add_polygon(vs3_reader *r, scene_builder *builder, size_t index,
                              uint32_t surface, uint32_t material, rad_error *error)
{
    const vs3_polygon *p = &r->polygon[index];
    size_t capacity = 1, count = 1;
    vs3_piece *pieces = rad_alloc_array(1, sizeof(*pieces));
    rad_status status = RAD_OK;
    if (!pieces)
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
    memcpy(pieces[0].corner, p->corner, p->corner_count * sizeof(rad_vec3));
    pieces[0].count = p->corner_count;
    double smallest = RAD_DEGENERATE_RELATIVE_AREA * p->area;
    for (size_t h = index + 1; h < r->polygon_count; h++) {
        const vs3_polygon *hole = &r->polygon[h];
        if (hole->base_index != index)
            continue;
        rad_vec3 corner[4];
        for (uint32_t k = 0; k < hole->corner_count; k++) /* counter-clockwise like p */
            corner[k] = hole->kind == VS3_SURFACE ? hole->corner[k]
                                                  : hole->corner[hole->corner_count - 1 - k];
        size_t old_count = count;
        for (size_t q = 0; q < old_count; q++) {
            vs3_piece rest = pieces[q];
            pieces[q].count = 0; /* replaced by what lies outside the hole */
            for (uint32_t e = 0; e < hole->corner_count && rest.count >= 3; e++) {
                rad_vec3 a = corner[e], b = corner[(e + 1) % hole->corner_count];
                vs3_piece outside = rest;
                outside.count = clip(outside.corner, outside.count, a, b, p->normal, -1);
                rest.count = clip(rest.corner, rest.count, a, b, p->normal, 1);
                if (outside.count + 4 > VS3_PIECE_CORNERS || rest.count + 4 > VS3_PIECE_CORNERS) {
                    status = rad_fail(error, RAD_ERR_UNSUPPORTED,
                                      "%s:%lu: surface %u has too many subsurfaces to cut out",
                                      r->path, p->line, p->number);
                    goto done;
                }
                if (piece_area(&outside) <= smallest)
                    continue;
                if (!rad_grow_array((void **)&pieces, &capacity, count + 1, sizeof(*pieces))) {
                    status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
                    goto done;
                }
                pieces[count++] = outside;
            }
        }
    }
    for (size_t q = 0; q < count && status == RAD_OK; q++)
        status = add_fan(builder, surface, material, &pieces[q], smallest, error);
done:
    free(pieces);
    return status;
}

static rad_status build(vs3_reader *r, scene_builder *builder, rad_error *error)
{
    rad_material grey;
    memset(&grey, 0, sizeof(grey));
    snprintf(grey.name, sizeof(grey.name), "vs3");
    grey.albedo = (rad_rgb){0.5, 0.5, 0.5};
    uint32_t material = scene_builder_material(builder, &grey);
    double *area = rad_alloc_array(r->polygon_count, sizeof(*area));
    double *weighted = rad_alloc_array(r->polygon_count, sizeof(*weighted));
    uint32_t *surface = rad_alloc_array(r->polygon_count, sizeof(*surface));
    rad_status status = RAD_OK;
    if (material == UINT32_MAX || !area || !weighted || !surface) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
        goto done;
    }
    for (size_t i = 0; i < r->polygon_count; i++) {
        const vs3_polygon *p = &r->polygon[i];
        if (scene_builder_find_surface(builder, p->name) != UINT32_MAX) {
            status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: surface name '%s' is used twice",
                              r->path, p->line, p->name);
            goto done;
        }
        if (p->root == i) {
            surface[i] = scene_builder_surface(builder, p->name);
            if (surface[i] == UINT32_MAX) {
                status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
                goto done;
            }
            scene_builder_set_surface_flags(builder, surface[i],
                                            p->kind == VS3_SURFACE ? 0u
                                                                   : RAD_SURFACE_OBSTRUCTION);
        } else {
            surface[i] = surface[p->root];
            /* reserve the combined polygon's own name, so that no later surface takes it */
            if (scene_builder_surface(builder, p->name) == UINT32_MAX) {
                status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
                goto done;
            }
        }
        area[p->root] += p->area;
        weighted[p->root] += p->area * p->emissivity;
        status = add_polygon(r, builder, i, surface[i], material, error);
        if (status != RAD_OK)
            goto done;
    }
    for (size_t i = 0; i < r->polygon_count; i++)
        if (r->polygon[i].root == i)
            scene_builder_set_surface_emissivity(builder, surface[i], weighted[i] / area[i]);
done:
    free(area);
    free(weighted);
    free(surface);
    return status;
}

rad_status rad_scene_load_vs3(const char *path, const rad_load_options *options,
                              rad_scene **out, rad_vs3_control *control, rad_error *error)
{
    *out = NULL;
    vs3_reader r;
    memset(&r, 0, sizeof(r));
    r.path = path;
    if (options)
        r.options = *options;
    r.control.eps = 1e-4;
    r.control.max_u = 12;
    r.control.max_o = 8;
    FILE *file = fopen(path, "r");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    scene_builder *builder = NULL;
    rad_status status = parse_file(&r, file, error);
    fclose(file);
    if (status == RAD_OK)
        status = resolve(&r, error);
    if (status == RAD_OK)
        status = scene_builder_create(path, options, &builder, error);
    if (status == RAD_OK)
        status = build(&r, builder, error);
    if (status == RAD_OK) {
        status = scene_builder_finish(builder, out, error);
        builder = NULL;
    }
    if (status == RAD_OK && control)
        *control = r.control;
    scene_builder_destroy(builder);
    reader_free(&r);
    return status;
}

/* The scene surface named `name`, or UINT32_MAX. */
static uint32_t scene_surface(const rad_scene *scene, const char *name)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, name) == 0)
            return s;
    return UINT32_MAX;
}

rad_status rad_viewfactor_matrix_apply_vs3_masks(const char *path, rad_scene *scene,
                                                 rad_viewfactor_matrix **matrix,
                                                 rad_error *error)
{
    vs3_reader r;
    memset(&r, 0, sizeof(r));
    r.path = path;
    rad_viewfactor_matrix *m = *matrix, *result = NULL;
    uint32_t n = m->n;
    uint32_t *base_of = NULL;   /* per surface: the base a mask masks, UINT32_MAX if none */
    double *extra = NULL;       /* per surface: masked area to add back to a base */
    rad_status status = RAD_OK;
    FILE *file = fopen(path, "r");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    status = parse_file(&r, file, error);
    fclose(file);
    if (status == RAD_OK)
        status = resolve(&r, error);
    if (status != RAD_OK)
        goto done;
    if (n != scene->surface_count) {
        status = rad_fail(error, RAD_ERR_INVALID, "%s: the matrix has %u surfaces, the scene %u",
                          path, n, scene->surface_count);
        goto done;
    }
    base_of = rad_alloc_array(n, sizeof(*base_of));
    extra = rad_alloc_array(n, sizeof(*extra));
    if (!base_of || !extra) {
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    for (uint32_t I = 0; I < n; I++)
        base_of[I] = UINT32_MAX;
    uint64_t added = 0;
    for (size_t i = 0; i < r.polygon_count; i++) {
        const vs3_polygon *p = &r.polygon[i];
        if (p->kind != VS3_MASK)
            continue;
        const vs3_polygon *base = &r.polygon[r.polygon[p->base_index].root];
        uint32_t M = scene_surface(scene, p->name), B = scene_surface(scene, base->name);
        if (M == UINT32_MAX || B == UINT32_MAX) {
            status = rad_fail(error, RAD_ERR_INVALID,
                              "%s:%lu: mask '%s' or its base '%s' is not a surface of the scene",
                              path, p->line, p->name, base->name);
            goto done;
        }
        base_of[M] = B;
        extra[B] += p->area;
        extra[M] = p->area;
        added += 2;
    }
    if (!added)
        goto done;
    status = rad_viewfactor_matrix_create(n, m->row_start[n] + added, &result, error);
    if (status != RAD_OK)
        goto done;
    uint64_t k = 0;
    for (uint32_t I = 0; I < n; I++) {
        result->row_start[I] = k;
        if (base_of[I] != UINT32_MAX) { /* a mask sees only its base */
            result->area[I] = extra[I];
            result->column[k] = base_of[I];
            result->value[k++] = 1;
            continue;
        }
        if (!(extra[I] > 0)) { /* neither mask nor base: as computed */
            result->area[I] = m->area[I];
            for (uint64_t e = m->row_start[I]; e < m->row_start[I + 1]; e++, k++) {
                result->column[k] = m->column[e];
                result->value[k] = m->value[e];
                result->error_bound[k] = m->error_bound[e];
            }
            continue;
        }
        /* a base: its cut part's factors, over the whole area; then its masks */
        double whole = m->area[I] + extra[I];
        double scale = m->area[I] / whole;
        result->area[I] = whole;
        uint64_t e = m->row_start[I];
        for (uint32_t J = 0; J < n; J++) {
            bool masked = base_of[J] == I;
            bool stored = e < m->row_start[I + 1] && m->column[e] == J;
            if (!masked && !stored)
                continue;
            result->column[k] = J;
            result->value[k] = masked ? extra[J] / whole : m->value[e] * scale;
            result->error_bound[k] = masked ? 0 : m->error_bound[e] * scale;
            k++;
            if (stored)
                e++;
        }
    }
    result->row_start[n] = k;
    for (uint32_t I = 0; I < n; I++)
        if (base_of[I] != UINT32_MAX)
            scene->surfaces[I].flags &= ~(uint32_t)RAD_SURFACE_OBSTRUCTION;
    rad_viewfactor_matrix_destroy(m);
    *matrix = result;
done:
    free(base_of);
    free(extra);
    reader_free(&r);
    return status;
}
