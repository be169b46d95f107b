//! The table cache under the abuse real users give it: two `strandlight bake` processes writing
//! the same folder at once, and a bake killed (SIGKILL, no chance to clean up) at several moments.
//! Whatever happens, every table file in the folder is complete and passes its own checksum, and
//! the next bake finishes the job, keeping the tables that were complete.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;
use strandlight_tables::asset::read_asset;

/// A small but complete bake (every model, 8 nodes per direction axis): about 2 s.
fn bake_command(dir: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_strandlight"));
    command
        .args([
            "bake",
            "--model",
            "all",
            "--resolution",
            "8",
            "--json",
            "--out",
        ])
        .arg(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    command
}

fn fresh_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Table files in `dir`, each of which must read back and verify.
fn valid_tables(dir: &Path) -> Vec<String> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if name.ends_with(".sltab") {
            read_asset(&path).unwrap_or_else(|e| panic!("a damaged table was left behind: {e}"));
            names.push(name);
        }
    }
    names.sort();
    names
}

fn bake_json(output: std::process::Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "bake failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("bake --json prints JSON")
}

#[test]
fn two_bakes_at_once_leave_valid_tables() {
    let dir = fresh_dir("two-bakes");
    let first = bake_command(&dir).spawn().unwrap();
    let second = bake_command(&dir).spawn().unwrap();
    let reports = [first, second].map(|child| bake_json(child.wait_with_output().unwrap()));
    let tables = valid_tables(&dir);
    let reported = reports[0]["tables"].as_array().unwrap().len();
    assert_eq!(tables.len(), reported, "{tables:?}");
    assert!(
        reported >= 10,
        "a bake of every model writes at least ten tables"
    );
    // The temporary files of both writers were renamed or removed.
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // A third bake finds everything current.
    let third = bake_json(bake_command(&dir).output().unwrap());
    let tables_json = third["tables"].as_array().unwrap();
    assert!(tables_json.iter().all(|t| t["cached"] == true), "{third}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_killed_bake_leaves_a_valid_cache() {
    let dir = fresh_dir("killed-bake");
    let mut seen_partial = false;
    for millis in [300, 700, 1100] {
        std::fs::remove_dir_all(&dir).unwrap();
        let mut child = bake_command(&dir).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(millis));
        let finished_early = child.try_wait().unwrap().is_some();
        child.kill().unwrap();
        child.wait().unwrap();
        let survivors = if dir.exists() {
            valid_tables(&dir)
        } else {
            Vec::new()
        };
        println!(
            "killed after {millis} ms: {} complete tables",
            survivors.len()
        );
        seen_partial |= !finished_early;
        // The next bake completes the folder and keeps what was complete.
        let report = bake_json(bake_command(&dir).output().unwrap());
        let tables = report["tables"].as_array().unwrap();
        let cached = tables.iter().filter(|t| t["cached"] == true).count();
        assert_eq!(
            cached,
            survivors.len(),
            "every complete survivor is reused: {report}"
        );
        assert_eq!(valid_tables(&dir).len(), tables.len());
    }
    assert!(
        seen_partial,
        "every bake finished before it could be killed"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
