/*
 * test_seams.c - display continuity where two neighbouring polygons of one smooth region
 * split their shared edge into different counts (T-vertices).
 *
 * Scenes (OBJ, one surface, coplanar, z = 0):
 *   - a unit quad next to a trapezoid (1,0) (3,0) (3,3) (1,1): at patch size 0.5 the quad
 *     splits the shared edge x = 1 in 2, the trapezoid in 6 (nested: 4 T-vertices); at 0.4
 *     in 3 and 8 (neither nests: all 9 inner points are T-vertices);
 *   - two triangles (0,0) (1,0) (0,1) and (1,0) (2,2) (0,1) sharing their edge (1,0)-(0,1),
 *     split 3 and 5 times at patch size 0.5 (triangle patches with T-vertices);
 *   - a unit square framed by four trapezoids (a 3 x 3 square): at patch size 1 the square
 *     is one patch with T-vertices on all four edges.
 * The radiosity is set directly, linear in x and y at each patch's centroid, so the
 * values vary along the seam. Independent of the library's own T-vertex search, the test
 * finds by brute force every vertex lying strictly inside a patch edge and checks:
 *   - its count against the closed form (n1 - 1) + (n2 - 1) - 2 (gcd(n1, n2) - 1);
 *   - rad_reconstruct_vertices gives it the linear interpolation of that edge's end
 *     values (1e-6), and every other vertex the area-weighted mean of B / pi (recomputed
 *     here, 1e-12);
 *   - the lit mesh (.obj, read back) has no T-junction: no vertex of the file lies strictly
 *     inside an edge of a face; faces are front-facing, none degenerate, and their areas
 *     add up to the polygons' (closed form);
 *   - a render looking straight down with the seam on a pixel boundary has no jump there:
 *     the third difference of four pixels across the seam (zero for a kink, the jump
 *     itself for a step) stays below 2e-3 of the values.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

#define PI 3.14159265358979323846
#define ON_EDGE 1e-9
#define IMAGE_SIZE 256u

typedef struct seam_case {
    const char *name;
    const char *obj;
    double patch_size;
    uint32_t expected_tvertices;
    double area;      /* the polygons' total area */
    bool render_seam; /* the seam is the line x = 1, y in [0, 1] */
    uint32_t expected_added; /* other regions' vertices inside a patch edge */
} seam_case;

/* The field: radiance 1 + 0.5 x + y (and 2x that, and a constant) at each centroid. */
static void set_field(const rad_mesh *mesh, rad_rgb *B)
{
    for (uint32_t p = 0; p < mesh->patch_count; p++) {
        rad_vec3 c = mesh->patches[p].centroid;
        double g = 1 + 0.5 * c.x + c.y;
        B[p] = (rad_rgb){PI * g, PI * 2 * g, PI * 0.25};
    }
}

/* t of point x along segment a-b when x lies strictly inside it (within ON_EDGE of the
 * segment's length), else -1. */
static double inside_segment(rad_vec3 a, rad_vec3 b, rad_vec3 x, double tolerance)
{
    double ex = b.x - a.x, ey = b.y - a.y, ez = b.z - a.z;
    double length2 = ex * ex + ey * ey + ez * ez;
    double t = ((x.x - a.x) * ex + (x.y - a.y) * ey + (x.z - a.z) * ez) / length2;
    double dx = a.x + t * ex - x.x, dy = a.y + t * ey - x.y, dz = a.z + t * ez - x.z;
    double distance = sqrt(dx * dx + dy * dy + dz * dz);
    if (distance > tolerance * sqrt(length2) || t <= tolerance || t >= 1 - tolerance)
        return -1;
    return t;
}

/* The scenes' regions are told apart by material: a vertex's is its patches'. */
static uint32_t material_of(const rad_mesh *mesh, uint32_t v)
{
    for (uint32_t p = 0; p < mesh->patch_count; p++)
        for (uint32_t k = 0; k < mesh->patches[p].vertex_count; k++)
            if (mesh->patches[p].vertex[k] == v)
                return mesh->patches[p].material;
    return UINT32_MAX;
}

static void check_vertices(const seam_case *c, const rad_mesh *mesh, const rad_rgb *B,
                           const rad_rgb *L)
{
    uint32_t tvertices = 0, means = 0;
    double worst_lerp = 0, worst_mean = 0, before = 0;
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        /* the area-weighted mean, recomputed */
        double sum[3] = {0, 0, 0}, weight = 0;
        for (uint32_t p = 0; p < mesh->patch_count; p++)
            for (uint32_t k = 0; k < mesh->patches[p].vertex_count; k++)
                if (mesh->patches[p].vertex[k] == v) {
                    double a = mesh->patches[p].area;
                    sum[0] += a * B[p].r, sum[1] += a * B[p].g, sum[2] += a * B[p].b;
                    weight += a;
                }
        double mean[3] = {sum[0] / (PI * weight), sum[1] / (PI * weight),
                          sum[2] / (PI * weight)};
        bool is_t = false;
        for (uint32_t p = 0; p < mesh->patch_count && !is_t; p++) {
            const rad_patch *patch = &mesh->patches[p];
            if (patch->material != material_of(mesh, v)) /* another region */
                continue;
            for (uint32_t k = 0; k < patch->vertex_count && !is_t; k++) {
                uint32_t a = patch->vertex[k], b = patch->vertex[(k + 1) % patch->vertex_count];
                if (a == v || b == v)
                    continue;
                double t = inside_segment(mesh->vertices[a], mesh->vertices[b],
                                          mesh->vertices[v], ON_EDGE);
                if (t < 0)
                    continue;
                is_t = true;
                tvertices++;
                const double *la = &L[a].r, *lb = &L[b].r, *lv = &L[v].r;
                for (int ch = 0; ch < 3; ch++) {
                    double expected = la[ch] + t * (lb[ch] - la[ch]);
                    worst_lerp = fmax(worst_lerp, fabs(lv[ch] - expected));
                    before = fmax(before, fabs(mean[ch] - expected));
                }
            }
        }
        if (!is_t) {
            means++;
            const double *lv = &L[v].r;
            for (int ch = 0; ch < 3; ch++)
                worst_mean = fmax(worst_mean, fabs(lv[ch] - mean[ch]) / fabs(mean[ch]));
        }
    }
    printf("%s: %u patches, %u vertices, %u T-vertices (expected %u): worst off the coarse "
           "edge's interpolation %.3g (area-weighted means alone: %.3g); %u other vertices "
           "off their mean by %.3g relative\n",
           c->name, mesh->patch_count, mesh->vertex_count, tvertices, c->expected_tvertices,
           worst_lerp, before, means, worst_mean);
    CHECK(tvertices == c->expected_tvertices);
    CHECK(worst_lerp <= 1e-6);
    if (c->expected_tvertices > 0)
        CHECK(before > 1e-3); /* the scene does exercise the constraint */
    CHECK(worst_mean <= 1e-12);
}

/* Reads back the lit mesh written as OBJ. */
static void check_lit_mesh(const seam_case *c, const rad_mesh *mesh, const rad_rgb *B,
                           const rad_rgb *L)
{
    char name[64];
    snprintf(name, sizeof(name), "%s.obj", c->name);
    rad_error error;
    CHECK(rad_lit_mesh_write(mesh, B, test_path(name), NULL, &error) == RAD_OK);
    size_t size = 0;
    char *text = (char *)test_read_bytes(test_path(name), &size);
    CHECK(text != NULL);
    if (!text)
        return;
    uint32_t expected_vertices = mesh->vertex_count + c->expected_added;
    rad_vec3 *position = calloc(expected_vertices + 1, sizeof(*position));
    rad_rgb *radiance = calloc(expected_vertices + 1, sizeof(*radiance));
    uint32_t (*face)[3] = calloc(4 * (size_t)mesh->patch_count * 8, sizeof(*face));
    uint32_t vertices = 0, radiance_lines = 0, faces = 0, bad_radiance = 0, bad_index = 0;
    text = realloc(text, size + 1);
    text[size] = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        double x, y, z, r, g, b;
        unsigned f[6];
        if (sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3 && vertices < expected_vertices) {
            position[vertices++] = (rad_vec3){x, y, z};
        } else if (sscanf(line, "#radiance %lf %lf %lf", &r, &g, &b) == 3 &&
                   radiance_lines < expected_vertices) {
            radiance[radiance_lines] = (rad_rgb){r, g, b};
            if (radiance_lines < mesh->vertex_count) {
                const rad_rgb *expected = &L[radiance_lines];
                bad_radiance += fabs(r - expected->r) > 1e-8 * fabs(expected->r) ||
                                fabs(g - expected->g) > 1e-8 * fabs(expected->g) ||
                                fabs(b - expected->b) > 1e-8 * fabs(expected->b);
            }
            radiance_lines++;
        } else if (sscanf(line, "f %u//%u %u//%u %u//%u", &f[0], &f[1], &f[2], &f[3], &f[4],
                          &f[5]) == 6 &&
                   faces < 4 * mesh->patch_count * 8) {
            for (int k = 0; k < 3; k++) {
                bad_index += f[2 * k] < 1 || f[2 * k] > expected_vertices;
                face[faces][k] = f[2 * k] - 1;
            }
            faces++;
        }
    }
    free(text);
    CHECK(vertices == expected_vertices);
    CHECK(radiance_lines == expected_vertices);
    /* an added vertex lies strictly inside an edge of a patch of its own region, which the
     * file's faces do not show: found in the mesh, and its radiance is the interpolation
     * along that edge of the region's values */
    uint32_t bad_added = 0;
    for (uint32_t v = mesh->vertex_count; v < vertices; v++) {
        bool found = false;
        for (uint32_t p = 0; p < mesh->patch_count && !found; p++) {
            const rad_patch *patch = &mesh->patches[p];
            for (uint32_t k = 0; k < patch->vertex_count && !found; k++) {
                uint32_t a = patch->vertex[k], b = patch->vertex[(k + 1) % patch->vertex_count];
                double t = inside_segment(mesh->vertices[a], mesh->vertices[b], position[v],
                                          1e-7);
                if (t < 0)
                    continue;
                const double *la = &L[a].r, *lb = &L[b].r, *lv = &radiance[v].r;
                bool agree = true;
                for (int ch = 0; ch < 3; ch++)
                    agree = agree && fabs(lv[ch] - (la[ch] + t * (lb[ch] - la[ch]))) <=
                                         1e-6 * fabs(la[ch]) + 1e-6;
                found = agree;
            }
        }
        bad_added += !found;
    }
    CHECK(bad_added == 0);
    CHECK(bad_radiance == 0);
    CHECK(bad_index == 0);
    uint32_t junctions = 0, back = 0, degenerate = 0;
    double area = 0;
    for (uint32_t f = 0; f < faces && bad_index == 0; f++) {
        rad_vec3 p[3];
        for (int k = 0; k < 3; k++)
            p[k] = position[face[f][k]];
        double cross_z = (p[1].x - p[0].x) * (p[2].y - p[0].y) -
                         (p[1].y - p[0].y) * (p[2].x - p[0].x);
        area += 0.5 * cross_z;
        back += cross_z < 0;
        degenerate += fabs(cross_z) < 1e-9;
        for (uint32_t v = 0; v < vertices; v++)
            for (int k = 0; k < 3; k++)
                if (v != face[f][k] && v != face[f][(k + 1) % 3] &&
                    inside_segment(p[k], p[(k + 1) % 3], position[v], 1e-7) >= 0)
                    junctions++;
    }
    printf("%s: %u vertices (%u added), %u faces, area %.9g (expected %.9g), T-junctions %u, "
           "back faces %u, degenerate %u\n",
           name, vertices, vertices - mesh->vertex_count, faces, area, c->area, junctions, back,
           degenerate);
    CHECK(junctions == 0);
    CHECK(back == 0);
    CHECK(degenerate == 0);
    CHECK_NEAR(area, c->area, 1e-6);
    free(position);
    free(radiance);
    free(face);
}

/* Renders the square x in [0.5, 1.5], y in [0, 1] from straight above onto 256 x 256
 * pixels: the seam x = 1 falls between columns 127 and 128. */
static void check_render(const seam_case *c, const rad_mesh *mesh, const rad_rgb *B)
{
    rad_camera camera = {{1, 0.5, 1}, {1, 0.5, 0}, {0, 1, 0}, 2 * atan(0.5) * 180 / PI};
    rad_image *image = test_new_image(IMAGE_SIZE, IMAGE_SIZE);
    rad_render_options options = {.samples_per_pixel = 64, .seed = 3};
    rad_error error;
    CHECK(rad_render(mesh, B, &camera, &options, image, &error) == RAD_OK);
    double worst = 0, worst_elsewhere = 0, lo = INFINITY, hi = 0;
    for (uint32_t y = 0; y < IMAGE_SIZE; y++) {
        double p[IMAGE_SIZE];
        for (uint32_t x = 0; x < IMAGE_SIZE; x++) {
            p[x] = test_pixel(image, x, y)[0];
            lo = fmin(lo, p[x]);
            hi = fmax(hi, p[x]);
        }
        /* third difference: 0 for a linear function with a kink between 127 and 128, the
         * step itself for a jump there */
        for (uint32_t x = 2; x + 2 < IMAGE_SIZE; x++) {
            double d = fabs(-p[x - 2] + 3 * p[x - 1] - 3 * p[x] + p[x + 1]) / 2;
            if (x == IMAGE_SIZE / 2)
                worst = fmax(worst, d);
            else if (x < IMAGE_SIZE / 2 - 8 || x > IMAGE_SIZE / 2 + 8)
                worst_elsewhere = fmax(worst_elsewhere, d);
        }
    }
    printf("%s render: values %.4f to %.4f; across the seam the worst step %.3g (elsewhere "
           "%.3g)\n",
           c->name, lo, hi, worst, worst_elsewhere);
    CHECK(lo > 1.4 && hi < 3.1); /* 1 + 0.5 x + y over the square, reconstructed */
    CHECK(worst < 2e-3 * hi);
    rad_image_destroy(image);
}

static void run_case(const seam_case *c)
{
    char name[64];
    snprintf(name, sizeof(name), "%s-scene.obj", c->name);
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    CHECK(rad_scene_load(test_write_file(name, c->obj), NULL, &scene, &error) == RAD_OK);
    if (scene)
        CHECK(rad_mesh_build(scene, c->patch_size, &mesh, &error) == RAD_OK);
    if (!mesh) {
        rad_scene_destroy(scene);
        return;
    }
    rad_rgb *B = calloc(mesh->patch_count, sizeof(*B));
    rad_rgb *L = calloc(mesh->vertex_count, sizeof(*L));
    set_field(mesh, B);
    rad_reconstruct_vertices(mesh, B, L);
    check_vertices(c, mesh, B, L);
    check_lit_mesh(c, mesh, B, L);
    if (c->render_seam)
        check_render(c, mesh, B);
    free(B);
    free(L);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
}

int main(void)
{
    const char *quads = "o floor\n"
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 3 0 0\nv 3 3 0\n"
                        "f 1 2 3 4\nf 2 5 6 3\n";
    const char *triangles = "o floor\n"
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 0\n"
                            "f 1 2 3\nf 2 4 3\n";
    /* quad 2 against trapezoid 6: 1 + 5 - 2 (gcd 2) */
    seam_case nested = {"nested", quads, 0.5, 4, 5, true, 0};
    /* quad 3 against trapezoid 8: 2 + 7 */
    seam_case crossed = {"crossed", quads, 0.4, 9, 5, true, 0};
    /* triangle 3 against triangle 5: 2 + 4; areas 0.5 and 1.5 */
    seam_case fan = {"triangles", triangles, 0.5, 6, 2, false, 0};
    /* a unit square framed by four trapezoids out to a 3 x 3 square: at patch size 1 the
     * square is one patch with 2 T-vertices on each of its 4 edges (1 against 3) */
    const char *frame = "o floor\n"
                        "v 1 1 0\nv 2 1 0\nv 2 2 0\nv 1 2 0\n"
                        "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\n"
                        "f 1 2 3 4\nf 5 6 2 1\nf 6 7 3 2\nf 7 8 4 3\nf 8 5 1 4\n";
    seam_case framed = {"frame", frame, 1, 8, 9, false, 0};
    /* the quads in two materials: two regions, each keeping its values, whose common edge
     * gets an added vertex for each of the other side's inner points: 4 (2 against 6) and
     * 9 (3 against 8) */
    test_write_file("two.mtl", "newmtl left\nKd 0.5 0.5 0.5\nnewmtl right\nKd 0.4 0.4 0.4\n");
    const char *two = "mtllib two.mtl\no floor\n"
                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 3 0 0\nv 3 3 0\n"
                      "usemtl left\nf 1 2 3 4\nusemtl right\nf 2 5 6 3\n";
    seam_case materials = {"materials", two, 0.5, 0, 5, false, 4};
    seam_case materials_crossed = {"materials-crossed", two, 0.4, 0, 5, false, 9};
    run_case(&nested);
    run_case(&crossed);
    run_case(&fan);
    run_case(&framed);
    run_case(&materials);
    run_case(&materials_crossed);
    return test_finish("test_seams");
}
