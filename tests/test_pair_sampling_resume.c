/*
 * test_pair_sampling_resume.c - a sampled pair that resumes its first look's rounds
 * (pair_sample_visibility_resume, src/surface_viewfactors/pair_transfer.c) comes out as a
 * fresh pair_sample_visibility with the same arguments: the same fraction, bound and flags,
 * bit for bit, with the first look's segments not cast again; after a call for another pair
 * or stream it is a fresh run. Two unit squares 2 apart with a 5 x 5 grid of small squares
 * half way, at several targets and budgets. Not here: whether the sampled fraction is
 * right (test_viewfactor_obstructed holds it to Monte Carlo and closed forms).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "surface_viewfactors/pair_transfer.h"
#include "surface_viewfactors/vf_geometry.h"
#include "testlib.h"

static char text[1 << 16];
static size_t used;
static int vertices;

static void quad(const char *name, const double c[4][3])
{
    used += (size_t)snprintf(text + used, sizeof(text) - used, "o %s\n", name);
    for (int k = 0; k < 4; k++)
        used += (size_t)snprintf(text + used, sizeof(text) - used, "v %.17g %.17g %.17g\n",
                                 c[k][0], c[k][1], c[k][2]);
    used += (size_t)snprintf(text + used, sizeof(text) - used, "f %d %d %d %d\n", vertices + 1,
                             vertices + 2, vertices + 3, vertices + 4);
    vertices += 4;
}

static bool same(const pair_visibility *a, const pair_visibility *b)
{
    return a->fraction == b->fraction && a->bound == b->bound && a->capped == b->capped &&
           a->unseen == b->unseen;
}

int main(void)
{
    const double p[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const double q[4][3] = {{0, 0, 2}, {0, 1, 2}, {1, 1, 2}, {1, 0, 2}};
    quad("p", p);
    quad("q", q);
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++) {
            double x = 0.05 + 0.2 * i, y = 0.05 + 0.2 * j;
            const double o[4][3] = {{x, y, 1}, {x + 0.1, y, 1}, {x + 0.1, y + 0.1, 1},
                                    {x, y + 0.1, 1}};
            char name[32];
            snprintf(name, sizeof(name), "o%d_%d", i, j);
            quad(name, o);
        }
    rad_error error = {0};
    rad_scene *scene = NULL;
    vf_geometry g;
    rad_tracer *tracer = NULL;
    pair_workspace w;
    memset(&g, 0, sizeof(g));
    bool ok = rad_scene_load(test_write_file("grid.obj", text), NULL, &scene, &error) == RAD_OK &&
              vf_geometry_build(scene, &g, &error) == RAD_OK &&
              rad_tracer_create_for_scene(RAD_TRACER_EMBREE_FAST, scene, &tracer, &error) ==
                  RAD_OK &&
              pair_workspace_init(&w, 1024);
    CHECK(ok);
    if (!ok) {
        printf("%s\n", error.message);
        return test_finish("test_pair_sampling_resume");
    }
    const vf_polygon *pp = &g.polygons[g.surfaces[0].first_polygon];
    const vf_polygon *qq = &g.polygons[g.surfaces[1].first_polygon];
    const double targets[] = {0.5, 0.05, 0.01, 1e-3, 1e-5};
    const uint32_t budgets[] = {64, 200, 1024};
    uint32_t saved = 0, cases = 0;
    for (unsigned t = 0; t < sizeof(targets) / sizeof(*targets); t++)
        for (unsigned b = 0; b < sizeof(budgets) / sizeof(*budgets); b++)
            for (uint64_t stream = 1; stream <= 3; stream++) {
                pair_visibility fresh, look, resumed, again;
                pair_sample_visibility(pp, qq, tracer, targets[t], budgets[b], stream, &w,
                                       &fresh);
                pair_sample_visibility(pp, qq, tracer, INFINITY, budgets[b], stream, &w, &look);
                pair_sample_visibility_resume(pp, qq, tracer, targets[t], budgets[b], stream, &w,
                                              &resumed);
                CHECK(same(&fresh, &resumed));
                /* what the first look cast is not cast again, and nothing else is skipped */
                CHECK(resumed.rays <= fresh.rays && resumed.rays + look.rays >= fresh.rays);
                saved += fresh.rays - resumed.rays;
                /* after another stream's call, a fresh run */
                pair_sample_visibility(pp, qq, tracer, INFINITY, budgets[b], stream + 100, &w,
                                       &look);
                pair_sample_visibility_resume(pp, qq, tracer, targets[t], budgets[b], stream, &w,
                                              &again);
                CHECK(same(&fresh, &again) && again.rays == fresh.rays);
                cases++;
                if (t == 2 && b == 2 && stream == 1)
                    printf("target %g, %u rays at most: fraction %.6f, bound %.4f, %u rays "
                           "fresh, %u resumed\n",
                           targets[t], budgets[b], fresh.fraction, fresh.bound, fresh.rays,
                           resumed.rays);
            }
    printf("%u cases: resumed runs cast %u fewer segments in all\n", cases, saved);
    /* the first look's rounds were taken, not only compared */
    CHECK(saved > 0);
    pair_workspace_free(&w);
    rad_tracer_destroy(tracer);
    vf_geometry_free(&g);
    rad_scene_destroy(scene);
    return test_finish("test_pair_sampling_resume");
}
