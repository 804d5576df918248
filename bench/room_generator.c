/*
 * room_generator.c - writes one floor of a furnished building as binary glTF (.glb), and
 * optionally OBJ + MTL, for bench/hierarchical.
 *
 * usage: room_generator TRIANGLES FOLDER [--obj]
 *        (writes FOLDER/rooms-TRIANGLES.glb, and .obj + .mtl with --obj; prints one line
 *        "rooms triangles=N rooms=R grid=CxR edge=L" with the exact count N)
 *
 * Every room is the same 5 m x 4 m x 2.8 m box (y up, metres) with the same furniture: a
 * table (top and four legs) with a ball on it, a stool, a bed, a cupboard with a ring on
 * it, a bookcase, a column, a ball and a ring on the floor, and three ceiling lights (thin
 * boxes 4 cm below the ceiling whose bottom face emits). Rooms stand in a grid, walls 0.2
 * m thick; neighbouring rooms are joined by a door (1 m x 2.1 m) with its reveal. Nothing
 * faces outwards: the building is closed, so every ray ends on a surface.
 *
 * The triangle count is set in two steps: the number of rooms is TRIANGLES / 10000
 * rounded (at least 1), then one tessellation length L is found by bisection so that the
 * scene has as many triangles as possible but no more than TRIANGLES: flat faces are
 * grids of cells at most L wide, curved objects have edges about L / 4 long. So scenes of
 * different sizes hold the same rooms, tessellated alike.
 *
 * Radiosity surfaces are one-sided: walls, floor and ceiling face into the room, objects
 * face outwards, counter-clockwise seen from the front (glTF's rule). Every triangle is
 * checked against a point it must face (or face away from) as it is made; the program
 * stops with a message if one does not.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ROOM_TRIANGLES 10000 /* triangles per room the room count aims at */
#define ROOM_X 5.0           /* room inside, metres */
#define ROOM_Z 4.0
#define ROOM_Y 2.8
#define WALL 0.2 /* wall thickness */
#define DOOR_WIDTH 1.0
#define DOOR_HEIGHT 2.1
#define CURVED_EDGE_SHARE (1.0 / 4) /* curved objects' edge length / flat cell size */
#define PI 3.14159265358979323846

typedef struct material {
    const char *name;
    float albedo[3];
    float emission; /* emitted radiance = emission x the light colour below */
} material;

static const float light_colour[3] = {1.0f, 0.92f, 0.8f};

enum { PLASTER, WOOD_FLOOR, CEILING, OAK, FABRIC, CUPBOARD, CERAMIC, STONE, BRASS, FIXTURE,
       LAMP, MATERIALS };
static const material materials[MATERIALS] = {
    [PLASTER] = {"plaster", {0.75f, 0.72f, 0.66f}, 0},
    [WOOD_FLOOR] = {"floor_wood", {0.50f, 0.34f, 0.22f}, 0},
    [CEILING] = {"ceiling_white", {0.82f, 0.82f, 0.80f}, 0},
    [OAK] = {"oak", {0.60f, 0.42f, 0.26f}, 0},
    [FABRIC] = {"fabric_red", {0.62f, 0.16f, 0.12f}, 0},
    [CUPBOARD] = {"cupboard_blue", {0.18f, 0.28f, 0.60f}, 0},
    [CERAMIC] = {"ceramic_green", {0.22f, 0.52f, 0.26f}, 0},
    [STONE] = {"stone", {0.58f, 0.58f, 0.54f}, 0},
    [BRASS] = {"brass", {0.72f, 0.60f, 0.22f}, 0},
    [FIXTURE] = {"lamp_housing", {0.30f, 0.30f, 0.30f}, 0},
    [LAMP] = {"lamp_light", {0.80f, 0.80f, 0.80f}, 10},
};

/* One glTF mesh (one primitive): a run of vertices and of triangle indices. */
typedef struct mesh {
    char name[48];
    int material;
    size_t first_vertex, vertex_count, first_index, index_count;
    float lo[3], hi[3]; /* bounds of its vertices */
} mesh;

/* How each new triangle must face: towards or away from a reference point, which for a
 * cylinder is on its vertical axis at the triangle's height and for a ring is on the
 * ring's centre line. */
typedef enum { REF_POINT, REF_AXIS, REF_RING } reference_kind;

typedef struct scene {
    float *positions; /* x y z per vertex */
    size_t vertex_count, vertex_capacity;
    uint32_t *indices; /* three per triangle, relative to their mesh's first vertex */
    size_t index_count, index_capacity;
    mesh *meshes;
    size_t mesh_count, mesh_capacity;
    double cell;         /* flat faces: largest cell edge */
    double curved_edge;  /* curved objects: edge length aimed at */
    reference_kind kind; /* the facing check of the triangles being made */
    double ref[3], ring_radius;
    int facing; /* +1: the front faces away from the reference, -1: towards it */
    int room_columns, room_rows, rooms;
} scene;

static void *grow(void *array, size_t *capacity, size_t needed, size_t item)
{
    if (needed <= *capacity)
        return array;
    size_t capacity_new = *capacity ? *capacity : 1024;
    while (capacity_new < needed)
        capacity_new *= 2;
    void *grown = realloc(array, capacity_new * item);
    if (!grown) {
        fputs("room_generator: out of memory\n", stderr);
        exit(1);
    }
    *capacity = capacity_new;
    return grown;
}

/* A new mesh named room_I_J_PART. */
static void begin_mesh(scene *s, int material_index, int i, int j, const char *part)
{
    s->meshes = grow(s->meshes, &s->mesh_capacity, s->mesh_count + 1, sizeof(*s->meshes));
    mesh *m = &s->meshes[s->mesh_count++];
    memset(m, 0, sizeof(*m));
    snprintf(m->name, sizeof(m->name), "room_%d_%d_%s", i, j, part);
    m->material = material_index;
    m->first_vertex = s->vertex_count;
    m->first_index = s->index_count;
}

static void end_mesh(scene *s)
{
    mesh *m = &s->meshes[s->mesh_count - 1];
    m->vertex_count = s->vertex_count - m->first_vertex;
    m->index_count = s->index_count - m->first_index;
    for (int a = 0; a < 3; a++) {
        m->lo[a] = INFINITY;
        m->hi[a] = -INFINITY;
    }
    for (size_t v = m->first_vertex; v < s->vertex_count; v++)
        for (int a = 0; a < 3; a++) {
            m->lo[a] = fminf(m->lo[a], s->positions[3 * v + a]);
            m->hi[a] = fmaxf(m->hi[a], s->positions[3 * v + a]);
        }
}

/* A new vertex; its index within the current mesh. */
static uint32_t vertex(scene *s, const double p[3])
{
    s->positions = grow(s->positions, &s->vertex_capacity, s->vertex_count + 1,
                        3 * sizeof(*s->positions));
    for (int a = 0; a < 3; a++)
        s->positions[3 * s->vertex_count + a] = (float)p[a];
    return (uint32_t)(s->vertex_count++ - s->meshes[s->mesh_count - 1].first_vertex);
}

static void set_reference(scene *s, reference_kind kind, double x, double y, double z,
                          int facing)
{
    s->kind = kind;
    s->ref[0] = x;
    s->ref[1] = y;
    s->ref[2] = z;
    s->facing = facing;
}

/* Triangle a b c (indices in the current mesh), after checking how it faces. */
static void triangle(scene *s, uint32_t a, uint32_t b, uint32_t c)
{
    const float *p0 = s->positions + 3 * (s->meshes[s->mesh_count - 1].first_vertex + a);
    const float *p1 = s->positions + 3 * (s->meshes[s->mesh_count - 1].first_vertex + b);
    const float *p2 = s->positions + 3 * (s->meshes[s->mesh_count - 1].first_vertex + c);
    double e1[3], e2[3], centre[3], ref[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
        centre[k] = ((double)p0[k] + p1[k] + p2[k]) / 3;
        ref[k] = s->ref[k];
    }
    if (s->kind == REF_AXIS)
        ref[1] = centre[1];
    if (s->kind == REF_RING) {
        double dx = centre[0] - s->ref[0], dz = centre[2] - s->ref[2];
        double r = sqrt(dx * dx + dz * dz);
        ref[0] = s->ref[0] + s->ring_radius * dx / r;
        ref[2] = s->ref[2] + s->ring_radius * dz / r;
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    double dot = 0;
    for (int k = 0; k < 3; k++)
        dot += n[k] * (centre[k] - ref[k]);
    if (!(dot * s->facing > 0)) {
        fprintf(stderr, "room_generator: mesh %s: triangle at (%g, %g, %g) faces the wrong way\n",
                s->meshes[s->mesh_count - 1].name, centre[0], centre[1], centre[2]);
        exit(1);
    }
    s->indices = grow(s->indices, &s->index_capacity, s->index_count + 3, sizeof(*s->indices));
    s->indices[s->index_count++] = a;
    s->indices[s->index_count++] = b;
    s->indices[s->index_count++] = c;
}

/* Grid lines from lo to hi, cells at most `cell` wide, with lines at hole_lo and hole_hi
 * when they lie inside; returns how many lines (at most 1 + 3 * cells + 3). */
static int grid_lines(double lo, double hi, double hole_lo, double hole_hi, double cell,
                      double *out, int capacity)
{
    double stops[4] = {lo, hole_lo, hole_hi, hi};
    int count = 0;
    out[count++] = lo;
    for (int k = 1; k < 4; k++) {
        double from = out[count - 1], to = stops[k];
        if (!(to > from + 1e-9) || (k < 3 && !(to < hi - 1e-9)))
            continue;
        int cells = (int)ceil((to - from) / cell - 1e-9);
        for (int c = 1; c <= cells && count < capacity; c++)
            out[count++] = c == cells ? to : from + (to - from) * c / cells;
    }
    return count;
}

/* An axis-aligned rectangle in the plane coordinate[axis] = at, spanning lo..hi along the
 * next two axes (b = axis + 1, c = axis + 2, cyclic), facing +axis (facing 1) or -axis
 * (-1), as a grid of cells; cells inside hole (b_lo, b_hi, c_lo, c_hi; NULL = none) are
 * left out. Vertices are made only for used grid points. */
static void rectangle(scene *s, int axis, int facing, double at, const double lo[2],
                      const double hi[2], const double *hole)
{
    enum { MAX_LINES = 4096 };
    static double lines_b[MAX_LINES], lines_c[MAX_LINES];
    int b = (axis + 1) % 3, c = (axis + 2) % 3;
    double no_hole[4] = {lo[0], lo[0], lo[1], lo[1]};
    const double *h = hole ? hole : no_hole;
    int nb = grid_lines(lo[0], hi[0], h[0], h[1], s->cell, lines_b, MAX_LINES);
    int nc = grid_lines(lo[1], hi[1], h[2], h[3], s->cell, lines_c, MAX_LINES);
    uint32_t *map = malloc((size_t)nb * (size_t)nc * sizeof(*map));
    if (!map) {
        fputs("room_generator: out of memory\n", stderr);
        exit(1);
    }
    for (size_t k = 0; k < (size_t)nb * (size_t)nc; k++)
        map[k] = UINT32_MAX;
    for (int i = 0; i + 1 < nb; i++)
        for (int j = 0; j + 1 < nc; j++) {
            double mid_b = (lines_b[i] + lines_b[i + 1]) / 2;
            double mid_c = (lines_c[j] + lines_c[j + 1]) / 2;
            if (hole && mid_b > h[0] && mid_b < h[1] && mid_c > h[2] && mid_c < h[3])
                continue;
            uint32_t corner[4];
            static const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; k++) {
                uint32_t *slot = &map[(size_t)(i + di[k]) * (size_t)nc + (size_t)(j + dj[k])];
                if (*slot == UINT32_MAX) {
                    double p[3];
                    p[axis] = at;
                    p[b] = lines_b[i + di[k]];
                    p[c] = lines_c[j + dj[k]];
                    *slot = vertex(s, p);
                }
                corner[k] = *slot;
            }
            if (facing > 0) { /* b x c = +axis */
                triangle(s, corner[0], corner[1], corner[2]);
                triangle(s, corner[0], corner[2], corner[3]);
            } else {
                triangle(s, corner[0], corner[2], corner[1]);
                triangle(s, corner[0], corner[3], corner[2]);
            }
        }
    free(map);
}

/* Which faces of a box to make: bit 2 * axis for the -axis face, 2 * axis + 1 for +axis. */
enum { NO_BOTTOM = 0x3F & ~(1 << 2), NO_TOP_BOTTOM = 0x3F & ~(3 << 2), ALL_FACES = 0x3F };

/* A box facing outwards (inward = 0) or inwards; only the faces in the mask. */
static void box(scene *s, const double lo[3], const double hi[3], int faces, int inward)
{
    set_reference(s, REF_POINT, (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2,
                  (lo[2] + hi[2]) / 2, inward ? -1 : 1);
    for (int axis = 0; axis < 3; axis++) {
        int b = (axis + 1) % 3, c = (axis + 2) % 3;
        double rect_lo[2] = {lo[b], lo[c]}, rect_hi[2] = {hi[b], hi[c]};
        for (int side = 0; side < 2; side++)
            if (faces & (1 << (2 * axis + side)))
                rectangle(s, axis, (side ? 1 : -1) * (inward ? -1 : 1), side ? hi[axis] : lo[axis],
                          rect_lo, rect_hi, NULL);
    }
}

static int segments(double length, double edge, int least)
{
    int n = (int)ceil(length / edge);
    return n < least ? least : n;
}

/* A sphere of radius r around c: rings of latitude, triangles at the poles. */
static void sphere(scene *s, const double c[3], double r)
{
    int around = segments(2 * PI * r, s->curved_edge, 12), rings = segments(PI * r, s->curved_edge, 6);
    set_reference(s, REF_POINT, c[0], c[1], c[2], 1);
    double p[3] = {c[0], c[1] - r, c[2]};
    uint32_t south = vertex(s, p), first = 0;
    for (int i = 1; i < rings; i++) {
        double polar = PI * i / rings;
        for (int j = 0; j < around; j++) {
            double azimuth = 2 * PI * j / around;
            p[0] = c[0] + r * sin(polar) * cos(azimuth);
            p[1] = c[1] - r * cos(polar);
            p[2] = c[2] + r * sin(polar) * sin(azimuth);
            uint32_t v = vertex(s, p);
            if (i == 1 && j == 0)
                first = v;
        }
    }
    p[0] = c[0];
    p[1] = c[1] + r;
    p[2] = c[2];
    uint32_t north = vertex(s, p);
    for (int j = 0; j < around; j++) {
        uint32_t j1 = (uint32_t)((j + 1) % around);
        triangle(s, south, first + (uint32_t)j, first + j1);
        for (int i = 1; i + 1 < rings; i++) {
            uint32_t a = first + (uint32_t)((i - 1) * around), b = a + (uint32_t)around;
            triangle(s, a + (uint32_t)j, b + j1, a + j1);
            triangle(s, a + (uint32_t)j, b + (uint32_t)j, b + j1);
        }
        uint32_t last = first + (uint32_t)((rings - 2) * around);
        triangle(s, north, last + j1, last + (uint32_t)j);
    }
}

/* An upright cylinder of radius r on the base point c, height h, its side (rows at most
 * one flat cell high) and, if top_cap, a fan closing its top. */
static void cylinder(scene *s, const double c[3], double r, double h, int top_cap)
{
    int around = segments(2 * PI * r, s->curved_edge, 12), rows = segments(h, s->cell, 1);
    set_reference(s, REF_AXIS, c[0], c[1], c[2], 1);
    uint32_t first = 0;
    for (int i = 0; i <= rows; i++)
        for (int j = 0; j < around; j++) {
            double azimuth = 2 * PI * j / around;
            double p[3] = {c[0] + r * cos(azimuth), c[1] + h * i / rows, c[2] + r * sin(azimuth)};
            uint32_t v = vertex(s, p);
            if (i == 0 && j == 0)
                first = v;
        }
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < around; j++) {
            uint32_t a = first + (uint32_t)(i * around), b = a + (uint32_t)around;
            uint32_t j1 = (uint32_t)((j + 1) % around);
            triangle(s, a + (uint32_t)j, b + (uint32_t)j, b + j1);
            triangle(s, a + (uint32_t)j, b + j1, a + j1);
        }
    if (!top_cap)
        return;
    set_reference(s, REF_POINT, c[0], c[1], c[2], 1);
    double p[3] = {c[0], c[1] + h, c[2]};
    uint32_t centre = vertex(s, p), top = first + (uint32_t)(rows * around);
    for (int j = 0; j < around; j++)
        triangle(s, centre, top + (uint32_t)((j + 1) % around), top + (uint32_t)j);
}

/* A ring (torus) lying flat: centre line a circle of radius big around c, tube radius
 * small; the tube's lowest points at c[1] - small. */
static void ring(scene *s, const double c[3], double big, double small)
{
    int around = segments(2 * PI * (big + small), s->curved_edge, 16);
    int tube = 2 * (segments(2 * PI * small, s->curved_edge, 8) / 2); /* even: a bottom circle */
    set_reference(s, REF_RING, c[0], c[1], c[2], 1);
    s->ring_radius = big;
    uint32_t first = 0;
    for (int i = 0; i < around; i++)
        for (int j = 0; j < tube; j++) {
            double u = 2 * PI * i / around, v = 2 * PI * j / tube;
            double radius = big + small * cos(v);
            double p[3] = {c[0] + radius * cos(u), c[1] + small * sin(v), c[2] + radius * sin(u)};
            uint32_t index = vertex(s, p);
            if (i == 0 && j == 0)
                first = index;
        }
    for (int i = 0; i < around; i++)
        for (int j = 0; j < tube; j++) {
            uint32_t i1 = (uint32_t)((i + 1) % around), j1 = (uint32_t)((j + 1) % tube);
            uint32_t a = first + (uint32_t)(i * tube), b = first + i1 * (uint32_t)tube;
            triangle(s, a + (uint32_t)j, a + j1, b + j1);
            triangle(s, a + (uint32_t)j, b + j1, b + (uint32_t)j);
        }
}

/* box() with corners relative to the room origin o. */
static void room_box(scene *s, const double o[3], double x0, double y0, double z0, double x1,
                     double y1, double z1, int faces)
{
    double lo[3] = {o[0] + x0, o[1] + y0, o[2] + z0}, hi[3] = {o[0] + x1, o[1] + y1, o[2] + z1};
    box(s, lo, hi, faces, 0);
}

static int room_exists(const scene *s, int i, int j)
{
    return i >= 0 && j >= 0 && i < s->room_columns && j < s->room_rows &&
           j * s->room_columns + i < s->rooms;
}

/* The walls, floor and ceiling of room (i, j), all facing in, with a door to each
 * neighbour; the reveal of the doors to the +x and +z neighbours. */
static void room_shell(scene *s, int i, int j, const double o[3])
{
    const double x1 = o[0] + ROOM_X, z1 = o[2] + ROOM_Z, y1 = ROOM_Y;
    const double door_z0 = o[2] + (ROOM_Z - DOOR_WIDTH) / 2, door_z1 = door_z0 + DOOR_WIDTH;
    const double door_x0 = o[0] + (ROOM_X - DOOR_WIDTH) / 2, door_x1 = door_x0 + DOOR_WIDTH;
    /* holes in the walls x = const (b = y, c = z) and z = const (b = x, c = y) */
    const double hole_x[4] = {0, DOOR_HEIGHT, door_z0, door_z1};
    const double hole_z[4] = {door_x0, door_x1, 0, DOOR_HEIGHT};
    const double yz_lo[2] = {0, o[2]}, yz_hi[2] = {y1, z1};
    const double xy_lo[2] = {o[0], 0}, xy_hi[2] = {x1, y1};
    const double zx_lo[2] = {o[2], o[0]}, zx_hi[2] = {z1, x1};

    begin_mesh(s, PLASTER, i, j, "walls");
    set_reference(s, REF_POINT, o[0] + ROOM_X / 2, ROOM_Y / 2, o[2] + ROOM_Z / 2, -1);
    rectangle(s, 0, 1, o[0], yz_lo, yz_hi, room_exists(s, i - 1, j) ? hole_x : NULL);
    rectangle(s, 0, -1, x1, yz_lo, yz_hi, room_exists(s, i + 1, j) ? hole_x : NULL);
    rectangle(s, 2, 1, o[2], xy_lo, xy_hi, room_exists(s, i, j - 1) ? hole_z : NULL);
    rectangle(s, 2, -1, z1, xy_lo, xy_hi, room_exists(s, i, j + 1) ? hole_z : NULL);
    if (room_exists(s, i + 1, j)) { /* reveal of the door in the slab x1 .. x1 + WALL */
        set_reference(s, REF_POINT, x1 + WALL / 2, DOOR_HEIGHT / 2, (door_z0 + door_z1) / 2, -1);
        const double xy_lo_door[2] = {x1, 0}, xy_hi_door[2] = {x1 + WALL, DOOR_HEIGHT};
        const double zx_lo_door[2] = {door_z0, x1}, zx_hi_door[2] = {door_z1, x1 + WALL};
        rectangle(s, 2, 1, door_z0, xy_lo_door, xy_hi_door, NULL);
        rectangle(s, 2, -1, door_z1, xy_lo_door, xy_hi_door, NULL);
        rectangle(s, 1, -1, DOOR_HEIGHT, zx_lo_door, zx_hi_door, NULL);
    }
    if (room_exists(s, i, j + 1)) { /* reveal of the door in the slab z1 .. z1 + WALL */
        set_reference(s, REF_POINT, (door_x0 + door_x1) / 2, DOOR_HEIGHT / 2, z1 + WALL / 2, -1);
        const double yz_lo_door[2] = {0, z1}, yz_hi_door[2] = {DOOR_HEIGHT, z1 + WALL};
        const double zx_lo_door[2] = {z1, door_x0}, zx_hi_door[2] = {z1 + WALL, door_x1};
        rectangle(s, 0, 1, door_x0, yz_lo_door, yz_hi_door, NULL);
        rectangle(s, 0, -1, door_x1, yz_lo_door, yz_hi_door, NULL);
        rectangle(s, 1, -1, DOOR_HEIGHT, zx_lo_door, zx_hi_door, NULL);
    }
    end_mesh(s);

    begin_mesh(s, WOOD_FLOOR, i, j, "floor");
    set_reference(s, REF_POINT, o[0] + ROOM_X / 2, -1, o[2] + ROOM_Z / 2, 1);
    rectangle(s, 1, 1, 0, zx_lo, zx_hi, NULL);
    if (room_exists(s, i + 1, j)) { /* the thresholds */
        const double lo[2] = {door_z0, x1}, hi[2] = {door_z1, x1 + WALL};
        rectangle(s, 1, 1, 0, lo, hi, NULL);
    }
    if (room_exists(s, i, j + 1)) {
        const double lo[2] = {z1, door_x0}, hi[2] = {z1 + WALL, door_x1};
        rectangle(s, 1, 1, 0, lo, hi, NULL);
    }
    end_mesh(s);

    begin_mesh(s, CEILING, i, j, "ceiling");
    set_reference(s, REF_POINT, o[0] + ROOM_X / 2, ROOM_Y / 2, o[2] + ROOM_Z / 2, -1);
    rectangle(s, 1, -1, y1, zx_lo, zx_hi, NULL);
    end_mesh(s);
}

/* The furniture, curved objects and lights of a room whose inside starts at o. Doors are
 * in the middle of each wall, so everything stands in the corners or the middle. */
static void room_contents(scene *s, int i, int j, const double o[3])
{
    begin_mesh(s, OAK, i, j, "table"); /* top 0.72-0.76 m, legs 5 cm square */
    room_box(s, o, 0.5, 0.72, 2.6, 1.7, 0.76, 3.5, ALL_FACES);
    for (int leg = 0; leg < 4; leg++) {
        double x = leg & 1 ? 1.6 : 0.55, z = leg & 2 ? 3.4 : 2.65;
        room_box(s, o, x, 0, z, x + 0.05, 0.72, z + 0.05, NO_TOP_BOTTOM);
    }
    end_mesh(s);

    begin_mesh(s, OAK, i, j, "bookcase"); /* 0.4 deep, 1 m wide, 1.8 m tall */
    room_box(s, o, 4.45, 0, 2.8, 4.85, 1.8, 2.83, NO_BOTTOM);
    room_box(s, o, 4.45, 0, 3.77, 4.85, 1.8, 3.8, NO_BOTTOM);
    room_box(s, o, 4.82, 0, 2.83, 4.85, 1.8, 3.77, NO_BOTTOM & ~(3 << 4));
    for (int board = 0; board < 4; board++) {
        double y = 0.1 + 0.55 * board;
        room_box(s, o, 4.45, y, 2.83, 4.82, y + 0.025, 3.77, ALL_FACES & ~(3 << 4) & ~(1 << 1));
    }
    end_mesh(s);

    begin_mesh(s, FABRIC, i, j, "bed");
    room_box(s, o, 0.3, 0, 0.2, 2.2, 0.45, 1.1, NO_BOTTOM);
    room_box(s, o, 0.3, 0.45, 0.2, 2.2, 0.9, 0.35, NO_BOTTOM);
    end_mesh(s);

    begin_mesh(s, CUPBOARD, i, j, "cupboard");
    room_box(s, o, 3.6, 0, 0.1, 4.8, 2.0, 0.7, NO_BOTTOM);
    end_mesh(s);

    begin_mesh(s, STONE, i, j, "column");
    const double column_base[3] = {o[0] + 3.6, 0, o[2] + 2.9};
    cylinder(s, column_base, 0.15, ROOM_Y, 0);
    end_mesh(s);

    begin_mesh(s, OAK, i, j, "stool");
    const double stool_base[3] = {o[0] + 2.1, 0, o[2] + 3.0};
    cylinder(s, stool_base, 0.18, 0.45, 1);
    end_mesh(s);

    begin_mesh(s, CERAMIC, i, j, "balls");
    const double on_table[3] = {o[0] + 1.1, 0.76 + 0.12, o[2] + 3.05};
    sphere(s, on_table, 0.12);
    const double on_floor[3] = {o[0] + 1.0, 0.3, o[2] + 1.85};
    sphere(s, on_floor, 0.3);
    end_mesh(s);

    begin_mesh(s, BRASS, i, j, "rings");
    const double on_cupboard[3] = {o[0] + 4.2, 2.0 + 0.05, o[2] + 0.4};
    ring(s, on_cupboard, 0.2, 0.05);
    const double ring_on_floor[3] = {o[0] + 2.6, 0.08, o[2] + 1.5};
    ring(s, ring_on_floor, 0.3, 0.08);
    end_mesh(s);

    /* three lights: 0.6 m squares 6 cm below the ceiling, in 4 cm deep housings */
    static const double lights[3][2] = {{1.25, 1.3}, {3.25, 1.3}, {2.5, 3.0}};
    begin_mesh(s, FIXTURE, i, j, "lamp_housings");
    for (int k = 0; k < 3; k++)
        room_box(s, o, lights[k][0] - 0.3, ROOM_Y - 0.06, lights[k][1] - 0.3, lights[k][0] + 0.3,
                 ROOM_Y - 0.02, lights[k][1] + 0.3, NO_BOTTOM);
    end_mesh(s);
    begin_mesh(s, LAMP, i, j, "lamps");
    for (int k = 0; k < 3; k++)
        room_box(s, o, lights[k][0] - 0.3, ROOM_Y - 0.06, lights[k][1] - 0.3, lights[k][0] + 0.3,
                 ROOM_Y - 0.02, lights[k][1] + 0.3, 1 << 2);
    end_mesh(s);
}

/* The whole floor at flat cell size `cell`; returns its triangle count. */
static size_t build(scene *s, double cell)
{
    s->vertex_count = s->index_count = s->mesh_count = 0;
    s->cell = cell;
    s->curved_edge = cell * CURVED_EDGE_SHARE;
    for (int r = 0; r < s->rooms; r++) {
        int i = r % s->room_columns, j = r / s->room_columns;
        const double origin[3] = {i * (ROOM_X + WALL), 0, j * (ROOM_Z + WALL)};
        room_shell(s, i, j, origin);
        room_contents(s, i, j, origin);
    }
    return s->index_count / 3;
}

static void put_u32(FILE *file, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, file);
}

/* A growing text buffer for the glTF JSON. */
typedef struct text {
    char *data;
    size_t length, capacity;
} text;

static void add(text *t, const char *format, ...) __attribute__((format(printf, 2, 3)));

static void add(text *t, const char *format, ...)
{
    for (;;) {
        va_list args;
        va_start(args, format);
        size_t room = t->capacity - t->length;
        int n = vsnprintf(t->data ? t->data + t->length : NULL, room, format, args);
        va_end(args);
        if (n >= 0 && (size_t)n < room) {
            t->length += (size_t)n;
            return;
        }
        t->data = grow(t->data, &t->capacity, t->length + (size_t)(n < 0 ? 0 : n) + 1, 1);
    }
}

/* Closes a file written under a temporary name and gives it its real name. */
static int finish(FILE *file, const char *temporary, const char *path)
{
    int failed = ferror(file);
    failed |= fclose(file) != 0;
    if (failed || rename(temporary, path) != 0) {
        fprintf(stderr, "room_generator: cannot write %s\n", path);
        remove(temporary);
        return 0;
    }
    return 1;
}

static int write_glb(const scene *s, const char *path)
{
    text json = {0};
    add(&json, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"bench/room_generator.c\"},"
               "\"extensionsUsed\":[\"KHR_materials_emissive_strength\"],"
               "\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (size_t m = 0; m < s->mesh_count; m++)
        add(&json, "%s%zu", m ? "," : "", m);
    add(&json, "]}],\"nodes\":[");
    for (size_t m = 0; m < s->mesh_count; m++)
        add(&json, "%s{\"mesh\":%zu}", m ? "," : "", m);
    add(&json, "],\"meshes\":[");
    for (size_t m = 0; m < s->mesh_count; m++)
        add(&json,
            "%s{\"name\":\"%s\",\"primitives\":[{\"attributes\":{\"POSITION\":%zu},"
            "\"indices\":%zu,\"material\":%d}]}",
            m ? "," : "", s->meshes[m].name, 2 * m, 2 * m + 1, s->meshes[m].material);
    add(&json, "],\"materials\":[");
    for (int k = 0; k < MATERIALS; k++) {
        const material *mat = &materials[k];
        add(&json, "%s{\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
                   "[%g,%g,%g,1],\"metallicFactor\":0}",
            k ? "," : "", mat->name, mat->albedo[0], mat->albedo[1], mat->albedo[2]);
        if (mat->emission > 0)
            add(&json, ",\"emissiveFactor\":[%g,%g,%g],\"extensions\":"
                       "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%g}}",
                light_colour[0], light_colour[1], light_colour[2], mat->emission);
        add(&json, "}");
    }
    size_t position_bytes = s->vertex_count * 12, index_bytes = s->index_count * 4;
    add(&json, "],\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
               "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu,\"target\":34962},"
               "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34963}],"
               "\"accessors\":[",
        position_bytes + index_bytes, position_bytes, position_bytes, index_bytes);
    for (size_t m = 0; m < s->mesh_count; m++) {
        const mesh *e = &s->meshes[m];
        add(&json,
            "%s{\"bufferView\":0,\"byteOffset\":%zu,\"componentType\":5126,\"count\":%zu,"
            "\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
            "{\"bufferView\":1,\"byteOffset\":%zu,\"componentType\":5125,\"count\":%zu,"
            "\"type\":\"SCALAR\"}",
            m ? "," : "", e->first_vertex * 12, e->vertex_count, e->lo[0], e->lo[1], e->lo[2],
            e->hi[0], e->hi[1], e->hi[2], e->first_index * 4, e->index_count);
    }
    add(&json, "]}");
    while (json.length % 4)
        add(&json, " ");

    char temporary[4300];
    snprintf(temporary, sizeof(temporary), "%s.part", path);
    FILE *glb = fopen(temporary, "wb");
    if (!glb) {
        fprintf(stderr, "room_generator: cannot write %s\n", path);
        free(json.data);
        return 0;
    }
    size_t bin_bytes = position_bytes + index_bytes;
    put_u32(glb, 0x46546C67u); /* "glTF" */
    put_u32(glb, 2);
    put_u32(glb, (uint32_t)(12 + 8 + json.length + 8 + bin_bytes));
    put_u32(glb, (uint32_t)json.length);
    put_u32(glb, 0x4E4F534Au); /* "JSON" */
    fwrite(json.data, 1, json.length, glb);
    put_u32(glb, (uint32_t)bin_bytes);
    put_u32(glb, 0x004E4942u); /* "BIN" */
    fwrite(s->positions, 4, 3 * s->vertex_count, glb); /* little-endian hosts only */
    for (size_t k = 0; k < s->index_count; k++)
        put_u32(glb, s->indices[k]);
    free(json.data);
    return finish(glb, temporary, path);
}

static int write_obj(const scene *s, const char *folder, const char *stem)
{
    char path[4200], temporary[4300];
    snprintf(path, sizeof(path), "%s/%s.mtl", folder, stem);
    snprintf(temporary, sizeof(temporary), "%s.part", path);
    FILE *mtl = fopen(temporary, "w");
    if (!mtl) {
        fprintf(stderr, "room_generator: cannot write %s\n", path);
        return 0;
    }
    for (int k = 0; k < MATERIALS; k++) {
        const material *mat = &materials[k];
        fprintf(mtl, "newmtl %s\nKd %g %g %g\n", mat->name, mat->albedo[0], mat->albedo[1],
                mat->albedo[2]);
        if (mat->emission > 0)
            fprintf(mtl, "Ke %g %g %g\n", light_colour[0] * mat->emission,
                    light_colour[1] * mat->emission, light_colour[2] * mat->emission);
    }
    if (!finish(mtl, temporary, path))
        return 0;
    snprintf(path, sizeof(path), "%s/%s.obj", folder, stem);
    snprintf(temporary, sizeof(temporary), "%s.part", path);
    FILE *obj = fopen(temporary, "w");
    if (!obj) {
        fprintf(stderr, "room_generator: cannot write %s\n", path);
        return 0;
    }
    fprintf(obj, "mtllib %s.mtl\n", stem);
    for (size_t v = 0; v < s->vertex_count; v++)
        fprintf(obj, "v %.7g %.7g %.7g\n", s->positions[3 * v], s->positions[3 * v + 1],
                s->positions[3 * v + 2]);
    for (size_t m = 0; m < s->mesh_count; m++) {
        const mesh *e = &s->meshes[m];
        fprintf(obj, "o %s\nusemtl %s\n", e->name, materials[e->material].name);
        for (size_t k = e->first_index; k < e->first_index + e->index_count; k += 3)
            fprintf(obj, "f %zu %zu %zu\n", e->first_vertex + s->indices[k] + 1,
                    e->first_vertex + s->indices[k + 1] + 1,
                    e->first_vertex + s->indices[k + 2] + 1);
    }
    return finish(obj, temporary, path);
}

int main(int argc, char **argv)
{
    int with_obj = argc == 4 && strcmp(argv[3], "--obj") == 0;
    char *end = NULL;
    long wanted = argc >= 3 ? strtol(argv[1], &end, 10) : 0;
    if ((argc != 3 && !with_obj) || !end || *end || wanted < 1 || wanted > 20000000) {
        fputs("usage: room_generator TRIANGLES FOLDER [--obj]\n", stderr);
        return 2;
    }
    scene s = {0};
    s.rooms = (int)((wanted + ROOM_TRIANGLES / 2) / ROOM_TRIANGLES);
    if (s.rooms < 1)
        s.rooms = 1;
    s.room_columns = (int)ceil(sqrt((double)s.rooms));
    s.room_rows = (s.rooms + s.room_columns - 1) / s.room_columns;

    /* The count falls as the cell grows: bisect on log(cell) for the finest cell whose
     * count is at most the one asked for (steps of ceil() make it only roughly monotone,
     * so the answer is close to, not always the closest to, the count asked for). */
    double fine = 0.002, coarse = 4.0; /* metres; the coarse count is about 1000 a room */
    if (build(&s, coarse) > (size_t)wanted)
        fine = coarse; /* too few triangles asked for: the coarsest scene */
    for (int step = 0; step < 40 && fine < coarse; step++) {
        double middle = sqrt(fine * coarse);
        if (build(&s, middle) <= (size_t)wanted)
            coarse = middle;
        else
            fine = middle;
    }
    size_t triangles = build(&s, coarse);

    char stem[64], path[4200];
    snprintf(stem, sizeof(stem), "rooms-%ld", wanted);
    snprintf(path, sizeof(path), "%s/%s.glb", argv[2], stem);
    int ok = write_glb(&s, path) && (!with_obj || write_obj(&s, argv[2], stem));
    if (ok)
        printf("rooms triangles=%zu rooms=%d grid=%dx%d edge=%.4g file=%s\n", triangles, s.rooms,
               s.room_columns, s.room_rows, s.cell, path);
    free(s.positions);
    free(s.indices);
    free(s.meshes);
    return ok ? 0 : 1;
}
