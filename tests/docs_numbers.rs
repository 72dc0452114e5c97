//! Numbers written in the docs are what the code computes now: the
//! cloud-field statistics table of docs/physics.md (`cumulus stats` at its
//! defaults) is recomputed and compared at the precision it is printed
//! with; the error tables of docs/renderer.md and docs/physics.md are the
//! committed report CSVs, which are recomputed; the README's command table
//! lists every flag.

use cumulus::prepare::Prepared;
use cumulus::report::field_stats::{column_field, field_stats};
use cumulus::scene::Scene;

/// The text of a file of the crate, `path` relative to its root.
fn doc(path: &str) -> String {
    std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR")))
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The statistics table's row of `scene` in `text`: cloud fraction, D,
/// exponent.
fn stats_row(text: &str, scene: &str) -> [f64; 3] {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("| `{scene}.toml` | 0.")))
        .unwrap_or_else(|| panic!("no statistics row for {scene}"));
    let cells: Vec<&str> = line.split('|').map(str::trim).collect();
    let num = |s: &str| -> f64 {
        s.split_whitespace()
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("`{s}` in {line}"))
    };
    [num(cells[2]), num(cells[3]), num(cells[4])]
}

#[test]
fn statistics_table_matches_the_code() {
    let docs = ["README.md", "docs/physics.md"].map(|p| (p, doc(p)));
    for name in ["fair_weather", "bomex"] {
        let sc = Scene::load(std::path::Path::new(&format!("scenes/{name}.toml")))
            .expect("shipped scene");
        let p = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = &sc.render;
        // `cumulus stats` defaults: 512 columns, 48 levels, tau 1, 4 cells.
        let s = field_stats(
            &column_field(&p.density_frame(r, r.quality()), 512, 48),
            1.0,
            4,
        );
        let got = [
            s.cloud_fraction,
            s.dimension.expect("D"),
            s.size_fit.expect("fit").slope,
        ];
        for (path, text) in &docs {
            let want = stats_row(text, name);
            for (k, (g, w)) in got.iter().zip(want).enumerate() {
                let step = if k == 0 { 5e-4 } else { 5e-3 };
                assert!(
                    (g - w).abs() <= step + 1e-9,
                    "{name}: {path} says {w}, the code gives {g:.4} (column {k})"
                );
            }
        }
    }
}

/// The rows of a committed CSV under `docs/`, by column name.
fn csv_rows(path: &str) -> Vec<std::collections::HashMap<String, f64>> {
    let text = std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR")))
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(h, v)| {
                    let v = v
                        .parse()
                        .unwrap_or_else(|_| panic!("{path}: `{v}` in column {h}"));
                    (h.to_string(), v)
                })
                .collect()
        })
        .collect()
}

/// `got` printed with `decimals` decimals is `committed` (one unit of the
/// last place of slack for the rounding of a value on a boundary).
fn same_printed(got: f64, committed: f64, decimals: i32) -> bool {
    (got - committed).abs() <= 1.01 * 10f64.powi(-decimals)
}

/// The table of the doc at `path` that follows the line containing
/// `marker`: its rows' cells, bold marks removed.
fn doc_table(path: &str, marker: &str) -> Vec<Vec<String>> {
    let readme = doc(path);
    let start = readme
        .find(marker)
        .unwrap_or_else(|| panic!("no `{marker}`"));
    readme[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().trim_matches('*').to_string())
                .collect()
        })
        .collect()
}

/// A table cell is the committed value at the precision it is printed
/// with (`0.0082` for 0.008194; `12.1` for 12.0867; `0` for 0.0000).
fn cell_matches(cell: &str, value: f64) -> bool {
    let decimals = cell.split('.').nth(1).map_or(0, |d| d.len()) as i32;
    let shown: f64 = cell.replace(',', "").parse().unwrap_or(f64::NAN);
    (shown - value).abs() <= 0.5001 * 10f64.powi(-decimals)
}

/// `docs/render_quality/render_quality.csv` is what the code measures now
/// (the error columns; wall time depends on the machine), recomputed for
/// two of its rows, the least and the default step count, against the
/// full 2,048-step reference; and docs/renderer.md's table is that CSV.
#[test]
fn render_quality_report_matches_the_code() {
    use cumulus::report::render_quality;
    let rows = csv_rows("docs/render_quality/render_quality.csv");
    let table = doc_table("docs/renderer.md", "### Error against cost (rendering)");
    assert!(table.len() >= 5, "doc table: {table:?}");
    for cells in &table {
        let steps: f64 = cells[0].parse().expect("steps");
        let row = rows
            .iter()
            .find(|r| r["steps"] == steps)
            .unwrap_or_else(|| panic!("docs/renderer.md row of {steps} steps is not in the CSV"));
        for (k, col) in [(2, "mean_abs_error"), (3, "max_abs_error")] {
            assert!(
                cell_matches(&cells[k], row[col]),
                "docs/renderer.md says {} for {col} at {} steps; the CSV has {}",
                cells[k],
                row["steps"],
                row[col]
            );
        }
    }
    let sc = Scene::load(std::path::Path::new("scenes/fair_weather.toml")).expect("shipped");
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let r = &sc.render;
    let (w, h) = (r.width.min(320), r.height.min(240));
    let report = render_quality::measure(&p.frame(r, r.quality()), w, h, &[8, 48], || {});
    for got in &report.rows {
        let row = rows
            .iter()
            .find(|row| row["steps"] == got.steps as f64)
            .expect("row in the CSV");
        for (col, v) in [
            ("mean_abs_error", got.mean_error),
            ("max_abs_error", got.max_error),
        ] {
            assert!(
                same_printed(v as f64, row[col], 6),
                "{} steps: the CSV's {col} is {}, the code gives {v:.6}: run docs/regenerate.sh",
                got.steps,
                row[col]
            );
        }
    }
}

/// `docs/convergence/convergence.csv` is what the code measures now (the
/// error columns, all rows: the runs are short), and docs/physics.md's table
/// is that CSV.
#[test]
fn convergence_report_matches_the_code() {
    use cumulus::report::convergence;
    let rows = csv_rows("docs/convergence/convergence.csv");
    let table = doc_table("docs/physics.md", "## Error against run time (physics)");
    assert!(table.len() >= 5, "doc table: {table:?}");
    let columns = [
        "err_z_m",
        "err_w_mps",
        "err_theta_v_K",
        "err_qc_gkg",
        "err_cloud_base_m",
        "err_cloud_top_m",
        "life_mismatch",
    ];
    for cells in &table {
        let dt: f64 = cells[0].parse().expect("dt");
        let row = rows
            .iter()
            .find(|r| r["dt_s"] == dt)
            .unwrap_or_else(|| panic!("docs/physics.md row dt = {dt} is not in the CSV"));
        for (k, col) in columns.iter().enumerate() {
            assert!(
                cell_matches(&cells[k + 2], row[*col]),
                "docs/physics.md says {} for {col} at dt = {dt}; the CSV has {}",
                cells[k + 2],
                row[*col]
            );
        }
    }
    let sc = Scene::load(std::path::Path::new("scenes/bomex.toml")).expect("shipped");
    let atm = sc.atmosphere(None).expect("atmosphere");
    let dts: Vec<f64> = rows.iter().map(|r| r["dt_s"]).collect();
    let report = convergence::measure(&sc.physics, &atm, 1800.0, &dts, || {});
    for (got, row) in report.rows.iter().zip(&rows) {
        let values = [
            got.err_z_m,
            got.err_w_mps,
            got.err_theta_v_k,
            got.err_qc_gkg,
            got.err_cloud_base_m,
            got.err_cloud_top_m,
            got.life_mismatch,
        ];
        for (col, v) in columns.iter().zip(values) {
            let decimals = if *col == "life_mismatch" { 4 } else { 6 };
            assert!(
                same_printed(v, row[*col], decimals),
                "dt = {}: the CSV's {col} is {}, the code gives {v}: run docs/regenerate.sh",
                got.dt_s,
                row[*col]
            );
        }
    }
}

/// Every flag each command's `--help` lists is in that command's row of
/// the README's command table (a flag added to the code and not to the
/// README fails here).
#[test]
fn readme_command_table_lists_every_flag() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).expect("README");
    for cmd in [
        "simulate",
        "profile",
        "convergence",
        "render",
        "bench",
        "stats",
        "export",
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cumulus"))
            .args([cmd, "--help"])
            .output()
            .expect("run cumulus");
        let help = String::from_utf8_lossy(&out.stdout);
        let row = readme
            .lines()
            .find(|l| l.starts_with(&format!("| `cumulus {cmd} ")))
            .unwrap_or_else(|| panic!("no README row for `cumulus {cmd}`"));
        let first_cell = row.split(" | ").next().unwrap_or(row);
        let flags: Vec<&str> = help
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .filter(|w| !matches!(*w, "--help" | "--version"))
            .collect();
        assert!(!flags.is_empty(), "{cmd} --help lists no flags:\n{help}");
        for f in flags {
            let listed = [' ', '`', ']', '\\']
                .iter()
                .any(|end| first_cell.contains(&format!("{f}{end}")));
            assert!(listed, "README's `cumulus {cmd}` row does not list {f}");
        }
    }
}
