//! `pdq run` and `pdq check`: drive a simulation built from a deck and report on it.

use super::observers::analysis::AnalysisPlan;
use super::record::{columns, frame_store};
use super::step_loop::{drive, CheckpointPlan, Plan, SolverChoice};
use super::thermo::Thermo;
use crate::input::deck::{Colouring, Equilibrium, Scene, SolverSpec};
use crate::input::setup::{self, Setup};
use crate::model::{Model, ModelVisitor};
use crate::output::checkpoint::{self, Checkpoint};
use crate::parallel;
#[cfg(feature = "mpi")]
use crate::parallel::comm::Transport;
use crate::parallel::decomposition::{Layout, Procs, Walls};
use crate::parallel::snapshot::Snapshot;
use crate::solve::static_start::StaticStart;
use crate::voids::{Connectivity, Scheme};
use std::path::PathBuf;

pub use super::check::check;
use super::check::describe;

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
    /// Under relaxation (ADR or the implicit solve): the load steps solved (0 in an explicit
    /// run), those that reached the tolerance within `max_iterations`, and whether the last
    /// one did.
    pub load_steps: u64,
    pub converged_steps: u64,
    pub last_step_converged: bool,
    /// The run ended before its last step because `[time] stop_at_broken_bonds` was reached.
    pub stopped_at_broken: bool,
    /// The run ended before its last step because this probe's displacement passed its
    /// `stop_beyond`.
    pub stopped_at_probe: Option<String>,
    /// The run ended before its last step because this history column fell below
    /// `[time] stop_below_peak`'s fraction of its peak.
    pub stopped_below_peak: Option<String>,
}

impl Summary {
    /// Whether the run's solve converged: `None` for an explicit run (nothing iterates),
    /// else whether every load step reached its tolerance. A run that stopped early (at
    /// `stop_at_broken_bonds`, a probe's `stop_beyond` or `stop_below_peak`) may end inside
    /// its last load step,
    /// unconverged by design; every step before it must have converged.
    pub fn solve_converged(&self) -> Option<bool> {
        if self.load_steps == 0 {
            return None;
        }
        let stopped = self.stopped_at_broken
            || self.stopped_at_probe.is_some()
            || self.stopped_below_peak.is_some();
        let earlier = self.load_steps - u64::from(!self.last_step_converged);
        let earlier_converged = self.converged_steps == earlier;
        Some(earlier_converged && (self.last_step_converged || stopped))
    }
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

/// Runs a deck with the model of type `M`, which need not be in the registry (a model written
/// in a test, an example or another crate): the deck's `[model] name` is not consulted.
pub fn run_model<M: Model>(scene: &Scene, opts: &RunOptions) -> Result<Summary, String> {
    let setup = setup::build_as::<M>(scene).map_err(|e| e.to_string())?;
    run_setup(setup, scene, opts)
}

/// Runs a deck to the end.
pub fn run(scene: &Scene, opts: &RunOptions) -> Result<Summary, String> {
    struct Visit<'a>(&'a Scene, &'a RunOptions);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<Summary, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            #[cfg(feature = "mpi")]
            if crate::parallel::comm_mpi::launched_by_mpirun()
                && super::run_part::per_rank(self.0, self.1)
            {
                return on_ranks_per_rank(model, self.0, self.1);
            }
            let setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
            run_setup(setup, self.0, self.1)
        }
    }
    setup::with_model(scene, Visit(scene, opts)).map_err(|e| e.to_string())?
}

/// One procCube per rank under `mpirun`, each built on its own (`run_part`).
#[cfg(feature = "mpi")]
fn on_ranks_per_rank<M: Model>(
    model: M,
    scene: &Scene,
    opts: &RunOptions,
) -> Result<Summary, String> {
    let (job, mpi) = crate::parallel::comm_mpi::Mpi::job().ok_or("MPI was already initialized")?;
    let (rank, ranks) = (mpi.rank(), mpi.size());
    let quiet = RunOptions {
        quiet: opts.quiet || rank != 0,
        ..opts.clone()
    };
    let result = super::run_part::run_rank(model, scene, &quiet, rank, ranks, Box::new(mpi));
    match job.end(result)? {
        Some(s) => Ok(s),
        // Other ranks have nothing to print; a summary-less Ok ends them quietly.
        None => std::process::exit(0),
    }
}

/// The layout, and how many workers: MPI ranks when launched by `mpirun`, threads otherwise.
pub(crate) fn choose_layout<M: Model>(
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

/// How the run takes its steps, from the deck's `[solver]`; ADR's fictitious masses are
/// measured here, on the whole scene.
fn solver_choice<M: Model>(
    setup: &mut Setup<M>,
    scene: &Scene,
    quiet: bool,
) -> Result<SolverChoice, String> {
    Ok(match setup.solver {
        SolverSpec::Explicit => SolverChoice::Explicit,
        SolverSpec::Relaxation {
            tolerance,
            max_iterations,
            method,
            krylov_iterations,
            coarse,
            ..
        } => {
            let newton = method != Equilibrium::Relaxation;
            crate::solve::adr::check_model::<M>(newton)
                .map_err(|e| format!("{}:{}: {e}", scene.file, scene.solver.line))?;
            if newton {
                SolverChoice::Implicit {
                    tolerance,
                    max_iterations,
                    matrix_free: crate::solve::MatrixFree {
                        diagonal: crate::solve::krylov::Diagonal::of(&setup.sim),
                        max_iterations: krylov_iterations,
                        always: method == Equilibrium::NewtonKrylov,
                        coarse,
                    },
                }
            } else {
                let mass = crate::solve::adr::fictitious_mass(&mut setup.sim);
                if !quiet {
                    match mass.lambda_max {
                        Some(l) => eprintln!(
                            "relaxation fictitious mass from the stiffest mode, λ_max = {l:.4} of the Gershgorin bound's 2 ({} force evaluations)",
                            mass.evaluations
                        ),
                        None => eprintln!("relaxation fictitious mass: the book's (no free DOF with a bond to estimate from)"),
                    }
                }
                SolverChoice::Adr {
                    mass,
                    tolerance,
                    max_iterations,
                }
            }
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
    let solver = solver_choice(&mut setup, scene, opts.quiet)?;
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
        (None, Some(until)) => Some(static_start(&mut setup, scene, opts, until)?),
        _ => None,
    };
    if let (Some(c), false) = (&resume, opts.quiet) {
        eprintln!(
            "restart    from step {} (t = {:.6e}) of {}: {} broken bonds",
            c.state.step,
            c.state.time,
            c.deck,
            c.state.broken.len()
        );
    }
    let start = Prepared {
        setup,
        scene,
        opts,
        dir,
        solver,
        scene_hash,
        resume,
        static_start,
    };
    #[cfg(feature = "mpi")]
    if crate::parallel::comm_mpi::launched_by_mpirun() {
        return start.on_ranks();
    }
    start.on_threads()
}

/// The static start to `until`, restored into the scene; refused when it already breaks the
/// bonds at which the run would stop.
fn static_start<M: Model>(
    setup: &mut Setup<M>,
    scene: &Scene,
    opts: &RunOptions,
    until: f64,
) -> Result<StaticStart, String> {
    let walls = opts.walls.unwrap_or(scene.parallel.walls);
    let at = |e: String| format!("{}:{}: {e}", scene.file, scene.time.line);
    let s = crate::solve::static_start::solve(setup, until, walls).map_err(at)?;
    let stop = scene.time.stop_at_broken_bonds;
    if stop > 0 && s.broken as u64 >= stop {
        return Err(at(format!(
            "[time] the static start to static_until = {until:e} broke {} bonds, already as many as stop_at_broken_bonds = {stop}: the run would stop before it began; start earlier",
            s.broken
        )));
    }
    s.state.restore_particles(&mut setup.sim);
    Ok(s)
}

/// A run ready to be laid out: the scene built, the solver chosen, the state to start from.
struct Prepared<'a, M: Model> {
    setup: Setup<M>,
    scene: &'a Scene,
    opts: &'a RunOptions,
    dir: PathBuf,
    solver: SolverChoice,
    scene_hash: u64,
    resume: Option<Checkpoint>,
    static_start: Option<StaticStart>,
}

impl<M: Model> Prepared<'_, M> {
    /// Said after the run's header (`prepare`), by the root only.
    fn say_static(&self, quiet: bool) {
        if let (Some(s), false) = (&self.static_start, quiet) {
            eprintln!("{}", s.describe());
        }
    }

    /// The state the procCubes start from: a checkpoint's, or the static start's.
    fn start_state(&self) -> Option<&Snapshot> {
        let resume = self.resume.as_ref().map(|c| &c.state);
        resume.or(self.static_start.as_ref().map(|s| &s.state))
    }

    /// The whole scene, to be kept by the root for its frames, and the state the procCubes
    /// start from (as [`Self::start_state`]), once the procCubes are built.
    fn into_start(self) -> (Setup<M>, Option<Snapshot>) {
        let start = self.resume.map(|c| c.state);
        (self.setup, start.or(self.static_start.map(|s| s.state)))
    }

    /// What the step loop needs to know about the run on `layout`.
    fn plan(&self, layout: &Layout) -> Result<Plan, String> {
        let setup = &self.setup;
        let facts = RunFacts {
            columns: columns(setup),
            steps: setup.steps,
            dt_critical: setup.dt_limit(),
            measured: setup.dt_measured.is_some(),
            horizon: setup.horizon,
            thermo: setup
                .sim
                .pairs
                .is_some()
                .then(|| Thermo::of_setup(setup, self.scene.units.boltzmann())),
            analyses: analysis_plans(setup, self.scene),
            first_step: self.start_state().map_or(0, |c| c.step),
            static_evaluations: self.static_start.as_ref().map_or(0, |s| s.evaluations),
            solver: self.solver.clone(),
            scene_hash: self.scene_hash,
        };
        run_plan(facts, self.scene, self.opts, &self.dir, layout)
    }

    /// One procCube per rank under `mpirun`; the root gathers the frames and the summary.
    #[cfg(feature = "mpi")]
    fn on_ranks(self) -> Result<Summary, String> {
        let (job, mpi) =
            crate::parallel::comm_mpi::Mpi::job().ok_or("MPI was already initialized")?;
        let result = self.step_on_ranks(mpi);
        match job.end(result)? {
            Some(s) => Ok(s),
            // Other ranks have nothing to print; a summary-less Ok ends them quietly.
            None => std::process::exit(0),
        }
    }

    /// [`Prepared::on_ranks`] on this rank's transport; the summary on the root.
    #[cfg(feature = "mpi")]
    fn step_on_ranks(self, mpi: crate::parallel::comm_mpi::Mpi) -> Result<Option<Summary>, String> {
        let (scene, opts) = (self.scene, self.opts);
        let (rank, ranks) = (mpi.rank(), mpi.size());
        let layout = choose_layout(&self.setup, scene, opts, ranks)?;
        // Every rank makes the directory (the same one, on a shared file system), so that a
        // failure stops them all instead of leaving some waiting for the root.
        let quiet = RunOptions {
            quiet: opts.quiet || rank != 0,
            ..opts.clone()
        };
        prepare(
            &self.setup,
            scene,
            &quiet,
            &self.dir,
            &layout,
            "ranks",
            ranks,
        )?;
        self.say_static(quiet.quiet);
        let plans = crate::parallel::decomposition::cell_plans(&layout);
        let cube = parallel::build_cube(&self.setup, &layout, &plans, rank, Box::new(mpi));
        crate::parallel::comm_mpi::injected_failure(rank)?;
        let mut p = self.plan(&layout)?;
        // Every rank holds the whole scene here, but the output is the same as a per-rank
        // setup's: in parts on several ranks.
        p.in_parts = scene.output.in_parts(ranks, true);
        let (setup, start) = self.into_start();
        let store = (rank == 0 && ranks > 1 && !p.in_parts).then(|| frame_store(setup));
        let summary = drive(cube, &p, store, start.as_ref())?;
        if let Some(s) = &summary {
            report(s, opts, scene.output.frames_every > 0);
        }
        Ok(summary)
    }

    /// One procCube per worker thread; the root's thread gathers the frames and the summary.
    fn on_threads(self) -> Result<Summary, String> {
        let (scene, opts) = (self.scene, self.opts);
        let threads = opts.threads.unwrap_or(scene.parallel.threads);
        let layout = choose_layout(&self.setup, scene, opts, threads)?;
        prepare(
            &self.setup,
            scene,
            opts,
            &self.dir,
            &layout,
            "threads",
            threads,
        )?;
        self.say_static(opts.quiet);
        let cubes = parallel::thread_cubes(&self.setup, &layout);
        let mut p = self.plan(&layout)?;
        p.in_parts = scene.output.in_parts(cubes.len(), false);
        let (setup, start) = self.into_start();
        let start = start.as_ref();
        // One procCube writes its frames itself, and so do procCubes writing in parts;
        // otherwise the root gathers them.
        let gathered = cubes.len() > 1 && !p.in_parts;
        let store = std::sync::Mutex::new(gathered.then(|| frame_store(setup)));
        let results = parallel::on_threads(cubes, |cube| {
            let s = if cube.plan.rank == 0 {
                store.lock().unwrap().take()
            } else {
                None
            };
            drive(cube, &p, s, start)
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
    let n = setup.sim.particles.len();
    check_resume(&c, &path, (scene_hash, n), (start, setup.steps), &setup.sim)?;
    c.state.restore_particles(&mut setup.sim);
    Ok(c)
}

/// Refuses a checkpoint that is not of this deck's scene (`scene`: its hash and particle
/// count), or whose run started at another time or integrated otherwise than `sim`, or that is
/// past the run's end (`run`: its start time and last step).
pub(super) fn check_resume<M: Model>(
    c: &Checkpoint,
    path: &std::path::Path,
    (scene_hash, n): (u64, usize),
    (start, steps): (f64, u64),
    sim: &crate::engine::simulation::Simulation<M>,
) -> Result<(), String> {
    c.check_matches::<M>(path, scene_hash, n)?;
    // Steps count from the run's start (`[time] static_until`, or 0): a checkpoint of a run
    // that started elsewhere would end the restart at another time.
    let began = c.state.time - c.state.step as f64 * c.state.dt;
    if (began - start).abs() > 1e-6 * (c.state.time.abs() + c.state.dt) {
        return Err(format!(
            "checkpoint {}: its run started at t = {began:.6e} (step {} at t = {:.6e}), the deck now starts at t = {start:.6e} ([time] static_until); a restart continues the same run",
            path.display(),
            c.state.step,
            c.state.time
        ));
    }
    if c.state.dt != sim.dt || checkpoint::integrator(&c.state.integrator) != Some(sim.integrator) {
        return Err(format!(
            "checkpoint {}: it was written with time step {:e} ({}), the deck now gives {:e} ({}); a restart continues with the same integration",
            path.display(),
            c.state.dt,
            c.state.integrator,
            sim.dt,
            sim.integrator.name()
        ));
    }
    if c.state.step >= steps {
        return Err(format!(
            "checkpoint {} is at step {}, the run ends at step {steps}: nothing to do (give more steps with --steps)",
            path.display(),
            c.state.step,
        ));
    }
    Ok(())
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

pub(super) fn report(summary: &Summary, opts: &RunOptions, frames: bool) {
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
    if let Some(column) = &summary.stopped_below_peak {
        eprintln!(
            "stopped    at step {}: {column} fell below [time] stop_below_peak's fraction of its peak",
            summary.steps
        );
    }
    eprintln!(
        "done       {} steps in {:.2} s; {} broken bonds",
        summary.steps, summary.seconds, summary.broken
    );
    eprint!("{}", summary.timing);
    eprintln!(
        "results    {}: history.csv, timing.txt, pictures/ (PNG){}",
        summary.output.display(),
        if frames {
            ", frames.xdmf (open in ParaView; colour by damage)"
        } else {
            ""
        }
    );
}

/// The deck's `[[analysis]]` entries as the step loop runs them.
fn analysis_plans<M: Model>(setup: &Setup<M>, scene: &Scene) -> Vec<AnalysisPlan> {
    let p = &setup.sim.particles;
    // The particle with global id 0 (every worker holds the whole scene at setup).
    let anchor = p
        .gid
        .iter()
        .position(|&g| g == 0)
        .map_or([0.0; 3], |i| p.x0[i]);
    analysis_plans_at(anchor, scene)
}

/// The deck's analyses, their voxels anchored at `anchor` (the reference position of the
/// particle with global id 0).
pub(super) fn analysis_plans_at(anchor: [f64; 3], scene: &Scene) -> Vec<AnalysisPlan> {
    scene
        .analyses
        .iter()
        .map(|a| AnalysisPlan {
            name: a.name.clone(),
            kind: a.kind,
            every: a.every,
            voxel: a.voxel,
            connectivity: if a.all_neighbours {
                Connectivity::All
            } else {
                Connectivity::Face
            },
            scheme: match a.scheme.as_str() {
                "min-label" => Scheme::MinLabel,
                "gather" => Scheme::Gather,
                _ => Scheme::Boundary,
            },
            anchor,
        })
        .collect()
}

/// What a run's plan takes from its built scene (the whole scene's setup, or a per-rank one).
pub(super) struct RunFacts {
    pub columns: Vec<String>,
    pub steps: u64,
    /// The critical step Δt was chosen against, and whether it was measured.
    pub dt_critical: f64,
    pub measured: bool,
    pub horizon: f64,
    pub thermo: Option<Thermo>,
    pub analyses: Vec<AnalysisPlan>,
    pub first_step: u64,
    pub static_evaluations: u64,
    pub solver: SolverChoice,
    pub scene_hash: u64,
}

/// What the step loop needs to know about the run on `layout`.
pub(super) fn run_plan(
    facts: RunFacts,
    scene: &Scene,
    opts: &RunOptions,
    dir: &std::path::Path,
    layout: &Layout,
) -> Result<Plan, String> {
    let out = &scene.output;
    let peak_stop = super::observers::peak_stop(scene, &facts.columns)?;
    Ok(Plan {
        columns: facts.columns,
        dir: dir.to_path_buf(),
        steps: facts.steps,
        every: out.history_every,
        frames_every: out.frames_every,
        progress: out.progress,
        quiet: opts.quiet,
        final_state: out.final_state,
        shuffle_every: scene.parallel.shuffle_every,
        stop_at_broken: scene.time.stop_at_broken_bonds,
        probe_stops: scene
            .probes
            .iter()
            .map(|p| (p.name.clone(), p.stop_beyond))
            .collect(),
        peak_stop,
        layout: layout.describe(),
        first_step: facts.first_step,
        static_evaluations: facts.static_evaluations,
        solver: facts.solver,
        dt_critical: facts.dt_critical,
        dt_critical_name: if facts.measured {
            "measured critical step"
        } else {
            "stable bound"
        },
        material_names: scene.materials.iter().map(|m| m.name.clone()).collect(),
        spacing: scene.spacing,
        checkpoints: CheckpointPlan {
            dir: dir.join("checkpoints"),
            every: out.checkpoint_every,
            minutes: out.checkpoint_minutes,
            keep: out.checkpoint_keep,
            scene_hash: facts.scene_hash,
            deck: scene.file.clone(),
        },
        thermo: facts.thermo,
        picture: out.picture.map(|c| match c {
            // Bondless particles (no horizon) have no damage to show.
            Colouring::Auto if facts.horizon <= 0.0 => Colouring::Speed,
            Colouring::Auto => Colouring::Damage,
            c => c,
        }),
        title: scene.title.clone(),
        analyses: facts.analyses,
        deform: scene.deform.clone(),
        in_parts: false,
    })
}
