/*
 * reflector_planes.h - where the light a flat surface reflects kinks on the surfaces
 * around it (internal).
 *
 * A point in front of a flat region's plane sees the region's front; a point behind it
 * sees none of it. Crossing the plane beside the region, the factor to it grows from 0
 * linearly with the height above the plane, so the light it reflects onto another
 * surface has a kink along the line its plane cuts that surface (a first-derivative
 * discontinuity: the D1 event of discontinuity meshing). Shown linearly between vertices a
 * patch apart the kink is cut off: on the Cornell box the tall block's face at the height
 * of the short block's top came out 3.4 % too bright on 2 rows at 128 x 128 (the short
 * block's top is bright, the face beside it dim). light_refine splits such patches.
 *
 * For a region R (area A, reflected radiosity L, its centre a distance d from the patch's)
 * far from the patch, the factor's slope across its plane is about A / (pi d^3) (the point
 * beside R at height h: F ~ A cos / (pi d^2) x h / d), so the irradiance's slope changes
 * by about L A / (pi d^3) there, and interpolation across a patch of size s (its longest
 * edge; a plane along a quad's diagonal crosses up to sqrt 2 s) misses the kink by about
 * a quarter of that times s. Relative to the patch's own irradiance H:
 *
 *     kink = L A s / (4 pi d^3 H),   d at least R's radius.
 *
 * An estimate, not a bound: beside a large R, at a distance rho from its edge, the slope
 * is about 1 / (2 rho), which d floored at the radius (1 / R there) understates.
 *
 * reflector_kink gives the largest over the regions whose plane crosses the patch (its
 * corners strictly on both sides) and that lie at least partly in front of it.
 */
#ifndef RAD_RENDER_REFLECTOR_PLANES_H
#define RAD_RENDER_REFLECTOR_PLANES_H

#include "radiosity.h"

/* Regions a patch is tested against, at most: the brightest (A L) first. The test is a few
 * dozen flops; a mesh of n candidate patches tests at most REFLECTOR_TESTS / n regions. */
#define REFLECTOR_TESTS 20000000u

typedef struct reflector {
    rad_vec3 normal, centre; /* unit normal of the region's first patch; area centroid */
    double offset;           /* normal . x = offset on its plane */
    double radius;           /* of the sphere about centre holding its corners */
    double strength;         /* A L: area times the luminance of its reflected radiosity */
} reflector;

typedef struct reflector_set {
    reflector *items; /* brightest first */
    uint32_t count;
} reflector_set;

/* The mesh's flat regions (patches joined by shared vertices: one surface, one material,
 * one plane) that reflect light in solution B (B - E per patch), brightest first. */
rad_status reflectors_build(const rad_mesh *mesh, const rad_rgb *B,
                            const rad_patch_inputs *inputs, reflector_set *out,
                            rad_error *error);

void reflectors_free(reflector_set *set);

/* The largest kink (above) a region's plane makes in the patch (corners from vertices,
 * longest edge `size`), whose own irradiance is `irradiance` (radiosity units, > 0),
 * testing the first `limit` regions; 0 when no region's plane crosses it. */
double reflector_kink(const reflector_set *set, uint32_t limit, const rad_patch *patch,
                      const rad_vec3 *vertices, double size, double irradiance);

#endif
