//! Every scene key the parser accepts is documented in docs/scene.md.

use cumulus::scene::Scene;
use cumulus::sim::ParametricProfile;

fn keys(prefix: &str, v: &toml::Value, out: &mut Vec<String>) {
    if let toml::Value::Table(t) = v {
        for (k, v) in t {
            let full = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            if v.is_table() {
                keys(&full, v, out);
            } else {
                out.push(full);
            }
        }
    }
}

#[test]
fn every_scene_key_is_documented() {
    let mut scene = Scene::default();
    // Optional sections and keys, filled so they serialise.
    scene.atmosphere.parametric = Some(ParametricProfile::default());
    scene.atmosphere.sounding = Some("x.csv".into());
    scene.atmosphere.surface_pressure_hpa = Some(1000.0);
    scene.atmosphere.inversion_base_m = Some(1000.0);
    scene.projection.band_bottom_m = Some(1.0);
    scene.projection.band_top_m = Some(2.0);
    let value = toml::Value::try_from(&scene).expect("serialises");
    let mut all = Vec::new();
    keys("", &value, &mut all);
    assert!(all.len() > 50, "{all:?}");
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/scene.md"))
        .expect("docs/scene.md");
    for key in all {
        let (table, name) = key.rsplit_once('.').unwrap_or(("", &key));
        let header = format!("[{table}]");
        let in_table = table.is_empty() || doc.contains(&header);
        assert!(
            in_table && doc.contains(&format!("| `{name}` |")),
            "`{key}` is not documented in docs/scene.md"
        );
    }
}
