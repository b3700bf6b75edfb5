//! Where a manifest's values are written in its text: what a refused value's excerpt
//! points at.

/// Byte offset of the start of the line that declares segment `id` (at or after `from`).
pub(super) fn find_segment(text: &str, id: &str, from: usize) -> usize {
    let at = |needle: &str| text[from..].find(needle).map(|p| p + from);
    let hit = at(&format!("\"{id}\""))
        .or_else(|| at(&format!("'{id}'")))
        .or_else(|| at(&format!("id: {id}")));
    match hit {
        Some(p) => text[..p].rfind('\n').map_or(0, |n| n + 1),
        None => text.find("segments").unwrap_or(0),
    }
}

/// Byte offset and length of `key` and its value at or after `from` (the whole text's
/// start if the key is not written there).
pub(super) fn locate(text: &str, key: &str, from: usize) -> (usize, usize) {
    let from = from.min(text.len());
    let Some(start) = text[from..].find(key).map(|p| p + from) else {
        return (from, 1);
    };
    let rest = &text[start + key.len()..];
    let value = rest.trim_start_matches([':', ' ']);
    let skipped = rest.len() - value.len();
    let mut depth = 0i32;
    let mut end = value.len();
    for (i, c) in value.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => {
                depth -= 1;
                if depth == 0 {
                    end = i + 1;
                    break;
                }
            }
            ',' | '}' | '\n' | '\r' if depth == 0 => {
                end = i;
                break;
            }
            _ => {}
        }
    }
    (start, key.len() + skipped + value[..end].trim_end().len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_is_located_with_its_value() {
        let text = "site: { latitude_deg: 95, gravity_mps2: .nan }\nm: [[1, 0], [0, 1]], x";
        let (o, l) = locate(text, "gravity_mps2", 0);
        assert_eq!(&text[o..o + l], "gravity_mps2: .nan");
        let (o, l) = locate(text, "m", 40);
        assert_eq!(&text[o..o + l], "m: [[1, 0], [0, 1]]");
        assert_eq!(locate(text, "absent", 3), (3, 1));
    }
}
