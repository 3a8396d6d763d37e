//! One procCube's time stepping: particles and bonds, forces, loads and constraints, integration.
//!
//! ```text
//! [thermostat half step] → first-order DOFs (Euler) → kick → constrain → drift
//!      → exchange (forward) → [state pass → reverse-sum → finish] → pair pass
//!      → reverse force sum → loads, constraints → kick → constrain → [thermostat]
//! ```
//! The exchange points are where the wall method's ghost messages go. The step is handed the
//! exchange (`parallel::wall::WallExchange` on procCubes); a simulation on its own, with no
//! ghosts, steps with [`Local`], which does nothing there.

use crate::engine::bonds::BondList;
use crate::engine::boundary::{Constraint, Load};
use crate::engine::forces;
use crate::engine::pair_pass::NonBonded;
use crate::engine::particles::Particles;
use crate::engine::thermostat::Thermostat;
use crate::engine::timing::{Phase, Timing};
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use std::time::Instant;

/// Time integration of the generalized degrees of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Velocity Verlet (half kick, drift, forces, half kick): second order, symplectic.
    VelocityVerlet,
    /// The thesis's scheme (appendix A.3.2): v += Δt·F/m, then x += Δt·v. Read with the
    /// stored velocities as half-step ones, v(t + Δt/2) = v(t − Δt/2) + Δt·F(t)/m, it is the
    /// leapfrog scheme, whose positions are velocity Verlet's (docs/theory.md §10).
    Leapfrog,
}

impl Integrator {
    pub fn name(self) -> &'static str {
        match self {
            Integrator::VelocityVerlet => "velocity-verlet",
            Integrator::Leapfrog => "leapfrog",
        }
    }

    /// The integrator a deck or a checkpoint names. "euler" and "semi-implicit-euler" are the
    /// leapfrog's older names (checkpoints written before it was named say the latter).
    pub fn from_name(name: &str) -> Option<Integrator> {
        match name {
            "verlet" | "velocity-verlet" => Some(Integrator::VelocityVerlet),
            "leapfrog" | "euler" | "semi-implicit-euler" => Some(Integrator::Leapfrog),
            _ => None,
        }
    }
}

/// Moves ghost data between procCubes at the points of the step where the wall method needs it.
pub trait Exchange<M: Model> {
    /// Alterable attributes of owned particles to their ghost copies.
    fn forward(&mut self, _p: &mut Particles<M>) {}
    /// Partial state sums on ghosts back to their owners (summed on arrival).
    fn reverse_state(&mut self, _p: &mut Particles<M>) {}
    /// Finished state of owned particles to their ghost copies.
    fn forward_state(&mut self, _p: &mut Particles<M>) {}
    /// Generalized forces on ghosts back to their owners (summed on arrival).
    fn reverse_force(&mut self, _p: &mut Particles<M>) {}
}

/// No ghosts: nothing to move.
#[derive(Clone, Copy, Debug, Default)]
pub struct Local;
impl<M: Model> Exchange<M> for Local {
    fn forward(&mut self, p: &mut Particles<M>) {
        // Ghosts stepped without their exchange would keep stale positions: a procCube steps
        // through `Cube::advance`, never through its simulation alone.
        assert_eq!(
            p.len(),
            p.n_owned,
            "a store with ghosts stepped without its wall exchange"
        );
    }
}

pub struct Simulation<M: Model> {
    pub model: M,
    pub particles: Particles<M>,
    pub bonds: BondList<M::Bond>,
    pub constraints: Vec<Constraint>,
    pub loads: Vec<Load>,
    pub integrator: Integrator,
    pub dt: f64,
    pub time: f64,
    pub step: u64,
    pub timing: Timing,
    /// The non-bonded pass, if the deck has a `[pair]` law; `None` costs nothing.
    pub pairs: Option<Box<dyn NonBonded<M>>>,
    /// With a pair law: Σ x·F of the last evaluation over this procCube's held particles (owned
    /// and ghost), before the force return: the virial of every internal force, bonds and
    /// pairs, whose sum over procCubes gives the pressure.
    pub virial: f64,
    /// The deck's `[thermostat]`, if any.
    pub thermostat: Option<Thermostat>,
}

impl<M: Model> Simulation<M> {
    pub fn new(model: M, particles: Particles<M>, bonds: BondList<M::Bond>, dt: f64) -> Self {
        Simulation {
            model,
            particles,
            bonds,
            constraints: Vec::new(),
            loads: Vec::new(),
            integrator: Integrator::VelocityVerlet,
            dt,
            time: 0.0,
            step: 0,
            timing: Timing::default(),
            pairs: None,
            virial: 0.0,
            thermostat: None,
        }
    }

    /// Whether each second-order DOF of the owned particles (particle-major) is free: held by
    /// no boundary condition (fixed or driven).
    pub fn free_dofs(&self) -> Vec<bool> {
        let n2 = second_order::<M>();
        let mut free = vec![true; self.particles.n_owned * n2];
        for c in &self.constraints {
            for &i in &c.particles {
                for &k in c.dofs.iter().filter(|&&k| k < n2) {
                    free[i as usize * n2 + k] = false;
                }
            }
        }
        free
    }

    /// Forces at the current state, loads and constraint reactions included, with no ghosts.
    /// Returns the number of bonds that broke.
    pub fn compute_forces(&mut self) -> usize {
        self.compute_forces_with(&mut Local)
    }

    /// [`Simulation::compute_forces`] with ghost data moved by `exchange`.
    pub fn compute_forces_with(&mut self, exchange: &mut impl Exchange<M>) -> usize {
        let p = &mut self.particles;
        let mut t = Instant::now();
        exchange.forward(p);
        t = self.timing.lap(Phase::Communication, t);
        if <M::State as Attributes>::LEN > 0 {
            forces::state_pass(&self.model, p, &mut self.bonds);
            exchange.reverse_state(p);
            forces::finish_state(&self.model, p);
            exchange.forward_state(p);
            t = self.timing.lap(Phase::State, t);
        }
        let broken = forces::pair_pass(&self.model, p, &mut self.bonds);
        t = self.timing.lap(Phase::Forces, t);
        if let Some(pairs) = &mut self.pairs {
            pairs.add_forces(p, &self.bonds);
            self.virial = held_virial(p);
            t = self.timing.lap(Phase::Pairs, t);
        }
        exchange.reverse_force(p);
        t = self.timing.lap(Phase::Communication, t);
        for load in &self.loads {
            load.apply(p, self.time);
        }
        for c in &mut self.constraints {
            c.take_forces(p);
        }
        self.timing.lap(Phase::Boundary, t);
        broken
    }

    /// v += h·F/m on every owned second-order DOF.
    fn kick(&mut self, h: f64) {
        let n = second_order::<M>();
        let p = &mut self.particles;
        for i in 0..p.n_owned {
            let f = p.force[i].as_slice();
            let inv = p.inv_inertia[i].as_slice();
            let a = p.alter[i].as_mut_slice();
            for k in 0..n {
                a[n + k] += h * f[k] * inv[k];
            }
        }
    }

    /// q += h·F/C on every owned first-order DOF (forward Euler with the rates of the last
    /// force evaluation). Compiled away for models without first-order DOFs.
    fn advance_first_order(&mut self, h: f64) {
        if M::FIRST_ORDER == 0 {
            return;
        }
        let n = second_order::<M>();
        let p = &mut self.particles;
        for i in 0..p.n_owned {
            let f = p.force[i].as_slice();
            let inv = p.inv_inertia[i].as_slice();
            let a = p.alter[i].as_mut_slice();
            for k in 0..M::FIRST_ORDER {
                a[2 * n + k] += h * f[n + k] * inv[n + k];
            }
        }
    }

    /// q += h·v on every owned second-order DOF (the model composes finite rotations).
    fn drift(&mut self, h: f64) {
        let p = &mut self.particles;
        for a in &mut p.alter[..p.n_owned] {
            self.model.drift(a, h);
        }
    }

    /// Advances one time step with no ghosts; returns the number of bonds that broke in it.
    pub fn advance(&mut self) -> usize {
        self.advance_with(&mut Local)
    }

    /// [`Simulation::advance`] with ghost data moved by `exchange`.
    /// A simulation stepped on its own is the whole scene: the thermostat's sums are its own.
    pub fn advance_with(&mut self, exchange: &mut impl Exchange<M>) -> usize {
        self.thermostat_begin(&mut |_| {});
        self.begin_step();
        let broken = self.compute_forces_with(exchange);
        self.end_step();
        self.thermostat_end(&mut |_| {});
        broken
    }

    /// The thermostat's part before [`Simulation::begin_step`]; `sum` adds a slice over every
    /// procCube of the run.
    pub fn thermostat_begin(&mut self, sum: &mut dyn FnMut(&mut [f64])) {
        if let Some(t) = &mut self.thermostat {
            let start = Instant::now();
            t.begin_step(&mut self.particles, self.dt, sum);
            self.timing.lap(Phase::Integration, start);
        }
    }

    /// The thermostat's part after [`Simulation::end_step`]; `sum` as for
    /// [`Simulation::thermostat_begin`].
    pub fn thermostat_end(&mut self, sum: &mut dyn FnMut(&mut [f64])) {
        if let Some(t) = &mut self.thermostat {
            let start = Instant::now();
            t.end_step(&mut self.particles, self.dt, self.step, sum);
            self.timing.lap(Phase::Integration, start);
        }
    }

    /// The part of a step before its force evaluation: first-order DOFs, the first kick, the
    /// drift; time and step count move on. A procCube refreshes its neighbour lists between
    /// this and the forces.
    pub fn begin_step(&mut self) {
        let (dt, t0) = (self.dt, self.time);
        let start = Instant::now();
        self.advance_first_order(dt);
        match self.integrator {
            Integrator::VelocityVerlet => self.kick(0.5 * dt),
            Integrator::Leapfrog => self.kick(dt),
        }
        for c in &self.constraints {
            c.set_drift_velocity(&mut self.particles, t0, dt);
        }
        self.drift(dt);
        self.time = t0 + dt;
        self.step += 1;
        self.timing.lap(Phase::Integration, start);
    }

    /// The part of a step after its force evaluation: the second kick, constraints.
    pub fn end_step(&mut self) {
        let start = Instant::now();
        if self.integrator == Integrator::VelocityVerlet {
            self.kick(0.5 * self.dt);
        }
        for c in &self.constraints {
            c.set_velocity(&mut self.particles, self.time, self.dt);
        }
        self.timing.lap(Phase::Integration, start);
    }

    pub fn strain_energy(&self) -> f64 {
        crate::engine::bond_sums::strain_energy(&self.model, &self.particles, &self.bonds)
    }

    pub fn kinetic_energy(&self) -> f64 {
        self.particles.kinetic_energy()
    }
}

/// Σ x·F over every held particle, ghosts included, before the force return (the virial by
/// "F dot r", as LAMMPS's `fdotr`): a ghost sits at its periodic image, so each bond or pair
/// counts (x_i − x_j)·F_ij once whichever procCube holds its ends, and no bond needs its own
/// tally.
fn held_virial<M: Model>(p: &Particles<M>) -> f64 {
    (0..p.len())
        .map(|i| {
            let (x, f) = (p.pos(i), &p.force[i].as_slice()[..3]);
            x[0] * f[0] + x[1] * f[1] + x[2] * f[2]
        })
        .sum()
}

/// Σ_j V_j C_ij for each particle and DOF, C_ij the bond stiffness of [`Model::bond_stiffness`]:
/// V_i times it bounds the particle's diagonal stiffness (docs/theory.md §4, §5).
pub fn stiffness_sums<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
) -> Vec<M::Force> {
    stiffness_sums_of(model, p, bonds, |law, _, _, geom| {
        model.bond_stiffness(law, geom)
    })
}

/// Σ_j V_j C_ij with C_ij from `stiffness(law, i, j, geom)`.
pub fn stiffness_sums_of<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
    stiffness: impl Fn(&M::Law, usize, usize, &crate::model::BondGeom) -> M::Force,
) -> Vec<M::Force> {
    let mut sum = vec![M::Force::default(); p.len()];
    for (i, j, b) in bonds.iter() {
        let law = model.law(p.material[i], p.material[j]);
        let c = stiffness(&law, i, j, &bonds.geom[b]);
        let c = c.as_slice();
        // β ≤ 1 (partial volume) is left out, which errs on the safe side; a calibrated bar bond
        // (input/bars.rs) or a surface-corrected one can be stiffer than its law, and counts.
        let beta = bonds.geom[b].beta.max(1.0);
        for (k, v) in sum[i].as_mut_slice().iter_mut().enumerate() {
            *v += p.volume[j] * c[k] * beta;
        }
        for (k, v) in sum[j].as_mut_slice().iter_mut().enumerate() {
            *v += p.volume[i] * c[k] * beta;
        }
    }
    sum
}

/// The stable time step and the particle that sets it (docs/theory.md §4): for each second-order
/// DOF the Silling–Askari bound √(2m / (V_i Σ_j V_j C_ij)), for each first-order DOF the
/// forward-Euler bound C / (V_i Σ_j V_j K_ij) (Gershgorin: twice the diagonal bounds the
/// largest eigenvalue). Infinite if no particle has a bond.
pub fn stable_time_step<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
) -> (f64, usize) {
    let [second, first] = stable_time_steps(model, p, bonds);
    if first.0 < second.0 {
        first
    } else {
        second
    }
}

/// [`stable_time_step`] of the second-order and of the first-order DOFs apart.
pub fn stable_time_steps<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &BondList<M::Bond>,
) -> [(f64, usize); 2] {
    let sum = stiffness_sums(model, p, bonds);
    let n2 = second_order::<M>();
    let mut best = [(f64::INFINITY, 0); 2];
    for (i, s) in sum.iter().enumerate().take(p.n_owned) {
        let inv = p.inv_inertia[i].as_slice();
        for (k, &s) in s.as_slice().iter().enumerate() {
            if s > 0.0 {
                let inertia = 1.0 / (inv[k] * p.volume[i] * s);
                let (dt, order) = if k < n2 {
                    ((2.0 * inertia).sqrt(), 0)
                } else {
                    (inertia, 1)
                };
                if dt < best[order].0 {
                    best[order] = (dt, i);
                }
            }
        }
    }
    best
}
