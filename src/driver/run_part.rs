//! `pdq run` with setup per rank (`parallel::part`): each worker builds only its procCube from
//! the geometry, so that its memory is its share of the scene, and then steps it as any run.
//! Used under `mpirun` when the deck has nothing `Scene::built_whole_by` names (the whole-scene
//! setup builds those); `run_on_threads` runs it on threads (tests).
//!
//! Frames and checkpoints are written in parts, and a restart reads its procCube's share of a
//! checkpoint a part at a time, so no rank holds the whole scene. Only with `[output] parts =
//! false` does the root keep the scene's particles (no bonds) to gather the frames into.

use super::record::{columns_of, FrameStore};
use super::run::{analysis_plans_at, run_plan, RunFacts, RunOptions, Summary};
use super::step_loop::{drive, SolverChoice};
use crate::engine::particles::Particles;
use crate::input::deck::Scene;
use crate::input::geometry::SceneSites;
use crate::model::{Model, ModelVisitor};
use crate::output::checkpoint::Checkpoint;
use crate::parallel::comm::{Team, Transport};
use crate::parallel::part::{self, Parts};

/// Whether `pdq run` builds this deck per rank under `mpirun`.
pub fn per_rank(scene: &Scene, opts: &RunOptions) -> bool {
    let _ = opts;
    scene.built_whole_by().is_none()
}

/// Runs procCube `rank` of `ranks` over `transport`, built on its own; the root's summary.
pub fn run_rank<M: Model>(
    model: M,
    scene: &Scene,
    opts: &RunOptions,
    rank: usize,
    ranks: usize,
    transport: Box<dyn Transport>,
) -> Result<Option<Summary>, String> {
    crate::input::setup::memory::guard_per_rank::<M>(scene, ranks).map_err(|e| e.to_string())?;
    let procs = opts.procs.clone().unwrap_or(scene.parallel.procs.clone());
    let walls = opts.walls.unwrap_or(scene.parallel.walls);
    let parts = part::parts(scene, &procs, walls, ranks).map_err(|e| {
        if scene.parallel.line > 0 && opts.procs.is_none() && !e.starts_with(&scene.file) {
            format!("{}:{}: {e}", scene.file, scene.parallel.line)
        } else {
            e
        }
    })?;
    let scene_hash = scene_hash::<M>(scene, &parts.sites);
    let mut anchor = [0.0; 3];
    parts.sites.for_each(|s| {
        if s.gid == 0 {
            anchor = s.position;
        }
    });
    let in_parts = scene.output.in_parts(ranks, true);
    let gathered = rank == 0 && ranks > 1 && !in_parts;
    let store = gathered.then(|| whole_store(&model, &parts.sites));
    let mut ps =
        part::build_part(model, scene, &parts, rank, transport).map_err(|e| e.to_string())?;
    #[cfg(feature = "mpi")]
    crate::parallel::comm_mpi::injected_failure(rank)?;
    let steps = opts.steps.unwrap_or(ps.steps);
    let resume = match opts.restart.as_ref().or(scene.output.restart.as_ref()) {
        Some(from) => Some(resume_part(
            &mut ps.cube,
            from,
            (scene_hash, parts.sites.len()),
            steps,
        )?),
        None => None,
    };
    let dir = opts
        .output
        .clone()
        .unwrap_or_else(|| scene.output.directory.clone());
    std::fs::create_dir_all(&dir)
        .map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    let bonds = Team::new(ps.cube.wall.transport()).sum(ps.cube.sim.bonds.len() as f64);
    if rank == 0 && !opts.quiet {
        eprint!("{}", describe::<M>(scene, &parts, &ps, bonds, steps, ranks));
        eprintln!("output     {}", dir.display());
        if let Some(c) = &resume {
            eprintln!(
                "restart    from step {} (t = {:.6e}) of {}, read by each rank for its procCube",
                c.state.step, c.state.time, c.deck
            );
        }
    }
    let probes: Vec<&str> = scene.probes.iter().map(|p| p.name.as_str()).collect();
    let facts = RunFacts {
        columns: columns_of(&ps.cube.sim, &probes, &scene.solver.item),
        steps,
        dt_critical: ps.dt_critical,
        measured: false,
        horizon: scene.horizon,
        thermo: None,
        analyses: analysis_plans_at(anchor, scene),
        first_step: resume.as_ref().map_or(0, |c| c.state.step),
        static_evaluations: 0,
        solver: SolverChoice::Explicit,
        scene_hash,
    };
    let mut plan = run_plan(facts, scene, opts, &dir, &parts.layout)?;
    plan.in_parts = in_parts;
    ps.cube.sim.timing.add(
        crate::engine::timing::Phase::Setup,
        std::time::Duration::from_secs_f64(ps.seconds),
    );
    let summary = drive(ps.cube, &plan, store, resume.as_ref().map(|c| &c.state))?;
    if let Some(s) = &summary {
        super::run::report(s, opts, scene.output.frames_every > 0);
    }
    Ok(summary)
}

/// Reads the share of procCube `cube` (its owned particles and ghosts, and the bonds between
/// them) of the checkpoint to resume from, a part at a time, checks that it belongs to this
/// deck (`scene`: its hash and particle count) and run of `steps`, and puts its particles in.
fn resume_part<M: Model>(
    cube: &mut crate::parallel::Cube<M>,
    from: &std::path::Path,
    scene: (u64, usize),
    steps: u64,
) -> Result<Checkpoint, String> {
    let mut local = cube.sim.particles.gid.clone();
    local.sort_unstable();
    let keep = |g: u32| local.binary_search(&g).is_ok();
    let (path, c) = crate::output::checkpoint::resolve_some(from, Some(&keep))?;
    // Decks with a static start are built whole (`Scene::built_whole_by`): runs start at t = 0.
    super::run::check_resume(&c, &path, scene, (0.0, steps), &cube.sim)?;
    c.state.restore_particles(&mut cube.sim);
    Ok(c)
}

/// The hash a checkpoint of this scene carries, streamed from the geometry in id order (the
/// whole-scene setup's `checkpoint::scene_hash` of the same scene).
fn scene_hash<M: Model>(scene: &Scene, sites: &SceneSites) -> u64 {
    crate::output::checkpoint::scene_hash_of::<M>(scene, &[], sites.len(), |each| {
        sites.for_each(|s| each(&s.position, s.volume, s.material))
    })
}

/// The scene's particles in id order, for the root to gather frames into.
fn whole_store<M: Model>(model: &M, sites: &SceneSites) -> FrameStore<M> {
    let n = sites.len();
    let (mut x0, mut volume, mut material) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    sites.for_each(|s| {
        x0.push(s.position);
        volume.push(s.volume);
        material.push(s.material);
    });
    FrameStore {
        particles: Particles::new(model, (0..n as u32).collect(), x0, volume, material),
        damage: vec![0.0; n],
        index_of: (0..n as u32).collect(),
    }
}

fn describe<M: Model>(
    scene: &Scene,
    parts: &Parts,
    ps: &part::PartSetup<M>,
    bonds: f64,
    steps: u64,
    ranks: usize,
) -> String {
    let dt = ps.cube.sim.dt;
    format!(
        "deck       {} ({})\nmodel      {} (units {})\nparticles  {} (built per rank)\nbonds      {bonds}\ntime step  {dt:.4e} ({:.3} of the stable bound {:.4e}, set by particle {})\nsteps      {steps}\nparallel   {} on {ranks} rank{}, rank 0 built its procCube in {:.2} s\n",
        scene.file,
        scene.title,
        M::NAME,
        scene.units.name(),
        parts.sites.len(),
        dt / ps.dt_critical,
        ps.dt_critical,
        ps.dt_critical_gid,
        parts.layout.describe(),
        if ranks == 1 { "" } else { "s" },
        ps.seconds,
    )
}

/// [`run_rank`] on `threads` threads of this process (one procCube each); the summary.
pub fn run_on_threads(scene: &Scene, opts: &RunOptions, threads: usize) -> Result<Summary, String> {
    struct Visit<'a>(&'a Scene, &'a RunOptions, usize);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<Summary, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let (scene, opts, n) = (self.0, self.1, self.2);
            let teams = crate::parallel::comm::Threads::team(n);
            let results: Vec<_> = std::thread::scope(|s| {
                let handles: Vec<_> = teams
                    .into_iter()
                    .enumerate()
                    .map(|(k, t)| {
                        let m = model.clone();
                        s.spawn(move || run_rank(m, scene, opts, k, n, Box::new(t)))
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).collect()
            });
            let mut summary = None;
            for r in results {
                if let Some(s) = r? {
                    summary = Some(s);
                }
            }
            summary.ok_or_else(|| "the root procCube returned no summary".to_string())
        }
    }
    crate::input::setup::with_model(scene, Visit(scene, opts, threads))
        .map_err(|e| e.to_string())?
}
