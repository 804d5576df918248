/*
 * display_mesh.h - what the image renderer and the lit mesh show of a solution (internal).
 *
 * Two neighbouring polygons of one smooth region that split their shared edge into
 * different counts leave T-vertices: mesh vertices strictly inside an edge of a patch on
 * the other side. display_mesh_build finds them, and gives
 *   - each T-vertex a constraint: its radiance is the linear interpolation between the
 *     two nearest vertices along its line that are no T-vertices ("anchors"), which makes
 *     it the interpolation along the coarse edge it lies in, so both sides of the edge
 *     show the same values (C0);
 *   - the display triangles: every patch split into triangles through the points that lie
 *     strictly inside its edges, so the triangles meet corner to corner (no T-junction a
 *     rasteriser or a ray could slip through); a patch without such points keeps the
 *     plain split (0,1,2), (0,2,3). Those points include other regions' vertices (a
 *     crease, or two materials side by side, split differently): the patch's region then
 *     gets an added vertex there, interpolated along the edge, so values stay per region.
 * Detection is a hash of patch edges (an edge used once is a boundary or part of a
 * T-junction), then the once-used edges joined into straight chains through shared
 * vertices, each chain sorted along its line: O(n log n) in the patch count.
 */
#ifndef RAD_RENDER_DISPLAY_MESH_H
#define RAD_RENDER_DISPLAY_MESH_H

#include "radiosity.h"

typedef struct display_tvertex {
    uint32_t vertex;   /* the T-vertex */
    uint32_t from, to; /* the anchors either side along its line */
    double t;          /* its place between them: 0 at `from`, 1 at `to` */
} display_tvertex;

/* A vertex added where another region's vertex lies strictly inside a patch edge. */
typedef struct display_extra {
    uint32_t at;       /* the other region's vertex: the position */
    uint32_t from, to; /* the edge it lies in (its own region's vertices) */
    double t;          /* its place along the edge: 0 at `from`, 1 at `to` */
} display_extra;

typedef struct display_mesh {
    uint32_t vertex_count;    /* the mesh's vertices, then the added ones */
    display_extra *extras;    /* the added vertices: vertex mesh->vertex_count + k */
    uint32_t extra_count;
    uint32_t (*triangles)[3]; /* into the vertices above, counter-clockwise (front) */
    uint32_t *patch_of;       /* per triangle: its patch */
    uint32_t triangle_count;
    display_tvertex *tvertices; /* in an order where a T-vertex that is another's anchor
                                   (a rare cross of two lines) comes first */
    uint32_t tvertex_count;
} display_mesh;

/* Finds the T-vertices and, when `triangles` is true, makes the display triangles and
 * the added vertices (without: vertex_count is the mesh's). */
rad_status display_mesh_build(const rad_mesh *mesh, bool triangles, display_mesh *out,
                              rad_error *error);

/* The displayed radiance at every vertex (display->vertex_count of them): the
 * area-weighted mean of B / pi over the patches sharing it, then the T-vertex
 * constraints, then the added vertices. `display` may be NULL (the mesh's vertices, means
 * only). False when out of memory (the values are then all 0). */
bool display_mesh_radiance(const rad_mesh *mesh, const display_mesh *display, const rad_rgb *B,
                           rad_rgb *vertex_radiance);

/* The same, leaving out the patches marked in `hidden` (NULL: none), which nothing can
 * see (inside a closed object, or under one resting on them): a vertex they share with
 * visible patches takes the visible ones' mean, and a vertex of hidden patches alone 0. */
bool display_mesh_radiance_weighted(const rad_mesh *mesh, const display_mesh *display,
                                    const rad_rgb *B, const uint8_t *hidden,
                                    rad_rgb *vertex_radiance);

/* Makes values given at the mesh's vertices (the first mesh->vertex_count) displayable:
 * each T-vertex takes the interpolation between its anchors, and each added vertex the
 * interpolation along its edge (display_mesh_radiance_weighted ends with this). */
void display_mesh_constrain(const rad_mesh *mesh, const display_mesh *display,
                            rad_rgb *vertex_values);
/* Marks in hidden[p] (mesh->patch_count values) the patches no one can see: every ray of
 * a few over the patch's hemisphere meets the back of a surface of `tracer` (the scene, or
 * the patches); rays leave the centre `leave` off the patch (hidden_patches.c). With
 * `near` (NULL: not wanted), marks there the patches with a surface within near_widths x
 * sqrt(area) along one of those rays. */
void display_hidden_patches(const rad_mesh *mesh, const rad_tracer *tracer, double leave,
                            uint8_t *hidden, uint8_t *near, double near_widths);

/* How many display triangles, from the first, belong to front patches: the twins of
 * two-sided surfaces come after every front patch (rad_mesh), and so do their display
 * triangles, which are in patch order. A tracer of these alone sees each cell once; a hit
 * on a front's back is its twin. */
uint32_t display_mesh_front_triangles(const rad_mesh *mesh, const display_mesh *display);

/* The positions of all display->vertex_count vertices. */
void display_mesh_positions(const rad_mesh *mesh, const display_mesh *display,
                            rad_vec3 *positions);

void display_mesh_free(display_mesh *display);

#endif
