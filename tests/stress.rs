//! The stability stress tests of `pdq stress` (docs/stability.md), at sizes a test can afford.

use pdq::lab::stress::{self, Failure, Lattice, StressOptions};

#[test]
fn the_bound_is_below_the_measured_critical_step_on_every_lattice() {
    for lattice in [Lattice::Regular, Lattice::Jittered, Lattice::SteelConcrete] {
        for model in ["pmb", "micropolar"] {
            let r = stress::critical_step(model, lattice, 6, 400, 6).unwrap();
            println!(
                "{model} {}: critical / bound between {:.3} and {:.3}",
                lattice.name(),
                r.lo,
                r.hi
            );
            // The default safety factor 0.8 leaves a margin only if the true limit is above
            // the bound; velocity Verlet's limit 2/ω_max is below 4 × the Gershgorin bound.
            assert!(
                r.lo > 1.2,
                "{model} {}: stable only to {}",
                lattice.name(),
                r.lo
            );
            assert!(
                r.hi < 4.0,
                "{model} {}: no blow-up below {}",
                lattice.name(),
                r.hi
            );
        }
    }
}

#[test]
fn the_measured_critical_step_is_the_empirical_one() {
    for lattice in [Lattice::Regular, Lattice::Jittered, Lattice::SteelConcrete] {
        for model in ["pmb", "concrete", "lps", "micropolar"] {
            let r = stress::critical_step(model, lattice, 6, 400, 8).unwrap();
            let empirical = (r.lo * r.hi).sqrt();
            println!(
                "{model} {}: empirical {empirical:.3}, measured {:.3} (× bound)",
                lattice.name(),
                r.measured
            );
            assert!(
                (empirical / r.measured - 1.0).abs() < stress::MEASURED_AGREEMENT,
                "{model} {}: empirical {empirical:.3} against measured {:.3}",
                lattice.name(),
                r.measured
            );
        }
    }
}

#[test]
fn energy_stays_within_its_integration_error_over_a_long_vibration() {
    for model in ["pmb", "lps", "thermal"] {
        let r = stress::drift(model, 5, 4000, false).unwrap();
        println!(
            "{model}: largest |E - E0|/E0 {:.2e}, drift {:+.2e}, heat {:?}",
            r.largest, r.drift, r.content_change
        );
        assert!(r.largest < 0.1, "{model}: energy strays by {}", r.largest);
        assert!(
            r.drift.abs() < 1e-3,
            "{model}: energy drifts by {}",
            r.drift
        );
        if let Some(c) = r.content_change {
            assert!(c.abs() < 1e-12, "heat content changes by {c}");
        }
    }
}

/// At 0.8 × the measured critical step (about twice the bound's Δt) the energy error is
/// larger, as Δt², but still an oscillation, not a growth: velocity Verlet stays symplectic
/// below its limit (docs/stability.md).
#[test]
fn energy_stays_bounded_at_the_measured_critical_step() {
    for model in ["pmb", "lps", "micropolar"] {
        // The quick level's block (`pdq stress --quick`): on 5³ the oscillation's mean over a
        // tenth of 4000 steps is too coarse a drift estimate at this step.
        let at_bound = stress::drift(model, 6, 10_000, false).unwrap();
        let r = stress::drift(model, 6, 10_000, true).unwrap();
        println!(
            "{model}: Δt {:.2} × bound; largest |E - E0|/E0 {:.2e} (at the bound {:.2e}), drift {:+.2e}",
            r.dt_factor, r.largest, at_bound.largest, r.drift
        );
        assert!(
            r.dt_factor > 1.2,
            "{model}: the measured step is longer than the bound"
        );
        assert!(r.largest < 0.3, "{model}: energy strays by {}", r.largest);
        assert!(
            r.drift.abs() < 5e-3,
            "{model}: energy drifts by {}",
            r.drift
        );
        // Larger than at the bound, by about the ratio of the steps squared.
        let expected = (r.dt_factor / at_bound.dt_factor).powi(2);
        let ratio = r.largest / at_bound.largest;
        assert!(
            ratio > 0.5 * expected && ratio < 2.0 * expected,
            "{model}: error ratio {ratio:.2} against (Δt ratio)² {expected:.2}"
        );
    }
}

#[test]
fn sudden_failure_leaves_finite_state_and_bounded_energy() {
    for case in [Failure::Cut, Failure::Shatter, Failure::Impact(1000.0)] {
        let r = stress::failure("pmb", case, 150).unwrap();
        println!(
            "{}: {} of {} bonds broken, largest E/E0 {:.4}, final {:.4}",
            case.name(),
            r.broken,
            r.bonds,
            r.largest,
            r.last
        );
        assert!(r.finite, "{}: non-finite state", case.name());
        assert!(r.broken > 0, "{}: nothing broke", case.name());
        assert!(
            r.largest < 1.05,
            "{}: energy grew to {}",
            case.name(),
            r.largest
        );
        assert!(r.fastest < 0.5, "{}: a particle ran away", case.name());
    }
}

#[test]
fn unknown_models_and_sections_are_refused_by_name() {
    let opts = |models: &[&str], sections: &[&str]| StressOptions {
        quick: true,
        sections: sections.iter().map(|s| s.to_string()).collect(),
        models: models.iter().map(|s| s.to_string()).collect(),
        threads: 1,
    };
    let e = stress::run(&opts(&["pbm"], &[])).unwrap_err();
    assert!(e.contains("'pbm'"), "{e}");
    let e = stress::run(&opts(&[], &["speed"])).unwrap_err();
    assert!(e.contains("'speed'"), "{e}");
}
