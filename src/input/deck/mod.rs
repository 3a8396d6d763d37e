//! The input deck: TOML in, engine types out.
//!
//! This is the only module that knows TOML. Unknown keys are errors with their line (serde's
//! `deny_unknown_fields`, located by the toml crate); every quantity may carry units, which are
//! checked against the dimension the key expects and converted once into the deck's unit system
//! (see [`crate::input::units`]); anything semantically wrong is reported with the entry's line.
//!
//! A deck is read in two passes. serde reads the text into the section structs of `sections`
//! (layout and spelling). The `Converter` (`convert.rs`) then checks each section and converts
//! it into its part of the [`Scene`] (the types of `spec.rs`), one method per section:
//! `[model]` and `[materials]` in `model.rs`, `[lattice]` in `lattice.rs`, `[[geometry]]` and
//! the shapes of regions in `shape.rs`, `[[bar]]` in `bar.rs`, `[[boundary]]`, `[[load]]` and
//! `[[initial]]` in `boundary.rs`, `[time]` and `[solver]` in `time.rs`, `[output]`,
//! `[[probe]]` and `[[analysis]]` in `output.rs`, `[parallel]` in `parallel.rs`, `[thermostat]` in
//! `thermostat.rs`. A deck in `units = "lj"` is first searched for values written with
//! units, which it cannot take (`plain.rs`).

mod bar;
mod boundary;
mod convert;
mod deform;
mod lattice;
mod model;
mod output;
mod pair;
mod parallel;
mod plain;
mod sections;
mod shape;
mod spec;
mod thermostat;
mod time;

pub use super::materials::MaterialLines;
pub use spec::{
    AnalysisKind, AnalysisSpec, BarSpec, BoundarySpec, Colouring, CriticalStep, DeformSpec,
    Equilibrium, InitialSpec, LoadKind, LoadSpec, Located, ModelLines, OutputSpec, ParallelSpec,
    PeakStop, ProbeSpec, Region, RunLength, Scene, SolverSpec, ThermostatKind, ThermostatSpec,
    TimeSpec, VelocitySpec,
};
pub use time::DEFAULT_KRYLOV_ITERATIONS;

use convert::{Converter, LineIndex};
use sections::DeckFile;
use std::fmt;
use std::path::Path;

/// A deck problem, with the file and line it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct DeckError {
    pub file: String,
    pub line: Option<usize>,
    pub message: String,
}

impl fmt::Display for DeckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.file, l, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for DeckError {}

/// Reads and checks a deck file.
pub fn load(path: &Path) -> Result<Scene, DeckError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DeckError {
        file: file.clone(),
        line: None,
        message: format!("cannot read the deck: {e}"),
    })?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "run".into());
    parse(&text, &file, &stem)
}

/// Checks a deck given as text; `file` names it in messages, `stem` names the default output.
pub fn parse(text: &str, file: &str, stem: &str) -> Result<Scene, DeckError> {
    let lines = LineIndex::new(text);
    let deck: DeckFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| lines.line(s.start));
        DeckError {
            file: file.to_string(),
            line,
            message: e.message().trim().to_string(),
        }
    })?;
    if crate::input::units::UnitSystem::from_name(deck.units.get_ref())
        == Ok(crate::input::units::UnitSystem::Lj)
    {
        plain::refuse_units(text, file, &lines)?;
    }
    Converter::new(file, lines).scene(deck, stem)
}
