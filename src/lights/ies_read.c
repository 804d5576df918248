/*
 * ies_read.c - IES LM-63 photometric files (rad_photometry_read).
 *
 * The file, in order:
 *   - a format line: none (LM-63-1986), `IESNA91` (1991), `IESNA:LM-63-1995`,
 *     `IESNA:LM-63-2002` or `IES:LM-63:2019` (also `IESNA:LM-63-1986` / `-1991`); any other
 *     line starting with `IESNA` or `IES:LM-63` is read as 2002 with a warning;
 *   - header lines (`[KEYWORD] value` from 1991 on, free text in 1986), not interpreted;
 *   - `TILT=NONE`, `TILT=INCLUDE` (then the tilt block: lamp-to-luminaire geometry, the
 *     number of tilt angles, the angles, their multiplying factors; read, checked to be
 *     numbers and ignored with one warning) or `TILT=<file>` (ignored with a warning);
 *   - the numbers, separated by white space or commas, spread over lines freely: number of
 *     lamps, lumens per lamp (-1: absolute photometry), candela multiplier, number of
 *     vertical angles, number of horizontal angles, photometric type (1 C, 2 B, 3 A), units
 *     type, width, length, height; ballast factor, the twelfth number (below), input
 *     watts; the vertical angles, the horizontal angles, then the candela values, for each
 *     horizontal angle all the vertical ones.
 *
 * Factors: a stored candela value is the file's value x the candela multiplier x the
 * ballast factor, and also x the twelfth number in the formats where it is the
 * "ballast-lamp photometric factor" (1986, 1991 and 1995). In LM-63-2002 that number is
 * "future use" and in 2019 the file generation type (a code such as 1.10000): read there
 * and not applied. The number of lamps, lumens per lamp, units, dimensions and input watts
 * are read as numbers and not used: the candela values are the luminaire's already, in
 * relative photometry too (they are for its rated lamp lumens).
 *
 * Checks (RAD_ERR_PARSE, "FILE:LINE: ..." with the line of the offending number; a file
 * that ends early names its last line): a missing TILT line; a token that is not a plain
 * decimal number (no inf, nan or hex) or is out of double's range; counts that are not
 * integers in 1..100000; a photometric type outside 1..3; vertical angles not strictly
 * ascending or outside [0,180] (type C) or [-90,90] (types A and B); horizontal angles not
 * strictly ascending, outside their range, or not one of the symmetric variants (type C:
 * a single 0, 0..90, 0..180, 90..270, 0..360; types A and B: a single 0, 0..90, -90..90);
 * a negative multiplier or ballast factor, or factors whose product overflows; a
 * negative candela value, or one above IES_MOST_CANDELA (1e30) once multiplied (no
 * luminaire comes near, and it keeps every interpolation and the flux finite); a short
 * table; NUL bytes; a file over 16 MiB. Text after the table is ignored with a warning.
 * Not checked: the units type, the dimensions, the lamp count and lumens (only that they
 * are numbers), the vertical angles' first and last values (a web listed 0..90 is simply
 * dark above the horizontal). A single vertical angle is read; its web has no flux.
 *
 * The flux (rad_photometry.lumens) is the exact integral over the sphere of the web as
 * rad_photometry_candela interpolates it (bilinear in the angles in degrees, the
 * symmetric variants unfolded): per interval of the polar angle the integral of a linear
 * function times sin (type C: the vertical angle from the nadir; types A and B: the
 * horizontal angle from the polar axis's equator, whose weight is cos), and the trapezoid
 * rule (exact for linear) along the other angle.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/alloc.h"
#include "core/error.h"
#include "radiosity.h"

#define IES_MOST_BYTES ((size_t)16 << 20) /* 16 MiB */
#define IES_MOST_COUNT 100000u            /* angles of one kind, tilt angles */
#define IES_MOST_CANDELA 1e30             /* a stored candela value */
#define QUOTE 40                          /* characters of a token quoted in a message */

typedef enum ies_format { IES_1986, IES_1991, IES_1995, IES_2002, IES_2019 } ies_format;

typedef struct reader {
    const char *path;
    const char *text; /* the file, NUL-terminated; no other NUL in it */
    size_t size;
    size_t pos;              /* the cursor */
    unsigned long line;      /* the line of text[pos] */
    unsigned long last_line; /* the line the file ends on */
    rad_log_fn log;
    void *log_user;
    rad_error *error;
} reader;

/* A token: where it starts, how long it is, its line. */
typedef struct token {
    const char *start;
    size_t length;
    unsigned long line;
} token;

/* ------------------------------------------------------------------------------------ */
/* The file                                                                             */

/* Reads the whole file (at most IES_MOST_BYTES; one byte more tells it is larger). */
static rad_status read_whole(const char *path, char **text, size_t *size, rad_error *error)
{
    *text = NULL;
    *size = 0;
    FILE *file = fopen(path, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    size_t capacity = 0, length = 0;
    char *data = NULL;
    for (;;) {
        if (length + 1 >= capacity) { /* room for a byte more and the NUL */
            size_t grown = capacity ? 2 * capacity : 65536;
            if (grown > IES_MOST_BYTES + 2)
                grown = IES_MOST_BYTES + 2;
            char *bigger = rad_resize_array(data, grown, 1);
            if (!bigger) {
                free(data);
                fclose(file);
                return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
            }
            data = bigger;
            capacity = grown;
        }
        /* leave one byte for the terminating NUL */
        size_t wanted = capacity - 1 - length;
        size_t got = fread(data + length, 1, wanted, file);
        length += got;
        if (length > IES_MOST_BYTES) {
            free(data);
            fclose(file);
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s: larger than 16 MiB: not a photometric file this reader takes",
                            path);
        }
        if (got < wanted) {
            if (ferror(file)) {
                int saved = errno;
                free(data);
                fclose(file);
                return rad_fail(error, RAD_ERR_IO, "%s: cannot read: %s", path,
                                strerror(saved));
            }
            break; /* the end of the file */
        }
    }
    fclose(file);
    data[length] = 0;
    *text = data;
    *size = length;
    return RAD_OK;
}

static bool is_line_end(char c) { return c == '\n' || c == '\r'; }

static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }

static bool is_separator(char c) { return is_blank(c) || is_line_end(c) || c == ','; }

/* Steps over the line end at pos (CR LF, LF or a lone CR). */
static void skip_line_end(reader *r)
{
    if (r->text[r->pos] == '\r' && r->pos + 1 < r->size && r->text[r->pos + 1] == '\n')
        r->pos++;
    r->pos++;
    r->line++;
}

/* The line the text ends on (a line end at the very end does not start another). */
static unsigned long count_last_line(const char *text, size_t size)
{
    unsigned long line = 1;
    for (size_t k = 0; k < size; k++) {
        if (text[k] == '\n' || (text[k] == '\r' && (k + 1 >= size || text[k + 1] != '\n'))) {
            if (k + 1 < size)
                line++;
        }
    }
    return line;
}

/* The line of byte `at`. */
static unsigned long line_of(const char *text, size_t at)
{
    unsigned long line = 1;
    for (size_t k = 0; k < at; k++)
        if (text[k] == '\n' || (text[k] == '\r' && text[k + 1] != '\n'))
            line++;
    return line;
}

/* The next line without its end, false at the end of the file. */
static bool next_line(reader *r, token *line)
{
    if (r->pos >= r->size)
        return false;
    line->start = r->text + r->pos;
    line->line = r->line;
    size_t end = r->pos;
    while (end < r->size && !is_line_end(r->text[end]))
        end++;
    line->length = end - r->pos;
    r->pos = end;
    if (r->pos < r->size)
        skip_line_end(r);
    return true;
}

/* The next token (white space and commas separate them), false at the end of the file. */
static bool next_token(reader *r, token *t)
{
    while (r->pos < r->size && is_separator(r->text[r->pos])) {
        if (is_line_end(r->text[r->pos]))
            skip_line_end(r);
        else
            r->pos++;
    }
    if (r->pos >= r->size)
        return false;
    t->start = r->text + r->pos;
    t->line = r->line;
    size_t end = r->pos;
    while (end < r->size && !is_separator(r->text[end]))
        end++;
    t->length = end - r->pos;
    r->pos = end;
    return true;
}

/* Trims blanks at both ends. */
static void trim(token *t)
{
    while (t->length && is_blank(t->start[0])) {
        t->start++;
        t->length--;
    }
    while (t->length && is_blank(t->start[t->length - 1]))
        t->length--;
}

static bool starts_with(const token *t, const char *prefix)
{
    size_t n = strlen(prefix);
    return t->length >= n && strncasecmp(t->start, prefix, n) == 0;
}

static int quoted_length(const token *t) { return t->length > QUOTE ? QUOTE : (int)t->length; }

/* ------------------------------------------------------------------------------------ */
/* Numbers                                                                              */

typedef enum scanned { SCAN_OK, SCAN_END, SCAN_NOT_NUMBER, SCAN_RANGE } scanned;

/* A plain decimal number: digits, sign, point and exponent only (strtod would also take
 * inf, nan and hexadecimal), all of the token. */
static scanned parse_number(const token *t, double *value)
{
    char buffer[256];
    if (t->length == 0 || t->length >= sizeof(buffer))
        return SCAN_NOT_NUMBER;
    for (size_t k = 0; k < t->length; k++) {
        char c = t->start[k];
        if (!((c >= '0' && c <= '9') || c == '+' || c == '-' || c == '.' || c == 'e' ||
              c == 'E'))
            return SCAN_NOT_NUMBER;
    }
    memcpy(buffer, t->start, t->length);
    buffer[t->length] = 0;
    char *end = NULL;
    *value = strtod(buffer, &end);
    if (end != buffer + t->length)
        return SCAN_NOT_NUMBER;
    if (!isfinite(*value))
        return SCAN_RANGE;
    return SCAN_OK;
}

static scanned scan_number(reader *r, token *t, double *value)
{
    if (!next_token(r, t))
        return SCAN_END;
    return parse_number(t, value);
}

/* A refusal for a number of the header or the tilt block: `what` names it. */
static rad_status number_failure(reader *r, scanned how, const token *t, const char *what)
{
    if (how == SCAN_END)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the file ends before the %s", r->path,
                        r->last_line, what);
    if (how == SCAN_RANGE)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the %s '%.*s' is out of range",
                        r->path, t->line, what, quoted_length(t), t->start);
    return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the %s '%.*s' is not a number", r->path,
                    t->line, what, quoted_length(t), t->start);
}

static rad_status read_number(reader *r, const char *what, double *value, token *t)
{
    scanned how = scan_number(r, t, value);
    return how == SCAN_OK ? RAD_OK : number_failure(r, how, t, what);
}

/* An integer in [least, IES_MOST_COUNT]. */
static rad_status read_count(reader *r, const char *what, uint32_t least, uint32_t *count)
{
    double value;
    token t;
    rad_status status = read_number(r, what, &value, &t);
    if (status != RAD_OK)
        return status;
    if (value != floor(value) || value < least)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the %s '%.*s' is not %s integer",
                        r->path, t.line, what, quoted_length(&t), t.start,
                        least ? "a positive" : "a non-negative");
    if (value > IES_MOST_COUNT)
        return rad_fail(r->error, RAD_ERR_PARSE,
                        "%s:%lu: the %s %.0f is more than this reader takes (%u)", r->path,
                        t.line, what, value, IES_MOST_COUNT);
    *count = (uint32_t)value;
    return RAD_OK;
}

/* A number that is not negative. */
static rad_status read_factor(reader *r, const char *what, double *value, token *t)
{
    rad_status status = read_number(r, what, value, t);
    if (status == RAD_OK && *value < 0)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the %s %g is negative", r->path,
                        t->line, what, *value);
    return status;
}

/* ------------------------------------------------------------------------------------ */
/* The header and the tilt block                                                        */

/* The format line, if line 1 is one (the reader is then past it). */
static ies_format read_format(reader *r)
{
    size_t start = r->pos;
    unsigned long line = r->line;
    token t;
    if (!next_line(r, &t))
        return IES_1986;
    trim(&t);
    static const struct {
        const char *prefix;
        ies_format format;
    } known[] = {{"IESNA91", IES_1991},           {"IESNA:LM-63-1986", IES_1986},
                 {"IESNA:LM-63-1991", IES_1991},  {"IESNA:LM-63-1995", IES_1995},
                 {"IESNA:LM-63-2002", IES_2002},  {"IES:LM-63:2019", IES_2019}};
    for (size_t k = 0; k < sizeof(known) / sizeof(known[0]); k++)
        if (starts_with(&t, known[k].prefix))
            return known[k].format;
    if (starts_with(&t, "IESNA") || starts_with(&t, "IES:LM-63")) {
        rad_warn(r->log, r->log_user, "%s:%lu: unknown format line '%.*s': read as LM-63-2002",
                 r->path, t.line, quoted_length(&t), t.start);
        return IES_2002;
    }
    r->pos = start; /* 1986: line 1 is a header line (or the TILT line) */
    r->line = line;
    return IES_1986;
}

/* If `line` is a TILT line, its value (trimmed). */
static bool tilt_value(const token *line, token *value)
{
    token t = *line;
    trim(&t);
    if (!starts_with(&t, "TILT"))
        return false;
    t.start += 4;
    t.length -= 4;
    trim(&t);
    if (t.length == 0 || t.start[0] != '=')
        return false;
    t.start++;
    t.length--;
    trim(&t);
    *value = t;
    return true;
}

/* Reads and drops the tilt block of TILT=INCLUDE. */
static rad_status skip_tilt_block(reader *r)
{
    double value;
    token t;
    rad_status status = read_number(r, "lamp-to-luminaire geometry of the TILT=INCLUDE block",
                                    &value, &t);
    uint32_t count = 0;
    if (status == RAD_OK)
        status = read_count(r, "number of tilt angles", 0, &count);
    for (int part = 0; part < 2 && status == RAD_OK; part++) {
        const char *what = part == 0 ? "tilt angles" : "tilt multiplying factors";
        for (uint32_t k = 0; k < count && status == RAD_OK; k++) {
            scanned how = scan_number(r, &t, &value);
            if (how == SCAN_END)
                status = rad_fail(r->error, RAD_ERR_PARSE,
                                  "%s:%lu: the file ends after %u of %u %s", r->path,
                                  r->last_line, k, count, what);
            else if (how != SCAN_OK)
                status = rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: %s %u: '%.*s' is %s",
                                  r->path, t.line, what, k + 1, quoted_length(&t), t.start,
                                  how == SCAN_RANGE ? "out of range" : "not a number");
        }
    }
    return status;
}

/* The header lines up to and including TILT= (and its block). */
static rad_status read_header(reader *r)
{
    token line, value;
    for (;;) {
        if (!next_line(r, &line))
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: no TILT= line (the header ends with TILT=NONE, "
                            "TILT=INCLUDE or TILT=<file>)",
                            r->path, r->last_line);
        if (tilt_value(&line, &value))
            break;
    }
    if (value.length == 0)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: TILT= without a value", r->path,
                        line.line);
    if (value.length == 4 && strncasecmp(value.start, "NONE", 4) == 0)
        return RAD_OK;
    if (value.length == 7 && strncasecmp(value.start, "INCLUDE", 7) == 0) {
        rad_status status = skip_tilt_block(r);
        if (status == RAD_OK)
            rad_warn(r->log, r->log_user,
                     "%s:%lu: TILT=INCLUDE: the tilt data is ignored (the lamps are taken as "
                     "they were photometered)",
                     r->path, line.line);
        return status;
    }
    rad_warn(r->log, r->log_user,
             "%s:%lu: TILT=%.*s: the tilt file is ignored (the lamps are taken as they were "
             "photometered)",
             r->path, line.line, quoted_length(&value), value.start);
    return RAD_OK;
}

/* ------------------------------------------------------------------------------------ */
/* The angles and the table                                                             */

/* Reads `count` strictly ascending angles in [least, most]; the lines of the first and the
 * last go to the caller (for the check of the symmetric variants). */
static rad_status read_angles(reader *r, const char *what, uint32_t count, double least,
                              double most, double *angles, unsigned long *first_line,
                              unsigned long *last_line)
{
    for (uint32_t k = 0; k < count; k++) {
        token t;
        double value = 0;
        scanned how = scan_number(r, &t, &value);
        if (how == SCAN_END)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: the file ends after %u of %u %s angles", r->path,
                            r->last_line, k, count, what);
        if (how != SCAN_OK)
            return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: %s angle %u: '%.*s' is %s",
                            r->path, t.line, what, k + 1, quoted_length(&t), t.start,
                            how == SCAN_RANGE ? "out of range" : "not a number");
        if (value < least || value > most)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: %s angle %u is %g, outside [%g, %g] for this photometric "
                            "type",
                            r->path, t.line, what, k + 1, value, least, most);
        if (k > 0 && !(value > angles[k - 1]))
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: %s angle %u is %g, not above the one before (%g): not "
                            "ascending",
                            r->path, t.line, what, k + 1, value, angles[k - 1]);
        angles[k] = value + 0.0; /* -0 becomes 0 */
        if (k == 0)
            *first_line = t.line;
        *last_line = t.line;
    }
    return RAD_OK;
}

/* The horizontal angles form one of the symmetric variants of their type. */
static rad_status check_horizontal_set(reader *r, uint32_t type, const double *h, uint32_t count,
                                       unsigned long first_line, unsigned long last_line)
{
    double first = h[0], last = h[count - 1];
    if (type == 1) {
        const char *variants = "type C's are a single 0, 0..90, 0..180, 90..270 or 0..360";
        if (count == 1 && first != 0)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: the single horizontal angle is %g, not 0 (%s)", r->path,
                            first_line, first, variants);
        if (first != 0 && first != 90)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: the horizontal angles start at %g (%s)", r->path,
                            first_line, first, variants);
        if (count > 1 && ((first == 0 && last != 90 && last != 180 && last != 360) ||
                          (first == 90 && last != 270)))
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: the horizontal angles run %g..%g (%s)", r->path, last_line,
                            first, last, variants);
        return RAD_OK;
    }
    const char *variants = "types A and B have a single 0, 0..90 or -90..90";
    if (count == 1 && first != 0)
        return rad_fail(r->error, RAD_ERR_PARSE,
                        "%s:%lu: the single horizontal angle is %g, not 0 (%s)", r->path,
                        first_line, first, variants);
    if (first != 0 && first != -90)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the horizontal angles start at %g (%s)",
                        r->path, first_line, first, variants);
    if (count > 1 && last != 90)
        return rad_fail(r->error, RAD_ERR_PARSE, "%s:%lu: the horizontal angles run %g..%g (%s)",
                        r->path, last_line, first, last, variants);
    return RAD_OK;
}

/* The numbers of the whole table multiplied: candela[h * vertical_count + v]. */
static rad_status read_candela(reader *r, rad_photometry *ph, double factor)
{
    uint32_t nv = ph->vertical_count, nh = ph->horizontal_count;
    uint64_t total = (uint64_t)nv * nh;
    /* n tokens take at least 2n - 1 bytes: a table longer than the rest of the file can
     * hold is short, and is found so at the file's end without allocating all of it */
    uint64_t can_hold = (uint64_t)(r->size - r->pos) / 2 + 1;
    uint64_t capacity = total < can_hold ? total : can_hold;
    ph->candela = rad_alloc_array((size_t)capacity, sizeof(double));
    if (!ph->candela)
        return rad_fail(r->error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
    for (uint64_t k = 0; k < total; k++) {
        token t;
        double value = 0;
        scanned how = scan_number(r, &t, &value);
        uint32_t h = (uint32_t)(k / nv), v = (uint32_t)(k % nv);
        if (how == SCAN_END)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: the file ends after %llu of %llu candela values (%u "
                            "horizontal x %u vertical angles)",
                            r->path, r->last_line, (unsigned long long)k,
                            (unsigned long long)total, nh, nv);
        if (how != SCAN_OK)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: candela value at horizontal %g, vertical %g: '%.*s' is %s",
                            r->path, t.line, ph->horizontal_degrees[h], ph->vertical_degrees[v],
                            quoted_length(&t), t.start,
                            how == SCAN_RANGE ? "out of range" : "not a number");
        if (value < 0)
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: candela value at horizontal %g, vertical %g is negative (%g)",
                            r->path, t.line, ph->horizontal_degrees[h], ph->vertical_degrees[v],
                            value);
        double stored = value * factor;
        if (!(stored <= IES_MOST_CANDELA))
            return rad_fail(r->error, RAD_ERR_PARSE,
                            "%s:%lu: candela value at horizontal %g, vertical %g is %g x %g "
                            "(multiplier and ballast factors): more than %g cd",
                            r->path, t.line, ph->horizontal_degrees[h], ph->vertical_degrees[v],
                            value, factor, IES_MOST_CANDELA);
        if (k >= capacity) /* cannot happen: see can_hold */
            return rad_fail(r->error, RAD_ERR_INTERNAL, "%s: the candela table overflowed",
                            r->path);
        ph->candela[k] = stored + 0.0;
    }
    return RAD_OK;
}

/* ------------------------------------------------------------------------------------ */
/* The flux                                                                             */

static const double DEGREES = 3.14159265358979323846 / 180.0;

/* The integral of f(a) sin(a) over [a0, a1] (radians) for f linear from f0 at a0 to f1 at
 * a1 is w0 f0 + w1 f1. With m the middle and h the half width:
 * w0,1 = sin m sin h -/+ cos m (sin h - h cos h) / h, the last factor by its series for a
 * small h (no cancellation). */
static void sin_weights(double a0, double a1, double *w0, double *w1)
{
    double m = 0.5 * (a0 + a1), h = 0.5 * (a1 - a0);
    double g;
    if (h < 1e-2) {
        double h2 = h * h;
        g = h2 * (1.0 / 3 - h2 * (1.0 / 30 - h2 * (1.0 / 840 - h2 / 45360)));
    } else {
        g = (sin(h) - h * cos(h)) / h;
    }
    double s = sin(m) * sin(h), c = cos(m) * g;
    *w0 = s - c;
    *w1 = s + c;
}

/* Per angle, its weight in the integral of a piecewise linear function times sin(angle +
 * shift) over the angles' range (degrees in, radians inside). */
static void polar_weights(const double *angles, uint32_t count, double shift, double *weight)
{
    for (uint32_t k = 0; k < count; k++)
        weight[k] = 0;
    for (uint32_t k = 0; k + 1 < count; k++) {
        double w0, w1;
        sin_weights((angles[k] + shift) * DEGREES, (angles[k + 1] + shift) * DEGREES, &w0, &w1);
        weight[k] += w0;
        weight[k + 1] += w1;
    }
}

/* Per angle, its trapezoid weight (radians) over the angles' range. */
static void trapezoid_weights(const double *angles, uint32_t count, double *weight)
{
    for (uint32_t k = 0; k < count; k++)
        weight[k] = 0;
    for (uint32_t k = 0; k + 1 < count; k++) {
        double half = 0.5 * (angles[k + 1] - angles[k]) * DEGREES;
        weight[k] += half;
        weight[k + 1] += half;
    }
}

/* rad_photometry.lumens: sum over the table of (horizontal weight) x (vertical weight) x
 * candela. Type C: vertical polar (sin of the angle from the nadir), horizontal trapezoid
 * times the unfolding 360 / range (a single angle: 2 pi). Types A and B: horizontal polar
 * (cos of the angle, i.e. sin of angle + 90), times 180 / range (a single angle: the
 * integral of cos over -90..90, 2), vertical trapezoid. */
static rad_status compute_lumens(reader *r, rad_photometry *ph)
{
    uint32_t nv = ph->vertical_count, nh = ph->horizontal_count;
    double *weights = rad_alloc_array((size_t)nv + nh, sizeof(double));
    if (!weights)
        return rad_fail(r->error, RAD_ERR_NOMEM, "%s: out of memory", r->path);
    double *wv = weights, *wh = weights + nv;
    const double *h = ph->horizontal_degrees;
    if (ph->photometric_type == 1) {
        polar_weights(ph->vertical_degrees, nv, 0, wv);
        if (nh == 1) {
            wh[0] = 2 * 3.14159265358979323846;
        } else {
            trapezoid_weights(h, nh, wh);
            double unfold = 360.0 / (h[nh - 1] - h[0]);
            for (uint32_t j = 0; j < nh; j++)
                wh[j] *= unfold;
        }
    } else {
        trapezoid_weights(ph->vertical_degrees, nv, wv);
        if (nh == 1) {
            wh[0] = 2;
        } else {
            polar_weights(h, nh, 90, wh);
            double unfold = 180.0 / (h[nh - 1] - h[0]);
            for (uint32_t j = 0; j < nh; j++)
                wh[j] *= unfold;
        }
    }
    double lumens = 0;
    for (uint32_t j = 0; j < nh; j++) {
        const double *row = ph->candela + (size_t)j * nv;
        double sum = 0;
        for (uint32_t k = 0; k < nv; k++)
            sum += wv[k] * row[k];
        lumens += wh[j] * sum;
    }
    free(weights);
    /* weights are not negative but for rounding: a zero web stays 0, not -1e-300 */
    ph->lumens = lumens > 0 ? lumens : 0;
    if (!isfinite(ph->lumens))
        return rad_fail(r->error, RAD_ERR_PARSE, "%s: the flux of the candela table is not finite",
                        r->path);
    return RAD_OK;
}

/* ------------------------------------------------------------------------------------ */
/* The whole file                                                                       */

static rad_status read_photometry(reader *r, rad_photometry *ph)
{
    const char *path = r->path;
    ies_format format = read_format(r);
    rad_status status = read_header(r);
    if (status != RAD_OK)
        return status;

    double multiplier, unused; /* unused: read, checked to be a number, not applied */
    uint32_t nv = 0, nh = 0, type = 0;
    token t;
    if ((status = read_number(r, "number of lamps", &unused, &t)) != RAD_OK ||
        (status = read_number(r, "lumens per lamp", &unused, &t)) != RAD_OK ||
        (status = read_factor(r, "candela multiplier", &multiplier, &t)) != RAD_OK ||
        (status = read_count(r, "number of vertical angles", 1, &nv)) != RAD_OK ||
        (status = read_count(r, "number of horizontal angles", 1, &nh)) != RAD_OK)
        return status;
    double value;
    if ((status = read_number(r, "photometric type", &value, &t)) != RAD_OK)
        return status;
    if (value != 1 && value != 2 && value != 3)
        return rad_fail(r->error, RAD_ERR_PARSE,
                        "%s:%lu: the photometric type '%.*s' is not 1 (C), 2 (B) or 3 (A)", path,
                        t.line, quoted_length(&t), t.start);
    type = (uint32_t)value;
    if ((status = read_number(r, "units type", &unused, &t)) != RAD_OK ||
        (status = read_number(r, "width", &unused, &t)) != RAD_OK ||
        (status = read_number(r, "length", &unused, &t)) != RAD_OK ||
        (status = read_number(r, "height", &unused, &t)) != RAD_OK)
        return status;
    double ballast, twelfth;
    bool lamp_factor = format == IES_1986 || format == IES_1991 || format == IES_1995;
    token last_factor;
    if ((status = read_factor(r, "ballast factor", &ballast, &last_factor)) != RAD_OK)
        return status;
    if (lamp_factor)
        status = read_factor(r, "ballast-lamp photometric factor", &twelfth, &last_factor);
    else
        status = read_number(r,
                             format == IES_2019 ? "file generation type" : "future-use number",
                             &twelfth, &t);
    if (status != RAD_OK || (status = read_number(r, "input watts", &unused, &t)) != RAD_OK)
        return status;
    double factor = multiplier * ballast * (lamp_factor ? twelfth : 1.0);
    if (!isfinite(factor))
        return rad_fail(r->error, RAD_ERR_PARSE,
                        "%s:%lu: the candela multiplier and the ballast factors multiply to "
                        "more than double's range",
                        path, last_factor.line);

    ph->photometric_type = type;
    ph->vertical_count = nv;
    ph->horizontal_count = nh;
    ph->vertical_degrees = rad_alloc_array(nv, sizeof(double));
    ph->horizontal_degrees = rad_alloc_array(nh, sizeof(double));
    if (!ph->vertical_degrees || !ph->horizontal_degrees)
        return rad_fail(r->error, RAD_ERR_NOMEM, "%s: out of memory", path);
    double least = type == 1 ? 0 : -90, most = type == 1 ? 180 : 90;
    unsigned long first_line = 0, last_line = 0;
    status = read_angles(r, "vertical", nv, least, most, ph->vertical_degrees, &first_line,
                         &last_line);
    if (status != RAD_OK)
        return status;
    status = read_angles(r, "horizontal", nh, type == 1 ? 0 : -90, type == 1 ? 360 : 90,
                         ph->horizontal_degrees, &first_line, &last_line);
    if (status == RAD_OK)
        status = check_horizontal_set(r, type, ph->horizontal_degrees, nh, first_line, last_line);
    if (status == RAD_OK)
        status = read_candela(r, ph, factor);
    if (status == RAD_OK && next_token(r, &t))
        rad_warn(r->log, r->log_user, "%s:%lu: text after the candela table ('%.*s') is ignored",
                 path, t.line, quoted_length(&t), t.start);
    if (status == RAD_OK)
        status = compute_lumens(r, ph);
    return status;
}

rad_status rad_photometry_read(const char *path, rad_log_fn log, void *log_user,
                               rad_photometry **out, rad_error *error)
{
    if (out)
        *out = NULL;
    if (!path || !out)
        return rad_fail(error, RAD_ERR_INVALID, "rad_photometry_read: no %s",
                        path ? "out pointer" : "path");
    char *text = NULL;
    size_t size = 0;
    rad_status status = read_whole(path, &text, &size, error);
    if (status != RAD_OK)
        return status;
    const char *nul = memchr(text, 0, size);
    if (nul) {
        status = rad_fail(error, RAD_ERR_PARSE, "%s:%lu: holds a NUL byte: not a text file", path,
                          line_of(text, (size_t)(nul - text)));
        free(text);
        return status;
    }
    reader r = {path, text, size, 0, 1, count_last_line(text, size), log, log_user, error};
    if (size >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        r.pos = 3; /* a UTF-8 byte order mark */
    rad_photometry *ph = rad_alloc_array(1, sizeof(*ph));
    if (!ph) {
        free(text);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
    }
    snprintf(ph->source, sizeof(ph->source), "%s", path);
    status = read_photometry(&r, ph);
    free(text);
    if (status != RAD_OK) {
        rad_photometry_destroy(ph);
        return status;
    }
    *out = ph;
    return RAD_OK;
}
