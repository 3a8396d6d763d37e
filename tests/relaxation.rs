//! Adaptive dynamic relaxation: equilibrium at every load step (residual below the tolerance,
//! reactions balancing the load), a linear response proportional to the load, the same answer
//! on one and on several procCubes, for PMB, LPS and micropolar; models it cannot relax are
//! refused.

mod common;

use common::bar_deck;
use pdq::driver::run::{run, RunOptions, Summary};
use pdq::input::deck;
use pdq::parallel::decomposition::{Procs, Walls};

fn relax(model: &str, threads: usize, procs: [usize; 3]) -> (Summary, Vec<Vec<f64>>) {
    let scene = deck::parse(&bar_deck(model, "adr"), "bar.toml", "bar").unwrap();
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "pdq-adr-{model}-{threads}-{}-{k}",
        std::process::id()
    ));
    let s = run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            threads: Some(threads),
            procs: Some(Procs::Given(procs)),
            walls: Some(Walls::Whole),
            ..Default::default()
        },
    )
    .unwrap();
    let (header, rows) = pdq::lab::validate::read_history(&dir).unwrap();
    let col = |name: &str| header.iter().position(|c| c == name).unwrap();
    let picked = rows
        .iter()
        .map(|r| {
            [
                "load_pull",
                "reaction_left_x",
                "tip_ux",
                "iterations",
                "residual",
            ]
            .iter()
            .map(|c| r[col(c)])
            .collect()
        })
        .collect();
    let _ = std::fs::remove_dir_all(dir);
    (s, picked)
}

#[test]
fn each_load_step_ends_in_equilibrium_with_a_response_proportional_to_the_load() {
    for model in ["pmb", "lps", "micropolar"] {
        let (s, rows) = relax(model, 1, [1, 1, 1]);
        assert_eq!(s.steps, 4);
        assert_eq!(s.converged_steps, 4, "{model}: every load step converges");
        let tip_at_full = rows[4][2];
        for (k, r) in rows.iter().enumerate().skip(1) {
            let (load, reaction, tip, iterations, residual) = (r[0], r[1], r[2], r[3], r[4]);
            assert!(residual <= 1e-9, "{model} step {k}: residual {residual:e}");
            // The support holds what the load pulls.
            assert!(
                (load + reaction).abs() <= 1e-6 * load,
                "{model} step {k}: load {load} against reaction {reaction}"
            );
            // Linear elasticity, small strain: the tip moves in proportion to the load.
            let expected = tip_at_full * k as f64 / 4.0;
            assert!(
                (tip - expected).abs() <= 1e-4 * tip_at_full,
                "{model} step {k}: tip {tip:e}, proportional {expected:e}"
            );
            eprintln!(
                "{model} load step {k}: {load:.0} N, tip {tip:.4e} m, {iterations} iterations, residual {residual:.1e}"
            );
        }
        eprintln!(
            "{model}: {} force evaluations for 4 load steps",
            s.force_evaluations
        );
    }
}

#[test]
fn relaxation_gives_the_same_equilibrium_on_several_procubes() {
    let (_, one) = relax("pmb", 1, [1, 1, 1]);
    let (_, two) = relax("pmb", 2, [2, 1, 1]);
    let (a, b) = (one[4][2], two[4][2]);
    eprintln!("tip on 1 procCube {a:.10e}, on 2 {b:.10e}");
    // Both stop within the tolerance of the same equilibrium.
    assert!((a - b).abs() <= 1e-6 * a.abs(), "{a:e} against {b:e}");
}

#[test]
fn relaxation_refuses_a_temperature_model() {
    let text = bar_deck("thermal", "adr");
    let scene = deck::parse(&text, "bar.toml", "bar").unwrap();
    let e = run(
        &scene,
        &RunOptions {
            quiet: true,
            output: Some(
                std::env::temp_dir().join(format!("pdq-adr-thermal-{}", std::process::id())),
            ),
            ..Default::default()
        },
    )
    .expect_err("thermal cannot be relaxed");
    assert!(e.contains("bar.toml:") && e.contains("first-order"), "{e}");
}

#[test]
fn a_relaxation_restarted_between_load_steps_ends_bit_identical() {
    let text = bar_deck("pmb", "adr").replace(
        "history_every = 1",
        "history_every = 1\ncheckpoint_every = 2",
    );
    let scene = deck::parse(&text, "bar.toml", "bar").unwrap();
    let dir = |name: &str| {
        std::env::temp_dir().join(format!("pdq-adr-restart-{name}-{}", std::process::id()))
    };
    let opts = |out: std::path::PathBuf,
                steps: Option<u64>,
                restart: Option<std::path::PathBuf>| RunOptions {
        output: Some(out),
        quiet: true,
        steps,
        restart,
        ..Default::default()
    };
    let (straight, resumed) = (dir("straight"), dir("resumed"));
    run(&scene, &opts(straight.clone(), None, None)).unwrap();
    run(&scene, &opts(resumed.clone(), Some(2), None)).unwrap();
    let r = run(&scene, &opts(resumed.clone(), None, Some(resumed.clone()))).unwrap();
    assert_eq!((r.first_step, r.steps), (2, 4));
    for file in ["final_positions.csv", "history.csv"] {
        let a = std::fs::read_to_string(straight.join(file)).unwrap();
        let b = std::fs::read_to_string(resumed.join(file)).unwrap();
        assert!(a == b, "{file} differs after restarting between load steps");
    }
    let _ = std::fs::remove_dir_all(straight);
    let _ = std::fs::remove_dir_all(resumed);
}
