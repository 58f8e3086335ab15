// Hard shadow mapping (Williams 1978): one depth comparison per pixel against
// the shadow map seen from the light's centre. Visibility is 0 or 1.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/read_counts.wgsl

// The settings, declared once in Rust (`HardSettingsUniform`, ssm-techniques/hard/src/lib.rs),
// whose derive writes this struct.
// #import rust/HardSettings
@group(2) @binding(0) var shadow_map: texture_2d<f32>;
@group(2) @binding(1) var<uniform> settings: HardSettings;
// Counters 0 and 1: hard_lookup's (pixels, texel reads) and (pixels, bytes those reads fetched)
// per bucket (common/read_counts.wgsl), written only with COUNT_READS (a counting frame,
// TechniqueSetup::count_work).
@group(2) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

// Texel reads of this invocation, each a textureLoad (1 texel): the G-buffer's two (position and
// normal, at every pixel), and the one shadow-map texel of a pixel that needs the lookup. The
// normal offset reads none (it takes the map's size only).
var<private> reads: u32 = 0u;
// The bytes those reads fetched: a texel costs its format's size. The G-buffer's position and
// normal are Rgba32Float (ssm-core's GBuffer::POSITION_FORMAT, NORMAL_FORMAT), the shadow map's
// linear depth R32Float (LightDepthMap::FORMAT).
var<private> read_bytes: u32 = 0u;
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const SHADOW_MAP_TEXEL_BYTES: u32 = 4u;

fn hard_visibility(point: ScreenPoint) -> f32 {
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    reads += 1u;
    read_bytes += SHADOW_MAP_TEXEL_BYTES;
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(shadow_map, uvd.xy));
}

@fragment
fn hard_lookup(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    reads = 2u;
    read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    let visibility = hard_visibility(point);
    if (COUNT_READS) {
        let word = read_count_word(0u, point.texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(1u, point.texel);
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], read_bytes);
    }
    return visibility;
}
