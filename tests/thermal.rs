//! Heat conduction against Fourier's law: a bar with a temperature step in the middle spreads
//! it as T = ½ erfc((x − x_s) / (2√(αt))), α = k/(ρc). The bar is periodic across its section,
//! so every particle sees a whole family and the answer is one-dimensional.

use pdq::input::{deck, setup};
use pdq::parallel;
use pdq::parallel::decomposition::{Procs, Walls};

/// erfc by Abramowitz & Stegun 7.1.26 (|error| < 1.5e-7), plenty for a 2 % check.
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.3275911 * z);
    let poly = t
        * (0.254829592
            + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    let e = poly * (-z * z).exp();
    if x >= 0.0 {
        e
    } else {
        2.0 - e
    }
}

fn bar_deck(length: usize, duration: f64, safety: f64) -> String {
    format!(
        r#"
units = "SI"
[model]
name = "thermal"
m = 3
[lattice]
spacing = "1 mm"
periodic = ["y", "z"]
[materials.slab]
density = "1000 kg/m^3"
# Mechanically very soft: conduction, not sound, sets the time step.
bulk_modulus = "0.001 Pa"
thermal_conductivity = 1.0
specific_heat = 1000.0
[[geometry]]
shape = "box"
material = "slab"
min = "0 0 0 mm"
max = "{length} 10 10 mm"
[[initial]]
region = {{ shape = "box", min = "0 0 0 mm", max = "{half} 10 10 mm" }}
temperature = 1.0
[time]
duration = "{duration} s"
safety_factor = {safety}
[output]
progress = false
"#,
        half = length / 2
    )
}

/// The bar after 36 s on `threads` procCubes along x, against the erf solution.
fn erf_error(threads: usize, safety: f64) -> Conduction {
    let (length, duration) = (120, 36.0);
    let scene = deck::parse(&bar_deck(length, duration, safety), "bar.toml", "bar").unwrap();
    let s = setup::build_as::<pdq::models::thermal::Thermal>(&scene).unwrap();
    let layout =
        parallel::layout(&s, &Procs::Given([threads, 1, 1]), threads, Walls::Whole).unwrap();
    let steps = s.steps;
    let dt = s.sim.dt;
    let cubes = parallel::thread_cubes(&s, &layout);
    let rows = parallel::on_threads(cubes, |mut c| {
        c.start();
        for _ in 0..steps {
            c.advance().unwrap();
        }
        let p = &c.sim.particles;
        (0..p.n_owned)
            .map(|i| (p.x0[i][0], p.alter[i].temperature))
            .collect::<Vec<_>>()
    });
    let t = steps as f64 * dt;
    let xs = 0.5 * length as f64 * 1e-3;
    let profile: Vec<(f64, f64)> = rows.into_iter().flatten().collect();
    let misfit = |diffusivity: f64| -> (f64, f64) {
        let mut worst: f64 = 0.0;
        let mut squares = 0.0;
        for &(x, temp) in &profile {
            let exact = 0.5 * erfc((x - xs) / (2.0 * (diffusivity * t).sqrt()));
            worst = worst.max((temp - exact).abs());
            squares += (temp - exact).powi(2);
        }
        (worst, squares)
    };
    // The diffusivity that fits best (golden section), against k/(ρc).
    let target = 1.0 / (1000.0 * 1000.0);
    let (mut a, mut b) = (0.5 * target, 1.5 * target);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if misfit(c).1 < misfit(d).1 {
            b = d;
        } else {
            a = c;
        }
    }
    Conduction {
        worst: misfit(target).0,
        fitted: 0.5 * (a + b) / target,
        profile,
    }
}

struct Conduction {
    /// Largest |T − T_erf| (the step is 1).
    worst: f64,
    /// Best-fitting diffusivity over k/(ρc).
    fitted: f64,
    profile: Vec<(f64, f64)>,
}

#[test]
fn a_temperature_step_spreads_as_the_erf_solution() {
    let c = erf_error(1, 0.5);
    println!(
        "max |T - T_erf| = {:.4} (step height 1); fitted diffusivity / (k/rho c) = {:.4}",
        c.worst, c.fitted
    );
    assert!(c.worst < 0.02, "max |T - T_erf| = {}", c.worst);
    assert!(
        (c.fitted - 1.0).abs() < 0.02,
        "diffusivity off by {:.2}%",
        100.0 * (c.fitted - 1.0)
    );
}

#[test]
fn conduction_does_not_depend_on_the_layout() {
    let one = erf_error(1, 0.8).profile;
    let three = erf_error(3, 0.8).profile;
    let sorted = |mut v: Vec<(f64, f64)>| {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    let (one, three) = (sorted(one), sorted(three));
    assert_eq!(one.len(), three.len());
    let d = one
        .iter()
        .zip(&three)
        .map(|(a, b)| (a.1 - b.1).abs())
        .fold(0.0, f64::max);
    println!("1 vs 3 procCubes: max temperature difference {d:.2e}");
    assert!(d < 1e-12, "temperatures differ by {d}");
}
