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

/// The tests' solid, in the model's own keys (its sample, [`pdq::model::Model::sample`]): a
/// rock of K = 14.9 GPa at ν = ¼ (E = 22.35 GPa), 2200 kg/m³, bonds breaking at `s0`;
/// `full`: with the model's optional terms (thermal expansion, relative-rotation stiffness).
#[allow(dead_code)]
pub fn rock(model: &str, s0: f64, full: bool) -> (pdq::model::ModelInfo, pdq::model::Sample) {
    let info = pdq::models::find(model).unwrap_or_else(|| panic!("no model '{model}'"));
    let sample = info
        .sample(&pdq::model::SampleOf::Solid {
            youngs_modulus: 22.35e9,
            density: 2200.0,
            critical_stretch: s0,
            steel: false,
            full,
        })
        .unwrap_or_else(|| panic!("model '{model}' has no sample material"));
    (info, sample)
}

/// `[model.options]` with these lines, or nothing.
fn options_table(options: &str) -> String {
    if options.is_empty() {
        String::new()
    } else {
        format!("[model.options]\n{options}")
    }
}

/// The notched-pull deck of the layout tests (`tests/decks/notched_pull.toml`, PMB) made over
/// for any registered model with its full sample rock: a state pass (`lps`), rotations with
/// a relative-rotation stiffness (`micropolar`); a model with first-order DOFs (`thermal`)
/// also gets heat generated in one slab and held cold in another, conducted across procCube
/// faces into thermal expansion. Each still cracks within its 500 steps.
#[allow(dead_code)]
pub fn model_pull_deck(model: &str) -> String {
    let base = include_str!("../decks/notched_pull.toml");
    let rock_lines =
        "density = \"2200 kg/m^3\"\nbulk_modulus = \"14.9 GPa\"\ncritical_stretch = 0.0005\n";
    assert!(base.contains(rock_lines) && base.contains("name = \"pmb\""));
    let (info, sample) = rock(model, 0.0005, true);
    let mut text = base
        .replace("name = \"pmb\"", &format!("name = \"{model}\""))
        .replace(rock_lines, &sample.material)
        // `[model.options]` must follow `[model]`.
        .replace(
            "[lattice]",
            &format!("{}[lattice]", options_table(&sample.options)),
        );
    if info.first_order > 0 {
        text.push_str("[[load]]\nname = \"heater\"\nregion = { shape = \"slab\", axis = \"y\", from = \"0 mm\", to = \"2 mm\" }\nheat_source = 2e12\n[[boundary]]\nname = \"cold\"\nregion = { shape = \"box\", min = \"5 8 0 mm\", max = \"25 10 10 mm\" }\ntemperature = 0.0\n");
    }
    text
}

/// A bar 40 × 6 × 6 mm of the model's plain sample rock, held at x ≤ 3 mm and pulled by 10 N
/// at x ≥ 37 mm in four load steps solved by `kind` (`adr` or `implicit`) to 10⁻⁹
/// (tests/relaxation.rs, tests/implicit.rs).
#[allow(dead_code)]
pub fn bar_deck(model: &str, kind: &str) -> String {
    // The full sample: LPS at ν ≠ ¼ (its dilatation term on), micropolar with kappa.
    let (_, sample) = rock(model, 0.05, true);
    let (options, material) = (options_table(&sample.options), sample.material);
    format!(
        r#"units = "SI"
[model]
name = "{model}"
horizon = "3.015 mm"
{options}[lattice]
spacing = "1 mm"
[materials.rock]
{material}[[geometry]]
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

/// inputs/lj_melt.toml at 8 × 8 × 8 fcc cells (2,048 atoms), 200 steps, final state written.
#[allow(dead_code)]
pub fn lj_deck() -> String {
    let text = std::fs::read_to_string("inputs/lj_melt.toml").unwrap();
    for old in [
        "max = [33.5, 33.5, 33.5]",
        "steps = 100",
        "progress = false",
    ] {
        assert!(text.contains(old), "inputs/lj_melt.toml lost '{old}'");
    }
    text.replace("max = [33.5, 33.5, 33.5]", "max = [13.4, 13.4, 13.4]")
        .replace("steps = 100", "steps = 200")
        .replace("progress = false", "progress = false\nfinal_state = true")
        + "\n[parallel]\nshuffle_every = 10\n"
}

/// Final positions by id.
#[allow(dead_code)]
pub fn final_positions(dir: &std::path::Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(dir.join("final_positions.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[1], v[2], v[3]]
        })
        .collect()
}

/// Largest distance between the same atom in two runs, over periodic images of a cube of side
/// `period` (an atom may be wrapped into the box in one run and not yet in another).
#[allow(dead_code)]
pub fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]], period: f64) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| {
            (0..3).map(move |k| {
                let d = x[k] - y[k];
                (d - period * (d / period).round()).abs()
            })
        })
        .fold(0.0, f64::max)
}

/// The head of an lj deck: `cells`³ fcc cells at reduced density `density` (mass 1 per atom),
/// periodic along x, y and z, material `argon`, bondless point particles, the box's upper faces
/// `trim` below the whole cells (half-open boxes leave their sites out either way). The
/// sections that follow are the test's.
#[allow(dead_code)]
pub fn fcc_box(density: f64, cells: usize, trim: f64) -> String {
    let a = (4.0 / density).cbrt();
    format!(
        r#"units = "lj"
[model]
name = "point"
[lattice]
kind = "fcc"
density = {density}
periodic = ["x", "y", "z"]
[materials.argon]
density = {density}
[[geometry]]
shape = "box"
material = "argon"
min = [0, 0, 0]
max = [{l}, {l}, {l}]
"#,
        l = cells as f64 * a - trim
    )
}
