// One pixel's work in a compute pass that counts, with COUNT_READS (a counting frame), into the
// pass's own binding `read_counts: array<atomic<u32>>` (common/read_counts.wgsl's layout; units of
// ssm-core's ReadCounts): the framework's passes after a technique (core/own_surface_share.wgsl,
// core/beyond_frame.wgsl) and pcss's side faces.

// #import common/read_counts.wgsl

// Adds one pixel and `amount` of the counter's unit to counter `counter`, in the bucket of `texel`.
fn record_pixel_count(counter: u32, texel: vec2<i32>, amount: u32) {
    if (COUNT_READS) {
        let word = read_count_word(counter, texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], amount);
    }
}

// The pixel's texel reads under counter `reads_counter` (unit `reads`) and the bytes it writes to
// storage under `bytes_counter` (unit `storage_bytes`), without the bytes the reads fetched.
fn record_pixel_work(reads_counter: u32, bytes_counter: u32, texel: vec2<i32>, reads: u32, bytes: u32) {
    record_pixel_count(reads_counter, texel, reads);
    record_pixel_count(bytes_counter, texel, bytes);
}

// The same with the bytes its reads fetched (each texel read times its format's size) under
// `read_bytes_counter` (unit `read_bytes`).
fn record_pixel_work_and_read_bytes(
    reads_counter: u32,
    bytes_counter: u32,
    read_bytes_counter: u32,
    texel: vec2<i32>,
    reads: u32,
    bytes: u32,
    read_bytes: u32,
) {
    record_pixel_work(reads_counter, bytes_counter, texel, reads, bytes);
    record_pixel_count(read_bytes_counter, texel, read_bytes);
}
