//! The deforming periodic box (`[deform]`, issue 24's MD example): a perfect crystal at rest
//! in a growing box keeps zero forces and has, row by row, the pressure and energy of its
//! lattice sum at the current lattice parameter (wrong ghost images would break both at the
//! box's faces); a warm crystal follows the same trajectory on other layouts and after a
//! restart; and the deck's checks.

use crate::common::{final_positions, layout, max_distance, run_quietly};
use pdq::driver::run::RunOptions;
use std::path::PathBuf;

/// An lj deck of 8 × 8 × 8 fcc cells at density 1.0, periodic, LJ cut at 2.5 σ, 200 steps of
/// 0.005 τ, the box growing at `rate` per τ along each axis, with `extra` appended.
fn deck(rate: f64, extra: &str) -> String {
    let head = crate::common::fcc_box(1.0, 8, 0.05);
    format!(
        r#"{head}[pair]
law = "lj"
cutoff = 2.5
skin = 0.3
[pair.materials.argon]
epsilon = 1.0
sigma = 1.0
[deform]
strain_rate = [{rate}, {rate}, {rate}]
[time]
dt = 0.005
steps = 200
[output]
history_every = 20
final_state = true
progress = false
{extra}"#
    )
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdq-deform-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The history's columns by name.
fn columns(dir: &std::path::Path) -> std::collections::BTreeMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols: std::collections::BTreeMap<String, Vec<f64>> =
        names.iter().map(|n| (n.clone(), Vec::new())).collect();
    for l in lines {
        for (n, v) in names.iter().zip(l.split(',')) {
            cols.get_mut(n).unwrap().push(v.parse().unwrap());
        }
    }
    cols
}

/// Per atom, the LJ energy ½ Σ U(r) and virial ½ Σ (−r U'(r)) over an fcc lattice of cell side
/// `a`, within `cutoff`, by direct summation over lattice vectors.
fn lattice_sums(a: f64, cutoff: f64) -> (f64, f64) {
    let n = (2.0 * cutoff / a).ceil() as i64 + 1;
    let (mut energy, mut virial) = (0.0, 0.0);
    for i in -n..=n {
        for j in -n..=n {
            for k in -n..=n {
                if (i + j + k) % 2 != 0 || (i, j, k) == (0, 0, 0) {
                    continue;
                }
                let r = 0.5 * a * ((i * i + j * j + k * k) as f64).sqrt();
                if r < cutoff {
                    let s6 = r.powi(-6);
                    energy += 0.5 * 4.0 * (s6 * s6 - s6);
                    virial += 0.5 * (48.0 * s6 * s6 - 24.0 * s6);
                }
            }
        }
    }
    (energy, virial)
}

#[test]
fn a_crystal_at_rest_in_a_growing_box_has_its_lattice_sums_row_by_row() {
    let rate = 0.05; // 5 % along each axis over the run's 1 τ
    for (threads, procs) in [(1, [1, 1, 1]), (4, [2, 2, 1])] {
        let dir = out_dir(&format!("rest-{threads}"));
        run_quietly(&deck(rate, ""), "deform.toml", &dir, layout(threads, procs)).unwrap();
        let c = columns(&dir);
        let n = 2048.0;
        let a0 = (4.0f64 / 1.0).cbrt();
        for (r, t) in c["time"].iter().enumerate() {
            // The box changes at the end of each step (as LAMMPS's fix deform): a row's
            // forces, energy and virial are those of the box before its step's change, its
            // volume that after.
            let before = 1.0 + rate * (t - 0.005).max(0.0);
            let (energy, virial) = lattice_sums(a0 * before, 2.5);
            let volume = n * (a0 * (1.0 + rate * t)).powi(3) / 4.0;
            let pressure = n * virial / (3.0 * volume);
            let e = c["pair_energy"][r] / n;
            let p = c["pressure"][r];
            assert!(
                (e - energy).abs() < 1e-9 * energy.abs(),
                "{procs:?} row {r}: energy per atom {e} against the lattice sum {energy}"
            );
            assert!(
                (p - pressure).abs() < 1e-9 * pressure.abs(),
                "{procs:?} row {r} (stretch {before}): pressure {p} against {pressure}"
            );
            // By symmetry every force is zero, so nothing moves relative to the box.
            assert!(c["kinetic_energy"][r] < 1e-20, "{procs:?} row {r}");
        }
        // The crystal went from tension to more tension: the sums differ along the run.
        let (first, last) = (c["pressure"][0], *c["pressure"].last().unwrap());
        assert!(last < first - 1.0, "pressure {first} → {last}");
        let x = final_positions(&dir);
        let top = x.iter().map(|p| p[0]).fold(f64::MIN, f64::max);
        let period = 8.0 * a0 * (1.0 + rate);
        assert!(
            top > 0.9 * period && top < period,
            "the atoms fill the grown box (x up to {top}, period {period})"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}

#[test]
fn a_warm_crystal_in_a_growing_box_is_the_same_on_other_layouts_and_after_a_restart() {
    let text = deck(
        0.1,
        "checkpoint_every = 100\n[velocity]\ntemperature = 0.3\nseed = 5\n",
    );
    let one = out_dir("warm-1");
    run_quietly(&text, "deform.toml", &one, layout(1, [1, 1, 1])).unwrap();
    let reference = final_positions(&one);
    let period = 8.0 * 4.0f64.cbrt() * 1.1;
    for (threads, procs) in [(2, [2, 1, 1]), (4, [1, 2, 2])] {
        let dir = out_dir(&format!("warm-{threads}"));
        run_quietly(&text, "deform.toml", &dir, layout(threads, procs)).unwrap();
        let d = max_distance(&reference, &final_positions(&dir), period);
        eprintln!("{procs:?}: positions within {d:.2e} of one thread's");
        assert!(d < 1e-9, "{procs:?}: positions differ by {d:e}");
        std::fs::remove_dir_all(&dir).ok();
    }
    // Stopped at step 100 and restarted from its checkpoint: the box resumes at its size.
    let resumed = out_dir("warm-resumed");
    let first = RunOptions {
        steps: Some(100),
        ..layout(1, [1, 1, 1])
    };
    run_quietly(&text, "deform.toml", &resumed, first).unwrap();
    let again = RunOptions {
        restart: Some(resumed.join("checkpoints")),
        ..layout(2, [2, 1, 1])
    };
    run_quietly(&text, "deform.toml", &resumed, again).unwrap();
    let d = max_distance(&reference, &final_positions(&resumed), period);
    eprintln!("restarted on 2 threads: positions within {d:.2e}");
    assert!(d < 1e-9, "restart: positions differ by {d:e}");
    let (p, q) = (columns(&one), columns(&resumed));
    let last = |c: &std::collections::BTreeMap<String, Vec<f64>>| *c["pressure"].last().unwrap();
    assert!((last(&p) - last(&q)).abs() < 1e-9 * last(&p).abs());
    for d in [one, resumed] {
        std::fs::remove_dir_all(&d).ok();
    }
}

#[test]
fn the_deck_refuses_a_deformation_it_cannot_do() {
    let base = deck(0.1, "");
    let cases = [
        (
            base.replace(r#"periodic = ["x", "y", "z"]"#, r#"periodic = ["x", "y"]"#),
            "that axis is not periodic",
        ),
        (
            base.replace("strain_rate = [0.1, 0.1, 0.1]", "strain_rate = [0.1, 0.1]"),
            "deform.toml:23: invalid length 2, expected an array of length 3",
        ),
        (
            base.replace("[deform]\n", "[deform]\nevery = 0\n"),
            "every must be ≥ 1",
        ),
        (
            base.replace(
                "strain_rate = [0.1, 0.1, 0.1]",
                "strain_rate = [0.1, nan, 0]",
            ),
            "finite",
        ),
    ];
    for (text, expected) in cases {
        let e = pdq::input::deck::parse(&text, "deform.toml", "deform")
            .err()
            .unwrap_or_else(|| panic!("accepted:\n{text}"))
            .to_string();
        assert!(e.contains(expected), "'{expected}' not in: {e}");
    }
    // A box squeezed until its cells are narrower than the pair reach stops with the reason.
    let dir = out_dir("squeeze");
    let squeeze = deck(-0.5, "").replace("steps = 200", "steps = 2000");
    let e = run_quietly(&squeeze, "deform.toml", &dir, layout(1, [1, 1, 1])).unwrap_err();
    assert!(e.contains("narrower than the pair law's reach"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
