// What VSSM's passes share: the fixed-point moments and their 64-bit arithmetic. A texel of the
// summed-area table holds (Σz low word, Σz high word, Σz² low word, Σz² high word), each moment
// scaled by MOMENT_SCALE.

// Fixed-point scale of a moment in [0, 1]: the largest f32 below 2^32.
const MOMENT_SCALE: f32 = 4294967040.0;
// The linear depth of a texel with no surface (common/shadow_map.wgsl's NO_SURFACE).
const EMPTY_TEXEL: f32 = 3.40282347e38;

// The moments (z, z²) of linear depth `depth`, z = depth / far in [0, 1] (an empty texel is at the
// far plane), as fixed-point words.
fn fixed_moments(depth: f32, far: f32) -> vec2<u32> {
    let z = select(clamp(depth / far, 0.0, 1.0), 1.0, depth >= EMPTY_TEXEL);
    return vec2<u32>(u32(z * MOMENT_SCALE), u32(z * z * MOMENT_SCALE));
}

// 64-bit sums (low, high) of both moments plus one texel's words.
fn add_moments(sums: vec4<u32>, moments: vec2<u32>) -> vec4<u32> {
    return add_sums(sums, vec4<u32>(moments.x, 0u, moments.y, 0u));
}

// The sum of two pairs of 64-bit numbers, wrapping (the difference of table entries is exact).
fn add_sums(a: vec4<u32>, b: vec4<u32>) -> vec4<u32> {
    let low = a.xz + b.xz;
    let carry = vec2<u32>(low < a.xz);
    let high = a.yw + b.yw + carry;
    return vec4<u32>(low.x, high.x, low.y, high.y);
}

fn subtract_sums(a: vec4<u32>, b: vec4<u32>) -> vec4<u32> {
    let low = a.xz - b.xz;
    let borrow = vec2<u32>(a.xz < b.xz);
    let high = a.yw - b.yw - borrow;
    return vec4<u32>(low.x, high.x, low.y, high.y);
}

// Both 64-bit sums as floats, in moment units (a texel of z = 1 counts 1).
fn sums_to_float(sums: vec4<u32>) -> vec2<f32> {
    let scale = 4294967296.0 / MOMENT_SCALE;
    return vec2<f32>(f32(sums.y) * scale + f32(sums.x) / MOMENT_SCALE, f32(sums.w) * scale + f32(sums.z) / MOMENT_SCALE);
}
