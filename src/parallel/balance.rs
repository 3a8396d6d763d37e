//! How the wall method cuts the cells into procCubes: by the bond work of each layer of cells
//! (the candidate pairs its cells scan), from the particles per cell alone, so that a layout can
//! be chosen before any procCube holds a particle.

use super::decomposition::{cell_plans, CellPlan, Layout, Walls, AXES};
use crate::engine::cells::{Domain, HALF_SHELL};

/// The particles of each cell of a grid: where each cell's run starts in the store, and the
/// store order (see [`Layout::with_cells`]).
/// [`Cells`] of a store of particles at `x0`.
fn binned(x0: &[[f64; 3]]) -> impl Fn(&Domain) -> (Vec<u32>, Vec<u32>) + '_ {
    |d: &Domain| {
        let (_, start, order) = d.grid.bin(x0);
        (start, order)
    }
}

pub type Cells<'a> = dyn Fn(&Domain) -> (Vec<u32>, Vec<u32>) + 'a;

/// Bond work of each layer of cells along each axis: what a procCube taking those layers
/// evaluates (the pairs its cells scan), so that cuts balance work rather than particles.
fn layer_work(domain: &Domain, cell_count: &[u32]) -> [Vec<u64>; 3] {
    let d = domain.grid.dims;
    let mut c = [vec![0u64; d[0]], vec![0u64; d[1]], vec![0u64; d[2]]];
    for z in 0..d[2] {
        for y in 0..d[1] {
            for x in 0..d[0] {
                let w = cell_work(domain, cell_count, [x as i64, y as i64, z as i64]) as u64;
                c[0][x] += w;
                c[1][y] += w;
                c[2][z] += w;
            }
        }
    }
    c
}

/// Cuts `counts` into `parts` runs of at least one layer with sums as equal as possible.
fn balanced_cuts(counts: &[u64], parts: usize) -> Vec<usize> {
    let n = counts.len();
    let total: u64 = counts.iter().sum();
    let mut cuts = vec![0];
    let mut prefix = 0u64;
    let mut layer = 0;
    for k in 1..parts {
        let target = (total as f64) * k as f64 / parts as f64;
        let min = cuts[k - 1] + 1;
        let max = n - (parts - k);
        while layer < n && (prefix as f64) + (counts[layer] as f64) / 2.0 < target {
            prefix += counts[layer];
            layer += 1;
        }
        let cut = layer.clamp(min, max);
        while layer < cut {
            prefix += counts[layer];
            layer += 1;
        }
        while layer > cut {
            layer -= 1;
            prefix -= counts[layer];
        }
        cuts.push(cut);
    }
    cuts.push(n);
    cuts
}

impl Layout {
    /// `procs` procCubes cut from the domain's cells, balanced by bond work along each axis.
    /// `cell_count` is the number of particles in each cell of the grid.
    pub fn new(
        procs: [usize; 3],
        base: &Domain,
        x0: &[[f64; 3]],
        walls: Walls,
    ) -> Result<Layout, String> {
        Layout::with_cells(procs, base, walls, &binned(x0))
    }

    /// [`Layout::new`] with the particles of each cell from `cells`: the start of each cell's
    /// run in the store and the store order (empty when only the counts are known, for a
    /// procCube that fills its cells itself).
    pub fn with_cells(
        procs: [usize; 3],
        base: &Domain,
        walls: Walls,
        cells: &Cells<'_>,
    ) -> Result<Layout, String> {
        let domain = base.for_procs(procs);
        let g = &domain.grid;
        for a in 0..3 {
            if procs[a] == 0 {
                return Err(format!(
                    "procs = {procs:?}: every axis needs at least one procCube"
                ));
            }
            if procs[a] > g.dims[a] {
                return Err(format!(
                    "procs = {procs:?}: {} procCubes along {} but the scene is only {} cell{} wide there (its cells are {:.4e} wide, at least one horizon, so a procCube is never thinner than the horizon); use at most {} procCube{} along {}, or a smaller horizon",
                    procs[a],
                    AXES[a],
                    g.dims[a],
                    if g.dims[a] == 1 { "" } else { "s" },
                    g.size[a],
                    g.dims[a],
                    if g.dims[a] == 1 { "" } else { "s" },
                    AXES[a]
                ));
            }
        }
        let (start, order) = cells(&domain);
        let cell_count: Vec<u32> = start.windows(2).map(|w| w[1] - w[0]).collect();
        let counts = layer_work(&domain, &cell_count);
        let cuts = [0, 1, 2].map(|a| balanced_cuts(&counts[a], procs[a]));
        Ok(Layout {
            procs,
            cuts,
            walls,
            domain,
            start,
            order,
        })
    }

    /// The layout of `workers` procCubes that keeps the busiest procCube least loaded (owned
    /// particles plus a share for its ghosts).
    pub fn auto(
        workers: usize,
        domain: &Domain,
        x0: &[[f64; 3]],
        walls: Walls,
    ) -> Result<Layout, String> {
        Layout::auto_with_cells(workers, domain, walls, &binned(x0))
    }

    /// [`Layout::auto`] with the particles of each cell from `cells` (see [`Layout::with_cells`]).
    pub fn auto_with_cells(
        workers: usize,
        domain: &Domain,
        walls: Walls,
        cells: &Cells<'_>,
    ) -> Result<Layout, String> {
        let mut best: Option<(f64, Layout)> = None;
        for px in 1..=workers {
            for py in 1..=workers / px {
                if !workers.is_multiple_of(px * py) {
                    continue;
                }
                let pz = workers / (px * py);
                if px * py * pz != workers {
                    continue;
                }
                let Ok(layout) = Layout::with_cells([px, py, pz], domain, walls, cells) else {
                    continue;
                };
                let plans = cell_plans(&layout);
                let cell_count = layout.cell_count();
                let cost = plans
                    .iter()
                    .map(|p| {
                        let ghosts: u64 = p.held[p.owned_cells..]
                            .iter()
                            .map(|h| cell_count[h.cell] as u64)
                            .sum();
                        // Bond work grows with the candidate pairs a procCube's cells scan;
                        // a ghost costs packing and unpacking twice a step but no bond work.
                        pair_work(&layout.domain, p, &cell_count) + 5.0 * ghosts as f64
                    })
                    .fold(0.0, f64::max);
                if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                    best = Some((cost, layout));
                }
            }
        }
        best.map(|(_, l)| l).ok_or_else(|| {
            format!(
                "no layout of {workers} procCubes fits a scene {:?} cells wide (cells are at least one horizon); use fewer threads or ranks",
                domain.grid.dims
            )
        })
    }
}

/// Candidate pairs the cell at `at` scans: with itself and its half shell.
fn cell_work(domain: &Domain, cell_count: &[u32], at: [i64; 3]) -> f64 {
    let g = &domain.grid;
    let count_at = |at: [i64; 3]| -> f64 {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let n = g.dims[a] as i64;
            if domain.periodic[a] {
                c[a] = at[a].rem_euclid(n) as usize;
            } else if (0..n).contains(&at[a]) {
                c[a] = at[a] as usize;
            } else {
                return 0.0;
            }
        }
        cell_count[g.index(c)] as f64
    };
    let n = count_at(at);
    let around: f64 = HALF_SHELL
        .iter()
        .map(|o| {
            count_at([
                at[0] + o[0] as i64,
                at[1] + o[1] as i64,
                at[2] + o[2] as i64,
            ])
        })
        .sum();
    n * (0.5 * n + around)
}

/// Candidate pairs the owned cells of `p` scan.
fn pair_work(domain: &Domain, p: &CellPlan, cell_count: &[u32]) -> f64 {
    p.held[..p.owned_cells]
        .iter()
        .map(|h| cell_work(domain, cell_count, h.at))
        .sum()
}
