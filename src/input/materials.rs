//! `[materials.NAME]` tables: `kind`, `density` and `compressive_strength` are the deck's;
//! every other key belongs to the model, which reads it through [`crate::model::Material`]
//! and refuses the ones it does not use. The deck keeps where each key was written, so a
//! model's error points at its line.

use super::units::UnitSystem;
use crate::model::material::canonical_key;
use crate::model::{Dimension, Material, MaterialKind, ModelError, Written};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// One material table: every key with its value as written.
pub(super) type MaterialSection = BTreeMap<String, Spanned<MaterialValue>>;

/// A value of a material key as written.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum MaterialValue {
    Integer(i64),
    Float(f64),
    Text(String),
    /// A boolean, an array, a table: refused by whoever reads the key.
    Other(toml::Value),
}

impl MaterialValue {
    fn written(&self) -> Written {
        match self {
            MaterialValue::Integer(v) => Written::Number(*v as f64),
            MaterialValue::Float(v) => Written::Number(*v),
            MaterialValue::Text(t) => Written::Text(t.clone()),
            MaterialValue::Other(v) => Written::Other(v.type_str()),
        }
    }
}

/// Where a material and each of its keys are in the deck.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialLines {
    pub line: usize,
    /// Each key (by its full name) and its line.
    pub keys: Vec<(String, usize)>,
}

impl MaterialLines {
    /// The line an error about this material points at: its key's, if it names one.
    pub fn of(&self, e: &ModelError) -> usize {
        let key = match e {
            ModelError::Material { key: Some(k), .. } => k.as_str(),
            _ => return self.line,
        };
        self.keys
            .iter()
            .find(|(k, _)| k == key)
            .map_or(self.line, |(_, l)| *l)
    }
}

/// The keys the deck reads itself.
const SHARED: [&str; 4] = ["kind", "density", "compressive_strength", "fc"];

/// Material number `index`, called `name`, from its table at `line`: its kind, density and f'c
/// read here, every other key handed on as written. An error is its line and message.
pub(super) fn read(
    name: &str,
    index: u16,
    table: &MaterialSection,
    line: usize,
    sys: UnitSystem,
    line_of: &dyn Fn(&Spanned<MaterialValue>) -> usize,
) -> Result<(Material, MaterialLines), (usize, String)> {
    let ctx = format!("material '{name}'");
    let units = sys.as_units();
    let key_line = |k: &str| table.get(k).map_or(line, line_of);
    let value = |k: &str, dim: Dimension| -> Result<Option<f64>, (usize, String)> {
        match table.get(k) {
            None => Ok(None),
            Some(v) => units
                .value(&v.get_ref().written(), dim)
                .map(Some)
                .map_err(|e| (key_line(k), format!("{ctx}: {k}: {e}"))),
        }
    };
    let kind = match table.get("kind").map(|v| v.get_ref()) {
        None => MaterialKind::Solid,
        Some(MaterialValue::Text(t)) if t == "solid" => MaterialKind::Solid,
        Some(MaterialValue::Text(t)) if t == "concrete" => MaterialKind::Concrete,
        Some(MaterialValue::Text(t)) if t == "steel" => MaterialKind::Steel,
        Some(other) => {
            let given = match other {
                MaterialValue::Text(t) => t.clone(),
                _ => "a value that is not a word".to_string(),
            };
            return Err((
                key_line("kind"),
                format!("{ctx}: unknown kind '{given}' (use \"solid\", \"concrete\" or \"steel\")"),
            ));
        }
    };
    let density = match value("density", Dimension::DENSITY)? {
        Some(d) if d.is_finite() && d > 0.0 => d,
        Some(d) => return Err((line, format!("{ctx}: density must be > 0 (got {d})"))),
        None => return Err((line, format!("{ctx}: missing field `density`"))),
    };
    let fc = ["compressive_strength", "fc"]
        .into_iter()
        .find(|k| table.contains_key(*k));
    let compressive_strength = match fc {
        Some(k) => match value(k, Dimension::STRESS)? {
            Some(x) if !(x.is_finite() && x > 0.0) => {
                return Err((
                    key_line(k),
                    format!("{ctx}: compressive_strength must be > 0 (got {x})"),
                ))
            }
            v => v,
        },
        None => None,
    };
    let keys = table
        .iter()
        .filter(|(k, _)| !SHARED.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.get_ref().written()))
        .collect();
    let lines = MaterialLines {
        line,
        keys: table
            .iter()
            .map(|(k, v)| (canonical_key(k).to_string(), line_of(v)))
            .collect(),
    };
    let mut material = Material::new(name, index, kind, density, keys, units)
        .map_err(|e| (lines.of(&e), e.to_string()))?;
    material.compressive_strength = compressive_strength;
    Ok((material, lines))
}

/// A table of pair-law keys (`[pair.materials.NAME]`, `[[pair.between]]`) as a [`Material`]
/// called `name` with number `index`, every key handed on as written (less those in `skip`),
/// so that a pair law reads them with units checked like a model's.
pub(super) fn read_keys(
    name: &str,
    index: u16,
    table: &MaterialSection,
    skip: &[&str],
    line: usize,
    sys: UnitSystem,
    line_of: &dyn Fn(&Spanned<MaterialValue>) -> usize,
) -> Result<(Material, MaterialLines), (usize, String)> {
    let keys = table
        .iter()
        .filter(|(k, _)| !skip.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.get_ref().written()))
        .collect();
    let lines = MaterialLines {
        line,
        keys: table.iter().map(|(k, v)| (k.clone(), line_of(v))).collect(),
    };
    let material = Material::new(name, index, MaterialKind::Solid, 0.0, keys, sys.as_units())
        .map_err(|e| (lines.of(&e), e.to_string()))?;
    Ok((material, lines))
}

/// The two material names of a `[[pair.between]]` table's `materials = ["a", "b"]`.
pub(super) fn pair_names(table: &MaterialSection) -> Option<[String; 2]> {
    match table.get("materials").map(|v| v.get_ref()) {
        Some(MaterialValue::Other(toml::Value::Array(a))) if a.len() == 2 => match (&a[0], &a[1]) {
            (toml::Value::String(x), toml::Value::String(y)) => Some([x.clone(), y.clone()]),
            _ => None,
        },
        _ => None,
    }
}
