//! Voids and cracks on voxels (Hemani et al. 2014, `shared/seeds/004`): particle positions
//! are put on a grid of voxels, and connected sets of *marked* voxels are labelled as clusters.
//!
//! - **Voids**: a voxel holding at least one particle is occupied; the empty voxels are
//!   marked. The cluster that reaches the grid's border (the grid has one empty voxel of
//!   margin on every non-periodic side) is the outside; every other cluster is a void.
//! - **Cracks**: a voxel holding the midpoint of a broken bond is marked; each cluster is a
//!   crack, with its broken bonds and their mean opening.
//!
//! [`region`] is a procCube's share of the grid; [`labels`] labels a grid cut into procCubes without gathering it (local union-find, then
//! the labels merged across procCube faces); [`find_voids`] is the same on one grid.
//! [`tracking`] follows clusters from one analysis to the next; [`largest`] gathers the largest
//! ones' voxels for a picture.

pub mod labels;
pub mod largest;
pub mod region;
pub mod tracking;
mod union_find;

pub use labels::{label, Labelled, Scheme};
pub use region::{deposit, Region};

/// A grid of voxels, periodic along some axes.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelGrid {
    /// The corner of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// The side of a voxel along each axis: the size asked for, except along a periodic axis,
    /// where it is stretched a little so that a whole number of voxels spans the period.
    pub size: [f64; 3],
    pub dims: [usize; 3],
    /// Along a periodic axis the last voxel touches the first, and there is no margin.
    pub periodic: [bool; 3],
    /// Voxel (0, 0, 0)'s coordinates on the fixed voxel lattice of the run: grids of later
    /// analyses may be larger, and `offset` lets voxels be matched between them.
    pub offset: [i64; 3],
}

/// Which marked voxels touch: across a face (6 neighbours) or also across an edge or a
/// corner (26).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connectivity {
    Face,
    All,
}

impl Connectivity {
    pub fn name(self) -> &'static str {
        match self {
            Connectivity::Face => "face",
            Connectivity::All => "all",
        }
    }
}

/// One cluster: a void or a crack.
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster {
    /// 1, 2, … in the order of each cluster's first voxel (x fastest, then y, then z).
    pub label: u32,
    pub voxels: u64,
    pub volume: f64,
    /// Area of the voxel faces between the cluster and unmarked voxels. For a smooth surface
    /// this counts the staircase: a sphere's comes out about 3/2 of 4πR².
    pub surface: f64,
    /// Half the length of the vector of those faces' areas by axis: the area of a thin planar
    /// cluster (a crack) whatever its orientation, as a plane of normal n crosses the faces
    /// normal to axis a in proportion to |n_a|. For a curved crack it is a lower bound.
    pub area: f64,
    pub centroid: [f64; 3],
    /// The radius of a sphere of the cluster's volume.
    pub equivalent_radius: f64,
    /// First and last voxel along each axis.
    pub first: [usize; 3],
    pub last: [usize; 3],
    /// Cracks: the broken bonds whose midpoints lie in the cluster, and their mean opening
    /// (current length less reference length).
    pub bonds: u64,
    pub opening: f64,
}

/// Every voxel's label and the voids of one grid.
#[derive(Clone, Debug)]
pub struct VoidMap {
    pub grid: VoxelGrid,
    /// Per voxel (x fastest): [`OCCUPIED`], [`OUTSIDE`], or the label of its void.
    pub labels: Vec<u32>,
    pub voids: Vec<Cluster>,
}

/// The label of an occupied voxel.
pub const OCCUPIED: u32 = u32::MAX;
/// The label of an empty voxel connected to the outside.
pub const OUTSIDE: u32 = 0;

/// Along one axis of a grid: periodic with this origin and period, or bounded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    Bounded { lo: f64, hi: f64 },
    Periodic { origin: f64, period: f64 },
}

impl VoxelGrid {
    /// The grid of voxels of side `size` around `points`, with one empty voxel of margin on
    /// every side. Voxels are centred on `points[0]`'s lattice: a lattice of spacing `size`
    /// puts one site at the centre of each voxel, so an intact body has no empty voxel.
    pub fn around(points: &[[f64; 3]], size: f64) -> Result<VoxelGrid, String> {
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
        let extent = [0, 1, 2].map(|a| Extent::Bounded {
            lo: lo[a],
            hi: hi[a],
        });
        VoxelGrid::spanning(first, extent, [size; 3])
    }

    /// The grid of voxels of sides `size` centred on `anchor`'s lattice, spanning each bounded
    /// axis from `lo` to `hi` with one voxel of margin on each side, and each periodic axis
    /// exactly (there, voxels are stretched to a whole number per period).
    pub fn spanning(
        anchor: [f64; 3],
        extent: [Extent; 3],
        size: [f64; 3],
    ) -> Result<VoxelGrid, String> {
        if !size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(format!(
                "voxel size must be a positive length, got {size:?}"
            ));
        }
        let mut grid = VoxelGrid {
            origin: [0.0; 3],
            size,
            dims: [0; 3],
            periodic: [false; 3],
            offset: [0; 3],
        };
        for a in 0..3 {
            match extent[a] {
                Extent::Bounded { lo, hi } => {
                    if !(lo.is_finite() && hi.is_finite() && anchor[a].is_finite()) {
                        return Err(format!(
                            "a particle is at a non-finite position along axis {a}: positions must be finite"
                        ));
                    }
                    // Voxel boundaries half a voxel off the anchor's lattice, one voxel of
                    // margin below `lo` and above `hi`.
                    let below = ((anchor[a] - lo) / size[a] + 0.5).ceil();
                    grid.origin[a] = anchor[a] - (below + 0.5) * size[a];
                    grid.offset[a] = -(below as i64);
                    let n = ((hi - grid.origin[a]) / size[a]).floor() + 2.0;
                    grid.dims[a] = if n < 1e15 { n as usize } else { usize::MAX };
                }
                Extent::Periodic { origin, period } => {
                    let n = (period / size[a]).round().max(1.0);
                    let s = period / n;
                    // The first voxel's centre in [origin, origin + s): centres run through
                    // the period in order.
                    let j = ((origin - anchor[a]) / s).ceil();
                    grid.origin[a] = anchor[a] + (j - 0.5) * s;
                    grid.offset[a] = j as i64;
                    grid.size[a] = s;
                    grid.dims[a] = if n < 1e15 { n as usize } else { usize::MAX };
                    grid.periodic[a] = true;
                }
            }
        }
        let voxels = grid
            .dims
            .iter()
            .try_fold(1usize, |acc, &n| acc.checked_mul(n));
        match voxels {
            Some(v) if v <= 1 << 31 => Ok(grid),
            _ => Err(format!(
                "{:?} voxels of {:e} is more than 2^31: use larger voxels",
                grid.dims, size[0]
            )),
        }
    }

    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The coordinates of the voxel holding `p` (wrapped along periodic axes), if inside.
    pub fn coords_of(&self, p: &[f64; 3]) -> Option<[usize; 3]> {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let f = ((p[a] - self.origin[a]) / self.size[a]).floor();
            if !f.is_finite() {
                return None;
            }
            let f = if self.periodic[a] {
                f.rem_euclid(self.dims[a] as f64)
            } else {
                f
            };
            if !(f >= 0.0 && f < self.dims[a] as f64) {
                return None;
            }
            c[a] = f as usize;
        }
        Some(c)
    }

    /// The voxel holding `p`, if inside the grid.
    pub fn voxel_of(&self, p: &[f64; 3]) -> Option<usize> {
        self.coords_of(p).map(|c| self.index(c))
    }

    pub fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
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

    /// The volume of one voxel.
    pub fn voxel_volume(&self) -> f64 {
        self.size.iter().product()
    }

    /// The centre of the voxel at (fractional) coordinates `c`.
    pub fn centre(&self, c: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.origin[a] + (c[a] + 0.5) * self.size[a])
    }

    /// Whether some axis is bounded, so that the grid has a margin and an outside.
    pub fn has_outside(&self) -> bool {
        self.periodic.iter().any(|p| !p)
    }
}

/// Labels the empty voxels of `grid` (`occupied` per voxel) and measures the voids: the
/// labelling of [`labels`] on one procCube.
pub fn find_voids(grid: &VoxelGrid, occupied: &[bool], connectivity: Connectivity) -> VoidMap {
    assert_eq!(occupied.len(), grid.len(), "one occupancy flag per voxel");
    let region = Region::whole(grid.clone());
    let empty: Vec<bool> = occupied.iter().map(|o| !o).collect();
    let mut team = crate::parallel::comm::Team::new(crate::parallel::comm::Solo::new());
    let found = label(
        &mut team,
        &region,
        &empty,
        &[],
        connectivity,
        Scheme::Boundary,
    );
    let labels = occupied
        .iter()
        .zip(&found.labels)
        .map(|(&o, &l)| if o { OCCUPIED } else { l })
        .collect();
    VoidMap {
        grid: grid.clone(),
        labels,
        voids: found.clusters,
    }
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
