//! `units = "lj"`: every quantity is a plain number in σ, ε, m, τ. Lennard-Jones units have no
//! size in SI, so "3 mm" cannot be converted into them; this pass finds any value written with
//! a unit, in any section, and refuses it at its line, naming the key.

use super::convert::LineIndex;
use super::DeckError;
use crate::input::units::written_with_unit;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Strings that are not quantities whatever they hold: names of files and free text.
const FREE_TEXT: [&str; 4] = ["title", "output.directory", "output.restart", "validation"];

/// Refuses the first string in `text` written with a unit (`written_with_unit`).
pub(super) fn refuse_units(text: &str, file: &str, lines: &LineIndex) -> Result<(), DeckError> {
    // The deck has been read once already, so it parses.
    let Ok(root) = DeTable::parse(text) else {
        return Ok(());
    };
    match first_unit(root.get_ref(), "") {
        None => Ok(()),
        Some((key, value, at)) => Err(DeckError {
            file: file.to_string(),
            line: Some(lines.line(at)),
            message: format!(
                "{key} = \"{value}\" has a unit, but a deck in units = \"lj\" takes plain numbers (lengths in σ, energies in ε, masses in m, times in τ = σ√(m/ε), temperatures in ε/k_B): write the number alone"
            ),
        }),
    }
}

/// The first (key, string, byte offset) under `table` written with a unit, in document order.
fn first_unit(table: &DeTable, path: &str) -> Option<(String, String, usize)> {
    let mut entries: Vec<_> = table.iter().collect();
    entries.sort_by_key(|(_, v)| v.span().start);
    for (k, v) in entries {
        let key = if path.is_empty() {
            k.get_ref().to_string()
        } else {
            format!("{path}.{}", k.get_ref())
        };
        if FREE_TEXT.contains(&key.as_str()) {
            continue;
        }
        if let Some(found) = in_value(v, &key) {
            return Some(found);
        }
    }
    None
}

fn in_value(v: &Spanned<DeValue>, key: &str) -> Option<(String, String, usize)> {
    match v.get_ref() {
        DeValue::String(s) if written_with_unit(s) => {
            Some((key.to_string(), s.to_string(), v.span().start))
        }
        DeValue::Table(t) => first_unit(t, key),
        DeValue::Array(a) => a.iter().find_map(|x| in_value(x, key)),
        _ => None,
    }
}
