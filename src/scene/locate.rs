//! Where a key is in a scene's TOML text, for errors that name the line.

/// 1-based line and column of byte `offset` in `text`.
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// 1-based line of the dotted `key` (e.g. `physics.sph.sound_speed_mps`) in
/// TOML text: the line `name = ...` under the table header of its parent
/// (or written dotted from a parent table).
pub fn locate_key(text: &str, key: &str) -> Option<usize> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut table: Vec<String> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(h) = line.strip_prefix('[') {
            let h = h.trim_start_matches('[').split(']').next().unwrap_or("");
            table = h.split('.').map(|s| s.trim().to_owned()).collect();
            continue;
        }
        let Some((lhs, _)) = line.split_once('=') else {
            continue;
        };
        let mut full: Vec<String> = table.clone();
        full.extend(
            lhs.split('.')
                .map(|s| s.trim().trim_matches('"').to_owned()),
        );
        if full.len() == parts.len() && full.iter().zip(&parts).all(|(a, b)| a == b) {
            return Some(n + 1);
        }
    }
    None
}

/// The dotted key assigned on 1-based `line` of TOML text (its table
/// header, then the left-hand side), if that line assigns one.
pub(super) fn key_at_line(text: &str, line: usize) -> Option<String> {
    let mut table: Vec<String> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let l = raw.trim();
        if let Some(h) = l.strip_prefix('[') {
            let h = h.trim_start_matches('[').split(']').next().unwrap_or("");
            table = h.split('.').map(|s| s.trim().to_owned()).collect();
        } else if n + 1 == line {
            let (lhs, _) = l.split_once('=')?;
            let mut full = table.clone();
            full.extend(
                lhs.split('.')
                    .map(|s| s.trim().trim_matches('"').to_owned()),
            );
            return Some(full.join("."));
        }
        if n + 1 >= line {
            break;
        }
    }
    None
}

/// A TOML type error in a user's words: serde's "expected u32", "expected
/// f64" and "expected struct RenderSettings" name Rust's types; a scene's
/// author wrote a number or a table.
pub(super) fn plain_types(message: &str) -> String {
    const TYPES: [(&str, &str); 12] = [
        ("expected u8", "expected a whole number 0..=255"),
        ("expected u16", "expected a whole number 0..=65535"),
        ("expected u32", "expected a whole number, 0 or more"),
        ("expected u64", "expected a whole number, 0 or more"),
        ("expected usize", "expected a whole number, 0 or more"),
        ("expected i32", "expected a whole number"),
        ("expected i64", "expected a whole number"),
        ("expected f32", "expected a number"),
        ("expected f64", "expected a number"),
        ("expected a sequence", "expected an array, [a, b, ...]"),
        ("expected a string", "expected a string in quotes"),
        ("expected a boolean", "expected true or false"),
    ];
    let mut m = message.to_owned();
    for (rust, plain) in TYPES {
        if let Some(at) = m.find(rust) {
            let end = at + rust.len();
            // Whole words only: "expected u32" and not "expected u32x".
            if !m[end..].starts_with(|c: char| c.is_alphanumeric() || c == '_') {
                m.replace_range(at..end, plain);
            }
        }
    }
    if let Some(at) = m.find("expected struct ") {
        let rest = &m[at + "expected struct ".len()..];
        let len = rest
            .find(|c: char| !c.is_alphanumeric() && c != '_')
            .unwrap_or(rest.len());
        m.replace_range(
            at..at + "expected struct ".len() + len,
            "expected a table of keys",
        );
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_key_finds_table_and_dotted_keys() {
        let t = "name = \"x\"\n[physics]\ndt_s = 1\nsph.sound_speed_mps = 2\n[physics.wind]\nspeed_mps = -1\n";
        assert_eq!(locate_key(t, "physics.dt_s"), Some(3));
        assert_eq!(locate_key(t, "physics.sph.sound_speed_mps"), Some(4));
        assert_eq!(locate_key(t, "physics.wind.speed_mps"), Some(6));
        assert_eq!(locate_key(t, "physics.radius_m"), None);
        assert_eq!(
            key_at_line(t, 4).as_deref(),
            Some("physics.sph.sound_speed_mps")
        );
        assert_eq!(key_at_line(t, 2), None);
    }
}
