//! `pdq run` and `pdq check`: drive a simulation built from a deck and report on it.

use crate::deck::Scene;
use crate::model::{Model, ModelVisitor};
use crate::output::{Frames, History, Progress};
use crate::particles::Particles;
use crate::setup::{self, Setup};
use crate::timing::Phase;
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
}

/// Options the command line may set over the deck.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub steps: Option<u64>,
    pub output: Option<PathBuf>,
    pub quiet: bool,
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
            c.push(format!("reaction_{}_{}", b.name, dof_name(d)));
        }
    }
    for (name, _) in &setup.probes {
        for k in ["ux", "uy", "uz"] {
            c.push(format!("{name}_{k}"));
        }
    }
    c
}

fn dof_name(d: usize) -> String {
    match d {
        0 => "x".into(),
        1 => "y".into(),
        2 => "z".into(),
        k => format!("dof{k}"),
    }
}

fn row<M: Model>(setup: &Setup<M>, damage: &[f64]) -> Vec<f64> {
    let sim = &setup.sim;
    let (ke, se) = (sim.kinetic_energy(), sim.strain_energy());
    let mut r = vec![
        sim.step as f64,
        sim.time,
        ke,
        se,
        ke + se,
        sim.bonds.broken_count() as f64,
        damage.iter().cloned().fold(0.0, f64::max),
    ];
    for l in &sim.loads {
        let t = l.total(sim.time);
        let norm = (l.vector[0].powi(2) + l.vector[1].powi(2) + l.vector[2].powi(2)).sqrt();
        let along = if norm > 0.0 {
            (t[0] * l.vector[0] + t[1] * l.vector[1] + t[2] * l.vector[2]) / norm
        } else {
            0.0
        };
        r.push(along);
    }
    for b in &sim.constraints {
        r.extend_from_slice(&b.reaction);
    }
    for (_, i) in &setup.probes {
        r.extend_from_slice(&sim.particles.displacement(*i));
    }
    r
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
        + nb * crate::bonds::BondList::<M::Bond>::bytes_per_bond();
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
    let _ = writeln!(
        s,
        "memory     {:.1} MiB (particles and bonds)",
        mem as f64 / 1048576.0
    );
    let _ = writeln!(
        s,
        "time step  critical {:.4e} (particle {}), chosen {:.4e} ({:.3} x critical), {}",
        setup.dt_critical,
        p.gid[setup.dt_critical_particle],
        sim.dt,
        sim.dt / setup.dt_critical,
        sim.integrator.name()
    );
    let _ = writeln!(
        s,
        "run        {} steps to t = {:.4e}; {} boundary conditions, {} loads, {} probes",
        setup.steps,
        setup.steps as f64 * sim.dt,
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
    std::fs::create_dir_all(&dir)
        .map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    if !opts.quiet {
        eprint!("{}", describe(&setup, scene));
        eprintln!("output     {}", dir.display());
    }
    let io = |e: std::io::Error| format!("writing output in {}: {e}", dir.display());
    let mut history = History::create(&dir.join("history.csv"), &columns(&setup)).map_err(io)?;
    let mut frames = if scene.output.frames_every > 0 {
        Some(Frames::new(&dir).map_err(io)?)
    } else {
        None
    };
    let every = scene.output.history_every;
    let frames_every = scene.output.frames_every;
    let steps = setup.steps;

    let t = Instant::now();
    let damage = setup.sim.bonds.damage(setup.sim.particles.len());
    history.row(&row(&setup, &damage)).map_err(io)?;
    if let Some(f) = frames.as_mut() {
        f.write(0, 0.0, &setup.sim.particles, &damage).map_err(io)?;
    }
    setup.sim.timing.lap(Phase::Output, t);

    let mut progress = Progress::new(steps, scene.output.progress && !opts.quiet);
    let wall = Instant::now();
    let mut broken = setup.sim.bonds.broken_count();
    for step in 1..=steps {
        broken += setup.sim.advance();
        let last = step == steps;
        let want_row = step % every == 0 || last;
        let want_frame = frames_every > 0 && (step % frames_every == 0 || last);
        if want_row || want_frame {
            let t = Instant::now();
            let damage = setup.sim.bonds.damage(setup.sim.particles.len());
            if want_row {
                history.row(&row(&setup, &damage)).map_err(io)?;
            }
            if want_frame {
                if let Some(f) = frames.as_mut() {
                    f.write(step, setup.sim.time, &setup.sim.particles, &damage)
                        .map_err(io)?;
                }
            }
            setup.sim.timing.lap(Phase::Output, t);
        }
        progress.update(step, broken);
    }
    history.flush().map_err(io)?;
    let seconds = wall.elapsed().as_secs_f64();
    let n = setup.sim.particles.n_owned;
    let timing = setup.sim.timing.table(n as f64 * steps as f64);
    std::fs::write(dir.join("timing.txt"), &timing).map_err(io)?;
    let summary = Summary {
        particles: n,
        bonds: setup.sim.bonds.len(),
        steps,
        dt: setup.sim.dt,
        broken: setup.sim.bonds.broken_count(),
        kinetic_energy: setup.sim.kinetic_energy(),
        strain_energy: setup.sim.strain_energy(),
        output: dir,
        seconds,
        timing,
    };
    if !opts.quiet {
        eprintln!(
            "done       {} steps in {:.2} s; {} broken bonds",
            steps, seconds, summary.broken
        );
        eprint!("{}", summary.timing);
        eprintln!(
            "results    {}: history.csv, timing.txt{}",
            summary.output.display(),
            if frames.is_some() {
                ", frames.pvd (open in ParaView; colour by damage)"
            } else {
                ""
            }
        );
    }
    Ok(summary)
}

/// `pdq check`: builds everything, times a few steps and reports without running.
pub fn check(scene: &Scene) -> Result<String, String> {
    struct Visit<'a>(&'a Scene);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<String, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let mut setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
            let mut s = describe(&setup, self.0);
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
