// PVSM step 5 (Sec. 5.2): the pyramid of the shadow-map tile grid, built on the GPU (the paper
// moves it off the CPU) in one workgroup: level 0 is the grid, each next level the maximum of four
// cells of the one below, down to a single cell. The whole pyramid is then read back for the
// kd-tree.

// #import common/read_counts.wgsl

// The settings, declared once in Rust (`PyramidSettingsUniform`, ssm-techniques/pvsm/src/smtg.rs),
// whose derive writes this struct.
// #import rust/PyramidSettings

@group(0) @binding(0) var<uniform> pyramid_settings: PyramidSettings;
@group(0) @binding(1) var<storage, read> grid: array<u32>;
// Every level, level 0 first, as resolutions along u and v.
@group(0) @binding(2) var<storage, read_write> pyramid: array<vec2<f32>>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_SMTG_PYRAMID (cells read) and
// READ_COUNTER_SMTG_PYRAMID_READ_BYTES (the bytes they fetched).
@group(0) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;

// The ReadCounts counters of this pass (READ_COUNTERS in src/gpu.rs).
const READ_COUNTER_SMTG_PYRAMID: u32 = 5u;
const READ_COUNTER_SMTG_PYRAMID_READ_BYTES: u32 = 6u;

// Bytes of one cell read: a grid cell's two u32 (its resolutions along u and v) or a pyramid cell's
// vec2<f32> (src/gpu.rs sizes both buffers at 8 bytes a cell, checked by a test of the crate).
const SMTG_CELL_BYTES: u32 = 8u;

const THREADS: u32 = 256u;

@compute @workgroup_size(256)
fn pvsm_pyramid(@builtin(local_invocation_index) thread: u32) {
    var side = pyramid_settings.grid_size;
    // Cells read, each one storage element of a map of cells (ReadCounts' convention: one texel).
    var reads = 0u;
    for (var cell = thread; cell < side * side; cell += THREADS) {
        pyramid[cell] = vec2<f32>(bitcast<f32>(grid[2u * cell]), bitcast<f32>(grid[2u * cell + 1u]));
        reads += 1u;
    }
    var below = 0u;
    loop {
        storageBarrier();
        workgroupBarrier();
        if (side <= 1u) {
            break;
        }
        let above = below + side * side;
        let half = side / 2u;
        for (var cell = thread; cell < half * half; cell += THREADS) {
            let x = cell % half;
            let y = cell / half;
            let at = below + 2u * y * side + 2u * x;
            pyramid[above + cell] = max(max(pyramid[at], pyramid[at + 1u]), max(pyramid[at + side], pyramid[at + side + 1u]));
            reads += 4u;
        }
        below = above;
        side = half;
    }
    if (COUNT_READS) {
        let word = read_count_word(READ_COUNTER_SMTG_PYRAMID, vec2<i32>(i32(thread), 0));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(READ_COUNTER_SMTG_PYRAMID_READ_BYTES, vec2<i32>(i32(thread), 0));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], reads * SMTG_CELL_BYTES);
    }
}
