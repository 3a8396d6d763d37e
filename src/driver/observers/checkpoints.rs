//! Checkpoints by step count, by wall time, at the end, and on a signal (SIGTERM or Ctrl-C
//! writes one and ends the run).

use super::{Observer, Watch};
use crate::driver::step_loop::{CheckpointPlan, Plan};
use crate::engine::timing::Phase;
use crate::model::Model;
use crate::output::checkpoint::Checkpoint;
use crate::output::checkpoint_parts::{self, PartRecord};
use crate::parallel::comm::Reduce;
use crate::parallel::snapshot::Snapshot;
use crate::parallel::Cube;
use std::ops::ControlFlow;
use std::time::Instant;

impl CheckpointPlan {
    fn enabled(&self) -> bool {
        self.every > 0 || self.minutes > 0.0
    }
}

/// Whether to stop on a signal and whether the wall clock calls for a checkpoint, agreed by
/// all workers (each sees its own signal flag and clock; all must act at the same step).
fn agree_on_stop<M: Model>(cube: &mut Cube<M>, stop: bool, clock_due: bool) -> (bool, bool) {
    let mut v = [stop as u8 as f64, clock_due as u8 as f64];
    cube.team().reduce(&mut v, Reduce::Max);
    (v[0] > 0.0, v[1] > 0.0)
}

/// Looks at every step after the first: whether a checkpoint is due depends on the wall clock
/// and the signals, which each worker sees alone, so the decision is a reduction inside
/// `observe`.
pub(super) struct Checkpoints<'a> {
    plan: &'a CheckpointPlan,
    first: u64,
    /// When the last checkpoint was written (or the run started).
    written: Instant,
    workers: usize,
    in_parts: bool,
}

impl<'a> Checkpoints<'a> {
    pub fn new(plan: &'a Plan, workers: usize) -> Self {
        Checkpoints {
            plan: &plan.checkpoints,
            first: plan.first_step,
            written: Instant::now(),
            workers,
            in_parts: plan.in_parts,
        }
    }
}

/// Writes a checkpoint of this step (a collective), keeping the newest `keep`: in parts (each
/// procCube its own, then the root the index) or gathered on the root. The root gets the path
/// and the bytes written; an error goes to the worker that met it, and to the root.
pub(super) fn write_checkpoint<M: Model>(
    cube: &mut Cube<M>,
    ck: &CheckpointPlan,
    keep: usize,
    in_parts: bool,
) -> Option<Result<(std::path::PathBuf, u64), String>> {
    let failed = |e: std::io::Error| format!("writing checkpoint in {}: {e}", ck.dir.display());
    if !in_parts {
        let c = Checkpoint::gather(cube, ck.scene_hash, &ck.deck)?;
        return Some(c.write(&ck.dir, keep).map_err(failed));
    }
    let c = Checkpoint {
        state: Snapshot::local(cube),
        particles: cube.global_particles,
        scene_hash: ck.scene_hash,
        deck: ck.deck.clone(),
    };
    let rank = cube.wall.transport().rank();
    let part = checkpoint_parts::write_part(&ck.dir, &c, rank);
    let mine = part.as_ref().map(|p| p.to_bytes()).unwrap_or_default();
    let records = cube.team().gather(&mine);
    let Some(records) = records else {
        return part.err().map(|e| Err(failed(e)));
    };
    let records: Vec<Option<PartRecord>> =
        records.iter().map(|b| PartRecord::from_bytes(b)).collect();
    if let Some(k) = records.iter().position(|r| r.is_none()) {
        let why = part.err().map_or(String::new(), |e| format!(": {e}"));
        return Some(Err(format!(
            "writing checkpoint in {}: part {k} was not written (its rank says why){why}",
            ck.dir.display()
        )));
    }
    let records: Vec<PartRecord> = records.into_iter().flatten().collect();
    Some(checkpoint_parts::write_index(&ck.dir, &c, &records, keep).map_err(failed))
}

impl<M: Model> Observer<M> for Checkpoints<'_> {
    fn due(&self, step: u64, _last: bool) -> bool {
        step > self.first
    }

    /// Writes a checkpoint when one is due; a signal stops the run here.
    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let ck = self.plan;
        let (step, last) = (watch.step, watch.last);
        // All workers must act on a signal at the same step, so they agree on it: at every
        // step on one procCube (free), every 10 steps on several (a reduction costs a few
        // microseconds, 1-2 % of a small scene's step).
        let (stop, clock_due) = if self.workers == 1 || step.is_multiple_of(10) || last {
            let clock_due =
                ck.minutes > 0.0 && self.written.elapsed().as_secs_f64() >= 60.0 * ck.minutes;
            agree_on_stop(cube, crate::output::signals::requested(), clock_due)
        } else {
            (false, false)
        };
        let due = stop
            || clock_due
            || (ck.every > 0 && step.is_multiple_of(ck.every))
            || (ck.enabled() && last);
        if due {
            let t = Instant::now();
            match write_checkpoint(cube, ck, ck.keep, self.in_parts) {
                Some(Ok((path, size))) => {
                    watch
                        .tally
                        .checkpoints
                        .push((path, size, t.elapsed().as_secs_f64()))
                }
                Some(Err(e)) => watch.error = Some(e),
                None => {}
            }
            self.written = Instant::now();
            cube.sim.timing.lap(Phase::Output, t);
        }
        if !stop {
            return Ok(ControlFlow::Continue(()));
        }
        watch.agree(cube)?;
        let tally = &mut watch.tally;
        tally.interrupted = Some(
            tally
                .checkpoints
                .last()
                .map(|c| c.0.clone())
                .unwrap_or_else(|| ck.dir.clone()),
        );
        Ok(ControlFlow::Break(()))
    }
}
