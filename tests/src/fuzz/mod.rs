//! An in-process, seeded mutation fuzzer for every file reader of the project (issue #15, "Bad
//! input"). For each [`targets::Target`] it builds a seed corpus ([`seeds`]), runs
//! `execs × STRANDLIGHT_FUZZ_EXECS` mutants ([`mutate`]) plus random junk behind the seeds'
//! first bytes, and checks each execution:
//!
//! - it returns (a panic is a finding; it runs under `catch_unwind`),
//! - no single allocation exceeds `(64 + bytes_out_per_byte_in) × input length + 64 MiB`
//!   (measured by the [`alloc::CountingAlloc`] the test binary installs),
//! - it takes less than [`EXEC_TIME_CAP`] (a watchdog ends the process, with the input saved,
//!   if one runs for [`WATCHDOG`]),
//! - a refusal names the file (its message contains the target's `file_name`),
//! - a load round-trips (issue #39): what loaded is written back with the project's writer for
//!   that kind of data, loaded again, and must be the same data bit for bit (counts, positions,
//!   widths and colours; map size and pixels; table asset; SRBF set); a mismatch, a writer that
//!   refuses what the reader accepted, or a written file that does not load is a finding.
//!   [`round_trip`] lists the writer of each target and why no tolerance is needed. (Outside
//!   the allocation and time figures of the reader; under `catch_unwind` and the watchdog. A
//!   load with the [`round_trip::fingerprint`] of one that round-tripped already is counted
//!   without writing it again: the writers and readers are deterministic.)
//!
//! Strict prefixes of the seeds must be refused where the format fixes its own size (every
//! prefix of the smallest generated seed, a sample of the others). Deterministic: the same
//! multiplier gives the same mutants. A finding is saved under
//! `target/strandlight-fuzz/<target>/` with the seed and edits that made it, so it can become
//! a regression test beside the reader.
//!
//! The input being executed is also written to `target/strandlight-fuzz/<target>/current.bin`
//! first: an abort (an allocation so large that the system refuses it) leaves it behind.

pub mod alloc;
pub mod mutate;
pub mod round_trip;
pub mod seeds;
pub mod targets;

use std::collections::{BTreeMap, HashSet};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, Once, OnceLock};
use std::time::{Duration, Instant};

use strandlight_tables::split_mix::SplitMix64;

use seeds::Seed;
use targets::Target;

/// Fixed allowance of the wild-allocation bound, beyond the per-byte part: decoders keep small
/// tables and buffers whose size does not follow the input's.
pub const ALLOCATION_SLACK: usize = 64 << 20;
/// An execution slower than this is a finding (seeds are small; a normal one takes well under
/// a millisecond to a few milliseconds).
pub const EXEC_TIME_CAP: Duration = Duration::from_secs(3);
/// An execution still running after this is a hang: the process ends with the input saved.
pub const WATCHDOG: Duration = Duration::from_secs(60);
/// Bytes of random junk behind a seed's first bytes, at most.
const JUNK_MAX: usize = 512;
/// One execution in this many is junk behind a seed's head instead of a mutant.
const JUNK_EVERY: usize = 16;
/// The first bytes of every format read here (junk goes behind them): `.hair`, a TressFX 4
/// version, a PLY header, a `.data` strand count, Radiance, OpenEXR, the table asset, JSON,
/// USD text, a USD crate file, a zip (USDZ), Ogawa, binary glTF, glTF JSON.
const SIGNATURES: [&[u8]; 14] = [
    b"HAIR",
    &[0, 0, 0x80, 0x40],
    b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n",
    &[2, 0, 0, 0],
    b"#?RADIANCE\n",
    &[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0],
    b"STRNDLUT\x02\0\0\0",
    b"{\"format\":\"strandlight-srbf-set\",",
    b"#usda 1.0\n",
    b"PXR-USDC\x00\x08\x00\x00\x00\x00\x00\x00",
    b"PK\x03\x04",
    b"Ogawa\xff\x01\x00",
    b"glTF\x02\0\0\0",
    b"{\"asset\":{\"version\":\"2.0\"},",
];
/// Each target must reach at least this many kinds of refusal, and some mutants must load:
/// otherwise the mutations are not getting past the first check.
pub const MIN_REFUSAL_KINDS: usize = 3;
/// Random strict prefixes checked per seed (the smallest generated seed gets all of them).
const SAMPLED_PREFIXES: usize = 48;

/// The workspace's `target/` folder (`$CARGO_TARGET_DIR` when set).
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .parent()
                .expect("the tests crate lives in the workspace")
                .join("target")
        })
}

/// Where findings and the current input go: `target/strandlight-fuzz/`.
pub fn fuzz_dir() -> PathBuf {
    target_dir().join("strandlight-fuzz")
}

/// A scratch folder of this process (for readers that take a path), created on first use: in
/// `/dev/shm` where there is one, since on ext4 closing a file truncated and rewritten in place
/// forces it to disk (milliseconds per execution), else under `target/strandlight-fuzz/`.
pub fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let shm = Path::new("/dev/shm");
        let parent = if shm.is_dir() {
            shm.join("strandlight-fuzz")
        } else {
            fuzz_dir()
        };
        // Folders left by earlier runs whose process is gone.
        if let Ok(entries) = std::fs::read_dir(&parent) {
            for entry in entries.flatten() {
                let name = entry.file_name().to_string_lossy().into_owned();
                if let Some(pid) = name.strip_prefix("scratch-")
                    && Path::new("/proc").is_dir()
                    && !Path::new("/proc").join(pid).exists()
                {
                    let _ = std::fs::remove_dir_all(entry.path());
                }
            }
        }
        let dir = parent.join(format!("scratch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("target/ is writable");
        dir
    })
}

/// `STRANDLIGHT_FUZZ_EXECS`: the multiplier of every target's CI execution count (default 1;
/// fractions such as 0.1 allowed for a quick look).
pub fn execs_multiplier() -> f64 {
    match std::env::var("STRANDLIGHT_FUZZ_EXECS") {
        Ok(v) => v
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|m| m.is_finite() && *m > 0.0)
            .unwrap_or_else(|| panic!("STRANDLIGHT_FUZZ_EXECS={v:?} is not a positive number")),
        Err(_) => 1.0,
    }
}

/// What went wrong in one execution.
#[derive(Clone, Debug)]
pub enum Problem {
    Panic(String),
    WildAllocation {
        bytes: usize,
        bound: usize,
    },
    Slow(Duration),
    /// The refusal's message does not contain the file's name.
    UnnamedFile {
        kind: String,
        message: String,
    },
    /// A seed written by the project's own writer does not load.
    SeedRefused,
    /// A strict prefix of a valid file was accepted.
    PrefixLoaded {
        prefix: usize,
        of: usize,
    },
    /// The input loaded, but written back and loaded again it is not the same (or the writer
    /// refused it, or its output did not load, or either panicked).
    RoundTrip {
        through: &'static str,
        mismatch: String,
    },
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::Panic(m) => write!(f, "panic: {m}"),
            Problem::WildAllocation { bytes, bound } => {
                write!(
                    f,
                    "wild allocation: one request of {bytes} bytes (bound {bound})"
                )
            }
            Problem::Slow(d) => write!(
                f,
                "slow: {:.2} s (cap {:?})",
                d.as_secs_f64(),
                EXEC_TIME_CAP
            ),
            Problem::UnnamedFile { kind, message } => {
                write!(f, "error {kind} does not name the file: {message:?}")
            }
            Problem::SeedRefused => {
                write!(f, "a seed written by the project's own writer is refused")
            }
            Problem::PrefixLoaded { prefix, of } => {
                write!(f, "the first {prefix} of {of} bytes of a valid file loaded")
            }
            Problem::RoundTrip { through, mismatch } => {
                write!(f, "round trip ({through}): {mismatch}")
            }
        }
    }
}

/// A finding with how to reproduce it.
#[derive(Clone, Debug)]
pub struct Finding {
    pub problem: Problem,
    /// The seed and the edits (or the prefix, or the junk) that made the input.
    pub origin: String,
    /// The input, saved under `target/strandlight-fuzz/<target>/`.
    pub saved: PathBuf,
}

/// One target's figures.
#[derive(Debug, Default)]
pub struct Report {
    pub target: String,
    pub seeds: Vec<(String, usize)>,
    pub executions: usize,
    /// Executions that loaded (whatever their round trip gave).
    pub ok: usize,
    /// The writer and reader of the round trip.
    pub round_trip: &'static str,
    /// Loads written back, loaded again and found the same (or, `round_trips_repeated` of them,
    /// the same data as such a load).
    pub round_trips: usize,
    pub round_trips_repeated: usize,
    /// Loads the written format cannot hold (not findings), with one reason.
    pub not_representable: usize,
    pub not_representable_example: Option<String>,
    /// Refusals by error variant.
    pub refusals: BTreeMap<String, usize>,
    /// One message per variant, for the log.
    pub examples: BTreeMap<String, String>,
    pub prefixes_checked: usize,
    /// Largest single allocation seen, as a multiple of the input's length (inputs ≥ 1 kB).
    pub largest_allocation_per_byte: f64,
    pub findings: Vec<Finding>,
    pub seconds: f64,
}

impl Report {
    /// Prints the figures and each finding.
    pub fn print(&self) {
        eprintln!(
            "fuzz {}: {} executions ({} mutants and junk, {} prefixes) in {:.1} s: {} Ok, {} refused, {} findings",
            self.target,
            self.executions,
            self.executions - self.prefixes_checked,
            self.prefixes_checked,
            self.seconds,
            self.ok,
            self.refusals.values().sum::<usize>(),
            self.findings.len()
        );
        for (name, len) in &self.seeds {
            eprintln!("  seed {name}: {len} bytes");
        }
        eprintln!(
            "  round trip ({}): {} of {} loads the same when written and loaded again ({} of them the same data as an earlier load)",
            self.round_trip, self.round_trips, self.ok, self.round_trips_repeated
        );
        if let Some(why) = &self.not_representable_example {
            eprintln!(
                "  {} loads not representable in the written format, e.g. {why}",
                self.not_representable
            );
        }
        for (kind, count) in &self.refusals {
            eprintln!(
                "  refused {count:>6} × {kind}: e.g. {}",
                self.examples[kind]
            );
        }
        eprintln!(
            "  largest allocation: {:.1} bytes per input byte (inputs of 1 kB or more)",
            self.largest_allocation_per_byte
        );
        for f in self.findings.iter().take(SAVED_FINDINGS) {
            eprintln!(
                "  FINDING {}\n    from {}\n    saved {}",
                f.problem,
                f.origin,
                f.saved.display()
            );
        }
        if self.findings.len() > SAVED_FINDINGS {
            eprintln!(
                "  … and {} more findings (not saved)",
                self.findings.len() - SAVED_FINDINGS
            );
        }
    }
}

/// The panic message of the execution in flight (the hook keeps it instead of printing).
static FUZZING: AtomicBool = AtomicBool::new(false);
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

fn install_panic_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if FUZZING.load(Ordering::SeqCst) {
                let message = info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(non-string payload)".into());
                let at = info
                    .location()
                    .map(|l| format!(" at {}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some(format!("{message}{at}"));
            } else {
                previous(info);
            }
        }));
    });
}

/// Milliseconds since [`epoch`] at which the execution in flight started (0: none), and the
/// path of its saved input, read by the watchdog thread.
static STARTED_MS: AtomicU64 = AtomicU64::new(0);
static CURRENT_INPUT: Mutex<Option<PathBuf>> = Mutex::new(None);

fn epoch() -> Instant {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

fn start_watchdog() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        epoch();
        std::thread::spawn(|| {
            loop {
                std::thread::sleep(Duration::from_millis(500));
                let started = STARTED_MS.load(Ordering::SeqCst);
                if started == 0 {
                    continue;
                }
                let now = epoch().elapsed().as_millis() as u64;
                if now.saturating_sub(started) > WATCHDOG.as_millis() as u64 {
                    let input = CURRENT_INPUT.lock().unwrap_or_else(|e| e.into_inner()).clone();
                    eprintln!(
                        "FINDING hang: an execution has run for more than {WATCHDOG:?}; its input is {}",
                        input.map(|p| p.display().to_string()).unwrap_or_default()
                    );
                    std::process::exit(101);
                }
            }
        });
    });
}

/// The result of one execution.
enum Outcome {
    /// Loaded, written back and loaded again the same; or `repeated`: loaded to the same data
    /// as an earlier input that did.
    Ok {
        repeated: bool,
    },
    /// Loaded; the written format cannot hold it.
    NotRepresentable(String),
    Refused(targets::Refusal),
    Problem(Problem),
}

/// The largest single allocation `target` may make for an input of `len` bytes.
pub fn allocation_bound(target: &Target, len: usize) -> usize {
    (64 + target.bytes_out_per_byte_in as usize)
        .saturating_mul(len)
        .saturating_add(ALLOCATION_SLACK)
}

/// Runs one input through `target` with every check. `round_tripped` holds the
/// [`round_trip::fingerprint`]s of the loads that round-tripped already.
fn execute(
    target: &Target,
    data: &[u8],
    current: &mut std::fs::File,
    round_tripped: &mut HashSet<u64>,
) -> (Outcome, usize) {
    // Kept on disk first: an abort inside the reader leaves the input behind. (One open file,
    // rewritten in place: cheaper than creating a file per execution.)
    {
        use std::io::{Seek, Write};
        current.set_len(0).expect("target/ is writable");
        current.rewind().expect("target/ is writable");
        current.write_all(data).expect("target/ is writable");
    }
    *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    FUZZING.store(true, Ordering::SeqCst);
    STARTED_MS.store(epoch().elapsed().as_millis() as u64 + 1, Ordering::SeqCst);
    let start = Instant::now();
    let (result, largest) =
        alloc::measure(|| catch_unwind(AssertUnwindSafe(|| (target.run)(data))));
    let elapsed = start.elapsed();
    let bound = allocation_bound(target, data.len());
    let panic_message = || {
        LAST_PANIC
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .unwrap_or_else(|| "(no message)".into())
    };
    let outcome = match result {
        Err(_) => Outcome::Problem(Problem::Panic(panic_message())),
        Ok(_) if largest > bound => Outcome::Problem(Problem::WildAllocation {
            bytes: largest,
            bound,
        }),
        Ok(_) if elapsed > EXEC_TIME_CAP => Outcome::Problem(Problem::Slow(elapsed)),
        Ok(Ok(loaded)) => {
            // The round trip, still under the watchdog but outside the reader's figures; once
            // for each distinct load (the writers and readers are deterministic).
            let fingerprint = round_trip::fingerprint(&loaded);
            let round_trip = catch_unwind(AssertUnwindSafe(|| {
                if round_tripped.contains(&fingerprint) {
                    return Ok(Outcome::Ok { repeated: true });
                }
                match (target.reload)(&loaded)? {
                    round_trip::Reloaded::Loaded(again) => {
                        round_trip::compare(&loaded, &again)?;
                        round_tripped.insert(fingerprint);
                        Ok(Outcome::Ok { repeated: false })
                    }
                    round_trip::Reloaded::NotRepresentable(why) => {
                        Ok(Outcome::NotRepresentable(why))
                    }
                }
            }));
            let mismatch = |mismatch| {
                Outcome::Problem(Problem::RoundTrip {
                    through: target.round_trip,
                    mismatch,
                })
            };
            match round_trip {
                Ok(Ok(outcome)) => outcome,
                Ok(Err(m)) => mismatch(m),
                Err(_) => mismatch(format!("panic: {}", panic_message())),
            }
        }
        Ok(Err(refusal)) if !refusal.message.contains(target.file_name) => {
            Outcome::Problem(Problem::UnnamedFile {
                kind: refusal.kind,
                message: refusal.message,
            })
        }
        Ok(Err(refusal)) => Outcome::Refused(refusal),
    };
    STARTED_MS.store(0, Ordering::SeqCst);
    FUZZING.store(false, Ordering::SeqCst);
    (outcome, largest)
}

/// A stable seed for a target's random stream.
fn stream_seed(name: &str) -> u64 {
    name.bytes()
        .fold(0xF0CC_5EED_u64, |h, b| h.rotate_left(8) ^ b as u64)
}

/// Fuzzes one target from its own seeds: see [`run_with_seeds`].
pub fn run(target: &Target) -> Report {
    run_with_seeds(target, seeds::seeds(target.name))
}

/// Fuzzes one target: seeds, prefixes, mutants and junk. The caller holds
/// [`alloc::MEASURING`] and has checked [`alloc::is_installed`].
pub fn run_with_seeds(target: &Target, seeds: Vec<Seed>) -> Report {
    install_panic_hook();
    start_watchdog();
    let started = Instant::now();
    assert!(!seeds.is_empty(), "{}: no seeds", target.name);
    let out_dir = fuzz_dir().join(target.name);
    std::fs::create_dir_all(&out_dir).expect("target/ is writable");
    let current = out_dir.join("current.bin");
    *CURRENT_INPUT.lock().unwrap_or_else(|e| e.into_inner()) = Some(current.clone());
    let report = Report {
        target: target.name.into(),
        round_trip: target.round_trip,
        seeds: seeds
            .iter()
            .map(|s| (s.name.clone(), s.bytes.len()))
            .collect(),
        ..Report::default()
    };
    let mut rng = SplitMix64::new(stream_seed(target.name));

    let current_file = std::fs::File::create(&current).expect("target/ is writable");
    let mut session = Session {
        target,
        report,
        out_dir,
        current_file,
        round_tripped: HashSet::new(),
    };
    session.run_seeds(&seeds);
    if target.prefixes_fail {
        session.run_prefixes(&seeds, &mut rng);
    }
    session.run_mutants(&seeds, &mut rng);
    let Session {
        mut report,
        current_file,
        ..
    } = session;
    drop(current_file); // closed before it is removed
    let _ = std::fs::remove_file(&current);
    report.seconds = started.elapsed().as_secs_f64();
    report
}

/// One target's fuzzing under way: the report it fills, the folder its findings go to, and
/// what every execution shares (the open file that keeps the current input on disk, the
/// fingerprints of the loads that round-tripped already).
struct Session<'a> {
    target: &'a Target,
    report: Report,
    out_dir: PathBuf,
    current_file: std::fs::File,
    round_tripped: HashSet<u64>,
}

impl Session<'_> {
    /// Executes one input, counts its outcome and saves it if it found a problem. Returns
    /// whether the input loaded.
    fn record(&mut self, data: &[u8], origin: String) -> bool {
        let (outcome, largest) = execute(
            self.target,
            data,
            &mut self.current_file,
            &mut self.round_tripped,
        );
        let report = &mut self.report;
        report.executions += 1;
        if data.len() >= 1024 {
            report.largest_allocation_per_byte = report
                .largest_allocation_per_byte
                .max(largest as f64 / data.len() as f64);
        }
        let problem = match outcome {
            Outcome::Ok { repeated } => {
                report.ok += 1;
                report.round_trips += 1;
                report.round_trips_repeated += repeated as usize;
                return true;
            }
            Outcome::NotRepresentable(why) => {
                report.ok += 1;
                report.not_representable += 1;
                report.not_representable_example.get_or_insert(why);
                return true;
            }
            Outcome::Refused(r) => {
                report.examples.entry(r.kind.clone()).or_insert(r.message);
                *report.refusals.entry(r.kind).or_default() += 1;
                return false;
            }
            Outcome::Problem(p) => p,
        };
        let loaded = matches!(problem, Problem::RoundTrip { .. });
        report.ok += loaded as usize;
        self.save_finding(data, problem, origin);
        loaded
    }

    fn save_finding(&mut self, data: &[u8], problem: Problem, origin: String) {
        save_finding(&mut self.report, &self.out_dir, data, problem, origin);
    }

    /// Every seed loads (the generated ones must; a shared one that does not is reported).
    fn run_seeds(&mut self, seeds: &[Seed]) {
        for seed in seeds {
            let loaded = self.record(&seed.bytes, format!("seed {}", seed.name));
            if !loaded && seed.generated && self.report.findings.is_empty() {
                self.save_finding(
                    &seed.bytes,
                    Problem::SeedRefused,
                    format!("seed {}", seed.name),
                );
            }
        }
    }

    /// Strict prefixes must be refused: all of the smallest generated seed's, a sample of
    /// every other seed's. For formats that fix their own size ([`Target::prefixes_fail`]).
    fn run_prefixes(&mut self, seeds: &[Seed], rng: &mut SplitMix64) {
        let smallest = seeds
            .iter()
            .filter(|s| s.generated)
            .min_by_key(|s| s.bytes.len())
            .map(|s| s.name.clone());
        for seed in seeds {
            let cuts: Vec<usize> = if Some(&seed.name) == smallest.as_ref() {
                (0..seed.bytes.len()).collect()
            } else {
                (0..SAMPLED_PREFIXES)
                    .map(|_| rng.below(seed.bytes.len()))
                    .collect()
            };
            for cut in cuts {
                let prefix = &seed.bytes[..cut];
                let loaded = self.record(prefix, format!("seed {}, first {cut} bytes", seed.name));
                self.report.prefixes_checked += 1;
                if loaded {
                    self.save_finding(
                        prefix,
                        Problem::PrefixLoaded {
                            prefix: cut,
                            of: seed.bytes.len(),
                        },
                        format!("seed {}, first {cut} bytes", seed.name),
                    );
                }
            }
        }
    }

    /// Mutants, and now and then junk behind a seed's first bytes (its magic and header start):
    /// `execs × STRANDLIGHT_FUZZ_EXECS` executions in all.
    fn run_mutants(&mut self, seeds: &[Seed], rng: &mut SplitMix64) {
        let executions = (self.target.execs as f64 * execs_multiplier()).round() as usize;
        for i in 0..executions {
            let seed = &seeds[rng.below(seeds.len())];
            let (data, origin) = if i % JUNK_EVERY == JUNK_EVERY - 1 {
                junk(seed, rng)
            } else {
                mutant(self.target, seeds, seed, i, rng)
            };
            self.record(&data, origin);
        }
    }
}

/// Random bytes behind a head: mostly this format's own (the first bytes of `seed`), one time
/// in four another format's signature, so that every reader also meets its neighbours' files.
/// Returns the input and where it came from.
fn junk(seed: &Seed, rng: &mut SplitMix64) -> (Vec<u8>, String) {
    let (head_bytes, head_name): (&[u8], String) = if rng.below(4) > 0 {
        let head = rng.below(seed.bytes.len().min(64) + 1);
        (
            &seed.bytes[..head],
            format!("the first {head} bytes of seed {}", seed.name),
        )
    } else {
        let magic = SIGNATURES[rng.below(SIGNATURES.len())];
        (
            magic,
            format!("the signature {:?}", magic.escape_ascii().to_string()),
        )
    };
    let mut junk = head_bytes.to_vec();
    let len = rng.below(JUNK_MAX + 1);
    junk.extend((0..len).map(|_| rng.next_u64() as u8));
    (junk, format!("junk: {head_name} and {len} random bytes"))
}

/// Mutant `i` of `seed` (the edits may splice in a random partner seed), resealed half the
/// time where the target can fix up its integrity check, so that the mutation reaches the
/// parser behind it. Returns the input and an origin that names how it was made.
fn mutant(
    target: &Target,
    seeds: &[Seed],
    seed: &Seed,
    i: usize,
    rng: &mut SplitMix64,
) -> (Vec<u8>, String) {
    let other = &seeds[rng.below(seeds.len())];
    let (mut data, edits) = mutate::mutate(&seed.bytes, &other.bytes, rng);
    let resealed = match target.reseal {
        Some(reseal) if rng.below(2) == 0 => {
            reseal(&mut data);
            true
        }
        _ => false,
    };
    let origin = format!(
        "seed {}, edits {edits:?}{}{} (mutant {i} of stream {:#x}, STRANDLIGHT_FUZZ_EXECS={})",
        seed.name,
        if edits.contains(&mutate::Edit::Splice) {
            format!(" (splice partner {})", other.name)
        } else {
            String::new()
        },
        if resealed { ", resealed" } else { "" },
        stream_seed(target.name),
        execs_multiplier(),
    );
    (data, origin)
}

/// Findings of one target saved to disk at most (a bug hit by many mutants is still counted).
const SAVED_FINDINGS: usize = 20;

fn save_finding(report: &mut Report, dir: &Path, data: &[u8], problem: Problem, origin: String) {
    let n = report.findings.len();
    let saved = dir.join(format!("finding-{n}.bin"));
    if n < SAVED_FINDINGS {
        std::fs::write(&saved, data).expect("target/ is writable");
        let note = format!("{problem}\nfrom {origin}\n{} bytes\n", data.len());
        std::fs::write(saved.with_extension("txt"), note).expect("target/ is writable");
    }
    report.findings.push(Finding {
        problem,
        origin,
        saved,
    });
}

/// Runs the target named `name` as a test: takes [`alloc::MEASURING`], checks the counting
/// allocator is installed, fuzzes, prints, and fails on any finding.
pub fn fuzz_target(name: &str) -> Report {
    let _measuring = alloc::MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    assert!(
        alloc::is_installed(),
        "the test binary must install fuzz::alloc::CountingAlloc as its #[global_allocator]"
    );
    let target = targets::all()
        .into_iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("no fuzz target {name}"));
    let report = run(&target);
    report.print();
    assert!(
        report.refusals.len() >= MIN_REFUSAL_KINDS && report.ok > 0,
        "fuzz {name}: the mutants reach only {:?} and {} loads; the fuzzing is shallow",
        report.refusals.keys().collect::<Vec<_>>(),
        report.ok
    );
    assert!(
        report.round_trips > 0 || !report.findings.is_empty(),
        "fuzz {name}: no load was round-tripped ({} not representable)",
        report.not_representable
    );
    assert!(
        report.findings.is_empty(),
        "fuzz {name}: {} findings (inputs saved under {}):\n{}",
        report.findings.len(),
        fuzz_dir().join(name).display(),
        report
            .findings
            .iter()
            .take(SAVED_FINDINGS)
            .map(|f| format!(
                "  {}\n    from {}\n    saved {}",
                f.problem,
                f.origin,
                f.saved.display()
            ))
            .collect::<Vec<_>>()
            .join("\n")
    );
    report
}
