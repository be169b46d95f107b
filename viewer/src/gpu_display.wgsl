// The window's picture from a frame's sums, on the GPU (gpu_display.rs): the automatic exposure
// metered on the hair (the 90th percentile of its luminance, `strandlight_scene::exposure`), the
// hair over the backdrop at that exposure, and the PNG's tonemap into 8-bit sRGB bytes.

struct Params {
    width: u32,
    height: u32,
    // The sums' second half holds multiple scattering to add.
    with_multiple: u32,
    has_backdrop: u32,
    // The running sum's colour scale (its share of the lights' power, inverted).
    scale: f32,
    // 1: `manual_stops`; 0: the metered stops.
    manual: u32,
    manual_stops: f32,
    _pad: u32,
}

// The luminance histogram: COARSE_BINS bins of BIN_STOPS each from LOWEST_STOP up, then FINE_BINS
// inside the bin that holds the 90th percentile (1/4096 of a stop).
const COARSE_BINS: u32 = 512u;
const FINE_BINS: u32 = 1024u;
const BIN_STOPS: f32 = 0.25;
const LOWEST_STOP: f32 = -64.0;
// `strandlight_scene::exposure`: AUTO_TARGET, AUTO_LIMIT_STOPS; image_metrics::HAIR_ALPHA.
const AUTO_TARGET: f32 = 2.0;
const AUTO_LIMIT_STOPS: f32 = 20.0;
const HAIR_ALPHA: f32 = 1e-3;

struct Meter {
    coarse: array<atomic<u32>, 512>,
    fine: array<atomic<u32>, 1024>,
    total: atomic<u32>,
    // The coarse bin of the 90th percentile and its rank inside that bin.
    bin: u32,
    rank: u32,
    stops: f32,
}

@group(0) @binding(0) var<storage, read> sums: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> backdrop: array<vec4<f32>>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> meter: Meter;
@group(0) @binding(4) var picture: texture_storage_2d<rgba8unorm, write>;

fn inside(id: vec3<u32>) -> bool {
    return id.x < params.width && id.y < params.height;
}

// The frame's pre-multiplied colour (scaled) and coverage at `id`.
fn frame_pixel(id: vec3<u32>) -> vec4<f32> {
    let i = id.y * params.width + id.x;
    var rgb = sums[i].rgb;
    if params.with_multiple != 0u {
        rgb += sums[params.width * params.height + i].rgb;
    }
    return vec4<f32>(rgb * params.scale, sums[i].a);
}

fn finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// log2 of the hair's luminance at `id`; a value below LOWEST_STOP where there is no lit hair.
fn hair_log_luminance(id: vec3<u32>) -> f32 {
    let p = frame_pixel(id);
    let l = dot(p.rgb, vec3<f32>(0.2126, 0.7152, 0.0722)) / p.a;
    if p.a > HAIR_ALPHA && finite(l) && l > 0.0 {
        return log2(l);
    }
    return LOWEST_STOP - 1.0;
}

fn coarse_position(log_l: f32) -> f32 {
    return (log_l - LOWEST_STOP) / BIN_STOPS;
}

@compute @workgroup_size(8, 8)
fn meter_coarse(@builtin(global_invocation_id) id: vec3<u32>) {
    if !inside(id) {
        return;
    }
    let log_l = hair_log_luminance(id);
    if log_l < LOWEST_STOP - 0.5 {
        return;
    }
    let bin = u32(clamp(coarse_position(log_l), 0.0, f32(COARSE_BINS - 1u)));
    atomicAdd(&meter.coarse[bin], 1u);
    atomicAdd(&meter.total, 1u);
}

// The rank `strandlight_scene::exposure::metered_stops` selects, the 90th percentile:
// total * 9 / 10 (written so that it cannot overflow), at most the last.
fn p90_rank(total: u32) -> u32 {
    return min((total / 10u) * 9u + ((total % 10u) * 9u) / 10u, total - 1u);
}

@compute @workgroup_size(1)
fn meter_pick_coarse() {
    let total = atomicLoad(&meter.total);
    meter.bin = COARSE_BINS;
    if total == 0u {
        return;
    }
    let k = p90_rank(total);
    var below = 0u;
    for (var b = 0u; b < COARSE_BINS; b++) {
        let n = atomicLoad(&meter.coarse[b]);
        if k < below + n {
            meter.bin = b;
            meter.rank = k - below;
            return;
        }
        below += n;
    }
}

@compute @workgroup_size(8, 8)
fn meter_fine(@builtin(global_invocation_id) id: vec3<u32>) {
    if !inside(id) || meter.bin == COARSE_BINS {
        return;
    }
    let log_l = hair_log_luminance(id);
    if log_l < LOWEST_STOP - 0.5 {
        return;
    }
    let position = clamp(coarse_position(log_l), 0.0, f32(COARSE_BINS) - 1e-3);
    if u32(position) != meter.bin {
        return;
    }
    let fine = u32(clamp(fract(position) * f32(FINE_BINS), 0.0, f32(FINE_BINS - 1u)));
    atomicAdd(&meter.fine[fine], 1u);
}

@compute @workgroup_size(1)
fn meter_pick_fine() {
    meter.stops = 0.0;
    if meter.bin == COARSE_BINS {
        return;
    }
    var below = 0u;
    for (var f = 0u; f < FINE_BINS; f++) {
        let n = atomicLoad(&meter.fine[f]);
        if meter.rank < below + n {
            let position = f32(meter.bin) + (f32(f) + 0.5) / f32(FINE_BINS);
            let log_p90 = LOWEST_STOP + position * BIN_STOPS;
            meter.stops = clamp(log2(AUTO_TARGET) - log_p90, -AUTO_LIMIT_STOPS, AUTO_LIMIT_STOPS);
            return;
        }
        below += n;
    }
}

// One channel of the PNG's tonemap (`strandlight_tables::image_out::tonemap_channel`): Reinhard,
// the sRGB curve, 8 bits (returned as the byte over 255, which the unorm store keeps exactly).
fn tonemap(c: f32) -> f32 {
    var x = 0.0;
    if finite(c) {
        x = max(c, 0.0);
    }
    let p = x / (1.0 + x);
    var s = 12.92 * p;
    if p > 0.0031308 {
        s = 1.055 * pow(p, 1.0 / 2.4) - 0.055;
    }
    return round(clamp(s * 255.0, 0.0, 255.0)) / 255.0;
}

@compute @workgroup_size(8, 8)
fn display(@builtin(global_invocation_id) id: vec3<u32>) {
    if !inside(id) {
        return;
    }
    let p = frame_pixel(id);
    var behind = vec3<f32>(0.0);
    if params.has_backdrop != 0u {
        behind = backdrop[id.y * params.width + id.x].rgb;
    }
    var stops = meter.stops;
    if params.manual != 0u {
        stops = params.manual_stops;
    }
    let c = exp2(stops) * (p.rgb + (1.0 - clamp(p.a, 0.0, 1.0)) * behind);
    let out = vec4<f32>(tonemap(c.r), tonemap(c.g), tonemap(c.b), 1.0);
    textureStore(picture, vec2<i32>(id.xy), out);
}
