//! A run's state gathered by global id on the root — what a checkpoint writes (`output::
//! checkpoint`) and a restart or a static start puts back — independent of the layout: a
//! snapshot taken on one layout restores onto any other.
//!
//! It holds the reference position and every alterable attribute and force by global id, the
//! broken bonds as pairs of global ids, the history of every bond whose history is not zero,
//! and the step, time, time step and integrator.

use crate::input::setup::Setup;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::f64s;
use crate::parallel::Cube;

/// A run's state at the end of a step, by global id.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub integrator: String,
    pub model: String,
    /// `name:len` of each alterable field, `|`, the bond history's, `|`, the force's.
    pub schema: String,
    pub x0: Vec<[f64; 3]>,
    /// Alterable records, `Alter::LEN` values per particle, by global id.
    pub alter: Vec<f64>,
    /// The generalized forces of the last evaluation, `Force::LEN` per particle, by global id:
    /// the integrator's state (velocity Verlet starts a step with them). Recomputing them would
    /// not do: an LPS bond that broke in the last pair pass still counted in its state pass.
    pub force: Vec<f64>,
    /// Broken bonds, (smaller, larger) global id, sorted.
    pub broken: Vec<(u32, u32)>,
    /// Bonds with a non-zero history, sorted, and their histories (`Bond::LEN` each).
    pub history_pairs: Vec<(u32, u32)>,
    pub history: Vec<f64>,
    /// The thermostat's state (Nosé–Hoover's ξ and η, the others' removed energy), if the run
    /// has one: a restart continues its dynamics, not a fresh thermostat.
    pub thermostat: Option<crate::engine::thermostat::Saved>,
}

/// The names and lengths of the alterable and bond-history fields of `M`.
pub fn schema<M: Model>() -> String {
    let fields = |f: &[crate::model::attributes::Field]| {
        f.iter()
            .map(|f| format!("{}:{}", f.name, f.len))
            .collect::<Vec<_>>()
            .join(",")
    };
    format!(
        "{}|{}|{}",
        fields(<M::Alter as Attributes>::FIELDS),
        fields(<M::Bond as Attributes>::FIELDS),
        fields(<M::Force as Attributes>::FIELDS)
    )
}

impl Snapshot {
    /// Gathers the state of every procCube on the root, which gets the snapshot; every worker
    /// must call it.
    pub fn gather<M: Model>(cube: &mut Cube<M>) -> Option<Snapshot> {
        let la = <M::Alter as Attributes>::LEN;
        let lb = <M::Bond as Attributes>::LEN;
        let lf = <M::Force as Attributes>::LEN;
        let p = &cube.sim.particles;
        let mut mine: Vec<f64> = Vec::with_capacity(p.n_owned * (4 + la + lf));
        for i in 0..p.n_owned {
            mine.push(p.gid[i] as f64);
            mine.extend_from_slice(&p.x0[i]);
            mine.extend_from_slice(p.alter[i].as_slice());
            mine.extend_from_slice(p.force[i].as_slice());
        }
        let b = &cube.sim.bonds;
        let mut bonds: Vec<f64> = Vec::new();
        for (i, j, k) in b.iter() {
            let h = b.history[k].as_slice();
            if b.broken[k] || h.iter().any(|&x| x != 0.0) {
                let (gi, gj) = (p.gid[i], p.gid[j]);
                bonds.push(gi.min(gj) as f64);
                bonds.push(gi.max(gj) as f64);
                bonds.push(if b.broken[k] { 1.0 } else { 0.0 });
                bonds.extend_from_slice(h);
            }
        }
        // Bonds a shuffle dropped once broken: broken, history no longer needed.
        for &(a, c) in &cube.dropped {
            bonds.extend_from_slice(&[a as f64, c as f64, 1.0]);
            bonds.extend(std::iter::repeat_n(0.0, lb));
        }
        let (step, time, dt) = (cube.sim.step, cube.sim.time, cube.sim.dt);
        let integrator = cube.sim.integrator.name().to_string();
        // Global values, the same on every procCube.
        let thermostat = cube.sim.thermostat.as_ref().map(|t| t.save());
        let n = cube.global_particles;
        let mut team = cube.team();
        let particles = team.gather(bytemuck::cast_slice(&mine));
        let bonds = team.gather(bytemuck::cast_slice(&bonds));
        let (particles, bonds) = (particles?, bonds?);
        let mut x0 = vec![[f64::NAN; 3]; n];
        let mut alter = vec![f64::NAN; n * la];
        let mut force = vec![f64::NAN; n * lf];
        for bytes in particles {
            for r in f64s(&bytes).chunks_exact(4 + la + lf) {
                let g = r[0] as usize;
                x0[g] = [r[1], r[2], r[3]];
                alter[g * la..(g + 1) * la].copy_from_slice(&r[4..4 + la]);
                force[g * lf..(g + 1) * lf].copy_from_slice(&r[4 + la..]);
            }
        }
        let mut rows: Vec<(u32, u32, bool, Vec<f64>)> = Vec::new();
        for bytes in bonds {
            for r in f64s(&bytes).chunks_exact(3 + lb) {
                rows.push((r[0] as u32, r[1] as u32, r[2] != 0.0, r[3..].to_vec()));
            }
        }
        rows.sort_by_key(|r| (r.0, r.1));
        let mut c = Snapshot {
            step,
            time,
            dt,
            integrator,
            model: M::NAME.to_string(),
            schema: schema::<M>(),
            x0,
            alter,
            force,
            broken: Vec::new(),
            history_pairs: Vec::new(),
            history: Vec::new(),
            thermostat,
        };
        for (a, b, broken, h) in rows {
            if broken {
                c.broken.push((a, b));
            }
            if h.iter().any(|&x| x != 0.0) {
                c.history_pairs.push((a, b));
                c.history.extend_from_slice(&h);
            }
        }
        Some(c)
    }

    /// Puts the snapshot's particles into a freshly built scene: reference positions (a
    /// shuffle may have wrapped some around a periodic box), alterable attributes, time and
    /// step. Bonds are marked per procCube by [`Snapshot::restore_bonds`].
    pub fn restore_particles<M: Model>(&self, setup: &mut Setup<M>) {
        let la = <M::Alter as Attributes>::LEN;
        let sim = &mut setup.sim;
        let p = &mut sim.particles;
        for i in 0..p.len() {
            let g = p.gid[i] as usize;
            p.x0[i] = self.x0[g];
            p.alter[i]
                .as_mut_slice()
                .copy_from_slice(&self.alter[g * la..(g + 1) * la]);
        }
        sim.time = self.time;
        sim.step = self.step;
        if let (Some(saved), Some(t)) = (&self.thermostat, &mut sim.thermostat) {
            t.restore(saved);
        }
    }

    /// Marks the broken bonds of a procCube and sets bond histories, by global ids; sets its
    /// clock.
    pub fn restore_bonds<M: Model>(&self, cube: &mut Cube<M>) {
        let lb = <M::Bond as Attributes>::LEN;
        let sim = &mut cube.sim;
        sim.time = self.time;
        sim.step = self.step;
        let gid = &sim.particles.gid;
        let key = |i: usize, j: usize| (gid[i].min(gid[j]), gid[i].max(gid[j]));
        let b = &mut sim.bonds;
        let bonds: Vec<(usize, usize, usize)> = b.iter().collect();
        for (i, j, k) in bonds {
            let pair = key(i, j);
            if self.broken.binary_search(&pair).is_ok() {
                b.broken[k] = true;
            }
            if lb > 0 {
                if let Ok(at) = self.history_pairs.binary_search(&pair) {
                    b.history[k]
                        .as_mut_slice()
                        .copy_from_slice(&self.history[at * lb..(at + 1) * lb]);
                }
            }
        }
    }

    /// The forces of the last evaluation, over the ones a restarted procCube's first
    /// evaluation found (call after `Cube::start`).
    pub fn restore_forces<M: Model>(&self, cube: &mut Cube<M>) {
        let lf = <M::Force as Attributes>::LEN;
        // The restored positions need not lie in the cells the neighbour lists were drawn
        // from (the layout came from the reference positions): the first step shuffles and
        // rebuilds. The start's forces are the checkpoint's, restored here.
        if let Some(pairs) = &mut cube.sim.pairs {
            pairs.invalidate();
        }
        let p = &mut cube.sim.particles;
        for i in 0..p.n_owned {
            let g = p.gid[i] as usize;
            p.force[i]
                .as_mut_slice()
                .copy_from_slice(&self.force[g * lf..(g + 1) * lf]);
        }
    }
}
