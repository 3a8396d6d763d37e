//! Stop criteria: `[time] stop_at_broken_bonds`, and the blow-up check, which ends a run whose
//! state is no longer finite (or runs away) with an error naming the step, the particle and
//! the likely cause.

use super::{frame_due, row_due, Observer, Watch};
use crate::driver::step_loop::Plan;
use crate::engine::timing::Phase;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::output::Frames;
use crate::parallel::comm::{f64s, Reduce};
use crate::parallel::Cube;
use std::ops::ControlFlow;
use std::time::Instant;

/// `[time] stop_at_broken_bonds`: the run ends at the step where that many bonds have broken,
/// counted over every procCube (a reduction), as if it were the last.
pub(super) struct BrokenBonds {
    first: u64,
    limit: u64,
}

impl BrokenBonds {
    pub fn new(plan: &Plan) -> Self {
        BrokenBonds {
            first: plan.first_step,
            limit: plan.stop_at_broken,
        }
    }
}

impl<M: Model> Observer<M> for BrokenBonds {
    fn due(&self, step: u64, _last: bool) -> bool {
        step > self.first && self.limit > 0
    }

    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let mut n = [cube.broken_count() as f64];
        cube.team().reduce(&mut n, Reduce::Sum);
        if n[0] < self.limit as f64 {
            return Ok(ControlFlow::Continue(()));
        }
        watch.tally.stopped_at_broken = true;
        Ok(ControlFlow::Break(()))
    }
}

/// Before anything records the state (at the steps of a row or a frame): the workers agree on
/// output errors, and a run that blew up stops with a frame and a checkpoint for inspection.
pub(super) struct BlowUp<'a> {
    plan: &'a Plan,
}

impl<'a> BlowUp<'a> {
    pub fn new(plan: &'a Plan) -> Self {
        BlowUp { plan }
    }
}

impl<M: Model> Observer<M> for BlowUp<'_> {
    fn due(&self, step: u64, last: bool) -> bool {
        row_due(self.plan, step, last) || frame_due(self.plan, step, last)
    }

    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let t = Instant::now();
        watch.agree(cube)?;
        let limit = (!self.plan.solver.quasi_static()).then_some(0.5 * self.plan.spacing);
        if let Some(gid) = first_blown_up(cube, limit) {
            return Err(blow_up(cube, self.plan, watch, gid));
        }
        cube.sim.timing.lap(Phase::Output, t);
        Ok(ControlFlow::Continue(()))
    }
}

/// The smallest global id of a particle that blew up, on every worker (a reduction: all must
/// call it): coordinates or velocities not finite, or (explicit runs) a speed that carries it
/// more than half a lattice spacing per step, which a stable run of a solid never reaches
/// (about half the wave speed).
fn first_blown_up<M: Model>(cube: &mut Cube<M>, limit: Option<f64>) -> Option<u32> {
    let p = &cube.sim.particles;
    let n2 = crate::model::second_order::<M>();
    let dt = cube.sim.dt;
    let runaway = |a: &[f64]| match limit {
        Some(half_spacing) => {
            let v2 = a[n2] * a[n2] + a[n2 + 1] * a[n2 + 1] + a[n2 + 2] * a[n2 + 2];
            v2 * dt * dt > half_spacing * half_spacing
        }
        None => false,
    };
    let mine = (0..p.n_owned)
        .filter(|&i| {
            let a = p.alter[i].as_slice();
            a.iter().any(|v| !v.is_finite()) || runaway(a)
        })
        .map(|i| p.gid[i] as f64)
        .fold(f64::INFINITY, f64::min);
    let mut v = [mine];
    cube.team().reduce(&mut v, Reduce::Min);
    v[0].is_finite().then_some(v[0] as u32)
}

/// Stops a run that blew up: writes a frame and a checkpoint of the state for inspection (all
/// workers take part) and returns the message naming the step, the particle and the likely
/// cause.
fn blow_up<M: Model>(cube: &mut Cube<M>, plan: &Plan, watch: &mut Watch<M>, gid: u32) -> String {
    let step = watch.step;
    let root = cube.wall.transport().rank() == 0;
    if root && watch.frames.is_none() {
        watch.frames = Frames::new(&plan.dir).ok();
    }
    let frame = super::frames::write_frame(cube, watch, plan, 0);
    let ck = &plan.checkpoints;
    let checkpoint =
        super::checkpoints::write_checkpoint(cube, ck, ck.keep.max(1) + 1, plan.in_parts);
    // The particle's reference position and material, from its procCube.
    let p = &cube.sim.particles;
    let mine: Vec<f64> = (0..p.n_owned)
        .find(|&i| p.gid[i] == gid)
        .map(|i| vec![p.x0[i][0], p.x0[i][1], p.x0[i][2], p.material[i] as f64])
        .unwrap_or_default();
    let Some(all) = cube.team().gather(bytemuck::cast_slice(&mine)) else {
        return "another worker stopped the run: it blew up".into();
    };
    let Some(x) = all.iter().map(|b| f64s(b)).find(|v| v.len() == 4) else {
        return format!("the run blew up at step {step}: particle {gid}");
    };
    let files: Vec<String> = [frame, checkpoint.and_then(|c| c.ok()).map(|c| c.0)]
        .into_iter()
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    let material = plan
        .material_names
        .get(x[3] as usize)
        .map_or("?", |s| s.as_str());
    format!(
        "the run blew up at step {step}: particle {gid} (material '{material}', reference position [{:.6e}, {:.6e}, {:.6e}]) has a position or velocity that is not finite, or moves more than half a lattice spacing per step. Likely cause: {}. For inspection: {}",
        x[0],
        x[1],
        x[2],
        likely_cause(plan, cube.sim.dt),
        if files.is_empty() {
            "no file could be written".to_string()
        } else {
            files.join(", ")
        }
    )
}

/// What most likely made a run blow up: relaxation diverging, or the time step against the
/// stable one.
fn likely_cause(plan: &Plan, dt: f64) -> String {
    let ratio = dt / plan.dt_critical;
    if plan.solver.quasi_static() {
        "relaxation diverged: check the loads, supports and materials".to_string()
    } else if ratio > 1.0 {
        format!(
            "the time step is {ratio:.2} × the {} ({dt:.4e} against {:.4e}): lower dt or drop force_dt",
            plan.dt_critical_name, plan.dt_critical
        )
    } else {
        format!(
            "the time step is within the {} ({ratio:.2} × {:.4e}): check the material's stiffness and density, and the loads and prescribed velocities",
            plan.dt_critical_name, plan.dt_critical
        )
    }
}
