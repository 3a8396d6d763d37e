//! `pdq bench --ranks`: the standard scene under `mpirun`, one procCube per rank.

use super::BenchOptions;
#[cfg(feature = "mpi")]
use super::{bench_name, bytes_of, line};
#[cfg(feature = "mpi")]
use crate::input::{deck, setup};
#[cfg(feature = "mpi")]
use crate::model::{Model, ModelVisitor};
#[cfg(feature = "mpi")]
use crate::parallel::{self, decomposition::Procs};
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

/// Runs this program's bench under `mpirun -np ranks` and returns its line.
pub(super) fn ranks_line(opts: &BenchOptions, ranks: usize) -> Result<String, String> {
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
