//! The membrane model: a two-particle spring oscillates at ω = √(2k/m), a flat sheet at rest
//! stays at rest, and the stable step is the spring network's √(2m/Σk).

use pdq::input::deck;
use pdq::input::setup::build_as;
use pdq::models::membrane::Membrane;

/// A one-layer sheet of nx × ny particles 1 apart, k = 300, mass 2 (density 2, volume 1).
fn sheet(nx: usize, ny: usize, time: &str, extra: &str) -> deck::Scene {
    let text = format!(
        r#"units = "lj"
[model]
name = "membrane"
m = 1.5
[lattice]
spacing = 1
[materials.skin]
density = 2
spring_constant = 300
[[geometry]]
shape = "box"
material = "skin"
min = [0, 0, 0]
max = [{nx}, {ny}, 1]
[time]
{time}
{extra}"#
    );
    deck::parse(&text, "membrane.toml", "membrane").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_spring_oscillates_at_the_square_root_of_2k_over_m() {
    let (k, m) = (300.0f64, 2.0f64);
    let omega = (2.0 * k / m).sqrt();
    let period = 2.0 * std::f64::consts::PI / omega;
    let dt = period / 2000.0;
    let extra = "[[initial]]\nregion = { ids = [0] }\nvelocity = [-0.01, 0, 0]\n[[initial]]\nregion = { ids = [1] }\nvelocity = [0.01, 0, 0]\n";
    let scene = sheet(2, 1, &format!("dt = {dt}\nsteps = 1"), extra);
    let mut sim = build_as::<Membrane>(&scene).unwrap().sim;
    assert_eq!(sim.particles.n_owned, 2);
    let stretch = |sim: &pdq::engine::simulation::Simulation<Membrane>| {
        let (a, b) = (sim.particles.alter[0].pos, sim.particles.alter[1].pos);
        (b[0] - a[0]).abs() - 1.0
    };
    // Upward zero crossings of the stretch, linearly interpolated.
    let mut crossings = Vec::new();
    let mut before = stretch(&sim);
    while crossings.len() < 4 {
        sim.advance();
        let now = stretch(&sim);
        if before < 0.0 && now >= 0.0 {
            crossings.push(sim.time - dt * now / (now - before));
        }
        before = now;
        assert!(sim.step < 20_000, "no oscillation");
    }
    let measured = (crossings[3] - crossings[0]) / 3.0;
    assert!(
        (measured / period - 1.0).abs() < 1e-5,
        "period {measured} vs 2π/√(2k/m) = {period}"
    );
    // Amplitude: each end moves v/ω, so the spring stretches by 2v/ω at most.
    let energy = sim.strain_energy() + sim.kinetic_energy();
    assert!((energy - 0.5 * m * 2.0 * 0.01f64.powi(2)).abs() < 1e-4 * energy);
}

#[test]
fn a_flat_sheet_at_rest_stays_at_rest_and_its_step_is_the_spring_bound() {
    let scene = sheet(5, 4, "steps = 200", "");
    let setup = build_as::<Membrane>(&scene).unwrap();
    // An inner particle has 4 direct and 4 diagonal springs: √(2m / 8k).
    let hand = (2.0f64 * 2.0 / (8.0 * 300.0)).sqrt();
    assert!(
        (setup.dt_critical - hand).abs() < 1e-12 * hand,
        "{} vs {hand}",
        setup.dt_critical
    );
    let bonds = setup.sim.bonds.geom.len();
    // Direct: 4·4 + 5·3 = 31, diagonal 2·4·3 = 24.
    assert_eq!(bonds, 31 + 24);
    let mut sim = setup.sim;
    for _ in 0..200 {
        sim.advance();
    }
    for (a, x0) in sim.particles.alter.iter().zip(&sim.particles.x0) {
        assert_eq!(a.pos, *x0);
        assert_eq!(a.vel, [0.0; 3]);
    }
}

#[test]
fn the_membrane_horizon_picks_direct_and_diagonal_neighbours() {
    let text = |m: &str| {
        format!(
            "units = \"lj\"\n[model]\nname = \"membrane\"\nm = {m}\n[lattice]\nspacing = 1\n[materials.skin]\ndensity = 2\nspring_constant = 300\n[[geometry]]\nshape = \"box\"\nmaterial = \"skin\"\nmin = [0, 0, 0]\nmax = [3, 3, 1]\n[time]\nsteps = 1\n"
        )
    };
    for bad in ["1.2", "2.5"] {
        let scene = deck::parse(&text(bad), "m.toml", "m").unwrap();
        let err = build_as::<Membrane>(&scene).err().unwrap().to_string();
        assert!(
            err.contains("m.toml:2:") && err.contains("between √2 and 2"),
            "{err}"
        );
    }
    let no_k = text("1.5").replace("spring_constant = 300\n", "");
    let scene = deck::parse(&no_k, "m.toml", "m").unwrap();
    let err = build_as::<Membrane>(&scene).err().unwrap().to_string();
    assert!(err.contains("needs 'spring_constant'"), "{err}");
}
