// One pixel's work in a compute pass that counts, with COUNT_READS (a counting frame), its texel
// reads under counter `reads_counter` and the bytes it writes to storage under `bytes_counter`
// (ssm-core's ReadCounts, units `reads` and `storage_bytes`), into the pass's own binding
// `read_counts: array<atomic<u32>>` (common/read_counts.wgsl's layout): the framework's passes
// after a technique (core/own_surface_share.wgsl, core/beyond_frame.wgsl).

// #import common/read_counts.wgsl

fn record_pixel_work(reads_counter: u32, bytes_counter: u32, texel: vec2<i32>, reads: u32, bytes: u32) {
    if (COUNT_READS) {
        let reads_word = read_count_word(reads_counter, texel);
        atomicAdd(&read_counts[reads_word], 1u);
        atomicAdd(&read_counts[reads_word + 1u], reads);
        let bytes_word = read_count_word(bytes_counter, texel);
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], bytes);
    }
}
