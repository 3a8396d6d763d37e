//! What a run records: the history row (named columns), the frame gathered on the root, and
//! the final state by global id.

use super::run::Summary;
use super::step_loop::{Plan, Tally};
use crate::engine::particles::Particles;
use crate::engine::timing::Phase;
use crate::input::deck::SolverSpec;
use crate::input::setup::Setup;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::{f64s, Reduce};
use crate::parallel::Cube;
use std::fmt::Write as _;

/// The names of the history columns, in the order of [`Row::values`].
pub(crate) fn columns<M: Model>(setup: &Setup<M>) -> Vec<String> {
    let probes: Vec<&str> = setup.probes.iter().map(|(n, _)| n.as_str()).collect();
    columns_of(&setup.sim, &probes, &setup.solver)
}

/// [`columns`] of a simulation (the whole scene's or one procCube's: every procCube has every
/// boundary condition and load), its probes' names and its solver.
pub(crate) fn columns_of<M: Model>(
    sim: &crate::engine::simulation::Simulation<M>,
    probes: &[&str],
    solver: &SolverSpec,
) -> Vec<String> {
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
    if sim.pairs.is_some() {
        // total_energy then includes the pairs' energy.
        for k in [
            "pair_energy",
            "pair_virial",
            "pairs_in_range",
            "potential_energy",
            "temperature",
            "pressure",
        ] {
            c.push(k.into());
        }
    }
    if sim.thermostat.is_some() {
        c.push("conserved_energy".into());
    }
    for l in &sim.loads {
        c.push(format!("load_{}", l.name));
    }
    for b in &sim.constraints {
        for &d in &b.dofs {
            c.push(format!("reaction_{}_{}", b.name, dof_name::<M>(d)));
        }
    }
    for b in &sim.constraints {
        for d in b.dofs.iter().filter(|&&d| d < 3) {
            c.push(format!("displacement_{}_{}", b.name, dof_name::<M>(*d)));
        }
    }
    for name in probes {
        for k in ["ux", "uy", "uz"] {
            c.push(format!("{name}_{k}"));
        }
    }
    c.push("residual_force".into());
    if let SolverSpec::Relaxation { .. } = solver {
        c.push("iterations".into());
        c.push("residual".into());
    }
    c
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

/// One row of `history.csv`, by name; [`Row::values`] lays it out in the order of
/// [`columns`].
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Row {
    pub step: u64,
    pub time: f64,
    pub kinetic_energy: f64,
    pub strain_energy: f64,
    pub broken_bonds: u64,
    pub max_damage: f64,
    /// With a pair law: the pairs' energy, virial Σ r·F and the pairs within their cutoff.
    pub pairs: Option<[f64; 3]>,
    /// With a pair law: the virial of every internal force, bonds and pairs (Σ x·F).
    pub virial: f64,
    /// With a pair law: temperature and pressure ([`super::thermo::Thermo::of`]).
    pub thermo: Option<[f64; 2]>,
    /// With a thermostat: the energy it holds (`Thermostat::reservoir`), a global value.
    pub reservoir: Option<f64>,
    /// Each load's total along its direction, in deck order.
    pub loads: Vec<f64>,
    /// Each constraint's reaction on each of its DOFs, in deck order.
    pub reactions: Vec<f64>,
    /// Each constraint's mean displacement along each of its translational DOFs, in deck
    /// order: with the reaction, the load–displacement curve of a grip.
    pub grips: Vec<f64>,
    /// Each probe's displacement, in deck order.
    pub probes: Vec<[f64; 3]>,
    /// √(Σ F²) over the free second-order DOFs: how far from equilibrium.
    pub residual_force: f64,
    /// Under a quasi-static solver: the last load step's iterations and relative residual.
    pub solve: Option<(u64, f64)>,
}

impl Row {
    /// The CSV values, in column order.
    pub fn values(&self) -> Vec<f64> {
        let mut v = vec![
            self.step as f64,
            self.time,
            self.kinetic_energy,
            self.strain_energy,
            self.kinetic_energy + self.strain_energy + self.pairs.map_or(0.0, |p| p[0]),
            self.broken_bonds as f64,
            self.max_damage,
        ];
        if let Some(p) = self.pairs {
            v.extend(p);
            v.push(self.strain_energy + p[0]);
            v.extend(self.thermo.unwrap_or([f64::NAN; 2]));
        }
        if let Some(r) = self.reservoir {
            let pairs = self.pairs.map_or(0.0, |p| p[0]);
            v.push(self.kinetic_energy + self.strain_energy + pairs + r);
        }
        v.extend_from_slice(&self.loads);
        v.extend_from_slice(&self.reactions);
        v.extend_from_slice(&self.grips);
        v.extend(self.probes.iter().flatten());
        v.push(self.residual_force);
        if let Some((iterations, residual)) = self.solve {
            v.push(iterations as f64);
            v.push(residual);
        }
        v
    }

    /// One procCube's share of the row, reduced over all procCubes in one reduction (every
    /// worker must call it, and every worker gets the whole row).
    pub fn reduced<M: Model>(cube: &mut Cube<M>, damage: &[f64], n_probes: usize) -> Row {
        let sim = &cube.sim;
        let (ke, se) = (sim.kinetic_energy(), sim.strain_energy());
        let mut sums = vec![ke, se, cube.broken_count() as f64];
        let n_loads = sim.loads.len();
        let pairs = sim.pairs.as_ref().map(|p| p.tally());
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
        let first_grip = sums.len();
        sums.extend(grip_sums(&sim.constraints, &sim.particles));
        let first_probe = sums.len();
        sums.resize(first_probe + 3 * n_probes, 0.0);
        for &(k, i) in &cube.probes {
            sums[first_probe + 3 * k..first_probe + 3 * k + 3]
                .copy_from_slice(&sim.particles.displacement(i));
        }
        // Σ F² over the free second-order DOFs (supported ones hold 0).
        let n2 = crate::model::second_order::<M>();
        let p = &sim.particles;
        sums.push(
            (0..p.n_owned)
                .flat_map(|i| p.force[i].as_slice()[..n2].iter())
                .map(|f| f * f)
                .sum(),
        );
        if let Some(t) = pairs {
            sums.extend([t.energy, t.virial, t.pairs as f64, sim.virial]);
        }
        let (step, time) = (sim.step, sim.time);
        let mut team = cube.team();
        team.reduce(&mut sums, Reduce::Sum);
        let max_damage = team.max(damage.iter().cloned().fold(0.0, f64::max));
        let probes = sums[first_probe..first_probe + 3 * n_probes]
            .chunks_exact(3)
            .map(|u| [u[0], u[1], u[2]])
            .collect();
        Row {
            step,
            time,
            kinetic_energy: sums[0],
            strain_energy: sums[1],
            broken_bonds: sums[2] as u64,
            max_damage,
            loads: sums[3..3 + n_loads].to_vec(),
            reactions: sums[3 + n_loads..first_grip].to_vec(),
            grips: grip_means(&cube.sim.constraints, &sums[first_grip..first_probe]),
            probes,
            residual_force: sums[first_probe + 3 * n_probes].sqrt(),
            pairs: pairs.map(|_| {
                let at = first_probe + 3 * n_probes + 1;
                [sums[at], sums[at + 1], sums[at + 2]]
            }),
            virial: pairs.map_or(0.0, |_| sums[first_probe + 3 * n_probes + 4]),
            thermo: None,
            solve: None,
            reservoir: cube.sim.thermostat.as_ref().map(|t| t.reservoir()),
        }
    }
}

/// For each constraint, its owned particles' count and then their summed displacement along
/// each translational DOF it holds (summed over procCubes before [`grip_means`]).
fn grip_sums<M: Model>(
    constraints: &[crate::engine::boundary::Constraint],
    p: &Particles<M>,
) -> Vec<f64> {
    let mut sums = Vec::new();
    for b in constraints {
        sums.push(b.particles.len() as f64);
        for &d in b.dofs.iter().filter(|&&d| d < 3) {
            sums.push(
                b.particles
                    .iter()
                    .map(|&i| p.displacement(i as usize)[d])
                    .sum(),
            );
        }
    }
    sums
}

/// Mean displacements from [`grip_sums`] summed over procCubes (0 for an empty constraint).
fn grip_means(constraints: &[crate::engine::boundary::Constraint], sums: &[f64]) -> Vec<f64> {
    let mut means = Vec::new();
    let mut at = 0;
    for b in constraints {
        let count = sums[at];
        let n = b.dofs.iter().filter(|&&d| d < 3).count();
        means.extend(sums[at + 1..at + 1 + n].iter().map(|s| {
            if count > 0.0 {
                s / count
            } else {
                0.0
            }
        }));
        at += 1 + n;
    }
    means
}

/// Owned particles' global indices, damage and every declared record (alterable, fixed, state,
/// force), gathered on the root.
pub(crate) fn gather_frame<M: Model>(
    cube: &mut Cube<M>,
    damage: &[f64],
    store: &mut Option<FrameStore<M>>,
) {
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
pub(crate) struct FrameStore<M: Model> {
    pub particles: Particles<M>,
    pub damage: Vec<f64>,
    /// Store index of each global id.
    pub index_of: Vec<u32>,
}

pub(crate) fn frame_store<M: Model>(setup: Setup<M>) -> FrameStore<M> {
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

/// Final positions by global id and the broken bonds, at full precision, for comparing runs.
fn write_final_state(
    dir: &std::path::Path,
    last: &Final,
    broken: &[(u32, u32)],
) -> std::io::Result<()> {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("final_positions.csv"))?);
    writeln!(f, "id,x,y,z,damage,vx,vy,vz")?;
    for (g, ((p, d), v)) in last
        .position
        .iter()
        .zip(&last.damage)
        .zip(&last.velocity)
        .enumerate()
    {
        writeln!(
            f,
            "{g},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e}",
            p[0], p[1], p[2], d, v[0], v[1], v[2]
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
pub(crate) fn balance_table(rows: &[Vec<f64>], steps: u64) -> String {
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

/// The end of a run on every worker: totals reduced, the final positions, damage and broken
/// bonds gathered by global id, each procCube's share of the time; the root writes
/// `timing.txt` (and the final state if asked) and returns the summary, with what the loop
/// counted (`tally`) and its wall time.
pub(crate) fn finish<M: Model>(
    mut cube: Cube<M>,
    plan: &Plan,
    tally: Tally,
    seconds: f64,
) -> Result<Option<Summary>, String> {
    let io = |e| plan.io(e);
    let n_global = cube.global_particles;
    let mut totals = [
        (cube.sim.bonds.len() + cube.dropped.len()) as f64,
        cube.broken_count() as f64,
        cube.sim.kinetic_energy(),
        cube.sim.strain_energy(),
    ];
    cube.team().reduce(&mut totals, Reduce::Sum);
    // Gathered on the root unless the run writes in parts and the deck did not ask for the
    // final state: then no rank holds the scene, and the summary has neither.
    let whole = !plan.in_parts || plan.final_state;
    let (last, broken_pairs) = if whole {
        (
            final_positions(&mut cube, n_global),
            final_broken_pairs(&mut cube),
        )
    } else {
        (Final::default(), Vec::new())
    };
    let picture = plan
        .picture
        .map(|colouring| super::picture::write_picture(&mut cube, plan, colouring));
    let balance = balance_rows(&mut cube);
    let Some(balance) = balance else {
        return Ok(None);
    };
    let steps = cube.sim.step - plan.first_step;
    let mut timing = cube.sim.timing.table(n_global as f64 * steps as f64);
    let _ = writeln!(
        timing,
        "bonds: {} ({} broken); {}{}",
        totals[0] as usize,
        totals[1] as usize,
        plan.layout,
        if tally.shuffles > 0 {
            format!(", {} shuffles moved particles", tally.shuffles)
        } else {
            String::new()
        }
    );
    if cube.sim.pairs.is_some() {
        let _ = writeln!(
            timing,
            "neighbour lists: {} rebuilds, by migration to neighbouring procCubes",
            cube.rebuilds
        );
    }
    if balance.len() > 1 {
        timing.push_str(&balance_table(&balance, steps));
    }
    // With the throughput, so that timing.txt says what the checkpoints cost.
    if let Some((_, size, secs)) = tally.checkpoints.last() {
        let _ = writeln!(
            timing,
            "checkpoints: {} written, the last {:.1} MB in {:.3} s ({:.0} MB/s)",
            tally.checkpoints.len(),
            *size as f64 / 1e6,
            secs,
            *size as f64 / 1e6 / secs.max(1e-9)
        );
    }
    std::fs::write(plan.dir.join("timing.txt"), &timing).map_err(io)?;
    if plan.final_state {
        write_final_state(&plan.dir, &last, &broken_pairs).map_err(io)?;
    }
    if let Some(drawn) = picture {
        drawn?;
    }
    // The results are written: a picture that cannot be drawn is reported, not fatal.
    if let Err(e) = crate::output::pictures::history_pictures(&plan.dir, &plan.title) {
        eprintln!("warning: the history pictures were not drawn: {e}");
    }
    Ok(Some(Summary {
        particles: n_global,
        bonds: totals[0] as usize,
        steps: cube.sim.step,
        dt: cube.sim.dt,
        broken: totals[1] as usize,
        kinetic_energy: totals[2],
        strain_energy: totals[3],
        output: plan.dir.clone(),
        seconds,
        timing,
        layout: plan.layout.clone(),
        shuffles: tally.shuffles,
        positions: last.position,
        damage: last.damage,
        broken_pairs,
        interrupted: tally.interrupted,
        checkpoints: tally.checkpoints,
        first_step: plan.first_step,
        force_evaluations: tally.evaluations,
        load_steps: tally.load_steps,
        converged_steps: tally.converged,
        last_step_converged: tally.solved.is_none_or(|r| r.converged),
        stopped_at_broken: tally.stopped_at_broken,
        stopped_at_probe: tally.stopped_at_probe,
        stopped_below_peak: tally.stopped_below_peak,
    }))
}

/// Current positions, damage, material and velocity by global id, on the root (empty
/// elsewhere).
fn final_positions<M: Model>(cube: &mut Cube<M>, n_global: usize) -> Final {
    let damage = cube.damage();
    let p = &cube.sim.particles;
    let mut mine: Vec<f64> = Vec::new();
    for (i, d) in damage.iter().enumerate() {
        let v = p.velocity(i);
        mine.push(p.gid[i] as f64);
        mine.extend_from_slice(&p.pos(i));
        mine.extend([*d, p.material[i] as f64, v[0], v[1], v[2]]);
    }
    let Some(parts) = cube.team().gather(bytemuck::cast_slice(&mine)) else {
        return Final::default();
    };
    let mut f = Final {
        position: vec![[f64::NAN; 3]; n_global],
        damage: vec![f64::NAN; n_global],
        material: vec![0.0; n_global],
        velocity: vec![[0.0; 3]; n_global],
    };
    for bytes in parts {
        for rec in f64s(&bytes).chunks_exact(9) {
            let id = rec[0] as usize;
            f.position[id] = [rec[1], rec[2], rec[3]];
            f.damage[id] = rec[4];
            f.material[id] = rec[5];
            f.velocity[id] = [rec[6], rec[7], rec[8]];
        }
    }
    f
}

/// The final state by global id, on the root.
#[derive(Default)]
struct Final {
    position: Vec<[f64; 3]>,
    damage: Vec<f64>,
    material: Vec<f64>,
    velocity: Vec<[f64; 3]>,
}

/// The broken bonds as sorted (smaller, larger) global id pairs, on the root.
fn final_broken_pairs<M: Model>(cube: &mut Cube<M>) -> Vec<(u32, u32)> {
    let pairs: Vec<f64> = cube
        .broken_pairs()
        .iter()
        .flat_map(|&(a, b)| [a as f64, b as f64])
        .collect();
    let mut all: Vec<(u32, u32)> = cube
        .team()
        .gather(bytemuck::cast_slice(&pairs))
        .unwrap_or_default()
        .iter()
        .flat_map(|b| {
            f64s(b)
                .chunks_exact(2)
                .map(|c| (c[0] as u32, c[1] as u32))
                .collect::<Vec<_>>()
        })
        .collect();
    all.sort_unstable();
    all
}

/// Each procCube's particles, ghosts, force, communication and step-loop seconds and bytes
/// sent, on the root (`None` elsewhere).
fn balance_rows<M: Model>(cube: &mut Cube<M>) -> Option<Vec<Vec<f64>>> {
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
    let all = cube.team().gather(bytemuck::cast_slice(&balance))?;
    Some(all.iter().map(|b| f64s(b)).collect())
}
