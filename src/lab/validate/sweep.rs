//! Studies built on the cantilever case files: `pdq validate --sweep` (error against run time
//! over section resolutions, horizon ratios and solvers) and `--compare-adr` (ADR against an
//! explicit load ramp).

use super::case_file::{self, Edit};
use super::measures::{column, read_history};
use super::{run_case, Level};
use crate::driver::run::{self, RunOptions};
use crate::input::deck;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use toml::Value;

/// The lattice spacing of the cantilever files, which `resize` keeps.
const SPACING: &str = "0.01 m";

/// The cantilever of `validation/cantilever_MODEL.toml` with `cells` lattice planes across its
/// square section and horizon ratio `m`: span 10 sections, clamped over three planes, the
/// load on the last two, the probes under the load's centroid (as in the file); its solve
/// stops at relative residual `tolerance` where one is given.
fn resize(
    cells: usize,
    m: f64,
    tolerance: Option<f64>,
) -> impl Fn(&mut toml::Table) -> Result<(), String> {
    move |deck| {
        let dx = 0.01;
        if deck.get("lattice").and_then(|l| l.get("spacing")) != Some(&Value::from(SPACING)) {
            return Err(format!(
                "the sweep resizes a cantilever of spacing {SPACING}"
            ));
        }
        let (length_x, h) = ((10 * cells + 4) as f64 * dx, cells as f64 * dx);
        let mid = h / 2.0;
        let at = |x: f64| Value::from(format!("{x} {mid} {mid} m"));
        entry(deck, "geometry", None)?
            .insert("max".into(), Value::from(format!("{length_x} {h} {h} m")));
        let load = entry(deck, "load", Some("tip"))?;
        let region = load.get_mut("region").and_then(Value::as_table_mut);
        let region = region.ok_or("the cantilever's load 'tip' has no region")?;
        region.insert(
            "from".into(),
            Value::from(format!("{} m", length_x - 2.0 * dx)),
        );
        region.insert("to".into(), Value::from(format!("{length_x} m")));
        entry(deck, "probe", Some("tip"))?.insert("at".into(), at(length_x - 0.5 * dx));
        entry(deck, "probe", Some("tip_inner"))?.insert("at".into(), at(length_x - 1.5 * dx));
        let model = deck.get_mut("model").and_then(Value::as_table_mut);
        model
            .ok_or("the cantilever has no [model]")?
            .insert("m".into(), Value::from(m));
        if let Some(t) = tolerance {
            let solver = deck.get_mut("solver").and_then(Value::as_table_mut);
            solver
                .ok_or("the cantilever has no [solver]")?
                .insert("tolerance".into(), Value::from(t));
        }
        Ok(())
    }
}

/// The first item of the deck's array of tables `array` (named `name`, if given).
fn entry<'d>(
    deck: &'d mut toml::Table,
    array: &str,
    name: Option<&str>,
) -> Result<&'d mut toml::Table, String> {
    deck.get_mut(array)
        .and_then(Value::as_array_mut)
        .and_then(|a| {
            a.iter_mut()
                .find(|x| name.is_none() || x.get("name").and_then(Value::as_str) == name)
        })
        .and_then(Value::as_table_mut)
        .ok_or_else(|| format!("the deck has no [[{array}]] {}", name.unwrap_or("")))
}

/// One point of the resolution sweep.
pub struct SweepPoint {
    pub model: String,
    pub cells: usize,
    pub m: f64,
    pub solver: &'static str,
    pub particles: usize,
    /// Against Timoshenko with the deck's isotropic E and ν.
    pub error_percent: f64,
    /// Against Timoshenko with the lattice's own E along the axis and G = C44.
    pub lattice_error_percent: f64,
    /// The lattice's E along [100] over the deck's E.
    pub lattice_youngs_ratio: f64,
    pub converged: Option<bool>,
    pub seconds: f64,
    pub force_evaluations: u64,
}

/// What `pdq validate --sweep` runs: every model × section resolution × horizon ratio ×
/// solver.
pub struct SweepPlan<'a> {
    pub models: &'a [String],
    /// Lattice planes across the square section, odd (a particle on the axis).
    pub planes: &'a [usize],
    pub ms: &'a [f64],
    /// "implicit", "newton_krylov", "adr".
    pub solvers: &'a [String],
    /// procCubes of each run.
    pub threads: usize,
    /// The relative residual each solve stops at, in place of the case file's. The 10⁻⁹ of
    /// the files is below what a matrix-free solve of 158,750 particles reaches (its force
    /// differences stall near 2·10⁻⁹); a fine sweep asks 10⁻⁸, which moves a deflection by
    /// far less than its last printed digit.
    pub tolerance: Option<f64>,
}

/// `pdq validate --sweep`: the elastic cantilever of each model (`cases/cantilever_MODEL.toml`)
/// at each section resolution and horizon ratio m, solved by each solver; the error against
/// Timoshenko with the deck's isotropic moduli and with the lattice's own along the beam's
/// axis (`lattice.rs`), the run time of each, a table and a PNG plot of error against run
/// time. Runs one at a time.
pub fn sweep(output: &Path, cases: &Path, plan: &SweepPlan) -> Result<String, String> {
    if let Some(t) = plan.tolerance {
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            return Err(format!(
                "--tolerance {t}: give a relative residual between 0 and 1"
            ));
        }
    }
    if let Some(c) = plan.planes.iter().find(|&&c| c % 2 == 0 || c < 3) {
        return Err(format!(
            "--planes {c}: give odd numbers ≥ 3 (a particle on the axis)"
        ));
    }
    std::fs::create_dir_all(output).map_err(|e| format!("{}: {e}", output.display()))?;
    let mut points = Vec::new();
    for model in plan.models {
        for &c in plan.planes {
            for &m in plan.ms {
                for solver in plan.solvers {
                    let how = case_file::ElasticSolver::named(solver)
                        .map_err(|e| format!("--solvers: {e}"))?;
                    let solver = how.name();
                    let file = cases.join(format!("cantilever_{model}.toml"));
                    let edit = resize(c, m, plan.tolerance);
                    let mut case =
                        case_file::load_with(&file, Level::Quick, how, Some(&edit as Edit))?;
                    if !(m == 3.0 && [7, 13].contains(&c)) {
                        case.name = format!("cantilever_{model}_{c}planes_m{m}");
                    }
                    case.plot = None;
                    let dir = output.join(format!("{}_{solver}", case.name));
                    eprintln!("sweep      {} by {solver} ...", case.name);
                    let lattice = lattice_reference(&case)?;
                    let o = run_case(&case, &dir, plan.threads)?;
                    let lattice_error = 100.0 * (o.measured - lattice.value) / lattice.value;
                    eprintln!(
                        "           {:+.2} % (lattice moduli {lattice_error:+.2} %) in {:.1} s ({} particles)",
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
                        lattice_error_percent: lattice_error,
                        lattice_youngs_ratio: lattice.youngs_ratio,
                        converged: o.converged,
                        seconds: o.seconds,
                        force_evaluations: o.force_evaluations,
                    });
                }
            }
        }
    }
    report_sweep(output, &points)
}

/// A cantilever's reference with the lattice's own moduli.
struct LatticeReference {
    value: f64,
    /// E along [100] over the deck's E.
    youngs_ratio: f64,
}

/// The reference of `case` with its lattice's E along [100] and G = C44 in place of the deck's
/// isotropic E and G (the beam lies along x, a lattice axis).
fn lattice_reference(case: &super::Case) -> Result<LatticeReference, String> {
    let formula = case
        .formula_of
        .as_ref()
        .ok_or_else(|| format!("case {} has no formula to evaluate", case.name))?;
    let table: toml::Table = toml::from_str(&case.deck).map_err(|e| e.to_string())?;
    let scene = deck::parse(&case.deck, &format!("{}.toml", case.name), &case.name)
        .map_err(|e| format!("case {}: {e}", case.name))?;
    let c = super::lattice::constants_of(&table, &scene)?;
    let moduli = super::formulas::Moduli {
        youngs: c.youngs_modulus_100(),
        shear: c.c44,
    };
    let value = formula.evaluate_with(&scene, Some(moduli))?.value;
    // The cantilevers have one material.
    let e = scene
        .materials
        .first()
        .and_then(|m| {
            m.quantity("youngs_modulus", crate::model::Dimension::STRESS)
                .ok()
        })
        .flatten()
        .ok_or("the cantilever's material has no youngs_modulus")?;
    Ok(LatticeReference {
        value,
        youngs_ratio: moduli.youngs / e,
    })
}

/// The sweep's table, `sweep.md` and `sweep.png` (|error| against log run time).
fn report_sweep(output: &Path, points: &[SweepPoint]) -> Result<String, String> {
    let mut t = String::from("| model | planes across | m | solver | particles | error % (isotropic E, ν) | error % (lattice E[100], C44) | lattice E[100]/E | converged | force evaluations | run time s |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for p in points {
        let converged = match p.converged {
            Some(true) => "yes",
            Some(false) => "**no**",
            None => "-",
        };
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {:+.2} | {:+.2} | {:.4} | {converged} | {} | {:.1} |",
            p.model,
            p.cells,
            p.m,
            p.solver,
            p.particles,
            p.error_percent,
            p.lattice_error_percent,
            p.lattice_youngs_ratio,
            p.force_evaluations,
            p.seconds
        );
    }
    // Error against run time, one series per model and solver.
    let mut series_points: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for p in points {
        let name = format!("{} {}", p.model, p.solver);
        let xy = (p.seconds.max(1e-3).log10(), p.error_percent.abs());
        match series_points.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => v.push(xy),
            None => series_points.push((name, vec![xy])),
        }
    }
    let series: Vec<crate::output::plot::Series> = series_points
        .iter()
        .map(|(n, pts)| crate::output::plot::Series {
            name: n,
            points: pts,
            mark: crate::output::plot::Mark::Points,
        })
        .collect();
    let png = output.join("sweep.png");
    crate::output::plot::xy(
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

/// ADR against an explicit load ramp on the quick LPS cantilever (`cases/cantilever_lps.toml`):
/// the explicit run ramps the load over `ramp_periods` periods of the beam's first bending mode
/// and holds it for three; the smallest relative residual it reaches after the ramp is then
/// asked of ADR, and the force evaluations of both are compared. Returns the lines to print.
pub fn compare_adr(
    output: &Path,
    cases: &Path,
    threads: usize,
    ramp_periods: f64,
) -> Result<String, String> {
    if !(ramp_periods.is_finite() && ramp_periods > 0.0) {
        return Err(format!(
            "--ramp-periods must be a number of periods > 0 (got {ramp_periods})"
        ));
    }
    let deck = case_file::deck_table(&cases.join("cantilever_lps.toml"))?;
    // First bending period: ω₁ = 1.875² √(EI / (ρ A L⁴)) with the case's section and span.
    let (e, rho, h, span): (f64, f64, f64, f64) = (10.0e9, 2400.0, 0.07, 0.70);
    let omega = 1.875f64.powi(2) * (e * h * h / 12.0 / rho).sqrt() / (span * span);
    let period = 2.0 * std::f64::consts::PI / omega;
    // The explicit ramp as PDQ runs it by default (Δt = 0.8 × the Silling–Askari bound), then
    // at 0.8 × its measured critical step, the limit an explicit code could step at.
    let mut out = String::new();
    for critical_step in ["bound", "measured"] {
        let ramp = Ramp {
            periods: ramp_periods,
            period,
            critical_step,
        };
        out.push_str(&compare_once(&deck, output, threads, &ramp)?);
    }
    Ok(out)
}

/// The explicit load ramp of [`compare_adr`].
struct Ramp<'a> {
    periods: f64,
    period: f64,
    critical_step: &'a str,
}

impl Ramp<'_> {
    /// The cantilever's deck made an explicit run: no `[solver]`, the load ramped over the
    /// ramp and held for three periods, a history row every 20 steps.
    fn explicit(&self, deck: &toml::Table) -> Result<toml::Table, String> {
        let mut deck = deck.clone();
        deck.remove("solver");
        let time = deck
            .get_mut("time")
            .and_then(Value::as_table_mut)
            .ok_or("no [time]")?;
        let duration = (self.periods + 3.0) * self.period;
        time.insert("duration".into(), Value::from(format!("{duration} s")));
        time.insert("critical_step".into(), Value::from(self.critical_step));
        let mut history = toml::Table::new();
        let ramp = format!("{} s", self.periods * self.period);
        history.insert("ramp".into(), Value::from(ramp));
        entry(&mut deck, "load", Some("tip"))?.insert("history".into(), Value::Table(history));
        let output = deck
            .get_mut("output")
            .and_then(Value::as_table_mut)
            .ok_or("no [output]")?;
        output.insert("history_every".into(), Value::from(20));
        output.remove("frames_every");
        Ok(deck)
    }
}

/// Runs a deck table quietly into `dir`; the summary and the seconds it took.
fn run_table(
    deck: &toml::Table,
    dir: &Path,
    threads: usize,
) -> Result<(run::Summary, f64), String> {
    let text = toml::to_string(deck).map_err(|e| e.to_string())?;
    let scene =
        deck::parse(&text, "compare.toml", "compare").map_err(|e| format!("compare: {e}"))?;
    let t = Instant::now();
    let s = run::run(
        &scene,
        &RunOptions {
            output: Some(dir.to_path_buf()),
            quiet: true,
            threads: Some(threads),
            ..Default::default()
        },
    )?;
    Ok((s, t.elapsed().as_secs_f64()))
}

/// One explicit ramp of [`compare_adr`], and ADR to the smallest residual it reached after
/// the ramp.
fn compare_once(
    deck: &toml::Table,
    output: &Path,
    threads: usize,
    ramp: &Ramp,
) -> Result<String, String> {
    let critical_step = ramp.critical_step;
    let dir = output.join(format!("compare_explicit_{critical_step}"));
    let (s, explicit_seconds) = run_table(&ramp.explicit(deck)?, &dir, threads)?;
    let (header, rows) = read_history(&dir)?;
    let col = |name: &str| column(&header, name);
    let (time, load, force) = (col("time")?, col("load_tip")?, col("residual_force")?);
    let step = col("step")?;
    let reactions: Vec<usize> = ["x", "y", "z"]
        .iter()
        .map(|c| col(&format!("reaction_clamp_{c}")))
        .collect::<Result<_, _>>()?;
    let relative = |r: &[f64]| {
        let scale = (r[load].powi(2) + reactions.iter().map(|&k| r[k].powi(2)).sum::<f64>()).sqrt();
        r[force] / scale.max(f64::MIN_POSITIVE)
    };
    let ramp_end = ramp.periods * ramp.period;
    let (best_row, best) = rows
        .iter()
        .filter(|r| r[time] >= ramp_end)
        .map(|r| (r, relative(r)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or("the explicit run has no rows after its ramp")?;
    let explicit_evaluations = best_row[step] as u64;
    let mut adr = deck.clone();
    let solver = adr
        .get_mut("solver")
        .and_then(Value::as_table_mut)
        .ok_or("no [solver]")?;
    solver.insert("tolerance".into(), Value::from(best));
    let adr_dir = output.join(format!("compare_adr_{critical_step}"));
    let (a, adr_seconds) = run_table(&adr, &adr_dir, threads)?;
    Ok(format!(
        "explicit load ramp, Δt from the {critical_step} critical step ({} periods of {:.2} ms, then held for 3; {} steps in all, {explicit_seconds:.1} s): smallest relative residual after the ramp {best:.2e}, reached at step {explicit_evaluations}\nADR to the same residual: {} force evaluations ({adr_seconds:.1} s)\nratio explicit/ADR force evaluations: {:.1}\n",
        ramp.periods,
        1e3 * ramp.period,
        s.steps,
        a.force_evaluations,
        explicit_evaluations as f64 / a.force_evaluations.max(1) as f64
    ))
}
