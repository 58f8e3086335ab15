// Counted work (issue #40; ssm-core's ReadCounts), for `--count-work`: the counters of the
// technique's one ReadCounts buffer (ssm-techniques/wedges's COUNTERS, in this order), bound as
// `read_counts` by every shader that counts. Conventions: a textureLoad is one texel read, and so
// is one element of a per-pixel storage array read (the final buffer, the fragment counts); the
// mesh's storage arrays (positions, faces, edge records) are geometry, not texels, and are not
// counted; every atomic built-in (load, store, add, min) is one atomic; a plain store to storage
// writes its type's bytes. The counting code is compiled out unless COUNT_READS.

// #import common/read_counts.wgsl

const COUNTER_DEPTH_COPY_READS: u32 = 0u;
const COUNTER_RESOLVE_READS: u32 = 1u;
const COUNTER_WEDGE_READS: u32 = 2u;
const COUNTER_BLEND_READS: u32 = 3u;
const COUNTER_BLEND_STORAGE_BYTES: u32 = 4u;
const COUNTER_SILHOUETTE_ATOMICS: u32 = 5u;
const COUNTER_SILHOUETTE_STORAGE_BYTES: u32 = 6u;

// Adds one invocation, and `amount` of the counter's unit, to counter `counter`, in the bucket of `texel`.
fn record_count(counter: u32, texel: vec2<i32>, amount: u32) {
    if (COUNT_READS) {
        let word = read_count_word(counter, texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], amount);
    }
}
