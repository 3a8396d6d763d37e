//! The wall method under MPI: `mpirun -np 2` and `-np 4` give the thread runs' results, and a
//! binary built with MPI runs without `mpirun` as one rank. Needs the `mpi` feature and
//! `mpirun` on the PATH (`.ci/run` installs Open MPI).
#![cfg(feature = "mpi")]

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;
use pdq::parallel::decomposition::{Procs, Walls};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{final_positions, lj_deck, max_distance, max_relative_difference};

const DECK: &str = "tests/decks/notched_pull.toml";

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-mpi-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Final positions (by id) and broken bonds that `pdq run` wrote.
fn read_final(dir: &Path) -> (Vec<[f64; 3]>, Vec<(u32, u32)>) {
    let pos = std::fs::read_to_string(dir.join("final_positions.csv")).unwrap();
    let positions = pos
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[1], v[2], v[3]]
        })
        .collect();
    let br = std::fs::read_to_string(dir.join("broken_bonds.csv")).unwrap();
    let broken = br
        .lines()
        .skip(1)
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    (positions, broken)
}

fn mpirun(np: usize, extra: &[&str], dir: &Path) {
    mpirun_deck(np, Path::new(DECK), extra, dir)
}

fn mpirun_deck(np: usize, deck: &Path, extra: &[&str], dir: &Path) {
    let out = Command::new("mpirun")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .args(["--oversubscribe", "-np", &np.to_string()])
        .arg(env!("CARGO_BIN_EXE_pdq"))
        .arg("run")
        .arg(deck)
        .args(["--quiet", "--output"])
        .arg(dir)
        .args(extra)
        .output()
        .expect("mpirun must be on the PATH for the MPI tests (apt-get install openmpi-bin)");
    assert!(
        out.status.success(),
        "mpirun -np {np} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The deck run on 4 threads as 2×2×1 procCubes, the reference of the rank runs.
fn threads_reference(deck_path: &Path, dir: &Path) -> pdq::driver::run::Summary {
    let scene = deck::load(deck_path).unwrap();
    run(
        &scene,
        &RunOptions {
            output: Some(dir.to_path_buf()),
            quiet: true,
            threads: Some(4),
            procs: Some(Procs::Given([2, 2, 1])),
            walls: Some(Walls::Whole),
            ..Default::default()
        },
    )
    .unwrap()
}

#[test]
fn mpi_ranks_agree_with_threads() {
    let threads_dir = out_dir("threads");
    let reference = threads_reference(Path::new(DECK), &threads_dir);
    assert!(reference.broken > 100);
    let (ref_pos, ref_broken) = read_final(&threads_dir);
    assert_eq!(ref_broken, reference.broken_pairs);

    // Without mpirun: one rank, same answer.
    let solo = out_dir("solo");
    let out = Command::new(env!("CARGO_BIN_EXE_pdq"))
        .args(["run", DECK, "--quiet", "--output"])
        .arg(&solo)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (pos, broken) = read_final(&solo);
    assert!(max_relative_difference(&ref_pos, &pos) <= 1e-12);
    assert_eq!(broken, ref_broken, "one rank without mpirun");

    for (np, extra) in [
        (2, vec![]),
        (4, vec!["--procs", "2x2x1"]),
        (4, vec!["--procs", "1x2x2", "--walls", "trimmed"]),
    ] {
        let dir = out_dir(&format!("np{np}-{}", extra.len()));
        mpirun(np, &extra, &dir);
        let (pos, broken) = read_final(&dir);
        let d = max_relative_difference(&ref_pos, &pos);
        eprintln!("mpirun -np {np} {extra:?}: max relative position difference {d:.2e}");
        assert!(d <= 1e-12, "-np {np}: positions differ by {d:e}");
        assert_eq!(
            broken, ref_broken,
            "-np {np} {extra:?}: broken bonds differ"
        );
        // The history the root wrote matches the threads' at every row (energies to round-off).
        let h = std::fs::read_to_string(dir.join("history.csv")).unwrap();
        let r = std::fs::read_to_string(threads_dir.join("history.csv")).unwrap();
        assert_eq!(h.lines().count(), r.lines().count());
        let _ = std::fs::remove_dir_all(dir);
    }
    let _ = std::fs::remove_dir_all(threads_dir);
    let _ = std::fs::remove_dir_all(solo);
}

#[test]
fn lps_micropolar_and_thermal_ranks_agree_with_threads() {
    for model in ["lps", "micropolar", "thermal"] {
        let deck_dir = out_dir(&format!("{model}-deck"));
        std::fs::create_dir_all(&deck_dir).unwrap();
        let deck_path = deck_dir.join(format!("{model}_pull.toml"));
        std::fs::write(&deck_path, common::model_pull_deck(model)).unwrap();
        let threads_dir = out_dir(&format!("{model}-threads"));
        let reference = threads_reference(&deck_path, &threads_dir);
        assert!(reference.broken > 50, "{model}: the deck must crack");
        let (ref_pos, ref_broken) = read_final(&threads_dir);
        for (np, extra) in [
            (2, vec![]),
            (4, vec!["--procs", "1x2x2", "--walls", "trimmed"]),
        ] {
            let dir = out_dir(&format!("{model}-np{np}"));
            mpirun_deck(np, &deck_path, &extra, &dir);
            let (pos, broken) = read_final(&dir);
            let d = max_relative_difference(&ref_pos, &pos);
            eprintln!(
                "{model}: mpirun -np {np} {extra:?}: max relative position difference {d:.2e}"
            );
            assert!(d <= 1e-12, "{model} -np {np}: positions differ by {d:e}");
            assert_eq!(broken, ref_broken, "{model} -np {np}: broken bonds differ");
            let _ = std::fs::remove_dir_all(dir);
        }
        let _ = std::fs::remove_dir_all(threads_dir);
        let _ = std::fs::remove_dir_all(deck_dir);
    }
}

#[test]
fn a_bad_layout_under_mpi_says_what_to_change() {
    let dir = out_dir("bad");
    let out = Command::new("mpirun")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .args(["--oversubscribe", "-np", "2"])
        .arg(env!("CARGO_BIN_EXE_pdq"))
        .args(["run", DECK, "--quiet", "--procs", "1x1x4", "--output"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("one procCube per worker"), "{err}");
}

/// The LJ melt's non-bonded pass under MPI: 200 steps with list rebuilds and shuffles on 2 and
/// 4 ranks follow one thread's trajectory to round-off.
#[test]
fn the_lj_melt_on_ranks_agrees_with_one_thread() {
    let base = out_dir("lj");
    std::fs::create_dir_all(&base).unwrap();
    let deck_path = base.join("lj.toml");
    std::fs::write(&deck_path, lj_deck()).unwrap();
    let one = base.join("one");
    let scene = deck::load(&deck_path).unwrap();
    run(
        &scene,
        &RunOptions {
            output: Some(one.clone()),
            quiet: true,
            threads: Some(1),
            ..Default::default()
        },
    )
    .unwrap();
    let reference = final_positions(&one);
    let period = 8.0 * (4.0f64 / 0.8442).cbrt();
    for (np, extra) in [(2, vec![]), (4, vec!["--procs", "2x2x1"])] {
        let dir = base.join(format!("np{np}"));
        mpirun_deck(np, &deck_path, &extra, &dir);
        let d = max_distance(&reference, &final_positions(&dir), period);
        eprintln!("LJ melt, mpirun -np {np}: positions within {d:.2e} of one thread's");
        assert!(d < 1e-9, "-np {np}: positions differ by {d:e}");
    }
    let _ = std::fs::remove_dir_all(base);
}

/// Checkpoints under MPI: `mpirun -np 2` stopped at step 250 and restarted ends bit-identical
/// to `mpirun -np 2` straight through; a checkpoint written by one thread resumes on two ranks
/// with the same broken bonds and positions within 1e-12.
#[test]
fn restarts_under_mpi() {
    let work = out_dir("restart");
    std::fs::create_dir_all(&work).unwrap();
    let text = std::fs::read_to_string(DECK).unwrap().replace(
        "final_state = true",
        "final_state = true\ncheckpoint_every = 250",
    );
    let deck_path = work.join("pull.toml");
    std::fs::write(&deck_path, &text).unwrap();
    let straight = work.join("straight");
    mpirun_deck(2, &deck_path, &[], &straight);
    let resumed = work.join("resumed");
    mpirun_deck(2, &deck_path, &["--steps", "250"], &resumed);
    let from = resumed.to_str().unwrap().to_string();
    mpirun_deck(2, &deck_path, &["--restart", &from], &resumed);
    for file in ["final_positions.csv", "broken_bonds.csv", "history.csv"] {
        let a = std::fs::read_to_string(straight.join(file)).unwrap();
        let b = std::fs::read_to_string(resumed.join(file)).unwrap();
        assert!(a == b, "-np 2: {file} differs after the restart");
    }
    // One thread writes the checkpoint, two ranks resume from it.
    let one = work.join("one");
    let scene = deck::parse(&text, "pull.toml", "pull").unwrap();
    run(
        &scene,
        &RunOptions {
            output: Some(one.clone()),
            quiet: true,
            steps: Some(250),
            threads: Some(1),
            ..Default::default()
        },
    )
    .unwrap();
    let from = one.join("checkpoints/checkpoint_00000250.h5");
    mpirun_deck(2, &deck_path, &["--restart", from.to_str().unwrap()], &one);
    let (pa, ba) = read_final(&straight);
    let (pb, bb) = read_final(&one);
    assert_eq!(ba, bb, "different bonds broke");
    let d = max_relative_difference(&pa, &pb);
    eprintln!(
        "MPI restart: -np 2 bit-identical; 1 thread -> -np 2 at step 250: {} broken bonds, the same; positions within {d:.1e}",
        bb.len()
    );
    assert!(d <= 1e-12, "positions differ by {d:e}");
    // Four ranks write the checkpoint in parts; two ranks, and one thread, resume from it.
    let four = work.join("four");
    mpirun_deck(4, &deck_path, &["--steps", "250"], &four);
    let index = four.join("checkpoints/checkpoint_00000250.h5");
    let parts = four.join("checkpoints/checkpoint_00000250.parts");
    assert_eq!(
        std::fs::read_dir(&parts).unwrap().count(),
        4,
        "one part per rank"
    );
    let two = work.join("four-two");
    mpirun_deck(2, &deck_path, &["--restart", index.to_str().unwrap()], &two);
    let (p2, b2) = read_final(&two);
    assert_eq!(ba, b2, "-np 4 parts -> -np 2: different bonds broke");
    let d2 = max_relative_difference(&pa, &p2);
    let thread = work.join("four-thread");
    run(
        &scene,
        &RunOptions {
            output: Some(thread.clone()),
            quiet: true,
            threads: Some(1),
            restart: Some(index.clone()),
            ..Default::default()
        },
    )
    .unwrap();
    let (p1, b1) = read_final(&thread);
    assert_eq!(ba, b1, "-np 4 parts -> 1 thread: different bonds broke");
    let d1 = max_relative_difference(&pa, &p1);
    eprintln!(
        "checkpoint in 4 parts at step 250 -> -np 2: positions within {d2:.1e}; -> 1 thread: {d1:.1e}; the same {} broken bonds",
        b1.len()
    );
    assert!(
        d2 <= 1e-12 && d1 <= 1e-12,
        "positions differ by {d2:e}, {d1:e}"
    );
    let _ = std::fs::remove_dir_all(work);
}

/// `mpirun -np 4` of the pull deck for many steps, with `env`; the child, not waited for.
fn spawn_ranks(dir: &Path, env: &[(&str, &str)]) -> std::process::Child {
    Command::new("mpirun")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .envs(env.iter().copied())
        .args(["--oversubscribe", "-np", "4"])
        .arg(env!("CARGO_BIN_EXE_pdq"))
        .arg("run")
        .arg(DECK)
        .args(["--quiet", "--steps", "1000000", "--output"])
        .arg(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mpirun must be on the PATH for the MPI tests")
}

/// Waits for `child` at most `limit`; kills it and fails if it hangs; its stderr.
fn ended_within(mut child: std::process::Child, limit: std::time::Duration, what: &str) -> String {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr).to_string();
            assert!(
                !status.success(),
                "{what}: the job ended as if nothing happened\n{err}"
            );
            return err;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{what}: the other ranks hang ({limit:?})");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// The MPI rank (`OMPI_COMM_WORLD_RANK`) of each of `mpirun`'s children.
fn ranks_of(mpirun: u32) -> Vec<(u32, usize)> {
    let children = std::fs::read_to_string(format!("/proc/{mpirun}/task/{mpirun}/children"))
        .unwrap_or_default();
    children
        .split_whitespace()
        .filter_map(|pid| {
            let env = std::fs::read(format!("/proc/{pid}/environ")).ok()?;
            let rank = env
                .split(|&b| b == 0)
                .filter_map(|v| std::str::from_utf8(v).ok())
                .find_map(|v| v.strip_prefix("OMPI_COMM_WORLD_RANK="))?
                .parse()
                .ok()?;
            Some((pid.parse().ok()?, rank))
        })
        .collect()
}

/// A rank that meets an error alone (injected once its procCube is built, while the others
/// wait for its ghosts) and a rank killed with SIGKILL mid-run: every rank stops within a
/// minute and the message names the rank.
#[test]
fn a_rank_that_fails_or_dies_stops_every_rank() {
    let dir = out_dir("fail-rank");
    let child = spawn_ranks(&dir, &[("PDQ_TEST_FAIL_RANK", "2")]);
    let err = ended_within(child, std::time::Duration::from_secs(60), "rank 2 failing");
    assert!(err.contains("error on rank 2 of 4"), "{err}");
    eprintln!("rank 2 failing: {}", err.lines().next().unwrap_or(""));
    let dir = out_dir("kill-rank");
    let child = spawn_ranks(&dir, &[]);
    let history = dir.join("history.csv");
    let start = std::time::Instant::now();
    while std::fs::read_to_string(&history).map_or(0, |h| h.lines().count()) < 3 {
        assert!(
            start.elapsed().as_secs() < 120,
            "the run did not start stepping"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let ranks = ranks_of(child.id());
    let &(pid, rank) = ranks
        .iter()
        .find(|r| r.1 == 1)
        .unwrap_or_else(|| panic!("no rank 1 among {ranks:?}"));
    Command::new("kill")
        .args(["-9", &pid.to_string()])
        .status()
        .unwrap();
    let err = ended_within(child, std::time::Duration::from_secs(60), "rank 1 killed");
    assert!(err.contains(&format!("rank {rank}")), "{err}");
    eprintln!(
        "rank 1 killed: {}",
        err.lines().find(|l| l.contains("rank 1")).unwrap_or("")
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Voids under MPI (issue 24): the holes deck's voids table on 2 and 4 ranks is the one
/// thread's, byte for byte, with the default merge and with the min-label one.
#[test]
fn voids_on_ranks_are_the_threads_voids() {
    let deck = Path::new("tests/decks/holes.toml");
    let reference = out_dir("voids-threads");
    threads_reference(deck, &reference);
    let table = std::fs::read_to_string(reference.join("voids_clusters.csv")).unwrap();
    assert_eq!(table.lines().filter(|l| l.starts_with("0,")).count(), 3);
    let text = std::fs::read_to_string(deck).unwrap();
    let min_label = out_dir("voids-min-label.toml");
    std::fs::write(
        &min_label,
        text.replace(
            "kind = \"voids\"",
            "kind = \"voids\"\nscheme = \"min-label\"",
        ),
    )
    .unwrap();
    for (np, d) in [(2, deck), (4, deck), (4, min_label.as_path())] {
        let dir = out_dir(&format!("voids-{np}"));
        mpirun_deck(np, d, &[], &dir);
        let got = std::fs::read_to_string(dir.join("voids_clusters.csv")).unwrap();
        assert!(
            got == table,
            "{np} ranks ({}):\n{got}\nthreads:\n{table}",
            d.display()
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
    let _ = std::fs::remove_file(min_label);
    std::fs::remove_dir_all(reference).unwrap();
}
