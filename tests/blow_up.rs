//! A run whose time step is forced above the stable bound stops with a message naming the
//! step, the particle and the likely cause, and leaves a frame and a checkpoint of the state.

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;

#[test]
fn a_time_step_above_the_bound_stops_the_run_with_a_diagnosis_and_inspection_files() {
    let text = include_str!("decks/notched_pull.toml")
        .replace("steps = 500", "steps = 500\ndt = \"1 us\"\nforce_dt = true")
        .replace("history_every = 100", "history_every = 10")
        // Bonds that never break: the instability must be caught, not arrested by fracture.
        .replace("critical_stretch = 0.0005", "critical_stretch = 1000.0");
    let scene = deck::parse(&text, "pull.toml", "pull").unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-blow-up-{}", std::process::id()));
    let e = run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            ..Default::default()
        },
    )
    .expect_err("the run must stop");
    eprintln!("{e}");
    assert!(
        e.contains("blew up at step") && e.contains("particle"),
        "{e}"
    );
    assert!(
        e.contains("× the stable bound") && e.contains("lower dt"),
        "{e}"
    );
    let step: u64 = e
        .split("at step ")
        .nth(1)
        .and_then(|s| s.split(':').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!(step < 500, "caught before the end");
    let frame = dir.join(format!("frames/frame_{step:08}.h5"));
    let checkpoint = dir.join(format!("checkpoints/checkpoint_{step:08}.h5"));
    assert!(frame.exists() && e.contains(frame.to_str().unwrap()), "{e}");
    assert!(
        checkpoint.exists() && e.contains(checkpoint.to_str().unwrap()),
        "{e}"
    );
    // The inspection checkpoint reads back.
    let c = pdq::output::checkpoint::Checkpoint::read(&checkpoint).unwrap();
    assert_eq!(c.state.step, step);
    let _ = std::fs::remove_dir_all(dir);
}
