// Percentage-closer soft shadows (Fernando 2005), with the regular n×n blocker
// search and m×m filter grids that Buades et al. (2015) and Shen et al. (2011)
// compare against; shared by the fragment pass (pcss.wgsl) and the compute pass
// whose workgroups share the shadow-map texels they read (pcss_tiled.wgsl).
// Each entry file defines `tap_depth(uv)`, where a tap's depth comes from.
//
// 1. Blocker search: the region of the shadow map through which the receiver
//    can see the light at the nearest possible blocker depth (the frame's near
//    plane) is sampled on an n×n grid; texels nearer the light than the
//    receiver are blockers, and their depths are averaged.
// 2. Penumbra estimate: with parallel planes, the light seen from the
//    receiver through the blocker plane at d_blocker spans
//    w_light * (d_receiver - d_blocker) / (d_receiver * d_blocker) in the
//    map's normalised units (Fernando's w_penumbra scaled to the map).
// 3. PCF over that extent on an m×m grid.
//
// With `receiver_plane` on, each tap compares against the depth of the
// receiver's tangent plane along that tap's ray rather than the receiver's
// own depth, so that a wide kernel on a surface tilted to the light does not
// find the surface itself (Isidoro 2006). Off, this is Fernando's sketch.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/read_counts.wgsl

// The settings, declared once in Rust (`PcssSettingsUniform`, ssm-techniques/pcss/src/lib.rs),
// whose derive writes this struct.
// #import rust/PcssSettings

@group(2) @binding(0) var shadow_map: texture_2d<f32>;
@group(2) @binding(1) var<uniform> settings: PcssSettings;
// Counter 0: (pixels, reads), counter 1: (pixels, bytes read) per bucket (common/read_counts.wgsl).
@group(2) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

// Texel reads of this invocation, each a textureLoad of one texel (nearest, no sampler): the
// G-buffer's two (position and normal) at every pixel, trivial ones (background, trivially lit or
// dark) included, and every shadow-map tap of a computed pixel (counted in each entry file's
// tap_depth; a tap past the map's border counts as one, as hard's lookup does, though
// shadow_map_depth fetches nothing there), or in the tiled pass the texels an invocation loaded
// into the tile instead of the taps that read the tile.
var<private> reads: u32 = 0u;
// The bytes those reads fetched, each texel its format's size: the G-buffer's position and normal
// are Rgba32Float (ssm-core's GBuffer::POSITION_FORMAT, NORMAL_FORMAT), the shadow map's linear
// depth R32Float (LightDepthMap::FORMAT; a tap past the border, counted as a read, counts a
// texel's bytes too). A tap read from the tiled pass's workgroup memory is no read and no bytes.
var<private> read_bytes: u32 = 0u;
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const SHADOW_MAP_TEXEL_BYTES: u32 = 4u;

// A pixel's lookup, prepared before its taps.
struct PcssPixel {
    // Shadow-map coordinates and light depth of the lookup point (the normal offset applied).
    uvd: vec3<f32>,
    // What each tap is compared with (the settings' receiver model; common/shadow_map.wgsl).
    receiver: TapPlane,
    // Half extent of the blocker search, shadow-map coordinates; every tap of both steps lies
    // inside uvd.xy ± search (the filter's extent is the light through the blockers' plane, which
    // is no nearer the light than the near plane the search uses).
    search: vec2<f32>,
};

fn pcss_pixel(point: ScreenPoint) -> PcssPixel {
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let receiver = receiver_tap_plane(frame, lookup, point.normal, uvd.z, settings.receiver_plane != 0u);
    return PcssPixel(uvd, receiver, light_half_extent_uv(frame, frame.projection.z, uvd.z));
}

// Steps 1 to 3 for a pixel that needs them.
fn soft_visibility(pixel: PcssPixel) -> f32 {
    let uvd = pixel.uvd;
    let receiver = pixel.receiver;
    // 1. Blocker search over the light's back-projection through the near plane.
    let n = max(settings.blocker_kernel, 1u);
    var blocker_sum = 0.0;
    var blocker_count = 0u;
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let uv = uvd.xy + vec2<f32>(grid_offset(i, n), grid_offset(j, n)) * pixel.search;
            let depth = tap_depth(uv);
            if (depth < tap_plane_depth(receiver, uv)) {
                blocker_sum += depth;
                blocker_count += 1u;
            }
        }
    }
    if (blocker_count == 0u) {
        return 1.0;
    }
    let blocker_depth = blocker_sum / f32(blocker_count);

    // 2. Penumbra extent, 3. PCF over it.
    let filter_extent = light_half_extent_uv(frame, blocker_depth, uvd.z);
    // A penumbra narrower than a texel is not in the map: the m×m taps of a filter narrower than a
    // texel read the one or two texels at the lookup, and their share only moves the map's own
    // quantised edge (under a near-point light it made PCSS worse than a hard shadow from the same
    // map). One tap at the lookup is that hard shadow, the most the map holds.
    let narrower_than_a_texel = all(filter_extent * vec2<f32>(textureDimensions(shadow_map)) < vec2<f32>(0.5));
    let m = select(max(settings.pcf_kernel, 1u), 1u, narrower_than_a_texel);
    var lit = 0.0;
    for (var j = 0u; j < m; j++) {
        for (var i = 0u; i < m; i++) {
            let uv = uvd.xy + vec2<f32>(grid_offset(i, m), grid_offset(j, m)) * filter_extent;
            lit += select(0.0, 1.0, tap_plane_depth(receiver, uv) <= tap_depth(uv));
        }
    }
    return lit / f32(m * m);
}

// Records this invocation's pixel and its reads (with COUNT_READS: the settings' count_reads, or a
// counting frame), at every pixel of the screen.
fn record_pcss_reads(texel: vec2<i32>) {
    record_pcss_reads_of(texel, 1u);
}

// Records `pixels` (0 or 1) and this invocation's reads and their bytes: 0 for an invocation of the tiled pass past
// the screen's edge, which only loaded its share of the tile, so that the invocations counted are
// the screen's pixels in both passes.
fn record_pcss_reads_of(texel: vec2<i32>, pixels: u32) {
    if (COUNT_READS && (pixels != 0u || reads != 0u)) {
        let word = read_count_word(0u, texel);
        atomicAdd(&read_counts[word], pixels);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(1u, texel);
        atomicAdd(&read_counts[bytes_word], pixels);
        atomicAdd(&read_counts[bytes_word + 1u], read_bytes);
    }
}
