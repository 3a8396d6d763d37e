//! The `Converter`: what every section's check needs (the file for messages, where each byte
//! of the deck is, the unit system), and `scene`, which checks the sections one by one and
//! composes the [`Scene`] from their parts. The sections' own checks are in the sibling
//! modules, one `impl Converter` block each.

use super::sections::DeckFile;
use super::spec::{ModelLines, Scene};
use super::DeckError;
use crate::input::units::UnitSystem;
use toml::Spanned;

/// Byte offset → 1-based line number.
pub(super) struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub(super) fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { starts }
    }

    pub(super) fn line(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset)
    }
}

pub(super) struct Converter {
    pub(super) file: String,
    pub(super) lines: LineIndex,
    /// The deck's unit system, once `units` is read (the first thing `scene` does).
    pub(super) sys: UnitSystem,
}

pub(super) type R<T> = Result<T, DeckError>;

impl Converter {
    pub(super) fn new(file: &str, lines: LineIndex) -> Self {
        Converter {
            file: file.to_string(),
            lines,
            sys: UnitSystem::Si,
        }
    }

    pub(super) fn error_at(&self, line: usize, message: String) -> DeckError {
        DeckError {
            file: self.file.clone(),
            line: Some(line),
            message,
        }
    }

    pub(super) fn err<T>(&self, line: usize, message: impl Into<String>) -> R<T> {
        Err(self.error_at(line, message.into()))
    }

    pub(super) fn line_of<T>(&self, s: &Spanned<T>) -> usize {
        self.lines.line(s.span().start)
    }

    /// The whole deck, checked section by section. The order of the checks is the order in
    /// which a deck's mistakes are reported: the first one found is the one the user sees.
    pub(super) fn scene(mut self, deck: DeckFile, stem: &str) -> R<Scene> {
        let units_line = self.line_of(&deck.units);
        self.sys = UnitSystem::from_name(deck.units.get_ref())
            .or_else(|e| self.err(units_line, format!("units: {e}")))?;
        let (names, materials, material_lines) = self.materials(&deck.materials)?;
        let lattice = self.lattice(&deck.lattice)?;
        let any_periodic = !deck.lattice.get_ref().periodic.is_empty();
        let model = self.model(deck.model, lattice.spacing, any_periodic)?;
        let ops = self.geometry(&deck.geometry, &names)?;
        let bars = self.bars(&deck.bar, lattice.spacing, &names, &materials)?;
        if ops.is_empty() && bars.is_empty() {
            return self.err(
                1,
                "the deck has no [[geometry]] or [[bar]] entry: there are no particles",
            );
        }
        let bondless = (!model.bonded).then_some(model.name.as_str());
        let time = self.time(deck.time, bondless)?;
        let boundaries = self.boundaries(&deck.boundary)?;
        let loads = self.loads(&deck.load, &boundaries)?;
        let initial = self.initial(&deck.initial)?;
        let velocity = self.velocity(deck.velocity.as_ref())?;
        let output = self.output(deck.output.as_ref(), stem)?;
        let parallel = self.parallel(deck.parallel.as_ref())?;
        let solver = self.solver(deck.solver.as_ref(), bondless)?;
        let pair = self.pair(deck.pair.as_ref(), &names)?;
        if let (Some(p), false) = (&pair, solver.item == super::spec::SolverSpec::Explicit) {
            return self.err(
                p.line,
                "[pair] acts in explicit time stepping only: its neighbour lists follow the particles step by step; remove [solver] or the [pair] section",
            );
        }
        let thermostat = self.thermostat(deck.thermostat.as_ref(), &names, &time, &solver)?;
        // The names of the periodic axes are checked here, after the sections above, as they
        // always have been, so that a deck with several mistakes still reports the same first.
        let periodic = self.periodic(&deck.lattice)?;
        let probes = self.probes(&deck.probe)?;
        let bonded = bondless.is_none();
        let bond_drops = (pair.is_some() && bonded) || parallel.shuffle_every > 0;
        let analyses = self.analyses(&deck.analysis, lattice.spacing, !bonded, bond_drops)?;
        let pair_line = pair.as_ref().map(|p| p.line);
        let deform = self.deform(deck.deform.as_ref(), periodic, !bonded, pair_line)?;
        Ok(Scene {
            file: self.file.clone(),
            periodic,
            parallel,
            title: deck.title.unwrap_or_else(|| stem.to_string()),
            units: self.sys,
            model: model.name,
            model_options: model.options,
            model_lines: ModelLines {
                model: model.line,
                materials: material_lines,
            },
            horizon: model.horizon,
            spacing: lattice.spacing,
            partial_volume: model.partial_volume,
            surface_correction: model.surface_correction,
            materials,
            lattice,
            ops,
            bars,
            time,
            boundaries,
            loads,
            initial,
            velocity,
            output,
            probes,
            analyses,
            solver,
            pair,
            thermostat,
            deform,
        })
    }

    /// The index of the material called `name`, for an entry at `line` that names it.
    pub(super) fn material_id(&self, names: &[String], name: &str, line: usize) -> R<u16> {
        match names.iter().position(|n| n == name) {
            Some(i) => Ok(i as u16),
            None => self.err(
                line,
                format!(
                    "unknown material '{name}' (materials: {})",
                    names.join(", ")
                ),
            ),
        }
    }

    /// A vector from the deck, refused if any component is not a finite number.
    pub(super) fn finite3(&self, v: [f64; 3], line: usize, what: &str) -> R<[f64; 3]> {
        if v.iter().all(|c| c.is_finite()) {
            Ok(v)
        } else {
            self.err(line, format!("{what} must be finite numbers (got {v:?})"))
        }
    }
}

/// Whether `n` may name a boundary, a load or a probe (it becomes a column or a file name).
pub(super) fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}
