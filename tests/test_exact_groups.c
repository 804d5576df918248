/*
 * test_exact_groups.c - pairs of patches called clear by their groups
 * (exact_pairs_group in src/patch_formfactors/exact_pairs.c), against rays.
 *
 * Groups of neighbouring coplanar patches stand for a rectangle around them; two groups
 * whose rectangles' hull no triangle cuts make every pair between them clear, and the form
 * factors then take those pairs' unoccluded transfer with no ray. Checked on the built-in
 * Cornell box and on a floor under a ceiling with 24 boxes standing between them: for
 * every facing pair the groups call clear, 8 random segments between the two patches
 * that carry light (each end in front of the other patch's plane, not grazing), traced by
 * Embree against every triangle, must all get through (their ends a twentieth of the way
 * in from the patches' edges: a wall that only touches the pair's hull does not count);
 * and the groups must call a tenth of the pairs or more clear (else the test checks
 * nothing). With every group pair called clear instead, 33 % of the Cornell box's segments
 * and 11 % of the boxes' are blocked. The pairs between groups that are not clear screen
 * only the triangles their groups' list keeps: those they call clear get the same check
 * (and are symmetric); with every list emptied, so that those pairs are all called clear,
 * 33 % of the Cornell box's segments and 5.5 % of the boxes' are blocked.
 *
 * The pairs that neither calls clear and that one triangle is proven to hide wholly
 * (exact_pairs_hidden: the form factors give them 0 with no ray; the triangle's face is the
 * convex quad it makes with a neighbour in its plane, hiding_faces.c; or a convex solid
 * holds one patch, the floor under a block, and the other lies apart) get 8 segments each
 * too, none of which may get through, and there must be a number of them (49,777 in the
 * Cornell box, 1,530 among the boxes). A third scene has a quad folded along its diagonal
 * between a floor and a ceiling: with its two triangles taken as one face (the test of
 * their plane dropped), 6 of 0.24 M segments of pairs proven hidden get through (116,842
 * of 2.0 M, with a finer mesh and a smaller fold, when every triangle across the hull was
 * tried, not only the screening's one across the centroids); with a solid taken to hold
 * patches up to 20 units outside its faces, 53,091 of 0.5 M of the Cornell box's do.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/random.h"
#include "core/vec3.h"
#include "patch_formfactors/exact_pairs.h"
#include "testlib.h"
#include "trace/ray.h"

#define SEGMENTS 8u

static rad_vec3 random_point(const rad_mesh *mesh, const rad_patch *patch, rad_rng *rng)
{
    /* a random point of the patch's fan triangle (0, k, k + 1) chosen uniformly by index:
     * not uniform in area, any point of the patch will do */
    uint32_t k = 1 + (uint32_t)(rad_rng_uniform(rng) * (patch->vertex_count - 2));
    if (k > patch->vertex_count - 2)
        k = patch->vertex_count - 2;
    double u = rad_rng_uniform(rng), v = rad_rng_uniform(rng);
    if (u + v > 1) {
        u = 1 - u;
        v = 1 - v;
    }
    rad_vec3 a = mesh->vertices[patch->vertex[0]], b = mesh->vertices[patch->vertex[k]],
             c = mesh->vertices[patch->vertex[k + 1]];
    rad_vec3 x = v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v)));
    /* a twentieth of the way to the centre: a segment along a surface that merely touches
     * the pair's hull (a wall next to both) grazes it, which neither test counts */
    return v3_lerp(x, patch->centroid, 0.05);
}

static void check_scene(const char *name, const rad_scene *scene, double patch_size,
                        uint64_t least_hidden)
{
    rad_error error;
    rad_mesh *mesh = NULL;
    rad_mesh_options options = {.patch_size = patch_size};
    CHECK(rad_mesh_build_with(scene, &options, &mesh, &error) == RAD_OK);
    rad_tracer *tracer = NULL;
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_EMBREE, scene, &tracer, &error) == RAD_OK);
    rad_vec3 lo, hi;
    v3_bounds(mesh->vertices, mesh->vertex_count, &lo, &hi);
    double epsilon = 1e-9 * v3_length(v3_sub(hi, lo));
    exact_pairs pairs;
    CHECK(exact_pairs_build(mesh, tracer, epsilon, &pairs, &error) == RAD_OK);
    CHECK(exact_pairs_group(&pairs, mesh, 2, &error) == RAD_OK);
    CHECK(pairs.group_count > 0);

    uint64_t facing = 0, grouped_clear = 0, listed_clear = 0, blocked = 0, clear_alone = 0,
             segments = 0, hidden_pairs = 0, hidden_segments = 0, hidden_through = 0;
    rad_ray rays[SEGMENTS];
    uint8_t occluded[SEGMENTS];
    for (uint32_t i = 0; i < mesh->patch_count; i++) {
        const rad_patch *pi = &mesh->patches[i];
        for (uint32_t j = i + 1; j < mesh->patch_count; j++) {
            const rad_patch *pj = &mesh->patches[j];
            if (v3_dot(pi->normal, v3_sub(pj->centroid, pi->centroid)) <= 0 ||
                v3_dot(pj->normal, v3_sub(pi->centroid, pj->centroid)) <= 0)
                continue;
            facing++;
            bool clear = exact_pairs_group_clear(&pairs, i, j);
            CHECK(clear == exact_pairs_group_clear(&pairs, j, i)); /* symmetric */
            double G;
            uint32_t crossing_ij, crossing_ji;
            bool screened_clear =
                exact_pairs_transfer(&pairs, i, j, false, 1e-2, &G, &crossing_ij) ==
                EXACT_CLEAR;
            CHECK(screened_clear == (exact_pairs_transfer(&pairs, j, i, false, 1e-2, &G,
                                                          &crossing_ji) == EXACT_CLEAR));
            bool hidden =
                !clear && !screened_clear && exact_pairs_hidden(&pairs, i, j, crossing_ij);
            CHECK(hidden == (!clear && !screened_clear &&
                             exact_pairs_hidden(&pairs, j, i, crossing_ji)));
            if (!clear && screened_clear) /* screened from its groups' list of triangles */
                listed_clear++;
            else if (hidden)
                hidden_pairs++;
            else if (!clear)
                continue;
            else
                grouped_clear++;
            clear_alone += clear && screened_clear;
            /* segments that carry light: each end in front of the other patch (by more
             * than a grazing angle, which in float meets the end's own surface) */
            rad_rng rng = rad_rng_seed(11, i, j);
            unsigned count = 0;
            for (unsigned tries = 0; count < SEGMENTS && tries < 8 * SEGMENTS; tries++) {
                rad_vec3 a = random_point(mesh, pi, &rng), b = random_point(mesh, pj, &rng);
                double length = v3_length(v3_sub(b, a));
                if (v3_dot(pi->normal, v3_sub(b, a)) > 0.01 * length &&
                    v3_dot(pj->normal, v3_sub(a, b)) > 0.01 * length)
                    ray_segment(&rays[count++], a, b);
            }
            rad_tracer_occluded(tracer, rays, count, occluded);
            for (unsigned s = 0; s < count; s++)
                if (hidden)
                    hidden_through += !occluded[s];
                else
                    blocked += occluded[s];
            if (hidden)
                hidden_segments += count;
            else
                segments += count;
        }
    }
    printf("%s: %u patches, %u groups, %llu facing pairs, %llu clear by their groups "
           "(%llu of them clear by their own screening too), %llu more clear by their "
           "groups' lists of triangles, %llu of %llu segments blocked\n",
           name, mesh->patch_count, pairs.group_count, (unsigned long long)facing,
           (unsigned long long)grouped_clear, (unsigned long long)clear_alone,
           (unsigned long long)listed_clear, (unsigned long long)blocked,
           (unsigned long long)segments);
    printf("%s: %llu pairs proven hidden by one triangle, %llu of %llu segments got through\n",
           name, (unsigned long long)hidden_pairs, (unsigned long long)hidden_through,
           (unsigned long long)hidden_segments);
    CHECK(hidden_through == 0);
    CHECK(hidden_segments > hidden_pairs * SEGMENTS / 2);
    CHECK(hidden_pairs >= least_hidden);
    CHECK(pairs.group_list != NULL);
    CHECK(blocked == 0);
    CHECK(segments > (grouped_clear + listed_clear) * SEGMENTS / 2);
    CHECK(grouped_clear > facing / 10);
    CHECK(listed_clear > facing / 100 || least_hidden < 100); /* the folded quad: few */
    exact_pairs_free(&pairs);
    rad_tracer_destroy(tracer);
    rad_mesh_destroy(mesh);
}

/* A 6 x 6 floor under a ceiling 2 up, facing each other, into an OBJ. */
static void floor_and_ceiling(test_obj *obj)
{
    test_obj_add(obj, "mtllib boxes.mtl\n");
    test_obj_object(obj, "floor", "white");
    test_obj_rectangle(obj, 1, 0, 0, 0, 6, 6, 1);
    test_obj_object(obj, "ceiling", "white");
    test_obj_rectangle(obj, 1, 2, 0, 0, 6, 6, -1);
}

/* Loads the OBJ text (as `file`) and checks it. */
static void check_obj(const char *name, const char *file, const test_obj *obj,
                      double patch_size, uint64_t least_hidden)
{
    rad_error error;
    rad_scene *scene = NULL;
    CHECK(rad_scene_load(test_write_file(file, obj->data), NULL, &scene, &error) == RAD_OK);
    if (scene)
        check_scene(name, scene, patch_size, least_hidden);
    rad_scene_destroy(scene);
}

int main(void)
{
    rad_error error;
    rad_scene *cornell = NULL;
    CHECK(rad_scene_cornell_box(&cornell, &error) == RAD_OK);
    check_scene("Cornell box", cornell, 2 * rad_default_patch_size(cornell, RAD_SOLVER_JACOBI),
                10000);
    rad_scene_destroy(cornell);

    /* 24 boxes between a floor and a ceiling */
    test_write_file("boxes.mtl", "newmtl white\nKd 0.5 0.5 0.5\n");
    test_obj obj = {0};
    floor_and_ceiling(&obj);
    rad_rng rng = rad_rng_seed(5, 0, 0);
    for (int b = 0; b < 24; b++) {
        char box[16];
        snprintf(box, sizeof(box), "box%d", b);
        test_obj_object(&obj, box, "white");
        double x = 0.3 + 5.2 * rad_rng_uniform(&rng), z = 0.3 + 5.2 * rad_rng_uniform(&rng);
        double y = 0.3 + 1.2 * rad_rng_uniform(&rng);
        test_obj_box(&obj, x, y, z, x + 0.2, y + 0.2, z + 0.2, false);
    }
    check_obj("boxes between a floor and a ceiling", "boxes.obj", &obj, 0.2, 1000);
    free(obj.data);

    /* a quad folded along its diagonal between a floor and a ceiling: its two triangles
     * are not one face (a segment passes the fold where the crossing of one triangle's
     * plane lies inside the quad) */
    test_obj folded = {0};
    floor_and_ceiling(&folded);
    test_obj_object(&folded, "folded", "white");
    test_obj_add(&folded, "v 1 1 1\nv 5 1 1\nv 5 1 5\nv 1 1.9 5\nf %d %d %d\nf %d %d %d\n",
                 folded.vertices + 1, folded.vertices + 2, folded.vertices + 3,
                 folded.vertices + 1, folded.vertices + 3, folded.vertices + 4);
    folded.vertices += 4;
    check_obj("a folded quad between a floor and a ceiling", "folded.obj", &folded, 0.4, 10);
    free(folded.data);
    return test_finish("test_exact_groups");
}
