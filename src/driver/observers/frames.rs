//! The frames, written as HDF5 with their XDMF index: in parts (each procCube its own file,
//! the root the index), from the one procCube, or gathered on the root.

use super::{frame_due, Observer, Watch};
use crate::driver::step_loop::Plan;
use crate::engine::timing::Phase;
use crate::model::Model;
use crate::output::Frames;
use crate::parallel::comm::f64s;
use crate::parallel::Cube;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

/// The root's frame series: new, or reopened at the step a restart resumes from.
pub(super) fn open(plan: &Plan) -> Result<Frames, String> {
    if plan.first_step > 0 {
        Frames::resume(&plan.dir, plan.first_step, plan.frames_every)
    } else {
        Frames::new(&plan.dir).map_err(|e| plan.io(e))
    }
}

/// A frame every `frames_every` steps and at the last; the series itself is the
/// [`Watch`]'s, which the blow-up check adds its frame to.
pub(super) struct FrameSeries<'a> {
    plan: &'a Plan,
}

impl<'a> FrameSeries<'a> {
    pub fn new(plan: &'a Plan) -> Self {
        FrameSeries { plan }
    }
}

impl<M: Model> Observer<M> for FrameSeries<'_> {
    fn due(&self, step: u64, last: bool) -> bool {
        frame_due(self.plan, step, last)
    }

    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let t = Instant::now();
        // The broken bonds of the last history row.
        let broken = watch.tally.broken;
        write_frame(cube, watch, self.plan, broken);
        cube.sim.timing.lap(Phase::Output, t);
        Ok(ControlFlow::Continue(()))
    }
}

/// Writes the frame of this step (a collective): in parts, from the one procCube, or gathered
/// on the root. The root gets the file (or the parts' directory); an error goes to
/// [`Watch::error`] on the worker that met it.
pub(super) fn write_frame<M: Model>(
    cube: &mut Cube<M>,
    watch: &mut Watch<M>,
    plan: &Plan,
    broken: usize,
) -> Option<PathBuf> {
    let (step, time) = (watch.step, cube.sim.time);
    let (rank, workers) = (cube.wall.transport().rank(), cube.wall.transport().size());
    if !plan.in_parts && workers > 1 {
        watch.gather(cube);
        let (f, s) = (watch.frames.as_mut()?, watch.store.as_ref()?);
        return f
            .write(step, time, &s.particles, &s.damage, broken)
            .map_err(|e| watch.error = Some(plan.io(e)))
            .ok();
    }
    let damage = watch.damage.get_or_insert_with(|| cube.damage());
    let p = &cube.sim.particles;
    if !plan.in_parts {
        return match watch.frames.as_mut()?.write(step, time, p, damage, broken) {
            Ok(path) => Some(path),
            Err(e) => {
                watch.error = Some(plan.io(e));
                None
            }
        };
    }
    let part = Frames::write_part(&plan.dir, step, time, (rank, workers), p, (damage, broken));
    let n = match &part {
        Ok(_) => p.n_owned as f64,
        Err(e) => {
            watch.error = Some(plan.io(std::io::Error::new(e.kind(), e.to_string())));
            -1.0
        }
    };
    let counts = cube.team().gather(bytemuck::cast_slice(&[n]))?;
    let counts: Vec<f64> = counts.iter().flat_map(|b| f64s(b)).collect();
    let (Ok((_, arrays)), Some(frames)) = (part, watch.frames.as_mut()) else {
        return None;
    };
    if let Some(k) = counts.iter().position(|&c| c < 0.0) {
        watch.error = Some(format!(
            "part {k} of the frame at step {step} could not be written (its rank says why)"
        ));
        return None;
    }
    let counts = counts.iter().map(|&c| c as usize).collect();
    match frames.list_parts(step, time, counts, arrays) {
        Ok(()) => Some(plan.dir.join(format!("frames/frame_{step:08}"))),
        Err(e) => {
            watch.error = Some(plan.io(e));
            None
        }
    }
}
