//! Bars as one-dimensional members (src/input/bars.rs): a bar carries E·A·ε whatever its area and the
//! lattice spacing, and a prestrained bar held at both ends pulls with E·A·ε_p.

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;

const E: f64 = 29.0e6; // psi
const LENGTH: f64 = 60.0; // in

/// A lone steel bar along x, spacing `dx` (horizon 3 dx), area `area`, held across everywhere,
/// fixed along x over its first 4 in; its last 4 in either pulled by `force` (lbf) or, with a
/// prestrain, also fixed. Solved by the implicit solve.
fn bar_deck(dx: f64, area: f64, force: f64, prestrain: f64) -> String {
    corrected_bar_deck(dx, area, force, prestrain, false)
}

/// [`bar_deck`], with the energy surface correction on or off.
fn corrected_bar_deck(dx: f64, area: f64, force: f64, prestrain: f64, correction: bool) -> String {
    let correction = if correction {
        "surface_correction = \"energy\"\n"
    } else {
        ""
    };
    let far_end = if prestrain == 0.0 {
        format!(
            "[[load]]\nname = \"pull\"\nregion = {{ shape = \"slab\", axis = \"x\", from = \"{} in\", to = \"{} in\" }}\ntotal_force = \"{force} 0 0 lbf\"\nhistory = {{ ramp = \"1 s\" }}\n",
            LENGTH - 4.0,
            LENGTH + 1.0
        )
    } else {
        format!(
            "[[boundary]]\nname = \"right\"\nregion = {{ shape = \"slab\", axis = \"x\", from = \"{} in\", to = \"{} in\" }}\nfixed = [\"x\"]\n",
            LENGTH - 4.0,
            LENGTH + 1.0
        )
    };
    format!(
        r#"units = "in-lbf-s"
[model]
name = "concrete"
horizon = "{horizon} in"
{correction}[lattice]
spacing = "{dx} in"
[materials.steel]
kind = "steel"
density = "490 lb/ft^3"
youngs_modulus = "{E} psi"
poisson_ratio = 0.3
yield_stretch = 0.01
[[bar]]
material = "steel"
area = "{area} in^2"
from = "0 0 0 in"
to = "{LENGTH} 0 0 in"
prestrain = {prestrain}
[[boundary]]
name = "across"
region = {{ shape = "slab", axis = "x", from = "-1 in", to = "{far} in" }}
fixed = ["y", "z"]
[[boundary]]
name = "left"
region = {{ shape = "slab", axis = "x", from = "-1 in", to = "4 in" }}
fixed = ["x"]
{far_end}[[probe]]
name = "a"
at = "20 0 0 in"
[[probe]]
name = "b"
at = "40 0 0 in"
[time]
duration = "1 s"
[solver]
kind = "implicit"
load_steps = 1
tolerance = 1e-10
[output]
progress = false
history_every = 1
"#,
        horizon = 3.0 * dx,
        far = LENGTH + 1.0,
    )
}

/// The last history row's values of `columns`.
fn solve(text: &str, columns: &[&str]) -> Vec<f64> {
    let scene = deck::parse(text, "bar.toml", "bar").unwrap();
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("pdq-bars-{}-{k}", std::process::id()));
    let options = RunOptions {
        output: Some(dir.clone()),
        quiet: true,
        threads: Some(1),
        ..Default::default()
    };
    run(&scene, &options).unwrap();
    let (header, rows) = pdq::lab::validate::read_history(&dir).unwrap();
    let _ = std::fs::remove_dir_all(dir);
    let last = rows.last().unwrap();
    columns
        .iter()
        .map(|c| last[header.iter().position(|h| h == c).unwrap()])
        .collect()
}

#[test]
fn a_bar_carries_e_a_strain_at_every_area_and_spacing() {
    let cases = [(1.0, 0.2), (1.0, 2.0), (0.5, 0.2), (2.0, 0.79)];
    for ((dx, area), correction) in cases.into_iter().zip([false, true, false, true]) {
        let force = 1000.0;
        let deck = corrected_bar_deck(dx, area, force, 0.0, correction);
        let u = solve(&deck, &["a_ux", "b_ux"]);
        // Probes sit on particles more than a horizon from both ends, 20 in apart (± a spacing).
        let strain = (u[1] - u[0]) / 20.0;
        let modulus = force / (area * strain);
        eprintln!("dx {dx} in, A {area} in²: E·A·ε gives E = {modulus:.5e} psi");
        assert!(
            (modulus / E - 1.0).abs() < 1e-5,
            "dx {dx}, A {area}: the bar's modulus is {modulus:e}, not {E:e}"
        );
    }
}

#[test]
fn a_prestrained_bar_held_at_both_ends_pulls_with_e_a_prestrain() {
    let (area, prestrain) = (0.5, 0.007);
    for dx in [1.0, 0.5] {
        let r = solve(
            &bar_deck(dx, area, 0.0, prestrain),
            &["reaction_left_x", "reaction_right_x", "a_ux"],
        );
        let pull = E * area * prestrain;
        eprintln!(
            "dx {dx}: reactions {:.1} and {:.1} lbf, E·A·ε_p = {pull:.1}",
            r[0], r[1]
        );
        // The bar pulls its left holder towards +x; the holder's reaction points to −x.
        assert!(
            (r[0] / -pull - 1.0).abs() < 1e-6 && (r[1] / pull - 1.0).abs() < 1e-6,
            "dx {dx}: reactions {r:?} against ±{pull}"
        );
        assert!(
            r[2].abs() < 1e-9,
            "the bar held at both ends stays put: {}",
            r[2]
        );
    }
}
