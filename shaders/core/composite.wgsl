// Composite shading: ambient plus, per light, visibility × Lambert.
// One additive pass per light over a base pass that writes the ambient term.

// #import common/screen_pass.wgsl

@group(2) @binding(0) var visibility: texture_2d<f32>;

const ALBEDO: f32 = 0.8;
const AMBIENT: f32 = 0.12;
const BACKGROUND: vec3<f32> = vec3<f32>(0.02, 0.025, 0.035);

@fragment
fn composite_base(in: FullscreenVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(select(BACKGROUND, vec3<f32>(ALBEDO * AMBIENT), screen_point(in).covered), 1.0);
}

@fragment
fn composite_light(in: FullscreenVertex) -> @location(0) vec4<f32> {
    let point = screen_point(in);
    if (!point.covered) {
        return vec4<f32>(0.0);
    }
    let to_light = frame.centre.xyz - point.position;
    let distance = max(length(to_light), 1e-6);
    let direction = to_light / distance;
    // Lambert at the receiver times the light's own cosine (a one-sided emitter).
    let lambert = max(dot(point.normal, direction), 0.0) * max(dot(-direction, frame.normal.xyz), 0.0);
    let lit = clamp(textureLoad(visibility, point.texel, 0).x, 0.0, 1.0);
    let radiance = ALBEDO * (1.0 - AMBIENT) * frame.centre.w * lambert * lit;
    return vec4<f32>(radiance * frame.colour.xyz, 1.0);
}
