//! The state pass through the wall method: partial sums on ghosts go home (reverse), finished
//! states come back to the ghosts (forward), and a model whose pair force reads both ends'
//! states gives the same results on every layout. The model here is a test double of a
//! state-based law (a dilatation-like sum of bond stretches), not physics for production.

use pdq::attributes::Attributes;
use pdq::decomposition::{Procs, Walls};
use pdq::model::{check_options, stretch, BondGeom, Model, ModelBuild, Side};
use pdq::models::pmb::{Force3, Motion};
use pdq::{deck, parallel, setup};

mod common;
use common::max_relative_difference;

pdq::attributes! {
    /// Volume-weighted sum of bond stretches around a particle.
    pub struct Dilatation { pub theta: f64 }
}

#[derive(Clone, Debug)]
struct StretchSum {
    c: f64,
    s0: f64,
    density: f64,
}

impl Model for StretchSum {
    const NAME: &'static str = "stretch-sum";
    const SUMMARY: &'static str = "test double of a state-based law";
    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = Dilatation;
    type Force = Force3;
    type Law = ();

    fn build(b: &ModelBuild) -> Result<Self, String> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let m = &b.materials[0];
        Ok(StretchSum {
            c: m.micromodulus.ok_or("micromodulus")?,
            s0: m.critical_stretch.ok_or("critical_stretch")?,
            density: m.density,
        })
    }
    fn inertia(&self, _: u16, volume: f64, _: &()) -> Force3 {
        Force3 {
            force: [self.density * volume; 3],
        }
    }
    fn law(&self, _: u16, _: u16) {}
    fn bond_stiffness(&self, _: &(), geom: &BondGeom) -> Force3 {
        Force3 {
            force: [self.c / geom.length; 3],
        }
    }
    fn lame(&self, _: u16) -> (f64, f64) {
        (0.0, 0.0)
    }
    fn state(
        &self,
        _: &(),
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &(),
    ) -> (Dilatation, Dilatation) {
        let (s, _, _) = stretch(i, j, geom);
        (
            Dilatation {
                theta: j.volume * s,
            },
            Dilatation {
                theta: i.volume * s,
            },
        )
    }
    fn finish_state(&self, state: &mut Dilatation, _: &()) {
        state.theta *= 1.0e9;
    }
    fn pair(
        &self,
        _: &(),
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &mut (),
    ) -> Option<(Force3, Force3)> {
        let (s, y, r) = stretch(i, j, geom);
        if s > self.s0 {
            return None;
        }
        // The force reads both ends' states: wrong or stale ghost states change it.
        let mix = s + 0.05 * (i.state.theta + j.state.theta);
        let f = self.c * mix * i.volume * j.volume / r;
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }
    fn energy(&self, _: &(), i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (s, _, _) = stretch(i, j, geom);
        0.5 * self.c * s * s * geom.length * i.volume * j.volume
    }
}

const DECK: &str = r#"units = "SI"
[model]
name = "pmb"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.rock]
density = "2200 kg/m^3"
micromodulus = 1.6863e22
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

/// Positions by global id and sorted broken pairs after `steps` steps on `procs`.
fn run(procs: [usize; 3], walls: Walls, steps: usize) -> (Vec<[f64; 3]>, Vec<(u32, u32)>) {
    let scene = deck::parse(DECK, "t.toml", "t").unwrap();
    let s = setup::build_as::<StretchSum>(&scene).unwrap();
    let layout = parallel::layout(&s, &Procs::Given(procs), procs.iter().product(), walls).unwrap();
    let cubes = parallel::thread_cubes(&s, &layout);
    let parts = parallel::on_threads(cubes, |mut c| {
        c.start();
        for _ in 0..steps {
            c.sim.advance();
        }
        let p = &c.sim.particles;
        let pos: Vec<(u32, [f64; 3])> = (0..p.n_owned).map(|i| (p.gid[i], p.pos(i))).collect();
        (pos, c.broken_pairs())
    });
    let mut pos = vec![[f64::NAN; 3]; s.sim.particles.len()];
    let mut broken = Vec::new();
    for (p, b) in parts {
        for (g, x) in p {
            pos[g as usize] = x;
        }
        broken.extend(b);
    }
    broken.sort_unstable();
    (pos, broken)
}

#[test]
fn state_passes_give_the_same_results_on_every_layout() {
    assert_eq!(<Dilatation as Attributes>::LEN, 1);
    let (reference, broken) = run([1, 1, 1], Walls::Whole, 300);
    assert!(!broken.is_empty(), "the block must tear");
    for (procs, walls) in [
        ([2, 1, 1], Walls::Whole),
        ([2, 2, 2], Walls::Whole),
        ([3, 2, 1], Walls::Trimmed),
        ([1, 3, 2], Walls::Trimmed),
    ] {
        let (pos, b) = run(procs, walls, 300);
        let d = max_relative_difference(&reference, &pos);
        assert!(d <= 1e-12, "{procs:?}: positions differ by {d:e}");
        assert_eq!(b, broken, "{procs:?}: broken bonds differ");
    }
}
