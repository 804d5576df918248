/*
 * convergence_plot.c - rad_convergence_plot_write: a convergence history as a standalone
 * SVG (log y with decade ticks, linear x, one panel against the steps and one against
 * time); rad_convergence_plot_compare: several runs' residuals on the same axes. It draws what it is given and computes nothing about the solve; the history
 * comes from convergence_history.c. The text is built in memory and written atomically.
 */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"

enum { PLOT_WIDTH = 760, PLOT_LEFT = 90, PLOT_RIGHT = 730, PANEL_HEIGHT = 230,
       FIRST_PANEL_TOP = 78, PANEL_GAP = 96 };

/* A growing text; `failed` once an allocation failed (every later append is dropped). */
typedef struct svg_text {
    char *data;
    size_t length, capacity;
    int failed;
} svg_text;

static void put(svg_text *t, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void put(svg_text *t, const char *format, ...)
{
    if (t->failed)
        return;
    va_list args;
    va_start(args, format);
    int need = vsnprintf(NULL, 0, format, args);
    va_end(args);
    if (need < 0) {
        t->failed = 1;
        return;
    }
    void *data = t->data;
    if (!rad_grow_array(&data, &t->capacity, t->length + (size_t)need + 1, 1)) {
        t->failed = 1;
        return;
    }
    t->data = data;
    va_start(args, format);
    vsnprintf(t->data + t->length, (size_t)need + 1, format, args);
    va_end(args);
    t->length += (size_t)need;
}

/* `text` with XML's special characters escaped. */
static void put_escaped(svg_text *t, const char *text)
{
    for (const char *c = text; *c; c++) {
        switch (*c) {
        case '&': put(t, "&amp;"); break;
        case '<': put(t, "&lt;"); break;
        case '>': put(t, "&gt;"); break;
        case '"': put(t, "&quot;"); break;
        default: put(t, "%c", *c);
        }
    }
}

/* A step of 1, 2 or 5 times a power of ten giving at most about `target` ticks over
 * [0, range]. */
static double nice_step(double range, int target)
{
    double raw = range / target;
    double decade = pow(10, floor(log10(raw)));
    double m = raw / decade;
    return decade * (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10);
}

typedef struct panel {
    double top, x_max;     /* pixels; the x axis runs over [0, x_max] */
    int decade_lo, decade_hi;
    const char *x_label;
    const char *id;        /* "steps" or "time" */
} panel;

static double px(const panel *p, double x)
{
    return PLOT_LEFT + (PLOT_RIGHT - PLOT_LEFT) * x / p->x_max;
}

static double py(const panel *p, double v)
{
    double f = (log10(v) - p->decade_lo) / (p->decade_hi - p->decade_lo);
    return p->top + PANEL_HEIGHT * (1 - f);
}

static void put_axes(svg_text *t, const panel *p, const char *y_label)
{
    double bottom = p->top + PANEL_HEIGHT;
    put(t, "<g class=\"panel\" id=\"%s\">\n", p->id);
    put(t, "<rect x=\"%d\" y=\"%.2f\" width=\"%d\" height=\"%d\" fill=\"none\" "
           "stroke=\"#444\"/>\n", PLOT_LEFT, p->top, PLOT_RIGHT - PLOT_LEFT, PANEL_HEIGHT);
    int decades = p->decade_hi - p->decade_lo;
    int every = decades > 12 ? 2 : 1;
    for (int k = p->decade_lo; k <= p->decade_hi; k++) {
        double y = py(p, pow(10, k));
        put(t, "<line class=\"ytick\" data-value=\"1e%d\" x1=\"%d\" y1=\"%.3f\" x2=\"%d\" "
               "y2=\"%.3f\" stroke=\"#ddd\"/>\n", k, PLOT_LEFT, y, PLOT_RIGHT, y);
        if ((k - p->decade_lo) % every == 0)
            put(t, "<text x=\"%d\" y=\"%.2f\" text-anchor=\"end\" font-size=\"12\">10"
                   "<tspan dy=\"-6\" font-size=\"9\">%d</tspan></text>\n",
                PLOT_LEFT - 6, y + 4, k);
    }
    double step = nice_step(p->x_max, 6);
    for (int i = 0; i * step <= p->x_max * (1 + 1e-9); i++) {
        double x = px(p, i * step);
        put(t, "<line class=\"xtick\" data-value=\"%g\" x1=\"%.3f\" y1=\"%.2f\" x2=\"%.3f\" "
               "y2=\"%.2f\" stroke=\"#444\"/>\n", i * step, x, bottom, x, bottom + 5);
        put(t, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\" font-size=\"12\">%g</text>\n",
            x, bottom + 19, i * step);
    }
    put(t, "<text class=\"xlabel\" x=\"%d\" y=\"%.2f\" text-anchor=\"middle\" "
           "font-size=\"13\">", (PLOT_LEFT + PLOT_RIGHT) / 2, bottom + 40);
    put_escaped(t, p->x_label);
    put(t, "</text>\n");
    put(t, "<text class=\"ylabel\" transform=\"translate(22 %.2f) rotate(-90)\" "
           "text-anchor=\"middle\" font-size=\"13\">", p->top + PANEL_HEIGHT / 2.0);
    put_escaped(t, y_label);
    put(t, "</text>\n");
}

/* A dotted line where the phase changes, named, except into the first phase after the
 * start (a solver's steps all have its one phase; the hierarchical solver's change). */
static void put_phases(svg_text *t, const panel *p, const rad_convergence *h, bool by_time)
{
    for (size_t i = 2; i < h->count; i++) {
        const char *was = h->points[i - 1].phase, *now = h->points[i].phase;
        if (!was || !now || strcmp(was, now) == 0)
            continue;
        double x = px(p, by_time ? h->points[i].seconds : (double)h->points[i].step);
        put(t, "<line class=\"phase\" x1=\"%.3f\" y1=\"%.2f\" x2=\"%.3f\" y2=\"%.2f\" "
               "stroke=\"#888\" stroke-dasharray=\"2 3\"/>\n", x, p->top, x, p->top + PANEL_HEIGHT);
        bool left = x > PLOT_RIGHT - 90; /* near the right edge: the name to the left */
        put(t, "<text class=\"phase\" x=\"%.2f\" y=\"%.2f\" font-size=\"11\" fill=\"#555\" "
               "text-anchor=\"%s\">", left ? x - 3 : x + 3, p->top + 12, left ? "end" : "start");
        put_escaped(t, now);
        put(t, "</text>\n");
    }
}

static double value_of(const rad_convergence_point *q, size_t field)
{
    return *(const double *)((const char *)q + field);
}

/* A value a log axis can show. */
static bool drawable(const rad_convergence_point *q, size_t field)
{
    double v = value_of(q, field);
    return v > 0 && isfinite(v);
}

/* The curve of one field (offset into rad_convergence_point) against steps or seconds. */
static void put_curve(svg_text *t, const panel *p, const rad_convergence *h, size_t field,
                      bool by_time, const char *class_name, const char *style)
{
    put(t, "<path class=\"%s\" fill=\"none\" %s d=\"", class_name, style);
    bool drawing = false;
    for (size_t i = 0; i < h->count; i++) {
        const rad_convergence_point *q = &h->points[i];
        if (!drawable(q, field)) {
            drawing = false;
            continue;
        }
        double x = by_time ? q->seconds : (double)q->step;
        put(t, "%s%.3f,%.3f", drawing ? " L" : " M", px(p, x), py(p, value_of(q, field)));
        drawing = true;
    }
    put(t, "\"/>\n");
    /* a point with no drawn neighbour (the direct solver's one) would be invisible */
    for (size_t i = 0; i < h->count; i++) {
        const rad_convergence_point *q = &h->points[i];
        if (!drawable(q, field) || (i > 0 && drawable(q - 1, field)) ||
            (i + 1 < h->count && drawable(q + 1, field)))
            continue;
        double x = by_time ? q->seconds : (double)q->step;
        put(t, "<circle class=\"%s-point\" cx=\"%.3f\" cy=\"%.3f\" r=\"3.5\" fill=\"white\" %s/>\n",
            class_name, px(p, x), py(p, value_of(q, field)), style);
    }
}

/* Colours of the compared runs' curves, in order (then again). */
static const char *const run_colour[] = {"#1f5fbf", "#d9730d", "#2a9d3a", "#b8307a",
                                         "#6b4fbf", "#7f7f1f"};
#define RUN_COLOURS (sizeof(run_colour) / sizeof(run_colour[0]))

/* One history with its residual and criterion (names NULL), or several runs' residuals,
 * each named in the legend (names given). */
static rad_status plot_write(const rad_convergence *histories, const char *const *names,
                             size_t runs, const char *path,
                             const rad_convergence_plot_options *options, rad_error *error)
{
    for (size_t r = 0; r < runs; r++)
        if (histories[r].count == 0)
            return rad_fail(error, RAD_ERR_INVALID, "%s: no steps to plot", path);
    if (runs == 0)
        return rad_fail(error, RAD_ERR_INVALID, "%s: no steps to plot", path);
    rad_convergence_plot_options none = {0};
    const rad_convergence_plot_options *o = options ? options : &none;
    const char *y_label = o->y_label ? o->y_label : "relative to the emitted power sum A |E| (1)";
    bool residual = o->residual || names, criterion = o->criterion_label && !names;

    /* y range: the decades around every drawn positive value */
    double lo = INFINITY, hi = 0, steps = 0, seconds = 0;
    for (size_t r = 0; r < runs; r++)
        for (size_t i = 0; i < histories[r].count; i++) {
            const rad_convergence_point *q = &histories[r].points[i];
            double v[2] = {residual ? q->residual : NAN, criterion ? q->criterion : NAN};
            for (int k = 0; k < 2; k++)
                if (v[k] > 0 && isfinite(v[k])) {
                    lo = fmin(lo, v[k]);
                    hi = fmax(hi, v[k]);
                }
            steps = fmax(steps, q->step);
            if (isfinite(q->seconds))
                seconds = fmax(seconds, q->seconds);
        }
    int decade_lo = -1, decade_hi = 0; /* nothing positive: an empty frame */
    if (hi > 0) {
        /* a value a rounding error above a power of ten (an unshot fraction of 1) does not
         * open a decade of its own */
        decade_lo = (int)floor(log10(lo) + 1e-9);
        decade_hi = (int)ceil(log10(hi) - 1e-9);
        if (decade_hi <= decade_lo)
            decade_hi = decade_lo + 1;
    }
    panel panels[2];
    int count = 0;
    double top = FIRST_PANEL_TOP;
    if (o->step_label) {
        panels[count++] = (panel){top, steps > 0 ? steps : 1, decade_lo, decade_hi,
                                  o->step_label, "steps"};
        top += PANEL_HEIGHT + PANEL_GAP;
    }
    panels[count++] = (panel){top, seconds > 0 ? seconds : 1, decade_lo, decade_hi,
                              o->time_label ? o->time_label : "solver time (s)", "time"};
    int height = (int)(top + PANEL_HEIGHT + 56);

    svg_text t = {0};
    put(&t, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
        PLOT_WIDTH, height, PLOT_WIDTH, height);
    put(&t, "<title>");
    put_escaped(&t, o->title ? o->title : "convergence");
    put(&t, "</title>\n<text class=\"title\" x=\"%d\" y=\"26\" text-anchor=\"middle\" "
            "font-size=\"16\">", PLOT_WIDTH / 2);
    put_escaped(&t, o->title ? o->title : "convergence");
    put(&t, "</text>\n");
    /* legend */
    double lx = PLOT_LEFT;
    for (size_t r = 0; names && r < runs; r++) {
        double ly = 50 + 16.0 * (double)(r / 3);
        double at = lx + 215.0 * (double)(r % 3);
        put(&t, "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"%s\" "
                "stroke-width=\"2\"/><text class=\"legend\" x=\"%.0f\" y=\"%.0f\" "
                "font-size=\"12\">", at, ly, at + 28, ly, run_colour[r % RUN_COLOURS], at + 34,
            ly + 4);
        put_escaped(&t, names[r]);
        put(&t, "</text>\n");
    }
    if (residual && !names) {
        put(&t, "<line x1=\"%.0f\" y1=\"50\" x2=\"%.0f\" y2=\"50\" stroke=\"#1f5fbf\" "
                "stroke-width=\"2\"/><text x=\"%.0f\" y=\"54\" font-size=\"12\">relative "
                "residual</text>\n", lx, lx + 28, lx + 34);
        lx += 190;
    }
    if (criterion) {
        put(&t, "<line x1=\"%.0f\" y1=\"50\" x2=\"%.0f\" y2=\"50\" stroke=\"#d9730d\" "
                "stroke-width=\"2\" stroke-dasharray=\"6 3\"/><text x=\"%.0f\" y=\"54\" "
                "font-size=\"12\">", lx, lx + 28, lx + 34);
        put_escaped(&t, o->criterion_label);
        put(&t, "</text>\n");
    }
    for (int k = 0; k < count; k++) {
        const panel *p = &panels[k];
        bool by_time = strcmp(p->id, "time") == 0;
        put_axes(&t, p, y_label);
        if (!names)
            put_phases(&t, p, &histories[0], by_time);
        if (criterion)
            put_curve(&t, p, &histories[0], offsetof(rad_convergence_point, criterion), by_time,
                      "criterion",
                      "stroke=\"#d9730d\" stroke-width=\"2\" stroke-dasharray=\"6 3\"");
        for (size_t r = 0; residual && r < runs; r++) {
            char style[96];
            snprintf(style, sizeof(style), "stroke=\"%s\" stroke-width=\"2\" data-run=\"%zu\"",
                     names ? run_colour[r % RUN_COLOURS] : "#1f5fbf", r);
            put_curve(&t, p, &histories[r], offsetof(rad_convergence_point, residual), by_time,
                      "residual", style);
        }
        put(&t, "</g>\n");
    }
    put(&t, "</svg>\n");
    if (t.failed) {
        free(t.data);
        return rad_fail(error, RAD_ERR_NOMEM, "%s: no memory for the plot", path);
    }
    rad_status status = rad_write_file_atomic(path, t.data, t.length, error);
    free(t.data);
    return status;
}

rad_status rad_convergence_plot_write(const rad_convergence *history, const char *path,
                                      const rad_convergence_plot_options *options,
                                      rad_error *error)
{
    if (!history)
        return rad_fail(error, RAD_ERR_INVALID, "%s: no steps to plot", path);
    return plot_write(history, NULL, 1, path, options, error);
}

rad_status rad_convergence_plot_compare(const rad_convergence *histories,
                                        const char *const *names, size_t runs,
                                        const char *path,
                                        const rad_convergence_plot_options *options,
                                        rad_error *error)
{
    if (!histories || !names)
        return rad_fail(error, RAD_ERR_INVALID, "%s: no runs to compare", path);
    return plot_write(histories, names, runs, path, options, error);
}
