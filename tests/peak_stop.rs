//! `[time] stop_below_peak`: the quick lap-splice pullout ends once its pull has fallen below a
//! quarter of its peak, with the rows and the peak of the run that goes on to its end, and a
//! restart from a checkpoint past the peak stops at the same row with the same history.

use pdq::driver::run::{RunOptions, Summary};
use std::path::{Path, PathBuf};

mod common;

const SPLICE: &str = include_str!("../validation/lap_splice_fast.toml");
const STOP: &str = "stop_below_peak = { column = \"reaction_right_grip_x\", fraction = 0.25 }";
const COLUMN: &str = "reaction_right_grip_x";

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-peak-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(text: &str, dir: &Path, opts: RunOptions) -> Summary {
    common::run_quietly(text, "splice.toml", dir, opts).expect("the pullout runs")
}

fn history(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("history.csv")).unwrap()
}

/// (step, |pull|) of every history row.
fn pulls(history: &str) -> Vec<(f64, f64)> {
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (s, c) = (0, header.iter().position(|h| *h == COLUMN).unwrap());
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (v[s], v[c].abs())
        })
        .collect()
}

#[test]
fn a_pullout_stops_past_its_peak_with_the_rows_and_peak_of_the_whole_run() {
    assert!(
        SPLICE.contains(STOP),
        "the quick splice deck stops below its peak"
    );
    let (stopped_dir, whole_dir) = (out_dir("stopped"), out_dir("whole"));
    let stopped = run(SPLICE, &stopped_dir, RunOptions::default());
    let whole = run(&SPLICE.replace(STOP, ""), &whole_dir, RunOptions::default());
    assert_eq!(stopped.stopped_below_peak.as_deref(), Some(COLUMN));
    assert!(whole.stopped_below_peak.is_none());
    assert!(
        stopped.steps < whole.steps,
        "{} against {} steps",
        stopped.steps,
        whole.steps
    );
    let (a, b) = (history(&stopped_dir), history(&whole_dir));
    assert!(
        b.starts_with(&a),
        "the stopped run's rows are the whole run's first rows"
    );
    // Only the last row has fallen below a quarter of the rows before it.
    let rows = pulls(&a);
    let mut peak = 0.0f64;
    for (k, &(step, pull)) in rows.iter().enumerate() {
        let fallen = pull < 0.25 * peak;
        assert_eq!(
            fallen,
            k == rows.len() - 1,
            "row at step {step}: {pull} against {peak}"
        );
        peak = peak.max(pull);
    }
    let whole_peak = pulls(&b).iter().fold(0.0f64, |m, r| m.max(r.1));
    assert_eq!(
        peak, whole_peak,
        "the run that went on found no higher peak"
    );
    eprintln!(
        "stopped at step {} of {}: peak {peak:.1} lbf",
        stopped.steps, whole.steps
    );

    // A restart from a checkpoint between the peak and the stop ends at the same row.
    let peak_step = rows.iter().find(|r| r.1 == peak).unwrap().0 as u64;
    let at = (peak_step + (stopped.steps - peak_step) / 2) / 10 * 10;
    assert!(at > peak_step && at < stopped.steps);
    let with_checkpoint = SPLICE.replace(
        "[output]\n",
        &format!("[output]\ncheckpoint_every = {at}\n"),
    );
    let dir = out_dir("resumed");
    let first = run(
        &with_checkpoint,
        &dir,
        RunOptions {
            steps: Some(at),
            ..Default::default()
        },
    );
    assert_eq!(first.checkpoints.len(), 1);
    let resumed = run(
        &with_checkpoint,
        &dir,
        RunOptions {
            restart: Some(dir.join("checkpoints")),
            ..Default::default()
        },
    );
    assert_eq!((resumed.first_step, resumed.steps), (at, stopped.steps));
    assert_eq!(resumed.stopped_below_peak.as_deref(), Some(COLUMN));
    assert!(history(&dir) == a, "the resumed history differs");
    for d in [stopped_dir, whole_dir, dir] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn a_stop_on_a_column_the_run_does_not_write_is_refused_by_name() {
    let text = SPLICE.replace(STOP, &STOP.replace(COLUMN, "reaction_grip_x"));
    let dir = out_dir("unknown");
    let e = common::run_quietly(&text, "splice.toml", &dir, RunOptions::default()).unwrap_err();
    for phrase in [
        "stop_below_peak",
        "'reaction_grip_x'",
        "reaction_right_grip_x",
    ] {
        assert!(e.contains(phrase), "{phrase:?} not in: {e}");
    }
    let _ = std::fs::remove_dir_all(dir);
}
