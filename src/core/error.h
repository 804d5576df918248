/*
 * error.h - filling a rad_error: one formatted line, "file:line: message".
 *
 * Every fallible library function reports through rad_fail(), which returns the status so
 * that a caller can write `return rad_fail(error, RAD_ERR_IO, "%s: cannot open", path);`.
 * A NULL error record is allowed: the status is still returned.
 */
#ifndef RAD_CORE_ERROR_H
#define RAD_CORE_ERROR_H

#include "radiosity.h"

#if defined(__GNUC__) || defined(__clang__)
#define RAD_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define RAD_PRINTF(fmt, args)
#endif

/* Sets error (when not NULL) and returns status. The message is one line: control
 * characters in it (from quoted input) become '?'. */
rad_status rad_fail(rad_error *error, rad_status status, const char *format, ...)
    RAD_PRINTF(3, 4);

/* Sends one formatted warning to the log callback (when not NULL), one line as above. */
void rad_warn(rad_log_fn log, void *user, const char *format, ...) RAD_PRINTF(3, 4);

#endif
