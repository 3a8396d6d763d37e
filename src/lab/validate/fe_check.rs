//! `pdq validate --fe-check`: are the beam formulas fair references? Each elastic case's
//! reference (Timoshenko cantilever or simply supported beam, `formulas.rs`) against linear 3D
//! elasticity by finite elements (`elasticity_fe.rs`) on the case's own body, supports, load
//! and read-out, at several element orders, so that the mesh's own error shows.
//!
//! How a deck becomes an elasticity problem: the body is the deck's first box; a cantilever's
//! clamp holds the whole face at the clamp's end (the clamped particles are rigid), a simply
//! supported beam's supports are lines across the width under the bottom face at the centre
//! of each support's region (as the formula takes them), held in the support's components;
//! a load is a uniform body force over its region with the load's total; the deflection is
//! read at the probes' points as the case's measure reads it.

use super::elasticity_fe::{planes_through, BodyLoad, Problem, Support};
use super::formulas::{self, Formula};
use super::measures::Measure;
use super::{Case, Level};
use crate::input::deck::{self, Scene};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

pub struct FeCheckOptions {
    pub cases: PathBuf,
    pub level: Level,
    /// Case names (every elastic beam case when empty).
    pub only: Vec<String>,
    pub output: PathBuf,
    /// Element orders, each a solve.
    pub orders: Vec<usize>,
    /// Elements across the beam's depth (and at most that length along it).
    pub elements_across: usize,
}

/// One case checked.
pub struct FeRow {
    pub case: String,
    /// The formula's deflection.
    pub formula: f64,
    /// (order, unknowns, the elasticity deflection read as the case reads it, seconds).
    pub solves: Vec<(usize, usize, f64, f64)>,
}

impl FeRow {
    /// The finest solve's deflection over the formula's.
    pub fn ratio(&self) -> f64 {
        self.solves.last().map_or(f64::NAN, |s| s.2) / self.formula
    }
}

/// Checks the chosen cases; returns the report (also written to `fe_check.md`) and the rows.
pub fn fe_check(opts: &FeCheckOptions) -> Result<(String, Vec<FeRow>), String> {
    if opts.orders.is_empty() || opts.elements_across == 0 {
        return Err("--fe-check needs at least one element order and one element across".into());
    }
    let all = super::cases(&opts.cases, opts.level, super::ElasticSolver::Implicit)?;
    let beams: Vec<&Case> = all.iter().filter(|c| is_beam(c)).collect();
    for name in &opts.only {
        if !beams.iter().any(|c| &c.name == name) {
            let names: Vec<&str> = beams.iter().map(|c| c.name.as_str()).collect();
            return Err(format!(
                "no elastic beam case '{name}' to check (cases: {})",
                names.join(", ")
            ));
        }
    }
    let mut rows = Vec::new();
    for case in beams
        .iter()
        .filter(|c| opts.only.is_empty() || opts.only.contains(&c.name))
    {
        rows.push(check_case(case, &opts.orders, opts.elements_across)?);
    }
    let report = report(&rows, opts);
    std::fs::create_dir_all(&opts.output).map_err(|e| format!("{}: {e}", opts.output.display()))?;
    let path = opts.output.join("fe_check.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((report, rows))
}

fn is_beam(case: &Case) -> bool {
    matches!(
        case.formula_of,
        Some(Formula::TimoshenkoCantilever { .. } | Formula::TimoshenkoSimplySupported { .. })
    )
}

/// The case's deflection by elasticity at each order.
pub fn check_case(case: &Case, orders: &[usize], across: usize) -> Result<FeRow, String> {
    let scene = deck::parse(&case.deck, &format!("{}.toml", case.name), &case.name)
        .map_err(|e| format!("case {}: {e}", case.name))?;
    let at = |e: String| format!("case {}: the finite-element check: {e}", case.name);
    let mut solves = Vec::new();
    for &order in orders {
        let start = Instant::now();
        let problem = problem_of(case, &scene, order, across).map_err(at)?;
        let solution = problem.solve().map_err(at)?;
        let probe = |name: &str| -> Result<f64, String> {
            let p = scene
                .probes
                .iter()
                .find(|p| p.name == name)
                .ok_or(format!("no probe '{name}'"))?;
            Ok(solution.displacement_at(p.at)?[2])
        };
        let deflection = match &case.measure_of {
            Some(Measure::DeflectionAt { probes }) => {
                let sum: Result<f64, String> = probes.iter().map(|n| probe(n)).sum();
                -sum.map_err(at)? / probes.len() as f64
            }
            Some(Measure::DeflectionBetween { mid, ends }) => {
                let ends = (probe(&ends[0]).map_err(at)? + probe(&ends[1]).map_err(at)?) / 2.0;
                -(probe(mid).map_err(at)? - ends)
            }
            _ => {
                return Err(at(
                    "it reads deflection_at or deflection_between measures only".into(),
                ))
            }
        };
        solves.push((
            order,
            solution.unknowns,
            deflection,
            start.elapsed().as_secs_f64(),
        ));
    }
    Ok(FeRow {
        case: case.name.clone(),
        formula: case.reference,
        solves,
    })
}

/// The elasticity problem of a beam case at element order `order`, `across` elements deep.
fn problem_of(case: &Case, scene: &Scene, order: usize, across: usize) -> Result<Problem, String> {
    let body = formulas::beam_body(scene)?;
    let (lo, hi) = (body.min, body.max);
    let longest = (hi[2] - lo[2]) / across as f64;
    let (mut start, mut breaks, mut supports, load) = (
        lo[0],
        [vec![], vec![], vec![]],
        vec![],
        match &case.formula_of {
            Some(
                Formula::TimoshenkoCantilever { load, .. }
                | Formula::TimoshenkoSimplySupported { load, .. },
            ) => load,
            _ => return Err("not a beam formula".into()),
        },
    );
    match &case.formula_of {
        Some(Formula::TimoshenkoCantilever { clamp, .. }) => {
            start = formulas::clamp_face(scene, clamp)?;
            supports.push(Support {
                at: [Some(start), None, None],
                dofs: [true; 3],
            });
        }
        Some(Formula::TimoshenkoSimplySupported {
            supports: names, ..
        }) => {
            for name in names {
                let x = formulas::region_centre(scene, name)?;
                let (rlo, _) =
                    formulas::region_box(formulas::boundary_region(scene, name)?, lo, hi, name)?;
                if rlo[2] > lo[2] + scene.spacing {
                    return Err(format!("support '{name}' is not at the bottom face: lines under the bottom face only"));
                }
                let spec = scene
                    .boundaries
                    .iter()
                    .find(|b| &b.name == name)
                    .ok_or(format!("no boundary '{name}'"))?;
                let dofs = [0, 1, 2].map(|c| spec.dofs.contains(&c));
                supports.push(Support {
                    at: [Some(x), None, Some(lo[2])],
                    dofs,
                });
                breaks[0].push(x);
            }
        }
        _ => unreachable!("checked above"),
    }
    let (llo, lhi) = formulas::region_box(formulas::load_region(scene, load)?, lo, hi, load)?;
    for a in 0..3 {
        breaks[a].extend([llo[a], lhi[a]]);
    }
    let starts = [start, lo[1], lo[2]];
    Ok(Problem {
        planes: [0, 1, 2].map(|a| planes_through(starts[a], hi[a], &breaks[a], longest)),
        order,
        youngs: body.youngs,
        poisson: body.poisson,
        supports,
        loads: vec![BodyLoad {
            lo: llo,
            hi: lhi,
            total: formulas::total_force(scene, load)?,
        }],
    })
}

fn report(rows: &[FeRow], opts: &FeCheckOptions) -> String {
    let mut s = format!(
        "# Beam formulas against 3D elasticity (`pdq validate --fe-check {}`, {} elements across the depth)\n\n",
        opts.level.flag(),
        opts.elements_across
    );
    s.push_str("| case | order | unknowns | elasticity deflection | change from the order before | formula | elasticity / formula | run time s |\n|---|---|---|---|---|---|---|---|\n");
    for row in rows {
        let mut before = None;
        for &(order, unknowns, value, seconds) in &row.solves {
            let change = before.map_or("".into(), |b: f64| format!("{:+.2e}", value / b - 1.0));
            let _ = writeln!(
                s,
                "| {} | {order} | {unknowns} | {value:.6e} | {change} | {:.6e} | {:.5} | {seconds:.1} |",
                row.case,
                row.formula,
                value / row.formula
            );
            before = Some(value);
        }
    }
    s
}
