//! The one interface every fiber scattering function implements.

use crate::angles::FiberAngles;
use glam::DVec3;

/// Linear RGB triple, one value per channel.
pub type Rgb = [f64; 3];

/// A fiber's bidirectional scattering function S(ω_i, ω_o) per RGB channel, in the convention
/// `L_o = D ∫ S L_i cos θ_i dω_i` (units 1/sr). Evaluated in f64; the runtime's f32 path casts.
pub trait ScatteringFunction: Send + Sync {
    /// Short name used in table metadata and reports.
    fn name(&self) -> &'static str;

    fn eval(&self, angles: &FiberAngles) -> Rgb;

    fn eval_f32(&self, angles: &FiberAngles) -> [f32; 3] {
        self.eval(angles).map(|v| v as f32)
    }

    /// S for world-space directions around tangent `u` (`wi` toward the light).
    fn eval_directions(&self, u: DVec3, wi: DVec3, wo: DVec3) -> Rgb {
        self.eval(&FiberAngles::from_directions(u, wi, wo))
    }
}
