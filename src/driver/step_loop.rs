//! The step loop of one worker: the solver advances the procCube, and the outputs and stop
//! criteria observe it when due.

use super::record::{gather_frame, FrameStore, Row};
use super::run::Summary;
use crate::engine::timing::Phase;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::output::checkpoint::Checkpoint;
use crate::output::{Frames, History, Progress};
use crate::parallel::comm::{Reduce, Transport};
use crate::parallel::snapshot::Snapshot;
use crate::parallel::Cube;
use crate::solve::{Adr, Explicit, Newton, Relaxed, Solver};
use std::path::PathBuf;
use std::time::Instant;

/// The smallest global id of a particle that blew up, on every worker (a reduction: all must
/// call it): coordinates or velocities not finite, or (explicit runs) a speed that carries it
/// more than half a lattice spacing per step, which a stable run of a solid never reaches
/// (about half the wave speed).
fn first_blown_up<M: Model>(cube: &mut Cube<M>, limit: Option<f64>) -> Option<u32> {
    let p = &cube.sim.particles;
    let n2 = crate::model::second_order::<M>();
    let dt = cube.sim.dt;
    let runaway = |a: &[f64]| match limit {
        Some(half_spacing) => {
            let v2 = a[n2] * a[n2] + a[n2 + 1] * a[n2 + 1] + a[n2 + 2] * a[n2 + 2];
            v2 * dt * dt > half_spacing * half_spacing
        }
        None => false,
    };
    let mine = (0..p.n_owned)
        .filter(|&i| {
            let a = p.alter[i].as_slice();
            a.iter().any(|v| !v.is_finite()) || runaway(a)
        })
        .map(|i| p.gid[i] as f64)
        .fold(f64::INFINITY, f64::min);
    let mut v = [mine];
    cube.team().reduce(&mut v, Reduce::Min);
    v[0].is_finite().then_some(v[0] as u32)
}

/// Stops a run that blew up: writes a frame and a checkpoint of the state for inspection (all
/// workers take part) and returns the message naming the step, the particle and the likely
/// cause.
fn blow_up<M: Model>(
    cube: &mut Cube<M>,
    plan: &Plan,
    mut store: Option<FrameStore<M>>,
    frames: Option<Frames>,
    gid: u32,
    step: u64,
) -> String {
    let damage = cube.damage();
    gather_frame(cube, &damage, &mut store);
    let ck = &plan.checkpoints;
    let checkpoint = Checkpoint::gather(cube, ck.scene_hash, &ck.deck)
        .map(|c| c.write(&ck.dir, ck.keep.max(1) + 1));
    let Some(store) = store else {
        return "another worker stopped the run: it blew up".into();
    };
    let mut files = Vec::new();
    let frames = match frames {
        Some(f) => Ok(f),
        None => Frames::new(&plan.dir),
    };
    if let Ok(path) =
        frames.and_then(|mut f| f.write(step, cube.sim.time, &store.particles, &store.damage, 0))
    {
        files.push(path.display().to_string());
    }
    if let Some(Ok((path, _))) = checkpoint {
        files.push(path.display().to_string());
    }
    let i = store.index_of[gid as usize] as usize;
    let p = &store.particles;
    let material = plan
        .material_names
        .get(p.material[i] as usize)
        .map_or("?", |s| s.as_str());
    let ratio = cube.sim.dt / plan.dt_critical;
    let cause = if plan.solver.quasi_static() {
        "relaxation diverged: check the loads, supports and materials".to_string()
    } else if ratio > 1.0 {
        format!(
            "the time step is {ratio:.2} × the {} ({:.4e} against {:.4e}): lower dt or drop force_dt",
            plan.dt_critical_name, cube.sim.dt, plan.dt_critical
        )
    } else {
        format!(
            "the time step is within the {} ({ratio:.2} × {:.4e}): check the material's stiffness and density, and the loads and prescribed velocities",
            plan.dt_critical_name, plan.dt_critical
        )
    };
    format!(
        "the run blew up at step {step}: particle {gid} (material '{material}', reference position [{:.6e}, {:.6e}, {:.6e}]) has a position or velocity that is not finite, or moves more than half a lattice spacing per step. Likely cause: {cause}. For inspection: {}",
        p.x0[i][0],
        p.x0[i][1],
        p.x0[i][2],
        if files.is_empty() {
            "no file could be written".to_string()
        } else {
            files.join(", ")
        }
    )
}

/// True on every worker if any worker failed (so that all stop together, none left waiting).
fn any_failed<M: Model>(cube: &mut Cube<M>, failed: bool) -> bool {
    cube.team().max(if failed { 1.0 } else { 0.0 }) > 0.0
}

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

impl CheckpointPlan {
    fn enabled(&self) -> bool {
        self.every > 0 || self.minutes > 0.0
    }
}

/// Whether to stop on a signal and whether the wall clock calls for a checkpoint, agreed by
/// all workers (each sees its own signal flag and clock; all must act at the same step).
fn agree_on_stop<M: Model>(cube: &mut Cube<M>, stop: bool, clock_due: bool) -> (bool, bool) {
    let mut v = [stop as u8 as f64, clock_due as u8 as f64];
    cube.team().reduce(&mut v, Reduce::Max);
    (v[0] > 0.0, v[1] > 0.0)
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
    /// Newton's method with the assembled tangent (`src/solve/implicit.rs`).
    Implicit {
        tolerance: f64,
        max_iterations: u64,
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
            } => Box::new(Newton::new(*tolerance, *max_iterations, stop_at_broken)),
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
    pub converged: u64,
    /// The last load step's solve (quasi-static solvers).
    pub solved: Option<Relaxed>,
    /// Broken bonds at the last history row.
    pub broken: usize,
    pub shuffles: u64,
    pub stopped_at_broken: bool,
    pub stopped_at_probe: Option<String>,
    pub interrupted: Option<PathBuf>,
    pub checkpoints: Vec<(PathBuf, u64, f64)>,
}

/// The root's history and frame files, and the first error writing them: kept until every
/// worker has agreed to stop (an error on one worker must not leave the others waiting).
struct Files {
    history: Option<History>,
    frames: Option<Frames>,
    error: Option<String>,
}

impl Files {
    fn open(plan: &Plan, root: bool) -> Files {
        let mut files = Files {
            history: None,
            frames: None,
            error: None,
        };
        if !root {
            return files;
        }
        let (dir, first) = (&plan.dir, plan.first_step);
        let h = if first > 0 {
            History::resume(&dir.join("history.csv"), &plan.columns, first, plan.every)
        } else {
            History::create(&dir.join("history.csv"), &plan.columns)
        };
        match h {
            Ok(h) => files.history = Some(h),
            Err(e) => files.error = Some(plan.io(e)),
        }
        if plan.frames_every > 0 && files.error.is_none() {
            let f = if first > 0 {
                Frames::resume(dir, first, plan.frames_every)
            } else {
                Frames::new(dir).map_err(|e| plan.io(e))
            };
            match f {
                Ok(f) => files.frames = Some(f),
                Err(e) => files.error = Some(e),
            }
        }
        files
    }

    /// Fails on every worker if any worker failed.
    fn agree<M: Model>(&mut self, cube: &mut Cube<M>) -> Result<(), String> {
        if any_failed(cube, self.error.is_some()) {
            return Err(self
                .error
                .take()
                .unwrap_or_else(|| "another worker failed".into()));
        }
        Ok(())
    }
}

impl Plan {
    pub fn io(&self, e: std::io::Error) -> String {
        format!("writing output in {}: {e}", self.dir.display())
    }
}

/// The step loop of one worker; the root (rank 0) writes the output and returns the summary.
pub(crate) fn drive<M: Model>(
    mut cube: Cube<M>,
    plan: &Plan,
    mut store: Option<FrameStore<M>>,
    resume: Option<&Snapshot>,
) -> Result<Option<Summary>, String> {
    let root = cube.wall.transport().rank() == 0;
    start(&mut cube, resume);
    let mut files = Files::open(plan, root);
    let mut solver = plan.solver.start::<M>(root, plan.stop_at_broken);
    let first = plan.first_step;
    let mut tally = Tally {
        evaluations: plan.static_evaluations + plan.solver.setup_evaluations(),
        ..Tally::default()
    };
    let mut clock = CheckpointClock::new(cube.wall.transport().size());
    let mut progress = Progress::new(plan.steps, root && plan.progress && !plan.quiet);
    let wall = Instant::now();
    for step in first..=plan.steps {
        if step > first {
            match solver.advance(&mut cube, step)? {
                Some(r) => {
                    tally.evaluations += r.iterations;
                    tally.converged += r.converged as u64;
                    tally.solved = Some(r);
                }
                None => tally.evaluations += 1,
            }
            shuffle_when_due(&mut cube, plan, step, &mut tally)?;
        }
        // Enough bonds broken ends the run here, as if this were the last step.
        let halted = step > first && broken_enough(&mut cube, plan.stop_at_broken);
        tally.stopped_at_broken |= halted;
        let mut last = step == plan.steps || halted;
        last |= observe(
            &mut cube, plan, step, last, &mut files, &mut store, &mut tally,
        )?;
        progress.update(step, tally.broken);
        if step > first && clock.checkpoint(&mut cube, plan, step, last, &mut files, &mut tally)? {
            break;
        }
        if last {
            break;
        }
    }
    files.agree(&mut cube)?;
    let seconds = wall.elapsed().as_secs_f64();
    super::record::finish(cube, plan, files.history, tally, seconds)
}

/// Restores a checkpoint's bonds, makes the bond counts whole, computes the first forces.
fn start<M: Model>(cube: &mut Cube<M>, resume: Option<&Snapshot>) {
    let t = Instant::now();
    if let Some(c) = resume {
        c.restore_bonds(cube);
    }
    cube.start();
    if let Some(c) = resume {
        c.restore_forces(cube);
    }
    cube.sim.timing.lap(Phase::Setup, t);
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

/// `[time] stop_at_broken_bonds` reached, on every worker (a reduction).
fn broken_enough<M: Model>(cube: &mut Cube<M>, stop_at_broken: u64) -> bool {
    stop_at_broken > 0 && {
        let mut n = [cube.broken_count() as f64];
        cube.team().reduce(&mut n, Reduce::Sum);
        n[0] >= stop_at_broken as f64
    }
}

/// The history row and the frame, when due; whether a probe's `stop_beyond` ends the run here.
fn observe<M: Model>(
    cube: &mut Cube<M>,
    plan: &Plan,
    step: u64,
    last: bool,
    files: &mut Files,
    store: &mut Option<FrameStore<M>>,
    tally: &mut Tally,
) -> Result<bool, String> {
    // A restarted run has the row and frame of its first step from before.
    let again = plan.first_step > 0 && step == plan.first_step;
    let want_row = (step.is_multiple_of(plan.every) || last) && !again;
    let want_frame =
        plan.frames_every > 0 && (step.is_multiple_of(plan.frames_every) || last) && !again;
    if !(want_row || want_frame) {
        return Ok(false);
    }
    let t = Instant::now();
    files.agree(cube)?;
    let limit = (!plan.solver.quasi_static()).then_some(0.5 * plan.spacing);
    if let Some(gid) = first_blown_up(cube, limit) {
        return Err(blow_up(
            cube,
            plan,
            store.take(),
            files.frames.take(),
            gid,
            step,
        ));
    }
    let damage = cube.damage();
    let mut probe_halt = None;
    if want_row {
        let mut row = Row::reduced(cube, &damage, plan.probe_stops.len());
        // Every worker has the whole row, so all stop alike.
        probe_halt = plan
            .probe_stops
            .iter()
            .zip(&row.probes)
            .find_map(|((name, limit), u)| {
                let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                (length > *limit).then(|| name.clone())
            });
        if plan.solver.quasi_static() {
            let s = tally.solved.unwrap_or_default();
            row.solve = Some((s.iterations, s.residual));
        }
        tally.broken = row.broken_bonds as usize;
        if let Some(h) = files.history.as_mut() {
            if let Err(e) = h.row(&row.values()) {
                files.error = Some(plan.io(e));
            }
        }
    }
    // A probe's stop makes this the last step: its frame is written too.
    if want_frame || (plan.frames_every > 0 && probe_halt.is_some()) {
        gather_frame(cube, &damage, store);
        if let (Some(f), Some(s)) = (files.frames.as_mut(), store.as_ref()) {
            if let Err(e) = f.write(step, cube.sim.time, &s.particles, &s.damage, tally.broken) {
                files.error = Some(plan.io(e));
            }
        }
    }
    cube.sim.timing.lap(Phase::Output, t);
    let halts = probe_halt.is_some();
    if halts {
        tally.stopped_at_probe = probe_halt;
    }
    Ok(halts)
}

/// Checkpoints by step count, by wall time, at the end, and on a signal.
struct CheckpointClock {
    last: Instant,
    workers: usize,
}

impl CheckpointClock {
    fn new(workers: usize) -> Self {
        CheckpointClock {
            last: Instant::now(),
            workers,
        }
    }

    /// Writes a checkpoint when one is due; true when a signal stops the run here.
    fn checkpoint<M: Model>(
        &mut self,
        cube: &mut Cube<M>,
        plan: &Plan,
        step: u64,
        last: bool,
        files: &mut Files,
        tally: &mut Tally,
    ) -> Result<bool, String> {
        let ck = &plan.checkpoints;
        // All workers must act on a signal at the same step, so they agree on it: at every
        // step on one procCube (free), every 10 steps on several (a reduction costs a few
        // microseconds, 1-2 % of a small scene's step).
        let (stop, clock_due) = if self.workers == 1 || step.is_multiple_of(10) || last {
            let clock_due =
                ck.minutes > 0.0 && self.last.elapsed().as_secs_f64() >= 60.0 * ck.minutes;
            agree_on_stop(cube, crate::output::signals::requested(), clock_due)
        } else {
            (false, false)
        };
        let due = stop
            || clock_due
            || (ck.every > 0 && step.is_multiple_of(ck.every))
            || (ck.enabled() && last);
        if due {
            let t = Instant::now();
            if let Some(c) = Checkpoint::gather(cube, ck.scene_hash, &ck.deck) {
                match c.write(&ck.dir, ck.keep) {
                    Ok((path, size)) => {
                        tally
                            .checkpoints
                            .push((path, size, t.elapsed().as_secs_f64()))
                    }
                    Err(e) => {
                        files.error =
                            Some(format!("writing checkpoint in {}: {e}", ck.dir.display()))
                    }
                }
            }
            self.last = Instant::now();
            cube.sim.timing.lap(Phase::Output, t);
        }
        if stop {
            files.agree(cube)?;
            tally.interrupted = Some(
                tally
                    .checkpoints
                    .last()
                    .map(|c| c.0.clone())
                    .unwrap_or_else(|| ck.dir.clone()),
            );
        }
        Ok(stop)
    }
}
