//! PDQ's LJ melt against LAMMPS's `lj/cut` from the same start (issue 23): PDQ writes the
//! positions and velocities as a LAMMPS data file (`pdq lammps-data`), LAMMPS reads it, and
//! both run 100 steps of NVE. The thermo (temperature, potential energy per atom, pressure)
//! must agree to 6 significant digits at step 0 and to 1e-3 over the 100 steps; in a growing
//! box (`[deform]` against `fix deform`) to 1e-8. Skipped, with a message, when `lmp` (or
//! `$PDQ_LMP`) cannot be run.

use pdq::driver::export::lammps_data;
use pdq::driver::run::{run, RunOptions};
use pdq::input::deck;
use std::process::Command;

/// LAMMPS's run of the data file: the same law, skin and step; neighbour lists checked every
/// step so that no pair is missed (bench/in.lj rebuilds blindly every 20).
const LAMMPS_IN: &str = "units lj
atom_style atomic
boundary p p p
read_data start.data
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
neighbor 0.3 bin
neigh_modify every 1 delay 0 check yes
fix 1 all nve
timestep 0.005
thermo 10
thermo_style custom step temp pe press
thermo_modify format float %.15g norm yes
run 100
";

/// (step, temperature, potential energy per atom, pressure) from LAMMPS's thermo output.
fn lammps_thermo(text: &str) -> Vec<[f64; 4]> {
    let mut rows = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.first() == Some(&"Step") {
            inside = true;
            continue;
        }
        if inside {
            let v: Vec<f64> = w.iter().filter_map(|s| s.parse().ok()).collect();
            if v.len() != 4 || v.len() != w.len() {
                break;
            }
            rows.push([v[0], v[1], v[2], v[3]]);
        }
    }
    rows
}

#[test]
fn the_lj_melt_has_lammps_thermo_from_the_same_start() {
    against_lammps("", "", "melt", 1e-3);
}

/// The melt in a box growing at 5 % per τ along each axis (`[deform]`) against LAMMPS's
/// `fix deform … erate 0.05 … remap x`: both change the box at the end of each step, so the
/// thermo agrees to round-off, not merely to the one step's strain that another order gives.
#[test]
fn the_lj_melt_in_a_growing_box_has_lammps_thermo_from_the_same_start() {
    against_lammps(
        "\n[deform]\nstrain_rate = [0.05, 0.05, 0.05]\n",
        "fix 2 all deform 1 x erate 0.05 y erate 0.05 z erate 0.05 remap x\n",
        "deform",
        1e-8,
    );
}

/// Runs the example at 8 × 8 × 8 fcc cells (2,048 atoms; a row every 10 steps) with `deck`
/// appended, and LAMMPS from the same start with `fixes` added; the thermo must agree to 1e-6
/// at step 0 and to `tolerance` (relative) after.
fn against_lammps(deck: &str, fixes: &str, name: &str, tolerance: f64) {
    let lmp = std::env::var("PDQ_LMP").unwrap_or_else(|_| "lmp".into());
    if Command::new(&lmp).arg("-h").output().is_err() {
        eprintln!("skipped: cannot run '{lmp}' (apt-get install lammps, or set PDQ_LMP)");
        return;
    }
    let text = std::fs::read_to_string("inputs/lj_melt.toml").unwrap();
    for kept in [
        "max = [33.5, 33.5, 33.5]",
        "history_every = 10",
        "steps = 100",
    ] {
        assert!(text.contains(kept), "inputs/lj_melt.toml lost '{kept}'");
    }
    let text = text.replace("max = [33.5, 33.5, 33.5]", "max = [13.4, 13.4, 13.4]") + deck;
    let scene = deck::parse(&text, "lj_melt.toml", "lj_melt").unwrap();
    let dir = std::env::temp_dir().join(format!("pdq-lammps-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let data = lammps_data(&scene).unwrap();
    assert_eq!(data.atoms.len(), 2048);
    std::fs::write(dir.join("start.data"), data.text()).unwrap();
    let input = LAMMPS_IN.replace("fix 1 all nve\n", &format!("fix 1 all nve\n{fixes}"));
    std::fs::write(dir.join("in.lj"), input).unwrap();
    let out = Command::new(&lmp)
        .current_dir(&dir)
        .args(["-in", "in.lj", "-log", "none"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let theirs = lammps_thermo(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(theirs.len(), 11, "{}", String::from_utf8_lossy(&out.stdout));

    run(
        &scene,
        &RunOptions {
            output: Some(dir.join("pdq")),
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    let history = std::fs::read_to_string(dir.join("pdq/history.csv")).unwrap();
    let rows: Vec<&str> = history.lines().collect();
    let col = |name: &str| rows[0].split(',').position(|c| c == name).unwrap();
    let (step, temp, pe, press) = (
        col("step"),
        col("temperature"),
        col("potential_energy"),
        col("pressure"),
    );
    let value = |row: &str, k: usize| row.split(',').nth(k).unwrap().parse::<f64>().unwrap();
    assert_eq!(rows.len(), 12, "{history}");
    let mut worst = [0.0f64; 3];
    for (row, lam) in rows[1..].iter().zip(&theirs) {
        assert_eq!(value(row, step), lam[0]);
        let ours = [value(row, temp), value(row, pe) / 2048.0, value(row, press)];
        let tolerance = if lam[0] == 0.0 { 1e-6 } else { tolerance };
        for k in 0..3 {
            let rel = (ours[k] - lam[k + 1]).abs() / lam[k + 1].abs();
            worst[k] = worst[k].max(rel);
            assert!(
                rel < tolerance,
                "{name}, step {}: {} PDQ {} LAMMPS {} (relative {rel:.2e})",
                lam[0],
                ["temperature", "pe/atom", "pressure"][k],
                ours[k],
                lam[k + 1]
            );
        }
    }
    println!("{name}: largest relative differences over 100 steps: temperature {:.2e}, pe/atom {:.2e}, pressure {:.2e}", worst[0], worst[1], worst[2]);
    std::fs::remove_dir_all(&dir).ok();
}
