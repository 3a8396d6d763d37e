//! The frames: the whole scene gathered on the root, written as HDF5 with its XDMF index.

use super::{frame_due, Observer, Watch};
use crate::driver::step_loop::Plan;
use crate::engine::timing::Phase;
use crate::model::Model;
use crate::output::Frames;
use crate::parallel::Cube;
use std::ops::ControlFlow;
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
        watch.gather(cube);
        // The broken bonds of the last history row.
        let broken = watch.tally.broken;
        if let (Some(f), Some(s)) = (watch.frames.as_mut(), watch.store.as_ref()) {
            if let Err(e) = f.write(watch.step, cube.sim.time, &s.particles, &s.damage, broken) {
                watch.error = Some(self.plan.io(e));
            }
        }
        cube.sim.timing.lap(Phase::Output, t);
        Ok(ControlFlow::Continue(()))
    }
}
