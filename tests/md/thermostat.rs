//! Thermostats (issue 23): Langevin and Nosé–Hoover sample the canonical kinetic energy (mean
//! and variance), Berendsen and rescale reach their target, Nosé–Hoover conserves its H and
//! restarts bit-identically, Langevin is the same on every layout; the deck's checks; and the
//! leapfrog, whose positions are velocity Verlet's.

use pdq::driver::run::RunOptions;
use pdq::input::{deck, setup};
use pdq::models::point::Point;
use pdq::parallel;
use pdq::parallel::decomposition::{Procs, Walls};
use std::path::PathBuf;

/// 500 LJ atoms: 5³ fcc cells at ρ* = 0.8442 in a periodic box, LJ cut at 2.5σ and shifted (so
/// that the energy has no jumps at the cutoff), Maxwell–Boltzmann start at `t_start`.
fn lj_deck(t_start: f64, steps: u64, extra: &str) -> String {
    let head = crate::common::fcc_box(0.8442, 5, 0.01);
    format!(
        r#"{head}[velocity]
temperature = {t_start}
seed = 87287
[pair]
law = "lj"
cutoff = 2.5
skin = 0.2
shift = true
[pair.materials.argon]
epsilon = 1.0
sigma = 1.0
[time]
dt = 0.005
steps = {steps}
[output]
progress = false
{extra}"#
    )
}

const N: f64 = 500.0;

fn scene(text: &str) -> Result<deck::Scene, String> {
    deck::parse(text, "t.toml", "t").map_err(|e| e.to_string())
}

/// Per step of a run on one procCube: kinetic energy, pair energy and the thermostat's
/// reservoir.
fn trace(text: &str, steps: usize) -> Vec<[f64; 3]> {
    let s = setup::build_as::<Point>(&scene(text).unwrap()).unwrap();
    let layout = parallel::layout(&s, &Procs::Given([1, 1, 1]), 1, Walls::Whole).unwrap();
    let mut c = parallel::thread_cubes(&s, &layout).pop().unwrap();
    c.start();
    let mut out = Vec::with_capacity(steps);
    for _ in 0..steps {
        c.advance().unwrap();
        let pe = c.sim.pairs.as_ref().unwrap().tally().energy;
        let r = c.sim.thermostat.as_ref().map_or(0.0, |t| t.reservoir());
        out.push([c.sim.kinetic_energy(), pe, r]);
    }
    out
}

/// Mean and variance of `x` with their standard errors from `blocks` block averages (each
/// block far longer than the correlation time, so that the blocks are independent).
fn block_stats(x: &[f64], blocks: usize) -> (f64, f64, f64, f64) {
    let len = x.len() / blocks;
    let mean = x[..len * blocks].iter().sum::<f64>() / (len * blocks) as f64;
    let (mut means, mut vars) = (Vec::new(), Vec::new());
    for b in x.chunks_exact(len) {
        means.push(b.iter().sum::<f64>() / len as f64);
        vars.push(b.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / len as f64);
    }
    let spread = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let s2 = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        (m, (s2 / v.len() as f64).sqrt())
    };
    let (m, m_err) = spread(&means);
    let (v, v_err) = spread(&vars);
    (m, m_err, v, v_err)
}

/// The canonical ⟨KE⟩ = (dof/2)·k_B·T₀ and var(KE) = (dof/2)·(k_B·T₀)², checked within four
/// standard errors of the block averages.
fn check_canonical(name: &str, ke: &[f64], dof: f64, t0: f64, blocks: usize) {
    let (m, m_err, v, v_err) = block_stats(ke, blocks);
    let (want_m, want_v) = (0.5 * dof * t0, 0.5 * dof * t0 * t0);
    eprintln!(
        "{name}: <KE> = {m:.3} ± {m_err:.3} (canonical {want_m:.3}), var KE = {v:.2} ± {v_err:.2} (canonical {want_v:.2}), {} steps in {blocks} blocks",
        ke.len()
    );
    assert!(
        (m - want_m).abs() < 4.0 * m_err,
        "{name}: mean {m} ± {m_err}, want {want_m}"
    );
    assert!(
        (v - want_v).abs() < 4.0 * v_err,
        "{name}: variance {v} ± {v_err}, want {want_v}"
    );
    // The errors must be small enough to tell: NVE's kinetic energy fluctuates about half as
    // much as the canonical one in this liquid, and a mean off by 1 % is a wrong temperature.
    assert!(
        v_err < 0.15 * want_v && m_err < 0.005 * want_m,
        "{name}: too few samples"
    );
}

const EQUILIBRATE: usize = 2_000;

#[test]
fn langevin_samples_the_canonical_kinetic_energy() {
    let t0 = 1.5;
    let text = lj_deck(
        t0,
        1,
        "[thermostat]\nkind = \"langevin\"\ntemperature = 1.5\ndamping = 0.5\nseed = 7\n",
    );
    let steps = 32_000;
    let run = trace(&text, EQUILIBRATE + steps);
    let ke: Vec<f64> = run[EQUILIBRATE..].iter().map(|r| r[0]).collect();
    // Langevin's random forces move the centre of mass too: all 3N DOFs are thermalized.
    check_canonical("langevin", &ke, 3.0 * N, t0, 32);
}

#[test]
fn nose_hoover_samples_the_canonical_kinetic_energy_and_conserves_its_h() {
    let t0 = 1.5;
    let text = lj_deck(
        t0,
        1,
        "[thermostat]\nkind = \"nose-hoover\"\ntemperature = 1.5\ndamping = 0.1\n",
    );
    let steps = 32_000;
    let run = trace(&text, EQUILIBRATE + steps);
    let ke: Vec<f64> = run[EQUILIBRATE..].iter().map(|r| r[0]).collect();
    check_canonical("nose-hoover", &ke, 3.0 * N - 3.0, t0, 32);
    // H = KE + PE + dof·k_B·T₀·η + ½Qξ² over the whole run: its drift is the integrator's
    // error, far below the kinetic energy's canonical spread √(dof/2)·k_B·T₀ ≈ 41.
    let h: Vec<f64> = run.iter().map(|r| r[0] + r[1] + r[2]).collect();
    let drift = h.iter().map(|x| (x - h[0]).abs()).fold(0.0, f64::max);
    let spread = (0.5 * (3.0 * N - 3.0)).sqrt() * t0;
    let kept: f64 = run
        .iter()
        .map(|r| (r[0] + r[1] - run[0][0] - run[0][1]).abs())
        .fold(0.0, f64::max);
    eprintln!("nose-hoover: H drifts by {drift:.3e} over {} steps; KE + PE alone by {kept:.3}; KE spread {spread:.1}", run.len());
    // Measured: 1.5 over 34,000 steps (the velocity-Verlet error and the force's jump at the
    // cutoff, which the energy shift does not remove).
    assert!(drift < 0.08 * spread, "H drifted by {drift}");
    // Without the reservoir the energy is not kept: the bound above can fail.
    assert!(kept > 10.0 * drift);
}

#[test]
fn berendsen_and_rescale_reach_their_target_and_count_what_they_take() {
    let dir = out_dir("berendsen");
    // A cold crystal heated to a liquid: T 0.5 → 1.5 with τ = 0.1 (20 steps).
    let text = lj_deck(
        0.5,
        1000,
        "history_every = 1\n[thermostat]\nkind = \"berendsen\"\ntemperature = 1.5\ndamping = 0.1\n",
    );
    crate::common::run_quietly(&text, "b.toml", &dir, RunOptions::default()).unwrap();
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let rows: Vec<Vec<f64>> = history
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let head: Vec<&str> = history.lines().next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|c| *c == name).unwrap();
    let (ke, total, conserved) = (
        col("kinetic_energy"),
        col("total_energy"),
        col("conserved_energy"),
    );
    let temperature = |r: &Vec<f64>| 2.0 * r[ke] / (3.0 * N - 3.0);
    let last: Vec<f64> = rows[800..].iter().map(temperature).collect();
    let mean = last.iter().sum::<f64>() / last.len() as f64;
    eprintln!(
        "berendsen: T over the last 200 steps {mean:.4} (target 1.5), from {:.3}",
        temperature(&rows[0])
    );
    assert!((mean - 1.5).abs() < 0.015, "{mean}");
    // It put energy in (removed < 0), and total + removed stays what it was to the NVE error.
    let put_in = rows[1000][total] - rows[0][total];
    let kept = rows
        .iter()
        .map(|r| (r[conserved] - rows[0][conserved]).abs())
        .fold(0.0, f64::max);
    eprintln!("berendsen: total energy rose by {put_in:.2}, total + reservoir moved by {kept:.2e}");
    assert!(put_in > 300.0 && kept < 2e-3 * put_in, "{put_in} {kept}");
    let _ = std::fs::remove_dir_all(&dir);

    // Rescale every 10 steps: exactly T₀ right after each.
    let text = lj_deck(
        0.5,
        1,
        "[thermostat]\nkind = \"rescale\"\ntemperature = 1.5\nevery = 10\n",
    );
    let run = trace(&text, 100);
    for (k, r) in run.iter().enumerate() {
        let t = 2.0 * r[0] / (3.0 * N - 3.0);
        if (k + 1) % 10 == 0 {
            assert!((t - 1.5).abs() < 1e-12, "step {}: T = {t}", k + 1);
        } else {
            assert!(
                (t - 1.5).abs() > 1e-6,
                "step {}: T = {t} between rescales",
                k + 1
            );
        }
    }
}

type State = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// Positions (by global id, wrapped into the box) and velocities after `steps` on `procs`.
fn end_state(text: &str, procs: [usize; 3], steps: usize) -> State {
    end_state_from(text, procs, steps, |_| {})
}

/// [`end_state`] with `prepare` applied to each procCube after its start.
fn end_state_from(
    text: &str,
    procs: [usize; 3],
    steps: usize,
    prepare: impl Fn(&mut parallel::Cube<Point>) + Sync,
) -> State {
    let s = setup::build_as::<Point>(&scene(text).unwrap()).unwrap();
    let n = s.sim.particles.len();
    let workers = procs.iter().product();
    let layout = parallel::layout(&s, &Procs::Given(procs), workers, Walls::Whole).unwrap();
    let period = s.domain.period;
    let cubes = parallel::thread_cubes(&s, &layout);
    let parts = parallel::on_threads(cubes, |mut c| {
        c.start();
        prepare(&mut c);
        for _ in 0..steps {
            c.advance().unwrap();
        }
        let p = &c.sim.particles;
        (0..p.n_owned)
            .map(|i| {
                let v = p.velocity(i);
                (p.gid[i], p.pos(i), [v[0], v[1], v[2]])
            })
            .collect::<Vec<_>>()
    });
    let (mut x, mut v) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    for part in parts {
        for (g, xi, vi) in part {
            x[g as usize] = std::array::from_fn(|k| xi[k].rem_euclid(period[k]));
            v[g as usize] = vi;
        }
    }
    (x, v)
}

/// The largest difference between two sets of positions in a periodic box (minimum image)
/// and between two sets of velocities.
fn differences(a: &State, b: &State, period: f64) -> (f64, f64) {
    let mut dx: f64 = 0.0;
    let mut dv: f64 = 0.0;
    for (p, q) in a.0.iter().zip(&b.0) {
        for k in 0..3 {
            let d = p[k] - q[k];
            dx = dx.max((d - period * (d / period).round()).abs());
        }
    }
    for (p, q) in a.1.iter().zip(&b.1) {
        for k in 0..3 {
            dv = dv.max((p[k] - q[k]).abs());
        }
    }
    (dx, dv)
}

#[test]
fn langevin_is_the_same_on_one_and_two_proc_cubes() {
    let period = 5.0 * (4.0f64 / 0.8442).cbrt();
    let deck = |seed: u64| {
        lj_deck(
            1.5,
            1,
            &format!("[thermostat]\nkind = \"langevin\"\ntemperature = 1.0\ndamping = 0.5\nseed = {seed}\n"),
        )
    };
    let steps = 200;
    let one = end_state(&deck(7), [1, 1, 1], steps);
    let again = end_state(&deck(7), [1, 1, 1], steps);
    assert!(
        one == again,
        "the same deck on the same layout must repeat bit for bit"
    );
    let other = end_state(&deck(8), [1, 1, 1], steps);
    let (ox, ov) = differences(&one, &other, period);
    eprintln!(
        "langevin after {steps} steps, another seed: positions {ox:.2} apart, velocities {ov:.2}"
    );
    for procs in [[2, 1, 1], [3, 1, 1]] {
        let (dx, dv) = differences(&one, &end_state(&deck(7), procs, steps), period);
        eprintln!("langevin after {steps} steps, 1x1x1 vs {procs:?}: positions within {dx:.1e}, velocities {dv:.1e}");
        assert!(dx < 1e-9 && dv < 1e-8, "{procs:?}: {dx} {dv}");
    }
    assert!(
        ox > 0.01 && ov > 0.1,
        "another seed must give another trajectory"
    );
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-thermo-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs `text` (400 steps, a checkpoint every 200) straight, and to step 200 then restarted;
/// returns the two output directories and the thermostat state of the step-200 checkpoint.
fn straight_and_restarted(text: &str, name: &str) -> (PathBuf, PathBuf, Vec<f64>) {
    let straight = out_dir(&format!("{name}-straight"));
    crate::common::run_quietly(text, "nh.toml", &straight, RunOptions::default()).unwrap();
    let resumed = out_dir(&format!("{name}-resumed"));
    let first = RunOptions {
        steps: Some(200),
        ..Default::default()
    };
    crate::common::run_quietly(text, "nh.toml", &resumed, first).unwrap();
    let at = resumed.join("checkpoints/checkpoint_00000200.h5");
    let c = pdq::output::checkpoint::Checkpoint::read(&at).unwrap();
    let saved = c
        .state
        .thermostat
        .expect("the checkpoint holds the thermostat");
    assert_eq!(saved.kind, "nose-hoover");
    let restart = RunOptions {
        restart: Some(resumed.join("checkpoints")),
        ..Default::default()
    };
    crate::common::run_quietly(text, "nh.toml", &resumed, restart).unwrap();
    (straight, resumed, saved.values)
}

const RESTART_OUTPUT: &str =
    "history_every = 20\nfinal_state = true\ncheckpoint_every = 200\n[thermostat]\nkind = \"nose-hoover\"\n";

#[test]
fn a_nose_hoover_restart_continues_bit_identically() {
    // A PMB solid (bonds, no pair law) held at T = 0.08 (its start at 0.1 shares its energy
    // with the bonds): every restart of a bonded scene is bit-identical, so what is tested is
    // the thermostat's state.
    let text = format!(
        r#"units = "lj"
[model]
name = "pmb"
m = 3
[lattice]
spacing = 1.0
[materials.rock]
density = 1.0
bulk_modulus = 50.0
critical_stretch = 0.5
[[geometry]]
shape = "box"
material = "rock"
min = [0, 0, 0]
max = [8, 8, 8]
[velocity]
temperature = 0.1
seed = 3
[time]
steps = 400
[output]
progress = false
{RESTART_OUTPUT}temperature = 0.08
damping = 2.0
"#
    );
    let (straight, resumed, xi_eta) = straight_and_restarted(&text, "nh-pmb");
    assert!(xi_eta[0] != 0.0 && xi_eta[1] != 0.0, "{xi_eta:?}");
    let read = |d: &PathBuf, f: &str| std::fs::read_to_string(d.join(f)).unwrap();
    for f in ["history.csv", "final_positions.csv"] {
        assert!(
            read(&straight, f) == read(&resumed, f),
            "{f} differs after the restart"
        );
    }
    let last = "checkpoints/checkpoint_00000400.h5";
    let a = pdq::output::checkpoint::Checkpoint::read(&straight.join(last)).unwrap();
    let b = pdq::output::checkpoint::Checkpoint::read(&resumed.join(last)).unwrap();
    assert!(a == b, "the final checkpoints differ");
    eprintln!("nose-hoover on a PMB solid: 400 steps = 200 + restart + 200 bit for bit; ξ, η at step 200: {xi_eta:?}");
    let _ = std::fs::remove_dir_all(straight);
    let _ = std::fs::remove_dir_all(resumed);
}

#[test]
fn a_nose_hoover_lj_restart_continues_to_round_off() {
    // With a pair law a restart rebuilds the neighbour lists at its first step, so the pair
    // sums add in another order: the continuation is the same to round-off, not bit for bit
    // (as for every [pair] deck; the history's ten digits do not see it).
    let extra = format!("{RESTART_OUTPUT}temperature = 1.0\ndamping = 0.1\n");
    let text = lj_deck(1.5, 400, &extra);
    let (straight, resumed, xi_eta) = straight_and_restarted(&text, "nh-lj");
    assert!(xi_eta[0] != 0.0 && xi_eta[1] != 0.0, "{xi_eta:?}");
    let read = |d: &PathBuf, f: &str| std::fs::read_to_string(d.join(f)).unwrap();
    let history = read(&straight, "history.csv");
    assert!(history.lines().next().unwrap().contains("conserved_energy"));
    assert!(
        history == read(&resumed, "history.csv"),
        "history.csv differs"
    );
    let positions = |d: &PathBuf| crate::common::final_positions(d);
    let period = 5.0 * (4.0f64 / 0.8442).cbrt();
    let (a, b) = (positions(&straight), positions(&resumed));
    let (dx, _) = differences(&(a, vec![]), &(b, vec![]), period);
    eprintln!("nose-hoover LJ restart: positions within {dx:.1e} of the straight run");
    assert!(dx < 1e-9, "{dx}");
    let _ = std::fs::remove_dir_all(straight);
    let _ = std::fs::remove_dir_all(resumed);
}

#[test]
fn the_deck_refuses_bad_thermostats_at_their_lines() {
    let base = lj_deck(1.5, 10, "");
    // The [thermostat] header's line; a case's `line` counts its keys from it (0: the header).
    let header = base.lines().count() + 1;
    let cases: [(&str, usize, &str); 12] = [
        (
            "kind = \"andersen\"\ntemperature = 1.0\n",
            1,
            "unknown kind 'andersen'",
        ),
        (
            "kind = \"berendsen\"\ntemperature = -1.0\ndamping = 0.1\n",
            2,
            "temperature must be ≥ 0",
        ),
        (
            "kind = \"berendsen\"\ntemperature = 1.0\ndamping = 0.0\n",
            3,
            "damping must be a time > 0",
        ),
        (
            "kind = \"berendsen\"\ntemperature = 1.0\n",
            0,
            "kind = \"berendsen\" needs 'damping'",
        ),
        (
            "kind = \"langevin\"\ntemperature = 1.0\ndamping = 1.0\n",
            0,
            "needs 'seed'",
        ),
        (
            "kind = \"rescale\"\ntemperature = 1.0\ndamping = 1.0\n",
            3,
            "takes no 'damping'",
        ),
        (
            "kind = \"rescale\"\ntemperature = 1.0\nevery = 0\n",
            3,
            "every must be a number of steps ≥ 1",
        ),
        (
            "kind = \"langevin\"\ntemperature = 1.0\ndamping = 1.0\nseed = -2\n",
            4,
            "seed must be an integer ≥ 0",
        ),
        (
            "kind = \"berendsen\"\ntemperature = 1.0\ndamping = 0.1\nmaterials = [\"water\"]\n",
            4,
            "materials: unknown material 'water'",
        ),
        (
            "kind = \"nose-hoover\"\ntemperature = 0.0\ndamping = 0.1\n",
            2,
            "needs a temperature > 0",
        ),
        (
            "kind = \"berendsen\"\ntemperature = 1.0\ndamping = 0.1\ncolour = 1\n",
            4,
            "unknown field `colour`",
        ),
        (
            "kind = \"berendsen\"\ntemperature = 1.0\ndamping = \"0.1 s\"\n",
            3,
            "has a unit",
        ),
    ];
    for (extra, line, message) in cases {
        let err = scene(&format!("{base}[thermostat]\n{extra}")).expect_err(extra);
        let want = format!("t.toml:{}: ", header + line);
        assert!(
            err.contains(message) && err.starts_with(&want),
            "{extra}: {err} (want {want})"
        );
    }
    // Nosé–Hoover belongs to the velocity-Verlet step.
    let leapfrog = format!(
        "{}[thermostat]\nkind = \"nose-hoover\"\ntemperature = 1.0\ndamping = 0.1\n",
        base.replace("dt = 0.005", "dt = 0.005\nintegrator = \"leapfrog\"")
    );
    let err = scene(&leapfrog).unwrap_err();
    assert!(
        err.contains(&format!("t.toml:{}: ", header + 2)) && err.contains("velocity-Verlet"),
        "{err}"
    );
}

#[test]
fn the_setup_refuses_groups_it_cannot_thermostat() {
    let build = |extra: &str| {
        let text = lj_deck(1.5, 10, extra);
        setup::build_as::<Point>(&scene(&text).unwrap())
            .err()
            .map(|e| e.to_string())
    };
    let thermostat = "[thermostat]\nkind = \"berendsen\"\ntemperature = 1.0\ndamping = 0.1\n";
    assert_eq!(build(thermostat), None);
    let held = format!(
        "[[boundary]]\nname = \"wall\"\nregion = {{ shape = \"slab\", axis = \"z\", from = 0, to = 1 }}\nfixed = [\"all\"]\n{thermostat}"
    );
    let err = build(&held).unwrap();
    assert!(err.contains("held by boundary 'wall'"), "{err}");
    let line = lj_deck(1.5, 10, &held)
        .lines()
        .position(|l| l == "[thermostat]")
        .unwrap()
        + 1;
    assert!(err.starts_with(&format!("t.toml:{line}: ")), "{err}");
    // The free particles alone are fine.
    let free = held.replace(
        "damping = 0.1\n",
        "damping = 0.1\nregion = { shape = \"slab\", axis = \"z\", from = 1, to = 100 }\n",
    );
    assert_eq!(build(&free), None);
    let short = build(&thermostat.replace("0.1", "0.001")).unwrap();
    assert!(short.contains("shorter than the time step"), "{short}");
    let nobody = build(&thermostat.replace(
        "0.1\n",
        "0.1\nregion = { shape = \"slab\", axis = \"z\", from = 100, to = 101 }\n",
    ))
    .unwrap();
    assert!(nobody.contains("selects no particle"), "{nobody}");
}

#[test]
fn leapfrog_positions_are_velocity_verlets_from_the_half_step_velocity() {
    use pdq::engine::simulation::Integrator;
    let period = 5.0 * (4.0f64 / 0.8442).cbrt();
    let verlet = lj_deck(1.5, 1, "");
    for name in ["leapfrog", "euler", "semi-implicit-euler"] {
        let text = verlet.replace(
            "dt = 0.005",
            &format!("dt = 0.005\nintegrator = \"{name}\""),
        );
        assert_eq!(scene(&text).unwrap().time.integrator, Integrator::Leapfrog);
    }
    // The perfect crystal feels no force; 50 steps of velocity Verlet melt it a little first,
    // then the runs go on with one integrator or the other.
    let start = |c: &mut parallel::Cube<Point>, then: Integrator, half_back: bool| {
        for _ in 0..50 {
            c.advance().unwrap();
        }
        c.sim.integrator = then;
        if half_back {
            // Leapfrog's stored velocity is v(t − Δt/2) = v(t) − (Δt/2)·F(t)/m.
            let p = &mut c.sim.particles;
            for i in 0..p.n_owned {
                let (f, inv) = (p.force[i].force, p.inv_inertia[i].force);
                for k in 0..3 {
                    p.alter[i].vel[k] -= 0.5 * 0.005 * f[k] * inv[k];
                }
            }
        }
    };
    let steps = 200;
    let vv = end_state_from(&verlet, [1, 1, 1], steps, |c| {
        start(c, Integrator::VelocityVerlet, false)
    });
    let lf = end_state_from(&verlet, [1, 1, 1], steps, |c| {
        start(c, Integrator::Leapfrog, true)
    });
    let (dx, _) = differences(&vv, &lf, period);
    // Started from v(t) instead, it is another trajectory.
    let naive = end_state_from(&verlet, [1, 1, 1], steps, |c| {
        start(c, Integrator::Leapfrog, false)
    });
    let (nx, _) = differences(&vv, &naive, period);
    eprintln!("leapfrog vs velocity Verlet after {steps} steps: positions within {dx:.1e}; from v(t) instead of v(t - dt/2): {nx:.1e}");
    assert!(dx < 1e-10, "{dx}");
    assert!(nx > 1e-6, "{nx}");
}
