//! Typed errors for out-of-range physical parameters. Every model validates its parameters on
//! construction so that no NaN can leak into a table from a bad input.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    #[error("parameter `{name}` is not a finite number ({value})")]
    NotFinite { name: &'static str, value: f64 },
    #[error("parameter `{name}` = {value} is out of range: {requirement}")]
    OutOfRange {
        name: &'static str,
        value: f64,
        requirement: &'static str,
    },
    #[error("unknown preset `{name}` (known: {known})")]
    UnknownPreset { name: String, known: String },
}

/// Checks that `value` is finite and satisfies `ok`, naming the parameter in the error.
pub fn check(
    name: &'static str,
    value: f64,
    ok: impl FnOnce(f64) -> bool,
    requirement: &'static str,
) -> Result<f64, ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite { name, value });
    }
    if !ok(value) {
        return Err(ParamError::OutOfRange {
            name,
            value,
            requirement,
        });
    }
    Ok(value)
}

/// The common case: a finite value that must not be negative.
pub fn check_non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    check(name, value, |v| v >= 0.0, "must be ≥ 0")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_and_range_are_distinguished() {
        assert!(matches!(
            check_non_negative("sigma_a", f64::NAN),
            Err(ParamError::NotFinite { .. })
        ));
        assert!(matches!(
            check_non_negative("sigma_a", -1.0),
            Err(ParamError::OutOfRange { .. })
        ));
        assert_eq!(check_non_negative("sigma_a", 0.0), Ok(0.0));
    }
}
