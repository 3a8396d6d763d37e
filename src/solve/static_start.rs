//! The static start of an explicit run (`[time] static_until`): instead of stepping through
//! the slow, quasi-static beginning of a load history (a beam loaded through its elastic
//! range before it cracks), the run reaches `static_until` by one implicit static solve —
//! supports and loads at their values there, Newton's method to equilibrium (`solve/implicit.rs`) —
//! and steps explicitly from that state, at rest. The skipped steps would have ended near the
//! same state only if the loading were slow against the structure's periods; the static start
//! is that limit, without the vibration a dynamic ramp leaves.
//!
//! The solve runs on the whole scene in one procCube, whatever the run's layout, and is
//! handed to the run's procCubes as a restart is (an in-memory [`Checkpoint`] at step 0): the
//! same start on every layout and rank count. Under MPI every rank solves it alike.

use crate::input::setup::Setup;
use crate::model::Model;
use crate::parallel::decomposition::{cell_plans, Layout, Walls};
use crate::parallel::snapshot::Snapshot;
use crate::solve::Newton;
use std::time::Instant;

/// Residual of the static solve, relative to the applied forces and reactions (the implicit
/// solver's default).
const TOLERANCE: f64 = 1e-8;
/// Newton iterations allowed: an elastic state takes one or two.
const MAX_ITERATIONS: u64 = 20;

/// The state the explicit run starts from, and what reaching it took.
pub struct StaticStart {
    /// The state at `static_until`: step 0, time `static_until`, velocities zero.
    pub state: Snapshot,
    pub evaluations: u64,
    pub residual: f64,
    /// Bonds broken by the static solve (counted in the run's damage from the start).
    pub broken: usize,
    /// How the last tangent was factored ("Cholesky", …) and its nonzeros.
    pub method: &'static str,
    pub nonzeros: usize,
    pub seconds: f64,
}

impl StaticStart {
    /// One line for the run's header.
    pub fn describe(&self) -> String {
        format!(
            "static     start at t = {:.4e} by the implicit solve: {} force evaluations, relative residual {:.1e}, {} bonds broken, tangent {} with {} nonzeros ({:.1} s)",
            self.state.time,
            self.evaluations,
            self.residual,
            self.broken,
            self.method,
            self.nonzeros,
            self.seconds
        )
    }
}

/// Solves for the static equilibrium of `setup` under its supports and loads at time `until`.
pub fn solve<M: Model>(setup: &Setup<M>, until: f64, walls: Walls) -> Result<StaticStart, String> {
    let start = Instant::now();
    let layout = Layout::new([1, 1, 1], &setup.domain, &setup.sim.particles.x0, walls)?;
    let plans = cell_plans(&layout);
    let mut cube = crate::parallel::build_cube(
        setup,
        &layout,
        &plans,
        0,
        Box::new(crate::parallel::comm::Solo::new()),
    );
    cube.start();
    // One load step from 0 to `until`.
    cube.sim.dt = until;
    // Matrix-free where the factor would not fit (`solve/newton.rs`).
    let matrix_free = crate::solve::MatrixFree {
        diagonal: crate::solve::krylov::Diagonal::of(&setup.sim),
        max_iterations: crate::input::deck::DEFAULT_KRYLOV_ITERATIONS,
        always: false,
        coarse: true,
    };
    let mut newton = Newton::new(TOLERANCE, MAX_ITERATIONS, 0).with_matrix_free(matrix_free, false);
    let r = newton
        .load_step(&mut cube)
        .map_err(|e| format!("[time] static_until: {e} (or leave static_until out)"))?;
    if !r.converged {
        return Err(format!(
            "[time] static_until = {until:e}: the static solve did not converge (relative residual {:.2e} after {MAX_ITERATIONS} Newton iterations, {} bonds broken): the structure may not stand the loads at that time; start earlier",
            r.residual,
            cube.broken_count()
        ));
    }
    let broken = cube.broken_count();
    // No tangent when the start state is already in equilibrium (no load yet at `until`).
    let (method, nonzeros) = match newton.tangent() {
        _ if newton.is_matrix_free() => ("matrix-free", 0),
        Some(k) => (k.method, k.nonzeros),
        None => ("not needed", 0),
    };
    cube.sim.dt = setup.sim.dt;
    cube.sim.step = 0;
    cube.sim.time = until;
    let state =
        Snapshot::gather(&mut cube).ok_or("the static start's one procCube gathered no state")?;
    Ok(StaticStart {
        state,
        evaluations: r.iterations,
        residual: r.residual,
        broken,
        method,
        nonzeros,
        seconds: start.elapsed().as_secs_f64(),
    })
}
