//! The static start of an explicit run (`[time] static_until`): the run begins at the
//! implicit solve's equilibrium under the loads of that time, at rest; the same start on every
//! layout; a restart after it continues as a run that never stopped; what cannot be done is
//! refused on the [time] line.

mod common;

use common::{bar_deck, layout};
use pdq::driver::run::{RunOptions, Summary};
use std::path::{Path, PathBuf};

/// The bar of tests/implicit.rs (10 N ramped over 1 ms), explicit, started statically at
/// 0.5 ms and stepped `steps` times from there, with a checkpoint every 30 steps.
fn started_deck(model: &str, steps: u64) -> String {
    let text = bar_deck(model, "implicit");
    let solver = text.find("[solver]").unwrap();
    let boundary = text.find("[[boundary]]").unwrap();
    let text = format!("{}{}", &text[..solver], &text[boundary..]);
    text.replace(
        "duration = \"1 ms\"",
        &format!("steps = {steps}\nstatic_until = \"0.5 ms\""),
    )
    .replace(
        "history_every = 1",
        "history_every = 10\ncheckpoint_every = 30",
    )
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-static-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run_in(text: &str, dir: &Path, opts: RunOptions) -> Result<Summary, String> {
    common::run_quietly(text, "bar.toml", dir, opts)
}

/// The history's rows as (column → value) lookups.
fn rows(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    pdq::lab::validate::read_history(dir).unwrap()
}

fn at(header: &[String], row: &[f64], name: &str) -> f64 {
    row[header.iter().position(|c| c == name).unwrap()]
}

#[test]
fn the_run_starts_at_the_implicit_equilibrium_at_rest() {
    for model in ["pmb", "lps", "micropolar"] {
        // The implicit solve's second load step is t = 0.5 ms, the load 5 N.
        let solved = out_dir(&format!("{model}-implicit"));
        run_in(&bar_deck(model, "implicit"), &solved, RunOptions::default()).unwrap();
        let (h, r) = rows(&solved);
        let row = r.iter().find(|r| at(&h, r, "time") == 0.5e-3).unwrap();
        let static_tip = at(&h, row, "tip_ux");

        let started = out_dir(&format!("{model}-started"));
        let s = run_in(&started_deck(model, 60), &started, layout(1, [1, 1, 1])).unwrap();
        assert_eq!(s.steps, 60);
        let (h, r) = rows(&started);
        let first = &r[0];
        assert_eq!(
            at(&h, first, "time"),
            0.5e-3,
            "{model}: the run starts at static_until"
        );
        assert_eq!(
            at(&h, first, "load_pull"),
            5.0,
            "{model}: the load of that time"
        );
        assert_eq!(at(&h, first, "kinetic_energy"), 0.0, "{model}: at rest");
        let tip = at(&h, first, "tip_ux");
        assert!(
            (tip - static_tip).abs() <= 1e-6 * static_tip.abs(),
            "{model}: tip {tip:e} at the start, {static_tip:e} by the implicit solve"
        );
        // The load keeps rising slowly against the bar's periods: the bar follows it
        // quasi-statically, with kinetic energy a small part of the strain energy.
        let last = r.last().unwrap();
        let (kinetic, strain) = (
            at(&h, last, "kinetic_energy"),
            at(&h, last, "strain_energy"),
        );
        assert!(
            kinetic < 1e-3 * strain,
            "{model}: kinetic {kinetic:e} against strain {strain:e} after 60 steps"
        );
        eprintln!(
            "{model}: tip {tip:.6e} m at the static start (implicit solve {static_tip:.6e}); after 60 steps kinetic/strain energy {:.1e}",
            kinetic / strain
        );
        let _ = std::fs::remove_dir_all(solved);
        let _ = std::fs::remove_dir_all(started);
    }
}

#[test]
fn the_static_start_is_the_same_on_every_layout() {
    let text = started_deck("lps", 60);
    let one = out_dir("one");
    let two = out_dir("two");
    run_in(&text, &one, layout(1, [1, 1, 1])).unwrap();
    run_in(&text, &two, layout(2, [2, 1, 1])).unwrap();
    let (h, a) = rows(&one);
    let (_, b) = rows(&two);
    // The start is solved on the whole scene whatever the layout: bit-identical.
    assert!(a[0] == b[0], "first rows differ:\n{:?}\n{:?}", a[0], b[0]);
    // Stepping on two procCubes sums forces in another order (tests/wall_method.rs).
    for (ra, rb) in a.iter().zip(&b) {
        for (k, name) in h.iter().enumerate() {
            let scale = a.iter().map(|r| r[k].abs()).fold(0.0, f64::max);
            assert!(
                (ra[k] - rb[k]).abs() <= 1e-9 * scale.max(f64::MIN_POSITIVE),
                "{name}: {} on one procCube, {} on two",
                ra[k],
                rb[k]
            );
        }
    }
    let _ = std::fs::remove_dir_all(one);
    let _ = std::fs::remove_dir_all(two);
}

#[test]
fn a_restart_after_a_static_start_ends_bit_identical() {
    let text = started_deck("pmb", 60);
    let straight = out_dir("straight");
    run_in(&text, &straight, layout(2, [2, 1, 1])).unwrap();
    let resumed = out_dir("resumed");
    run_in(
        &text,
        &resumed,
        RunOptions {
            steps: Some(30),
            ..layout(2, [2, 1, 1])
        },
    )
    .unwrap();
    let r = run_in(
        &text,
        &resumed,
        RunOptions {
            restart: Some(resumed.join("checkpoints")),
            ..layout(2, [2, 1, 1])
        },
    )
    .unwrap();
    assert_eq!((r.first_step, r.steps), (30, 60));
    // The same checkpoint under a deck that starts elsewhere: refused.
    let e = run_in(
        &text.replace("\"0.5 ms\"", "\"0.4 ms\""),
        &resumed,
        RunOptions {
            restart: Some(resumed.join("checkpoints/checkpoint_00000030.h5")),
            ..layout(2, [2, 1, 1])
        },
    )
    .unwrap_err();
    assert!(
        e.contains("started at t = 5.0") && e.contains("static_until"),
        "{e}"
    );
    for file in ["final_positions.csv", "history.csv"] {
        let a = std::fs::read_to_string(straight.join(file)).unwrap();
        let b = std::fs::read_to_string(resumed.join(file)).unwrap();
        assert!(a == b, "{file} differs after the restart");
    }
    let _ = std::fs::remove_dir_all(straight);
    let _ = std::fs::remove_dir_all(resumed);
}

#[test]
fn what_a_static_start_cannot_do_is_refused_on_the_time_line() {
    let dir = out_dir("refused");
    let refused = |text: &str| -> String {
        run_in(text, &dir, layout(1, [1, 1, 1])).expect_err("must be refused")
    };
    let text = started_deck("pmb", 60);
    // Not before the end of the run.
    let e = refused(&text.replace("steps = 60", "duration = \"0.4 ms\""));
    assert!(
        e.contains("static_until") && e.contains("not before the end"),
        "{e}"
    );
    // Not a time.
    let e = refused(&text.replace("\"0.5 ms\"", "\"-1 ms\""));
    assert!(e.contains("static_until must be a time > 0"), "{e}");
    // With a quasi-static solver.
    let e = refused(&text.replace(
        "[[boundary]]",
        "[solver]\nkind = \"adr\"\nload_steps = 4\n[[boundary]]",
    ));
    assert!(e.contains("quasi-static [solver]"), "{e}");
    // With initial velocities.
    let e = refused(&format!(
        "{text}[[initial]]\nregion = {{ shape = \"slab\", axis = \"x\", from = \"20 mm\", to = \"40 mm\" }}\nvelocity = \"1 0 0 m/s\"\n"
    ));
    assert!(e.contains("at rest"), "{e}");
    // With temperature.
    let e = refused(&started_deck("thermal", 60));
    assert!(e.contains("temperature"), "{e}");
    // With periodic axes.
    let e = refused(&text.replace(
        "spacing = \"1 mm\"",
        "spacing = \"1 mm\"\nperiodic = [\"x\"]",
    ));
    assert!(e.contains("periodic"), "{e}");
    // A stop at broken bonds the static start already passed: at a critical stretch of
    // 1.2e-5 the static state at 5 N breaks 24 bonds at the load's and clamp's edges (and
    // converges); the run would stop after one step.
    let e = refused(
        &text
            .replace("critical_stretch = 5e-2", "critical_stretch = 1.2e-5")
            .replace("steps = 60", "steps = 60\nstop_at_broken_bonds = 1"),
    );
    assert!(
        e.contains("broke 24 bonds") && e.contains("stop_at_broken_bonds = 1"),
        "{e}"
    );
    // A load the structure cannot stand: the static solve does not converge.
    let e = refused(&text.replace("critical_stretch = 5e-2", "critical_stretch = 1e-7"));
    assert!(
        e.contains("did not converge") || e.contains("singular"),
        "{e}"
    );
    assert!(e.starts_with("bar.toml:"), "names the deck and line: {e}");
    eprintln!("{e}");
}
