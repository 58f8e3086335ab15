// VSSM (Yang, Dong, Feng, Seidel and Kautz 2010, Variance Soft Shadow Mapping): the summed-area
// table of the shadow map's first two moments, z and z² (Donnelly and Lauritzen 2006), of the
// depth normalised by the light frame's far plane, and of the count of texels with a surface.
// Each texel's three numbers are fixed-point fields of one 128-bit integer (vssm_common.wgsl),
// summed with carry, so that a region's sums, the difference of four table entries, are exact
// whatever the region's size or place: a floating-point table loses the variance of small regions
// far from its origin to cancellation. Two passes, one thread per row (prefix sums along x) then
// one per column (along y).

// #import common/light_frame.wgsl
// #import vssm/vssm_common.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
// Rows pass.
@group(1) @binding(0) var depth_map: texture_2d<f32>;
@group(1) @binding(1) var row_sums_out: texture_storage_2d<rgba32uint, write>;
// Columns pass (its own layout of group 1).
@group(1) @binding(2) var row_sums: texture_2d<u32>;
@group(1) @binding(3) var table_out: texture_storage_2d<rgba32uint, write>;

@compute @workgroup_size(64)
fn vssm_sat_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(depth_map);
    if (id.x >= size.y) {
        return;
    }
    var sums = vec4<u32>(0u);
    for (var x = 0u; x < size.x; x++) {
        let texel = vec2<u32>(x, id.x);
        sums = add_sums(sums, texel_value(textureLoad(depth_map, texel, 0).x, frame.projection.w));
        textureStore(row_sums_out, texel, sums);
    }
}

@compute @workgroup_size(64)
fn vssm_sat_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(row_sums);
    if (id.x >= size.x) {
        return;
    }
    var sums = vec4<u32>(0u);
    for (var y = 0u; y < size.y; y++) {
        let texel = vec2<u32>(id.x, y);
        sums = add_sums(sums, textureLoad(row_sums, texel, 0));
        textureStore(table_out, texel, sums);
    }
}
