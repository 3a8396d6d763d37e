//! The wall-method decomposition: every pair evaluated exactly once on any layout, the same
//! results on every layout (threads here; `tests/mpi_runs.rs` does MPI), and clear refusals of
//! layouts that cannot work.

use pdq::driver::run::{run, RunOptions, Summary};
use pdq::input::deck;
use pdq::input::setup::build_as;
use pdq::models::pmb::Pmb;
use pdq::parallel;
use pdq::parallel::decomposition::{Procs, Walls};
use proptest::prelude::*;

mod common;
use common::max_relative_difference;
use std::collections::BTreeMap;

/// A PMB box of `n` particles per axis at unit spacing with horizon `h`, periodic on `periodic`.
fn box_deck(n: [usize; 3], h: f64, periodic: &[&str]) -> String {
    let per: Vec<String> = periodic.iter().map(|a| format!("\"{a}\"")).collect();
    format!(
        r#"units = "SI"
[model]
name = "pmb"
horizon = {h}
[lattice]
spacing = 1.0
periodic = [{}]
[materials.rock]
density = 1.0
micromodulus = 1.0
critical_stretch = 0.01
[[geometry]]
shape = "box"
material = "rock"
min = [0, 0, 0]
max = [{}, {}, {}]
[time]
steps = 1
dt = 1e-3
force_dt = true
[output]
progress = false
"#,
        per.join(", "),
        n[0],
        n[1],
        n[2]
    )
}

/// Pairs within the horizon by brute force, with periodic images: (gid, gid) → length.
fn brute_force(
    gid: &[u32],
    x: &[[f64; 3]],
    h: f64,
    period: [Option<f64>; 3],
) -> BTreeMap<(u32, u32), f64> {
    let mut m = BTreeMap::new();
    let h2 = h * h * (1.0 + 2e-10);
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let mut best = f64::INFINITY;
            let mut hits = 0;
            for kx in -1i32..=1 {
                for ky in -1i32..=1 {
                    for kz in -1i32..=1 {
                        let k = [kx, ky, kz];
                        if (0..3).any(|a| k[a] != 0 && period[a].is_none()) {
                            continue;
                        }
                        let d: f64 = (0..3)
                            .map(|a| {
                                let s = k[a] as f64 * period[a].unwrap_or(0.0);
                                (x[j][a] + s - x[i][a]).powi(2)
                            })
                            .sum();
                        if d <= h2 {
                            hits += 1;
                            best = best.min(d.sqrt());
                        }
                    }
                }
            }
            assert!(hits <= 1, "a pair within the horizon in two images");
            if hits == 1 {
                m.insert((gid[i].min(gid[j]), gid[i].max(gid[j])), best);
            }
        }
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn every_pair_is_evaluated_exactly_once_on_any_layout(
        n in (3usize..11, 3usize..11, 3usize..9),
        h in 1.0f64..3.2,
        procs in (1usize..4, 1usize..4, 1usize..4),
        periodic in (any::<bool>(), any::<bool>(), any::<bool>()),
        trimmed in any::<bool>(),
        jitter in 0.0f64..0.45,
        seed in any::<u64>(),
    ) {
        let n = [n.0, n.1, n.2];
        let flags = [periodic.0, periodic.1, periodic.2];
        let axes: Vec<&str> = ["x", "y", "z"].iter().zip(flags).filter(|(_, p)| *p).map(|(a, _)| *a).collect();
        let scene = deck::parse(&box_deck(n, h, &axes), "t.toml", "t").unwrap();
        let mut setup = match build_as::<Pmb>(&scene) {
            Ok(s) => s,
            Err(e) => {
                // Only a periodic axis shorter than three horizons may be refused.
                prop_assert!(e.message.contains("periodic axis"), "{}", e.message);
                return Ok(());
            }
        };
        // A random cloud: the lattice jittered (inside each particle's own lattice cube, so a
        // periodic box still holds every particle once).
        let mut state = seed | 1;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for x in setup.sim.particles.x0.iter_mut() {
            for v in x.iter_mut() {
                *v += 2.0 * jitter * rnd();
            }
        }
        let walls = if trimmed { Walls::Trimmed } else { Walls::Whole };
        let p = [procs.0, procs.1, procs.2];
        let layout = match parallel::layout(&setup, &Procs::Given(p), p.iter().product(), walls) {
            Ok(l) => l,
            Err(e) => {
                prop_assert!(e.contains("procCubes along") && e.contains("use at most"), "{}", e);
                return Ok(());
            }
        };
        let period = [0, 1, 2].map(|a| flags[a].then_some(n[a] as f64));
        let expected = brute_force(&setup.sim.particles.gid, &setup.sim.particles.x0, h, period);
        let cubes = parallel::thread_cubes(&setup, &layout);
        let mut seen: BTreeMap<(u32, u32), f64> = BTreeMap::new();
        let mut owned = 0;
        for c in &cubes {
            let p = &c.sim.particles;
            owned += p.n_owned;
            for (i, j, b) in c.sim.bonds.iter() {
                prop_assert!(i < p.n_owned, "a ghost owns a bond");
                let key = (p.gid[i].min(p.gid[j]), p.gid[i].max(p.gid[j]));
                prop_assert!(key.0 != key.1);
                prop_assert!(seen.insert(key, c.sim.bonds.geom[b].length).is_none(),
                    "pair {:?} evaluated twice", key);
            }
        }
        prop_assert_eq!(owned, setup.sim.particles.len());
        prop_assert_eq!(seen.len(), expected.len(), "layout {:?}", p);
        for (k, l) in &expected {
            let got = seen.get(k);
            prop_assert!(got.is_some(), "pair {:?} missing (layout {:?}, periodic {:?})", k, p, flags);
            prop_assert!((got.unwrap() - l).abs() <= 1e-12 * l, "pair {:?} length", k);
        }
    }
}

/// A notched block pulled apart fast enough to crack within 500 steps.
fn fracture_deck(extra: &str) -> String {
    format!("{}\n{extra}", include_str!("decks/notched_pull.toml"))
}

fn run_layout(text: &str, procs: [usize; 3], walls: Walls) -> Summary {
    run_with_history(text, procs, walls).0
}

/// A run and its `history.csv` as rows of numbers (with the header).
fn run_with_history(
    text: &str,
    procs: [usize; 3],
    walls: Walls,
) -> (Summary, Vec<String>, Vec<Vec<f64>>) {
    history_run(text, procs, walls, false)
}

/// [`run_with_history`], set up per procCube (`parallel::part`) where `per_rank`.
fn history_run(
    text: &str,
    procs: [usize; 3],
    walls: Walls,
    per_rank: bool,
) -> (Summary, Vec<String>, Vec<Vec<f64>>) {
    let scene = deck::parse(text, "t.toml", "t").unwrap();
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "pdq-wall-{}-{}-{}x{}x{}-{}",
        std::process::id(),
        RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        procs[0],
        procs[1],
        procs[2],
        walls.name()
    ));
    let n = procs.iter().product();
    let options = RunOptions {
        output: Some(dir.clone()),
        quiet: true,
        threads: Some(n),
        procs: Some(Procs::Given(procs)),
        walls: Some(walls),
        ..Default::default()
    };
    let s = if per_rank {
        pdq::driver::run_part::run_on_threads(&scene, &options, n)
    } else {
        run(&scene, &options)
    }
    .unwrap();
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let _ = std::fs::remove_dir_all(dir);
    (s, header, rows)
}

#[test]
fn fracture_results_do_not_depend_on_the_layout() {
    let text = fracture_deck("");
    let reference = run_layout(&text, [1, 1, 1], Walls::Whole);
    assert!(
        reference.broken > 100,
        "the deck must crack within 500 steps ({} broken)",
        reference.broken
    );
    assert!(reference.positions.iter().all(|p| p[0].is_finite()));
    for (procs, walls) in [
        ([2, 1, 1], Walls::Whole),
        ([1, 2, 2], Walls::Whole),
        ([2, 2, 2], Walls::Whole),
        ([3, 2, 1], Walls::Whole),
        ([2, 2, 2], Walls::Trimmed),
        ([3, 2, 1], Walls::Trimmed),
    ] {
        let s = run_layout(&text, procs, walls);
        let d = max_relative_difference(&reference.positions, &s.positions);
        eprintln!(
            "{procs:?} {}: max relative position difference {d:.2e}, {} broken",
            walls.name(),
            s.broken
        );
        assert!(
            d <= 1e-12,
            "{procs:?} {}: positions differ by {d:e}",
            walls.name()
        );
        assert_eq!(s.bonds, reference.bonds, "{procs:?}: bond count");
        assert_eq!(
            s.broken_pairs,
            reference.broken_pairs,
            "{procs:?} {}: broken bonds differ",
            walls.name()
        );
    }
}

#[test]
fn reinforced_concrete_results_do_not_depend_on_the_layout() {
    // Two materials and bond history (steel plasticity) across procCube faces.
    let text = r#"units = "SI"
[model]
name = "concrete"
horizon = "3.015 mm"
[lattice]
spacing = "1 mm"
[materials.concrete]
kind = "concrete"
density = "2400 kg/m^3"
youngs_modulus = "25 GPa"
poisson_ratio = 0.25
tensile_stretch = 0.0003
compressive_stretch = -0.003
[materials.steel]
kind = "steel"
density = "7850 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.25
yield_stretch = 0.0005
failure_stretch = 0.01
[[geometry]]
shape = "box"
material = "concrete"
min = "0 0 0 mm"
max = "30 8 8 mm"
[[geometry]]
shape = "box"
material = "steel"
min = "0 3 3 mm"
max = "30 5 5 mm"
[time]
steps = 500
[[boundary]]
name = "left"
region = { shape = "slab", axis = "x", from = "0 mm", to = "3 mm" }
fixed = ["all"]
[[boundary]]
name = "right"
region = { shape = "slab", axis = "x", from = "27 mm", to = "30 mm" }
velocity = "3 0 0 m/s"
components = ["x"]
history = { ramp = "1 us" }
[output]
progress = false
history_every = 100
"#;
    let reference = run_layout(text, [1, 1, 1], Walls::Whole);
    assert!(reference.broken > 0, "the bar must crack");
    for procs in [[2, 1, 1], [2, 2, 2], [3, 2, 1]] {
        let s = run_layout(text, procs, Walls::Trimmed);
        let d = max_relative_difference(&reference.positions, &s.positions);
        assert!(d <= 1e-12, "{procs:?}: positions differ by {d:e}");
        assert_eq!(s.broken_pairs, reference.broken_pairs, "{procs:?}");
    }
}

#[test]
fn the_same_layout_gives_bit_identical_results() {
    let text = fracture_deck("");
    let a = run_layout(&text, [2, 2, 1], Walls::Whole);
    let b = run_layout(&text, [2, 2, 1], Walls::Whole);
    assert_eq!(max_relative_difference(&a.positions, &b.positions), 0.0);
    assert_eq!(a.broken_pairs, b.broken_pairs);
}

#[test]
fn periodic_box_gives_every_particle_a_whole_family() {
    // Periodic on all axes, a lattice has no surface: every particle has 122 bonds at m = 3,
    // on one procCube (it sends its walls to itself) and on several.
    let text = box_deck([10, 10, 10], 3.015, &["x", "y", "z"]);
    let scene = deck::parse(&text, "t.toml", "t").unwrap();
    let setup = build_as::<Pmb>(&scene).unwrap();
    for procs in [[1, 1, 1], [2, 1, 1], [2, 2, 2], [3, 1, 1]] {
        let layout = parallel::layout(
            &setup,
            &Procs::Given(procs),
            procs.iter().product(),
            Walls::Whole,
        )
        .unwrap();
        let cubes = parallel::thread_cubes(&setup, &layout);
        let counts = parallel::on_threads(cubes, |mut c| {
            c.start();
            c.sim.bonds.initial[..c.sim.particles.n_owned].to_vec()
        });
        for (k, c) in counts.iter().enumerate() {
            assert!(
                c.iter().all(|&n| n == 122),
                "{procs:?}: procCube {k} has particles with {:?} bonds",
                c.iter().filter(|&&n| n != 122).take(3).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn a_periodic_bar_has_no_seam() {
    // A bar periodic along x, sliding along x as a rigid body: if ghost images across the seam
    // were misplaced, the bonds there would stretch (strain energy, broken bonds). Layouts agree.
    let mut text = box_deck([12, 4, 4], 3.015, &["x"]);
    text = text.replace("steps = 1\ndt = 1e-3", "steps = 200\ndt = 1e-3");
    text.push_str(
        "[[initial]]\nregion = { shape = \"box\", min = [0, 0, 0], max = [12, 4, 4] }\nvelocity = [0.01, 0, 0]\n",
    );
    let a = run_layout(&text, [1, 1, 1], Walls::Whole);
    let b = run_layout(&text, [3, 1, 1], Walls::Trimmed);
    assert!(max_relative_difference(&a.positions, &b.positions) <= 1e-12);
    assert_eq!(a.broken, 0);
    assert!(a.kinetic_energy > 0.0);
    assert!(
        a.strain_energy <= 1e-20 * a.kinetic_energy,
        "strain energy {} in a rigid slide",
        a.strain_energy
    );
    // Positions along x advanced by v·t everywhere: their spread is the lattice's.
    let xs: Vec<f64> = a.positions.iter().map(|p| p[0]).collect();
    let min = xs.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!((min - (0.5 + 0.01 * 0.2)).abs() < 1e-9, "min x {min}");
}

#[test]
fn layouts_that_cannot_work_say_what_to_change() {
    let scene = deck::parse(&fracture_deck(""), "t.toml", "t").unwrap();
    let setup = build_as::<Pmb>(&scene).unwrap();
    // Particles 9 mm apart across with a 3.015 mm horizon: 2 cells, so 4 procCubes cannot fit.
    let e = parallel::layout(&setup, &Procs::Given([1, 4, 1]), 4, Walls::Whole).unwrap_err();
    assert!(
        e.contains("4 procCubes along y") && e.contains("use at most 2"),
        "{e}"
    );
    let e = parallel::layout(&setup, &Procs::Given([2, 1, 1]), 3, Walls::Whole).unwrap_err();
    assert!(e.contains("one procCube per worker"), "{e}");

    // In a deck: the message names the file and line of [parallel].
    let text = format!("{}\n[parallel]\nprocs = [1, 1, 9]\n", fracture_deck(""));
    let scene = deck::parse(&text, "t.toml", "t").unwrap();
    let e = run(
        &scene,
        &RunOptions {
            quiet: true,
            output: Some(std::env::temp_dir().join("pdq-wall-bad")),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        e.contains("t.toml:") && e.contains("9 procCubes along z"),
        "{e}"
    );

    for (bad, what) in [
        ("procs = [0, 1, 1]", "at least 1"),
        ("procs = \"many\"", "\"auto\""),
        ("threads = 3\nprocs = [2, 1, 1]", "one procCube per thread"),
        ("walls = \"thin\"", "trimmed"),
        ("cell_factor = 0.5", "thinner than the horizon"),
        ("cell_factor = 1.5\nskin = 0.5", "not both"),
    ] {
        let text = format!("{}\n[parallel]\n{bad}\n", fracture_deck(""));
        let e = deck::parse(&text, "t.toml", "t").unwrap_err().to_string();
        assert!(e.contains("t.toml:") && e.contains(what), "{bad}: {e}");
    }

    // A periodic axis shorter than three horizons.
    let scene = deck::parse(&box_deck([8, 4, 4], 3.015, &["y"]), "t.toml", "t").unwrap();
    let e = build_as::<Pmb>(&scene).err().unwrap().to_string();
    assert!(
        e.contains("periodic axis y") && e.contains("three horizons"),
        "{e}"
    );
}

/// Two halves of a free block thrown along x at different speeds: the block travels several
/// cells, so particles cross procCube faces, and it tears at the middle.
fn flying_block(extra: &str) -> String {
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
critical_stretch = 0.002
[[geometry]]
shape = "box"
material = "rock"
min = "0 0 0 mm"
max = "20 8 8 mm"
[time]
steps = 400
[[initial]]
region = {{ shape = "box", min = "0 0 0 mm", max = "10 8 8 mm" }}
velocity = "150 10 0 m/s"
[[initial]]
region = {{ shape = "box", min = "10 0 0 mm", max = "20 8 8 mm" }}
velocity = "260 0 -5 m/s"
[output]
progress = false
history_every = 50
{extra}
"#
    )
}

#[test]
fn shuffled_runs_match_unshuffled_ones() {
    // Same cells (the skin) for both, so that only the shuffling differs.
    let plain = flying_block("[parallel]\nskin = 0.25\n");
    let reference = run_layout(&plain, [1, 1, 1], Walls::Whole);
    assert!(reference.broken > 100, "{} broken", reference.broken);
    let travel = reference
        .positions
        .iter()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min);
    assert!(
        travel > 0.008,
        "the block must travel several cells ({travel})"
    );
    for (procs, walls) in [([2, 1, 1], Walls::Whole), ([4, 1, 1], Walls::Trimmed)] {
        let shuffled = flying_block("[parallel]\nshuffle_every = 20\n");
        let s = run_layout(&shuffled, procs, walls);
        assert!(s.shuffles > 0, "{procs:?}: no particle changed procCube");
        let d = max_relative_difference(&reference.positions, &s.positions);
        eprintln!(
            "{procs:?} shuffled {} times: max relative position difference {d:.2e}",
            s.shuffles
        );
        assert!(d <= 1e-12, "{procs:?}: positions differ by {d:e}");
        assert_eq!(s.broken_pairs, reference.broken_pairs, "{procs:?}");
        assert_eq!(s.broken, reference.broken);
        // Damage counts bonds a shuffle dropped once broken.
        assert_eq!(s.damage, reference.damage, "{procs:?}: damage");
    }
}

#[test]
fn a_particle_further_than_the_next_proc_cube_is_an_error() {
    // One shuffle after 400 steps: the block's rear has crossed two of the four procCubes,
    // which migration (to neighbours only) must refuse by name rather than lose.
    let late = flying_block("[parallel]\nshuffle_every = 400\n");
    let scene = deck::parse(&late, "t.toml", "t").unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-far-jump-{}", std::process::id()));
    let options = RunOptions {
        output: Some(dir.clone()),
        quiet: true,
        threads: Some(4),
        procs: Some(Procs::Given([4, 1, 1])),
        walls: Some(Walls::Whole),
        ..Default::default()
    };
    let Err(e) = run(&scene, &options) else {
        panic!("the jump must be refused");
    };
    let _ = std::fs::remove_dir_all(dir);
    assert!(
        e.contains("particle ")
            && e.contains("further than the next procCube")
            && e.contains("shuffle_every")
            && e.contains("step 400"),
        "{e}"
    );
}

#[test]
fn shuffles_keep_reactions_loads_and_damage() {
    // A notched bar carried along x at 80 m/s by two grips that pull it apart at 4 m/s, with a
    // total-force load and a probe: particles cross procCube faces, the grips keep reacting,
    // and the history must not notice the shuffles.
    let deck = |parallel: &str| {
        format!(
            "{}[parallel]\n{parallel}\n",
            include_str!("decks/carried_bar.toml")
        )
    };
    let plain = deck("skin = 0.25");
    let shuffled = deck("shuffle_every = 5");
    let (a, header, rows_a) = run_with_history(&plain, [1, 1, 1], Walls::Whole);
    let (b, _, rows_b) = run_with_history(&shuffled, [2, 2, 1], Walls::Whole);
    assert!(
        b.shuffles > 0,
        "the grips must carry particles across a face"
    );
    let right = header.iter().position(|h| h == "reaction_right_x").unwrap();
    assert!(
        rows_a.iter().skip(1).all(|r| r[right].abs() > 0.1),
        "the right grip must pull on the bar all along"
    );
    assert_eq!(a.broken_pairs, b.broken_pairs);
    assert!(max_relative_difference(&a.positions, &b.positions) <= 1e-12);
    for (k, d) in a.damage.iter().zip(&b.damage).enumerate() {
        assert!(
            (d.0 - d.1).abs() <= 1e-12,
            "particle {k}: damage {} vs {}",
            d.0,
            d.1
        );
    }
    // Set up per procCube, each particle's places in the grips, the load and the probe travel
    // with it: no procCube holds the whole scene's lists.
    let (c, _, rows_c) = history_run(&shuffled, [2, 2, 1], Walls::Whole, true);
    assert_eq!(b.shuffles, c.shuffles);
    assert_eq!(a.broken_pairs, c.broken_pairs);
    assert!(max_relative_difference(&a.positions, &c.positions) <= 1e-12);
    for rows in [rows_b, rows_c] {
        assert_eq!(rows_a.len(), rows.len());
        for (ra, rb) in rows_a.iter().zip(&rows) {
            for (c, name) in header.iter().enumerate() {
                let scale = rows_a.iter().map(|r| r[c].abs()).fold(1e-30, f64::max);
                assert!(
                    (ra[c] - rb[c]).abs() <= 1e-9 * scale + 1e-12,
                    "step {}: {name} {} vs {}",
                    ra[0],
                    ra[c],
                    rb[c]
                );
            }
        }
    }
}

#[test]
fn shuffling_on_a_short_periodic_axis_finds_the_right_images() {
    // A periodic axis of exactly three cells, two procCubes along it: a slide that wraps.
    let base = box_deck([12, 6, 4], 3.015, &["x"])
        .replace("steps = 1\ndt = 1e-3", "steps = 300\ndt = 5e-3")
        .replace("critical_stretch = 0.01", "critical_stretch = 0.02");
    let slide = "[[initial]]\nregion = { shape = \"box\", min = [0, 0, 0], max = [12, 6, 4] }\nvelocity = [20, 0, 0]\n[[initial]]\nregion = { shape = \"box\", min = [0, 0, 0], max = [12, 6, 1] }\nvelocity = [20.5, 0, 0]\n";
    let plain = format!("{base}{slide}[parallel]\nskin = 0.25\n");
    let shuffled = format!("{base}{slide}[parallel]\nshuffle_every = 5\n");
    let a = run_layout(&plain, [1, 1, 1], Walls::Whole);
    for procs in [[2, 1, 1], [3, 1, 1]] {
        let b = run_layout(&shuffled, procs, Walls::Whole);
        assert!(b.shuffles > 0);
        assert_eq!(a.broken_pairs, b.broken_pairs, "{procs:?}");
        let drift: Vec<[f64; 3]> = a.positions.clone();
        // Shuffled positions are wrapped into the box; compare modulo the period.
        let wrapped: Vec<[f64; 3]> = b
            .positions
            .iter()
            .zip(&drift)
            .map(|(p, q)| {
                let k = ((q[0] - p[0]) / 12.0).round();
                [p[0] + 12.0 * k, p[1], p[2]]
            })
            .collect();
        let d = max_relative_difference(&a.positions, &wrapped);
        assert!(d <= 1e-12, "{procs:?}: positions differ by {d:e}");
    }
}

#[test]
fn lps_micropolar_and_thermal_results_do_not_depend_on_the_layout() {
    for model in ["lps", "micropolar", "thermal"] {
        let text = common::model_pull_deck(model);
        let (reference, header, ref_rows) = run_with_history(&text, [1, 1, 1], Walls::Whole);
        assert!(
            reference.broken > 50,
            "{model}: the deck must crack within 500 steps ({} broken)",
            reference.broken
        );
        for (procs, walls) in [
            ([2, 1, 1], Walls::Whole),
            ([2, 2, 2], Walls::Trimmed),
            ([3, 2, 1], Walls::Whole),
        ] {
            let (s, h, rows) = run_with_history(&text, procs, walls);
            let d = max_relative_difference(&reference.positions, &s.positions);
            eprintln!(
                "{model} {procs:?} {}: max relative position difference {d:.2e}, {} broken",
                walls.name(),
                s.broken
            );
            assert!(d <= 1e-12, "{model} {procs:?}: positions differ by {d:e}");
            assert_eq!(s.broken_pairs, reference.broken_pairs, "{model} {procs:?}");
            // Every history column (energies, reactions: moments, the cold support's heat)
            // agrees to round-off, relative to the column's largest value; a support whose
            // reaction is round-off zero (a detached end) is measured against all reactions.
            assert_eq!(h, header);
            assert_eq!(rows.len(), ref_rows.len());
            let column_max = |k: usize| {
                ref_rows
                    .iter()
                    .fold(0.0f64, |m, r: &Vec<f64>| m.max(r[k].abs()))
            };
            let reactions = (0..header.len())
                .filter(|&k| header[k].starts_with("reaction_"))
                .map(column_max)
                .fold(0.0, f64::max);
            for k in 0..header.len() {
                let scale = if header[k].starts_with("reaction_") {
                    column_max(k).max(1e-6 * reactions)
                } else {
                    column_max(k)
                };
                for (a, b) in rows.iter().zip(&ref_rows) {
                    assert!(
                        (a[k] - b[k]).abs() <= 1e-9 * scale,
                        "{model} {procs:?}: history column {} differs: {} vs {}",
                        header[k],
                        a[k],
                        b[k]
                    );
                }
            }
        }
    }
}
