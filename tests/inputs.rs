//! Every example deck in `inputs/` parses and builds; the quick one runs and breaks bonds.

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;
use std::path::Path;

#[test]
fn every_example_deck_parses() {
    let mut n = 0;
    for entry in std::fs::read_dir("inputs").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = deck::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.ops.is_empty());
            n += 1;
        }
    }
    assert!(n >= 3, "expected the three example decks, found {n}");
}

#[test]
fn thesis_cantilever_deck_is_in_inch_pound_units() {
    let scene = deck::load(Path::new("inputs/cantilever_2in.toml")).unwrap();
    let c = &scene.materials[0];
    let e = c.quantity("youngs_modulus", pdq::model::Dimension::STRESS);
    assert_eq!(e, Ok(Some(3.605e6)));
    // 145 lb/ft³ as pound-mass: 145 / 1728 / 386.09 lbf·s²/in⁴.
    assert!((c.density / (145.0 / 1728.0 / 386.09) - 1.0).abs() < 1e-12);
    assert_eq!(scene.horizon, 6.0);
    let out = pdq::driver::run::check(&scene).unwrap();
    assert!(out.contains("37500"), "{out}");
}

#[test]
fn quick_example_runs_and_cracks() {
    let scene = deck::load(Path::new("inputs/pmb_block.toml")).unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-inputs-{}", std::process::id()));
    let s = run(
        &scene,
        &RunOptions {
            steps: None,
            output: Some(dir.clone()),
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.particles, 3900);
    assert!(s.broken > 0, "the notched block must crack");
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let header = history.lines().next().unwrap();
    for col in [
        "time",
        "kinetic_energy",
        "strain_energy",
        "broken_bonds",
        "tip_ux",
        "reaction_grip_right_x",
    ] {
        assert!(
            header.split(',').any(|c| c == col),
            "missing column {col}: {header}"
        );
    }
    assert_eq!(history.lines().count(), 1 + 1 + 2000 / 20);
    assert!(dir.join("frames.xdmf").exists() && dir.join("timing.txt").exists());
    // The grip moves at 0.5 m/s after a 5 µs ramp: its mean displacement is that motion.
    let names: Vec<&str> = header.split(',').collect();
    let last: Vec<f64> = history
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let at = |name: &str| last[names.iter().position(|&c| c == name).unwrap()];
    let expected = 0.5 * (at("time") - 2.5e-6);
    let moved = at("displacement_grip_right_x");
    assert!(
        (moved - expected).abs() < 1e-3 * expected,
        "grip moved {moved}, expected {expected}"
    );
    assert_eq!(at("displacement_grip_left_x"), 0.0);
    // Every run leaves its pictures; `pdq pictures` draws the same again.
    let pictures = [
        "energy.png",
        "broken_bonds.png",
        "load_displacement_grip_right_x.png",
        "reaction_grip_left_x.png",
        "probe_tip.png",
        "cracks_count.png",
        "cracks_area.png",
    ];
    for p in pictures {
        let file = dir.join("pictures").join(p);
        let bytes = std::fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000, "{p}");
    }
    assert!(dir.join("picture.png").exists(), "the damage picture");
    // Where the largest cracks are: the largest is drawn in dark red (140, 10, 10).
    let largest = dir.join("pictures/cracks_largest.png");
    let mut reader = png::Decoder::new(std::fs::File::open(&largest).unwrap())
        .read_info()
        .unwrap();
    let mut rgb = vec![0; reader.output_buffer_size()];
    reader.next_frame(&mut rgb).unwrap();
    let count = |c: [u8; 3]| rgb.chunks_exact(3).filter(|p| *p == c).count();
    assert!(count([140, 10, 10]) > 5000, "the largest crack is drawn");
    std::fs::remove_dir_all(dir.join("pictures")).unwrap();
    let again = pdq::output::pictures::redraw(&dir, "again").unwrap();
    for p in pictures {
        assert!(
            again.contains(&dir.join("pictures").join(p)),
            "{p} not redrawn"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Runs a variant of the example deck, quietly, into a fresh temporary directory.
fn run_variant(text: &str, name: &str) -> (pdq::driver::run::Summary, std::path::PathBuf) {
    let scene = deck::parse(text, &format!("pmb_block_{name}.toml"), name).unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-inputs-{name}-{}", std::process::id()));
    let s = run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    (s, dir)
}

/// A probe's `stop_beyond` ends the run at the first history row where the probe has moved
/// farther than that, with that row and a frame of that step as the last.
#[test]
fn a_run_stops_once_a_probe_has_moved_far_enough() {
    let text = std::fs::read_to_string("inputs/pmb_block.toml")
        .unwrap()
        .replace(
            "at = \"40 5 5 mm\"",
            "at = \"40 5 5 mm\"\nstop_beyond = \"0.1 mm\"",
        );
    let (s, dir) = run_variant(&text, "probe");
    assert_eq!(s.stopped_at_probe.as_deref(), Some("tip"));
    assert!(!s.stopped_at_broken);
    // The grip pulls at 0.5 m/s: the tip passes 0.1 mm well before the 2000 steps that take
    // it to 0.22 mm.
    assert!(
        s.steps < 2000 && s.steps.is_multiple_of(20),
        "stopped at step {}",
        s.steps
    );
    let (header, rows) = pdq::lab::validate::read_history(&dir).unwrap();
    let ux = header.iter().position(|c| c == "tip_ux").unwrap();
    let step = header.iter().position(|c| c == "step").unwrap();
    let (last, before) = (&rows[rows.len() - 1], &rows[rows.len() - 2]);
    assert_eq!(
        last[step] as u64, s.steps,
        "the stop step's row is the last"
    );
    assert!(
        last[ux] > 1e-4 && before[ux] <= 1e-4,
        "{} then {}",
        before[ux],
        last[ux]
    );
    for file in [
        format!("frames/frame_{:08}.h5", s.steps),
        format!("checkpoints/checkpoint_{:08}.h5", s.steps),
    ] {
        assert!(dir.join(&file).exists(), "{file} is written at the stop");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// `[time] stop_at_broken_bonds` ends the run at the first step with that many broken bonds,
/// with that step's history row as the last, and says so in the summary.
#[test]
fn a_run_stops_once_enough_bonds_have_broken() {
    let text = std::fs::read_to_string("inputs/pmb_block.toml")
        .unwrap()
        .replace("[time]\n", "[time]\nstop_at_broken_bonds = 40\n");
    let (s, dir) = run_variant(&text, "stop");
    assert!(s.stopped_at_broken, "the run must stop early");
    assert!(
        s.broken >= 40 && s.steps < 2000,
        "{} broken at step {}",
        s.broken,
        s.steps
    );
    // The last row read as the validation suite reads it.
    let last = |column: &str| pdq::lab::validate::last_of(&dir, column).unwrap();
    assert_eq!(
        last("step") as u64,
        s.steps,
        "the stop step's row is the last"
    );
    assert!(last("broken_bonds") >= 40.0);
    std::fs::remove_dir_all(dir).unwrap();
}
