//! Adaptive dynamic relaxation (Kilic & Madenci 2010; THEORY.md §5): quasi-static equilibrium
//! under the deck's loads and supports, one load step at a time, for every model with
//! second-order degrees of freedom.
//!
//! Each load step moves the supports to their positions at the step's end (the loads follow
//! their time history there too), then iterates a damped pseudo-dynamics with a fictitious
//! mass λ_i per DOF (λ_i = 5/4 · V_i Σ_j V_j C_ij, the Gershgorin bound ¼ Σ_j |K_ij| with the
//! book's safety factor 5, pseudo time step 1) and the damping c = 2√(uᵀ¹Ku / uᵀu) from the
//! local diagonal stiffness ¹K_ii = −(F_iⁿ − F_iⁿ⁻¹)/(λ_i u̇_iⁿ⁻½), until the residual force
//! is below `tolerance` times the applied forces and support reactions. The Rayleigh quotient
//! of the damping is taken over the translations only: mixed with rotations it would weigh
//! lengths against angles by the choice of units (micropolar needed ten times the iterations). Bonds break during the
//! iterations as the stretch passes their limit, as in explicit stepping. Velocities are zero
//! at the start and end of each load step, so a checkpoint between load steps holds the whole
//! state. Sums over particles are reduced over procCubes: every procCube iterates alike.

use crate::attributes::Attributes;
use crate::comm::{Reduce, Team};
use crate::model::{second_order, Model};
use crate::parallel::Cube;
use crate::particles::Particles;
use crate::timing::Phase;
use std::time::Instant;

/// The book's safety factor on the fictitious mass (Madenci & Oterkus 2014).
const MASS_SAFETY: f64 = 5.0;

/// Damping used when the stiffness estimate asks for more than critical (both reference codes).
const DAMPING_CAP: f64 = 1.9;

/// What one load step took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Relaxed {
    /// Force evaluations (iterations) spent.
    pub iterations: u64,
    /// |residual| / |applied forces and reactions| at the end.
    pub residual: f64,
    pub converged: bool,
}

/// The fictitious mass of each second-order DOF, by global id (`second_order::<M>()` values
/// per particle), from a store that holds whole families.
pub fn fictitious_mass<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &crate::bonds::BondList<M::Bond>,
) -> Vec<f64> {
    let n2 = second_order::<M>();
    let sums = crate::simulation::stiffness_sums(model, p, bonds);
    let mut by_gid = vec![0.0; p.len() * n2];
    for (i, sum) in sums.iter().enumerate().take(p.n_owned) {
        let g = p.gid[i] as usize;
        for k in 0..n2 {
            // A particle without bonds still needs a finite mass.
            let lambda = 0.25 * MASS_SAFETY * p.volume[i] * sum.as_slice()[k];
            by_gid[g * n2 + k] = if lambda > 0.0 { lambda } else { f64::MAX };
        }
    }
    by_gid
}

/// Second-order coordinates minus their reference (translations from x0, rotations from 0).
fn displacement<M: Model>(p: &Particles<M>, i: usize, k: usize) -> f64 {
    let q = p.alter[i].as_slice()[k];
    if k < 3 {
        q - p.x0[i][k]
    } else {
        q
    }
}

/// Sets every owned particle's velocities to zero: quasi-static solvers start and end each
/// load step at rest.
pub fn zero_velocities<M: Model>(p: &mut Particles<M>) {
    let n2 = second_order::<M>();
    for a in &mut p.alter[..p.n_owned] {
        a.as_mut_slice()[n2..2 * n2].fill(0.0);
    }
}

impl<M: Model> Cube<M> {
    /// The start of a quasi-static load step (relaxation or the implicit solve): supports to
    /// their positions at the end of the step (a displacement history lands exactly; a velocity
    /// moves them by v·Δt), free particles held, the clock to the step's end.
    pub fn begin_load_step(&mut self) {
        let n = self.sim.particles.n_owned;
        let (t0, dt) = (self.sim.time, self.sim.dt);
        let start = Instant::now();
        zero_velocities(&mut self.sim.particles);
        for c in &self.sim.constraints {
            c.set_drift_velocity(&mut self.sim.particles, t0, dt);
        }
        let sim = &mut self.sim;
        for a in &mut sim.particles.alter[..n] {
            sim.model.drift(a, dt);
        }
        zero_velocities(&mut self.sim.particles);
        self.sim.time = t0 + dt;
        self.sim.step += 1;
        self.sim.timing.lap(Phase::Integration, start);
    }

    /// One load step of adaptive dynamic relaxation: supports and loads move to time
    /// `sim.time + sim.dt`, then the particles relax to equilibrium. `mass_by_gid` is
    /// [`fictitious_mass`]. Every worker must call it.
    pub fn relax_step(
        &mut self,
        mass_by_gid: &[f64],
        tolerance: f64,
        max_iterations: u64,
    ) -> Relaxed {
        let n2 = second_order::<M>();
        let n = self.sim.particles.n_owned;
        self.begin_load_step();
        let start = Instant::now();
        let lambda: Vec<f64> = (0..n)
            .flat_map(|i| {
                let g = self.sim.particles.gid[i] as usize;
                mass_by_gid[g * n2..(g + 1) * n2].to_vec()
            })
            .collect();
        self.sim.timing.lap(Phase::Integration, start);

        let mut iterations = 1;
        self.sim.compute_forces();
        // Forces of this and of the previous iteration, two buffers swapped: no allocation per
        // iteration.
        let mut previous: Vec<f64> = Vec::with_capacity(n * n2);
        self.owned_forces(n2, &mut previous);
        let mut force: Vec<f64> = Vec::with_capacity(n * n2);
        // u̇^½ = F⁰ / (2λ) (pseudo time step 1).
        {
            let p = &mut self.sim.particles;
            for i in 0..n {
                let a = p.alter[i].as_mut_slice();
                for k in 0..n2 {
                    a[n2 + k] = previous[i * n2 + k] / (2.0 * lambda[i * n2 + k]);
                }
            }
        }
        let mut residual;
        loop {
            let t = Instant::now();
            {
                let sim = &mut self.sim;
                for a in &mut sim.particles.alter[..n] {
                    sim.model.drift(a, 1.0);
                }
            }
            self.sim.timing.lap(Phase::Integration, t);
            self.sim.compute_forces();
            iterations += 1;
            let t = Instant::now();
            self.owned_forces(n2, &mut force);
            // uᵀ¹Ku, uᵀu, |F|², and the scale: applied loads and support reactions.
            let p = &self.sim.particles;
            let mut sums = [0.0f64; 3];
            for i in 0..n {
                let a = p.alter[i].as_slice();
                for k in 0..n2 {
                    let idx = i * n2 + k;
                    let v = a[n2 + k];
                    // The damping follows the translations: a Rayleigh quotient that mixed
                    // lengths and angles would weigh them by the choice of units.
                    if k < 3 {
                        let u = displacement(p, i, k);
                        if v != 0.0 {
                            let stiffness = -(force[idx] - previous[idx]) / (lambda[idx] * v);
                            sums[0] += u * stiffness * u;
                        }
                        sums[1] += u * u;
                    }
                    sums[2] += force[idx] * force[idx];
                }
            }
            // Each procCube holds its share of every load's total and support's reaction:
            // summed, they are the whole scene's.
            let mut all: Vec<f64> = sums.to_vec();
            for l in &self.sim.loads {
                all.extend_from_slice(&l.total(self.sim.time));
            }
            for c in &self.sim.constraints {
                all.extend_from_slice(&c.reaction);
            }
            Team::new(self.sim.exchange.transport()).reduce(&mut all, Reduce::Sum);
            let scale = all[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
            residual = all[2].sqrt() / scale.max(f64::MIN_POSITIVE);
            if residual <= tolerance || iterations >= max_iterations {
                self.sim.timing.lap(Phase::Integration, t);
                break;
            }
            let ratio = all[0] / all[1].max(f64::MIN_POSITIVE);
            let mut c = if ratio > 0.0 { 2.0 * ratio.sqrt() } else { 0.0 };
            if c > 2.0 {
                c = DAMPING_CAP;
            }
            // u̇ⁿ⁺½ = [(2 − c)u̇ⁿ⁻½ + 2Fⁿ/λ] / (2 + c).
            let p = &mut self.sim.particles;
            for i in 0..n {
                let a = p.alter[i].as_mut_slice();
                for k in 0..n2 {
                    let idx = i * n2 + k;
                    a[n2 + k] =
                        ((2.0 - c) * a[n2 + k] + 2.0 * force[idx] / lambda[idx]) / (2.0 + c);
                }
            }
            std::mem::swap(&mut previous, &mut force);
            self.sim.timing.lap(Phase::Integration, t);
        }
        zero_velocities(&mut self.sim.particles);
        Relaxed {
            iterations,
            residual,
            converged: residual <= tolerance,
        }
    }

    /// Forces on the second-order DOFs of owned particles (zero on supported DOFs).
    fn owned_forces(&self, n2: usize, out: &mut Vec<f64>) {
        let p = &self.sim.particles;
        out.clear();
        for f in &p.force[..p.n_owned] {
            out.extend_from_slice(&f.as_slice()[..n2]);
        }
    }
}

/// Refuses what relaxation (or the implicit solve) cannot do, naming the reason.
pub fn check_model<M: Model>(implicit: bool) -> Result<(), String> {
    if M::FIRST_ORDER > 0 {
        return Err(format!(
            "[solver] kind = \"{}\" solves for mechanical equilibrium; model '{}' has {} first-order degree(s) of freedom (temperature): use the explicit solver",
            if implicit { "implicit" } else { "adr" },
            M::NAME,
            M::FIRST_ORDER
        ));
    }
    if <M::Force as Attributes>::LEN == 0 {
        return Err("[solver] the model has no degrees of freedom".into());
    }
    Ok(())
}
