//! The LAMMPS peer of `pdq bench`: `peri/pmb` or `peri/lps` on the standard scene, run by
//! `lmp` in the same invocation.

use super::ranks::mpirun;
use super::BenchOptions;
use std::process::Command;

/// The LAMMPS input of the LPS peer benchmark (`shared/bench/lammps_lps.in`).
const LAMMPS_LPS: &str = "units si\nboundary s s s\natom_style peri\natom_modify map array\nlattice sc 0.001\nregion box block 0 ${n} 0 ${n} 0 ${n}\ncreate_box 1 box\ncreate_atoms 1 region box\npair_style peri/lps\npair_coeff * * 14.9e9 14.9e9 0.0030150 0.0005 0.25\nset group all density 2200\nset group all volume 1.0e-9\nvelocity all set 0.0 0.0 0.0 sum no units box\nregion top block INF INF INF INF $(v_n-2) ${n} units lattice\ngroup top region top\nvelocity top set 0.0 0.0 1.0 sum no units box\nneighbor 0.0010 bin\nfix 1 all nve\ntimestep 1.0e-7\nthermo 100\nrun ${steps}\n";

const LAMMPS_PMB: &str = "units si\nboundary s s s\natom_style peri\natom_modify map array\nlattice sc 0.001\nregion box block 0 ${n} 0 ${n} 0 ${n}\ncreate_box 1 box\ncreate_atoms 1 region box\npair_style peri/pmb\npair_coeff * * 1.6863e22 0.0030150 0.0005 0.25\nset group all density 2200\nset group all volume 1.0e-9\nvelocity all set 0.0 0.0 0.0 sum no units box\nregion top block INF INF INF INF $(v_n-2) ${n} units lattice\ngroup top region top\nvelocity top set 0.0 0.0 1.0 sum no units box\nneighbor 0.0010 bin\nfix 1 all nve\ntimestep 1.0e-7\nthermo 100\nrun ${steps}\n";

/// The LAMMPS pair style a bench is compared with: `lj/cut` on the LJ melt; on the standard
/// scene the model's own peer ([`crate::model::Model::LAMMPS_PEER`]), else `peri/pmb`, whose
/// solid the benchmark's is.
pub(super) fn peer_style(opts: &BenchOptions) -> &'static str {
    if opts.scene == "lj" {
        return "lj/cut";
    }
    crate::models::find(&opts.model)
        .and_then(|m| m.lammps_peer)
        .unwrap_or("peri/pmb")
}

/// LAMMPS `peri/pmb` (or `peri/lps`) on the same scene: `Ok(Ok((line, µs per particle-step)))`, or
/// `Ok(Err(line))` saying why it was skipped (no `lmp` on the PATH).
#[allow(clippy::type_complexity)]
pub(super) fn peer(
    opts: &BenchOptions,
    ranks: usize,
) -> Result<Result<(String, f64), String>, String> {
    let lmp = std::env::var("PDQ_LMP").unwrap_or_else(|_| "lmp".into());
    let dir = std::env::temp_dir().join(format!("pdq-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let style = peer_style(opts);
    let (name, text) = match style {
        "lj/cut" => ("lammps_lj.in", super::lj::LAMMPS_LJ),
        "peri/lps" => ("lammps_lps.in", LAMMPS_LPS),
        _ => ("lammps_pmb.in", LAMMPS_PMB),
    };
    let input = dir.join(name);
    std::fs::write(&input, text).map_err(|e| e.to_string())?;
    let mut cmd = if ranks > 1 {
        let mut c = mpirun(ranks);
        c.arg(&lmp);
        c
    } else {
        Command::new(&lmp)
    };
    let output = cmd
        .current_dir(&dir)
        .args(["-in", name, "-var", "n"])
        .arg(opts.n.to_string())
        .args(["-var", "steps"])
        .arg(opts.steps.to_string())
        .args(["-log", "none"])
        .output();
    let _ = std::fs::remove_dir_all(&dir);
    let output = match output {
        Ok(o) => o,
        Err(e) => {
            return Ok(Err(format!(
                "bench peer=lammps-{style} skipped: cannot run '{lmp}' ({e}); install it with apt-get install lammps\n"
            )))
        }
    };
    let text = String::from_utf8_lossy(&output.stdout);
    // "Loop time of 61.4 on 1 procs for 200 steps with 68921 atoms"
    let line = text
        .lines()
        .find(|l| l.starts_with("Loop time of"))
        .ok_or_else(|| format!("LAMMPS printed no 'Loop time' line:\n{text}"))?;
    let w: Vec<&str> = line.split_whitespace().collect();
    let secs: f64 = w
        .get(3)
        .and_then(|s| s.parse().ok())
        .ok_or("bad Loop time line")?;
    let atoms: f64 = w
        .get(11)
        .and_then(|s| s.parse().ok())
        .ok_or("bad Loop time line")?;
    let steps: f64 = w
        .get(8)
        .and_then(|s| s.parse().ok())
        .ok_or("bad Loop time line")?;
    let us = 1e6 * secs / (atoms * steps);
    Ok(Ok((
        format!(
            "bench peer=lammps-{style} particles={atoms} steps={steps} threads=1 ranks={ranks} us_per_particle_step={us:.4}\n"
        ),
        us,
    )))
}
