//! Peridynamic contact through the non-bonded pass: two blocks that share no bond meet and
//! rebound with their total momentum kept, never closer than half the contact distance; without
//! the pair law they pass through each other; and the pair pass gives the same motion on every
//! layout of procCubes (pairs across procCube faces found once, their forces sent home).

use pdq::input::{deck, setup};
use pdq::models::pmb::Pmb;
use pdq::parallel;
use pdq::parallel::decomposition::{Procs, Walls};

mod common;
use common::max_relative_difference;

/// Two 6 mm blocks 4 mm apart (more than the horizon: no bond joins them) flying at each other.
fn deck_text(contact: bool) -> String {
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
critical_stretch = 0.02
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "6 6 6 mm"
[[geometry]]
shape = "box"
material = "rock"
min = "10 0.3 0 mm"
max = "16 6.3 6 mm"
[[initial]]
region = {{ shape = "box", min = "-1 -1 -1 mm", max = "8 8 8 mm" }}
velocity = "60 0 0 m/s"
[[initial]]
region = {{ shape = "box", min = "8 -1 -1 mm", max = "17 8 8 mm" }}
velocity = "-60 0 0 m/s"
[time]
steps = 1
dt = "1e-7 s"
force_dt = true
{pair}
[output]
progress = false
"#,
        pair = if contact {
            "[pair]\nlaw = \"contact\"\n"
        } else {
            ""
        },
    )
}

struct Trace {
    /// Positions by global id at the end.
    end: Vec<[f64; 3]>,
    /// Total momentum at the start and at the end.
    momentum: ([f64; 3], [f64; 3]),
    /// The smallest distance between the two bodies over the run.
    closest: f64,
    /// Mean x velocity of the left body at the end.
    left_velocity: f64,
}

fn run(contact: bool, procs: [usize; 3], steps: usize) -> Trace {
    let scene = deck::parse(&deck_text(contact), "t.toml", "t").unwrap();
    let s = setup::build_as::<Pmb>(&scene).unwrap();
    let n = s.sim.particles.len();
    let workers = procs.iter().product();
    let layout = parallel::layout(&s, &Procs::Given(procs), workers, Walls::Trimmed).unwrap();
    let cubes = parallel::thread_cubes(&s, &layout);
    // Each worker's owned particles by global id: reference x (which body), position, velocity
    // and mass, after every step.
    let parts = parallel::on_threads(cubes, |mut c| {
        c.start();
        let mut frames = Vec::new();
        let snapshot = |c: &parallel::Cube<Pmb>| {
            let p = &c.sim.particles;
            (0..p.n_owned)
                .map(|i| {
                    let v = p.velocity(i);
                    let m = 1.0 / p.inv_inertia[i].force[0];
                    (p.gid[i], p.x0[i][0], p.pos(i), [v[0], v[1], v[2]], m)
                })
                .collect::<Vec<_>>()
        };
        frames.push(snapshot(&c));
        for _ in 0..steps {
            c.advance().unwrap();
            frames.push(snapshot(&c));
        }
        frames
    });
    let frame = |k: usize| {
        let mut all = vec![(0.0, [0.0; 3], [0.0; 3], 0.0); n];
        for part in &parts {
            for &(g, x0, x, v, m) in &part[k] {
                all[g as usize] = (x0, x, v, m);
            }
        }
        all
    };
    let momentum = |f: &[(f64, [f64; 3], [f64; 3], f64)]| {
        let mut p = [0.0; 3];
        for &(_, _, v, m) in f {
            for a in 0..3 {
                p[a] += m * v[a];
            }
        }
        p
    };
    let mut closest = f64::INFINITY;
    for k in 0..=steps {
        let f = frame(k);
        // Bodies by reference position: a shuffle moves x0 only on periodic axes (none here).
        type Entry<'a> = &'a (f64, [f64; 3], [f64; 3], f64);
        let (left, right): (Vec<Entry>, Vec<Entry>) = f.iter().partition(|e| e.0 < 8e-3);
        for a in &left {
            for b in &right {
                let d = [b.1[0] - a.1[0], b.1[1] - a.1[1], b.1[2] - a.1[2]];
                closest = closest.min((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
            }
        }
    }
    let last = frame(steps);
    let left: Vec<_> = last.iter().filter(|e| e.0 < 8e-3).collect();
    Trace {
        end: last.iter().map(|e| e.1).collect(),
        momentum: (momentum(&frame(0)), momentum(&last)),
        closest,
        left_velocity: left.iter().map(|e| e.2[0]).sum::<f64>() / left.len() as f64,
    }
}

const STEPS: usize = 900;

#[test]
fn blocks_rebound_with_momentum_kept_and_never_overlap() {
    let t = run(true, [1, 1, 1], STEPS);
    // Scale: one body's momentum, 216 particles of 2.2e-6 kg at 60 m/s.
    let scale = 216.0 * 2200.0 * 1e-9 * 60.0;
    for a in 0..3 {
        let drift = (t.momentum.1[a] - t.momentum.0[a]).abs() / scale;
        assert!(
            drift < 1e-12,
            "momentum {a} changed by {drift:e} of one body's"
        );
    }
    assert!(
        t.closest > 0.45e-3,
        "the bodies came {:.3e} m close: contact lets them within half its 0.9 mm distance",
        t.closest
    );
    assert!(
        t.left_velocity < -10.0,
        "the left block did not rebound: mean x velocity {:.2} m/s at the end",
        t.left_velocity
    );
}

#[test]
fn without_contact_the_blocks_pass_through() {
    let t = run(false, [1, 1, 1], STEPS);
    assert!(t.closest < 0.4e-3, "closest {:.3e} m", t.closest);
    assert!(t.left_velocity > 50.0, "{}", t.left_velocity);
}

#[test]
fn contact_is_the_same_on_every_layout() {
    let one = run(true, [1, 1, 1], 500);
    for procs in [[2, 1, 1], [3, 1, 1], [4, 1, 1]] {
        let other = run(true, procs, 500);
        let d = max_relative_difference(&one.end, &other.end);
        assert!(d < 1e-9, "{procs:?}: positions differ by {d:e}");
    }
}
