/*
 * test_pipeline.c - the library stages on the built-in Cornell box, checked against
 * independent references:
 *   - mesh: patch areas add up to the scene's area, no edge longer than the patch size,
 *     quads recovered from triangle pairs, vertices shared inside a region only; the
 *     cells of a folded quad know how far they lie behind its triangles (closed form);
 *   - form factors: 0 <= F <= 1, F_ii = 0, reciprocity, rows <= 1; the Embree and the
 *     brute-force backends give the same matrix; 1 and 2 threads give the same bits;
 *   - solvers: Jacobi, Gauss-Seidel and shooting agree with the direct LU solve within
 *     1e-4 relative on every patch and channel.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static double edge_length(const rad_mesh *mesh, const rad_patch *p, uint32_t k)
{
    rad_vec3 a = mesh->vertices[p->vertex[k]];
    rad_vec3 b = mesh->vertices[p->vertex[(k + 1) % p->vertex_count]];
    return sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

static void check_mesh(const rad_scene *scene, const rad_mesh *mesh)
{
    double area = 0, longest = 0;
    uint32_t quads = 0, left_wall = UINT32_MAX, left_wall_triangles = 0, left_wall_patches = 0;
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, "left_wall") == 0)
            left_wall = s;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        area += patch->area;
        quads += patch->vertex_count == 4;
        left_wall_patches += patch->surface == left_wall;
        left_wall_triangles += patch->surface == left_wall && patch->vertex_count == 3;
        for (uint32_t k = 0; k < patch->vertex_count; k++)
            longest = fmax(longest, edge_length(mesh, patch, k));
    }
    /* exact for flat quads; the left wall folds by 0.47 degrees, and the bilinear cells of
     * a folded quad have a slightly different area than its two triangles */
    CHECK_NEAR(area, rad_scene_area(scene), 1e-5);
    CHECK(longest <= mesh->patch_size * (1 + 1e-9));
    /* the Cornell box is all quads split in two: every patch is a quad again; the folded
     * left wall's cells record their bulge (under a millimetre), the others none */
    CHECK(left_wall_patches > 0 && left_wall_triangles == 0);
    CHECK(quads == mesh->patch_count);
    double bulge_left = 0, bulge_elsewhere = 0, behind_left = 0, behind_elsewhere = 0;
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        if (patch->surface == left_wall) {
            bulge_left = fmax(bulge_left, patch->bulge);
            behind_left = fmax(behind_left, patch->behind);
        } else {
            bulge_elsewhere = fmax(bulge_elsewhere, patch->bulge);
            behind_elsewhere = fmax(behind_elsewhere, patch->behind);
        }
    }
    /* the fourth corner of the left wall lies 3.2 mm off the first triangle's plane; the
     * bilinear surface strays a quarter of that at most, toward the room: every cell is
     * marked folded, none lies behind the triangles (which block rays) */
    printf("left wall bulge %.4f mm, behind %.3g mm\n", bulge_left, behind_left);
    CHECK(bulge_left > 0.5 && bulge_left < 2);
    CHECK(behind_left < 1e-9);
    CHECK(bulge_elsewhere == 0 && behind_elsewhere == 0);
    /* a grid shares vertices: far fewer than 4 per patch */
    CHECK(mesh->vertex_count < 2 * mesh->patch_count);
    /* but not across regions: no vertex is used by both the light and the ceiling */
    uint32_t light = UINT32_MAX, ceiling = UINT32_MAX;
    for (uint32_t s = 0; s < scene->surface_count; s++) {
        if (strcmp(scene->surfaces[s].name, "light") == 0)
            light = s;
        if (strcmp(scene->surfaces[s].name, "ceiling") == 0)
            ceiling = s;
    }
    CHECK(light != UINT32_MAX && ceiling != UINT32_MAX);
    uint8_t *used = calloc(mesh->vertex_count, 1);
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        for (uint32_t k = 0; k < mesh->patches[p].vertex_count; k++) {
            uint8_t bit = mesh->patches[p].surface == light     ? 1
                          : mesh->patches[p].surface == ceiling ? 2
                                                                : 0;
            used[mesh->patches[p].vertex[k]] |= bit;
        }
    int shared = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        shared += used[v] == 3;
    CHECK(shared == 0);
    free(used);
}

static rad_formfactors *formfactors(const rad_scene *scene, const rad_mesh *mesh,
                                    rad_tracer_backend backend, int threads)
{
    rad_tracer *tracer = NULL;
    rad_formfactors *ff = NULL;
    rad_error error;
    CHECK(rad_tracer_create_for_scene(backend, scene, &tracer, &error) == RAD_OK);
    rad_formfactor_options options = {0};
    options.threads = threads;
    options.seed = 7;
    rad_formfactor_report report;
    CHECK(rad_formfactors_compute(mesh, tracer, &options, &ff, &report, &error) == RAD_OK);
    CHECK(report.rays > 0 && report.pairs_facing <= report.pairs);
    rad_tracer_destroy(tracer);
    return ff;
}

static void check_formfactors(const rad_mesh *mesh, const rad_formfactors *ff)
{
    size_t n = ff->n;
    int out_of_range = 0, diagonal = 0, row_over = 0;
    double largest_row = 0;
    for (size_t i = 0; i < n; i++) {
        double row = 0;
        for (size_t j = 0; j < n; j++) {
            float F = ff->F[i * n + j];
            out_of_range += !(F >= 0 && F <= 1);
            row += F;
        }
        diagonal += ff->F[i * n + i] != 0;
        largest_row = fmax(largest_row, row);
        row_over += row > 1.02;
    }
    CHECK(out_of_range == 0);
    CHECK(diagonal == 0);
    /* A row may exceed 1 a little where a patch touches an occluder: the factor is the
     * analytic unoccluded value times a sampled visibility ratio, and 16 segments resolve
     * contact shadows only so far. */
    printf("largest row sum %.5f\n", largest_row);
    CHECK(row_over == 0);
    rad_formfactor_check check;
    rad_formfactors_check(ff, mesh, &check);
    CHECK(check.reciprocity < 1e-6);
    /* the checker agrees with the test's own loops */
    CHECK_NEAR(check.largest_row_sum, largest_row, 1e-12);
    CHECK(check.largest_factor <= 1);
    /* the box is open at the front: rows lose light; floor patches under the blocks see
     * nothing at all */
    CHECK(check.closure > 0.1);
    CHECK(check.empty_rows > 0);
}

static void check_solvers(const rad_scene *scene, const rad_mesh *mesh, const rad_formfactors *ff)
{
    rad_error error;
    rad_patch_inputs *inputs = NULL;
    CHECK(rad_patch_inputs_build(scene, mesh, &inputs, &error) == RAD_OK);
    rad_system system = rad_system_of(inputs, ff);
    uint32_t n = system.n;
    rad_rgb *reference = calloc(n, sizeof(*reference));
    rad_rgb *B = calloc(n, sizeof(*B));
    rad_solve_options options = {0};
    options.solver = RAD_SOLVER_DIRECT;
    rad_solve_report report;
    CHECK(rad_solve(&system, &options, reference, &report, &error) == RAD_OK);
    CHECK(report.residual < 1e-9);
    const rad_solver solvers[3] = {RAD_SOLVER_JACOBI, RAD_SOLVER_GAUSS_SEIDEL, RAD_SOLVER_SHOOT};
    const char *names[3] = {"jacobi", "gauss-seidel", "shoot"};
    for (int s = 0; s < 3; s++) {
        options.solver = solvers[s];
        options.tolerance = 1e-8;
        options.ambient = false;
        CHECK(rad_solve(&system, &options, B, &report, &error) == RAD_OK);
        CHECK(report.converged);
        double worst = 0;
        for (uint32_t i = 0; i < n; i++) {
            const double *b = &B[i].r, *r = &reference[i].r;
            for (int c = 0; c < 3; c++)
                if (r[c] > 1e-12)
                    worst = fmax(worst, fabs(b[c] - r[c]) / r[c]);
        }
        printf("%s: %u iterations, worst relative difference to direct %.3g\n", names[s],
               report.iterations, worst);
        CHECK(worst < 1e-4);
    }
    free(reference);
    free(B);
    rad_patch_inputs_destroy(inputs);
}

/* A unit square folded along its diagonal from (0,0) to (1,1): the corner (1,0) lifted by
 * `lift` along the normal (+z; negative: behind). Meshed in cells of 0.1, each cell's
 * `behind` is how far it lies behind the two triangles: the bilinear surface strays from
 * them by |lift| min(x (1 - y), y (1 - x)) toward the lift, so behind when the lift is, by
 * the largest of that over the cell (found here on a 21 x 21 grid), and nowhere in front;
 * two-sided, each cell's twin faces -z and lies behind when the lift is toward +z. Every
 * cell keeps the quad's bulge, a quarter of the lift either way. */
static void check_folded_quad(double lift, bool two_sided)
{
    char text[512];
    snprintf(text, sizeof(text),
             "v 0 0 0\nv 1 0 %.17g\nv 1 1 0\nv 0 1 0\no folded\nf 1 2 3\nf 1 3 4\n", lift);
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    rad_load_options options = {0};
    CHECK(rad_scene_load(test_write_file("folded.obj", text), &options, &scene, &error) ==
          RAD_OK);
    if (!scene)
        return;
    if (two_sided)
        CHECK(rad_scene_set_surface_flags(scene, "folded", RAD_SURFACE_TWO_SIDED, &error) ==
              RAD_OK);
    CHECK(rad_mesh_build(scene, 0.1, &mesh, &error) == RAD_OK);
    double largest = 0, worst = 0, edge_cells = 0;
    uint32_t cells = 0;
    for (uint32_t p = 0; mesh && p < mesh->patch_count; p++) {
        const rad_patch *patch = &mesh->patches[p];
        /* a twin faces the other way: it lies behind where the lift is toward +z */
        double toward_front = patch->normal.z > 0 ? lift : -lift;
        cells++;
        CHECK_NEAR(patch->bulge, fabs(lift) / 4, 1e-3); /* relative */
        double x0 = 1, x1 = 0, y0 = 1, y1 = 0;
        for (uint32_t k = 0; k < patch->vertex_count; k++) {
            rad_vec3 v = mesh->vertices[patch->vertex[k]];
            x0 = fmin(x0, v.x), x1 = fmax(x1, v.x), y0 = fmin(y0, v.y), y1 = fmax(y1, v.y);
        }
        double expected = 0;
        for (int i = 0; toward_front < 0 && i <= 20; i++)
            for (int j = 0; j <= 20; j++) {
                double x = x0 + (x1 - x0) * i / 20, y = y0 + (y1 - y0) * j / 20;
                expected = fmax(expected, -toward_front * fmin(x * (1 - y), y * (1 - x)));
            }
        worst = fmax(worst, fabs(patch->behind - expected));
        if (toward_front < 0)
            largest = fmax(largest, patch->behind);
        if (toward_front < 0 && x0 == 0 && y1 == 1)
            edge_cells = fmax(edge_cells, patch->behind);
    }
    printf("folded quad, lift %+g%s: %u cells, largest behind %.4g, worst error %.2g, the "
           "corner cell at (0, 1) %.3g\n",
           lift, two_sided ? ", two-sided" : "", cells, largest, worst, edge_cells);
    CHECK(cells == (two_sided ? 2 : 1) * (mesh ? mesh->patch_count / (two_sided ? 2 : 1) : 0));
    CHECK(mesh && mesh->patch_count >= (two_sided ? 200u : 100u));
    /* before, every cell took the quad's largest, a quarter of the lift. The mesh's
     * estimate (11 points a cell; the midpoints of a cell's diagonals lie on its flat
     * display triangles, not on the bilinear surface) is within 2e-3 of the lift of the
     * grid's here */
    CHECK(worst < 5e-3 * fabs(lift));
    /* the cells that lie behind: the centre's a quarter of the lift, the corner (0, 1)'s a
     * hundredth (1e-4 of the lift at its inner corner) */
    if (lift < 0 || two_sided) {
        CHECK(fabs(largest - fabs(lift) / 4) < 5e-3 * fabs(lift));
        CHECK(edge_cells > 0.005 * fabs(lift) && edge_cells < 0.015 * fabs(lift));
    }
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

int main(void)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    if (!scene)
        return test_finish("test_pipeline");
    CHECK(scene->surface_count == 8);
    CHECK(scene->triangle_count == 32);
    CHECK(scene->has_camera);
    CHECK(rad_scene_has_emitter(scene));
    CHECK(rad_mesh_build(scene, 60.0, &mesh, &error) == RAD_OK);
    printf("%u patches, %u vertices\n", mesh->patch_count, mesh->vertex_count);
    check_mesh(scene, mesh);
    check_folded_quad(0.01, false);
    check_folded_quad(-0.01, false);
    check_folded_quad(0.01, true);

    rad_formfactors *embree = formfactors(scene, mesh, RAD_TRACER_EMBREE, 2);
    rad_formfactors *embree1 = formfactors(scene, mesh, RAD_TRACER_EMBREE, 1);
    rad_formfactors *brute = formfactors(scene, mesh, RAD_TRACER_BRUTE_FORCE, 2);
    check_formfactors(mesh, embree);
    size_t cells = (size_t)embree->n * embree->n, differ = 0, thread_differ = 0;
    double worst = 0;
    for (size_t k = 0; k < cells; k++) {
        differ += embree->F[k] != brute->F[k];
        thread_differ += embree->F[k] != embree1->F[k];
        worst = fmax(worst, fabs(embree->F[k] - brute->F[k]));
    }
    printf("Embree vs brute force: %zu of %zu factors differ, largest difference %.3g\n",
           differ, cells, worst);
    /* a segment grazing an edge (floor to block face, say) may be decided differently by
     * the float BVH and the double-precision oracle: rarely, and by little */
    CHECK(differ <= cells / 1000);
    CHECK(worst < 1e-3);
    CHECK(thread_differ == 0);
    check_solvers(scene, mesh, embree);

    rad_formfactors_destroy(embree);
    rad_formfactors_destroy(embree1);
    rad_formfactors_destroy(brute);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    /* destroying NULL is harmless */
    rad_mesh_destroy(NULL);
    rad_scene_destroy(NULL);
    rad_formfactors_destroy(NULL);
    return test_finish("test_pipeline");
}
