// PVSM steps 3 and 4 (Sec. 4, 4.2, 5.1, 5.2), one invocation per pixel:
// - the average occluder depth from the low-resolution conservative map, in the region where the
//   light seen from the pixel crosses the near plane (no occluder: fully lit, skipped from then on);
// - the soft-shadowing filter s_α, the light's back-projection through the occluders' average
//   plane (α = (z_y - z_o) z_n / (z_y z_o) in the paper's notation), as half-axes in shadow-map
//   coordinates;
// - the pixel's footprint φ warped onto the map through the receiver's tangent plane, and the
//   anti-aliased filter h = M(φ) ⊗ s_α (the appendix's Gaussian convolution);
// - the screen sizes n0, n1 of h along the map's axes (Eq. 4), the predicted texel sizes (Eq. 5;
//   without antialiasing also bounded for a point sample, pvsm_common.wgsl's predicted_texels),
//   and the resolution they ask of every tile-grid cell the filter reads (the grid keeps the
//   finest: the maximum of texels per unit, by atomicMax on the float's bits).

// #import pvsm/pvsm_common.wgsl
// #import common/read_counts.wgsl

@group(2) @binding(2) var low_res_map: texture_2d<f32>;
@group(2) @binding(3) var<storage, read_write> kernels: array<Kernel>;
// Per grid cell, the finest resolution needed along u then v, as f32 bits (0: none).
@group(2) @binding(4) var<storage, read_write> grid: array<atomic<u32>>;
// COUNTER_* of pvsm_common.wgsl.
@group(2) @binding(5) var<storage, read_write> counters: array<atomic<u32>, COUNTERS>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_KERNEL_SHAPE (texel reads),
// READ_COUNTER_KERNEL_SHAPE_READ_BYTES (the bytes they fetched), READ_COUNTER_KERNEL_SHAPE_ATOMICS
// (atomic operations) and READ_COUNTER_PREDICTED_TEXELS (a diagnostic: the texels the pixel's own
// predicted resolution puts under its filter).
@group(2) @binding(6) var<storage, read_write> read_counts: array<atomic<u32>>;

// The ReadCounts counters of this pass (READ_COUNTERS in src/gpu.rs).
const READ_COUNTER_KERNEL_SHAPE: u32 = 2u;
const READ_COUNTER_KERNEL_SHAPE_READ_BYTES: u32 = 3u;
const READ_COUNTER_KERNEL_SHAPE_ATOMICS: u32 = 4u;
const READ_COUNTER_PREDICTED_TEXELS: u32 = 15u;

// Bytes of one texel of the low-resolution map's levels: R32Float (ssm-core's
// LightDepthMap::FORMAT, checked by a test of the crate).
const LOW_RES_TEXEL_BYTES: u32 = 4u;

// Most texels one pixel's count below adds: keeps a 32-bit bucket from overflowing at a large
// viewport under a filter many thousand predicted texels wide (a cost no prediction asks for).
const PREDICTED_TEXELS_CAP: f32 = 100000.0;

// Records, for a filtered pixel, the texels of its own predicted size (Eq. 5) that its filter (the
// parallelogram of half axes (u.x, u.y) and (0, v_height), area 4·|u.x|·v_height) covers, at least
// one: what the filter would read from a tile of exactly the pixel's resolution, against which the
// walk's reads in the tile it gets (pvsm_filter.wgsl) are set (the diagnostics'
// pvsm_filter_reads_over_predicted).
fn record_predicted_texels(pixel: vec2<u32>, u: vec2<f32>, v_height: f32, texel: vec2<f32>) {
    if (COUNT_READS) {
        let texels = clamp(4.0 * abs(u.x) * v_height / max(texel.x * texel.y, 1e-30), 1.0, PREDICTED_TEXELS_CAP);
        let word = read_count_word(READ_COUNTER_PREDICTED_TEXELS, vec2<i32>(pixel));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], u32(round(texels)));
    }
}

// Records one pixel's texel reads (one per textureLoad, ReadCounts' convention: the G-buffer's two
// at every pixel, trivial ones included, and the low-resolution map's), the bytes they fetched
// (`read_bytes`: GBUFFER_TEXEL_BYTES and LOW_RES_TEXEL_BYTES a texel) and atomics, with
// COUNT_READS (the settings' count_reads).
fn record_kernel_work(pixel: vec2<u32>, reads: u32, read_bytes: u32, atomics: u32) {
    if (COUNT_READS) {
        let word = read_count_word(READ_COUNTER_KERNEL_SHAPE, vec2<i32>(pixel));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(READ_COUNTER_KERNEL_SHAPE_READ_BYTES, vec2<i32>(pixel));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], read_bytes);
        let atomics_word = read_count_word(READ_COUNTER_KERNEL_SHAPE_ATOMICS, vec2<i32>(pixel));
        atomicAdd(&read_counts[atomics_word], 1u);
        atomicAdd(&read_counts[atomics_word + 1u], atomics);
    }
}

// How much the pixel's tangent plane's depth changes over `half_texel` (shadow-map coordinates)
// along both axes: the receiver's own depth spread within a texel of that size.
fn plane_change(point: ScreenPoint, uv: vec2<f32>, d: f32, half_texel: vec2<f32>) -> f32 {
    let here = tap_receiver_depth(frame, point.position, point.normal, uv, d, true);
    let along_u = tap_receiver_depth(frame, point.position, point.normal, uv + vec2<f32>(half_texel.x, 0.0), d, true) - here;
    let along_v = tap_receiver_depth(frame, point.position, point.normal, uv + vec2<f32>(0.0, half_texel.y), d, true) - here;
    return abs(along_u) + abs(along_v);
}

// The area of texel `texel` (of side 1) inside the rectangle `region` (xy min, zw max, in texels).
fn texel_area_in(region: vec4<f32>, texel: vec2<i32>) -> f32 {
    let low = max(region.xy, vec2<f32>(texel));
    let high = min(region.zw, vec2<f32>(texel) + 1.0);
    let overlap = max(high - low, vec2<f32>(0.0));
    return overlap.x * overlap.y;
}

// kdtree::MIN_TILE_SIZE: the fewest texels a tile's map has (checked by a test of the crate).
const MIN_TILE_SIZE: f32 = 8.0;

// Texels per side of the blocker search's region at the mip level its detection reads (every
// pixel pays for it, lit or not: a coarser level only makes the test more conservative).
const DETECTION_TEXELS: f32 = 4.0;

// Whether a texel or block centred on `uv`, `slack` from its centre to its edges, at light depth
// `depth` (a block's nearest) can hold a point between the receiver at `uvd` and the light: the
// light seen from the receiver crosses the plane at that depth in the rectangle uvd.xy ± the
// light's extent there (light_half_extent_uv, the search region's own formula, 2% nearer as the
// region is, so that a texel whose light grazes an occluder's edge still counts), and the texel
// must meet it. A texel in front of the receiver's plane but outside it cannot occlude the point: walls,
// floor and ceiling beside a light in a room, which the search region through the nearest depth
// (about 0 there) reaches from every pixel.
fn in_cone(uv: vec2<f32>, depth: f32, uvd: vec3<f32>, slack: vec2<f32>) -> bool {
    return all(abs(uv - uvd.xy) <= light_half_extent_uv(frame, 0.98 * depth, uvd.z) + slack);
}

// What cone_samples found: the blockers' depth sum, their count and the nearest (the receiver's
// depth where none), and the texels it read (each a texel of the low-resolution map's level 0).
struct ConeSamples {
    sum: f32,
    count: f32,
    nearest: f32,
    reads: u32,
};

// The blocker search's n×n samples over uvd.xy ± extent on the low-resolution map, each a blocker
// where it lies in front of the receiver's plane by more than `tolerance` and in the receiver's
// light cone (in_cone, `slack`: half a texel).
fn cone_samples(uvd: vec3<f32>, extent: vec2<f32>, n: u32, receiver: TapPlane, tolerance: f32, slack: vec2<f32>) -> ConeSamples {
    var found = ConeSamples(0.0, 0.0, uvd.z, 0u);
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let uv = uvd.xy + vec2<f32>(grid_offset(i, n), grid_offset(j, n)) * extent;
            let depth = shadow_map_depth(low_res_map, uv);
            // shadow_map_depth reads a texel only inside the map.
            found.reads += select(0u, 1u, all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0)));
            if (depth < tap_plane_depth(receiver, uv) - tolerance && in_cone(uv, depth, uvd, slack)) {
                found.sum += depth;
                found.count += 1.0;
                found.nearest = min(found.nearest, depth);
            }
        }
    }
    return found;
}

// The size in texels of level `level` of the low-resolution map's mip chain, from the base's:
// textureDimensions with a level argument reads the base level's size on lavapipe (Mesa 22.3), and
// loads past a level's edge return 0.
fn low_res_level_size(level: u32) -> vec2<f32> {
    return vec2<f32>(max(textureDimensions(low_res_map, 0) >> vec2<u32>(level), vec2<u32>(1u)));
}

// Most blocks the descent follows per level of the min-depth chain.
const DESCENT_BLOCKS: u32 = 16u;
// Regions the retry samples when the region's samples found no blocker: each a quarter of the last.
const RETRY_REGIONS: u32 = 6u;

// Adds `block` (texel x, y and its nearest depth) to the first `count` of `blocks`, or, when they
// are DESCENT_BLOCKS, in place of the farthest if it is nearer; whether a block was left out.
fn keep_nearest(blocks: ptr<function, array<vec3<f32>, DESCENT_BLOCKS>>, count: ptr<function, u32>, block: vec3<f32>) -> bool {
    if (*count < DESCENT_BLOCKS) {
        (*blocks)[*count] = block;
        *count += 1u;
        return false;
    }
    var farthest = 0u;
    for (var k = 1u; k < DESCENT_BLOCKS; k++) {
        if ((*blocks)[k].z > (*blocks)[farthest].z) {
            farthest = k;
        }
    }
    if (block.z < (*blocks)[farthest].z) {
        (*blocks)[farthest] = block;
    }
    return true;
}

// Shadow-map coordinates where the camera ray through `pixel` meets the pixel's tangent plane;
// w = 0 where it does not.
fn plane_uv(point: ScreenPoint, pixel: vec2<f32>) -> vec3<f32> {
    let hit = tangent_point(point.position, point.normal, pixel);
    if (hit.w == 0.0 || !in_front_of_light(frame, hit.xyz)) {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(light_uv_depth(frame, hit.xyz).xy, 1.0);
}

@compute @workgroup_size(8, 8)
fn pvsm_kernel(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    var kernel: Kernel;
    kernel.flags = 0u;
    let point = screen_point_at(vec2<i32>(id.xy));
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        kernel.flags = select(0u, KERNEL_DARK, trivial == 0.0);
        kernels[index] = kernel;
        // The G-buffer's two texels.
        record_kernel_work(id.xy, 2u, 2u * GBUFFER_TEXEL_BYTES, 0u);
        return;
    }
    let uvd = light_uv_depth(frame, point.position);
    let d = uvd.z;

    // Blocker search on the conservative map (Sec. 4, 5.2), in two parts.
    // 1. Detection: every texel of the region where the light seen from the pixel crosses the near
    //    plane, at the finest level of the map's minimum-depth mip chain where the region spans at
    //    most DETECTION_TEXELS texels a side. A level's texel holds the nearest depth under it, so no
    //    occluder of the conservative map is missed: a pixel with none is fully lit.
    // 2. The average occluder depth on the full-resolution level (the minimum of a coarse texel
    //    would pull the average towards the light): where the region spans at most blocker_kernel
    //    texels a side, every texel of it once, weighted by its area inside the region (the exact
    //    average of the map over the region, for no more reads than the samples); otherwise
    //    blocker_kernel² samples. The coarse blockers stand in when the samples fall between
    //    occluders too thin to be hit.
    let base_size = vec2<f32>(textureDimensions(low_res_map, 0));
    let levels = textureNumLevels(low_res_map);
    // The region is the light seen from the pixel through the nearest occluder's plane: the top of
    // the min-depth chain holds the nearest depth of the whole map, and no occluder is nearer the
    // light. The frame's near plane would be looser, and unbounded where the frame fit clips the
    // scene's box at the light's plane (near ≈ 0: the whole map, then read at its 1×1 level). 2%
    // nearer, as the frame's own near plane, so that a pixel whose light only grazes an occluder's
    // edge still finds it (the parallel-square test's penumbra error rises from 0.0175 to 0.0197
    // without it).
    let nearest = textureLoad(low_res_map, vec2<i32>(0), i32(levels - 1u)).x;
    // The G-buffer's two texels and this one, and the bytes the reads fetched.
    var reads = 3u;
    var read_bytes = 2u * GBUFFER_TEXEL_BYTES + LOW_RES_TEXEL_BYTES;
    let search = light_half_extent_uv(frame, clamp(0.98 * nearest, frame.projection.z, d), d);
    let n = max(settings.blocker_kernel, 1u);
    let span = max(2.0 * search * base_size, vec2<f32>(1.0));
    let level = min(u32(max(ceil(log2(max(span.x, span.y) / DETECTION_TEXELS)), 0.0)), levels - 1u);
    let level_size = low_res_level_size(level);
    let texel = shadow_texel_size(frame, low_res_map, d);
    // A texel's nearest depth of the receiver itself is its tangent plane's at the texel's nearest
    // corner (and a conservative map adds up to a texel): the plane's change across half a texel,
    // capped at a texel's worth so that a surface seen edge-on by the light still finds the rest of
    // its own object in front of it.
    let bias = scene_length(frame, settings.constant_bias) + texel;
    let coarse_tolerance = bias + min(plane_change(point, uvd.xy, d, 0.5 / level_size), f32(1u << level) * texel);
    let fine_tolerance = bias + min(plane_change(point, uvd.xy, d, 0.5 / base_size), texel);
    // What each tap is compared with (the settings' receiver model), prepared once.
    let receiver = receiver_tap_plane(frame, point.position, point.normal, d, settings.receiver_plane != 0u);
    let low = vec2<i32>(floor((uvd.xy - search) * level_size));
    let high = vec2<i32>(floor((uvd.xy + search) * level_size));
    let limit = vec2<i32>(level_size) - 1;
    // The region in the full-resolution level's texels, and whether it is small enough to read whole.
    let region = vec4<f32>((uvd.xy - search) * base_size, (uvd.xy + search) * base_size);
    let fine_span = vec2<i32>(floor(region.zw)) - vec2<i32>(floor(region.xy)) + 1;
    let whole = all(fine_span <= vec2<i32>(i32(n)));
    // In an interior (a closed mesh holds the light: a room lit from its wall or ceiling), the
    // walls, floor and ceiling beside the light lie next to its plane, in front of the receiver's
    // and inside the region through the nearest depth, though none can hide the light from it:
    // averaged in, they make every filter huge and blur the shadows away. There only texels in
    // the receiver's light cone count (in_cone), and steps 1 to 4 below find those. Elsewhere the
    // paper's search, which counts every texel of the region in front of the receiver (measured:
    // the cone search everywhere raises contact's error from 0.027 to 0.052; docs/notes/pvsm.md).
    let cone_search = light_enclosed(frame);
    var coarse_sum = 0.0;
    var coarse_count = 0.0;
    // The detection's blocks (the nearest DESCENT_BLOCKS), where the descent starts, and whether
    // any was left out.
    var blocks: array<vec3<f32>, DESCENT_BLOCKS>;
    var block_count = 0u;
    var blocks_left_out = false;
    // Area-weighted sums over the full-resolution level: at level 0 the detection reads those very
    // texels with the same tolerance (the level's texel is the base's), so it gathers them too.
    var sum = 0.0;
    var count = 0.0;
    // The nearest blocker found, and the half extent of the region whose samples found it.
    var nearest_found = d;
    var sampled_extent = search;
    for (var y = max(low.y, 0); y <= min(high.y, limit.y); y++) {
        for (var x = max(low.x, 0); x <= min(high.x, limit.x); x++) {
            let depth = textureLoad(low_res_map, vec2<i32>(x, y), i32(level)).x;
            reads += 1u;
            read_bytes += LOW_RES_TEXEL_BYTES;
            let uv = (vec2<f32>(f32(x), f32(y)) + 0.5) / level_size;
            if (depth < tap_plane_depth(receiver, uv) - coarse_tolerance) {
                coarse_sum += depth;
                coarse_count += 1.0;
                blocks_left_out = keep_nearest(&blocks, &block_count, vec3<f32>(f32(x), f32(y), depth)) || blocks_left_out;
                if (level == 0u && whole && (!cone_search || in_cone(uv, depth, uvd, 0.5 / level_size))) {
                    let area = texel_area_in(region, vec2<i32>(x, y));
                    sum += area * depth;
                    count += area;
                }
            }
        }
    }
    if (coarse_count > 0.0 && level > 0u && whole) {
        let fine_low = max(vec2<i32>(floor(region.xy)), vec2<i32>(0));
        let fine_high = min(vec2<i32>(floor(region.zw)), vec2<i32>(base_size) - 1);
        for (var y = fine_low.y; y <= fine_high.y; y++) {
            for (var x = fine_low.x; x <= fine_high.x; x++) {
                let depth = textureLoad(low_res_map, vec2<i32>(x, y), 0).x;
                reads += 1u;
                read_bytes += LOW_RES_TEXEL_BYTES;
                let uv = (vec2<f32>(f32(x), f32(y)) + 0.5) / base_size;
                if (depth < tap_plane_depth(receiver, uv) - fine_tolerance && (!cone_search || in_cone(uv, depth, uvd, 0.5 / base_size))) {
                    let area = texel_area_in(region, vec2<i32>(x, y));
                    sum += area * depth;
                    count += area;
                }
            }
        }
    } else if (coarse_count > 0.0 && !whole) {
        for (var j = 0u; j < n; j++) {
            for (var i = 0u; i < n; i++) {
                let uv = uvd.xy + vec2<f32>(grid_offset(i, n), grid_offset(j, n)) * search;
                let depth = shadow_map_depth(low_res_map, uv);
                // shadow_map_depth reads a texel only inside the map.
                let inside = all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0));
                reads += select(0u, 1u, inside);
                read_bytes += select(0u, LOW_RES_TEXEL_BYTES, inside);
                if (depth < tap_plane_depth(receiver, uv) - fine_tolerance && (!cone_search || in_cone(uv, depth, uvd, 0.5 / base_size))) {
                    sum += depth;
                    count += 1.0;
                    nearest_found = min(nearest_found, depth);
                }
            }
        }
    }
    // The detection saw blocks, but no texel read since lies in front of the receiver and in its
    // light's cone: the region's samples fell between thin occluders or on walls beside the light,
    // or the region is too small for a texel's area to count (a point light).
    if (cone_search && count == 0.0 && coarse_count > 0.0 && !whole) {
        // 1. The same samples over regions a quarter as wide each time, centred on the point: the
        //    occluders straight above it, whose cones the region's n×n grid (the region reaching to
        //    the walls beside the light) samples too sparsely.
        var shrink = 0.25;
        for (var attempt = 0u; attempt < RETRY_REGIONS && count == 0.0; attempt++) {
            let found = cone_samples(uvd, search * shrink, n, receiver, fine_tolerance, 0.5 / base_size);
            reads += found.reads;
            read_bytes += found.reads * LOW_RES_TEXEL_BYTES;
            sum = found.sum;
            count = found.count;
            nearest_found = found.nearest;
            sampled_extent = search * shrink;
            shrink *= 0.25;
        }
    }
    var coarse_stands_in = count == 0.0;
    if (cone_search && count == 0.0 && coarse_count > 0.0 && level > 0u) {
        // 2. The descent: the detected blocks followed down the min-depth chain, keeping the
        //    children that meet the cone and pass the detection's test at their level, to the
        //    full-resolution texels that are blockers by the samples' test. Their
        //    depths are the average; where it keeps none and left no block out, the detection's
        //    blocks held no blocker and the pixel is lit.
        var descent_level = level;
        var left_out = blocks_left_out;
        while (descent_level > 0u && block_count > 0u) {
            descent_level -= 1u;
            let size = low_res_level_size(descent_level);
            let level_tolerance = bias + min(plane_change(point, uvd.xy, d, 0.5 / size), f32(1u << descent_level) * texel);
            var children: array<vec3<f32>, DESCENT_BLOCKS>;
            var child_count = 0u;
            for (var b = 0u; b < block_count; b++) {
                for (var c = 0u; c < 4u; c++) {
                    let child = vec2<i32>(blocks[b].xy) * 2 + vec2<i32>(i32(c & 1u), i32(c >> 1u));
                    if (any(child >= vec2<i32>(size))) {
                        continue;
                    }
                    let depth = textureLoad(low_res_map, child, i32(descent_level)).x;
                    reads += 1u;
                    read_bytes += LOW_RES_TEXEL_BYTES;
                    let uv = (vec2<f32>(child) + 0.5) / size;
                    let plane = tap_plane_depth(receiver, uv);
                    let in_front = depth < plane - select(level_tolerance, fine_tolerance, descent_level == 0u);
                    if (in_front && in_cone(uv, depth, uvd, 0.5 / size)) {
                        left_out = keep_nearest(&children, &child_count, vec3<f32>(vec2<f32>(child), depth)) || left_out;
                    }
                }
            }
            blocks = children;
            block_count = child_count;
        }
        for (var b = 0u; b < block_count; b++) {
            sum += blocks[b].z;
            count += 1.0;
            nearest_found = min(nearest_found, blocks[b].z);
        }
        coarse_stands_in = count == 0.0 && left_out;
    }
    if (coarse_stands_in) {
        // 3. No blocker found but the detection saw blocks (the paper's search), or the descent
        //    left out blocks that may have held them: the detection's nearest depths stand in.
        sum = coarse_sum;
        count = coarse_count;
    }
    if (cone_search && count > 0.0 && !whole && !coarse_stands_in) {
        // 4. Every texel that can occlude the point lies in the light's cone at its depth, no
        //    nearer than the nearest blocker found, so inside the region through that depth: where
        //    it is less than half as wide as the region sampled (the region through a wall beside the
        //    light is many times wider than the occluders' cones), the same samples over it, up to
        //    twice, estimate the same average more densely.
        for (var refinement = 0u; refinement < 2u; refinement++) {
            let implied = light_half_extent_uv(frame, 0.98 * nearest_found, d);
            if (any(implied >= 0.5 * sampled_extent)) {
                break;
            }
            let found = cone_samples(uvd, implied, n, receiver, fine_tolerance, 0.5 / base_size);
            reads += found.reads;
            read_bytes += found.reads * LOW_RES_TEXEL_BYTES;
            if (found.count == 0.0) {
                break;
            }
            sum = found.sum;
            count = found.count;
            nearest_found = found.nearest;
            sampled_extent = implied;
        }
    }

    if (count == 0.0 && settings.prediction != 3u) {
        // The conservative map guarantees no occluder was missed: fully lit (Sec. 5.2).
        kernel.flags = KERNEL_LIT;
        kernels[index] = kernel;
        atomicAdd(&counters[COUNTER_LIT], 1u);
        record_kernel_work(id.xy, reads, read_bytes, 1u);
        return;
    }
    // With prediction = fixed the pixel is still filtered (the single map decides), with no penumbra
    // where no blocker was seen.
    let average = select(d, sum / max(count, 1e-30), count > 0.0);
    // s_α: the light seen from the receiver through the plane at the average occluder depth.
    let soft_filter = light_half_extent_uv(frame, average, d);

    // φ: the pixel's half axes warped onto the map through its tangent plane (Fig. 5).
    let pixel = vec2<f32>(id.xy) + 0.5;
    let right = plane_uv(point, pixel + vec2<f32>(0.5, 0.0));
    let left = plane_uv(point, pixel - vec2<f32>(0.5, 0.0));
    let down = plane_uv(point, pixel + vec2<f32>(0.0, 0.5));
    let up = plane_uv(point, pixel - vec2<f32>(0.0, 0.5));
    var u_phi = vec2<f32>(0.0);
    var v_phi = vec2<f32>(0.0);
    if (right.z * left.z * down.z * up.z > 0.0) {
        u_phi = 0.5 * (right.xy - left.xy);
        v_phi = 0.5 * (down.xy - up.xy);
    }
    // h for the prediction always includes φ: a hard shadow needs at least one texel per pixel.
    let h = convolve(vec2<f32>(soft_filter.x, 0.0), vec2<f32>(0.0, soft_filter.y), u_phi, v_phi);
    if (settings.antialiasing != 0u) {
        kernel.u_axis = h.xy;
        kernel.v_height = h.z;
    } else {
        kernel.u_axis = vec2<f32>(soft_filter.x, 0.0);
        kernel.v_height = soft_filter.y;
    }

    // Eqs. 4 and 5 (pvsm_common.wgsl's predicted_texels): the texel size each axis needs.
    var texel_size = vec2<f32>(1.0 / settings.fixed_size);
    var atomics = 1u;
    if (settings.prediction != 3u) {
        // Without antialiasing, one pixel's size at the point, in shadow-map coordinates at its depth.
        let pixel_texel = pixel_world_size(point.position, pixel) / (2.0 * d * frame.projection.xy * settings.hard_texels);
        let pixel_uv = select(vec2<f32>(0.0), pixel_texel, settings.antialiasing == 0u);
        let predicted = predicted_texels(settings.prediction, h, soft_filter, u_phi, v_phi, pixel_uv);
        // No tile is coarser than MIN_TILE_SIZE texels over the whole map: a larger texel (a light
        // hidden by an occluder at its plane) would push the normal offset past the light.
        texel_size = clamp(predicted.zw, vec2<f32>(1e-7), vec2<f32>(1.0 / MIN_TILE_SIZE));
        let resolution = 1.0 / texel_size;
        // Every grid cell the filter (and the pixel's footprint) can read asks for this resolution.
        let reach = vec2<f32>(abs(h.x) + abs(u_phi.x) + abs(v_phi.x), abs(h.y) + h.z + abs(u_phi.y) + abs(v_phi.y));
        let cells = f32(settings.grid_size);
        let low = vec2<i32>(clamp(floor((uvd.xy - reach) * cells), vec2<f32>(0.0), vec2<f32>(cells - 1.0)));
        let high = vec2<i32>(clamp(floor((uvd.xy + reach) * cells), vec2<f32>(0.0), vec2<f32>(cells - 1.0)));
        for (var y = low.y; y <= high.y; y++) {
            for (var x = low.x; x <= high.x; x++) {
                let cell = u32(y) * settings.grid_size + u32(x);
                atomicMax(&grid[2u * cell], bitcast<u32>(resolution.x));
                atomicMax(&grid[2u * cell + 1u], bitcast<u32>(resolution.y));
                atomics += 2u;
            }
        }
    }
    // The normal offset is applied per tile, in that tile's texels (pvsm_filter.wgsl); here, its
    // bound: never more than half-way to the occluders found (or to the near plane), since a texel
    // can be larger than the gap (an occluder nearly touching the light widens the frame).
    let clearance = select(d - frame.projection.z, d - average, count > 0.0);
    kernel.offset = 0.5 * max(clearance, 0.0);
    kernel.centre = uvd.xy;
    kernel.depth = d;
    kernel.texel = texel_size;
    kernel.blocker_depth = average;
    kernel.flags = KERNEL_ACTIVE;
    kernels[index] = kernel;
    atomicAdd(&counters[COUNTER_FILTERED], 1u);
    record_kernel_work(id.xy, reads, read_bytes, atomics);
    record_predicted_texels(id.xy, kernel.u_axis, kernel.v_height, texel_size);
}
