/*
 * error.c - status names, error records and warnings.
 */
#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>

const char *rad_status_name(rad_status status)
{
    switch (status) {
    case RAD_OK: return "success";
    case RAD_ERR_IO: return "I/O error";
    case RAD_ERR_PARSE: return "malformed input";
    case RAD_ERR_INVALID: return "invalid argument";
    case RAD_ERR_NOMEM: return "out of memory";
    case RAD_ERR_UNSUPPORTED: return "unsupported";
    case RAD_ERR_INTERNAL: return "internal error";
    }
    return "unknown status";
}

rad_status rad_fail(rad_error *error, rad_status status, const char *format, ...)
{
    if (error) {
        va_list args;
        va_start(args, format);
        error->status = status;
        vsnprintf(error->message, sizeof(error->message), format, args);
        va_end(args);
    }
    return status;
}

void rad_warn(rad_log_fn log, void *user, const char *format, ...)
{
    if (!log)
        return;
    char line[RAD_ERROR_MESSAGE_MAX];
    va_list args;
    va_start(args, format);
    vsnprintf(line, sizeof(line), format, args);
    va_end(args);
    log(user, line);
}
