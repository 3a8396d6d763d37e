//! Voids on voxels (Hemani et al. 2014, `shared/seeds/004`): particle positions are put on a
//! grid of voxels, a voxel holding at least one particle is occupied, and the empty voxels are
//! joined into connected sets. The set that reaches the grid's border (the grid has one empty
//! voxel of margin all round) is the outside; every other set is a void inside the body.
//!
//! This is the labelling on one procCube's grid; the merge across procCubes, the tracking
//! between analyses and the in-situ observer build on it (issue 24).

mod union_find;

use union_find::UnionFind;

/// A grid of cubic voxels.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelGrid {
    /// The corner of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// The side of a voxel.
    pub size: f64,
    pub dims: [usize; 3],
}

/// Which empty voxels touch: across a face (6 neighbours, the default) or also across an edge
/// or a corner (26).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connectivity {
    Face,
    All,
}

/// One void: a connected set of empty voxels inside the body.
#[derive(Clone, Debug, PartialEq)]
pub struct Void {
    /// 1, 2, … in the order of each void's first voxel (x fastest, then y, then z).
    pub label: u32,
    pub voxels: u64,
    pub volume: f64,
    /// Area of the voxel faces between the void and occupied voxels. For a smooth surface
    /// this counts the staircase: a sphere's comes out about 3/2 of 4πR².
    pub surface: f64,
    pub centroid: [f64; 3],
    /// The radius of a sphere of the void's volume.
    pub equivalent_radius: f64,
}

/// Every voxel's label and the voids.
#[derive(Clone, Debug)]
pub struct VoidMap {
    pub grid: VoxelGrid,
    /// Per voxel (x fastest): [`OCCUPIED`], [`OUTSIDE`], or the label of its void.
    pub labels: Vec<u32>,
    pub voids: Vec<Void>,
}

/// The label of an occupied voxel.
pub const OCCUPIED: u32 = u32::MAX;
/// The label of an empty voxel connected to the outside.
pub const OUTSIDE: u32 = 0;

impl VoxelGrid {
    /// The grid of voxels of side `size` around `points`, with one empty voxel of margin on
    /// every side. Voxels are centred on `points[0]`'s lattice: a lattice of spacing `size`
    /// puts one site at the centre of each voxel, so an intact body has no empty voxel.
    pub fn around(points: &[[f64; 3]], size: f64) -> Result<VoxelGrid, String> {
        if !(size.is_finite() && size > 0.0) {
            return Err(format!("voxel size must be a positive length, got {size}"));
        }
        let first = *points
            .first()
            .ok_or("no particles to put on voxels".to_string())?;
        let mut lo = first;
        let mut hi = first;
        for p in points {
            for a in 0..3 {
                if !p[a].is_finite() {
                    return Err(format!("a particle is at {p:?}: positions must be finite"));
                }
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let mut origin = [0.0; 3];
        let mut dims = [0usize; 3];
        for a in 0..3 {
            // Voxel boundaries half a voxel off the first point's lattice, one voxel of margin.
            let below = ((first[a] - lo[a]) / size + 0.5).ceil();
            origin[a] = first[a] - (below + 0.5) * size;
            let n = ((hi[a] - origin[a]) / size).floor() as usize + 2;
            dims[a] = n;
        }
        let voxels = dims.iter().try_fold(1usize, |acc, &n| acc.checked_mul(n));
        match voxels {
            Some(v) if v <= 1 << 31 => Ok(VoxelGrid { origin, size, dims }),
            _ => Err(format!(
                "{dims:?} voxels of {size:e} is more than 2^31: use larger voxels"
            )),
        }
    }

    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The voxel holding `p`, if inside the grid.
    pub fn voxel_of(&self, p: &[f64; 3]) -> Option<usize> {
        let mut index = 0;
        for a in (0..3).rev() {
            let f = ((p[a] - self.origin[a]) / self.size).floor();
            if !(f >= 0.0 && (f as usize) < self.dims[a]) {
                return None;
            }
            index = index * self.dims[a] + f as usize;
        }
        Some(index)
    }

    /// Which voxels hold at least one of `points` (points outside the grid are left out).
    pub fn occupancy(&self, points: &[[f64; 3]]) -> Vec<bool> {
        let mut occupied = vec![false; self.len()];
        for p in points {
            if let Some(v) = self.voxel_of(p) {
                occupied[v] = true;
            }
        }
        occupied
    }

    fn coords(&self, v: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [v % nx, (v / nx) % ny, v / (nx * ny)]
    }

    fn centre(&self, v: usize) -> [f64; 3] {
        let c = self.coords(v);
        [0, 1, 2].map(|a| self.origin[a] + (c[a] as f64 + 0.5) * self.size)
    }
}

/// Labels the empty voxels of `grid` (`occupied` per voxel) and measures the voids.
pub fn find_voids(grid: &VoxelGrid, occupied: &[bool], connectivity: Connectivity) -> VoidMap {
    assert_eq!(occupied.len(), grid.len(), "one occupancy flag per voxel");
    let [nx, ny, nz] = grid.dims;
    let index = |x: usize, y: usize, z: usize| (z * ny + y) * nx + x;
    // Neighbours reached from a voxel towards smaller indices: every touching pair once.
    let back: Vec<[i64; 3]> = match connectivity {
        Connectivity::Face => vec![[-1, 0, 0], [0, -1, 0], [0, 0, -1]],
        Connectivity::All => {
            let mut v = Vec::new();
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        if (dz, dy, dx) < (0, 0, 0) {
                            v.push([dx, dy, dz]);
                        }
                    }
                }
            }
            v
        }
    };
    let mut sets = UnionFind::new(grid.len());
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let v = index(x, y, z);
                if occupied[v] {
                    continue;
                }
                for d in &back {
                    let (a, b, c) = (x as i64 + d[0], y as i64 + d[1], z as i64 + d[2]);
                    if a < 0 || b < 0 || c < 0 || a >= nx as i64 || b >= ny as i64 {
                        continue;
                    }
                    let u = index(a as usize, b as usize, c as usize);
                    if !occupied[u] {
                        sets.join(u, v);
                    }
                }
            }
        }
    }
    label_and_measure(grid, occupied, &mut sets)
}

/// Labels from the sets: the one holding voxel 0 (a margin voxel, always empty) is the
/// outside; the others are numbered in order of their first voxel.
fn label_and_measure(grid: &VoxelGrid, occupied: &[bool], sets: &mut UnionFind) -> VoidMap {
    let outside = sets.root(0);
    let mut label_of_root: Vec<u32> = vec![OCCUPIED; grid.len()];
    let mut labels = vec![OCCUPIED; grid.len()];
    let mut voids: Vec<Void> = Vec::new();
    let mut sums: Vec<[f64; 3]> = Vec::new();
    let cell = grid.size.powi(3);
    for v in 0..grid.len() {
        if occupied[v] {
            continue;
        }
        let r = sets.root(v);
        if r == outside {
            labels[v] = OUTSIDE;
            continue;
        }
        if label_of_root[r] == OCCUPIED {
            label_of_root[r] = voids.len() as u32 + 1;
            voids.push(Void {
                label: voids.len() as u32 + 1,
                voxels: 0,
                volume: 0.0,
                surface: 0.0,
                centroid: [0.0; 3],
                equivalent_radius: 0.0,
            });
            sums.push([0.0; 3]);
        }
        let l = label_of_root[r];
        labels[v] = l;
        let k = l as usize - 1;
        voids[k].voxels += 1;
        let c = grid.centre(v);
        for a in 0..3 {
            sums[k][a] += c[a];
        }
        voids[k].surface += occupied_faces(grid, occupied, v) as f64 * grid.size * grid.size;
    }
    for (w, s) in voids.iter_mut().zip(&sums) {
        w.volume = w.voxels as f64 * cell;
        w.centroid = s.map(|x| x / w.voxels as f64);
        w.equivalent_radius = (3.0 * w.volume / (4.0 * std::f64::consts::PI)).cbrt();
    }
    VoidMap {
        grid: grid.clone(),
        labels,
        voids,
    }
}

/// How many of voxel `v`'s six faces it shares with an occupied voxel.
fn occupied_faces(grid: &VoxelGrid, occupied: &[bool], v: usize) -> u32 {
    let c = grid.coords(v);
    let stride = [1, grid.dims[0], grid.dims[0] * grid.dims[1]];
    let mut n = 0;
    for a in 0..3 {
        if c[a] > 0 && occupied[v - stride[a]] {
            n += 1;
        }
        if c[a] + 1 < grid.dims[a] && occupied[v + stride[a]] {
            n += 1;
        }
    }
    n
}

impl VoidMap {
    /// Volume of the voids over the volume of the body (occupied voxels and voids).
    pub fn porosity(&self) -> f64 {
        let occupied = self.labels.iter().filter(|&&l| l == OCCUPIED).count() as f64;
        let voids: f64 = self.voids.iter().map(|v| v.voxels as f64).sum();
        if occupied + voids > 0.0 {
            voids / (occupied + voids)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests;
