//! `pdq run` and `pdq check`: drive a simulation built from a deck and report on it.

use crate::engine::particles::Particles;
use crate::engine::timing::Phase;
use crate::input::deck::{Scene, SolverSpec};
use crate::input::setup::{self, Setup};
use crate::model::attributes::Attributes;
use crate::model::{Model, ModelVisitor};
use crate::output::checkpoint::{self, Checkpoint};
use crate::output::{Frames, History, Progress};
use crate::parallel::comm::{f64s, Reduce, Transport};
use crate::parallel::decomposition::{Layout, Procs, Walls};
use crate::parallel::{self, Cube};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// What a finished run reports.
#[derive(Clone, Debug)]
pub struct Summary {
    pub particles: usize,
    pub bonds: usize,
    pub steps: u64,
    pub dt: f64,
    pub broken: usize,
    pub kinetic_energy: f64,
    pub strain_energy: f64,
    pub output: PathBuf,
    pub seconds: f64,
    pub timing: String,
    pub layout: String,
    /// Particle shuffles that moved particles between procCubes.
    pub shuffles: u64,
    /// Final positions by global id, and the broken bonds as sorted global id pairs (when the
    /// deck asks for `final_state`, or for tests).
    pub positions: Vec<[f64; 3]>,
    /// Final damage by global id.
    pub damage: Vec<f64>,
    pub broken_pairs: Vec<(u32, u32)>,
    /// The run stopped early on SIGTERM or SIGINT after writing this checkpoint.
    pub interrupted: Option<PathBuf>,
    /// Checkpoints written: path, size in bytes, seconds to gather and write.
    pub checkpoints: Vec<(PathBuf, u64, f64)>,
    /// The step the run started from (a restart's checkpoint step, else 0).
    pub first_step: u64,
    /// Force evaluations of the step loop: one per step explicitly, the iterations of every
    /// load step under relaxation.
    pub force_evaluations: u64,
    /// Under relaxation: load steps that reached the tolerance within `max_iterations`.
    pub converged_steps: u64,
    /// The run ended before its last step because `[time] stop_at_broken_bonds` was reached.
    pub stopped_at_broken: bool,
    /// The run ended before its last step because this probe's displacement passed its
    /// `stop_beyond`.
    pub stopped_at_probe: Option<String>,
}

/// Options the command line may set over the deck.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub steps: Option<u64>,
    pub output: Option<PathBuf>,
    pub quiet: bool,
    /// Worker threads (one procCube each); the deck's `[parallel] threads` otherwise.
    pub threads: Option<usize>,
    pub procs: Option<Procs>,
    pub walls: Option<Walls>,
    /// Resume from this checkpoint, or from the newest readable one in this directory.
    pub restart: Option<PathBuf>,
}

/// Runs a deck to the end.
pub fn run(scene: &Scene, opts: &RunOptions) -> Result<Summary, String> {
    struct Visit<'a>(&'a Scene, &'a RunOptions);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<Summary, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
            run_setup(setup, self.0, self.1)
        }
    }
    setup::with_model(scene, Visit(scene, opts)).map_err(|e| e.to_string())?
}

fn columns<M: Model>(setup: &Setup<M>) -> Vec<String> {
    let mut c: Vec<String> = [
        "step",
        "time",
        "kinetic_energy",
        "strain_energy",
        "total_energy",
        "broken_bonds",
        "max_damage",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for l in &setup.sim.loads {
        c.push(format!("load_{}", l.name));
    }
    for b in &setup.sim.constraints {
        for &d in &b.dofs {
            c.push(format!("reaction_{}_{}", b.name, dof_name::<M>(d)));
        }
    }
    for (name, _) in &setup.probes {
        for k in ["ux", "uy", "uz"] {
            c.push(format!("{name}_{k}"));
        }
    }
    c.push("residual_force".into());
    if let SolverSpec::Relaxation { .. } = setup.solver {
        c.push("iterations".into());
        c.push("residual".into());
    }
    c
}

/// A quasi-static solver: each step is a load step solved to equilibrium.
#[derive(Clone)]
enum QuasiStatic {
    /// Adaptive dynamic relaxation with these fictitious masses by global id.
    Adr {
        mass: crate::solve::adr::FictitiousMass,
        tolerance: f64,
        max_iterations: u64,
    },
    /// Newton's method with the assembled tangent (`src/implicit.rs`).
    Implicit { tolerance: f64, max_iterations: u64 },
}

/// x, y, z for translations, else the model's name of the generalized force (`moment_x`,
/// `heat`).
fn dof_name<M: Model>(d: usize) -> String {
    if d < 3 {
        return ["x", "y", "z"][d].into();
    }
    let mut offset = 0;
    for f in <M::Force as Attributes>::FIELDS {
        if d < offset + f.len {
            return match f.len {
                1 => f.name.to_string(),
                3 => format!("{}_{}", f.name, ["x", "y", "z"][d - offset]),
                _ => format!("{}{}", f.name, d - offset),
            };
        }
        offset += f.len;
    }
    format!("dof{d}")
}

/// One procCube's share of a history row, reduced over all procCubes; the root gets the row.
fn row<M: Model>(cube: &mut Cube<M>, damage: &[f64], n_probes: usize) -> Vec<f64> {
    let sim = &cube.sim;
    let (ke, se) = (sim.kinetic_energy(), sim.strain_energy());
    let mut sums = vec![ke, se, cube.broken_count() as f64];
    for l in &sim.loads {
        let t = l.total(sim.time);
        let norm = (l.vector[0].powi(2) + l.vector[1].powi(2) + l.vector[2].powi(2)).sqrt();
        let along = if norm > 0.0 {
            (t[0] * l.vector[0] + t[1] * l.vector[1] + t[2] * l.vector[2]) / norm
        } else {
            0.0
        };
        sums.push(along);
    }
    for b in &sim.constraints {
        sums.extend_from_slice(&b.reaction);
    }
    let first_probe = sums.len();
    sums.resize(first_probe + 3 * n_probes, 0.0);
    for &(k, i) in &cube.probes {
        sums[first_probe + 3 * k..first_probe + 3 * k + 3]
            .copy_from_slice(&sim.particles.displacement(i));
    }
    // Σ F² over the free second-order DOFs (supported ones hold 0): how far from equilibrium.
    let n2 = crate::model::second_order::<M>();
    let p = &sim.particles;
    sums.push(
        (0..p.n_owned)
            .flat_map(|i| p.force[i].as_slice()[..n2].iter())
            .map(|f| f * f)
            .sum(),
    );
    let (step, time) = (sim.step as f64, sim.time);
    let mut team = cube.team();
    team.reduce(&mut sums, Reduce::Sum);
    let max_damage = team.max(damage.iter().cloned().fold(0.0, f64::max));
    let mut r = vec![
        step,
        time,
        sums[0],
        sums[1],
        sums[0] + sums[1],
        sums[2],
        max_damage,
    ];
    let squared = sums.pop().unwrap_or(0.0);
    r.extend_from_slice(&sums[3..]);
    r.push(squared.sqrt());
    r
}

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
    let cause = if plan.relaxation.is_some() {
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

/// Owned particles' global indices, damage and every declared record (alterable, fixed, state,
/// force), gathered on the root.
fn gather_frame<M: Model>(cube: &mut Cube<M>, damage: &[f64], store: &mut Option<FrameStore<M>>) {
    // Reference positions travel too: a shuffle moves them with particles it wraps around a
    // periodic box.
    let lens = [
        <M::Alter as Attributes>::LEN,
        <M::Fixed as Attributes>::LEN,
        <M::State as Attributes>::LEN,
        <M::Force as Attributes>::LEN,
    ];
    let record = 5 + lens.iter().sum::<usize>();
    let p = &cube.sim.particles;
    let n = p.n_owned;
    let mut mine = Vec::with_capacity(n * record);
    for (i, &d) in damage.iter().enumerate().take(n) {
        mine.push(p.gid[i] as f64);
        mine.push(d);
        mine.extend_from_slice(&p.x0[i]);
        mine.extend_from_slice(p.alter[i].as_slice());
        mine.extend_from_slice(p.fixed[i].as_slice());
        mine.extend_from_slice(p.state[i].as_slice());
        mine.extend_from_slice(p.force[i].as_slice());
    }
    let all = cube.team().gather(bytemuck::cast_slice(&mine));
    if let (Some(all), Some(store)) = (all, store.as_mut()) {
        for bytes in all {
            for rec in f64s(&bytes).chunks_exact(record) {
                let g = store.index_of[rec[0] as usize] as usize;
                store.damage[g] = rec[1];
                store.particles.x0[g] = [rec[2], rec[3], rec[4]];
                let sp = &mut store.particles;
                let targets = [
                    sp.alter[g].as_mut_slice(),
                    sp.fixed[g].as_mut_slice(),
                    sp.state[g].as_mut_slice(),
                    sp.force[g].as_mut_slice(),
                ];
                let mut at = 5;
                for (t, len) in targets.into_iter().zip(lens) {
                    t.copy_from_slice(&rec[at..at + len]);
                    at += len;
                }
            }
        }
    }
}

/// The whole scene on the root, refreshed from all procCubes for each frame.
struct FrameStore<M: Model> {
    particles: Particles<M>,
    damage: Vec<f64>,
    /// Store index of each global id.
    index_of: Vec<u32>,
}

/// What every worker needs to know about the run beyond its own procCube.
struct Plan {
    columns: Vec<String>,
    dir: PathBuf,
    steps: u64,
    every: u64,
    frames_every: u64,
    progress: bool,
    quiet: bool,
    final_state: bool,
    shuffle_every: u64,
    /// `[time] stop_at_broken_bonds` (0 = off).
    stop_at_broken: u64,
    /// Each probe's name and `stop_beyond` (infinite when not given), in deck order.
    probe_stops: Vec<(String, f64)>,
    layout: String,
    /// The step the loop starts from: 0, or the step of the checkpoint it resumes.
    first_step: u64,
    /// Force evaluations of the static start (`[time] static_until`), 0 without one.
    static_evaluations: u64,
    /// A quasi-static solver, if the deck asks for one (else explicit time steps).
    relaxation: Option<QuasiStatic>,
    /// For the blow-up diagnosis: the stable time step, what it is, and the material names.
    dt_critical: f64,
    dt_critical_name: &'static str,
    material_names: Vec<String>,
    spacing: f64,
    checkpoints: CheckpointPlan,
}

/// When to write checkpoints, and what identifies them.
struct CheckpointPlan {
    dir: PathBuf,
    every: u64,
    minutes: f64,
    keep: usize,
    scene_hash: u64,
    deck: String,
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

/// The step loop of one worker; the root (rank 0) writes the output and returns the summary.
fn drive<M: Model>(
    mut cube: Cube<M>,
    plan: &Plan,
    mut store: Option<FrameStore<M>>,
    resume: Option<&Checkpoint>,
) -> Result<Option<Summary>, String> {
    let root = cube.wall.transport().rank() == 0;
    let t = Instant::now();
    if let Some(c) = resume {
        c.restore_bonds(&mut cube);
    }
    cube.start();
    if let Some(c) = resume {
        c.restore_forces(&mut cube);
    }
    cube.sim.timing.lap(Phase::Setup, t);
    let dir = &plan.dir;
    let io = |e: std::io::Error| format!("writing output in {}: {e}", dir.display());

    let mut error: Option<String> = None;
    let mut history = None;
    let mut frames = None;
    let first = plan.first_step;
    if root {
        let h = if first > 0 {
            History::resume(&dir.join("history.csv"), &plan.columns, first, plan.every)
        } else {
            History::create(&dir.join("history.csv"), &plan.columns)
        };
        match h {
            Ok(h) => history = Some(h),
            Err(e) => error = Some(io(e)),
        }
        if plan.frames_every > 0 && error.is_none() {
            let f = if first > 0 {
                Frames::resume(dir, first, plan.frames_every)
            } else {
                Frames::new(dir).map_err(io)
            };
            match f {
                Ok(f) => frames = Some(f),
                Err(e) => error = Some(e),
            }
        }
    }
    let ck = &plan.checkpoints;
    let mut checkpoints: Vec<(PathBuf, u64, f64)> = Vec::new();
    let mut last_checkpoint = Instant::now();
    let mut interrupted = None;
    // The fictitious mass's estimate and a static start count: force evaluations the run
    // needed.
    let estimate = plan.static_evaluations
        + match &plan.relaxation {
            Some(QuasiStatic::Adr { mass, .. }) => mass.evaluations,
            _ => 0,
        };
    let (mut evaluations, mut converged) = (estimate, 0u64);
    // Grows (doubles) only if relaxation diverges with the estimated masses.
    let mut mass_scale = 1.0f64;
    let mut relaxed: Option<crate::solve::adr::Relaxed> = None;
    let mut tangent: Option<crate::solve::implicit::Tangent> = None;
    let workers = cube.wall.transport().size();
    let mut progress = Progress::new(plan.steps, root && plan.progress && !plan.quiet);
    let wall = Instant::now();
    let mut broken = 0usize;
    let mut shuffles = 0u64;
    let mut stopped_at_broken = false;
    let mut stopped_at_probe = None;
    for step in first..=plan.steps {
        if step > first {
            let r = match &plan.relaxation {
                None => {
                    cube.advance();
                    evaluations += 1;
                    None
                }
                Some(QuasiStatic::Adr {
                    mass,
                    tolerance,
                    max_iterations,
                }) => {
                    let before = mass_scale;
                    let r =
                        cube.relax_step(&mass.by_gid, &mut mass_scale, *tolerance, *max_iterations);
                    if mass_scale != before && root {
                        eprintln!(
                            "warning    relaxation diverged at step {step}: repeated with the fictitious masses ×{mass_scale}{}",
                            if r.diverged { ", and diverged again" } else { "" }
                        );
                    }
                    Some(r)
                }
                Some(QuasiStatic::Implicit {
                    tolerance,
                    max_iterations,
                }) => Some(
                    cube.implicit_step(
                        &mut tangent,
                        *tolerance,
                        *max_iterations,
                        plan.stop_at_broken,
                    )
                    .map_err(|e| {
                        format!("{e} (or use [solver] kind = \"adr\", which assembles no tangent)")
                    })?,
                ),
            };
            if let Some(r) = r {
                evaluations += r.iterations;
                converged += r.converged as u64;
                relaxed = Some(r);
            }
            if plan.shuffle_every > 0 && step % plan.shuffle_every == 0 {
                let t = Instant::now();
                // Every worker sees the same scene here, so all fail alike.
                if cube.shuffle()? {
                    shuffles += 1;
                }
                cube.sim.timing.lap(Phase::Communication, t);
            }
        }
        // Enough bonds broken ends the run here, as if this were the last step.
        let halted = plan.stop_at_broken > 0 && step > first && {
            let mut n = [cube.broken_count() as f64];
            cube.team().reduce(&mut n, Reduce::Sum);
            n[0] >= plan.stop_at_broken as f64
        };
        stopped_at_broken |= halted;
        let mut last = step == plan.steps || halted;
        // A restarted run has the row and frame of its first step from before.
        let again = first > 0 && step == first;
        let want_row = (step % plan.every == 0 || last) && !again;
        let want_frame = plan.frames_every > 0 && (step % plan.frames_every == 0 || last) && !again;
        if want_row || want_frame {
            let t = Instant::now();
            if any_failed(&mut cube, error.is_some()) {
                return Err(error.unwrap_or_else(|| "another worker failed".into()));
            }
            let limit = plan.relaxation.is_none().then_some(0.5 * plan.spacing);
            if let Some(gid) = first_blown_up(&mut cube, limit) {
                return Err(blow_up(&mut cube, plan, store, frames, gid, step));
            }
            let damage = cube.damage();
            let mut probe_halt = None;
            if want_row {
                let n_probes = plan.probe_stops.len();
                let mut r = row(&mut cube, &damage, n_probes);
                // The probes' displacements end the row (before the residual); every worker
                // has the whole row, so all stop alike.
                let first_probe = r.len() - 1 - 3 * n_probes;
                probe_halt = plan
                    .probe_stops
                    .iter()
                    .enumerate()
                    .find_map(|(k, (name, limit))| {
                        let u = &r[first_probe + 3 * k..first_probe + 3 * k + 3];
                        let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                        (length > *limit).then(|| name.clone())
                    });
                if plan.relaxation.is_some() {
                    let last = relaxed.unwrap_or_default();
                    r.push(last.iterations as f64);
                    r.push(last.residual);
                }
                broken = r[5] as usize;
                if let Some(h) = history.as_mut() {
                    if let Err(e) = h.row(&r) {
                        error = Some(io(e));
                    }
                }
            }
            // A probe's stop makes this the last step: its frame is written too.
            let want_frame = want_frame || (plan.frames_every > 0 && probe_halt.is_some());
            if probe_halt.is_some() {
                last = true;
                stopped_at_probe = probe_halt;
            }
            if want_frame {
                gather_frame(&mut cube, &damage, &mut store);
                if let (Some(f), Some(s)) = (frames.as_mut(), store.as_ref()) {
                    if let Err(e) = f.write(step, cube.sim.time, &s.particles, &s.damage, broken) {
                        error = Some(io(e));
                    }
                }
            }
            cube.sim.timing.lap(Phase::Output, t);
        }
        progress.update(step, broken);
        // All workers must act on a signal at the same step, so they agree on it: at every
        // step on one procCube (free), every 10 steps on several (a reduction costs a few
        // microseconds, 1-2 % of a small scene's step).
        if step > first {
            let (stop, clock_due) = if workers == 1 || step.is_multiple_of(10) || last {
                let clock_due = ck.minutes > 0.0
                    && last_checkpoint.elapsed().as_secs_f64() >= 60.0 * ck.minutes;
                agree_on_stop(&mut cube, crate::output::signals::requested(), clock_due)
            } else {
                (false, false)
            };
            let due = stop
                || clock_due
                || (ck.every > 0 && step.is_multiple_of(ck.every))
                || (ck.enabled() && last);
            if due {
                let t = Instant::now();
                let c = Checkpoint::gather(&mut cube, ck.scene_hash, &ck.deck);
                if let Some(c) = c {
                    match c.write(&ck.dir, ck.keep) {
                        Ok((path, size)) => {
                            checkpoints.push((path, size, t.elapsed().as_secs_f64()))
                        }
                        Err(e) => {
                            error = Some(format!("writing checkpoint in {}: {e}", ck.dir.display()))
                        }
                    }
                }
                last_checkpoint = Instant::now();
                cube.sim.timing.lap(Phase::Output, t);
            }
            if stop {
                if any_failed(&mut cube, error.is_some()) {
                    return Err(error.unwrap_or_else(|| "another worker failed".into()));
                }
                interrupted = Some(
                    checkpoints
                        .last()
                        .map(|c| c.0.clone())
                        .unwrap_or_else(|| ck.dir.clone()),
                );
                break;
            }
        }
        if last {
            break;
        }
    }
    let steps_done = cube.sim.step;
    if any_failed(&mut cube, error.is_some()) {
        return Err(error.unwrap_or_else(|| "another worker failed".into()));
    }
    let seconds = wall.elapsed().as_secs_f64();

    // Totals, the final state, and where each procCube's time went.
    let n_global = cube.global_particles;
    let mut totals = [
        (cube.sim.bonds.len() + cube.dropped.len()) as f64,
        cube.broken_count() as f64,
        cube.sim.kinetic_energy(),
        cube.sim.strain_energy(),
    ];
    cube.team().reduce(&mut totals, Reduce::Sum);
    let damage = cube.damage();
    let mut mine: Vec<f64> = Vec::new();
    for (i, d) in damage.iter().enumerate() {
        mine.push(cube.sim.particles.gid[i] as f64);
        mine.extend_from_slice(&cube.sim.particles.pos(i));
        mine.push(*d);
    }
    let positions = cube.team().gather(bytemuck::cast_slice(&mine));
    let pairs: Vec<f64> = cube
        .broken_pairs()
        .iter()
        .flat_map(|&(a, b)| [a as f64, b as f64])
        .collect();
    let pairs = cube.team().gather(bytemuck::cast_slice(&pairs));
    let traffic = cube.wall.traffic;
    let tm = &cube.sim.timing;
    let balance = [
        cube.sim.particles.n_owned as f64,
        cube.plan.ghosts() as f64,
        tm.get(Phase::Forces).as_secs_f64() + tm.get(Phase::State).as_secs_f64(),
        tm.get(Phase::Communication).as_secs_f64(),
        tm.total().as_secs_f64()
            - tm.get(Phase::Setup).as_secs_f64()
            - tm.get(Phase::Output).as_secs_f64(),
        traffic.bytes as f64,
    ];
    let balance = cube.team().gather(bytemuck::cast_slice(&balance));
    if !root {
        return Ok(None);
    }
    let mut position = vec![[f64::NAN; 3]; n_global];
    let mut damage_by_id = vec![f64::NAN; n_global];
    for bytes in positions.unwrap_or_default() {
        for rec in f64s(&bytes).chunks_exact(5) {
            position[rec[0] as usize] = [rec[1], rec[2], rec[3]];
            damage_by_id[rec[0] as usize] = rec[4];
        }
    }
    let mut broken_pairs: Vec<(u32, u32)> = pairs
        .unwrap_or_default()
        .iter()
        .flat_map(|b| {
            f64s(b)
                .chunks_exact(2)
                .map(|c| (c[0] as u32, c[1] as u32))
                .collect::<Vec<_>>()
        })
        .collect();
    broken_pairs.sort_unstable();
    let balance: Vec<Vec<f64>> = balance
        .unwrap_or_default()
        .iter()
        .map(|b| f64s(b))
        .collect();
    let mut timing = cube
        .sim
        .timing
        .table(n_global as f64 * (steps_done - first) as f64);
    let _ = writeln!(
        timing,
        "bonds: {} ({} broken); {}{}",
        totals[0] as usize,
        totals[1] as usize,
        plan.layout,
        if shuffles > 0 {
            format!(", {shuffles} shuffles moved particles")
        } else {
            String::new()
        }
    );
    if balance.len() > 1 {
        timing.push_str(&balance_table(&balance, steps_done - first));
    }
    if let Some(h) = history.as_mut() {
        h.flush().map_err(io)?;
    }
    std::fs::write(dir.join("timing.txt"), &timing).map_err(io)?;
    if plan.final_state {
        write_final_state(dir, &position, &damage_by_id, &broken_pairs).map_err(io)?;
    }
    if let Some((_, size, secs)) = checkpoints.last() {
        let _ = writeln!(
            timing,
            "checkpoints: {} written, the last {:.1} MB in {:.3} s",
            checkpoints.len(),
            *size as f64 / 1e6,
            secs
        );
    }
    Ok(Some(Summary {
        particles: n_global,
        bonds: totals[0] as usize,
        steps: steps_done,
        dt: cube.sim.dt,
        broken: totals[1] as usize,
        kinetic_energy: totals[2],
        strain_energy: totals[3],
        output: plan.dir.clone(),
        seconds,
        timing,
        layout: plan.layout.clone(),
        shuffles,
        positions: position,
        damage: damage_by_id,
        broken_pairs,
        interrupted,
        checkpoints,
        first_step: first,
        force_evaluations: evaluations,
        converged_steps: converged,
        stopped_at_broken,
        stopped_at_probe,
    }))
}

/// Final positions by global id and the broken bonds, at full precision, for comparing runs.
fn write_final_state(
    dir: &std::path::Path,
    position: &[[f64; 3]],
    damage: &[f64],
    broken: &[(u32, u32)],
) -> std::io::Result<()> {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("final_positions.csv"))?);
    writeln!(f, "id,x,y,z,damage")?;
    for (g, (p, d)) in position.iter().zip(damage).enumerate() {
        writeln!(
            f,
            "{g},{:.17e},{:.17e},{:.17e},{:.17e}",
            p[0], p[1], p[2], d
        )?;
    }
    f.flush()?;
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("broken_bonds.csv"))?);
    writeln!(f, "id_a,id_b")?;
    for (a, b) in broken {
        writeln!(f, "{a},{b}")?;
    }
    f.flush()
}

/// Particles and time per procCube, max/mean, and the share of time spent communicating.
fn balance_table(rows: &[Vec<f64>], steps: u64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<9} {:>10} {:>8} {:>10} {:>10} {:>10} {:>12}",
        "procCube", "particles", "ghosts", "forces s", "comm s", "step s", "bytes/step"
    );
    for (k, r) in rows.iter().enumerate() {
        let _ = writeln!(
            s,
            "{:<9} {:>10} {:>8} {:>10.3} {:>10.3} {:>10.3} {:>12.0}",
            k,
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            r[5] / steps.max(1) as f64
        );
    }
    let col = |c: usize| -> (f64, f64) {
        let max = rows.iter().map(|r| r[c]).fold(0.0, f64::max);
        let mean = rows.iter().map(|r| r[c]).sum::<f64>() / rows.len() as f64;
        (max, mean)
    };
    let (pmax, pmean) = col(0);
    let (fmax, fmean) = col(2);
    let (cmax, _) = col(3);
    let (smax, _) = col(4);
    let _ = writeln!(
        s,
        "load balance: particles max/mean {:.3}, force time max/mean {:.3}; communication {:.1}% of the slowest step loop",
        pmax / pmean.max(1e-300),
        fmax / fmean.max(1e-300),
        100.0 * cmax / smax.max(1e-300)
    );
    s
}

/// The layout, and how many workers: MPI ranks when launched by `mpirun`, threads otherwise.
fn choose_layout<M: Model>(
    setup: &Setup<M>,
    scene: &Scene,
    opts: &RunOptions,
    workers: usize,
) -> Result<Layout, String> {
    let procs = opts.procs.clone().unwrap_or(scene.parallel.procs.clone());
    let walls = opts.walls.unwrap_or(scene.parallel.walls);
    parallel::layout(setup, &procs, workers, walls).map_err(|e| {
        if scene.parallel.line > 0 && opts.procs.is_none() {
            format!("{}:{}: {e}", scene.file, scene.parallel.line)
        } else {
            e
        }
    })
}

fn run_setup<M: Model>(
    mut setup: Setup<M>,
    scene: &Scene,
    opts: &RunOptions,
) -> Result<Summary, String> {
    if let Some(n) = opts.steps {
        setup.steps = n;
    }
    let dir = opts
        .output
        .clone()
        .unwrap_or_else(|| scene.output.directory.clone());
    let relaxation = match setup.solver {
        SolverSpec::Explicit => None,
        SolverSpec::Relaxation {
            tolerance,
            max_iterations,
            implicit,
            ..
        } => {
            crate::solve::adr::check_model::<M>(implicit)
                .map_err(|e| format!("{}:{}: {e}", scene.file, scene.solver_line))?;
            if implicit {
                Some(QuasiStatic::Implicit {
                    tolerance,
                    max_iterations,
                })
            } else {
                let mass = crate::solve::adr::fictitious_mass(&mut setup.sim);
                if !opts.quiet {
                    match mass.lambda_max {
                        Some(l) => eprintln!(
                            "relaxation fictitious mass from the stiffest mode, λ_max = {l:.4} of the Gershgorin bound's 2 ({} force evaluations)",
                            mass.evaluations
                        ),
                        None => eprintln!("relaxation fictitious mass: the book's (no free DOF with a bond to estimate from)"),
                    }
                }
                Some(QuasiStatic::Adr {
                    mass,
                    tolerance,
                    max_iterations,
                })
            }
        }
    };
    let scene_hash = checkpoint::scene_hash(&setup, scene);
    let resume = match opts.restart.as_ref().or(scene.output.restart.as_ref()) {
        Some(from) => Some(resume_from(
            &mut setup,
            from,
            scene_hash,
            scene.time.static_until.unwrap_or(0.0),
        )?),
        None => None,
    };
    // A static start is handed to the procCubes as a restart at step 0 is; a restart from a
    // checkpoint has passed it already.
    let static_start = match (&resume, scene.time.static_until) {
        (None, Some(until)) => {
            let walls = opts.walls.unwrap_or(scene.parallel.walls);
            let at = |e: String| format!("{}:{}: {e}", scene.file, scene.time_line);
            let s =
                crate::solve::static_start::solve(&setup, until, walls, scene_hash, &scene.file)
                    .map_err(at)?;
            let stop = scene.time.stop_at_broken_bonds;
            if stop > 0 && s.broken as u64 >= stop {
                return Err(at(format!(
                    "[time] the static start to static_until = {until:e} broke {} bonds, already as many as stop_at_broken_bonds = {stop}: the run would stop before it began; start earlier",
                    s.broken
                )));
            }
            s.checkpoint.restore_particles(&mut setup);
            Some(s)
        }
        _ => None,
    };
    let resume = resume
        .as_ref()
        .or(static_start.as_ref().map(|s| &s.checkpoint));
    // Said after the run's header (`prepare`), by the root only.
    let static_line = static_start.as_ref().map(|s| s.describe());
    let say_static = |quiet: bool| {
        if let (Some(line), false) = (&static_line, quiet) {
            eprintln!("{line}");
        }
    };
    if let (Some(c), false) = (resume.filter(|_| static_start.is_none()), opts.quiet) {
        eprintln!(
            "restart    from step {} (t = {:.6e}) of {}: {} broken bonds",
            c.step,
            c.time,
            c.deck,
            c.broken.len()
        );
    }
    // The implicit solve assembles one matrix in one process.
    let one_cube = |layout: &Layout| -> Result<(), String> {
        let cubes: usize = layout.procs.iter().product();
        if matches!(relaxation, Some(QuasiStatic::Implicit { .. })) && cubes > 1 {
            return Err(format!(
                "{}:{}: [solver] kind = \"implicit\" runs on one procCube, the layout has {cubes} (--threads 1, no mpirun); use kind = \"adr\" for several",
                scene.file, scene.solver_line
            ));
        }
        Ok(())
    };
    let plan = |layout: &Layout| Plan {
        columns: columns(&setup),
        dir: dir.clone(),
        steps: setup.steps,
        every: scene.output.history_every,
        frames_every: scene.output.frames_every,
        progress: scene.output.progress,
        quiet: opts.quiet,
        final_state: scene.output.final_state,
        shuffle_every: scene.parallel.shuffle_every,
        stop_at_broken: scene.time.stop_at_broken_bonds,
        probe_stops: scene
            .probes
            .iter()
            .map(|p| (p.name.clone(), p.stop_beyond))
            .collect(),
        layout: layout.describe(),
        first_step: resume.map_or(0, |c| c.step),
        static_evaluations: static_start.as_ref().map_or(0, |s| s.evaluations),
        relaxation: relaxation.clone(),
        dt_critical: setup.dt_limit(),
        dt_critical_name: if setup.dt_measured.is_some() {
            "measured critical step"
        } else {
            "stable bound"
        },
        material_names: scene.materials.iter().map(|m| m.name.clone()).collect(),
        spacing: scene.spacing,
        checkpoints: CheckpointPlan {
            dir: dir.join("checkpoints"),
            every: scene.output.checkpoint_every,
            minutes: scene.output.checkpoint_minutes,
            keep: scene.output.checkpoint_keep,
            scene_hash,
            deck: scene.file.clone(),
        },
    };

    #[cfg(feature = "mpi")]
    if crate::parallel::comm_mpi::launched_by_mpirun() {
        let mpi = crate::parallel::comm_mpi::Mpi::init().ok_or("MPI was already initialized")?;
        let (rank, ranks) = (mpi.rank(), mpi.size());
        let layout = choose_layout(&setup, scene, opts, ranks)?;
        one_cube(&layout)?;
        // Every rank makes the directory (the same one, on a shared file system), so that a
        // failure stops them all instead of leaving some waiting for the root.
        let quiet = RunOptions {
            quiet: opts.quiet || rank != 0,
            ..opts.clone()
        };
        prepare(&setup, scene, &quiet, &dir, &layout, "ranks", ranks)?;
        say_static(quiet.quiet);
        let plans = crate::parallel::decomposition::cell_plans(&layout);
        let cube = parallel::build_cube(&setup, &layout, &plans, rank, Box::new(mpi));
        let p = plan(&layout);
        let store = (rank == 0).then(|| frame_store(setup));
        let summary = drive(cube, &p, store, resume)?;
        return match summary {
            Some(s) => {
                report(&s, opts, scene.output.frames_every > 0);
                Ok(s)
            }
            // Other ranks have nothing to print; a summary-less Ok ends them quietly.
            None => std::process::exit(0),
        };
    }

    let threads = opts.threads.unwrap_or(scene.parallel.threads);
    let layout = choose_layout(&setup, scene, opts, threads)?;
    one_cube(&layout)?;
    prepare(&setup, scene, opts, &dir, &layout, "threads", threads)?;
    say_static(opts.quiet);
    let cubes = parallel::thread_cubes(&setup, &layout);
    let p = plan(&layout);
    let store = std::sync::Mutex::new(Some(frame_store(setup)));
    let results = parallel::on_threads(cubes, |cube| {
        let s = if cube.plan.rank == 0 {
            store.lock().unwrap().take()
        } else {
            None
        };
        drive(cube, &p, s, resume)
    });
    let mut summary = None;
    for r in results {
        if let Some(s) = r? {
            summary = Some(s);
        }
    }
    let summary = summary.ok_or("the root procCube returned no summary")?;
    report(&summary, opts, scene.output.frames_every > 0);
    Ok(summary)
}

/// Reads the checkpoint to resume from, checks that it belongs to this deck, and puts its
/// particles into the freshly built scene.
fn resume_from<M: Model>(
    setup: &mut Setup<M>,
    from: &std::path::Path,
    scene_hash: u64,
    start: f64,
) -> Result<Checkpoint, String> {
    let (path, c) = checkpoint::resolve(from)?;
    c.check_matches::<M>(&path, scene_hash, setup.sim.particles.len())?;
    // Steps count from the run's start (`[time] static_until`, or 0): a checkpoint of a run
    // that started elsewhere would end the restart at another time.
    let began = c.time - c.step as f64 * c.dt;
    if (began - start).abs() > 1e-6 * (c.time.abs() + c.dt) {
        return Err(format!(
            "checkpoint {}: its run started at t = {began:.6e} (step {} at t = {:.6e}), the deck now starts at t = {start:.6e} ([time] static_until); a restart continues the same run",
            path.display(),
            c.step,
            c.time
        ));
    }
    let sim = &setup.sim;
    if c.dt != sim.dt || checkpoint::integrator(&c.integrator) != Some(sim.integrator) {
        return Err(format!(
            "checkpoint {}: it was written with time step {:e} ({}), the deck now gives {:e} ({}); a restart continues with the same integration",
            path.display(),
            c.dt,
            c.integrator,
            sim.dt,
            sim.integrator.name()
        ));
    }
    if c.step >= setup.steps {
        return Err(format!(
            "checkpoint {} is at step {}, the run ends at step {}: nothing to do (give more steps with --steps)",
            path.display(),
            c.step,
            setup.steps
        ));
    }
    c.restore_particles(setup);
    Ok(c)
}

fn frame_store<M: Model>(setup: Setup<M>) -> FrameStore<M> {
    let n = setup.sim.particles.len();
    let mut index_of = vec![0u32; n];
    for (i, &g) in setup.sim.particles.gid.iter().enumerate() {
        index_of[g as usize] = i as u32;
    }
    FrameStore {
        particles: setup.sim.particles,
        damage: vec![0.0; n],
        index_of,
    }
}

/// Creates the output directory and prints what is about to run.
fn prepare<M: Model>(
    setup: &Setup<M>,
    scene: &Scene,
    opts: &RunOptions,
    dir: &PathBuf,
    layout: &Layout,
    workers: &str,
    n: usize,
) -> Result<(), String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    if !opts.quiet {
        eprint!("{}", describe(setup, scene));
        let unit = if n == 1 {
            workers.trim_end_matches('s')
        } else {
            workers
        };
        eprintln!("parallel   {} on {n} {unit}", layout.describe());
        eprintln!("output     {}", dir.display());
    }
    Ok(())
}

fn report(summary: &Summary, opts: &RunOptions, frames: bool) {
    if let Some(c) = &summary.interrupted {
        // Said even with --quiet: the run did not finish.
        eprintln!(
            "stopped    by a signal at step {}; checkpoint {}\nresume     with: pdq run DECK --restart {} (exit code {})",
            summary.steps,
            c.display(),
            c.display(),
            crate::output::signals::EXIT_INTERRUPTED
        );
    }
    if opts.quiet {
        return;
    }
    if summary.stopped_at_broken {
        eprintln!(
            "stopped    at step {}: {} broken bonds reached [time] stop_at_broken_bonds",
            summary.steps, summary.broken
        );
    }
    if let Some(probe) = &summary.stopped_at_probe {
        eprintln!(
            "stopped    at step {}: probe '{probe}' moved beyond its stop_beyond",
            summary.steps
        );
    }
    eprintln!(
        "done       {} steps in {:.2} s; {} broken bonds",
        summary.steps, summary.seconds, summary.broken
    );
    eprint!("{}", summary.timing);
    eprintln!(
        "results    {}: history.csv, timing.txt{}",
        summary.output.display(),
        if frames {
            ", frames.xdmf (open in ParaView; colour by damage)"
        } else {
            ""
        }
    );
}

fn material_counts<M: Model>(p: &Particles<M>, scene: &Scene) -> String {
    let mut counts = vec![0usize; scene.materials.len()];
    for &m in &p.material[..p.n_owned] {
        counts[m as usize] += 1;
    }
    scene
        .materials
        .iter()
        .zip(&counts)
        .map(|(m, c)| format!("{} {} ({})", c, m.name, m.kind.name()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The description `pdq run` prints before stepping and `pdq check` prints alone.
fn describe<M: Model>(setup: &Setup<M>, scene: &Scene) -> String {
    let sim = &setup.sim;
    let p = &sim.particles;
    let n = p.n_owned;
    let nb = sim.bonds.len();
    let mem = n * Particles::<M>::bytes_per_particle()
        + nb * crate::engine::bonds::BondList::<M::Bond>::bytes_per_bond();
    let mut s = String::new();
    let _ = writeln!(s, "deck       {} ({})", scene.file, scene.title);
    let _ = writeln!(s, "model      {} (units {})", M::NAME, scene.units.name());
    let _ = writeln!(s, "particles  {n}: {}", material_counts(p, scene));
    let _ = writeln!(
        s,
        "bonds      {nb}, each stored once ({:.1} per particle counting both ends), horizon {} = {:.3} x spacing {}",
        2.0 * nb as f64 / n.max(1) as f64,
        scene.horizon,
        scene.horizon / scene.spacing,
        scene.spacing
    );
    if scene.periodic.iter().any(|&p| p) {
        let _ = writeln!(
            s,
            "           (not counting bonds across periodic faces: the procCubes add those; the run's total is in timing.txt)"
        );
    }
    let _ = writeln!(
        s,
        "memory     {:.1} MiB (particles and bonds)",
        mem as f64 / 1048576.0
    );
    let critical = match setup.dt_measured {
        Some((dt, evaluations)) => format!(
            "{dt:.4e} measured on the stiffest mode ({evaluations} force evaluations; the Silling–Askari bound is {:.4e}, {:.2} x below, set by particle {})",
            setup.dt_critical,
            dt / setup.dt_critical,
            p.gid[setup.dt_critical_particle]
        ),
        None => format!(
            "{:.4e} (Silling–Askari bound, particle {})",
            setup.dt_critical, p.gid[setup.dt_critical_particle]
        ),
    };
    let _ = writeln!(
        s,
        "time step  critical {critical}, chosen {:.4e} ({:.3} x critical), {}",
        sim.dt,
        sim.dt / setup.dt_limit(),
        sim.integrator.name()
    );
    let start = scene.time.static_until.unwrap_or(0.0);
    if start > 0.0 {
        let _ = writeln!(
            s,
            "static     start at t = {start:.4e}: supports and loads there, equilibrium by the implicit solve, at rest"
        );
    }
    let _ = writeln!(
        s,
        "run        {} steps to t = {:.4e}; {} boundary conditions, {} loads, {} probes",
        setup.steps,
        start + setup.steps as f64 * sim.dt,
        sim.constraints.len(),
        sim.loads.len(),
        setup.probes.len()
    );
    for c in &sim.constraints {
        let _ = writeln!(
            s,
            "  boundary {:<12} {} particles",
            c.name,
            c.particles.len()
        );
    }
    for l in &sim.loads {
        let _ = writeln!(
            s,
            "  load     {:<12} {} particles",
            l.name,
            l.particles.len()
        );
    }
    s
}

/// `pdq check`: builds everything, times a few steps and reports without running.
pub fn check(scene: &Scene) -> Result<String, String> {
    struct Visit<'a>(&'a Scene);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<String, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let mut setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
            let mut s = describe(&setup, self.0);
            // The deck's layout is checked here too, so a run does not find it wrong later.
            let threads = self.0.parallel.threads;
            let layout = choose_layout(&setup, self.0, &RunOptions::default(), threads)?;
            let _ = writeln!(
                s,
                "parallel   {} for {threads} thread{} (one core is timed below)",
                layout.describe(),
                if threads == 1 { "" } else { "s" }
            );
            let _ = writeln!(s, "setup      {:.2} s", setup.seconds);
            let calib = 5.min(setup.steps.max(1));
            let t = Instant::now();
            for _ in 0..calib {
                setup.sim.advance();
            }
            let per_step = t.elapsed().as_secs_f64() / calib as f64;
            let _ = writeln!(
                s,
                "estimate   {:.3} s per step from {calib} steps -> {:.1} s for {} steps ({:.3} us per particle-step)",
                per_step,
                per_step * setup.steps as f64,
                setup.steps,
                1e6 * per_step / setup.sim.particles.n_owned as f64
            );
            Ok(s)
        }
    }
    setup::with_model(scene, Visit(scene)).map_err(|e| e.to_string())?
}
