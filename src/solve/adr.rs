//! Adaptive dynamic relaxation (Kilic & Madenci 2010; docs/theory.md §5): quasi-static equilibrium
//! under the deck's loads and supports, one load step at a time, for every model with
//! second-order degrees of freedom.
//!
//! Each load step moves the supports to their positions at the step's end (the loads follow
//! their time history there too), then iterates a damped pseudo-dynamics with a fictitious
//! mass λ_i per DOF and pseudo time step 1, with the damping c = 2√(uᵀ¹Ku / uᵀu) from the
//! local diagonal stiffness ¹K_ii = −(F_iⁿ − F_iⁿ⁻¹)/(λ_i u̇_iⁿ⁻½), until the residual force
//! is below `tolerance` times the applied forces and support reactions. The Rayleigh quotient
//! of the damping is taken over the translations only: mixed with rotations it would weigh
//! lengths against angles by the choice of units (micropolar needed ten times the iterations).
//! Bonds break during the iterations as the stretch passes their limit, as in explicit
//! stepping. Velocities are zero at the start and end of each load step, so a checkpoint
//! between load steps holds the whole state. Sums over particles are reduced over procCubes:
//! every procCube iterates alike.
//!
//! The fictitious mass. The iterations needed grow as √(λ_max/λ_min) of M⁻¹K, and the pseudo
//! time step 1 is stable while λ_max(M⁻¹K) < 4. The book takes λ_i = ¼ Σ_j |K_ij| (a Gershgorin
//! bound, so λ_max ≤ 4 for any stiffness) times a safety factor 5. On a peridynamic lattice
//! that bound is loose: on the suite's quick cantilevers the stiffest mode is 0.66 of it for
//! PMB and 0.63 for LPS (the Lanczos estimate below), so the book's masses are 6–7× heavier
//! than stability needs, which costs about √6.6 in iterations. PDQ keeps the Gershgorin shape,
//! b_i = V_i Σ_j V_j C_ij per DOF with C_ij from [`Model::relaxation_stiffness`] (a diagonal
//! preconditioner), and scales it by a measured λ_max(B⁻¹K): a Lanczos run of
//! [`crate::engine::spectrum::LANCZOS_STEPS`] force evaluations on the undeformed scene, with K applied as force
//! differences. The masses are then b_i · λ_max / [`TARGET_EIGENVALUE`], 7/8 of the stability
//! limit; stiffness only falls as bonds break, and should the iterations diverge all the same,
//! `Adr::load_step` repeats the load step with doubled masses. The estimate is made once,
//! serially, before the scene is cut into procCubes, so every layout and a restart get the same
//! masses (a doubling is not carried into a restart).

use crate::engine::particles::Particles;
use crate::engine::simulation::Simulation;
use crate::engine::timing::Phase;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use crate::solve::Solver;
use std::time::Instant;

/// The book's safety factor on the Gershgorin mass (Madenci & Oterkus 2014), used only when the
/// stiffest mode cannot be estimated (no free DOF with a bond).
const MASS_SAFETY: f64 = 5.0;

/// The largest eigenvalue of M⁻¹K the masses are scaled to: 7/8 of the stability limit 4 of
/// the pseudo time step 1. The estimate is converged (the same four digits at 30, 60 and 120
/// steps on the suite's cantilevers) and stiffness only falls as bonds break, so the margin is
/// for what the estimate cannot see; `Adr::load_step` doubles the masses if the iterations diverge.
pub const TARGET_EIGENVALUE: f64 = 3.5;

/// Damping used when the stiffness estimate asks for more than critical (both reference codes).
const DAMPING_CAP: f64 = 1.9;

/// A relative residual taken for divergence of the iterations.
pub const DIVERGED: f64 = 1e3;

/// What one load step took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Relaxed {
    /// Force evaluations (iterations) spent.
    pub iterations: u64,
    /// |residual| / |applied forces and reactions| at the end.
    pub residual: f64,
    pub converged: bool,
    /// The iterations diverged (residual over [`DIVERGED`] or not finite).
    pub diverged: bool,
}

/// The fictitious masses of a scene and how they were found.
#[derive(Clone, Debug)]
pub struct FictitiousMass {
    /// Mass of each second-order DOF, by global id (`second_order::<M>()` values per particle).
    pub by_gid: Vec<f64>,
    /// λ_max of B⁻¹K (B: the Gershgorin masses b_i; at most 2 by Gershgorin's theorem), or
    /// `None` when there was nothing to estimate and the book's masses are used.
    pub lambda_max: Option<f64>,
    /// Force evaluations the estimate took.
    pub evaluations: u64,
}

/// The fictitious mass of each second-order DOF (module comment), from the whole scene in one
/// store (the setup's, before the procCubes are cut). The scene is left as it was found.
pub fn fictitious_mass<M: Model>(sim: &mut Simulation<M>) -> FictitiousMass {
    let n2 = second_order::<M>();
    let n = sim.particles.n_owned;
    let shape = gershgorin_shape(sim);
    let mut free = sim.free_dofs();
    for (f, &b) in free.iter_mut().zip(&shape) {
        *f &= b > 0.0;
    }
    let (lambda_max, evaluations) = match crate::engine::spectrum::stiffest_mode(sim, &shape, &free)
    {
        Some((l, e)) if l.is_finite() && l > 0.0 => (Some(l), e),
        Some((_, e)) => (None, e),
        None => (None, 0),
    };
    let factor = lambda_max.map_or(0.25 * MASS_SAFETY, |l| l / TARGET_EIGENVALUE);
    let p = &sim.particles;
    let mut by_gid = vec![0.0; p.len() * n2];
    for i in 0..n {
        let g = p.gid[i] as usize;
        for k in 0..n2 {
            // A particle without bonds still needs a finite mass.
            let lambda = factor * shape[i * n2 + k];
            by_gid[g * n2 + k] = if lambda > 0.0 { lambda } else { f64::MAX };
        }
    }
    FictitiousMass {
        by_gid,
        lambda_max,
        evaluations,
    }
}

/// The Gershgorin shape of the stiffness, b_i = V_i Σ_j V_j C_ij for each second-order DOF of
/// the owned particles in store order, C_ij from [`Model::relaxation_stiffness`]: ADR's masses
/// before their scaling, and the matrix-free Newton solve's diagonal preconditioner.
pub fn gershgorin_shape<M: Model>(sim: &Simulation<M>) -> Vec<f64> {
    let n2 = second_order::<M>();
    let (model, p) = (&sim.model, &sim.particles);
    let sums =
        crate::engine::simulation::stiffness_sums_of(model, p, &sim.bonds, |law, i, j, geom| {
            model.relaxation_stiffness(law, &p.side(i), &p.side(j), geom)
        });
    let mut shape = vec![0.0; p.n_owned * n2];
    for (i, sum) in sums.iter().enumerate().take(p.n_owned) {
        for k in 0..n2 {
            shape[i * n2 + k] = p.volume[i] * sum.as_slice()[k];
        }
    }
    shape
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

/// The start of a quasi-static load step (relaxation or the implicit solve): supports to
/// their positions at the end of the step (a displacement history lands exactly; a velocity
/// moves them by v·Δt), free particles held, the clock to the step's end.
pub fn begin_load_step<M: Model>(cube: &mut Cube<M>) {
    let n = cube.sim.particles.n_owned;
    let (t0, dt) = (cube.sim.time, cube.sim.dt);
    let start = Instant::now();
    zero_velocities(&mut cube.sim.particles);
    for c in &cube.sim.constraints {
        c.set_drift_velocity(&mut cube.sim.particles, t0, dt);
    }
    let sim = &mut cube.sim;
    for a in &mut sim.particles.alter[..n] {
        sim.model.drift(a, dt);
    }
    zero_velocities(&mut cube.sim.particles);
    cube.sim.time = t0 + dt;
    cube.sim.step += 1;
    cube.sim.timing.lap(Phase::Integration, start);
}

/// Adaptive dynamic relaxation (Kilic & Madenci 2010, docs/theory.md §5) with these
/// fictitious masses; they double, for this and every later load step, when a step diverges.
pub struct Adr {
    pub mass: FictitiousMass,
    pub tolerance: f64,
    pub max_iterations: u64,
    /// Whether this worker reports a divergence (the root only).
    pub report: bool,
    mass_scale: f64,
}

impl Adr {
    pub fn new(mass: FictitiousMass, tolerance: f64, max_iterations: u64, report: bool) -> Self {
        Adr {
            mass,
            tolerance,
            max_iterations,
            report,
            mass_scale: 1.0,
        }
    }

    /// One load step of adaptive dynamic relaxation: supports and loads move to time
    /// `sim.time + sim.dt`, then the particles relax to equilibrium, with the fictitious masses
    /// times the mass scale. If the iterations diverge (the fictitious masses too light for a
    /// stiffness the estimate missed) the step starts again from where it began, bonds and
    /// history restored, with the mass scale doubled for this and every later step. Every
    /// worker must call it (the divergence test is on the reduced residual, so all decide
    /// alike).
    pub fn load_step<M: Model>(&mut self, cube: &mut Cube<M>) -> Relaxed {
        let n2 = second_order::<M>();
        let n = cube.sim.particles.n_owned;
        begin_load_step(cube);
        let start = Instant::now();
        let saved = (
            cube.sim.particles.alter[..n].to_vec(),
            cube.sim.bonds.broken.clone(),
            cube.sim.bonds.history.clone(),
        );
        cube.sim.timing.lap(Phase::Integration, start);
        let mut spent = 0;
        loop {
            let t = Instant::now();
            let lambda: Vec<f64> = (0..n)
                .flat_map(|i| {
                    let g = cube.sim.particles.gid[i] as usize;
                    self.mass.by_gid[g * n2..(g + 1) * n2]
                        .iter()
                        .map(|m| m * self.mass_scale)
                })
                .collect();
            cube.sim.timing.lap(Phase::Integration, t);
            let left = self.max_iterations.saturating_sub(spent);
            let mut r = relax(cube, &lambda, self.tolerance, left);
            spent += r.iterations;
            r.iterations = spent;
            if !r.diverged || spent >= self.max_iterations || self.mass_scale > 1e6 {
                return r;
            }
            cube.sim.particles.alter[..n].copy_from_slice(&saved.0);
            cube.sim.bonds.broken.clone_from(&saved.1);
            cube.sim.bonds.history.clone_from(&saved.2);
            self.mass_scale *= 2.0;
        }
    }
}

impl<M: Model> Solver<M> for Adr {
    fn advance(&mut self, cube: &mut Cube<M>, step: u64) -> Result<Option<Relaxed>, String> {
        let before = self.mass_scale;
        let r = self.load_step(cube);
        if self.mass_scale != before && self.report {
            eprintln!(
                "warning    relaxation diverged at step {step}: repeated with the fictitious masses ×{}{}",
                self.mass_scale,
                if r.diverged { ", and diverged again" } else { "" }
            );
        }
        Ok(Some(r))
    }
}

/// The iterations of one load step with masses `lambda` (owned DOFs in order), at most
/// `max_iterations` force evaluations; stops early when they diverge.
fn relax<M: Model>(
    cube: &mut Cube<M>,
    lambda: &[f64],
    tolerance: f64,
    max_iterations: u64,
) -> Relaxed {
    let n2 = second_order::<M>();
    let n = cube.sim.particles.n_owned;
    let mut iterations = 1;
    cube.compute_forces();
    // Forces of this and of the previous iteration, two buffers swapped: no allocation per
    // iteration.
    let mut previous: Vec<f64> = Vec::with_capacity(n * n2);
    owned_forces(cube, n2, &mut previous);
    let mut force: Vec<f64> = Vec::with_capacity(n * n2);
    // u̇^½ = F⁰ / (2λ) (pseudo time step 1).
    {
        let p = &mut cube.sim.particles;
        for i in 0..n {
            let a = p.alter[i].as_mut_slice();
            for k in 0..n2 {
                a[n2 + k] = previous[i * n2 + k] / (2.0 * lambda[i * n2 + k]);
            }
        }
    }
    let mut residual;
    let mut diverged;
    loop {
        let t = Instant::now();
        {
            let sim = &mut cube.sim;
            for a in &mut sim.particles.alter[..n] {
                sim.model.drift(a, 1.0);
            }
        }
        cube.sim.timing.lap(Phase::Integration, t);
        cube.compute_forces();
        iterations += 1;
        let t = Instant::now();
        owned_forces(cube, n2, &mut force);
        // uᵀ¹Ku, uᵀu, |F|², and the scale: applied loads and support reactions.
        let p = &cube.sim.particles;
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
        for l in &cube.sim.loads {
            all.extend_from_slice(&l.total(cube.sim.time));
        }
        for c in &cube.sim.constraints {
            all.extend_from_slice(&c.reaction);
        }
        cube.team().reduce(&mut all, Reduce::Sum);
        let scale = all[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
        residual = all[2].sqrt() / scale.max(f64::MIN_POSITIVE);
        // A crack can raise the residual to about the applied forces, never a thousand
        // times over: that is the exponential growth of an unstable pseudo time step.
        diverged = residual.is_nan() || residual > DIVERGED;
        if residual <= tolerance || iterations >= max_iterations || diverged {
            cube.sim.timing.lap(Phase::Integration, t);
            break;
        }
        let ratio = all[0] / all[1].max(f64::MIN_POSITIVE);
        let mut c = if ratio > 0.0 { 2.0 * ratio.sqrt() } else { 0.0 };
        if c > 2.0 {
            c = DAMPING_CAP;
        }
        // u̇ⁿ⁺½ = [(2 − c)u̇ⁿ⁻½ + 2Fⁿ/λ] / (2 + c).
        let p = &mut cube.sim.particles;
        for i in 0..n {
            let a = p.alter[i].as_mut_slice();
            for k in 0..n2 {
                let idx = i * n2 + k;
                a[n2 + k] = ((2.0 - c) * a[n2 + k] + 2.0 * force[idx] / lambda[idx]) / (2.0 + c);
            }
        }
        std::mem::swap(&mut previous, &mut force);
        cube.sim.timing.lap(Phase::Integration, t);
    }
    zero_velocities(&mut cube.sim.particles);
    Relaxed {
        iterations,
        residual,
        converged: residual <= tolerance,
        diverged,
    }
}

/// Forces on the second-order DOFs of owned particles (zero on supported DOFs).
fn owned_forces<M: Model>(cube: &Cube<M>, n2: usize, out: &mut Vec<f64>) {
    let p = &cube.sim.particles;
    out.clear();
    for f in &p.force[..p.n_owned] {
        out.extend_from_slice(&f.as_slice()[..n2]);
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
