//! Engine properties that must hold for any deck: conservation, bond history, breaking rule,
//! time-step checks, and the bond search.

use pdq::input::deck;
use pdq::input::setup::{build_as, Setup};
use pdq::models::concrete::Concrete;
use pdq::models::pmb::Pmb;

/// A PMB block of `nx × ny × nz` particles at 1 mm spacing, horizon 3.015 mm, plus `extra` TOML.
fn block(nx: usize, ny: usize, nz: usize, material: &str, extra: &str) -> String {
    format!(
        r#"units = "SI"
[model]
name = "pmb"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.rock]
density = "2200 kg/m^3"
bulk_modulus = "14.9 GPa"
{material}
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "{nx} {ny} {nz} mm"
[output]
progress = false
{extra}"#
    )
}

fn setup_pmb(text: &str) -> Setup<Pmb> {
    let scene = deck::parse(text, "test.toml", "test").expect("deck parses");
    build_as::<Pmb>(&scene).expect("setup builds")
}

fn momentum_scale(s: &Setup<Pmb>) -> f64 {
    let p = &s.sim.particles;
    (0..p.n_owned)
        .map(|i| {
            let v = p.velocity(i);
            p.volume[i] * 2200.0 * (v[0].abs() + v[1].abs() + v[2].abs())
        })
        .sum()
}

#[test]
fn free_body_conserves_linear_momentum() {
    // Two regions thrown at each other hard enough to break bonds: momentum must still hold.
    let text = block(
        10,
        8,
        8,
        "critical_stretch = 0.001",
        r#"[time]
steps = 300
[[initial]]
region = { shape = "box", min = "0 0 0 mm", max = "5 8 8 mm" }
velocity = "30 -5 2 m/s"
[[initial]]
region = { shape = "box", min = "5 0 0 mm", max = "10 8 8 mm" }
velocity = "-20 4 1 m/s"
"#,
    );
    let mut s = setup_pmb(&text);
    let p0 = s.sim.particles.momentum();
    let scale = momentum_scale(&s);
    for _ in 0..300 {
        s.sim.advance();
    }
    assert!(
        s.sim.bonds.broken_count() > 0,
        "the impact should break bonds"
    );
    let p1 = s.sim.particles.momentum();
    for k in 0..3 {
        assert!(
            (p1[k] - p0[k]).abs() <= 1e-12 * scale,
            "momentum component {k}: {} -> {} (scale {scale})",
            p0[k],
            p1[k]
        );
    }
}

#[test]
fn elastic_vibration_conserves_energy() {
    // A free block given a smooth stretching velocity field vibrates; no bond can break.
    let text = block(
        8,
        8,
        8,
        "",
        r#"[time]
steps = 10000
"#,
    );
    let mut s = setup_pmb(&text);
    assert!(
        (s.sim.dt / s.dt_critical - 0.8).abs() < 1e-12,
        "default safety factor"
    );
    let n = s.sim.particles.n_owned;
    for i in 0..n {
        let x = s.sim.particles.x0[i];
        let c = 0.004;
        let v = s.sim.particles.velocity_mut(i);
        v[0] = 2.0 * (x[0] - c);
        v[1] = -(x[1] - c);
        v[2] = 0.5 * (x[2] - c) * (x[0] - c) / c;
    }
    s.sim.compute_forces();
    let energy = |s: &Setup<Pmb>| s.sim.kinetic_energy() + s.sim.strain_energy();
    let e0 = energy(&s);
    let mut first = Vec::new();
    let mut last = Vec::new();
    for step in 1..=10_000 {
        s.sim.advance();
        if step <= 1000 {
            first.push(energy(&s));
        } else if step > 9000 {
            last.push(energy(&s));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let drift = (mean(&last) - mean(&first)).abs() / e0;
    let min_strain = s.sim.strain_energy();
    assert!(min_strain > 0.0);
    assert_eq!(s.sim.bonds.broken_count(), 0);
    eprintln!("relative energy drift over 10,000 steps: {drift:e}");
    assert!(
        drift < 1e-4,
        "relative energy drift {drift:e} over 10,000 steps"
    );
}

#[test]
fn a_broken_bond_stays_broken_when_the_crack_closes() {
    // Two halves pulled apart (bonds across the middle break), pushed back to where they
    // started, then pulled apart again by less than the critical stretch: the thesis code
    // re-formed the bonds here; PDQ must carry no force across the crack.
    let text = block(
        12,
        4,
        4,
        "critical_stretch = 0.001",
        r#"[time]
steps = 300
dt = "1e-8 s"
[[boundary]]
name = "left"
region = { shape = "box", min = "0 0 0 mm", max = "6 4 4 mm" }
displacement = "-0.05 0 0 mm"
history = { table = [["0 s", 0], ["1e-6 s", 1], ["2e-6 s", 0], ["3e-6 s", 0.02]] }
[[boundary]]
name = "right"
region = { shape = "box", min = "6 0 0 mm", max = "12 4 4 mm" }
displacement = "0.05 0 0 mm"
history = { table = [["0 s", 0], ["1e-6 s", 1], ["2e-6 s", 0], ["3e-6 s", 0.02]] }
"#,
    );
    let mut s = setup_pmb(&text);
    for _ in 0..100 {
        s.sim.advance();
    }
    let broken_open: Vec<bool> = s.sim.bonds.broken.clone();
    let count_open = broken_open.iter().filter(|&&b| b).count();
    assert!(
        count_open > 0,
        "pulling apart must break the bonds across the middle"
    );
    for _ in 0..100 {
        s.sim.advance();
    }
    // Closed again: every particle back at its reference position.
    for i in 0..s.sim.particles.n_owned {
        let u = s.sim.particles.displacement(i);
        assert!(
            u.iter().all(|c| c.abs() < 1e-12),
            "particle {i} not back: {u:?}"
        );
    }
    assert_eq!(
        s.sim.bonds.broken, broken_open,
        "closing the crack changed the broken set"
    );
    for _ in 0..100 {
        s.sim.advance();
    }
    // Reopened by 2% of the first opening (stretch across the crack far below s0).
    assert_eq!(s.sim.bonds.broken, broken_open);
    let reaction = s.sim.constraints[0].reaction[0];
    assert!(
        reaction.abs() < 1e-12,
        "a force {reaction} N is carried across a broken crack"
    );
}

/// `head` (units, model, lattice, materials) plus two particles of `material`, cubes of side
/// `h` two spacings apart: a scene of exactly one bond.
fn two_particles(head: &str, material: &str, h: f64) -> String {
    format!(
        r#"{head}
[[geometry]]
shape = "box"
material = "{material}"
min = [0, 0, 0]
max = [{h:e}, {h:e}, {h:e}]
[[geometry]]
shape = "box"
material = "{material}"
min = [{h2:e}, 0, 0]
max = [{h3:e}, {h:e}, {h:e}]
[time]
steps = 1
[output]
progress = false
"#,
        h2 = 2.0 * h,
        h3 = 3.0 * h
    )
}

/// Two particles at distance 2 mm, the right one displaced to stretch `s`.
fn pair_after_stretch(s: f64, s0: f64) -> bool {
    let text = format!(
        r#"units = "SI"
[model]
name = "pmb"
horizon = "3.015 mm"
partial_volume = false
[lattice]
spacing = "1 mm"
[materials.rock]
density = 2200
bulk_modulus = 14.9e9
critical_stretch = {s0:e}
"#
    );
    let text = two_particles(&text, "rock", 0.001);
    let mut st = setup_pmb(&text);
    assert_eq!(st.sim.bonds.len(), 1);
    let p = &mut st.sim.particles;
    let right = (0..2).find(|&i| p.x0[i][0] > 0.001).unwrap();
    p.alter[right].pos[0] = p.x0[right][0] + s * 0.002;
    st.sim.compute_forces();
    st.sim.bonds.broken[0]
}

#[test]
fn bonds_break_exactly_when_stretch_exceeds_critical() {
    let s0 = 0.0005;
    assert!(!pair_after_stretch(s0 * (1.0 - 1e-9), s0));
    assert!(!pair_after_stretch(0.0, s0));
    assert!(
        !pair_after_stretch(-0.5, s0),
        "compression never breaks a PMB bond"
    );
    assert!(pair_after_stretch(s0 * (1.0 + 1e-9), s0));
    assert!(pair_after_stretch(10.0 * s0, s0));
}

#[test]
fn a_time_step_above_critical_is_refused() {
    let text = block(6, 6, 6, "", "[time]\nsteps = 10\ndt = \"1e-6 s\"\n");
    let scene = deck::parse(&text, "test.toml", "test").unwrap();
    let err = build_as::<Pmb>(&scene).err().expect("must be refused");
    let msg = err.to_string();
    assert!(msg.contains("above the stable time step"), "{msg}");
    assert!(
        msg.contains("force_dt"),
        "the message says how to override: {msg}"
    );
    // Forcing it is allowed.
    let forced = text.replace("dt = \"1e-6 s\"", "dt = \"1e-6 s\"\nforce_dt = true");
    let scene = deck::parse(&forced, "test.toml", "test").unwrap();
    assert!(build_as::<Pmb>(&scene).is_ok());
}

#[test]
fn semi_implicit_euler_runs_and_conserves_momentum() {
    let text = block(
        6,
        6,
        6,
        "",
        "[time]\nsteps = 200\nintegrator = \"euler\"\n[[initial]]\nregion = { shape = \"box\", min = \"0 0 0 mm\", max = \"3 6 6 mm\" }\nvelocity = \"1 0 0 m/s\"\n",
    );
    let mut s = setup_pmb(&text);
    let p0 = s.sim.particles.momentum();
    for _ in 0..200 {
        s.sim.advance();
    }
    let p1 = s.sim.particles.momentum();
    assert!((p1[0] - p0[0]).abs() < 1e-12 * p0[0].abs());
    assert!(s.sim.strain_energy() > 0.0);
}

#[test]
fn steel_bond_keeps_its_plastic_stretch() {
    // One steel bond stretched past yield and released keeps a permanent set: at zero force
    // its length is the plastic stretch, which the bond history holds.
    let text = r#"units = "in-lbf-s"
[model]
name = "concrete"
horizon = "3 in"
partial_volume = false
[lattice]
spacing = "1 in"
[materials.steel]
kind = "steel"
density = "490 lb/ft^3"
youngs_modulus = "29000 ksi"
poisson_ratio = 0.3
yield_stretch = 0.01
"#;
    let text = two_particles(text, "steel", 1.0);
    let scene = deck::parse(&text, "t.toml", "t").unwrap();
    let mut st = build_as::<Concrete>(&scene).unwrap();
    let right = (0..2).find(|&i| st.sim.particles.x0[i][0] > 1.0).unwrap();
    let stretch_to = |st: &mut Setup<Concrete>, s: f64| {
        st.sim.particles.alter[right].pos[0] = st.sim.particles.x0[right][0] + 2.0 * s;
        st.sim.compute_forces();
        st.sim.particles.force[right].force[0]
    };
    let f_yield = stretch_to(&mut st, 0.01).abs();
    let f_beyond = stretch_to(&mut st, 0.03).abs();
    assert!(
        (f_beyond - f_yield).abs() < 1e-9 * f_yield,
        "perfectly plastic"
    );
    assert!((st.sim.bonds.history[0].plastic_stretch - 0.02).abs() < 1e-12);
    let f_back = stretch_to(&mut st, 0.02);
    assert!(
        f_back.abs() < 1e-9 * f_yield,
        "unloaded to the plastic stretch: no force"
    );
    let f_compressed = stretch_to(&mut st, 0.015);
    assert!(
        f_compressed > 0.0,
        "shorter than the set length pushes the particles apart"
    );
    assert!(!st.sim.bonds.broken[0]);
}

/// The head of a two-particle deck of the thesis's concrete at `horizon` (in), its tensile
/// failure given by the line `failure`.
fn thesis_concrete(horizon: f64, failure: &str) -> String {
    format!(
        r#"units = "in-lbf-s"
[model]
name = "concrete"
horizon = "{horizon} in"
[lattice]
spacing = "1 in"
[materials.concrete]
kind = "concrete"
density = "145 lb/ft^3"
youngs_modulus = "3605 ksi"
poisson_ratio = 0.25
{failure}
compressive_stretch = -1.1e-3
"#
    )
}

#[test]
fn concrete_bond_breaks_in_tension_and_compression() {
    let text = |s_t: f64| thesis_concrete(3.0, &format!("tensile_stretch = {s_t:e}"));
    for (s, broken) in [
        (1.0e-4, false),
        (1.5e-4, true),
        (-1.0e-3, false),
        (-1.2e-3, true),
    ] {
        let deck_text = two_particles(&text(1.387e-4), "concrete", 1.0);
        let scene = deck::parse(&deck_text, "t.toml", "t").unwrap();
        let mut st = build_as::<Concrete>(&scene).unwrap();
        let right = (0..2).find(|&i| st.sim.particles.x0[i][0] > 1.0).unwrap();
        st.sim.particles.alter[right].pos[0] = st.sim.particles.x0[right][0] + 2.0 * s;
        st.sim.compute_forces();
        assert_eq!(st.sim.bonds.broken[0], broken, "stretch {s}");
        // Back to zero stretch: the broken bond stays broken and carries nothing.
        st.sim.particles.alter[right].pos[0] = st.sim.particles.x0[right][0];
        st.sim.particles.alter[right].pos[1] = st.sim.particles.x0[right][1] + 0.01;
        st.sim.compute_forces();
        assert_eq!(st.sim.bonds.broken[0], broken);
        if broken {
            assert_eq!(st.sim.particles.force[right].force, [0.0; 3]);
        }
    }
}

#[test]
fn concrete_fracture_energy_sets_the_tensile_stretch_from_the_horizon() {
    // At ν = ¼ the thesis's micromodulus makes G_F = π c δ⁵ s_t²/10 = 1.2 E δ s_t²: the
    // fracture energy of the thesis's stretch at its 3 in horizon must break the bond where
    // that stretch does, and the same energy at twice the horizon at a stretch 1/√2 as large.
    let (e, s_t) = (3.605e6, 1.387e-4);
    let text = thesis_concrete;
    let g_f = 1.2 * e * 3.0 * s_t * s_t;
    for (horizon, at) in [(3.0, s_t), (6.0, s_t / 2f64.sqrt())] {
        for (s, broken) in [(0.97 * at, false), (1.03 * at, true)] {
            let failure = format!("fracture_energy = \"{g_f:e} lbf/in\"");
            let deck_text = two_particles(&text(horizon, &failure), "concrete", 1.0);
            let scene = deck::parse(&deck_text, "t.toml", "t").unwrap();
            let mut st = build_as::<Concrete>(&scene).unwrap();
            let right = (0..2).find(|&i| st.sim.particles.x0[i][0] > 1.0).unwrap();
            st.sim.particles.alter[right].pos[0] = st.sim.particles.x0[right][0] + 2.0 * s;
            st.sim.compute_forces();
            assert_eq!(st.sim.bonds.broken[0], broken, "δ {horizon}, stretch {s}");
        }
    }
    for (failure, says) in [
        (
            format!("tensile_stretch = {s_t:e}\nfracture_energy = \"1 lbf/in\""),
            "not both",
        ),
        (
            String::new(),
            "needs 'tensile_stretch' or 'fracture_energy'",
        ),
    ] {
        let deck_text = two_particles(&text(3.0, &failure), "concrete", 1.0);
        let err = deck::parse(&deck_text, "t.toml", "t")
            .map_err(|e| e.to_string())
            .and_then(|scene| {
                build_as::<Concrete>(&scene)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            })
            .unwrap_err();
        assert!(err.contains(says), "{err}");
    }
}

#[test]
fn two_identical_materials_give_the_single_material_result() {
    // The bond loop has a fast path for scenes of one material; a scene of two materials with
    // the same properties takes the general path and must give bit-identical results.
    let props = "critical_stretch = 0.001";
    let extra = r#"[time]
steps = 200
[[initial]]
region = { shape = "box", min = "0 0 0 mm", max = "5 8 8 mm" }
velocity = "30 -5 2 m/s"
"#;
    let one = block(10, 8, 8, props, extra);
    let two = one.replace(
        "[[geometry]]",
        "[materials.twin]\ndensity = \"2200 kg/m^3\"\nbulk_modulus = \"14.9 GPa\"\ncritical_stretch = 0.001\n\n[[geometry]]",
    ) + "[[geometry]]\nshape = \"box\"\nmaterial = \"twin\"\nmin = \"0 0 4 mm\"\nmax = \"10 8 8 mm\"\n";
    let (mut a, mut b) = (setup_pmb(&one), setup_pmb(&two));
    assert_eq!(b.sim.model.laws().len(), 4, "two materials: four laws");
    for _ in 0..200 {
        a.sim.advance();
        b.sim.advance();
    }
    assert!(a.sim.bonds.broken_count() > 0);
    assert_eq!(a.sim.bonds.broken, b.sim.bonds.broken);
    for i in 0..a.sim.particles.n_owned {
        assert_eq!(
            a.sim.particles.alter[i], b.sim.particles.alter[i],
            "particle {i}"
        );
    }
}

#[test]
fn bonds_at_exactly_the_horizon_are_all_kept() {
    // m = 3 on a 1 mm lattice puts 30 of an interior particle's 122 neighbours at exactly the
    // horizon; rounding of the coordinates must not decide which of them bond. The origin is
    // shifted to an awkward value so the coordinates are not exact in binary.
    let text = block(9, 9, 9, "", "[time]\nsteps = 1\n")
        .replace("horizon = \"3.015 mm\"", "m = 3")
        .replace(
            "spacing = \"1 mm\"",
            "spacing = \"1 mm\"\norigin = \"0.013 0.027 0.0031 mm\"",
        )
        .replace("min = \"0 0 0 mm\"", "min = \"0.013 0.027 0.0031 mm\"")
        .replace("max = \"9 9 9 mm\"", "max = \"9.013 9.027 9.0031 mm\"");
    let s = setup_pmb(&text);
    let p = &s.sim.particles;
    assert_eq!(p.n_owned, 729);
    let centre = (0..p.n_owned)
        .min_by(|&a, &b| {
            let d = |i: usize| {
                (0..3)
                    .map(|k| (p.x0[i][k] * 1e3 - 4.5).powi(2))
                    .sum::<f64>()
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    assert_eq!(s.sim.bonds.initial[centre], 122);
    // Every interior particle (3 spacings from every face) has the full family.
    for i in 0..p.n_owned {
        let x = p.x0[i].map(|c| c * 1e3);
        let inner = [0.013, 0.027, 0.0031]
            .iter()
            .enumerate()
            .all(|(k, o)| x[k] - o > 3.4 && x[k] - o < 5.6);
        if inner {
            assert_eq!(s.sim.bonds.initial[i], 122, "particle {i} at {x:?}");
        }
    }
}

#[test]
fn the_same_deck_gives_bit_identical_results() {
    let text = std::fs::read_to_string("inputs/pmb_block.toml").unwrap();
    let run = || {
        let mut s = setup_pmb(&text);
        for _ in 0..400 {
            s.sim.advance();
        }
        s
    };
    let (a, b) = (run(), run());
    assert!(a.sim.bonds.broken_count() > 0, "the run should crack");
    assert_eq!(a.sim.bonds.broken, b.sim.bonds.broken);
    assert!(a.sim.particles.alter == b.sim.particles.alter);
}

/// The bond sweep runs PMB four bonds per lane group; groups with a broken bond, groups in
/// which a bond breaks now and the ends of lists go one bond at a time. Through a crack that
/// opens step by step (bonds breaking in the very passes compared), its forces and broken flags
/// are those of the PMB loop written by hand one bond at a time, bit for bit.
/// The lane-sweep tests' crack: the halves x < 6 mm and x ≥ 6 mm pulled apart by `a` each,
/// sheared and squeezed across in proportion, so that each pass opens it further.
fn open_crack<M: pdq::model::Model<Alter = pdq::models::pmb::Motion>>(
    p: &mut pdq::engine::particles::Particles<M>,
    a: f64,
) {
    for i in 0..p.len() {
        let x0 = p.x0[i];
        let side = if x0[0] < 6e-3 { -1.0 } else { 1.0 };
        p.alter[i].pos = [
            x0[0] + side * a,
            x0[1] + 0.3 * a * x0[2] / 4e-3,
            x0[2] - 0.2 * side * a,
        ];
    }
}

#[test]
fn the_lane_sweep_gives_the_one_bond_forces_and_breaks() {
    use pdq::engine::forces::pair_pass;
    use pdq::lab::bench::yardstick::hand_pmb_pass;
    let text = block(12, 5, 4, "critical_stretch = 0.001", "[time]\nsteps = 1\n");
    let mut s = setup_pmb(&text);
    let law = s.sim.model.laws()[0];
    let sim = &mut s.sim;
    let mut passes_with_breaks = 0;
    for t in 0..40 {
        open_crack(&mut sim.particles, 1e-7 * t as f64);
        let mut hand_broken = sim.bonds.broken.clone();
        let before = hand_broken.iter().filter(|&&b| b).count();
        let mut hand_force = vec![[0.0f64; 3]; sim.particles.len()];
        hand_pmb_pass(
            &sim.particles.alter,
            &sim.particles.volume,
            sim.bonds.offsets(),
            sim.bonds.partners(),
            &sim.bonds.geom,
            &mut hand_broken,
            &mut hand_force,
            law.c,
            law.s0,
        );
        let newly = pair_pass(&sim.model, &mut sim.particles, &mut sim.bonds);
        assert_eq!(
            sim.bonds.broken, hand_broken,
            "pass {t}: broken flags differ"
        );
        assert_eq!(newly, hand_broken.iter().filter(|&&b| b).count() - before);
        for (i, f) in hand_force.iter().enumerate() {
            let g = sim.particles.force[i].force;
            assert!(
                g.iter().zip(f).all(|(a, b)| a.to_bits() == b.to_bits()),
                "pass {t}, particle {i}: {g:?} against {f:?}"
            );
        }
        passes_with_breaks += usize::from(newly > 0);
    }
    let broken = sim.bonds.broken.iter().filter(|&&b| b).count();
    assert!(
        passes_with_breaks >= 3 && broken > 100,
        "the crack must open during the compared passes: {passes_with_breaks} passes broke bonds, {broken} broken in all"
    );
}

/// The concrete model's lane sweep (four concrete or interface bonds at a time, steel bonds
/// one by one) gives, pass after pass while a reinforced block cracks and its bar yields, the
/// forces, broken flags and plastic stretches of `Model::pair` called bond by bond in bond
/// order, bit for bit.
#[test]
fn the_concrete_lane_sweep_gives_the_one_bond_forces_history_and_breaks() {
    use pdq::engine::forces::pair_pass;
    use pdq::model::Model;
    let text = r#"units = "SI"
[model]
name = "concrete"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.concrete]
kind = "concrete"
density = "2400 kg/m^3"
youngs_modulus = "30 GPa"
poisson_ratio = 0.2
tensile_stretch = 0.001
compressive_stretch = -0.004
[materials.steel]
kind = "steel"
density = "7850 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.3
yield_stretch = 0.0015
[[geometry]]
shape = "box"
material = "concrete"
min = "0 0 0 mm"
max = "12 5 4 mm"
[[bar]]
material = "steel"
area = "0.5 mm^2"
from = "0.5 2.5 1.5 mm"
to = "11.5 2.5 1.5 mm"
[time]
steps = 1
[output]
progress = false
"#;
    let scene = deck::parse(text, "test.toml", "test").expect("deck parses");
    let mut s = build_as::<Concrete>(&scene).expect("setup builds");
    let sim = &mut s.sim;
    let (mut passes_with_breaks, mut yielded) = (0, false);
    for t in 0..40 {
        open_crack(&mut sim.particles, 2e-7 * t as f64);
        let (mut broken, mut history) = (sim.bonds.broken.clone(), sim.bonds.history.clone());
        let before = broken.iter().filter(|&&b| b).count();
        let mut force = vec![[0.0f64; 3]; sim.particles.len()];
        let offsets = sim.bonds.offsets().to_vec();
        for i in 0..offsets.len() - 1 {
            let mut fi = [0.0; 3];
            for b in offsets[i] as usize..offsets[i + 1] as usize {
                let j = sim.bonds.partners()[b] as usize;
                if broken[b] {
                    continue;
                }
                let p = &sim.particles;
                let law = sim.model.law(p.material[i], p.material[j]);
                let geom = sim.bonds.geom[b];
                match sim
                    .model
                    .pair(&law, &p.side(i), &p.side(j), &geom, &mut history[b])
                {
                    Some((a, c)) => (0..3).for_each(|k| {
                        fi[k] += a.force[k];
                        force[j][k] += c.force[k];
                    }),
                    None => broken[b] = true,
                }
            }
            (0..3).for_each(|k| force[i][k] += fi[k]);
        }
        let newly = pair_pass(&sim.model, &mut sim.particles, &mut sim.bonds);
        assert_eq!(sim.bonds.broken, broken, "pass {t}: broken flags differ");
        assert_eq!(newly, broken.iter().filter(|&&b| b).count() - before);
        let bits = |h: &[pdq::models::concrete::PlasticStretch]| {
            h.iter()
                .map(|h| h.plastic_stretch.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(
            bits(&sim.bonds.history),
            bits(&history),
            "pass {t}: history"
        );
        for (i, f) in force.iter().enumerate() {
            let g = sim.particles.force[i].force;
            assert!(
                g.iter().zip(f).all(|(a, b)| a.to_bits() == b.to_bits()),
                "pass {t}, particle {i}: {g:?} against {f:?}"
            );
        }
        passes_with_breaks += usize::from(newly > 0);
        yielded |= history.iter().any(|h| h.plastic_stretch != 0.0);
    }
    let broken = sim.bonds.broken.iter().filter(|&&b| b).count();
    assert!(
        passes_with_breaks >= 3 && broken > 100 && yielded,
        "the block must crack and the bar yield during the compared passes: {passes_with_breaks} passes broke bonds, {broken} broken, yielded {yielded}"
    );
}
