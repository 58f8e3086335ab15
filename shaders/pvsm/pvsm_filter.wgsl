// PVSM step 8 (Sec. 4.1, 4.2, 5.2), once per tile, one invocation per pixel: the filter h of the
// pixel integrated over the part of the tile's shadow map it covers, each texel a quad of constant
// depth whose weight is the exact area of its intersection with h (Eq. 2; h's vertical
// half-axis is the map's, and each one-texel-wide column of the parallelogram is taken as an
// axis-aligned box, as Sec. 4.2 does). The pixel's accumulator gets the visible covered area Σ c·o
// and the covered area Σ c, so that tiles sharing a filter merge exactly (Sec. 5.2's V·A and A).

// #import pvsm/pvsm_common.wgsl

struct TileSettings {
    // The tile's rectangle of the light frame's shadow-map coordinates.
    uv_min: vec2<f32>,
    uv_max: vec2<f32>,
    // Texels of its map (the top-left part of the tile atlas).
    size: vec2<f32>,
    _pad0: f32,
    _pad1: f32,
};

@group(2) @binding(2) var<storage, read> kernels: array<Kernel>;
// Per pixel: (Σ c·o, Σ c).
@group(2) @binding(3) var<storage, read_write> accumulated: array<vec2<f32>>;
// Per pixel: 1 once its filter was decimated in some tile (cleared per light).
@group(2) @binding(4) var<storage, read_write> decimated: array<u32>;
// COUNTER_* of pvsm_common.wgsl (the resolve pass adds the decimated and uncovered pixels).
@group(2) @binding(5) var<storage, read_write> counters: array<atomic<u32>, COUNTERS>;
@group(3) @binding(0) var<uniform> tile: TileSettings;
@group(3) @binding(1) var tile_map: texture_2d<f32>;

// Most texel columns (and rows) one filter integrates: wider filters take every k-th texel, each
// standing for a k×k block (the fixed-resolution mode and huge lights).
const MAX_TEXELS_PER_AXIS: f32 = 96.0;

// Smallest half-axis of a filter, in texels of the tile (see integrate).
const MIN_HALF_TEXELS: f32 = 1e-3;

// (Σ c·o, Σ c, decimated) of the filter (u, v_height) centred on `centre` (shadow-map
// coordinates) over this tile (decimated: 1 when the filter spans more than MAX_TEXELS_PER_AXIS
// texels and is read at every k-th), for a receiver at light depth `depth` with tangent plane
// (`position`, `normal`). With settings.predicted_stride, a tile finer than the pixel's predicted
// texel size `predicted` (a neighbour in the tile needed more) is read at every k-th texel, k the
// ratio: the prediction says that many texels suffice, and a pixel's cost stays about ρ² whatever
// the tile's resolution.
fn integrate(centre: vec2<f32>, u: vec2<f32>, v_height: f32, depth: f32, position: vec3<f32>, normal: vec3<f32>, predicted: vec2<f32>) -> vec3<f32> {
    let extent = tile.uv_max - tile.uv_min;
    let scale = tile.size / extent;
    // The filter in the tile's texel units. A filter narrower than a texel weighs the texels under
    // it by area (Eq. 2), which tends to the texel under the point as it shrinks: the hard shadow
    // test. Its half-axes are floored at MIN_HALF_TEXELS only so that a filter of zero size (a
    // point light with antialiasing off) is that test, not an empty integral; a floor of half a
    // texel made it a one-texel box centred on the point, which blurs a hard edge over a texel.
    // Point samples (classic PCF) need a texel centre inside: a filter at least one texel wide.
    let floor_half = select(MIN_HALF_TEXELS, 0.5, settings.point_samples != 0u);
    let c = (centre - tile.uv_min) * scale;
    let ux = max(abs(u.x) * scale.x, floor_half);
    let uy = select(u.y, -u.y, u.x < 0.0) * scale.y;
    let vy = max(v_height * scale.y, floor_half);
    let x_low = max(c.x - ux, 0.0);
    let x_high = min(c.x + ux, tile.size.x);
    let reach_y = abs(uy) + vy;
    if (x_low >= x_high || c.y + reach_y <= 0.0 || c.y - reach_y >= tile.size.y) {
        return vec3<f32>(0.0);
    }
    let stride = max(vec2<f32>(1.0), select(vec2<f32>(1.0), floor(predicted * scale), settings.predicted_stride != 0u));
    let step = max(stride, ceil(vec2<f32>(2.0 * ux, 2.0 * reach_y) / MAX_TEXELS_PER_AXIS));
    let slope = select(0.0, uy / ux, ux > 1e-6);
    // What each texel is compared with (the settings' receiver model), prepared once.
    let receiver = receiver_tap_plane(frame, position, normal, depth, settings.receiver_plane != 0u);
    var visible = 0.0;
    var covered = 0.0;
    var column = floor(x_low / step.x) * step.x;
    loop {
        if (column >= x_high) {
            break;
        }
        let left = max(column, x_low);
        let right = min(column + step.x, x_high);
        let width = right - left;
        if (width > 0.0) {
            // This column of h, taken as an axis-aligned box at its middle's height.
            let middle = 0.5 * (left + right);
            let y_centre = c.y + (middle - c.x) * slope;
            let bottom = max(y_centre - vy, 0.0);
            let top = min(y_centre + vy, tile.size.y);
            var row = floor(bottom / step.y) * step.y;
            loop {
                if (row >= top) {
                    break;
                }
                var height = min(row + step.y, top) - max(row, bottom);
                let texel = vec2<f32>(column, row) + 0.5 * step;
                if (settings.point_samples != 0u) {
                    // Classic PCF: the whole texel when its centre is inside the filter, else nothing.
                    let inside = texel.x >= x_low && texel.x < x_high && texel.y >= y_centre - vy && texel.y < y_centre + vy;
                    height = select(0.0, step.y, inside);
                }
                if (height > 0.0) {
                    let z = textureLoad(tile_map, vec2<i32>(min(texel, tile.size - vec2<f32>(0.5))), 0).x;
                    let uv = tile.uv_min + texel / scale;
                    let compared = tap_plane_depth(receiver, uv);
                    let area = select(width, step.x, settings.point_samples != 0u) * height;
                    // o(t) = 1 when the receiver is no farther than the texel's occluder (Eq. 2); the
                    // tile map's depths carry the depth bias already.
                    visible += select(0.0, area, compared <= z);
                    covered += area;
                }
                row += step.y;
            }
        }
        column += step.x;
    }
    // In shadow-map coordinates, not texels: tiles of different resolutions merge by true area.
    let texel_area = 1.0 / (scale.x * scale.y);
    return vec3<f32>(vec2<f32>(visible, covered) * texel_area, select(0.0, 1.0, any(step > stride)));
}

@compute @workgroup_size(8, 8)
fn pvsm_tile_filter(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    let kernel = kernels[index];
    if (kernel.flags != KERNEL_ACTIVE) {
        return;
    }
    let point = screen_point_at(vec2<i32>(id.xy));
    // The normal offset, in this tile's texels at the pixel's depth (a coarser predicted texel would
    // move the point past nearby occluders), within the kernel's bound. A tile's texels can be far
    // longer along one axis than the other (Eq. 5 per axis). Compared with the receiver's tangent
    // plane, a texel's depth differs from the plane's only by the surface's curvature, and the
    // finer side is offset enough; an offset of the longer side moved the lookup across narrow
    // penumbrae along the finer axis (thin bars' shadows shifted by half their width). Compared with
    // the receiver's own depth, the longer side's slope needs the longer side's offset.
    let tile_texel = 2.0 * kernel.depth * frame.projection.xy * (tile.uv_max - tile.uv_min) / tile.size;
    let world_texel = select(max(tile_texel.x, tile_texel.y), min(tile_texel.x, tile_texel.y), settings.receiver_plane != 0u);
    let offset = min(settings.normal_offset * world_texel, kernel.offset);
    let k = max(settings.supersampling, 1u);
    if (k == 1u) {
        let lookup = offset_point(point.position, point.normal, offset);
        let uvd = light_uv_depth(frame, lookup);
        let sums = integrate(uvd.xy, kernel.u_axis, kernel.v_height, uvd.z, lookup, point.normal, kernel.texel);
        accumulated[index] += sums.xy;
        if (sums.z > 0.0) {
            decimated[index] = 1u;
        }
        return;
    }
    // Screen-space supersampling (Fig. 11's comparison): k×k points of the pixel's tangent plane,
    // each filtered on its own; their sums add up, as their filters have the same area.
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < k; j++) {
        for (var i = 0u; i < k; i++) {
            let pixel = vec2<f32>(id.xy) + (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(k);
            let hit = tangent_point(point.position, point.normal, pixel);
            if (hit.w == 0.0 || !in_front_of_light(frame, hit.xyz)) {
                continue;
            }
            let sub_lookup = offset_point(hit.xyz, point.normal, offset);
            let uvd = light_uv_depth(frame, sub_lookup);
            sum += integrate(uvd.xy, kernel.u_axis, kernel.v_height, uvd.z, sub_lookup, point.normal, kernel.texel);
        }
    }
    accumulated[index] += sum.xy;
    if (sum.z > 0.0) {
        decimated[index] = 1u;
    }
}

// The final visibility (Sec. 5.2's merge: V = Σ V·A / Σ A) into the framework's target.
@group(3) @binding(2) var visibility: texture_storage_2d<r32float, read_write>;

@compute @workgroup_size(8, 8)
fn pvsm_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    let kernel = kernels[index];
    var value = 1.0;
    if (kernel.flags == KERNEL_DARK) {
        value = 0.0;
    } else if (kernel.flags == KERNEL_ACTIVE) {
        let sums = accumulated[index];
        // No tile under the filter. Every grid cell a filter can read asks for a tile, so this is a
        // lookup point that the normal offset moved into a cell no pixel asked for, or one outside
        // the light frame. Read as lit, and counted (pvsm_uncovered_pixels).
        value = select(1.0, clamp(sums.x / sums.y, 0.0, 1.0), sums.y > 0.0);
        if (sums.y <= 0.0) {
            atomicAdd(&counters[COUNTER_UNCOVERED], 1u);
        }
        if (decimated[index] != 0u) {
            atomicAdd(&counters[COUNTER_DECIMATED], 1u);
        }
    }
    textureStore(visibility, vec2<i32>(id.xy), vec4<f32>(value));
}
