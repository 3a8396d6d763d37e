//! Checkpoints and restarts: a run that stops and resumes ends exactly where one that never
//! stopped ends; a restart on another layout breaks the same bonds; a run killed while writing
//! a checkpoint, or stopped by SIGTERM, resumes; damaged or foreign checkpoints are refused.

use pdq::driver::run::{RunOptions, Summary};
use pdq::output::checkpoint::Checkpoint;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{layout, max_relative_difference};

const PULL: &str = include_str!("decks/notched_pull.toml");

/// The notched pull deck (500 steps, cracks) with a checkpoint every 250 steps.
fn pull_deck(model: &str) -> String {
    let text = match model {
        "pmb" => PULL.to_string(),
        "concrete" => concrete_pull_deck(),
        _ => common::model_pull_deck(model),
    };
    assert!(text.contains("final_state = true"));
    text.replace(
        "final_state = true",
        "final_state = true\ncheckpoint_every = 250",
    )
}

/// The notched pull in the thesis's concrete model, with a steel bar along x under the notch
/// that yields as the block is pulled apart: the bonds that carry history (their plastic
/// stretch) must resume as they were.
fn concrete_pull_deck() -> String {
    let mut text = common::model_pull_deck("concrete");
    text.push_str(
        r#"[materials.steel]
kind = "steel"
density = "7850 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.3
yield_stretch = 2e-4
failure_stretch = 0.05
[[bar]]
material = "steel"
area = "3 mm^2"
from = "0 5 2 mm"
to = "30 5 2 mm"
"#,
    );
    text
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-ckpt-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run_deck(text: &str, dir: &Path, opts: RunOptions) -> Result<Summary, String> {
    common::run_quietly(text, "pull.toml", dir, opts)
}

fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap()
}

#[test]
fn a_restarted_run_ends_bit_identical_to_one_that_never_stopped() {
    for (model, threads, procs) in [
        ("pmb", 1, [1, 1, 1]),
        ("pmb", 2, [2, 1, 1]),
        ("lps", 2, [2, 1, 1]),
        ("micropolar", 1, [1, 1, 1]),
        ("thermal", 1, [1, 1, 1]),
        ("concrete", 2, [2, 1, 1]),
    ] {
        let text = pull_deck(model);
        let straight = out_dir(&format!("{model}-{threads}-straight"));
        let s = run_deck(&text, &straight, layout(threads, procs)).unwrap();
        assert!(s.broken > 0, "{model}: the pull must crack");
        let resumed = out_dir(&format!("{model}-{threads}-resumed"));
        let first = run_deck(
            &text,
            &resumed,
            RunOptions {
                steps: Some(250),
                ..layout(threads, procs)
            },
        )
        .unwrap();
        assert_eq!(first.checkpoints.len(), 1);
        let r = run_deck(
            &text,
            &resumed,
            RunOptions {
                restart: Some(resumed.join("checkpoints")),
                ..layout(threads, procs)
            },
        )
        .unwrap();
        assert_eq!((r.first_step, r.steps), (250, 500));
        for file in ["final_positions.csv", "broken_bonds.csv", "history.csv"] {
            assert!(
                read(&straight, file) == read(&resumed, file),
                "{model} on {threads} threads: {file} differs after the restart"
            );
        }
        // The final checkpoints hold the same bytes of state: positions, velocities, forces,
        // broken bonds and bond histories.
        let a = Checkpoint::read(&straight.join("checkpoints/checkpoint_00000500.h5")).unwrap();
        let b = Checkpoint::read(&resumed.join("checkpoints/checkpoint_00000500.h5")).unwrap();
        assert!(a == b, "{model}: the final checkpoints differ");
        if model == "concrete" {
            // The restart resumed bonds with history: the bar had yielded by step 250.
            let mid = Checkpoint::read(&resumed.join("checkpoints/checkpoint_00000250.h5"));
            let yielded = mid.unwrap().state.history_pairs.len();
            assert!(
                yielded > 0,
                "concrete: no steel bond had yielded at the restart"
            );
            eprintln!("concrete: {yielded} bonds with plastic stretch at the restart");
        }
        eprintln!(
            "{model}, {threads} thread(s): 500 straight = 250 + restart + 250, {} broken bonds, bit-identical",
            s.broken
        );
        let _ = std::fs::remove_dir_all(straight);
        let _ = std::fs::remove_dir_all(resumed);
    }
}

#[test]
fn a_checkpoint_from_one_procube_resumes_on_four() {
    let text = pull_deck("pmb");
    let straight = out_dir("layout-straight");
    let s = run_deck(&text, &straight, layout(1, [1, 1, 1])).unwrap();
    let dir = out_dir("layout-resumed");
    run_deck(
        &text,
        &dir,
        RunOptions {
            steps: Some(250),
            ..layout(1, [1, 1, 1])
        },
    )
    .unwrap();
    let r = run_deck(
        &text,
        &dir,
        RunOptions {
            restart: Some(dir.join("checkpoints/checkpoint_00000250.h5")),
            ..layout(4, [2, 2, 1])
        },
    )
    .unwrap();
    assert_eq!(s.broken_pairs, r.broken_pairs, "different bonds broke");
    let d = max_relative_difference(&s.positions, &r.positions);
    eprintln!(
        "1x1x1 -> 2x2x1 at step 250: {} broken bonds, the same set; positions within {d:.1e}",
        r.broken
    );
    assert!(d <= 1e-12, "positions differ by {d:e}");
    let _ = std::fs::remove_dir_all(straight);
    let _ = std::fs::remove_dir_all(dir);
}

fn pdq() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pdq"))
}

/// `pdq run DECK --quiet --output OUT` with `extra` arguments.
fn pdq_run(deck: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = pdq();
    c.arg("run")
        .arg(deck)
        .arg("--quiet")
        .arg("--output")
        .arg(out)
        .args(extra);
    c
}

/// Runs `pdq run` to the end and checks that it succeeded.
fn pdq_run_ok(deck: &Path, out: &Path, extra: &[&str]) {
    let status = pdq_run(deck, out, extra).status().unwrap();
    assert!(status.success(), "pdq run {extra:?} failed");
}

/// Writes `text` as a deck file in `dir` and returns its path.
fn deck_file(dir: &Path, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("pull.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn wait_for(what: &str, timeout: Duration, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < timeout, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_run_killed_while_writing_a_checkpoint_resumes_from_the_previous_one() {
    let work = out_dir("kill");
    let text = pull_deck("pmb").replace("checkpoint_every = 250", "checkpoint_every = 100");
    let deck = deck_file(&work, &text);
    let out = work.join("out");
    // Checkpoints at 100 and 200.
    pdq_run_ok(&deck, &out, &["--steps", "200"]);
    // Resume, and kill the run halfway through writing the checkpoint of step 300.
    let from = out.to_str().unwrap().to_string();
    let mut child = pdq_run(&deck, &out, &["--restart", &from])
        .env("PDQ_CHECKPOINT_PAUSE_MS", "30000")
        .spawn()
        .unwrap();
    let tmp = out.join("checkpoints/.checkpoint_00000300.h5.tmp");
    wait_for(
        "the checkpoint of step 300 to be half written",
        Duration::from_secs(120),
        || {
            tmp.exists()
                && std::fs::metadata(&tmp)
                    .map(|m| m.len() > 0)
                    .unwrap_or(false)
        },
    );
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    assert!(!out.join("checkpoints/checkpoint_00000300.h5").exists());
    // The half-written file is not a checkpoint; the previous one loads.
    assert!(Checkpoint::read(&tmp).is_err());
    let (path, c) = pdq::output::checkpoint::resolve(&out).unwrap();
    assert_eq!(c.state.step, 200, "resumes from {}", path.display());
    pdq_run_ok(&deck, &out, &["--restart", &from]);
    let straight = work.join("straight");
    pdq_run_ok(&deck, &straight, &[]);
    for file in ["final_positions.csv", "broken_bonds.csv", "history.csv"] {
        assert!(read(&straight, file) == read(&out, file), "{file} differs");
    }
    let _ = std::fs::remove_dir_all(work);
}

#[test]
fn sigterm_writes_a_checkpoint_and_the_run_resumes_from_it() {
    let work = out_dir("term");
    // No checkpoints on a schedule: the signal alone makes one. Two procCubes agree on it.
    let text = pull_deck("pmb").replace("checkpoint_every = 250", "");
    let deck = deck_file(&work, &text);
    let out = work.join("out");
    let child = pdq_run(&deck, &out, &["--threads", "2", "--steps", "100000000"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it is stepping (a few history rows), then ask it to stop.
    wait_for(
        "the run to start stepping",
        Duration::from_secs(120),
        || {
            std::fs::read_to_string(out.join("history.csv"))
                .map(|h| h.lines().count() > 3)
                .unwrap_or(false)
        },
    );
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let done = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert_eq!(
        done.status.code(),
        Some(pdq::output::signals::EXIT_INTERRUPTED as i32),
        "{stderr}"
    );
    assert!(stderr.contains("--restart"), "says how to resume: {stderr}");
    let (_, c) = pdq::output::checkpoint::resolve(&out).unwrap();
    assert!(c.state.step > 0);
    eprintln!(
        "SIGTERM: stopped at step {} with a checkpoint; {stderr}",
        c.state.step
    );
    // Resuming to a few steps further matches a run that went there straight.
    let end = (c.state.step + 50).to_string();
    let from = out.to_str().unwrap().to_string();
    pdq_run_ok(
        &deck,
        &out,
        &["--threads", "2", "--steps", &end, "--restart", &from],
    );
    let straight = work.join("straight");
    pdq_run_ok(&deck, &straight, &["--threads", "2", "--steps", &end]);
    for file in ["final_positions.csv", "broken_bonds.csv"] {
        assert!(read(&straight, file) == read(&out, file), "{file} differs");
    }
    let _ = std::fs::remove_dir_all(work);
}

#[test]
fn foreign_truncated_and_damaged_checkpoints_are_refused() {
    let text = pull_deck("pmb");
    let dir = out_dir("bad");
    run_deck(
        &text,
        &dir,
        RunOptions {
            steps: Some(250),
            ..Default::default()
        },
    )
    .unwrap();
    let good = dir.join("checkpoints/checkpoint_00000250.h5");
    let restart = |deck: &str, from: &Path| -> String {
        run_deck(
            deck,
            &dir.join("again"),
            RunOptions {
                restart: Some(from.to_path_buf()),
                ..Default::default()
            },
        )
        .expect_err("the restart must be refused")
    };
    // Another model.
    let e = restart(&pull_deck("lps"), &good);
    assert!(e.contains("model 'pmb'") && e.contains("'lps'"), "{e}");
    // Another geometry (a wider block), and another material.
    let wider = text.replace("max = \"30 10 10 mm\"", "max = \"31 10 10 mm\"");
    assert_ne!(wider, text, "the deck's block changed");
    let e = restart(&wider, &good);
    assert!(e.contains("particles") || e.contains("geometry"), "{e}");
    let e = restart(&text.replace("14.9 GPa", "20 GPa"), &good);
    assert!(e.contains("materials"), "{e}");
    // Truncated, and one byte changed in the middle.
    let bytes = std::fs::read(&good).unwrap();
    let cut = dir.join("truncated.h5");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let e = restart(&text, &cut);
    assert!(e.contains("truncated.h5"), "{e}");
    for at in [bytes.len() / 3, bytes.len() / 2, bytes.len() - 100] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x5a;
        let path = dir.join("damaged.h5");
        std::fs::write(&path, &bad).unwrap();
        let e = restart(&text, &path);
        assert!(e.contains("damaged.h5"), "byte {at}: {e}");
    }
    // A frame is not a checkpoint; nor is a file that does not exist.
    let e = restart(&text, &dir.join("history.csv"));
    assert!(e.contains("history.csv"), "{e}");
    let e = restart(&text, &dir.join("nothing.h5"));
    assert!(e.contains("no such file"), "{e}");
    eprintln!("refused: {e}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn pdq_info_describes_frames_and_checkpoints() {
    let text = pull_deck("pmb").replace(
        "history_every = 100",
        "history_every = 100\nframes_every = 250",
    );
    let dir = out_dir("info");
    let s = run_deck(&text, &dir, RunOptions::default()).unwrap();
    let info = |file: &Path| {
        let out = pdq().arg("info").arg(file).output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let c = info(&dir.join("checkpoints/checkpoint_00000500.h5"));
    assert!(c.contains("step       500"), "{c}");
    assert!(c.contains(&format!("{} broken", s.broken)), "{c}");
    assert!(c.contains(&format!("particles  {}", s.particles)), "{c}");
    let f = info(&dir.join("frames/frame_00000500.h5"));
    assert!(
        f.contains("step       500") && f.contains("damage[1]"),
        "{f}"
    );
    assert!(f.contains(&format!("{} broken", s.broken)), "{f}");
    let out = pdq()
        .arg("info")
        .arg(dir.join("history.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("history.csv"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn checkpoints_on_the_wall_clock_keep_the_newest() {
    let text = pull_deck("pmb").replace(
        "checkpoint_every = 250",
        "checkpoint_minutes = 0.00002\ncheckpoint_keep = 2",
    );
    let dir = out_dir("clock");
    let s = run_deck(&text, &dir, RunOptions::default()).unwrap();
    let on_disk = std::fs::read_dir(dir.join("checkpoints")).unwrap().count();
    eprintln!(
        "every 1.2 ms of wall time: {} checkpoints written, {on_disk} kept",
        s.checkpoints.len()
    );
    assert!(s.checkpoints.len() > 2, "{} written", s.checkpoints.len());
    assert_eq!(on_disk, 2);
    let (_, c) = pdq::output::checkpoint::resolve(&dir).unwrap();
    assert_eq!(c.state.step, 500, "the last step always gets one");
    let _ = std::fs::remove_dir_all(dir);
}
