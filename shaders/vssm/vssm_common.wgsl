// What VSSM's passes share: the fixed-point moments of a texel and the 128-bit arithmetic of
// their sums. A texel of the summed-area table holds one 128-bit integer, four 32-bit words from
// the lowest: bits 0-50 hold Σz², bits 51-101 Σz and bits 102-127 the number of texels with a
// surface, each moment a fixed-point number (z · MOMENT_SCALE, below 2^27). A texel with no
// surface adds nothing to the moments: it is not at any depth, and a region's empty part is
// answered apart from its surfaces (vssm.wgsl). The fields never carry into one another: at most
// 4096² = 2^24 texels of moments below 2^27 sum to below 2^51, and 2^24 texels count below 2^26.
// So the difference of two entries, taken modulo 2^128, holds each field of a region exactly.

// Bytes of one texel of the table (Rgba32Uint: ssm-techniques/vssm's TABLE_FORMAT), for the
// counted work's bytes read.
const TABLE_TEXEL_BYTES: u32 = 16u;

// Fixed-point scale of a moment in [0, 1]: a multiple of 8 just below 2^27 (f32 holds it exactly).
const MOMENT_SCALE: f32 = 134217712.0;
// The linear depth of a texel with no surface (common/shadow_map.wgsl's NO_SURFACE).
const EMPTY_TEXEL: f32 = 3.40282347e38;

// The 128-bit table value of one texel of linear depth `depth`: z = depth / far in [0, 1] and
// z², fixed point, and a count of 1; all 0 for a texel with no surface.
fn texel_value(depth: f32, far: f32) -> vec4<u32> {
    if (depth >= EMPTY_TEXEL) {
        return vec4<u32>(0u);
    }
    let z = clamp(depth / far, 0.0, 1.0);
    let z_fixed = u32(z * MOMENT_SCALE);
    let z2_fixed = u32(z * z * MOMENT_SCALE);
    // Σz starts at bit 51: word 1's top 13 bits, then word 2; the count at bit 102, word 3's bit 6.
    return vec4<u32>(z2_fixed, z_fixed << 19u, z_fixed >> 13u, 1u << 6u);
}

// The sum of two 128-bit numbers, wrapping (the difference of table entries is exact).
fn add_sums(a: vec4<u32>, b: vec4<u32>) -> vec4<u32> {
    let sum = a + b;
    let carry0 = u32(sum.x < a.x);
    let word1 = sum.y + carry0;
    let carry1 = u32(sum.y < a.y) + u32(word1 < carry0);
    let word2 = sum.z + carry1;
    let carry2 = u32(sum.z < a.z) + u32(word2 < carry1);
    return vec4<u32>(sum.x, word1, word2, sum.w + carry2);
}

fn subtract_sums(a: vec4<u32>, b: vec4<u32>) -> vec4<u32> {
    let difference = a - b;
    let borrow0 = u32(a.x < b.x);
    let word1 = difference.y - borrow0;
    let borrow1 = u32(a.y < b.y) + u32(difference.y < borrow0);
    let word2 = difference.z - borrow1;
    let borrow2 = u32(a.z < b.z) + u32(difference.z < borrow1);
    return vec4<u32>(difference.x, word1, word2, difference.w - borrow2);
}

// A region's three sums as floats: (Σz², Σz, texels with a surface), the moments in z units (a
// texel of z = 1 counts 1).
fn sums_to_float(sums: vec4<u32>) -> vec3<f32> {
    let z2 = (f32(sums.y & 0x7ffffu) * 4294967296.0 + f32(sums.x)) / MOMENT_SCALE;
    let z = (f32(sums.w & 0x3fu) * 35184372088832.0 + f32(sums.z) * 8192.0 + f32(sums.y >> 19u)) / MOMENT_SCALE;
    return vec3<f32>(z2, z, f32(sums.w >> 6u));
}
