//! Per-rank setup (`parallel::part`) against the whole-scene setup: on a scene with a notch, a
//! spherical hole, a periodic axis, a steel bar across the procCube cuts, boundary conditions,
//! a load and a probe, every procCube of every layout gets the same particles (ids, positions,
//! volumes, materials, in the same store order), the same bonds (lengths bit for bit; β, which
//! the bar's calibration scales, to round-off), the same share of the boundary conditions,
//! loads and probes and the same stable step; and stepping both gives the same broken bonds and
//! positions.

use pdq::input::deck::{self, Scene};
use pdq::input::setup;
use pdq::models::pmb::Pmb;
use pdq::parallel::comm::Threads;
use pdq::parallel::decomposition::{Procs, Walls};
use pdq::parallel::part::{self, PartSetup};
use pdq::parallel::{self, Cube};

fn scene() -> Scene {
    let text = include_str!("decks/notched_pull.toml").replace(
        "spacing = \"1 mm\"",
        "spacing = \"1 mm\"\nperiodic = [\"y\"]",
    ) + r#"
[[geometry]]
op = "subtract"
shape = "sphere"
center = "8 5 5 mm"
radius = "2.5 mm"
[materials.steel]
density = "7850 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.25
critical_stretch = 0.01
[[bar]]
material = "steel"
area = "1.5 mm^2"
from = "1.2 5.3 2.3 mm"
to = "28.8 5.3 2.3 mm"
[[load]]
name = "push"
region = { shape = "slab", axis = "z", from = "9 mm", to = "10 mm" }
total_force = "0 0 -50 N"
[[probe]]
name = "tip"
at = "29.5 5 5 mm"
"#;
    let text = text.replace("steps = 500", "steps = 300");
    deck::parse(&text, "t.toml", "t").unwrap()
}

fn whole(scene: &Scene, procs: [usize; 3]) -> (f64, Vec<Cube<Pmb>>) {
    let s = setup::build_as::<Pmb>(scene).unwrap();
    let n = procs.iter().product();
    let layout = parallel::layout(&s, &Procs::Given(procs), n, Walls::default()).unwrap();
    (s.dt_critical, parallel::thread_cubes(&s, &layout))
}

fn per_rank(scene: &Scene, procs: [usize; 3]) -> Vec<PartSetup<Pmb>> {
    let n = procs.iter().product();
    let parts = part::parts(scene, &Procs::Given(procs), Walls::default(), n).unwrap();
    let model = setup::model_as::<Pmb>(scene).unwrap();
    std::thread::scope(|s| {
        let handles: Vec<_> = Threads::team(n)
            .into_iter()
            .enumerate()
            .map(|(k, t)| {
                let (m, parts) = (model.clone(), &parts);
                s.spawn(move || part::build_part(m, scene, parts, k, Box::new(t)).unwrap())
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

/// Bonds as (global id, global id, length), in store order.
fn bonds(c: &Cube<Pmb>) -> Vec<(u32, u32, f64)> {
    let (b, gid) = (&c.sim.bonds, &c.sim.particles.gid);
    b.iter()
        .map(|(i, j, k)| (gid[i], gid[j], b.geom[k].length))
        .collect()
}

fn same_cube(a: &Cube<Pmb>, b: &Cube<Pmb>, what: &str) {
    let (p, q) = (&a.sim.particles, &b.sim.particles);
    assert_eq!(p.n_owned, q.n_owned, "{what}: owned");
    assert_eq!(p.gid, q.gid, "{what}: ids in store order");
    assert_eq!(p.x0, q.x0, "{what}: positions");
    assert_eq!(p.volume, q.volume, "{what}: volumes");
    assert_eq!(p.material, q.material, "{what}: materials");
    assert_eq!(bonds(a), bonds(b), "{what}: bonds");
    // β: the bar's γ sums over procCubes in another order.
    let beta = |c: &Cube<Pmb>| -> Vec<f64> { c.sim.bonds.geom.iter().map(|g| g.beta).collect() };
    for (x, y) in beta(a).iter().zip(&beta(b)) {
        assert!(
            (x - y).abs() <= 1e-12 * x.abs(),
            "{what}: β {x} against {y}"
        );
    }
    let names = |c: &Cube<Pmb>| -> Vec<(String, Vec<u32>)> {
        let c = &c.sim.constraints;
        c.iter()
            .map(|c| (c.name.clone(), c.particles.clone()))
            .collect()
    };
    assert_eq!(names(a), names(b), "{what}: boundary conditions");
    // A load's particles in any order (the whole scene lists them in its store order).
    let sorted = |l: &pdq::engine::boundary::Load| {
        let mut v: Vec<(u32, f64)> = l.particles.iter().copied().zip(l.weight.clone()).collect();
        v.sort_by_key(|w| w.0);
        v
    };
    assert_eq!(a.sim.loads.len(), b.sim.loads.len());
    for (l, m) in a.sim.loads.iter().zip(&b.sim.loads) {
        for ((i, x), (j, y)) in sorted(l).iter().zip(&sorted(m)) {
            assert_eq!(i, j, "{what}: load particles");
            assert!(
                (x - y).abs() <= 1e-14 * x.abs(),
                "{what}: load weight {x} {y}"
            );
        }
    }
    assert_eq!(a.probes, b.probes, "{what}: probes");
    // To round-off: the bar's γ, in each bond's β, sums over procCubes in another order.
    let (x, y) = (a.sim.dt, b.sim.dt);
    assert!(
        (x - y).abs() <= 1e-14 * x,
        "{what}: time step {x} against {y}"
    );
}

/// Broken bonds and final positions, by global id.
type Outcome = (Vec<(u32, u32)>, Vec<(u32, [f64; 3])>);

/// Steps a set of procCubes on threads; the broken bonds and final positions by global id.
fn step(cubes: Vec<Cube<Pmb>>, steps: u64) -> Outcome {
    let out = parallel::on_threads(cubes, |mut c| {
        c.start();
        for _ in 0..steps {
            c.advance().unwrap();
        }
        let p = &c.sim.particles;
        let x = (0..p.n_owned)
            .map(|i| (p.gid[i], p.alter[i].pos))
            .collect::<Vec<_>>();
        (c.broken_pairs(), x)
    });
    let mut broken: Vec<(u32, u32)> = out.iter().flat_map(|o| o.0.clone()).collect();
    let mut x: Vec<(u32, [f64; 3])> = out.into_iter().flat_map(|o| o.1).collect();
    broken.sort_unstable();
    x.sort_by_key(|v| v.0);
    (broken, x)
}

#[test]
fn per_rank_setup_builds_the_whole_scene_setups_proccubes() {
    let scene = scene();
    for procs in [[1, 1, 1], [2, 1, 1], [1, 3, 1], [2, 1, 2]] {
        let (dt, a) = whole(&scene, procs);
        let b = per_rank(&scene, procs);
        assert_eq!(a.len(), b.len());
        for (k, (a, b)) in a.iter().zip(&b).enumerate() {
            same_cube(a, &b.cube, &format!("{procs:?} procCube {k}"));
            let x = b.dt_critical;
            assert!(
                (x - dt).abs() <= 1e-14 * dt,
                "{procs:?}: stable step {x} against {dt}"
            );
        }
    }
}

#[test]
fn per_rank_setup_steps_to_the_same_cracks() {
    let scene = scene();
    let (_, a) = whole(&scene, [2, 1, 1]);
    let (broken_a, x_a) = step(a, 300);
    assert!(
        broken_a.len() > 100,
        "the notch cracks: {} broken",
        broken_a.len()
    );
    for procs in [[2, 1, 1], [1, 1, 2]] {
        let b = per_rank(&scene, procs)
            .into_iter()
            .map(|p| p.cube)
            .collect();
        let (broken_b, x_b) = step(b, 300);
        assert_eq!(broken_a, broken_b, "{procs:?}: broken bonds");
        for ((g, x), (h, y)) in x_a.iter().zip(&x_b) {
            assert_eq!(g, h);
            for e in 0..3 {
                assert!(
                    (x[e] - y[e]).abs() <= 1e-12 * (1.0 + x[e].abs()),
                    "{procs:?}: particle {g}"
                );
            }
        }
    }
}

/// A whole run (history, final state) set up per rank matches the whole-scene setup's.
#[test]
fn a_run_set_up_per_rank_matches_the_whole_scene_run() {
    use pdq::driver::run::{run, RunOptions};
    let scene = scene();
    let dir =
        |what: &str| std::env::temp_dir().join(format!("pdq-part-{}-{what}", std::process::id()));
    let opts = |what: &str| RunOptions {
        output: Some(dir(what)),
        quiet: true,
        threads: Some(2),
        procs: Some(Procs::Given([2, 1, 1])),
        ..Default::default()
    };
    let a = run(&scene, &opts("whole")).unwrap();
    let b = pdq::driver::run_part::run_on_threads(&scene, &opts("part"), 2).unwrap();
    assert_eq!(a.particles, b.particles);
    assert_eq!(a.bonds, b.bonds);
    assert_eq!(a.dt, b.dt);
    assert!(a.broken > 100, "the notch cracks");
    assert_eq!(a.broken_pairs, b.broken_pairs);
    for (x, y) in a.positions.iter().zip(&b.positions) {
        for e in 0..3 {
            assert!((x[e] - y[e]).abs() <= 1e-12 * (1.0 + x[e].abs()));
        }
    }
    let history = |what: &str| std::fs::read_to_string(dir(what).join("history.csv")).unwrap();
    let (ha, hb) = (history("whole"), history("part"));
    assert_eq!(ha.lines().next(), hb.lines().next(), "history columns");
    for (la, lb) in ha.lines().zip(hb.lines()).skip(1) {
        for (x, y) in la.split(',').zip(lb.split(',')) {
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            // Sums over procCubes differ in order: round-off, also around zero.
            assert!(
                (x - y).abs() <= 1e-9 * x.abs().max(y.abs()) + 1e-12,
                "history {la} against {lb}"
            );
        }
    }
    for what in ["whole", "part"] {
        let _ = std::fs::remove_dir_all(dir(what));
    }
}
