//! Helpers shared by the integration tests that compare runs.

/// Largest difference between two position sets, relative to the largest coordinate.
#[allow(dead_code)]
pub fn max_relative_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len(), "different particle counts");
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
        / scale
}

/// The notched-pull deck of the layout tests (`tests/decks/notched_pull.toml`, PMB) made over
/// for another model: the state pass (`lps`), rotations with a relative-rotation stiffness
/// (`micropolar`), or heat generated in one slab, held cold in another and conducted across
/// procCube faces into thermal expansion (`thermal`). Each still cracks within its 500 steps.
#[allow(dead_code)]
pub fn model_pull_deck(model: &str) -> String {
    let base = include_str!("../decks/notched_pull.toml");
    let rock =
        "density = \"2200 kg/m^3\"\nbulk_modulus = \"14.9 GPa\"\ncritical_stretch = 0.0005\n";
    assert!(base.contains(rock) && base.contains("name = \"pmb\""));
    let (material, extra) = match model {
        "lps" => (
            "density = \"2200 kg/m^3\"\nbulk_modulus = \"14.9 GPa\"\npoisson_ratio = 0.3\ncritical_stretch = 0.0005\n",
            "",
        ),
        "micropolar" => (
            "density = \"2200 kg/m^3\"\nyoungs_modulus = \"26.8 GPa\"\npoisson_ratio = 0.2\ncritical_stretch = 0.0005\n",
            "[model.options]\nkappa = 0.05\n",
        ),
        "thermal" => (
            "density = \"2200 kg/m^3\"\nbulk_modulus = \"14.9 GPa\"\ncritical_stretch = 0.0005\nthermal_conductivity = 2.0\nspecific_heat = 900.0\nthermal_expansion = 1e-5\n",
            "[[load]]\nname = \"heater\"\nregion = { shape = \"slab\", axis = \"y\", from = \"0 mm\", to = \"2 mm\" }\nheat_source = 2e12\n[[boundary]]\nname = \"cold\"\nregion = { shape = \"box\", min = \"5 8 0 mm\", max = \"25 10 10 mm\" }\ntemperature = 0.0\n",
        ),
        other => panic!("no pull deck for model '{other}'"),
    };
    let text = base
        .replace("name = \"pmb\"", &format!("name = \"{model}\""))
        .replace(rock, material);
    // `[model.options]` must follow `[model]`; the other additions go at the end.
    if extra.starts_with("[model.options]") {
        text.replace("[lattice]", &format!("{extra}[lattice]"))
    } else {
        format!("{text}{extra}")
    }
}

/// A bar 40 × 6 × 6 mm held at x ≤ 3 mm and pulled by 10 N at x ≥ 37 mm in four load steps
/// solved by `kind` (`adr` or `implicit`) to 10⁻⁹ (tests/relaxation.rs, tests/implicit.rs).
#[allow(dead_code)]
pub fn bar_deck(model: &str, kind: &str) -> String {
    let material = match model {
        "micropolar" => "youngs_modulus = \"22.35 GPa\"\npoisson_ratio = 0.2\n",
        "lps" => "bulk_modulus = \"14.9 GPa\"\npoisson_ratio = 0.3\n",
        _ => "bulk_modulus = \"14.9 GPa\"\n",
    };
    format!(
        r#"units = "SI"
[model]
name = "{model}"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.rock]
density = "2200 kg/m^3"
{material}critical_stretch = 0.05
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "40 6 6 mm"
[time]
duration = "1 ms"
[solver]
kind = "{kind}"
load_steps = 4
tolerance = 1e-9
[[boundary]]
name = "left"
region = {{ shape = "slab", axis = "x", from = "0 mm", to = "3 mm" }}
fixed = ["all"]
[[load]]
name = "pull"
region = {{ shape = "slab", axis = "x", from = "37 mm", to = "40 mm" }}
total_force = "10 0 0 N"
history = {{ ramp = "1 ms" }}
[[probe]]
name = "tip"
at = "39 3 3 mm"
[output]
progress = false
history_every = 1
final_state = true
"#
    )
}

/// Runs deck `text` (named `name` in messages) quietly into `dir`, with `opts` otherwise.
#[allow(dead_code)]
pub fn run_quietly(
    text: &str,
    name: &str,
    dir: &std::path::Path,
    opts: pdq::driver::run::RunOptions,
) -> Result<pdq::driver::run::Summary, String> {
    let scene = pdq::input::deck::parse(text, name, "test").map_err(|e| e.to_string())?;
    pdq::driver::run::run(
        &scene,
        &pdq::driver::run::RunOptions {
            output: Some(dir.to_path_buf()),
            quiet: true,
            ..opts
        },
    )
}

/// `threads` procCubes laid out as `procs`, whole walls.
#[allow(dead_code)]
pub fn layout(threads: usize, procs: [usize; 3]) -> pdq::driver::run::RunOptions {
    pdq::driver::run::RunOptions {
        threads: Some(threads),
        procs: Some(pdq::parallel::decomposition::Procs::Given(procs)),
        walls: Some(pdq::parallel::decomposition::Walls::Whole),
        ..Default::default()
    }
}
