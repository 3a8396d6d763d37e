//! `pdq check` and the description `pdq run` prints before stepping: particles per
//! material, bonds, memory, the time step, and an estimated run time.

use super::run::{choose_layout, RunOptions};
use crate::engine::particles::Particles;
use crate::input::deck::Scene;
use crate::input::setup::{self, Setup};
use crate::model::{Model, ModelVisitor};
use std::fmt::Write as _;
use std::time::Instant;

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
pub(crate) fn describe<M: Model>(setup: &Setup<M>, scene: &Scene) -> String {
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
    let e = &setup.memory;
    let free = setup::memory::available().map_or(String::new(), |(b, _)| {
        format!(", {:.0} MiB free", b / 1048576.0)
    });
    let _ = writeln!(
        s,
        "memory     {:.1} MiB (particles and bonds); estimated before building: {:.1} MiB of records, {:.1} MiB at the peak of setup per process{free}",
        mem as f64 / 1048576.0,
        e.records / 1048576.0,
        e.peak / 1048576.0
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
    if let Some(t) = &sim.thermostat {
        let _ = writeln!(s, "{}", describe_thermostat(t, n));
    }
    s
}

/// The thermostat's line: kind, target, time constant and group, for checking a group before
/// a long run.
fn describe_thermostat(t: &crate::engine::thermostat::Thermostat, n: usize) -> String {
    use crate::engine::thermostat::Kind;
    let group = t
        .member
        .as_ref()
        .map_or(n, |m| m.iter().filter(|&&b| b).count());
    let how = match t.kind {
        Kind::Rescale { every } => format!("every {every} steps"),
        Kind::Berendsen { tau } | Kind::NoseHoover { tau, .. } => format!("damping {tau:.4e}"),
        Kind::Langevin { tau, seed } => format!("damping {tau:.4e}, seed {seed}"),
    };
    format!(
        "thermostat {} to T = {} ({how}) on {group} particles, {} degrees of freedom",
        t.kind.name(),
        t.temperature,
        t.dof
    )
}

/// `pdq check`: builds everything, times a few steps and reports without running.
pub fn check(scene: &Scene) -> Result<String, String> {
    struct Visit<'a>(&'a Scene);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<String, String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
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
            // One procCube of the whole scene, as a one-thread run steps it (with a pair law,
            // its neighbour lists come from the procCube's cells).
            let one = crate::parallel::layout(
                &setup,
                &crate::parallel::decomposition::Procs::Given([1, 1, 1]),
                1,
                crate::parallel::decomposition::Walls::Whole,
            )?;
            let mut cube = crate::parallel::thread_cubes(&setup, &one).remove(0);
            cube.start();
            let t = Instant::now();
            for _ in 0..calib {
                cube.advance()?;
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
