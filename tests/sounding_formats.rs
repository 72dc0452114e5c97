//! Soundings in the formats meteorologists download read to the same
//! levels as our CSV: the University of Wyoming TEXT:LIST listing and a
//! SHARPpy %RAW% file and IGRA2 sounding data of the BOMEX sounding
//! (`tests/reference/make_format_examples.py`, heights above sea level, each
//! format's own rounding), and bad lines named by file and line.

use std::path::{Path, PathBuf};

use cumulus::sim::Sounding;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn load(p: &Path) -> Sounding {
    Sounding::load(p, 101_325.0).unwrap_or_else(|e| panic!("{e}"))
}

/// Compares `other` with the CSV within the rounding of its format:
/// pressure to `dp_hpa`, height to `dz_m`, temperature and dewpoint to
/// `dt_k` (the mixing ratio follows the dewpoint: 7 % per K).
fn same_levels(other: &Sounding, dp_hpa: f64, dz_m: f64, dt_k: f64) {
    let csv = load(&root().join("scenes/bomex_sounding.csv"));
    assert_eq!(other.levels().len(), csv.levels().len());
    for (a, b) in other.levels().iter().zip(csv.levels()) {
        let (pa, pb) = (a.pressure_pa.unwrap_or(0.0), b.pressure_pa.unwrap_or(0.0));
        assert!((pa - pb).abs() <= dp_hpa * 100.0, "p {pa} vs {pb}");
        assert!(
            (a.height_m - b.height_m).abs() <= dz_m,
            "z {} vs {}",
            a.height_m,
            b.height_m
        );
        assert!(
            (a.temperature_k - b.temperature_k).abs() <= dt_k,
            "T at {} m",
            b.height_m
        );
        let rel = (a.mixing_ratio - b.mixing_ratio).abs() / b.mixing_ratio;
        assert!(rel <= 0.07 * dt_k + 1e-3, "q at {} m: {rel}", b.height_m);
    }
}

#[test]
fn wyoming_text_list_reads_like_the_csv() {
    let s = load(&root().join("tests/data/formats/bomex_wyoming.txt"));
    same_levels(&s, 0.05, 0.5, 0.05);
}

#[test]
fn sharppy_raw_reads_like_the_csv() {
    let s = load(&root().join("tests/data/formats/bomex_sharppy.txt"));
    same_levels(&s, 0.005, 0.005, 0.005);
}

#[test]
fn igra2_sounding_data_reads_like_the_csv() {
    // The file holds two soundings; the first is read. The dewpoint comes
    // from two rounded tenths (temperature and depression).
    let s = load(&root().join("tests/data/formats/bomex_igra2.txt"));
    same_levels(&s, 0.005, 0.5, 0.1);
}

#[test]
fn a_bad_line_is_named_with_file_and_line() {
    let text = std::fs::read_to_string(root().join("tests/data/formats/bomex_wyoming.txt"))
        .expect("example");
    // Line 9 (the third level): a temperature that is not a number.
    let bad: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 8 {
                l.replacen("26.4", "26,x", 1)
            } else {
                l.to_owned()
            }
        })
        .collect();
    let e = Sounding::parse(&bad.join("\n"), Path::new("w.txt"), 101_325.0)
        .expect_err("bad temperature");
    assert!(e.to_string().starts_with("w.txt:9:"), "{e}");
    // An unsorted level (a height below the previous) in SHARPpy: its line.
    let text = std::fs::read_to_string(root().join("tests/data/formats/bomex_sharppy.txt"))
        .expect("example");
    let bad = text.replacen("    25.00,", "     1.00,", 1);
    let e = Sounding::parse(&bad, Path::new("s.txt"), 101_325.0).expect_err("unsorted");
    assert!(e.to_string().starts_with("s.txt:8:"), "{e}");
}
