// Texture reads per pixel, counted per pass (ssm-core/src/read_counts.rs): each pass's
// (pixels, reads) pairs spread over READ_COUNT_BUCKETS buckets chosen by pixel.

const READ_COUNT_BUCKETS: u32 = 256u;

// Whether the pipeline counts reads (ReadCounts::pipeline_constants): a constant of the pipeline,
// so that without it the counting code is compiled out rather than skipped at run time.
override COUNT_READS: bool = false;

// The first of the two words of pass `pass_index`'s bucket for pixel `texel`.
fn read_count_word(pass_index: u32, texel: vec2<i32>) -> u32 {
    let bucket = u32(texel.x + texel.y * 7) % READ_COUNT_BUCKETS;
    return (pass_index * READ_COUNT_BUCKETS + bucket) * 2u;
}
