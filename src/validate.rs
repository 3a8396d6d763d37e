//! `pdq validate`: cases that compare PDQ with engineering formulas and report the error.
//!
//! A case is a deck (made here, at a coarse `--quick` or a fine `--full` resolution), a
//! reference value from a formula (THEORY.md §7), a tolerance, and an extractor that reads the
//! measured value from the run's output. The runner writes `report.md` with the table (case,
//! quantity, PDQ, reference, error, particles, run time) and a PNG plot per case.

use crate::deck;
use crate::run::{self, RunOptions, Summary};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The resolution of a validation run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Coarse versions of every case: minutes on 2 cores, run in CI.
    Quick,
    /// Finer lattices (the thesis's resolution where the case is one of its problems).
    Full,
}

/// Elastic cases must meet their tolerance; strength cases report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Elastic,
    Strength,
}

/// Reads a curve, as (x, y) points, from a run's output directory.
pub type CurveReader = fn(&Path) -> Result<Vec<(f64, f64)>, String>;

/// A plot of a case: the measured curve (read from the run's output) against the reference.
pub struct Plot {
    pub x_label: String,
    pub y_label: String,
    pub reference: Vec<(f64, f64)>,
    pub measured: CurveReader,
}

/// One validation case.
pub struct Case {
    pub name: String,
    pub quantity: String,
    pub unit: &'static str,
    pub kind: Kind,
    pub reference: f64,
    /// Where the reference comes from.
    pub formula: String,
    pub tolerance_percent: f64,
    pub deck: String,
    /// The measured value from the run's summary and output directory.
    pub extract: fn(&Summary, &Path) -> Result<f64, String>,
    pub plot: Option<Plot>,
}

/// What running a case gave.
pub struct Outcome {
    pub name: String,
    pub quantity: String,
    pub unit: &'static str,
    pub kind: Kind,
    pub measured: f64,
    pub reference: f64,
    pub formula: String,
    pub error_percent: f64,
    pub tolerance_percent: f64,
    pub particles: usize,
    pub force_evaluations: u64,
    pub seconds: f64,
    pub passed: bool,
    pub plot: Option<PathBuf>,
}

/// The columns of `history.csv` by name, and its rows.
pub fn read_history(dir: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let path = dir.join("history.csv");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| format!("{}: empty", path.display()))?
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| {
                    v.parse::<f64>()
                        .map_err(|e| format!("{}: {e}", path.display()))
                })
                .collect::<Result<Vec<f64>, String>>()
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((header, rows))
}

/// The last value of a history column.
pub fn last_of(dir: &Path, column: &str) -> Result<f64, String> {
    let (header, rows) = read_history(dir)?;
    let c = header
        .iter()
        .position(|h| h == column)
        .ok_or_else(|| format!("history.csv has no column '{column}'"))?;
    rows.last()
        .map(|r| r[c])
        .ok_or_else(|| "history.csv has no rows".to_string())
}

/// A beam of the suite: square section of `cells` lattice planes (odd, so that a particle sits
/// on the axis) at dx = 10 mm, E = 10 GPa, ν = 1/4 (PMB's own) or 0.2 for micropolar (where its
/// shear bonds act: at ν = 1/4 it is PMB); bond-based models with the energy surface
/// correction, LPS without (it has none); m = 3; relaxed by ADR to 10⁻⁷ in one load step.
struct Beam {
    model: String,
    cells: usize,
    m: f64,
    dx: f64,
    e: f64,
    nu: f64,
}

impl Beam {
    fn new(model: &str, level: Level) -> Beam {
        let (cells, m) = match level {
            Level::Quick => (7, 3.0),
            Level::Full => (13, 3.0),
        };
        Beam {
            model: model.to_string(),
            cells,
            m,
            dx: 0.01,
            e: 10.0e9,
            nu: if model == "micropolar" { 0.2 } else { 0.25 },
        }
    }

    /// Section depth: sites sit at cell centres, so a box [0, n dx] holds n planes.
    fn h(&self) -> f64 {
        self.cells as f64 * self.dx
    }

    fn inertia(&self) -> f64 {
        self.h().powi(4) / 12.0
    }

    /// κGA with κ = 5/6.
    fn shear_stiffness(&self) -> f64 {
        5.0 / 6.0 * self.e / (2.0 * (1.0 + self.nu)) * self.h() * self.h()
    }

    /// The deck through `[solver]`: model, lattice, material and a box `length_x` long.
    fn deck_head(&self, title: &str, length_x: f64) -> String {
        let (model, m, dx, e, nu, h) = (&self.model, self.m, self.dx, self.e, self.nu, self.h());
        let material = match model.as_str() {
            "pmb" => format!("youngs_modulus = \"{e} Pa\"\n"),
            _ => format!("youngs_modulus = \"{e} Pa\"\npoisson_ratio = {nu}\n"),
        };
        let correction = if model == "lps" {
            ""
        } else {
            "surface_correction = \"energy\"\n"
        };
        format!(
            r#"title = "validation: {model} {title}"
units = "SI"
[model]
name = "{model}"
m = {m}
{correction}[lattice]
spacing = "{dx} m"
[materials.solid]
density = "2400 kg/m^3"
{material}critical_stretch = 1.0
[[geometry]]
shape = "box"
material = "solid"
min = "0 0 0 m"
max = "{length_x} {h} {h} m"
[time]
duration = "1 s"
{ADR_SOLVER}"#
        )
    }

    /// The material in words, for the report.
    fn describe(&self) -> String {
        format!(
            "h = {:.3} m, E = {:.0} GPa, ν = {}",
            self.h(),
            self.e / 1e9,
            self.nu
        )
    }
}

/// The solver of the beam decks: ADR in one load step to 10⁻⁷.
const ADR_SOLVER: &str =
    "[solver]\nkind = \"adr\"\nload_steps = 1\ntolerance = 1e-7\nmax_iterations = 400000\n";

/// What `--solver implicit` puts in its place: Newton with the assembled tangent, to 10⁻⁹.
const IMPLICIT_SOLVER: &str =
    "[solver]\nkind = \"implicit\"\nload_steps = 1\ntolerance = 1e-9\nmax_iterations = 20\n";

/// The output section of the beam decks: a history row and a frame per load step.
const BEAM_OUTPUT: &str = "[output]\nprogress = false\nhistory_every = 1\nframes_every = 1\n";

/// An elastic cantilever of `model` (span 10 sections), clamped over three lattice planes at
/// x = 0 and loaded at its free end by a total force P downward on the last two planes; the
/// tip deflection of the centre of the end section against Timoshenko beam theory.
fn cantilever(model: &str, level: Level) -> Case {
    cantilever_of(Beam::new(model, level))
}

fn cantilever_of(beam: Beam) -> Case {
    let model = beam.model.clone();
    let (dx, e, h) = (beam.dx, beam.e, beam.h());
    let length_x = (10 * beam.cells + 4) as f64 * dx;
    let p: f64 = -1000.0;
    // Clamp: the three planes x < 3 dx, so the beam starts at x = 3 dx. Load: the last two
    // planes, centred at x = L_x − dx.
    let span = (length_x - dx) - 3.0 * dx;
    let (inertia, shear_stiffness) = (beam.inertia(), beam.shear_stiffness());
    let bending = p.abs() * span.powi(3) / (3.0 * e * inertia);
    let shear = p.abs() * span / shear_stiffness;
    let mid = h / 2.0;
    let deck = format!(
        r#"{head}[[boundary]]
name = "clamp"
region = {{ shape = "slab", axis = "x", from = "0 m", to = "{clamp_to} m" }}
fixed = ["all"]
[[load]]
name = "tip"
region = {{ shape = "slab", axis = "x", from = "{load_from} m", to = "{length_x} m" }}
total_force = "0 0 {p} N"
[[probe]]
name = "tip"
at = "{tip_x} {mid} {mid} m"
{BEAM_OUTPUT}"#,
        head = beam.deck_head("cantilever, end load", length_x),
        clamp_to = 3.0 * dx,
        load_from = length_x - 2.0 * dx,
        tip_x = length_x - 0.5 * dx,
    );
    Case {
        name: if beam.m == 3.0 && [7, 13].contains(&beam.cells) {
            format!("cantilever_{model}")
        } else {
            format!("cantilever_{model}_{}planes_m{}", beam.cells, beam.m)
        },
        quantity: "tip deflection".into(),
        unit: "m",
        kind: Kind::Elastic,
        reference: bending + shear,
        formula: format!(
            "Timoshenko PL³/3EI + PL/κGA, κ = 5/6; L = {span:.3} m, {}",
            beam.describe()
        ),
        tolerance_percent: 2.0,
        deck,
        extract: |_, dir| Ok(-last_of(dir, "tip_uz")?),
        plot: Some(Plot {
            x_label: "x (m)".into(),
            y_label: "deflection of the beam axis (m)".into(),
            // w(ξ) = Pξ²(3L − ξ)/6EI + Pξ/κGA from the clamp face at x = 3 dx.
            reference: (0..=50)
                .map(|k| {
                    let xi = span * k as f64 / 50.0;
                    let w = p * xi * xi * (3.0 * span - xi) / (6.0 * e * inertia)
                        + p * xi / shear_stiffness;
                    (3.0 * dx + xi, w)
                })
                .collect(),
            measured: |dir| axis_deflection(dir),
        }),
    }
}

/// A simply supported beam of `model` (span 20 sections between the support lines) under a
/// uniform load on its top layer; the midspan deflection of the beam's axis relative to the
/// axis above the supports (which removes the local indentation of the line supports, which
/// beam theory does not have) against 5wL⁴/384EI + wL²/8κGA.
fn simply_supported(model: &str, level: Level) -> Case {
    let beam = Beam::new(model, level);
    let (dx, e, h) = (beam.dx, beam.e, beam.h());
    // An odd number of planes puts one at midspan; supports under the end planes.
    let length_x = (20 * beam.cells + 1) as f64 * dx;
    let span = length_x - dx;
    let total: f64 = 20_000.0;
    let w = total / length_x;
    let (inertia, shear_stiffness) = (beam.inertia(), beam.shear_stiffness());
    let bending = 5.0 * w * span.powi(4) / (384.0 * e * inertia);
    let shear = w * span * span / (8.0 * shear_stiffness);
    let mid = h / 2.0;
    let deck = format!(
        r#"{head}[[boundary]]
name = "pin"
region = {{ shape = "box", min = "0 0 0 m", max = "{dx} {h} {dx} m" }}
fixed = ["x", "y", "z"]
[[boundary]]
name = "roller"
region = {{ shape = "box", min = "{roller_x} 0 0 m", max = "{length_x} {h} {dx} m" }}
fixed = ["y", "z"]
[[load]]
name = "top"
region = {{ shape = "box", min = "0 0 {top_z} m", max = "{length_x} {h} {h} m" }}
total_force = "0 0 -{total} N"
[[probe]]
name = "mid"
at = "{mid_x} {mid} {mid} m"
[[probe]]
name = "left"
at = "{left_x} {mid} {mid} m"
[[probe]]
name = "right"
at = "{right_x} {mid} {mid} m"
{BEAM_OUTPUT}"#,
        head = beam.deck_head("simply supported beam, uniform load", length_x),
        roller_x = length_x - dx,
        top_z = h - dx,
        mid_x = length_x / 2.0,
        left_x = dx / 2.0,
        right_x = length_x - dx / 2.0,
    );
    Case {
        name: format!("simply_supported_{model}"),
        quantity: "midspan deflection".into(),
        unit: "m",
        kind: Kind::Elastic,
        reference: bending + shear,
        formula: format!(
            "5wL⁴/384EI + wL²/8κGA, κ = 5/6; L = {span:.3} m between the support lines, w = {w:.1} N/m, {}",
            beam.describe()
        ),
        tolerance_percent: 2.0,
        deck,
        extract: |_, dir| {
            let mid = last_of(dir, "mid_uz")?;
            let ends = 0.5 * (last_of(dir, "left_uz")? + last_of(dir, "right_uz")?);
            Ok(ends - mid)
        },
        plot: Some(Plot {
            x_label: "x (m)".into(),
            y_label: "deflection of the beam axis (m)".into(),
            // w(x) = −w x (L³ − 2Lx² + x³)/24EI − w x (L − x)/2κGA from the left support line.
            reference: (0..=60)
                .map(|k| {
                    let x = span * k as f64 / 60.0;
                    let v = w * x * (span.powi(3) - 2.0 * span * x * x + x.powi(3))
                        / (24.0 * e * inertia)
                        + w * x * (span - x) / (2.0 * shear_stiffness);
                    (dx / 2.0 + x, -v)
                })
                .collect(),
            measured: |dir| axis_deflection(dir),
        }),
    }
}

/// (x₀, u_z) of the particles on the beam's axis in the last frame (those nearest the line
/// through the section's centre along x).
fn axis_deflection(dir: &Path) -> Result<Vec<(f64, f64)>, String> {
    let frames = dir.join("frames");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&frames)
        .map_err(|e| format!("{}: {e}", frames.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "h5"))
        .collect();
    files.sort();
    let last = files.last().ok_or("no frames")?;
    let f = hdf5_pure::File::open(last).map_err(|e| format!("{}: {e}", last.display()))?;
    let read = |name: &str| {
        f.dataset(name)
            .and_then(|d| d.read_f64())
            .map_err(|e| format!("{}: {name}: {e}", last.display()))
    };
    let (points, u) = (read("points")?, read("displacement")?);
    let x0: Vec<[f64; 3]> = points
        .chunks_exact(3)
        .zip(u.chunks_exact(3))
        .map(|(p, u)| [p[0] - u[0], p[1] - u[1], p[2] - u[2]])
        .collect();
    let centre = |k: usize| {
        let (lo, hi) = x0
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x[k]), b.max(x[k])));
        0.5 * (lo + hi)
    };
    let (yc, zc) = (centre(1), centre(2));
    let off = |x: &[f64; 3]| (x[1] - yc).hypot(x[2] - zc);
    let nearest = x0.iter().map(off).fold(f64::MAX, f64::min);
    let mut line: Vec<(f64, f64)> = x0
        .iter()
        .zip(u.chunks_exact(3))
        .filter(|(x, _)| off(x) <= nearest + 1e-9)
        .map(|(x, u)| (x[0], u[2]))
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(line)
}

/// The cases of a level, in report order.
pub fn cases(level: Level) -> Vec<Case> {
    let models = ["pmb", "lps", "micropolar"];
    let mut all: Vec<Case> = models.iter().map(|m| cantilever(m, level)).collect();
    all.extend(models.iter().map(|m| simply_supported(m, level)));
    all
}

/// Runs `case` with its output in `dir`.
pub fn run_case(case: &Case, dir: &Path, threads: usize) -> Result<Outcome, String> {
    let scene = deck::parse(&case.deck, &format!("{}.toml", case.name), &case.name)
        .map_err(|e| format!("case {}: {e}", case.name))?;
    let start = Instant::now();
    let summary = run::run(
        &scene,
        &RunOptions {
            output: Some(dir.to_path_buf()),
            quiet: true,
            threads: Some(threads),
            ..Default::default()
        },
    )
    .map_err(|e| format!("case {}: {e}", case.name))?;
    let seconds = start.elapsed().as_secs_f64();
    let measured = (case.extract)(&summary, dir)?;
    let error_percent = 100.0 * (measured - case.reference) / case.reference;
    let passed = measured.is_finite()
        && (case.kind == Kind::Strength || error_percent.abs() <= case.tolerance_percent);
    let plot = match &case.plot {
        Some(pl) => {
            let measured_curve = (pl.measured)(dir)?;
            let path = dir.with_extension("png");
            crate::plot::xy(
                &path,
                &format!(
                    "{}: PDQ {:.4e}, reference {:.4e} ({:+.2} %)",
                    case.name, measured, case.reference, error_percent
                ),
                &pl.x_label,
                &pl.y_label,
                &[
                    crate::plot::Series {
                        name: "PDQ",
                        points: &measured_curve,
                        mark: crate::plot::Mark::Points,
                    },
                    crate::plot::Series {
                        name: "reference",
                        points: &pl.reference,
                        mark: crate::plot::Mark::Line,
                    },
                ],
            )?;
            Some(path)
        }
        None => None,
    };
    Ok(Outcome {
        name: case.name.clone(),
        quantity: case.quantity.clone(),
        unit: case.unit,
        kind: case.kind,
        measured,
        reference: case.reference,
        formula: case.formula.clone(),
        error_percent,
        tolerance_percent: case.tolerance_percent,
        particles: summary.particles,
        force_evaluations: summary.force_evaluations,
        seconds,
        passed,
        plot,
    })
}

/// The table `pdq validate` prints and writes into `report.md`.
pub fn table(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| case | quantity | PDQ | reference | error % | tolerance % | result | particles | force evaluations | run time s |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for o in outcomes {
        let result = match (o.kind, o.passed) {
            (Kind::Strength, _) => "reported",
            (Kind::Elastic, true) => "pass",
            (Kind::Elastic, false) => "FAIL",
        };
        let _ = writeln!(
            s,
            "| {} | {} ({}) | {:.5e} | {:.5e} | {:+.2} | {} | {} | {} | {} | {:.1} |",
            o.name,
            o.quantity,
            o.unit,
            o.measured,
            o.reference,
            o.error_percent,
            o.tolerance_percent,
            result,
            o.particles,
            o.force_evaluations,
            o.seconds
        );
    }
    s
}

/// Options of `pdq validate`.
#[derive(Clone, Debug)]
pub struct ValidateOptions {
    pub level: Level,
    /// Solve the elastic cases by the implicit solve instead of ADR (one thread).
    pub implicit: bool,
    /// Case names to run (all when empty).
    pub only: Vec<String>,
    pub output: PathBuf,
    pub threads: usize,
}

/// Runs the cases, writes `report.md` into the output directory and returns the table and
/// whether every elastic case met its tolerance.
pub fn run_all(opts: &ValidateOptions) -> Result<(String, bool), String> {
    let mut all = cases(opts.level);
    let mut threads = opts.threads;
    if opts.implicit {
        for case in &mut all {
            if !case.deck.contains(ADR_SOLVER) {
                return Err(format!(
                    "case {}: no ADR solver block to replace",
                    case.name
                ));
            }
            case.deck = case.deck.replace(ADR_SOLVER, IMPLICIT_SOLVER);
        }
        // One matrix in one process.
        threads = 1;
    }
    for name in &opts.only {
        if !all.iter().any(|c| &c.name == name) {
            let names: Vec<&str> = all.iter().map(|c| c.name.as_str()).collect();
            return Err(format!(
                "no validation case '{name}' (cases: {})",
                names.join(", ")
            ));
        }
    }
    std::fs::create_dir_all(&opts.output).map_err(|e| format!("{}: {e}", opts.output.display()))?;
    let mut outcomes = Vec::new();
    for case in all
        .iter()
        .filter(|c| opts.only.is_empty() || opts.only.contains(&c.name))
    {
        let dir = opts.output.join(&case.name);
        eprintln!("case       {} ...", case.name);
        let o = run_case(case, &dir, threads)?;
        eprintln!(
            "           {} = {:.5e} {} against {:.5e} ({:+.2} %) in {:.1} s",
            o.quantity, o.measured, o.unit, o.reference, o.error_percent, o.seconds
        );
        outcomes.push(o);
    }
    let t = table(&outcomes);
    let mut report = String::new();
    let _ = writeln!(
        report,
        "# PDQ validation ({}, solved by {})\n",
        match opts.level {
            Level::Quick => "--quick",
            Level::Full => "--full",
        },
        if opts.implicit {
            "the implicit solve"
        } else {
            "ADR"
        }
    );
    report.push_str(&t);
    report.push_str("\nReferences:\n\n");
    for o in &outcomes {
        let _ = writeln!(report, "- `{}`: {}", o.name, o.formula);
    }
    for o in &outcomes {
        if let Some(p) = &o.plot {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let _ = writeln!(report, "\n![{}]({name})", o.name);
        }
    }
    let path = opts.output.join("report.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: {e}", path.display()))?;
    let ok = outcomes.iter().all(|o| o.passed);
    Ok((t, ok))
}

/// ADR against an explicit load ramp on the quick LPS cantilever: the explicit run ramps the
/// load over five periods of the beam's first bending mode and holds it for three; the
/// smallest relative residual it reaches after the ramp is then asked of ADR, and the force
/// evaluations of both are compared. Returns the lines to print.
pub fn compare_adr(output: &Path, threads: usize) -> Result<String, String> {
    let case = cantilever("lps", Level::Quick);
    // First bending period: ω₁ = 1.875² √(EI / (ρ A L⁴)) with the case's section and span.
    let (e, rho, h, span): (f64, f64, f64, f64) = (10.0e9, 2400.0, 0.07, 0.70);
    let omega = 1.875f64.powi(2) * (e * h * h / 12.0 / rho).sqrt() / (span * span);
    let period = 2.0 * std::f64::consts::PI / omega;
    let adr_block = ADR_SOLVER;
    if !case.deck.contains(adr_block) {
        return Err("the cantilever deck changed: update compare_adr".into());
    }
    let explicit = case
        .deck
        .replace(adr_block, "")
        .replace(
            "duration = \"1 s\"",
            &format!("duration = \"{} s\"", 8.0 * period),
        )
        .replace(
            "total_force = \"0 0 -1000 N\"",
            &format!(
                "total_force = \"0 0 -1000 N\"\nhistory = {{ ramp = \"{} s\" }}",
                5.0 * period
            ),
        )
        .replace("history_every = 1\nframes_every = 1", "history_every = 20");
    let dir = output.join("compare_explicit");
    let scene = deck::parse(&explicit, "compare_explicit.toml", "compare")
        .map_err(|e| format!("compare: {e}"))?;
    let t = Instant::now();
    let s = run::run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            threads: Some(threads),
            ..Default::default()
        },
    )?;
    let explicit_seconds = t.elapsed().as_secs_f64();
    let (header, rows) = read_history(&dir)?;
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("history has no column '{name}'"))
    };
    let (time, load, force) = (col("time")?, col("load_tip")?, col("residual_force")?);
    let reactions: Vec<usize> = ["x", "y", "z"]
        .iter()
        .map(|c| col(&format!("reaction_clamp_{c}")))
        .collect::<Result<_, _>>()?;
    let relative = |r: &[f64]| {
        let scale = (r[load].powi(2) + reactions.iter().map(|&k| r[k].powi(2)).sum::<f64>()).sqrt();
        r[force] / scale.max(f64::MIN_POSITIVE)
    };
    let (best_row, best) = rows
        .iter()
        .filter(|r| r[time] >= 5.0 * period)
        .map(|r| (r, relative(r)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or("the explicit run has no rows after its ramp")?;
    let explicit_evaluations = best_row[0] as u64;
    let adr_deck = case
        .deck
        .replace("tolerance = 1e-7", &format!("tolerance = {best:e}"));
    let adr_dir = output.join("compare_adr");
    let scene = deck::parse(&adr_deck, "compare_adr.toml", "compare")
        .map_err(|e| format!("compare: {e}"))?;
    let t = Instant::now();
    let a = run::run(
        &scene,
        &RunOptions {
            output: Some(adr_dir),
            quiet: true,
            threads: Some(threads),
            ..Default::default()
        },
    )?;
    let adr_seconds = t.elapsed().as_secs_f64();
    Ok(format!(
        "explicit load ramp (5 periods of {:.2} ms, then held; {} steps in all, {explicit_seconds:.1} s): smallest relative residual after the ramp {best:.2e}, reached at step {explicit_evaluations}\nADR to the same residual: {} force evaluations ({adr_seconds:.1} s)\nratio explicit/ADR force evaluations: {:.1}\n",
        1e3 * period,
        s.steps,
        a.force_evaluations,
        explicit_evaluations as f64 / a.force_evaluations.max(1) as f64
    ))
}

/// One point of the resolution sweep.
pub struct SweepPoint {
    pub model: String,
    pub cells: usize,
    pub m: f64,
    pub solver: &'static str,
    pub particles: usize,
    pub error_percent: f64,
    pub seconds: f64,
    pub force_evaluations: u64,
}

/// `pdq validate --sweep`: the elastic cantilever of each model at each section resolution
/// (lattice planes across the section, odd) and horizon ratio m, solved by each solver
/// ("implicit", "adr"); the error against Timoshenko and the run time of each, a table and a
/// PNG plot of error against run time. Runs one at a time on one thread.
pub fn sweep(
    output: &Path,
    models: &[String],
    cells: &[usize],
    ms: &[f64],
    solvers: &[String],
) -> Result<String, String> {
    std::fs::create_dir_all(output).map_err(|e| format!("{}: {e}", output.display()))?;
    let mut points = Vec::new();
    for model in models {
        for &c in cells {
            if c % 2 == 0 || c < 3 {
                return Err(format!(
                    "--cells {c}: give odd numbers ≥ 3 (a particle on the axis)"
                ));
            }
            for &m in ms {
                for solver in solvers {
                    let solver: &'static str = match solver.as_str() {
                        "implicit" => "implicit",
                        "adr" => "adr",
                        other => {
                            return Err(format!(
                                "--solvers: unknown solver '{other}' (use implicit, adr)"
                            ))
                        }
                    };
                    let mut beam = Beam::new(model, Level::Quick);
                    beam.cells = c;
                    beam.m = m;
                    let mut case = cantilever_of(beam);
                    if solver == "implicit" {
                        case.deck = case.deck.replace(ADR_SOLVER, IMPLICIT_SOLVER);
                    }
                    case.plot = None;
                    let dir = output.join(format!("{}_{solver}", case.name));
                    eprintln!("sweep      {} by {solver} ...", case.name);
                    let o = run_case(&case, &dir, 1)?;
                    eprintln!(
                        "           {:+.2} % in {:.1} s ({} particles)",
                        o.error_percent, o.seconds, o.particles
                    );
                    let _ = std::fs::remove_dir_all(&dir);
                    points.push(SweepPoint {
                        model: model.clone(),
                        cells: c,
                        m,
                        solver,
                        particles: o.particles,
                        error_percent: o.error_percent,
                        seconds: o.seconds,
                        force_evaluations: o.force_evaluations,
                    });
                }
            }
        }
    }
    let mut t = String::from("| model | planes across | m | solver | particles | error % | force evaluations | run time s |\n|---|---|---|---|---|---|---|---|\n");
    for p in &points {
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {:+.2} | {} | {:.1} |",
            p.model,
            p.cells,
            p.m,
            p.solver,
            p.particles,
            p.error_percent,
            p.force_evaluations,
            p.seconds
        );
    }
    // Error against run time, one series per model and solver.
    let mut series_points: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for p in &points {
        let name = format!("{} {}", p.model, p.solver);
        let xy = (p.seconds.max(1e-3).log10(), p.error_percent.abs());
        match series_points.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => v.push(xy),
            None => series_points.push((name, vec![xy])),
        }
    }
    let names: Vec<String> = series_points.iter().map(|(n, _)| n.clone()).collect();
    let series: Vec<crate::plot::Series> = series_points
        .iter()
        .zip(&names)
        .map(|((_, pts), n)| crate::plot::Series {
            name: n,
            points: pts,
            mark: crate::plot::Mark::Points,
        })
        .collect();
    let png = output.join("sweep.png");
    crate::plot::xy(
        &png,
        "elastic cantilever: |error| against run time",
        "log10(run time / s)",
        "|error| against Timoshenko (%)",
        &series,
    )?;
    let report =
        format!("# Cantilever sweep: error against run time\n\n{t}\n![sweep](sweep.png)\n");
    let path = output.join("sweep.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(t)
}
