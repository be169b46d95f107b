// K-buffer build (Hunz §5.2, Vasilakis & Fudos' k+-buffer; the strands shaded by
// strand_shading.wgsl and the fiber model, which holds group 2, so the buffer is group 3). WebGPU has no
// fragment interlock, so the k nearest fragments are found without one, in two passes:
// 1. `fs_kbuffer_depths` inserts each fragment's depth into its pixel's k slots, kept sorted, by
//    a cascade of atomicMin: the slot keeps the smaller value and the larger one moves on to the
//    next slot. Concurrent insertions commute, so the slots end as the k smallest depths.
// 2. `fs_kbuffer_colors` shades each fragment whose depth is among them into its slot, claiming
//    the slot by setting its depth's sign bit (so two fragments of equal depth take two slots, or
//    the second is dropped when only one of them made the k); the others (beyond the k nearest)
//    are dropped and counted, as the k+-buffer drops them.

#import strandlight::strand_quads::{VertexOut, strand_draw_vertex}
#import strandlight::strand_shading::{behind_head, shade}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

struct KBufferParams {
    width: u32,
    k: u32,
    _pad0: u32,
    _pad1: u32,
};

const EMPTY_SLOT: u32 = 0xffffffffu;
// Depths are ≥ 0, so their sign bit is free to mark a slot whose colour is written.
const CLAIMED: u32 = 0x80000000u;

@group(3) @binding(0) var<storage, read_write> slot_depths: array<atomic<u32>>;
// Pre-multiplied RGBA as two pack2x16float words.
@group(3) @binding(1) var<storage, read_write> slot_colors: array<vec2<u32>>;
// [0]: fragments beyond the k nearest of their pixel.
@group(3) @binding(2) var<storage, read_write> kbuffer_counters: array<atomic<u32>, 2>;
@group(3) @binding(3) var<uniform> kbuffer: KBufferParams;

// Positive floats order as their bit patterns.
fn depth_key(in: VertexOut) -> u32 {
    return bitcast<u32>(in.clip.z);
}

fn first_slot(in: VertexOut) -> u32 {
    return (u32(in.clip.y) * kbuffer.width + u32(in.clip.x)) * kbuffer.k;
}

@fragment
fn fs_kbuffer_depths(in: VertexOut) {
    if (in.alpha <= 0.0 || behind_head(in)) { return; }
    let base = first_slot(in);
    var key = depth_key(in);
    for (var i = 0u; i < kbuffer.k; i++) {
        let previous = atomicMin(&slot_depths[base + i], key);
        if (previous == EMPTY_SLOT) { return; }
        key = max(previous, key);
    }
}

@fragment
fn fs_kbuffer_colors(in: VertexOut) {
    if (in.alpha <= 0.0 || behind_head(in)) { return; }
    let base = first_slot(in);
    let key = depth_key(in);
    for (var i = 0u; i < kbuffer.k; i++) {
        // The weak exchange may fail spuriously: retry while the slot still holds our depth.
        loop {
            let r = atomicCompareExchangeWeak(&slot_depths[base + i], key, key | CLAIMED);
            if (r.exchanged) {
                let color = shade(in);
                slot_colors[base + i] = vec2<u32>(pack2x16float(color.rg), pack2x16float(color.ba));
                return;
            }
            if (r.old_value != key) { break; }
        }
    }
    atomicAdd(&kbuffer_counters[0], 1u);
}
