// One axis of a strandlight `Table` as the GPU reads it, and the cell a coordinate falls in:
// the WGSL twin of `Axis::cell`, shared by every shader that interpolates a table (the env view's
// 4D convolution tables, the point-light lookup textures).
#define_import_path strandlight::table_axis

struct TableAxis {
    min: f32,
    inv_range: f32,
    last_index: f32,
    inv_exponent: f32,
    // 0: x itself; 1: asin(x); 2: −acos(x).
    warp: u32,
    _pad_a: u32,
    _pad_b: u32,
    _pad_c: u32,
};

// The lower node of the cell holding x and the upper node's weight.
struct TableCell {
    lower: u32,
    upper_weight: f32,
};

fn table_cell(a: TableAxis, x: f32) -> TableCell {
    if (a.last_index < 1.0) { return TableCell(0u, 0.0); }
    var w = x;
    if (a.warp == 1u) { w = asin(clamp(x, -1.0, 1.0)); }
    if (a.warp == 2u) { w = -acos(clamp(x, -1.0, 1.0)); }
    var t = clamp((w - a.min) * a.inv_range, 0.0, 1.0);
    if (a.inv_exponent != 1.0) { t = pow(t, a.inv_exponent); }
    let f = t * a.last_index;
    let lower = min(floor(f), a.last_index - 1.0);
    return TableCell(u32(lower), f - lower);
}
