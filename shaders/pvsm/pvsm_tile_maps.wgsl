// PVSM step 7's culling to the tile (Sec. 5.2): before a tile's map is drawn, one invocation per
// triangle keeps those that can touch the tile's part of the light frame and appends their indices
// to a compact index buffer, whose count becomes the tile draw's indirect arguments. A triangle is
// dropped only when all three corners lie in front of the light and beyond the same side plane of
// the tile's frustum; anything crossing the light's plane is kept for the clipper.

// #import common/light_frame.wgsl

// The settings, declared once in Rust (`CullSettingsUniform`, ssm-techniques/pvsm/src/tile_maps.rs),
// whose derive writes this struct.
// #import rust/CullSettings

// The tile's own frame: its view_proj maps the tile's rectangle onto clip space's [-1, 1]².
@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var<uniform> cull: CullSettings;
// ssm-core's SceneVertex as 32-bit words: position (3), normal (3), role (1).
@group(1) @binding(1) var<storage, read> vertices: array<u32>;
@group(1) @binding(2) var<storage, read> indices: array<u32>;
@group(1) @binding(3) var<storage, read_write> culled: array<u32>;
// draw_indexed_indirect's arguments: index count, instance count, first index, base vertex, first
// instance (cleared to zero before the pass).
@group(1) @binding(4) var<storage, read_write> draw: array<atomic<u32>, 5>;

const VERTEX_WORDS: u32 = 7u;

fn clip_position(index: u32) -> vec4<f32> {
    let base = index * VERTEX_WORDS;
    let position = vec3<f32>(bitcast<f32>(vertices[base]), bitcast<f32>(vertices[base + 1u]), bitcast<f32>(vertices[base + 2u]));
    return frame.view_proj * vec4<f32>(position, 1.0);
}

@compute @workgroup_size(256)
fn pvsm_tile_cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let triangle = id.y * 65535u * 256u + id.x;
    if (triangle == 0u) {
        atomicStore(&draw[1], 1u);
    }
    if (triangle >= cull.triangle_count) {
        return;
    }
    let first = cull.first_index + 3u * triangle;
    let corners = vec3<u32>(indices[first], indices[first + 1u], indices[first + 2u]);
    let a = clip_position(corners.x);
    let b = clip_position(corners.y);
    let c = clip_position(corners.z);
    let in_front = a.w > 0.0 && b.w > 0.0 && c.w > 0.0;
    let outside = (a.x > a.w && b.x > b.w && c.x > c.w) || (a.x < -a.w && b.x < -b.w && c.x < -c.w)
        || (a.y > a.w && b.y > b.w && c.y > c.w) || (a.y < -a.w && b.y < -b.w && c.y < -c.w);
    if (in_front && outside) {
        return;
    }
    let slot = atomicAdd(&draw[0], 3u);
    culled[slot] = corners.x;
    culled[slot + 1u] = corners.y;
    culled[slot + 2u] = corners.z;
}
