// Counted work (issue #40; ssm-core's ReadCounts), for `--count-work`: every Atty pass that reads
// texels, does atomics or writes storage binds its own slice of the technique's counters as
// `read_counts` (ssm-techniques/atty's CounterPlan), so its counters are 0, 1, ... whichever side
// or pyramid it runs for. Conventions: a textureLoad is one texel read (Atty reads no texel any
// other way), and fetches its texture's texel size in bytes (unit read_bytes, beside every pass's
// reads: each shader's `*_TEXEL_BYTES` overrides, which the pipelines set from the textures'
// formats, since the receiver map and the soft shadow maps change format with the settings); a
// textureStore to a storage texture writes its format's texel size; a micro-patch record 32 bytes.
// The counting code is compiled out unless COUNT_READS.

// #import common/read_counts.wgsl

// Adds one invocation, and `amount` of the counter's unit, to counter `counter` of this pass's
// slice, in the bucket of `texel`.
fn record_count(counter: u32, texel: vec2<i32>, amount: u32) {
    if (COUNT_READS) {
        let word = read_count_word(counter, texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], amount);
    }
}
