//! A run's state gathered by global id on the root — what a checkpoint writes (`output::
//! checkpoint`) and a restart or a static start puts back — independent of the layout: a
//! snapshot taken on one layout restores onto any other. A snapshot may also hold only some
//! particles (`ids`): one procCube's part of a checkpoint written in parts, or what a
//! procCube set up on its own reads back of one.
//!
//! It holds the reference position and every alterable attribute and force by global id, the
//! broken bonds as pairs of global ids, the history of every bond whose history is not zero,
//! and the step, time, time step and integrator.

use crate::engine::simulation::Simulation;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::f64s;
use crate::parallel::Cube;

/// A run's state at the end of a step, by global id.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub integrator: String,
    pub model: String,
    /// `name:len` of each alterable field, `|`, the bond history's, `|`, the force's.
    pub schema: String,
    /// The global ids of the rows below, ascending; `None`: every particle, row = global id.
    pub ids: Option<Vec<u32>>,
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
    /// The state of this procCube alone: its owned particles by global id (ascending), and
    /// the broken bonds and bond histories it holds.
    pub fn local<M: Model>(cube: &Cube<M>) -> Snapshot {
        let la = <M::Alter as Attributes>::LEN;
        let lb = <M::Bond as Attributes>::LEN;
        let lf = <M::Force as Attributes>::LEN;
        let p = &cube.sim.particles;
        let mut order: Vec<usize> = (0..p.n_owned).collect();
        order.sort_unstable_by_key(|&i| p.gid[i]);
        let b = &cube.sim.bonds;
        let mut rows: Vec<(u32, u32, bool, &[f64])> = Vec::new();
        for (i, j, k) in b.iter() {
            let h = b.history[k].as_slice();
            if b.broken[k] || h.iter().any(|&x| x != 0.0) {
                let (gi, gj) = (p.gid[i], p.gid[j]);
                rows.push((gi.min(gj), gi.max(gj), b.broken[k], h));
            }
        }
        // Bonds a shuffle dropped once broken: broken, history no longer needed.
        let zero = vec![0.0; lb];
        rows.extend(cube.dropped.iter().map(|&(a, c)| (a, c, true, &zero[..])));
        rows.sort_by_key(|r| (r.0, r.1));
        let mut s = Snapshot {
            step: cube.sim.step,
            time: cube.sim.time,
            dt: cube.sim.dt,
            integrator: cube.sim.integrator.name().to_string(),
            model: M::NAME.to_string(),
            schema: schema::<M>(),
            ids: Some(order.iter().map(|&i| p.gid[i]).collect()),
            x0: order.iter().map(|&i| p.x0[i]).collect(),
            alter: Vec::with_capacity(order.len() * la),
            force: Vec::with_capacity(order.len() * lf),
            broken: Vec::new(),
            history_pairs: Vec::new(),
            history: Vec::new(),
            // Global values, the same on every procCube.
            thermostat: cube.sim.thermostat.as_ref().map(|t| t.save()),
        };
        for &i in &order {
            s.alter.extend_from_slice(p.alter[i].as_slice());
            s.force.extend_from_slice(p.force[i].as_slice());
        }
        for (a, c, broken, h) in rows {
            s.add_bond((a, c), broken, h);
        }
        s
    }

    /// Records bond (a, b): broken or not, and its history if not zero.
    fn add_bond(&mut self, pair: (u32, u32), broken: bool, h: &[f64]) {
        if broken {
            self.broken.push(pair);
        }
        if h.iter().any(|&x| x != 0.0) {
            self.history_pairs.push(pair);
            self.history.extend_from_slice(h);
        }
    }

    /// The row of global id `g`, if the snapshot holds it.
    pub fn row(&self, g: u32) -> Option<usize> {
        match &self.ids {
            None => ((g as usize) < self.x0.len()).then_some(g as usize),
            Some(ids) => ids.binary_search(&g).ok(),
        }
    }

    /// The snapshots of several procCubes (or checkpoint parts) as one, holding every particle
    /// they hold, ascending by global id; `dense`: with every particle of a scene of that
    /// many, row = global id (`ids` is `None`).
    pub fn merge(parts: Vec<Snapshot>, dense: Option<usize>) -> Option<Snapshot> {
        let first = parts.first()?;
        let (la, lf) = (first.alter_len(), first.force_len());
        let lb = first.history_len();
        let mut rows: Vec<(u32, usize, usize)> = Vec::new();
        for (k, s) in parts.iter().enumerate() {
            for r in 0..s.x0.len() {
                let g = s.ids.as_ref().map_or(r as u32, |ids| ids[r]);
                rows.push((g, k, r));
            }
        }
        rows.sort_unstable();
        rows.dedup_by_key(|r| r.0);
        let mut m = Snapshot {
            ids: Some(rows.iter().map(|r| r.0).collect()),
            x0: Vec::with_capacity(rows.len()),
            alter: Vec::with_capacity(rows.len() * la),
            force: Vec::with_capacity(rows.len() * lf),
            broken: Vec::new(),
            history_pairs: Vec::new(),
            history: Vec::new(),
            ..first.clone_header()
        };
        for &(_, k, r) in &rows {
            let s = &parts[k];
            m.x0.push(s.x0[r]);
            m.alter.extend_from_slice(&s.alter[r * la..(r + 1) * la]);
            m.force.extend_from_slice(&s.force[r * lf..(r + 1) * lf]);
        }
        // Ascending and distinct: complete exactly when there are n and the last is n − 1.
        if let Some(n) = dense {
            if rows.len() == n && rows.last().is_none_or(|r| r.0 as usize + 1 == n) {
                m.ids = None;
            }
        }
        let mut bonds: Vec<((u32, u32), bool, &[f64])> = Vec::new();
        let none = vec![0.0; lb];
        for s in &parts {
            bonds.extend(s.broken.iter().map(|&p| (p, true, &none[..])));
            for (t, &p) in s.history_pairs.iter().enumerate() {
                bonds.push((p, false, &s.history[t * lb..(t + 1) * lb]));
            }
        }
        bonds.sort_by_key(|b| b.0);
        // A bond listed as broken and with a history comes in twice: merged.
        let mut at = 0;
        while at < bonds.len() {
            let pair = bonds[at].0;
            let (mut broken, mut h) = (false, &none[..]);
            while at < bonds.len() && bonds[at].0 == pair {
                broken |= bonds[at].1;
                if bonds[at].2.iter().any(|&x| x != 0.0) {
                    h = bonds[at].2;
                }
                at += 1;
            }
            m.add_bond(pair, broken, h);
        }
        Some(m)
    }

    /// Step, time, time step, integrator, model, schema and thermostat, without particles.
    fn clone_header(&self) -> Snapshot {
        Snapshot {
            step: self.step,
            time: self.time,
            dt: self.dt,
            integrator: self.integrator.clone(),
            model: self.model.clone(),
            schema: self.schema.clone(),
            ids: Some(Vec::new()),
            x0: Vec::new(),
            alter: Vec::new(),
            force: Vec::new(),
            broken: Vec::new(),
            history_pairs: Vec::new(),
            history: Vec::new(),
            thermostat: self.thermostat.clone(),
        }
    }

    /// Values per particle of the alterable records, per bond of the history, per particle of
    /// the forces, from the schema.
    fn schema_lens(&self) -> [usize; 3] {
        let mut lens = [0; 3];
        for (k, part) in self.schema.split('|').enumerate().take(3) {
            lens[k] = part
                .split(',')
                .filter_map(|f| f.split_once(':')?.1.parse::<usize>().ok())
                .sum();
        }
        lens
    }
    fn alter_len(&self) -> usize {
        self.schema_lens()[0]
    }
    fn history_len(&self) -> usize {
        self.schema_lens()[1]
    }
    fn force_len(&self) -> usize {
        self.schema_lens()[2]
    }

    /// Gathers the state of every procCube on the root, which gets the snapshot of every
    /// particle (row = global id); every worker must call it.
    pub fn gather<M: Model>(cube: &mut Cube<M>) -> Option<Snapshot> {
        let mine = Snapshot::local(cube);
        let n = cube.global_particles;
        let all = cube.team().gather(&mine.to_bytes())?;
        let parts: Vec<Snapshot> = all.iter().map(|b| mine.with_rows_of(b)).collect();
        Snapshot::merge(parts, Some(n))
    }

    /// The particles and bonds as bytes for a gather (the header is the receiver's own).
    fn to_bytes(&self) -> Vec<u8> {
        let pairs = |p: &[(u32, u32)]| -> Vec<f64> {
            p.iter().flat_map(|&(a, b)| [a as f64, b as f64]).collect()
        };
        let ids: Vec<f64> = (0..self.x0.len())
            .map(|r| self.ids.as_ref().map_or(r as u32, |ids| ids[r]) as f64)
            .collect();
        let x0: Vec<f64> = self.x0.iter().flatten().copied().collect();
        let lists = [
            ids,
            x0,
            self.alter.clone(),
            self.force.clone(),
            pairs(&self.broken),
            pairs(&self.history_pairs),
            self.history.clone(),
        ];
        let mut v: Vec<f64> = lists.iter().map(|l| l.len() as f64).collect();
        for l in lists {
            v.extend(l);
        }
        bytemuck::cast_slice(&v).to_vec()
    }

    /// A snapshot from [`Snapshot::to_bytes`], with this one's header.
    fn with_rows_of(&self, bytes: &[u8]) -> Snapshot {
        let v = f64s(bytes);
        let (lens, mut rest) = v.split_at(7);
        let mut take = |k: usize| {
            let (a, b) = rest.split_at(lens[k] as usize);
            rest = b;
            a.to_vec()
        };
        let pairs = |v: Vec<f64>| {
            v.chunks_exact(2)
                .map(|c| (c[0] as u32, c[1] as u32))
                .collect()
        };
        let ids = take(0).iter().map(|&g| g as u32).collect();
        let x0 = take(1)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Snapshot {
            ids: Some(ids),
            x0,
            alter: take(2),
            force: take(3),
            broken: pairs(take(4)),
            history_pairs: pairs(take(5)),
            history: take(6),
            ..self.clone_header()
        }
    }

    /// Puts the snapshot's particles into a freshly built scene or procCube: reference positions (a
    /// shuffle may have wrapped some around a periodic box), alterable attributes, time and
    /// step. Bonds are marked per procCube by [`Snapshot::restore_bonds`].
    pub fn restore_particles<M: Model>(&self, sim: &mut Simulation<M>) {
        let la = <M::Alter as Attributes>::LEN;
        let p = &mut sim.particles;
        for i in 0..p.len() {
            if let Some(r) = self.row(p.gid[i]) {
                p.x0[i] = self.x0[r];
                p.alter[i]
                    .as_mut_slice()
                    .copy_from_slice(&self.alter[r * la..(r + 1) * la]);
            }
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
        for i in 0..b.owners() {
            for k in b.family(i) {
                let pair = key(i, b.partners()[k] as usize);
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
            if let Some(r) = self.row(p.gid[i]) {
                p.force[i]
                    .as_mut_slice()
                    .copy_from_slice(&self.force[r * lf..(r + 1) * lf]);
            }
        }
    }
}
