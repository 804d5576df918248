/*
 * image_read.c - rad_image_read: Radiance RGBE (.hdr), portable float maps (.pfm) and
 * OpenEXR (.exr, decoded by OpenEXR in exr.c).
 *
 * The whole file is read into memory and the format is recognised by its magic ("#?",
 * "PF"/"Pf" or the bytes 76 2f 31 01), not by the name. The image returned has row 0 at
 * the top, whatever order the file stores its rows in. Every length is checked against the
 * bytes actually present before anything is allocated or copied (for EXR, by OpenEXR and
 * exr.c), so a truncated or hostile file is RAD_ERR_PARSE, never a crash. Not supported:
 * XYZE pictures (RAD_ERR_UNSUPPORTED), the PFM scale magnitude (only its sign, the byte
 * order, is used) and the Radiance header's colour correction; EXPOSURE lines are undone
 * so pixels come back as radiance. EXR limits: see exr.h.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "image/exr.h"

_Static_assert(sizeof(float) == 4, "PFM needs 32-bit floats");

/* Header lines longer than this are not ones we interpret (format, exposure, size). */
#define HEADER_FIELD_MAX 128
/* New-style RLE stores at most 127 pixels of one channel in 2 bytes, i.e. 8 bytes per 127
 * pixels; a file claiming more pixels per byte of data than this is truncated. (Only the
 * obsolete old-style repeat pixels can pack tighter; such files are rejected.) */
#define RGBE_MAX_PIXELS_PER_BYTE 16
/* The exponent byte is biased by 128 and the mantissa bytes hold 8 bits: value =
 * (byte + 0.5) 2^(E - 136), the centre of the truncation interval the encoder used. */
#define RGBE_EXPONENT_OFFSET (128 + 8)
/* Scanline widths that may be new-style run-length encoded. */
#define RGBE_RLE_MIN_WIDTH 8
#define RGBE_RLE_MAX_WIDTH 0x7fff
/* The first four bytes of every OpenEXR file (20000630 little-endian). */
static const uint8_t EXR_MAGIC[4] = {0x76, 0x2f, 0x31, 0x01};

typedef struct reader {
    const char *path;  /* for messages */
    const uint8_t *data;
    size_t size;
    size_t at;         /* next unread byte */
    rad_error *error;
} reader;

static size_t remaining(const reader *in)
{
    return in->size - in->at;
}

/* ----------------------------------------------------------------------------------- */
/* The file                                                                            */

static rad_status read_whole_file(const char *path, uint8_t **data, size_t *size,
                                  rad_error *error)
{
    *data = NULL;
    *size = 0;
    FILE *stream = fopen(path, "rb");
    if (!stream)
        return rad_fail(error, RAD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    uint8_t *buffer = NULL;
    size_t capacity = 0, used = 0;
    rad_status status = RAD_OK;
    for (;;) {
        if (!rad_grow_array((void **)&buffer, &capacity, used + 65536, 1)) {
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", path);
            break;
        }
        size_t got = fread(buffer + used, 1, capacity - used, stream);
        used += got;
        if (got == 0 || used < capacity) {
            if (ferror(stream))
                status = rad_fail(error, RAD_ERR_IO, "%s: read failed: %s", path,
                                  strerror(errno));
            else if (!feof(stream))
                continue;
            break;
        }
    }
    fclose(stream);
    if (status != RAD_OK) {
        free(buffer);
        return status;
    }
    *data = buffer;
    *size = used;
    return RAD_OK;
}

/* ----------------------------------------------------------------------------------- */
/* Small text parsing helpers (ASCII, locale-independent except strtod)                */

static int is_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

static void skip_spaces(reader *in)
{
    while (in->at < in->size && is_space(in->data[in->at]))
        in->at++;
}

/* A decimal integer in [1, UINT32_MAX]; 0 when there is none. */
static int parse_dimension(const char **text, uint32_t *value)
{
    const char *s = *text;
    uint64_t v = 0;
    if (*s < '0' || *s > '9')
        return 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        v = v * 10 + (uint64_t)(*s - '0');
        if (v > UINT32_MAX)
            return 0;
    }
    if (v == 0)
        return 0;
    *value = (uint32_t)v;
    *text = s;
    return 1;
}

/* Copies the next whitespace-free token (at most size - 1 bytes) into buffer. */
static int next_token(reader *in, char *buffer, size_t size)
{
    skip_spaces(in);
    size_t length = 0;
    while (in->at < in->size && !is_space(in->data[in->at])) {
        if (length + 1 >= size)
            return 0;
        buffer[length++] = (char)in->data[in->at++];
    }
    buffer[length] = 0;
    return length > 0;
}

/* ----------------------------------------------------------------------------------- */
/* PFM                                                                                 */

static rad_status read_pfm(reader *in, rad_image **out)
{
    size_t channels = in->data[1] == 'F' ? 3 : 1;
    in->at = 2;
    if (in->at >= in->size || !is_space(in->data[in->at]))
        return rad_fail(in->error, RAD_ERR_PARSE, "%s: not a PFM file (bad magic)", in->path);

    char token[64];
    uint32_t width = 0, height = 0;
    const char *cursor = token;
    if (!next_token(in, token, sizeof(token)) || !parse_dimension(&cursor, &width) || *cursor)
        return rad_fail(in->error, RAD_ERR_PARSE, "%s: PFM header: bad width", in->path);
    cursor = token;
    if (!next_token(in, token, sizeof(token)) || !parse_dimension(&cursor, &height) ||
        *cursor)
        return rad_fail(in->error, RAD_ERR_PARSE, "%s: PFM header: bad height", in->path);
    char *end = NULL;
    double scale = 0;
    if (next_token(in, token, sizeof(token)))
        scale = strtod(token, &end);
    if (!end || *end || !isfinite(scale) || scale == 0)
        return rad_fail(in->error, RAD_ERR_PARSE,
                        "%s: PFM header: bad scale (a non-zero number whose sign gives the "
                        "byte order)", in->path);
    /* Exactly one whitespace byte separates the header from the data. */
    if (in->at >= in->size || !is_space(in->data[in->at]))
        return rad_fail(in->error, RAD_ERR_PARSE, "%s: PFM header: no data after it",
                        in->path);
    in->at++;

    int little_endian = scale < 0;
    size_t row_values = (size_t)width * channels;
    if ((size_t)height > SIZE_MAX / 4 / row_values)
        return rad_fail(in->error, RAD_ERR_PARSE,
                        "%s: PFM size %" PRIu32 " x %" PRIu32 " is too large", in->path,
                        width, height);
    size_t needed = row_values * height * 4;
    if (remaining(in) < needed)
        return rad_fail(in->error, RAD_ERR_PARSE,
                        "%s: truncated: %" PRIu32 " x %" PRIu32 " PFM needs %zu bytes of "
                        "pixel data, the file has %zu", in->path, width, height, needed,
                        remaining(in));

    rad_image *image = NULL;
    rad_status status = rad_image_create(width, height, &image, in->error);
    if (status != RAD_OK)
        return status;
    const uint8_t *p = in->data + in->at;
    for (uint32_t file_row = 0; file_row < height; file_row++) {
        /* PFM stores the bottom row first. */
        float *row = image->rgb + (size_t)(height - 1 - file_row) * width * 3;
        for (uint32_t x = 0; x < width; x++) {
            float value[3];
            for (size_t c = 0; c < channels; c++, p += 4) {
                uint32_t bits = little_endian
                    ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                          (uint32_t)p[3] << 24
                    : (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 |
                          (uint32_t)p[0] << 24;
                memcpy(&value[c], &bits, sizeof(value[c]));
            }
            if (channels == 1)
                value[1] = value[2] = value[0];
            memcpy(row + 3 * (size_t)x, value, sizeof(value));
        }
    }
    *out = image;
    return RAD_OK;
}

/* ----------------------------------------------------------------------------------- */
/* Radiance RGBE                                                                       */

/* The next header line (without its '\n'); 0 when the data ends before a newline. */
static int next_line(reader *in, const char **line, size_t *length)
{
    const uint8_t *start = in->data + in->at;
    const uint8_t *newline = memchr(start, '\n', remaining(in));
    if (!newline)
        return 0;
    *line = (const char *)start;
    *length = (size_t)(newline - start);
    in->at += *length + 1;
    return 1;
}

/* Copies a line into a NUL-terminated buffer without trailing whitespace; 0 if too long. */
static int copy_line(const char *line, size_t length, char *buffer, size_t size)
{
    while (length > 0 && is_space((unsigned char)line[length - 1]))
        length--;
    if (length >= size)
        return 0;
    memcpy(buffer, line, length);
    buffer[length] = 0;
    return 1;
}

/* One axis of the resolution line: "-Y 480" or "+X 640". */
static int parse_axis(const char **text, char *sign, char *axis, uint32_t *count)
{
    const char *s = *text;
    while (*s == ' ' || *s == '\t')
        s++;
    if ((s[0] != '+' && s[0] != '-') || (s[1] != 'X' && s[1] != 'Y'))
        return 0;
    *sign = s[0];
    *axis = s[1];
    s += 2;
    if (*s != ' ' && *s != '\t')
        return 0;
    while (*s == ' ' || *s == '\t')
        s++;
    if (!parse_dimension(&s, count))
        return 0;
    *text = s;
    return 1;
}

/* Reads one scanline of n pixels (4 bytes each) into scan: new-style RLE, or flat with
 * old-style repeat pixels (1,1,1,k: repeat the previous pixel k << shift times). */
static rad_status read_scanline(reader *in, uint8_t *scan, uint32_t n, uint32_t index)
{
    const uint8_t *d = in->data + in->at;
    if (n >= RGBE_RLE_MIN_WIDTH && n <= RGBE_RLE_MAX_WIDTH && remaining(in) >= 4 &&
        d[0] == 2 && d[1] == 2 && !(d[2] & 0x80)) {
        uint32_t width = (uint32_t)d[2] << 8 | d[3];
        if (width != n)
            return rad_fail(in->error, RAD_ERR_PARSE,
                            "%s: scanline %" PRIu32 ": run-length width %" PRIu32
                            ", expected %" PRIu32, in->path, index, width, n);
        in->at += 4;
        for (int c = 0; c < 4; c++) {
            for (uint32_t x = 0; x < n;) {
                if (remaining(in) < 1)
                    goto truncated;
                uint32_t code = in->data[in->at++];
                uint32_t count = code > 128 ? code - 128 : code;
                if (count == 0 || count > n - x)
                    return rad_fail(in->error, RAD_ERR_PARSE,
                                    "%s: scanline %" PRIu32 ": bad run length", in->path,
                                    index);
                if (remaining(in) < (code > 128 ? 1 : count))
                    goto truncated;
                for (uint32_t k = 0; k < count; k++, x++)
                    scan[4 * (size_t)x + (size_t)c] =
                        in->data[code > 128 ? in->at : in->at + k];
                in->at += code > 128 ? 1 : count;
            }
        }
        return RAD_OK;
    }

    unsigned shift = 0;
    for (uint32_t x = 0; x < n;) {
        if (remaining(in) < 4)
            goto truncated;
        const uint8_t *p = in->data + in->at;
        in->at += 4;
        if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
            uint64_t count = (uint64_t)p[3] << shift;
            if (x == 0 || shift > 24 || count > n - x)
                return rad_fail(in->error, RAD_ERR_PARSE,
                                "%s: scanline %" PRIu32 ": bad repeat pixel", in->path, index);
            for (uint64_t k = 0; k < count; k++, x++)
                memcpy(scan + 4 * (size_t)x, scan + 4 * ((size_t)x - 1), 4);
            shift += 8;
        } else {
            memcpy(scan + 4 * (size_t)x, p, 4);
            x++;
            shift = 0;
        }
    }
    return RAD_OK;

truncated:
    return rad_fail(in->error, RAD_ERR_PARSE, "%s: truncated in scanline %" PRIu32,
                    in->path, index);
}

static rad_status read_hdr(reader *in, rad_image **out)
{
    char field[HEADER_FIELD_MAX];
    const char *line;
    size_t length;
    unsigned line_number = 0;
    double exposure = 1; /* product of the EXPOSURE lines: file value = radiance * this */
    for (;;) {
        if (!next_line(in, &line, &length))
            return rad_fail(in->error, RAD_ERR_PARSE,
                            "%s: Radiance header does not end (no empty line)", in->path);
        line_number++;
        if (length == 0 || (length == 1 && line[0] == '\r'))
            break;
        if (length >= 7 && memcmp(line, "FORMAT=", 7) == 0) {
            if (!copy_line(line + 7, length - 7, field, sizeof(field)))
                field[0] = 0;
            if (strcmp(field, "32-bit_rle_xyze") == 0)
                return rad_fail(in->error, RAD_ERR_UNSUPPORTED,
                                "%s:%u: XYZE pictures are not supported (only RGBE)",
                                in->path, line_number);
            if (strcmp(field, "32-bit_rle_rgbe") != 0)
                return rad_fail(in->error, RAD_ERR_PARSE, "%s:%u: unknown FORMAT",
                                in->path, line_number);
        } else if (length >= 9 && memcmp(line, "EXPOSURE=", 9) == 0) {
            char *end = NULL;
            double value = 0;
            if (copy_line(line + 9, length - 9, field, sizeof(field)))
                value = strtod(field, &end);
            if (!end || end == field || *end || !isfinite(value) || !(value > 0))
                return rad_fail(in->error, RAD_ERR_PARSE, "%s:%u: bad EXPOSURE", in->path,
                                line_number);
            exposure *= value;
        }
    }

    /* The resolution line: slow (scanline) axis first, e.g. "-Y 480 +X 640". */
    char sign[2], axis[2];
    uint32_t count[2];
    const char *cursor = field;
    line_number++;
    if (!next_line(in, &line, &length) || !copy_line(line, length, field, sizeof(field)) ||
        !parse_axis(&cursor, &sign[0], &axis[0], &count[0]) ||
        !parse_axis(&cursor, &sign[1], &axis[1], &count[1]) || *cursor ||
        axis[0] == axis[1])
        return rad_fail(in->error, RAD_ERR_PARSE,
                        "%s:%u: bad resolution line (expected like \"-Y 480 +X 640\")",
                        in->path, line_number);
    uint32_t scanlines = count[0], scan_length = count[1];
    int y_first = axis[0] == 'Y';
    uint32_t width = y_first ? scan_length : scanlines;
    uint32_t height = y_first ? scanlines : scan_length;
    if ((size_t)scanlines > SIZE_MAX / scan_length ||
        (size_t)scanlines * scan_length / RGBE_MAX_PIXELS_PER_BYTE > remaining(in))
        return rad_fail(in->error, RAD_ERR_PARSE,
                        "%s: truncated: %" PRIu32 " x %" PRIu32 " pixels in %zu bytes",
                        in->path, width, height, remaining(in));

    rad_image *image = NULL;
    rad_status status = rad_image_create(width, height, &image, in->error);
    if (status != RAD_OK)
        return status;
    uint8_t *scan = rad_alloc_array(scan_length, 4);
    if (!scan) {
        rad_image_destroy(image);
        return rad_fail(in->error, RAD_ERR_NOMEM, "%s: out of memory", in->path);
    }
    for (uint32_t s = 0; s < scanlines && status == RAD_OK; s++) {
        status = read_scanline(in, scan, scan_length, s);
        for (uint32_t p = 0; p < scan_length && status == RAD_OK; p++) {
            /* "-Y" runs from the top row down, "+X" from the left column rightwards. */
            uint32_t row, column;
            if (y_first) {
                row = sign[0] == '-' ? s : height - 1 - s;
                column = sign[1] == '+' ? p : width - 1 - p;
            } else {
                column = sign[0] == '+' ? s : width - 1 - s;
                row = sign[1] == '-' ? p : height - 1 - p;
            }
            const uint8_t *rgbe = scan + 4 * (size_t)p;
            float *pixel = image->rgb + ((size_t)row * width + column) * 3;
            if (rgbe[3] == 0) {
                pixel[0] = pixel[1] = pixel[2] = 0;
                continue;
            }
            double unit = ldexp(1.0, (int)rgbe[3] - RGBE_EXPONENT_OFFSET) / exposure;
            for (int c = 0; c < 3; c++)
                pixel[c] = (float)((rgbe[c] + 0.5) * unit);
        }
    }
    free(scan);
    if (status != RAD_OK) {
        rad_image_destroy(image);
        return status;
    }
    *out = image;
    return RAD_OK;
}

/* ----------------------------------------------------------------------------------- */

rad_status rad_image_read(const char *path, rad_image **out, rad_error *error)
{
    if (!out)
        return rad_fail(error, RAD_ERR_INVALID, "rad_image_read: no output pointer");
    *out = NULL;
    if (!path)
        return rad_fail(error, RAD_ERR_INVALID, "rad_image_read: no path");
    reader in = {.path = path, .error = error};
    uint8_t *data = NULL;
    rad_status status = read_whole_file(path, &data, &in.size, error);
    if (status != RAD_OK)
        return status;
    in.data = data;
    if (in.size >= 2 && data[0] == '#' && data[1] == '?')
        status = read_hdr(&in, out);
    else if (in.size >= 2 && data[0] == 'P' && (data[1] == 'F' || data[1] == 'f'))
        status = read_pfm(&in, out);
    else if (in.size >= sizeof(EXR_MAGIC) &&
             memcmp(data, EXR_MAGIC, sizeof(EXR_MAGIC)) == 0)
        status = rad_exr_read(data, in.size, path, out, error);
    else
        status = rad_fail(error, RAD_ERR_PARSE,
                          "%s: not a PFM, Radiance HDR or OpenEXR image (unknown magic)",
                          path);
    free(data);
    return status;
}
