//! Malformed decks fed to the real `pdq check`: each must fail cleanly (non-zero exit,
//! `error: <file>:<line>: <message>` on stderr, no panic) with a message that names the problem
//! and, where the problem sits on a known line, that line.
//!
//! Every case is a small edit of [`BASE`], a valid 6 × 6 × 6 block that checks in milliseconds.
//! Expected lines are found in the edited deck text, never hard-coded, so the base deck may
//! change freely.

use std::path::PathBuf;
use std::process::Command;

/// A valid deck: 216 particles 1 mm apart, clamped at the bottom layer.
const BASE: &str = r#"# A 6 x 6 x 6 block of particles, 1 mm apart, clamped at the bottom.
title = "deck_errors base"
units = "SI"

[model]
name = "pmb"
horizon = "3.015 mm"

[lattice]
spacing = "1 mm"

[materials.mortar]
density = "2200 kg/m^3"
youngs_modulus = "30 GPa"
critical_stretch = 0.0005

[[geometry]]
shape = "box"
material = "mortar"
min = "0 0 0 mm"
max = "6 6 6 mm"

[time]
steps = 10
safety_factor = 0.8

[[boundary]]
name = "clamp"
region = { shape = "slab", axis = "z", from = "0 mm", to = "1 mm" }
fixed = ["all"]

[output]
progress = false
"#;

/// The boundary's region in [`BASE`], for cases that swap it.
const CLAMP_REGION: &str = r#"{ shape = "slab", axis = "z", from = "0 mm", to = "1 mm" }"#;

/// [`BASE`] with `from` (which must occur exactly once) replaced by `to`.
fn edit(from: &str, to: &str) -> String {
    edit_deck(BASE, from, to)
}

fn edit_deck(deck: &str, from: &str, to: &str) -> String {
    let n = deck.matches(from).count();
    assert_eq!(
        n, 1,
        "the deck has {n} occurrences of {from:?}, want exactly 1"
    );
    deck.replacen(from, to, 1)
}

/// [`BASE`] with `text` inserted just before the line `[time]`.
fn insert_before_time(text: &str) -> String {
    edit("[time]\n", &format!("{text}\n[time]\n"))
}

/// 1-based number of the only line of `deck` that starts with `start` (ignoring indentation).
fn line_of(deck: &str, start: &str) -> usize {
    let hits: Vec<usize> = lines_starting(deck, start);
    assert_eq!(
        hits.len(),
        1,
        "want exactly one line starting with {start:?}, found {hits:?}"
    );
    hits[0]
}

/// 1-based number of the last line of `deck` that starts with `start`.
fn last_line_of(deck: &str, start: &str) -> usize {
    *lines_starting(deck, start)
        .last()
        .unwrap_or_else(|| panic!("no line starts with {start:?}"))
}

fn lines_starting(deck: &str, start: &str) -> Vec<usize> {
    deck.lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with(start))
        .map(|(i, _)| i + 1)
        .collect()
}

struct Outcome {
    path: PathBuf,
    success: bool,
    stdout: String,
    stderr: String,
}

/// Writes `deck` to a fresh file named after `case` and runs `pdq check` on it.
fn check(case: &str, deck: &str) -> Outcome {
    let dir = std::env::temp_dir().join(format!("pdq_deck_errors_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create the temp dir");
    let path = dir.join(format!("{case}.toml"));
    std::fs::write(&path, deck).expect("write the deck");
    let out = Command::new(env!("CARGO_BIN_EXE_pdq"))
        .arg("check")
        .arg(&path)
        .current_dir(&dir)
        .output()
        .expect("run pdq");
    Outcome {
        path,
        success: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `pdq check` must reject `deck` cleanly, say every one of `phrases`, and, when `line` is
/// given, locate the error at that line of the deck.
fn assert_rejected(case: &str, deck: &str, phrases: &[&str], line: Option<usize>) {
    let out = check(case, deck);
    let stderr = &out.stderr;
    let ctx = format!(
        "case {case}, deck {}:\n{deck}\n--- stderr:\n{stderr}",
        out.path.display()
    );
    assert!(!out.success, "pdq check accepted a bad deck; {ctx}");
    assert!(!stderr.contains("panicked"), "pdq panicked; {ctx}");
    assert!(stderr.contains("error:"), "no 'error:' on stderr; {ctx}");
    // Phrases are looked for with the file name blanked out: it contains the case name.
    let message = stderr.replace(&out.path.display().to_string(), "<deck>");
    for p in phrases {
        assert!(message.contains(p), "stderr does not mention {p:?}; {ctx}");
    }
    if let Some(line) = line {
        let at = format!("{}:{line}:", out.path.display());
        assert!(stderr.contains(&at), "error not located at {at:?}; {ctx}");
    }
    let _ = std::fs::remove_file(&out.path);
}

// ---------------------------------------------------------------------------------------------
// The base deck itself.

#[test]
fn base_deck_checks() {
    let out = check("base", BASE);
    assert!(
        out.success && out.stdout.contains("particles"),
        "the base deck must pass; stdout:\n{}\nstderr:\n{}",
        out.stdout,
        out.stderr
    );
    let particles = out.stdout.lines().find(|l| l.starts_with("particles"));
    assert!(
        particles.is_some_and(|l| l.contains("216")),
        "6 x 6 x 6 particles expected:\n{}",
        out.stdout
    );
    let _ = std::fs::remove_file(&out.path);
}

// ---------------------------------------------------------------------------------------------
// Keys the deck does not know.

/// A stray top-level key (meant as a comment, or a typo of a section name).
#[test]
fn unknown_top_level_key() {
    let deck = edit("units = \"SI\"\n", "units = \"SI\"\ncolour = \"red\"\n");
    assert_rejected(
        "top_key",
        &deck,
        &["colour", "unknown field"],
        Some(line_of(&deck, "colour")),
    );
}

/// A typo inside a table: `horizn` for `horizon`.
#[test]
fn unknown_key_in_model() {
    let deck = edit("horizon = ", "horizn = ");
    assert_rejected(
        "model_key",
        &deck,
        &["horizn", "horizon"],
        Some(line_of(&deck, "horizn")),
    );
}

/// A misspelt material property.
#[test]
fn unknown_key_in_material() {
    let deck = edit("critical_stretch", "critical_strech");
    let line = line_of(&deck, "critical_strech");
    assert_rejected("material_key", &deck, &["critical_strech"], Some(line));
}

/// A `[model.options]` entry the model does not have.
#[test]
fn unknown_model_option() {
    let deck = edit(
        "horizon = \"3.015 mm\"\n",
        "horizon = \"3.015 mm\"\n\n[model.options]\nbogus = 1\n",
    );
    assert_rejected(
        "model_option",
        &deck,
        &["bogus", "pmb"],
        Some(line_of(&deck, "[model]")),
    );
}

// ---------------------------------------------------------------------------------------------
// Units.

/// A unit PDQ does not know.
#[test]
fn unknown_unit() {
    let deck = edit("\"2200 kg/m^3\"", "\"3 furlongs\"");
    let line = line_of(&deck, "density");
    assert_rejected(
        "unknown_unit",
        &deck,
        &["furlongs", "unknown unit"],
        Some(line),
    );
}

/// A length where a stress belongs.
#[test]
fn dimension_mismatch() {
    let deck = edit("\"30 GPa\"", "\"3 in\"");
    let line = line_of(&deck, "youngs_modulus");
    assert_rejected(
        "dimension",
        &deck,
        &["stress", "length", "3 in"],
        Some(line),
    );
}

/// A unit system that does not exist.
#[test]
fn unknown_unit_system() {
    let deck = edit("units = \"SI\"", "units = \"furlong-firkin-fortnight\"");
    let line = line_of(&deck, "units");
    assert_rejected(
        "unit_system",
        &deck,
        &["furlong-firkin-fortnight", "unit system"],
        Some(line),
    );
}

/// A vector with two components.
#[test]
fn vector_with_two_numbers() {
    let deck = edit("max = \"6 6 6 mm\"", "max = \"6 6 mm\"");
    assert_rejected(
        "two_numbers",
        &deck,
        &["three numbers", "6 6 mm"],
        Some(line_of(&deck, "max")),
    );
}

// ---------------------------------------------------------------------------------------------
// TOML itself.

/// A missing `=`.
#[test]
fn bad_toml_syntax() {
    let deck = edit("steps = 10", "steps 10");
    assert_rejected(
        "syntax",
        &deck,
        &["expected `=`"],
        Some(line_of(&deck, "steps 10")),
    );
}

/// The same key twice in a table.
#[test]
fn duplicate_toml_key() {
    let deck = edit("steps = 10\n", "steps = 10\nsteps = 11\n");
    assert_rejected(
        "duplicate_key",
        &deck,
        &["duplicate key"],
        Some(line_of(&deck, "steps = 11")),
    );
}

/// The whole `[time]` table left out.
#[test]
fn missing_time() {
    let deck = edit("[time]\nsteps = 10\nsafety_factor = 0.8\n", "");
    assert_rejected("no_time", &deck, &["missing field `time`"], None);
}

// ---------------------------------------------------------------------------------------------
// Model, horizon and materials.

/// A model name that is not registered.
#[test]
fn unknown_model() {
    let deck = edit("name = \"pmb\"", "name = \"pmbb\"");
    let line = line_of(&deck, "[model]");
    assert_rejected(
        "model_name",
        &deck,
        &["pmbb", "unknown model", "concrete"],
        Some(line),
    );
}

/// A negative horizon (semantic errors are located at the table that holds the key).
#[test]
fn negative_horizon() {
    let deck = edit("\"3.015 mm\"", "\"-3 mm\"");
    assert_rejected(
        "negative_horizon",
        &deck,
        &["horizon", "> 0"],
        Some(line_of(&deck, "[model]")),
    );
}

/// A horizon smaller than the lattice spacing: no particle would have a bond.
#[test]
fn horizon_below_spacing() {
    let deck = edit("\"3.015 mm\"", "\"0.5 mm\"");
    let line = line_of(&deck, "[model]");
    assert_rejected(
        "small_horizon",
        &deck,
        &["horizon", "smaller than the lattice spacing"],
        Some(line),
    );
}

/// A negative density.
#[test]
fn negative_density() {
    let deck = edit("\"2200 kg/m^3\"", "\"-2200 kg/m^3\"");
    let line = line_of(&deck, "[materials.mortar]");
    assert_rejected(
        "negative_density",
        &deck,
        &["mortar", "density", "> 0"],
        Some(line),
    );
}

/// Poisson's ratio 0.3 with bond-based PMB, which is fixed at 1/4.
#[test]
fn pmb_with_poisson_ratio() {
    let deck = edit(
        "critical_stretch = 0.0005\n",
        "critical_stretch = 0.0005\npoisson_ratio = 0.3\n",
    );
    assert_rejected(
        "pmb_poisson",
        &deck,
        &["mortar", "Poisson", "0.3", "poisson_ratio"],
        None,
    );
}

/// A PMB material that gives both its critical stretch and a fracture energy to derive it from.
#[test]
fn pmb_with_stretch_and_fracture_energy() {
    let deck = edit(
        "critical_stretch = 0.0005\n",
        "critical_stretch = 0.0005\nfracture_energy = \"10 J/m^2\"\n",
    );
    assert_rejected(
        "pmb_stretch_and_energy",
        &deck,
        &[
            "mortar",
            "'critical_stretch' or 'fracture_energy', not both",
        ],
        None,
    );
}

/// As above, but the error should point at the material (or its poisson_ratio), not at `[model]`.
#[test]
fn pmb_with_poisson_ratio_line() {
    let deck = edit(
        "critical_stretch = 0.0005\n",
        "critical_stretch = 0.0005\npoisson_ratio = 0.3\n",
    );
    let line = line_of(&deck, "[materials.mortar]");
    assert_rejected("pmb_poisson_line", &deck, &["poisson_ratio"], Some(line));
}

/// The concrete model with a concrete material lacking its tensile stretch.
fn concrete_without_tensile_stretch_deck() -> String {
    let deck = edit("name = \"pmb\"", "name = \"concrete\"");
    edit_deck(
        &deck,
        "critical_stretch = 0.0005\n",
        "kind = \"concrete\"\npoisson_ratio = 0.25\ncompressive_stretch = -0.005\n",
    )
}

#[test]
fn concrete_without_tensile_stretch() {
    let deck = concrete_without_tensile_stretch_deck();
    assert_rejected(
        "concrete_tensile",
        &deck,
        &["mortar", "tensile_stretch", "concrete"],
        None,
    );
}

#[test]
fn concrete_without_tensile_stretch_line() {
    let deck = concrete_without_tensile_stretch_deck();
    let line = line_of(&deck, "[materials.mortar]");
    assert_rejected(
        "concrete_tensile_line",
        &deck,
        &["tensile_stretch"],
        Some(line),
    );
}

// ---------------------------------------------------------------------------------------------
// Geometry.

/// No `[[geometry]]` at all: no particles.
#[test]
fn no_geometry() {
    let deck = edit(
        "[[geometry]]\nshape = \"box\"\nmaterial = \"mortar\"\nmin = \"0 0 0 mm\"\nmax = \"6 6 6 mm\"\n",
        "",
    );
    assert_rejected(
        "no_geometry",
        &deck,
        &["[[geometry]]", "no particles"],
        None,
    );
}

/// A box between lattice sites (sites sit at 0.5 mm, 1.5 mm, ...).
#[test]
fn geometry_box_selects_no_site() {
    let deck = edit(
        "min = \"0 0 0 mm\"\nmax = \"6 6 6 mm\"",
        "min = \"0.1 0.1 0.1 mm\"\nmax = \"0.3 0.3 0.3 mm\"",
    );
    let line = line_of(&deck, "[[geometry]]");
    assert_rejected(
        "empty_box",
        &deck,
        &["geometry entry 0", "selects no lattice site"],
        Some(line),
    );
}

/// A subtract larger than the block removes every particle.
fn subtract_everything_deck() -> String {
    insert_before_time("[[geometry]]\nshape = \"box\"\nop = \"subtract\"\nmin = \"-1 -1 -1 mm\"\nmax = \"7 7 7 mm\"\n")
}

#[test]
fn subtract_removes_everything() {
    let deck = subtract_everything_deck();
    assert_rejected("subtract_all", &deck, &["no particles", "subtracted"], None);
}

#[test]
fn subtract_removes_everything_line() {
    let deck = subtract_everything_deck();
    let line = last_line_of(&deck, "[[geometry]]");
    assert_rejected("subtract_all_line", &deck, &["no particles"], Some(line));
}

/// A geometry entry naming a material that is not defined (typo).
#[test]
fn unknown_material_in_geometry() {
    let deck = edit("material = \"mortar\"", "material = \"mortr\"");
    let line = line_of(&deck, "[[geometry]]");
    assert_rejected(
        "material_name",
        &deck,
        &["mortr", "unknown material", "mortar"],
        Some(line),
    );
}

/// A key that belongs to another shape.
#[test]
fn box_given_a_radius() {
    let deck = edit(
        "max = \"6 6 6 mm\"",
        "max = \"6 6 6 mm\"\nradius = \"1 mm\"",
    );
    let line = line_of(&deck, "[[geometry]]");
    assert_rejected("box_radius", &deck, &["box", "radius"], Some(line));
}

/// A reinforcing bar along a zero direction vector.
#[test]
fn bar_with_zero_direction() {
    let deck = insert_before_time(
        "[[bar]]\nmaterial = \"mortar\"\narea = \"1 mm^2\"\nfrom = \"1 1 1 mm\"\ndirection = [0, 0, 0]\nlength = \"3 mm\"\n",
    );
    let line = line_of(&deck, "[[bar]]");
    assert_rejected("bar_direction", &deck, &["direction"], Some(line));
}

// ---------------------------------------------------------------------------------------------
// Time.

/// A time step far above the stable one, without `force_dt`.
fn dt_too_large_deck() -> String {
    edit("safety_factor = 0.8", "dt = \"1 s\"")
}

#[test]
fn dt_above_stable_time_step() {
    let deck = dt_too_large_deck();
    assert_rejected(
        "dt_large",
        &deck,
        &["dt", "stable time step", "force_dt"],
        None,
    );
}

#[test]
fn dt_above_stable_time_step_line() {
    let deck = dt_too_large_deck();
    let line = line_of(&deck, "[time]");
    assert_rejected("dt_large_line", &deck, &["stable time step"], Some(line));
}

/// A critical step that is neither the bound nor measured.
#[test]
fn unknown_critical_step() {
    let deck = edit(
        "safety_factor = 0.8",
        "safety_factor = 0.8\ncritical_step = \"guessed\"",
    );
    let line = line_of(&deck, "[time]");
    assert_rejected(
        "critical_step",
        &deck,
        &["critical_step", "guessed", "bound", "measured"],
        Some(line),
    );
}

/// The measured critical step with a quasi-static solver, which has no time step.
#[test]
fn measured_critical_step_with_relaxation() {
    let deck = edit(
        "safety_factor = 0.8",
        "safety_factor = 0.8\ncritical_step = \"measured\"",
    ) + "[solver]\nkind = \"adr\"\n";
    let line = line_of(&deck, "[time]");
    assert_rejected(
        "critical_step_adr",
        &deck,
        &["critical_step", "explicit"],
        Some(line),
    );
}

/// A preconditioner the matrix-free solve does not have, and one given to ADR (which has no
/// linear solve to precondition).
#[test]
fn unknown_or_misplaced_preconditioner() {
    let unknown = edit("safety_factor = 0.8", "safety_factor = 0.8")
        + "[solver]\nkind = \"newton_krylov\"\npreconditioner = \"multigrid\"\n";
    let line = line_of(&unknown, "[solver]");
    assert_rejected(
        "preconditioner_unknown",
        &unknown,
        &["preconditioner", "multigrid", "two_level", "diagonal"],
        Some(line),
    );
    let misplaced = edit("safety_factor = 0.8", "safety_factor = 0.8")
        + "[solver]\nkind = \"adr\"\npreconditioner = \"diagonal\"\n";
    let line = line_of(&misplaced, "[solver]");
    assert_rejected(
        "preconditioner_adr",
        &misplaced,
        &["preconditioner", "newton_krylov"],
        Some(line),
    );
}

/// The measured critical step is accepted, shown by `pdq check` with the bound, and above it
/// (the bound is 1.4–2.4× below the limit, docs/stability.md); a dt between the two passes.
#[test]
fn measured_critical_step_is_shown_and_above_the_bound() {
    let deck = edit(
        "safety_factor = 0.8",
        "safety_factor = 0.8\ncritical_step = \"measured\"",
    );
    let out = check("critical_step_measured", &deck);
    assert!(out.success, "{}", out.stderr);
    let line = out
        .stdout
        .lines()
        .chain(out.stderr.lines())
        .find(|l| l.starts_with("time step"))
        .expect("a time step line")
        .to_string();
    assert!(line.contains("measured on the stiffest mode"), "{line}");
    let number_after = |key: &str| -> f64 {
        let rest = &line[line.find(key).expect(key) + key.len()..];
        rest.split([' ', ','])
            .find(|w| !w.is_empty())
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("no number after {key:?} in {line}"))
    };
    let (measured, bound) = (number_after("critical "), number_after("bound is "));
    assert!(
        measured > 1.3 * bound && measured < 2.5 * bound,
        "measured {measured:e} against bound {bound:e}: {line}"
    );
    // A dt between the bound and the measured limit is refused by the bound alone.
    let dt = 0.5 * (measured + bound);
    let deck = edit(
        "safety_factor = 0.8",
        &format!("dt = \"{dt:e} s\"\ncritical_step = \"measured\""),
    );
    let out = check("critical_step_measured_dt", &deck);
    assert!(out.success, "{}", out.stderr);
    let deck = edit("safety_factor = 0.8", &format!("dt = \"{dt:e} s\""));
    assert_rejected("critical_step_bound_dt", &deck, &["stable time step"], None);
}

/// An integrator PDQ does not have (leapfrog it has: the semi-implicit Euler scheme).
#[test]
fn unknown_integrator() {
    let deck = edit(
        "safety_factor = 0.8",
        "safety_factor = 0.8\nintegrator = \"rk4\"",
    );
    let line = line_of(&deck, "[time]");
    assert_rejected(
        "integrator",
        &deck,
        &["rk4", "integrator", "verlet", "leapfrog"],
        Some(line),
    );
}

/// A time given without a number: the message should show a time example, not a stress.
#[test]
fn time_without_a_number() {
    let deck = edit("safety_factor = 0.8", "dt = \"fast\"");
    let out = check("dt_fast", &deck);
    assert!(
        !out.stderr.contains("GPa"),
        "a time should not be exemplified by a stress:\n{}",
        out.stderr
    );
    assert_rejected(
        "dt_fast",
        &deck,
        &["fast", "s\""],
        Some(line_of(&deck, "dt")),
    );
}

// ---------------------------------------------------------------------------------------------
// Boundary conditions.

/// A boundary region above the block: it clamps nothing.
#[test]
fn boundary_region_selects_nothing() {
    let deck = edit(
        "from = \"0 mm\", to = \"1 mm\"",
        "from = \"10 mm\", to = \"11 mm\"",
    );
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected(
        "empty_region",
        &deck,
        &["clamp", "selects no particle"],
        Some(line),
    );
}

/// A cylinder region with a negative radius.
#[test]
fn cylinder_with_negative_radius() {
    let cyl = r#"{ shape = "cylinder", base = "3 3 0 mm", axis = "z", length = "1 mm", radius = "-1 mm" }"#;
    let deck = edit(CLAMP_REGION, cyl);
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected(
        "negative_radius",
        &deck,
        &["cylinder", "radius", "> 0"],
        Some(line),
    );
}

/// A boundary both fixed and moving.
#[test]
fn boundary_fixed_and_velocity() {
    let deck = edit(
        "fixed = [\"all\"]",
        "fixed = [\"all\"]\nvelocity = \"0 0 1 m/s\"",
    );
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected(
        "fixed_velocity",
        &deck,
        &["clamp", "fixed", "velocity", "exactly one"],
        Some(line),
    );
}

/// Explicit ids past the last particle (the block has ids 0..=215).
#[test]
fn region_with_nonexistent_id() {
    let deck = edit(CLAMP_REGION, "{ ids = [0, 999] }");
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected("bad_id", &deck, &["999", "does not exist"], Some(line));
}

/// Two boundaries with the same name (copy-paste).
#[test]
fn duplicate_boundary_name() {
    let clamp =
        format!("[[boundary]]\nname = \"clamp\"\nregion = {CLAMP_REGION}\nfixed = [\"all\"]\n");
    let deck = edit(&clamp, &format!("{clamp}\n{clamp}"));
    let line = last_line_of(&deck, "[[boundary]]");
    assert_rejected(
        "duplicate_name",
        &deck,
        &["clamp", "used twice"],
        Some(line),
    );
}

/// PMB given two stiffnesses: which one counts would be a silent guess.
#[test]
fn pmb_with_two_stiffnesses() {
    let deck = edit(
        "critical_stretch = 0.0005\n",
        "critical_stretch = 0.0005\nbulk_modulus = \"20 GPa\"\n",
    );
    let line = line_of(&deck, "[materials.mortar]");
    assert_rejected(
        "pmb_two_stiffnesses",
        &deck,
        &["mortar", "bulk_modulus", "youngs_modulus", "not several"],
        Some(line),
    );
}

/// A PMB-style critical stretch under the concrete model, which reads tensile/compressive
/// stretches instead: the user's failure criterion would be lost.
#[test]
fn concrete_with_a_key_it_does_not_use() {
    let deck = edit("name = \"pmb\"", "name = \"concrete\"");
    let deck = edit_deck(
        &deck,
        "critical_stretch = 0.0005\n",
        "kind = \"concrete\"\npoisson_ratio = 0.25\ntensile_stretch = 1e-4\ncompressive_stretch = -1e-3\ncritical_stretch = 0.0005\n",
    );
    // At the key the model does not read (the model, not the deck, knows its keys).
    let line = line_of(&deck, "critical_stretch");
    assert_rejected(
        "concrete_unused_key",
        &deck,
        &["mortar", "critical_stretch", "does not use"],
        Some(line),
    );
}

/// Two probes with one name would give two identical history columns.
#[test]
fn duplicate_probe_name() {
    let deck = format!(
        "{BASE}\n[[probe]]\nname = \"tip\"\nat = \"3 3 6 mm\"\n\n[[probe]]\nname = \"tip\"\nat = \"3 3 0 mm\"\n"
    );
    let line = last_line_of(&deck, "name = \"tip\"") - 1;
    assert_rejected(
        "duplicate_probe",
        &deck,
        &["probe", "tip", "twice"],
        Some(line),
    );
}

/// TOML's `nan` is a float: a velocity made of it would fill the run with NaN.
#[test]
fn nan_in_a_boundary_velocity() {
    let deck = edit("fixed = [\"all\"]", "velocity = [nan, 0, 0]");
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected(
        "nan_velocity",
        &deck,
        &["clamp", "velocity", "finite"],
        Some(line),
    );
}

/// Two bars along the same line put particles on top of each other (a bond of length zero).
#[test]
fn overlapping_bars() {
    let bar = "[[bar]]\nmaterial = \"mortar\"\narea = \"1 mm^2\"\nfrom = \"0.2 3.2 3.2 mm\"\nto = \"5.2 3.2 3.2 mm\"\n";
    let deck = insert_before_time(&format!("{bar}\n{bar}"));
    assert_rejected(
        "overlapping_bars",
        &deck,
        &["coincide", "overlapping"],
        None,
    );
}

/// A history table with a NaN time would make the load factor undefined.
#[test]
fn nan_in_a_history_table() {
    let deck = edit(
        "fixed = [\"all\"]",
        "displacement = \"0 0 1 mm\"\nhistory = { table = [[0, 0], [nan, 1]] }",
    );
    let line = line_of(&deck, "[[boundary]]");
    assert_rejected("nan_history", &deck, &["history", "finite"], Some(line));
}

/// A broken-bond count to stop at must be at least 1.
#[test]
fn stop_at_zero_broken_bonds() {
    let deck = edit("steps = 10\n", "steps = 10\nstop_at_broken_bonds = 0\n");
    assert_rejected("stop_zero", &deck, &["stop_at_broken_bonds", ">= 1"], None);
}

/// A peak stop needs a fraction strictly between 0 and 1 (1 would stop at the first dip).
#[test]
fn a_peak_stop_fraction_outside_zero_to_one() {
    for f in ["0", "1", "-0.5", "nan"] {
        let stop =
            format!("steps = 10\nstop_below_peak = {{ column = \"load_load\", fraction = {f} }}\n");
        let deck = edit("steps = 10\n", &stop);
        assert_rejected(
            "peak_stop",
            &deck,
            &["stop_below_peak", "fraction in (0, 1)"],
            None,
        );
    }
}

/// A probe's stop distance must be a positive length: a negative one would stop at once.
#[test]
fn a_probe_stop_of_negative_length() {
    let deck =
        format!("{BASE}\n[[probe]]\nname = \"tip\"\nat = \"3 3 6 mm\"\nstop_beyond = \"-1 mm\"\n");
    let line = line_of(&deck, "[[probe]]");
    assert_rejected(
        "probe_stop",
        &deck,
        &["probe 'tip'", "stop_beyond", "> 0"],
        Some(line),
    );
}

/// A prestrained bar in a model whose bonds keep no plastic stretch (PMB): refused at the bar.
#[test]
fn prestrain_in_a_model_without_plastic_stretch() {
    let bar = "[[bar]]\nmaterial = \"mortar\"\narea = \"1 mm^2\"\nfrom = \"0.2 3.2 3.2 mm\"\nto = \"5.2 3.2 3.2 mm\"\nprestrain = 0.002\n";
    let deck = insert_before_time(bar);
    let line = line_of(&deck, "[[bar]]");
    assert_rejected(
        "prestrain_pmb",
        &deck,
        &["bar 0", "cannot prestrain", "pmb"],
        Some(line),
    );
}

/// Prestrain and prestress together, and a transfer length without either.
#[test]
fn prestrain_given_twice_or_transfer_length_alone() {
    let bar = "[[bar]]\nmaterial = \"mortar\"\narea = \"1 mm^2\"\nfrom = \"0.2 3.2 3.2 mm\"\nto = \"5.2 3.2 3.2 mm\"\n";
    let deck = insert_before_time(&format!("{bar}prestrain = 0.002\nprestress = \"60 MPa\"\n"));
    let line = line_of(&deck, "[[bar]]");
    assert_rejected("prestrain_twice", &deck, &["bar 0", "not both"], Some(line));
    let deck = insert_before_time(&format!("{bar}transfer_length = \"2 mm\"\n"));
    assert_rejected(
        "transfer_length_alone",
        &deck,
        &["bar 0", "transfer_length needs prestrain"],
        Some(line),
    );
}

/// More workers than any machine has: refused at `[parallel]` (found by tests/deck_fuzz.rs:
/// `threads = 100000000000` kept the layout search going for hours, and two procCube counts
/// of 2³² multiplied to 0 procCubes).
#[test]
fn absurd_worker_counts() {
    let deck = format!("{BASE}\n[parallel]\nthreads = 100000000000\n");
    let line = line_of(&deck, "[parallel]");
    assert_rejected(
        "threads_huge",
        &deck,
        &["threads = 100000000000", "at most 1048576"],
        Some(line),
    );
    let deck = format!("{BASE}\n[parallel]\nprocs = [4294967296, 4294967296, 1]\nthreads = 1\n");
    assert_rejected(
        "procs_overflow",
        &deck,
        &[
            "procs = [4294967296, 4294967296, 1]",
            "more than 1048576 procCubes",
        ],
        Some(line),
    );
}
