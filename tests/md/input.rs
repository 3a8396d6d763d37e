//! The molecular-dynamics input (issue 23): fcc and bcc lattices given by density, periodic
//! boxes of whole cells, Lennard-Jones units, the Maxwell–Boltzmann start and the bondless
//! point model.

use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;
use pdq::input::setup::build_as;
use pdq::models::point::Point;

/// An lj deck of `cells`³ fcc cells at reduced density 0.8442, periodic along x, y and z.
fn fcc_deck(cells: usize, extra: &str) -> String {
    let head = crate::common::fcc_box(0.8442, cells, 0.0);
    format!("{head}[time]\ndt = 0.005\nsteps = 10\n{extra}")
}

fn scene(text: &str) -> Result<deck::Scene, String> {
    deck::parse(text, "md.toml", "md").map_err(|e| e.to_string())
}

#[test]
fn a_periodic_fcc_box_has_period_n_a_and_twelve_neighbours_across_it() {
    let s = scene(&fcc_deck(10, "")).unwrap();
    let setup = build_as::<Point>(&s).unwrap();
    let x = &setup.sim.particles.x0;
    assert_eq!(x.len(), 4000);
    let a = (4.0f64 / 0.8442).cbrt();
    for p in setup.domain.period {
        assert!((p - 10.0 * a).abs() < 1e-12 * p, "{p}");
        assert!((p - 16.796).abs() < 1e-3, "{p}");
    }
    // Every particle, counted over minimum images: 12 neighbours at a/√2, none nearer.
    let near = a / 2f64.sqrt();
    let period = setup.domain.period;
    for (i, xi) in x.iter().enumerate() {
        let mut count = 0;
        for (j, xj) in x.iter().enumerate() {
            if i == j {
                continue;
            }
            let r2: f64 = (0..3)
                .map(|k| {
                    let d = xj[k] - xi[k];
                    let d = d - period[k] * (d / period[k]).round();
                    d * d
                })
                .sum();
            let r = r2.sqrt();
            assert!(
                r > near * (1.0 - 1e-9),
                "particles {i} and {j} are {r} apart"
            );
            if r < near * (1.0 + 1e-9) {
                count += 1;
            }
        }
        assert_eq!(count, 12, "particle {i} at {xi:?}");
    }
}

#[test]
fn density_spacing_and_kind_are_checked() {
    let with = |from: &str, to: &str| scene(&fcc_deck(3, "").replace(from, to));
    let both = with(
        "density = 0.8442\nperiodic",
        "density = 0.8442\nspacing = 1.0\nperiodic",
    );
    assert!(both
        .unwrap_err()
        .contains("md.toml:4: [lattice] give 'spacing'"));
    let neither = with("density = 0.8442\nperiodic", "periodic").unwrap_err();
    assert!(neither.contains("needs 'spacing'"), "{neither}");
    let kind = with("\"fcc\"", "\"hcp\"").unwrap_err();
    assert!(kind.contains("unknown kind 'hcp'"), "{kind}");
    let s = with("\"fcc\"", "\"bcc\"").unwrap();
    assert!((s.spacing - (2.0f64 / 0.8442).cbrt()).abs() < 1e-15);
}

#[test]
fn lj_decks_take_plain_numbers_only() {
    let s = scene(&fcc_deck(3, "")).unwrap();
    assert_eq!(s.units, pdq::input::units::UnitSystem::Lj);
    let text = fcc_deck(3, "").replace("dt = 0.005", "dt = \"0.005 s\"");
    let err = scene(&text).unwrap_err();
    assert!(
        err.contains("md.toml:16: time.dt = \"0.005 s\" has a unit")
            && err.contains("plain numbers"),
        "{err}"
    );
    let text = fcc_deck(3, "").replace("density = 0.8442\n[[", "density = \"0.8 kg/m^3\"\n[[");
    let err = scene(&text).unwrap_err();
    assert!(err.contains("md.toml:9: materials.argon.density"), "{err}");
    // A name that starts with a digit is no quantity.
    assert!(scene(&format!("title = \"3D argon\"\n{}", fcc_deck(3, ""))).is_ok());
}

#[test]
fn the_point_model_needs_dt_and_no_horizon() {
    let no_dt = fcc_deck(3, "").replace("dt = 0.005\n", "");
    let err = scene(&no_dt).unwrap_err();
    assert!(
        err.contains(
            "md.toml:15: [time] model point has no bonds to bound the time step; give [time] dt"
        ),
        "{err}"
    );
    let factor = fcc_deck(3, "").replace("dt = 0.005", "dt = 0.005\nsafety_factor = 0.5");
    assert!(scene(&factor).unwrap_err().contains("safety_factor"));
    let horizon = fcc_deck(3, "").replace("name = \"point\"", "name = \"point\"\nm = 3");
    let err = scene(&horizon).unwrap_err();
    assert!(
        err.contains("md.toml:2: [model] model 'point' has no bonds"),
        "{err}"
    );
    let adr = format!("{}[solver]\nkind = \"adr\"\n", fcc_deck(3, ""));
    assert!(scene(&adr)
        .unwrap_err()
        .contains("only kind = \"explicit\""));
}

#[test]
fn the_maxwell_boltzmann_start_has_the_temperature_and_no_momentum() {
    let extra = "[velocity]\ntemperature = 1.44\nseed = 87287\n";
    let s = scene(&fcc_deck(4, extra)).unwrap();
    let setup = build_as::<Point>(&s).unwrap();
    let p = &setup.sim.particles;
    let (mut momentum, mut scale, mut twice_ke) = ([0.0; 3], 0.0, 0.0);
    let mass = 1.0 / p.inv_inertia[0].force[0];
    assert!((mass - 1.0).abs() < 1e-12, "{mass}");
    for a in &p.alter[..p.n_owned] {
        for (m, v) in momentum.iter_mut().zip(a.vel) {
            *m += mass * v;
            scale += mass * v.abs();
            twice_ke += mass * v * v;
        }
    }
    assert!(
        momentum.iter().all(|c| c.abs() < 1e-12 * scale),
        "{momentum:?}"
    );
    let t = twice_ke / (3.0 * p.n_owned as f64 - 3.0);
    assert!((t - 1.44).abs() < 1e-12 * 1.44, "{t}");
    // [velocity] wins over [[initial]]; another seed, other velocities.
    let initial = "[[initial]]\nvelocity = [5, 0, 0]\n";
    let both =
        build_as::<Point>(&scene(&fcc_deck(4, &format!("{initial}{extra}"))).unwrap()).unwrap();
    assert_eq!(both.sim.particles.alter[0].vel, p.alter[0].vel);
    let other = scene(&fcc_deck(4, &extra.replace("87287", "87288"))).unwrap();
    let other = build_as::<Point>(&other).unwrap();
    assert_ne!(other.sim.particles.alter[0].vel, p.alter[0].vel);
    let bad = scene(&fcc_deck(4, &extra.replace("87287", "-1"))).unwrap_err();
    assert!(bad.contains("seed must be an integer"), "{bad}");
}

#[test]
fn the_lj_melt_runs_small_and_keeps_its_energy() {
    // The example at 6 × 6 × 6 fcc cells (864 atoms) instead of 20³.
    let text = std::fs::read_to_string("inputs/lj_melt.toml")
        .unwrap()
        .replace("max = [33.5, 33.5, 33.5]", "max = [10, 10, 10]");
    let scene = deck::parse(&text, "lj_melt.toml", "lj_melt").unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-md-{}", std::process::id()));
    let s = run(
        &scene,
        &RunOptions {
            output: Some(dir.clone()),
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(s.particles, 864);
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let rows: Vec<&str> = history.lines().collect();
    assert_eq!(rows.len(), 1 + 11, "{history}");
    let col = |name: &str| rows[0].split(',').position(|c| c == name).unwrap();
    let value = |row: &str, k: usize| row.split(',').nth(k).unwrap().parse::<f64>().unwrap();
    let (ke, total, pe) = (
        col("kinetic_energy"),
        col("total_energy"),
        col("pair_energy"),
    );
    // The start is at T* = 1.44 exactly: KE = (3N − 3)·T/2.
    let want = 0.5 * (3.0 * 864.0 - 3.0) * 1.44;
    assert!(
        (value(rows[1], ke) - want).abs() < 1e-9 * want,
        "{}",
        rows[1]
    );
    // The perfect fcc crystal at ρ* = 0.8442, LJ cut (unshifted) at 2.5σ: LAMMPS's in.lj prints
    // E_pair = -6.7733681 per atom at step 0 (any box of whole cells wider than two cutoffs).
    let pe0 = value(rows[1], pe) / 864.0;
    assert!(
        (pe0 + 6.7733681).abs() < 1e-6,
        "potential energy per atom at the start {pe0}"
    );
    // NVE with velocity Verlet while the crystal melts. The unshifted cut makes the energy jump
    // by U(r_c) whenever a pair crosses the cutoff (as in LAMMPS's lj/cut), so what velocity
    // Verlet conserves is the energy of the shifted potential: total − pairs·U(r_c). Its error
    // is 1.9e-4 at Δt = 0.005 over the melt's first 100 steps, 5.9e-5 at Δt/2 and 1.5e-5 at Δt/4
    // (second order); the unshifted total is off by 2e-3 whatever Δt (the jumps).
    let u_cut = 4.0 * (2.5f64.powi(-12) - 2.5f64.powi(-6));
    let pairs = col("pairs_in_range");
    let shifted = |row: &str| value(row, total) - value(row, pairs) * u_cut;
    let e0 = shifted(rows[1]);
    for row in &rows[2..] {
        let drift = (shifted(row) - e0).abs() / e0.abs();
        assert!(drift < 4e-4, "energy drift {drift:e}: {row}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
