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
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_KERNEL_SHAPE (texel reads) and
// READ_COUNTER_KERNEL_SHAPE_ATOMICS (atomic operations).
@group(2) @binding(6) var<storage, read_write> read_counts: array<atomic<u32>>;

// The ReadCounts counters of this pass (PvsmReadCounter in src/lib.rs).
const READ_COUNTER_KERNEL_SHAPE: u32 = 1u;
const READ_COUNTER_KERNEL_SHAPE_ATOMICS: u32 = 2u;

// Records one pixel's texel reads (one per textureLoad, ReadCounts' convention: the G-buffer's two
// at every pixel, trivial ones included, and the low-resolution map's) and atomics, with
// COUNT_READS (the settings' count_reads).
fn record_kernel_work(pixel: vec2<u32>, reads: u32, atomics: u32) {
    if (COUNT_READS) {
        let word = read_count_word(READ_COUNTER_KERNEL_SHAPE, vec2<i32>(pixel));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
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
        record_kernel_work(id.xy, 2u, 0u);
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
    // The G-buffer's two texels and this one.
    var reads = 3u;
    let search = light_half_extent_uv(frame, clamp(0.98 * nearest, frame.projection.z, d), d);
    let n = max(settings.blocker_kernel, 1u);
    let span = max(2.0 * search * base_size, vec2<f32>(1.0));
    let level = min(u32(max(ceil(log2(max(span.x, span.y) / DETECTION_TEXELS)), 0.0)), levels - 1u);
    // The level's size from the base's: textureDimensions with a level argument reads the base
    // level's size on lavapipe (Mesa 22.3), and loads past a level's edge return 0.
    let level_size = vec2<f32>(max(textureDimensions(low_res_map, 0) >> vec2<u32>(level), vec2<u32>(1u)));
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
    var coarse_sum = 0.0;
    var coarse_count = 0.0;
    // Area-weighted sums over the full-resolution level: at level 0 the detection reads those very
    // texels with the same tolerance (the level's texel is the base's), so it gathers them too.
    var sum = 0.0;
    var count = 0.0;
    for (var y = max(low.y, 0); y <= min(high.y, limit.y); y++) {
        for (var x = max(low.x, 0); x <= min(high.x, limit.x); x++) {
            let depth = textureLoad(low_res_map, vec2<i32>(x, y), i32(level)).x;
            reads += 1u;
            let uv = (vec2<f32>(f32(x), f32(y)) + 0.5) / level_size;
            if (depth < tap_plane_depth(receiver, uv) - coarse_tolerance) {
                coarse_sum += depth;
                coarse_count += 1.0;
                if (level == 0u && whole) {
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
                let uv = (vec2<f32>(f32(x), f32(y)) + 0.5) / base_size;
                if (depth < tap_plane_depth(receiver, uv) - fine_tolerance) {
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
                reads += select(0u, 1u, all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0)));
                if (depth < tap_plane_depth(receiver, uv) - fine_tolerance) {
                    sum += depth;
                    count += 1.0;
                }
            }
        }
    }
    if (count == 0.0) {
        sum = coarse_sum;
        count = coarse_count;
    }
    if (count == 0.0 && settings.prediction != 3u) {
        // The conservative map guarantees no occluder was missed: fully lit (Sec. 5.2).
        kernel.flags = KERNEL_LIT;
        kernels[index] = kernel;
        atomicAdd(&counters[COUNTER_LIT], 1u);
        record_kernel_work(id.xy, reads, 1u);
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
    record_kernel_work(id.xy, reads, atomics);
}
