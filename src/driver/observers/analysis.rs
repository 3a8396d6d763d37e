//! In-situ analysis (`[[analysis]]`, issue 24): every `every` steps, voids or cracks on voxels
//! of the current positions, labelled over the procCubes without gathering the grid
//! (`voids/`), followed from one analysis to the next; the root writes the tables
//! (`output/analysis.rs`).

use super::{Observer, Watch};
use crate::driver::step_loop::Plan;
use crate::engine::simulation::Exchange;
use crate::engine::timing::Phase;
use crate::input::deck::AnalysisKind;
use crate::model::Model;
use crate::output::analysis::{AnalysisFiles, Found, Looking};
use crate::output::pictures::{largest_clusters, LargestOf};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use crate::voids::largest::{largest, SHOWN};
use crate::voids::tracking::Tracker;
use crate::voids::{deposit, label, Connectivity, Extent, Region, Scheme, VoxelGrid};
use std::ops::ControlFlow;
use std::time::Instant;

/// One `[[analysis]]` as the run does it.
#[derive(Clone, Debug)]
pub(crate) struct AnalysisPlan {
    pub name: String,
    pub kind: AnalysisKind,
    pub every: u64,
    pub voxel: f64,
    pub connectivity: Connectivity,
    pub scheme: Scheme,
    /// A lattice site (the first particle's reference position): voxels are centred on its
    /// lattice, the same at every analysis.
    pub anchor: [f64; 3],
}

pub(super) struct Analysis<'a> {
    plan: &'a Plan,
    spec: &'a AnalysisPlan,
    tracker: Tracker,
    /// The root's tables (`None` elsewhere).
    files: Option<AnalysisFiles>,
}

impl<'a> Analysis<'a> {
    /// Opens the tables on the root (reopens them after a restart); an error goes to
    /// `error`, for the workers to agree on.
    pub fn open(
        plan: &'a Plan,
        spec: &'a AnalysisPlan,
        root: bool,
        error: &mut Option<String>,
    ) -> Self {
        let resume = (plan.first_step > 0).then_some(plan.first_step);
        let mut files = None;
        let mut used = 0;
        if root && error.is_none() {
            let looking = match spec.kind {
                AnalysisKind::Voids => Looking::Voids,
                AnalysisKind::Cracks => Looking::Cracks,
            };
            match AnalysisFiles::open(&plan.dir, &spec.name, looking, resume) {
                Ok((f, u)) => (files, used) = (Some(f), u),
                Err(e) => *error = Some(plan.io(e)),
            }
        }
        Analysis {
            plan,
            spec,
            // Ids after a restart continue past those used before (the root's count; the
            // others never hand out ids).
            tracker: Tracker::new(used + 1, resume.is_some()),
            files,
        }
    }

    /// The points marked on the voxels, with their values: owned particles' positions
    /// (voids), or the midpoints of broken bonds with their opening (cracks).
    fn points<M: Model>(&self, cube: &mut Cube<M>) -> (Vec<[f64; 3]>, Option<Vec<[f64; 2]>>) {
        let p = &cube.sim.particles;
        match self.spec.kind {
            AnalysisKind::Voids => ((0..p.n_owned).map(|i| p.pos(i)).collect(), None),
            AnalysisKind::Cracks => {
                // Ghosts at the current positions (they are refreshed before each force
                // evaluation anyway, so this changes nothing that follows).
                Exchange::forward(&mut cube.wall, &mut cube.sim.particles);
                let (p, b) = (&cube.sim.particles, &cube.sim.bonds);
                let mut mids = Vec::new();
                let mut values = Vec::new();
                for (i, j, k) in b.iter() {
                    if !b.broken[k] {
                        continue;
                    }
                    let (yi, yj) = (p.pos(i), p.pos(j));
                    let (xi, xj) = (p.x0[i], p.x0[j]);
                    let length = |a: [f64; 3], b: [f64; 3]| {
                        (0..3).map(|d| (b[d] - a[d]).powi(2)).sum::<f64>().sqrt()
                    };
                    mids.push([0, 1, 2].map(|d| 0.5 * (yi[d] + yj[d])));
                    values.push([length(yi, yj) - length(xi, xj), 1.0]);
                }
                (mids, Some(values))
            }
        }
    }

    /// The voxel grid over every particle's current position (a reduction) and the cells'
    /// box, on the run's voxel lattice.
    fn grid<M: Model>(&self, cube: &mut Cube<M>) -> Result<VoxelGrid, String> {
        let p = &cube.sim.particles;
        let mut bounds = [f64::NEG_INFINITY; 6];
        for i in 0..p.n_owned {
            let x = p.pos(i);
            for a in 0..3 {
                bounds[a] = bounds[a].max(-x[a]);
                bounds[a + 3] = bounds[a + 3].max(x[a]);
            }
        }
        cube.team().reduce(&mut bounds, Reduce::Max);
        let d = &cube.layout.domain;
        let extent = [0, 1, 2].map(|a| {
            if d.periodic[a] {
                Extent::Periodic {
                    origin: d.grid.origin[a],
                    period: d.period[a],
                }
            } else {
                let top = d.grid.origin[a] + d.grid.dims[a] as f64 * d.grid.size[a];
                Extent::Bounded {
                    lo: (-bounds[a]).min(d.grid.origin[a]),
                    hi: bounds[a + 3].max(top),
                }
            }
        });
        // Crack voxels are shifted a quarter voxel off the lattice: bond midpoints lie on
        // lattice sites or halfway between them, so none falls on a voxel face, where
        // round-off (a different layout) could tip it either way.
        let shift = match self.spec.kind {
            AnalysisKind::Voids => 0.0,
            AnalysisKind::Cracks => 0.25 * self.spec.voxel,
        };
        let mut anchor = self.spec.anchor.map(|x| x + shift);
        let mut size = [self.spec.voxel; 3];
        // In a deforming box the voxels stretch with it: the same voxels hold the same
        // matter, so tracking matches them by place.
        if let Some(d) = &cube.deform {
            anchor = d.map(anchor);
            size = [0, 1, 2].map(|a| size[a] * d.stretch()[a]);
        }
        VoxelGrid::spanning(anchor, extent, size)
            .map_err(|e| format!("[[analysis]] '{}': {e}", self.spec.name))
    }

    /// This procCube's region of `grid`: the voxels whose centres lie in its cells.
    fn region<M: Model>(&self, cube: &Cube<M>, grid: VoxelGrid) -> Result<Region, String> {
        let l = &cube.layout;
        let g = &l.domain.grid;
        let walls = [0, 1, 2].map(|a| {
            (1..l.procs[a])
                .map(|k| g.origin[a] + l.cuts[a][k] as f64 * g.size[a])
                .collect()
        });
        Region::new(grid, walls, cube.plan.rank)
            .map_err(|e| format!("[[analysis]] '{}': {e}", self.spec.name))
    }
}

impl<M: Model> Observer<M> for Analysis<'_> {
    fn due(&self, step: u64, last: bool) -> bool {
        let again = self.plan.first_step > 0 && step == self.plan.first_step;
        (step.is_multiple_of(self.spec.every) || last) && !again
    }

    fn observe(
        &mut self,
        cube: &mut Cube<M>,
        watch: &mut Watch<M>,
    ) -> Result<ControlFlow<()>, String> {
        let t = Instant::now();
        let (points, values) = self.points(cube);
        let grid = self.grid(cube)?;
        let region = self.region(cube, grid)?;
        let mut team = cube.team();
        let (mut marked, sums) = deposit(&mut team, &region, &points, values.as_deref());
        if self.spec.kind == AnalysisKind::Voids {
            // Voids are the empty voxels.
            marked.iter_mut().for_each(|m| *m = !*m);
        }
        let s = self.spec;
        let found = label(&mut team, &region, &marked, &sums, s.connectivity, s.scheme);
        let (events, ids) = self.tracker.follow(&mut team, &region, &found);
        if watch.last {
            let shown = largest(&mut team, &region, &found, SHOWN);
            if let (Some(voxels), Some(_)) = (shown, &self.files) {
                let of = LargestOf {
                    name: &self.spec.name,
                    title: &self.plan.title,
                    what: self.spec.kind.name(),
                    step: watch.step,
                    total: found.clusters.len(),
                };
                if let Err(e) = largest_clusters(&self.plan.dir, &of, &region.grid, &voxels) {
                    watch.error = Some(e);
                }
            }
        }
        if let Some(files) = &mut self.files {
            let row = Found {
                step: watch.step,
                time: cube.sim.time,
                grid: &region.grid,
                clusters: &found.clusters,
                ids: &ids,
                outside: found.outside,
                rounds: found.rounds,
                events: &events,
            };
            if let Err(e) = files.write(&row) {
                watch.error = Some(self.plan.io(e));
            }
        }
        cube.sim.timing.lap(Phase::Analysis, t);
        Ok(ControlFlow::Continue(()))
    }
}
