//! Layout invariance of the non-bonded pass (issue 23): the LJ melt over 200 steps, its
//! neighbour lists rebuilt (atoms migrating to their new procCubes) as atoms move and a
//! shuffle every 10 steps besides,
//! follows the same trajectory to round-off on 1, 2 and 4 procCubes on threads (the MPI ranks'
//! version is in tests/mpi_runs.rs).

use crate::common::{final_positions, layout, lj_deck, max_distance, run_quietly};

#[test]
fn the_lj_melt_is_the_same_on_1_2_and_4_threads() {
    let text = lj_deck();
    let base = std::env::temp_dir().join(format!("pdq-md-layouts-{}", std::process::id()));
    let one = base.join("one");
    run_quietly(&text, "lj.toml", &one, layout(1, [1, 1, 1])).unwrap();
    let reference = final_positions(&one);
    assert_eq!(reference.len(), 2048);
    let period = 8.0 * (4.0f64 / 0.8442).cbrt();
    // The atoms moved: the comparison is of a trajectory, not of a lattice.
    let start = pdq::input::setup::build_as::<pdq::models::point::Point>(
        &pdq::input::deck::parse(&text, "lj.toml", "lj").unwrap(),
    )
    .unwrap()
    .sim
    .particles
    .x0;
    let moved = max_distance(&reference, &start, period);
    assert!(moved > 0.3, "atoms moved at most {moved}");
    let history = std::fs::read_to_string(one.join("history.csv")).unwrap();
    for (threads, procs) in [(2, [2, 1, 1]), (4, [2, 2, 1]), (4, [1, 2, 2])] {
        let dir = base.join(format!("{procs:?}"));
        run_quietly(&text, "lj.toml", &dir, layout(threads, procs)).unwrap();
        let d = max_distance(&reference, &final_positions(&dir), period);
        eprintln!("{threads} threads {procs:?}: positions within {d:.2e} of one thread's");
        assert!(d < 1e-9, "{procs:?}: positions differ by {d:e}");
        // Atoms did change procCube: the lists were rebuilt, each by a migration.
        let timing = std::fs::read_to_string(dir.join("timing.txt")).unwrap();
        let line = timing
            .lines()
            .find(|l| l.starts_with("neighbour lists:"))
            .unwrap_or_else(|| panic!("no neighbour-list line in timing.txt:\n{timing}"));
        let numbers: Vec<u64> = line
            .split(|c: char| !c.is_ascii_digit())
            .filter_map(|w| w.parse().ok())
            .collect();
        assert!(
            numbers.len() == 1 && numbers[0] > 0 && line.contains("by migration"),
            "{procs:?}: {line}"
        );
        let other = std::fs::read_to_string(dir.join("history.csv")).unwrap();
        assert_eq!(other.lines().count(), history.lines().count());
    }
    // The same layout again: bit-identical.
    let again = base.join("again");
    run_quietly(&text, "lj.toml", &again, layout(1, [1, 1, 1])).unwrap();
    assert!(final_positions(&again) == reference, "one thread twice");
    std::fs::remove_dir_all(&base).ok();
}

/// The melt with free faces along z (periodic along x and y only): procCubes cut across a
/// non-periodic axis, where a procCube has no neighbour on one side, keep every atom once and
/// follow one thread's trajectory.
#[test]
fn the_lj_melt_with_free_faces_is_the_same_cut_across_them() {
    let text = lj_deck();
    let periodic = r#"periodic = ["x", "y", "z"]"#;
    assert!(
        text.contains(periodic),
        "inputs/lj_melt.toml lost '{periodic}'"
    );
    let text = text.replace(periodic, r#"periodic = ["x", "y"]"#);
    let base = std::env::temp_dir().join(format!("pdq-md-free-{}", std::process::id()));
    let one = base.join("one");
    run_quietly(&text, "lj.toml", &one, layout(1, [1, 1, 1])).unwrap();
    let reference = final_positions(&one);
    assert_eq!(reference.len(), 2048);
    let period = 8.0 * (4.0f64 / 0.8442).cbrt();
    for (threads, procs) in [(2, [1, 1, 2]), (4, [2, 1, 2])] {
        let dir = base.join(format!("{procs:?}"));
        run_quietly(&text, "lj.toml", &dir, layout(threads, procs)).unwrap();
        let last = final_positions(&dir);
        assert_eq!(last.len(), 2048, "{procs:?}: atoms lost or doubled");
        let d = max_distance(&reference, &last, period);
        eprintln!("{threads} threads {procs:?}, free z faces: positions within {d:.2e}");
        assert!(d < 1e-9, "{procs:?}: positions differ by {d:e}");
        let timing = std::fs::read_to_string(dir.join("timing.txt")).unwrap();
        assert!(
            timing.contains("by migration") && !timing.contains("lists: 0 rebuilds"),
            "{procs:?}: no rebuild by migration:\n{timing}"
        );
    }
    std::fs::remove_dir_all(&base).ok();
}
