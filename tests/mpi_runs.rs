//! The wall method under MPI: `mpirun -np 2` and `-np 4` give the thread runs' results, and a
//! binary built with MPI runs without `mpirun` as one rank. Needs the `mpi` feature and
//! `mpirun` on the PATH (`.ci/run` installs Open MPI).
#![cfg(feature = "mpi")]

use pdq::deck;
use pdq::decomposition::{Procs, Walls};
use pdq::run::{run, RunOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::max_relative_difference;

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
fn threads_reference(deck_path: &Path, dir: &Path) -> pdq::run::Summary {
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
