// PVSM step 2 (Sec. 5.2): the low-resolution shadow map rendered conservatively, so that an
// occluder thinner than a texel still marks every texel it touches (the blocker search and the
// fully-lit test rely on it). Without hardware conservative rasterization this is Hasselgren et
// al. 2005's second algorithm (GPU Gems 2, ch. 42): each triangle, pulled from the scene's buffers
// by vertex index, is enlarged by half a texel's diagonal (its edges' planes pushed out, the new
// corners their intersections), and the fragment stage discards what lies outside the original
// triangle's bounding box grown by half a texel. Each texel keeps the nearest linear depth,
// clamped to the triangle's own depth range (an enlarged triangle extrapolates its depth).

// #import common/light_frame.wgsl

// The settings, declared once in Rust (`RasterSettingsUniform`, ssm-techniques/pvsm/src/low_res_map.rs),
// whose derive writes this struct.
// #import rust/RasterSettings

@group(0) @binding(0) var<uniform> frame: LightFrame;
// ssm-core's SceneVertex as 32-bit words: position (3), normal (3), role (1).
@group(1) @binding(0) var<storage, read> vertices: array<u32>;
@group(1) @binding(1) var<storage, read> indices: array<u32>;
@group(1) @binding(2) var<uniform> raster: RasterSettings;

const VERTEX_WORDS: u32 = 7u;

struct ConservativeVertex {
    @builtin(position) clip: vec4<f32>,
    // The original triangle's bounding box in NDC, grown by half a texel: xy min, zw max.
    @location(0) @interpolate(flat) bounds: vec4<f32>,
    // Its nearest and farthest linear depth.
    @location(1) @interpolate(flat) depth_range: vec2<f32>,
};

fn corner_position(triangle: u32, corner: u32) -> vec3<f32> {
    let base = indices[triangle * 3u + corner] * VERTEX_WORDS;
    return vec3<f32>(bitcast<f32>(vertices[base]), bitcast<f32>(vertices[base + 1u]), bitcast<f32>(vertices[base + 2u]));
}

@vertex
fn pvsm_conservative_vertex(@builtin(vertex_index) index: u32) -> ConservativeVertex {
    let triangle = index / 3u;
    let corner = index % 3u;
    var world: array<vec3<f32>, 3>;
    var clip: array<vec4<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        world[k] = corner_position(triangle, k);
        clip[k] = frame.view_proj * vec4<f32>(world[k], 1.0);
    }
    let depths = vec3<f32>(light_depth(frame, world[0]), light_depth(frame, world[1]), light_depth(frame, world[2]));
    var out: ConservativeVertex;
    out.clip = clip[corner];
    out.depth_range = vec2<f32>(min(depths.x, min(depths.y, depths.z)), max(depths.x, max(depths.y, depths.z)));
    out.bounds = vec4<f32>(-1e30, -1e30, 1e30, 1e30);
    let in_front = clip[0].w > 0.0 && clip[1].w > 0.0 && clip[2].w > 0.0;
    if (raster.enlarge == 0u || !in_front) {
        // Hardware conservative rasterization, or a triangle crossing the light's plane (left to clipping).
        return out;
    }
    var ndc: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        ndc[k] = clip[k].xyz / clip[k].w;
    }
    out.bounds = vec4<f32>(
        min(ndc[0].xy, min(ndc[1].xy, ndc[2].xy)) - raster.half_texel,
        max(ndc[0].xy, max(ndc[1].xy, ndc[2].xy)) + raster.half_texel,
    );
    // Orientation in homogeneous 2D: the edge planes must face outwards.
    var h = array<vec3<f32>, 3>(clip[0].xyw, clip[1].xyw, clip[2].xyw);
    if (determinant(mat3x3<f32>(h[0], h[1], h[2])) < 0.0) {
        let swap = h[1];
        h[1] = h[2];
        h[2] = swap;
    }
    // Each edge's plane through the eye, pushed out by the half texel's diagonal (Hasselgren Alg. 2).
    var planes: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        var plane = cross(h[k], h[(k + 2u) % 3u]);
        plane.z -= dot(raster.half_texel, abs(plane.xy));
        planes[k] = plane;
    }
    // The enlarged corner k is where the planes of its two edges meet.
    let moved = cross(planes[corner], planes[(corner + 1u) % 3u]);
    if (abs(moved.z) < 1e-20) {
        return out;
    }
    // Its depth on the original triangle's plane in NDC (z is affine in NDC x, y), kept in range.
    let d1 = ndc[1] - ndc[0];
    let d2 = ndc[2] - ndc[0];
    let normal = cross(d1, d2);
    let xy = moved.xy / moved.z;
    var z = ndc[0].z;
    if (abs(normal.z) > 1e-20) {
        z = ndc[0].z - (normal.x * (xy.x - ndc[0].x) + normal.y * (xy.y - ndc[0].y)) / normal.z;
    }
    z = clamp(z, min(ndc[0].z, min(ndc[1].z, ndc[2].z)), max(ndc[0].z, max(ndc[1].z, ndc[2].z)));
    let w = moved.z;
    out.clip = vec4<f32>(moved.x, moved.y, z * w, w) * sign(w);
    return out;
}

@fragment
fn pvsm_conservative_fragment(in: ConservativeVertex) -> @location(0) f32 {
    let ndc = vec2<f32>(in.clip.x / raster.size.x * 2.0 - 1.0, 1.0 - in.clip.y / raster.size.y * 2.0);
    if (any(ndc < in.bounds.xy) || any(ndc > in.bounds.zw)) {
        discard;
    }
    // Reversed depth: z = near/d after the divide... d = near·far / (z (far - near) + near).
    let near = frame.projection.z;
    let far = frame.projection.w;
    let depth = near * far / max(in.clip.z * (far - near) + near, 1e-30);
    return clamp(depth, in.depth_range.x, in.depth_range.y);
}
