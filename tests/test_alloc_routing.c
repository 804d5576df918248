/*
 * test_alloc_routing.c - every heap allocation of src/ and tools/ goes through the hooked
 * functions of src/core/alloc.h, so that test_alloc_failure's sweeps reach it.
 *
 * Scans every .c and .h file under src/ and tools/ (found from this file's own path) for
 * a call of malloc, calloc, realloc, reallocarray, strdup, strndup, aligned_alloc or
 * posix_memalign outside comments and string literals; src/core/alloc.c, where the hooked
 * functions call the C library, is the one file allowed. Each call found is reported with
 * its file and line.
 */
#define _XOPEN_SOURCE 700
#include <ctype.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const char *const forbidden[] = {"malloc",  "calloc",  "realloc",       "reallocarray",
                                        "strdup",  "strndup", "aligned_alloc", "posix_memalign"};

static int files_scanned;
static int calls_found;

/* Blanks comments and string and character literals (newlines kept, for line numbers). */
static void blank_comments_and_literals(char *text)
{
    for (char *p = text; *p;) {
        if (p[0] == '/' && p[1] == '*') {
            char *end = strstr(p + 2, "*/");
            char *stop = end ? end + 2 : p + strlen(p);
            for (; p < stop; p++)
                if (*p != '\n')
                    *p = ' ';
        } else if (p[0] == '/' && p[1] == '/') {
            for (; *p && *p != '\n'; p++)
                *p = ' ';
        } else if (*p == '"' || *p == '\'') {
            char quote = *p++;
            for (; *p && *p != quote && *p != '\n'; p++) {
                if (*p == '\\' && p[1])
                    *p++ = ' ';
                *p = ' ';
            }
            if (*p == quote)
                p++;
        } else {
            p++;
        }
    }
}

static void scan(const char *path, const char *relative)
{
    size_t size = 0;
    char *text = (char *)test_read_bytes(path, &size);
    if (!text)
        return;
    char *copy = realloc(text, size + 1);
    if (!copy) {
        free(text);
        return;
    }
    text = copy;
    text[size] = 0;
    files_scanned++;
    blank_comments_and_literals(text);
    for (size_t k = 0; k < sizeof(forbidden) / sizeof(forbidden[0]); k++) {
        size_t length = strlen(forbidden[k]);
        for (char *at = strstr(text, forbidden[k]); at; at = strstr(at + length, forbidden[k])) {
            bool starts = at == text || !(isalnum((unsigned char)at[-1]) || at[-1] == '_');
            const char *after = at + length;
            while (*after == ' ' || *after == '\t')
                after++;
            if (!starts || *after != '(')
                continue;
            int line = 1;
            for (const char *p = text; p < at; p++)
                line += *p == '\n';
            test_fail(__FILE__, __LINE__, "%s:%d: %s() called directly: use rad_alloc_array, "
                      "rad_resize_array or rad_grow_array (src/core/alloc.h)",
                      relative, line, forbidden[k]);
            calls_found++;
        }
    }
    free(text);
}

static size_t root_length;

static int visit(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
    (void)st;
    (void)ftw;
    size_t length = strlen(path);
    if (type != FTW_F || length < 2 ||
        !(strcmp(path + length - 2, ".c") == 0 || strcmp(path + length - 2, ".h") == 0))
        return 0;
    const char *relative = path + root_length;
    if (strcmp(relative, "src/core/alloc.c") == 0)
        return 0;
    scan(path, relative);
    return 0;
}

int main(void)
{
    /* this file is <root>/tests/test_alloc_routing.c */
    char root[4096];
    snprintf(root, sizeof(root), "%s", __FILE__);
    char *tests = strstr(root, "tests/test_alloc_routing.c");
    CHECK(tests != NULL && root[0] == '/');
    if (!tests || root[0] != '/')
        return test_finish("test_alloc_routing");
    *tests = 0;
    root_length = strlen(root);
    char folder[4200];
    snprintf(folder, sizeof(folder), "%ssrc", root);
    CHECK(nftw(folder, visit, 16, FTW_PHYS) == 0);
    snprintf(folder, sizeof(folder), "%stools", root);
    CHECK(nftw(folder, visit, 16, FTW_PHYS) == 0);
    CHECK(files_scanned > 50);
    CHECK(calls_found == 0);
    printf("%d files of src/ and tools/ scanned, %d direct allocation calls\n", files_scanned,
           calls_found);
    return test_finish("test_alloc_routing");
}
