//! The matrix-free linear solve of Newton's method (Newton–Krylov): K δ = F by preconditioned
//! conjugate gradients, with the tangent never assembled. Each product K·v is one force
//! evaluation of the engine, a forward difference along v:
//!
//!   K·v ≈ −[F(u + h v) − F(u)] / h,
//!
//! so it holds for every model alike (bond-based, state-based, micropolar through the model's
//! `drift`, as the assembled tangent's columns), and it runs on every procCube of the layout as
//! an explicit step does: each procCube moves its own particles, the force evaluation exchanges
//! the ghosts, and the dot products are reduced over procCubes in rank order (the same layout
//! gives the same bits). The memory is a few vectors of the free DOFs, where the factored
//! tangent of a 20,787-particle micropolar beam took 14.5 GB.
//!
//! The preconditioner has two levels. The first is diagonal: the Gershgorin shape
//! b_i = V_i Σ_j V_j C_ij that ADR's fictitious masses are made of
//! ([`crate::solve::adr::gershgorin_shape`]), computed once on the whole scene before it is cut
//! into procCubes. It puts translations and rotations, surface and interior particles on one
//! scale, but alone it leaves CG's iterations growing with the beam's slenderness (about √κ
//! of a bending problem). The second, where the deck keeps it (`[solver] preconditioner`),
//! solves exactly for the rigid motions of groups of particles ([`crate::solve::coarse`]),
//! which is where a beam's bending lives.
//!
//! The step h makes the largest move of any DOF [`DIFFERENCE_STEP`] of the shortest bond
//! (radians for rotations): the truncation error of the difference is then about 1e-7 of the
//! product and its round-off far smaller. A product that is that inexact only slows Newton's
//! convergence, never moves its solution: the residual Newton tests is the force itself.
//! Bonds and their history are restored after each product, so a bond that a probe
//! stretches past its limit does not break; the probe is a derivative, not a move. A probe
//! that breaks a bond all the same (one within h of its limit: a crack's front has many) is
//! made again with a shorter step, as the lost force would read as a huge negative stiffness.

use crate::engine::simulation::Simulation;
use crate::engine::timing::Phase;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use crate::solve::coarse::Coarse;
use std::time::Instant;

/// The largest move of a DOF in a difference product, relative to the shortest bond (lengths)
/// or in radians (rotations).
const DIFFERENCE_STEP: f64 = 1e-7;
/// A product whose probe broke a bond is made again with the step shortened by this, at most
/// [`SHRINKS`] times (down to 1e-7 · 8⁻⁶ ≈ 4e-13 of the shortest bond, where the difference's
/// round-off is still about 1e-8 of the product at the stretches of concrete).
const SHRINK: f64 = 0.125;
const SHRINKS: u32 = 6;

/// The diagonal preconditioner of the matrix-free solve, by global id (`second_order::<M>()`
/// values per particle).
#[derive(Clone, Debug)]
pub struct Diagonal {
    pub by_gid: Vec<f64>,
}

impl Diagonal {
    /// The Gershgorin shape of the whole scene's stiffness (one store, before the procCubes are
    /// cut: every layout and a restart get the same preconditioner).
    pub fn of<M: Model>(sim: &Simulation<M>) -> Self {
        let n2 = second_order::<M>();
        let shape = crate::solve::adr::gershgorin_shape(sim);
        let p = &sim.particles;
        let mut by_gid = vec![0.0; p.len() * n2];
        for i in 0..p.n_owned {
            let g = p.gid[i] as usize;
            for k in 0..n2 {
                by_gid[g * n2 + k] = shape[i * n2 + k];
            }
        }
        Diagonal { by_gid }
    }

    /// 1 / b for the owned DOFs of `cube` in store order; 0 for supported DOFs and for DOFs
    /// without stiffness (a particle without bonds), which CG then leaves alone.
    fn inverse<M: Model>(&self, cube: &Cube<M>, free: &[bool]) -> Vec<f64> {
        let n2 = second_order::<M>();
        let p = &cube.sim.particles;
        let mut inv = vec![0.0; p.n_owned * n2];
        for i in 0..p.n_owned {
            let g = p.gid[i] as usize;
            for k in 0..n2 {
                let b = self.by_gid[g * n2 + k];
                if free[i * n2 + k] && b > 0.0 && b.is_finite() {
                    inv[i * n2 + k] = 1.0 / b;
                }
            }
        }
        inv
    }
}

/// How one linear solve went.
#[derive(Clone, Copy, Debug, Default)]
pub struct Solved {
    /// CG iterations, one force evaluation each.
    pub iterations: u64,
    /// |F − K δ| at the end, in the units of the force.
    pub residual: f64,
    pub converged: bool,
    /// Force evaluations that measured the coarse level's matrix (0: kept or none).
    pub coarse_evaluations: u64,
    /// CG met a direction of zero or negative curvature (a tangent that is not positive
    /// definite: a softening crack, a mechanism) and stopped there.
    pub indefinite: bool,
}

/// CG's preconditioner: the diagonal and the coarse level, if the solve keeps one. With
/// `rebuild` (the start of a load step) the coarse level is measured anew at the current state
/// into `coarse`; otherwise it is used as it is.
pub struct Preconditioner<'a> {
    pub diagonal: &'a Diagonal,
    pub coarse: &'a mut Option<Coarse>,
    pub rebuild: bool,
}

/// The state a difference product starts from and returns to.
pub(super) struct Base<M: Model> {
    alter: Vec<M::Alter>,
    broken: Vec<bool>,
    history: Vec<M::Bond>,
    /// F(u) on the owned DOFs.
    force: Vec<f64>,
    /// Largest DOF moves measured against: the shortest bond (reduced over procCubes) for the
    /// translations, 1 rad for the rotations.
    reference: [f64; 2],
}

impl<M: Model> Base<M> {
    fn new(cube: &mut Cube<M>, force: &[f64]) -> Self {
        let n = cube.sim.particles.n_owned;
        let mut shortest = [cube
            .sim
            .bonds
            .geom
            .iter()
            .fold(f64::INFINITY, |m, g| m.min(g.length))];
        cube.team().reduce(&mut shortest, Reduce::Min);
        Base {
            alter: cube.sim.particles.alter[..n].to_vec(),
            broken: cube.sim.bonds.broken.clone(),
            history: cube.sim.bonds.history.clone(),
            force: force.to_vec(),
            reference: [shortest[0], 1.0],
        }
    }

    /// The particles, bonds and history as they were.
    fn restore(&self, cube: &mut Cube<M>) {
        let n = self.alter.len();
        cube.sim.particles.alter[..n].copy_from_slice(&self.alter);
        cube.sim.bonds.broken.clone_from(&self.broken);
        cube.sim.bonds.history.clone_from(&self.history);
    }
}

/// Sums over the owned DOFs of every procCube (rank order).
fn dots(cube: &mut Cube<impl Model>, pairs: &[(&[f64], &[f64])]) -> Vec<f64> {
    let mut sums: Vec<f64> = pairs
        .iter()
        .map(|(a, b)| a.iter().zip(*b).map(|(x, y)| x * y).sum())
        .collect();
    cube.team().reduce(&mut sums, Reduce::Sum);
    sums
}

/// `out` = K·v on the owned DOFs by one forward difference of the force (module comment);
/// zero on supported DOFs. The scene is left as `base` holds it.
pub(super) fn tangent_times<M: Model>(
    cube: &mut Cube<M>,
    base: &Base<M>,
    v: &[f64],
    free: &[bool],
    out: &mut [f64],
) {
    let n2 = second_order::<M>();
    let n = base.alter.len();
    let mut largest = [0.0f64];
    for (idx, x) in v.iter().enumerate() {
        let r = base.reference[usize::from(idx % n2 >= 3)];
        largest[0] = largest[0].max(x.abs() / r);
    }
    cube.team().reduce(&mut largest, Reduce::Max);
    if largest[0] == 0.0 {
        out.fill(0.0);
        return;
    }
    let mut h = DIFFERENCE_STEP / largest[0];
    for shrunk in 0.. {
        let sim = &mut cube.sim;
        for i in 0..n {
            let a = sim.particles.alter[i].as_mut_slice();
            for k in 0..n2 {
                a[n2 + k] = h * v[i * n2 + k];
            }
            sim.model.drift(&mut sim.particles.alter[i], 1.0);
            sim.particles.alter[i].as_mut_slice()[n2..2 * n2].fill(0.0);
        }
        let mut broke = [cube.compute_forces() as f64];
        cube.team().reduce(&mut broke, Reduce::Max);
        if broke[0] == 0.0 || shrunk == SHRINKS {
            break;
        }
        // A bond within h of its limit broke under the probe: its force, gone, would enter
        // the product as a stiffness of −F/h, a huge negative curvature that stops CG. A
        // shorter step leaves it whole.
        base.restore(cube);
        h *= SHRINK;
    }
    let p = &cube.sim.particles;
    for (i, f) in p.force[..n].iter().enumerate() {
        for (k, &f) in f.as_slice()[..n2].iter().enumerate() {
            let idx = i * n2 + k;
            out[idx] = if free[idx] {
                -(f - base.force[idx]) / h
            } else {
                0.0
            };
        }
    }
    base.restore(cube);
}

/// Solves K δ = `force` over the free DOFs of every procCube by preconditioned conjugate
/// gradients, from δ = 0, until |F − K δ| ≤ `target` or `max_iterations`. `force` is F(u) of
/// the current state on the owned DOFs (zero on supported ones); the state is left as found,
/// its forces those of the last product (the caller evaluates them again after its update).
/// Every procCube must call it alike.
pub fn solve<M: Model>(
    cube: &mut Cube<M>,
    precondition: Preconditioner<'_>,
    force: &[f64],
    target: f64,
    max_iterations: u64,
) -> (Vec<f64>, Solved) {
    let t = Instant::now();
    let free = cube.sim.free_dofs();
    let inverse = precondition.diagonal.inverse(cube, &free);
    let base = Base::new(cube, force);
    let mut solved = Solved::default();
    if precondition.rebuild {
        cube.sim.timing.lap(Phase::Integration, t);
        *precondition.coarse = Coarse::build(cube, &base, &free);
        solved.coarse_evaluations = precondition.coarse.as_ref().map_or(0, |c| c.evaluations);
    }
    let t = Instant::now();
    let coarse = precondition.coarse.as_ref();
    let len = force.len();
    let mut x = vec![0.0; len];
    let mut r: Vec<f64> = force
        .iter()
        .zip(&free)
        .map(|(&f, &ok)| if ok { f } else { 0.0 })
        .collect();
    let mut z: Vec<f64> = r.iter().zip(&inverse).map(|(a, b)| a * b).collect();
    if let Some(c) = coarse {
        c.correct(cube, &free, &r, &mut z);
    }
    let mut p = z.clone();
    let mut q = vec![0.0; len];
    let sums = dots(cube, &[(&r, &z), (&r, &r)]);
    let (mut rz, mut rr) = (sums[0], sums[1]);
    cube.sim.timing.lap(Phase::Integration, t);
    while rr.sqrt() > target && solved.iterations < max_iterations {
        tangent_times(cube, &base, &p, &free, &mut q);
        solved.iterations += 1;
        let t = Instant::now();
        let pq = dots(cube, &[(&p, &q)])[0];
        if pq.is_nan() || pq <= 0.0 {
            solved.indefinite = true;
            cube.sim.timing.lap(Phase::Integration, t);
            break;
        }
        let alpha = rz / pq;
        for idx in 0..len {
            x[idx] += alpha * p[idx];
            r[idx] -= alpha * q[idx];
            z[idx] = r[idx] * inverse[idx];
        }
        if let Some(c) = coarse {
            c.correct(cube, &free, &r, &mut z);
        }
        let sums = dots(cube, &[(&r, &z), (&r, &r)]);
        let beta = sums[0] / rz;
        (rz, rr) = (sums[0], sums[1]);
        for idx in 0..len {
            p[idx] = z[idx] + beta * p[idx];
        }
        cube.sim.timing.lap(Phase::Integration, t);
    }
    solved.residual = rr.sqrt();
    solved.converged = solved.residual <= target;
    (x, solved)
}
