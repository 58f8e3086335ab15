// VSSM (Yang, Dong, Feng, Seidel and Kautz 2010, Variance Soft Shadow Mapping): the summed-area
// table of the shadow map's first two moments, z and z² (Donnelly and Lauritzen 2006), of the
// depth normalised by the light frame's far plane, and of the count of texels with a surface.
// Each texel's three numbers are fixed-point fields of one 128-bit integer (vssm_common.wgsl),
// summed with carry, so that a region's sums, the difference of four table entries, are exact
// whatever the region's size or place: a floating-point table loses the variance of small regions
// far from its origin to cancellation. Two passes, one thread per row (prefix sums along x) then
// one per column (along y).

// #import common/light_frame.wgsl
// #import common/read_counts.wgsl
// #import vssm/vssm_common.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
// Rows pass.
@group(1) @binding(0) var depth_map: texture_2d<f32>;
@group(1) @binding(1) var row_sums_out: texture_storage_2d<rgba32uint, write>;
// Columns pass (its own layout of group 1).
@group(1) @binding(2) var row_sums: texture_2d<u32>;
@group(1) @binding(3) var table_out: texture_storage_2d<rgba32uint, write>;
// Both passes: (threads, count) per bucket (common/read_counts.wgsl), written only with
// COUNT_READS (a counting frame, TechniqueSetup::count_work). Counters: 0 the rows pass's texel
// reads, 1 the bytes they fetched, 2 its storage bytes, 3 to 5 the columns pass's. Each thread
// loads one texel (a textureLoad: an r32float depth of 4 bytes in the rows pass, an rgba32uint
// row sum of 16 in the columns pass) and stores one rgba32uint texel (16 bytes) per texel of its
// row or column.
@group(1) @binding(4) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel of the depth map (R32Float: ssm-core's LightDepthMap::FORMAT).
const DEPTH_TEXEL_BYTES: u32 = 4u;

// Adds one counter's `amount` for the thread of row or column `line` (its bucket).
fn record_sat_count(counter: u32, line: u32, amount: u32) {
    if (COUNT_READS) {
        let word = read_count_word(counter, vec2<i32>(0, i32(line)));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], amount);
    }
}

// Adds one thread's `texels` loaded, of `texel_bytes` each, and stored to the counters from
// `counter` (reads) on.
fn record_sat_work(counter: u32, line: u32, texels: u32, texel_bytes: u32) {
    record_sat_count(counter, line, texels);
    record_sat_count(counter + 1u, line, texel_bytes * texels);
    record_sat_count(counter + 2u, line, TABLE_TEXEL_BYTES * texels);
}

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
    record_sat_work(0u, id.x, size.x, DEPTH_TEXEL_BYTES);
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
    record_sat_work(3u, id.x, size.y, TABLE_TEXEL_BYTES);
}
