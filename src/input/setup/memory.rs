//! The memory guard (issue 25): before the scene is built, how much memory building it will
//! take, against what this process may have. A scene that will not fit is refused with the
//! numbers and the remedies, never an allocation abort or the kernel's kill.
//!
//! The estimate counts the lattice sites the geometry fills (without storing them) and gives
//! every particle the bonds of an interior one (a bound: surface particles have fewer), and the
//! pairs of its neighbour list with a pair law. Setup holds its temporaries beside the records:
//! the peak resident memory of `pdq run` with a frame and a checkpoint measured 1.88 times the
//! particle and bond records (980,154 PMB particles, 57.2 million bonds: 1,201 MiB against
//! 638 MiB, docs/performance.md), so the estimate is 2.0 times them. A deck that every worker
//! builds whole needs all of it in each MPI rank: ranks sharing a machine multiply it.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::input::deck::{DeckError, Scene};
use crate::input::geometry;
use crate::model::Model;

/// Peak resident memory over the particle and bond records, as measured (module doc).
const PEAK_OVER_RECORDS: f64 = 2.0;

/// What building the scene will take.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    pub particles: f64,
    /// Bonds, stored once: particles × interior bonds / 2.
    pub bonds: f64,
    /// Neighbour-list pairs (with a pair law), stored once.
    pub pairs: f64,
    /// Bytes of the particle, bond and pair records.
    pub records: f64,
    /// Bytes at the peak of setup, per worker process.
    pub peak: f64,
}

/// Counts the scene and estimates its memory for model `M`; `reach` is the pair law's cutoff
/// + skin (0 without one). `None` if the geometry is one the builder refuses (it says why).
pub fn estimate<M: Model>(scene: &Scene, reach: f64) -> Option<Estimate> {
    let lattice = &scene.lattice;
    let particles = geometry::count_particles(
        &scene.lattice,
        &scene.geometry_ops(),
        &scene.geometry_bars(),
    )?;
    let per_bond = if M::BONDED {
        neighbours(lattice, scene.horizon)
    } else {
        0.0
    };
    let per_pair = neighbours(lattice, reach);
    let (bonds, pairs) = (0.5 * particles * per_bond, 0.5 * particles * per_pair);
    let records = particles * Particles::<M>::bytes_per_particle() as f64
        + bonds * BondList::<M::Bond>::bytes_per_bond() as f64
        + pairs * 8.0;
    Some(Estimate {
        particles,
        bonds,
        pairs,
        records,
        peak: PEAK_OVER_RECORDS * records,
    })
}

/// Beyond this many spacings the sites within a radius are not counted one by one (that
/// takes (2·radius/step)³ tests: `pdq check` of a horizon of 10⁶ spacings never ended) but
/// taken from the ball's volume, within 0.2 % of the count there on sc, fcc and bcc.
const COUNTED_RADIUS: f64 = 40.0;

/// Lattice sites within `radius` of an interior site (bonds or pairs of one particle).
fn neighbours(lattice: &geometry::Lattice, radius: f64) -> f64 {
    if radius.is_nan() || radius <= COUNTED_RADIUS * lattice.spacing {
        return geometry::neighbours_within(lattice, radius) as f64;
    }
    let ball = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    ball / lattice.site_volume()
}

/// Bytes this process may still allocate, and where the figure comes from: the smaller of the
/// cgroup's limit less its usage and the kernel's MemAvailable. `None` if neither is readable.
pub fn available() -> Option<(f64, &'static str)> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let cgroup = read("/sys/fs/cgroup/memory.max")
        .and_then(|m| m.trim().parse::<f64>().ok())
        .map(|limit| {
            let used = read("/sys/fs/cgroup/memory.current")
                .and_then(|u| u.trim().parse::<f64>().ok())
                .unwrap_or(0.0);
            (limit - used, "the cgroup's memory.max less memory.current")
        });
    let meminfo = read("/proc/meminfo").and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some((kb * 1024.0, "MemAvailable in /proc/meminfo"))
    });
    match (cgroup, meminfo) {
        (Some(c), Some(m)) => Some(if c.0 < m.0 { c } else { m }),
        (c, m) => c.or(m),
    }
}

/// Worker processes of this run on this machine: MPI ranks here (as Open MPI and MPICH tell
/// them), else 1 (threads share one process).
fn processes_here() -> f64 {
    ["OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse::<f64>().ok())
        .unwrap_or(1.0)
        .max(1.0)
}

/// The estimate, or an error with the numbers and the remedies when the scene will not fit in
/// what the process may have.
pub fn guard<M: Model>(scene: &Scene, reach: f64) -> Result<Estimate, DeckError> {
    let Some(e) = estimate::<M>(scene, reach) else {
        // The builder reports what is wrong with the geometry.
        return Ok(Estimate::default());
    };
    let remedy = match scene.built_whole_by() {
        Some(what) => format!("; more MPI ranks do not help, as every rank of this deck builds the whole scene ({what} is not built per rank yet; docs/wall_method.md, setup per rank)"),
        None => ", or MPI ranks on more machines: under mpirun each rank builds only its procCube (docs/wall_method.md, setup per rank)".to_string(),
    };
    refuse_beyond(scene, e, 1.0, &remedy)
}

/// Peak resident memory of a rank that builds only its procCube (`parallel::part`), over its
/// share of the records, as measured (docs/performance.md, memory guard): 1.68 at one rank and
/// 1.91 at four, where the ghosts and the image of a frame's part are a larger share.
const PER_RANK_PEAK_OVER_RECORDS: f64 = 2.0;

/// [`guard`] for a run whose `ranks` ranks each build only their procCube: each needs about
/// its share of the records.
pub fn guard_per_rank<M: Model>(scene: &Scene, ranks: usize) -> Result<Estimate, DeckError> {
    let Some(mut e) = estimate::<M>(scene, 0.0) else {
        return Ok(Estimate::default());
    };
    e.peak = PER_RANK_PEAK_OVER_RECORDS * e.records / ranks.max(1) as f64;
    let remedy = ", or more MPI ranks on more machines (each rank builds only its procCube)";
    refuse_beyond(scene, e, ranks as f64, remedy)
}

/// `e` if its peak, times the ranks on this machine, fits what this process may have; else the
/// error with the numbers and the remedies.
fn refuse_beyond(
    scene: &Scene,
    e: Estimate,
    ranks: f64,
    remedy: &str,
) -> Result<Estimate, DeckError> {
    let Some((free, source)) = available() else {
        return Ok(e);
    };
    let here = processes_here();
    if e.peak * here <= free {
        return Ok(e);
    }
    let gib = |b: f64| b / (1u64 << 30) as f64;
    let on_machine = if here > 1.0 {
        format!(" × {here} ranks on this machine")
    } else {
        String::new()
    };
    let share = if ranks > 1.0 {
        format!(" for each of {ranks} ranks")
    } else {
        String::new()
    };
    Err(scene.error(
        None,
        format!(
            "the scene will not fit in memory: {:.3e} particles and about {:.3e} bonds{} need about {:.1} GiB{share} to set up ({:.1} GiB of particle and bond records in all, × the measured peak of setup over them){on_machine}, and this process may have {:.1} GiB ({source}). Nothing was allocated. Remedies: a coarser lattice (twice the spacing: 1/8 of the particles and bonds), a smaller horizon (m = 3 → 2: about 1/3.4 of the bonds), fewer or smaller [[geometry]] entries, or a machine with more memory{remedy}",
            e.particles,
            e.bonds,
            if e.pairs > 0.0 { format!(" and {:.3e} neighbour pairs", e.pairs) } else { String::new() },
            gib(e.peak),
            gib(e.records),
            gib(free)
        ),
    ))
}
