//! Property-based fuzzing of every parser a user feeds: scene TOML
//! (`Scene::parse`), soundings in all four formats (`Sounding::parse`),
//! the endless volume database (`Database::load`) and the exported
//! volumes (`read_vol`, `read_vdb`). Each is fed (a) random text or
//! bytes and (b) the shipped files, or files made by the code's own
//! writers, mutated: bit flips, deletions, insertions, truncation,
//! duplicated, deleted, swapped and foreign lines, numbers replaced by
//! huge, NaN, negative or empty values, and fields replaced whole. Text
//! is edited by line and field so that the edits reach the checks deep
//! in the parsers, past the first line.
//!
//! The properties: a parser never panics, never hangs (each call runs
//! on a worker thread that must return within [`PATIENCE`]; only
//! parsers are called, never a simulation), and an error names the file
//! it was given (and, for the line-oriented text formats, a line of that
//! text; where the message quotes the offending text, that line holds
//! it). What a parser accepts is checked to be sound (finite levels,
//! volumes of the size their header gives).
//!
//! Deterministic: every property runs proptest's ChaCha generator from
//! a fixed seed ([`config`]), so CI draws the same cases every run and
//! a failure reproduces; `PROPTEST_RNG_SEED` is not read. Failure
//! persistence is off: a bug found is kept as a named regression test
//! at the end of this file instead. The case counts keep the whole file
//! under a minute in `cargo test --release --test fuzz_parsers` on two
//! cores.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use glam::Vec3;
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::{Index, select};
use proptest::test_runner::{Config, RngAlgorithm, RngSeed, TestRunner};

use cumulus::endless::Database;
use cumulus::render::cpu::density_grid::Grid;
use cumulus::report::vdb::{read_vdb, vdb_bytes};
use cumulus::report::volume_export::{read_vol, vol_bytes};
use cumulus::scene::{Scene, SceneError};
use cumulus::sim::{Atmosphere, Sounding, SoundingError};

/// How long one parser call may take before it counts as a hang.
const PATIENCE: Duration = Duration::from_secs(10);

/// The path the text parsers are told they read.
const SCENE_PATH: &str = "fuzz/input.toml";
const SOUNDING_PATH: &str = "fuzz/input.csv";

/// A property's configuration: `cases` cases from a fixed seed, no
/// persistence file, shrinking bounded in time (a hang shrinks slowly).
fn config(cases: u32) -> Config {
    Config {
        cases,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x00C0_FFEE),
        max_shrink_time: 60_000,
        ..Config::default()
    }
}

/// `f()` on a worker thread: its value, its panic passed on, or a panic
/// of our own when it has not returned within [`PATIENCE`].
fn within<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(PATIENCE) {
        Ok(v) => {
            let _ = worker.join();
            v
        }
        Err(RecvTimeoutError::Timeout) => panic!("{what} still running after {PATIENCE:?}"),
        Err(RecvTimeoutError::Disconnected) => match worker.join() {
            Err(panic) => std::panic::resume_unwind(panic),
            Ok(()) => unreachable!("the worker sends before it ends"),
        },
    }
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The files in `dir` (relative to the repository) whose names end
/// with one of `exts`, with their text, sorted by name.
fn shipped(dir: &str, exts: &[&str]) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir(repo(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| exts.iter().any(|x| n.ends_with(x)))
        })
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("shipped file reads");
            (
                format!("{dir}/{}", p.file_name().unwrap().to_string_lossy()),
                text,
            )
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no {exts:?} files in {dir}");
    out
}

fn scenes() -> Vec<(String, String)> {
    shipped("scenes", &[".toml"])
}

fn soundings() -> Vec<(String, String)> {
    let mut all = shipped("scenes", &[".csv"]);
    all.extend(shipped("tests/data", &[".csv"]));
    all.extend(shipped("tests/data/formats", &[".txt"]));
    all
}

/// Every line of `files`, for edits that insert a line from elsewhere.
fn lines_of(files: &[(String, String)]) -> Vec<String> {
    let mut lines: Vec<String> = files
        .iter()
        .flat_map(|(_, t)| t.lines().map(str::to_owned))
        .collect();
    lines.sort();
    lines.dedup();
    lines
}

// ---------------------------------------------------------------------
// Edits

/// One edit of a file's bytes; indices are taken modulo what they index.
#[derive(Debug, Clone)]
enum Edit {
    FlipBit(Index, u8),
    Delete(Index, usize),
    Insert(Index, Vec<u8>),
    /// Overwrites the bytes at a place (a binary field's value).
    Overwrite(Index, Vec<u8>),
    Truncate(Index),
    DuplicateLine(Index),
    DeleteLine(Index),
    SwapLines(Index, Index),
    InsertLine(Index, String),
    /// The `which`-th number on a line replaced; `pad` keeps a
    /// fixed-column file's columns where the new text fits.
    ReplaceNumber {
        line: Index,
        which: Index,
        with: String,
        pad: bool,
    },
    /// The value of a `key = value` line, else the `which`-th
    /// comma-separated field, else the `which`-th word, replaced.
    ReplaceField {
        line: Index,
        which: Index,
        with: String,
    },
    /// Every `\n` written `\r\n`.
    CrLf,
}

/// Text that stands for a number in a file: ordinary values, the
/// extremes, non-numbers and nothing.
fn number_text() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => select(vec![
            "", " ", "-", "+", ".", "e", "1e", "1e+", "-.", "nan", "NaN", "-nan", "inf", "-inf",
            "+inf", "infinity", "1e308", "-1e308", "1e309", "-1e309", "1e-320", "0", "-0",
            "0.0", "-1", "1", "2", "-9999", "-8888", "-9999.00", "9999", "99999999", "1e5",
            "100001", "1e15", "1e300", "4294967295", "4294967296", "2147483648",
            "9223372036854775807", "-9223372036854775808", "18446744073709551616",
            "340282366920938463463374607431768211456", "0x1F", "1_000", "1,5", "\u{661}",
            "12abc", "--1", "1e5e5", "00000000000000000000000001",
        ])
        .prop_map(str::to_owned),
        2 => any::<f64>().prop_map(|v| v.to_string()),
        2 => any::<i64>().prop_map(|v| v.to_string()),
        2 => (-1e5..1e5f64).prop_map(|v| format!("{v:.1}")),
        1 => any::<u32>().prop_map(|v| v.to_string()),
    ]
}

/// A value for a whole field: a number, or a TOML value of another
/// type, or one of `values` (those the shipped files use).
fn field_text(values: Vec<String>) -> impl Strategy<Value = String> {
    prop_oneof![
        3 => number_text(),
        1 => select(vec![
            "\"\"", "\"x\"", "true", "false", "[]", "[1, 2, 3]", "[1e400, 0, 0]", "{}",
            "{ x = 1 }", "\"\\u0000\"", "'''\n'''", "\"\"\"", "[", "{", "\"",
        ])
        .prop_map(str::to_owned),
        3 => select(values),
    ]
}

/// Bytes that stand for a binary field: zero, one, the extremes of the
/// integer and float types, and random words.
fn word_bytes() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        select(vec![
            0u32,
            1,
            2,
            3,
            7,
            8,
            64,
            512,
            4096,
            32768,
            0x7fff_ffff,
            0x8000_0000,
            u32::MAX,
        ])
        .prop_map(|v| v.to_le_bytes().to_vec()),
        select(vec![
            0i64,
            -1,
            1,
            40,
            1 << 31,
            i64::MAX,
            i64::MIN,
            -(1 << 40)
        ])
        .prop_map(|v| v.to_le_bytes().to_vec()),
        select(vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            -f32::MAX,
            f32::MIN_POSITIVE,
            -1.0,
            0.0,
            -0.0,
            1e20,
        ])
        .prop_map(|v| v.to_le_bytes().to_vec()),
        vec(any::<u8>(), 1..=8),
    ]
}

/// Edits that treat a file as bytes.
fn byte_edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(at, bit)| Edit::FlipBit(at, bit)),
        (any::<Index>(), 1usize..64).prop_map(|(at, n)| Edit::Delete(at, n)),
        (any::<Index>(), vec(any::<u8>(), 1..32)).prop_map(|(at, b)| Edit::Insert(at, b)),
        any::<Index>().prop_map(Edit::Truncate),
    ]
}

/// Edits for a text format: mostly by line and field.
fn text_edit(pool: Vec<String>, values: Vec<String>) -> impl Strategy<Value = Edit> {
    prop_oneof![
        2 => byte_edit(),
        1 => any::<Index>().prop_map(Edit::DuplicateLine),
        1 => any::<Index>().prop_map(Edit::DeleteLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        1 => (any::<Index>(), prop_oneof![3 => select(pool), 1 => "\\PC{0,40}"])
            .prop_map(|(at, l)| Edit::InsertLine(at, l)),
        5 => (any::<Index>(), any::<Index>(), number_text(), any::<bool>()).prop_map(
            |(line, which, with, pad)| Edit::ReplaceNumber { line, which, with, pad }
        ),
        3 => (any::<Index>(), any::<Index>(), field_text(values))
            .prop_map(|(line, which, with)| Edit::ReplaceField { line, which, with }),
        1 => Just(Edit::CrLf),
    ]
}

/// Edits for a binary format: bytes, fields overwritten, and (for the
/// database's text lines) numbers.
fn binary_edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => byte_edit(),
        3 => (any::<Index>(), word_bytes()).prop_map(|(at, w)| Edit::Overwrite(at, w)),
        1 => (any::<Index>(), any::<Index>(), number_text(), Just(false)).prop_map(
            |(line, which, with, pad)| Edit::ReplaceNumber { line, which, with, pad }
        ),
        1 => any::<Index>().prop_map(Edit::DuplicateLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
    ]
}

/// The byte ranges of the numbers on `line`: runs of digits, signs,
/// points and exponents that hold a digit.
fn numbers(line: &[u8]) -> Vec<(usize, usize)> {
    let part = |c: u8| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+' | b'e' | b'E');
    let mut out = Vec::new();
    let mut i = 0;
    while i < line.len() {
        if part(line[i]) {
            let start = i;
            while i < line.len() && part(line[i]) {
                i += 1;
            }
            if line[start..i].iter().any(u8::is_ascii_digit) {
                out.push((start, i));
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The byte ranges of the fields of `line` ([`Edit::ReplaceField`]).
fn fields(line: &[u8]) -> Vec<(usize, usize)> {
    if let Some(eq) = line.iter().position(|&c| c == b'=') {
        return vec![(eq + 1, line.len())];
    }
    let sep: &dyn Fn(u8) -> bool = if line.contains(&b',') {
        &|c| c == b','
    } else {
        &|c: u8| c.is_ascii_whitespace()
    };
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &c) in line.iter().enumerate() {
        if sep(c) {
            if i > start || line.contains(&b',') {
                out.push((start, i));
            }
            start = i + 1;
        }
    }
    if line.len() > start {
        out.push((start, line.len()));
    }
    out
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    let len = bytes.len();
    match edit {
        Edit::FlipBit(at, bit) if len > 0 => bytes[at.index(len)] ^= 1 << bit,
        Edit::Delete(at, n) if len > 0 => {
            let a = at.index(len);
            bytes.drain(a..(a + n).min(len));
        }
        Edit::Insert(at, b) => {
            let a = at.index(len + 1);
            bytes.splice(a..a, b.iter().copied());
        }
        Edit::Overwrite(at, w) if len > 0 => {
            let a = at.index(len);
            let end = (a + w.len()).min(len);
            bytes[a..end].copy_from_slice(&w[..end - a]);
        }
        Edit::Truncate(at) => bytes.truncate(at.index(len + 1)),
        Edit::CrLf => {
            *bytes = String::from_utf8_lossy(bytes)
                .replace('\n', "\r\n")
                .into_bytes()
        }
        Edit::FlipBit(..) | Edit::Delete(..) | Edit::Overwrite(..) => {}
        _ => {
            let mut lines: Vec<Vec<u8>> =
                bytes.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
            edit_lines(&mut lines, edit);
            *bytes = lines.join(&b'\n');
        }
    }
}

fn edit_lines(lines: &mut Vec<Vec<u8>>, edit: &Edit) {
    let n = lines.len();
    match edit {
        Edit::DuplicateLine(at) => {
            let i = at.index(n);
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        Edit::DeleteLine(at) if n > 1 => {
            lines.remove(at.index(n));
        }
        Edit::SwapLines(a, b) => lines.swap(a.index(n), b.index(n)),
        Edit::InsertLine(at, l) => lines.insert(at.index(n + 1), l.clone().into_bytes()),
        Edit::ReplaceNumber {
            line,
            which,
            with,
            pad,
        } => {
            let l = &mut lines[line.index(n)];
            let spots = numbers(l);
            if spots.is_empty() {
                return;
            }
            let (a, b) = spots[which.index(spots.len())];
            let mut w = with.clone();
            if *pad && w.len() < b - a {
                w = format!("{w:>width$}", width = b - a);
            }
            l.splice(a..b, w.into_bytes());
        }
        Edit::ReplaceField { line, which, with } => {
            let l = &mut lines[line.index(n)];
            let spots = fields(l);
            if spots.is_empty() {
                return;
            }
            let (a, b) = spots[which.index(spots.len())];
            l.splice(a..b, with.clone().into_bytes());
        }
        _ => {}
    }
}

fn edited(original: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut b = original.to_vec();
    for e in edits {
        apply(&mut b, e);
    }
    b
}

/// The values of the `key = value` lines of `files`.
fn values_of(files: &[(String, String)]) -> Vec<String> {
    let mut v: Vec<String> = files
        .iter()
        .flat_map(|(_, t)| t.lines())
        .filter_map(|l| l.split_once('=').map(|(_, v)| v.trim().to_owned()))
        .collect();
    v.sort();
    v.dedup();
    v
}

/// The fields of the comma-separated lines of `files`.
fn fields_of(files: &[(String, String)]) -> Vec<String> {
    let mut v: Vec<String> = files
        .iter()
        .flat_map(|(_, t)| t.lines())
        .filter(|l| l.contains(','))
        .flat_map(|l| l.split(',').map(|f| f.trim().to_owned()))
        .collect();
    v.sort();
    v.dedup();
    v
}

// ---------------------------------------------------------------------
// What each parser promises

/// The text of 1-based `line` of `text` as the parsers count lines.
fn line_of(text: &str, line: usize) -> Option<&str> {
    text.lines().nth(line.checked_sub(1)?)
}

/// The text between the backticks after `is ` in `message`, if any
/// (`` `temperature_C` is `warm` ``): what the offending line holds.
fn quoted_value(message: &str) -> Option<&str> {
    let rest = message.split_once(" is `")?.1;
    rest.split_once('`').map(|(v, _)| v)
}

/// A scene parsed from `text`: no panic, no hang, and an error that
/// names the file and a line that holds what it is about. A scene that
/// parses also builds its atmosphere (tables, not a simulation), whose
/// error names the file too.
fn check_scene(text: String) {
    let outcome = within("Scene::parse", move || {
        let parsed = Scene::parse(&text, Path::new(SCENE_PATH));
        let atm = parsed.as_ref().ok().map(|s| s.atmosphere(None).err());
        (text, parsed, atm)
    });
    let (text, parsed, atm) = outcome;
    let nlines = text.lines().count();
    match parsed {
        Ok(_) => {
            if let Some(Some(e)) = atm {
                let msg = e.to_string();
                // A sounding it names is not there: the scene's key is
                // blamed, as for every other atmosphere error.
                assert!(msg.starts_with(&format!("{SCENE_PATH}:")), "{msg}");
            }
        }
        Err(e) => {
            let msg = e.to_string();
            match &e {
                SceneError::Parse { line, column, .. } => {
                    let head = format!("{SCENE_PATH}:{line}:{column}: ");
                    assert!(msg.starts_with(&head), "{msg:?} does not start {head:?}");
                    assert!(
                        (1..=nlines + 1).contains(line),
                        "line {line} of a {nlines}-line text: {msg}"
                    );
                }
                SceneError::Invalid { line, key, .. } => {
                    let head = match line {
                        Some(l) => format!("{SCENE_PATH}:{l}: `{key}`: "),
                        None => format!("{SCENE_PATH}: `{key}`: "),
                    };
                    assert!(msg.starts_with(&head), "{msg:?} does not start {head:?}");
                    if let Some(l) = line {
                        let last = key.rsplit('.').next().unwrap_or(key);
                        let at = line_of(&text, *l)
                            .unwrap_or_else(|| panic!("line {l} of a {nlines}-line text: {msg}"));
                        assert!(at.contains(last), "line {l} is {at:?}: {msg}");
                    }
                }
                other => panic!("Scene::parse read no file yet returned {other:?}"),
            }
        }
    }
}

/// A sounding parsed from `text`: no panic, no hang; an error names the
/// file and a line of `text` (`path:LINE: message`), which holds the
/// text the message quotes; a sounding that loads has finite levels,
/// rising, at positive pressures, and builds an atmosphere.
fn check_sounding(text: String) {
    let (text, parsed) = within("Sounding::parse", move || {
        let parsed = Sounding::parse(&text, Path::new(SOUNDING_PATH), 101_325.0)
            .inspect(|s| drop(Atmosphere::from_sounding(s)));
        (text, parsed)
    });
    let nlines = text.lines().count();
    match parsed {
        Ok(s) => {
            let levels = s.levels();
            assert!(levels.len() >= 2, "{} levels", levels.len());
            for (i, l) in levels.iter().enumerate() {
                let p = l.pressure_pa.expect("pressures filled");
                assert!(
                    l.height_m.is_finite()
                        && p.is_finite()
                        && p > 0.0
                        && l.temperature_k.is_finite()
                        && l.temperature_k > 0.0
                        && l.mixing_ratio.is_finite()
                        && l.mixing_ratio >= 0.0,
                    "level {i}: {l:?}"
                );
                if i > 0 {
                    assert!(l.height_m > levels[i - 1].height_m, "level {i}: {l:?}");
                }
            }
        }
        Err(e) => {
            let msg = e.to_string();
            let SoundingError::Invalid {
                path,
                line,
                message,
            } = &e
            else {
                panic!("Sounding::parse read no file yet returned {e:?}");
            };
            assert_eq!(path, Path::new(SOUNDING_PATH), "{msg}");
            let head = format!("{SOUNDING_PATH}:{line}: ");
            assert!(msg.starts_with(&head), "{msg:?} does not start {head:?}");
            let line = *line as usize;
            assert!(
                (1..=nlines.max(1)).contains(&line),
                "line {line} of a {nlines}-line text: {msg}"
            );
            // A quoted CSV field may run over lines: its first.
            if let Some(v) = quoted_value(message).and_then(|v| v.lines().next()) {
                let at = line_of(&text, line).unwrap_or("");
                assert!(at.contains(v), "line {line} is {at:?}: {msg}");
            }
        }
    }
}

/// An error of a binary reader: it names `path` first.
fn names_path(msg: &str, path: &Path) {
    let p = path.display().to_string();
    assert!(
        msg.starts_with(&format!("{p}: ")),
        "{msg:?} does not name {p}"
    );
}

/// A tiny database as `Database::save` writes it, stamped `PRINT`.
const PRINT: u64 = 0x0123_4567_89ab_cdef;

fn tiny_database() -> Vec<u8> {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    BYTES.get_or_init(save_tiny_database).clone()
}

fn save_tiny_database() -> Vec<u8> {
    let volumes = vec![vec![0u8, 10, 200, 255], vec![5u8, 0, 0, 1], vec![9u8; 4]];
    let db = Database {
        dims: [2, 1, 2],
        distance: cumulus::endless::distances(&volumes),
        volumes,
        interval_s: 30.0,
        origin: Vec3::new(0.0, 500.0, 0.0),
        extent: Vec3::new(100.0, 50.0, 100.0),
        extinction_per_m: 0.05,
        build_s: 1.5,
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("db.volumes");
    db.save(&path, PRINT).expect("saves");
    std::fs::read(&path).expect("reads")
}

/// A database whose header gives sizes of its own (each a size, an
/// extreme, or not a size), over the tiny database's body cut or
/// repeated: the sizes must be checked against the file before
/// anything is allocated for them.
fn database_with_header() -> impl Strategy<Value = Vec<u8>> {
    let any_size = || {
        select(vec![
            "0",
            "1",
            "2",
            "3",
            "4",
            "-1",
            "1.5",
            "65536",
            "1073741824",
            "2147483648",
            "4294967296",
            "9223372036854775807",
            "18446744073709551615",
            "18446744073709551616",
            "1e300",
            "null",
            "\"3\"",
        ])
    };
    // Mostly small volumes, and many of them: what passes the header's
    // own checks and asks for the most.
    let dim = || prop_oneof![3 => select(vec!["1", "2"]), 1 => any_size()];
    let count = prop_oneof![
        1 => select(vec!["1", "2", "3", "4"]),
        2 => select(vec!["65536", "1073741824", "2147483648"]),
        1 => any_size(),
    ];
    (dim(), dim(), dim(), count, any::<Index>()).prop_map(|(x, y, z, count, cut)| {
        let db = tiny_database();
        let body_at = db
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c == b'\n')
            .nth(1)
            .map_or(db.len(), |(i, _)| i + 1);
        let body = db[body_at..].repeat(3);
        let mut bytes = format!(
            "cumulus-volumes 1 {PRINT:016x}\n{{\"dims\":[{x},{y},{z}],\"count\":{count},\
             \"interval_s\":30.0,\"origin\":[0.0,500.0,0.0],\"extent\":[100.0,50.0,100.0],\
             \"extinction_per_m\":0.05,\"build_s\":1.5}}\n"
        )
        .into_bytes();
        bytes.extend_from_slice(&body[..cut.index(body.len() + 1)]);
        bytes
    })
}

fn check_database(bytes: Vec<u8>, path: &Path) {
    std::fs::write(path, &bytes).expect("write the case");
    let p = path.to_owned();
    let loaded = within("Database::load", move || Database::load(&p, PRINT));
    match loaded {
        Ok(None) => {}
        Ok(Some(db)) => {
            let voxels = db.dims.iter().try_fold(1_usize, |n, &d| n.checked_mul(d));
            assert!(
                db.volumes.iter().all(|v| Some(v.len()) == voxels),
                "{:?}",
                db.dims
            );
            assert_eq!(db.distance.len(), db.len() * db.len());
        }
        Err(e) => names_path(&e.to_string(), path),
    }
}

fn tiny_grid() -> (Grid, Vec<f32>) {
    let g = Grid::new(
        [3, 2, 2],
        Vec3::new(-10.0, 500.0, 0.0),
        Vec3::new(20.0, 700.0, 40.0),
    )
    .expect("grid");
    let values = (0..g.len()).map(|i| (i % 5) as f32 * 0.01).collect();
    (g, values)
}

fn check_vol(bytes: Vec<u8>, path: &Path) {
    std::fs::write(path, &bytes).expect("write the case");
    let p = path.to_owned();
    match within("read_vol", move || read_vol(&p)) {
        Ok((grid, values)) => assert_eq!(values.len(), grid.len()),
        Err(e) => names_path(&e.to_string(), path),
    }
}

fn check_vdb(bytes: Vec<u8>, path: &Path) {
    std::fs::write(path, &bytes).expect("write the case");
    let p = path.to_owned();
    if let Err(e) = within("read_vdb", move || read_vdb(&p)) {
        names_path(&e.to_string(), path);
    }
}

// ---------------------------------------------------------------------
// The properties

/// A sounding CSV of plausible rising levels, a few fields swapped for
/// hostile text: reaches the range checks and the hydrostatic filling.
fn sounding_csv() -> impl Strategy<Value = String> {
    let level = (1.0..3000.0f64, 0.0..30.0f64, any::<bool>(), -3.0..3.0f64);
    (
        any::<bool>(),
        vec(level, 2..40),
        vec((any::<Index>(), 0usize..4, number_text()), 0..3),
    )
        .prop_map(|(rh, levels, hostile)| {
            let hum = if rh {
                "relative_humidity_pct"
            } else {
                "dewpoint_C"
            };
            let mut rows: Vec<[String; 4]> = Vec::new();
            let mut h = 0.0;
            for (dh, dep, blank, noise) in levels {
                let t = 26.0 - 6.5 * h / 1000.0 + noise;
                let p = 1013.0 * (-h / 8000.0f64).exp();
                let q = if rh { 100.0 - 2.0 * dep } else { t - dep };
                let p = if blank {
                    String::new()
                } else {
                    format!("{p:.1}")
                };
                rows.push([format!("{h:.0}"), p, format!("{t:.1}"), format!("{q:.1}")]);
                h += dh;
            }
            for (row, col, with) in hostile {
                let n = rows.len();
                rows[row.index(n)][col] = with;
            }
            let mut text = format!("height_m,pressure_hPa,temperature_C,{hum}\n");
            for r in rows {
                text.push_str(&r.join(","));
                text.push('\n');
            }
            text
        })
}

/// TOML nested `n` deep: arrays, inline tables or a dotted table name
/// (the TOML reader's recursion must be bounded).
fn nested(n: usize, kind: usize) -> String {
    match kind {
        0 => format!("name = {}1{}\n", "[".repeat(n), "]".repeat(n)),
        1 => format!(
            "[render]\nwidth = {}1{}\n",
            "{a = ".repeat(n),
            "}".repeat(n)
        ),
        _ => format!("[physics{}]\nx = 1\n", ".a".repeat(n)),
    }
}

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn scenes_from_random_text_fail_cleanly(
        text in prop_oneof![
            "\\PC{0,400}",
            "(\\[[a-z.]{0,20}\\]\n|[a-z_.]{1,20} = [-0-9.e\"a-z\\[\\], ]{0,12}\n){0,12}",
            (0usize..3000, 0usize..3).prop_map(|(n, kind)| nested(n, kind)),
        ]
    ) {
        check_scene(text);
    }

    #[test]
    fn soundings_from_random_text_fail_cleanly(
        text in prop_oneof![
            "\\PC{0,400}",
            "height_m,pressure_hPa,temperature_C,(dewpoint_C|relative_humidity_pct)\n([-0-9.e, ]{0,30}\n){0,10}",
            "%RAW%\n([-0-9.e, ]{0,30}\n){0,10}%END%\n",
            "x\n-+\n   PRES   HGHT   TEMP   DWPT\n-+\n([-0-9. ]{0,35}\n){0,10}",
            "#[A-Z0-9]{11} 1969 06 22\n([-0-9 ]{0,45}\n){0,10}",
        ]
    ) {
        check_sounding(text);
    }

    #[test]
    fn sounding_csvs_with_hostile_fields_fail_cleanly(text in sounding_csv()) {
        check_sounding(text);
    }
}

proptest! {
    #![proptest_config(config(8000))]

    #[test]
    fn mutated_shipped_scenes_fail_cleanly(
        (file, edits) in {
            let files = scenes();
            let (pool, values) = (lines_of(&files), values_of(&files));
            (select(files), vec(text_edit(pool, values), 1..5))
        }
    ) {
        let text = String::from_utf8_lossy(&edited(file.1.as_bytes(), &edits)).into_owned();
        check_scene(text);
    }

    #[test]
    fn mutated_shipped_soundings_fail_cleanly(
        (file, edits) in {
            let files = soundings();
            let (pool, values) = (lines_of(&files), fields_of(&files));
            (select(files), vec(text_edit(pool, values), 1..5))
        }
    ) {
        let text = String::from_utf8_lossy(&edited(file.1.as_bytes(), &edits)).into_owned();
        check_sounding(text);
    }
}

/// Runs `check` on `cases` files drawn from `bytes`, each written to
/// `name` in one temporary folder (removed at the end), as `proptest!`
/// runs a property: a panic fails it with the smallest input found.
fn fuzz_file<S: Strategy<Value = Vec<u8>>>(
    cases: u32,
    name: &str,
    bytes: S,
    check: fn(Vec<u8>, &Path),
) {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join(name);
    TestRunner::new(config(cases))
        .run(&bytes, |b| {
            check(b, &path);
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
}

fn vol_file() -> Vec<u8> {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    BYTES
        .get_or_init(|| {
            let (g, v) = tiny_grid();
            vol_bytes(&g, &v).expect("vol bytes")
        })
        .clone()
}

fn vdb_file() -> Vec<u8> {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    BYTES
        .get_or_init(|| {
            let (g, v) = tiny_grid();
            vdb_bytes(&g, &v, "fuzz").expect("vdb bytes")
        })
        .clone()
}

/// The binary readers' cases.
const FILE_CASES: u32 = 4000;

#[test]
fn databases_from_random_or_mutated_bytes_fail_cleanly() {
    let bytes = prop_oneof![
        1 => vec(any::<u8>(), 0..256),
        4 => vec(binary_edit(), 1..5).prop_map(|e| edited(&tiny_database(), &e)),
        2 => database_with_header(),
    ];
    fuzz_file(FILE_CASES, "db.volumes", bytes, check_database);
}

#[test]
fn vol_files_from_random_or_mutated_bytes_fail_cleanly() {
    let bytes = prop_oneof![
        1 => vec(any::<u8>(), 0..256),
        4 => vec(binary_edit(), 1..5).prop_map(|e| edited(&vol_file(), &e)),
    ];
    fuzz_file(FILE_CASES, "fuzz.vol", bytes, check_vol);
}

#[test]
fn vdb_files_from_random_or_mutated_bytes_fail_cleanly() {
    let bytes = prop_oneof![
        1 => vec(any::<u8>(), 0..256),
        4 => vec(binary_edit(), 1..5).prop_map(|e| edited(&vdb_file(), &e)),
    ];
    fuzz_file(FILE_CASES, "fuzz.vdb", bytes, check_vdb);
}

// ---------------------------------------------------------------------
// The files the mutations start from are read by their parsers.

#[test]
fn the_unmutated_inputs_parse() {
    for (name, text) in scenes() {
        Scene::parse(&text, Path::new(&name)).unwrap_or_else(|e| panic!("{e}"));
    }
    for (name, text) in soundings() {
        Sounding::parse(&text, Path::new(&name), 101_325.0).unwrap_or_else(|e| panic!("{e}"));
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let p = dir.path().join("db.volumes");
    std::fs::write(&p, tiny_database()).expect("write");
    assert!(Database::load(&p, PRINT).expect("loads").is_some());
    let (g, v) = tiny_grid();
    let p = dir.path().join("v.vol");
    std::fs::write(&p, vol_bytes(&g, &v).expect("bytes")).expect("write");
    assert_eq!(read_vol(&p).expect("reads"), (g, v.clone()));
    let p = dir.path().join("v.vdb");
    std::fs::write(&p, vdb_bytes(&g, &v, "fuzz").expect("bytes")).expect("write");
    read_vdb(&p).expect("reads");
}

/// The edits do what they say (a broken mutator fuzzes nothing).
#[test]
fn the_edits_edit() {
    let text = b"a = 1\nb = -2.5e3, 7\n".to_vec();
    assert_eq!(numbers(b"b = -2.5e3, 7"), vec![(4, 10), (12, 13)]);
    assert_eq!(fields(b"1, 2,3"), vec![(0, 1), (2, 4), (5, 6)]);
    assert_eq!(fields(b"k = v"), vec![(3, 5)]);
    assert_eq!(fields(b"  12  3 "), vec![(2, 4), (6, 7)]);
    let crlf = edited(&text, &[Edit::CrLf]);
    assert_eq!(crlf, b"a = 1\r\nb = -2.5e3, 7\r\n");
}

// ---------------------------------------------------------------------
// Regressions: each input the properties found broke a parser.

fn sounding_error(text: &str) -> String {
    let text = text.to_owned();
    within("Sounding::parse", move || {
        Sounding::parse(&text, Path::new(SOUNDING_PATH), 101_325.0)
    })
    .expect_err("refused")
    .to_string()
}

/// The pressures were filled, and the atmosphere's table built, metre by
/// metre up to 1e15 m: the parse never returned.
#[test]
fn sounding_with_a_height_of_1e15_m_is_an_error_not_a_hang() {
    let e = sounding_error(
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,,26.2,26.2\n1e15,,23.1,-4.3\n",
    );
    assert!(
        e.starts_with("fuzz/input.csv:3: `height_m` is 1e15, expected 0..=100000 m"),
        "{e}"
    );
}

/// The same in a SHARPpy file, said in its own terms (`HGHT`, above sea
/// level).
#[test]
fn sharppy_sounding_1e15_m_high_is_an_error_in_its_own_terms() {
    let e = sounding_error(
        "%TITLE%\n KEY\n%RAW%\n1000, 10, 26, 22, 90, 5\n900, 1e15, 20, 15, 90, 5\n%END%\n",
    );
    assert!(
        e.starts_with("fuzz/input.csv:5: HGHT is 1e15 m")
            && e.contains("at most 100000 m above it"),
        "{e}"
    );
}

/// A value too large for `f64` read as infinity and reached the CSV as
/// `inf`: the error quoted `inf` under the CSV's column name, which the
/// file has neither of.
#[test]
fn sharppy_sounding_with_an_infinite_temperature_quotes_the_file() {
    let e = sounding_error(
        "%TITLE%\n KEY\n%RAW%\n1000, 10, 26, 22, 90, 5\n900, 900, 1e999, 15, 90, 5\n%END%\n",
    );
    assert!(
        e.starts_with("fuzz/input.csv:5: `TEMP` is `1e999`, expected a finite number"),
        "{e}"
    );
}

/// A header and no rows was blamed on line 2 of a one-line file: the
/// header's line was taken as where the reader stood after it.
#[test]
fn sounding_of_a_header_alone_names_the_header_line() {
    let header = "height_m,pressure_hPa,temperature_C,dewpoint_C\n";
    let e = sounding_error(header);
    assert!(e.starts_with("fuzz/input.csv:1: 0 data rows"), "{e}");
    let e = sounding_error(&format!("# a comment\n{header}"));
    assert!(e.starts_with("fuzz/input.csv:2: 0 data rows"), "{e}");
    let e = sounding_error("# a comment\nheight_m,temperature_C,dewpoint_C\n0,20,10\n");
    assert!(
        e.starts_with("fuzz/input.csv:2: missing column `pressure_hPa`"),
        "{e}"
    );
}

/// With Windows line ends a `#` comment line was not counted: every
/// error named the line above the one at fault.
#[test]
fn sounding_with_windows_line_ends_names_the_line_of_the_bad_row() {
    let e = sounding_error(
        "# BOMEX\r\nheight_m,pressure_hPa,temperature_C,dewpoint_C\r\n0,1000,20,10\r\n10,999,warm,10\r\n",
    );
    assert!(
        e.starts_with("fuzz/input.csv:4: `temperature_C` is `warm`"),
        "{e}"
    );
}

/// Blank lines were not counted either, and a row of the wrong length
/// quoted the csv crate's own (wrong) line in its message.
#[test]
fn sounding_with_blank_lines_names_the_line_of_the_bad_row() {
    let h = "height_m,pressure_hPa,temperature_C,dewpoint_C";
    let e = sounding_error(&format!("\n\n{h}\n\n0,1000,20,10\n\n10,999,warm,10\n"));
    assert!(
        e.starts_with("fuzz/input.csv:7: `temperature_C` is `warm`"),
        "{e}"
    );
    let e = sounding_error(&format!("# a\n\n{h}\n# b\n\n0,1000,20,10\n10,999,20\n"));
    assert_eq!(
        e,
        "fuzz/input.csv:7: malformed row: 3 fields, expected 4 as in the header"
    );
}

/// A `"` not closed took in the rest of the file as one field, and the
/// error quoted all of it.
#[test]
fn sounding_with_an_unclosed_quote_says_so_in_one_line() {
    let e = sounding_error(
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,\"\n10,999,19,9\n20,998,18,8\n",
    );
    assert_eq!(
        e,
        "fuzz/input.csv:2: `dewpoint_C` is a quoted field that runs past its line \
         (a `\"` not closed?), expected a number"
    );
}

/// A database header's sizes, the tiny database's body after it.
fn database_file(dims: &str, count: &str) -> (tempfile::TempDir, PathBuf) {
    let db = tiny_database();
    let body_at = db
        .iter()
        .enumerate()
        .filter(|&(_, &c)| c == b'\n')
        .nth(1)
        .map(|(i, _)| i + 1)
        .expect("two lines");
    let mut bytes = format!(
        "cumulus-volumes 1 {PRINT:016x}\n{{\"dims\":{dims},\"count\":{count},\"interval_s\":30.0,\
         \"origin\":[0.0,500.0,0.0],\"extent\":[100.0,50.0,100.0],\"extinction_per_m\":0.05,\
         \"build_s\":1.5}}\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&db[body_at..]);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("db.volumes");
    std::fs::write(&path, bytes).expect("write");
    (dir, path)
}

/// 2^31 volumes of one voxel passed the size check, and the list of
/// them was allocated before the file was read: 48 GiB, whose failure
/// aborted the program.
#[test]
fn database_header_of_2_pow_31_volumes_is_an_error_not_an_abort() {
    let (_dir, path) = database_file("[1,1,1]", "2147483648");
    let e = Database::load(&path, PRINT)
        .expect_err("refused")
        .to_string();
    assert!(e.starts_with(&format!("{}: ", path.display())), "{e}");
    assert!(e.contains("shorter than its header says"), "{e}");
}

/// Dims whose product is 2^64 + 4 wrapped to 4 voxels, and the database
/// loaded with dims no volume has.
#[test]
fn database_header_whose_dims_multiply_past_usize_is_an_error() {
    let (_dir, path) = database_file("[111620,429509837,384773]", "3");
    let e = Database::load(&path, PRINT)
        .expect_err("refused")
        .to_string();
    assert!(e.contains("empty or oversized volumes"), "{e}");
    // The same body under its own dims loads.
    let (_dir, path) = database_file("[2,1,2]", "3");
    assert!(Database::load(&path, PRINT).expect("loads").is_some());
}

/// `volumes` times the cells' height overflowed `usize` in the check
/// (a panic where overflow is checked, as in `cargo test`).
#[test]
fn endless_volumes_of_i64_max_is_an_error_not_an_overflow() {
    let text = "[simulation.endless]\nvolumes = 9223372036854775807\ncells = [2, 512, 2]\n";
    let e = Scene::parse(text, Path::new(SCENE_PATH))
        .expect_err("refused")
        .to_string();
    assert!(
        e.starts_with("fuzz/input.toml:2: `simulation.endless.volumes`"),
        "{e}"
    );
}
