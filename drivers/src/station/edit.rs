//! Editing a station file's values in its own text: the layout, the comments and the
//! units as written stay; a value changes where it stands, a missing one is added beside
//! its neighbours (`ratecal explain --twin --write-twin`). The values are located by
//! parsing the file again with spans (serde-saphyr's `Spanned`).

use serde::Deserialize;
use serde_saphyr::Spanned;
use std::collections::BTreeMap;

/// One value to write: a registry term's parameter in the catalogue's unit, with its
/// standard uncertainty (which decides the digits written).
#[derive(Debug, Clone, PartialEq)]
pub struct SetValue {
    /// Registry id: a nominal term (`accel_bias`, `gyro_scale`, ...) or a catalogue effect.
    pub effect: String,
    /// Parameter name (`x`, `rzz_mm`).
    pub param: String,
    /// The value, in the catalogue's unit.
    pub value: f64,
    /// Its standard uncertainty (0: written with full precision).
    pub u: f64,
    /// For a user effect: its `.effect` file, as the station file references it
    /// (`imu.user_effects`).
    pub file: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scalar {
    Number(#[allow(dead_code)] f64),
    Text(String),
}

type Params = Spanned<BTreeMap<String, Spanned<f64>>>;
type Effects = Spanned<BTreeMap<String, Params>>;
type Triple = Option<Vec<Spanned<Scalar>>>;

#[derive(Deserialize)]
struct Skel {
    table: Spanned<TableSkel>,
    imu: Spanned<ImuSkel>,
}

#[derive(Deserialize)]
struct TableSkel {
    #[serde(default)]
    effects: Option<Effects>,
}

#[derive(Deserialize)]
struct ImuSkel {
    #[serde(default)]
    accel_bias: Triple,
    #[serde(default)]
    gyro_bias: Triple,
    #[serde(default)]
    accel_scale: Triple,
    #[serde(default)]
    gyro_scale: Triple,
    #[serde(default)]
    effects: Option<Effects>,
    #[serde(default)]
    user_effects: Option<Spanned<BTreeMap<String, Spanned<UserSkel>>>>,
}

#[derive(Deserialize)]
struct UserSkel {
    #[serde(default)]
    values: Option<Params>,
}

/// The nominal terms: the unit a bare `0` is replaced in, and how many of the
/// station file's internal unit one catalogue unit is (`accel_bias` m/s^2, `gyro_bias`
/// deg/s, the scales ppm, internally a ratio).
const NOMINAL: [(&str, &str, f64); 4] = [
    ("accel_bias", "mg", 1.0),
    ("gyro_bias", "deg/s", 1.0),
    ("accel_scale", "ppm", 1e-6),
    ("gyro_scale", "ppm", 1e-6),
];

/// Replacements: byte range and new text.
type Edits = Vec<(usize, usize, String)>;

/// `text` (a station file that parses) with every value of `sets` written: a value the
/// file states is replaced where it stands (in the unit it is written in), a missing one
/// is added (a parameter into its effect's map, an effect under `imu.effects` or, for a
/// station-side one, `table.effects`, a nominal triple under `imu`). Fails when the text
/// does not parse or a value is not a registry parameter.
pub fn edit(text: &str, sets: &[SetValue]) -> Result<String, String> {
    let skel: Skel = serde_saphyr::from_str(text).map_err(|e| e.to_string())?;
    let mut edits: Edits = Vec::new();
    let mut new_blocks = NewBlocks::default();
    let mut by_effect: BTreeMap<&str, Vec<&SetValue>> = BTreeMap::new();
    for s in sets {
        by_effect.entry(s.effect.as_str()).or_default().push(s);
    }
    let imu = &skel.imu.value;
    for (id, values) in by_effect {
        let Some(effect) = ratecal_physics::effect(id) else {
            let file = values.iter().find_map(|v| v.file.clone()).ok_or_else(|| {
                format!("`{id}` is neither a registry effect nor a user effect's")
            })?;
            if let Some(entry) = user(text, imu, id, &file, &values, &mut edits)? {
                new_blocks.add(start(&skel.imu)?, "user_effects", entry);
            }
            continue;
        };
        let named = |name: &str| {
            values
                .iter()
                .find(|v| v.param == name)
                .map(|v| (v.value, v.u))
        };
        if let Some(&(key, unit0, per)) = NOMINAL.iter().find(|n| n.0 == id) {
            let list = match key {
                "accel_bias" => &imu.accel_bias,
                "gyro_bias" => &imu.gyro_bias,
                "accel_scale" => &imu.accel_scale,
                _ => &imu.gyro_scale,
            };
            let axes: [Option<(f64, f64)>; 3] = ["x", "y", "z"].map(named);
            match list {
                Some(list) if list.len() == 3 => {
                    for (item, ax) in list.iter().zip(axes) {
                        if let Some((v, u)) = ax {
                            let (a, b) = span(item)?;
                            let old = &text[a..b];
                            let unit = match &item.value {
                                Scalar::Text(s) => unit_of(s).unwrap_or(unit0),
                                Scalar::Number(_) => unit0,
                            };
                            let q = quantity(v * per, u * per, unit)?;
                            edits.push((a, b, requote(old, &q)));
                        }
                    }
                }
                _ => {
                    let items: Vec<String> = axes
                        .iter()
                        .map(|ax| {
                            let (v, u) = ax.unwrap_or((0.0, 0.0));
                            quantity(v * per, u * per, unit0)
                        })
                        .collect::<Result<_, _>>()?;
                    insert_entry(
                        text,
                        start(&skel.imu)?,
                        &format!("{key}: [{}]", items.join(", ")),
                        &mut edits,
                    );
                }
            }
            continue;
        }
        let (block, owner) = if effect.station_side() {
            (&skel.table.value.effects, start(&skel.table)?)
        } else {
            (&imu.effects, start(&skel.imu)?)
        };
        let params: Vec<(&str, f64, f64)> = effect
            .params()
            .iter()
            .filter_map(|p| named(p.name).map(|(v, u)| (p.name, v, u)))
            .collect();
        let flow = |ps: &[(&str, f64, f64)]| {
            let inner: Vec<String> = ps
                .iter()
                .map(|(n, v, u)| format!("{n}: {}", number(*v, *u)))
                .collect();
            format!("{{ {} }}", inner.join(", "))
        };
        match block {
            None => new_blocks.add(owner, "effects", format!("{id}: {}", flow(&params))),
            Some(block) => match block.value.get(id) {
                None => insert_entry(
                    text,
                    start(block)?,
                    &format!("{id}: {}", flow(&params)),
                    &mut edits,
                ),
                Some(map) => {
                    for (name, v, u) in params {
                        match map.value.get(name) {
                            Some(old) => {
                                let (a, b) = span(old)?;
                                edits.push((a, b, number(v, u)));
                            }
                            None => insert_entry(
                                text,
                                start(map)?,
                                &format!("{name}: {}", number(v, u)),
                                &mut edits,
                            ),
                        }
                    }
                }
            },
        }
    }
    new_blocks.write(text, &mut edits);
    Ok(apply(text, edits))
}

/// The blocks the edit adds (`imu.effects`, `table.effects`, `imu.user_effects` where the
/// file has none): their entries gathered, so that one key holds every entry.
#[derive(Default)]
struct NewBlocks(Vec<(usize, &'static str, Vec<String>)>);

impl NewBlocks {
    /// Entry `entry` under `key`, a block the map starting at `owner` lacks.
    fn add(&mut self, owner: usize, key: &'static str, entry: String) {
        match self.0.iter_mut().find(|b| (b.0, b.1) == (owner, key)) {
            Some(b) => b.2.push(entry),
            None => self.0.push((owner, key, vec![entry])),
        }
    }

    /// The blocks' insertions, in the owner's style (flow or block).
    fn write(self, text: &str, edits: &mut Edits) {
        for (owner, key, entries) in self.0 {
            let block = if text[owner..].starts_with('{') {
                format!("{key}: {{ {} }}", entries.join(", "))
            } else {
                let pad = " ".repeat(column(text, owner) + 2);
                let lines: Vec<String> = entries.iter().map(|e| format!("\n{pad}{e}")).collect();
                format!("{key}:{}", lines.concat())
            };
            insert_entry(text, owner, &block, edits);
        }
    }
}

/// `text` with the edits made, from the end backwards. Insertions at one place (the end
/// of `imu.effects` is often the end of `imu` too) end up in the order they were asked
/// for, the deeper block's entries first: an effect added to `imu.effects` stays inside it
/// when `imu.user_effects` is added after it.
fn apply(text: &str, edits: Edits) -> String {
    let depth = |s: &str| {
        s.strip_prefix('\n')
            .map_or(usize::MAX, |r| r.len() - r.trim_start_matches(' ').len())
    };
    let mut order: Vec<(usize, (usize, usize, String))> = edits.into_iter().enumerate().collect();
    // Made from the end, a later insertion at the same place lands before an earlier one:
    // shallower ones and later ones are made first.
    order.sort_by(|(i, x), (j, y)| {
        y.0.cmp(&x.0)
            .then(y.1.cmp(&x.1))
            .then(depth(&x.2).cmp(&depth(&y.2)))
            .then(j.cmp(i))
    });
    let mut out = text.to_string();
    for (_, (a, b, s)) in order {
        out.replace_range(a..b, &s);
    }
    out
}

/// A user effect's values under `imu.user_effects` (the entry, or its `values`, added
/// when missing); the entry, when the file has no `imu.user_effects` to add it to.
fn user(
    text: &str,
    imu: &ImuSkel,
    id: &str,
    file: &str,
    values: &[&SetValue],
    edits: &mut Edits,
) -> Result<Option<String>, String> {
    let flow = || {
        let inner: Vec<String> = values
            .iter()
            .map(|v| format!("{}: {}", v.param, number(v.value, v.u)))
            .collect();
        format!("{{ {} }}", inner.join(", "))
    };
    let entry = || format!("{id}: {{ file: {file:?}, values: {} }}", flow());
    match &imu.user_effects {
        None => return Ok(Some(entry())),
        Some(block) => match block.value.get(id) {
            None => insert_entry(text, start(block)?, &entry(), edits),
            Some(u) => match &u.value.values {
                None => insert_entry(text, start(u)?, &format!("values: {}", flow()), edits),
                Some(map) => {
                    for v in values {
                        match map.value.get(&v.param) {
                            Some(old) => {
                                let (a, b) = span(old)?;
                                edits.push((a, b, number(v.value, v.u)));
                            }
                            None => insert_entry(
                                text,
                                start(map)?,
                                &format!("{}: {}", v.param, number(v.value, v.u)),
                                edits,
                            ),
                        }
                    }
                }
            },
        },
    }
    Ok(None)
}

/// Where a node starts (a block map: its first key; a flow collection: its bracket).
fn start<T>(s: &Spanned<T>) -> Result<usize, String> {
    s.referenced
        .span()
        .byte_offset()
        .map(|o| o as usize)
        .ok_or_else(|| "the station file's values have no byte offsets".to_string())
}

/// A scalar's byte range.
fn span<T>(s: &Spanned<T>) -> Result<(usize, usize), String> {
    let a = start(s)?;
    let n = s.referenced.span().byte_len().unwrap_or(0) as usize;
    Ok((a, a + n))
}

/// `new` quoted as `old` is.
fn requote(old: &str, new: &str) -> String {
    match old.chars().next() {
        Some(q @ ('"' | '\'')) => format!("{q}{new}{q}"),
        _ => new.to_string(),
    }
}

/// The unit of a quantity's text (`1.2 mg` -> `mg`), when it is one of the unit table's.
fn unit_of(s: &str) -> Option<&'static str> {
    let s = s.trim().trim_matches(['"', '\'']);
    let body = s.trim_start_matches(|c: char| c.is_ascii_digit() || "+-.eE ".contains(c));
    ratecal_physics::units::UNITS
        .iter()
        .find(|u| u.0 == body.trim())
        .map(|u| u.0)
}

/// `value` and `u` (the station file's internal unit) written in `unit`.
fn quantity(value: f64, u: f64, unit: &str) -> Result<String, String> {
    let (_, f) =
        ratecal_physics::units::unit(unit).ok_or_else(|| format!("unknown unit {unit}"))?;
    Ok(format!("{} {unit}", number(value / f, u / f)))
}

/// A number to two significant digits of its uncertainty (full precision without one).
pub fn number(v: f64, u: f64) -> String {
    if u > 0.0 && u.is_finite() {
        let d = (1 - u.log10().floor() as i32).clamp(0, 15) as usize;
        let s = format!("{v:.d$}");
        if s.trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            return s.trim_start_matches('-').to_string();
        }
        s
    } else {
        format!("{v}")
    }
}

fn line_start(text: &str, pos: usize) -> usize {
    text[..pos].rfind('\n').map_or(0, |i| i + 1)
}

fn column(text: &str, pos: usize) -> usize {
    pos - line_start(text, pos)
}

/// Where a block map whose first key is at `first` ends: the end of its last line that is
/// indented at least as far as that key (blank and comment lines after it are not its).
fn block_end(text: &str, first: usize) -> usize {
    let col = column(text, first);
    let mut end = text[first..].find('\n').map_or(text.len(), |i| first + i);
    let mut at = end;
    while at < text.len() {
        let next = at + 1;
        let stop = text[next..].find('\n').map_or(text.len(), |i| next + i);
        let line = &text[next..stop];
        let body = line.trim_start();
        if body.is_empty() || body.starts_with('#') {
            at = stop;
            continue;
        }
        if line.len() - body.len() < col {
            break;
        }
        end = stop;
        at = stop;
    }
    end
}

/// The closing bracket of the flow collection opening at `open`.
fn flow_close(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0usize;
    let mut quote: Option<char> = None;
    for (i, c) in text[open..].char_indices() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '{' | '[') => depth += 1,
            (None, '}' | ']') => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i);
                }
            }
            _ => {}
        }
    }
    None
}

/// Adds `entry` (`key: value`) to the map at `map`: inside its braces for a flow map, on
/// a line of its own after its last line for a block map.
fn insert_entry(text: &str, map: usize, entry: &str, edits: &mut Edits) {
    if text[map..].starts_with('{') {
        let Some(close) = flow_close(text, map) else {
            return;
        };
        let inner = &text[map + 1..close];
        if inner.trim().is_empty() {
            // A second entry into the same empty map joins the first one's.
            match edits.iter_mut().find(|e| (e.0, e.1) == (map, close + 1)) {
                Some(e) => {
                    let first = e.2.strip_suffix(" }").unwrap_or(&e.2).to_string();
                    e.2 = format!("{first}, {entry} }}");
                }
                None => edits.push((map, close + 1, format!("{{ {entry} }}"))),
            }
        } else {
            let at = map + 1 + inner.trim_end().len();
            edits.push((at, at, format!(", {entry}")));
        }
    } else {
        let end = block_end(text, map);
        let pad = " ".repeat(column(text, map));
        edits.push((end, end, format!("\n{pad}{entry}")));
    }
}

#[derive(Deserialize)]
struct Sections {
    #[serde(default)]
    site: Option<BTreeMap<String, Spanned<serde::de::IgnoredAny>>>,
    #[serde(default)]
    table: Option<BTreeMap<String, Spanned<serde::de::IgnoredAny>>>,
    #[serde(default)]
    mount: Option<BTreeMap<String, Spanned<serde::de::IgnoredAny>>>,
    #[serde(default)]
    imu: Option<BTreeMap<String, Spanned<serde::de::IgnoredAny>>>,
}

/// Where the value of `section.key` (`site.latitude_deg`, `table.outer_axis`) starts in a
/// station file's text, and the length of its first line: for errors located at a value.
pub fn locate(text: &str, section: &str, key: &str) -> Option<(usize, usize)> {
    let s: Sections = serde_saphyr::from_str(text).ok()?;
    let map = match section {
        "site" => s.site,
        "table" => s.table,
        "mount" => s.mount,
        "imu" => s.imu,
        _ => None,
    }?;
    let a = start(map.get(key)?).ok()?;
    let n = text[a..].find('\n').unwrap_or(text.len() - a);
    Some((a, n.max(1)))
}
