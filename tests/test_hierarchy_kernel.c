/*
 * test_hierarchy_kernel.c - the hierarchical solver's factor from a point to a far planar
 * node taken whole (hier_planar_node_factor, the kernel's second-order expansion about the
 * node's centroid) against the exact factor of the node's polygon (Lambert's contour
 * formula), from 6 to 40 of the node's radii, on the axis and obliquely, with the
 * receiving point facing the node and turned from it: within (radius / distance)^4 of the
 * exact value, and closer to it than the disk A cos cos / (pi r^2 + A) it replaced, whose
 * error falls only as (radius / distance)^2.
 */
#include <math.h>
#include <stdlib.h>

#include "geometry/contour.h"
#include "solve/hierarchical/hierarchy.h"
#include "testlib.h"

static void fail_on(rad_status status, const rad_error *error, const char *what)
{
    if (status != RAD_OK) {
        fprintf(stderr, "%s: %s\n", what, error->message);
        exit(1);
    }
}

static double disk(rad_vec3 x, rad_vec3 nx, const hnode *q)
{
    rad_vec3 d = v3_sub(q->centroid, x);
    double r2 = v3_dot(d, d), r = sqrt(r2);
    double cos_x = fmax(0, v3_dot(nx, d) / r), cos_q = fmax(0, -v3_dot(q->normal, d) / r);
    return q->area * cos_x * cos_q / (RAD_PI * r2 + q->area);
}

int main(void)
{
    rad_error error;
    test_tmpdir();
    /* a 2 x 0.5 rectangle facing +z (its second moment is far from a disk's), in 8 x 2
     * patches of 0.25: the tree's root is the plane */
    test_write_file("plate.obj", "v -1 -0.25 0\nv 1 -0.25 0\nv 1 0.25 0\nv -1 0.25 0\n"
                                 "f 1 2 3 4\n");
    rad_scene *scene = NULL;
    fail_on(rad_scene_load(test_path("plate.obj"), NULL, &scene, &error), &error, "load");
    rad_mesh *mesh = NULL;
    fail_on(test_mesh_uniform(scene, 0.25, &mesh, &error), &error, "mesh");
    CHECK(mesh->patch_count == 16);
    hier_tree tree;
    CHECK(hier_tree_build(mesh, &tree));
    const hnode *root = &tree.nodes[0];
    CHECK(root->planar && root->count == 16);
    CHECK_NEAR(root->area, 1.0, 1e-12);
    /* the second moment about the centroid: 2^3 x 0.5 / 12 along x, 2 x 0.5^3 / 12 along y */
    CHECK_NEAR(root->moment[0], 8 * 0.5 / 12, 1e-6);
    CHECK_NEAR(root->moment[1], 2 * 0.125 / 12, 1e-6);
    CHECK(fabs(root->moment[2]) < 1e-9 && fabs(root->moment[3]) < 1e-9);

    const rad_vec3 corners[4] = {v3(-1, -0.25, 0), v3(1, -0.25, 0), v3(1, 0.25, 0),
                                 v3(-1, 0.25, 0)};
    const double R = root->radius; /* sqrt(1 + 1/16) */
    const double ratios[] = {6, 10, 20, 40};
    const double tilts[] = {0, 0.5, 1.0}; /* radians from the plate's normal */
    const double azimuths[] = {0, 0.8, 1.571};
    double worst_scaled = 0, worst_disk_scaled = 0;
    int better = 0, cases = 0;
    for (unsigned i = 0; i < sizeof(ratios) / sizeof(*ratios); i++)
        for (unsigned t = 0; t < sizeof(tilts) / sizeof(*tilts); t++)
            for (unsigned a = 0; a < sizeof(azimuths) / sizeof(*azimuths); a++)
                for (int turned = 0; turned < 2; turned++) {
                    double D = ratios[i] * R;
                    rad_vec3 dir = v3(sin(tilts[t]) * cos(azimuths[a]),
                                      sin(tilts[t]) * sin(azimuths[a]), cos(tilts[t]));
                    rad_vec3 x = v3_scale(dir, D);
                    /* facing the plate's centre, or turned 0.4 rad from it */
                    rad_vec3 nx = v3_scale(dir, -1);
                    if (turned)
                        nx = v3_normalize(v3_add(nx, v3(0.4 * cos(tilts[t]), 0.2,
                                                         -0.4 * sin(tilts[t]))));
                    double exact = contour_point_to_polygon(x, nx, corners, 4, v3(0, 0, 1), 1e-12);
                    double f = hier_planar_node_factor(x, nx, root);
                    CHECK(exact > 0 && f == f);
                    double scale = pow(R / D, 4), relative = fabs(f / exact - 1);
                    double disk_relative = fabs(disk(x, nx, root) / exact - 1);
                    worst_scaled = fmax(worst_scaled, relative / scale);
                    worst_disk_scaled = fmax(worst_disk_scaled, disk_relative / scale);
                    better += relative < disk_relative;
                    cases++;
                }
    printf("expansion: worst relative error %.3f x (R/D)^4; disk: %.1f x (R/D)^4; expansion "
           "closer in %d of %d cases\n",
           worst_scaled, worst_disk_scaled, better, cases);
    CHECK(worst_scaled < 2.0);
    CHECK(worst_disk_scaled > 100); /* the disk's error is of lower order */
    CHECK(better == cases);
    /* behind the receiver's plane (edge-on), or the receiver behind the plate: no
     * expansion */
    CHECK(isnan(hier_planar_node_factor(v3(0, 0, 10), v3(1, 0, 0), root)));
    CHECK(isnan(hier_planar_node_factor(v3(0, 0, -10), v3(0, 0, 1), root)));
    hier_tree_free(&tree);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return test_finish("test_hierarchy_kernel");
}
