//! The step loop of one worker: the solver advances the procCube, and the observers (outputs,
//! stop criteria, analyses: `driver/observers/`) watch it when due.

use super::observers::observers;
use super::record::FrameStore;
use super::run::Summary;
use crate::engine::timing::Phase;
use crate::model::Model;
use crate::parallel::deform::Deform;
use crate::parallel::snapshot::Snapshot;
use crate::parallel::Cube;
use crate::solve::{Adr, Explicit, Newton, Relaxed, Solver};
use std::path::PathBuf;
use std::time::Instant;

/// What every worker needs to know about the run beyond its own procCube.
pub(crate) struct Plan {
    pub columns: Vec<String>,
    pub dir: PathBuf,
    pub steps: u64,
    pub every: u64,
    pub frames_every: u64,
    pub progress: bool,
    pub quiet: bool,
    pub final_state: bool,
    pub shuffle_every: u64,
    /// `[time] stop_at_broken_bonds` (0 = off).
    pub stop_at_broken: u64,
    /// Each probe's name and `stop_beyond` (infinite when not given), in deck order.
    pub probe_stops: Vec<(String, f64)>,
    /// `[time] stop_below_peak`, with its column's index in `columns`.
    pub peak_stop: Option<(usize, crate::input::deck::PeakStop)>,
    pub layout: String,
    /// The step the loop starts from: 0, or the step of the checkpoint it resumes.
    pub first_step: u64,
    /// Force evaluations of the static start (`[time] static_until`), 0 without one.
    pub static_evaluations: u64,
    /// How each step is taken.
    pub solver: SolverChoice,
    /// For the blow-up diagnosis: the stable time step, what it is, and the material names.
    pub dt_critical: f64,
    pub dt_critical_name: &'static str,
    pub material_names: Vec<String>,
    pub spacing: f64,
    pub checkpoints: CheckpointPlan,
    /// With a pair law: how rows get their temperature and pressure.
    pub thermo: Option<super::thermo::Thermo>,
    /// `[output] picture`: what `picture.png` of the final state is coloured by.
    pub picture: Option<crate::input::deck::Colouring>,
    /// The deck's title, for the picture.
    pub title: String,
    /// `[[analysis]]`: voids and cracks on voxels, in deck order.
    pub analyses: Vec<super::observers::analysis::AnalysisPlan>,
    /// `[deform]`: the periodic box changing with time.
    pub deform: Option<crate::input::deck::DeformSpec>,
    /// Frames and checkpoints are written in parts, one per procCube, instead of gathered on
    /// the root (runs on several MPI ranks).
    pub in_parts: bool,
}

/// When to write checkpoints, and what identifies them.
pub(crate) struct CheckpointPlan {
    pub dir: PathBuf,
    pub every: u64,
    pub minutes: f64,
    pub keep: usize,
    pub scene_hash: u64,
    pub deck: String,
}

/// How each step of a run is taken, as the deck chose; each worker starts its own
/// [`Solver`] from it.
#[derive(Clone)]
pub(crate) enum SolverChoice {
    Explicit,
    /// Adaptive dynamic relaxation with these fictitious masses by global id.
    Adr {
        mass: crate::solve::adr::FictitiousMass,
        tolerance: f64,
        max_iterations: u64,
    },
    /// Newton's method (`src/solve/newton.rs`): the factored tangent where it serves, else
    /// (or always, as `matrix_free.always` says) matrix-free.
    Implicit {
        tolerance: f64,
        max_iterations: u64,
        matrix_free: crate::solve::MatrixFree,
    },
}

impl SolverChoice {
    pub fn quasi_static(&self) -> bool {
        !matches!(self, SolverChoice::Explicit)
    }

    /// This worker's solver; `root` reports what the solve says on the way.
    fn start<M: Model>(&self, root: bool, stop_at_broken: u64) -> Box<dyn Solver<M>> {
        match self {
            SolverChoice::Explicit => Box::new(Explicit),
            SolverChoice::Adr {
                mass,
                tolerance,
                max_iterations,
            } => Box::new(Adr::new(mass.clone(), *tolerance, *max_iterations, root)),
            SolverChoice::Implicit {
                tolerance,
                max_iterations,
                matrix_free,
            } => Box::new(
                Newton::new(*tolerance, *max_iterations, stop_at_broken)
                    .with_matrix_free(matrix_free.clone(), root),
            ),
        }
    }

    /// Force evaluations spent before the first step (the fictitious masses' estimate).
    fn setup_evaluations(&self) -> u64 {
        match self {
            SolverChoice::Adr { mass, .. } => mass.evaluations,
            _ => 0,
        }
    }
}

/// What the loop counts on the way, for the summary.
#[derive(Default)]
pub(crate) struct Tally {
    pub evaluations: u64,
    /// Load steps solved by relaxation, and how many of them reached the tolerance.
    pub load_steps: u64,
    pub converged: u64,
    /// The last load step's solve (quasi-static solvers).
    pub solved: Option<Relaxed>,
    /// Broken bonds at the last history row.
    pub broken: usize,
    pub shuffles: u64,
    pub stopped_at_broken: bool,
    pub stopped_at_probe: Option<String>,
    /// The column of `[time] stop_below_peak` that ended the run.
    pub stopped_below_peak: Option<String>,
    pub interrupted: Option<PathBuf>,
    pub checkpoints: Vec<(PathBuf, u64, f64)>,
}

impl Tally {
    /// One step of the solver: a force evaluation, or a load step's solve.
    fn count(&mut self, solved: Option<Relaxed>) {
        match solved {
            Some(r) => {
                self.evaluations += r.iterations;
                self.load_steps += 1;
                self.converged += r.converged as u64;
                self.solved = Some(r);
            }
            None => self.evaluations += 1,
        }
    }
}

impl Plan {
    pub fn io(&self, e: std::io::Error) -> String {
        format!("writing output in {}: {e}", self.dir.display())
    }
}

/// The step loop of one worker: the solver advances the procCube, and the observers
/// (`driver/observers/`: stop criteria, history rows, frames, progress, checkpoints) watch it when
/// due. Every worker runs it alike (SPMD); the root writes the output and returns the summary.
pub(crate) fn drive<M: Model>(
    mut cube: Cube<M>,
    plan: &Plan,
    store: Option<FrameStore<M>>,
    resume: Option<&Snapshot>,
) -> Result<Option<Summary>, String> {
    let root = cube.wall.transport().rank() == 0;
    start(&mut cube, plan, resume)?;
    let mut solver = plan.solver.start::<M>(root, plan.stop_at_broken);
    let first = plan.first_step;
    let tally = Tally {
        evaluations: plan.static_evaluations + plan.solver.setup_evaluations(),
        ..Tally::default()
    };
    let (mut watch, mut observers) = observers(plan, &mut cube, store, tally);
    let wall = Instant::now();
    for step in first..=plan.steps {
        if step > first {
            let solved = solver.advance(&mut cube, step)?;
            watch.tally.count(solved);
            shuffle_when_due(&mut cube, plan, step, &mut watch.tally)?;
        }
        watch.at(step, step == plan.steps);
        for o in &mut observers {
            // A stop makes this the last step for the observers after it.
            if o.due(step, watch.last) && o.observe(&mut cube, &mut watch)?.is_break() {
                watch.last = true;
            }
        }
        if watch.last {
            break;
        }
    }
    for o in &mut observers {
        o.finish(&mut cube, &mut watch);
    }
    watch.agree(&mut cube)?;
    let seconds = wall.elapsed().as_secs_f64();
    super::record::finish(cube, plan, watch.tally, seconds)
}

/// Restores a checkpoint's bonds and box, makes the bond counts whole, computes the first
/// forces.
fn start<M: Model>(
    cube: &mut Cube<M>,
    plan: &Plan,
    resume: Option<&Snapshot>,
) -> Result<(), String> {
    let t = Instant::now();
    if let Some(d) = &plan.deform {
        let start = cube.layout.domain.clone();
        cube.deform = Some(Deform::new(d.rate, d.every, start));
        if let Some(c) = resume {
            // The checkpoint's positions are in the box of its last change; the first step
            // rebins.
            let since = (c.step % d.every.max(1)) as f64 * cube.sim.dt;
            cube.set_box(c.time - since)?;
        }
    }
    if let Some(c) = resume {
        c.restore_bonds(cube);
    }
    cube.start();
    if let Some(c) = resume {
        c.restore_forces(cube);
    }
    cube.sim.timing.lap(Phase::Setup, t);
    Ok(())
}

fn shuffle_when_due<M: Model>(
    cube: &mut Cube<M>,
    plan: &Plan,
    step: u64,
    tally: &mut Tally,
) -> Result<(), String> {
    if plan.shuffle_every > 0 && step.is_multiple_of(plan.shuffle_every) {
        let t = Instant::now();
        // Every worker sees the same scene here, so all fail alike.
        if cube.shuffle()? {
            tally.shuffles += 1;
        }
        cube.sim.timing.lap(Phase::Communication, t);
    }
    Ok(())
}
