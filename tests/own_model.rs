//! A model written outside `src/` and `models/`, with a material parameter of its own, built
//! from a deck and run without editing anything in the crate (issue 22): the proof that a
//! model is one file. The law is a bond-based solid whose bonds soften linearly past the
//! critical stretch s0 and break at its own `softening_stretch` s_f (a cohesive bond law):
//!
//! f = c·s for s ≤ s0, f = c·s0·(s_f − s)/(s_f − s0) for s0 < s ≤ s_f, broken beyond s_f,
//! c = 12E/(πδ⁴) (bond-based, ν = ¼).
//!
//! Without history the softening branch is reversible; that is this law's simplification,
//! not the engine's (the engine still never lets a broken bond carry force again).

use pdq::driver::run::{run_model, RunOptions};
use pdq::input::deck;
use pdq::model::{
    bond_based_lame, check_options, stretch, BondGeom, Dimension, Material, Model, ModelBuild,
    ModelError, ModelInfo, PairTable, Sample, SampleOf, Side,
};
use pdq::models::pmb::{Force3, Motion};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Law {
    c: f64,
    s0: f64,
    sf: f64,
}

#[derive(Clone, Debug)]
struct Softening {
    laws: PairTable<Law>,
    density: Vec<f64>,
    delta: f64,
}

fn own_law(m: &Material, delta: f64) -> Result<Law, ModelError> {
    m.only_uses(
        &["youngs_modulus", "critical_stretch", "softening_stretch"],
        Softening::NAME,
    )?;
    let name = Softening::NAME;
    let e = m.required("youngs_modulus", Dimension::STRESS, name)?;
    let s0 = m.required("critical_stretch", Dimension::NUMBER, name)?;
    let sf = m.required("softening_stretch", Dimension::NUMBER, name)?;
    if sf <= s0 {
        return Err(m.key_error(
            "softening_stretch",
            format!(
                "material '{}': softening_stretch ({sf}) must exceed critical_stretch ({s0})",
                m.name
            ),
        ));
    }
    Ok(Law {
        c: 12.0 * e / (PI * delta.powi(4)),
        s0,
        sf,
    })
}

impl Model for Softening {
    const NAME: &'static str = "softening";
    const SUMMARY: &'static str = "bond-based solid with linear softening (a test's own model)";
    type Alter = Motion;
    type Fixed = ();
    type Bond = ();
    type State = ();
    type Force = Force3;
    type Law = Law;

    fn build(b: &ModelBuild) -> Result<Self, ModelError> {
        check_options(Self::NAME, Self::OPTIONS, b.options)?;
        let own = b.per_material(own_law)?;
        Ok(Softening {
            laws: PairTable::new(&own, |a, b| Law {
                c: a.c.min(b.c),
                s0: a.s0.min(b.s0),
                sf: a.sf.min(b.sf),
            }),
            density: b.materials.iter().map(|m| m.density).collect(),
            delta: b.horizon,
        })
    }

    /// Its sample for the lab's scenes: the same stiffness, bonds softening from s0 to 8 s0.
    /// It has no unbreakable sample (it needs both stretches).
    fn sample(of: &SampleOf) -> Option<Sample> {
        let (e, density, s0) = match *of {
            SampleOf::Benchmark {
                micromodulus,
                horizon,
                critical_stretch,
                density,
            } => (
                micromodulus * PI * horizon.powf(4.0) / 12.0,
                density,
                critical_stretch,
            ),
            SampleOf::Solid {
                youngs_modulus,
                density,
                critical_stretch,
                ..
            } if critical_stretch.is_finite() => (youngs_modulus, density, critical_stretch),
            SampleOf::Solid { .. } => return None,
        };
        Some(Sample::new(format!(
            "density = {density}\nyoungs_modulus = {e:e}\ncritical_stretch = {s0:e}\nsoftening_stretch = {:e}\n",
            8.0 * s0
        )))
    }

    fn inertia(&self, material: u16, volume: f64, _: &()) -> Force3 {
        Force3 {
            force: [self.density[material as usize] * volume; 3],
        }
    }

    fn law(&self, mi: u16, mj: u16) -> Law {
        self.laws.get(mi, mj)
    }

    fn bond_stiffness(&self, law: &Law, geom: &BondGeom) -> Force3 {
        Force3 {
            force: [law.c / geom.length; 3],
        }
    }

    fn lame(&self, material: u16) -> (f64, f64) {
        bond_based_lame(self.law(material, material).c, self.delta)
    }

    fn pair(
        &self,
        law: &Law,
        i: &Side<Self>,
        j: &Side<Self>,
        geom: &BondGeom,
        _: &mut (),
    ) -> Option<(Force3, Force3)> {
        let (s, y, r) = stretch(i, j, geom);
        if s > law.sf {
            return None;
        }
        let f = if s <= law.s0 {
            law.c * s
        } else {
            law.c * law.s0 * (law.sf - s) / (law.sf - law.s0)
        };
        let f = f * geom.beta * i.volume * j.volume / r;
        let fi = [f * y[0], f * y[1], f * y[2]];
        Some((
            Force3 { force: fi },
            Force3 {
                force: [-fi[0], -fi[1], -fi[2]],
            },
        ))
    }

    fn energy(&self, law: &Law, i: &Side<Self>, j: &Side<Self>, geom: &BondGeom, _: &()) -> f64 {
        let (s, _, _) = stretch(i, j, geom);
        let w = if s <= law.s0 {
            0.5 * law.c * s * s
        } else {
            // The elastic part, plus the area under the softening branch from s0 to s.
            let k = law.c * law.s0 / (law.sf - law.s0);
            0.5 * law.c * law.s0 * law.s0
                + k * ((law.sf - law.s0) * (s - law.s0) - 0.5 * (s - law.s0).powi(2))
        };
        w * geom.length * geom.beta * i.volume * j.volume
    }
}

/// A bar 20 × 4 × 4 mm, held at one end and pulled at the other to a strain of `strain`
/// over the run, slowly (quasi-statically enough for a bond-count question).
fn pull_deck(material: &str, strain: f64) -> String {
    let speed = strain * 20e-3 / 40e-6; // the strain is reached at t = 40 µs
    format!(
        r#"title = "a pulled bar of the softening model"
units = "SI"

[model]
name = "softening"
horizon = "3.015 mm"

[lattice]
spacing = "1 mm"

[materials.rock]
density = "2200 kg/m^3"
{material}
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "20 4 4 mm"

[time]
duration = "40 us"

[[boundary]]
name = "held"
region = {{ shape = "slab", axis = "x", from = "0 mm", to = "2 mm" }}
fixed = ["all"]

[[boundary]]
name = "pulled"
region = {{ shape = "slab", axis = "x", from = "18 mm", to = "20 mm" }}
velocity = "{speed} 0 0 m/s"
components = ["x"]

[output]
history_every = 100
"#
    )
}

const ROCK: &str =
    "youngs_modulus = \"20 GPa\"\ncritical_stretch = 0.0005\nsoftening_stretch = 0.004\n";

fn run(text: &str, name: &str) -> Result<pdq::driver::run::Summary, String> {
    let scene = deck::parse(text, &format!("{name}.toml"), name).map_err(|e| e.to_string())?;
    let dir = std::env::temp_dir().join(format!("pdq_own_model_{name}_{}", std::process::id()));
    let opts = RunOptions {
        output: Some(dir.clone()),
        quiet: true,
        ..Default::default()
    };
    let out = run_model::<Softening>(&scene, &opts);
    let _ = std::fs::remove_dir_all(&dir);
    out
}

/// Its own parameter decides when bonds break. Below the critical stretch nothing breaks.
/// Past it the softening bonds localize into one band, whose bonds stretch far beyond the bar's
/// mean strain: with s_f = 0.004 they break, with s_f = 1 (nearly plastic) the same pull
/// breaks none.
#[test]
fn own_parameter_decides_when_bonds_break() {
    let elastic = run(&pull_deck(ROCK, 0.0003), "elastic").unwrap();
    assert!(elastic.steps > 0 && elastic.bonds > 0);
    assert_eq!(elastic.broken, 0, "a strain of 3e-4 is below s0 = 5e-4");
    let brittle = run(&pull_deck(ROCK, 0.002), "brittle").unwrap();
    assert!(brittle.broken > 0, "the softened band passes s_f = 0.004");
    let tough = ROCK.replace("softening_stretch = 0.004", "softening_stretch = 1.0");
    let tough = run(&pull_deck(&tough, 0.002), "tough").unwrap();
    assert_eq!(tough.broken, 0, "no bond reaches s_f = 1");
    assert_eq!(tough.bonds, brittle.bonds);
}

/// The model's errors reach the user at the line of the key they are about.
#[test]
fn own_parameter_errors_name_the_key_and_its_line() {
    let bad = ROCK.replace("softening_stretch = 0.004", "softening_stretch = 0.0001");
    let text = pull_deck(&bad, 0.002);
    let err = run(&text, "bad").unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("softening_stretch"))
        .unwrap()
        + 1;
    assert!(err.contains(&format!("bad.toml:{line}:")), "{err}");
    assert!(
        err.contains("softening_stretch") && err.contains("must exceed"),
        "{err}"
    );

    let typo = ROCK.replace("softening_stretch", "softening_strech");
    let text = pull_deck(&typo, 0.002);
    let err = run(&text, "typo").unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("softening_strech"))
        .unwrap()
        + 1;
    assert!(err.contains(&format!("typo.toml:{line}:")), "{err}");
    assert!(err.contains("does not use 'softening_strech'"), "{err}");

    let units = ROCK.replace("\"20 GPa\"", "\"20 mm\"");
    let err = run(&pull_deck(&units, 0.002), "units").unwrap_err();
    assert!(err.contains("stress") && err.contains("length"), "{err}");
}

/// Its own sample material puts it on the benchmark's scene, as a registered model's does.
#[test]
fn own_sample_makes_the_benchmark_scene() {
    let text = pdq::lab::bench::standard_deck_of(&ModelInfo::of::<Softening>(), 6, 20).unwrap();
    assert!(text.contains("name = \"softening\"") && text.contains("softening_stretch = 4e-3"));
    let s = run(&text, "bench").unwrap();
    assert_eq!(s.steps, 20);
    assert!(s.bonds > 0);
}
