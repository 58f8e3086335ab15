// Atty et al. 2006, Soft Shadow Maps: the micro-patch list. Each occluder-map texel becomes a
// micro-patch (Sec. 3.2), merged with its neighbours into one where their depths agree, and its
// penumbra rectangle on the soft shadow map (Sec. 3.3) is bounded by the deepest receiver under
// it; the patches that can hide anything are appended to a list that the accumulation draws with
// one indirect instanced draw, so its vertex work follows the patches drawn, not the map's texels.

// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl
// #import atty/atty_geometry.wgsl
// #import atty/atty_counts.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var occluder_map: texture_2d<f32>;
@group(1) @binding(1) var<uniform> settings: AttySettings;
// The receiver map's max-pyramid (atty_receiver_bounds.wgsl).
@group(1) @binding(2) var receiver_bounds: texture_2d<f32>;
// The occluder map's min-max pyramid (atty_patch_merge.wgsl).
@group(1) @binding(3) var patch_merge: texture_2d<f32>;
@group(1) @binding(4) var<storage, read_write> patches: array<MicroPatchRecord>;
// The accumulation's indirect draw: (4 vertices, patch count, 0, 0).
@group(1) @binding(5) var<storage, read_write> draw_arguments: array<atomic<u32>, 4>;
// This pass's counters (atty_counts.wgsl): 0, texel reads; 1, the bytes they fetched; 2, atomics
// (one per patch listed); 3, bytes written to storage (one 32-byte record per patch listed).
@group(1) @binding(6) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel read (the pipeline sets them from the formats: src/lib.rs's
// patches_pipeline): of the occluder map (R32Float), of the receiver map's max-pyramid (R32Float)
// and of the occluder map's min-max pyramid (Rg32Float).
override OCCLUDER_TEXEL_BYTES: u32;
override BOUNDS_TEXEL_BYTES: u32;
override MERGE_TEXEL_BYTES: u32;

// Texel reads of this invocation (textureLoad calls), and the bytes they fetched, for the counts.
var<private> reads: u32;
var<private> read_bytes: u32;

// The deepest receiver among the SSM texels whose centres lie in the rectangle [low, high] (SSM
// coordinates, [-1, 1]), from the max-pyramid at the finest level where the texels span at most
// 2×2; 0 when the rectangle holds no texel centre.
fn deepest_receiver(low: vec2<f32>, high: vec2<f32>) -> f32 {
    let size = settings.soft_shadow_map_size;
    let last_texel = vec2<i32>(i32(size) - 1);
    // Texels t whose centres t + 1/2 lie in the rectangle.
    let first = max(vec2<i32>(ceil((low * 0.5 + 0.5) * size - 0.5)), vec2<i32>(0));
    let last = min(vec2<i32>(floor((high * 0.5 + 0.5) * size - 0.5)), last_texel);
    if (any(last < first)) {
        return 0.0;
    }
    let levels = textureNumLevels(receiver_bounds);
    var level = 0u;
    while (level + 1u < levels && any((last >> vec2<u32>(level)) - (first >> vec2<u32>(level)) > vec2<i32>(1))) {
        level++;
    }
    // Texel t of level L covers t·2^L to (t + 1)·2^L − 1, the last one to the map's end.
    // Mip sizes halve rounding down. (Computed, not asked of textureDimensions(t, level): on
    // lavapipe that gave wrong sizes for a level not known at compile time, which dropped shadow
    // here; not traced further, to naga's SPIR-V or to the driver.)
    let level_last = max(vec2<i32>(i32(size) >> level) - 1, vec2<i32>(0));
    let a = min(first >> vec2<u32>(level), level_last);
    let b = min(last >> vec2<u32>(level), level_last);
    reads += 4u;
    read_bytes += 4u * BOUNDS_TEXEL_BYTES;
    let lower = max(textureLoad(receiver_bounds, a, level).x, textureLoad(receiver_bounds, vec2<i32>(b.x, a.y), level).x);
    let upper = max(textureLoad(receiver_bounds, vec2<i32>(a.x, b.y), level).x, textureLoad(receiver_bounds, b, level).x);
    return max(lower, upper);
}

// Neighbouring micro-patches at one depth hide, from any receiver point, parts of the light that
// join exactly (Sec. 5.1.2: the overlap or gap of Eq. 3 grows with their depth difference δh and
// vanishes with it), so an aligned block of texels whose depths agree within `merge_tolerance`
// micro-patch widths is drawn as one patch: the same occlusion for a fraction of the quads.
// Returns (level, depth) for the block of 2^level texels whose first texel is `texel`, the depth
// the middle of its range; level -1 when `texel` is not the first of its block.
fn merged_block(texel: vec2<u32>, depth: f32) -> vec2<f32> {
    if (settings.merge_tolerance <= 0.0) {
        return vec2<f32>(0.0, depth);
    }
    var level = 0u;
    var patch_depth = depth;
    let levels = textureNumLevels(patch_merge);
    let tan_half = max(frame.projection.x, frame.projection.y);
    loop {
        if (level + 1u >= levels) {
            break;
        }
        let block = texel >> vec2<u32>(level + 1u);
        // The level's size, halving rounding down (not textureDimensions(t, level): see deepest_receiver).
        if (any(block >= vec2<u32>(u32(settings.occluder_map_size) >> (level + 1u)))) {
            break;
        }
        let range = textureLoad(patch_merge, vec2<i32>(block), i32(level + 1u)).xy;
        reads += 1u;
        read_bytes += MERGE_TEXEL_BYTES;
        let width = 2.0 * range.x * tan_half / settings.occluder_map_size;
        if (range.y >= NO_SURFACE || range.y - range.x > settings.merge_tolerance * width) {
            break;
        }
        level++;
        patch_depth = 0.5 * (range.x + range.y);
    }
    if (any((texel & vec2<u32>((1u << level) - 1u)) != vec2<u32>(0u))) {
        return vec2<f32>(-1.0, 0.0);
    }
    return vec2<f32>(f32(level), patch_depth);
}

// Depth of a neighbouring texel of the occluder map, or -1 outside the map or where it is empty.
fn neighbour_depth(texel: vec2<i32>) -> f32 {
    let n = i32(settings.occluder_map_size);
    if (any(texel < vec2<i32>(0)) || any(texel >= vec2<i32>(n))) {
        return -1.0;
    }
    let depth = textureLoad(occluder_map, texel, 0).x;
    reads += 1u;
    read_bytes += OCCLUDER_TEXEL_BYTES;
    return select(depth, -1.0, depth >= NO_SURFACE);
}

// The occluder's depth change per texel along `step` at `texel` (depth `depth`): the smaller of the
// two one-sided differences, so that a depth edge (a silhouette) does not count as a slope.
fn depth_step(texel: vec2<i32>, depth: f32, step: vec2<i32>) -> f32 {
    var smallest = -1.0;
    for (var side = -1; side <= 1; side += 2) {
        let neighbour = neighbour_depth(texel + side * step);
        if (neighbour >= 0.0 && (smallest < 0.0 || abs(neighbour - depth) < smallest)) {
            smallest = abs(neighbour - depth);
        }
    }
    return max(smallest, 0.0);
}

// One invocation per occluder-map texel: its micro-patch (or its block's, Sec. 3.2), appended to
// the patch list with its penumbra rectangle (Sec. 3.3) unless an empty texel, another texel of
// its block, or no receiver behind it means it hides nothing.
@compute @workgroup_size(8, 8, 1)
fn atty_patches(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = u32(settings.occluder_map_size);
    if (any(id.xy >= vec2<u32>(n))) {
        return;
    }
    let listed = u32(list_patch(id.xy));
    let texel = vec2<i32>(id.xy);
    record_count(0u, texel, reads);
    record_count(1u, texel, read_bytes);
    record_count(2u, texel, listed);
    record_count(3u, texel, 32u * listed);
}

// The micro-patch of occluder texel `texel`: appends it to the list, and says whether it did.
fn list_patch(texel: vec2<u32>) -> bool {
    let depth = textureLoad(occluder_map, vec2<i32>(texel), 0).x;
    reads = 1u;
    read_bytes = OCCLUDER_TEXEL_BYTES;
    if (depth >= NO_SURFACE || depth <= 0.0) {
        return false;
    }
    let tan_half = frame.projection.xy;
    // The aligned block of 2^level texels starting at this one that is drawn as one micro-patch.
    let merged = merged_block(texel, depth);
    if (merged.x < 0.0) {
        // Another texel of its block draws it.
        return false;
    }
    let span = exp2(merged.x);
    let patch_depth = merged.y;
    // Sec. 3.2: the texel (or block) as a micro-patch parallel to the light, at its depth, covering its image area.
    let texel_ndc = (vec2<f32>(texel) + 0.5 * span) / settings.occluder_map_size * 2.0 - 1.0;
    let half_size = patch_depth * tan_half * span / settings.occluder_map_size;
    let self_shadow_depth = settings.self_shadow_tolerance * 2.0 * max(half_size.x, half_size.y) / span;
    // The patch stands for the occluder's surface across its texels, whose depth runs this far on
    // either side of the patch's (its slope across half the patch): the receiver-plane test
    // (atty_accumulation.wgsl) counts a patch whose surface reaches the receiver's plane as lying on it.
    var depth_spread = 0.0;
    if (settings.receiver_plane != 0.0) {
        let slope = vec2<f32>(depth_step(vec2<i32>(texel), depth, vec2<i32>(1, 0)), depth_step(vec2<i32>(texel), depth, vec2<i32>(0, 1)));
        depth_spread = 0.5 * span * (slope.x + slope.y);
    }
    let light_half = vec2<f32>(frame.u_axis.w, frame.v_axis.w);
    // Sec. 3.3: the penumbra extent is a pyramid whose section on the SSM is the rectangle centred
    // on the texel's own ndc position, of half extent penumbra_half_ndc at the receiver's depth,
    // growing with it: evaluated at the far plane it covers every receiver (conservative).
    var bound = frame.projection.w;
    if (settings.receiver_bounded != 0.0) {
        // Bounded by the deepest receiver under the rectangle instead: the rectangle at the far
        // plane holds every texel the patch can shade; the deepest receiver among them, z₁, gives
        // a smaller rectangle that still holds them (each receiver's own rectangle lies within the
        // one at any depth behind it), and the deepest receiver in that, z₂, a smaller one again.
        // The texels dropped are those whose receiver is not behind the patch: the same pixels.
        for (var refinement = 0; refinement < 2; refinement++) {
            let half_extent = penumbra_half_ndc(light_half, tan_half, half_size, patch_depth, bound);
            let deepest = deepest_receiver(texel_ndc - half_extent, texel_ndc + half_extent);
            // No receiver behind the patch under its rectangle: it hides nothing anywhere.
            if (deepest <= patch_depth + self_shadow_depth) {
                return false;
            }
            bound = min(bound, deepest);
        }
    }
    let half_ndc = penumbra_half_ndc(light_half, tan_half, half_size, patch_depth, bound);
    let slot = atomicAdd(&draw_arguments[1], 1u);
    patches[slot] = MicroPatchRecord(texel_ndc, half_ndc, patch_depth, self_shadow_depth, span, depth_spread);
    return true;
}
