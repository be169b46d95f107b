// A strandlight `Table` of four axes and RGB values as the env view reads it (group 2,
// table_binding.rs): row-major, channels innermost, uploaded as-is and interpolated
// quadrilinearly exactly like `Table::lookup`. The single-scattering table is the SRBF
// convolution table I (fourth axis 1/λ) or, for directional lights, the direct table S·cos θ_i
// (its fourth axis has one node); the multiple-scattering table is I_G (fourth axis σ̄_f).
#define_import_path strandlight::table_lookup

#import strandlight::table_axis::{TableAxis, table_cell}

struct TableLayout {
    axes: array<TableAxis, 4>,
    // Element strides of the four axes.
    strides: vec4<u32>,
};

@group(2) @binding(0) var<uniform> single_layout: TableLayout;
@group(2) @binding(1) var<storage, read> single_table: array<f32>;
@group(2) @binding(2) var<uniform> multiple_layout: TableLayout;
@group(2) @binding(3) var<storage, read> multiple_table: array<f32>;

// The 16 corners of a 4D cell: base offset, per-axis steps (0 on one-node axes), weights.
struct Cell4 {
    base: u32,
    step: vec4<u32>,
    w: vec4<f32>,
};

fn cell4(t: TableLayout, coords: vec4<f32>) -> Cell4 {
    var out: Cell4;
    out.base = 0u;
    for (var k = 0u; k < 4u; k++) {
        let c = table_cell(t.axes[k], coords[k]);
        out.base += c.lower * t.strides[k];
        out.w[k] = c.upper_weight;
        out.step[k] = select(0u, t.strides[k], t.axes[k].last_index >= 1.0);
    }
    return out;
}

fn corner_weight(c: Cell4, corner: u32) -> f32 {
    var weight = 1.0;
    for (var k = 0u; k < 4u; k++) {
        if (((corner >> k) & 1u) == 1u) {
            weight *= c.w[k];
        } else {
            weight *= 1.0 - c.w[k];
        }
    }
    return weight;
}

fn corner_offset(c: Cell4, corner: u32) -> u32 {
    var offset = c.base;
    for (var k = 0u; k < 4u; k++) {
        if (((corner >> k) & 1u) == 1u) { offset += c.step[k]; }
    }
    return offset;
}

fn single_lookup(coords: vec4<f32>) -> vec3<f32> {
    let c = cell4(single_layout, coords);
    var acc = vec3<f32>(0.0);
    for (var corner = 0u; corner < 16u; corner++) {
        let w = corner_weight(c, corner);
        // Zero weights are skipped, as on the CPU.
        if (w == 0.0) { continue; }
        let o = corner_offset(c, corner);
        acc += w * vec3<f32>(single_table[o], single_table[o + 1u], single_table[o + 2u]);
    }
    return acc;
}

fn multiple_lookup(coords: vec4<f32>) -> vec3<f32> {
    let c = cell4(multiple_layout, coords);
    var acc = vec3<f32>(0.0);
    for (var corner = 0u; corner < 16u; corner++) {
        let w = corner_weight(c, corner);
        if (w == 0.0) { continue; }
        let o = corner_offset(c, corner);
        acc += w * vec3<f32>(multiple_table[o], multiple_table[o + 1u], multiple_table[o + 2u]);
    }
    return acc;
}
