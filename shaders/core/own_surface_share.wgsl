// The surface's own share of the light (ssm-core's own_surface.rs), run by the framework after a
// technique that samples the light from its centre: on a closed mesh whose tangent plane cuts the
// light, the solid hides the part of the light behind that plane (the ground truth's rays that
// leave behind it are blocked), which a map seen from the centre cannot show. With s the fraction
// of the light in front of the plane (light_share_in_front), at a covered pixel of a closed mesh
// that no shared rule answers (unlit_by_rule) and with 0 < s < 1:
// - the light's centre in front of the plane: V = s * V_technique. The technique's map sees the
//   other occluders; a convex solid's own surface lies behind the tangent plane, so it is not
//   among them, and the product charges the technique only for what it models;
// - the centre behind the plane, or on it: V = s. From behind, the technique's map sees the
//   solid's own front from the centre, so its value says nothing of the front part of the light.
//   On the plane (within the positions' rounding, CENTRE_ON_PLANE), the map sees the surface
//   edge-on and techniques answer the degenerate view as they happen to (hard 1, wedges 0.5 from
//   the solid's own silhouette, which the product would charge twice). The limit: other
//   occluders of the front part are not seen there.
// Elsewhere the technique's value is kept.

// #import common/screen_pass.wgsl
// #import common/pixel_work.wgsl

@group(2) @binding(0) var visibility: texture_storage_2d<r32float, read_write>;
// Counters 0 (texel reads), 1 (storage bytes) and 2 (the bytes the reads fetched), (invocations,
// count) per bucket (common/read_counts.wgsl); written only with COUNT_READS (a counting frame).
// Each textureLoad is one texel: the G-buffer's two per invocation inside the target (Rgba32Float,
// 16 bytes each), the technique's visibility where it is scaled (r32float, 4 bytes); a store
// writes one r32float, 4 bytes.
@group(2) @binding(1) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel of the G-buffer's position and normal (GBuffer::POSITION_FORMAT and
// NORMAL_FORMAT, Rgba32Float) and of the visibility (VISIBILITY_FORMAT, R32Float); a test in
// ssm-core's own_surface.rs reads these lines.
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const VISIBILITY_TEXEL_BYTES: u32 = 4u;

// How far in front of the plane, as a fraction of the scene's diagonal, the light's centre must be
// for the technique's value to count: the G-buffer's positions' rounding at the scene's scale.
const CENTRE_ON_PLANE: f32 = 1e-6;

@compute @workgroup_size(8, 8)
fn own_surface_share(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(visibility);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let point = screen_point_at(texel);
    var reads = 2u;
    var read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    var stored = 0u;
    if (point.closed && point.covered && !unlit_by_rule(point)) {
        let share = light_share_in_front(frame, point.position, point.normal);
        if (share > 0.0 && share < 1.0) {
            var with_share = share;
            if (light_centre_height(frame, point.position, point.normal) > scene_length(frame, CENTRE_ON_PLANE)) {
                with_share = share * textureLoad(visibility, texel).x;
                reads += 1u;
                read_bytes += VISIBILITY_TEXEL_BYTES;
            }
            textureStore(visibility, texel, vec4<f32>(with_share, 0.0, 0.0, 0.0));
            stored = VISIBILITY_TEXEL_BYTES;
        }
    }
    record_pixel_work_and_read_bytes(0u, 1u, 2u, texel, reads, stored, read_bytes);
}
