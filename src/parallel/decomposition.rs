//! The wall-method decomposition (thesis chapter 3): procCubes cut from the cell grid, the
//! five staged ghost messages, and each procCube's particles, ghosts and bonds.
//!
//! ProcCube faces lie on cell faces, so every cell has one owner. A cell pairs with itself
//! and with the 13 cells of [`HALF_SHELL`], all of which lie south, down, up-south or west of
//! it; the five messages (east, west, north, up, down — nothing goes south) bring exactly those
//! cells to every procCube. Each pair of particles within the horizon is therefore evaluated
//! once, by the owner of the cell it is found from, and a bond across a face lives (with its
//! history) on that side. The plan is computed from cells alone, identically on every worker,
//! so sender and receiver agree on every message without negotiating.

use crate::engine::bonds::{BondList, Families};
pub use crate::engine::cells::Domain;
use crate::engine::cells::HALF_SHELL;
pub use crate::input::procs::{Procs, Walls};
use std::ops::Range;

/// The five ghost messages in order, as (axis, direction): east, west, north, up, down.
pub const STAGES: [(usize, i64); 5] = [(0, 1), (0, -1), (1, 1), (2, 1), (2, -1)];
pub const STAGE_NAMES: [&str; 5] = ["east", "west", "north", "up", "down"];
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// ProcCubes as ranges of cell layers along each axis.
#[derive(Clone, Debug)]
pub struct Layout {
    pub procs: [usize; 3],
    /// `cuts[a][k]..cuts[a][k + 1]` are the cell layers of the k-th procCube along axis a.
    pub cuts: [Vec<usize>; 3],
    pub walls: Walls,
    /// The cells, possibly coarser than the scene's along an axis so that procCubes split it
    /// evenly (any cells of side ≥ the horizon find the same bonds).
    pub domain: Domain,
    /// Store indices of the particles of cell c: `order[start[c]..start[c + 1]]`, increasing.
    pub start: Vec<u32>,
    pub order: Vec<u32>,
}

impl Layout {
    /// Particles in each cell.
    pub fn cell_count(&self) -> Vec<u32> {
        self.start.windows(2).map(|w| w[1] - w[0]).collect()
    }

    pub fn cubes(&self) -> usize {
        self.procs.iter().product()
    }

    pub(crate) fn coords(&self, k: usize) -> [usize; 3] {
        let p = self.procs;
        [k % p[0], (k / p[0]) % p[1], k / (p[0] * p[1])]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.procs[1] + c[1]) * self.procs[0] + c[0]
    }

    /// Cell box `[lo, hi)` of procCube `k`.
    pub fn cube_box(&self, k: usize) -> ([i64; 3], [i64; 3]) {
        let c = self.coords(k);
        let lo = [0, 1, 2].map(|a| self.cuts[a][c[a]] as i64);
        let hi = [0, 1, 2].map(|a| self.cuts[a][c[a] + 1] as i64);
        (lo, hi)
    }

    /// The procCube next to `k` along `axis` in direction `dir`, and the periods a cell
    /// coordinate gains on the way (wrapping around a periodic axis).
    pub fn neighbour(
        &self,
        k: usize,
        axis: usize,
        dir: i64,
        periodic: bool,
    ) -> Option<(usize, i64)> {
        let mut c = self.coords(k);
        let p = self.procs[axis] as i64;
        let v = c[axis] as i64 + dir;
        let wrap = if (0..p).contains(&v) {
            0
        } else if periodic {
            -dir
        } else {
            return None;
        };
        c[axis] = v.rem_euclid(p) as usize;
        Some((self.index(c), wrap))
    }

    pub fn describe(&self) -> String {
        format!(
            "{}x{}x{} procCubes ({} walls)",
            self.procs[0],
            self.procs[1],
            self.procs[2],
            self.walls.name()
        )
    }
}

/// A cell a procCube holds: its own, or a ghost copy of a neighbour's (maybe a periodic image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldCell {
    /// Unwrapped cell coordinates in the holder's frame (-1 or n for ghosts past an edge).
    pub at: [i64; 3],
    /// The cell in the grid.
    pub cell: usize,
    /// Periods added along each axis to reach `at` from `cell`.
    pub wraps: [i64; 3],
}

/// One of the five messages, seen from one procCube, in cells.
#[derive(Clone, Debug, Default)]
pub struct CellStage {
    pub to: Option<usize>,
    /// Held cells sent, in order.
    pub send: Vec<usize>,
    pub from: Option<usize>,
    /// Held cells received (appended in order).
    pub recv: Range<usize>,
    /// Periods the received cells gain.
    pub wraps: [i64; 3],
}

/// The cells one procCube holds and the messages it sends and receives.
#[derive(Clone, Debug)]
pub struct CellPlan {
    pub lo: [i64; 3],
    pub hi: [i64; 3],
    /// Owned cells first (in the grid's order), then ghosts in order of arrival.
    pub held: Vec<HeldCell>,
    pub owned_cells: usize,
    pub stages: Vec<CellStage>,
}

impl CellPlan {
    /// Whether an owned cell pairs with a cell at `at` through the half shell.
    fn uses(&self, at: [i64; 3]) -> bool {
        HALF_SHELL.iter().any(|h| {
            (0..3).all(|a| {
                let v = at[a] - h[a] as i64;
                v >= self.lo[a] && v < self.hi[a]
            })
        })
    }
}

/// The cell plans of every procCube of `layout`.
pub fn cell_plans(layout: &Layout) -> Vec<CellPlan> {
    let domain = &layout.domain;
    let g = &domain.grid;
    let n = layout.cubes();
    let mut plans: Vec<CellPlan> = (0..n)
        .map(|k| {
            let (lo, hi) = layout.cube_box(k);
            let mut held = Vec::new();
            // The grid's own order (y slowest), which keeps bond partners close in memory.
            for y in lo[1]..hi[1] {
                for z in lo[2]..hi[2] {
                    for x in lo[0]..hi[0] {
                        held.push(HeldCell {
                            at: [x, y, z],
                            cell: g.index([x as usize, y as usize, z as usize]),
                            wraps: [0; 3],
                        });
                    }
                }
            }
            CellPlan {
                lo,
                hi,
                owned_cells: held.len(),
                held,
                stages: vec![CellStage::default(); STAGES.len()],
            }
        })
        .collect();

    for (s, &(axis, dir)) in STAGES.iter().enumerate() {
        // Every procCube's wall as it stands before this stage's messages arrive.
        let walls: Vec<Vec<usize>> = plans
            .iter()
            .map(|p| {
                let layer = if dir > 0 { p.hi[axis] - 1 } else { p.lo[axis] };
                (0..p.held.len())
                    .filter(|&i| p.held[i].at[axis] == layer)
                    .collect()
            })
            .collect();
        for (k, wall) in walls.into_iter().enumerate() {
            let Some((r, wrap)) = layout.neighbour(k, axis, dir, domain.periodic[axis]) else {
                continue;
            };
            let cells: Vec<HeldCell> = wall
                .iter()
                .map(|&i| {
                    let mut h = plans[k].held[i];
                    h.at[axis] += wrap * g.dims[axis] as i64;
                    h.wraps[axis] += wrap;
                    h
                })
                .collect();
            plans[k].stages[s].to = Some(r);
            plans[k].stages[s].send = wall;
            let rp = &mut plans[r];
            let start = rp.held.len();
            rp.held.extend(cells);
            let st = &mut rp.stages[s];
            st.from = Some(k);
            st.recv = start..rp.held.len();
            st.wraps[axis] = wrap;
        }
    }

    if layout.walls == Walls::Trimmed {
        trim(&mut plans);
    }
    plans
}

/// Drops every ghost cell that its holder neither pairs with nor passes on to someone who needs
/// it. Works backwards from the last message, so "passes on" is known when it is asked.
fn trim(plans: &mut [CellPlan]) {
    let mut keep: Vec<Vec<bool>> = plans
        .iter()
        .map(|p| (0..p.held.len()).map(|i| i < p.owned_cells).collect())
        .collect();
    let mut forwarded: Vec<Vec<bool>> = plans.iter().map(|p| vec![false; p.held.len()]).collect();
    for s in (0..STAGES.len()).rev() {
        for r in 0..plans.len() {
            let Some(k) = plans[r].stages[s].from else {
                continue;
            };
            let recv = plans[r].stages[s].recv.clone();
            for (pos, idx) in recv.enumerate() {
                let needed = plans[r].uses(plans[r].held[idx].at) || forwarded[r][idx];
                keep[r][idx] = needed;
                if needed {
                    let src = plans[k].stages[s].send[pos];
                    forwarded[k][src] = true;
                }
            }
        }
    }
    // Renumber held cells without the dropped ones; a receiver's kept cells are exactly the
    // sender's kept sends, in the same order.
    let new_index: Vec<Vec<Option<usize>>> = keep
        .iter()
        .map(|kp| {
            let mut next = 0;
            kp.iter()
                .map(|&k| {
                    k.then(|| {
                        next += 1;
                        next - 1
                    })
                })
                .collect()
        })
        .collect();
    let old: Vec<CellPlan> = plans.to_vec();
    for (r, p) in plans.iter_mut().enumerate() {
        p.held = old[r]
            .held
            .iter()
            .zip(&keep[r])
            .filter(|(_, &k)| k)
            .map(|(h, _)| *h)
            .collect();
        for s in 0..STAGES.len() {
            let st = &old[r].stages[s];
            if let Some(to) = st.to {
                let rs = &old[to].stages[s].recv;
                p.stages[s].send = st
                    .send
                    .iter()
                    .zip(rs.clone())
                    .filter(|&(_, ri)| keep[to][ri])
                    .map(|(&i, _)| {
                        new_index[r][i].expect("a kept ghost was sent from a dropped one")
                    })
                    .collect();
            }
            if st.from.is_some() {
                let kept: Vec<usize> = st.recv.clone().filter_map(|i| new_index[r][i]).collect();
                p.stages[s].recv = match (kept.first(), kept.last()) {
                    (Some(&a), Some(&b)) => a..b + 1,
                    _ => {
                        let at = old[r].held[..st.recv.start]
                            .iter()
                            .zip(&keep[r])
                            .filter(|(_, &k)| k)
                            .count();
                        at..at
                    }
                };
            }
        }
    }
}

/// One message of the particle-level plan, seen from one procCube.
#[derive(Clone, Debug, Default)]
pub struct Stage {
    pub to: Option<usize>,
    /// Local indices (owned or ghost) sent, in order.
    pub send: Vec<u32>,
    pub from: Option<usize>,
    /// Local indices where the received particles go.
    pub recv: Range<usize>,
    /// Added to received positions (a periodic image), zero otherwise.
    pub shift: [f64; 3],
}

/// One procCube's particles and messages.
#[derive(Clone, Debug)]
pub struct CubePlan {
    pub rank: usize,
    pub n_owned: usize,
    /// Global store index of every local particle: owned first, then ghosts.
    pub global: Vec<u32>,
    /// Offset added to each local particle's reference position (periodic images).
    pub shift: Vec<[f64; 3]>,
    pub cells: CellPlan,
    /// Local particles of each held cell.
    pub cell_range: Vec<Range<usize>>,
    /// For each owned cell, the held cells of its 13 half-shell neighbours (`u32::MAX`: none
    /// held there): where its bonds and non-bonded pairs are found.
    pub half_shell: Vec<[u32; 13]>,
    pub stages: Vec<Stage>,
}

/// The particle-level plan of procCube `rank`, from the layout's binning of the scene.
pub fn cube_plan(layout: &Layout, plans: &[CellPlan], rank: usize) -> CubePlan {
    let (cell_start, order) = (&layout.start, &layout.order);
    let plan = &plans[rank];
    let counts: Vec<u32> = plan
        .held
        .iter()
        .map(|h| cell_start[h.cell + 1] - cell_start[h.cell])
        .collect();
    let global = plan
        .held
        .iter()
        .flat_map(|h| order[cell_start[h.cell] as usize..cell_start[h.cell + 1] as usize].iter())
        .copied()
        .collect();
    particle_plan(rank, plan, &counts, global, layout.domain.period)
}

/// The particle-level plan of a procCube whose held cells hold `counts` particles each, with
/// `global` the ids of its particles in store order (held cell by held cell). Particles of a
/// cell are contiguous, so every message is a list of cell runs.
pub fn particle_plan(
    rank: usize,
    plan: &CellPlan,
    counts: &[u32],
    global: Vec<u32>,
    period: [f64; 3],
) -> CubePlan {
    let mut next = 0;
    let cell_range: Vec<Range<usize>> = counts
        .iter()
        .map(|&n| {
            next += n as usize;
            next - n as usize..next
        })
        .collect();
    debug_assert_eq!(
        next,
        global.len(),
        "cell counts disagree with the particles"
    );
    let mut shift = Vec::with_capacity(global.len());
    for (h, r) in plan.held.iter().zip(&cell_range) {
        let s = [0, 1, 2].map(|a| h.wraps[a] as f64 * period[a]);
        shift.extend(std::iter::repeat_n(s, r.len()));
    }
    let n_owned = cell_range
        .get(plan.owned_cells.wrapping_sub(1))
        .map_or(0, |r| r.end);
    let stages = plan
        .stages
        .iter()
        .map(|st| {
            let send = st
                .send
                .iter()
                .flat_map(|&i| cell_range[i].clone().map(|j| j as u32))
                .collect();
            let recv = if st.recv.is_empty() {
                let at = cell_range
                    .get(st.recv.start)
                    .map_or(global.len(), |r| r.start);
                at..at
            } else {
                cell_range[st.recv.start].start..cell_range[st.recv.end - 1].end
            };
            Stage {
                to: st.to,
                send,
                from: st.from,
                recv,
                shift: [0, 1, 2].map(|a| st.wraps[a] as f64 * period[a]),
            }
        })
        .collect();
    CubePlan {
        rank,
        n_owned,
        global,
        shift,
        half_shell: half_shell(plan),
        cells: plan.clone(),
        cell_range,
        stages,
    }
}

impl CellPlan {
    /// The five messages at the level of cells: held cell indices sent, held cells received.
    /// Forwarding per-cell values along them gives every procCube its ghost cells' values.
    pub fn cell_stages(&self) -> Vec<Stage> {
        self.stages
            .iter()
            .map(|st| Stage {
                to: st.to,
                send: st.send.iter().map(|&c| c as u32).collect(),
                from: st.from,
                recv: st.recv.clone(),
                shift: [0.0; 3],
            })
            .collect()
    }

    /// Index among the held cells of the owned cell at grid coordinates `at`.
    pub fn owned_index(&self, at: [usize; 3]) -> usize {
        let (lo, hi) = (self.lo, self.hi);
        let [nx, _, nz] = [0, 1, 2].map(|a| (hi[a] - lo[a]) as usize);
        debug_assert!(
            (0..3).all(|a| at[a] as i64 >= lo[a] && (at[a] as i64) < hi[a]),
            "cell {at:?} is not owned ({lo:?}..{hi:?})"
        );
        let [x, y, z] = [0, 1, 2].map(|a| at[a] - lo[a] as usize);
        // Owned cells are held y slowest, then z, then x (see `cell_plans`).
        (y * nz + z) * nx + x
    }
}

/// The held cells of each owned cell's 13 half-shell neighbours (`u32::MAX`: not held).
fn half_shell(c: &CellPlan) -> Vec<[u32; 13]> {
    // The owned box grown by one cell each way holds every cell the half shell reaches.
    let base = [0, 1, 2].map(|a| c.lo[a] - 1);
    let ext = [0, 1, 2].map(|a| (c.hi[a] - c.lo[a] + 2) as usize);
    let slot = |at: [i64; 3]| -> Option<usize> {
        let mut i = 0;
        for a in (0..3).rev() {
            let v = at[a] - base[a];
            if v < 0 || v >= ext[a] as i64 {
                return None;
            }
            i = i * ext[a] + v as usize;
        }
        Some(i)
    };
    let mut at_slot: Vec<u32> = vec![u32::MAX; ext.iter().product()];
    for (k, h) in c.held.iter().enumerate() {
        let s = slot(h.at).expect("a held cell lies outside the grown box");
        debug_assert!(at_slot[s] == u32::MAX, "two held cells at {:?}", h.at);
        at_slot[s] = k as u32;
    }
    (0..c.owned_cells)
        .map(|k| {
            let at = c.held[k].at;
            HALF_SHELL.map(|o| {
                let t = [0, 1, 2].map(|a| at[a] + o[a] as i64);
                slot(t).map_or(u32::MAX, |s| at_slot[s])
            })
        })
        .collect()
}

impl CubePlan {
    /// The procCube's bonds: each owned cell with itself and its half shell, owned or ghost.
    /// `x0` holds the local reference positions (ghost images already shifted).
    pub fn find_bonds<H: crate::model::attributes::Attributes>(
        &self,
        x0: &[[f64; 3]],
        horizon: f64,
        dx: f64,
        partial: bool,
    ) -> BondList<H> {
        let c = &self.cells;
        let h2 = horizon * horizon * (1.0 + 2e-10);
        let mut families = Families::new(x0.len(), horizon, dx, partial);
        let mut found: Vec<(u32, f64)> = Vec::new();
        for k in 0..c.owned_cells {
            let neighbours: Vec<Range<usize>> = self.half_shell[k]
                .iter()
                .filter(|&&q| q != u32::MAX)
                .map(|&q| self.cell_range[q as usize].clone())
                .collect();
            for i in self.cell_range[k].clone() {
                let xi = x0[i];
                found.clear();
                let mut visit = |j: usize| {
                    let xj = x0[j];
                    let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if r2 <= h2 {
                        found.push((j as u32, r2.sqrt()));
                    }
                };
                for j in i + 1..self.cell_range[k].end {
                    visit(j);
                }
                for r in &neighbours {
                    for j in r.clone() {
                        visit(j);
                    }
                }
                families.close(i, &mut found);
            }
        }
        families.finish()
    }

    /// Ghost particles this procCube holds.
    pub fn ghosts(&self) -> usize {
        self.global.len() - self.n_owned
    }

    /// Particles sent per forward exchange.
    pub fn particles_sent(&self) -> usize {
        self.stages.iter().map(|s| s.send.len()).sum()
    }
}
