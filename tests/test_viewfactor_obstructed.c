/*
 * test_viewfactor_obstructed.c - view factors where obstructions hide most segments, against
 * closed forms and the test's own Monte-Carlo runs (issue 17): a tube inside a coaxial
 * obstruction tube inside an enclosing sphere, which sees the sphere only through the
 * tubes' open ends (Howell's coaxial-cylinder factor, and brute-force ray casting against
 * every triangle), its row summing to 1 when the blocker is a surface too, and two plates
 * seen through a slot narrower than the sampling strata, and a street canyon of a generated
 * city seen through the gap between buildings (16 seeds: at most 2 outside the 95 % bound,
 * none outside twice it), a diamond touching a floor's plane past a low wall, and plates
 * behind grids of 50 and 160 small squares. Each
 * other factor must lie within its reported error bound of the reference. Not here: the
 * unobstructed closed forms (test_viewfactors.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const double pi = 3.14159265358979323846;

static char text[1 << 18];

/* xorshift64: the test's own random numbers in [0, 1) */
static double uniform(uint64_t *state)
{
    *state ^= *state << 13, *state ^= *state >> 7, *state ^= *state << 17;
    return (double)(*state >> 11) * (1.0 / 9007199254740992.0);
}

/* A tube (no caps) of radius r and height h centred on the origin along z: `segments`
 * around, `bands` along, facing out or in. Written as an OBJ file; returns its path. */
static const char *write_tube(const char *name, double r, double h, int segments, int bands,
                              bool outward)
{
    size_t n = 0;
    for (int b = 0; b <= bands; b++)
        for (int s = 0; s < segments; s++) {
            double a = 2 * pi * s / segments;
            n += (size_t)snprintf(text + n, sizeof(text) - n, "v %.17g %.17g %.17g\n",
                                  r * cos(a), r * sin(a), -h / 2 + h * b / bands);
        }
    for (int b = 0; b < bands; b++)
        for (int s = 0; s < segments; s++) {
            int q[4] = {b * segments + s + 1, b * segments + (s + 1) % segments + 1,
                        (b + 1) * segments + (s + 1) % segments + 1, (b + 1) * segments + s + 1};
            if (outward)
                n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d %d\n", q[0], q[1],
                                      q[2], q[3]);
            else
                n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d %d\n", q[3], q[2],
                                      q[1], q[0]);
        }
    return test_write_file(name, text);
}

/* A UV sphere of radius R facing in, `bands` latitude bands. */
static const char *write_sphere(const char *name, double R, int bands)
{
    int segments = 2 * bands;
    size_t n = (size_t)snprintf(text, sizeof(text), "v 0 0 %.17g\n", R);
    for (int b = 1; b < bands; b++)
        for (int s = 0; s < segments; s++) {
            double theta = pi * b / bands, phi = 2 * pi * s / segments;
            n += (size_t)snprintf(text + n, sizeof(text) - n, "v %.17g %.17g %.17g\n",
                                  R * sin(theta) * cos(phi), R * sin(theta) * sin(phi),
                                  R * cos(theta));
        }
    n += (size_t)snprintf(text + n, sizeof(text) - n, "v 0 0 %.17g\n", -R);
    int south = 2 + (bands - 1) * segments;
#define RING(b, s) (2 + ((b) - 1) * segments + ((s) % segments))
    for (int s = 0; s < segments; s++) {
        /* counter-clockwise seen from inside */
        n += (size_t)snprintf(text + n, sizeof(text) - n, "f 1 %d %d\n", RING(1, s + 1),
                              RING(1, s));
        n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d\n", south,
                              RING(bands - 1, s), RING(bands - 1, s + 1));
        for (int b = 1; b + 1 < bands; b++)
            n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d %d\n", RING(b, s + 1),
                                  RING(b + 1, s + 1), RING(b + 1, s), RING(b, s));
    }
#undef RING
    return test_write_file(name, text);
}

/* Howell's catalogue: from the inside of an outer cylinder (radius r2) to the outside of a
 * coaxial inner one (r1), both of length l. */
static double coaxial_outer_to_inner(double r1, double r2, double l)
{
    double R = r2 / r1, L = l / r1, A = L * L + R * R - 1, B = L * L - R * R + 1;
    return 1 / R - 1 / (pi * R) *
                       (acos(B / A) - 1 / (2 * L) *
                                          (sqrt((A + 2) * (A + 2) - 4 * R * R) *
                                               acos(B / (R * A)) +
                                           B * asin(1 / R) - pi * A / 2));
}

static uint32_t surface_named(const rad_scene *scene, const char *name)
{
    for (uint32_t s = 0; s < scene->surface_count; s++)
        if (strcmp(scene->surfaces[s].name, name) == 0)
            return s;
    test_fail(__FILE__, __LINE__, "no surface %s", name);
    return 0;
}

/* The scene of these files and its matrix (default options, but exact_occluders when not
 * 0); false, with nothing held, when either fails. */
static bool load_and_compute_exact(const rad_scene_file *files, uint32_t count,
                                   uint32_t exact_occluders, rad_scene **scene,
                                   rad_viewfactor_matrix **m, rad_viewfactor_report *report)
{
    rad_error error = {0};
    *scene = NULL;
    *m = NULL;
    CHECK(rad_scene_load_files(files, count, NULL, scene, &error) == RAD_OK);
    if (!*scene)
        return false;
    rad_viewfactor_options options = {.exact_occluders = exact_occluders}; /* 0: default */
    CHECK(rad_viewfactor_matrix_compute(*scene, &options, m, report, &error) == RAD_OK);
    if (!*m) {
        rad_scene_destroy(*scene);
        *scene = NULL;
        return false;
    }
    return true;
}

static bool load_and_compute(const rad_scene_file *files, uint32_t count, rad_scene **scene,
                             rad_viewfactor_matrix **m, rad_viewfactor_report *report)
{
    return load_and_compute_exact(files, count, 0, scene, m, report);
}

/* F_IJ and its error bound (0 and 0 when not stored). */
static double factor(const rad_viewfactor_matrix *m, uint32_t I, uint32_t J, double *bound)
{
    *bound = 0;
    for (uint64_t k = m->row_start[I]; k < m->row_start[I + 1]; k++)
        if (m->column[k] == J) {
            *bound = m->error_bound[k];
            return m->value[k];
        }
    return 0;
}

/* The share of cosine-distributed rays from uniform points of surface `from` whose first
 * hit is on surface `to`: brute-force ray casting against every triangle of the scene, an
 * independent code path (no polygons, no quadrature, no occluder tree). */
static double monte_carlo(const rad_scene *scene, uint32_t from, uint32_t to, uint32_t rays,
                          double *standard_error)
{
    rad_error error = {0};
    rad_tracer *tracer = NULL;
    CHECK(rad_tracer_create_for_scene(RAD_TRACER_BRUTE_FORCE, scene, &tracer, &error) ==
          RAD_OK);
    const rad_surface *s = &scene->surfaces[from];
    double *cumulative = malloc(s->triangle_count * sizeof(double));
    rad_ray *batch = malloc(4096 * sizeof(rad_ray));
    rad_hit *hits = malloc(4096 * sizeof(rad_hit));
    CHECK(cumulative && batch && hits && tracer);
    double total = 0;
    for (uint32_t t = 0; t < s->triangle_count; t++) {
        const rad_triangle *tri = &scene->triangles[s->first_triangle + t];
        rad_vec3 a = scene->positions[tri->vertex[0]], b = scene->positions[tri->vertex[1]],
                 c = scene->positions[tri->vertex[2]];
        double u[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, v[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        total += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        cumulative[t] = total;
    }
    uint64_t state = 0x9E3779B97F4A7C15ull, reached = 0;
    for (uint32_t done = 0; done < rays;) {
        uint32_t count = rays - done < 4096 ? rays - done : 4096;
        for (uint32_t k = 0; k < count; k++) {
            double pick = uniform(&state) * total;
            uint32_t t = 0;
            while (t + 1 < s->triangle_count && cumulative[t] < pick)
                t++;
            const rad_triangle *tri = &scene->triangles[s->first_triangle + t];
            rad_vec3 a = scene->positions[tri->vertex[0]], b = scene->positions[tri->vertex[1]],
                     c = scene->positions[tri->vertex[2]];
            double r1 = sqrt(uniform(&state)), r2 = uniform(&state);
            double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2;
            double x[3] = {wa * a.x + wb * b.x + wc * c.x, wa * a.y + wb * b.y + wc * c.y,
                           wa * a.z + wb * b.z + wc * c.z};
            double e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e2[3] = {c.x - a.x, c.y - a.y,
                                                                       c.z - a.z};
            double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
            double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int d = 0; d < 3; d++)
                n[d] /= ln;
            /* an orthonormal frame (t1, t2, n) */
            double h[3] = {fabs(n[0]) < 0.6 ? 1 : 0, fabs(n[0]) < 0.6 ? 0 : 1, 0};
            double t1[3] = {h[1] * n[2] - h[2] * n[1], h[2] * n[0] - h[0] * n[2],
                            h[0] * n[1] - h[1] * n[0]};
            double lt = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
            for (int d = 0; d < 3; d++)
                t1[d] /= lt;
            double t2[3] = {n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2],
                            n[0] * t1[1] - n[1] * t1[0]};
            double q = uniform(&state), phi = 2 * pi * uniform(&state), rr = sqrt(q);
            double dx = rr * cos(phi), dy = rr * sin(phi), dz = sqrt(fmax(0, 1 - q));
            rad_ray *ray = &batch[k];
            for (int d = 0; d < 3; d++) {
                ray->origin[d] = (float)x[d];
                ray->direction[d] = (float)(dx * t1[d] + dy * t2[d] + dz * n[d]);
            }
            ray->t_near = 1e-5f;
            ray->t_far = INFINITY;
        }
        rad_tracer_intersect(tracer, batch, count, hits);
        for (uint32_t k = 0; k < count; k++)
            reached += hits[k].triangle != RAD_NO_HIT &&
                       scene->triangles[hits[k].triangle].surface == to;
        done += count;
    }
    double share = (double)reached / rays;
    *standard_error = sqrt(share * (1 - share) / rays);
    free(cumulative);
    free(batch);
    free(hits);
    rad_tracer_destroy(tracer);
    return share;
}

/* The case: a tube (r 0.125, h 1) inside a coaxial tube (r 0.25, h 1) inside a
 * sphere (r 2). The inner tube sees the sphere only through the annulus' open ends:
 * F = 1 - F(inner -> outer tube) = 1 - (r2 / r1) F(outer -> inner) by reciprocity.
 * exact_occluders: 4 (the pairs seen through the annulus are sampled), or enough for every
 * pair to be clipped exactly (0, the default, is that). Those pairs' light comes from a sliver just
 * below the tube's rim, between all the quadrature points: that integral once came out
 * 0.06 % low with a bound 10 times smaller (the tube's row 0.99994, bound 6e-6). */
static void check_tube_in_tube(bool blocker_is_surface, uint32_t exact_occluders)
{
    const char *tube = write_tube("tube.obj", 0.125, 1, 32, 2, true);
    const char *blocker = write_tube("blocker.obj", 0.25, 1, 32, 2, false);
    const char *sphere = write_sphere("sphere.obj", 2, 8);
    rad_scene_file files[3] = {{tube, 0, false},
                               {blocker, blocker_is_surface ? 0 : RAD_SURFACE_OBSTRUCTION,
                                false},
                               {sphere, 0, false}};
    rad_scene *scene;
    rad_viewfactor_matrix *m;
    rad_viewfactor_report report;
    if (!load_and_compute_exact(files, 3, exact_occluders, &scene, &m, &report))
        return;
    uint32_t T = surface_named(scene, "tube"), S = surface_named(scene, "sphere"),
             B = surface_named(scene, "blocker");
    double bound, F = factor(m, T, S, &bound);
    double closed = 1 - 2 * coaxial_outer_to_inner(0.125, 0.25, 1);
    /* the same triangles either way (only the blocker's flag differs): one run serves both */
    static double reference = -1, standard_error;
    if (reference < 0)
        reference = monte_carlo(scene, T, S, 400000, &standard_error);
    printf("tube in tube in sphere (blocker %s, exact behind %u): F(tube -> sphere) %.6f, bound "
           "%.2g; brute-force Monte Carlo %.6f +- %.2g; closed form (round tubes) %.6f; pairs: "
           "%llu unobstructed, %llu exact, %llu sampled (%llu saw nothing), %llu proven "
           "hidden; largest bound %.2g\n",
           blocker_is_surface ? "a surface" : "an obstruction", report.exact_occluders, F,
           bound, reference,
           standard_error, closed, (unsigned long long)report.unobstructed_pairs,
           (unsigned long long)report.exact_pairs, (unsigned long long)report.sampled_pairs,
           (unsigned long long)report.unseen_pairs, (unsigned long long)report.hidden_pairs,
           report.largest_error_bound);
    /* the closed form is for round tubes; 32-gons differ from it by about 0.4 % */
    CHECK_NEAR(closed, 0.0891316, 1e-5);
    CHECK_NEAR(reference, closed, 0.01);
    CHECK_NEAR(F, closed, 0.01);
    /* the meshed scene's own value: within the reported bound (and the reference's noise) */
    CHECK(fabs(F - reference) <= 3 * standard_error + bound);
    CHECK(bound > 0 && bound <= report.largest_error_bound);
    /* every polygon pair is counted under one method */
    CHECK(report.unobstructed_pairs + report.exact_pairs + report.sampled_pairs +
              report.hidden_pairs ==
          report.polygon_pairs);
    CHECK(report.obstructed_pairs == report.exact_pairs + report.sampled_pairs);
    if (blocker_is_surface) {
        /* the inner tube sees the outer one or, past its ends, the sphere: its row is 1 */
        double row = 0, row_bound = 0, b;
        for (uint32_t J = 0; J < scene->surface_count; J++) {
            row += factor(m, T, J, &b);
            row_bound += b;
        }
        double to_blocker = factor(m, T, B, &b);
        printf("  tube row sum %.6f (bound %.2g); F(tube -> blocker) %.6f, closed form %.6f\n",
               row, row_bound, to_blocker, 2 * coaxial_outer_to_inner(0.125, 0.25, 1));
        CHECK(fabs(row - 1) <= row_bound);
        CHECK(row_bound < 2e-3);
        if (report.exact_occluders >= 100) {
            /* the pairs exact but a few past the work budget: the row to the accuracy
             * (1e-4 x sqrt(F) a factor) */
            CHECK(report.sampled_pairs <= report.exact_pairs / 1000);
            CHECK(row_bound <= 1e-4 * (sqrt(to_blocker) + sqrt(F)));
        }
    }
    rad_viewfactor_matrix_destroy(m);
    rad_scene_destroy(scene);
}

/* Two unit plates, "one" at z = 0 (facing up) and "two" at z = 1 (facing down), with
 * `between` (OBJ lines, vertices from 9 on) at z = 0.5: written as `name`, their matrix
 * computed with `exact_occluders`. Returns F(one -> two) in *F and its bound; false when
 * the scene or the matrix failed. */
static bool plates_factor(const char *name, const char *between, uint32_t exact_occluders,
                          rad_viewfactor_report *report, double *F, double *bound)
{
    size_t n = (size_t)snprintf(text, sizeof(text),
                                "o one\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                                "o two\nv 0 0 1\nv 0 1 1\nv 1 1 1\nv 1 0 1\nf 5 6 7 8\n%s",
                                between);
    CHECK(n < sizeof(text));
    const char *path = test_write_file(name, text);
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (!scene)
        return false;
    rad_viewfactor_matrix *m = NULL;
    rad_viewfactor_options options = {.exact_occluders = exact_occluders};
    CHECK(rad_viewfactor_matrix_compute(scene, &options, &m, report, &error) == RAD_OK);
    if (m)
        *F = factor(m, surface_named(scene, "one"), surface_named(scene, "two"), bound);
    rad_viewfactor_matrix_destroy(m);
    rad_scene_destroy(scene);
    return m != NULL;
}

/* The share of 4 M cosine rays from uniform points of the lower plate (random numbers from
 * `seed`) that land on the upper one and that `passes` lets through z = 0.5 at (x, y): the
 * test's own geometry, no ray tracer. */
static double plates_monte_carlo(bool (*passes)(double x, double y), uint64_t seed,
                                 double *standard_error)
{
    uint64_t state = seed, hits = 0, samples = 4000000;
    for (uint64_t k = 0; k < samples; k++) {
        double x = uniform(&state), y = uniform(&state), q = uniform(&state);
        double phi = 2 * pi * uniform(&state), r = sqrt(q), dz = sqrt(fmax(0, 1 - q));
        double dx = r * cos(phi) / dz, dy = r * sin(phi) / dz;
        double x1 = x + dx, y1 = y + dy;
        hits += x1 >= 0 && x1 <= 1 && y1 >= 0 && y1 <= 1 && passes(x + 0.5 * dx, y + 0.5 * dy);
    }
    double reference = (double)hits / samples;
    *standard_error = sqrt(reference * (1 - reference) / samples);
    return reference;
}

/* Rectangles at z = 0.5 as OBJ lines after `v` vertices: x0 y0 x1 y1 each. */
static size_t write_rectangles(char *out, size_t size, double (*box)[4], int count, int v)
{
    size_t n = 0;
    for (int k = 0; k < count; k++, v += 4)
        n += (size_t)snprintf(out + n, size - n,
                              "v %.17g %.17g 0.5\nv %.17g %.17g 0.5\nv %.17g %.17g 0.5\n"
                              "v %.17g %.17g 0.5\nf %d %d %d %d\n",
                              box[k][0], box[k][1], box[k][2], box[k][1], box[k][2], box[k][3],
                              box[k][0], box[k][3], v + 1, v + 2, v + 3, v + 4);
    return n;
}

static bool through_slot(double x, double y)
{
    (void)y;
    return x >= 0.49 && x <= 0.51;
}

/* Plates 1 x 1 at z = 0 (facing up) and z = 1 (facing down); between them at z = 0.5 a
 * wall with a slot x in [0.49, 0.51] across it, 0.02 wide: narrower than the cells of
 * the first look (0.5) and of the finest sampling round (1/32). The wall is two rectangles
 * (4 triangles: shadows clipped exactly) or each split n x n (sampled, unless
 * `exact_occluders` takes them all: clipped exactly, to accuracy x sqrt(F unobstructed),
 * F unobstructed = 0.19982 for unit squares 1 apart, Howell's catalogue). The reference
 * counts cosine rays from uniform points of the lower plate that cross z = 0.5 within the
 * slot and land on the upper plate. */
static void check_slot(int split, uint32_t exact_occluders)
{
    static char wall[1 << 17];
    double box[2 * 36][4];
    int count = 0;
    const double part[2][2] = {{-2, 0.49}, {0.51, 3}};
    for (int side = 0; side < 2; side++)
        for (int i = 0; i < split; i++)
            for (int j = 0; j < split; j++, count++) {
                box[count][0] = part[side][0] + (part[side][1] - part[side][0]) * i / split;
                box[count][2] = part[side][0] + (part[side][1] - part[side][0]) * (i + 1) / split;
                box[count][1] = -2 + 5.0 * j / split;
                box[count][3] = -2 + 5.0 * (j + 1) / split;
            }
    size_t n = (size_t)snprintf(wall, sizeof(wall), "o wall\n");
    write_rectangles(wall + n, sizeof(wall) - n, box, count, 8);
    rad_viewfactor_report report;
    double F = 0, bound = 0;
    if (!plates_factor("slot.obj", wall, exact_occluders, &report, &F, &bound))
        return;
    double standard_error,
        reference = plates_monte_carlo(through_slot, 0x2545F4914F6CDD1Dull, &standard_error);
    printf("slot 0.02 wide, wall as %d triangles, exact behind %u: F %.6f, bound %.2g; Monte "
           "Carlo %.6f +- %.2g; pairs: %llu exact, %llu sampled, %llu proven hidden\n",
           4 * split * split, report.exact_occluders, F, bound, reference, standard_error,
           (unsigned long long)report.exact_pairs, (unsigned long long)report.sampled_pairs,
           (unsigned long long)report.hidden_pairs);
    CHECK(F > 0);
    CHECK(fabs(F - reference) <= 3 * standard_error + bound);
    CHECK(report.hidden_pairs == 0);
    CHECK(report.exact_occluders == (exact_occluders ? exact_occluders : RAD_MAX_EXACT_OCCLUDERS));
    if (4u * (uint32_t)(split * split) <= report.exact_occluders) {
        CHECK(report.exact_pairs == 1);
        CHECK(bound <= 1e-4 * sqrt(0.19982));
    } else {
        CHECK(report.sampled_pairs == 1);
        CHECK(bound > 0);
    }
}

/* A wall with no slot, as many triangles: the pair is proven hidden (one plane covers the
 * window), F = 0 with no bound. */
static void check_proven_hidden(void)
{
    size_t n = (size_t)snprintf(text, sizeof(text),
                                "o one\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                                "o two\nv 0 0 1\nv 0 1 1\nv 1 1 1\nv 1 0 1\nf 5 6 7 8\no wall\n");
    int v = 8;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double x0 = -1 + 0.75 * i, x1 = -1 + 0.75 * (i + 1);
            double y0 = -1 + 0.75 * j, y1 = -1 + 0.75 * (j + 1);
            n += (size_t)snprintf(text + n, sizeof(text) - n,
                                  "v %.17g %.17g 0.5\nv %.17g %.17g 0.5\nv %.17g %.17g 0.5\n"
                                  "v %.17g %.17g 0.5\nf %d %d %d %d\n",
                                  x0, y0, x1, y0, x1, y1, x0, y1, v + 1, v + 2, v + 3, v + 4);
            v += 4;
        }
    const char *path = test_write_file("wall.obj", text);
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load(path, NULL, &scene, &error) == RAD_OK);
    if (!scene)
        return;
    /* without sight rays the pair must be proven hidden; with them (the default) no ray
     * meets it, and it is 0 without a first look or a proof */
    for (int sight = 0; sight < 2; sight++) {
        rad_viewfactor_matrix *m = NULL;
        rad_viewfactor_report report;
        rad_viewfactor_options options = {.sight_rays = sight ? 0 : RAD_SIGHT_RAYS_NONE};
        CHECK(rad_viewfactor_matrix_compute(scene, &options, &m, &report, &error) == RAD_OK);
        if (m) {
            double bound, F = factor(m, surface_named(scene, "one"),
                                     surface_named(scene, "two"), &bound);
            printf("wall of 32 triangles, %s: F %.3g bound %.3g, %llu proven hidden, %llu "
                   "sampled, %llu surface pairs no sight ray met\n",
                   sight ? "sight rays" : "no sight rays", F, bound,
                   (unsigned long long)report.hidden_pairs,
                   (unsigned long long)report.sampled_pairs,
                   (unsigned long long)report.unmet_pairs);
            CHECK(F == 0 && bound == 0);
            CHECK(report.hidden_pairs == (sight ? 0u : 1u));
            CHECK(sight ? report.unmet_pairs >= 1 : report.unmet_pairs == 0);
        }
        rad_viewfactor_matrix_destroy(m);
    }
    rad_scene_destroy(scene);
}

/* Box buildings [x0, x1] x [0, h] x [z0, z1] (walls and roof, facing out) appended to the
 * OBJ text at n, vertices numbered from *v + 1. */
static size_t append_building(size_t n, int *v, double x0, double x1, double z0, double z1,
                              double h)
{
    const double corner[8][3] = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1},
                                 {x0, h, z0}, {x1, h, z0}, {x1, h, z1}, {x0, h, z1}};
    for (int k = 0; k < 8; k++)
        n += (size_t)snprintf(text + n, sizeof(text) - n, "v %.17g %.17g %.17g\n", corner[k][0],
                              corner[k][1], corner[k][2]);
    /* counter-clockwise seen from outside: -z, +x, +z, -x walls, then the roof */
    const int face[5][4] = {{1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 8, 4}, {4, 8, 5, 1}, {5, 8, 7, 6}};
    for (int f = 0; f < 5; f++)
        n += (size_t)snprintf(text + n, sizeof(text) - n, "f %d %d %d %d\n", *v + face[f][0],
                              *v + face[f][1], *v + face[f][2], *v + face[f][3]);
    *v += 8;
    return n;
}

/* A street canyon of a generated city block: a wall (10 x 20.9 m, facing +z) and a low roof
 * 44-54 m away (10 x 10 m at 7.8 m, facing up) past three taller buildings; they see each
 * other only through the street between the buildings, over about 7 % of the exchange,
 * and only from the wall's part above the roof's plane. Sampling the whole wall, most
 * segments weighed nothing, and a few visible ones among many blocked made a replicates'
 * spread far below the error (seed 1 of the 1k city: 0.04 % visible, bound 80 times too
 * small). F(roof -> wall) against brute-force ray casting, with 16 seeds. */
static void check_street_canyon(void)
{
    const char *wall = test_write_file("wall.obj", "v 112 0 176\nv 122 0 176\n"
                                                   "v 122 20.8667 176\nv 112 20.8667 176\n"
                                                   "f 1 2 3 4\n");
    const char *roof = test_write_file("roof.obj", "v 130 7.81022 220\nv 130 7.81022 230\n"
                                                   "v 140 7.81022 230\nv 140 7.81022 220\n"
                                                   "f 1 2 3 4\n");
    int v = 0;
    size_t n = 0;
    n = append_building(n, &v, 112, 122, 184, 194, 22.8253);
    n = append_building(n, &v, 112, 122, 202, 212, 24.7839);
    n = append_building(n, &v, 130, 140, 202, 212, 14.9258);
    const char *blocks = test_write_file("canyon_blocks.obj", text);
    rad_scene_file files[3] = {{wall, 0, false},
                               {roof, 0, false},
                               {blocks, RAD_SURFACE_OBSTRUCTION, false}};
    rad_scene *scene = NULL;
    rad_error error = {0};
    CHECK(rad_scene_load_files(files, 3, NULL, &scene, &error) == RAD_OK);
    if (!scene)
        return;
    uint32_t W = surface_named(scene, "wall"), R = surface_named(scene, "roof");
    double standard_error, reference = monte_carlo(scene, R, W, 2000000, &standard_error);
    CHECK(reference > 5 * standard_error);
    /* The segments' outcome depends on the seed. The bound is a 95 % one, so 16 seeds may
     * see one or two outside it by chance, but none outside twice it. */
    unsigned outside = 0;
    double worst = 0;
    for (uint64_t seed = 1; seed <= 16; seed++) {
        rad_viewfactor_options options = {.seed = seed, .exact_occluders = 4}; /* sampled */
        rad_viewfactor_matrix *m = NULL;
        rad_viewfactor_report report;
        CHECK(rad_viewfactor_matrix_compute(scene, &options, &m, &report, &error) == RAD_OK);
        if (!m)
            break;
        CHECK(report.sampled_pairs == 1);
        double bound, F = factor(m, R, W, &bound);
        outside += fabs(F - reference) > 3 * standard_error + bound;
        worst = fmax(worst, fabs(F - reference) / (3 * standard_error + 2 * bound));
        if (seed == 1)
            printf("street canyon: F(roof -> wall) %.4g, bound %.2g (seed 1); brute-force Monte "
                   "Carlo %.4g +- %.2g\n",
                   F, bound, reference, standard_error);
        rad_viewfactor_matrix_destroy(m);
    }
    printf("  16 seeds: %u outside their bound (+ 3 standard errors); largest miss %.2f of "
           "twice it\n",
           outside, worst);
    CHECK(outside <= 2);
    CHECK(worst <= 1);
    rad_scene_destroy(scene);
}

/* A floor (unit square, facing up) and a diamond (2 m^2) standing on its plane 3 m away
 * (facing it, its lowest corner touching the floor's plane) past a low wall: the diamond's
 * part in front of the floor's plane is the diamond with that corner twice, which once
 * made the exact path drop the wall (the unobstructed 0.0268 for about 0.0146). */
static void check_corner_on_plane(void)
{
    const char *floor = test_write_file("floor.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                     "f 1 2 3 4\n");
    const char *diamond = test_write_file("diamond.obj", "v 3 0.5 0\nv 3 -0.5 1\nv 3 0.5 2\n"
                                                         "v 3 1.5 1\nf 1 2 3 4\n");
    const char *wall = test_write_file("low_wall.obj", "v 2 -2 -1\nv 2 3 -1\nv 2 3 0.6\n"
                                                       "v 2 -2 0.6\nf 1 2 3 4\n");
    rad_scene_file files[3] = {
        {floor, 0, false}, {diamond, 0, false}, {wall, RAD_SURFACE_OBSTRUCTION, false}};
    rad_scene *scene;
    rad_viewfactor_matrix *m;
    rad_viewfactor_report report;
    if (!load_and_compute(files, 3, &scene, &m, &report))
        return;
    uint32_t F0 = surface_named(scene, "floor"), D = surface_named(scene, "diamond");
    double bound, F = factor(m, F0, D, &bound), standard_error;
    double reference = monte_carlo(scene, F0, D, 400000, &standard_error);
    printf("diamond on the floor's plane past a low wall: F %.5f, bound %.2g; brute-force "
           "Monte Carlo %.5f +- %.2g; %llu exact\n",
           F, bound, reference, standard_error, (unsigned long long)report.exact_pairs);
    CHECK(report.exact_pairs == 1);
    CHECK(fabs(F - reference) <= 3 * standard_error + bound);
    rad_viewfactor_matrix_destroy(m);
    rad_scene_destroy(scene);
}

/* The grid below: `grid_columns` x `grid_rows` squares over the unit square, each 0.6 x
 * 0.6 of its cell, centred. */
static int grid_columns, grid_rows;

static bool between_squares(double x, double y)
{
    if (!(x >= 0 && x < 1 && y >= 0 && y < 1))
        return true;
    double pitch_x = 1.0 / grid_columns, pitch_y = 1.0 / grid_rows;
    double cx = x - pitch_x * floor(x / pitch_x), cy = y - pitch_y * floor(y / pitch_y);
    return !(cx >= 0.2 * pitch_x && cx <= 0.8 * pitch_x && cy >= 0.2 * pitch_y &&
             cy <= 0.8 * pitch_y);
}

/* Plates 1 x 1 at z = 0 (up) and z = 1 (down) behind a grid of columns x rows small
 * squares at z = 0.5 (2 triangles each), against the test's own count of cosine rays from
 * the lower plate that pass between the squares and land on the upper one. Behind 4 exact
 * occluders the pair is sampled; by default (all of them) it is clipped exactly, to its
 * bound, and the bound to accuracy x sqrt(F unobstructed) (0.19982). The grid of 10 x 5
 * leaves at most SHADOW_MAX_PIECES visible pieces at every point; the one of 16 x 10
 * leaves more (some 40 squares' shadows on the upper plate at once), so its pair is
 * clipped on the second try, with room for more. (One of 20 x 12 is clipped too, but
 * its bound stays at 1.2 times the target: the deepest split cannot follow 80 kinks.) */
static void check_occluder_grid(int columns, int rows, uint32_t exact_occluders)
{
    static char grid[1 << 16];
    static double box[160][4];
    grid_columns = columns;
    grid_rows = rows;
    CHECK(columns * rows <= 160);
    if (columns * rows > 160)
        return;
    for (int i = 0; i < columns; i++)
        for (int j = 0; j < rows; j++) {
            double *b = box[rows * i + j], pitch_x = 1.0 / columns, pitch_y = 1.0 / rows;
            b[0] = pitch_x * (i + 0.2), b[1] = pitch_y * (j + 0.2);
            b[2] = pitch_x * (i + 0.8), b[3] = pitch_y * (j + 0.8);
        }
    size_t n = (size_t)snprintf(grid, sizeof(grid), "o grid\n");
    write_rectangles(grid + n, sizeof(grid) - n, box, columns * rows, 8);
    rad_viewfactor_report report;
    double F = 0, bound = 0;
    if (!plates_factor("grid.obj", grid, exact_occluders, &report, &F, &bound))
        return;
    double standard_error,
        reference = plates_monte_carlo(between_squares, 0x9E3779B97F4A7C15ull, &standard_error);
    printf("plates behind a grid of %d x %d squares, exact behind %u: F %.6f, bound %.2g; "
           "Monte Carlo %.6f +- %.2g; pairs: %llu exact (%llu on a second try), %llu "
           "sampled\n",
           columns, rows, report.exact_occluders, F, bound, reference, standard_error,
           (unsigned long long)report.exact_pairs, (unsigned long long)report.roomy_pairs,
           (unsigned long long)report.sampled_pairs);
    CHECK(fabs(F - reference) <= 3 * standard_error + bound);
    /* the pair meets its target (1e-4 x sqrt(F unobstructed)) only when clipped; the
     * sampled one stops at --max-rays far above it, and the run counts it short */
    if (report.exact_occluders >= 2u * (uint32_t)(columns * rows)) {
        CHECK(report.exact_pairs == 1 && report.sampled_pairs == 0);
        CHECK(report.roomy_pairs == (columns * rows > 50 ? 1u : 0u));
        CHECK(bound <= 1e-4 * sqrt(0.19982));
        CHECK(report.short_pairs == 0);
    } else {
        CHECK(report.sampled_pairs == 1);
        CHECK(bound > 1e-4 * sqrt(0.19982));
        CHECK(report.short_pairs == 1);
    }
}

int main(void)
{
    /* 4: the sampled path behind more occluders; 0: the default, every pair clipped */
    check_tube_in_tube(false, 4);
    check_tube_in_tube(true, 4);
    check_tube_in_tube(true, 0);
    check_slot(1, 4);
    check_slot(6, 4);
    check_slot(6, 0);
    check_occluder_grid(10, 5, 4);
    check_occluder_grid(10, 5, 0);
    check_occluder_grid(16, 10, 0);
    check_proven_hidden();
    check_street_canyon();
    check_corner_on_plane();
    return test_finish("test_viewfactor_obstructed");
}
