// PVSM step 2, continued: the minimum-depth mip chain of the conservative low-resolution map.
// Each texel of level l + 1 keeps the nearest depth of its four texels of level l, so that the
// blocker search can look at every texel of its region at a level where the region is a few
// texels wide, and still see every occluder the conservative map holds (Sec. 5.2: a pixel with
// no occluder there is fully lit, and skipped).

@group(0) @binding(0) var finer: texture_2d<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn pvsm_low_res_mip(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    let limit = vec2<i32>(textureDimensions(finer)) - 1;
    let base = vec2<i32>(id.xy) * 2;
    let a = textureLoad(finer, min(base, limit), 0).x;
    let b = textureLoad(finer, min(base + vec2<i32>(1, 0), limit), 0).x;
    let c = textureLoad(finer, min(base + vec2<i32>(0, 1), limit), 0).x;
    let d = textureLoad(finer, min(base + vec2<i32>(1, 1), limit), 0).x;
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(min(min(a, b), min(c, d))));
}
