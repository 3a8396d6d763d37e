//! Frames and checkpoints written in parts (`[output] parts = true`, the default on several MPI
//! ranks; here on threads): one file per procCube and an index; the parts read back as the
//! gathered checkpoint, a restart from them on another layout breaks the same bonds, and a run
//! killed at any point of writing them leaves the previous checkpoint readable and whole.

use pdq::driver::run::RunOptions;
use pdq::output::checkpoint::Checkpoint;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

mod common;
use common::{layout, max_relative_difference};

const PULL: &str = include_str!("decks/notched_pull.toml");

/// The notched pull (500 steps, cracks): checkpoints every `every` steps, frames every 250,
/// written in parts (`parts`) or gathered.
fn deck(every: u64, parts: bool) -> String {
    PULL.replace(
        "final_state = true",
        &format!(
            "final_state = true\ncheckpoint_every = {every}\nframes_every = 250\nparts = {parts}"
        ),
    )
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-parts-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(text: &str, dir: &Path, opts: RunOptions) -> pdq::driver::run::Summary {
    common::run_quietly(text, "pull.toml", dir, opts).unwrap()
}

#[test]
fn parts_read_back_as_the_gathered_checkpoint_and_resume_on_other_layouts() {
    let (parts, gathered) = (out_dir("parts"), out_dir("gathered"));
    let s = run(&deck(250, true), &parts, layout(2, [2, 1, 1]));
    run(&deck(250, false), &gathered, layout(2, [2, 1, 1]));
    assert!(s.broken > 0, "the pull must crack");
    let ck = parts.join("checkpoints");
    for k in 0..2 {
        let part = ck.join(format!("checkpoint_00000250.parts/part_{k:04}.h5"));
        assert!(part.is_file(), "no {}", part.display());
        let frame = parts.join(format!("frames/frame_00000250/part_{k:04}.h5"));
        assert!(frame.is_file(), "no {}", frame.display());
    }
    assert!(!parts.join("frames/frame_00000250.h5").exists());
    // The index reads as the whole checkpoint: the same bits as the gathered one.
    for step in [250, 500] {
        let name = format!("checkpoints/checkpoint_{step:08}.h5");
        let a = Checkpoint::read(&parts.join(&name)).unwrap();
        let b = Checkpoint::read(&gathered.join(&name)).unwrap();
        assert!(
            a == b,
            "step {step}: the parts differ from the gathered checkpoint"
        );
    }
    // The frame's parts hold every particle once.
    let f = pdq::output::frames::read_points(&parts.join("frames/frame_00000500")).unwrap();
    let mut ids = f.ids.clone();
    ids.sort_unstable();
    assert_eq!(ids, (0..s.particles as i32).collect::<Vec<_>>());
    let xdmf = std::fs::read_to_string(parts.join("frames.xdmf")).unwrap();
    assert!(xdmf.contains("CollectionType=\"Spatial\"") && xdmf.contains("part_0001.h5:/points"));
    let info = pdq::output::info::info(&ck.join("checkpoint_00000250.h5")).unwrap();
    assert!(info.contains("step       250"), "{info}");
    let part = pdq::output::info::info(&ck.join("checkpoint_00000250.parts/part_0001.h5")).unwrap();
    assert!(part.contains("part of a checkpoint"), "{part}");
    // Resumed from the parts at step 250: on the same layout bit-identical, on one and four
    // procCubes the same broken bonds.
    let from = ck.join("checkpoint_00000250.h5");
    for (threads, procs) in [(2, [2, 1, 1]), (1, [1, 1, 1]), (4, [2, 2, 1])] {
        let dir = out_dir(&format!("resumed-{threads}"));
        let opts = RunOptions {
            restart: Some(from.clone()),
            ..layout(threads, procs)
        };
        let r = run(&deck(250, true), &dir, opts);
        assert_eq!(
            s.broken_pairs, r.broken_pairs,
            "{threads} procCubes: other bonds broke"
        );
        let d = max_relative_difference(&s.positions, &r.positions);
        eprintln!("parts of 2x1x1 at step 250 -> {threads} procCubes: {} broken bonds, the same; positions within {d:.1e}", r.broken);
        if threads == 2 {
            assert_eq!(d, 0.0, "same layout: not bit-identical");
        }
        assert!(d <= 1e-12, "positions differ by {d:e}");
        let _ = std::fs::remove_dir_all(dir);
    }
    let _ = std::fs::remove_dir_all(parts);
    let _ = std::fs::remove_dir_all(gathered);
}

fn pdq_run(deck: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pdq"));
    c.arg("run")
        .arg(deck)
        .args(["--quiet", "--threads", "2", "--procs", "2x1x1", "--output"])
        .arg(out)
        .args(extra);
    c
}

fn wait_for(what: &str, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn non_empty(p: &Path) -> bool {
    std::fs::metadata(p).is_ok_and(|m| m.len() > 0)
}

/// `kill -9` halfway through a part, with every part on disk but no index, and halfway
/// through the index: each time the checkpoint of step 300 is not one, the previous (step
/// 200, in parts) reads whole, and the run resumed from it ends as one that never stopped.
#[test]
fn a_run_killed_while_writing_a_checkpoint_in_parts_resumes_from_the_previous_one() {
    let work = out_dir("kill");
    std::fs::create_dir_all(&work).unwrap();
    let deck_path = work.join("pull.toml");
    std::fs::write(&deck_path, deck(100, true)).unwrap();
    let straight = work.join("straight");
    assert!(pdq_run(&deck_path, &straight, &[])
        .status()
        .unwrap()
        .success());
    let ck = |out: &Path, name: &str| out.join("checkpoints").join(name);
    for point in ["file", "before-index", "index"] {
        let out = work.join(point);
        assert!(pdq_run(&deck_path, &out, &["--steps", "200"])
            .status()
            .unwrap()
            .success());
        let from = out.to_str().unwrap().to_string();
        let mut child = pdq_run(&deck_path, &out, &["--restart", &from])
            .env("PDQ_CHECKPOINT_PAUSE_MS", "30000")
            .env("PDQ_CHECKPOINT_PAUSE_AT", point)
            .spawn()
            .unwrap();
        let parts = ck(&out, "checkpoint_00000300.parts");
        wait_for(
            &format!("the checkpoint of step 300 at '{point}'"),
            || match point {
                "file" => non_empty(&parts.join(".part_0000.h5.tmp")),
                "before-index" => (0..2).all(|k| parts.join(format!("part_{k:04}.h5")).is_file()),
                _ => non_empty(&ck(&out, ".checkpoint_00000300.h5.tmp")),
            },
        );
        child.kill().unwrap(); // SIGKILL
        child.wait().unwrap();
        assert!(!ck(&out, "checkpoint_00000300.h5").exists(), "{point}");
        let (path, c) = pdq::output::checkpoint::resolve(&out).unwrap();
        assert_eq!(
            c.state.step,
            200,
            "{point}: resumes from {}",
            path.display()
        );
        assert!(
            c.state.ids.is_none(),
            "{point}: the previous checkpoint is not whole"
        );
        assert!(pdq_run(&deck_path, &out, &["--restart", &from])
            .status()
            .unwrap()
            .success());
        for file in ["final_positions.csv", "broken_bonds.csv", "history.csv"] {
            let a = std::fs::read(straight.join(file)).unwrap();
            let b = std::fs::read(out.join(file)).unwrap();
            assert!(a == b, "killed at '{point}': {file} differs");
        }
        eprintln!("killed at '{point}': resumed from step 200, ends as the run that never stopped");
    }
    let _ = std::fs::remove_dir_all(work);
}
