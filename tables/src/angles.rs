//! The fiber-frame angles every hair model is written in (Marschner 2003 §4; Hunz §3.1).

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// A pair of directions relative to a fiber.
///
/// `theta_i`, `theta_o` ∈ [−π/2, π/2] are inclinations from the normal plane (positive toward
/// the tip); `phi` = φ_o − φ_i is the relative azimuth, wrapped to (−π, π].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FiberAngles {
    pub theta_i: f64,
    pub theta_o: f64,
    pub phi: f64,
}

impl FiberAngles {
    pub fn new(theta_i: f64, theta_o: f64, phi: f64) -> Self {
        Self {
            theta_i,
            theta_o,
            phi: wrap_angle(phi),
        }
    }

    /// Angles of `wi` (toward the light) and `wo` (toward the viewer) around tangent `u`.
    /// None of the vectors need be normalized; a direction parallel to `u` gets φ = 0.
    pub fn from_directions(u: DVec3, wi: DVec3, wo: DVec3) -> Self {
        let u = u.normalize();
        let (wi, wo) = (wi.normalize(), wo.normalize());
        let theta_i = inclination(u, wi);
        let theta_o = inclination(u, wo);
        let pi = wi - u * u.dot(wi);
        let po = wo - u * u.dot(wo);
        // Signed angle from the projection of wi to that of wo, measured around u.
        let phi = u.dot(pi.cross(po)).atan2(pi.dot(po));
        Self::new(theta_i, theta_o, phi)
    }

    /// Marschner's half angle θ_h = (θ_i + θ_o)/2.
    pub fn theta_h(&self) -> f64 {
        0.5 * (self.theta_i + self.theta_o)
    }

    /// Marschner's difference angle θ_d = (θ_o − θ_i)/2, in [−π/2, π/2].
    pub fn theta_d(&self) -> f64 {
        0.5 * (self.theta_o - self.theta_i)
    }

    pub fn swapped(&self) -> Self {
        Self::new(self.theta_o, self.theta_i, -self.phi)
    }
}

/// Inclination of `w` from the plane normal to unit `u`; clamped so rounding never gives NaN.
pub fn inclination(u: DVec3, w: DVec3) -> f64 {
    u.dot(w)
        .clamp(-1.0, 1.0)
        .asin()
        .clamp(-FRAC_PI_2, FRAC_PI_2)
}

/// Wraps an angle to (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    let w = a.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

/// A unit direction from fiber-frame angles, with the tangent along +z and φ = 0 along +x.
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.cos() * phi.cos(),
        theta.cos() * phi.sin(),
        theta.sin(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_round_trip_through_directions() {
        let u = DVec3::Z;
        for &(ti, to, phi) in &[(0.3, -0.2, 1.0), (-1.2, 1.4, -2.9), (0.0, 0.0, PI)] {
            let phi_i = 0.7;
            let a =
                FiberAngles::from_directions(u, direction(ti, phi_i), direction(to, phi_i + phi));
            assert!((a.theta_i - ti).abs() < 1e-12);
            assert!((a.theta_o - to).abs() < 1e-12);
            assert!((a.phi - wrap_angle(phi)).abs() < 1e-12, "{a:?}");
        }
    }

    #[test]
    fn wrap_is_idempotent_and_in_range() {
        for k in -20..20 {
            let a = k as f64 * 0.77;
            let w = wrap_angle(a);
            assert!(w > -PI && w <= PI);
            assert!(
                ((a - w) / (2.0 * PI)).fract().abs() < 1e-9
                    || ((a - w) / (2.0 * PI)).fract().abs() > 1.0 - 1e-9
            );
        }
    }
}
