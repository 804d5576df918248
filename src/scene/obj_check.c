/*
 * obj_check.c - the OBJ checks of obj_check.h: face indices, v/vt/vn lines and material
 * libraries checked line by line (a line continued by a trailing backslash is one line,
 * as Assimp reads it), and the copy of the file Assimp reads when it must be told
 * differently.
 */
#include "obj_check.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/error.h"

static const char *const obj_list_name[OBJ_LISTS] = {"vertex", "texture coordinate", "normal"};

bool obj_names_has(obj_names *set, const char *name)
{
    if (set->last[0] && strcmp(set->last, name) == 0)
        return true;
    char key[300];
    snprintf(key, sizeof(key), "\n%.256s%c", name, set->with_lines ? '\t' : '\n');
    if (!set->text || !strstr(set->text, key))
        return false;
    snprintf(set->last, sizeof(set->last), "%s", name);
    return true;
}

/* Adds name (and its line, when the set keeps lines); false out of memory. */
static bool names_add(obj_names *set, const char *name, unsigned long line)
{
    char entry[300];
    int n = set->with_lines ? snprintf(entry, sizeof(entry), "%.256s\t%lu\n", name, line)
                 : snprintf(entry, sizeof(entry), "%.256s\n", name);
    if (!rad_grow_array((void **)&set->text, &set->capacity, set->length + (size_t)n + 2, 1))
        return false;
    if (set->length == 0)
        set->text[set->length++] = '\n';
    memcpy(set->text + set->length, entry, (size_t)n + 1);
    set->length += (size_t)n;
    return true;
}

/* The rest of a line after its keyword, without the blanks around it, in place. */
static char *rest_of_line(char *text)
{
    while (isspace((unsigned char)*text))
        text++;
    char *end = text + strlen(text);
    while (end > text && isspace((unsigned char)end[-1]))
        *--end = 0;
    return text;
}

static bool append_text(obj_check *c, const char *text, size_t n)
{
    if (!rad_grow_array((void **)&c->copy, &c->copy_capacity, c->copy_length + n + 1, 1))
        return false;
    memcpy(c->copy + c->copy_length, text, n);
    c->copy_length += n;
    c->copy[c->copy_length] = 0;
    return true;
}

/* The next line of `file` into *line (grown as needed); false at the end, or out of
 * memory (then *out_of_memory is set). */
static bool read_line(FILE *file, char **line, size_t *capacity, bool *out_of_memory)
{
    size_t length = 0;
    for (;;) {
        if (!rad_grow_array((void **)line, capacity, length + 4096, 1)) {
            *out_of_memory = true;
            return false;
        }
        if (!fgets(*line + length, (int)(*capacity - length), file))
            return length > 0;
        length += strlen(*line + length);
        if (length > 0 && (*line)[length - 1] == '\n')
            return true;
    }
}

static bool is_regular_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* A face's corners (v, v/vt, v//vn, v/vt/vn): each index is a number, not 0, and a
 * relative (negative) one does not reach before the first entry of its list; the largest
 * absolute index of each list is kept to be checked against the list's length at the end.
 * Indices are compared without negating them (INT64_MIN has no positive counterpart). */
static rad_status check_obj_face(obj_check *c, const char *corners, rad_error *error)
{
    const char *cursor = corners;
    for (;;) {
        while (isspace((unsigned char)*cursor))
            cursor++;
        if (!*cursor || *cursor == '#')
            return RAD_OK;
        const char *corner = cursor;
        size_t corner_length = strcspn(corner, " \t\r\n");
        for (int list = 0; list < OBJ_LISTS; list++) {
            if (list > 0) {
                if (*cursor != '/')
                    break;
                cursor++;
                if (list == OBJ_UV && *cursor == '/')
                    continue; /* v//vn */
                if (!*cursor || isspace((unsigned char)*cursor))
                    break; /* "v/" or "v/vt/": an empty last slot, as Assimp reads it */
            }
            char *end;
            errno = 0;
            long long index = strtoll(cursor, &end, 10);
            if (end == cursor || (*end && !isspace((unsigned char)*end) && *end != '/'))
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: face corner '%.*s' is not v, v/vt, v//vn or v/vt/vn "
                                "with whole-number indices",
                                c->path, c->line, (int)(corner_length > 40 ? 40 : corner_length),
                                corner);
            int width = (int)(end - cursor);
            const char *name = obj_list_name[list];
            if (index == 0)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: face refers to %s 0: OBJ indices start at 1", c->path,
                                c->line, name);
            if (index < 0 && (errno == ERANGE || index < -(long long)c->defined[list]))
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: face refers to %s %.*s (counting back) but only %lu "
                                "%s defined above it",
                                c->path, c->line, name, width, cursor, c->defined[list],
                                c->defined[list] == 1 ? "is" : "are");
            if (index > 0 && errno == ERANGE)
                return rad_fail(error, RAD_ERR_PARSE,
                                "%s:%lu: face refers to %s %.*s, beyond any file's count",
                                c->path, c->line, name, width, cursor);
            if (index > c->largest[list]) {
                c->largest[list] = index;
                c->largest_line[list] = c->line;
            }
            cursor = end;
        }
        if (*cursor && !isspace((unsigned char)*cursor))
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: face corner '%.*s' is not v, v/vt, v//vn or v/vt/vn with "
                            "whole-number indices",
                            c->path, c->line, (int)(corner_length > 40 ? 40 : corner_length),
                            corner);
    }
}

/* A v, vt or vn line (`numbers` after its keyword): at least `least` numbers, finite and
 * within single precision; v's optional weight w is not 0 (Assimp divides by it). The
 * line goes to the copy with numbers written ".5" as "0.5" (Assimp 5.2 does not count
 * them as numbers, and then reads the wrong values). */
static rad_status check_obj_numbers(obj_check *c, const char *keyword, const char *line,
                                    const char *numbers, int least, rad_error *error)
{
    const char *cursor = numbers;
    int count = 0;
    double value[4] = {0, 0, 0, 1};
    bool leading_point = false;
    for (;;) {
        while (*cursor == ' ' || *cursor == '\t')
            cursor++;
        if (!*cursor || *cursor == '#' || *cursor == '\r' || *cursor == '\n')
            break;
        char *end;
        double number = strtod(cursor, &end);
        if (end == cursor || (*end && !isspace((unsigned char)*end)))
            break; /* not a number: what follows is not a coordinate */
        if (!isfinite(number))
            return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: %s coordinate is not a finite number",
                            c->path, c->line, keyword);
        if (fabs(number) > FLT_MAX)
            return rad_fail(error, RAD_ERR_PARSE,
                            "%s:%lu: %s coordinate %g is beyond single precision", c->path,
                            c->line, keyword, number);
        if (count < 4)
            value[count] = number;
        count++;
        leading_point |= *cursor == '.';
        cursor = end;
    }
    if (count < least)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: '%s' line with %d number%s, %d expected",
                        c->path, c->line, keyword, count, count == 1 ? "" : "s", least);
    if (strcmp(keyword, "v") == 0 && count == 4 && value[3] == 0)
        return rad_fail(error, RAD_ERR_PARSE, "%s:%lu: vertex weight w is 0", c->path, c->line);
    bool ok = true;
    if (!leading_point)
        ok = append_text(c, line, strlen(line));
    else { /* the line again, a 0 before each number that starts with the point */
        c->copy_differs = true;
        ok = append_text(c, line, (size_t)(numbers - line));
        for (cursor = numbers; ok && *cursor;) {
            size_t blank = strspn(cursor, " \t");
            ok = append_text(c, cursor, blank);
            cursor += blank;
            if (ok && *cursor == '.')
                ok = append_text(c, "0", 1);
            size_t word = strcspn(cursor, " \t");
            ok = ok && append_text(c, cursor, word);
            cursor += word;
        }
    }
    return ok ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
}

/* One material library `name` of an mtllib line, written to the copy as the path Assimp
 * opens: the file beside the OBJ (or at its absolute path); else, as Blender and Assimp
 * do, a file of its base name beside the OBJ, with a warning. */
/* The shortest material library Assimp 5.2 reads (see add_obj_library). */
enum { OBJ_SMALLEST_LIBRARY = 8 };

static rad_status add_obj_library(obj_check *c, const char *name, rad_error *error)
{
    char library[8192 + 4096];
    snprintf(library, sizeof(library), "%s%s", name[0] == '/' ? "" : c->folder, name);
    struct stat st;
    bool exists = stat(library, &st) == 0;
    if (exists && !S_ISREG(st.st_mode))
        return rad_fail(error, RAD_ERR_IO, "%s:%lu: material library '%s' is not a file",
                        c->path, c->line, name);
    if (!exists) {
        const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
        char beside[8192 + 4096];
        snprintf(beside, sizeof(beside), "%s%s", c->folder, base);
        if (base == name || !*base || !is_regular_file(beside))
            return rad_fail(error, RAD_ERR_IO, "%s:%lu: material library '%s' not found%s%s%s",
                            c->path, c->line, name, base == name ? "" : " (nor '",
                            base == name ? "" : base, base == name ? "" : "' beside the OBJ)");
        rad_warn(c->options ? c->options->log : NULL, c->options ? c->options->log_user : NULL,
                 "%s:%lu: material library '%s' not found; '%s' beside the OBJ is read instead",
                 c->path, c->line, name, base);
        snprintf(library, sizeof(library), "%s", beside);
        c->copy_differs = true;
    }
    if (!append_text(c, "mtllib ", 7) || !append_text(c, library, strlen(library)) ||
        !append_text(c, "\n", 1))
        return rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
    FILE *file = fopen(library, "rb");
    if (!file)
        return rad_fail(error, RAD_ERR_IO, "%s:%lu: material library '%s': cannot open: %s",
                        c->path, c->line, name, strerror(errno));
    /* a NUL byte hides what follows it on its line from the checks below, and Assimp 5.2
     * crashed on a texture statement hidden that way (found by fuzz_mtl) */
    char chunk[4096];
    size_t got;
    bool has_nul = false;
    while (!has_nul && (got = fread(chunk, 1, sizeof(chunk), file)) > 0)
        has_nul = memchr(chunk, 0, got) != NULL;
    if (has_nul) {
        fclose(file);
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: material library '%s' holds a NUL byte: not a text file",
                        c->path, c->line, name);
    }
    rewind(file);
    /* Assimp 5.2 fails the whole OBJ ("File is too small", and leaks) on a library of 1
     * to 7 bytes: "newmtl a" is the shortest that defines a material */
    if (fstat(fileno(file), &st) == 0 && st.st_size > 0 && st.st_size < OBJ_SMALLEST_LIBRARY) {
        fclose(file);
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s:%lu: material library '%s' has %lld bytes, too few for a material "
                        "(Assimp 5.2 refuses a file of 1 to %d bytes): empty it or remove the "
                        "mtllib line",
                        c->path, c->line, name, (long long)st.st_size, OBJ_SMALLEST_LIBRARY - 1);
    }
    char *line = NULL;
    size_t capacity = 0;
    bool ok = true, in_material = false;
    unsigned long mtl_line = 0;
    rad_status status = RAD_OK;
    bool out_of_memory = false;
    while (ok && status == RAD_OK && read_line(file, &line, &capacity, &out_of_memory)) {
        char *p = line;
        if (++mtl_line == 1 && strncmp(p, "\xef\xbb\xbf", 3) == 0)
            p += 3; /* a UTF-8 byte order mark */
        while (isspace((unsigned char)*p))
            p++;
        size_t word = strcspn(p, " \t\r\n");
        if (strncmp(p, "newmtl", 6) == 0 && isspace((unsigned char)p[6])) {
            in_material = true;
            ok = names_add(&c->materials_defined, rest_of_line(p + 6), 0);
        } else if (!in_material && *p && *p != '#') {
            /* Assimp 5.2 crashes on some statements before the first newmtl (a texture,
             * one starting with 'a'): they belong to no material, so all are refused */
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s:%lu: material library '%s', line %lu: '%.*s' before the "
                              "first newmtl belongs to no material",
                              c->path, c->line, name, mtl_line, (int)(word < 40 ? word : 40), p);
        }
    }
    free(line);
    fclose(file);
    if (status != RAD_OK)
        return status;
    return ok && !out_of_memory ? RAD_OK : rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
}

/* An mtllib line's libraries: the whole rest of the line when it names a file (a name
 * with spaces), else each word (several libraries on one line, which Assimp 5.2 would
 * look up as one name). */
static rad_status check_obj_libraries(obj_check *c, char *names, rad_error *error)
{
    names = rest_of_line(names);
    if (!*names)
        return append_text(c, "\n", 1) ? RAD_OK
                                         : rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory",
                                                    c->path);
    char whole[8192 + 4096];
    snprintf(whole, sizeof(whole), "%s%s", names[0] == '/' ? "" : c->folder, names);
    if (is_regular_file(whole) || !strpbrk(names, " \t"))
        return add_obj_library(c, names, error);
    c->copy_differs = true; /* one mtllib line for each */
    for (char *word = strtok(names, " \t"); word; word = strtok(NULL, " \t")) {
        rad_status status = add_obj_library(c, word, error);
        if (status != RAD_OK)
            return status;
    }
    return RAD_OK;
}

rad_status obj_check_read(const char *path, const rad_load_options *options, FILE *file,
                          obj_check *c, rad_error *error)
{
    memset(c, 0, sizeof(*c));
    c->path = path;
    c->options = options;
    c->materials_used.with_lines = true;
    const char *slash = strrchr(path, '/');
    size_t folder_length = slash ? (size_t)(slash - path) + 1 : 0;
    if (folder_length >= sizeof(c->folder))
        folder_length = sizeof(c->folder) - 1;
    memcpy(c->folder, path, folder_length);
    c->folder[folder_length] = 0;
    char *line = NULL;
    size_t capacity = 0;
    rad_status status = RAD_OK;
    static const struct {
        const char *keyword;
        int list, least;
    } data[] = {{"v", OBJ_VERTEX, 3}, {"vt", OBJ_UV, 2}, {"vn", OBJ_NORMAL, 3}};
    unsigned long continued = 0; /* lines joined to the one before by a trailing '\\' */
    bool out_of_memory = false;
    while (status == RAD_OK && read_line(file, &line, &capacity, &out_of_memory)) {
        c->line += 1 + continued;
        continued = 0;
        for (;;) { /* a '\\' at the end continues the line on the next (Assimp joins them) */
            size_t n = strlen(line);
            while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
                n--;
            if (n == 0 || line[n - 1] != '\\')
                break;
            line[n - 1] = ' ';
            line[n] = 0;
            char *more = NULL;
            size_t more_capacity = 0;
            bool read = read_line(file, &more, &more_capacity, &out_of_memory);
            if (read && !rad_grow_array((void **)&line, &capacity, n + strlen(more) + 1, 1)) {
                read = false;
                out_of_memory = true;
            }
            if (read)
                strcpy(line + n, more);
            free(more);
            if (!read)
                break;
            continued++;
        }
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (p != line && isalpha((unsigned char)*p)) { /* Assimp 5.2 skips indented lines */
            memmove(line, p, strlen(p) + 1);
            p = line;
            c->copy_differs = true;
        }
        size_t word = strcspn(p, " \t\r\n");
        bool handled = false;
        for (size_t k = 0; k < sizeof(data) / sizeof(data[0]) && !handled; k++)
            if (word == strlen(data[k].keyword) && strncmp(p, data[k].keyword, word) == 0 &&
                p[word]) {
                handled = true;
                c->defined[data[k].list]++;
                status = check_obj_numbers(c, data[k].keyword, line, p + word,
                                           data[k].least, error);
            }
        if (handled)
            continue;
        if (word == 1 && p[0] == 'f') {
            status = check_obj_face(c, p + 1, error);
            char *comment = strchr(p, '#');
            if (comment) { /* Assimp 5.2 reads a comment after a face as corners */
                strcpy(comment, "\n");
                c->copy_differs = true;
            }
        }
        if (status == RAD_OK && word == 6 && strncmp(p, "usemtl", 6) == 0) {
            char name[256];
            snprintf(name, sizeof(name), "%s", p + 6);
            char *used = rest_of_line(name);
            if (*used && !obj_names_has(&c->materials_used, used) &&
                !names_add(&c->materials_used, used, c->line))
                status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
        }
        if (status == RAD_OK && word == 6 && strncmp(p, "mtllib", 6) == 0)
            status = check_obj_libraries(c, p + 6, error);
        else if (status == RAD_OK && !append_text(c, line, strlen(line)))
            status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
    }
    free(line);
    if (status == RAD_OK && out_of_memory)
        status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
    /* materials used but defined by no library (Assimp 5.2 makes them up, grey 0.6): the
     * default albedo, as faces without a material, and a warning at their first use */
    char *entry = c->materials_used.text ? c->materials_used.text + 1 : NULL;
    while (status == RAD_OK && entry && *entry) {
        char *tab = strchr(entry, '\t'), *end = tab ? strchr(tab, '\n') : NULL;
        if (!end)
            break;
        *tab = 0;
        unsigned long first = strtoul(tab + 1, NULL, 10);
        if (!obj_names_has(&c->materials_defined, entry)) {
            rad_warn(c->options ? c->options->log : NULL,
                     c->options ? c->options->log_user : NULL,
                     "%s:%lu: usemtl '%s': no material library of the file defines it; its "
                     "faces get the default albedo %g",
                     c->path, first, entry, RAD_DEFAULT_ALBEDO);
            if (!names_add(&c->materials_undefined, entry, 0))
                status = rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory", c->path);
        }
        entry = end + 1;
    }
    for (int list = 0; list < OBJ_LISTS && status == RAD_OK; list++)
        if ((unsigned long long)c->largest[list] > c->defined[list])
            status = rad_fail(error, RAD_ERR_PARSE,
                              "%s:%lu: face refers to %s %lld but only %lu %s defined", c->path,
                              c->largest_line[list], obj_list_name[list], c->largest[list],
                              c->defined[list], c->defined[list] == 1 ? "is" : "are");
    return status;
}

void obj_check_free(obj_check *c)
{
    free(c->copy);
    free(c->materials_defined.text);
    free(c->materials_used.text);
    free(c->materials_undefined.text);
    c->copy = NULL;
    c->materials_defined.text = c->materials_used.text = c->materials_undefined.text = NULL;
}

