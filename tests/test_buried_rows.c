/*
 * test_buried_rows.c - the form factors of floor patches that run under a block, against
 * a brute-force Monte-Carlo count of what their open part sees.
 *
 * The built-in Cornell box on the default mesh: a floor patch that a block's corner
 * covers in part takes its open part's area, and its row is what that open part sees
 * (mesh/exposed_area.h). The red wall is a folded quad (its corners are 3 mm off one
 * plane), so its patches have no exact polygon and their pairs are sampled from the
 * start; before 2026-12-06 such a pair with a partly buried patch kept a first pass of
 * four segments, and four that all landed on the open part took the whole patch's
 * transfer over the open part's area: a floor patch by the tall block's corner saw the
 * red wall 5.6 % too much and its row summed to 1.014.
 *
 * Checked here, with 64 segments a pair (the rows' own sampling noise small beside what
 * is looked for):
 *   - no row of the open box sums above 1 (before trimming) by more than the rows'
 *     sampling noise, 0.5 %, and none is trimmed (1.0147 before);
 *   - for every floor patch at least OPEN_CHECKED open, what its row gives each surface
 *     (the sum of F_ij over the surface's patches) against the share of cosine-distributed
 *     rays from uniform points of its open part that first meet that surface, found by
 *     testing every scene triangle (an independent path: no tracer, no patches): within
 *     4 sigma of the count and 3 % of the share. Measured when it was written: 64 such
 *     patches, the largest difference 0.62 of its allowance, a surface's share 0.9 % low
 *     on average for the block a patch runs under and 0.55 % for the rest; the patch by
 *     the tall block's corner saw the red wall 5.6 % too much before.
 * Patches mostly buried are a known limit (docs/DESIGN.md, "Buried parts"), counted here,
 * not checked: every surface's share reads low, a tenth open by 3-5 %, a fiftieth open by
 * up to 67 % (the block it runs under).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/random.h"
#include "core/vec3.h"
#include "testlib.h"

#define PI 3.14159265358979323846
#define POINTS 60000u      /* Monte-Carlo rays per patch */
#define OPEN_CHECKED 0.3   /* the patches checked: at least this share open */

/* The nearest scene triangle the ray meets past 1e-6 (test_ray_triangle, either side),
 * or UINT32_MAX. */
static uint32_t first_hit(const rad_scene *scene, rad_vec3 o, rad_vec3 d)
{
    double best = INFINITY;
    uint32_t hit = UINT32_MAX;
    for (uint32_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *v = scene->triangles[t].vertex;
        double t_hit = test_ray_triangle(o, d, scene->positions[v[0]], scene->positions[v[1]],
                                         scene->positions[v[2]], NULL, NULL);
        if (t_hit > 1e-6 && t_hit < best) {
            best = t_hit;
            hit = t;
        }
    }
    return hit;
}

static uint32_t surface_of_triangle(const rad_scene *scene, uint32_t t)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (t >= scene->surfaces[s].first_triangle &&
            t < scene->surfaces[s].first_triangle + scene->surfaces[s].triangle_count)
            return s;
    return UINT32_MAX;
}

int main(void)
{
    rad_error error;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_tracer *tracer = NULL;
    rad_formfactors *ff = NULL;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    CHECK(rad_mesh_build(scene, rad_default_patch_size(scene, RAD_SOLVER_AUTO), &mesh, &error) ==
          RAD_OK);
    CHECK(rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK);
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error) == RAD_OK);
    rad_formfactor_options options = {.seed = 1, .area = inputs->area, .visibility_rays = 64};
    rad_formfactor_report report;
    CHECK(rad_formfactors_compute(mesh, tracer, &options, &ff, &report, &error) == RAD_OK);
    const uint32_t n = mesh->patch_count, surfaces = scene->surface_count;
    printf("%u patches; largest row %.5f before trimming, %u trimmed\n", n,
           report.largest_row_sum, report.rows_trimmed);
    CHECK(report.largest_row_sum <= 1.005);
    CHECK(report.rows_trimmed == 0);

    uint32_t floor = UINT32_MAX;
    for (uint32_t s = 0; s < surfaces; s++)
        if (strcmp(scene->surfaces[s].name, "floor") == 0)
            floor = s;
    CHECK(floor != UINT32_MAX);
    double *by_surface = calloc(surfaces, sizeof(*by_surface));
    uint32_t *met = calloc(surfaces, sizeof(*met));
    CHECK(by_surface && met);
    uint32_t tested = 0, mostly_buried = 0;
    double worst = 0;
    rad_rng rng = rad_rng_seed(23, 0, 0);
    for (uint32_t i = 0; by_surface && met && i < n; i++) {
        const rad_patch *p = &mesh->patches[i];
        const double open = inputs->area[i] / p->area;
        if (p->surface != floor || p->vertex_count != 4 || !(open < 1 - 1e-9))
            continue;
        if (!(open >= OPEN_CHECKED)) {
            mostly_buried++;
            continue;
        }
        tested++;
        memset(by_surface, 0, surfaces * sizeof(*by_surface));
        memset(met, 0, surfaces * sizeof(*met));
        for (uint32_t j = 0; j < n; j++)
            by_surface[mesh->patches[j].surface] += ff->F[(size_t)i * n + j];
        /* uniform points of the patch's quad (its bilinear map, area-weighted by
         * rejection against the largest Jacobian), those under a block left out: a ray
         * straight up from them meets a block's top from below */
        rad_vec3 c[4];
        for (int k = 0; k < 4; k++)
            c[k] = mesh->vertices[p->vertex[k]];
        rad_vec3 normal = p->normal, a, b;
        a = fabs(normal.x) < 0.9 ? (rad_vec3){1, 0, 0} : (rad_vec3){0, 1, 0};
        a = v3_cross(normal, a);
        double la = sqrt(v3_dot(a, a));
        a = (rad_vec3){a.x / la, a.y / la, a.z / la};
        b = v3_cross(normal, a);
        double jacobian_most = 0;
        for (int k = 0; k < 4; k++) {
            rad_vec3 e1 = v3_sub(c[(k + 1) % 4], c[k]), e2 = v3_sub(c[(k + 3) % 4], c[k]);
            rad_vec3 x = v3_cross(e1, e2);
            jacobian_most = fmax(jacobian_most, sqrt(v3_dot(x, x)));
        }
        uint32_t rays = 0;
        while (rays < POINTS) {
            double s = rad_rng_uniform(&rng), t = rad_rng_uniform(&rng);
            rad_vec3 ds = {(1 - t) * (c[1].x - c[0].x) + t * (c[2].x - c[3].x),
                           (1 - t) * (c[1].y - c[0].y) + t * (c[2].y - c[3].y),
                           (1 - t) * (c[1].z - c[0].z) + t * (c[2].z - c[3].z)};
            rad_vec3 dt = {(1 - s) * (c[3].x - c[0].x) + s * (c[2].x - c[1].x),
                           (1 - s) * (c[3].y - c[0].y) + s * (c[2].y - c[1].y),
                           (1 - s) * (c[3].z - c[0].z) + s * (c[2].z - c[1].z)};
            rad_vec3 jx = v3_cross(ds, dt);
            if (rad_rng_uniform(&rng) * jacobian_most > sqrt(v3_dot(jx, jx)))
                continue;
            double w0 = (1 - s) * (1 - t), w1 = s * (1 - t), w2 = s * t, w3 = (1 - s) * t;
            rad_vec3 x = {w0 * c[0].x + w1 * c[1].x + w2 * c[2].x + w3 * c[3].x,
                          w0 * c[0].y + w1 * c[1].y + w2 * c[2].y + w3 * c[3].y,
                          w0 * c[0].z + w1 * c[1].z + w2 * c[2].z + w3 * c[3].z};
            uint32_t up = first_hit(scene, x, normal);
            if (up != UINT32_MAX) {
                const uint32_t *v = scene->triangles[up].vertex;
                rad_vec3 face = v3_cross(v3_sub(scene->positions[v[1]], scene->positions[v[0]]),
                                      v3_sub(scene->positions[v[2]], scene->positions[v[0]]));
                if (v3_dot(face, normal) > 0) /* met from behind: inside a block */
                    continue;
            }
            double u1 = rad_rng_uniform(&rng), u2 = rad_rng_uniform(&rng);
            double r = sqrt(u1), phi = 2 * PI * u2, h = sqrt(1 - u1);
            rad_vec3 d = {h * normal.x + r * (cos(phi) * a.x + sin(phi) * b.x),
                          h * normal.y + r * (cos(phi) * a.y + sin(phi) * b.y),
                          h * normal.z + r * (cos(phi) * a.z + sin(phi) * b.z)};
            uint32_t hit = first_hit(scene, x, d);
            if (hit != UINT32_MAX)
                met[surface_of_triangle(scene, hit)]++;
            rays++;
        }
        /* each surface's share: the count's noise (4 sigma) and the row's own sampled
         * visibility (9 segments a pair) */
        for (uint32_t s = 0; s < surfaces; s++) {
            double share = (double)met[s] / POINTS;
            double sigma = sqrt(fmax(share * (1 - share), 1.0 / POINTS) / POINTS);
            double off = fabs(by_surface[s] - share);
            double allowed = 4 * sigma + 0.03 * share;
            worst = fmax(worst, off / allowed);
            if (off > allowed || share > 0.05)
                printf("patch %u (open %.3f) sees '%s': row %.5f, count %.5f +- %.5f\n", i,
                       open, scene->surfaces[s].name, by_surface[s], share, sigma);
            CHECK(off <= allowed);
        }
    }
    printf("%u floor patches at least %.2f open checked, the largest difference %.2f of its "
           "allowance; %u less open not checked\n",
           tested, OPEN_CHECKED, worst, mostly_buried);
    CHECK(tested >= 8);
    free(by_surface);
    free(met);
    rad_formfactors_destroy(ff);
    rad_tracer_destroy(tracer);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return test_finish("test_buried_rows");
}
