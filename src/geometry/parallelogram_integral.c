/*
 * parallelogram_integral.c - adaptive integration over a parallelogram, split along the
 * direction in which the function changes fast; see parallelogram_integral.h.
 */
#include "geometry/parallelogram_integral.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>

#include "core/vec3.h"
#include "geometry/least_squares.h"

/* A cell is halved across one direction only when its fourth difference there is at least
 * this many times the other's, and not when both are within FLAT_DIFFERENCE of the largest
 * |f| it has seen. */
#define STRIP_RATIO 4.0
#define FLAT_DIFFERENCE 1e-9

/* 3-point Gauss-Legendre on [-1, 1] */
static const double gauss_node[3] = {-0.774596669241483377, 0, 0.774596669241483377};
static const double gauss_weight[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};

/* Probes along each of an outlier's two lines (below), and the outliers whose line probes'
 * values are kept (a pair of the 1k city had at most 8 outliers). */
#define LINE_PROBES 64
#define KEPT_LINES 8

typedef struct frame {
    const parallelogram_integral *c;
    rad_vec3 origin, a, b;
    double jacobian;    /* |a x b| */
    uint64_t lines;     /* the outliers whose lines are probed (line_probes_miss) */
    uint64_t *outliers; /* NULL, or the probes found outside their cells' range */
    /* f at the lattice's probes, and at the line probes of the first KEPT_LINES outliers
     * ([outlier][0: along t, 1: along s][probe]): NaN until known. A probe is tried again
     * each time a cell that holds it is about to be accepted. */
    double *probe_value;
    double (*line_value)[2][LINE_PROBES];
} frame;

typedef struct cell {
    double s0, s1, t0, t1;
} cell;

static inline double f_at(const frame *p, double s, double t)
{
    rad_vec3 x = v3_add(p->origin, v3_add(v3_scale(p->a, s), v3_scale(p->b, t)));
    return p->c->f(p->c->context, x);
}

static inline bool stopped(const frame *p) { return p->c->failed && *p->c->failed; }

static void corners_of(const frame *p, cell k, rad_vec3 corner[4])
{
    rad_vec3 a0 = v3_scale(p->a, k.s0), a1 = v3_scale(p->a, k.s1);
    rad_vec3 b0 = v3_scale(p->b, k.t0), b1 = v3_scale(p->b, k.t1);
    corner[0] = v3_add(p->origin, v3_add(a0, b0));
    corner[1] = v3_add(p->origin, v3_add(a1, b0));
    corner[2] = v3_add(p->origin, v3_add(a1, b1));
    corner[3] = v3_add(p->origin, v3_add(a0, b1));
}

/* Tells the cell callback which cell the next points belong to; whether f is smooth there. */
static bool enter(const frame *p, cell k, int level, int slot, int parent_slot)
{
    if (!p->c->cell)
        return p->c->min_splits == 0;
    rad_vec3 corner[4];
    corners_of(p, k, corner);
    return p->c->cell(p->c->context, corner, level, slot, parent_slot);
}

/* The 3 x 3 rule on the cell: value[3 i + j] is f at node i along s, node j along t. */
static double rule9(const frame *p, cell k, double *value)
{
    double hs = 0.5 * (k.s1 - k.s0), ht = 0.5 * (k.t1 - k.t0);
    double ms = 0.5 * (k.s0 + k.s1), mt = 0.5 * (k.t0 + k.t1);
    double sum = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = f_at(p, ms + hs * gauss_node[i], mt + ht * gauss_node[j]);
            value[3 * i + j] = v;
            sum += gauss_weight[i] * gauss_weight[j] * v;
        }
    return sum * hs * ht * p->jacobian;
}

/* The fourth divided difference of f at -1, -g, 0, g, 1 (g the outer Gauss node), up to a
 * constant factor: what a polynomial of degree 3 cannot follow along a centre line. */
static double fourth_difference(double e0, double g0, double m, double g1, double e1)
{
    const double g = gauss_node[2];
    /* weights 1 / prod (x_i - x_j) for the nodes above */
    double w_edge = 1 / (2 * (1 - g) * (1 + g)), w_inner = 1 / ((1 - g) * (1 + g) * 2 * g * g);
    double w_mid = 1 / (g * g);
    return fabs(w_edge * (e0 + e1) - w_inner * (g0 + g1) + w_mid * m);
}


/*
 * The edge check. A cell quartered holds 36 rule points in its children, on a grid of 6
 * positions each way (3 per half); the polynomial of degree 4 nearest them along each
 * direction (least squares) predicts f at -1, 0 and 1, so the grid predicts f at the
 * cell's corners, edge midpoints and centre, which are compared with f there. Where f is
 * smooth the prediction is good to h^5 and the check costs no split; a sliver of light or
 * shadow along an edge or at a corner, which no rule point sees, shows. A cell halved into
 * strips is checked along its centre line across the cut only (the midpoints of the two
 * edges parallel to the cut and the centre, against the 6 positions on that line): its
 * other check points would be extrapolated from the 3 nodes along the direction not cut,
 * a quadratic that misses even a smooth cubic. A sliver along an edge that was not cut
 * shows in the fourth difference that chose the cut, which takes that edge's midpoint; one
 * at a corner, seen by a quartered cell's check above the child's tolerance and above
 * what the rules disagree on, makes the child that holds that corner quarter too. A miss
 * weighs CHECK_SHARE_MARGIN times the part of the cell nearer that check point than any
 * other point (in the unit square of the cell's coordinates), as polygon_integral's edge
 * check does with 6: on the 1k city, against runs 1000 times finer, 6 left the errors of
 * the worst pairs at 0.9 of their bounds, 12 at 0.8 (the triangles' 0.8).
 */
#define CHECK_SHARE_MARGIN 12.0
#define CHECK_SHARE_LATTICE 120

enum { SPLIT_BOTH, SPLIT_S, SPLIT_T, SPLIT_KINDS };

/* predict6[m][a]: weight of position a (of 6) in f at m = -1, 0, 1 along a halved
 * direction */
static double predict6[3][6];
static double check_share[SPLIT_KINDS][3][3]; /* [kind][i along s][j along t] */
static pthread_once_t check_once = PTHREAD_ONCE_INIT;

/* the positions of the children's rule points along a halved direction, in [-1, 1] */
static double halved_position(int a)
{
    return (a < 3 ? -0.5 : 0.5) + 0.5 * gauss_node[a % 3];
}

static void check_compute(void)
{
    double six[6];
    const double *three = gauss_node;
    for (int a = 0; a < 6; a++)
        six[a] = halved_position(a);
    /* the quartic nearest the 6 positions, at -1, 0 and 1 */
    double design[6][5], at[3][5];
    for (int a = 0; a < 6; a++)
        for (int i = 0; i < 5; i++)
            design[a][i] = pow(six[a], i);
    for (int m = 0; m < 3; m++)
        for (int i = 0; i < 5; i++)
            at[m][i] = pow(m - 1.0, i);
    least_squares_predictor(&design[0][0], 6, 5, &at[0][0], 3, &predict6[0][0]);
    for (int kind = 0; kind < SPLIT_KINDS; kind++) {
        bool halved_s = kind != SPLIT_T, halved_t = kind != SPLIT_S;
        int ns = halved_s ? 6 : 3, nt = halved_t ? 6 : 3;
        unsigned nearest_count[3][3] = {{0}}, lattice = 0;
        for (int i = 0; i <= CHECK_SHARE_LATTICE; i++)
            for (int j = 0; j <= CHECK_SHARE_LATTICE; j++, lattice++) {
                double x = 2.0 * i / CHECK_SHARE_LATTICE - 1, y = 2.0 * j / CHECK_SHARE_LATTICE - 1;
                double best = INFINITY;
                int best_i = -1, best_j = -1;
                for (int a = 0; a < ns; a++)
                    for (int b = 0; b < nt; b++) {
                        double px = halved_s ? six[a] : three[a], py = halved_t ? six[b] : three[b];
                        double d = (px - x) * (px - x) + (py - y) * (py - y);
                        if (d < best)
                            best = d, best_i = best_j = -1;
                    }
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++) {
                        double px = a - 1.0, py = b - 1.0;
                        double d = (px - x) * (px - x) + (py - y) * (py - y);
                        if (d < best)
                            best = d, best_i = a, best_j = b;
                    }
                if (best_i >= 0)
                    nearest_count[best_i][best_j]++;
            }
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                check_share[kind][a][b] = CHECK_SHARE_MARGIN * nearest_count[a][b] / lattice;
    }
}

/*
 * The probes. However a cell is split, its rule points lie on a few lines across each
 * direction, and a band of light through a slit parallel to them (or a shadow as thin)
 * can fall between; rules can also agree by chance on a cell whose f they both miss.
 * Forcing splits before the rules are believed only narrows the gaps, at the price of
 * every cell of every pair (three each way cost the 1k city half its time). Instead,
 * PROBES points of a rank-1 lattice over the whole parallelogram, ((i + 1/2) / n,
 * ((i g mod n) + 1/2) / n) with n = 55 and g = 34 (Fibonacci numbers), take 55 distinct
 * values along either direction, 1/55 apart, so a band wider than that along either edge
 * holds one.
 *   - When a split's children are about to be accepted, f at the probes inside each is
 *     compared with the biquadratic through its 3 x 3 rule points, and the misses, each
 *     weighted by its probe's share of the whole (at most the cell's), count as error:
 *     above the tolerance, the children split on, and those with a miss above theirs are
 *     quartered. A miss is counted whole: allowing a part of the spread of the cell's rule
 *     values (which a kink inside a cell is missed by) left pairs of the 1k city with
 *     errors up to 20 times their bounds, against runs 1000 times finer (bench/README.md).
 *   - A probe beyond its cell's range by more than that range (an outlier) has found
 *     something no rule point saw. The cells around it split until their points see it
 *     too, but a band through it runs on along an edge's direction where no probe lies
 *     (a ridge across the square kept half its integral). So the integral is made again,
 *     with LINE_PROBES more probes along each of the outlier's two lines (s fixed, t from
 *     0 to 1, and t fixed), 1/64 apart: a band through the outlier along either edge holds
 *     them all. Each weighs its share of the strip of the cell it lies in (the cell's
 *     width across the line over LINE_PROBES): a band the rule points miss counts as if it
 *     filled its cells across, so they split until their points see it where it is lit,
 *     and nowhere else. A cell a line crosses is quartered rather than halved while it is
 *     wider than 1/32 both ways (holds_line): strips split to the deepest across one band
 *     could not resolve another crossing them (two crossing ridges lost 0.3 % of their
 *     integral with a bound of 5 %). (Before, every cell within 1/PROBES of the lines was
 *     quartered down to 1/32 whether f was smooth there or not: the 5 % of the 1k city's
 *     pairs with an outlier took a third of its time. Line probes weighing 1/PROBES of a
 *     strip instead, as if no band were wider than the lattice's spacing, left 10 more of
 *     its factors outside their bounds, by up to 3.4 times, against runs 100 times finer.)
 */
#define PROBES 55
#define PROBE_GENERATOR 34
_Static_assert(PROBES <= 64, "the probes are noted as bits of a uint64_t");
/* An outlier weighing more than this share of its cell's tolerance is followed. A probe
 * of the 1k city found light of 2e-3 of its cell's tolerance where every rule point read 0,
 * and the pair's whole transfer (4.4e-4, against a bound of 7e-5) lay beyond it. */
#define OUTLIER_SHARE 1e-4

static inline double probe_s(int i) { return (i + 0.5) / PROBES; }
static inline double probe_t(int i) { return (i * PROBE_GENERATOR % PROBES + 0.5) / PROBES; }

/* The 3-point Lagrange basis at the Gauss nodes, at x in [-1, 1]. */
static void lagrange3(double x, double l[3])
{
    const double g = gauss_node[2];
    l[0] = x * (x - g) / (2 * g * g);
    l[1] = 1 - x * x / (g * g);
    l[2] = x * (x + g) / (2 * g * g);
}

/* The biquadratic through the cell's 3 x 3 rule point values, at (s, t). */
static double biquadratic_at(cell k, const double *value, double s, double t)
{
    double ls[3], lt[3];
    lagrange3((2 * s - k.s0 - k.s1) / (k.s1 - k.s0), ls);
    lagrange3((2 * t - k.t0 - k.t1) / (k.t1 - k.t0), lt);
    double predicted = 0;
    for (int u = 0; u < 3; u++)
        for (int v = 0; v < 3; v++)
            predicted += ls[u] * lt[v] * value[3 * u + v];
    return predicted;
}

/* f at the probe (s, t), known or found (*known, NaN until then); the first probe f is
 * found at in a cell tells the callback that the cell's points are the next. */
static double probe_f(const frame *p, cell k, int level, int slot, int parent_slot, bool *told,
                      double *known, double s, double t)
{
    if (!isnan(*known))
        return *known;
    if (!*told) {
        if (p->c->select)
            p->c->select(p->c->context, level, slot);
        else
            enter(p, k, level, slot, parent_slot);
        *told = true;
    }
    return *known = f_at(p, s, t);
}

/* What f at the line probes in cell k misses the biquadratic through its rule points by,
 * each miss weighted by the probe's share of the strip of the cell along its line. */
static double line_probes_miss(const frame *p, cell k, const double *value, int level,
                               int slot, int parent_slot, bool *told)
{
    double sum = 0;
    int kept = 0;
    for (int i = 0; i < PROBES; i++) {
        if (!(p->lines >> i & 1))
            continue;
        double(*known)[LINE_PROBES] = kept < KEPT_LINES ? p->line_value[kept] : NULL;
        kept++;
        for (int along = 0; along < 2; along++) {
            /* along 0: the line s = probe_s(i), its probes spread over t; 1: t = probe_t(i) */
            double fixed = along == 0 ? probe_s(i) : probe_t(i);
            double fixed0 = along == 0 ? k.s0 : k.t0, fixed1 = along == 0 ? k.s1 : k.t1;
            double run0 = along == 0 ? k.t0 : k.s0, run1 = along == 0 ? k.t1 : k.s1;
            if (fixed < fixed0 || fixed >= fixed1)
                continue;
            double share = (fixed1 - fixed0) / LINE_PROBES;
            /* the probes with run in [run0, run1): m from ceil(run0 n - 1/2) */
            int first = (int)ceil(run0 * LINE_PROBES - 0.5);
            for (int m = first < 0 ? 0 : first; m < LINE_PROBES; m++) {
                double run = (m + 0.5) / LINE_PROBES;
                if (run >= run1)
                    break;
                if (run < run0)
                    continue;
                double s = along == 0 ? fixed : run, t = along == 0 ? run : fixed;
                double unkept = NAN;
                double f = probe_f(p, k, level, slot, parent_slot, told,
                                   known ? &known[along][m] : &unkept, s, t);
                sum += fabs(f - biquadratic_at(k, value, s, t)) * share;
            }
        }
    }
    return sum;
}

/* What f at the probes in cell k (told at (level, slot), a child of the one at slot
 * parent_slot a level up) misses the biquadratic through its rule points by, each miss
 * weighted by the probe's share of the whole (at most the cell's): an estimate of the
 * integral of that miss over the cell, 0 when no probe lies in it. A probe whose f lies
 * beyond the range of the rule points' values by more than that range, weighing more than
 * OUTLIER_SHARE of `tolerance`, is noted in *p->outliers. */
static double probe_miss(const frame *p, cell k, const double *value, int level, int slot,
                         int parent_slot, double tolerance)
{
    const double share = fmin(1.0 / PROBES, (k.s1 - k.s0) * (k.t1 - k.t0));
    double lo = value[0], hi = value[0];
    for (int v = 1; v < 9; v++) {
        lo = fmin(lo, value[v]);
        hi = fmax(hi, value[v]);
    }
    /* the probes with s in [s0, s1): i from ceil(s0 n - 1/2) to ceil(s1 n - 1/2) - 1 */
    int first = (int)ceil(k.s0 * PROBES - 0.5), last = (int)ceil(k.s1 * PROBES - 0.5);
    bool told = false;
    double sum = 0;
    for (int i = first < 0 ? 0 : first; i < last && i < PROBES; i++) {
        double s = probe_s(i), t = probe_t(i);
        if (s < k.s0 || s >= k.s1 || t < k.t0 || t >= k.t1)
            continue;
        double f = probe_f(p, k, level, slot, parent_slot, &told, &p->probe_value[i], s, t);
        sum += fabs(f - biquadratic_at(k, value, s, t)) * share;
        double beyond = fmax(f - hi, lo - f) - (hi - lo);
        if (p->outliers && beyond * share * p->jacobian > OUTLIER_SHARE * tolerance)
            *p->outliers |= (uint64_t)1 << i;
    }
    if (p->lines)
        sum += line_probes_miss(p, k, value, level, slot, parent_slot, &told);
    return sum * p->jacobian;
}

/* Whether one of the outliers' lines (p->lines) crosses cell k, wider than QUARTER_WIDTH
 * both ways. Such a cell is quartered when it splits, not halved into strips: a strip
 * across a band along the line, split to the deepest one way, could not split the other
 * way to resolve a band it crosses. Below that width strips may follow a band along the
 * line (quartered all the way down, a floor lit through a slit lost a quarter of its
 * light with a bound of 4 %). */
#define QUARTER_WIDTH (1.0 / 32)

static bool holds_line(const frame *p, cell k)
{
    if (!p->lines || !(k.s1 - k.s0 > QUARTER_WIDTH && k.t1 - k.t0 > QUARTER_WIDTH))
        return false;
    for (int i = 0; i < PROBES; i++)
        if (p->lines >> i & 1) {
            double s = probe_s(i), t = probe_t(i);
            if ((s >= k.s0 && s < k.s1) || (t >= k.t0 && t < k.t1))
                return true;
        }
    return false;
}

/* The miss of the children's prediction at the 3 x 3 check points (at[i][j]: f at s = i -
 * 1, t = j - 1 of the cell), as a share of the cell's integral's scale: sum of share times
 * |f - predicted|. */
static double check_miss(int kind, const double *part_value, double at[3][3],
                         double miss_at[3][3])
{
    bool halved_s = kind != SPLIT_T, halved_t = kind != SPLIT_S;
    int ns = halved_s ? 6 : 3, nt = halved_t ? 6 : 3;
    double grid[6][6];
    for (int a = 0; a < ns; a++)
        for (int b = 0; b < nt; b++) {
            int child;
            if (kind == SPLIT_BOTH)
                child = a < 3 ? (b < 3 ? 0 : 3) : (b < 3 ? 1 : 2);
            else if (kind == SPLIT_S)
                child = a < 3 ? 0 : 1;
            else
                child = b < 3 ? 0 : 1;
            grid[a][b] = part_value[9 * child + 3 * (a % 3) + b % 3];
        }
    double miss = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            miss_at[i][j] = 0;
            /* a strip checks its centre line across the cut only: f at the other check
             * points would be extrapolated from 3 nodes along the direction it was not cut
             * in, a quadratic that misses a smooth cubic there */
            if ((kind == SPLIT_S && j != 1) || (kind == SPLIT_T && i != 1))
                continue;
            double predicted = 0;
            for (int a = 0; a < ns; a++) {
                double ws = halved_s ? predict6[i][a] : (a == 1);
                for (int b = 0; b < nt; b++) {
                    double wt = halved_t ? predict6[j][b] : (b == 1);
                    predicted += ws * wt * grid[a][b];
                }
            }
            miss_at[i][j] = check_share[kind][i][j] * fabs(at[i][j] - predicted);
            miss += miss_at[i][j];
        }
    return miss;
}

/* Each child's corners as check points of its parent (i along s, j along t), in the order
 * (s0, t0), (s1, t0), (s1, t1), (s0, t1), per kind of split. */
static const int child_check[SPLIT_KINDS][4][4][2] = {
    [SPLIT_BOTH] = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}},
                    {{1, 0}, {2, 0}, {2, 1}, {1, 1}},
                    {{1, 1}, {2, 1}, {2, 2}, {1, 2}},
                    {{0, 1}, {1, 1}, {1, 2}, {0, 2}}},
    [SPLIT_S] = {{{0, 0}, {1, 0}, {1, 2}, {0, 2}}, {{1, 0}, {2, 0}, {2, 2}, {1, 2}}},
    [SPLIT_T] = {{{0, 0}, {2, 0}, {2, 1}, {0, 1}}, {{0, 1}, {2, 1}, {2, 2}, {0, 2}}},
};

/* Integral over cell k, child `slot` at level - 1 (of the one with `parent_slot` a level
 * up), whose rule9 value is `whole` with its points' values `value`; *error accumulates
 * the estimated error of what is returned. corner[4]: f at the cell's corners when the
 * edge check is on there. */
static double adapt(const frame *p, cell k, double whole, const double *value, double tolerance,
                    int level, int slot, int parent_slot, int splits_s, int splits_t,
                    bool smooth, bool quarter, const double *corner, double *error)
{
    const parallelogram_integral *c = p->c;
    bool check = c->edge_check && !smooth;
    bool need_s = !smooth && splits_s < c->min_splits;
    bool need_t = !smooth && splits_t < c->min_splits;
    bool can_s = splits_s < c->max_splits, can_t = splits_t < c->max_splits;
    double sm = 0.5 * (k.s0 + k.s1), tm = 0.5 * (k.t0 + k.t1);
    bool forced = need_s || need_t;
    double at[3][3] = {{0}};
    if (check || !forced) {
        /* the cell's edge midpoints: its points are the next, and the callback last told
         * of a child of it */
        if (c->select)
            c->select(c->context, level - 1, slot);
        else if (c->cell)
            enter(p, k, level - 1, slot, parent_slot);
        at[0][1] = f_at(p, k.s0, tm);
        at[2][1] = f_at(p, k.s1, tm);
        at[1][0] = f_at(p, sm, k.t0);
        at[1][2] = f_at(p, sm, k.t1);
        at[1][1] = value[4];
        if (check) {
            at[0][0] = corner[0];
            at[2][0] = corner[1];
            at[2][2] = corner[2];
            at[0][2] = corner[3];
        }
    }
    bool split_s, split_t;
    if (forced) {
        split_s = need_s || (can_s && !need_t);
        split_t = need_t || (can_t && !need_s);
    } else if (quarter || holds_line(p, k)) {
        split_s = can_s;
        split_t = can_t;
    } else {
        double along_s = fourth_difference(at[0][1], value[1], value[4], value[7], at[2][1]);
        double along_t = fourth_difference(at[1][0], value[3], value[4], value[5], at[1][2]);
        /* both at rounding level (f linear at every point the cell has): their ratio is
         * noise, and strips chosen by it put every rule line of a cell beside a band that
         * a quarter split found in its mirror image (half a band lost, at a tenth of the
         * bound) */
        double scale = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                scale = fmax(scale, fabs(at[i][j]));
        for (int v = 0; v < 9; v++)
            scale = fmax(scale, fabs(value[v]));
        bool flat = along_s <= FLAT_DIFFERENCE * scale && along_t <= FLAT_DIFFERENCE * scale;
        split_s = can_s && (flat || !(along_t > STRIP_RATIO * along_s && can_t));
        split_t = can_t && (flat || !(along_s > STRIP_RATIO * along_t && can_s));
    }
    cell child[4];
    int children = 0, kind = SPLIT_BOTH;
    if (split_s && split_t) {
        child[0] = (cell){k.s0, sm, k.t0, tm};
        child[1] = (cell){sm, k.s1, k.t0, tm};
        child[2] = (cell){sm, k.s1, tm, k.t1};
        child[3] = (cell){k.s0, sm, tm, k.t1};
        children = 4;
    } else if (split_s) {
        child[0] = (cell){k.s0, sm, k.t0, k.t1};
        child[1] = (cell){sm, k.s1, k.t0, k.t1};
        children = 2;
        kind = SPLIT_S;
    } else if (split_t) {
        child[0] = (cell){k.s0, k.s1, k.t0, tm};
        child[1] = (cell){k.s0, k.s1, tm, k.t1};
        children = 2;
        kind = SPLIT_T;
    }
    if (children == 0)
        return whole; /* max_splits 0: the first rule alone, with no estimate of its error
                         (a cell split to the deepest either way stops below, with one) */
    double part[4], part_value[4][9];
    bool part_smooth[4];
    for (int m = 0; m < children; m++) {
        part_smooth[m] = enter(p, child[m], level, m, slot);
        part[m] = rule9(p, child[m], part_value[m]);
    }
    double sum = 0;
    for (int m = 0; m < children; m++)
        sum += part[m];
    double rules = fabs(sum - whole), difference = rules, miss_at[3][3] = {{0}};
    double area = p->jacobian * (k.s1 - k.s0) * (k.t1 - k.t0);
    if (check)
        difference = fmax(difference, check_miss(kind, &part_value[0][0], at, miss_at) * area);
    int child_s = splits_s + split_s, child_t = splits_t + split_t;
    /* split to the deepest in either direction: splitting the other way could not see
     * what is left unresolved across this one (halves along a kink agree on it) */
    bool deepest = child_s >= c->max_splits || child_t >= c->max_splits;
    bool settled = smooth || (child_s >= c->min_splits && child_t >= c->min_splits);
    bool last_level = deepest || level + 1 >= PARALLELOGRAM_MAX_LEVELS;
    double probed[4] = {0, 0, 0, 0};
    if (c->probes && !smooth && ((difference <= tolerance && settled) || last_level)) {
        /* about to be accepted: the probes in each child must follow its rule points (at
         * the last level too: what they miss there counts in the bound, and an outlier
         * still starts the second pass) */
        double misses = 0;
        for (int m = 0; m < children && misses <= tolerance && !stopped(p); m++)
            if (!part_smooth[m]) {
                probed[m] = probe_miss(p, child[m], part_value[m], level, m, slot, tolerance);
                misses += probed[m];
            }
        difference = fmax(difference, misses);
    }
    if ((difference <= tolerance && settled) || last_level || stopped(p)) {
        *error += difference;
        return sum;
    }
    /* the tolerance shrinks with the square root of the area, as polygon_integral's */
    double t = tolerance * (children == 4 ? 0.5 : 0.70710678118654752), total = 0;
    for (int m = 0; m < children; m++) {
        double child_corner[4];
        /* a miss at a corner of the child, above its tolerance and above what the rules
         * disagree on, is something no rule point sees there (a kink the rules see misses
         * at the points along it too, and strips follow it): the child is quartered, for a
         * strip would check its centre line only and lose it */
        bool missed = false;
        if (check)
            for (int v = 0; v < 4; v++) {
                int i = child_check[kind][m][v][0], j = child_check[kind][m][v][1];
                child_corner[v] = at[i][j];
                missed = missed || miss_at[i][j] * area > fmax(t, rules);
            }
        /* what a probe saw and the rule points did not: quartered */
        missed = missed || probed[m] > t;
        total += adapt(p, child[m], part[m], part_value[m], t, level + 1, m, slot, child_s,
                       child_t, part_smooth[m], missed, check ? child_corner : NULL, error);
    }
    return total;
}

bool parallelogram_of(const rad_vec3 *polygon, unsigned count, rad_vec3 *origin, rad_vec3 *a,
                      rad_vec3 *b)
{
    if (count != 4)
        return false;
    *origin = polygon[0];
    *a = v3_sub(polygon[1], polygon[0]);
    *b = v3_sub(polygon[3], polygon[0]);
    rad_vec3 opposite = v3_sub(polygon[2], v3_add(polygon[0], v3_add(*a, *b)));
    double extent = fmax(v3_length(*a), v3_length(*b));
    return extent > 0 && v3_length(opposite) <= 1e-9 * extent;
}

double parallelogram_integrate_within(const parallelogram_integral *integral, rad_vec3 origin,
                                      rad_vec3 a, rad_vec3 b, double accuracy,
                                      double absolute, double *bound)
{
    uint64_t outliers = 0;
    double probe_values[PROBES], line_values[KEPT_LINES][2][LINE_PROBES];
    for (int i = 0; i < PROBES; i++)
        probe_values[i] = NAN;
    frame p = {integral, origin, a, b, v3_length(v3_cross(a, b)), 0, NULL, probe_values,
               line_values};
    cell whole_cell = {0, 1, 0, 1};
    double value[9], error = 0;
    bool smooth = enter(&p, whole_cell, 0, 0, 0);
    double whole = rule9(&p, whole_cell, value);
    double tolerance = fmax(fmax(accuracy * fabs(whole), absolute), 1e-15 * p.jacobian);
    double corner[4];
    bool check = integral->edge_check && !smooth;
    if (check) {
        pthread_once(&check_once, check_compute);
        corner[0] = f_at(&p, 0, 0);
        corner[1] = f_at(&p, 1, 0);
        corner[2] = f_at(&p, 1, 1);
        corner[3] = f_at(&p, 0, 1);
    }
    if (integral->probes && !smooth)
        p.outliers = &outliers;
    double result = adapt(&p, whole_cell, whole, value, tolerance, 1, 0, 0, 0, 0, smooth,
                          false, check ? corner : NULL, &error);
    if (outliers && !stopped(&p)) {
        /* a feature the rule points did not see, where an outlier found it, may reach along
         * either edge's direction beyond the cells that followed it: again, with probes
         * along the outliers' lines */
        for (int line = 0; line < KEPT_LINES; line++)
            for (int m = 0; m < LINE_PROBES; m++)
                line_values[line][0][m] = line_values[line][1][m] = NAN;
        p.lines = outliers;
        p.outliers = NULL;
        error = 0;
        result = adapt(&p, whole_cell, whole, value, tolerance, 1, 0, 0, 0, 0, smooth, false,
                       check ? corner : NULL, &error);
    }
    *bound = error;
    return result;
}
