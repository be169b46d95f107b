//! A panic inside another project's decoder becomes a [`HairError::Decode`] naming the file
//! (the USD and Alembic readers here; the glTF head reader uses [`panic_message`] the same way).
//!
//! The USD and Alembic readers are young crates that index and unwrap on what the file says;
//! a user's damaged file must give a message, not end the viewer. (A panic still prints through
//! the panic hook before it is caught.)

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use super::HairError;

/// Runs `decode`, turning a panic into a [`HairError::Decode`] for `file`.
pub(crate) fn without_panics<T>(
    file: &Path,
    format: &'static str,
    decode: impl FnOnce() -> Result<T, HairError>,
) -> Result<T, HairError> {
    // Nothing `decode` touches outlives it except through its result, so a half-done decode
    // leaves no broken state behind.
    catch_unwind(AssertUnwindSafe(decode)).unwrap_or_else(|panic| {
        Err(HairError::Decode {
            file: file.into(),
            format,
            why: format!(
                "the decoder failed on this file ({})",
                panic_message(&*panic)
            ),
        })
    })
}

/// The text a panic carried (`panic!`'s message), for an error that names the file instead.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_decode_error_naming_the_file() {
        let e = without_panics::<()>(Path::new("bad.usdc"), "USD", || {
            panic!("index 9 out of range")
        })
        .unwrap_err();
        assert!(matches!(e, HairError::Decode { .. }), "{e}");
        let text = e.to_string();
        assert!(
            text.contains("bad.usdc") && text.contains("index 9"),
            "{text}"
        );
    }
}
