/*
 * test_seen_pairs.c - the sight rays that find which surface pairs see each other at all
 * (seen_pairs.h), against closed forms and against every pair integrated:
 * - a unit square under a coaxial one 10 above (F 3.2e-3: 96 rays of 29958 expected to
 *   meet it) is met and integrated exactly (Howell's parallel rectangles);
 * - 40 plates 0.1 wide, 80 above, spread out (F from the square 1e-7 to 5e-7, from the
 *   plate 1e-5 to 5e-5, so that a few rays of either side are expected to meet it): each
 *   either met and integrated to what `sight_rays = NONE` (every pair integrated, checked
 *   against closed forms in test_viewfactors.c) gives, or not stored and then within the
 *   stated bound 3 / (N / A_I + N / A_J) of it; some of each, so both paths are taken;
 * - what the unmet plates hold of the square's row is within the largest row's reported
 *   estimate (Good and Turing's) plus its own error;
 * - a plate hidden behind a wall is unmet, with no first look or proof;
 * - the result is the same, bit for bit, for 1 and 2 threads.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "closed_forms.h"
#include "testlib.h"

#define PLATES 40

static void write_scene(test_obj *t, bool wall)
{
    test_obj_object(t, "square", NULL);
    test_obj_rectangle(t, 1, 0, 0, 0, 1, 1, 1); /* y = 0, facing +y, z and x in [0, 1] */
    test_obj_object(t, "near", NULL);
    test_obj_rectangle(t, 1, 10, 0, 0, 1, 1, -1);
    uint64_t state = 0x9e3779b97f4a7c15ull;
    for (int k = 0; k < PLATES; k++) {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        double u = (double)(state >> 11) / 9007199254740992.0;
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        double v = (double)(state >> 11) / 9007199254740992.0;
        double z = -40 + 80 * u, x = -40 + 80 * v;
        char name[32];
        snprintf(name, sizeof(name), "plate%d", k);
        test_obj_object(t, name, NULL);
        test_obj_rectangle(t, 1, 80, z, x, z + 0.1, x + 0.1, -1);
    }
    if (wall) {
        /* a plate under a roof: the square cannot see it */
        test_obj_object(t, "roof", NULL);
        test_obj_rectangle(t, 1, 3, 10, 10, 30, 30, 1);
        test_obj_object(t, "hidden", NULL);
        test_obj_rectangle(t, 1, 5, 20, 20, 21, 21, -1);
    }
}

static uint32_t surface_named(const rad_scene *scene, const char *name)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, name) == 0)
            return s;
    return UINT32_MAX;
}

static double factor(const rad_viewfactor_matrix *m, uint32_t I, uint32_t J, double *bound,
                     bool *stored)
{
    *bound = 0;
    *stored = false;
    for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
        if (m->column[k] == J) {
            *bound = m->error_bound[k];
            *stored = true;
            return m->value[k];
        }
    return 0;
}

static bool same_matrix(const rad_viewfactor_matrix *a, const rad_viewfactor_matrix *b)
{
    if (a->n != b->n || a->row_start[a->n] != b->row_start[b->n])
        return false;
    uint64_t count = a->row_start[a->n];
    return memcmp(a->row_start, b->row_start, (a->n + 1) * sizeof(uint64_t)) == 0 &&
           memcmp(a->column, b->column, count * sizeof(uint32_t)) == 0 &&
           memcmp(a->value, b->value, count * sizeof(double)) == 0 &&
           memcmp(a->error_bound, b->error_bound, count * sizeof(double)) == 0;
}

int main(void)
{
    test_obj t = {0};
    write_scene(&t, true);
    const char *path = test_write_file("plates.obj", t.data);
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (!scene)
        return test_finish("test_seen_pairs");
    rad_viewfactor_matrix *sight = NULL, *sight_one = NULL, *every = NULL;
    rad_viewfactor_report report, report_one, report_every;
    rad_viewfactor_options options = {.threads = 2};
    CHECK(rad_viewfactor_matrix_compute(scene, &options, &sight, &report, &error) == RAD_OK);
    options.threads = 1;
    CHECK(rad_viewfactor_matrix_compute(scene, &options, &sight_one, &report_one, &error) ==
          RAD_OK);
    options = (rad_viewfactor_options){.threads = 2, .sight_rays = RAD_SIGHT_RAYS_NONE};
    CHECK(rad_viewfactor_matrix_compute(scene, &options, &every, &report_every, &error) ==
          RAD_OK);
    if (!sight || !sight_one || !every) {
        rad_viewfactor_matrix_destroy(sight);
        rad_viewfactor_matrix_destroy(sight_one);
        rad_viewfactor_matrix_destroy(every);
        rad_scene_destroy(scene);
        return test_finish("test_seen_pairs");
    }
    CHECK(same_matrix(sight, sight_one));
    CHECK(report.sight_rays == 29958); /* ceil(-ln 0.05 / 1e-4) */
    CHECK(fabs(report.unmet_bound - 1e-4) < 1e-8);
    CHECK(report_every.sight_rays == 0 && report_every.unmet_pairs == 0);

    uint32_t square = surface_named(scene, "square"), near = surface_named(scene, "near");
    double bound, F;
    bool stored;
    F = factor(sight, square, near, &bound, &stored);
    double expected = parallel_rectangles(1, 1, 10);
    printf("square -> near: F %.9f bound %.2g, closed form %.9f\n", F, bound, expected);
    CHECK(stored && fabs(F - expected) <= 1e-4 * expected + bound);

    uint32_t met = 0, unmet = 0, outside = 0;
    double lost = 0, largest_unmet = 0;
    for (int k = 0; k < PLATES; k++) {
        char name[32];
        snprintf(name, sizeof(name), "plate%d", k);
        uint32_t plate = surface_named(scene, name);
        double every_bound;
        bool every_stored;
        double reference = factor(every, square, plate, &every_bound, &every_stored);
        F = factor(sight, square, plate, &bound, &stored);
        double a_i = sight->area[square], a_j = sight->area[plate];
        double unmet_bound =
            2.995732 / (report.sight_rays / a_i + report.sight_rays / a_j) / a_i;
        if (stored) {
            met++;
            /* integrated as without sight rays: the same value */
            outside += fabs(F - reference) > 1e-12 + 1e-9 * reference;
        } else {
            unmet++;
            lost += reference;
            largest_unmet = fmax(largest_unmet, reference);
            outside += reference > unmet_bound;
        }
    }
    printf("plates: %u met, %u unmet (largest F %.3g, bound %.3g), %u outside; the square's "
           "row lost %.3g (largest row estimate %.3g, mean %.3g)\n",
           met, unmet, largest_unmet, report.unmet_bound, outside, lost,
           report.missed_largest, report.missed_mean);
    CHECK(met > 0 && unmet > 0 && outside == 0);
    /* what the row lost is about the estimate (the surfaces met once over the rays), which
     * counts the square's rays only; the plates' own rays meet some of the rest */
    CHECK(lost <= report.missed_largest + 3 * sqrt(report.missed_largest / report.sight_rays));

    uint32_t hidden = surface_named(scene, "hidden");
    F = factor(sight, square, hidden, &bound, &stored);
    CHECK(!stored && F == 0);
    F = factor(every, square, hidden, &bound, &stored);
    CHECK(F == 0);
    printf("pairs: %llu unmet, %llu polygon pairs integrated (every pair: %llu, %llu proven "
           "hidden)\n",
           (unsigned long long)report.unmet_pairs, (unsigned long long)report.polygon_pairs,
           (unsigned long long)report_every.polygon_pairs,
           (unsigned long long)report_every.hidden_pairs);
    CHECK(report.hidden_pairs == 0 && report_every.hidden_pairs > 0);
    CHECK(report.unmet_pairs > 0 && report.polygon_pairs < report_every.polygon_pairs);

    rad_viewfactor_matrix_destroy(sight);
    rad_viewfactor_matrix_destroy(sight_one);
    rad_viewfactor_matrix_destroy(every);
    rad_scene_destroy(scene);
    free(t.data);
    return test_finish("test_seen_pairs");
}
