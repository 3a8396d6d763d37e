//! Newton's method on the equilibrium equations, one load step at a time: supports and loads
//! move to the step's end, then iterations δ = K⁻¹F, u += δ (through the model's `drift`, so
//! rotations compose) until the residual force is below the tolerance × (applied forces and
//! reactions), as relaxation measures it. Loads are dead loads; supported DOFs are held.
//!
//! Two ways to solve K δ = F:
//! - the factored tangent (`solve/implicit.rs`), kept between iterations and load steps while
//!   the iterations at least halve the residual and rebuilt when they do not (modified
//!   Newton: a few broken bonds leave it usable); one procCube, and memory for the factor;
//! - matrix-free conjugate gradients (`solve/krylov.rs`, Newton–Krylov), on any layout, in the
//!   memory of a few vectors. Each Newton iteration solves only as far as it needs
//!   (|F − Kδ| ≤ [`FORCING`] |F|, an inexact Newton method, and no further than half the
//!   tolerance asks), with the tangent of the current state.
//!
//! `[solver] kind = "implicit"` factors where it can and turns matrix-free where it cannot (the
//! factor would not fit in memory, or the layout has several procCubes);
//! `kind = "newton_krylov"` is matrix-free always.

use crate::engine::timing::Phase;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use crate::solve::adr::{begin_load_step, zero_velocities, Relaxed};
use crate::solve::coarse::Coarse;
use crate::solve::implicit::{assemble_tangent, NoTangent, Tangent};
use crate::solve::krylov::{self, Diagonal, Preconditioner};
use crate::solve::Solver;
use std::time::Instant;

/// The inexact Newton method's forcing term: each matrix-free solve reduces the residual of
/// its linear system to this fraction of the force. A tighter solve would not pay (the
/// difference products' own error is about 1e-7); a looser one costs Newton iterations.
const FORCING: f64 = 1e-6;

/// How Newton solves for its steps.
#[derive(Clone, Debug)]
pub struct MatrixFree {
    /// The preconditioner (the whole scene's, by global id).
    pub diagonal: Diagonal,
    /// CG iterations per Newton iteration.
    pub max_iterations: u64,
    /// Matrix-free from the start (`"newton_krylov"`), not only where the factor cannot serve.
    pub always: bool,
    /// Whether CG's preconditioner has the coarse level of rigid group motions
    /// (`[solver] preconditioner = "two_level"`, the default) or the diagonal alone.
    pub coarse: bool,
}

/// Newton's method (module comment).
pub struct Newton {
    pub tolerance: f64,
    pub max_iterations: u64,
    /// `[time] stop_at_broken_bonds` (0 = off): the iterations end there.
    pub stop_at_broken: u64,
    /// The matrix-free solve, if the run has its preconditioner.
    matrix_free: Option<MatrixFree>,
    /// Whether the steps are solved matrix-free now.
    krylov: bool,
    /// Whether this worker says when the solve turns matrix-free (the root only).
    report: bool,
    tangent: Option<Tangent>,
    /// The coarse level of the matrix-free solve's preconditioner, measured at the start of
    /// each load step.
    coarse: Option<Coarse>,
    /// CG iterations of every load step so far.
    pub krylov_iterations: u64,
}

impl Newton {
    /// Newton with the factored tangent only.
    pub fn new(tolerance: f64, max_iterations: u64, stop_at_broken: u64) -> Self {
        Newton {
            tolerance,
            max_iterations,
            stop_at_broken,
            matrix_free: None,
            krylov: false,
            report: false,
            tangent: None,
            coarse: None,
            krylov_iterations: 0,
        }
    }

    /// Newton that can solve matrix-free (always, or where the factor cannot serve).
    pub fn with_matrix_free(mut self, matrix_free: MatrixFree, report: bool) -> Self {
        self.krylov = matrix_free.always;
        self.matrix_free = Some(matrix_free);
        self.report = report;
        self
    }

    /// The tangent the last load step factored, if it needed one.
    pub fn tangent(&self) -> Option<&Tangent> {
        self.tangent.as_ref()
    }

    /// Whether the steps are solved matrix-free.
    pub fn is_matrix_free(&self) -> bool {
        self.krylov
    }

    /// Turns matrix-free for this and every later step, if it can, saying why.
    fn turn_matrix_free(&mut self, why: String) -> Result<(), String> {
        if self.matrix_free.is_none() {
            return Err(why);
        }
        if self.report {
            eprintln!("implicit   {why}: solving matrix-free (Newton–Krylov) from here on");
        }
        self.krylov = true;
        self.tangent = None;
        Ok(())
    }

    /// One load step (module comment). With `stop_at_broken` > 0 the iterations end,
    /// unconverged, once that many bonds have broken: the run ends there
    /// (`[time] stop_at_broken_bonds`), so a new tangent would be wasted.
    pub fn load_step<M: Model>(&mut self, cube: &mut Cube<M>) -> Result<Relaxed, String> {
        if !self.krylov && cube.wall.transport().size() > 1 {
            let cubes = cube.wall.transport().size();
            self.turn_matrix_free(format!(
                "the factored tangent is assembled on one procCube, the layout has {cubes}"
            ))?;
        }
        begin_load_step(cube);
        let mut evaluations = 0u64;
        let mut newton = 0u64;
        let mut previous = f64::INFINITY;
        let mut force = Vec::new();
        let residual = loop {
            cube.compute_forces();
            evaluations += 1;
            let (norm, scale) = residual_force(cube, &mut force);
            let residual = norm / scale.max(f64::MIN_POSITIVE);
            if residual <= self.tolerance
                || newton >= self.max_iterations
                || (self.stop_at_broken > 0 && broken_bonds(cube) >= self.stop_at_broken)
            {
                break residual;
            }
            let last = std::mem::replace(&mut previous, residual);
            let step = if self.krylov {
                let target = (FORCING * norm).max(0.5 * self.tolerance * scale);
                let Some((step, spent)) = self.krylov_step(cube, &force, target, newton == 0)
                else {
                    break residual;
                };
                evaluations += spent;
                step
            } else {
                // Rebuilt when the last iteration did not halve the residual: the tangent of
                // an earlier state no longer serves, as when many bonds have broken or the
                // structure's rotations grow (geometric stiffness). A few broken bonds leave
                // it good enough: the stale tangent is stiffer than the true one, so the
                // iterations still converge, and rebuilding at every break made a cracking run
                // spend nearly all its time assembling.
                let slow = newton > 0 && residual > 0.5 * last;
                if slow || self.tangent.is_none() {
                    match assemble_tangent(cube) {
                        Ok(k) => {
                            evaluations += k.evaluations;
                            self.tangent = Some(k);
                        }
                        Err(NoTangent::WouldNotFit(why)) => {
                            self.turn_matrix_free(why)?;
                            previous = f64::INFINITY;
                            continue;
                        }
                        Err(NoTangent::Failed(e)) => return Err(e),
                    }
                }
                let t = Instant::now();
                let step = self
                    .tangent
                    .as_ref()
                    .expect("assembled above")
                    .solve(&force);
                cube.sim.timing.lap(Phase::Integration, t);
                step
            };
            apply_step(cube, &step);
            newton += 1;
        };
        Ok(Relaxed {
            iterations: evaluations,
            residual,
            converged: residual <= self.tolerance,
            diverged: false,
        })
    }

    /// The matrix-free step and the force evaluations it took; `None` when CG made no
    /// progress at all (a tangent with negative curvature along the preconditioned force).
    /// The coarse level is measured at the first iteration of a load step (`first`): a
    /// function of the step's starting state alone, so a resumed run measures what the
    /// uninterrupted one did.
    fn krylov_step<M: Model>(
        &mut self,
        cube: &mut Cube<M>,
        force: &[f64],
        target: f64,
        first: bool,
    ) -> Option<(Vec<f64>, u64)> {
        let mf = self
            .matrix_free
            .as_ref()
            .expect("matrix-free with a preconditioner");
        let precondition = Preconditioner {
            diagonal: &mf.diagonal,
            coarse: &mut self.coarse,
            rebuild: mf.coarse && first,
        };
        let (step, solved) = krylov::solve(cube, precondition, force, target, mf.max_iterations);
        self.krylov_iterations += solved.iterations;
        if solved.indefinite && self.report {
            eprintln!(
                "warning    Newton–Krylov: the tangent is not positive definite (a softening crack or a mechanism); conjugate gradients stopped after {} iterations",
                solved.iterations
            );
        }
        // Whether any procCube moves: every one must take the same branch.
        let mut moves = [f64::from(u8::from(step.iter().any(|&d| d != 0.0)))];
        cube.team().reduce(&mut moves, Reduce::Max);
        (solved.iterations > 0 && moves[0] > 0.0)
            .then_some((step, solved.iterations + solved.coarse_evaluations))
    }
}

/// The force on the owned second-order DOFs into `force` (zero at supported ones), and |F| and
/// the scale it is measured against (applied forces and reactions), both over every procCube.
fn residual_force<M: Model>(cube: &mut Cube<M>, force: &mut Vec<f64>) -> (f64, f64) {
    let t = Instant::now();
    let n2 = second_order::<M>();
    let n = cube.sim.particles.n_owned;
    force.clear();
    for f in &cube.sim.particles.force[..n] {
        force.extend_from_slice(&f.as_slice()[..n2]);
    }
    let mut sums = vec![force.iter().map(|v| v * v).sum::<f64>()];
    for l in &cube.sim.loads {
        sums.extend_from_slice(&l.total(cube.sim.time));
    }
    for c in &cube.sim.constraints {
        sums.extend_from_slice(&c.reaction);
    }
    cube.team().reduce(&mut sums, Reduce::Sum);
    let scale = sums[1..].iter().map(|x| x * x).sum::<f64>().sqrt();
    cube.sim.timing.lap(Phase::Integration, t);
    (sums[0].sqrt(), scale)
}

/// The bonds broken on every procCube (as `[time] stop_at_broken_bonds` counts them), so that
/// every one stops at the same iteration.
fn broken_bonds<M: Model>(cube: &mut Cube<M>) -> u64 {
    let mut n = [cube.broken_count() as f64];
    cube.team().reduce(&mut n, Reduce::Sum);
    n[0] as u64
}

/// u += δ on the owned particles, through the model's drift (rotations compose).
fn apply_step<M: Model>(cube: &mut Cube<M>, step: &[f64]) {
    let t = Instant::now();
    let n2 = second_order::<M>();
    let sim = &mut cube.sim;
    for i in 0..sim.particles.n_owned {
        let a = sim.particles.alter[i].as_mut_slice();
        a[n2..2 * n2].copy_from_slice(&step[i * n2..(i + 1) * n2]);
        sim.model.drift(&mut sim.particles.alter[i], 1.0);
    }
    zero_velocities(&mut sim.particles);
    sim.timing.lap(Phase::Integration, t);
}

impl<M: Model> Solver<M> for Newton {
    fn advance(&mut self, cube: &mut Cube<M>, _step: u64) -> Result<Option<Relaxed>, String> {
        self.load_step(cube).map(Some).map_err(|e| {
            format!("{e} (or use [solver] kind = \"adr\", which assembles no tangent)")
        })
    }
}
