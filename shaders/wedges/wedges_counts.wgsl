// Counted work (issue #40; ssm-core's ReadCounts), for `--count-work`: the counters of the
// technique's one ReadCounts buffer (ssm-techniques/wedges's COUNTERS, in this order), bound as
// `read_counts` by every shader that counts. Conventions: a textureLoad is one texel read, and so
// is one element of a per-pixel storage array read (the final buffer, the fragment counts); the
// mesh's storage arrays (positions, faces, edge records) are geometry, not texels, and are not
// counted; every atomic built-in (load, store, add, min) is one atomic; a plain store to storage
// writes its type's bytes. Every pass that counts reads also counts the bytes they fetched: a
// texel at its format's size (the *_BYTES constants below, which a test in
// ssm-techniques/wedges's gpu.rs checks against the formats), a storage element at its type's.
// The counting code is compiled out unless COUNT_READS.

// #import common/read_counts.wgsl

// A pass's read bytes are the counter after its reads (record_reads).
const COUNTER_DEPTH_COPY_READS: u32 = 0u;
const COUNTER_RESOLVE_READS: u32 = 2u;
const COUNTER_WEDGE_READS: u32 = 4u;
const COUNTER_BLEND_READS: u32 = 6u;
const COUNTER_BLEND_STORAGE_BYTES: u32 = 8u;
const COUNTER_SILHOUETTE_ATOMICS: u32 = 9u;
const COUNTER_SILHOUETTE_STORAGE_BYTES: u32 = 10u;

// Bytes of one texel or element read: the G-buffer's depth (Depth32Float), position and normal
// (Rgba32Float); the silhouette buffer's seven parameter targets (Rgba32Float) and its count of
// fragments shaded (R32Float); the umbra mask (R8Unorm); an element of the final buffer
// (vec4<f32>) and of the fragment counts (u32).
const GBUFFER_DEPTH_BYTES: u32 = 4u;
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const SILHOUETTE_TEXEL_BYTES: u32 = 16u;
const SHADED_COUNT_TEXEL_BYTES: u32 = 4u;
const UMBRA_MASK_TEXEL_BYTES: u32 = 1u;
const FINAL_ELEMENT_BYTES: u32 = 16u;
const FRAGMENT_COUNT_BYTES: u32 = 4u;

// Adds one invocation, and `amount` of the counter's unit, to counter `counter`, in the bucket of `texel`.
fn record_count(counter: u32, texel: vec2<i32>, amount: u32) {
    if (COUNT_READS) {
        let word = read_count_word(counter, texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], amount);
    }
}

// Adds one invocation's `reads` to counter `reads_counter` and the `bytes` they fetched to the
// next (unit read_bytes).
fn record_reads(reads_counter: u32, texel: vec2<i32>, reads: u32, bytes: u32) {
    record_count(reads_counter, texel, reads);
    record_count(reads_counter + 1u, texel, bytes);
}
