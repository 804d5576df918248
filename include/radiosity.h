/*
 * radiosity.h - the public API of the radiosity library.
 *
 * This header is the manual. The library computes diffuse global illumination by the
 * radiosity method: a scene is split into patches, form factors between patches are
 * computed with visibility, the radiosity system B = E + diag(rho) F B is solved, and the
 * answer is reconstructed smoothly and rendered from a camera.
 *
 * The pipeline, one stage per section below:
 *   scene (import or built-in) -> mesh of patches -> patch inputs -> rad_solve_scene (the
 *   one entry point: form factors and a dense solver, or the hierarchical solver) ->
 *   reconstruct + render -> image / lit mesh / solution file; and, beside it, surface
 *   view factors for engineers. Tracers (ray queries) serve every stage that needs rays.
 *
 * Conventions shared by every function (see shared/docs/METHOD.md):
 *   - F_ij is the fraction of the energy leaving patch i that arrives at patch j.
 *   - Albedo rho is linear RGB in [0,1]; emission is given as emitted RADIANCE L_e; the
 *     exitance that enters the radiosity equation is E = pi * L_e. Radiosity B is an
 *     exitance (same unit as E); an image pixel holds radiance L = B / pi.
 *   - Surfaces are one-sided: the front is the side from which a triangle's vertices run
 *     counter-clockwise. Every surface blocks rays from both sides. A surface flagged
 *     RAD_SURFACE_TWO_SIDED (`--two-sided NAME`, glTF doubleSided) radiates and receives
 *     on both sides, each side with the material's values, in every solver and renderer.
 *
 * Errors: fallible functions return rad_status and, when the caller passes a rad_error,
 * fill it with a one-line message of the form "file:line: what is wrong" (the file and line
 * are left out when they are not known); a NULL rad_error is allowed (only the status then).
 * Warnings go to the rad_log callback of the options that take one; a NULL callback drops
 * them. No function prints or exits.
 *
 * Ownership: every function that hands back a new object through an `out` pointer
 * (rad_*_create, rad_*_load, rad_scene_load_files, rad_scene_cornell_box, rad_*_build,
 * rad_*_compute, rad_solution_read, rad_image_read, rad_viewfactor_matrix_script_f, ...)
 * gives it to the caller, who frees it with the *_destroy of its type (rad_scene_destroy,
 * rad_mesh_destroy, rad_patch_inputs_destroy, rad_tracer_destroy, rad_formfactors_destroy,
 * rad_viewfactor_matrix_destroy, rad_solution_destroy, rad_image_destroy); passing NULL to
 * a *_destroy is harmless. rad_system_of only points into what it is given: nothing to
 * free. Arrays and images the caller passes in to be filled (B, the image of rad_render,
 * ...) stay the caller's.
 *
 * Options and reports: a NULL options pointer means every default, and a zero field of an
 * options struct means that field's default (each field says which; the RAD_DEFAULT_*
 * constants below name them for callers that show them, as the CLI's help does). A NULL
 * report pointer (rad_*_report, the vs3 control, the path tracer's standard-error image)
 * means it is not wanted. Every function that takes options or a report accepts NULL for
 * it; what a function exists to compute (rad_image_compare's difference, an `out`
 * pointer, B) is not optional.
 *
 * Words: `tolerance` is always when an iteration stops (its stopping value, residual or
 * change of a sweep, is at most the tolerance); `accuracy` is always the error target of a
 * computed quantity (a view factor's relative error). rad_compare_options.block_tolerance
 * is the one other use, a pass mark of an image comparison (the CLI's --block-tolerance).
 *
 * Constants are `#define NAME value`: integers plain (they convert to the field they set,
 * and the CLI's help quotes them), flags `(1u << k)`.
 *
 * Threads: functions that take a `threads` field run in parallel with OpenMP (0 means all
 * cores). Every random number is derived from the seed and the item being computed, never
 * from the thread that computes it, so form-factor matrices, solutions and images are
 * bitwise the same for any thread count; surface view factors are summed in per-thread
 * tables and may differ in the last digits (relative 1e-15).
 */
#ifndef RADIOSITY_H
#define RADIOSITY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------ */
/* Errors and logging                                                                    */

typedef enum rad_status {
    RAD_OK = 0,
    RAD_ERR_IO,          /* a file could not be opened, read or written */
    RAD_ERR_PARSE,       /* a file was read but its content is malformed */
    RAD_ERR_INVALID,     /* an argument or a scene value is out of its domain */
    RAD_ERR_NOMEM,       /* an allocation failed or a size overflowed */
    RAD_ERR_UNSUPPORTED, /* a valid request this build cannot serve */
    RAD_ERR_INTERNAL     /* a bug: an invariant did not hold */
} rad_status;

#define RAD_ERROR_MESSAGE_MAX 1024

typedef struct rad_error {
    rad_status status;
    char message[RAD_ERROR_MESSAGE_MAX]; /* "file:line: message", no trailing newline */
} rad_error;

/* A short English name for a status ("I/O error", ...). Never NULL. */
const char *rad_status_name(rad_status status);

/* Receives one warning line (no trailing newline). */
typedef void (*rad_log_fn)(void *user, const char *message);

/* Receives the progress of a long phase: fraction in [0,1]. Called from one thread only. */
typedef void (*rad_progress_fn)(void *user, const char *phase, double fraction);

/* ------------------------------------------------------------------------------------ */
/* Defaults: what a zero options field (or NULL options) stands for, and what a file     */
/* leaves out                                                                            */

#define RAD_DEFAULT_QUADRATURE 1        /* rad_formfactor_options.quadrature: 1 x 1 */
#define RAD_DEFAULT_VISIBILITY_RAYS 4   /* rad_formfactor_options.visibility_rays: a patch
                                           pair's (the dense form factors) */
#define RAD_DEFAULT_LINK_VISIBILITY_RAYS 16 /* rad_hierarchy_options.visibility_rays: a
                                               link's, after a first 4 not all open */
#define RAD_DEFAULT_ACCURACY 1e-4       /* rad_viewfactor_options.accuracy */
#define RAD_DEFAULT_MAX_RAYS 1024       /* rad_viewfactor_options.max_rays */
#define RAD_SIGHT_RAYS_NONE UINT32_MAX  /* rad_viewfactor_options.sight_rays: none */
#define RAD_DEFAULT_EXACT_OCCLUDERS 1024 /* rad_viewfactor_options.exact_occluders */
#define RAD_MAX_EXACT_OCCLUDERS 1024     /* its largest value */
#define RAD_DEFAULT_EMISSIVITY 0.9      /* rad_surface.emissivity when the file gives none */
#define RAD_DEFAULT_RENDER_SPP 16       /* rad_render_options.samples_per_pixel */
#define RAD_DEFAULT_DIRECT_SAMPLES 8    /* rad_render_options.direct_samples */
#define RAD_DEFAULT_EDGE_SAMPLES 64     /* rad_render_options.edge_samples */
#define RAD_DEFAULT_MAX_DEPTH 5         /* max_depth of rad_render_options (mirror
                                           reflections) and rad_raytrace_options */
#define RAD_DEFAULT_RAYTRACE_SPP 4      /* rad_raytrace_options.samples_per_pixel */
#define RAD_DEFAULT_LIGHT_SAMPLES 16    /* rad_raytrace_options.light_samples */
#define RAD_DEFAULT_PATHTRACE_SPP 64    /* rad_pathtrace_options.samples_per_pixel */
#define RAD_DEFAULT_BLOCK_SIZE 8        /* rad_compare_options.block_size */
#define RAD_DEFAULT_BLOCK_TOLERANCE 0.1 /* rad_compare_options.block_tolerance */
#define RAD_DEFAULT_TOLERANCE 1e-4      /* tolerance of rad_solve_options,
                                           rad_hierarchy_options, rad_scene_solve_options */
#define RAD_DEFAULT_MAX_SWEEPS 10000    /* rad_solve_options.max_iterations: gathering */
#define RAD_DEFAULT_SHOTS_PER_PATCH 1000 /* rad_solve_options.max_iterations: shooting, n x */
#define RAD_DEFAULT_HIERARCHY_SWEEPS 1000 /* rad_hierarchy_options.max_iterations */
#define RAD_DEFAULT_REFINE_THRESHOLD 0.25 /* rad_hierarchy_options.refine_threshold */

/* ------------------------------------------------------------------------------------ */
/* Small value types                                                                     */

typedef struct rad_vec3 {
    double x, y, z;
} rad_vec3;

typedef struct rad_rgb {
    double r, g, b;
} rad_rgb;

/* A pinhole camera. fov_degrees is the VERTICAL field of view. */
typedef struct rad_camera {
    rad_vec3 eye;
    rad_vec3 target;
    rad_vec3 up;
    double fov_degrees;
} rad_camera;

/* ------------------------------------------------------------------------------------ */
/* Scene: triangles with materials, grouped into named surfaces                          */

/* A texture: linear RGB texels (decoded from 8-bit sRGB PNG or JPEG, the encoding of MTL
 * maps and of glTF's baseColorTexture and emissiveTexture), row 0 at the top. Looked up
 * bilinearly, repeating outside [0,1]. */
typedef struct rad_texture {
    char source[512]; /* the image file, or "FILE#N" for an image a glb embeds */
    uint32_t width, height;
    float *rgb;       /* width * height * 3 */
} rad_texture;

typedef struct rad_material {
    char name[128];
    rad_rgb albedo;   /* diffuse reflectance rho, linear RGB in [0,1] (MTL Kd) */
    rad_rgb emission; /* emitted radiance L_e, linear RGB >= 0 (MTL Ke) */
    rad_rgb specular; /* Phong specular and mirror reflectance K_S, [0,1] (MTL Ks); radiosity
                         ignores it, the ray tracer and `render --specular` use it */
    double shininess; /* Phong exponent n (MTL Ns), >= 0 */
    uint32_t albedo_texture; /* 1 + index into rad_scene.textures (MTL map_Kd, glTF
                                baseColorTexture): the albedo is then `albedo` times the
                                texel; 0 = none */
    uint32_t emission_texture; /* 1 + index into rad_scene.textures (MTL map_Ke, glTF
                                  emissiveTexture): the emitted radiance is then `emission`
                                  times the texel (linear RGB); 0 = none. Either texture is
                                  read at the triangle's texture coordinates (rad_scene.uv) */
} rad_material;

/* A surface is what the user named: an OBJ object (o) or group (g). Its triangles are the
 * contiguous range [first_triangle, first_triangle + triangle_count). */
typedef struct rad_surface {
    char name[128];
    uint32_t first_triangle;
    uint32_t triangle_count;
    uint32_t flags;    /* RAD_SURFACE_* below; 0 for a plain one-sided surface */
    double emissivity; /* hemispherical emissivity in (0,1] for grey-body exchange
                          (View3D's `emit` field); 0.9 unless the input says otherwise */
} rad_surface;

#define RAD_SURFACE_OBSTRUCTION (1u << 0) /* blocks rays but has no row or column of view
                                            factors (View3D `O`, `--obstruction FILE`) */
#define RAD_SURFACE_TWO_SIDED (1u << 1)   /* both sides radiate and receive: view factors
                                            give it one row whose area is twice the
                                            triangles'; the mesh gives each side its own
                                            patches (rad_patch.twin) (`--two-sided NAME`,
                                            glTF doubleSided) */

typedef struct rad_triangle {
    uint32_t vertex[3]; /* indices into rad_scene.positions, counter-clockwise = front */
    uint32_t material;  /* index into rad_scene.materials */
    uint32_t surface;   /* index into rad_scene.surfaces */
} rad_triangle;

/* Plain data, owned by the library; read it freely, change it only through the functions
 * below. After a successful load every triangle is non-degenerate, every coordinate is
 * finite, every index is in range and every albedo is in [0,1]. */
typedef struct rad_scene {
    rad_vec3 *positions;
    uint32_t position_count;
    rad_triangle *triangles;
    uint32_t triangle_count;
    rad_material *materials;
    uint32_t material_count;
    rad_surface *surfaces;
    uint32_t surface_count;
    rad_texture *textures;
    uint32_t texture_count;
    float (*uv)[3][2]; /* per triangle, per corner texture coordinates (u, v), v = 0 at an
                          image's bottom; NULL when no textured triangle has any */
    bool has_camera;   /* the file (or the built-in scene) defines a camera */
    rad_camera camera; /* valid when has_camera */
    rad_vec3 up;        /* the file's up direction, unit length: (0,1,0) unless the file says
                           otherwise (FBX UpAxis metadata); the default camera keeps it up */
    double unit_metres; /* metres per scene unit when the file says (glTF: 1; Collada: 1,
                           Assimp having applied its <unit> and <up_axis>; FBX:
                           UnitScaleFactor / 100), else 0. This library never rescales */
    char source[512];  /* file the scene came from, or "(built-in Cornell box)" */
    struct rad_light *lights; /* light sources besides emissive surfaces (rad_light), from
                                 the file (glTF KHR_lights_punctual, Assimp's lights) or
                                 added with rad_scene_add_light */
    uint32_t light_count;
    rad_vec3 north;     /* unit, perpendicular to up; zero = the default (rad_scene_north) */
} rad_scene;

typedef struct rad_load_options {
    rad_log_fn log; /* warnings: skipped degenerate triangles, missing emitters, ... */
    void *log_user;
} rad_load_options;

/* The albedo (grey) of surfaces whose file gives no material: STL, PLY without a material
 * element, OBJ faces before any usemtl, glTF primitives without a material. */
#define RAD_DEFAULT_ALBEDO 0.5

/* Reads a scene file through Assimp: OBJ + MTL, glTF 2.0 (.gltf, .glb), STL, FBX,
 * Collada, 3DS and the other formats Assimp reads; PLY (by extension, or content starting
 * "ply" and a line end) is read by the project itself: vertex x y z, faces fanned into
 * triangles, one surface named after the file, the first row of a material element as
 * its material (diffuse_* albedo, specular_*, specular_power), per-vertex colours unused. Materials map onto METHOD.md's units:
 * MTL Kd and glTF baseColorFactor are the albedo; MTL Ke, and glTF emissiveFactor times
 * KHR_materials_emissive_strength (read from the file's JSON: Assimp 5.2 drops it), the
 * emitted radiance; MTL map_Kd / glTF baseColorTexture and MTL map_Ke / glTF
 * emissiveTexture (PNG or JPEG, sRGB, in a file or inside a .glb) are decoded into
 * rad_scene.textures and multiply them (rad_material). A texture that is missing or
 * unreadable is a warning (the value is then the factor alone), and so is an emission
 * texture under an emission factor of 0 (it shows nothing). A surface is a mesh's name (OBJ o/g, glTF mesh, STL solid), else its
 * node's, else the file's name without extension. The first glTF camera becomes the
 * scene's camera. Lights become rad_scene.lights: glTF KHR_lights_punctual (read from the
 * JSON: each node of the default scene holding one, at its world transform, along its -Z;
 * color x intensity; a malformed light is an error), and Assimp's point, spot and
 * directional lights for other formats (their colour taken as cd or lux, a warning says
 * so; area and ambient lights skipped with a warning). A glTF material's doubleSided
 * makes every surface using it RAD_SURFACE_TWO_SIDED. A material with a specular colour
 * (MTL Ks) but a black diffuse one is a warning: radiosity sees it black. Degenerate
 * triangles are skipped with a warning;
 * non-finite coordinates, a missing material library or glTF buffer, a truncated .glb, an
 * index out of range, unreadable or empty files are errors. A View3D input file is read by
 * rad_scene_load_vs3 below (*.vs3, or View3D content). */
rad_status rad_scene_load(const char *path, const rad_load_options *options,
                          rad_scene **out, rad_error *error);

/* The control line (`C`) and title (`T`) of a View3D input file, with View3D's defaults
 * for what the file leaves out. radiosity honours `encl` and `emit` (the CLI applies
 * --enclosure and --script-f for them) and reads the rest for the record: the engine has
 * its own accuracy control, and always computes every row and column. */
typedef struct rad_vs3_control {
    char title[256];   /* the last T line, "" if none */
    double eps;        /* integration convergence criterion; 1e-4 */
    uint32_t max_u;    /* maxU: recursions for unobstructed factors; 12 */
    uint32_t max_o;    /* maxO: recursions for obstructed factors; 8 */
    uint32_t min_o;    /* minO: least recursions for obstructed factors; 0 */
    uint32_t row, col; /* a single row / column to compute (0 = all) */
    bool enclosure;    /* encl=1: the surfaces form an enclosure */
    bool emit;         /* emit=1: report script-F factors with the surfaces' emissivities */
    uint32_t out;      /* View3D's output format: 0 text, 1 binary */
    uint32_t list;     /* View3D's log detail */
} rad_vs3_control;

/* Reads a View3D 3.x input file with `F 3` geometry (vertices and surfaces given
 * separately). Lines (the first letter in either case; a token starting with `!` or `/`
 * begins a comment, also after data):
 *   T title            C name=value ...  (eps maxU maxO minO row col encl emit out list)
 *   F 3                V n x y z
 *   S|O|M|N n v1 v2 v3 v4 base cmb emit [name]    (v4 = 0 for a triangle)
 *   E, e or * (End of data): the rest of the file is not read.
 * Each S or O polygon becomes triangles of the surface named `name` (its number when the
 * name is missing); counter-clockwise from the front as in View3D. A quadrilateral must
 * be planar (its fourth vertex within 1e-5 of its size from the plane of the first three)
 * and convex. `cmb` = K joins the polygon to surface K's (View3D's combination: the same
 * view factors as its post-processing algebra; the emissivity is the area-weighted mean).
 * O surfaces get RAD_SURFACE_OBSTRUCTION: they block, they have no row or column.
 * `base` = K makes a subsurface (a window in wall K): as View3D's post-processing does,
 * K's own factors and area then exclude the subsurface, which is done here by cutting
 * the subsurface out of K's polygon into convex pieces. An N (null) surface is cut out of
 * its base the same way and is kept as an obstruction (it still blocks, it has no row),
 * which is View3D's "area of the base reduced, null removed from the matrix". Checked,
 * each with the line number: subsurfaces, null and mask surfaces lie in their base's
 * plane, inside it, facing the same way (null, mask: the opposite way, with a radiating
 * S base); base and cmb refer to earlier surfaces. An M (mask) surface lies on its base facing it: View3D makes the masked part
 * of the base exchange with the mask only (F_mask,base = 1). It is cut out of its base
 * like a null surface and kept as an obstruction for the computation; then
 * rad_viewfactor_matrix_apply_vs3_masks gives the mask its row and column and the base its
 * whole area. Not supported (RAD_ERR_UNSUPPORTED naming the line): `F 3a` and other
 * geometry kinds. Errors with the line number: a malformed line, an undefined or
 * repeated vertex, a vertex used twice in one surface, a non-planar or non-convex
 * quadrilateral, a zero-area surface, a repeated surface number or name, an emissivity
 * outside (0,1], a bad control value. Unknown control names are warnings. `control`
 * (optional) receives the C and T lines. rad_scene_load calls this for files named
 * *.vs3 and for files whose content is View3D's (first data line T, C or F, and a line
 * `F 3` alone). */
rad_status rad_scene_load_vs3(const char *path, const rad_load_options *options,
                              rad_scene **out, rad_vs3_control *control, rad_error *error);

/* True when rad_scene_load would read `path` as a View3D file (by name or content, as
 * above); false too when it cannot be opened. */
bool rad_scene_is_vs3(const char *path);

/* One input of rad_scene_load_files. */
typedef struct rad_scene_file {
    const char *path;
    uint32_t flags;     /* RAD_SURFACE_* for the file's surface(s), ORed into their own */
    bool keep_surfaces; /* keep the file's own surfaces (OBJ objects and groups, View3D
                           surfaces) instead of making the file one surface */
} rad_scene_file;

/* Several mesh files (any format rad_scene_load reads) as one scene in which each file is
 * ONE surface, named after the file's base name without its extension ("walls/north.stl"
 * is "north"), with `flags` (RAD_SURFACE_OBSTRUCTION for meshes that only block) and the
 * area-weighted mean emissivity of the file's own surfaces; or, with keep_surfaces, the
 * file's own surfaces with their names, flags and emissivities. A surface name that two
 * files give is RAD_ERR_INVALID. Materials are kept without their textures, albedo and
 * emission (view factors do not depend on them). */
rad_status rad_scene_load_files(const rad_scene_file *files, uint32_t count,
                                const rad_load_options *options, rad_scene **out,
                                rad_error *error);

/* Sets `flags` (ORed in) on what `name` names: the surface by that name, else every
 * surface with triangles of the material(s) by that name, the name matched as by
 * rad_scene_set_material. RAD_ERR_INVALID with its message when nothing matches. */
rad_status rad_scene_set_surface_flags(rad_scene *scene, const char *name, uint32_t flags,
                                       rad_error *error);

/* The Cornell box of the Cornell University Program of Computer Graphics (millimetres,
 * y up), with its official camera. Same geometry and materials as
 * shared/scenes/cornell-box.obj. */
rad_status rad_scene_cornell_box(rad_scene **out, rad_error *error);

void rad_scene_destroy(rad_scene *scene);

/* Total area of the scene's triangles, and its bounding box. */
double rad_scene_area(const rad_scene *scene);
void rad_scene_bounds(const rad_scene *scene, rad_vec3 *lo, rad_vec3 *hi);

/* True when some material with triangles has non-zero emission: an emission factor > 0
 * and, with an emission texture, a texel that is not black in a channel where the factor
 * is > 0. */
bool rad_scene_has_emitter(const rad_scene *scene);

/* A camera that frames the whole scene from the front: for a y-up scene from the -z side
 * looking +z; for a z-up scene (scene->up) from the -y side looking +y; up = scene->up. */
rad_camera rad_scene_default_camera(const rad_scene *scene);

/* Sets the albedo and/or the emitted radiance (either may be NULL) of what `name` names:
 * a surface by that name, else every material by that name (files repeat names; to set
 * one of them, name a surface that uses it); matched exactly, else ignoring case when that
 * leaves one surface or one material name. A surface keeps its other
 * material values, its textures included (a value set is the factor its texture then
 * multiplies); when its material is shared with triangles of other surfaces, it gets
 * its own copy first, so nothing else changes. RAD_ERR_INVALID, naming `name`, when
 * several names match ignoring case (the message lists them), when nothing matches
 * ("no surface or material 'X' in FILE; did you mean 'Y'?", Y the closest name by edit
 * distance), or when a value is out of its domain (albedo in [0,1], emission >= 0, both
 * finite). */
rad_status rad_scene_set_material(rad_scene *scene, const char *name, const rad_rgb *albedo,
                                  const rad_rgb *emission, rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Light sources besides emissive surfaces: point, spot, sun, sky, environment, luminaire */

/* Units. A light given in photometric units (intensity in candela, illuminance in lux,
 * luminance in cd/m^2) makes every radiance of the answer a luminance in cd/m^2 and every
 * irradiance an illuminance in lux (per RGB channel: a white light is equal in all three);
 * given in W/sr, W/m^2 and W/(m^2 sr) it gives W/(m^2 sr) and W/m^2. Emitted radiance of a
 * surface (Ke) is in the same unit as a luminance. Distances to point-like lights are
 * converted to metres with rad_scene.unit_metres (1 when 0), so a 100 cd lamp 2 m above
 * a floor gives 25 lux there whether the scene is in metres or millimetres. A light whose
 * file gives no unit (rad_light.unit_unknown: Collada and FBX lights), an environment map
 * (the map's own unit) or emitting surfaces alone make the answer relative: `radiosity
 * render --false-colour` then labels its legend "relative" instead of lx or cd/m^2. */

typedef enum rad_light_type {
    RAD_LIGHT_POINT = 1,   /* isotropic: intensity I (cd) in every direction */
    RAD_LIGHT_SPOT,        /* I inside inner_degrees of `direction`, 0 outside outer_degrees,
                              between them glTF's smooth falloff (KHR_lights_punctual:
                              t = clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1),
                              I t^2) */
    RAD_LIGHT_DIRECTIONAL, /* the sun: illuminance E_n (lux) on a plane facing it, arriving
                              along `direction` from a disk of angular_diameter_degrees */
    RAD_LIGHT_SKY,         /* a sky dome over the upper hemisphere of rad_scene.up: the
                              luminance distribution `sky`, scaled by `intensity` (the
                              zenith luminance, cd/m^2); nothing below the horizon */
    RAD_LIGHT_ENVIRONMENT, /* an equirectangular radiance map (`environment`) at infinity,
                              times `intensity` */
    RAD_LIGHT_LUMINAIRE    /* a photometric web (`photometry`, IES LM-63) at `position`,
                              its nadir (vertical angle 0) along `direction`, horizontal
                              angle 0 along `reference`; times `intensity` (1,1,1 = as the
                              file says) */
} rad_light_type;

typedef enum rad_sky_model {
    RAD_SKY_UNIFORM = 1,  /* L = L_z everywhere above the horizon: E_horizontal = pi L_z */
    RAD_SKY_CIE_OVERCAST, /* CIE standard overcast (Moon and Spencer): L = L_z (1 + 2 sin h)
                             / 3, h the elevation: E_horizontal = 7 pi L_z / 9 */
    RAD_SKY_CIE_CLEAR     /* CIE standard clear sky (CIE S 011 type 12), its sun along the
                             light's `direction` (the sun's own light is a separate
                             RAD_LIGHT_DIRECTIONAL) */
} rad_sky_model;

/* A photometric web read from an IES LM-63 file (rad_photometry_read). Candela values are
 * absolute (the file's multiplier and ballast factors applied). */
typedef struct rad_photometry {
    char source[512];            /* the file */
    uint32_t photometric_type;   /* 1 = type C (the usual), 2 = type B, 3 = type A */
    uint32_t vertical_count;     /* angles as the file lists them, ascending, degrees */
    uint32_t horizontal_count;
    double *vertical_degrees;
    double *horizontal_degrees;
    double *candela;             /* [h * vertical_count + v] */
    double lumens;               /* the flux of the web, integrated over the sphere (lm) */
} rad_photometry;

/* Reads an IES LM-63 file (1986, 1991, 1995, 2002 and 2019 headers; TILT=NONE, or the
 * tilt data of TILT=INCLUDE or of a TILT file beside it ignored with a warning through
 * `log`), every symmetric variant of the horizontal angles (a single 0: symmetric about the
 * axis; 0..90 quadrant; 0..180 bilateral; 90..270; 0..360). RAD_ERR_IO when it cannot be
 * read; RAD_ERR_PARSE naming the file and line for a short table, angles that are not
 * ascending or out of range, a bad header, count or number, a negative candela value or
 * multiplier, NUL bytes, a file over 16 MiB. */
rad_status rad_photometry_read(const char *path, rad_log_fn log, void *log_user,
                               rad_photometry **out, rad_error *error);
void rad_photometry_destroy(rad_photometry *photometry);

/* Candela toward (vertical angle, horizontal angle), degrees, photometric type C
 * conventions (vertical 0 = nadir, 180 = zenith; horizontal counter-clockwise seen from
 * above); bilinear in the table, the symmetric variants unfolded; 0 outside the table's
 * vertical range. Types A and B take the file's own angles, vertical and horizontal in
 * [-90, 90] (horizontal mirrored when the file lists 0..90), 0 beyond. */
double rad_photometry_candela(const rad_photometry *photometry, double vertical_degrees,
                              double horizontal_degrees);

typedef struct rad_light {
    rad_light_type type;
    char name[128];            /* what the file or the command line calls it */
    rad_vec3 position;         /* point, spot, luminaire: scene units */
    rad_vec3 direction;        /* unit. spot: its axis; luminaire: its nadir; directional
                                  and the clear sky's sun: the way the light travels (from
                                  the sun down to the scene) */
    rad_vec3 reference;        /* luminaire: horizontal angle 0 (perpendicular to direction;
                                  zero: chosen from the scene's axes) */
    rad_rgb intensity;         /* point, spot: I (cd); directional: E_n (lux); sky: zenith
                                  luminance (cd/m^2); environment, luminaire: a factor */
    double inner_degrees;      /* spot: half-angles from the axis, 0 <= inner <= outer <= 90 */
    double outer_degrees;
    double angular_diameter_degrees; /* directional: the disk seen (the sun: 0.53); 0 = a
                                        point at infinity, hard shadows */
    rad_sky_model sky;         /* RAD_LIGHT_SKY */
    double rotate_degrees;     /* environment: turned about rad_scene.up */
    rad_photometry *photometry; /* luminaire: owned by the scene once added */
    struct rad_image *environment; /* environment: owned by the scene once added */
    bool unit_unknown;         /* the file gives `intensity` in no known unit (Assimp's
                                  Collada and FBX lights: their colour, taken as cd or lux
                                  as given); results lit by it are relative, not photometric */
} rad_light;

/* Adds a copy of `light` to the scene (rad_scene.lights); on success the scene owns its
 * photometry and environment (freed by rad_scene_destroy), on failure the caller keeps
 * them. RAD_ERR_INVALID with a message naming the light for: a type out of range, a
 * non-finite value, a negative intensity, a zero direction where one is needed, spot
 * angles outside 0 <= inner <= outer <= 90, an angular diameter outside [0, 20), a
 * luminaire without photometry, an environment map that is missing or not 2:1;
 * RAD_ERR_UNSUPPORTED for a luminaire whose web is of photometric type B or A (type C, the
 * usual, only). */
rad_status rad_scene_add_light(rad_scene *scene, const rad_light *light, rad_error *error);

/* "point", "spot", "sun", "sky", "environment", "luminaire". Never NULL. */
const char *rad_light_type_name(rad_light_type type);

/* The scene's north (unit, perpendicular to rad_scene.up): -z for a y-up scene, +y for a
 * z-up one, unless rad_scene.north was set. East is north x up. */
rad_vec3 rad_scene_north(const rad_scene *scene);

/* Where the sun is: latitude and longitude in degrees (north and east positive), the
 * local date and time and the time zone's offset from UTC in hours (east positive), by
 * NOAA's solar position algorithm (its Solar Calculator spreadsheet, after Meeus; about
 * 0.01 degree for 1900..2100), its standard-atmosphere refraction added to the elevation.
 * Azimuth in degrees clockwise from north, in [0, 360); elevation in degrees above the
 * horizon. Either output may be NULL. RAD_ERR_INVALID, naming the field and its value,
 * for a latitude outside [-90, 90], a longitude outside [-180, 180], a year outside
 * 1900..2200, a month outside 1..12, a day the month lacks (leap years counted), an hour
 * outside [0, 24], an offset outside [-14, 14], or a NULL `when`. */
typedef struct rad_place_time {
    double latitude, longitude;
    int year, month, day;
    double hour;               /* local time, e.g. 13.5 for half past one */
    double utc_offset_hours;
} rad_place_time;

rad_status rad_sun_position(const rad_place_time *when, double *azimuth_degrees,
                            double *elevation_degrees, rad_error *error);

/* The sky's luminance relative to its zenith (L / L_z) toward a direction `elevation`
 * radians above the horizon, `gamma` radians from the sun, the sun `sun_elevation`
 * radians high (gamma and the sun used by RAD_SKY_CIE_CLEAR only: CIE S 011 type 12,
 * a = -1, b = -0.32, c = 10, d = -3, e = 0.45; a sun below the horizon is taken as it
 * stands). 0 below the horizon, for a NaN angle and for an unknown model. */
double rad_sky_relative_luminance(rad_sky_model sky, double elevation, double gamma,
                                  double sun_elevation);

/* The illuminance of an unobstructed horizontal plane under a sky of zenith luminance 1
 * (the integral of L / L_z sin h over the upper hemisphere): pi for the uniform sky,
 * 7 pi / 9 for the CIE overcast one, by quadrature for the clear sky with its sun
 * `sun_elevation` radians high. */
double rad_sky_horizontal_factor(rad_sky_model sky, double sun_elevation);

/* ------------------------------------------------------------------------------------ */
/* Mesh: the scene split into patches                                                    */

/* A patch is a planar triangle (vertex_count 3) or convex quadrilateral (vertex_count 4),
 * counter-clockwise seen from its front. */
typedef struct rad_patch {
    uint32_t vertex[4];   /* indices into rad_mesh.vertices; vertex[3] unused for triangles */
    uint32_t vertex_count; /* 3 or 4 */
    uint32_t surface;     /* index into the scene's surfaces */
    uint32_t material;    /* index into the scene's materials */
    double area;          /* scene units squared */
    rad_vec3 normal;      /* unit front normal */
    rad_vec3 centroid;
    double bulge;         /* 0 for a planar patch; for a cell of a slightly folded quad
                             (real data: the Cornell box's left wall folds by 0.47 degrees),
                             how far the quad's cells may stray from its input triangles,
                             either way: a quarter of the fold's lift */
    double behind;        /* how far this cell lies behind the input triangles, which are
                             what blocks rays (0 for a planar patch, and for a cell of a
                             folded quad that lies in front of them): rays leaving its front
                             start twice this in front */
    uint32_t twin;        /* 0 for a one-sided patch; on a two-sided surface
                             (RAD_SURFACE_TWO_SIDED), 1 + the index of the patch on the
                             other side: the same cell, corners in reverse order (so its
                             normal is opposite), its own vertices and its own radiosity */
} rad_patch;

/* Vertices are shared by the patches of one smooth region (coplanar input triangles of one
 * surface and one material), so values reconstructed at vertices interpolate without seams
 * inside a region and keep creases sharp between regions. A two-sided surface's patches
 * come twice: the front patches among the others in scene order, then, after every
 * one-sided and front patch, their twins (rad_patch.twin) in the same order, each side a
 * region of its own. Every solver thus sees two ordinary one-sided patches (a twin and its
 * front are coplanar and back to back: F = 0 between them), and both sides radiate and
 * receive. */
typedef struct rad_mesh {
    rad_vec3 *vertices;
    uint32_t vertex_count;
    rad_patch *patches;
    uint32_t patch_count;
    double patch_size; /* the longest-edge limit the mesh was built with */
    int shadow_levels, proximity_levels; /* and its rad_mesh_options' levels */
    uint32_t shadow_splits;     /* cells split where a sharp light's shadow edge crosses
                                   them (rad_mesh_options.shadow_levels) */
    bool shadow_budget_reached; /* the splits stopped at max_added_patches */
    uint32_t proximity_splits;  /* cells split because other surfaces are near them
                                   (rad_mesh_options.proximity_levels) */
    bool proximity_budget_reached; /* those splits stopped at max_added_patches */
} rad_mesh;

/* A patch size that gives roughly `target_patches` patches for the scene's area; 0 when
 * out of memory. */
double rad_mesh_default_patch_size(const rad_scene *scene, uint32_t target_patches);

/* The patches a mesh of this patch size would have before any shadow or proximity split;
 * 0 when out of memory. */
double rad_mesh_patch_count_at(const rad_scene *scene, double patch_size);

/* Splits every triangle (pairs of triangles forming a convex quadrilateral are merged
 * first) into patches whose edges are no longer than patch_size; the patches of
 * RAD_SURFACE_TWO_SIDED surfaces get their twins (above). */
rad_status rad_mesh_build(const rad_scene *scene, double patch_size, rad_mesh **out,
                          rad_error *error);

/* Shadow refinement. A patch carries one radiosity, so a shadow edge or a penumbra across
 * it is smeared over it. Where the scene's point, spot, luminaire or sun lights cast a
 * shadow (or a cone's edge) across a cell, or an emitting surface's penumbra crosses it,
 * the mesh splits the cell in four (quads into four quads, triangles into four similar
 * triangles), and the children again, `shadow_levels` times at most: shadow edges and
 * penumbrae are met at the patch size / 2^levels, in every solver (the hierarchical
 * solver's leaves are these patches) and in the lit mesh. A cell is split when, at 4 x 4
 * points of it (both sides for a two-sided surface), the share of the irradiance that the
 * shadow rays let through (the sharp lights', and 32 fixed points on the emitters, chosen
 * by power) differs by more than 1/4 between two points and that difference is more than
 * 1/4 of the light there; smooth fall-off never splits. The sky's shadows do not split
 * patches. The splits stop when they have added max_added_patches. */
#define RAD_SHADOW_LEVELS_DEFAULT 1
#define RAD_SHADOW_LEVELS_MAX 6

/* Proximity refinement. One patch size for a scene comes from the whole scene's extent,
 * so a room on a ground plane twenty times its size would get patches as large as its
 * walls. The light changes over the distance from a point to the surfaces it exchanges
 * light with, so every cell sends 32 cosine-weighted rays from its centre (both sides for
 * a two-sided surface): when a quarter of them or more meet a surface (the front of it:
 * a cell under a box or inside an object is left alone) and the cell's longest edge is
 * more than 1/3 of their mean distance, it is split in four, and the children again,
 * `proximity_levels` times at most. Open ground under the sky keeps its size; the
 * Cornell box keeps its default patches (its cells are a tenth of that distance). The CLI
 * asks for RAD_PROXIMITY_LEVELS_DEFAULT when the patch size is its automatic one
 * (rad_default_patch_size), and for none with an explicit --patch-size. */
#define RAD_PROXIMITY_LEVELS_DEFAULT 3
#define RAD_PROXIMITY_LEVELS_MAX 8

typedef struct rad_mesh_options {
    double patch_size;          /* the longest edge of a patch (required, > 0) */
    int shadow_levels;          /* 0: RAD_SHADOW_LEVELS_DEFAULT; -1: none; at most
                                   RAD_SHADOW_LEVELS_MAX */
    int proximity_levels;       /* 0: none; at most RAD_PROXIMITY_LEVELS_MAX */
    uint32_t max_added_patches; /* per refinement; 0: as many as the unrefined mesh has,
                                   at least 4096 */
} rad_mesh_options;

/* rad_mesh_build with options (rad_mesh_build is this with patch_size alone). */
rad_status rad_mesh_build_with(const rad_scene *scene, const rad_mesh_options *options,
                               rad_mesh **out, rad_error *error);

void rad_mesh_destroy(rad_mesh *mesh);

/* Each patch's average albedo and average emitted radiance L_e (not the exitance: that is
 * pi times it): its material's values, or for a textured material the mean over 8 x 8
 * points of the patch of albedo x albedo texel and of emission x emission texel, each
 * point's texel read at the scene triangle under it. `albedo` and `emission` (either may
 * be NULL) receive mesh->patch_count values. rad_patch_inputs_build uses it. */
rad_status rad_patch_materials(const rad_scene *scene, const rad_mesh *mesh, rad_rgb *albedo,
                               rad_rgb *emission, rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Tracer: ray queries against a triangle set                                            */

typedef enum rad_tracer_backend {
    RAD_TRACER_EMBREE = 0,  /* Embree 3 BVH, watertight (robust mode): the default */
    RAD_TRACER_BRUTE_FORCE, /* tests every triangle: a test oracle, slow */
    RAD_TRACER_EMBREE_FAST  /* Embree 3 BVH, not watertight, about 1.6x faster: a ray may
                               rarely slip along an edge two triangles share. For the
                               occlusion segments of form factors, where that is one
                               segment of many; never for camera rays */
} rad_tracer_backend;

/* A ray or segment: points origin + t * direction for t in [t_near, t_far]. direction
 * need not be unit length; t is measured in units of it. */
typedef struct rad_ray {
    float origin[3];
    float t_near;
    float direction[3];
    float t_far;
} rad_ray;

#define RAD_NO_HIT UINT32_MAX

/* A miss is {RAD_NO_HIT, t = INFINITY, u = v = 0, front = false}. */
typedef struct rad_hit {
    uint32_t triangle; /* index of the triangle hit, or RAD_NO_HIT */
    float t;           /* ray parameter of the hit */
    float u, v;        /* barycentric: point = (1-u-v) p0 + u p1 + v p2 */
    bool front;        /* the ray hit the triangle's front (counter-clockwise) side */
} rad_hit;

typedef struct rad_tracer rad_tracer;

/* Builds the acceleration structure over `triangle_count` triangles given as vertex
 * indices into `positions`. The tracer copies what it needs. RAD_ERR_INVALID for an index
 * out of range or a position that is not finite or does not fit a float. Zero triangles
 * is allowed: every ray misses. */
rad_status rad_tracer_create(rad_tracer_backend backend, const rad_vec3 *positions,
                             uint32_t position_count, const uint32_t (*triangles)[3],
                             uint32_t triangle_count, rad_tracer **out, rad_error *error);

/* A tracer over every triangle of the scene (the occluders for form factors). */
rad_status rad_tracer_create_for_scene(rad_tracer_backend backend, const rad_scene *scene,
                                       rad_tracer **out, rad_error *error);

void rad_tracer_destroy(rad_tracer *tracer);

/* The query contract (hot path: nothing is checked): every ray has finite values, a
 * non-zero direction and 0 <= t_near; t_near > t_far means nothing can be hit. Both sides
 * of every triangle count. Pass a few hundred rays or more per call for full speed. */

/* For each ray, occluded[k] = 1 when any triangle is hit for t in [t_near, t_far].
 * Safe to call from several threads at once. */
void rad_tracer_occluded(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                         uint8_t *occluded);

/* Closest hit for each ray. Safe to call from several threads at once. */
void rad_tracer_intersect(const rad_tracer *tracer, const rad_ray *rays, uint32_t count,
                          rad_hit *hits);

/* The same, for rays given in coherent runs (one origin, directions that turn little from
 * one ray to the next, as a hemisphere's strata in order): traced as packets, which is
 * faster for such rays and slower for scattered ones. The same hits. */
void rad_tracer_intersect_coherent(const rad_tracer *tracer, const rad_ray *rays,
                                   uint32_t count, rad_hit *hits);

/* ------------------------------------------------------------------------------------ */
/* Form factors                                                                          */

typedef struct rad_formfactor_options {
    uint32_t quadrature;     /* each patch is split m x m for the analytic part; 0 = 1; up
                                to 3, pairs far apart take the kernel's expansion instead */
    uint32_t visibility_rays; /* rays per patch pair that something may block (rounded to
                                 a square); 0 = 16. Pairs nothing can block get none */
    uint64_t seed;            /* seeds the stratified sample points */
    int threads;              /* 0 = all cores */
    rad_progress_fn progress;
    void *progress_user;
    const double *area;       /* NULL: F_ij = G_ij / the patch's area; else G_ij / area[i].
                                 rad_solve_scene gives rad_patch_inputs.area (the open part
                                 of a patch that runs under a box), whose means the inputs
                                 hold */
} rad_formfactor_options;

/* Counts what a form-factor computation did. */
typedef struct rad_formfactor_report {
    uint64_t pairs;            /* patch pairs considered (i < j) */
    uint64_t pairs_facing;     /* pairs that face each other and needed work */
    uint64_t pairs_refined;    /* pairs whose visibility was sampled with the full set of
                                  segments */
    uint64_t pairs_clear;      /* pairs nothing can come between: no segment needed */
    uint64_t pairs_exact;      /* pairs settled exactly with no segment: close pairs by
                                  shadow clipping, others proven hidden by one triangle */
    uint64_t rays;             /* occlusion rays cast */
    double seconds;            /* wall-clock time of the whole computation */
    double tracing_seconds;    /* time spent tracing, summed over threads */
    int threads;               /* threads used */
    uint32_t rows_trimmed;     /* rows whose sum came out above 1 + RAD_ROW_SUM_SLACK (no
                                  patch sees more than its hemisphere), scaled back to 1
                                  keeping reciprocity */
    double largest_row_sum;    /* the largest row sum before that */
    uint32_t largest_row;      /* its patch */
    uint32_t rank_rows;        /* rows i (with their pairs j > i) this process computed:
                                  all of them unless shared over MPI ranks */
    double rank_seconds;       /* this process's time computing its pairs (no waiting) */
} rad_formfactor_report;

/* The dense n x n matrix, row-major: F[i * n + j] = F_ij. Reciprocity holds exactly by
 * construction (A_i F_ij = A_j F_ji up to float rounding). */
typedef struct rad_formfactors {
    uint32_t n;
    float *F;
    double *area; /* n: the areas the rows were made with, A_i F_ij = A_j F_ji (the
                     patches', or rad_formfactor_options.area); rad_system_of takes these.
                     NULL (a matrix read back from a checkpoint): the patch inputs' */
} rad_formfactors;

/* Computes every F_ij of the mesh. `occluders` is a tracer over the scene's triangles (any
 * backend). The unoccluded point-to-patch factor is analytic (Lambert's contour formula,
 * integrated over the smaller patch: an m x m midpoint rule for pairs far apart, 4 x 4
 * for pairs close by, adaptive for touching pairs). A pair whose hull no triangle of
 * `occluders` cuts is visible as a whole, with no ray cast; a touching pair that at most
 * four triangles cut (a wall through a patch, a box on a floor) gets the exact visible
 * factor by shadow clipping, as the view-factor engine does; any other pair's visibility
 * is the kernel-weighted fraction of unoccluded rays between stratified points of the two
 * patches, with surfaces within a hair of either end tested in double precision. Rows
 * then sum to what the patch sees within RAD_ROW_SUM_SLACK. As a last guard, a row above
 * 1 + RAD_ROW_SUM_SLACK is scaled back to 1, each F_ij and F_ji by the same factor, and
 * counted in the report (rows_trimmed, largest_row_sum). After rad_ranks_begin joined a
 * job of several MPI ranks this is collective: every rank calls it with the same mesh and
 * options, computes the rows i (pairs j > i) given to it by their pair count, and every
 * rank gets the whole matrix, bitwise the serial one, with the report's counts summed
 * (rank_rows, rank_seconds: its own). A failure on any rank fails it on every rank. */
rad_status rad_formfactors_compute(const rad_mesh *mesh, const rad_tracer *occluders,
                                   const rad_formfactor_options *options,
                                   rad_formfactors **out, rad_formfactor_report *report,
                                   rad_error *error);

void rad_formfactors_destroy(rad_formfactors *formfactors);

/* The physical invariants of a form-factor matrix, measured. */
typedef struct rad_formfactor_check {
    double reciprocity;     /* largest |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji) over
                               pairs with a factor above 1e-6 */
    double largest_row_sum; /* max_i sum_j F_ij: above 1 means a row creates energy */
    double closure;         /* max_i |sum_j F_ij - 1|: meaningful for closed scenes only */
    double largest_factor;  /* max F_ij */
    uint32_t empty_rows;    /* patches that see nothing (hidden, or facing out of the scene) */
} rad_formfactor_check;

void rad_formfactors_check(const rad_formfactors *formfactors, const rad_mesh *mesh,
                           rad_formfactor_check *check);
/* The same with the areas the rows were made with (rad_formfactor_options.area; NULL: the
 * patches'), which reciprocity is measured with. */
void rad_formfactors_check_areas(const rad_formfactors *formfactors, const rad_mesh *mesh,
                                 const double *area, rad_formfactor_check *check);

/* ------------------------------------------------------------------------------------ */
/* View factors for engineers: surface to surface, sparse, with error bounds             */

/* A surface-to-surface view-factor matrix in compressed sparse rows. Rows and columns are
 * the scene's surfaces (n = scene->surface_count); obstruction surfaces have empty rows
 * and columns. Only non-zero factors are stored, columns ascending within a row, and the
 * sampled factors that came out 0 but carry an error bound (value 0, error_bound > 0). */
typedef struct rad_viewfactor_matrix {
    uint32_t n;
    double *area;          /* n: A_I (twice the triangles' area for a two-sided surface) */
    uint64_t *row_start;   /* n + 1: row I is entries [row_start[I], row_start[I + 1]) */
    uint32_t *column;      /* row_start[n] column indices J */
    double *value;         /* F_IJ */
    double *error_bound;   /* estimated absolute error of each F_IJ (about two standard
                              errors of its sampled obstruction, never less than the 95 %
                              Poisson limit of its rarer outcome's count: when every
                              segment agreed, the binomial bound on what they could have
                              missed; the quadrature error where integrated exactly) */
} rad_viewfactor_matrix;

typedef struct rad_viewfactor_options {
    double accuracy;     /* 0 = 1e-4. Relative error target of each unobstructed factor
                            (adaptive quadrature of the exact point-to-polygon factor).
                            Obstructed pairs: an absolute error of F of at most accuracy
                            x sqrt(F unobstructed), so that a row's sum stays within
                            accuracy: behind up to exact_occluders triangles by the same
                            quadrature of the visible part (shadows clipped exactly),
                            behind more by sampled visibility, until max_rays (pairs no
                            sight ray met
                            are left out, which a row sum does not recover: see
                            sight_rays) */
    uint32_t max_rays;   /* visibility rays per sampled polygon pair at most; 0 = 1024 */
    uint32_t exact_occluders; /* polygon pairs with at most this many scene triangles in
                            between get exact shadow clipping (each quadrature point's
                            visible part of the other polygon, with the triangles that can
                            shade that part of the polygon only), to an absolute error of
                            F of accuracy x sqrt(F unobstructed); pairs with more are
                            sampled. 0 = RAD_DEFAULT_EXACT_OCCLUDERS (=
                            RAD_MAX_EXACT_OCCLUDERS, the most). Fewer: more sampled pairs,
                            whose bounds stop at max_rays far above the accuracy (4: 8-10
                            times faster on generated cities, 73 % of the 1k city's pairs
                            short of it), and less time */
    uint32_t sight_rays; /* cosine-distributed rays from each surface that find which pairs
                            see each other at all; a pair no ray of either side met is
                            taken as F = 0, within 3 / sight_rays absolute (95 % for each
                            pair), and is neither integrated nor proven hidden. 0 =
                            ceil(-ln 0.05 / accuracy), about 3 / accuracy (at most 2^26);
                            RAD_SIGHT_RAYS_NONE: none, every pair is integrated or proven
                            hidden (exact zeros; far slower on large open scenes) */
    uint64_t seed;
    int threads;         /* 0 = all cores */
    rad_progress_fn progress;
    void *progress_user;
    bool sky_exact;      /* rad_sky_viewfactors_compute only. false: a tile of the sky that
                            more than 16 triangles obstruct is sampled by rays (seconds; bounds
                            about 1e-2 in a city, far above the accuracy); true: clipped
                            exactly as a pair of the matrix is, behind up to exact_occluders
                            triangles: bounds within the accuracy on the generated cities
                            of 150 to 1,014 surfaces, at some 12 times the matrix's time on
                            the 1k one */
    /* Long runs (see rad_viewfactor_matrix_compute): */
    const char *checkpoint;     /* NULL: none. Restart file of the rows done so far, written
                                   atomically (rank 0 of an MPI job writes every rank's rows)
                                   when checkpoint_interval seconds have passed since the last
                                   one (checked between rounds of rows) and when stopped */
    double checkpoint_interval; /* seconds; 0: after every round (1/64 of the rows) */
    const char *resume;         /* NULL: none. A checkpoint of this job (same scene geometry
                                   and surfaces, accuracy, max_rays, sight_rays,
                                   exact_occluders, seed) whose rows are taken
                                   as done; another job's is refused (RAD_ERR_INVALID naming
                                   the file). May be the checkpoint file itself */
    const volatile int *stop;   /* NULL: none. When it becomes non-zero (a signal handler),
                                   the run stops once the rows in progress are done (the
                                   round's others are left for later), writes the checkpoint
                                   (when one is set) and returns RAD_OK with no matrix and
                                   report.interrupted; during the last round it is ignored */
} rad_viewfactor_options;

typedef struct rad_viewfactor_report {
    uint64_t surface_pairs;      /* surface pairs considered (unmet_pairs included) */
    uint64_t polygon_pairs;      /* polygon pairs that face each other, of the surface
                                    pairs some sight ray met (of all, without sight rays) */
    /* every such polygon pair is one of: unobstructed_pairs, hidden_pairs, exact_pairs,
     * sampled_pairs */
    uint64_t unobstructed_pairs; /* nothing in between (shaft culling): analytic value */
    uint64_t hidden_pairs;       /* proven wholly hidden, exactly: the scene's shapes in a
                                    plane that separates the pair cover every segment
                                    between them (or, piece by piece or half by half, in
                                    a few planes); F = 0 with no error. Only pairs whose
                                    first 40 segments were all blocked are tried */
    uint64_t obstructed_pairs;   /* pairs with something in between, not proven hidden:
                                    exact_pairs + sampled_pairs */
    uint64_t exact_pairs;        /* of those, up to exact_occluders triangles in between:
                                    their shadows clipped exactly */
    uint64_t sampled_pairs;      /* of those, more occluders (or too many shadow pieces even
                                    with room for 1024, or out of work): visibility sampled */
    uint64_t unseen_pairs;       /* sampled pairs whose last round of segments was all
                                    blocked: F = 0, stored with the bound of what the
                                    segments could have missed */
    uint64_t capped_pairs;       /* sampled pairs that reached max_rays first */
    uint64_t short_pairs;        /* polygon pairs whose bound exceeds their target, the
                                    accuracy times sqrt(F unobstructed) absolute for an
                                    obstructed pair (the accuracy relative for an
                                    unobstructed one): the factors that do not meet the
                                    accuracy asked for (0: every one does) */
    uint64_t rays;               /* visibility rays cast (not counting the sight rays) */
    uint64_t unmet_pairs;        /* surface pairs (I, J > I) that no sight ray met: F = 0,
                                    not stored, each within unmet_bound (95 %), neither
                                    integrated nor proven hidden */
    uint32_t exact_occluders;    /* the options' exact_occluders (the default filled in) */
    uint32_t sight_rays;         /* sight rays cast from each surface (0: none) */
    uint64_t sight_rays_cast;    /* all of them, over every rank */
    double unmet_bound;          /* 3 / sight_rays: an unmet pair's F_IJ and F_JI are at most
                                    this (95 % for each pair) */
    double sight_seconds;        /* casting them and sharing the pairs they met */
    double missed_largest;       /* the largest share of a surface's view that the pairs its
                                    sight rays did not meet hold, by Good and Turing's
                                    estimate (the surfaces one ray met, over the rays): at
                                    most about what its row sum lacks (it counts only the
                                    surface's own rays) */
    double missed_mean;          /* the same, the mean over the surfaces */
    uint64_t nonzeros;           /* stored factors other than 0 */
    double largest_error_bound;  /* largest error_bound (absolute, in units of F) */
    double seconds;
    int threads;
    uint32_t rank_rows;          /* rows this process computed: all of them unless the work
                                    was shared over MPI ranks (rad_ranks_begin) */
    double rank_seconds;         /* this process's time computing its rows (no waiting) */
    uint32_t resumed_rows;       /* rows read from options.resume, not computed */
    uint32_t checkpoint_rows;    /* rows in the last checkpoint written (0: none written) */
    bool interrupted;            /* options.stop was raised: no matrix (*out NULL); the
                                    checkpoint holds checkpoint_rows rows */
    uint64_t roomy_pairs;        /* of the exact pairs, those clipped on a second try with
                                    room for more visible pieces a point and more work (a
                                    large polygon behind hundreds of triangles) */
} rad_viewfactor_report;

/* Computes the view factors between the scene's surfaces, each surface taken as a whole
 * (its triangles need not be coplanar: a curved surface given as a mesh is one surface and
 * may see itself). Every triangle of the scene, obstruction surfaces included, blocks.
 * Reciprocity A_I F_IJ = A_J F_JI holds by construction, 0 <= F_IJ <= 1, and an obstructed
 * factor never exceeds its unobstructed value. Memory grows with the non-zero count.
 * After rad_ranks_begin joined a job of several MPI ranks this is collective: every rank
 * calls it with the same scene and options, computes the rows given to it by estimated
 * cost (their obstruction), and rank 0 gets the whole matrix, bitwise the same as a serial
 * run, and the report's counts summed over the ranks; the other ranks get *out = NULL (and
 * RAD_OK). A failure on any rank fails it on every rank.
 * With options.checkpoint the rows go in 64 rounds (each rank's rows in 64 slices) and a
 * checkpoint may be written between two; options.resume continues a checkpointed job: the
 * matrix is then bitwise the one an uninterrupted run gives (the rows are independent of
 * one another and of who computes them), for any rank and thread counts on either side.
 * The report's pair and ray counts are then those of the rows computed in this run. */
rad_status rad_viewfactor_matrix_compute(const rad_scene *scene,
                                         const rad_viewfactor_options *options,
                                         rad_viewfactor_matrix **out,
                                         rad_viewfactor_report *report, rad_error *error);

void rad_viewfactor_matrix_destroy(rad_viewfactor_matrix *matrix);

/* F_IJ, or 0 when it is not stored. */
double rad_viewfactor_matrix_get(const rad_viewfactor_matrix *matrix, uint32_t row,
                                 uint32_t column);

/* The physical invariants of a view-factor matrix, measured (checked on every CLI run). */
typedef struct rad_viewfactor_check {
    double smallest, largest;   /* smallest and largest stored F_IJ: within [0, 1] */
    double reciprocity;         /* largest |A_I F_IJ - A_J F_JI| / max(A_I F_IJ, A_J F_JI) */
    double largest_planar_self; /* largest F_II of a planar surface: 0 */
    double largest_row_sum;     /* max_I sum_J F_IJ: above 1 means a row creates energy */
    double row_sum_deviation;   /* max_I |sum_J F_IJ - 1| over radiating surfaces */
    bool closed;                /* the radiating surfaces form a closed enclosure: every
                                   edge of their triangles is shared by exactly two of them */
} rad_viewfactor_check;

void rad_viewfactor_matrix_check(const rad_viewfactor_matrix *matrix, const rad_scene *scene,
                                 rad_viewfactor_check *check);

/* An empty matrix to fill by hand (tests, tools, post-processing): n surfaces and room for
 * `nonzeros` entries, every array zeroed (row_start all 0). The caller fills area,
 * row_start, column (ascending within a row), value and error_bound. Free with
 * rad_viewfactor_matrix_destroy. */
rad_status rad_viewfactor_matrix_create(uint32_t n, uint64_t nonzeros,
                                        rad_viewfactor_matrix **out, rad_error *error);

/* What the enclosure correction did. Relative changes are |dF_IJ| / F_IJ. */
typedef struct rad_enclosure_report {
    double row_deviation_before;   /* max_I |sum_J F_IJ - 1| before the correction */
    double row_deviation_after;    /* the same after it (about 1e-14) */
    double largest_relative_change; /* max over stored factors of |dF_IJ| / F_IJ */
    double reciprocity_after;      /* max |A_I F_IJ - A_J F_JI| / max(A_I F_IJ, A_J F_JI) */
    uint32_t iterations;           /* conjugate-gradient iterations */
} rad_enclosure_report;

/* Makes a closed enclosure's rows sum to 1 while keeping reciprocity exact: with the
 * symmetric transfers G_IJ = A_I F_IJ (the mean of A_I F_IJ and A_J F_JI where they
 * differ), it finds the correction dG minimising sum over stored entries (I,J) of
 * dG_IJ^2 / G_IJ^2 (relative changes; factors that are 0 stay 0) subject to
 * sum_J (G_IJ + dG_IJ) = A_I for every row. Lagrange multipliers give dG_IJ = G_IJ^2
 * (mu_I + mu_J), diagonal entries (curved surfaces) included, and mu solves the sparse
 * symmetric positive system sum_J G_IJ^2 (mu_I + mu_J) = A_I - sum_J G_IJ, by
 * preconditioned conjugate gradients to 1e-14 relative. Values change in place; areas,
 * the sparsity pattern and the error bounds stay. Surfaces flagged
 * RAD_SURFACE_OBSTRUCTION in `scene` (NULL: none) are left out. RAD_ERR_INVALID, with
 * the matrix untouched, when a row is empty (a surface that sees nothing cannot sum to
 * 1), when F_IJ is stored without F_JI, when the system is singular (a group of surfaces
 * that see only each other in two alternating sets, as two facing plates with nothing
 * else: rows can then be scaled in opposite directions) or when a factor would change
 * sign. */
rad_status rad_viewfactor_matrix_close_enclosure(rad_viewfactor_matrix *matrix,
                                                 const rad_scene *scene,
                                                 rad_enclosure_report *report,
                                                 rad_error *error);

/* Largest matrix rad_viewfactor_matrix_script_f accepts (dense LU, n^3 work). */
#define RAD_SCRIPT_F_MAX_SURFACES 4096

/* Grey-body total exchange factors (Hottel's script-F; View3D's `emit` option): with
 * emissivities eps_I in (0,1] (reflectance 1 - eps_I, diffuse),
 *   scriptF_IJ = eps_I [ (I - F diag(1 - eps))^-1 F ]_IJ eps_J,
 * the fraction of the energy emitted by I that is absorbed by J after any number of
 * diffuse reflections. Reciprocity A_I scriptF_IJ = A_J scriptF_JI holds when it holds
 * for F; in a closed enclosure each row sums to eps_I. Dense LU with partial pivoting:
 * more than RAD_SCRIPT_F_MAX_SURFACES surfaces is RAD_ERR_UNSUPPORTED, a singular system
 * RAD_ERR_INVALID. `*out` is a new matrix (same areas; zeros not stored; error_bound is
 * F's bound scaled by eps_I eps_J, the first-order bound without the reflections). */
rad_status rad_viewfactor_matrix_script_f(const rad_viewfactor_matrix *matrix,
                                          const double *emissivity,
                                          rad_viewfactor_matrix **out, rad_error *error);

/* View3D's mask factors, after rad_viewfactor_matrix_compute on the scene that
 * rad_scene_load_vs3 read from `path` (the file is read again for its M lines): each mask
 * M of base B gets the row F_MB = 1 and area A_M; B's area becomes its whole polygon's,
 * A_B = A_cut + sum A_M, its computed factors are scaled by A_cut / A_B and F_BM =
 * A_M / A_B, so reciprocity holds; other surfaces keep their factors (F_JM = 0). The
 * masks lose RAD_SURFACE_OBSTRUCTION in `scene`. *matrix is replaced (the old one is
 * freed) when the file has masks, untouched otherwise. */
rad_status rad_viewfactor_matrix_apply_vs3_masks(const char *path, rad_scene *scene,
                                                 rad_viewfactor_matrix **matrix,
                                                 rad_error *error);

/* Sky view factors (open scenes): SVF_I, the fraction of surface I's cosine-weighted
 * hemisphere from which a ray leaves the scene without meeting any triangle (obstructions
 * included), averaged over the surface; integrated directly, not taken as 1 - row sum.
 * The sky is an inward-facing box around the whole scene cut into 96 tiles that block
 * nothing; since nothing lies beyond it, the visible part of the box is exactly the sky
 * for any box that encloses the scene (no finite-distance error). SVF_I sums I's
 * polygons' transfers to the tiles: analytic where nothing stands in between, exact
 * shadow clipping (the tiles with up to 16 triangles in between integrated together by
 * adaptive quadrature to `accuracy`), and through the other tiles cosine-distributed
 * rays from the polygon (to accuracy x sqrt(their share), or 16 x max_rays a polygon),
 * with no shortcut that drops anything as hidden. Its error bound adds the parts' bounds
 * in quadrature, as a row's do. */
typedef struct rad_sky_report {
    uint64_t polygon_pairs;    /* (polygon, sky tile) pairs that face each other */
    uint64_t obstructed_pairs; /* of those, pairs with a triangle in between */
    uint64_t exact_pairs;      /* of those, clipped exactly */
    uint64_t sampled_pairs;    /* of those, sampled by rays */
    uint64_t capped_pairs;     /* polygons whose rays reached 16 x max_rays first */
    uint64_t rays;             /* rays that reached a sampled tile's direction, traced */
    double largest_error_bound; /* max_I of SVF_I's bound (absolute) */
    uint32_t surfaces;         /* surfaces given a sky view factor (not obstructions, area > 0) */
    uint32_t short_surfaces;   /* of those, surfaces whose SVF bound is above the accuracy
                                  (absolute: the sky's unobstructed share is 1, so this is
                                  accuracy x sqrt(F unobstructed), the matrix's target for
                                  an obstructed pair) */
    double seconds;
    int threads;
} rad_sky_report;

/* sky[I] and bound[I] for every surface I < scene->surface_count (0 and 0 for obstruction
 * surfaces and surfaces without area). options as for rad_viewfactor_matrix_compute
 * (accuracy, max_rays, seed, threads; no progress); the same for any thread count. Not
 * collective: call it on one rank. report may be NULL. */
rad_status rad_sky_viewfactors_compute(const rad_scene *scene,
                                       const rad_viewfactor_options *options, double *sky,
                                       double *bound, rad_sky_report *report,
                                       rad_error *error);

/* The consistency check: row sum + SVF = 1 for every radiating surface. */
typedef struct rad_sky_check {
    double largest_deviation; /* max_I |sum_J F_IJ + SVF_I - 1| */
    uint32_t worst_surface;   /* its I (UINT32_MAX when there is no radiating surface) */
    double worst_row_sum;     /* its row sum */
    double worst_row_bound;   /* its row's error bound (the factors' in quadrature) */
    double worst_sky_bound;   /* its SVF's bound */
} rad_sky_check;

void rad_sky_viewfactor_check(const rad_viewfactor_matrix *matrix, const rad_scene *scene,
                              const double *sky, const double *bound, rad_sky_check *check);

/* Writes sky[] and bound[] atomically: a path ending in .mtx gets a Matrix Market column
 * vector ("%%MatrixMarket matrix array real general", "% sky K BOUND NAME" comments, "N 1",
 * one value a line), the companion of a .mtx matrix; anything else CSV,
 * "index,surface,sky_view_factor,error_bound". Both leave obstruction surfaces out and
 * number the others from 1 as the matrix writers do. */
rad_status rad_sky_viewfactors_write(const rad_scene *scene, const double *sky,
                                     const double *bound, const char *path, rad_error *error);

/* Row repair (open and closed scenes): trims the rows that sum above 1, keeping
 * reciprocity. With G_IJ = A_I F_IJ (the mean of both directions where they differ) each
 * surface gets a scale s_I in (0, 1], the fixed point of "row I sums to 1, or s_I = 1 if
 * it then stays at or below 1" (Gauss-Seidel sweeps to 1e-15), and F'_IJ = s_I s_J G_IJ /
 * A_I, so A_I F'_IJ = A_J F'_JI to rounding (about 1e-16 relative). Rows at or below 1
 * change only through their neighbours' scales and never rise; curved surfaces' F_II
 * scale by s_I^2. Limits: 0 = none. */
typedef struct rad_row_repair_limits {
    double max_relative_change; /* largest |F'_IJ - F_IJ| / F_IJ allowed */
    double max_removed_share;   /* largest share of the exchange sum_IJ A_I F_IJ removed */
} rad_row_repair_limits;

enum { RAD_ROW_REPAIR_REFUSED_CHANGE = 1, RAD_ROW_REPAIR_REFUSED_REMOVED = 2 };

typedef struct rad_row_repair_report {
    uint32_t rows_above_one;        /* rows that summed above 1 before */
    uint32_t rows_trimmed;          /* rows whose scale is below 1 */
    double largest_row_sum_before, largest_row_sum_after;
    double largest_change;          /* max |F'_IJ - F_IJ| (absolute) */
    uint32_t largest_change_row, largest_change_column;
    double largest_change_before, largest_change_after; /* that factor's values */
    double largest_relative_change; /* max |F'_IJ - F_IJ| / F_IJ */
    uint32_t largest_relative_row, largest_relative_column; /* its I and J */
    double removed_share;           /* (sum A_I F_IJ - sum A_I F'_IJ) / sum A_I F_IJ */
    double reciprocity_after;       /* max |A_I F_IJ - A_J F_JI| / max(A_I F_IJ, A_J F_JI) */
    uint32_t sweeps;
    int refused;                    /* 0, or RAD_ROW_REPAIR_REFUSED_* */
} rad_row_repair_report;

/* Repairs `matrix` in place (values only; areas, pattern and error bounds stay). Surfaces
 * flagged RAD_SURFACE_OBSTRUCTION in `scene` (NULL: none) are left out. The report is
 * filled before the limits are checked: past a limit, RAD_ERR_INVALID with the matrix
 * untouched and report->refused set; also RAD_ERR_INVALID, untouched, when a non-zero
 * F_IJ is stored without F_JI. */
rad_status rad_viewfactor_matrix_repair_rows(rad_viewfactor_matrix *matrix,
                                             const rad_scene *scene,
                                             const rad_row_repair_limits *limits,
                                             rad_row_repair_report *report, rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Solvers for (I - diag(rho) F) B = E                                                   */

typedef enum rad_solver {
    RAD_SOLVER_AUTO = 0,     /* rad_solve_scene decides (see there); rad_solve: Jacobi */
    RAD_SOLVER_JACOBI,       /* gathering ("gather"): every patch from the previous iterate */
    RAD_SOLVER_GAUSS_SEIDEL, /* gathering with the newest values */
    RAD_SOLVER_SHOOT,        /* progressive refinement: most unshot power first */
    RAD_SOLVER_DIRECT,       /* LU factorisation, O(n^3): small scenes and tests only */
    RAD_SOLVER_HIERARCHICAL  /* links between element and cluster trees, no n x n matrix */
} rad_solver;

/* The solver's command-line name: "auto", "gather", "gauss-seidel", "shoot", "direct",
 * "hierarchical". Never NULL. */
const char *rad_solver_name(rad_solver solver);

/* The solver named `name` (as rad_solver_name gives it; "jacobi" is "gather"); false when
 * no solver has that name. */
bool rad_solver_from_name(const char *name, rad_solver *solver);

/* The per-patch inputs of the radiosity equation, the same for every solver and renderer,
 * built in one place (rad_patch_inputs_build): area A_i; albedo rho_i, the material's, or
 * for a textured material the mean of albedo x texel over the patch; exitance
 * E_i = pi L_e, the material's emitted radiance (times the mean of its emissive texture
 * over the patch); the direct irradiance H_i of the scene's light sources (rad_light: the
 * mean over the patch, shadows included); and the source term every solver uses,
 * S_i = E_i + rho_i H_i: the light sources enter the solution here, as its first bounce,
 * and B = S + diag(rho) F B. */
typedef struct rad_patch_inputs {
    uint32_t n;        /* mesh->patch_count */
    double *area;      /* A_i: the patch's area open to the scene (a patch running under a
                          box standing on it: the part outside the box), and every mean
                          over the patch below is its open part's */
    rad_rgb *albedo;   /* rho_i, in [0,1] */
    rad_rgb *exitance; /* E_i, >= 0 */
    rad_rgb *direct;   /* H_i, >= 0 (0 without light sources) */
    rad_rgb *direct_sharp; /* the part of H_i from point, spot, luminaire and sun lights,
                              which the renderers recompute at each pixel for exact
                              shadows */
    rad_rgb *source;   /* S_i = E_i + rho_i H_i */
} rad_patch_inputs;

rad_status rad_patch_inputs_build(const rad_scene *scene, const rad_mesh *mesh,
                                  rad_patch_inputs **out, rad_error *error);
void rad_patch_inputs_destroy(rad_patch_inputs *inputs);

/* The linear system of the dense solvers: the patch inputs and the form factors. */
typedef struct rad_system {
    uint32_t n;
    const float *F;          /* n x n row-major, F_ij */
    const double *area;      /* A_i */
    const rad_rgb *albedo;   /* rho_i */
    const rad_rgb *exitance; /* the source term: E_i, plus rho_i H_i with light sources
                                (rad_patch_inputs.source) */
} rad_system;

/* The system of `inputs` and `formfactors` (NULL: F = NULL), pointing into both: nothing
 * is copied or allocated. Its areas are the matrix's (rad_formfactors.area), so that
 * reciprocity holds, else the inputs'. */
rad_system rad_system_of(const rad_patch_inputs *inputs, const rad_formfactors *formfactors);

/* Watching a solver converge. Every solver (rad_solve's four, rad_solve_hierarchical, and
 * so rad_solve_scene) calls an optional observer after each step a learner would count,
 * with the state it has reached:
 *   gather (Jacobi): step 0 (B = E) and every sweep;
 *   gauss-seidel:    step 0 and every sweep;
 *   shoot:           step 0 and every `observe_every` shots (default: n / 16 shots, about
 *                    100 snapshots for a run of 6 n shots, as the Cornell box takes to
 *                    1e-4), and the answer;
 *   direct:          once, the answer (step 0);
 *   hierarchical:    step 0 (phase "start") and every sweep (phase "refine" for the
 *                    sweep after a refinement pass, "gather", "final gather").
 * The last call is always the answer handed out (final = true, B as returned, with the
 * ambient term for shooting) and its residual is the report's residual. A step number is
 * the iterations done: sweeps, or shots for shooting; a call's step is never repeated.
 * Cost: none without an observer. With one: Jacobi's and the hierarchical solver's
 * residual of B_k is the change of the sweep that follows it (the snapshot is handed over
 * one sweep late, with a copy of B: O(n)); Gauss-Seidel and shooting pay one pass over F
 * (O(n^2), one Jacobi sweep's work) per call for the residual; copying B to the
 * observer's layout is O(n). `seconds` leaves that cost out (the reports' seconds do not). */
typedef struct rad_solve_step {
    uint32_t step;           /* iterations done: sweeps, or shots for shooting */
    const char *phase;       /* "gather", "gauss-seidel", "shoot", "direct"; hierarchical:
                                "refine", "gather" or "final gather" (what made this B) */
    double seconds;          /* solver time since its start, the observer's cost left out */
    double criterion;        /* the solver's own stopping value at this step (Jacobi,
                                Gauss-Seidel, hierarchical: the relative change of the
                                sweep that made B, NaN at step 0; shooting: the unshot
                                fraction; direct: the residual) */
    double residual;         /* sum A |B - E - rho F B|_1 / sum A |E|_1 of this B, as
                                rad_solve_report (hierarchical: rad_hierarchy_report) */
    double unshot;           /* shooting: the unshot energy fraction; NaN for the others */
    uint32_t shooting_patch; /* shooting: the patch of the last shot; UINT32_MAX before
                                the first shot and for the other solvers */
    bool final;              /* the answer handed out: the last call */
    uint32_t n;              /* patches */
    const rad_rgb *B;        /* the radiosity now, n values; valid during the call only */
} rad_solve_step;

typedef void (*rad_solve_observer_fn)(void *user, const rad_solve_step *step);

/* The default of observe_every (shooting): n / RAD_OBSERVE_SHOTS_DIVISOR shots, at least 1. */
#define RAD_OBSERVE_SHOTS_DIVISOR 16

typedef struct rad_solve_options {
    rad_solver solver;       /* JACOBI, GAUSS_SEIDEL, SHOOT or DIRECT; AUTO = JACOBI */
    double tolerance;        /* Jacobi: relative residual; Gauss-Seidel: relative change of
                                a sweep; shooting: unshot fraction; 0 = 1e-4 */
    uint32_t max_iterations; /* sweeps, or shots for shooting; 0 = 10000 sweeps or 1000 n
                                shots */
    bool ambient;            /* shooting: add the ambient term for the unshot energy */
    int threads;
    rad_progress_fn progress;
    void *progress_user;
    rad_solve_observer_fn observer; /* NULL: none (no cost); see rad_solve_step */
    void *observer_user;
    uint32_t observe_every;  /* shooting: shots between two calls; 0 = n / 16 */
} rad_solve_options;

typedef struct rad_solve_report {
    uint32_t iterations;     /* sweeps, or shots for the shooting solver */
    double criterion;        /* the solver's own stopping value at the end */
    double residual;         /* sum_i A_i |B - E - rho F B|_1 / sum_i A_i |E|_1, all solvers */
    bool converged;          /* criterion <= tolerance */
    double seconds;
    uint32_t patch;          /* after an error about one patch (a row that creates energy,
                                a diverging or non-finite value): that patch, else
                                UINT32_MAX */
} rad_solve_report;

/* Fills B (n values, exitance). RAD_ERR_INVALID for a negative thread count, a
 * non-positive area, an albedo outside [0,1], a negative exitance, a row whose rho_i x
 * sum_j F_ij exceeds 1 + RAD_ROW_SUM_SLACK (it creates energy: no solver converges), an
 * iteration that diverges or stops being finite anyway (report->patch names the patch) or
 * the hierarchical solver (it needs the mesh: rad_solve_hierarchical); the direct solver
 * refuses more than RAD_DIRECT_MAX_PATCHES patches (RAD_ERR_UNSUPPORTED) and a singular system
 * (RAD_ERR_INVALID), and reports iterations 0. Shooting derives F_ji from F_ij by
 * reciprocity, so its residual levels off near float precision (about 1e-7). With the
 * ambient term on, `residual` measures B including it. After rad_ranks_begin joined a job
 * of several MPI ranks, the Jacobi solver (RAD_SOLVER_JACOBI) is collective: every rank
 * calls it with the same whole system, sweeps its block of rows and exchanges B after
 * each sweep; every rank gets B, bitwise the serial one. The other solvers do not talk to
 * other ranks. */
rad_status rad_solve(const rad_system *system, const rad_solve_options *options,
                     rad_rgb *B, rad_solve_report *report, rad_error *error);

/* The stated accuracy of a row sum of patch form factors: rad_formfactors_compute's rows
 * sum to what each patch sees within this (closed scenes with occluders, touching and
 * interpenetrating surfaces included; tests/test_near_surfaces.c, test_hierarchical.c);
 * as a last guard it scales a row above 1 + this back to 1 and reports it (below, the
 * rows' sampling error is left alone: cutting only the high side of it would darken every
 * scene); rad_solve refuses a system whose rho_i x sum_j F_ij exceeds 1 + this. */
#define RAD_ROW_SUM_SLACK 1e-2

/* Largest system the direct solver takes. */
#define RAD_DIRECT_MAX_PATCHES 4096

/* The relative residual used by every solver's report. */
double rad_system_residual(const rad_system *system, const rad_rgb *B);

/* ------------------------------------------------------------------------------------ */
/* Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991, with clusters)          */

/* The mesh's patches are the finest elements. Above them: a binary tree over each plane
 * (consecutive coplanar patches of one surface and material, e.g. one input polygon's
 * cells), and clusters (a bounding-volume tree) over the planes. Linking starts from the
 * root cluster linked to itself; a link is split (the larger node, or the cluster) while
 * B_source x F x A_receiver exceeds the threshold. Each link carries a form-factor estimate
 * (point-to-disk kernel between centres; clusters use the isotropic mean cosine 1/4;
 * patch-to-patch links use Lambert's contour formula) times a visibility fraction from a
 * few segments traced between the two nodes (4 first, 16 when they disagree; links
 * found fully hidden are dropped). Jacobi gathering over the links with push-pull between
 * levels alternates with refinement until nothing refines and the change is below the
 * tolerance; then a final gather at the leaves (each leaf gathers its ancestors' links
 * again from its own centre, far planar nodes taken by the kernel's second-order
 * expansion, every link's shadow traced from the leaf). The result is one B per mesh patch, so
 * rad_reconstruct_vertices and rad_render display it smoothly. Deterministic: every random
 * number comes from (seed, receiver, source), every sum has a fixed order, so B is bitwise
 * the same for any thread count. */
typedef struct rad_hierarchy_options {
    double refine_threshold;  /* BFA threshold, as a fraction of the scene's emitted power
                                 per patch; 0 = 0.25. Smaller = more links, more accurate */
    uint32_t visibility_rays; /* segments per link when the first 4 are not all open;
                                 0 = 16 */
    double tolerance;         /* relative change of a sweep (area-weighted); 0 = 1e-4 */
    uint32_t max_iterations;  /* sweeps; 0 = 1000 */
    uint64_t max_memory;      /* bytes the link store may use (both of its buffers); 0 =
                                 half the machine's memory. Refinement stops where it is
                                 when the next step would exceed it (report.memory_capped) */
    uint64_t seed;
    int threads;              /* 0 = all cores */
    /* When non-NULL and it becomes non-zero (a SIGINT handler, say), refinement and
     * gathering stop at the next sweep (the final gather at once, its partial result
     * dropped) and the current solution is returned (report.interrupted); B is then a
     * valid, less converged answer. */
    const volatile int *stop;
    rad_progress_fn progress;
    void *progress_user;
    rad_solve_observer_fn observer; /* NULL: none (no cost); see rad_solve_step */
    void *observer_user;
} rad_hierarchy_options;

typedef struct rad_hierarchy_report {
    uint64_t elements;       /* nodes inside planes (mesh patches included) */
    uint64_t clusters;       /* nodes above the planes */
    uint64_t leaves;         /* mesh patches */
    uint64_t links;          /* links at the end */
    uint64_t links_partial;  /* of which partly visible */
    uint64_t rays;           /* visibility segments traced */
    uint64_t link_bytes;     /* the most the link store held, bytes (this process's store:
                                over MPI ranks, this rank's share) */
    uint32_t passes;         /* refinement passes (each splits links one level) */
    uint32_t iterations;     /* Jacobi sweeps with push-pull */
    double change;           /* relative change of the last sweep: sum A |B_new - B|_1 /
                                sum A |E|_1 over the patches (the stopping value) */
    double residual;         /* the residual of the B returned, sum A |B - E - rho H B|_1 /
                                sum A |E|_1 with H the links' (and the final gather's)
                                transport: one more sweep, measured, not applied */
    bool converged;          /* change <= tolerance and nothing left to refine */
    bool memory_capped;      /* refinement stopped at max_memory */
    bool interrupted;        /* options.stop was raised */
    double seconds_build;    /* element and cluster trees */
    double seconds_refine;   /* link refinement, visibility included */
    double seconds_gather;   /* sweeps and push-pull */
    double seconds_final;    /* the final gather at the leaves */
    int threads;
    uint32_t patch;          /* after a diverging solve (RAD_ERR_INVALID): the patch whose
                                radiosity changed the most, else UINT32_MAX */
    /* Over MPI ranks (rad_rank_count() > 1) the tree is cut into receiver subtrees shared
     * by leaf count, and a rank holds the links received in its subtrees and the
     * shared_links; links, links_partial and rays above count every link and segment once,
     * over all ranks. With one process rank_links = links and shared_links = 0. */
    uint64_t rank_links;     /* links this process held at the end */
    uint64_t shared_links;   /* links every rank holds (received by the nodes above the cut) */
    double rank_seconds;     /* this process's solve time less its waiting for the other
                                ranks (exchanges and agreements; for the load imbalance) */
} rad_hierarchy_report;

/* Solves the mesh's radiosity hierarchically with the patch inputs of rad_patch_inputs_build:
 * B receives mesh->patch_count exitances, each at least the patch's own E. `occluders` is
 * a tracer over the scene's triangles (RAD_TRACER_EMBREE_FAST is the intended one).
 * RAD_ERR_INVALID for a negative thread count, a bad threshold or inputs of another mesh,
 * RAD_ERR_NOMEM when even the first links do not fit max_memory. */
rad_status rad_solve_hierarchical(const rad_mesh *mesh, const rad_patch_inputs *inputs,
                                  const rad_tracer *occluders,
                                  const rad_hierarchy_options *options, rad_rgb *B,
                                  rad_hierarchy_report *report, rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Convergence: history, plot and record of a solver's steps (rad_solve_step)           */

/* One step's numbers (NaN where the step has none). */
typedef struct rad_convergence_point {
    uint32_t step;     /* iterations done (x of the first panel) */
    double seconds;    /* solver time (x of the second panel) */
    double criterion;  /* the solver's own stopping value */
    double residual;   /* relative residual */
    double unshot;     /* shooting: unshot energy fraction */
    const char *phase; /* rad_solve_step.phase (a string the library owns), or NULL */
} rad_convergence_point;

/* The steps seen so far; zero-initialise, add with rad_convergence_add, free with
 * rad_convergence_free. */
typedef struct rad_convergence {
    rad_convergence_point *points;
    size_t count, capacity;
} rad_convergence;

/* Appends the step's numbers (not its B). RAD_ERR_NOMEM when it cannot grow. */
rad_status rad_convergence_add(rad_convergence *history, const rad_solve_step *step,
                               rad_error *error);
void rad_convergence_free(rad_convergence *history);

typedef struct rad_convergence_plot_options {
    const char *title;           /* the first line, e.g. "cornell-box: shoot, 3010 patches" */
    const char *step_label;      /* the first panel's x axis, e.g. "sweeps" or "shots";
                                    NULL: no step panel, only the time panel */
    bool residual;               /* draw the relative residual (its finite, positive points) */
    const char *criterion_label; /* draw the criterion too, with this name in the legend
                                    (e.g. "unshot energy fraction"); NULL: not drawn */
    const char *y_label;         /* NULL: "relative to the emitted power sum A |E| (1)" */
    const char *time_label;      /* the time panel's x axis; NULL: "solver time (s)" */
} rad_convergence_plot_options;

/* A standalone SVG of the history: a panel against the steps (when step_label is given)
 * and a panel against the solver time in seconds, each with a log y axis (decade ticks
 * labelled 10^k, a <line class="ytick" data-value="V"> per decade), a linear x axis, the
 * curves as <path class="residual"> and <path class="criterion"> (a non-positive or NaN
 * value breaks the line), a legend and the title; where the phase changes after the
 * first one (the hierarchical solver's "gather", "final gather") a dotted vertical
 * <line class="phase"> with the new phase's name. Written atomically. RAD_ERR_INVALID for
 * an empty history. */
rad_status rad_convergence_plot_write(const rad_convergence *history, const char *path,
                                      const rad_convergence_plot_options *options,
                                      rad_error *error);

/* Several runs on the same axes (`radiosity plot`): the relative residual of each of the
 * `runs` histories as its own <path class="residual" data-run="K"> in its own colour,
 * named in the legend by names[K] (e.g. the solver), with no criterion curves and no
 * phase lines; otherwise as rad_convergence_plot_write (criterion_label and residual
 * are ignored). RAD_ERR_INVALID when a history is empty or there is none. */
rad_status rad_convergence_plot_compare(const rad_convergence *histories,
                                        const char *const *names, size_t runs,
                                        const char *path,
                                        const rad_convergence_plot_options *options,
                                        rad_error *error);

/* A record of a solve's snapshots, streamed to its file as they come (memory: one
 * snapshot's text, about 16 n bytes), as JSON:
 *   {"format":"radiosity-record","version":1,"scene":S,"solver":V,"patches":n,
 *    "snapshots":[{"step":k,"seconds":s,"criterion":c,"residual":r,"unshot":u|null,
 *                  "shooting_patch":p|null,"final":true|false,"phase":"...",
 *                  "radiosity":"BASE64"},...]}
 * where BASE64 holds n x 3 float32 little-endian (R, G, B radiosity, W/m^2 or the
 * scene's unit, per patch in the mesh's patch order) and a NaN number is null. The file
 * appears, whole, at rad_solve_record_commit; rad_solve_record_abort (or an error) leaves
 * none. The snapshot text is refused up front (RAD_ERR_NOMEM, "--record: ...") when it
 * does not fit the run's memory budget. */
typedef struct rad_solve_record rad_solve_record;

rad_status rad_solve_record_open(const char *path, const char *scene, const char *solver,
                                 uint32_t patches, rad_solve_record **out, rad_error *error);
/* Appends one snapshot (step->n must be the record's patches). */
rad_status rad_solve_record_add(rad_solve_record *record, const rad_solve_step *step,
                                rad_error *error);
/* Closes the JSON and renames the file into place; frees the record either way. */
rad_status rad_solve_record_commit(rad_solve_record *record, rad_error *error);
/* Removes the temporary file and frees the record (NULL: nothing). */
void rad_solve_record_abort(rad_solve_record *record);
/* Snapshots added so far. */
uint32_t rad_solve_record_count(const rad_solve_record *record);

/* ------------------------------------------------------------------------------------ */
/* From a scene to its solution: the one entry point                                     */

/* Leaf patches the default patch size aims at: RAD_DEFAULT_PATCHES for the dense solvers
 * (and RAD_SOLVER_AUTO), RAD_HIERARCHICAL_DEFAULT_PATCHES for the hierarchical one. */
#define RAD_DEFAULT_PATCHES 3000
#define RAD_HIERARCHICAL_DEFAULT_PATCHES 30000
/* RAD_SOLVER_AUTO picks the dense gather up to this many patches, else hierarchical. */
#define RAD_DENSE_MAX_PATCHES 4096
/* When RAD_SOLVER_AUTO takes the hierarchical solver for a mesh of at most
 * RAD_AUTO_FINE_LINKS_PATCHES patches (one sized for the dense solvers, grown past
 * RAD_DENSE_MAX_PATCHES by its shadow and proximity refinement), its links are refined to
 * RAD_AUTO_REFINE_THRESHOLD unless refine_threshold is given: the accuracy of the dense
 * solve it stands in for. Measured on the furnished room on a ground plane
 * (test_room_ground, 4538 patches): per-surface error against the path tracer 5.4 % at
 * 0.25 (72,888 links), 5.0 % at 0.1, 4.1 % at 0.05 (143,428 links), 3.1 % at 0.02
 * (202,227), the run 2.68, 2.88, 2.69 and 2.96 s; Gauss-Seidel on that mesh 2.8 %. On
 * large meshes the links' memory rules (3.5 times the links at 0.05 on 31,210 patches). */
#define RAD_AUTO_FINE_LINKS_PATCHES 16384
#define RAD_AUTO_REFINE_THRESHOLD 0.05

/* The patch size for `solver` on this scene (rad_mesh_default_patch_size of the targets
 * above; 0 when out of memory). AUTO: the dense solvers' size, unless its mesh would have
 * more than RAD_DENSE_MAX_PATCHES patches (a scene whose own triangles are finer than that
 * size: the automatic choice then takes the hierarchical solver anyway), then the
 * hierarchical solver's. A furnished room of 9,942 triangles (bench/room_generator 10000,
 * 256 x 256 against a 16384-spp path-traced reference, block / pixel relative RMSE) had
 * 11,758 patches, one per merged input polygon, at 1.24 % / 2.10 % in 17.4 s; at the
 * hierarchical size, 34,054 patches, 0.31 % / 0.87 % in 23.0 s. */
double rad_default_patch_size(const rad_scene *scene, rad_solver solver);

typedef struct rad_scene_solve_options {
    rad_solver solver;         /* AUTO (0): dense Jacobi gathering up to
                                  RAD_DENSE_MAX_PATCHES patches when the matrix fits in
                                  memory, else hierarchical; the report says which ran */
    double tolerance;          /* when the iteration stops (each solver's criterion, as in
                                  rad_solve_options and rad_hierarchy_options); 0 = 1e-4 */
    uint32_t max_iterations;   /* sweeps, or shots for shooting; 0 = the solver's default */
    uint32_t quadrature;       /* dense form factors: m x m split per patch; 0 = 1 */
    uint32_t visibility_rays;  /* most visibility segments per patch pair or link; 0 = 9
                                  a patch pair, 16 a link */
    double refine_threshold;   /* hierarchical: 0 = 0.25 (RAD_AUTO_REFINE_THRESHOLD when
                                  AUTO takes it for a small mesh, above) */
    uint64_t max_memory;       /* bytes the solver's large buffers may use; 0 = no budget
                                  (hierarchical: links up to half the memory). Dense: the
                                  matrix (4 n^2 bytes, direct 12 n^2) must fit, else
                                  RAD_ERR_NOMEM before any work (AUTO then chooses
                                  hierarchical). Hierarchical: the trees (a bound, about
                                  700 n bytes) must fit, else RAD_ERR_NOMEM; the links
                                  get the rest (rad_hierarchy_options.max_memory). With a
                                  run's budget set (rad_memory_budget_set) the limit is
                                  also what is left of it: for the dense matrix after the
                                  patch inputs, the BVH and the threads; for the trees
                                  with 2 MB a thread; the links a quarter less */
    uint64_t seed;
    int threads;               /* 0 = all cores */
    const volatile int *stop;  /* hierarchical: stops at the next sweep (report.interrupted);
                                  with `checkpoint`, every solver: writes one at its next
                                  step and stops there */
    const rad_patch_inputs *inputs; /* the patch inputs when the caller has built them
                                  (rad_patch_inputs_build of this scene and mesh), to use
                                  them again in rad_render; NULL: built here */
    rad_log_fn log;            /* warnings: no emitter, iteration limit, memory cap, ... */
    void *log_user;
    rad_progress_fn progress;  /* "form factors", "solve", "refine", "gather", ... */
    void *progress_user;
    rad_solve_observer_fn observer; /* every solver's steps (rad_solve_step); NULL: none */
    void *observer_user;
    uint32_t observe_every;    /* shooting: shots between two calls; 0 = n / 16 */
    /* Checkpoints of a long solve (restart files; the CLI's --checkpoint, --resume). Each
     * holds the state at a point where the solver goes on as if never stopped: the dense
     * solvers' form-factor rows done (the rows go in 64 rounds per rank, a checkpoint
     * possible between two), then the whole matrix and the iterate between sweeps (shooting:
     * every n / 16 shots); the hierarchical solver's links, B and loop state between sweeps,
     * always one before its final gather, and between the final gather's 16 rounds of
     * leaves (with the rounds' corrections; a stop inside a round goes back to the last
     * checkpoint). A resumed
     * run gives B bitwise the same as an uninterrupted one, for any thread count (and rank
     * count). Written atomically; refused on resuming, naming the file, when made for
     * another scene, mesh, solver, --quadrature, --visibility-rays, --max-iterations,
     * --seed, --tolerance, --refine-threshold or link budget (RAD_ERR_INVALID). */
    const char *checkpoint;     /* NULL: none. Written when checkpoint_interval seconds have
                                   passed since the last (checked at the solver's steps
                                   only), and at `stop` */
    double checkpoint_interval; /* seconds; 0: at every step */
    const char *resume;         /* NULL: none. A checkpoint to go on from (it may be the
                                   `checkpoint` file itself) */
} rad_scene_solve_options;

typedef struct rad_scene_solve_report {
    rad_solver solver;         /* the solver that ran (never AUTO) */
    bool solver_chosen;        /* AUTO was asked: the library chose it */
    char reason[160];          /* one line on why this solver, e.g. "5000 patches > 4096" */
    uint32_t patches;
    uint32_t iterations;       /* sweeps, or shots */
    double residual;           /* relative residual of the B returned, every solver (see
                                  rad_solve_report, rad_hierarchy_report) */
    bool converged;
    bool interrupted;          /* options.stop was raised: B is the solution so far; with
                                  options.checkpoint, the checkpoint holds the state and B
                                  is only each patch's own exitance */
    bool resumed;              /* options.resume was read and the solve went on from it */
    uint32_t checkpoints;      /* checkpoints written */
    rad_formfactor_report formfactors; /* dense solvers */
    rad_formfactor_check check;        /* dense solvers */
    rad_solve_report solve;            /* dense solvers */
    rad_hierarchy_report hierarchy;    /* hierarchical */
    double seconds_inputs;       /* rad_patch_inputs_build (0 when options->inputs given) */
    double seconds_form_factors; /* dense: the matrix, with its check */
    double seconds_solve;        /* the solve itself */
    double seconds;              /* all of it */
} rad_scene_solve_report;

/* The radiosity of every patch of `mesh` (built from `scene`): builds the patch inputs
 * once, chooses the solver (options->solver, or the automatic choice above), computes the
 * form factors for the dense solvers or runs the hierarchical solver, and fills B
 * (mesh->patch_count exitances, every value finite and >= 0). A solver that stops at its
 * iteration limit is not an error: the report says converged = false and a warning goes
 * to options->log. RAD_ERR_UNSUPPORTED when a dense solver is asked for a matrix that
 * does not fit in memory. */
rad_status rad_solve_scene(const rad_scene *scene, const rad_mesh *mesh,
                           const rad_scene_solve_options *options, rad_rgb *B,
                           rad_scene_solve_report *report, rad_error *error);

/* The solver rad_solve_scene runs for this mesh and these options (RAD_SOLVER_AUTO
 * resolved), with one line on why in `reason` (NULL: not wanted). A caller that handles
 * Ctrl-C can tell from it whether options->stop will be honoured (hierarchical only). */
rad_solver rad_solve_scene_choice(const rad_mesh *mesh, const rad_scene_solve_options *options,
                                  char *reason, size_t size);

/* ------------------------------------------------------------------------------------ */
/* Images                                                                                */

/* Linear RGB radiance, row-major from the top-left pixel. */
typedef struct rad_image {
    uint32_t width, height;
    float *rgb; /* width * height * 3 */
} rad_image;

rad_status rad_image_create(uint32_t width, uint32_t height, rad_image **out,
                            rad_error *error);
void rad_image_destroy(rad_image *image);

/* Zero-initialised (or NULL) means automatic exposure and half-float EXR. */
typedef struct rad_image_write_options {
    bool fixed_exposure; /* PNG only: false = automatic (the 95th percentile of the lit
                            pixels' luminance is scaled to 0.9), true = use `exposure` */
    double exposure;     /* PNG only: radiance is multiplied by 2^exposure */
    bool exr_float;      /* .exr: 32-bit float channels instead of half (half keeps 11
                            significant bits; an image with a value above 65504, half's
                            largest, is written as float whatever this says) */
} rad_image_write_options;

/* Writes by the extension of path: .png (exposure, tone map, sRGB, 8-bit), .hdr (Radiance
 * RGBE; negative and NaN values are written as 0), .pfm (portable float map), .exr (OpenEXR
 * scanline, ZIP, R G B half, or float with exr_float). Writes to a
 * temporary name in the same folder and renames it, so a failed write leaves no file. */
rad_status rad_image_write(const rad_image *image, const char *path,
                           const rad_image_write_options *options, rad_error *error);

/* Reads a .pfm (colour or grey, either byte order) or a Radiance .hdr (flat or
 * run-length encoded RGBE; EXPOSURE lines undone; XYZE is RAD_ERR_UNSUPPORTED) or a
 * single-part scanline OpenEXR (R G B, or Y as grey; half or float; tiled, deep, multi-part
 * and other channel sets are RAD_ERR_UNSUPPORTED), whatever its name; row 0 of the result
 * is the top. */
rad_status rad_image_read(const char *path, rad_image **out, rad_error *error);

typedef struct rad_false_colour_options {
    double low, high; /* the scale's ends (the quantity's unit); both 0 = automatic: 0 (or,
                         logarithmic, the 1st percentile) to the 99th percentile */
    bool logarithmic; /* a logarithmic scale (low > 0) */
    const char *unit; /* written above the legend, e.g. "lx"; NULL = none. The legend's
                         font has digits and the letters of lx, cd/m^2, W/m^2, W/sr and
                         relative; other characters are left blank */
} rad_false_colour_options;

/* The luminance of each pixel of `values` in false colour, blue (low) through cyan, green
 * and yellow to red (high), with a legend bar of the scale, its values and unit on a band
 * added on the right (96 pixels). The result (*out, the caller's) holds linear RGB in
 * [0,1]: written as PNG with a fixed exposure of 0 it shows the scale's colours. */
rad_status rad_image_false_colour(const rad_image *values,
                                  const rad_false_colour_options *options, rad_image **out,
                                  rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Rendering                                                                             */

/* Where a render takes the emitters' direct light from (rad_render_options.direct_light). */
typedef enum rad_direct_light {
    RAD_DIRECT_VERTEX = 0,
    RAD_DIRECT_PIXEL,
    RAD_DIRECT_SOLUTION,
} rad_direct_light;

/* The image's size is the rad_image's (rad_render fills the image it is given). */
typedef struct rad_render_options {
    uint32_t samples_per_pixel; /* rounded to a square, stratified, box filter; 0 = 16 */
    uint32_t edge_samples;      /* more samples (rounded to a square) for a pixel whose first
                                   ones disagree by over 10 % in luminance, or that differs
                                   so from a row neighbour: silhouettes and the light's rim;
                                   0 = 64 (256 with RAD_DIRECT_PIXEL) */
    /* The two-pass method: with `materials` (the scene's) given, a surface whose specular
     * reflectance Ks > 0 adds Ks times the radiance seen along the mirror direction, traced
     * through the radiosity-lit scene, up to max_depth reflections (0 = 5). NULL = the
     * radiosity solution alone. */
    const rad_material *materials;
    uint32_t max_depth;
    uint64_t seed;
    int threads;
    rad_progress_fn progress;
    void *progress_user;
    /* The scene the mesh was built from, for its textures (albedo and emission): a hit on
     * a textured surface shows the emitted radiance at the point (emission x its texel)
     * plus the albedo at the point (albedo x its texel) times the irradiance reconstructed
     * at the vertices from (B_i - E_i) / rho_i (the patch's mean exitance and albedo, as
     * the solve used them; 0 where rho_i is 0), so texture detail finer than the patches
     * survives. NULL (or no textured material): the solution alone, B interpolated. */
    const rad_scene *scene;
    /* The patch inputs the solve used (rad_patch_inputs_build of scene and mesh; n must be
     * mesh->patch_count, else RAD_ERR_INVALID): E_i and rho_i above. NULL = rad_render
     * builds them from `scene` itself when it has a textured material (the same values:
     * the build is deterministic). Read only for textured surfaces of `scene`. */
    const rad_patch_inputs *inputs;
    /* Pixels hold the irradiance arriving at the surface seen (illuminance in lux with
     * photometric lights) instead of its radiance: (B_i - E_i) / rho_i reconstructed, the
     * sharp light sources added per pixel as for radiance; a black patch shows its direct
     * light alone; misses and mirrors show nothing. Needs `scene`. */
    bool irradiance;
    /* How the emitters' direct light (emissive surfaces; with `scene`) reaches the image:
     * RAD_DIRECT_VERTEX (the default): computed at every mesh vertex, at a point a tenth of
     *   the way into the vertex's patches, together with a final gather there (up to 2048
     *   cosine rays meeting the solution's reflected light (B - E) / pi, or the sky), and
     *   interpolated: the vertex shows E / pi + rho / pi (H_emitters + H_gathered); soft
     *   shadows, contact shadows and the light next to creases follow the light, not patch
     *   means. In a penumbra (a display triangle whose corners' shadow rays disagree, or
     *   one of which finds a part of the light) each pixel sample computes H_emitters
     *   itself with 64 shadow rays, as RAD_DIRECT_PIXEL does: a penumbra's kinks are not
     *   cut off by interpolation, with a little noise there; elsewhere no pixel noise;
     * RAD_DIRECT_PIXEL: H_emitters computed at every pixel sample by `direct_samples`
     *   shadow rays to points of the emitters (stratified over the pixel's samples; exact
     *   soft shadows, a little noise in penumbrae), the rest (H_gathered) at the vertices as
     *   above;
     * RAD_DIRECT_SOLUTION: interpolated from the solution like the rest (the classic
     *   radiosity image).
     * H_emitters, wherever it is computed: with at most 64 emitting triangles of uniform
     * emission, their unshadowed irradiance is summed exactly (Lambert's contour formula)
     * and the shadow rays say what share of it gets through (the ratio estimator of Heitz,
     * Hill and McGuire 2018: exact where nothing blocks the light); otherwise 1024 light
     * samples a vertex (MIS with 512 cosine rays) or `direct_samples` a pixel sample (MIS
     * with as many).
     * Without emissive surfaces, both compute the final gather at the vertices when the
     * scene has light sources (its rays that leave the scene meet the sky and environment
     * lights: their direct light); a scene with neither gets the classic image. Point,
     * spot, luminaire and sun light is computed at each pixel in every mode.
     * direct_samples 0 = RAD_DEFAULT_DIRECT_SAMPLES (RAD_DIRECT_PIXEL only). */
    rad_direct_light direct_light;
    uint32_t direct_samples;
} rad_render_options;

/* Radiance at every mesh vertex: the area-weighted average of B/pi over the patches that
 * share the vertex; a T-vertex (a vertex strictly inside an edge of a neighbouring patch of
 * its region, where two polygons split their shared edge into different counts) takes
 * instead the linear interpolation along that edge, so the displayed radiance is
 * continuous across it. `vertex_radiance` receives mesh->vertex_count values. */
void rad_reconstruct_vertices(const rad_mesh *mesh, const rad_rgb *B,
                              rad_rgb *vertex_radiance);

/* Bytes the light at the vertices needs after a solve, for a memory budget's up-front
 * check (rad_memory_budget_need): the default render's and lit mesh's per-vertex light on
 * this mesh (their arrays and the two tracers it builds; the light's finer mesh, which
 * takes only what is left past these, not counted). 0 when the scene has no emitter and
 * no light source (nothing is computed at the vertices then). */
uint64_t rad_vertex_light_bytes(const rad_scene *scene, const rad_mesh *mesh);

/* Renders the mesh lit by the solution B (per patch exitance) through the camera: primary
 * rays hit the patches, radiance is interpolated from vertex values (textured surfaces:
 * options->scene above); back faces of one-sided patches and misses are black (a hit on
 * the back of a patch with a twin shows the twin there); mirror reflections are added
 * when options->materials is given (above). Fills `image` (its size decides the
 * resolution). After rad_ranks_begin joined a job of several MPI ranks this is
 * collective: every rank calls it with the same arguments and renders every N-th row,
 * and every rank's image is then whole, bitwise a serial run's. A failure on any rank
 * fails it on every rank. */
rad_status rad_render(const rad_mesh *mesh, const rad_rgb *B, const rad_camera *camera,
                      const rad_render_options *options, rad_image *image,
                      rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Illuminance at points: work planes and measuring points                               */

#define RAD_DEFAULT_GATHER_RAYS 16384 /* rad_illuminance_options.gather_rays */

typedef struct rad_illuminance_options {
    uint32_t gather_rays;      /* directions over the hemisphere for the light from surfaces
                                  and the sky, stratified, cosine-weighted; 0 = 16384 */
    const rad_patch_inputs *inputs; /* the patch inputs the solve used (E_i); NULL: built */
    uint64_t seed;
    int threads;
} rad_illuminance_options;

/* The irradiance (illuminance in lux with photometric lights) at each point, on the
 * side its unit normal faces: the sharp light sources (point, spot, luminaire, sun) by
 * exact shadow rays; the emitters' direct light by 64 light samples and 64 cosine rays
 * combined by multiple importance sampling; then a final gather over the hemisphere: a
 * ray that hits a patch brings its reflected radiance ((B - E) / pi interpolated from the
 * vertices), a ray that leaves the scene the sky's. `E` receives `count` values. */
rad_status rad_illuminance(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                           const rad_vec3 *points, const rad_vec3 *normals, uint32_t count,
                           const rad_illuminance_options *options, rad_rgb *E,
                           rad_error *error);

/* A horizontal calculation grid (normals up) `height` above the floor: points `spacing`
 * apart over the scene's extent across rad_scene.up, half a spacing in from its edges, at
 * the lowest scene point plus `height`, kept where the first surface straight below is
 * the front of an upward-facing surface (the floor, not the outside of the building or
 * the inside of a wall) and the first straight above is a front or nothing (not inside a
 * closed object: a block, a cupboard). *points is the caller's (free()); RAD_ERR_INVALID for a height
 * or spacing that is not positive and finite, or more than 10^7 points; *count may be 0. */
rad_status rad_work_plane(const rad_scene *scene, double height, double spacing,
                          rad_vec3 **points, uint32_t *count, rad_error *error);

/* The illuminance on an unobstructed horizontal plane under the scene's sky lights alone
 * (their sum, lux; environment maps are not counted): the reference of the daylight
 * factor. 0 when there is none. */
double rad_sky_horizontal_illuminance(const rad_scene *scene);

/* ------------------------------------------------------------------------------------ */
/* Ray tracing (Whitted, Phong model) and path tracing                                   */

/* A point light of the classic Phong model: no distance falloff (METHOD.md section 1). */
typedef struct rad_point_light {
    rad_vec3 position;
    rad_rgb intensity; /* I_L */
} rad_point_light;

typedef struct rad_raytrace_options {
    const rad_point_light *lights; /* point lights, may be NULL when light_count is 0 */
    uint32_t light_count;
    rad_rgb ambient;            /* I_A; the ambient reflectance K_A is the albedo Kd */
    uint32_t light_samples;     /* points sampled on the emitters (all together, chosen by
                                   power) per shading point; 0 = 16 */
    uint32_t max_depth;         /* reflected rays followed; 0 = 5 */
    uint32_t samples_per_pixel; /* stratified, box filter; 0 = 4 */
    uint64_t seed;
    int threads;
    rad_progress_fn progress;
    void *progress_user;
} rad_raytrace_options;

/* Whitted ray tracing with the Phong model of METHOD.md section 1:
 *   I = I_E + K_A I_A + sum over lights (K_D <N,L> + K_S <V,R>^n) I_L S_L + K_S I_R
 * with I_E the emitted radiance, K_A = K_D the albedo (each times its texture's texel at
 * the point hit), S_L the shadow-ray visibility and I_R the radiance along the mirror
 * direction. Point lights follow the classic model (no distance falloff).
 * Emissive surfaces act as area lights, sampled for soft shadows (a triangle by its mean
 * emitted power, L_e the emission texel at the sampled point): each sample adds
 * (K_D + K_S <V,R>^n) / pi * L_e cos(surface) cos(light) / r^2 / pdf, the Phong model read as
 * a reflectance function, so their diffuse part is exactly radiosity's direct light. Back
 * faces show black (one-sided surfaces; the back of a RAD_SURFACE_TWO_SIDED one is shaded
 * as its front, and a two-sided emitter lights both sides). One sample per pixel goes
 * through the pixel's centre. Fills `image` (its size sets the resolution). */
rad_status rad_raytrace(const rad_scene *scene, const rad_camera *camera,
                        const rad_raytrace_options *options, rad_image *image,
                        rad_error *error);

typedef struct rad_pathtrace_options {
    uint32_t samples_per_pixel; /* 0 = 64; the largest k^2 <= spp are stratified over the
                                   pixel, the rest uniform */
    uint32_t max_depth;         /* light reaches the eye after at most this many reflections
                                   (1 = direct light only); 0 = no limit (Russian roulette
                                   ends paths) */
    uint64_t seed;
    int threads;
    rad_progress_fn progress;
    void *progress_user;
} rad_pathtrace_options;

typedef struct rad_pathtrace_report {
    uint64_t rays;  /* closest-hit and shadow rays (of every rank) */
    double seconds;
    uint64_t rank_tiles;  /* 16 x 16 tiles this process traced: all of them unless the work
                             was shared over MPI ranks (rad_ranks_begin) */
    double rank_seconds;  /* this process's time tracing them (no waiting) */
} rad_pathtrace_report;

/* An unbiased path tracer for the same Lambertian scenes radiosity solves (albedo Kd,
 * emitted radiance Ke, each times its texture's texel at the point; one-sided unless
 * RAD_SURFACE_TWO_SIDED): cosine-weighted importance sampling, next-event
 * estimation on emitters combined with BSDF sampling by multiple importance sampling,
 * Russian roulette. Deterministic per seed for any thread count; parallel over tiles. The
 * reference for checking radiosity images. `standard_error` (NULL, or an image of the
 * same size) receives each pixel's standard error of the mean, per channel, estimated
 * from that pixel's own samples (+INFINITY with one sample per pixel).
 * After rad_ranks_begin joined a job of several MPI ranks this is collective: every rank
 * calls it with the same arguments, traces the tiles given to it by estimated cost, and
 * rank 0's image (and standard error) is then whole, bitwise the same as a serial run's;
 * the other ranks' images hold only their own tiles. A failure on any rank fails it on
 * every rank (rank 0 alone may fail gathering). */
rad_status rad_pathtrace(const rad_scene *scene, const rad_camera *camera,
                         const rad_pathtrace_options *options, rad_image *image,
                         rad_image *standard_error, rad_pathtrace_report *report,
                         rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Comparing images                                                                      */

typedef struct rad_compare_options {
    uint32_t block_size;    /* side of the square blocks compared; 0 = 8 */
    double block_tolerance; /* relative difference a block may have; 0 = 0.10 */
} rad_compare_options;

typedef struct rad_image_difference {
    double rmse;                 /* sqrt of the mean over pixels and channels of (a - b)^2 */
    double mean_relative_error;  /* mean over pixels of |a - b|_1 / |b|_1, over the pixels
                                    where b is not black */
    rad_rgb mean_a, mean_b;      /* mean radiance per channel */
    double worst_block_error;    /* largest relative difference of two blocks' means,
                                    |mean_a - mean_b|_1 / |mean_b|_1 */
    uint32_t worst_block_x, worst_block_y; /* its top-left pixel */
    uint32_t block_count;        /* whole blocks compared */
    uint32_t blocks_within;      /* how many of them are within block_tolerance */
    double blocks_within_tolerance; /* that fraction (0 when there is no whole block) */
    /* The accuracy measures of a render against a converged reference, on luminance
     * Y = 0.2126 R + 0.7152 G + 0.0722 B: */
    double block_relative_rmse;  /* the RMS over whole blocks of |Y_a - Y_b| / Y_b, the
                                    blocks' mean luminances, Y_b floored at 1e-3 of the
                                    image's mean */
    double pixel_relative_rmse;  /* sqrt(mean over pixels of (Y_a - Y_b)^2) / mean(Y_b),
                                    leaving out the light sources seen directly: pixels
                                    whose reference luminance exceeds 20 times the image's
                                    median, and 2 pixels around them */
    uint32_t pixels_left_out;    /* how many pixels that left out */
} rad_image_difference;

/* Compares a against b (the reference). The images must have the same size
 * (RAD_ERR_INVALID otherwise), and finite (RAD_ERR_INVALID naming the first bad pixel;
 * false_colour is left untouched on failure). Blocks tile the image from the top-left
 * corner; partial blocks at the right and bottom edges are left out. A block whose
 * reference mean is black scores 0 when a's is black too, else HUGE_VAL. `false_colour` (NULL, or an image of the same size)
 * receives a picture of where they differ: per pixel, the relative difference mapped
 * from blue (none) through green and yellow to red (100 % or more). */
rad_status rad_image_compare(const rad_image *a, const rad_image *b,
                             const rad_compare_options *options,
                             rad_image_difference *difference, rad_image *false_colour,
                             rad_error *error);

/* ------------------------------------------------------------------------------------ */
/* Output files                                                                          */

/* The lit mesh: the solution as geometry other tools read, view-independent. Each mesh
 * vertex carries its linear radiance (rad_reconstruct_vertices: what the renderer
 * interpolates) and a display colour: radiance times an exposure, clamped to [0,1]. After
 * the mesh's vertices come added ones, where a vertex of one region lies strictly inside
 * a patch edge of another (a crease or two materials side by side whose sides split their
 * common edge differently): each is its own region's interpolation along that edge. The
 * automatic exposure is the PNG one applied to vertices: the 95th percentile of the
 * luminance of the lit vertices (luminance > 0) is scaled to 0.9. Vertices are per smooth
 * region (rad_mesh), so creases and emitters stay sharp; patches are written as the
 * triangles the renderer uses: a quad as (0,1,2) and (0,2,3), a patch with T-vertices or
 * added vertices on its edges split through them, so faces meet corner to corner; a
 * two-sided surface's twins are faces of their own, wound to face their side, with their
 * own vertices and colours (viewers that cull back faces show each side's). Coordinates
 * are the scene's own (the built-in Cornell box is in millimetres); radiance is in the
 * unit of the emitters' Ke, the same numbers as a .pfm render. */
typedef struct rad_lit_mesh_options {
    bool fixed_exposure; /* false = automatic (above), true = use `exposure` */
    double exposure;     /* the display colour is radiance * 2^exposure */
    const rad_patch_inputs *inputs; /* NULL, or the patch inputs B was solved with
                                  (rad_patch_inputs_build of this scene and mesh; n must be
                                  mesh->patch_count): every vertex then also carries its
                                  irradiance, see rad_lit_mesh_write */
    /* NULL, or the scene B was solved for: when it has emitters or light sources
     * (rad_light) and direct_light is not
     * RAD_DIRECT_SOLUTION, every vertex carries the light computed at it, as the default
     * render shows it (rad_render_options.direct_light, RAD_DIRECT_VERTEX: the emitters'
     * direct light by 1024 light samples, a final gather of the solution's reflected light
     * by 1024 rays, plus here the sharp sources' direct light by one shadow ray each), on
     * the mesh split where the emitters' shadows bend the light (each piece keeps its
     * patch's B), instead of the area-weighted mean of its patches' B; the illuminance
     * (with inputs) is then that incident light. Costs about 2000-2600 rays per vertex.
     * Patches show their mean albedo (the file has no textures). */
    const rad_scene *scene;
    rad_direct_light direct_light; /* RAD_DIRECT_VERTEX (default) or RAD_DIRECT_SOLUTION;
                                      RAD_DIRECT_PIXEL, an image's mode, acts as VERTEX */
    uint64_t seed;                 /* of the vertex light's rays */
    int threads;                   /* 0 = all cores */
    /* NULL, or receives after a successful write (malloc'ed: free() it) the patch of mesh
     * each written triangle comes from, in the file's order, *triangle_patch_count of them:
     * with the light at the vertices the mesh is shown split where the emitters' shadows
     * bend the light, so this, not rad_lit_mesh_triangle_patches, names a picked
     * triangle's patch then (`radiosity view`). */
    uint32_t **triangle_patches;
    uint32_t *triangle_patch_count;
} rad_lit_mesh_options;

/* Writes the mesh lit by B (per-patch exitance) by the extension of path:
 *   .ply  binary little-endian PLY. Vertex: float x y z, float nx ny nz, uchar red green
 *         blue (the display colour, sRGB-encoded), float radiance_r radiance_g radiance_b
 *         (linear), with inputs then float illuminance_r illuminance_g illuminance_b;
 *         face: list uchar int vertex_indices. Comments give the exposure.
 *   .glb  binary glTF 2.0, one mesh of triangles with POSITION, NORMAL, COLOR_0 (the
 *         display colour as float RGB, linear as glTF requires: viewers apply the sRGB
 *         curve themselves), _RADIANCE (float RGB linear radiance, an application
 *         attribute), with inputs _ILLUMINANCE (float VEC3, likewise), and an unlit
 *         material (KHR_materials_unlit), so viewers show the colours as they are, not
 *         shaded again.
 *   .obj  `v x y z r g b` (the display colour, sRGB-encoded, in [0,1]: the vertex-colour
 *         extension MeshLab and Blender read), `vn`, triangles `f a//a b//b c//c`; the
 *         linear radiance is a comment line `#radiance R G B` per vertex, in vertex order,
 *         after the `v` lines (with inputs, each followed by `#illuminance R G B`), so the
 *         file stays one plain OBJ for every reader.
 * With options->inputs, the illuminance: per patch the irradiance (B_i - E_i) / rho_i per
 * channel where rho_i > 0 (the incident light, direct and interreflected; a negative
 * rounding residue is 0), and H_i, the light sources' direct light alone, where rho_i = 0:
 * a black patch reflects nothing, so B tells nothing of the light other surfaces send it.
 * Vertices get it exactly as the radiance (area-weighted means, T-vertices and added
 * vertices interpolated), times pi instead of over pi: lux with lights in candela and lux,
 * else pi x the unit of Ke. Without inputs the files hold no illuminance at all.
 * options NULL = automatic exposure, no illuminance. Atomic like rad_image_write.
 * RAD_ERR_INVALID for an unknown extension, a non-finite exposure, a non-finite B or
 * irradiance (naming the patch), or inputs->n other than mesh->patch_count (naming
 * both). */
rad_status rad_lit_mesh_write(const rad_mesh *mesh, const rad_rgb *B, const char *path,
                              const rad_lit_mesh_options *options, rad_error *error);

/* The patch (index into mesh->patches) of each triangle of the lit mesh rad_lit_mesh_write
 * writes for this mesh with the patches' own light (RAD_DIRECT_SOLUTION, or no scene; with
 * the light at the vertices take rad_lit_mesh_options.triangle_patches), in the file's
 * triangle order: *patch_of gets *triangle_count
 * values (malloc'ed: free() it), so patches[p].surface and .material name what a picked
 * triangle belongs to (`radiosity view` does). On failure *patch_of is NULL and
 * *triangle_count 0. */
rad_status rad_lit_mesh_triangle_patches(const rad_mesh *mesh, uint32_t **patch_of,
                                         uint32_t *triangle_count, rad_error *error);

/* A solution file: the per-patch radiosity B of one scene and meshing, so a scene is
 * solved once and rendered from many views (radiosity is view-independent). Binary,
 * little-endian: magic "\x89RADSOL\n", format version (uint32, RAD_SOLUTION_VERSION),
 * patch count (uint32), fingerprint (uint64), patch size (double), the mesh's shadow and
 * proximity levels (two int32, rad_mesh_options; version 2), then B as patch_count x 3
 * doubles (r, g, b), then an FNV-1a 64 checksum of every byte before it. Version 1 files
 * (no levels: the default shadow levels, no proximity refinement) are read too. */
#define RAD_SOLUTION_VERSION 2

typedef struct rad_solution {
    uint32_t patch_count;
    double patch_size;    /* the mesh was built with rad_mesh_build_with these options */
    int shadow_levels;    /* rad_mesh_options.shadow_levels */
    int proximity_levels; /* rad_mesh_options.proximity_levels */
    uint64_t fingerprint; /* rad_solution_fingerprint of that scene and mesh */
    rad_rgb *B;           /* patch_count exitances */
    char source[512];     /* the file it was read from */
} rad_solution;

/* A hash of what the solution depends on: the scene's positions and triangles (vertices,
 * materials, surfaces), each patch's albedo and exitance as the solve sees them
 * (rad_patch_inputs_build), the patch size, and the mesh's vertex count, patch count and
 * patch vertices. Floating-point values are hashed bit for bit. */
rad_status rad_solution_fingerprint(const rad_scene *scene, const rad_mesh *mesh,
                                    uint64_t *fingerprint, rad_error *error);

/* Writes B (mesh->patch_count values) for this scene and mesh. Atomic like
 * rad_image_write. */
rad_status rad_solution_write(const rad_scene *scene, const rad_mesh *mesh, const rad_rgb *B,
                              const char *path, rad_error *error);

/* Reads a solution file and checks it whole: RAD_ERR_PARSE, with a message naming the
 * file, when it is not a solution file, has another format version, is truncated or too
 * long, fails its checksum, or holds a negative or non-finite value. It is not yet tied to
 * a scene: build the mesh with its patch_size, then call rad_solution_match. */
rad_status rad_solution_read(const char *path, rad_solution **out, rad_error *error);

/* RAD_OK when the solution belongs to this scene and mesh (same fingerprint), else
 * RAD_ERR_INVALID with a message naming the file. */
rad_status rad_solution_match(const rad_solution *solution, const rad_scene *scene,
                              const rad_mesh *mesh, rad_error *error);

void rad_solution_destroy(rad_solution *solution);

/* Layouts of a surface view-factor matrix file. */
typedef enum rad_viewfactor_format {
    RAD_VIEWFACTOR_CSV = 0,       /* "surface,NAME1,...", then "NAMEi,F_i1,..." (%.9g) */
    RAD_VIEWFACTOR_MATRIX_MARKET, /* "%%MatrixMarket matrix coordinate real general", then
                                     "% surface K AREA NAME" comment lines naming the rows
                                     in order with their areas, "ROWS COLUMNS NONZEROS" and
                                     one "I J F_IJ" line per stored factor, 1-based, %.17g */
    RAD_VIEWFACTOR_VIEW3D         /* View3D's text output (its SaveF0 layout, what its
                                     ViewHT and readers take): the header
                                     "View3D 3.3 0 ENCL EMIT N" padded to 30 characters,
                                     the areas (%g), one row of N factors per surface
                                     (%.6f), the emissivities (%.3f) */
} rad_viewfactor_format;

/* The format named by a file's extension: .mtx is Matrix Market, anything else CSV
 * (View3D's layout has no extension of its own: ask for it explicitly). */
rad_viewfactor_format rad_viewfactor_format_for_path(const char *path);

typedef struct rad_viewfactor_write_options {
    rad_viewfactor_format format;
    bool enclosure; /* View3D header's `encl` field: the rows were closed (--enclosure) */
    bool script_f;  /* View3D header's `emit` field: the values are script-F factors */
    bool error_bounds; /* the values are the factors' error bounds (the Matrix Market
                          comment line says so) */
} rad_viewfactor_write_options;

/* Writes the matrix of `scene`'s surfaces (matrix->n == scene->surface_count). Surfaces
 * flagged RAD_SURFACE_OBSTRUCTION are left out of every layout (rows and columns; Matrix
 * Market indices count only the surfaces written). options NULL = CSV. Atomic like
 * rad_image_write. */
rad_status rad_viewfactor_matrix_write(const rad_scene *scene,
                                       const rad_viewfactor_matrix *matrix, const char *path,
                                       const rad_viewfactor_write_options *options,
                                       rad_error *error);

/* The same to an open stream (standard output, say). */
rad_status rad_viewfactor_matrix_print(const rad_scene *scene,
                                       const rad_viewfactor_matrix *matrix, FILE *stream,
                                       const rad_viewfactor_write_options *options,
                                       rad_error *error);

/* Writes `size` bytes to path atomically (temporary name, then rename). */
rad_status rad_write_file_atomic(const char *path, const void *data, size_t size,
                                 rad_error *error);

/* Peak resident memory of this process so far, in bytes. */
uint64_t rad_peak_memory_bytes(void);

/* The memory budget (the CLI's --max-memory): one process-wide limit on the bytes the run
 * holds, drawn down as it proceeds. "In use" is every byte of the C heap not yet freed
 * (the library's buffers, the scene, mesh, patch inputs, trees, links, matrices, images,
 * per-thread buffers, and Assimp's, libpng's, ... allocations: the allocator's own count)
 * plus Embree's BVH blocks (its memory monitor; those Embree takes from malloc are
 * counted twice, erring on the side of refusing) plus what rad_memory_budget_reserve
 * promised to buffers made later. Not counted: the program's code and static data, the
 * shared libraries, thread stacks, and heap memory freed but kept by the allocator (the
 * gap between the budget and the peak resident size).
 *
 * With a budget set:
 *   - steps whose size is known before their work refuse up front, with RAD_ERR_NOMEM and
 *     a message "--max-memory: WHAT needs X, more than the Y left of the budget of Z":
 *     the dense matrix (rad_solve_scene), the hierarchical trees, the Embree BVH (an
 *     estimate of 128 bytes a triangle), the view-factor matrix (20 bytes an entry, up to
 *     both directions of every pair of surfaces that do not face away), and the images
 *     the CLI reserves;
 *   - any other allocation of the library that would exceed it fails as if the machine
 *     were out of memory (RAD_ERR_NOMEM from the function that made it; nothing is
 *     written), and Embree's monitor cancels a BVH build that would (RAD_ERR_NOMEM);
 *     rad_memory_budget_refusal then says how much was asked for;
 *   - the hierarchical solver's links get what is left after its trees and 2 MB a thread,
 *     less a quarter kept for its per-pass buffers (rad_scene_solve_options.max_memory).
 * Small allocations (and Embree's small blocks) are checked once every megabyte of them
 * per thread, so the heap may pass the budget by at most 1 MB per thread. Thread safe. */

/* Sets the budget to `bytes` (0 = none, the default) and clears the reservations, the
 * high-water mark and the recorded refusal. Set it before the run's first step. */
void rad_memory_budget_set(uint64_t bytes);

/* The budget set, 0 = none. */
uint64_t rad_memory_budget(void);

/* Bytes in use now as the budget counts them (heap + Embree), without reservations. */
uint64_t rad_memory_in_use(void);

/* Bytes left: the budget less what is in use and reserved (0 when over); UINT64_MAX
 * without a budget. */
uint64_t rad_memory_budget_left(void);

/* The high-water mark since rad_memory_budget_set: the most that was in use and reserved
 * plus the bytes asked for, at a check that passed. A run given exactly this budget makes
 * the same checks and passes them (with one thread; Embree's parallel build and several
 * threads' allocations make it vary by a little). 0 without a budget. */
uint64_t rad_memory_budget_peak(void);

/* Up-front check: RAD_OK when `bytes` more fit the budget (or there is none), else
 * RAD_ERR_NOMEM with "--max-memory: WHAT needs X, more than the Y left of the budget of
 * Z". Takes nothing: the step allocates afterwards, and those allocations count. */
rad_status rad_memory_budget_need(uint64_t bytes, const char *what, rad_error *error);

/* Promises `bytes` to a buffer made later (an image after the solve): counted as in use
 * until rad_memory_budget_unreserve gives them back, just before that buffer is made. */
void rad_memory_budget_reserve(uint64_t bytes);
void rad_memory_budget_unreserve(uint64_t bytes);

/* After a RAD_ERR_NOMEM: true when the budget refused something since it was set, with
 * "--max-memory: X more, with Y in use, would exceed the budget of Z" (the first refusal)
 * in `text`. */
bool rad_memory_budget_refusal(char *text, size_t size);

/* ---- Several processes: MPI ranks (a build with -DRAD_MPI=ON) ----
 * A program (the tool) launched by `mpirun -np N` or `srun` calls rad_ranks_begin first;
 * from then on the functions documented as collective share their work over the N ranks
 * and return the result on rank 0. Without that call, in a build without RAD_MPI, or in a
 * process not started by mpirun or srun, there is one rank and nothing changes. */

/* Joins the MPI job when this process was launched by mpirun or srun (MPI_Init, OpenMP
 * threads below each rank); returns the rank count (1 when not launched so, and always
 * without RAD_MPI). */
int rad_ranks_begin(void);

/* Leaves the job (MPI_Finalize) when rad_ranks_begin joined it; one rank again. */
void rad_ranks_end(void);

/* This process's rank (0 .. count - 1) and the rank count: 0 and 1 outside a job. */
int rad_rank(void);
int rad_rank_count(void);

/* Ends the whole job at once with exit_code (MPI_Abort over several ranks, else exit()):
 * for a rank that failed alone, after it printed its message. The one library function
 * that exits; it does not return. */
void rad_ranks_abort(int exit_code);

/* Bytes this rank has sent and received through the collective steps so far. */
uint64_t rad_ranks_bytes_communicated(void);

/* Collective: how many ranks pass failed = true (0 when every rank went well), on every
 * rank: lets the ranks agree to stop together (same error everywhere) or to abort (a rank
 * failed alone). Outside a job: failed ? 1 : 0. */
int rad_ranks_failures(bool failed);

/* One rank's share of a run, for the run summary. */
typedef struct rad_rank_report {
    uint64_t work;               /* items done: view-factor rows, image rows */
    double seconds;              /* time spent on them (without waiting for other ranks) */
    uint64_t peak_memory;        /* rad_peak_memory_bytes() */
    uint64_t bytes_communicated; /* rad_ranks_bytes_communicated() */
} rad_rank_report;

/* Collective: every rank's report to rank 0's all[0 .. rad_rank_count() - 1] (other ranks'
 * `all` is not touched). */
rad_status rad_ranks_gather_reports(const rad_rank_report *mine, rad_rank_report *all,
                                    rad_error *error);

/* Seconds on a monotonic clock (CLOCK_MONOTONIC; its zero is arbitrary): the clock of every
 * `seconds` field of the reports above. A duration is the difference of two readings. */
double rad_clock_seconds(void);

#ifdef __cplusplus
}
#endif

#endif /* RADIOSITY_H */
