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

/* A message is one line: control characters (of the input a message quotes: a name, a
 * token, a file's last bytes) become '?'. */
static void one_line(char *text)
{
    for (; *text; text++)
        if ((unsigned char)*text < 0x20 || *text == 0x7f)
            *text = '?';
}

rad_status rad_fail(rad_error *error, rad_status status, const char *format, ...)
{
    if (error) {
        va_list args;
        va_start(args, format);
        error->status = status;
        vsnprintf(error->message, sizeof(error->message), format, args);
        va_end(args);
        one_line(error->message);
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
    one_line(line);
    log(user, line);
}
