//! What watches a run: the history rows (with the probes' stops), the frames, the checkpoints
//! (with the signals), the progress line, the stop criteria and the in-situ analyses
//! (`[[analysis]]`: voids and cracks) are [`Observer`]s of the step loop (`step_loop::drive`),
//! called in the order of [`observers`] after every step. Another watcher plugs in the same
//! way: an observer of its own (copy `history.rs`), added to that list.

pub(crate) mod analysis;
mod checkpoints;
mod frames;
mod history;
mod stops;

pub(crate) use history::peak_stop;

use super::record::{gather_frame, FrameStore};
use super::step_loop::{Plan, Tally};
use crate::model::Model;
use crate::output::{Frames, Progress};
use crate::parallel::Cube;
use std::ops::ControlFlow;

/// Something that watches the run from the step loop: an output, an analysis or a stop
/// criterion.
///
/// The loop is SPMD: every worker (a thread or an MPI rank) runs it on its own procCube and
/// calls the same observers, in the same order, at the same steps. That is what lets an
/// observer use collectives (a reduction over procCubes, a gather on the root, the ghost
/// exchange behind `Cube::damage`): the other workers reach the same call. An observer keeps
/// it so:
/// - `due` decides from the step, whether it is the last, and what the observer was built with
///   from the plan: the same on every worker. What a worker sees alone (its wall clock, a
///   signal) becomes a decision inside `observe`, through a reduction, as the checkpoints do.
/// - `observe` stops the run (`Break`) or fails (`Err`) on every worker alike, decided on
///   reduced values. An error only this worker sees (writing a file on the root) goes to
///   [`Watch::error`] instead; the workers agree on it ([`Watch::agree`]) at the next output
///   step and at the end, so none is left waiting in a collective.
/// - It watches: particles, bonds and forces are left as they were, so a run's results do not
///   depend on what watches it.
pub(crate) trait Observer<M: Model> {
    /// Whether it observes at `step`; `last`: the run ends after this step.
    fn due(&self, step: u64, last: bool) -> bool;
    /// Looks at the procCube at a step it is due. `Break` ends the run after this step, and
    /// the observers after this one see the step as the last.
    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String>;
    /// After the last step, on every worker, in the list's order.
    fn finish(&mut self, _cube: &mut Cube<M>, _watch: &mut Watch<M>) {}
}

/// What the observers of one worker share: the step, what the run has counted, an output
/// error, and what several of them look at (the damage, the scene gathered on the
/// root), computed once per step by whoever asks first. Every worker asks at the same point,
/// as the observers run in the same order everywhere.
pub(crate) struct Watch<M: Model> {
    pub step: u64,
    /// The run ends after this step: the deck's last step, or an observer stopped it.
    pub last: bool,
    /// What the run counted, for the summary.
    pub tally: Tally,
    /// An error writing output on this worker, kept until the workers agree to stop.
    pub error: Option<String>,
    /// The root's frame series (`None` elsewhere or without frames): the frames observer adds
    /// to it, and so does the blow-up check, whose frame belongs in the same index.
    frames: Option<Frames>,
    /// The whole scene on the root, refreshed by [`Watch::gather`].
    store: Option<FrameStore<M>>,
    damage: Option<Vec<f64>>,
    gathered: bool,
}

impl<M: Model> Watch<M> {
    /// The next step: nothing computed for it yet.
    pub(crate) fn at(&mut self, step: u64, last: bool) {
        self.step = step;
        self.last = last;
        self.damage = None;
        self.gathered = false;
    }

    /// Each owned particle's damage at this step (a collective: the broken counts of bonds
    /// to ghosts come home).
    pub fn damage(&mut self, cube: &mut Cube<M>) -> &[f64] {
        self.damage.get_or_insert_with(|| cube.damage())
    }

    /// Gathers the whole scene with its damage on the root (a collective), once per step.
    pub fn gather(&mut self, cube: &mut Cube<M>) {
        if !self.gathered {
            let damage = self.damage.get_or_insert_with(|| cube.damage());
            gather_frame(cube, damage, &mut self.store);
            self.gathered = true;
        }
    }

    /// Fails on every worker if any worker has an output error (a reduction).
    /// The others learn which worker failed (the highest numbered, if several).
    pub fn agree(&mut self, cube: &mut Cube<M>) -> Result<(), String> {
        let me = cube.wall.transport().rank() as f64;
        let failed = cube
            .team()
            .max(if self.error.is_some() { me + 1.0 } else { 0.0 });
        if failed > 0.0 {
            return Err(self.error.take().unwrap_or_else(|| {
                format!(
                    "worker {} failed writing output (it says why)",
                    failed as usize - 1
                )
            }));
        }
        Ok(())
    }
}

/// Whether the history row is written at `step`. A restarted run has the row and frame of its
/// first step from before.
fn row_due(plan: &Plan, step: u64, last: bool) -> bool {
    let again = plan.first_step > 0 && step == plan.first_step;
    (step.is_multiple_of(plan.every) || last) && !again
}

/// Whether a frame is written at `step` (a probe's stop makes a step the last, so its frame is
/// written too).
fn frame_due(plan: &Plan, step: u64, last: bool) -> bool {
    let again = plan.first_step > 0 && step == plan.first_step;
    plan.frames_every > 0 && (step.is_multiple_of(plan.frames_every) || last) && !again
}

/// One worker's observers, in the order they run, and what they share. The order matters: a
/// stop criterion before the outputs makes its step the last, so its row, frame, analyses and
/// checkpoint are written; the blow-up check comes before anything records the state; the
/// frame after the row, whose broken-bond count it carries.
pub(crate) fn observers<'a, M: Model>(
    plan: &'a Plan,
    cube: &mut Cube<M>,
    store: Option<FrameStore<M>>,
    tally: Tally,
) -> (Watch<M>, Vec<Box<dyn Observer<M> + 'a>>) {
    let (rank, workers) = (cube.wall.transport().rank(), cube.wall.transport().size());
    let root = rank == 0;
    let mut watch = Watch {
        step: plan.first_step,
        last: false,
        tally,
        error: None,
        frames: None,
        store,
        damage: None,
        gathered: false,
    };
    let history = history::HistoryRows::open(plan, root, &mut watch.error);
    if root && plan.frames_every > 0 && watch.error.is_none() {
        match frames::open(plan) {
            Ok(f) => watch.frames = Some(f),
            Err(e) => watch.error = Some(e),
        }
    }
    let progress = Progress::new(
        plan.first_step,
        plan.steps,
        root && plan.progress && !plan.quiet,
    );
    let mut list: Vec<Box<dyn Observer<M> + 'a>> = vec![
        Box::new(stops::BrokenBonds::new(plan)),
        Box::new(stops::BlowUp::new(plan)),
        Box::new(history),
        Box::new(frames::FrameSeries::new(plan)),
    ];
    for a in &plan.analyses {
        list.push(Box::new(analysis::Analysis::open(
            plan,
            a,
            root,
            &mut watch.error,
        )));
    }
    list.push(Box::new(ProgressLine(progress)));
    list.push(Box::new(checkpoints::Checkpoints::new(plan, workers)));
    (watch, list)
}

/// The progress line on the root's terminal, every step.
struct ProgressLine(Progress);

impl<M: Model> Observer<M> for ProgressLine {
    fn due(&self, _step: u64, _last: bool) -> bool {
        true
    }

    fn observe(
        &mut self,
        _cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        self.0.update(watch.step, watch.tally.broken);
        Ok(ControlFlow::Continue(()))
    }
}
