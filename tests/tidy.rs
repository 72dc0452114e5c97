//! The architecture invariants of ARCHITECTURE.md, checked on the source
//! text (as rust-analyzer's tidy tests do): each test names the file and
//! line that breaks its rule. Comments are not code: lines starting with
//! `//` are skipped.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Every `.rs` file under `src/<dir>`, with its code lines (line number,
/// text), comments left out.
fn code(dir: &str) -> Vec<(PathBuf, Vec<(usize, String)>)> {
    fn walk(p: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(p).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir);
    let mut files = Vec::new();
    walk(&root, &mut files);
    files.sort();
    files
        .into_iter()
        .map(|f| {
            let text = std::fs::read_to_string(&f).expect("read");
            let lines = text
                .lines()
                .enumerate()
                .filter(|(_, l)| !l.trim_start().starts_with("//"))
                .map(|(i, l)| (i + 1, l.to_owned()))
                .collect();
            (f, lines)
        })
        .collect()
}

/// `file:line: text` for every code line under `src/<dir>` (files for which
/// `skip` is false) that `bad` flags.
fn offences(dir: &str, skip: impl Fn(&Path) -> bool, bad: impl Fn(&str) -> bool) -> Vec<String> {
    let mut out = Vec::new();
    for (file, lines) in code(dir) {
        if skip(&file) {
            continue;
        }
        for (n, l) in lines {
            if bad(&l) {
                out.push(format!("{}:{n}: {}", file.display(), l.trim()));
            }
        }
    }
    out
}

#[test]
fn sim_depends_on_nothing_graphical_nor_on_scene_or_report() {
    let banned = [
        "wgpu",
        "winit",
        "egui",
        "crate::render",
        "crate::scene",
        "crate::report",
        "crate::prepare",
        "crate::panel",
    ];
    let o = offences("sim", |_| false, |l| banned.iter().any(|b| l.contains(b)));
    assert!(
        o.is_empty(),
        "sim/ reaches outside the simulator:\n{}",
        o.join("\n")
    );
}

/// The first path segments named after `crate::sim::` on a line:
/// `crate::sim::{Band, ProjectedField}` gives both names.
fn sim_items(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("crate::sim") {
        rest = &rest[i + "crate::sim".len()..];
        let Some(after) = rest.strip_prefix("::") else {
            // `use crate::sim;` names the whole simulator.
            out.push("sim".to_owned());
            continue;
        };
        if let Some(group) = after.strip_prefix('{') {
            let inner = group.split('}').next().unwrap_or("");
            for item in inner.split(',') {
                let first = item.trim().split("::").next().unwrap_or("").trim();
                if !first.is_empty() {
                    out.push(first.to_owned());
                }
            }
        } else {
            let name: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.push(name);
        }
    }
    out
}

#[test]
fn render_sees_the_simulation_only_through_p() {
    let allowed = ["ProjectedField", "Band", "projection"];
    let o = offences(
        "render",
        |_| false,
        |l| {
            sim_items(l).iter().any(|n| !allowed.contains(&n.as_str()))
                || [
                    "crate::scene",
                    "crate::prepare",
                    "crate::report",
                    "crate::panel",
                ]
                .iter()
                .any(|b| l.contains(b))
        },
    );
    assert!(
        o.is_empty(),
        "render/ reaches into the simulator beyond P (ProjectedField, Band) or into the scene:\n{}",
        o.join("\n")
    );
}

#[test]
fn sim_items_reads_use_lines() {
    assert_eq!(
        sim_items("use crate::sim::{Band, ProjectedField};"),
        ["Band", "ProjectedField"]
    );
    assert_eq!(sim_items("use crate::sim::Parcels;"), ["Parcels"]);
    assert_eq!(
        sim_items("f(crate::sim::projection::Band { })"),
        ["projection"]
    );
    assert_eq!(sim_items("use crate::sim;"), ["sim"]);
}

#[test]
fn only_the_binaries_edge_reads_the_environment() {
    let banned = ["env::var", "var_os(", "from_env(", "env::args", "env::vars"];
    let o = offences(
        "",
        |f| f.components().any(|c| c.as_os_str() == "bin"),
        |l| banned.iter().any(|b| l.contains(b)),
    );
    assert!(
        o.is_empty(),
        "the library reads the environment:\n{}",
        o.join("\n")
    );
}

#[test]
fn output_files_are_written_only_through_the_atomic_writer() {
    let banned = [
        "File::create",
        "fs::write(",
        "OpenOptions",
        "save_buffer",
        ".save_with_format(",
        "fs::copy(",
    ];
    let o = offences(
        "",
        |f| f.ends_with("src/io.rs"),
        |l| banned.iter().any(|b| l.contains(b)),
    );
    assert!(
        o.is_empty(),
        "a file is written outside cumulus::io::write_atomically:\n{}",
        o.join("\n")
    );
}

#[test]
fn the_codemap_names_every_module() {
    let arch =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md"))
            .expect("ARCHITECTURE.md");
    let mut missing = Vec::new();
    for (file, _) in code("") {
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or("");
        // A folder's mod.rs is named by the folder.
        let wanted = match name {
            "lib.rs" => continue,
            "mod.rs" | "main.rs" => format!(
                "{}/",
                file.parent()
                    .and_then(|d| d.file_name())
                    .and_then(|n| n.to_str())
                    .unwrap_or("")
            ),
            n => n.to_owned(),
        };
        if !arch.contains(&wanted) {
            missing.push(format!("{} ({wanted})", file.display()));
        }
    }
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md does not name:\n{}",
        missing.join("\n")
    );
}

/// Whether `line` holds a calendar date, `YYYY-MM-DD`.
fn has_date(line: &str) -> bool {
    let b = line.as_bytes();
    b.windows(10).any(|w| {
        let digits = |r: std::ops::Range<usize>| w[r].iter().all(u8::is_ascii_digit);
        digits(0..4) && w[4] == b'-' && digits(5..7) && w[7] == b'-' && digits(8..10)
    })
}

/// Every file under `dir` (relative to the crate) whose name ends in one
/// of `exts`.
fn files_under(dir: &str, exts: &[&str]) -> Vec<PathBuf> {
    fn walk(p: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(p) else {
            return;
        };
        for e in entries {
            let p = e.expect("entry").path();
            if p.is_dir() {
                walk(&p, exts, out);
            } else if exts.iter().any(|x| p.to_string_lossy().ends_with(x)) {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join(dir),
        exts,
        &mut out,
    );
    out.sort();
    out
}

/// History lives in CHANGELOG.md and the git log. The README and every
/// comment in the code and shaders say what is true now, with no date;
/// the other docs may put a date beside a figure only as the day it was
/// measured ("measured YYYY-MM-DD" on the same line).
#[test]
fn no_dated_narrative_outside_the_changelog() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut bad = Vec::new();
    let mut check = |path: &Path, allow_measured: bool, comments_only: bool| {
        let text = std::fs::read_to_string(path).expect("read");
        for (n, line) in text.lines().enumerate() {
            let t = line.trim_start();
            if comments_only && !t.starts_with("//") {
                continue;
            }
            if has_date(line) && !(allow_measured && line.contains("measured")) {
                bad.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
            }
        }
    };
    check(&root.join("README.md"), false, false);
    check(&root.join("ARCHITECTURE.md"), true, false);
    for f in files_under("docs", &[".md"]) {
        check(&f, true, false);
    }
    for f in files_under("shaders", &[".md"]) {
        check(&f, true, false);
    }
    for dir in ["src", "tests", "benches", "examples", "shaders"] {
        for f in files_under(dir, &[".rs", ".wgsl"]) {
            check(&f, false, true);
        }
    }
    assert!(
        bad.is_empty(),
        "dated lines (history belongs in CHANGELOG.md; a doc may say \"measured DATE\" \
         beside a figure):\n{}",
        bad.join("\n")
    );
}

/// The sibling modules each file of `src/<dir>` imports (`super::name`
/// on a code line before its tests), by module name; `*_tests.rs` files
/// and a folder's `mod.rs` left out.
fn sibling_imports(dir: &str) -> std::collections::BTreeMap<String, Vec<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir);
    let mut out = std::collections::BTreeMap::new();
    for e in std::fs::read_dir(&root).expect("read_dir") {
        let p = e.expect("entry").path();
        let name = p.file_stem().map(|s| s.to_string_lossy().into_owned());
        let Some(name) = name else { continue };
        let module = if p.is_dir() {
            p.join("mod.rs")
        } else {
            p.clone()
        };
        if name == "mod" || name.ends_with("tests") || !module.exists() {
            continue;
        }
        let text = std::fs::read_to_string(&module).expect("read");
        let mut deps = Vec::new();
        for line in text.lines() {
            if line.starts_with("#[cfg(test)]") {
                break;
            }
            if line.trim_start().starts_with("//") {
                continue;
            }
            for part in line.split("super::").skip(1) {
                let dep: String = part
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if !dep.is_empty() && dep != "super" && !deps.contains(&dep) {
                    deps.push(dep);
                }
            }
        }
        out.insert(name, deps);
    }
    out
}

/// A circle of imports among `graph`'s modules, if there is one.
fn circle(graph: &std::collections::BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    fn visit(
        m: &str,
        graph: &std::collections::BTreeMap<String, Vec<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == m) {
            return Some(path[i..].to_vec());
        }
        if done.contains(m) {
            return None;
        }
        path.push(m.to_string());
        for d in graph.get(m).into_iter().flatten() {
            if graph.contains_key(d)
                && let Some(c) = visit(d, graph, path, done)
            {
                return Some(c);
            }
        }
        path.pop();
        done.insert(m.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
}

/// The renderer's files import each other in layers (ARCHITECTURE.md):
/// no two files of `render/`, `render/cpu/` or `render/gpu/` reach each
/// other through their imports.
#[test]
fn render_modules_import_each_other_without_a_circle() {
    for dir in ["render", "render/cpu", "render/gpu"] {
        let graph = sibling_imports(dir);
        assert!(graph.len() > 5, "{dir}: {graph:?}");
        if let Some(c) = circle(&graph) {
            panic!("src/{dir}: a circle of imports: {}", c.join(" -> "));
        }
    }
}

/// Nothing below the reports reaches up into them: the endless player and
/// the renderer take what they share from `render`, not from `report`.
#[test]
fn endless_and_render_do_not_import_report() {
    let o = offences("endless", |_| false, |l| l.contains("crate::report"));
    assert!(o.is_empty(), "endless/ imports report:\n{}", o.join("\n"));
    let o = offences("render", |_| false, |l| l.contains("crate::report"));
    assert!(o.is_empty(), "render/ imports report:\n{}", o.join("\n"));
}
