//! The state pass through the wall method: partial sums on ghosts go home (reverse), finished
//! states come back to the ghosts (forward), and LPS, whose pair force reads both ends'
//! dilatations and weighted volumes, gives the same dilatations, positions and cracks on every
//! layout of procCubes, whole or trimmed walls.

use pdq::input::{deck, setup};
use pdq::models::lps::Lps;
use pdq::parallel;
use pdq::parallel::decomposition::{Procs, Walls};

mod common;
use common::max_relative_difference;

const DECK: &str = r#"units = "SI"
[model]
name = "lps"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.rock]
density = "2200 kg/m^3"
bulk_modulus = "14.9 GPa"
poisson_ratio = 0.3
critical_stretch = 0.001
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "16 12 10 mm"
[time]
steps = 1
dt = 2e-8
force_dt = true
[[initial]]
region = { shape = "box", min = "0 0 0 mm", max = "8 12 10 mm" }
velocity = "-40 3 -2 m/s"
[[initial]]
region = { shape = "box", min = "8 0 0 mm", max = "16 12 10 mm" }
velocity = "40 0 1 m/s"
[output]
progress = false
"#;

/// Positions and dilatations by global id and sorted broken pairs after `steps` steps on
/// `procs`.
#[allow(clippy::type_complexity)]
fn run(
    procs: [usize; 3],
    walls: Walls,
    steps: usize,
) -> (Vec<[f64; 3]>, Vec<f64>, Vec<(u32, u32)>) {
    let scene = deck::parse(DECK, "t.toml", "t").unwrap();
    let s = setup::build_as::<Lps>(&scene).unwrap();
    let layout = parallel::layout(&s, &Procs::Given(procs), procs.iter().product(), walls).unwrap();
    let cubes = parallel::thread_cubes(&s, &layout);
    let parts = parallel::on_threads(cubes, |mut c| {
        c.start();
        for _ in 0..steps {
            c.advance().unwrap();
        }
        let p = &c.sim.particles;
        let own: Vec<(u32, [f64; 3], f64)> = (0..p.n_owned)
            .map(|i| (p.gid[i], p.pos(i), p.state[i].dilatation))
            .collect();
        (own, c.broken_pairs())
    });
    let n = s.sim.particles.len();
    let (mut pos, mut theta) = (vec![[f64::NAN; 3]; n], vec![f64::NAN; n]);
    let mut broken = Vec::new();
    for (own, b) in parts {
        for (g, x, t) in own {
            pos[g as usize] = x;
            theta[g as usize] = t;
        }
        broken.extend(b);
    }
    broken.sort_unstable();
    (pos, theta, broken)
}

#[test]
fn state_passes_give_the_same_results_on_every_layout() {
    let (reference, ref_theta, broken) = run([1, 1, 1], Walls::Whole, 300);
    assert!(!broken.is_empty(), "the block must tear");
    let theta_scale = ref_theta.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    assert!(theta_scale > 0.0, "the block must change volume");
    for (procs, walls) in [
        ([2, 1, 1], Walls::Whole),
        ([2, 2, 2], Walls::Whole),
        ([3, 2, 1], Walls::Trimmed),
        ([1, 3, 2], Walls::Trimmed),
    ] {
        let (pos, theta, b) = run(procs, walls, 300);
        let d = max_relative_difference(&reference, &pos);
        assert!(d <= 1e-12, "{procs:?}: positions differ by {d:e}");
        let dt = ref_theta
            .iter()
            .zip(&theta)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / theta_scale;
        eprintln!(
            "{procs:?} {}: positions {d:.1e}, dilatations {dt:.1e}",
            walls.name()
        );
        assert!(dt <= 1e-8, "{procs:?}: dilatations differ by {dt:e}");
        assert_eq!(b, broken, "{procs:?}: broken bonds differ");
    }
}
