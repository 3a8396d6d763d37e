//! The history rows, and the probes' `stop_beyond`: a row is the state summed over procCubes
//! (`record::Row`), so every worker sees every probe and all stop alike.

use super::{row_due, Observer, Watch};
use crate::driver::record::Row;
use crate::driver::step_loop::Plan;
use crate::engine::timing::Phase;
use crate::model::Model;
use crate::output::History;
use crate::parallel::Cube;
use std::ops::ControlFlow;
use std::time::Instant;

/// `history.csv`, written by the root; a probe past its `stop_beyond` ends the run.
pub(super) struct HistoryRows<'a> {
    plan: &'a Plan,
    /// The root's file (`None` on the other workers).
    history: Option<History>,
}

impl<'a> HistoryRows<'a> {
    /// Creates the file, or reopens it at the step a restart resumes from; an error goes to
    /// `error`, for the workers to agree on.
    pub fn open(plan: &'a Plan, root: bool, error: &mut Option<String>) -> Self {
        let mut rows = HistoryRows {
            plan,
            history: None,
        };
        if !root {
            return rows;
        }
        let path = plan.dir.join("history.csv");
        let h = if plan.first_step > 0 {
            History::resume(&path, &plan.columns, plan.first_step, plan.every)
        } else {
            History::create(&path, &plan.columns)
        };
        match h {
            Ok(h) => rows.history = Some(h),
            Err(e) => *error = Some(plan.io(e)),
        }
        rows
    }
}

impl<M: Model> Observer<M> for HistoryRows<'_> {
    fn due(&self, step: u64, last: bool) -> bool {
        row_due(self.plan, step, last)
    }

    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let t = Instant::now();
        let plan = self.plan;
        let damage = watch.damage(cube);
        let mut row = Row::reduced(cube, damage, plan.probe_stops.len());
        let stretch = cube.deform.as_ref().map_or([1.0; 3], |d| d.stretch());
        row.thermo = plan.thermo.map(|t| t.of(&row, stretch));
        // Every worker has the whole row, so all stop alike.
        let probe_halt = plan
            .probe_stops
            .iter()
            .zip(&row.probes)
            .find_map(|((name, limit), u)| {
                let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                (length > *limit).then(|| name.clone())
            });
        if plan.solver.quasi_static() {
            let s = watch.tally.solved.unwrap_or_default();
            row.solve = Some((s.iterations, s.residual));
        }
        watch.tally.broken = row.broken_bonds as usize;
        if let Some(h) = self.history.as_mut() {
            if let Err(e) = h.row(&row.values()) {
                watch.error = Some(plan.io(e));
            }
        }
        cube.sim.timing.lap(Phase::Output, t);
        if probe_halt.is_none() {
            return Ok(ControlFlow::Continue(()));
        }
        watch.tally.stopped_at_probe = probe_halt;
        Ok(ControlFlow::Break(()))
    }

    /// The rows still buffered go to the file.
    fn finish(&mut self, _cube: &mut Cube<M>, watch: &mut Watch<M>) {
        if let Some(h) = self.history.as_mut() {
            if let Err(e) = h.flush() {
                watch.error = Some(self.plan.io(e));
            }
        }
    }
}
