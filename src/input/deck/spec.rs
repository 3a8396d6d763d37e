//! What the engine gets from a deck: the checked types, everything converted to the deck's
//! unit system. Each deck entry that a later message may have to point at carries its line:
//! a `line` field in the types of this module, [`Located`] around the engine's own types.

use super::DeckError;
use crate::engine::boundary::{History, Motion};
use crate::engine::simulation::Integrator;
use crate::input::bars::Prestrain;
use crate::input::geometry::{Bar, Lattice, Op, Shape};
use crate::input::materials::MaterialLines;
use crate::input::procs::{Procs, Walls};
use crate::input::units::UnitSystem;
use crate::model::{Material, ModelError, OptionValue};
use std::path::PathBuf;

/// A checked deck entry and the line it was written at, for messages that point back at it.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<T> {
    pub item: T,
    /// Deck line; 0 for a section the deck leaves out (its defaults apply).
    pub line: usize,
}

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
    /// Deck line of `[time]`, for messages.
    pub line: usize,
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
    /// End the run at the first history row where a column has fallen below a fraction of
    /// its peak (`[time] stop_below_peak`): a displacement-controlled test past its peak.
    pub stop_below_peak: Option<PeakStop>,
}

/// `[time] stop_below_peak`: the run ends at the first history row at which |`column`| is below
/// `fraction` × the largest |`column`| of the rows before it.
#[derive(Clone, Debug, PartialEq)]
pub struct PeakStop {
    /// A history.csv column (`reaction_right_grip_x`, `load_load`, `tip_uz`, …).
    pub column: String,
    /// In (0, 1).
    pub fraction: f64,
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

/// `[velocity]`: a Maxwell–Boltzmann start at `temperature` (in the deck's temperature unit:
/// kelvin, ε/k_B in lj), drawn from `seed`, on the particles of `region`.
#[derive(Clone, Debug, PartialEq)]
pub struct VelocitySpec {
    pub line: usize,
    pub temperature: f64,
    pub seed: u64,
    pub region: Region,
}

/// `[thermostat]`'s kind and the parameters it takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThermostatKind {
    Rescale { every: u64 },
    Berendsen { damping: f64 },
    Langevin { damping: f64, seed: u64 },
    NoseHoover { damping: f64 },
}

/// `[thermostat]`: the translational temperature of a group held at `temperature` (the deck's
/// temperature unit). The group is the particles of `region` whose material is in
/// `materials` (empty: any).
#[derive(Clone, Debug, PartialEq)]
pub struct ThermostatSpec {
    pub line: usize,
    pub kind: ThermostatKind,
    pub temperature: f64,
    pub region: Region,
    pub materials: Vec<u16>,
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
        /// How each load step reaches equilibrium.
        method: Equilibrium,
        /// Conjugate-gradient iterations per Newton iteration of the matrix-free solve.
        krylov_iterations: u64,
        /// Whether the matrix-free solve's preconditioner has its coarse level
        /// (`preconditioner = "two_level"`) or is the diagonal alone (`"diagonal"`).
        coarse: bool,
    },
}

/// How a quasi-static load step reaches equilibrium (`[solver] kind`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Equilibrium {
    /// Adaptive dynamic relaxation (`"adr"`).
    Relaxation,
    /// Newton's method (`"implicit"`): the factored tangent where it fits in memory on one
    /// procCube, else the matrix-free linear solve.
    Newton,
    /// Newton's method with the matrix-free linear solve always (`"newton_krylov"`).
    NewtonKrylov,
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
    /// `picture.png` of the final state, coloured by this (`None`: no picture).
    pub picture: Option<Colouring>,
    /// Frames and checkpoints in parts, one file per procCube: `Some(true)` whenever there
    /// are several procCubes, `Some(false)` never (gathered on the root), `None` on several
    /// MPI ranks only.
    pub parts: Option<bool>,
}

impl OutputSpec {
    /// Whether a run of `cubes` procCubes writes in parts; `ranks`: on MPI ranks.
    pub fn in_parts(&self, cubes: usize, ranks: bool) -> bool {
        cubes > 1 && self.parts.unwrap_or(ranks)
    }
}

/// What the particles of a picture are coloured by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colouring {
    /// Broken fraction of each particle's bonds, 0 to 1.
    Damage,
    /// The particle's material, in the order `pdq check` lists them.
    Material,
    /// |v|, from 0 to the largest.
    Speed,
    /// z of the current position, from the lowest to the highest.
    Height,
    /// Damage where the scene has bonds, else speed (the default).
    Auto,
}

impl Colouring {
    pub const NAMES: [&'static str; 5] = ["damage", "material", "speed", "height", "auto"];

    pub fn parse(name: &str) -> Option<Colouring> {
        Some(match name {
            "damage" => Colouring::Damage,
            "material" => Colouring::Material,
            "speed" => Colouring::Speed,
            "height" => Colouring::Height,
            "auto" => Colouring::Auto,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        Colouring::NAMES[self as usize]
    }
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

/// What an `[[analysis]]` looks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnalysisKind {
    /// Connected empty voxels inside the body.
    Voids,
    /// Connected voxels holding the midpoints of broken bonds.
    Cracks,
}

impl AnalysisKind {
    pub fn name(self) -> &'static str {
        match self {
            AnalysisKind::Voids => "voids",
            AnalysisKind::Cracks => "cracks",
        }
    }
}

/// An `[[analysis]]` entry, its defaults filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisSpec {
    /// Names its files: `NAME.csv`, `NAME_clusters.csv`, `NAME_events.csv`.
    pub name: String,
    pub line: usize,
    pub kind: AnalysisKind,
    pub every: u64,
    /// The voxel side (default: the lattice spacing, for fcc and bcc the cubic cell).
    pub voxel: f64,
    /// Voxels touching across edges and corners join too (default: only for cracks).
    pub all_neighbours: bool,
    /// `"boundary"`, `"min-label"` or `"gather"`.
    pub scheme: String,
}

/// `[deform]`: the periodic box's length along each axis is L0 (1 + rate·t), changed every
/// `every` steps with the particles mapped along.
#[derive(Clone, Debug, PartialEq)]
pub struct DeformSpec {
    pub line: usize,
    /// Engineering strain rate per axis, per unit time (0 along non-periodic axes).
    pub rate: [f64; 3],
    pub every: u64,
}

/// A `[[bar]]` entry: the bar, the initial strain of its own bonds and its line.
#[derive(Clone, Debug, PartialEq)]
pub struct BarSpec {
    pub bar: Bar,
    /// Zero strain: none; see `input/bars.rs`.
    pub prestrain: Prestrain,
    pub line: usize,
}

/// Where `[model]` and each material and its keys are written: what an error from building
/// the model points at. A [`ModelError`] names its material by index, so `materials` is in
/// the order of [`Scene::materials`].
#[derive(Clone, Debug, PartialEq)]
pub struct ModelLines {
    /// Deck line of `[model]`.
    pub model: usize,
    pub materials: Vec<MaterialLines>,
}

impl ModelLines {
    /// The line of the key or the material `e` is about, else of `[model]`.
    pub fn of(&self, e: &ModelError) -> usize {
        match e {
            ModelError::Material { material, .. } => self
                .materials
                .get(*material as usize)
                .map_or(self.model, |m| m.of(e)),
            ModelError::Model(_) => self.model,
        }
    }
}

/// `[pair]`: a non-bonded pair law and its parameters, as the law's build reads them.
#[derive(Clone, Debug, PartialEq)]
pub struct PairSpec {
    pub law: String,
    pub cutoff: Option<f64>,
    /// Neighbour-list skin; `None`: 0.3 × the law's cutoff.
    pub skin: Option<f64>,
    pub shift: Option<bool>,
    pub mixing: crate::model::pair::Mixing,
    /// Leave out pairs joined by an intact bond (the contact law always does).
    pub exclude_bonded: bool,
    /// Each material's table, in material order (no keys where the deck gives none).
    pub own: Vec<Material>,
    /// `[[pair.between]]` tables: the two materials and the keys.
    pub between: Vec<(u16, u16, Material)>,
    /// Where each table's keys are: the materials' then the between tables'.
    pub lines: Vec<MaterialLines>,
    /// Line of `[pair]`.
    pub line: usize,
}

impl PairSpec {
    /// The line a pair law's error points at.
    pub fn line_of(&self, e: &ModelError) -> usize {
        match e {
            ModelError::Material { material, .. } => self
                .lines
                .get(*material as usize)
                .map_or(self.line, |m| m.of(e)),
            ModelError::Model(_) => self.line,
        }
    }
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
    pub model_options: Vec<(String, OptionValue)>,
    /// Where `[model]` and the materials are, for the model's messages.
    pub model_lines: ModelLines,
    pub horizon: f64,
    pub spacing: f64,
    pub partial_volume: bool,
    /// Apply the energy surface correction to bond-based models.
    pub surface_correction: bool,
    pub materials: Vec<Material>,
    pub lattice: Lattice,
    /// The `[[geometry]]` entries in deck order.
    pub ops: Vec<Located<Op>>,
    pub bars: Vec<BarSpec>,
    pub time: TimeSpec,
    pub boundaries: Vec<BoundarySpec>,
    pub loads: Vec<LoadSpec>,
    pub initial: Vec<InitialSpec>,
    /// `[velocity]`, set after `[[initial]]`.
    pub velocity: Option<VelocitySpec>,
    pub output: OutputSpec,
    pub probes: Vec<ProbeSpec>,
    /// The `[[analysis]]` entries in deck order.
    pub analyses: Vec<AnalysisSpec>,
    /// `[solver]`, at line 0 if the deck leaves it out.
    pub solver: Located<SolverSpec>,
    /// The non-bonded pair law, if the deck has a `[pair]` section.
    pub pair: Option<PairSpec>,
    /// `[thermostat]`, if the deck has one.
    pub thermostat: Option<ThermostatSpec>,
    /// `[deform]`, if the deck has one.
    pub deform: Option<DeformSpec>,
}

impl Scene {
    /// An error from building the model: at the key or the material it is about, else at
    /// `[model]`.
    pub fn model_error(&self, e: &ModelError) -> DeckError {
        self.error(Some(self.model_lines.of(e)), format!("[model] {e}"))
    }

    /// A pair law's error, at the line of the table or key it is about.
    pub fn pair_error(&self, e: &ModelError) -> DeckError {
        let line = self.pair.as_ref().map(|p| p.line_of(e));
        self.error(line, format!("[pair] {e}"))
    }

    /// An error located at `line` of this deck.
    pub fn error(&self, line: Option<usize>, message: impl Into<String>) -> DeckError {
        DeckError {
            file: self.file.clone(),
            line,
            message: message.into(),
        }
    }

    /// The geometry entries without their lines, as `geometry::build` takes them.
    pub fn geometry_ops(&self) -> Vec<Op> {
        self.ops.iter().map(|o| o.item.clone()).collect()
    }

    /// The bars without their prestrain and lines, as `geometry::build` and the bar
    /// calibration take them.
    pub fn geometry_bars(&self) -> Vec<Bar> {
        self.bars.iter().map(|b| b.bar.clone()).collect()
    }

    /// What this deck uses that setup per rank (`parallel::part`) does not build yet, so that
    /// every MPI rank builds the whole scene, if anything.
    pub fn built_whole_by(&self) -> Option<&'static str> {
        let checks = [
            (self.pair.is_some(), "a [pair] law"),
            (self.surface_correction, "the surface correction"),
            (self.velocity.is_some(), "[velocity]"),
            (self.thermostat.is_some(), "a [thermostat]"),
            (self.deform.is_some(), "[deform]"),
            (self.time.static_until.is_some(), "a static start"),
            (
                self.time.critical_step == CriticalStep::Measured,
                "a measured critical step",
            ),
            (
                !matches!(self.solver.item, SolverSpec::Explicit),
                "a quasi-static [solver]",
            ),
        ];
        checks.iter().find(|c| c.0).map(|c| c.1)
    }

    /// Each bar's prestrain, in bar order.
    pub fn bar_prestrain(&self) -> Vec<Prestrain> {
        self.bars.iter().map(|b| b.prestrain).collect()
    }
}
