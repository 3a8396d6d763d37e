//! Conservation in free motion: energy in an elastic vibration for every model, angular
//! momentum (with the particles' spins) for micropolar bodies spinning through large angles.

use pdq::input::{deck, setup};
use pdq::model::Model;
use pdq::models::micropolar::Micropolar;

fn block(model: &str, material: &str, options: &str) -> String {
    format!(
        r#"
units = "SI"
[model]
name = "{model}"
m = 3
{options}
[lattice]
spacing = "1 mm"
[materials.solid]
density = "2000 kg/m^3"
{material}
[[geometry]]
shape = "box"
material = "solid"
min = "0 0 0 mm"
max = "7 7 7 mm"
[time]
steps = 1
safety_factor = 0.5
[output]
progress = false
"#
    )
}

/// A deterministic pseudo-random number in [−1, 1) for particle `i`, component `k`.
fn noise(i: usize, k: usize) -> f64 {
    let mut x = (i as u64 * 6364136223846793005 + k as u64 * 1442695040888963407) ^ 0x9e37_79b9;
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51afd7ed558ccd);
    x ^= x >> 33;
    (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// Largest relative change of the total energy over `steps` from a smooth initial velocity
/// field of size `v`.
fn energy_drift<M: Model>(text: &str, v: f64, steps: usize) -> f64 {
    let scene = deck::parse(text, "b.toml", "b").unwrap();
    let mut s = setup::build_as::<M>(&scene).unwrap();
    let n2 = pdq::model::second_order::<M>();
    // A smooth velocity field (the body's low modes, so that the time step resolves them):
    // a stretch along x, a bend along y, and spins of the shear rate's order.
    for i in 0..s.sim.particles.len() {
        let x = s.sim.particles.x0[i];
        let phase = |k: usize| (std::f64::consts::PI * x[k] / 7e-3).sin();
        let vel = s.sim.particles.velocity_mut(i);
        vel[0] = v * phase(0);
        vel[1] = 0.5 * v * phase(0) * phase(2);
        for (k, w) in vel.iter_mut().enumerate().take(n2).skip(3) {
            *w = v / 7e-3 * phase(k - 3);
        }
    }
    s.sim.compute_forces();
    let total = |s: &setup::Setup<M>| s.sim.kinetic_energy() + s.sim.strain_energy();
    let e0 = total(&s);
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        s.sim.advance();
        worst = worst.max((total(&s) - e0).abs() / e0);
    }
    assert_eq!(
        s.sim.bonds.broken_count(),
        0,
        "the vibration must stay elastic"
    );
    worst
}

#[test]
fn every_model_conserves_energy_in_an_elastic_vibration() {
    use pdq::models::{concrete::Concrete, lps::Lps, pmb::Pmb, thermal::Thermal};
    let e = "youngs_modulus = \"10 GPa\"";
    type Run = fn(&str, usize) -> f64;
    let cases: [(&str, String, Run); 5] = [
        ("pmb", block("pmb", e, ""), |t, n| energy_drift::<Pmb>(t, 0.01, n)),
        (
            "concrete",
            block(
                "concrete",
                "kind = \"concrete\"\nyoungs_modulus = \"10 GPa\"\npoisson_ratio = 0.25\ntensile_stretch = 0.01\ncompressive_stretch = -0.01",
                "",
            ),
            |t, n| energy_drift::<Concrete>(t, 0.01, n),
        ),
        (
            "lps",
            block("lps", &format!("{e}\npoisson_ratio = 0.3"), ""),
            |t, n| energy_drift::<Lps>(t, 0.01, n),
        ),
        (
            "micropolar",
            block("micropolar", &format!("{e}\npoisson_ratio = 0.2"), "[model.options]\nkappa = 0.1"),
            |t, n| energy_drift::<Micropolar>(t, 0.01, n),
        ),
        (
            "thermal",
            block("thermal", &format!("{e}\nthermal_conductivity = 1.0\nspecific_heat = 1000.0"), ""),
            |t, n| energy_drift::<Thermal>(t, 0.01, n),
        ),
    ];
    for (name, text, run) in cases {
        // Velocity Verlet's energy error is bounded and second order: a quarter of it at half
        // the step, over the same time. A force that is not the gradient of the energy
        // (a wrong moment, a wrong sign) drifts instead, and does not shrink so.
        let coarse = run(&text, 400);
        let fine = run(
            &text.replace("safety_factor = 0.5", "safety_factor = 0.25"),
            800,
        );
        println!(
            "{name}: largest relative energy change {coarse:.2e} (dt), {fine:.2e} (dt/2), ratio {:.2}",
            coarse / fine
        );
        assert!(coarse < 1e-2, "{name}: energy changes by {coarse:e}");
        assert!(coarse / fine > 3.0, "{name}: energy error not second order");
    }
}

/// Σ x × m v + J ω over the body.
fn angular_momentum(s: &setup::Setup<Micropolar>) -> [f64; 3] {
    let p = &s.sim.particles;
    let mut l = [0.0; 3];
    for i in 0..p.len() {
        let a = &p.alter[i];
        let inv = &p.inv_inertia[i];
        let (x, v) = (a.pos, a.vel);
        let m = 1.0 / inv.force[0];
        let j = 1.0 / inv.moment[0];
        let c = [
            x[1] * v[2] - x[2] * v[1],
            x[2] * v[0] - x[0] * v[2],
            x[0] * v[1] - x[1] * v[0],
        ];
        for k in 0..3 {
            l[k] += m * c[k] + j * a.angular_velocity[k];
        }
    }
    l
}

#[test]
fn a_free_spinning_micropolar_body_keeps_its_angular_momentum() {
    let text = block(
        "micropolar",
        "youngs_modulus = \"10 GPa\"\npoisson_ratio = 0.1",
        "[model.options]\nkappa = 0.2",
    );
    let scene = deck::parse(&text, "b.toml", "b").unwrap();
    let mut s = setup::build_as::<Micropolar>(&scene).unwrap();
    // Spin about a skew axis fast enough to turn through several radians, plus noise that
    // makes the body vibrate and its particles spin unevenly.
    let omega = [3000.0, -2000.0, 5000.0];
    let c = [0.0035; 3];
    for i in 0..s.sim.particles.len() {
        let a = &mut s.sim.particles.alter[i];
        let r = [a.pos[0] - c[0], a.pos[1] - c[1], a.pos[2] - c[2]];
        a.vel = [
            omega[1] * r[2] - omega[2] * r[1] + 0.01 * noise(i, 0),
            omega[2] * r[0] - omega[0] * r[2] + 0.01 * noise(i, 1),
            omega[0] * r[1] - omega[1] * r[0] + 0.01 * noise(i, 2),
        ];
        for (k, (w, o)) in a.angular_velocity.iter_mut().zip(omega).enumerate() {
            *w = o * (1.0 + 0.1 * noise(i, k + 3));
        }
    }
    s.sim.compute_forces();
    let l0 = angular_momentum(&s);
    let norm = (l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]).sqrt();
    let steps = 6000;
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        s.sim.advance();
        let l = angular_momentum(&s);
        let d = ((l[0] - l0[0]).powi(2) + (l[1] - l0[1]).powi(2) + (l[2] - l0[2]).powi(2)).sqrt();
        worst = worst.max(d / norm);
    }
    let turned = 6164.4 * s.sim.time;
    println!(
        "turned {turned:.2} rad in {steps} steps; largest relative change of angular momentum {worst:.2e}; broken bonds {}",
        s.sim.bonds.broken_count()
    );
    assert!(turned > 3.0, "the body must turn through large angles");
    assert!(worst < 1e-12, "angular momentum changes by {worst:e}");
}
