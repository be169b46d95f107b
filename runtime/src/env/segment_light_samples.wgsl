// The compact sources' visibility at samples along every strand segment, as the layered view's
// gather reads it (segment_light_visibility.rs writes it): each sample's transmittance toward
// each light slot of a batch, at j / per_segment along the segment, j = 0 ..= per_segment, two
// slots a word as f16 (pack2x16float: 10⁻³ relative, which the layers' fixed point is too).
#define_import_path strandlight::segment_light_samples

struct SampleCounts {
    // Samples in all: segments × (per_segment + 1).
    samples: u32,
    // batch.light_count.
    slots: u32,
    // Intervals a segment is cut into.
    per_segment: u32,
    _pad: u32,
};

fn words_per_sample(counts: SampleCounts) -> u32 {
    return (counts.slots + 1u) / 2u;
}

// The word holding slots 2·`word` and 2·`word` + 1 at sample `j` of `segment`.
fn sample_word(counts: SampleCounts, segment: u32, j: u32, word: u32) -> u32 {
    return (segment * (counts.per_segment + 1u) + j) * words_per_sample(counts) + word;
}

