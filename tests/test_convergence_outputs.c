/*
 * test_convergence_outputs.c - `--plot` and `--record` from the command line: the record's
 * snapshots (count, fields, the last one equal to the solution file written by the same
 * run, within float32 rounding, and its residual the --stats residual); the SVG parsed by a
 * real XML parser (libxml2's xmllint; without it those checks are skipped with a message),
 * its axes labelled, and its curve's first and last points, read back through the axis
 * ticks, equal to the run's first and last residuals; viewfactors --plot; the record the
 * same for 1 and 2 threads but for its times; bad options.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

/* The output of a shell command (static buffer, "" on failure). */
static const char *shell_output(const char *command)
{
    static char text[1 << 20];
    text[0] = '\0';
    FILE *p = popen(command, "r");
    if (!p)
        return text;
    size_t length = fread(text, 1, sizeof(text) - 1, p);
    text[length] = '\0';
    pclose(p);
    return text;
}

static bool have_xmllint(void)
{
    return system("xmllint --version >/dev/null 2>&1") == 0;
}

/* The values of every ` name="value"` in xmllint's answer to an attribute XPath, as
 * numbers; returns how many (at most max). */
static int xpath_numbers(const char *svg, const char *xpath, double *out, int max)
{
    char command[2048];
    snprintf(command, sizeof(command), "xmllint --xpath \"%s\" '%s' 2>/dev/null", xpath, svg);
    const char *text = shell_output(command);
    int count = 0;
    for (const char *q = strchr(text, '"'); q && count < max; q = strchr(q, '"')) {
        out[count++] = strtod(q + 1, NULL);
        q = strchr(q + 1, '"'); /* the closing quote */
        if (!q)
            break;
        q++;
    }
    return count;
}

/* The text of an XPath string() expression. */
static const char *xpath_string(const char *svg, const char *xpath)
{
    char command[2048];
    snprintf(command, sizeof(command), "xmllint --xpath \"string(%s)\" '%s' 2>/dev/null", xpath,
             svg);
    return shell_output(command);
}

/* The points of the path `class_name` in panel `panel` of the SVG (at most max). */
static int curve_points(const char *svg, const char *panel, const char *class_name,
                        double (*xy)[2], int max)
{
    char xpath[512];
    snprintf(xpath, sizeof(xpath),
             "//*[local-name()='g'][@id='%s']/*[local-name()='path'][@class='%s']/@d", panel,
             class_name);
    const char *d = xpath_string(svg, xpath);
    int count = 0;
    for (const char *c = d; *c && count < max; c++) {
        if (*c != 'M' && *c != 'L')
            continue;
        if (sscanf(c + 1, "%lf,%lf", &xy[count][0], &xy[count][1]) == 2)
            count++;
    }
    return count;
}

/* Maps pixel y to a value through the panel's decade ticks (log10 linear in y) and pixel
 * x to a value through its x ticks (linear). */
typedef struct axes {
    double y0, y1, log0, log1; /* two decade ticks: pixel and log10 value */
    double x0, x1, v0, v1;     /* two x ticks: pixel and value */
    bool ok;
} axes;

static axes read_axes(const char *svg, const char *panel)
{
    axes a = {0};
    double values[64], ys[64], xs[64], xvalues[64];
    char xpath[512];
    snprintf(xpath, sizeof(xpath),
             "//*[local-name()='g'][@id='%s']/*[local-name()='line'][@class='ytick']/@data-value",
             panel);
    int nv = xpath_numbers(svg, xpath, values, 64);
    snprintf(xpath, sizeof(xpath),
             "//*[local-name()='g'][@id='%s']/*[local-name()='line'][@class='ytick']/@y1", panel);
    int ny = xpath_numbers(svg, xpath, ys, 64);
    snprintf(xpath, sizeof(xpath),
             "//*[local-name()='g'][@id='%s']/*[local-name()='line'][@class='xtick']/@data-value",
             panel);
    int nxv = xpath_numbers(svg, xpath, xvalues, 64);
    snprintf(xpath, sizeof(xpath),
             "//*[local-name()='g'][@id='%s']/*[local-name()='line'][@class='xtick']/@x1", panel);
    int nx = xpath_numbers(svg, xpath, xs, 64);
    if (nv < 2 || nv != ny || nxv < 2 || nxv != nx)
        return a;
    a.y0 = ys[0];
    a.log0 = log10(values[0]);
    a.y1 = ys[nv - 1];
    a.log1 = log10(values[nv - 1]);
    a.x0 = xs[0];
    a.v0 = xvalues[0];
    a.x1 = xs[nx - 1];
    a.v1 = xvalues[nx - 1];
    a.ok = a.y0 != a.y1 && a.x0 != a.x1;
    return a;
}

static double axis_y(const axes *a, double y)
{
    return pow(10, a->log0 + (y - a->y0) * (a->log1 - a->log0) / (a->y1 - a->y0));
}

static double axis_x(const axes *a, double x)
{
    return a->v0 + (x - a->x0) * (a->v1 - a->v0) / (a->x1 - a->x0);
}

static cJSON *read_json(const char *name)
{
    size_t size = 0;
    uint8_t *bytes = test_read_bytes(test_path(name), &size);
    cJSON *root = bytes ? cJSON_ParseWithLength((const char *)bytes, size) : NULL;
    free(bytes);
    return root;
}

static double json_number(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(item) ? item->valuedouble : NAN;
}

/* Base64 (RFC 4648) into out; returns the bytes decoded, or 0 on a bad character. */
static size_t base64_decode(const char *text, uint8_t *out, size_t max)
{
    uint32_t bits = 0;
    int have = 0;
    size_t length = 0;
    for (const char *c = text; *c && *c != '='; c++) {
        const char *digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const char *where = strchr(digits, *c);
        if (!where)
            return 0;
        bits = bits << 6 | (uint32_t)(where - digits);
        have += 6;
        if (have >= 8) {
            have -= 8;
            if (length < max)
                out[length] = (uint8_t)(bits >> have);
            length++;
        }
    }
    return length;
}

static float little_endian_float(const uint8_t *b)
{
    uint32_t bits = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                    (uint32_t)b[3] << 24;
    float f;
    memcpy(&f, &bits, sizeof(f));
    return f;
}

/* The shooting run: record and plot against the run's own solution file and --stats. */
static void check_shooting_run(bool xml)
{
    CHECK(test_run_tool("solve --solver shoot --patch-size 100 --threads 2 --save-solution "
                        "s.sol --record r.json --plot p.svg --stats st.json --quiet") == 0);
    cJSON *stats = read_json("st.json");
    cJSON *record = read_json("r.json");
    rad_solution *solution = NULL;
    rad_error error = {0};
    CHECK(rad_solution_read(test_path("s.sol"), &solution, &error) == RAD_OK);
    CHECK(stats && record && solution);
    if (!stats || !record || !solution)
        goto done;
    uint32_t n = solution->patch_count;
    uint32_t shots = (uint32_t)json_number(stats, "iterations");
    double final_residual = json_number(stats, "final_residual");
    CHECK(json_number(stats, "patches") == n);
    CHECK(shots > n);

    const cJSON *format = cJSON_GetObjectItemCaseSensitive(record, "format");
    CHECK(cJSON_IsString(format) && strcmp(format->valuestring, "radiosity-record") == 0);
    CHECK(json_number(record, "version") == 1);
    const cJSON *solver = cJSON_GetObjectItemCaseSensitive(record, "solver");
    CHECK(cJSON_IsString(solver) && strcmp(solver->valuestring, "shoot") == 0);
    CHECK(cJSON_IsString(cJSON_GetObjectItemCaseSensitive(record, "scene")));
    CHECK(json_number(record, "patches") == n);
    const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(record, "snapshots");
    int count = cJSON_GetArraySize(snapshots);
    uint32_t every = n / RAD_OBSERVE_SHOTS_DIVISOR;
    fprintf(stderr, "shoot: %u patches, %u shots, %d snapshots every %u shots\n", n, shots,
            count, every);
    CHECK(count == (int)((shots + every - 1) / every + 1));
    CHECK(count >= 50 && count <= 200); /* the default aims at about 100 */
    const cJSON *first = cJSON_GetArrayItem(snapshots, 0);
    const cJSON *last = cJSON_GetArrayItem(snapshots, count - 1);
    CHECK(json_number(first, "step") == 0 && json_number(first, "unshot") == 1);
    CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(first, "shooting_patch")));
    CHECK(json_number(cJSON_GetArrayItem(snapshots, 1), "shooting_patch") < n);
    CHECK(json_number(last, "step") == shots);
    CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(last, "final")));
    CHECK_NEAR(json_number(last, "residual"), final_residual, 1e-8);
    double first_residual = json_number(first, "residual");
    CHECK(first_residual > 0.1 && first_residual < 1); /* B = E: the first bounce missing */

    /* the last snapshot is the solution written, within float32 rounding */
    const cJSON *radiosity = cJSON_GetObjectItemCaseSensitive(last, "radiosity");
    uint8_t *bytes = malloc(12 * (size_t)n + 16);
    CHECK(cJSON_IsString(radiosity) && bytes);
    if (cJSON_IsString(radiosity) && bytes) {
        CHECK(strlen(radiosity->valuestring) == 4 * ((12 * (size_t)n + 2) / 3));
        CHECK(base64_decode(radiosity->valuestring, bytes, 12 * (size_t)n + 16) == 12 * (size_t)n);
        double worst = 0;
        for (uint32_t i = 0; i < n; i++) {
            const rad_rgb b = solution->B[i];
            const double want[3] = {b.r, b.g, b.b};
            for (int c = 0; c < 3; c++) {
                double got = little_endian_float(bytes + 12 * (size_t)i + 4 * c);
                worst = fmax(worst, fabs(got - want[c]) / fmax(fabs(want[c]), 1e-30));
            }
        }
        CHECK(worst <= 6e-8); /* float32's half ulp */
    }
    free(bytes);

    if (xml) {
        const char *svg = test_path("p.svg");
        char command[4200];
        snprintf(command, sizeof(command), "xmllint --noout '%s'", svg);
        CHECK(system(command) == 0);
        CHECK(strstr(xpath_string(svg, "//*[local-name()='text'][@class='title']"), "shoot") !=
              NULL);
        CHECK(strstr(xpath_string(svg, "(//*[local-name()='text'][@class='xlabel'])[1]"),
                     "shots") != NULL);
        CHECK(strstr(xpath_string(svg, "(//*[local-name()='text'][@class='xlabel'])[2]"),
                     "solver time (s)") != NULL);
        CHECK(strstr(xpath_string(svg, "(//*[local-name()='text'][@class='ylabel'])[1]"),
                     "(1)") != NULL);
        static double xy[4096][2];
        int points = curve_points(svg, "steps", "residual", xy, 4096);
        axes a = read_axes(svg, "steps");
        CHECK(a.ok && points == count);
        if (a.ok && points >= 2) {
            CHECK_NEAR(axis_x(&a, xy[0][0]), 0, 1e-6);
            CHECK_NEAR(axis_y(&a, xy[0][1]), first_residual, 1e-3);
            CHECK_NEAR(axis_x(&a, xy[points - 1][0]), shots, 1e-3);
            CHECK_NEAR(axis_y(&a, xy[points - 1][1]), final_residual, 1e-3);
        }
        /* the unshot fraction starts at 1 and the time panel has the same curves */
        int unshot = curve_points(svg, "steps", "criterion", xy, 4096);
        CHECK(unshot == count && a.ok && fabs(axis_y(&a, xy[0][1]) - 1) < 1e-3);
        CHECK(curve_points(svg, "time", "residual", xy, 4096) == count);
    }
done:
    rad_solution_destroy(solution);
    cJSON_Delete(stats);
    cJSON_Delete(record);
}

/* Jacobi gathering: a snapshot per sweep and the answer; the plot's last point. */
static void check_gathering_run(bool xml)
{
    CHECK(test_run_tool("render --solver gather --patch-size 120 --size 32x32 --spp 1 -o g.png "
                        "--record g.json --plot g.svg --stats g-stats.json --quiet") == 0);
    cJSON *stats = read_json("g-stats.json");
    cJSON *record = read_json("g.json");
    CHECK(stats && record);
    if (stats && record) {
        uint32_t sweeps = (uint32_t)json_number(stats, "iterations");
        const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(record, "snapshots");
        int count = cJSON_GetArraySize(snapshots);
        CHECK(sweeps > 3 && count == (int)sweeps + 1);
        const cJSON *last = cJSON_GetArrayItem(snapshots, count - 1);
        CHECK_NEAR(json_number(last, "residual"), json_number(stats, "final_residual"), 1e-8);
        CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(last, "unshot")));
        CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(snapshots, 0),
                                                            "criterion")));
        if (xml) {
            const char *svg = test_path("g.svg");
            static double xy[4096][2];
            int points = curve_points(svg, "steps", "residual", xy, 4096);
            axes a = read_axes(svg, "steps");
            CHECK(a.ok && points == count);
            if (a.ok && points == count) {
                CHECK_NEAR(axis_y(&a, xy[0][1]),
                           json_number(cJSON_GetArrayItem(snapshots, 0), "residual"), 1e-3);
                CHECK_NEAR(axis_y(&a, xy[points - 1][1]), json_number(stats, "final_residual"),
                           1e-3);
                CHECK_NEAR(axis_x(&a, xy[points - 1][0]), sweeps, 1e-3);
            }
            /* Jacobi's criterion is its residual one sweep late: not drawn twice */
            CHECK(curve_points(svg, "steps", "criterion", xy, 4096) == 0);
        }
    }
    cJSON_Delete(stats);
    cJSON_Delete(record);
}

/* The hierarchical solver: a snapshot per sweep and the answer; its phases marked. */
static void check_hierarchical_run(bool xml)
{
    CHECK(test_run_tool("solve --solver hierarchical --patch-size 120 --threads 2 -o h.ply "
                        "--record h.json --plot h.svg --stats h-stats.json --quiet") == 0);
    cJSON *stats = read_json("h-stats.json");
    cJSON *record = read_json("h.json");
    CHECK(stats && record);
    if (stats && record) {
        const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(record, "snapshots");
        int count = cJSON_GetArraySize(snapshots);
        CHECK(count == (int)json_number(stats, "iterations") + 1);
        const cJSON *last = cJSON_GetArrayItem(snapshots, count - 1);
        CHECK_NEAR(json_number(last, "residual"), json_number(stats, "final_residual"), 1e-8);
        const cJSON *phase = cJSON_GetObjectItemCaseSensitive(last, "phase");
        CHECK(cJSON_IsString(phase) && strcmp(phase->valuestring, "final gather") == 0);
        if (xml) {
            const char *svg = test_path("h.svg");
            CHECK(strstr(xpath_string(svg, "(//*[local-name()='g'][@id='steps']/"
                                           "*[local-name()='text'][@class='phase'])[last()]"),
                         "final gather") != NULL);
            static double xy[4096][2];
            axes a = read_axes(svg, "steps");
            int points = curve_points(svg, "steps", "residual", xy, 4096);
            CHECK(a.ok && points == count);
            if (a.ok && points == count)
                CHECK_NEAR(axis_y(&a, xy[points - 1][1]), json_number(stats, "final_residual"),
                           1e-3);
        }
    }
    cJSON_Delete(stats);
    cJSON_Delete(record);
}

/* A room of 7 surfaces (6 walls and a table in the middle), one OBJ object each. */
static void write_room(const char *name)
{
    static char text[65536];
    size_t length = 0;
    int vertices = 0;
    const double walls[7][9] = {
        {0, 0, 0, 0, 0, 5, 4, 0, 0},  {0, 3, 0, 4, 3, 0, 0, 3, 5}, {0, 0, 0, 0, 3, 0, 0, 0, 5},
        {4, 0, 0, 4, 0, 5, 4, 3, 0},  {0, 0, 5, 0, 3, 5, 4, 0, 5}, {0, 0, 0, 4, 0, 0, 0, 3, 0},
        {1, 1, 1.5, 1, 1, 3.5, 3, 1, 1.5}};
    /* each wall: corner o, then o + u, o + v: quad o, o + u, o + u + v, o + v */
    for (int w = 0; w < 7; w++) {
        const double *o = walls[w], *a = walls[w] + 3, *b = walls[w] + 6;
        length += (size_t)snprintf(text + length, sizeof(text) - length,
                                   "o wall%d\nv %g %g %g\nv %g %g %g\nv %g %g %g\nv %g %g %g\n"
                                   "f %d %d %d %d\n",
                                   w, o[0], o[1], o[2], a[0], a[1], a[2], a[0] + b[0] - o[0],
                                   a[1] + b[1] - o[1], a[2] + b[2] - o[2], b[0], b[1], b[2],
                                   vertices + 1, vertices + 2, vertices + 3, vertices + 4);
        vertices += 4;
    }
    test_write_file(name, text);
}

static void check_viewfactors(bool xml)
{
    write_room("room.obj");
    CHECK(test_run_tool("viewfactors room.obj -o vf.csv --plot vf.svg --threads 2 --quiet") == 0);
    CHECK(test_file_exists(test_path("vf.csv")) && test_file_exists(test_path("vf.svg")));
    if (xml) {
        const char *svg = test_path("vf.svg");
        char command[4200];
        snprintf(command, sizeof(command), "xmllint --noout '%s'", svg);
        CHECK(system(command) == 0);
        CHECK(strstr(xpath_string(svg, "//*[local-name()='text'][@class='title']"),
                     "view factors") != NULL);
        CHECK(strstr(xpath_string(svg, "(//*[local-name()='text'][@class='xlabel'])[1]"),
                     "(s)") != NULL);
        static double xy[4096][2];
        axes a = read_axes(svg, "time");
        int points = curve_points(svg, "time", "criterion", xy, 4096);
        CHECK(a.ok && points >= 1);
        if (a.ok && points >= 1) /* it starts with all the pairs left */
            CHECK_NEAR(axis_y(&a, xy[0][1]), 1, 1e-3);
    }
}

/* The record does not depend on the thread count, but for the seconds. */
static void check_threads(void)
{
    CHECK(test_run_tool("solve --solver shoot --patch-size 100 --threads 1 --save-solution "
                        "t1.sol --record t1.json --quiet") == 0);
    CHECK(test_run_tool("solve --solver shoot --patch-size 100 --threads 2 --save-solution "
                        "t2.sol --record t2.json --quiet") == 0);
    cJSON *one = read_json("t1.json"), *two = read_json("t2.json");
    CHECK(one && two);
    if (one && two) {
        cJSON *s;
        cJSON_ArrayForEach(s, cJSON_GetObjectItemCaseSensitive(one, "snapshots"))
            cJSON_DeleteItemFromObjectCaseSensitive(s, "seconds");
        cJSON_ArrayForEach(s, cJSON_GetObjectItemCaseSensitive(two, "snapshots"))
            cJSON_DeleteItemFromObjectCaseSensitive(s, "seconds");
        CHECK(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(one, "snapshots")) > 2);
        CHECK(cJSON_Compare(one, two, true));
    }
    cJSON_Delete(one);
    cJSON_Delete(two);
}

static void check_bad_options(void)
{
    CHECK(test_run_tool("solve -o x.ply --plot x.png") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "x.png") != NULL);
    CHECK(test_run_tool("solve -o x.ply --record nowhere/r.json") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "nowhere/r.json") != NULL);
    CHECK(test_run_tool("solve -o x.ply --plot same.svg --record same.svg") == 2);
    CHECK(test_run_tool("render --solution s.sol -o x.png --record r2.json") == 2);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "--solution") != NULL);
    CHECK(test_run_tool("viewfactors room.obj --plot vf.pdf") == 2);
    /* a solve that fails leaves no record and no plot, not even a temporary file */
    CHECK(test_run_tool("solve --solver direct --patch-size 8 -o x.ply --record fail.json "
                        "--plot fail.svg") == 1);
    CHECK(test_count_files("fail.") == 0);
    CHECK(test_count_files("x.ply") == 0);
}

/* `radiosity plot`: two solvers' records on one plot, a curve each (data-run K), each
 * ending at its record's last residual; bad input refused with one line, nothing
 * written. */
static void check_compare(bool xml)
{
    const char *solvers[2] = {"gather", "shoot"};
    for (int k = 0; k < 2; k++) {
        char command[256];
        snprintf(command, sizeof(command),
                 "solve --solver %s --patch-size 120 -o c-%s.ply --record c-%s.json --quiet",
                 solvers[k], solvers[k], solvers[k]);
        CHECK(test_run_tool(command) == 0);
    }
    CHECK(test_run_tool("plot c-gather.json c-shoot.json -o compare.svg --quiet") == 0);
    if (xml) {
        const char *svg = test_path("compare.svg");
        char command[1024];
        snprintf(command, sizeof(command), "xmllint --noout '%s'", svg);
        CHECK(system(command) == 0);
        axes a = read_axes(svg, "steps");
        CHECK(a.ok);
        for (int k = 0; k < 2 && a.ok; k++) {
            char file[64], xpath[256];
            snprintf(file, sizeof(file), "c-%s.json", solvers[k]);
            cJSON *record = read_json(file);
            const cJSON *snapshots = cJSON_GetObjectItemCaseSensitive(record, "snapshots");
            int count = cJSON_GetArraySize(snapshots);
            snprintf(xpath, sizeof(xpath),
                     "//*[local-name()='g'][@id='steps']/*[local-name()='path'][@data-run='%d']/@d",
                     k);
            const char *d = xpath_string(svg, xpath);
            double last_x = NAN, last_y = NAN;
            int points = 0;
            for (const char *c = d; *c; c++)
                if ((*c == 'M' || *c == 'L') && sscanf(c + 1, "%lf,%lf", &last_x, &last_y) == 2)
                    points++;
            CHECK(points == count);
            const cJSON *last = cJSON_GetArrayItem(snapshots, count - 1);
            CHECK_NEAR(axis_y(&a, last_y), json_number(last, "residual"), 1e-3);
            CHECK_NEAR(axis_x(&a, last_x), json_number(last, "step"), 1e-3);
            cJSON_Delete(record);
            snprintf(xpath, sizeof(xpath), "(//*[local-name()='text'][@class='legend'])[%d]",
                     k + 1);
            const char *name = xpath_string(svg, xpath);
            size_t length = strlen(solvers[k]);
            CHECK(strncmp(name, solvers[k], length) == 0 &&
                  (name[length] == '\0' || name[length] == '\n'));
        }
    }
    test_write_file("not-a-record.json", "{\"format\": \"something else\"}\n");
    CHECK(test_run_tool("plot c-gather.json not-a-record.json -o refused.svg") == 1);
    CHECK(strstr(test_read_text(test_path("stderr.txt")), "not-a-record.json") != NULL);
    CHECK(test_count_files("refused") == 0);
    CHECK(test_run_tool("plot c-gather.json") == 2);       /* no -o */
    CHECK(test_run_tool("plot c-gather.json -o c.png") == 2); /* not an SVG */
}

int main(void)
{
    test_tmpdir();
    bool xml = have_xmllint();
    if (!xml)
        fprintf(stderr, "test_convergence_outputs: xmllint not installed (Debian: "
                        "libxml2-utils): the SVG checks are skipped\n");
    check_shooting_run(xml);
    check_gathering_run(xml);
    check_hierarchical_run(xml);
    check_viewfactors(xml);
    check_threads();
    check_bad_options();
    check_compare(xml);
    return test_finish("test_convergence_outputs");
}
