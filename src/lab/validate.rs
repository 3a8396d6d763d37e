//! `pdq validate`: cases that compare PDQ with engineering formulas and report the error.
//!
//! A case is a deck at a coarse `--quick` or a fine `--full` resolution, a reference value
//! from a formula (docs/theory.md §7–§8), a tolerance, and an extractor that reads the
//! measured value from the run's output. The cases are files, `validation/NAME.toml`
//! (`case_file.rs`; their formulas in `formulas.rs`, their measures in `measures.rs`). The
//! runner writes `report.md` with the table (case, quantity, PDQ, reference,
//! error, particles, run time) and a PNG plot per case.

use crate::driver::run::{self, RunOptions, Summary};
use crate::input::deck;
use formulas::Curve;
use measures::draw_damage_views;
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub mod case_file;
mod elasticity_fe;
pub mod fe_check;
pub mod formulas;
pub mod lattice;
pub mod measures;
mod sweep;

pub use case_file::ElasticSolver;
pub use measures::{last_of, read_history};
pub use sweep::{compare_adr, sweep, SweepPlan, SweepPoint};

/// The resolution of a validation run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Coarse versions of every case: minutes on 2 cores, run in CI.
    Quick,
    /// Finer lattices (`[validation.full]`).
    Full,
    /// The thesis's resolution (`[validation.thesis_resolution]`; the full level where a case has none,
    /// its full level being the thesis's already): hours on 2 cores, run outside CI.
    Thesis,
}

impl Level {
    /// The command-line flag that chooses it.
    pub fn flag(self) -> &'static str {
        match self {
            Level::Quick => "--quick",
            Level::Full => "--full",
            Level::Thesis => "--thesis",
        }
    }

    /// The case file's table of the level.
    pub fn table(self) -> &'static str {
        match self {
            Level::Quick => "[validation]",
            Level::Full => "[validation.full]",
            Level::Thesis => {
                "[validation.thesis_resolution] (or [validation.full] where it has none)"
            }
        }
    }
}

/// Elastic cases must meet their tolerance against the formula; strength cases report
/// theirs, and must stay in their regression band.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Elastic,
    Strength,
}

/// A regression band: the value a case last measured and how far (per cent of it) a run may
/// move from it before the suite fails. Re-measured on purpose when the physics changes
/// (validation/README.md, "What fails the suite").
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Band {
    pub value: f64,
    pub percent: f64,
}

impl Band {
    /// How far `measured` is from the band's value, per cent of it.
    pub fn deviation_percent(&self, measured: f64) -> f64 {
        100.0 * (measured - self.value) / self.value.abs()
    }

    pub fn holds(&self, measured: f64) -> bool {
        self.deviation_percent(measured).abs() <= self.percent
    }
}

/// Reads a curve, as (x, y) points, from a run's output directory.
pub type CurveReader = Box<dyn Fn(&Path) -> Result<Vec<(f64, f64)>, String> + Send + Sync>;

/// A plot of a case: the measured curve (read from the run's output) against the reference.
pub struct Plot {
    pub x_label: String,
    pub y_label: String,
    pub reference: Curve,
    pub measured: CurveReader,
}

/// Reads the measured value from a run's summary and output directory.
pub type Extractor = Box<dyn Fn(&Summary, &Path) -> Result<f64, String> + Send + Sync>;

/// One validation case.
pub struct Case {
    pub name: String,
    pub quantity: String,
    pub unit: String,
    pub kind: Kind,
    pub reference: f64,
    /// The thesis's own result, a second reference where the case is one of its problems.
    pub thesis: Option<f64>,
    /// Where the reference comes from.
    pub formula: String,
    /// The formula the reference is computed by, to compute it again with other moduli
    /// (`None` for a case made in code with a fixed reference).
    pub formula_of: Option<formulas::Formula>,
    /// How the measured value is read, to read it the same way elsewhere (`fe_check.rs`).
    pub measure_of: Option<measures::Measure>,
    pub tolerance_percent: f64,
    /// The regression band at this level (required of strength cases at `--quick`).
    pub band: Option<Band>,
    pub deck: String,
    /// The measured value from the run's summary and output directory.
    pub extract: Extractor,
    pub plot: Option<Plot>,
    /// Draw the last frame's deformed body coloured by damage (side and 3D views).
    pub damage_views: bool,
}

/// What running a case gave.
pub struct Outcome {
    pub name: String,
    pub quantity: String,
    pub unit: String,
    pub kind: Kind,
    pub measured: f64,
    pub reference: f64,
    pub thesis: Option<f64>,
    pub formula: String,
    pub error_percent: f64,
    pub tolerance_percent: f64,
    pub particles: usize,
    pub force_evaluations: u64,
    pub seconds: f64,
    /// Within the tolerance against the formula.
    pub passed: bool,
    /// Whether the solve converged (`None`: an explicit run, nothing iterates).
    pub converged: Option<bool>,
    pub band: Option<Band>,
    pub plot: Option<PathBuf>,
    /// The damage picture (side and 3D views), for the cases that draw one.
    pub views: Option<PathBuf>,
}

/// How a long case run survives being stopped: checkpoints on the clock, and a resume from
/// the newest one in the case's directory.
#[derive(Clone, Copy, Debug, Default)]
pub struct LongRun {
    /// A checkpoint every so many minutes of wall time (0: the deck's own setting).
    pub checkpoint_minutes: f64,
    /// Resume from the newest checkpoint in the case's directory, where there is one.
    pub resume: bool,
}

/// Runs `case` with its output in `dir`.
pub fn run_case(case: &Case, dir: &Path, threads: usize) -> Result<Outcome, String> {
    run_case_long(case, dir, threads, LongRun::default())
}

/// Runs `case` with its output in `dir`, checkpointed and resumed as `long` says. The run
/// time of a resumed case is that of this invocation only.
pub fn run_case_long(
    case: &Case,
    dir: &Path,
    threads: usize,
    long: LongRun,
) -> Result<Outcome, String> {
    let mut scene = deck::parse(&case.deck, &format!("{}.toml", case.name), &case.name)
        .map_err(|e| format!("case {}: {e}", case.name))?;
    if long.checkpoint_minutes > 0.0 {
        scene.output.checkpoint_minutes = long.checkpoint_minutes;
    }
    let checkpoints = dir.join("checkpoints");
    let has_checkpoint = std::fs::read_dir(&checkpoints)
        .map(|mut d| d.next().is_some())
        .unwrap_or(false);
    let restart = (long.resume && has_checkpoint).then_some(checkpoints);
    if long.resume && restart.is_none() {
        eprintln!(
            "case {}: no checkpoint in {} to resume from; starting",
            case.name,
            dir.display()
        );
    }
    // The deck beside its run directory, so that `pdq run` repeats or varies the case.
    // (Not `with_extension`: a sweep's run names hold the dot of a fractional m.)
    let mut deck_name = dir.file_name().unwrap_or_default().to_os_string();
    deck_name.push(".toml");
    let deck_path = dir.with_file_name(deck_name);
    if let Some(parent) = deck_path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    std::fs::write(&deck_path, &case.deck)
        .map_err(|e| format!("case {}: {}: {e}", case.name, deck_path.display()))?;
    let start = Instant::now();
    let summary = run::run(
        &scene,
        &RunOptions {
            output: Some(dir.to_path_buf()),
            quiet: true,
            threads: Some(threads),
            restart,
            ..Default::default()
        },
    )
    .map_err(|e| format!("case {}: {e}", case.name))?;
    let seconds = start.elapsed().as_secs_f64();
    let measured = (case.extract)(&summary, dir)?;
    let error_percent = 100.0 * (measured - case.reference) / case.reference;
    let passed = measured.is_finite() && error_percent.abs() <= case.tolerance_percent;
    let converged = summary.solve_converged();
    let plot = draw_plot(case, dir, measured, error_percent)?;
    // A picture that cannot be drawn is reported, not allowed to lose the measured value.
    let views = if case.damage_views {
        let path = dir.with_file_name(format!("{}_damage.png", case.name));
        match draw_damage_views(
            dir,
            &path,
            &format!("{}: damage at {:.4e} {}", case.name, measured, case.unit),
        ) {
            Ok(()) => Some(path),
            Err(e) => {
                eprintln!("warning: case {}: no damage picture: {e}", case.name);
                None
            }
        }
    } else {
        None
    };
    Ok(Outcome {
        name: case.name.clone(),
        quantity: case.quantity.clone(),
        unit: case.unit.clone(),
        kind: case.kind,
        measured,
        reference: case.reference,
        thesis: case.thesis,
        formula: case.formula.clone(),
        error_percent,
        tolerance_percent: case.tolerance_percent,
        particles: summary.particles,
        force_evaluations: summary.force_evaluations,
        seconds,
        passed,
        converged,
        band: case.band,
        plot,
        views,
    })
}

/// The case's plot, measured curve against the reference (`None`: the case draws none).
fn draw_plot(
    case: &Case,
    dir: &Path,
    measured: f64,
    error_percent: f64,
) -> Result<Option<PathBuf>, String> {
    Ok(match &case.plot {
        Some(pl) => {
            let measured_curve = (pl.measured)(dir)?;
            let reference = match &pl.reference {
                Curve::Points(p) => p.clone(),
                // A level over the measured range.
                Curve::Level(y) => {
                    let reach = measured_curve.iter().map(|p| p.0).fold(0.0, f64::max);
                    vec![(0.0, *y), (reach, *y)]
                }
            };
            let path = dir.with_extension("png");
            crate::output::plot::xy(
                &path,
                &format!(
                    "{}: PDQ {:.4e}, reference {:.4e} ({:+.2} %)",
                    case.name, measured, case.reference, error_percent
                ),
                &pl.x_label,
                &pl.y_label,
                &[
                    crate::output::plot::Series {
                        name: "PDQ",
                        points: &measured_curve,
                        mark: crate::output::plot::Mark::Points,
                    },
                    crate::output::plot::Series {
                        name: "reference",
                        points: &reference,
                        mark: crate::output::plot::Mark::Line,
                    },
                ],
            )?;
            Some(path)
        }
        None => None,
    })
}

impl Outcome {
    /// Why the case fails the suite, if it does: its solve did not converge, it is elastic
    /// and outside its tolerance, it has left its regression band, or it is a strength case
    /// at `--quick` without one.
    pub fn failures(&self, level: Level) -> Vec<String> {
        let mut why = Vec::new();
        if self.converged == Some(false) {
            why.push(format!(
                "{}: the solve did not converge (a load step ended at its max_iterations)",
                self.name
            ));
        }
        if self.kind == Kind::Elastic && !self.passed {
            why.push(format!(
                "{}: {:+.2} % against the formula, outside its {} %",
                self.name, self.error_percent, self.tolerance_percent
            ));
        }
        let file = format!("{}.toml (the case directory)", self.name);
        let table = level.table();
        match self.band {
            Some(b) if !b.holds(self.measured) => why.push(format!(
                "{}: {:.5e} left its regression band {:.5e} ± {} % ({:+.2} %); if the change is meant, re-measure it: {table} regression = {{ value = {:.5e}, percent = {} }} in {file}",
                self.name,
                self.measured,
                b.value,
                b.percent,
                b.deviation_percent(self.measured),
                self.measured,
                b.percent
            )),
            None if self.kind == Kind::Strength && level == Level::Quick => why.push(format!(
                "{}: a strength case without a regression band: record this run's value, {table} regression = {{ value = {:.5e}, percent = 2.0 }} in {file}",
                self.name, self.measured
            )),
            _ => {}
        }
        why
    }

    /// The band column: the band and whether the value is in it.
    fn band_cell(&self) -> String {
        match self.band {
            Some(b) if b.holds(self.measured) => {
                format!("{:.5e} ± {} %: in", b.value, b.percent)
            }
            Some(b) => format!(
                "{:.5e} ± {} %: **OUT** ({:+.2} %)",
                b.value,
                b.percent,
                b.deviation_percent(self.measured)
            ),
            None if self.kind == Kind::Strength => "none recorded".to_string(),
            None => "–".to_string(),
        }
    }
}

/// The table `pdq validate` prints and writes into `report.md`.
pub fn table(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| case | quantity | PDQ | reference | error % | tolerance % | result | converged | regression band | thesis (PDQ against it) | particles | force evaluations | run time s |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for o in outcomes {
        // Strength cases report against their tolerance (their regression band can fail them).
        let result = match (o.kind, o.passed) {
            (Kind::Strength, true) => "within",
            (Kind::Strength, false) => "outside",
            (Kind::Elastic, true) => "pass",
            (Kind::Elastic, false) => "FAIL",
        };
        let converged = match o.converged {
            Some(true) => "yes",
            Some(false) => "**NO**",
            None => "explicit",
        };
        let thesis = o.thesis.map_or("–".to_string(), |t| {
            format!("{t:.5e} ({:+.2} %)", 100.0 * (o.measured - t) / t)
        });
        let _ = writeln!(
            s,
            "| {} | {} ({}) | {:.5e} | {:.5e} | {:+.2} | {} | {} | {} | {} | {} | {} | {} | {:.1} |",
            o.name,
            o.quantity,
            o.unit,
            o.measured,
            o.reference,
            o.error_percent,
            o.tolerance_percent,
            result,
            converged,
            o.band_cell(),
            thesis,
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
    /// The directory of the case files (`validation/`).
    pub cases: PathBuf,
    pub level: Level,
    /// How the elastic cases are solved (the factored implicit solve runs on one thread).
    pub solver: ElasticSolver,
    /// Case names to run (all when empty).
    pub only: Vec<String>,
    pub output: PathBuf,
    pub threads: usize,
    pub long: LongRun,
}

/// The cases of a level, in report order: the files that `dir/suite.toml` lists (the elastic
/// ones by `solver`).
pub fn cases(dir: &Path, level: Level, solver: ElasticSolver) -> Result<Vec<Case>, String> {
    case_file::load_suite(dir, level, solver)
}

/// Runs the cases, writes `report.md` into the output directory and returns the table and
/// why cases failed (none when every solve converged, every elastic case met its tolerance
/// and every case with a regression band stayed in it).
pub fn run_all(opts: &ValidateOptions) -> Result<(String, Vec<String>), String> {
    let all = cases(&opts.cases, opts.level, opts.solver)?;
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
    let chosen: Vec<&Case> = all
        .iter()
        .filter(|c| opts.only.is_empty() || opts.only.contains(&c.name))
        .collect();
    let outcomes = run_chosen(&chosen, opts)?;
    let t = table(&outcomes);
    write_report(opts, &t, &outcomes)?;
    let failures = outcomes
        .iter()
        .flat_map(|o| o.failures(opts.level))
        .collect();
    Ok((t, failures))
}

/// Runs `chosen`, returning their outcomes in the same order.
fn run_chosen(chosen: &[&Case], opts: &ValidateOptions) -> Result<Vec<Outcome>, String> {
    let threads = opts.threads;
    // A factored implicit solve assembles one matrix in one process, on one thread. At --quick
    // the Newton cases (factored or matrix-free) are small, so they run side by side, one
    // thread each, `threads` at a time, while the others get every thread one after another;
    // at --full a factored tangent can fill the machine alone, and a matrix-free solve gets
    // every thread.
    let is_implicit = |c: &Case| {
        c.deck.contains("kind = \"implicit\"")
            || (opts.level == Level::Quick && c.deck.contains("kind = \"newton_krylov\""))
    };
    let at_once = if opts.level == Level::Quick {
        threads
    } else {
        1
    };
    let run_one = |case: &Case, threads: usize| -> Result<Outcome, String> {
        eprintln!("case       {} ...", case.name);
        let o = run_case_long(case, &opts.output.join(&case.name), threads, opts.long)?;
        eprintln!(
            "           {}: {} = {:.5e} {} against {:.5e} ({:+.2} %) in {:.1} s",
            o.name, o.quantity, o.measured, o.unit, o.reference, o.error_percent, o.seconds
        );
        Ok(o)
    };
    let mut slots: Vec<Option<Outcome>> = chosen.iter().map(|_| None).collect();
    // The strength cases (the girder) take longest: first, so that the short ones fill in.
    let mut implicit: Vec<usize> = (0..chosen.len())
        .filter(|&k| is_implicit(chosen[k]))
        .collect();
    implicit.sort_by_key(|&k| chosen[k].kind != Kind::Strength);
    let solved = crate::parallel::side_by_side(&implicit, at_once, |&k| run_one(chosen[k], 1));
    for (&index, outcome) in implicit.iter().zip(solved) {
        slots[index] = Some(outcome?);
    }
    for (index, case) in chosen.iter().enumerate() {
        if slots[index].is_none() {
            slots[index] = Some(run_one(case, threads)?);
        }
    }
    Ok(slots.into_iter().flatten().collect())
}

/// `report.md`: the table, the references, the pictures.
fn write_report(opts: &ValidateOptions, t: &str, outcomes: &[Outcome]) -> Result<(), String> {
    let mut report = String::new();
    let _ = writeln!(
        report,
        "# PDQ validation ({}, solved by {})\n",
        opts.level.flag(),
        match opts.solver {
            ElasticSolver::Implicit => "the implicit solve",
            ElasticSolver::NewtonKrylov => "Newton–Krylov",
            ElasticSolver::Adr => "ADR",
        }
    );
    report.push_str(t);
    report.push_str("\nReferences:\n\n");
    for o in outcomes {
        let _ = writeln!(report, "- `{}`: {}", o.name, o.formula);
    }
    for o in outcomes {
        for p in o.plot.iter().chain(&o.views) {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let _ = writeln!(report, "\n![{}]({name})", o.name);
        }
    }
    let path = opts.output.join("report.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: {e}", path.display()))
}
