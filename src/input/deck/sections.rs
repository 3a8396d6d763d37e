//! The TOML layout of a deck, as serde reads it: one struct per section, spelling and types
//! only. Unknown keys are refused here (`deny_unknown_fields`, located by the toml crate); what
//! the values mean is checked by the `Converter` methods of the sibling modules.

use crate::input::materials::MaterialSection;
use crate::input::units::{
    AccelerationVector, Area, ForceVector, Length, NumberDensity, Position, Stress, Time, Vector,
    VelocityVector,
};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// A whole deck: one field per top-level key or section, each with its span (its line).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DeckFile {
    pub(super) title: Option<String>,
    pub(super) units: Spanned<String>,
    pub(super) model: Spanned<ModelSection>,
    pub(super) lattice: Spanned<LatticeSection>,
    pub(super) materials: Spanned<BTreeMap<String, Spanned<MaterialSection>>>,
    #[serde(default)]
    pub(super) geometry: Vec<Spanned<ShapeSpec>>,
    #[serde(default)]
    pub(super) bar: Vec<Spanned<BarSection>>,
    pub(super) time: Spanned<TimeSection>,
    #[serde(default)]
    pub(super) boundary: Vec<Spanned<BoundarySection>>,
    #[serde(default)]
    pub(super) load: Vec<Spanned<LoadSection>>,
    #[serde(default)]
    pub(super) initial: Vec<Spanned<InitialSection>>,
    #[serde(default)]
    pub(super) velocity: Option<Spanned<VelocitySection>>,
    #[serde(default)]
    pub(super) output: Option<Spanned<OutputSection>>,
    #[serde(default)]
    pub(super) probe: Vec<Spanned<ProbeSection>>,
    #[serde(default)]
    pub(super) analysis: Vec<Spanned<AnalysisSection>>,
    #[serde(default)]
    pub(super) parallel: Option<Spanned<ParallelSection>>,
    #[serde(default)]
    pub(super) solver: Option<Spanned<SolverSection>>,
    #[serde(default)]
    pub(super) pair: Option<Spanned<PairSection>>,
    #[serde(default)]
    pub(super) thermostat: Option<Spanned<ThermostatSection>>,
    #[serde(default)]
    pub(super) deform: Option<Spanned<DeformSection>>,
    /// What `pdq validate` reads (validation/README.md); a run ignores it.
    #[serde(default, rename = "validation")]
    pub(super) _validation: Option<toml::Table>,
}

/// `[solver]`: explicit time stepping (the default) or quasi-static load steps (adaptive
/// dynamic relaxation, Newton with the factored tangent, Newton–Krylov).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SolverSection {
    pub(super) kind: String,
    pub(super) load_steps: Option<u64>,
    pub(super) tolerance: Option<f64>,
    pub(super) max_iterations: Option<u64>,
    pub(super) krylov_iterations: Option<u64>,
    pub(super) preconditioner: Option<String>,
}

/// `procs` is `[nx, ny, nz]` or `"auto"`.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum ProcsSpec {
    Given([i64; 3]),
    Word(String),
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct ParallelSection {
    pub(super) procs: Option<ProcsSpec>,
    pub(super) threads: Option<i64>,
    pub(super) walls: Option<String>,
    pub(super) shuffle_every: Option<i64>,
    pub(super) skin: Option<f64>,
    /// The thesis's cell factor: cells are this many horizons wide (1 + skin).
    pub(super) cell_factor: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ModelSection {
    pub(super) name: String,
    pub(super) horizon: Option<Length>,
    /// Horizon as a multiple of the lattice spacing.
    pub(super) m: Option<f64>,
    pub(super) partial_volume: Option<bool>,
    /// "none" (default) or "energy" (docs/theory.md §6).
    pub(super) surface_correction: Option<String>,
    #[serde(default)]
    pub(super) options: BTreeMap<String, OptionSpec>,
}

/// A model option: a number or a word.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum OptionSpec {
    Number(f64),
    Integer(i64),
    Word(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LatticeSection {
    /// "sc" (default), "fcc" or "bcc".
    pub(super) kind: Option<String>,
    /// The cubic cell side; or `density`.
    pub(super) spacing: Option<Length>,
    /// Sites per unit volume, giving the cell side (basis / density)^⅓; or `spacing`.
    pub(super) density: Option<NumberDensity>,
    pub(super) origin: Option<Position>,
    /// Axes that wrap around ("x", "y", "z"): the lattice box repeats along them.
    #[serde(default)]
    pub(super) periodic: Vec<String>,
    /// Random offsets of the sites, as a fraction of the spacing.
    #[serde(default)]
    pub(super) jitter: f64,
    #[serde(default)]
    pub(super) seed: u64,
}

/// A shape for geometry entries and regions; which keys apply depends on `shape`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct ShapeSpec {
    pub(super) shape: Option<String>,
    /// Geometry only: "add" (default) or "subtract".
    pub(super) op: Option<String>,
    /// Geometry only: material filled in by "add".
    pub(super) material: Option<String>,
    /// Regions only: explicit global particle ids.
    pub(super) ids: Option<Vec<u32>>,
    pub(super) min: Option<Position>,
    pub(super) max: Option<Position>,
    pub(super) base: Option<Position>,
    pub(super) center: Option<Position>,
    pub(super) axis: Option<AxisSpec>,
    pub(super) length: Option<Length>,
    pub(super) radius: Option<Length>,
    pub(super) polygon: Option<Vec<[Length; 2]>>,
    pub(super) from: Option<Length>,
    pub(super) to: Option<Length>,
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
pub(super) enum AxisSpec {
    Name(String),
    Direction([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BarSection {
    pub(super) material: String,
    pub(super) area: Area,
    pub(super) from: Position,
    pub(super) to: Option<Position>,
    pub(super) direction: Option<[f64; 3]>,
    pub(super) azimuth: Option<f64>,
    pub(super) elevation: Option<f64>,
    pub(super) length: Option<Length>,
    pub(super) spacing: Option<Length>,
    pub(super) prestrain: Option<f64>,
    pub(super) prestress: Option<Stress>,
    pub(super) transfer_length: Option<Length>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TimeSection {
    pub(super) steps: Option<u64>,
    pub(super) duration: Option<Time>,
    pub(super) dt: Option<Time>,
    pub(super) safety_factor: Option<f64>,
    pub(super) critical_step: Option<String>,
    pub(super) static_until: Option<Time>,
    pub(super) force_dt: Option<bool>,
    pub(super) integrator: Option<String>,
    pub(super) stop_at_broken_bonds: Option<i64>,
    pub(super) stop_below_peak: Option<PeakStopSection>,
}

/// `[time] stop_below_peak = { column = "…", fraction = … }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PeakStopSection {
    pub(super) column: String,
    pub(super) fraction: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct HistorySpec {
    pub(super) ramp: Option<Time>,
    pub(super) table: Option<Vec<(Time, f64)>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BoundarySection {
    pub(super) name: String,
    pub(super) region: ShapeSpec,
    pub(super) fixed: Option<Vec<String>>,
    pub(super) velocity: Option<VelocityVector>,
    pub(super) displacement: Option<Position>,
    /// Prescribed temperature (models with a temperature DOF), in the deck's degrees.
    pub(super) temperature: Option<f64>,
    pub(super) components: Option<Vec<String>>,
    pub(super) history: Option<HistorySpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LoadSection {
    pub(super) name: String,
    pub(super) region: Option<ShapeSpec>,
    pub(super) force_per_particle: Option<ForceVector>,
    pub(super) total_force: Option<ForceVector>,
    pub(super) body_force: Option<Vector<1, -2, -2>>,
    pub(super) gravity: Option<AccelerationVector>,
    /// Heat per unit time and area into a region one lattice layer thick.
    pub(super) heat_flux: Option<f64>,
    /// Heat per unit time and volume.
    pub(super) heat_source: Option<f64>,
    /// Heat per unit time shared by volume.
    pub(super) total_heat: Option<f64>,
    pub(super) history: Option<HistorySpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct InitialSection {
    pub(super) region: Option<ShapeSpec>,
    pub(super) velocity: Option<VelocityVector>,
    /// Radians per unit time (models with rotations).
    pub(super) angular_velocity: Option<Vector<0, 0, -1>>,
    /// Models with a temperature DOF.
    pub(super) temperature: Option<f64>,
}

/// `[velocity]`: Maxwell–Boltzmann velocities at a temperature.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VelocitySection {
    /// In kelvin, or in ε/k_B in an lj deck.
    pub(super) temperature: f64,
    pub(super) seed: i64,
    pub(super) region: Option<ShapeSpec>,
}

/// `[thermostat]`: a group's temperature held at a target (MD). Keys keep their spans so that
/// a bad value is reported at its own line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ThermostatSection {
    pub(super) kind: Spanned<String>,
    /// In kelvin, or in ε/k_B in an lj deck.
    pub(super) temperature: Spanned<f64>,
    pub(super) damping: Option<Spanned<Time>>,
    pub(super) seed: Option<Spanned<i64>>,
    pub(super) every: Option<Spanned<i64>>,
    pub(super) region: Option<ShapeSpec>,
    pub(super) materials: Option<Spanned<Vec<String>>>,
}

/// `[deform]`: engineering strain rates of the periodic box, per unit time of the deck's units.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DeformSection {
    pub(super) strain_rate: Spanned<[f64; 3]>,
    pub(super) every: Option<Spanned<i64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct OutputSection {
    pub(super) directory: Option<String>,
    pub(super) history_every: Option<u64>,
    pub(super) frames_every: Option<u64>,
    pub(super) progress: Option<bool>,
    pub(super) final_state: Option<bool>,
    pub(super) checkpoint_every: Option<u64>,
    pub(super) checkpoint_minutes: Option<f64>,
    pub(super) checkpoint_keep: Option<usize>,
    pub(super) restart: Option<String>,
    pub(super) picture: Option<String>,
    pub(super) parts: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProbeSection {
    pub(super) name: String,
    pub(super) at: Position,
    pub(super) stop_beyond: Option<Length>,
}

/// `[[analysis]]`: voids or cracks on voxels, in the step loop every `every` steps.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AnalysisSection {
    pub(super) kind: String,
    pub(super) name: Option<String>,
    pub(super) every: i64,
    pub(super) voxel: Option<Length>,
    pub(super) connectivity: Option<String>,
    pub(super) scheme: Option<String>,
}

/// `[pair]`: a non-bonded pair law beside the bonded model (`pairs/`), its per-material
/// parameters in `[pair.materials.NAME]` and per-pair ones in `[[pair.between]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PairSection {
    pub(super) law: String,
    pub(super) cutoff: Option<Length>,
    pub(super) skin: Option<Length>,
    pub(super) shift: Option<bool>,
    pub(super) mixing: Option<String>,
    /// "bonded": leave out pairs joined by an intact bond; "none" (default, but for contact).
    pub(super) exclude: Option<String>,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, Spanned<MaterialSection>>,
    /// Each table names its two materials in `materials = ["a", "b"]`; every other key is the
    /// law's.
    #[serde(default)]
    pub(super) between: Vec<Spanned<MaterialSection>>,
}
