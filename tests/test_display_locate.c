/*
 * test_display_locate.c - a hit on the scene's triangles placed in the display mesh
 * (src/reconstruct/display_locate.c), against Embree tracing the display mesh itself.
 *
 * Random rays inside the built-in Cornell box (its default mesh: quads, a folded wall,
 * shadow splits and their T-vertices) and inside a box around an octahedron standing on
 * its tip (triangles split into similar triangles, a mesh whose quads and triangles meet):
 *   - the point the located display triangle's barycentrics give is the hit point (within
 *     the folded wall's stray from its input triangles),
 *   - the located triangle is on the surface and side that the display tracer's hit is,
 *   - a miss is a miss for both,
 *   - at most 1 ray in 10^4 is not placed (the gather traces those on the display mesh),
 *   - the locator holds at most DISPLAY_LOCATE_BYTES_PER_TRIANGLE a display triangle, on
 *     a long thin strip (20 x 0.4, two triangles) too.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/random.h"
#include "core/vec3.h"
#include "reconstruct/display_locate.h"
#include "reconstruct/display_mesh.h"
#include "testlib.h"
#include "trace/ray.h"

#define RAYS 200000u

static void check_scene(const char *name, const rad_scene *scene, double patch_size)
{
    rad_error error;
    rad_mesh *mesh = NULL;
    rad_mesh_options options = {.patch_size = patch_size};
    CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_OK);
    display_mesh display = {0};
    CHECK(display_mesh_build(mesh, true, &display, &error) == RAD_OK);
    rad_vec3 *positions = calloc(display.vertex_count, sizeof(*positions));
    display_mesh_positions(mesh, &display, positions);
    uint32_t front = display_mesh_front_triangles(mesh, &display);
    rad_tracer *display_tracer = NULL, *scene_tracer = NULL;
    CHECK(rad_tracer_create(RAD_TRACER_EMBREE, positions, display.vertex_count,
                            (const uint32_t(*)[3])display.triangles, front, &display_tracer,
                            &error) == RAD_OK);
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &scene_tracer, &error) ==
          RAD_OK);
    display_locator *locator = NULL;
    CHECK(display_locator_build(scene, scene_tracer, mesh, &display, positions, front, 0, 2,
                                &locator, &error) == RAD_OK);
    CHECK(locator != NULL);

    rad_vec3 lo, hi;
    v3_bounds(scene->positions, scene->position_count, &lo, &hi);
    double diagonal = v3_length(v3_sub(hi, lo));
    double stray = 0; /* how far a folded quad's cells lie off its input triangles */
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        stray = fmax(stray, 2 * (mesh->patches[p].bulge + mesh->patches[p].behind));
    rad_ray *rays = calloc(RAYS, sizeof(*rays));
    rad_hit *reference = calloc(RAYS, sizeof(*reference));
    rad_hit *located = calloc(RAYS, sizeof(*located));
    rad_rng rng = rad_rng_seed(7, 0, 0);
    for (uint32_t k = 0; k < RAYS; k++) {
        rad_vec3 origin;
        origin.x = lo.x + (0.02 + 0.96 * rad_rng_uniform(&rng)) * (hi.x - lo.x);
        origin.y = lo.y + (0.02 + 0.96 * rad_rng_uniform(&rng)) * (hi.y - lo.y);
        origin.z = lo.z + (0.02 + 0.96 * rad_rng_uniform(&rng)) * (hi.z - lo.z);
        double z = 2 * rad_rng_uniform(&rng) - 1, phi = 2 * RAD_PI * rad_rng_uniform(&rng);
        double r = sqrt(fmax(0, 1 - z * z));
        ray_set(&rays[k], origin, v3(r * cos(phi), r * sin(phi), z), 0, INFINITY);
    }
    rad_tracer_intersect(display_tracer, rays, RAYS, reference);
    rad_tracer_intersect_coherent(scene_tracer, rays, RAYS, located);

    uint32_t hits = 0, unplaced = 0, off_point = 0, other_surface = 0, other_side = 0,
             miss_mismatch = 0;
    double worst = 0;
    for (uint32_t k = 0; k < RAYS; k++) {
        rad_hit *got = &located[k];
        const rad_hit *want = &reference[k];
        if ((got->triangle == RAD_NO_HIT) != (want->triangle == RAD_NO_HIT)) {
            miss_mismatch++;
            continue;
        }
        if (want->triangle == RAD_NO_HIT)
            continue;
        hits++;
        rad_vec3 point = v3(rays[k].origin[0] + got->t * rays[k].direction[0],
                            rays[k].origin[1] + got->t * rays[k].direction[1],
                            rays[k].origin[2] + got->t * rays[k].direction[2]);
        if (!display_locate(locator, got)) {
            unplaced++;
            continue;
        }
        CHECK(got->triangle < front);
        CHECK(got->u >= 0 && got->v >= 0 && got->u + got->v <= 1 + 1e-6);
        const uint32_t *v = display.triangles[got->triangle];
        rad_vec3 at = v3_add(v3_scale(positions[v[0]], 1 - got->u - got->v),
                             v3_add(v3_scale(positions[v[1]], got->u),
                                    v3_scale(positions[v[2]], got->v)));
        double apart = v3_length(v3_sub(at, point));
        worst = fmax(worst, apart);
        off_point += apart > stray + 1e-5 * diagonal;
        const rad_patch *mine = &mesh->patches[display.patch_of[got->triangle]];
        const rad_patch *theirs = &mesh->patches[display.patch_of[want->triangle]];
        other_surface += mine->surface != theirs->surface;
        other_side += got->front != want->front;
    }
    double bytes = (double)display_locator_bytes(locator) / front;
    printf("%s: %u patches, %u display triangles, %u rays: %u hits, %u not placed, "
           "farthest %.3g (stray %.3g, diagonal %.3g), %u on another surface, %u on "
           "another side, %u miss only one way; %.0f bytes a display triangle\n",
           name, mesh->patch_count, front, RAYS, hits, unplaced, worst, stray, diagonal,
           other_surface, other_side, miss_mismatch, bytes);
    CHECK(bytes <= DISPLAY_LOCATE_BYTES_PER_TRIANGLE);
    CHECK(hits > RAYS / 4);
    CHECK(unplaced <= hits / 10000);
    CHECK(off_point == 0);
    CHECK(other_surface <= hits / 10000);
    CHECK(other_side <= hits / 10000);
    CHECK(miss_mismatch <= RAYS / 10000);
    free(rays);
    free(reference);
    free(located);
    display_locator_destroy(locator);
    rad_tracer_destroy(display_tracer);
    rad_tracer_destroy(scene_tracer);
    free(positions);
    display_mesh_free(&display);
    rad_mesh_destroy(mesh);
}

int main(void)
{
    rad_error error;
    rad_scene *cornell = NULL;
    CHECK(rad_scene_cornell_box(&cornell, &error) == RAD_OK);
    check_scene("Cornell box", cornell, rad_default_patch_size(cornell, RAD_SOLVER_JACOBI));
    rad_scene_destroy(cornell);

    /* an octahedron on its tip (8 triangles) in a closed box, with a lamp above it */
    test_obj obj = {0};
    test_obj_add(&obj, "mtllib octahedron.mtl\n");
    test_obj_object(&obj, "room", "white");
    test_obj_rectangle(&obj, 1, 0, 0, 0, 4, 4, 1);  /* floor, y = 0 (z, x) */
    test_obj_rectangle(&obj, 1, 3, 0, 0, 4, 4, -1); /* ceiling */
    test_obj_rectangle(&obj, 0, 0, 0, 0, 3, 4, 1);  /* x = 0 (y, z) */
    test_obj_rectangle(&obj, 0, 4, 0, 0, 3, 4, -1);
    test_obj_rectangle(&obj, 2, 0, 0, 0, 4, 3, 1); /* z = 0 (x, y) */
    test_obj_rectangle(&obj, 2, 4, 0, 0, 4, 3, -1);
    test_obj_object(&obj, "lamp", "light");
    test_obj_rectangle(&obj, 1, 2.99, 1.5, 1.5, 2.5, 2.5, -1);
    test_obj_object(&obj, "octahedron", "white");
    int base = obj.vertices;
    test_obj_add(&obj, "v 2 0.2 2\nv 2 2.2 2\nv 2.8 1.2 2\nv 1.2 1.2 2\nv 2 1.2 2.8\n"
                       "v 2 1.2 1.2\n");
    obj.vertices += 6;
    static const int faces[8][3] = {{1, 3, 5}, {1, 5, 4}, {1, 4, 6}, {1, 6, 3},
                                    {2, 5, 3}, {2, 4, 5}, {2, 6, 4}, {2, 3, 6}};
    for (int f = 0; f < 8; f++)
        test_obj_add(&obj, "f %d %d %d\n", base + faces[f][0], base + faces[f][1],
                     base + faces[f][2]);
    test_write_file("octahedron.mtl", "newmtl white\nKd 0.7 0.7 0.7\n"
                                      "newmtl light\nKd 0 0 0\nKe 5 5 5\n");
    const char *path = test_write_file("octahedron.obj", obj.data);
    rad_scene *scene = NULL;
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (scene)
        check_scene("octahedron in a box", scene, 0.25);
    rad_scene_destroy(scene);
    free(obj.data);

    /* a long thin strip, 20 x 0.4 under a ceiling as thin (two triangles each, 50 to 1):
     * a grid over the (u, v) square would stretch each display triangle's box over many
     * cells (the locator took 1 kB a display triangle on such a strip) */
    test_obj strip = {0};
    test_obj_add(&strip, "mtllib octahedron.mtl\n");
    test_obj_object(&strip, "floor", "white");
    test_obj_rectangle(&strip, 1, 0, 0, 0, 0.4, 20, 1);
    test_obj_object(&strip, "ceiling", "light");
    test_obj_rectangle(&strip, 1, 0.4, 0, 0, 0.4, 20, -1);
    path = test_write_file("strip.obj", strip.data);
    scene = NULL;
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (scene)
        check_scene("thin strip", scene, 0.05);
    rad_scene_destroy(scene);
    free(strip.data);
    return test_finish("test_display_locate");
}
