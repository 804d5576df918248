/*
 * solve_record.c - rad_solve_record: a solve's snapshots (rad_solve_step), streamed as
 * JSON to a temporary file and renamed into place at the end (layout in radiosity.h).
 *
 * Each snapshot's numbers are printed by cJSON; its radiosity (n x 3 float32,
 * little-endian) is base64-encoded into one buffer made when the record opens, so the
 * record holds one snapshot at a time, whatever the number of steps. It does not decide
 * which steps are recorded: the caller adds what its observer receives.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/atomic_file.h"
#include "core/error.h"

struct rad_solve_record {
    rad_atomic_file file;
    uint32_t patches, count;
    unsigned char *bytes; /* 12 n: the float32 values */
    char *base64;         /* their base64 text, NUL-terminated */
};

/* Base64 (RFC 4648, with padding) of `size` bytes into out (4 ceil(size / 3) + 1). */
static void encode_base64(const unsigned char *in, size_t size, char *out)
{
    static const char digits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0, i = 0;
    for (; i + 2 < size; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (uint32_t)in[i + 1] << 8 | in[i + 2];
        out[o++] = digits[v >> 18 & 63];
        out[o++] = digits[v >> 12 & 63];
        out[o++] = digits[v >> 6 & 63];
        out[o++] = digits[v & 63];
    }
    if (i < size) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < size ? (uint32_t)in[i + 1] << 8 : 0);
        out[o++] = digits[v >> 18 & 63];
        out[o++] = digits[v >> 12 & 63];
        out[o++] = i + 1 < size ? digits[v >> 6 & 63] : '=';
        out[o++] = '=';
    }
    out[o] = '\0';
}

/* The little-endian bytes of a float, whatever the machine's order. */
static void put_float(unsigned char *out, float value)
{
    uint32_t bits;
    memcpy(&bits, &value, sizeof(bits));
    out[0] = (unsigned char)bits;
    out[1] = (unsigned char)(bits >> 8);
    out[2] = (unsigned char)(bits >> 16);
    out[3] = (unsigned char)(bits >> 24);
}

/* A number, or null for NaN and infinities (JSON has neither). */
static cJSON *number_or_null(double value)
{
    return isfinite(value) ? cJSON_CreateNumber(value) : cJSON_CreateNull();
}

/* Prints `object` without its closing brace; false when out of memory. */
static bool print_open(rad_solve_record *r, cJSON *object)
{
    char *text = object ? cJSON_PrintUnformatted(object) : NULL;
    cJSON_Delete(object);
    if (!text)
        return false;
    size_t length = strlen(text);
    fwrite(text, 1, length - 1, r->file.stream); /* without the final '}' */
    free(text);
    return true;
}

rad_status rad_solve_record_open(const char *path, const char *scene, const char *solver,
                                 uint32_t patches, rad_solve_record **out, rad_error *error)
{
    *out = NULL;
    if (patches == 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: a record of no patches", path);
    rad_solve_record *r = rad_alloc_array(1, sizeof(*r));
    if (!r)
        return rad_fail(error, RAD_ERR_NOMEM, "--record %s: no memory", path);
    size_t bytes = (size_t)patches * 12;
    r->patches = patches;
    r->bytes = rad_alloc_array(bytes, 1);
    r->base64 = rad_alloc_array(4 * ((bytes + 2) / 3) + 1, 1);
    if (!r->bytes || !r->base64) {
        free(r->bytes);
        free(r->base64);
        free(r);
        return rad_fail(error, RAD_ERR_NOMEM,
                        "--record %s: a snapshot of %u patches needs %.1f MB, more than the "
                        "memory left",
                        path, patches, (bytes + 4.0 * bytes / 3) / 1048576.0);
    }
    rad_status status = rad_atomic_open(&r->file, path, error);
    if (status != RAD_OK) {
        free(r->bytes);
        free(r->base64);
        free(r);
        return status;
    }
    cJSON *head = cJSON_CreateObject();
    if (head) {
        cJSON_AddStringToObject(head, "format", "radiosity-record");
        cJSON_AddNumberToObject(head, "version", 1);
        cJSON_AddStringToObject(head, "scene", scene ? scene : "");
        cJSON_AddStringToObject(head, "solver", solver ? solver : "");
        cJSON_AddNumberToObject(head, "patches", patches);
    }
    if (!print_open(r, head)) {
        rad_solve_record_abort(r);
        return rad_fail(error, RAD_ERR_NOMEM, "--record %s: no memory", path);
    }
    fputs(",\"snapshots\":[", r->file.stream);
    *out = r;
    return RAD_OK;
}

rad_status rad_solve_record_add(rad_solve_record *r, const rad_solve_step *step,
                                rad_error *error)
{
    if (step->n != r->patches || !step->B)
        return rad_fail(error, RAD_ERR_INVALID,
                        "%s: a snapshot of %u patches in a record of %u", r->file.final_path,
                        step->n, r->patches);
    cJSON *s = cJSON_CreateObject();
    if (s) {
        cJSON_AddNumberToObject(s, "step", step->step);
        cJSON_AddItemToObject(s, "seconds", number_or_null(step->seconds));
        cJSON_AddItemToObject(s, "criterion", number_or_null(step->criterion));
        cJSON_AddItemToObject(s, "residual", number_or_null(step->residual));
        cJSON_AddItemToObject(s, "unshot", number_or_null(step->unshot));
        if (step->shooting_patch == UINT32_MAX)
            cJSON_AddNullToObject(s, "shooting_patch");
        else
            cJSON_AddNumberToObject(s, "shooting_patch", step->shooting_patch);
        cJSON_AddBoolToObject(s, "final", step->final);
        if (step->phase)
            cJSON_AddStringToObject(s, "phase", step->phase);
    }
    if (r->count > 0)
        fputc(',', r->file.stream);
    if (!print_open(r, s))
        return rad_fail(error, RAD_ERR_NOMEM, "%s: no memory for a snapshot", r->file.final_path);
    for (uint32_t i = 0; i < r->patches; i++) {
        put_float(r->bytes + 12 * (size_t)i, (float)step->B[i].r);
        put_float(r->bytes + 12 * (size_t)i + 4, (float)step->B[i].g);
        put_float(r->bytes + 12 * (size_t)i + 8, (float)step->B[i].b);
    }
    encode_base64(r->bytes, 12 * (size_t)r->patches, r->base64);
    fputs(",\"radiosity\":\"", r->file.stream);
    fputs(r->base64, r->file.stream);
    fputs("\"}", r->file.stream);
    r->count++;
    if (ferror(r->file.stream))
        return rad_fail(error, RAD_ERR_IO, "%s: write failed", r->file.final_path);
    return RAD_OK;
}

uint32_t rad_solve_record_count(const rad_solve_record *r) { return r ? r->count : 0; }

rad_status rad_solve_record_commit(rad_solve_record *r, rad_error *error)
{
    fputs("]}\n", r->file.stream);
    rad_status status = rad_atomic_commit(&r->file, error);
    free(r->bytes);
    free(r->base64);
    free(r);
    return status;
}

void rad_solve_record_abort(rad_solve_record *r)
{
    if (!r)
        return;
    rad_atomic_abort(&r->file);
    free(r->bytes);
    free(r->base64);
    free(r);
}
