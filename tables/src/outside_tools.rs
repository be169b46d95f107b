//! The programs from outside this project that some tests need (Mitsuba 3 and NVIDIA's
//! `flip_evaluator` through Python, `xvfb-run`), and the rule for when something a test needs is
//! missing: a tool, a GPU device, or the shared data (`shared_data.rs`).
//!
//! A test that cannot find what it needs prints why and skips ([`skip_or_fail`]), so that a
//! newcomer's `cargo test` runs without them. `cargo test` hides the output of passing tests, so
//! in CI a skip would be invisible: `.ci/run` sets `STRANDLIGHT_REQUIRE_TOOLS=1`, under which the
//! same test fails instead.

use std::process::Command;

/// The variable that turns a missing tool, GPU device or shared data from a skip into a failure.
pub const REQUIRE_TOOLS_VAR: &str = "STRANDLIGHT_REQUIRE_TOOLS";

/// The variable naming the Python interpreter to run (default `python3`).
pub const PYTHON_VAR: &str = "STRANDLIGHT_PYTHON";

/// Whether a missing tool, GPU device or shared data must fail the test
/// (`STRANDLIGHT_REQUIRE_TOOLS` set and not `0`).
pub fn tools_required() -> bool {
    std::env::var(REQUIRE_TOOLS_VAR).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The Python interpreter: `$STRANDLIGHT_PYTHON`, else `python3`.
pub fn python() -> String {
    std::env::var(PYTHON_VAR).unwrap_or_else(|_| "python3".into())
}

/// Whether `python` can import every module in `modules`.
pub fn python_has_modules(modules: &[&str]) -> bool {
    let script = modules
        .iter()
        .map(|m| format!("import {m}"))
        .collect::<Vec<_>>()
        .join("; ");
    Command::new(python())
        .args(["-c", &script])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Whether a program answers `program --help` (it exists on the PATH).
pub fn program_exists(program: &str) -> bool {
    Command::new(program).arg("--help").output().is_ok()
}

/// Called by a test that cannot run here, with the reason: returns (the caller then returns
/// early) after printing `skipped: {reason}`, or panics with the reason under
/// `STRANDLIGHT_REQUIRE_TOOLS=1`. Every test that may skip comes through here, so that CI can
/// never pass a test that did not run.
pub fn skip_or_fail(reason: &str) {
    skip_or_fail_as(tools_required(), reason);
}

fn skip_or_fail_as(required: bool, reason: &str) {
    if required {
        panic!("{reason}, and {REQUIRE_TOOLS_VAR} is set: this test must run here, not skip");
    }
    eprintln!("skipped: {reason}");
}

/// Called by a test whose tool is missing: [`skip_or_fail`] with how to install it.
pub fn missing_tool(what: &str, install: &str) {
    skip_or_fail(&format!("{what} is not available ({install})"));
}

/// `true` when Python can import `modules`; otherwise [`missing_tool`] and `false`.
pub fn require_python_modules(modules: &[&str], install: &str) -> bool {
    if python_has_modules(modules) {
        return true;
    }
    missing_tool(
        &format!("{} with the module(s) {}", python(), modules.join(", ")),
        install,
    );
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_module_that_does_not_exist_is_missing() {
        assert!(!python_has_modules(&["strandlight_no_such_module_4711"]));
    }

    #[test]
    #[should_panic(expected = "this test must run here")]
    fn a_required_skip_fails() {
        skip_or_fail_as(true, "no such tool");
    }

    #[test]
    fn a_skip_that_is_not_required_returns() {
        skip_or_fail_as(false, "no such tool");
    }

    #[test]
    fn a_program_that_does_not_exist_is_missing() {
        assert!(!program_exists("strandlight-no-such-program-4711"));
    }
}
