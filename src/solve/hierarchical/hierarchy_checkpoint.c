/*
 * hierarchy_checkpoint.c - the hierarchical solver's state in a checkpoint
 * (hierarchy_checkpoint.h).
 *
 * Layout, little-endian: phase, iterations, passes, quiet passes (u32 each), rays, rays
 * traced alike on every rank (u64 each), flags (u32: 1 memory capped, 2 refining,
 * 4 converged), the last sweep's change and the gather's first (f64), the store's capacity
 * and peak bytes (u64), the patch count (u32), the link count (u64); per link its receiver
 * and source (u32), transfer and bound (f32), visible share and flags (u16, as a u32 pair);
 * then B per patch and down per leaf position (3 f64 each); in phase HIER_IN_FINAL then
 * the final gather's rounds done (u32) and its correction per leaf position (3 f64 each).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/error.h"
#include "solve/hierarchical/hierarchy_checkpoint.h"

enum { FLAG_CAPPED = 1, FLAG_REFINING = 2, FLAG_CONVERGED = 4 };

void hier_checkpoint_put(byte_sink *body, const hier_loop_state *state, uint32_t patches,
                         const hlink *links, uint64_t count, const rad_rgb *B,
                         const rad_rgb *down_by_position,
                         const rad_rgb *correction_by_position)
{
    sink_u32(body, state->phase);
    sink_u32(body, state->iterations);
    sink_u32(body, state->passes);
    sink_u32(body, state->quiet_passes);
    sink_u64(body, state->rays);
    sink_u64(body, state->rays_shared);
    sink_u32(body, (state->memory_capped ? FLAG_CAPPED : 0) |
                       (state->refining ? FLAG_REFINING : 0) |
                       (state->converged ? FLAG_CONVERGED : 0));
    sink_f64(body, state->sweep_change);
    sink_f64(body, state->first);
    sink_u64(body, state->capacity);
    sink_u64(body, state->peak_bytes);
    sink_u32(body, patches);
    sink_u64(body, count);
    for (uint64_t l = 0; l < count; l++) {
        const hlink *k = &links[l];
        sink_u32(body, k->receiver);
        sink_u32(body, k->source);
        sink_floats(body, &k->transfer, 1);
        sink_floats(body, &k->bound, 1);
        sink_u32(body, (uint32_t)k->visible | (uint32_t)k->flags << 16);
    }
    sink_rgbs(body, B, patches);
    sink_rgbs(body, down_by_position, patches);
    if (state->phase == HIER_IN_FINAL) {
        sink_u32(body, state->final_rounds);
        sink_rgbs(body, correction_by_position, patches);
    }
}

static bool rgbs_ok(const rad_rgb *v, uint32_t n, bool nonnegative)
{
    for (uint32_t k = 0; k < n; k++)
        if (!(isfinite(v[k].r) && isfinite(v[k].g) && isfinite(v[k].b)) ||
            (nonnegative && !(v[k].r >= 0 && v[k].g >= 0 && v[k].b >= 0)))
            return false;
    return true;
}

bool hier_checkpoint_get(byte_source *source, const char *path, const hier_tree *tree,
                         uint32_t patches, const uint8_t *keep, hier_loop_state *state,
                         hlink **links, size_t *count, size_t *capacity, rad_rgb *B,
                         rad_rgb *down_by_position, rad_rgb *correction_by_position,
                         rad_error *error)
{
    *links = NULL;
    *count = *capacity = 0;
    hier_loop_state s = {0};
    s.phase = source_u32(source);
    s.iterations = source_u32(source);
    s.passes = source_u32(source);
    s.quiet_passes = source_u32(source);
    s.rays = source_u64(source);
    s.rays_shared = source_u64(source);
    uint32_t flags = source_u32(source);
    s.memory_capped = flags & FLAG_CAPPED;
    s.refining = flags & FLAG_REFINING;
    s.converged = flags & FLAG_CONVERGED;
    s.sweep_change = source_f64(source);
    s.first = source_f64(source);
    s.capacity = source_u64(source);
    s.peak_bytes = source_u64(source);
    uint32_t n = source_u32(source);
    uint64_t listed = source_u64(source);
    if (source->short_read || s.phase < HIER_AT_PASS || s.phase > HIER_IN_FINAL ||
        n != patches || !(s.sweep_change >= 0) || !(s.first >= 0)) {
        rad_fail(error, RAD_ERR_PARSE, "%s: not a whole hierarchical solver state", path);
        return false;
    }
    if (listed > source_left(source) / 20) {
        rad_fail(error, RAD_ERR_PARSE, "%s: truncated (%llu links listed)", path,
                 (unsigned long long)listed);
        return false;
    }
    size_t room = listed > s.capacity ? (size_t)listed : (size_t)s.capacity;
    hlink *kept = rad_alloc_array(room ? room : 1, sizeof(hlink));
    if (!kept) {
        rad_fail(error, RAD_ERR_NOMEM, "%s: out of memory for %llu links", path,
                 (unsigned long long)listed);
        return false;
    }
    size_t held = 0;
    for (uint64_t l = 0; l < listed; l++) {
        hlink k;
        k.receiver = source_u32(source);
        k.source = source_u32(source);
        source_floats(source, &k.transfer, 1);
        source_floats(source, &k.bound, 1);
        uint32_t packed = source_u32(source);
        k.visible = (uint16_t)(packed & 0xffff);
        k.flags = (uint16_t)(packed >> 16);
        if (k.receiver >= tree->node_count || k.source >= tree->node_count ||
            !(k.transfer >= 0 && isfinite(k.transfer)) || !(k.bound >= 0)) {
            free(kept);
            rad_fail(error, RAD_ERR_PARSE, "%s: link %llu is out of range or not finite",
                     path, (unsigned long long)l);
            return false;
        }
        if (!keep || keep[k.receiver])
            kept[held++] = k;
    }
    source_rgbs(source, B, patches);
    source_rgbs(source, down_by_position, patches);
    bool corrections_ok = true;
    if (s.phase == HIER_IN_FINAL) {
        s.final_rounds = source_u32(source);
        source_rgbs(source, correction_by_position, patches);
        corrections_ok = rgbs_ok(correction_by_position, patches, false);
    }
    if (source->short_read || source_left(source) || !rgbs_ok(B, patches, true) ||
        !rgbs_ok(down_by_position, patches, false) || !corrections_ok) {
        free(kept);
        rad_fail(error, RAD_ERR_PARSE, "%s: %s", path,
                 source->short_read || source_left(source)
                     ? "the radiosity is truncated or followed by unexpected bytes"
                     : "a radiosity that is not finite");
        return false;
    }
    *state = s;
    *links = kept;
    *count = held;
    *capacity = room ? room : 1;
    return true;
}
