//! The report of `pdq stress`: one Markdown section per test, and the expectations a stable
//! engine must meet (any broken one fails the command; CI runs it).

use super::*;
use crate::parallel::side_by_side;

/// The critical time step against the Silling–Askari bound, and the measured one.
pub(super) fn dt_section(
    models: &[&str],
    quick: bool,
    threads: usize,
    broken_expectations: &mut Vec<String>,
) -> Result<String, String> {
    let mut out = String::new();
    let (n, steps, halvings) = if quick { (8, 500, 6) } else { (12, 3000, 12) };
    let jobs: Vec<(&str, Lattice)> = models
        .iter()
        .flat_map(|&m| {
            [Lattice::Regular, Lattice::Jittered, Lattice::SteelConcrete].map(|l| (m, l))
        })
        .collect();
    let rows = side_by_side(&jobs, threads, |&(m, l)| {
        critical_step(m, l, n, steps, halvings)
    });
    let _ = writeln!(
        out,
        "## Critical time step against the Silling–Askari bound\n\n{n}³ lattice sites, m = 3, free block, random initial velocities (and rotation rates, temperatures); blow-up = kinetic energy (or temperature spread) over {GROWTH}× its start within {steps} steps; geometric bisection between 0.25 and 8 × the bound, {halvings} halvings.\n\nThe measured critical step (`[time] critical_step = \"measured\"`) is 2/√λ_max(M⁻¹K) from {LANCZOS_STEPS} Lanczos steps before the excitation; it should agree with the empirical limit.\n\n| model | lattice | particles | bound Δt (s) | empirical Δt_crit / bound | measured Δt_crit / bound | empirical / measured | run time (s) |\n|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        let r = r?;
        if r.lo < 1.0 {
            broken_expectations.push(format!(
                "{} {}: unstable below the bound (stable only to {:.3} × the bound)",
                r.model,
                r.lattice.name(),
                r.lo
            ));
        }
        let ratio = if r.hi.is_finite() {
            format!(
                "{:.3} (stable {:.3}, unstable {:.3})",
                (r.lo * r.hi).sqrt(),
                r.lo,
                r.hi
            )
        } else {
            format!("> {:.1}", r.lo)
        };
        let empirical = (r.lo * r.hi).sqrt();
        if r.hi.is_finite() && (empirical / r.measured - 1.0).abs() > MEASURED_AGREEMENT {
            broken_expectations.push(format!(
                "{} {}: the measured critical step is {:.3} × the bound, the empirical one {empirical:.3} ×: they differ by more than {:.0} %",
                r.model,
                r.lattice.name(),
                r.measured,
                100.0 * MEASURED_AGREEMENT
            ));
        }
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.4e} | {ratio} | {:.3} | {:.3} | {:.1} |",
            r.model,
            r.lattice.name(),
            r.particles,
            r.bound,
            r.measured,
            empirical / r.measured,
            r.seconds
        );
    }
    out.push('\n');
    Ok(out)
}

/// The energy drift of an elastic vibration.
pub(super) fn drift_section(
    models: &[&str],
    quick: bool,
    threads: usize,
) -> Result<String, String> {
    let mut out = String::new();
    let (n, steps) = if quick { (6, 10_000) } else { (8, 100_000) };
    let jobs: Vec<(&str, bool)> = models
        .iter()
        .flat_map(|&m| [(m, false), (m, true)])
        .collect();
    let rows = side_by_side(&jobs, threads, |&(m, measured)| {
        drift(m, n, steps, measured)
    });
    let _ = writeln!(
        out,
        "## Energy drift of an elastic vibration\n\n{n}³ free block, stretching mode along x (0.1 m/s at the ends) plus random velocities up to 0.01 m/s, unbreakable bonds, {steps} steps at the default safety factor (0.8) × the bound, then × the critical step measured on the stiffest mode (`critical_step = \"measured\"`, same number of steps, so a longer time); E = kinetic + elastic energy sampled every {} steps.\n\n| model | particles | steps | Δt / bound | E₀ (J) | largest abs(E − E₀)/E₀ | drift (last − first tenth)/E₀ | heat content change | run time (s) |\n|---|---|---|---|---|---|---|---|---|",
        (steps / 1000).max(1)
    );
    for r in rows {
        let r = r?;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2} | {:.4e} | {:.2e} | {:+.2e} | {} | {:.1} |",
            r.model,
            r.particles,
            r.steps,
            r.dt_factor,
            r.energy,
            r.largest,
            r.drift,
            r.content_change
                .map(|c| format!("{c:+.1e}"))
                .unwrap_or_else(|| "–".into()),
            r.seconds
        );
    }
    out.push('\n');
    Ok(out)
}

/// Sudden failure: cut, shatter and impact.
pub(super) fn failure_section(
    models: &[&str],
    quick: bool,
    threads: usize,
    broken_expectations: &mut Vec<String>,
) -> Result<String, String> {
    let mut out = String::new();
    let steps = if quick { 400 } else { 3000 };
    let cases = [
        Failure::Cut,
        Failure::Shatter,
        Failure::Impact(100.0),
        Failure::Impact(1000.0),
    ];
    // A model whose sample repeats another's mechanics (thermal without expansion: PMB plus
    // conduction) would repeat that model's rows.
    let mut own_mechanics = Vec::new();
    for &m in models {
        if sample(m, &solid(CONCRETE_E, 2400.0, FAILURE_S0, false))?
            .mechanics_of
            .is_none()
        {
            own_mechanics.push(m);
        }
    }
    let jobs: Vec<(&str, Failure)> = own_mechanics
        .iter()
        .flat_map(|&m| cases.map(|c| (m, c)))
        .collect();
    let rows = side_by_side(&jobs, threads, |&(m, c)| failure(m, c, steps));
    let _ = writeln!(
        out,
        "## Sudden failure\n\nCritical stretch s0 = {FAILURE_S0}; cut and shatter: 20 × 8 × 8 block stretched along x to ½ s0 and 3 s0; impact: 16 × 16 × 12 block whose top 6 × 6 × 3 patch moves into it. {steps} steps at the default safety factor. E = kinetic + elastic energy of intact bonds; E ≤ E₀ is expected, since a breaking bond takes its energy with it.\n\n| model | case | particles | broken bonds | largest E/E₀ | final E/E₀ | all finite | fastest particle (spacings per step) | run time (s) |\n|---|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        let r = r?;
        if !r.finite || r.largest > 1.1 || r.fastest >= 0.5 {
            broken_expectations.push(format!(
                "{} {}: finite {}, largest E/E0 {:.4}, fastest {:.3} spacings per step",
                r.model,
                r.case.name(),
                r.finite,
                r.largest,
                r.fastest
            ));
        }
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} of {} | {:.4} | {:.4} | {} | {:.3} | {:.1} |",
            r.model,
            r.case.name(),
            r.particles,
            r.broken,
            r.bonds,
            r.largest,
            r.last,
            if r.finite { "yes" } else { "**no**" },
            r.fastest,
            r.seconds
        );
    }
    out.push('\n');
    Ok(out)
}
