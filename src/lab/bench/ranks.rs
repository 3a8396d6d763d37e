//! `pdq bench --ranks`: the standard scene under `mpirun`, one procCube per rank.

use super::{bench_name, field, median_lines, BenchOptions};
#[cfg(feature = "mpi")]
use super::{bytes_of, line};
#[cfg(feature = "mpi")]
use crate::input::{deck, setup};
#[cfg(feature = "mpi")]
use crate::model::{Model, ModelVisitor};
#[cfg(feature = "mpi")]
use crate::parallel::{self, decomposition::Procs};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::process::Command;

/// Under `mpirun`: this rank's procCube of the standard scene; rank 0 prints the line.
#[cfg(feature = "mpi")]
pub(super) struct MpiVisit<'a>(pub &'a deck::Scene, pub &'a BenchOptions);
#[cfg(feature = "mpi")]
impl ModelVisitor for MpiVisit<'_> {
    type Output = Result<String, String>;
    fn visit<M: Model>(self, model: M) -> Self::Output {
        use crate::parallel::comm::Transport;
        let mpi = crate::parallel::comm_mpi::Mpi::init().ok_or("MPI was already initialized")?;
        let (rank, ranks) = (mpi.rank(), mpi.size());
        let setup = setup::build(model, self.0).map_err(|e| e.to_string())?;
        let layout = parallel::layout(&setup, &Procs::Auto, ranks, self.1.walls)?;
        let plans = crate::parallel::decomposition::cell_plans(&layout);
        let cube = parallel::build_cube(&setup, &layout, &plans, rank, Box::new(mpi));
        let n = setup.sim.particles.len();
        drop(setup);
        let t = cube.timed_steps(self.1.steps);
        Ok(if rank == 0 {
            format!(
                "{} launcher=mpirun layout={}\n",
                line(
                    bench_name(self.1),
                    bytes_of::<M>(),
                    n,
                    self.1.steps,
                    1,
                    ranks,
                    &t
                ),
                layout.describe().replace(' ', "_")
            )
        } else {
            String::new()
        })
    }
}

/// `mpirun -np ranks`, allowed to run as root (containers) and on more ranks than cores.
pub(super) fn mpirun(ranks: usize) -> Command {
    let mut c = Command::new("mpirun");
    c.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .args(["--oversubscribe", "-np"])
        .arg(ranks.to_string());
    c
}

/// The rank counts of `--ranks`, `--rounds` times through, alternating as the thread counts
/// do: each run's line (with its speed-up over the one-rank run of the same round), then,
/// with more than one round, the medians per rank count.
pub(super) fn ranks_lines(opts: &BenchOptions) -> Result<String, String> {
    let mut out = String::new();
    let mut per_count: BTreeMap<usize, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for _ in 0..opts.rounds.max(1) {
        let mut one_rank = None;
        for &ranks in &opts.ranks {
            let line = ranks_line(opts, ranks)?;
            let us = line
                .lines()
                .find_map(|l| field(l, "us_per_particle_step")?.parse::<f64>().ok());
            let Some(us) = us else {
                out.push_str(&line);
                continue;
            };
            let entry = per_count.entry(ranks).or_default();
            entry.0.push(us);
            let speedup = match one_rank {
                _ if ranks == 1 => {
                    one_rank = Some(us);
                    None
                }
                Some(base) => Some(base / us),
                None => None,
            };
            match speedup {
                Some(s) => {
                    entry.1.push(s);
                    let _ = writeln!(out, "{} speedup={s:.2}", line.trim_end());
                }
                None => out.push_str(&line),
            }
        }
    }
    if opts.rounds > 1 {
        let counts = per_count
            .iter()
            .map(|(r, runs)| (format!("threads=1 ranks={r}"), runs));
        median_lines(&mut out, bench_name(opts), counts);
    }
    Ok(out)
}

/// Runs this program's bench under `mpirun -np ranks` and returns its line.
fn ranks_line(opts: &BenchOptions, ranks: usize) -> Result<String, String> {
    if !cfg!(feature = "mpi") {
        return Ok(format!(
            "bench ranks={ranks} skipped: this pdq was built without the 'mpi' feature (cargo build --release --features mpi)\n"
        ));
    }
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let out = mpirun(ranks)
        .arg(exe)
        .args([
            "bench",
            "--model",
            &opts.model,
            "--scene",
            &opts.scene,
            "--threads",
            "1",
            "--no-yardstick",
            "--steps",
        ])
        .arg(opts.steps.to_string())
        .arg("--n")
        .arg(opts.n.to_string())
        .args(["--walls", opts.walls.name()])
        .output();
    match out {
        Ok(o) if o.status.success() => Ok(String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| l.starts_with("bench"))
            .map(|l| format!("{l}\n"))
            .collect()),
        Ok(o) => Err(format!(
            "mpirun -np {ranks} failed: {}",
            String::from_utf8_lossy(&o.stderr)
        )),
        Err(e) => Ok(format!(
            "bench ranks={ranks} skipped: cannot run mpirun ({e}); install openmpi-bin\n"
        )),
    }
}
