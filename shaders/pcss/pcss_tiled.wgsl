// PCSS (pcss_common.wgsl) as a compute pass whose 8×8 workgroups share the shadow-map texels they
// read: the union of the group's pixels' windows (each pixel's taps lie in uv ± search) is loaded
// once into workgroup memory when it holds at most TILE_TEXELS texels, and every tap reads it
// there; a group whose union is larger reads the shadow map, as the fragment pass does. Either
// way a tap reads the texel the fragment pass reads, so the pixels are the same.

// #import pcss/pcss_common.wgsl

@group(3) @binding(0) var visibility_target: texture_storage_2d<r32float, write>;
// [workgroups that used their tile, workgroups with a pixel to compute] (the diagnostic).
@group(3) @binding(1) var<storage, read_write> tile_counts: array<atomic<u32>, 2>;

// Texels of the shared tile: 16,320 bytes, within WebGPU's default 16 KiB of workgroup memory
// with the window's four bounds.
const TILE_TEXELS: i32 = 4080;

var<workgroup> tile: array<f32, TILE_TEXELS>;
// The union of the group's windows in texels: min x, min y, max x, max y.
var<workgroup> window_bounds: array<atomic<i32>, 4>;
// This group's tile: its first texel, its width, and whether it holds the group's union.
var<private> tile_origin: vec2<i32>;
var<private> tile_width: i32;
var<private> tiled: bool;

// A texel read where the tap reads the shadow map; none where it reads the tile.
fn tap_depth(uv: vec2<f32>) -> f32 {
    if (!tiled || any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        reads += 1u;
        read_bytes += SHADOW_MAP_TEXEL_BYTES;
        return shadow_map_depth(shadow_map, uv);
    }
    // The texel shadow_map_depth reads, inside the union by construction.
    let texel = vec2<i32>(uv * vec2<f32>(textureDimensions(shadow_map))) - tile_origin;
    return tile[texel.y * tile_width + texel.x];
}

@compute @workgroup_size(8, 8)
fn pcss_filter_tiled(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if (local == 0u) {
        atomicStore(&window_bounds[0], 2147483647);
        atomicStore(&window_bounds[1], 2147483647);
        atomicStore(&window_bounds[2], -2147483647);
        atomicStore(&window_bounds[3], -2147483647);
    }
    workgroupBarrier();
    let inside = all(id.xy < textureDimensions(gbuffer_position));
    var point: ScreenPoint;
    var pixel: PcssPixel;
    var trivial = 1.0;
    let size = vec2<i32>(textureDimensions(shadow_map));
    if (inside) {
        point = screen_point_at(vec2<i32>(id.xy));
        trivial = trivial_visibility(point);
        if (trivial < 0.0) {
            pixel = pcss_pixel(point);
            let low = clamp(vec2<i32>(floor((pixel.uvd.xy - pixel.search) * vec2<f32>(size))), vec2<i32>(0), size - 1);
            let high = clamp(vec2<i32>(floor((pixel.uvd.xy + pixel.search) * vec2<f32>(size))), vec2<i32>(0), size - 1);
            atomicMin(&window_bounds[0], low.x);
            atomicMin(&window_bounds[1], low.y);
            atomicMax(&window_bounds[2], high.x);
            atomicMax(&window_bounds[3], high.y);
        }
    }
    workgroupBarrier();
    let low = vec2<i32>(atomicLoad(&window_bounds[0]), atomicLoad(&window_bounds[1]));
    let high = vec2<i32>(atomicLoad(&window_bounds[2]), atomicLoad(&window_bounds[3]));
    let extent = high - low + 1;
    let any_pixel = all(extent > vec2<i32>(0));
    tiled = any_pixel && extent.x * extent.y <= TILE_TEXELS;
    tile_origin = low;
    tile_width = extent.x;
    if (tiled) {
        for (var index = i32(local); index < extent.x * extent.y; index += 64) {
            tile[index] = textureLoad(shadow_map, low + vec2<i32>(index % extent.x, index / extent.x), 0).x;
            reads += 1u;
            read_bytes += SHADOW_MAP_TEXEL_BYTES;
        }
    }
    workgroupBarrier();
    if (local == 0u && any_pixel) {
        atomicAdd(&tile_counts[0], u32(tiled));
        atomicAdd(&tile_counts[1], 1u);
    }
    if (!inside) {
        record_pcss_reads_of(vec2<i32>(id.xy), 0u);
        return;
    }
    // The G-buffer's two texels, read at every pixel of the screen, trivial ones included.
    reads += 2u;
    read_bytes += 2u * GBUFFER_TEXEL_BYTES;
    var visibility = trivial;
    if (trivial < 0.0) {
        visibility = soft_visibility(pixel);
    }
    record_pcss_reads(point.texel);
    textureStore(visibility_target, vec2<i32>(id.xy), vec4<f32>(visibility));
}
