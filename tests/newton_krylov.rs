//! The matrix-free Newton solve (`[solver] kind = "newton_krylov"`, `src/solve/krylov.rs`):
//! the factored solve's deflections on the suite's quick cantilevers, on one procCube and on
//! two; the coarse level of its preconditioner changes the iterations, not the answer;
//! bit-identical run after run; and a solve held short of its iterations is reported
//! unconverged.

mod common;

use common::bar_deck;
use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;
use pdq::lab::validate::{self, ElasticSolver, Level};
use std::path::Path;

fn out(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("pdq-nk-{name}-{}", std::process::id()))
}

/// The quick cantilevers by the factored tangent (one thread) and matrix-free (one thread and
/// two): the deflection under the load to 1e-6 relative. Both solve to the cases' 1e-9.
#[test]
fn the_matrix_free_solve_gives_the_factored_deflections_on_the_quick_cantilevers() {
    let dir = Path::new("validation");
    let load = |s| validate::cases(dir, Level::Quick, s).unwrap().leak() as &'static [_];
    let (factored, free) = (
        load(ElasticSolver::Implicit),
        load(ElasticSolver::NewtonKrylov),
    );
    for name in ["cantilever_pmb", "cantilever_lps", "cantilever_micropolar"] {
        let pick = |cases: &'static [validate::Case]| cases.iter().find(|c| c.name == name);
        let (a, b) = (pick(factored).unwrap(), pick(free).unwrap());
        assert!(a.deck.contains("kind = \"implicit\""), "{name}");
        assert!(b.deck.contains("kind = \"newton_krylov\""), "{name}");
        let reference = validate::run_case(a, &out(&format!("{name}-factored")), 1).unwrap();
        assert_eq!(
            reference.converged,
            Some(true),
            "{name}: the factored solve converges"
        );
        for threads in [1, 2] {
            let o = validate::run_case(b, &out(&format!("{name}-free{threads}")), threads).unwrap();
            let difference = (o.measured - reference.measured).abs() / reference.measured.abs();
            eprintln!(
                "{name}: {:.10e} factored ({} evaluations), {:.10e} matrix-free on {threads} thread(s) ({} evaluations): {difference:.1e} apart",
                reference.measured, reference.force_evaluations, o.measured, o.force_evaluations
            );
            assert_eq!(
                o.converged,
                Some(true),
                "{name}, {threads} thread(s): converged"
            );
            assert!(
                difference <= 1e-6,
                "{name}, {threads} thread(s): {difference:e} apart"
            );
        }
    }
}

/// The quick beams matrix-free with the two-level preconditioner (the default) and with the
/// diagonal alone: the same deflection to 1e-6, and the coarse level, 162 force evaluations a
/// load step to measure, pays for itself at once on a beam in bending (the diagonal alone
/// needed 693 and 1,869 evaluations here, the two levels 289 and 302, 2026-12-07).
#[test]
fn the_coarse_level_cuts_the_iterations_and_keeps_the_deflection() {
    use validate::case_file::load_with;
    let diagonal_only = |deck: &mut toml::Table| match deck.get_mut("solver") {
        Some(toml::Value::Table(t)) => {
            t.insert("preconditioner".into(), "diagonal".into());
            Ok(())
        }
        _ => Err("no [solver]".to_string()),
    };
    for name in ["cantilever_pmb", "simply_supported_pmb"] {
        let path = Path::new("validation").join(format!("{name}.toml"));
        let (solver, quick) = (ElasticSolver::NewtonKrylov, Level::Quick);
        let two_level = load_with(&path, quick, solver, None).unwrap();
        let diagonal = load_with(&path, quick, solver, Some(&diagonal_only)).unwrap();
        assert!(
            two_level.deck.contains("kind = \"newton_krylov\""),
            "{name}: matrix-free"
        );
        assert!(
            diagonal.deck.contains("preconditioner = \"diagonal\""),
            "{name}"
        );
        let a = validate::run_case(&two_level, &out(&format!("{name}-two-level")), 1).unwrap();
        let b = validate::run_case(&diagonal, &out(&format!("{name}-diagonal")), 1).unwrap();
        let difference = (a.measured - b.measured).abs() / b.measured.abs();
        eprintln!(
            "{name}: two levels {:.10e} in {} evaluations, diagonal {:.10e} in {}: {difference:.1e} apart",
            a.measured, a.force_evaluations, b.measured, b.force_evaluations
        );
        assert_eq!(
            (a.converged, b.converged),
            (Some(true), Some(true)),
            "{name}"
        );
        assert!(difference <= 1e-6, "{name}: {difference:e} apart");
        assert!(
            2 * a.force_evaluations < b.force_evaluations,
            "{name}: the coarse level took {} evaluations, the diagonal alone {}",
            a.force_evaluations,
            b.force_evaluations
        );
    }
}

/// Runs the bar deck; its final positions.
fn positions(text: &str, threads: usize, tag: &str) -> Result<(String, bool), String> {
    let scene = deck::parse(text, "bar.toml", "bar").unwrap();
    let dir = out(tag);
    let s = run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            threads: Some(threads),
            ..Default::default()
        },
    )?;
    let p = std::fs::read_to_string(dir.join("final_positions.csv")).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    Ok((p, s.solve_converged() == Some(true)))
}

#[test]
fn the_matrix_free_solve_is_bit_identical_run_after_run() {
    for model in ["pmb", "lps"] {
        let text = bar_deck(model, "newton_krylov");
        let (a, ok) = positions(&text, 2, &format!("det-a-{model}")).unwrap();
        let (b, _) = positions(&text, 2, &format!("det-b-{model}")).unwrap();
        assert!(ok, "{model}: converged");
        assert!(
            a == b,
            "{model}: two runs of the same deck on the same layout differ"
        );
    }
}

/// One CG iteration per Newton iteration cannot reach 1e-9 in three Newton iterations: the
/// run says so (not converged), it does not pass as a solution.
#[test]
fn a_matrix_free_solve_short_of_iterations_is_unconverged() {
    let text = bar_deck("pmb", "newton_krylov").replace(
        "tolerance = 1e-9",
        "tolerance = 1e-9\nmax_iterations = 3\nkrylov_iterations = 1",
    );
    assert!(
        text.contains("krylov_iterations = 1"),
        "the bar deck's [solver] changed"
    );
    let (_, ok) = positions(&text, 1, "short").unwrap();
    assert!(!ok, "one CG iteration a step reported converged");
}
