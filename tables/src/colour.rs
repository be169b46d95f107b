//! The colour conventions every crate shares: Rec. 709 luminance (how lights are ranked, maps
//! fitted and images compared) and the sRGB transfer curve (how a linear value becomes a
//! display code).

/// Rec. 709 / sRGB luminance weights of linear R, G, B.
pub const REC709_LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Luminance of linear Rec. 709 RGB.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    let [wr, wg, wb] = REC709_LUMINANCE;
    wr * rgb[0] + wg * rgb[1] + wb * rgb[2]
}

/// [`luminance`] in f32, for GPU images and light powers.
pub fn luminance_f32(rgb: [f32; 3]) -> f32 {
    let [wr, wg, wb] = REC709_LUMINANCE.map(|w| w as f32);
    wr * rgb[0] + wg * rgb[1] + wb * rgb[2]
}

/// The sRGB transfer curve (IEC 61966-2-1) of linear `p` ∈ [0, 1].
pub fn srgb_encode(p: f64) -> f64 {
    if p <= 0.0031308 {
        12.92 * p
    } else {
        1.055 * p.powf(1.0 / 2.4) - 0.055
    }
}

/// [`srgb_encode`] in f32, as NVIDIA's FLIP computes it.
pub fn srgb_encode_f32(p: f32) -> f32 {
    if p <= 0.003_130_8 {
        12.92 * p
    } else {
        1.055 * p.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_has_unit_luminance_and_green_weighs_most() {
        assert!((luminance([1.0; 3]) - 1.0).abs() < 1e-12);
        assert!((luminance_f32([1.0; 3]) - 1.0).abs() < 1e-6);
        assert!(luminance([0.0, 1.0, 0.0]) > luminance([1.0, 0.0, 1.0]));
    }

    #[test]
    fn the_srgb_curve_is_continuous_at_its_knee_and_spans_zero_to_one() {
        // The standard's two pieces meet at 0.0031308 (to its published precision).
        let knee = 0.0031308;
        let linear_piece = 12.92 * knee;
        let power_piece = 1.055 * f64::powf(knee, 1.0 / 2.4) - 0.055;
        assert!((linear_piece - power_piece).abs() < 1e-6);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-12);
        // Mid grey (18%) encodes to the familiar code 118 of 255.
        assert_eq!((srgb_encode(0.18) * 255.0).round(), 118.0);
        for i in 0..=100 {
            let p = i as f64 / 100.0;
            assert!((srgb_encode(p) - srgb_encode_f32(p as f32) as f64).abs() < 1e-6);
        }
    }
}
