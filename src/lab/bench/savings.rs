//! `pdq bench --savings`: what a scene saves by leaving a feature out.

use super::{bench_models, median, standard_deck, yardstick, BenchOptions};
use crate::input::{deck, setup};
use crate::model::{Model, ModelInfo, ModelVisitor};
use crate::parallel;
use crate::parallel::decomposition::{Procs, Walls};
use std::fmt::Write as _;

/// Steps of one deck on `threads` threads (layout auto, whole walls), with a shuffle check
/// every `shuffle_every` steps: µs per particle-step and the share of the state pass.
fn time_deck(
    text: &str,
    threads: usize,
    steps: u64,
    shuffle_every: u64,
) -> Result<(f64, f64), String> {
    let scene = deck::parse(text, "<bench>", "bench").map_err(|e| e.to_string())?;
    struct Visit<'a>(&'a deck::Scene, usize, u64, u64);
    impl ModelVisitor for Visit<'_> {
        type Output = Result<(f64, f64), String>;
        fn visit<M: Model>(self, model: M) -> Self::Output {
            let Visit(scene, threads, steps, shuffle_every) = self;
            let setup = setup::build(model, scene).map_err(|e| e.to_string())?;
            let n = setup.sim.particles.n_owned;
            let layout = parallel::layout(&setup, &Procs::Auto, threads, Walls::Whole)?;
            let cubes = parallel::thread_cubes(&setup, &layout);
            drop(setup);
            let timed =
                parallel::on_threads(cubes, |c| c.timed_steps_shuffling(steps, shuffle_every));
            let t = timed.into_iter().next().ok_or("no procCube")??;
            let state = t
                .timing
                .get(crate::engine::timing::Phase::State)
                .as_secs_f64();
            Ok((
                1e6 * t.seconds / (n as f64 * steps as f64),
                state / t.seconds,
            ))
        }
    }
    setup::with_model(&scene, Visit(&scene, threads, steps, shuffle_every))
        .map_err(|e| e.to_string())?
}

/// The registered model with a benchmark solid of which `has` holds (the first in registry
/// order), to show what one feature costs.
fn model_with(has: impl Fn(&ModelInfo) -> bool, feature: &str) -> Result<&'static str, String> {
    bench_models()
        .into_iter()
        .find(|m| has(m))
        .map(|m| m.name)
        .ok_or_else(|| format!("no registered model has {feature}"))
}

/// Generalized forces of a model that have velocities (translations and rotations).
fn second_order(m: &ModelInfo) -> usize {
    m.force.iter().map(|f| f.len).sum::<usize>() - m.first_order
}

/// `pdq bench --savings`: the standard scene with and without each feature a deck may leave
/// out, alternating `rounds` times; medians and the saving. The plain scene is the
/// yardstick's model (PMB); the features are those of the first models that have them.
pub(super) fn savings(opts: &BenchOptions) -> Result<String, String> {
    let (n, steps) = (opts.n, opts.steps);
    let plain = yardstick::MODEL;
    let state = model_with(|m| !m.state.is_empty(), "a state pass")?;
    let rotating = model_with(|m| second_order(m) > 3, "rotation DOFs")?;
    let pmb = standard_deck(plain, n, steps)?;
    let unbreakable = pmb.replace("critical_stretch = 0.0005\n", "");
    let shuffling = format!("{pmb}[parallel]\nshuffle_every = 10\n");
    let contact = format!("{pmb}[pair]\nlaw = \"contact\"\n");
    // (feature, deck using it, threads, shuffle_every, deck without it, what differs)
    let pairs: [(&str, String, usize, u64, String, String); 5] = [
        ("damage checks", pmb.clone(), 1, 0, unbreakable, format!("{plain} with critical stretch 0.0005 against none (the engine drops the broken flags and break tests from the bond loop)")),
        ("state pass", standard_deck(state, n, steps)?, 1, 0, pmb.clone(), format!("{state} against {plain}, same scene: the state pass, its two exchanges and the state-based law")),
        ("rotation DOFs", standard_deck(rotating, n, steps)?, 1, 0, pmb.clone(), format!("{rotating} (6 DOFs, moments) against {plain} (3 DOFs), same stiffness; the difference includes the larger law")),
        ("contact pairs", contact, 1, 0, pmb.clone(), format!("{plain} with [pair] law = \"contact\" (the non-bonded pass: list builds from the cells, the crack-face check, the contact force) against no [pair], which skips the pass with one branch per step")),
        ("shuffling", shuffling, 2, 10, pmb, format!("{plain} on 2 threads with shuffle_every = 10 (cells widened by the 0.25 skin) against small-motion mode")),
    ];
    let mut out = String::new();
    let mut table = String::from("| feature | with it (µs per particle-step) | without (µs) | saving | runs | what is compared |\n|---|---|---|---|---|---|\n");
    for (feature, used, threads, every, unused, what) in &pairs {
        let (mut with, mut without, mut share) = (Vec::new(), Vec::new(), Vec::new());
        for r in 0..opts.rounds.max(1) {
            // Alternate which goes first, so a slow spell of the machine hits both.
            let (a, b) = if r % 2 == 0 {
                let a = time_deck(used, *threads, steps, *every)?;
                (a, time_deck(unused, *threads, steps, 0)?)
            } else {
                let b = time_deck(unused, *threads, steps, 0)?;
                (time_deck(used, *threads, steps, *every)?, b)
            };
            let _ = writeln!(
                out,
                "bench saving feature={} round={r} with_us={:.4} without_us={:.4}",
                feature.replace(' ', "_"),
                a.0,
                b.0
            );
            with.push(a.0);
            without.push(b.0);
            share.push(a.1);
        }
        let (w, wo) = (median(with.clone()), median(without.clone()));
        let saving = 100.0 * (w - wo) / w;
        let _ = writeln!(
            out,
            "bench saving median feature={} with_us={w:.4} without_us={wo:.4} saving_percent={saving:.1} runs={}",
            feature.replace(' ', "_"),
            with.len()
        );
        let mut what = what.to_string();
        if *feature == "state pass" {
            let _ = write!(
                what,
                "; the state pass alone is {:.0} % of the {state} step",
                100.0 * median(share)
            );
        }
        let _ = writeln!(
            table,
            "| {feature} | {w:.4} | {wo:.4} | {saving:.1} % | {} | {what} |",
            with.len()
        );
    }
    out.push('\n');
    out.push_str(&table);
    Ok(out)
}
