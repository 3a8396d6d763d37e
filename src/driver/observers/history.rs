//! The history rows, the probes' `stop_beyond` and `[time] stop_below_peak`: a row is the
//! state summed over procCubes (`record::Row`), so every worker sees every probe and every
//! column, and all stop alike.

use super::{row_due, Observer, Watch};
use crate::driver::record::Row;
use crate::driver::step_loop::Plan;
use crate::engine::timing::Phase;
use crate::input::deck::{PeakStop, Scene};
use crate::model::Model;
use crate::output::History;
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

/// `history.csv`, written by the root; a probe past its `stop_beyond` ends the run.
pub(super) struct HistoryRows<'a> {
    plan: &'a Plan,
    /// The root's file (`None` on the other workers).
    history: Option<History>,
    /// `[time] stop_below_peak`: the largest |value| of its column so far.
    peak: Option<Peak>,
}

/// The running peak of `[time] stop_below_peak`'s column.
struct Peak {
    column: usize,
    stop: PeakStop,
    largest: f64,
    /// Whether every worker holds `largest`: after a restart only the root has read it from
    /// the file, and the first row shares it.
    shared: bool,
}

/// `[time] stop_below_peak` with the index of its column in `columns`; an error naming the
/// columns there are if the run writes no such column.
pub(crate) fn peak_stop(
    scene: &Scene,
    columns: &[String],
) -> Result<Option<(usize, PeakStop)>, String> {
    let Some(stop) = &scene.time.stop_below_peak else {
        return Ok(None);
    };
    match columns.iter().position(|c| *c == stop.column) {
        Some(i) => Ok(Some((i, stop.clone()))),
        None => Err(format!(
            "{}:{}: [time] stop_below_peak names the history column '{}', which this run does not write; its columns are {}",
            scene.file,
            scene.time.line,
            stop.column,
            columns.join(", ")
        )),
    }
}

/// A value as history.csv writes it (ten digits after the point), so that the peak a restart
/// reads back from the file is the one the run had.
fn as_written(v: f64) -> f64 {
    format!("{v:.10e}").parse().unwrap_or(v)
}

/// The largest |value| of column `column` in the rows of the history file at `path`.
fn largest_in_file(path: &Path, column: usize) -> f64 {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(column)?.parse::<f64>().ok())
        .fold(0.0, |a, v| a.max(v.abs()))
}

impl<'a> HistoryRows<'a> {
    /// Creates the file, or reopens it at the step a restart resumes from; an error goes to
    /// `error`, for the workers to agree on.
    pub fn open(plan: &'a Plan, root: bool, error: &mut Option<String>) -> Self {
        let mut rows = HistoryRows {
            plan,
            history: None,
            peak: plan.peak_stop.clone().map(|(column, stop)| Peak {
                column,
                stop,
                largest: 0.0,
                shared: plan.first_step == 0,
            }),
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
        if let (Some(p), true) = (rows.peak.as_mut(), plan.first_step > 0) {
            p.largest = largest_in_file(&path, p.column);
        }
        rows
    }
}

impl Peak {
    /// Whether the row's value has fallen below the fraction of the peak of the rows before
    /// it; the peak then takes the row in. Every worker calls it at the same rows.
    fn fallen<M: Model>(&mut self, cube: &mut Cube<M>, values: &[f64]) -> bool {
        if !self.shared {
            let mut v = [self.largest];
            cube.team().reduce(&mut v, Reduce::Max);
            self.largest = v[0];
            self.shared = true;
        }
        let v = as_written(values[self.column]).abs();
        let fallen = v < self.stop.fraction * self.largest;
        self.largest = self.largest.max(v);
        fallen
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
        let values = row.values();
        if let Some(h) = self.history.as_mut() {
            if let Err(e) = h.row(&values) {
                watch.error = Some(plan.io(e));
            }
        }
        let fallen = self
            .peak
            .as_mut()
            .and_then(|p| p.fallen(cube, &values).then(|| p.stop.column.clone()));
        cube.sim.timing.lap(Phase::Output, t);
        if probe_halt.is_none() && fallen.is_none() {
            return Ok(ControlFlow::Continue(()));
        }
        watch.tally.stopped_at_probe = probe_halt;
        watch.tally.stopped_below_peak = fallen;
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
