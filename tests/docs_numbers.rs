//! Numbers written in the README are what the code computes now: the
//! cloud-field statistics table (`cumulus stats` at its defaults) is
//! recomputed and compared at the precision it is printed with.

use cumulus::prepare::Prepared;
use cumulus::report::field_stats::{column_field, field_stats};
use cumulus::scene::Scene;

/// The README row of `scene`: cloud fraction, D, exponent.
fn readme_row(readme: &str, scene: &str) -> [f64; 3] {
    let line = readme
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
fn readme_statistics_table_matches_the_code() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).expect("README");
    for name in ["fair_weather", "bomex"] {
        let sc = Scene::load(std::path::Path::new(&format!("scenes/{name}.toml")))
            .expect("shipped scene");
        let p = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = &sc.render;
        // `cumulus stats` defaults: 512 columns, 48 levels, tau 1, 4 cells.
        let s = field_stats(&column_field(&p.frame(r, r.quality()), 512, 48), 1.0, 4);
        let got = [
            s.cloud_fraction,
            s.dimension.expect("D"),
            s.size_fit.expect("fit").slope,
        ];
        let want = readme_row(&readme, name);
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            let step = if k == 0 { 5e-4 } else { 5e-3 };
            assert!(
                (g - w).abs() <= step + 1e-9,
                "{name}: README says {w}, the code gives {g:.4} (column {k})"
            );
        }
    }
}
