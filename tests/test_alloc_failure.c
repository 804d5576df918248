/*
 * test_alloc_failure.c - every allocation of a run may fail, and each failure is a clean
 * RAD_ERR_NOMEM.
 *
 * For each case (a small dense render of the built-in Cornell box written as PNG, a small
 * surface view-factor run written as CSV, an OBJ + MTL + PNG texture load, a glTF load,
 * a small hierarchical solve; then enclosure and script-F, the tracers with HDR, PFM and
 * EXR round trips, a textured render, the other dense solvers, two-thread runs, several
 * files as one scene, a View3D mask, the lit mesh and the solution file), the allocation
 * hook of src/core/alloc.h fails the nth
 * allocation for n = 1, 2, ... until the run succeeds without reaching it. Every failing
 * run must return RAD_ERR_NOMEM with a message, and leave nothing allocated (the ASan
 * build's leak checker sees every sweep) and no output file behind; a run that reaches the
 * failure and still succeeds has swallowed it, which is a failure of this test too.
 * Allocations inside Embree, Assimp, libpng, libjpeg, cJSON and OpenEXR are not hooked.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "testlib.h"

typedef rad_status (*alloc_case_fn)(rad_error *error);

static rad_status fail_nomem(rad_error *error)
{
    snprintf(error->message, sizeof(error->message), "out of memory");
    return error->status = RAD_ERR_NOMEM;
}

/* A coarse Cornell box mesh and its scene, both owned by the caller on RAD_OK. */
static rad_status coarse_cornell_box(rad_scene **scene, rad_mesh **mesh, rad_error *error)
{
    *mesh = NULL;
    rad_status status = rad_scene_cornell_box(scene, error);
    if (status != RAD_OK)
        return status;
    double patch_size = rad_mesh_default_patch_size(*scene, 24);
    if (patch_size > 0)
        status = rad_mesh_build(*scene, patch_size, mesh, error);
    else
        status = fail_nomem(error);
    if (status != RAD_OK) {
        rad_scene_destroy(*scene);
        *scene = NULL;
    }
    return status;
}

/* (a) Cornell box -> dense Jacobi solve -> 16 x 12 render -> PNG. */
static rad_status render_dense(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    rad_image *image = NULL;
    rad_status status = coarse_cornell_box(&scene, &mesh, error);
    if (status == RAD_OK) {
        B = calloc(mesh->patch_count, sizeof(*B)); /* the test's own: not counted */
        if (!B)
            status = fail_nomem(error);
    }
    if (status == RAD_OK) {
        rad_scene_solve_options options = {.solver = RAD_SOLVER_JACOBI, .threads = 1};
        status = rad_solve_scene(scene, mesh, &options, B, NULL, error);
    }
    if (status == RAD_OK)
        status = rad_image_create(16, 12, &image, error);
    if (status == RAD_OK) {
        rad_camera camera = rad_scene_default_camera(scene);
        rad_render_options options = {.threads = 1, .scene = scene};
        status = rad_render(mesh, B, &camera, &options, image, error);
    }
    if (status == RAD_OK)
        status = rad_image_write(image, test_path("render.png"), NULL, error);
    rad_image_destroy(image);
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return status;
}

/* A mesh of `scene` at about `patches` patches, solved by `solver` with `threads`, rendered
 * 12 x 10 with the scene's textures (and mirrors when `specular`). */
static rad_status solve_and_render(rad_scene *scene, uint32_t patches, rad_solver solver,
                                   int threads, bool specular, rad_error *error)
{
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    rad_image *image = NULL;
    rad_patch_inputs *inputs = NULL;
    rad_status status = RAD_OK;
    double patch_size = rad_mesh_default_patch_size(scene, patches);
    if (patch_size > 0)
        status = rad_mesh_build(scene, patch_size, &mesh, error);
    else
        status = fail_nomem(error);
    if (status == RAD_OK)
        status = rad_patch_inputs_build(scene, mesh, &inputs, error);
    if (status == RAD_OK) {
        B = calloc(mesh->patch_count, sizeof(*B));
        if (!B)
            status = fail_nomem(error);
    }
    if (status == RAD_OK) {
        rad_scene_solve_options options = {.solver = solver, .threads = threads,
                                           .inputs = inputs};
        status = rad_solve_scene(scene, mesh, &options, B, NULL, error);
    }
    if (status == RAD_OK)
        status = rad_image_create(12, 10, &image, error);
    if (status == RAD_OK) {
        rad_camera camera = rad_scene_default_camera(scene);
        rad_render_options options = {.threads = threads, .scene = scene, .inputs = inputs,
                                      .materials = specular ? scene->materials : NULL};
        status = rad_render(mesh, B, &camera, &options, image, error);
    }
    rad_image_destroy(image);
    free(B);
    rad_patch_inputs_destroy(inputs);
    rad_mesh_destroy(mesh);
    return status;
}

/* The textured OBJ: Gauss-Seidel, rendered with its texture; and path traced. */
static rad_status textured_render(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_image *image = NULL;
    rad_status status = rad_scene_load(test_path("textured.obj"), NULL, &scene, error);
    if (status == RAD_OK)
        status = solve_and_render(scene, 40, RAD_SOLVER_GAUSS_SEIDEL, 1, false, error);
    if (status == RAD_OK)
        status = rad_image_create(8, 6, &image, error);
    if (status == RAD_OK) {
        rad_camera camera = rad_scene_default_camera(scene);
        rad_pathtrace_options options = {.samples_per_pixel = 2, .max_depth = 2, .threads = 1};
        status = rad_pathtrace(scene, &camera, &options, image, NULL, NULL, error);
    }
    rad_image_destroy(image);
    rad_scene_destroy(scene);
    return status;
}

/* The Cornell box with a surface made a mirror-ish emitter (rad_scene_set_material), shot
 * and rendered with mirrors, then solved directly: two threads. */
static rad_status other_solvers(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_status status = rad_scene_cornell_box(&scene, error);
    if (status == RAD_OK) {
        rad_rgb albedo = {0.2, 0.3, 0.4};
        status = rad_scene_set_material(scene, scene->surfaces[0].name, &albedo, NULL, error);
    }
    if (status == RAD_OK)
        status = solve_and_render(scene, 20, RAD_SOLVER_SHOOT, 2, true, error);
    if (status == RAD_OK)
        status = solve_and_render(scene, 16, RAD_SOLVER_DIRECT, 2, false, error);
    rad_scene_destroy(scene);
    return status;
}

/* The Cornell box solved hierarchically with two threads (the renderer's two threads are
 * in other_solvers). */
static rad_status hierarchical_two_threads(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    rad_status status = rad_scene_cornell_box(&scene, error);
    if (status == RAD_OK)
        status = rad_mesh_build(scene, 300, &mesh, error);
    if (status == RAD_OK) {
        B = calloc(mesh->patch_count, sizeof(*B));
        if (!B)
            status = fail_nomem(error);
    }
    if (status == RAD_OK) {
        rad_scene_solve_options options = {.solver = RAD_SOLVER_HIERARCHICAL, .threads = 2,
                                           .refine_threshold = 2};
        status = rad_solve_scene(scene, mesh, &options, B, NULL, error);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return status;
}

/* Several files (an STL, a PLY and the OBJ, one kept by its surfaces) as one scene, and
 * their view factors. */
static rad_status several_files(rad_error *error)
{
    rad_scene_file files[3] = {{test_path("slab.stl"), 0, false},
                               {test_path("roof.ply"), 0, false},
                               {test_path("textured.obj"), 0, true}};
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL;
    rad_status status = rad_scene_load_files(files, 3, NULL, &scene, error);
    if (status == RAD_OK) {
        rad_viewfactor_options options = {.accuracy = 1e-2, .max_rays = 64, .threads = 2};
        status = rad_viewfactor_matrix_compute(scene, &options, &matrix, NULL, error);
    }
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return status;
}

/* (d) Cornell box -> hierarchical solve. */
static rad_status solve_hierarchical(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_rgb *B = NULL;
    rad_status status = coarse_cornell_box(&scene, &mesh, error);
    if (status == RAD_OK) {
        B = calloc(mesh->patch_count, sizeof(*B)); /* the test's own: not counted */
        if (!B)
            status = fail_nomem(error);
    }
    if (status == RAD_OK) {
        rad_scene_solve_options options = {.solver = RAD_SOLVER_HIERARCHICAL, .threads = 1};
        status = rad_solve_scene(scene, mesh, &options, B, NULL, error);
    }
    free(B);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return status;
}

/* (b) the Cornell box's surface view factors -> CSV. */
static rad_status viewfactors(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL;
    rad_status status = rad_scene_cornell_box(&scene, error);
    if (status == RAD_OK) {
        rad_viewfactor_options options = {.accuracy = 1e-2, .max_rays = 64, .threads = 1};
        status = rad_viewfactor_matrix_compute(scene, &options, &matrix, NULL, error);
    }
    if (status == RAD_OK)
        status = rad_viewfactor_matrix_write(scene, matrix, test_path("factors.csv"), NULL,
                                             error);
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return status;
}

/* (e) the closed Cornell box's view factors, closed as an enclosure, then script-F. */
static rad_status enclosure_script_f(rad_error *error)
{
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL, *script_f = NULL;
    double *emissivity = NULL;
    rad_status status = rad_scene_cornell_box(&scene, error);
    if (status == RAD_OK) {
        rad_viewfactor_options options = {.accuracy = 1e-2, .max_rays = 64, .threads = 1};
        status = rad_viewfactor_matrix_compute(scene, &options, &matrix, NULL, error);
    }
    if (status == RAD_OK)
        status = rad_viewfactor_matrix_close_enclosure(matrix, scene, NULL, error);
    if (status == RAD_OK) {
        emissivity = calloc(matrix->n, sizeof(*emissivity));
        if (!emissivity)
            status = fail_nomem(error);
        for (uint32_t k = 0; emissivity && k < matrix->n; k++)
            emissivity[k] = 0.9;
    }
    if (status == RAD_OK)
        status = rad_viewfactor_matrix_script_f(matrix, emissivity, &script_f, error);
    free(emissivity);
    rad_viewfactor_matrix_destroy(script_f);
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return status;
}

/* (f) Whitted and path-traced 8 x 6 images of the Cornell box written as HDR, PFM and EXR,
 * read back and compared. */
static rad_status trace_and_images(rad_error *error)
{
    static const char *const names[3] = {"traced.hdr", "traced.pfm", "traced.exr"};
    rad_scene *scene = NULL;
    rad_image *whitted = NULL, *traced = NULL, *deviation = NULL, *back = NULL;
    rad_status status = rad_scene_cornell_box(&scene, error);
    rad_camera camera = scene ? rad_scene_default_camera(scene) : (rad_camera){0};
    if (status == RAD_OK)
        status = rad_image_create(8, 6, &whitted, error);
    if (status == RAD_OK)
        status = rad_image_create(8, 6, &traced, error);
    if (status == RAD_OK)
        status = rad_image_create(8, 6, &deviation, error);
    if (status == RAD_OK) {
        rad_raytrace_options options = {.light_samples = 2, .samples_per_pixel = 1,
                                        .threads = 1};
        status = rad_raytrace(scene, &camera, &options, whitted, error);
    }
    if (status == RAD_OK) {
        rad_pathtrace_options options = {.samples_per_pixel = 4, .max_depth = 3, .threads = 1};
        status = rad_pathtrace(scene, &camera, &options, traced, deviation, NULL, error);
    }
    for (int k = 0; k < 3 && status == RAD_OK; k++) {
        status = rad_image_write(k == 1 ? whitted : traced, test_path(names[k]), NULL, error);
        if (status == RAD_OK)
            status = rad_image_read(test_path(names[k]), &back, error);
        if (status == RAD_OK) {
            rad_image_difference difference;
            status = rad_image_compare(back, traced, NULL, &difference, deviation, error);
        }
        rad_image_destroy(back);
        back = NULL;
    }
    rad_image_destroy(deviation);
    rad_image_destroy(traced);
    rad_image_destroy(whitted);
    rad_scene_destroy(scene);
    return status;
}

/* The coarse Cornell box and a solution for it, made before the sweeps that use them. */
static rad_scene *solved_scene;
static rad_mesh *solved_mesh;
static rad_rgb *solved_B;
static rad_patch_inputs *solved_inputs;

/* (g) the lit mesh as .ply, .glb and .obj (with the vertices' illuminance: the patch
 * inputs given), and the solution written, read and matched. */
static rad_status lit_mesh_and_solution(rad_error *error)
{
    static const char *const names[3] = {"lit.ply", "lit.glb", "lit.obj"};
    rad_status status = RAD_OK;
    rad_lit_mesh_options options = {.inputs = solved_inputs};
    for (int k = 0; k < 3 && status == RAD_OK; k++)
        status = rad_lit_mesh_write(solved_mesh, solved_B, test_path(names[k]), &options, error);
    rad_solution *solution = NULL;
    if (status == RAD_OK)
        status = rad_solution_write(solved_scene, solved_mesh, solved_B, test_path("saved.rad"),
                                    error);
    if (status == RAD_OK)
        status = rad_solution_read(test_path("saved.rad"), &solution, error);
    if (status == RAD_OK)
        status = rad_solution_match(solution, solved_scene, solved_mesh, error);
    rad_solution_destroy(solution);
    return status;
}

/* (h) a View3D file with a mask: loaded, its view factors computed, the mask applied. */
static rad_status vs3_masks(rad_error *error)
{
    const char *path = test_path("masked.vs3");
    rad_scene *scene = NULL;
    rad_viewfactor_matrix *matrix = NULL;
    rad_status status = rad_scene_load_vs3(path, NULL, &scene, NULL, error);
    if (status == RAD_OK) {
        rad_viewfactor_options options = {.accuracy = 1e-2, .max_rays = 64, .threads = 1};
        status = rad_viewfactor_matrix_compute(scene, &options, &matrix, NULL, error);
    }
    if (status == RAD_OK)
        status = rad_viewfactor_matrix_apply_vs3_masks(path, scene, &matrix, error);
    rad_viewfactor_matrix_destroy(matrix);
    rad_scene_destroy(scene);
    return status;
}

static rad_status load_scene(const char *name, rad_error *error)
{
    rad_scene *scene = NULL;
    rad_status status = rad_scene_load(test_path(name), NULL, &scene, error);
    rad_scene_destroy(scene);
    return status;
}

/* (c) an OBJ whose material library gives an albedo texture and an emitter. */
static rad_status load_obj(rad_error *error) { return load_scene("textured.obj", error); }

/* (c) a glTF of two triangles (a lit quad) with its buffer in a .bin file. */
static rad_status load_gltf(rad_error *error) { return load_scene("quad.gltf", error); }

static void write_obj_scene(void)
{
    unsigned char texels[4 * 4 * 3];
    for (size_t k = 0; k < sizeof(texels); k++)
        texels[k] = (unsigned char)(40 + 13 * k);
    test_write_png("albedo.png", 4, 4, texels);
    test_write_file("textured.mtl", "newmtl floor\nKd 0.8 0.8 0.8\nmap_Kd albedo.png\n"
                                    "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
    test_write_file("textured.obj", "mtllib textured.mtl\n"
                                    "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
                                    "v 0.4 0.9 0.4\nv 0.6 0.9 0.4\nv 0.6 0.9 0.6\n"
                                    "v 0.4 0.9 0.6\n"
                                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                    "o floor\nusemtl floor\nf 1/1 4/4 3/3 2/2\n"
                                    "o lamp\nusemtl lamp\nf 5 6 7 8\n");
}

static void write_gltf_scene(void)
{
    /* 4 positions (48 bytes) then 6 unsigned short indices (12 bytes) */
    const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1};
    const uint16_t indices[6] = {0, 2, 1, 0, 3, 2};
    FILE *file = fopen(test_path("quad.bin"), "wb");
    CHECK(file != NULL);
    if (!file)
        return;
    CHECK(fwrite(positions, sizeof(positions), 1, file) == 1);
    CHECK(fwrite(indices, sizeof(indices), 1, file) == 1);
    CHECK(fclose(file) == 0);
    test_write_file(
        "quad.gltf",
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"name\":\"quad\",\"primitives\":[{\"attributes\":{\"POSITION\":0},"
        "\"indices\":1,\"material\":0}]}],"
        "\"materials\":[{\"name\":\"glow\",\"emissiveFactor\":[1,0.5,0.25],"
        "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]}}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":60}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":"
        "\"VEC3\",\"min\":[0,0,0],\"max\":[1,0,1]},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}");
}

/* Runs `run` with the nth allocation failing, n = 1, 2, ..., until it succeeds without
 * reaching the failure; returns the allocations of the successful run. `output` (or NULL)
 * is the file the case writes: no failing run may leave it, or any temporary, behind. */
static uint64_t sweep(const char *name, alloc_case_fn run, const char *output)
{
    rad_error error;
    rad_alloc_fail_nth(UINT64_MAX); /* counts, never fails */
    memset(&error, 0, sizeof(error));
    rad_status status = run(&error);
    uint64_t allocations = rad_alloc_count();
    rad_alloc_fail_nth(0);
    CHECK(status == RAD_OK);
    if (status != RAD_OK) {
        fprintf(stderr, "%s: fails without an injected failure: %s\n", name, error.message);
        return 0;
    }
    int failures_before = test_failures;
    double start = rad_clock_seconds();
    uint64_t n = 1;
    for (; n <= allocations + 64; n++) {
        if (output)
            remove(test_path(output));
        memset(&error, 0, sizeof(error));
        rad_alloc_fail_nth(n);
        status = run(&error);
        bool injected = rad_alloc_failure_injected();
        rad_alloc_fail_nth(0);
        if (status == RAD_OK && !injected)
            break; /* past the last allocation */
        if (status == RAD_OK)
            test_fail(__FILE__, __LINE__, "%s: allocation %llu failed and the run succeeded",
                      name, (unsigned long long)n);
        else if (status != RAD_ERR_NOMEM || !injected || !error.message[0])
            test_fail(__FILE__, __LINE__, "%s: allocation %llu failed: %s%s (%s)", name,
                      (unsigned long long)n, rad_status_name(status),
                      injected ? "" : " without the injected failure", error.message);
        else if (output && test_count_files(output) != 0)
            test_fail(__FILE__, __LINE__, "%s: allocation %llu failed and left a file", name,
                      (unsigned long long)n);
        test_checks++;
        if (test_failures - failures_before > 20)
            break; /* enough to read */
    }
    CHECK(n <= allocations + 64);
    printf("%s: %llu allocations; n = 1 .. %llu swept, %d wrong (%.1f s)\n", name,
           (unsigned long long)allocations, (unsigned long long)(n - 1),
           test_failures - failures_before, rad_clock_seconds() - start);
    return allocations;
}

int main(void)
{
    test_tmpdir();
    write_obj_scene();
    write_gltf_scene();
    test_write_file("slab.stl", "solid slab\nfacet normal 0 1 0\nouter loop\n"
                                 "vertex 0 -0.5 0\nvertex 0 -0.5 1\nvertex 1 -0.5 0\n"
                                 "endloop\nendfacet\nendsolid slab\n");
    test_write_file("roof.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 2 0\n1 2 0\n0 2 1\n3 0 1 2\n");
    /* a 2 x 2 floor with a 1 x 1 mask on it, under a 2 x 2 ceiling */
    test_write_file("masked.vs3", "F 3\nV 1 0 0 0\nV 2 2 0 0\nV 3 2 2 0\nV 4 0 2 0\n"
                                  "V 5 0 0 1\nV 6 2 0 1\nV 7 2 2 1\nV 8 0 2 1\n"
                                  "V 9 0.5 0.5 0\nV 10 1.5 0.5 0\nV 11 1.5 1.5 0\n"
                                  "V 12 0.5 1.5 0\nS 1 1 2 3 4 0 0 0.9 floor\n"
                                  "M 2 12 11 10 9 1 0 0.4 rug\nS 3 5 8 7 6 0 0 0.9 ceiling\n");
    CHECK(sweep("scene load (OBJ + MTL + PNG texture)", load_obj, NULL) > 0);
    CHECK(sweep("scene load (glTF + .bin)", load_gltf, NULL) > 0);
    CHECK(sweep("view factors (Cornell box, CSV)", viewfactors, "factors.csv") > 0);
    CHECK(sweep("hierarchical solve (Cornell box)", solve_hierarchical, NULL) > 0);
    CHECK(sweep("dense render (Cornell box, 16 x 12 PNG)", render_dense, "render.png") > 0);
    CHECK(sweep("enclosure and script-F (Cornell box)", enclosure_script_f, NULL) > 0);
    CHECK(sweep("Whitted and path tracing, HDR, PFM and EXR written and read", trace_and_images,
                NULL) > 0);
    CHECK(sweep("textured OBJ: Gauss-Seidel, textured render, path tracing", textured_render,
                NULL) > 0);
    CHECK(sweep("Cornell box: set_material, shooting with mirrors, direct, 2 threads",
                other_solvers, NULL) > 0);
    CHECK(sweep("Cornell box: hierarchical, 2 threads", hierarchical_two_threads,
                NULL) > 0);
    CHECK(sweep("STL + PLY + OBJ as one scene, view factors, 2 threads", several_files, NULL) >
          0);
    CHECK(sweep("View3D file with a mask: load, view factors, mask", vs3_masks, NULL) > 0);
    rad_error error = {0};
    CHECK(coarse_cornell_box(&solved_scene, &solved_mesh, &error) == RAD_OK);
    solved_B = solved_mesh ? calloc(solved_mesh->patch_count, sizeof(*solved_B)) : NULL;
    CHECK(solved_B != NULL);
    if (solved_B) {
        rad_scene_solve_options options = {.solver = RAD_SOLVER_JACOBI, .threads = 1};
        CHECK(rad_solve_scene(solved_scene, solved_mesh, &options, solved_B, NULL, &error) ==
              RAD_OK);
        CHECK(rad_patch_inputs_build(solved_scene, solved_mesh, &solved_inputs, &error) ==
              RAD_OK);
        CHECK(sweep("lit mesh (PLY, GLB, OBJ) and solution file", lit_mesh_and_solution,
                    NULL) > 0);
    }
    free(solved_B);
    rad_patch_inputs_destroy(solved_inputs);
    rad_mesh_destroy(solved_mesh);
    rad_scene_destroy(solved_scene);
    return test_finish("test_alloc_failure");
}
