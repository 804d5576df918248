/*
 * raw_rays.c - benchmark: Embree's raw occlusion-ray rate on the Cornell box, the
 * reference that the form-factor phase of `radiosity render` is compared with.
 *
 * The scene's input triangles go into an Embree scene built the way the library's
 * occluder tracer builds it (one device with the default config, one triangle geometry
 * over shared float3 vertices padded by one vertex and uint3 indices, high build quality).
 * The rays are segments between random points of random patch pairs of the meshed scene
 * (t_near 1e-4, t_far 1 - 1e-4, mask 0xFFFFFFFF), all generated before timing starts.
 * They are traced with rtcOccluded1M in batches of 4096 with the default (incoherent)
 * context, one batch per OpenMP thread at a time, flush-to-zero and denormals-are-zero
 * set in every thread. Only the tracing is timed.
 *
 * usage: raw_rays [--patch-size MM] [--rays N] [--repeats R] [--threads T[,T...]]
 *   defaults: 21.5 mm, 4194304 rays (whole batches), 9 timed runs, threads 1,2
 * prints, per thread count, the median of the timed runs:
 *   raw_occlusion_rays_per_second threads=T value=RAYS_PER_SECOND
 * Lines starting with '#' are information only; RAW_RAYS_VERBOSE=1 adds every run's time.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include "radiosity.h"

enum { BATCH = 4096 };

#define SEGMENT_EPSILON 1e-4f
#define USAGE "usage: raw_rays [--patch-size MM] [--rays N] [--repeats R] [--threads T[,T...]]"

typedef struct settings {
    double patch_size;
    size_t rays;
    int repeats;
    int threads[16];
    int thread_count;
} settings;

static void die(const char *what)
{
    fprintf(stderr, "raw_rays: %s\n", what);
    exit(1);
}

static void usage_error(void)
{
    die(USAGE);
}

static void parse_arguments(int argc, char **argv, settings *s)
{
    s->patch_size = 21.5;
    s->rays = (size_t)1 << 22;
    s->repeats = 9;
    s->threads[0] = 1;
    s->threads[1] = 2;
    s->thread_count = 2;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--help") == 0 || strcmp(argv[a], "-h") == 0) {
            puts(USAGE);
            exit(0);
        }
        if (a + 1 >= argc)
            usage_error();
        const char *value = argv[++a];
        char *end = NULL;
        if (strcmp(argv[a - 1], "--patch-size") == 0) {
            s->patch_size = strtod(value, &end);
            if (*end || !(s->patch_size > 0))
                usage_error();
        } else if (strcmp(argv[a - 1], "--rays") == 0) {
            unsigned long long n = strtoull(value, &end, 10);
            if (*end || n < BATCH)
                usage_error();
            s->rays = (size_t)(n / BATCH * BATCH); /* whole batches only */
        } else if (strcmp(argv[a - 1], "--repeats") == 0) {
            long r = strtol(value, &end, 10);
            if (*end || r < 1 || r > 1000)
                usage_error();
            s->repeats = (int)r;
        } else if (strcmp(argv[a - 1], "--threads") == 0) {
            s->thread_count = 0;
            const char *p = value;
            while (*p && s->thread_count < 16) {
                long t = strtol(p, &end, 10);
                if (end == p || t < 1 || t > 1024 || (*end && *end != ','))
                    usage_error();
                s->threads[s->thread_count++] = (int)t;
                p = *end ? end + 1 : end;
            }
            if (s->thread_count == 0)
                usage_error();
        } else {
            usage_error();
        }
    }
}

/* SplitMix64: a small, fast generator; the seed is fixed so runs are comparable. */
static uint64_t rng_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double rng_uniform(uint64_t *state)
{
    return (double)(rng_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* A random point of the patch, as the pair engine places its sample points: bilinear for
 * quads, the area-preserving square-root warp for triangles. */
static rad_vec3 random_point(const rad_mesh *mesh, const rad_patch *patch, uint64_t *rng)
{
    double s = rng_uniform(rng), t = rng_uniform(rng);
    const rad_vec3 *v = mesh->vertices;
    rad_vec3 a = v[patch->vertex[0]], b = v[patch->vertex[1]], c = v[patch->vertex[2]];
    rad_vec3 p;
    if (patch->vertex_count == 4) {
        rad_vec3 d = v[patch->vertex[3]];
        double w[4] = {(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t};
        p.x = w[0] * a.x + w[1] * b.x + w[2] * c.x + w[3] * d.x;
        p.y = w[0] * a.y + w[1] * b.y + w[2] * c.y + w[3] * d.y;
        p.z = w[0] * a.z + w[1] * b.z + w[2] * c.z + w[3] * d.z;
    } else {
        double r = sqrt(s);
        double wa = 1 - r, wb = r * (1 - t), wc = r * t;
        p.x = wa * a.x + wb * b.x + wc * c.x;
        p.y = wa * a.y + wb * b.y + wc * c.y;
        p.z = wa * a.z + wb * b.z + wc * c.z;
    }
    return p;
}

/* Segments between random points of random pairs of distinct patches. */
static void make_rays(const rad_mesh *mesh, struct RTCRay *rays, size_t count)
{
    uint64_t rng = 0x5EEDu;
    uint32_t n = mesh->patch_count;
    for (size_t r = 0; r < count; r++) {
        uint32_t i = (uint32_t)(rng_next(&rng) % n);
        uint32_t j = (uint32_t)(rng_next(&rng) % (n - 1));
        j += j >= i; /* j != i */
        rad_vec3 p = random_point(mesh, &mesh->patches[i], &rng);
        rad_vec3 q = random_point(mesh, &mesh->patches[j], &rng);
        struct RTCRay *ray = &rays[r];
        ray->org_x = (float)p.x;
        ray->org_y = (float)p.y;
        ray->org_z = (float)p.z;
        ray->tnear = SEGMENT_EPSILON;
        ray->dir_x = (float)(q.x - p.x);
        ray->dir_y = (float)(q.y - p.y);
        ray->dir_z = (float)(q.z - p.z);
        ray->time = 0.0f;
        ray->tfar = 1.0f - SEGMENT_EPSILON;
        ray->mask = 0xFFFFFFFFu;
        ray->id = (unsigned)r;
        ray->flags = 0;
    }
}

/* Embree marks an occluded ray with tfar = -inf: put every tfar back between runs. */
static size_t reset_rays(struct RTCRay *rays, size_t count)
{
    size_t occluded = 0;
    for (size_t r = 0; r < count; r++) {
        occluded += rays[r].tfar == -INFINITY;
        rays[r].tfar = 1.0f - SEGMENT_EPSILON;
    }
    return occluded;
}

static void set_fp_modes(void)
{
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

/* The Embree scene of the scene's triangles, as the library's occluder tracer makes it. */
static RTCScene build_scene(RTCDevice device, const rad_scene *scene)
{
    float *vertices = calloc((size_t)scene->position_count + 1, 3 * sizeof(float));
    uint32_t *indices = malloc((size_t)scene->triangle_count * 3 * sizeof(uint32_t));
    if (!vertices || !indices)
        die("out of memory");
    for (uint32_t v = 0; v < scene->position_count; v++) {
        vertices[3 * v + 0] = (float)scene->positions[v].x;
        vertices[3 * v + 1] = (float)scene->positions[v].y;
        vertices[3 * v + 2] = (float)scene->positions[v].z;
    }
    for (uint32_t t = 0; t < scene->triangle_count; t++)
        for (int k = 0; k < 3; k++)
            indices[3 * t + (uint32_t)k] = scene->triangles[t].vertex[k];

    RTCScene rtc = rtcNewScene(device);
    rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               vertices, 0, 3 * sizeof(float), scene->position_count);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices,
                               0, 3 * sizeof(uint32_t), scene->triangle_count);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(rtc, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(rtc);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
        die("Embree failed to build the scene");
    /* The buffers are shared with Embree and must outlive the scene: kept until exit. */
    return rtc;
}

/* Traces every ray once with `threads` threads; returns the seconds it took. */
static double trace_all(RTCScene scene, struct RTCRay *rays, size_t count, int threads)
{
    long batches = (long)(count / BATCH);
    double seconds = 0;
#pragma omp parallel num_threads(threads)
    {
        set_fp_modes();
        struct RTCIntersectContext context;
        rtcInitIntersectContext(&context); /* default flags: incoherent */
#pragma omp barrier
#pragma omp single
        seconds = omp_get_wtime();
        /* the single's implicit barrier lines the threads up before the first batch */
#pragma omp for schedule(dynamic, 1)
        for (long b = 0; b < batches; b++)
            rtcOccluded1M(scene, &context, &rays[(size_t)b * BATCH], BATCH,
                          sizeof(struct RTCRay));
        /* the for's implicit barrier: every batch is done */
#pragma omp single
        seconds = omp_get_wtime() - seconds;
    }
    return seconds;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    settings s;
    parse_arguments(argc, argv, &s);
    set_fp_modes();

    rad_error error = {0};
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    if (rad_scene_cornell_box(&scene, &error) != RAD_OK ||
        rad_mesh_build(scene, s.patch_size, &mesh, &error) != RAD_OK)
        die(error.message);
    if (mesh->patch_count < 2)
        die("fewer than 2 patches");

    RTCDevice device = rtcNewDevice(NULL);
    if (!device)
        die("Embree could not create a device");
    RTCScene rtc = build_scene(device, scene);

    struct RTCRay *rays = aligned_alloc(64, s.rays * sizeof(struct RTCRay));
    if (!rays)
        die("out of memory for the rays");
    make_rays(mesh, rays, s.rays);
    printf("# Cornell box: %u triangles, patch size %g mm, %u patches; %zu rays (%.0f MB) "
           "per run, best and median of %d runs\n",
           scene->triangle_count, s.patch_size, mesh->patch_count, s.rays,
           (double)(s.rays * sizeof(struct RTCRay)) / 1e6, s.repeats);

    double *times = malloc((size_t)s.repeats * sizeof(double));
    if (!times)
        die("out of memory");
    for (int k = 0; k < s.thread_count; k++) {
        int threads = s.threads[k];
        trace_all(rtc, rays, s.rays, threads); /* warm-up: threads, caches, page faults */
        size_t occluded = reset_rays(rays, s.rays);
        for (int r = 0; r < s.repeats; r++) {
            times[r] = trace_all(rtc, rays, s.rays, threads);
            reset_rays(rays, s.rays);
        }
        if (getenv("RAW_RAYS_VERBOSE"))
            for (int r = 0; r < s.repeats; r++)
                printf("#   run %d: %.3f s\n", r, times[r]);
        qsort(times, (size_t)s.repeats, sizeof(double), compare_doubles);
        double median = times[s.repeats / 2];
        printf("# threads=%d occluded=%.1f%% best=%.3g rays/s median=%.3g rays/s\n", threads,
               100.0 * (double)occluded / (double)s.rays, (double)s.rays / times[0],
               (double)s.rays / median);
        printf("raw_occlusion_rays_per_second threads=%d value=%.0f\n", threads,
               (double)s.rays / median);
        fflush(stdout);
    }

    free(times);
    free(rays);
    rtcReleaseScene(rtc);
    rtcReleaseDevice(device);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return 0;
}
