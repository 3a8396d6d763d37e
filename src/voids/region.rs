//! One procCube's share of a voxel grid ([`Region`]: the voxels whose centres lie in its
//! cells) and the deposit of points on the voxels of whichever procCube holds them.

use super::VoxelGrid;
use crate::parallel::comm::{Team, Transport};

/// One procCube's share of a voxel grid: the voxels `lo..hi` along each axis, those whose
/// centres lie in its cells.
#[derive(Clone, Debug)]
pub struct Region {
    pub grid: VoxelGrid,
    pub lo: [usize; 3],
    pub hi: [usize; 3],
    procs: [usize; 3],
    me: [usize; 3],
    /// The procCube coordinate that owns each voxel layer, along each axis.
    owner: [Vec<u32>; 3],
}

impl Region {
    /// The region of procCube `rank` when the faces between procCubes along axis a lie at
    /// `walls[a]` (increasing; one fewer than the procCubes along a). Procubes are numbered
    /// x fastest, as the layout numbers them.
    pub fn new(grid: VoxelGrid, walls: [Vec<f64>; 3], rank: usize) -> Result<Region, String> {
        let procs = [0, 1, 2].map(|a| walls[a].len() + 1);
        let me = [
            rank % procs[0],
            (rank / procs[0]) % procs[1],
            rank / (procs[0] * procs[1]),
        ];
        let mut owner: [Vec<u32>; 3] = Default::default();
        let (mut lo, mut hi) = ([0; 3], [0; 3]);
        for a in 0..3 {
            owner[a] = (0..grid.dims[a])
                .map(|i| {
                    let centre = grid.origin[a] + (i as f64 + 0.5) * grid.size[a];
                    walls[a].partition_point(|&w| w <= centre) as u32
                })
                .collect();
            let range = |k: usize| {
                (
                    owner[a].partition_point(|&o| (o as usize) < k),
                    owner[a].partition_point(|&o| (o as usize) <= k),
                )
            };
            (lo[a], hi[a]) = range(me[a]);
            // Checked for every procCube, so that all workers fail alike.
            if let Some(k) = (0..procs[a]).find(|&k| range(k).0 == range(k).1) {
                let width = |k: usize| match k {
                    0 => f64::INFINITY,
                    k if k + 1 == procs[a] => f64::INFINITY,
                    k => walls[a][k] - walls[a][k - 1],
                };
                let thinnest = (0..procs[a]).map(width).fold(f64::INFINITY, f64::min);
                return Err(format!(
                    "voxels of {:.4e} along {} leave the procCube {} along it without a voxel (the thinnest procCube is {thinnest:.4e} wide): use smaller voxels or fewer procCubes",
                    grid.size[a],
                    ["x", "y", "z"][a],
                    k + 1
                ));
            }
        }
        Ok(Region {
            grid,
            lo,
            hi,
            procs,
            me,
            owner,
        })
    }

    /// The whole grid on one procCube.
    pub fn whole(grid: VoxelGrid) -> Region {
        Region::new(grid, Default::default(), 0).expect("a grid has at least one voxel")
    }

    /// Voxels along each axis.
    pub fn dims(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.hi[a] - self.lo[a])
    }

    pub fn len(&self) -> usize {
        self.dims().iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The global coordinates of local voxel `v`.
    pub fn coords(&self, v: usize) -> [usize; 3] {
        let d = self.dims();
        [
            self.lo[0] + v % d[0],
            self.lo[1] + (v / d[0]) % d[1],
            self.lo[2] + v / (d[0] * d[1]),
        ]
    }

    /// The local index of the voxel at global coordinates `c`, if this region holds it.
    pub fn local(&self, c: [usize; 3]) -> Option<usize> {
        let d = self.dims();
        if (0..3).all(|a| (self.lo[a]..self.hi[a]).contains(&c[a])) {
            Some(((c[2] - self.lo[2]) * d[1] + c[1] - self.lo[1]) * d[0] + c[0] - self.lo[0])
        } else {
            None
        }
    }

    /// The rank of the procCube holding the voxel at global coordinates `c`.
    pub fn owner_of(&self, c: [usize; 3]) -> usize {
        let o = [0, 1, 2].map(|a| self.owner[a][c[a]] as usize);
        (o[2] * self.procs[1] + o[1]) * self.procs[0] + o[0]
    }

    /// The procCube next to this one along `axis` in direction `dir` (±1), wrapping along a
    /// periodic axis.
    pub(super) fn neighbour(&self, axis: usize, dir: i64) -> Option<usize> {
        let p = self.procs[axis] as i64;
        let v = self.me[axis] as i64 + dir;
        if !(0..p).contains(&v) && !self.grid.periodic[axis] {
            return None;
        }
        let mut c = self.me;
        c[axis] = v.rem_euclid(p) as usize;
        Some((c[2] * self.procs[1] + c[1]) * self.procs[0] + c[0])
    }
}

/// Marks on each procCube's region: the voxels holding at least one of `points` (owned by any
/// procCube), and with `values` (one pair per point) their sums per voxel. A point's voxel may
/// belong to another procCube; it is sent there. Every worker must pass `values` or none.
pub fn deposit<T: Transport>(
    team: &mut Team<T>,
    region: &Region,
    points: &[[f64; 3]],
    values: Option<&[[f64; 2]]>,
) -> (Vec<bool>, Vec<[f64; 2]>) {
    let with_values = values.is_some();
    let values = values.unwrap_or(&[]);
    assert!(
        !with_values || values.len() == points.len(),
        "one value pair per point"
    );
    let mut marked = vec![false; region.len()];
    let mut sums = vec![[0.0; 2]; if with_values { region.len() } else { 0 }];
    let mut out: Vec<Vec<u8>> = vec![Vec::new(); team.size()];
    for (k, p) in points.iter().enumerate() {
        let Some(c) = region.grid.coords_of(p) else {
            continue;
        };
        let to = region.owner_of(c);
        let record = &mut out[to];
        record.extend_from_slice(&(region.grid.index(c) as u64).to_ne_bytes());
        if with_values {
            for x in values[k] {
                record.extend_from_slice(&x.to_ne_bytes());
            }
        }
    }
    let size = if with_values { 24 } else { 8 };
    // In rank order, so that sums are the same run after run.
    for bytes in team.all_to_all(out) {
        for r in bytes.chunks_exact(size) {
            let g = u64::from_ne_bytes(r[..8].try_into().unwrap()) as usize;
            let d = region.grid.dims;
            let c = [g % d[0], (g / d[0]) % d[1], g / (d[0] * d[1])];
            let Some(v) = region.local(c) else { continue };
            marked[v] = true;
            if with_values {
                for (i, s) in sums[v].iter_mut().enumerate() {
                    *s += f64::from_ne_bytes(r[8 + 8 * i..16 + 8 * i].try_into().unwrap());
                }
            }
        }
    }
    (marked, sums)
}
