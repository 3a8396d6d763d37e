//! The input deck: TOML in, engine types out.
//!
//! This is the only module that knows TOML. Unknown keys are errors with their line (serde's
//! `deny_unknown_fields`, located by the toml crate); every quantity may carry units, which are
//! checked against the dimension the key expects and converted once into the deck's unit system
//! (see [`crate::input::units`]); anything semantically wrong is reported with the entry's line.

pub use super::materials::MaterialLines;
use super::materials::{self, MaterialSection};
use crate::engine::boundary::{History, Motion, TEMPERATURE};
use crate::engine::simulation::Integrator;
use crate::input::bars::Prestrain;
use crate::input::geometry::{Bar, Lattice, Op, Shape};
use crate::input::procs::{Procs, Walls};
use crate::input::units::{
    AccelerationVector, Area, ForceVector, Length, Position, Stress, Time, UnitSystem, Vector,
    VelocityVector,
};
use crate::model::{Dimension, Material, ModelError, OptionValue};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;

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

// ---------------------------------------------------------------------------------------------
// The TOML layout.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DeckFile {
    title: Option<String>,
    units: Spanned<String>,
    model: Spanned<ModelSection>,
    lattice: Spanned<LatticeSection>,
    materials: Spanned<BTreeMap<String, Spanned<MaterialSection>>>,
    #[serde(default)]
    geometry: Vec<Spanned<ShapeSpec>>,
    #[serde(default)]
    bar: Vec<Spanned<BarSection>>,
    time: Spanned<TimeSection>,
    #[serde(default)]
    boundary: Vec<Spanned<BoundarySection>>,
    #[serde(default)]
    load: Vec<Spanned<LoadSection>>,
    #[serde(default)]
    initial: Vec<Spanned<InitialSection>>,
    #[serde(default)]
    output: Option<Spanned<OutputSection>>,
    #[serde(default)]
    probe: Vec<Spanned<ProbeSection>>,
    #[serde(default)]
    parallel: Option<Spanned<ParallelSection>>,
    #[serde(default)]
    solver: Option<Spanned<SolverSection>>,
    /// What `pdq validate` reads (validation/README.md); a run ignores it.
    #[serde(default, rename = "validation")]
    _validation: Option<toml::Table>,
}

/// `[solver]`: explicit time stepping (the default) or quasi-static adaptive dynamic
/// relaxation.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SolverSection {
    kind: String,
    load_steps: Option<u64>,
    tolerance: Option<f64>,
    max_iterations: Option<u64>,
}

/// `procs` is `[nx, ny, nz]` or `"auto"`.
#[derive(Deserialize)]
#[serde(untagged)]
enum ProcsSpec {
    Given([i64; 3]),
    Word(String),
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ParallelSection {
    procs: Option<ProcsSpec>,
    threads: Option<i64>,
    walls: Option<String>,
    shuffle_every: Option<i64>,
    skin: Option<f64>,
    /// The thesis's cell factor: cells are this many horizons wide (1 + skin).
    cell_factor: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelSection {
    name: String,
    horizon: Option<Length>,
    /// Horizon as a multiple of the lattice spacing.
    m: Option<f64>,
    partial_volume: Option<bool>,
    /// "none" (default) or "energy" (docs/theory.md §6).
    surface_correction: Option<String>,
    #[serde(default)]
    options: BTreeMap<String, OptionSpec>,
}

/// A model option: a number or a word.
#[derive(Deserialize)]
#[serde(untagged)]
enum OptionSpec {
    Number(f64),
    Integer(i64),
    Word(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LatticeSection {
    spacing: Length,
    origin: Option<Position>,
    /// Axes that wrap around ("x", "y", "z"): the lattice box repeats along them.
    #[serde(default)]
    periodic: Vec<String>,
    /// Random offsets of the sites, as a fraction of the spacing.
    #[serde(default)]
    jitter: f64,
    #[serde(default)]
    seed: u64,
}

/// A shape for geometry entries and regions; which keys apply depends on `shape`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ShapeSpec {
    shape: Option<String>,
    /// Geometry only: "add" (default) or "subtract".
    op: Option<String>,
    /// Geometry only: material filled in by "add".
    material: Option<String>,
    /// Regions only: explicit global particle ids.
    ids: Option<Vec<u32>>,
    min: Option<Position>,
    max: Option<Position>,
    base: Option<Position>,
    center: Option<Position>,
    axis: Option<AxisSpec>,
    length: Option<Length>,
    radius: Option<Length>,
    polygon: Option<Vec<[Length; 2]>>,
    from: Option<Length>,
    to: Option<Length>,
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
enum AxisSpec {
    Name(String),
    Direction([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BarSection {
    material: String,
    area: Area,
    from: Position,
    to: Option<Position>,
    direction: Option<[f64; 3]>,
    azimuth: Option<f64>,
    elevation: Option<f64>,
    length: Option<Length>,
    spacing: Option<Length>,
    prestrain: Option<f64>,
    prestress: Option<Stress>,
    transfer_length: Option<Length>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeSection {
    steps: Option<u64>,
    duration: Option<Time>,
    dt: Option<Time>,
    safety_factor: Option<f64>,
    critical_step: Option<String>,
    static_until: Option<Time>,
    force_dt: Option<bool>,
    integrator: Option<String>,
    stop_at_broken_bonds: Option<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HistorySpec {
    ramp: Option<Time>,
    table: Option<Vec<(Time, f64)>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoundarySection {
    name: String,
    region: ShapeSpec,
    fixed: Option<Vec<String>>,
    velocity: Option<VelocityVector>,
    displacement: Option<Position>,
    /// Prescribed temperature (models with a temperature DOF), in the deck's degrees.
    temperature: Option<f64>,
    components: Option<Vec<String>>,
    history: Option<HistorySpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadSection {
    name: String,
    region: Option<ShapeSpec>,
    force_per_particle: Option<ForceVector>,
    total_force: Option<ForceVector>,
    body_force: Option<Vector<1, -2, -2>>,
    gravity: Option<AccelerationVector>,
    /// Heat per unit time and area into a region one lattice layer thick.
    heat_flux: Option<f64>,
    /// Heat per unit time and volume.
    heat_source: Option<f64>,
    /// Heat per unit time shared by volume.
    total_heat: Option<f64>,
    history: Option<HistorySpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialSection {
    region: Option<ShapeSpec>,
    velocity: Option<VelocityVector>,
    /// Radians per unit time (models with rotations).
    angular_velocity: Option<Vector<0, 0, -1>>,
    /// Models with a temperature DOF.
    temperature: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct OutputSection {
    directory: Option<String>,
    history_every: Option<u64>,
    frames_every: Option<u64>,
    progress: Option<bool>,
    final_state: Option<bool>,
    checkpoint_every: Option<u64>,
    checkpoint_minutes: Option<f64>,
    checkpoint_keep: Option<usize>,
    restart: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProbeSection {
    name: String,
    at: Position,
    stop_beyond: Option<Length>,
}

// ---------------------------------------------------------------------------------------------
// What the engine gets.

/// A set of particles, selected in the reference configuration.
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    All,
    Shape(Shape),
    Ids(Vec<u32>),
}

/// How long to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunLength {
    Steps(u64),
    Duration(f64),
}

/// How the run is cut into procCubes and run.
#[derive(Clone, Debug, PartialEq)]
pub struct ParallelSpec {
    pub line: usize,
    pub procs: Procs,
    /// Worker threads (one procCube each) when not under MPI.
    pub threads: usize,
    pub walls: Walls,
    /// Steps between particle shuffles (0: never).
    pub shuffle_every: u64,
    /// Cells are the horizon times 1 + skin, so that stretched bonds stay between neighbours.
    pub skin: f64,
}

/// How the critical time step of an explicit run is found (`[time] critical_step`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CriticalStep {
    /// The Silling–Askari bound, per particle from its bonds (docs/theory.md §4).
    Bound,
    /// 2/√λ_max(M⁻¹K), the limit of central differences, with λ_max measured by a Lanczos run
    /// at setup (`spectrum::critical_time_step`).
    Measured,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TimeSpec {
    pub length: RunLength,
    pub dt: Option<f64>,
    pub safety_factor: f64,
    /// What Δt_crit is: the Silling–Askari bound, or measured from the stiffest mode.
    pub critical_step: CriticalStep,
    /// Reach this time by one static (implicit) solve, then step explicitly from rest there
    /// (`[time] static_until`); `None`: step from time 0.
    pub static_until: Option<f64>,
    pub force_dt: bool,
    pub integrator: Integrator,
    /// End the run after the first step (load step) at which at least this many bonds have
    /// broken; 0 = run to the end.
    pub stop_at_broken_bonds: u64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct BoundarySpec {
    pub name: String,
    pub line: usize,
    pub region: Region,
    pub dofs: Vec<usize>,
    pub motion: Motion,
    pub history: History,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadKind {
    /// The vector on every particle of the region.
    PerParticle([f64; 3]),
    /// The vector shared among the region's particles in proportion to their volumes.
    Total([f64; 3]),
    /// Force per unit volume.
    BodyForce([f64; 3]),
    /// Acceleration, applied as mass × g.
    Gravity([f64; 3]),
    /// Heat per unit time and area, on a region one lattice layer thick (V_i / spacing each).
    HeatFlux(f64),
    /// Heat per unit time and volume.
    HeatSource(f64),
    /// Heat per unit time, shared by volume.
    TotalHeat(f64),
}

impl LoadKind {
    /// Whether the load heats (first-order temperature DOF) rather than pushes.
    pub fn is_heat(&self) -> bool {
        matches!(
            self,
            LoadKind::HeatFlux(_) | LoadKind::HeatSource(_) | LoadKind::TotalHeat(_)
        )
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct LoadSpec {
    pub name: String,
    pub line: usize,
    pub region: Region,
    pub kind: LoadKind,
    pub history: History,
}

#[derive(Clone, Debug, PartialEq)]
pub struct InitialSpec {
    pub line: usize,
    pub region: Region,
    pub velocity: Option<[f64; 3]>,
    pub angular_velocity: Option<[f64; 3]>,
    pub temperature: Option<f64>,
}

/// How the deck's loads are followed in time.
#[derive(Clone, Debug, PartialEq)]
pub enum SolverSpec {
    /// Explicit time integration (`[time]` integrator).
    Explicit,
    /// Adaptive dynamic relaxation to equilibrium at each of `load_steps` equal steps of the
    /// loads' time history (docs/theory.md §5).
    Relaxation {
        load_steps: u64,
        /// Converged when |residual force| ≤ tolerance × |applied force and reactions|.
        tolerance: f64,
        /// Force evaluations per load step (ADR), Newton iterations per load step (implicit).
        max_iterations: u64,
        /// Newton's method with the assembled tangent (`kind = "implicit"`) instead of ADR.
        implicit: bool,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct OutputSpec {
    pub directory: PathBuf,
    pub history_every: u64,
    pub frames_every: u64,
    pub progress: bool,
    /// Write `final_positions.csv` and `broken_bonds.csv` at the end.
    pub final_state: bool,
    /// A checkpoint every N steps (0: none on a step count).
    pub checkpoint_every: u64,
    /// A checkpoint every so many minutes of wall time (0: none on the clock).
    pub checkpoint_minutes: f64,
    /// Checkpoints kept on disk (the newest ones).
    pub checkpoint_keep: usize,
    /// Resume from this checkpoint file, or the newest in this directory.
    pub restart: Option<PathBuf>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ProbeSpec {
    pub name: String,
    pub line: usize,
    pub at: [f64; 3],
    /// The run ends at the first history row where this probe's displacement is longer than
    /// this (`stop_beyond`; infinite when not given).
    pub stop_beyond: f64,
}

/// A deck after checking and unit conversion: everything in the deck's unit system.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub file: String,
    /// Axes that wrap around.
    pub periodic: [bool; 3],
    pub parallel: ParallelSpec,
    pub title: String,
    pub units: UnitSystem,
    pub model: String,
    pub model_line: usize,
    pub model_options: Vec<(String, OptionValue)>,
    /// Where each material and its keys are (same order as `materials`), for messages.
    pub material_lines: Vec<MaterialLines>,
    /// Deck line of `[time]`, for messages.
    pub time_line: usize,
    pub horizon: f64,
    pub spacing: f64,
    pub partial_volume: bool,
    /// Apply the energy surface correction to bond-based models.
    pub surface_correction: bool,
    pub materials: Vec<Material>,
    pub lattice: Lattice,
    pub ops: Vec<Op>,
    /// Deck line of each geometry entry, for messages.
    pub op_lines: Vec<usize>,
    pub bars: Vec<Bar>,
    pub bar_lines: Vec<usize>,
    /// Initial stretch of each bar's own bonds (zero strain: none); see `input/bars.rs`.
    pub bar_prestrain: Vec<Prestrain>,
    pub time: TimeSpec,
    pub boundaries: Vec<BoundarySpec>,
    pub loads: Vec<LoadSpec>,
    pub initial: Vec<InitialSpec>,
    pub output: OutputSpec,
    pub probes: Vec<ProbeSpec>,
    pub solver: SolverSpec,
    /// Deck line of `[solver]` (0 if absent), for messages.
    pub solver_line: usize,
}

impl Scene {
    /// An error from building the model: located at the material it names, else at `[model]`.
    /// An error from building the model: at the key or the material it is about, else at
    /// `[model]`.
    pub fn model_error(&self, e: &ModelError) -> DeckError {
        let line = match e {
            ModelError::Material { material, .. } => self
                .material_lines
                .get(*material as usize)
                .map_or(self.model_line, |m| m.of(e)),
            ModelError::Model(_) => self.model_line,
        };
        self.error(Some(line), format!("[model] {e}"))
    }

    /// An error located at `line` of this deck.
    pub fn error(&self, line: Option<usize>, message: impl Into<String>) -> DeckError {
        DeckError {
            file: self.file.clone(),
            line,
            message: message.into(),
        }
    }
}

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
    Converter {
        file: file.to_string(),
        lines,
        sys: UnitSystem::Si,
    }
    .scene(deck, stem)
}

/// Byte offset → 1-based line number.
struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { starts }
    }

    fn line(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset)
    }
}

struct Converter {
    file: String,
    lines: LineIndex,
    sys: UnitSystem,
}

type R<T> = Result<T, DeckError>;

impl Converter {
    fn error_at(&self, line: usize, message: String) -> DeckError {
        DeckError {
            file: self.file.clone(),
            line: Some(line),
            message,
        }
    }

    fn err<T>(&self, line: usize, message: impl Into<String>) -> R<T> {
        Err(self.error_at(line, message.into()))
    }

    fn line_of<T>(&self, s: &Spanned<T>) -> usize {
        self.lines.line(s.span().start)
    }

    fn scene(mut self, deck: DeckFile, stem: &str) -> R<Scene> {
        let units_line = self.line_of(&deck.units);
        self.sys = UnitSystem::from_name(deck.units.get_ref())
            .or_else(|e| self.err(units_line, format!("units: {e}")))?;
        let sys = self.sys;

        let (mat_names, materials, material_lines) = self.materials(&deck.materials)?;
        let material_id = |name: &str, line: usize| -> R<u16> {
            match mat_names.iter().position(|n| n == name) {
                Some(i) => Ok(i as u16),
                None => self.err(
                    line,
                    format!(
                        "unknown material '{name}' (materials: {})",
                        mat_names.join(", ")
                    ),
                ),
            }
        };

        // Lattice and horizon.
        let lat_line = self.line_of(&deck.lattice);
        let spacing = deck.lattice.get_ref().spacing.value(sys);
        if !(spacing.is_finite() && spacing > 0.0) {
            return self.err(
                lat_line,
                format!("lattice spacing must be > 0 (got {spacing})"),
            );
        }
        let lattice_periodic = deck.lattice.get_ref().periodic.clone();
        let (jitter, seed) = (deck.lattice.get_ref().jitter, deck.lattice.get_ref().seed);
        if !(0.0..0.5).contains(&jitter) {
            return self.err(
                lat_line,
                format!("[lattice] jitter = {jitter}: give a fraction of the spacing in [0, 0.5)"),
            );
        }
        if jitter > 0.0 && !lattice_periodic.is_empty() {
            return self.err(
                lat_line,
                "[lattice] jitter with periodic axes is not supported (the period is taken from the particles' extent)".to_string(),
            );
        }
        let origin = deck
            .lattice
            .get_ref()
            .origin
            .map(|o| o.value(sys))
            .unwrap_or([0.0; 3]);
        let model_line = self.line_of(&deck.model);
        let ms = deck.model.into_inner();
        let surface_correction = match ms.surface_correction.as_deref() {
            None | Some("none") => false,
            Some("energy") => true,
            Some(other) => {
                return self.err(
                    model_line,
                    format!(
                        "[model] unknown surface_correction '{other}' (use \"none\" or \"energy\")"
                    ),
                )
            }
        };
        if surface_correction && !lattice_periodic.is_empty() {
            return self.err(
                model_line,
                "[model] surface_correction = \"energy\" needs a body without periodic axes (the correction is found on the scene without its images)",
            );
        }
        let horizon = match (ms.horizon, ms.m) {
            (Some(h), None) => h.value(sys),
            (None, Some(m)) => m * spacing,
            (None, None) => {
                return self.err(
                    model_line,
                    "[model] needs 'horizon' or 'm' (horizon / spacing)",
                )
            }
            (Some(_), Some(_)) => {
                return self.err(model_line, "[model] give 'horizon' or 'm', not both")
            }
        };
        if !(horizon.is_finite() && horizon > 0.0) {
            return self.err(
                model_line,
                format!("[model] horizon must be > 0 (got {horizon})"),
            );
        }
        if horizon < spacing {
            return self.err(
                model_line,
                format!("[model] horizon {horizon} is smaller than the lattice spacing {spacing}: particles would have no bonds"),
            );
        }

        // Geometry.
        let mut ops = Vec::new();
        let mut op_lines = Vec::new();
        for (k, g) in deck.geometry.iter().enumerate() {
            let line = self.line_of(g);
            let g = g.get_ref();
            let ctx = format!("geometry entry {k}");
            if g.ids.is_some() {
                return self.err(
                    line,
                    format!("{ctx}: 'ids' selects particles in regions, not in geometry"),
                );
            }
            let shape = self.shape(g, line, &ctx)?;
            match g.op.as_deref().unwrap_or("add") {
                "add" => {
                    let Some(mat) = &g.material else {
                        return self.err(line, format!("{ctx}: an 'add' entry needs 'material'"));
                    };
                    ops.push(Op::Add {
                        shape,
                        material: material_id(mat, line)?,
                    });
                }
                "subtract" => {
                    if g.material.is_some() {
                        return self
                            .err(line, format!("{ctx}: a 'subtract' entry takes no material"));
                    }
                    ops.push(Op::Subtract { shape });
                }
                other => {
                    return self.err(
                        line,
                        format!("{ctx}: op must be \"add\" or \"subtract\", not \"{other}\""),
                    )
                }
            }
            op_lines.push(line);
        }
        let mut bars = Vec::new();
        let mut bar_lines = Vec::new();
        let mut bar_prestrain = Vec::new();
        for (k, b) in deck.bar.iter().enumerate() {
            let line = self.line_of(b);
            let bar = self.bar(b.get_ref(), k, line, spacing, &material_id)?;
            bar_prestrain.push(self.prestrain(
                b.get_ref(),
                k,
                line,
                &materials[bar.material as usize],
            )?);
            bars.push(bar);
            bar_lines.push(line);
        }
        if ops.is_empty() && bars.is_empty() {
            return self.err(
                1,
                "the deck has no [[geometry]] or [[bar]] entry: there are no particles",
            );
        }

        // Time.
        let time_line = self.line_of(&deck.time);
        let t = deck.time.into_inner();
        let length = match (t.steps, t.duration) {
            (Some(0), None) => return self.err(time_line, "[time] steps must be ≥ 1"),
            (Some(n), None) => RunLength::Steps(n),
            (None, Some(d)) => {
                let d = d.value(sys);
                if !(d.is_finite() && d > 0.0) {
                    return self.err(time_line, format!("[time] duration must be > 0 (got {d})"));
                }
                RunLength::Duration(d)
            }
            (None, None) => return self.err(time_line, "[time] needs 'steps' or 'duration'"),
            (Some(_), Some(_)) => {
                return self.err(time_line, "[time] give 'steps' or 'duration', not both")
            }
        };
        let dt = t.dt.map(|d| d.value(sys));
        if let Some(d) = dt {
            if !(d.is_finite() && d > 0.0) {
                return self.err(time_line, format!("[time] dt must be > 0 (got {d})"));
            }
        }
        let safety_factor = t.safety_factor.unwrap_or(0.8);
        if !(safety_factor > 0.0 && safety_factor <= 1.0) {
            return self.err(
                time_line,
                format!("[time] safety_factor must lie in (0, 1] (got {safety_factor})"),
            );
        }
        if dt.is_some() && t.safety_factor.is_some() {
            return self.err(time_line, "[time] give 'dt' or 'safety_factor', not both");
        }
        let critical_step = match t.critical_step.as_deref().unwrap_or("bound") {
            "bound" => CriticalStep::Bound,
            "measured" => CriticalStep::Measured,
            other => {
                return self.err(
                    time_line,
                    format!(
                        "[time] critical_step must be \"bound\" or \"measured\" (got \"{other}\")"
                    ),
                )
            }
        };
        let static_until = match t.static_until.map(|d| d.value(sys)) {
            None => None,
            Some(s) if !(s.is_finite() && s > 0.0) => {
                return self.err(
                    time_line,
                    format!("[time] static_until must be a time > 0 (got {s})"),
                );
            }
            Some(s) => match length {
                RunLength::Duration(d) if s >= d => {
                    return self.err(
                        time_line,
                        format!("[time] static_until = {s:e} is not before the end of the run (duration {d:e}): nothing would be left to step"),
                    );
                }
                _ => Some(s),
            },
        };
        let stop_at_broken_bonds = match t.stop_at_broken_bonds {
            None => 0,
            Some(n) if n >= 1 => n as u64,
            Some(n) => {
                return self.err(
                    time_line,
                    format!("[time] stop_at_broken_bonds must be a count >= 1 (got {n}); leave it out to run to the end"),
                )
            }
        };
        let integrator = match t.integrator.as_deref().unwrap_or("verlet") {
            "verlet" | "velocity-verlet" => Integrator::VelocityVerlet,
            "euler" | "semi-implicit-euler" => Integrator::SemiImplicitEuler,
            other => {
                return self.err(
                    time_line,
                    format!("[time] unknown integrator '{other}' (use \"verlet\" or \"euler\")"),
                )
            }
        };

        // Boundary conditions, loads, initial velocities.
        let mut boundaries = Vec::new();
        let mut names = Vec::new();
        for b in &deck.boundary {
            let line = self.line_of(b);
            let spec = self.boundary(b.get_ref(), line)?;
            if names.contains(&spec.name) {
                return self.err(line, format!("boundary name '{}' is used twice", spec.name));
            }
            names.push(spec.name.clone());
            boundaries.push(spec);
        }
        let mut loads = Vec::new();
        for l in &deck.load {
            let line = self.line_of(l);
            let spec = self.load(l.get_ref(), line)?;
            if names.contains(&spec.name) {
                return self.err(line, format!("load name '{}' is used twice", spec.name));
            }
            names.push(spec.name.clone());
            loads.push(spec);
        }
        let mut initial = Vec::new();
        for i in &deck.initial {
            let line = self.line_of(i);
            let s = i.get_ref();
            let region = match &s.region {
                Some(r) => self.region(r, line, "initial")?,
                None => Region::All,
            };
            let vector = |v: Option<[f64; 3]>, what: &str| -> R<Option<[f64; 3]>> {
                v.map(|v| self.finite3(v, line, &format!("initial: {what}")))
                    .transpose()
            };
            let spec = InitialSpec {
                line,
                region,
                velocity: vector(s.velocity.map(|v| v.value(sys)), "velocity")?,
                angular_velocity: vector(
                    s.angular_velocity.map(|v| v.value(sys)),
                    "angular_velocity",
                )?,
                temperature: s.temperature,
            };
            if let Some(t) = spec.temperature {
                if !t.is_finite() {
                    return self.err(
                        line,
                        format!("initial: temperature must be finite (got {t})"),
                    );
                }
            }
            if spec.velocity.is_none()
                && spec.angular_velocity.is_none()
                && spec.temperature.is_none()
            {
                return self.err(
                    line,
                    "initial: give 'velocity', 'angular_velocity' or 'temperature'",
                );
            }
            initial.push(spec);
        }

        // Output and probes.
        let (out, out_line) = match &deck.output {
            Some(o) => (o.get_ref(), self.line_of(o)),
            None => (&OutputSection::default(), 1),
        };
        let history_every = out.history_every.unwrap_or(10);
        if history_every == 0 {
            return self.err(out_line, "[output] history_every must be ≥ 1");
        }
        let output = OutputSpec {
            directory: PathBuf::from(
                out.directory
                    .clone()
                    .unwrap_or_else(|| format!("out/{stem}")),
            ),
            history_every,
            frames_every: out.frames_every.unwrap_or(0),
            progress: out.progress.unwrap_or(true),
            final_state: out.final_state.unwrap_or(false),
            checkpoint_every: out.checkpoint_every.unwrap_or(0),
            checkpoint_minutes: out.checkpoint_minutes.unwrap_or(0.0),
            checkpoint_keep: out.checkpoint_keep.unwrap_or(3),
            restart: out.restart.as_ref().map(PathBuf::from),
        };
        if !(output.checkpoint_minutes.is_finite() && output.checkpoint_minutes >= 0.0) {
            return self.err(out_line, "[output] checkpoint_minutes must be ≥ 0");
        }
        if output.checkpoint_keep == 0 {
            return self.err(out_line, "[output] checkpoint_keep must be ≥ 1");
        }
        let parallel = self.parallel(deck.parallel.as_ref())?;
        let (solver, solver_line) = match &deck.solver {
            None => (SolverSpec::Explicit, 0),
            Some(sec) => {
                let line = self.line_of(sec);
                let s = sec.get_ref();
                let solver = match s.kind.as_str() {
                    "explicit" => {
                        if s.load_steps.is_some()
                            || s.tolerance.is_some()
                            || s.max_iterations.is_some()
                        {
                            return self.err(line, "[solver] load_steps, tolerance and max_iterations belong to kind = \"adr\" or \"implicit\"");
                        }
                        SolverSpec::Explicit
                    }
                    kind @ ("adr" | "implicit") => {
                        let implicit = kind == "implicit";
                        let load_steps = s.load_steps.unwrap_or(10);
                        let tolerance = s.tolerance.unwrap_or(if implicit { 1e-8 } else { 1e-4 });
                        let max_iterations =
                            s.max_iterations
                                .unwrap_or(if implicit { 20 } else { 100_000 });
                        if load_steps == 0 || max_iterations == 0 {
                            return self
                                .err(line, "[solver] load_steps and max_iterations must be ≥ 1");
                        }
                        if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
                            return self.err(line, format!("[solver] tolerance must lie in (0, 1), the deck gives {tolerance}"));
                        }
                        SolverSpec::Relaxation {
                            load_steps,
                            tolerance,
                            max_iterations,
                            implicit,
                        }
                    }
                    other => {
                        return self.err(
                            line,
                            format!(
                                "[solver] unknown kind '{other}' (use \"explicit\", \"adr\" or \"implicit\")"
                            ),
                        )
                    }
                };
                (solver, line)
            }
        };
        let mut periodic = [false; 3];
        for a in &lattice_periodic {
            match a.as_str() {
                "x" => periodic[0] = true,
                "y" => periodic[1] = true,
                "z" => periodic[2] = true,
                other => {
                    return self.err(
                        lat_line,
                        format!(
                        "[lattice] periodic: unknown axis '{other}' (use \"x\", \"y\" or \"z\")"
                    ),
                    )
                }
            }
        }
        let mut probes = Vec::new();
        for p in &deck.probe {
            let line = self.line_of(p);
            let name = p.get_ref().name.clone();
            if !valid_name(&name) {
                return self.err(
                    line,
                    format!("probe name '{name}' must be letters, digits, '_' or '-'"),
                );
            }
            if probes.iter().any(|p: &ProbeSpec| p.name == name) {
                return self.err(line, format!("probe name '{name}' is used twice"));
            }
            let stop_beyond = match &p.get_ref().stop_beyond {
                None => f64::INFINITY,
                Some(d) => {
                    let d = d.value(sys);
                    if !(d.is_finite() && d > 0.0) {
                        return self.err(
                            line,
                            format!("probe '{name}': stop_beyond must be a length > 0 (got {d})"),
                        );
                    }
                    d
                }
            };
            probes.push(ProbeSpec {
                name,
                line,
                at: self.finite3(p.get_ref().at.value(sys), line, "probe: 'at'")?,
                stop_beyond,
            });
        }

        Ok(Scene {
            file: self.file.clone(),
            periodic,
            parallel,
            title: deck.title.unwrap_or_else(|| stem.to_string()),
            units: sys,
            model: ms.name,
            model_line,
            model_options: ms
                .options
                .into_iter()
                .map(|(k, v)| {
                    let v = match v {
                        OptionSpec::Number(x) => OptionValue::Number(x),
                        OptionSpec::Integer(x) => OptionValue::Number(x as f64),
                        OptionSpec::Word(w) => OptionValue::Word(w),
                    };
                    (k, v)
                })
                .collect(),
            material_lines,
            time_line,
            horizon,
            spacing,
            partial_volume: ms.partial_volume.unwrap_or(true),
            surface_correction,
            materials,
            lattice: Lattice {
                spacing,
                origin,
                jitter,
                seed,
            },
            ops,
            op_lines,
            bars,
            bar_lines,
            bar_prestrain,
            time: TimeSpec {
                length,
                dt,
                safety_factor,
                critical_step,
                static_until,
                force_dt: t.force_dt.unwrap_or(false),
                integrator,
                stop_at_broken_bonds,
            },
            boundaries,
            loads,
            initial,
            output,
            probes,
            solver,
            solver_line,
        })
    }

    fn parallel(&self, section: Option<&Spanned<ParallelSection>>) -> R<ParallelSpec> {
        let (p, line) = match section {
            Some(p) => (p.get_ref(), self.line_of(p)),
            None => (&ParallelSection::default(), 0),
        };
        let procs = match &p.procs {
            None => Procs::Auto,
            Some(ProcsSpec::Word(w)) if w == "auto" => Procs::Auto,
            Some(ProcsSpec::Word(w)) => {
                return self.err(
                    line,
                    format!("[parallel] procs = \"{w}\": give [nx, ny, nz] or \"auto\""),
                )
            }
            Some(ProcsSpec::Given(v)) => {
                if v.iter().any(|&n| n < 1) {
                    return self.err(
                        line,
                        format!("[parallel] procs = {v:?}: every count must be at least 1"),
                    );
                }
                Procs::Given(v.map(|n| n as usize))
            }
        };
        let threads = match (p.threads, &procs) {
            (Some(t), _) if t < 1 => {
                return self.err(line, format!("[parallel] threads = {t}: must be at least 1"))
            }
            (Some(t), Procs::Given(v)) if t as usize != v.iter().product::<usize>() => {
                return self.err(
                    line,
                    format!(
                        "[parallel] threads = {t} but procs = {v:?} makes {} procCubes; give one procCube per thread",
                        v.iter().product::<usize>()
                    ),
                )
            }
            (Some(t), _) => t as usize,
            (None, Procs::Given(v)) => v.iter().product(),
            (None, Procs::Auto) => 1,
        };
        let walls = match p.walls.as_deref() {
            None | Some("whole") => Walls::Whole,
            Some("trimmed") => Walls::Trimmed,
            Some(other) => {
                return self.err(
                    line,
                    format!("[parallel] walls = \"{other}\": use \"whole\" or \"trimmed\""),
                )
            }
        };
        let shuffle_every = match p.shuffle_every {
            None => 0,
            Some(n) if n >= 0 => n as u64,
            Some(n) => {
                return self.err(
                    line,
                    format!("[parallel] shuffle_every = {n}: give a number of steps (0 = never)"),
                )
            }
        };
        let skin = match (p.skin, p.cell_factor) {
            (Some(_), Some(_)) => {
                return self.err(
                    line,
                    "[parallel] give 'skin' or 'cell_factor' (= 1 + skin), not both",
                )
            }
            (None, Some(f)) if f.is_finite() && (1.0..=11.0).contains(&f) => Some(f - 1.0),
            (None, Some(f)) => {
                return self.err(
                    line,
                    format!("[parallel] cell_factor = {f}: cells are cell_factor horizons wide; give a number from 1 to 11 (below 1 a cell would be thinner than the horizon)"),
                )
            }
            (s, None) => s,
        };
        let skin = match skin {
            None if shuffle_every > 0 => 0.25,
            None => 0.0,
            Some(s) if s.is_finite() && (0.0..=10.0).contains(&s) => s,
            Some(s) => {
                return self.err(
                    line,
                    format!(
                        "[parallel] skin = {s}: give a fraction of the horizon between 0 and 10"
                    ),
                )
            }
        };
        Ok(ParallelSpec {
            line,
            procs,
            threads,
            walls,
            shuffle_every,
            skin,
        })
    }

    /// The materials in name order (their index is the material id), with where each key is.
    fn materials(
        &self,
        section: &Spanned<BTreeMap<String, Spanned<MaterialSection>>>,
    ) -> R<(Vec<String>, Vec<Material>, Vec<MaterialLines>)> {
        let names: Vec<String> = section.get_ref().keys().cloned().collect();
        if names.is_empty() {
            return self.err(self.line_of(section), "[materials] defines no material");
        }
        if names.len() > u16::MAX as usize {
            return self.err(self.line_of(section), "too many materials");
        }
        let line_of = |v: &Spanned<_>| self.line_of(v);
        let (mut materials, mut lines) = (Vec::new(), Vec::new());
        for (k, (name, m)) in section.get_ref().iter().enumerate() {
            let (material, at) = materials::read(
                name,
                k as u16,
                m.get_ref(),
                self.line_of(m),
                self.sys,
                &line_of,
            )
            .map_err(|(line, message)| self.error_at(line, message))?;
            materials.push(material);
            lines.push(at);
        }
        Ok((names, materials, lines))
    }

    /// A vector from the deck, refused if any component is not a finite number.
    fn finite3(&self, v: [f64; 3], line: usize, what: &str) -> R<[f64; 3]> {
        if v.iter().all(|c| c.is_finite()) {
            Ok(v)
        } else {
            self.err(line, format!("{what} must be finite numbers (got {v:?})"))
        }
    }

    fn axis_index(&self, a: &Option<AxisSpec>, line: usize, ctx: &str) -> R<usize> {
        match a {
            Some(AxisSpec::Name(n)) => match n.as_str() {
                "x" => Ok(0),
                "y" => Ok(1),
                "z" => Ok(2),
                _ => self.err(line, format!("{ctx}: axis must be \"x\", \"y\" or \"z\" (got \"{n}\")")),
            },
            Some(AxisSpec::Direction(_)) => self.err(
                line,
                format!("{ctx}: this shape needs a coordinate axis \"x\", \"y\" or \"z\", not a direction"),
            ),
            None => self.err(line, format!("{ctx}: needs 'axis'")),
        }
    }

    fn shape(&self, g: &ShapeSpec, line: usize, ctx: &str) -> R<Shape> {
        let sys = self.sys;
        let Some(kind) = g.shape.as_deref() else {
            return self.err(
                line,
                format!("{ctx}: needs 'shape' (box, cylinder, sphere, prism or slab)"),
            );
        };
        let allowed: &[&str] = match kind {
            "box" => &["min", "max"],
            "cylinder" => &["base", "axis", "length", "radius"],
            "sphere" => &["center", "radius"],
            "prism" => &["axis", "polygon", "from", "to"],
            "slab" => &["axis", "from", "to"],
            other => {
                return self.err(
                    line,
                    format!(
                        "{ctx}: unknown shape '{other}' (box, cylinder, sphere, prism or slab)"
                    ),
                )
            }
        };
        let present = [
            ("min", g.min.is_some()),
            ("max", g.max.is_some()),
            ("base", g.base.is_some()),
            ("center", g.center.is_some()),
            ("axis", g.axis.is_some()),
            ("length", g.length.is_some()),
            ("radius", g.radius.is_some()),
            ("polygon", g.polygon.is_some()),
            ("from", g.from.is_some()),
            ("to", g.to.is_some()),
        ];
        for (key, is) in present {
            if is && !allowed.contains(&key) {
                return self.err(
                    line,
                    format!(
                        "{ctx}: a {kind} does not take '{key}' (it takes {})",
                        allowed.join(", ")
                    ),
                );
            }
            if !is && allowed.contains(&key) {
                return self.err(line, format!("{ctx}: a {kind} needs '{key}'"));
            }
        }
        let shape = match kind {
            "box" => Shape::Box {
                min: g.min.unwrap().value(sys),
                max: g.max.unwrap().value(sys),
            },
            "cylinder" => Shape::Cylinder {
                base: g.base.unwrap().value(sys),
                axis: match g.axis.clone().unwrap() {
                    AxisSpec::Direction(d) => d,
                    AxisSpec::Name(_) => {
                        let mut d = [0.0; 3];
                        d[self.axis_index(&g.axis, line, ctx)?] = 1.0;
                        d
                    }
                },
                length: g.length.unwrap().value(sys),
                radius: g.radius.unwrap().value(sys),
            },
            "sphere" => Shape::Sphere {
                center: g.center.unwrap().value(sys),
                radius: g.radius.unwrap().value(sys),
            },
            "prism" => Shape::Prism {
                axis: self.axis_index(&g.axis, line, ctx)?,
                polygon: g
                    .polygon
                    .as_ref()
                    .unwrap()
                    .iter()
                    .map(|[a, b]| [a.value(sys), b.value(sys)])
                    .collect(),
                from: g.from.unwrap().value(sys),
                to: g.to.unwrap().value(sys),
            },
            _ => Shape::Slab {
                axis: self.axis_index(&g.axis, line, ctx)?,
                from: g.from.unwrap().value(sys),
                to: g.to.unwrap().value(sys),
            },
        };
        shape
            .validate()
            .or_else(|e| self.err(line, format!("{ctx} ({kind}): {e}")))?;
        Ok(shape)
    }

    fn region(&self, r: &ShapeSpec, line: usize, ctx: &str) -> R<Region> {
        let ctx = format!("{ctx}: region");
        if r.op.is_some() || r.material.is_some() {
            return self.err(
                line,
                format!("{ctx}: 'op' and 'material' belong to geometry entries"),
            );
        }
        if let Some(ids) = &r.ids {
            if r.shape.is_some() {
                return self.err(line, format!("{ctx}: give 'ids' or 'shape', not both"));
            }
            if ids.is_empty() {
                return self.err(line, format!("{ctx}: 'ids' is empty"));
            }
            return Ok(Region::Ids(ids.clone()));
        }
        if r.shape.as_deref() == Some("all") {
            let extra = [
                r.min.is_some(),
                r.max.is_some(),
                r.base.is_some(),
                r.center.is_some(),
                r.axis.is_some(),
                r.length.is_some(),
                r.radius.is_some(),
                r.polygon.is_some(),
                r.from.is_some(),
                r.to.is_some(),
            ];
            if extra.iter().any(|&e| e) {
                return self.err(line, format!("{ctx}: shape \"all\" takes no other key"));
            }
            return Ok(Region::All);
        }
        if r.shape.is_none() {
            return self.err(
                line,
                format!(
                    "{ctx}: needs 'shape' (box, cylinder, sphere, prism, slab or all) or 'ids'"
                ),
            );
        }
        Ok(Region::Shape(self.shape(r, line, &ctx)?))
    }

    fn bar(
        &self,
        b: &BarSection,
        k: usize,
        line: usize,
        lattice_spacing: f64,
        material_id: &dyn Fn(&str, usize) -> R<u16>,
    ) -> R<Bar> {
        let sys = self.sys;
        let ctx = format!("bar {k}");
        let material = material_id(&b.material, line)?;
        let area = b.area.value(sys);
        if !(area.is_finite() && area > 0.0) {
            return self.err(line, format!("{ctx}: area must be > 0 (got {area})"));
        }
        let spacing = b.spacing.map(|s| s.value(sys)).unwrap_or(lattice_spacing);
        if !(spacing.is_finite() && spacing > 0.0) {
            return self.err(line, format!("{ctx}: spacing must be > 0 (got {spacing})"));
        }
        let from = b.from.value(sys);
        let length = b.length.map(|l| l.value(sys));
        let bar = match (b.to, b.direction, b.azimuth.is_some() || b.elevation.is_some(), length) {
            (Some(to), None, false, None) => Bar {
                from,
                to: to.value(sys),
                area,
                spacing,
                material,
            },
            (None, Some(dir), false, Some(len)) => {
                if dir.iter().all(|&c| c == 0.0) || dir.iter().any(|c| !c.is_finite()) {
                    return self.err(line, format!("{ctx}: direction must be a non-zero vector (got {dir:?})"));
                }
                Bar::along(from, dir, len, area, spacing, material)
            }
            (None, None, true, Some(len)) => Bar::at_angle(
                from,
                b.azimuth.unwrap_or(0.0),
                b.elevation.unwrap_or(0.0),
                len,
                area,
                spacing,
                material,
            ),
            _ => {
                return self.err(
                    line,
                    format!("{ctx}: give 'to', or 'direction' and 'length', or 'azimuth'/'elevation' (degrees) and 'length'"),
                )
            }
        };
        if let Some(len) = length {
            if !(len.is_finite() && len > 0.0) {
                return self.err(line, format!("{ctx}: length must be > 0 (got {len})"));
            }
        }
        Ok(bar)
    }

    /// A bar's initial strain, given as `prestrain` or as `prestress` over the material's E,
    /// with its transfer length.
    fn prestrain(
        &self,
        b: &BarSection,
        k: usize,
        line: usize,
        material: &Material,
    ) -> R<Prestrain> {
        let ctx = format!("bar {k}");
        let strain = match (b.prestrain, b.prestress) {
            (None, None) => {
                if b.transfer_length.is_some() {
                    return self.err(
                        line,
                        format!("{ctx}: transfer_length needs prestrain or prestress"),
                    );
                }
                return Ok(Prestrain::default());
            }
            (Some(e), None) => e,
            (None, Some(stress)) => match material
                .positive("youngs_modulus", Dimension::STRESS)
                .or_else(|e| self.err(line, e.to_string()))?
            {
                Some(e) => stress.value(self.sys) / e,
                None => {
                    return self.err(
                        line,
                        format!(
                        "{ctx}: prestress needs youngs_modulus on material '{}'; or give prestrain",
                        material.name
                    ),
                    )
                }
            },
            (Some(_), Some(_)) => {
                return self.err(
                    line,
                    format!("{ctx}: give prestrain or prestress, not both"),
                )
            }
        };
        if !(strain.is_finite() && strain.abs() < 0.1) {
            return self.err(
                line,
                format!(
                    "{ctx}: prestrain must be a finite strain below 0.1 in size (got {strain})"
                ),
            );
        }
        let transfer_length = b.transfer_length.map_or(0.0, |l| l.value(self.sys));
        if !(transfer_length.is_finite() && transfer_length >= 0.0) {
            return self.err(
                line,
                format!("{ctx}: transfer_length must be a length >= 0 (got {transfer_length})"),
            );
        }
        Ok(Prestrain {
            strain,
            transfer_length,
        })
    }

    fn history(&self, h: &Option<HistorySpec>, line: usize, ctx: &str) -> R<History> {
        let hist = match h {
            None => History::Constant,
            Some(HistorySpec {
                ramp: Some(r),
                table: None,
            }) => History::Ramp {
                duration: r.value(self.sys),
            },
            Some(HistorySpec {
                ramp: None,
                table: Some(t),
            }) => History::Table(t.iter().map(|(t, f)| (t.value(self.sys), *f)).collect()),
            Some(_) => {
                return self.err(
                    line,
                    format!("{ctx}: history takes one of 'ramp' or 'table'"),
                )
            }
        };
        hist.validate()
            .or_else(|e| self.err(line, format!("{ctx}: {e}")))?;
        Ok(hist)
    }

    fn components(&self, names: &[String], line: usize, ctx: &str) -> R<Vec<usize>> {
        let mut dofs = Vec::new();
        for n in names {
            let more: &[usize] = match n.as_str() {
                "x" => &[0],
                "y" => &[1],
                "z" => &[2],
                "all" => &[0, 1, 2],
                "rx" => &[3],
                "ry" => &[4],
                "rz" => &[5],
                "rotation" => &[3, 4, 5],
                "temperature" => &[TEMPERATURE],
                other => {
                    return self.err(
                        line,
                        format!(
                        "{ctx}: unknown component '{other}' (use \"x\", \"y\", \"z\", \"all\", \"rx\", \"ry\", \"rz\", \"rotation\" or \"temperature\")"
                    ),
                    )
                }
            };
            for d in more {
                if !dofs.contains(d) {
                    dofs.push(*d);
                }
            }
        }
        if dofs.is_empty() {
            return self.err(line, format!("{ctx}: no component selected"));
        }
        dofs.sort_unstable();
        Ok(dofs)
    }

    fn boundary(&self, b: &BoundarySection, line: usize) -> R<BoundarySpec> {
        let ctx = format!("boundary '{}'", b.name);
        if !valid_name(&b.name) {
            return self.err(
                line,
                format!("{ctx}: names are letters, digits, '_' or '-'"),
            );
        }
        let region = self.region(&b.region, line, &ctx)?;
        let history = self.history(&b.history, line, &ctx)?;
        let comps = |c: &Option<Vec<String>>| -> R<Vec<usize>> {
            match c {
                Some(c) => self.components(c, line, &ctx),
                None => Ok(vec![0, 1, 2]),
            }
        };
        let (dofs, motion) = match (&b.fixed, b.velocity, b.displacement) {
            _ if b.temperature.is_some() => {
                if b.fixed.is_some() || b.velocity.is_some() || b.displacement.is_some() {
                    return self.err(
                        line,
                        format!("{ctx}: give exactly one of 'fixed', 'velocity', 'displacement' or 'temperature'"),
                    );
                }
                if b.components.is_some() {
                    return self.err(line, format!("{ctx}: 'temperature' takes no components"));
                }
                let t = b.temperature.unwrap_or_default();
                if !t.is_finite() {
                    return self.err(line, format!("{ctx}: temperature must be finite (got {t})"));
                }
                (vec![TEMPERATURE], Motion::Displacement(vec![t]))
            }
            (Some(f), None, None) => {
                if b.components.is_some() {
                    return self.err(line, format!("{ctx}: 'fixed' lists its own components"));
                }
                (self.components(f, line, &ctx)?, Motion::Fixed)
            }
            (None, Some(v), None) => {
                let dofs = comps(&b.components)?;
                if dofs.iter().any(|&d| d > 2) {
                    return self.err(line, format!("{ctx}: 'velocity' prescribes x, y, z only"));
                }
                let v = self.finite3(v.value(self.sys), line, &format!("{ctx}: velocity"))?;
                (
                    dofs.clone(),
                    Motion::Velocity(dofs.iter().map(|&d| v[d]).collect()),
                )
            }
            (None, None, Some(u)) => {
                let dofs = comps(&b.components)?;
                if dofs.iter().any(|&d| d > 2) {
                    return self.err(
                        line,
                        format!("{ctx}: 'displacement' prescribes x, y, z only"),
                    );
                }
                let u = self.finite3(u.value(self.sys), line, &format!("{ctx}: displacement"))?;
                (
                    dofs.clone(),
                    Motion::Displacement(dofs.iter().map(|&d| u[d]).collect()),
                )
            }
            _ => {
                return self.err(
                    line,
                    format!("{ctx}: give exactly one of 'fixed', 'velocity', 'displacement' or 'temperature'"),
                )
            }
        };
        Ok(BoundarySpec {
            name: b.name.clone(),
            line,
            region,
            dofs,
            motion,
            history,
        })
    }

    fn load(&self, l: &LoadSection, line: usize) -> R<LoadSpec> {
        let ctx = format!("load '{}'", l.name);
        if !valid_name(&l.name) {
            return self.err(
                line,
                format!("{ctx}: names are letters, digits, '_' or '-'"),
            );
        }
        let sys = self.sys;
        let kinds: Vec<LoadKind> = [
            l.force_per_particle
                .map(|v| LoadKind::PerParticle(v.value(sys))),
            l.total_force.map(|v| LoadKind::Total(v.value(sys))),
            l.body_force.map(|v| LoadKind::BodyForce(v.value(sys))),
            l.gravity.map(|v| LoadKind::Gravity(v.value(sys))),
            l.heat_flux.map(LoadKind::HeatFlux),
            l.heat_source.map(LoadKind::HeatSource),
            l.total_heat.map(LoadKind::TotalHeat),
        ]
        .into_iter()
        .flatten()
        .collect();
        if kinds.len() != 1 {
            return self.err(
                line,
                format!("{ctx}: give exactly one of 'force_per_particle', 'total_force', 'body_force', 'gravity', 'heat_flux', 'heat_source' or 'total_heat'"),
            );
        }
        match kinds[0] {
            LoadKind::PerParticle(v)
            | LoadKind::Total(v)
            | LoadKind::BodyForce(v)
            | LoadKind::Gravity(v) => {
                self.finite3(v, line, &format!("{ctx}: the load vector"))?;
            }
            LoadKind::HeatFlux(q) | LoadKind::HeatSource(q) | LoadKind::TotalHeat(q) => {
                if !q.is_finite() {
                    return self.err(line, format!("{ctx}: the heat must be finite (got {q})"));
                }
            }
        }
        let region = match &l.region {
            Some(r) => self.region(r, line, &ctx)?,
            None => Region::All,
        };
        Ok(LoadSpec {
            name: l.name.clone(),
            line,
            region,
            kind: kinds[0],
            history: self.history(&l.history, line, &ctx)?,
        })
    }
}

fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}
