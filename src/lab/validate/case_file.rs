//! Validation cases as files: `validation/NAME.toml` is a deck at the `--quick` resolution
//! (`pdq run` runs it as it stands) with a `[validation]` table that names the quantity, the
//! reference formula (`formulas.rs`), the measure (`measures.rs`), the tolerance, and what
//! `--full` and `--solver implicit` change in the deck. `validation/suite.toml` lists the
//! cases in report order. validation/README.md describes the format.

use super::formulas::Formula;
use super::measures::Measure;
use super::{Band, Case, Kind, Level, Plot};
use crate::input::deck;
use serde::Deserialize;
use std::path::Path;

/// The `[validation]` table of a case file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Validation {
    quantity: String,
    unit: String,
    kind: Kind,
    tolerance_percent: f64,
    /// The thesis's own result, where the case is one of its problems.
    thesis: Option<f64>,
    /// Added to the formula in the report: where the reference comes from, what is assumed.
    note: Option<String>,
    #[serde(default)]
    damage_views: bool,
    reference: Formula,
    measure: Measure,
    plot: PlotLabels,
    /// The value last measured at `--quick` and how far a run may move from it.
    regression: Option<Band>,
    /// What `--full` changes: the deck (merged over this one) and the table's entries.
    full: Option<FullLevel>,
    /// What `--thesis` changes, the same way (the full level where absent).
    thesis_resolution: Option<FullLevel>,
    /// What `--solver implicit` merges into the deck (elastic cases).
    implicit: Option<toml::Table>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlotLabels {
    x: String,
    y: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FullLevel {
    tolerance_percent: Option<f64>,
    quantity: Option<String>,
    /// The value last measured at `--full` (the `--quick` band does not carry over).
    regression: Option<Band>,
    #[serde(default)]
    deck: toml::Table,
}

/// The list of cases (`validation/suite.toml`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Suite {
    cases: Vec<String>,
}

/// How the elastic cases are solved: by their deck's ADR, or by Newton with the case's
/// `[validation.implicit]` settings, the tangent factored (`"implicit"`) or matrix-free
/// (`"newton_krylov"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElasticSolver {
    Adr,
    Implicit,
    NewtonKrylov,
}

impl ElasticSolver {
    /// The solver a `--solver` word names.
    pub fn named(word: &str) -> Result<Self, String> {
        match word {
            "adr" => Ok(ElasticSolver::Adr),
            "implicit" => Ok(ElasticSolver::Implicit),
            "newton_krylov" => Ok(ElasticSolver::NewtonKrylov),
            other => Err(format!(
                "unknown solver '{other}' (use implicit, newton_krylov, adr)"
            )),
        }
    }

    /// The word that names it.
    pub fn name(self) -> &'static str {
        match self {
            ElasticSolver::Adr => "adr",
            ElasticSolver::Implicit => "implicit",
            ElasticSolver::NewtonKrylov => "newton_krylov",
        }
    }
}

/// The cases listed in `dir/suite.toml`, in its order, at `level`; the elastic ones by
/// `solver`. A case file the list leaves out is refused, not skipped.
pub fn load_suite(dir: &Path, level: Level, solver: ElasticSolver) -> Result<Vec<Case>, String> {
    let path = dir.join("suite.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "{}: {e} (give the directory of the validation cases with --cases)",
            path.display()
        )
    })?;
    let suite: Suite = toml::from_str(&text).map_err(|e| located(&path, &text, &e))?;
    let listed = |stem: &str| suite.cases.iter().any(|c| c == stem);
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for entry in entries.flatten() {
        let p = entry.path();
        let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        if p.extension().is_some_and(|x| x == "toml") && stem != "suite" && !listed(stem) {
            return Err(format!(
                "{}: a case file that {} does not list",
                p.display(),
                path.display()
            ));
        }
    }
    suite
        .cases
        .iter()
        .map(|name| load(&dir.join(format!("{name}.toml")), level, solver))
        .collect()
}

/// One case file at `level`.
pub fn load(path: &Path, level: Level, solver: ElasticSolver) -> Result<Case, String> {
    load_with(path, level, solver, None)
}

/// A deck edit made after the level's (`sweep` resizes the cantilever with one).
pub type Edit<'a> = &'a dyn Fn(&mut toml::Table) -> Result<(), String>;

/// One case file at `level`, its deck changed by `edit` after the level's changes.
pub fn load_with(
    path: &Path,
    level: Level,
    solver: ElasticSolver,
    edit: Option<Edit>,
) -> Result<Case, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut deck: toml::Table = toml::from_str(&text).map_err(|e| located(path, &text, &e))?;
    let v: Validation = match deck.remove("validation") {
        Some(table) => table
            .try_into()
            .map_err(|e| format!("{}: [validation]: {e}", path.display()))?,
        None => return Err(format!("{}: no [validation] table", path.display())),
    };
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or_default();
    let (mut tolerance, mut quantity, mut changed) = (v.tolerance_percent, v.quantity, false);
    let finer = match level {
        Level::Quick => None,
        Level::Full => v.full.as_ref().map(|f| (f, "[validation.full]")),
        Level::Thesis => (v
            .thesis_resolution
            .as_ref()
            .map(|f| (f, "[validation.thesis_resolution]")))
        .or(v.full.as_ref().map(|f| (f, "[validation.full]"))),
    };
    let (band, band_table) = match finer {
        None if level == Level::Quick => (v.regression, "[validation]"),
        None => (None, ""),
        Some((f, table)) => (f.regression, table),
    };
    if let Some((finer, table)) = finer {
        merge(&mut deck, &finer.deck, "")
            .map_err(|e| format!("{}: {table}: {e}", path.display()))?;
        tolerance = finer.tolerance_percent.unwrap_or(tolerance);
        quantity = finer.quantity.clone().unwrap_or(quantity);
        changed = true;
    }
    if let Some(b) = band {
        if !(b.value.is_finite() && b.percent.is_finite() && b.percent > 0.0) {
            return Err(format!(
                "{}: {band_table} regression = {{ value = {}, percent = {} }}: give a finite value and a percent above 0",
                path.display(),
                b.value,
                b.percent
            ));
        }
    }
    if solver != ElasticSolver::Adr && v.kind == Kind::Elastic {
        let patch = v.implicit.as_ref().ok_or_else(|| {
            format!(
                "{}: no [validation.implicit] to solve it by",
                path.display()
            )
        })?;
        merge(&mut deck, patch, "")
            .map_err(|e| format!("{}: [validation.implicit]: {e}", path.display()))?;
        if solver == ElasticSolver::NewtonKrylov {
            if let Some(toml::Value::Table(t)) = deck.get_mut("solver") {
                t.insert("kind".into(), toml::Value::String("newton_krylov".into()));
            }
        }
        changed = true;
    }
    if let Some(edit) = edit {
        edit(&mut deck).map_err(|e| format!("{}: {e}", path.display()))?;
        changed = true;
    }
    // As written where nothing changed, so that the copy beside the run keeps its comments.
    let text = if changed {
        toml::to_string(&deck).map_err(|e| format!("{}: {e}", path.display()))?
    } else {
        text
    };
    let scene = deck::parse(&text, &format!("{name}.toml"), name)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let at = |e: String| format!("{}: [validation]: {e}", path.display());
    let reference = v.reference.evaluate(&scene).map_err(at)?;
    let (extract, measured) = v.measure.prepare(&scene).map_err(at)?;
    let formula = match &v.note {
        Some(note) => format!("{}; {note}", reference.formula),
        None => reference.formula,
    };
    Ok(Case {
        name: name.to_string(),
        quantity,
        unit: v.unit,
        kind: v.kind,
        reference: reference.value,
        thesis: v.thesis,
        formula,
        formula_of: Some(v.reference),
        measure_of: Some(v.measure),
        tolerance_percent: tolerance,
        band,
        deck: text,
        extract,
        damage_views: v.damage_views,
        plot: Some(Plot {
            x_label: v.plot.x,
            y_label: v.plot.y,
            reference: reference.curve,
            measured,
        }),
    })
}

/// The deck of a case file as a table, without its `[validation]`.
pub fn deck_table(path: &Path) -> Result<toml::Table, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut deck: toml::Table = toml::from_str(&text).map_err(|e| located(path, &text, &e))?;
    deck.remove("validation");
    Ok(deck)
}

/// Merges `patch` over `base`: tables key by key, arrays of tables item by item — by `name`
/// where the patch's item has one, else by position — and anything else replaced.
fn merge(base: &mut toml::Table, patch: &toml::Table, path: &str) -> Result<(), String> {
    use toml::Value;
    for (key, value) in patch {
        let here = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        match (base.get_mut(key), value) {
            (Some(Value::Table(b)), Value::Table(p)) => merge(b, p, &here)?,
            (Some(Value::Array(b)), Value::Array(p)) if p.iter().all(Value::is_table) => {
                for (k, item) in p.iter().enumerate() {
                    let item = item.as_table().expect("checked: a table");
                    let target = match item.get("name").and_then(Value::as_str) {
                        Some(n) => b
                            .iter_mut()
                            .find(|x| x.get("name").and_then(Value::as_str) == Some(n)),
                        None => b.get_mut(k),
                    };
                    match target.and_then(Value::as_table_mut) {
                        Some(t) => merge(t, item, &format!("{here}[{k}]"))?,
                        None => {
                            return Err(format!("{here}[{k}]: no such entry in the deck to change"))
                        }
                    }
                }
            }
            _ => {
                base.insert(key.clone(), value.clone());
            }
        }
    }
    Ok(())
}

/// A TOML error with the file and line it is at.
fn located(path: &Path, text: &str, e: &toml::de::Error) -> String {
    match e.span() {
        Some(s) => {
            let line = text[..s.start.min(text.len())].matches('\n').count() + 1;
            format!("{}:{line}: {}", path.display(), e.message().trim())
        }
        None => format!("{}: {}", path.display(), e.message().trim()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_patch_changes_tables_by_key_and_arrays_by_name_or_position() {
        let mut base = table(
            "[lattice]\nspacing = 1\nm = 3\n[[geometry]]\nmax = 1\n[[probe]]\nname = \"a\"\nat = 1\n[[probe]]\nname = \"b\"\nat = 2\n",
        );
        let patch = table(
            "[lattice]\nspacing = 2\n[[geometry]]\nmax = 5\n[[probe]]\nname = \"b\"\nat = 7\n",
        );
        merge(&mut base, &patch, "").unwrap();
        let want = table(
            "[lattice]\nspacing = 2\nm = 3\n[[geometry]]\nmax = 5\n[[probe]]\nname = \"a\"\nat = 1\n[[probe]]\nname = \"b\"\nat = 7\n",
        );
        assert_eq!(base, want);
        let e = merge(&mut base, &table("[[probe]]\nname = \"c\"\nat = 1\n"), "").unwrap_err();
        assert!(e.contains("probe[0]"), "{e}");
    }
}
