//! Uniform cells no smaller than the horizon, and the 13-cell half shell (thesis 3.4–3.5).
//!
//! Every pair of particles closer than the horizon lies in the same cell or in adjacent cells.
//! Pairing each cell with itself and with the 13 neighbours of [`HALF_SHELL`] visits every
//! adjacent pair of cells exactly once, so every pair of particles is found exactly once.

/// The half shell the wall method needs: (dx, dy, dz) with dy < 0, or dy = 0 and dz < 0, or
/// dy = dz = 0 and dx < 0. Every offset has dy ≤ 0, so a procCube pairs its cells only with
/// ghosts from the south, down, up-south and west sides — exactly what the five ghost messages
/// deliver (nothing ever comes from the north). Their negatives are the other 13 neighbours.
pub const HALF_SHELL: [[i32; 3]; 13] = [
    [-1, -1, -1],
    [0, -1, -1],
    [1, -1, -1],
    [-1, -1, 0],
    [0, -1, 0],
    [1, -1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, -1],
    [0, 0, -1],
    [1, 0, -1],
    [-1, 0, 0],
];

/// A box of cells over a set of points.
#[derive(Clone, Debug, PartialEq)]
pub struct CellGrid {
    pub origin: [f64; 3],
    pub size: [f64; 3],
    pub dims: [usize; 3],
}

impl CellGrid {
    /// Cells of side ≥ `min_size` covering every point.
    pub fn covering(points: &[[f64; 3]], min_size: f64) -> CellGrid {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if points.is_empty() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        CellGrid::covering_box(lo, hi, points.len(), min_size)
    }

    /// Cells of side ≥ `min_size` covering the box `[lo, hi]` of `points` points.
    pub fn covering_box(lo: [f64; 3], hi: [f64; 3], points: usize, min_size: f64) -> CellGrid {
        // Cells a hair larger than asked: with a side of exactly the horizon, rounding in
        // `coords` could put a pair at exactly the horizon two cells apart.
        let mut target = min_size * (1.0 + 1e-9);
        // A sparse scene (two bodies far apart, a long diagonal bar) would need more cells than
        // memory holds; larger cells stay correct, as only size >= horizon matters.
        let cap = (8 * points).max(4096) as f64;
        loop {
            let mut dims = [1usize; 3];
            let mut size = [target; 3];
            for k in 0..3 {
                let extent = hi[k] - lo[k];
                let n = (extent / target).floor().clamp(1.0, 1e15) as usize;
                dims[k] = n;
                // n cells span the extent exactly; never below the target.
                size[k] = (extent / n as f64).max(target);
            }
            let cells = dims.iter().map(|&d| d as f64).product::<f64>();
            if cells <= cap {
                return CellGrid {
                    origin: lo,
                    size,
                    dims,
                };
            }
            target *= (cells / cap).cbrt().max(1.01);
        }
    }

    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Integer cell coordinates of a point (clamped into the grid).
    #[inline]
    pub fn coords(&self, p: &[f64; 3]) -> [usize; 3] {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let f = ((p[k] - self.origin[k]) / self.size[k]).floor();
            c[k] = (f.max(0.0) as usize).min(self.dims[k] - 1);
        }
        c
    }

    /// Cells are numbered with y slowest, then z, then x: the half shell looks back at most one
    /// y-slab, so the particles a cell's bonds touch stay close together in the store.
    #[inline]
    pub fn index(&self, c: [usize; 3]) -> usize {
        (c[1] * self.dims[2] + c[2]) * self.dims[0] + c[0]
    }

    /// The neighbour of cell `c` at `offset`, if inside the grid.
    #[inline]
    pub fn neighbour(&self, c: [usize; 3], offset: [i32; 3]) -> Option<usize> {
        let mut n = [0usize; 3];
        for k in 0..3 {
            let v = c[k] as i64 + offset[k] as i64;
            if v < 0 || v >= self.dims[k] as i64 {
                return None;
            }
            n[k] = v as usize;
        }
        Some(self.index(n))
    }

    /// Cell of each point and the points grouped by cell: `(cell_of, start, order)` where the
    /// points of cell c are `order[start[c]..start[c + 1]]`, in increasing point index.
    pub fn bin(&self, points: &[[f64; 3]]) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let cell_of: Vec<u32> = points
            .iter()
            .map(|p| self.index(self.coords(p)) as u32)
            .collect();
        let mut start = vec![0u32; self.len() + 1];
        for &c in &cell_of {
            start[c as usize + 1] += 1;
        }
        for c in 0..self.len() {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; points.len()];
        for (i, &c) in cell_of.iter().enumerate() {
            order[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        (cell_of, start, order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_shell_is_half_of_the_neighbourhood() {
        let mut all = Vec::new();
        for o in HALF_SHELL {
            all.push(o);
            all.push([-o[0], -o[1], -o[2]]);
        }
        all.sort();
        all.dedup();
        assert_eq!(all.len(), 26);
        assert!(!all.contains(&[0, 0, 0]));
        assert!(HALF_SHELL.iter().all(|o| o[1] <= 0));
    }

    #[test]
    fn sparse_scenes_get_few_large_cells() {
        let pts = [[0.0, 0.0, 0.0], [10.0, 10.0, 10.0], [5.0, 5.0, 5.0]];
        let g = CellGrid::covering(&pts, 0.003);
        assert!(g.len() <= 4096, "{} cells", g.len());
        assert!(g.size.iter().all(|&s| s >= 0.003));
    }

    #[test]
    fn cells_are_never_smaller_than_requested() {
        let pts = [[0.0, 0.0, 0.0], [10.0, 2.5, 0.0]];
        let g = CellGrid::covering(&pts, 3.0);
        assert_eq!(g.dims, [3, 1, 1]);
        assert!(g.size.iter().all(|&s| s >= 3.0));
        assert_eq!(g.coords(&pts[1]), [2, 0, 0]);
    }
}

/// The cells of the whole scene and the axes that wrap around.
#[derive(Clone, Debug)]
pub struct Domain {
    pub grid: CellGrid,
    pub periodic: [bool; 3],
    /// Length of each periodic axis; the grid spans it exactly.
    pub period: [f64; 3],
}

impl Domain {
    /// The same box with the cell count along each axis rounded down to a multiple of
    /// `procs`, where that leaves at least one cell per procCube (and, on a periodic axis, at
    /// least three cells, so that a cell's two neighbours along it are different cells).
    pub fn for_procs(&self, procs: [usize; 3]) -> Domain {
        let mut d = self.clone();
        for (a, &p) in procs.iter().enumerate() {
            let n = self.grid.dims[a];
            let m = n - n % p.max(1);
            let least = if self.periodic[a] { p.max(3) } else { p };
            if m >= least && m != n {
                d.grid.size[a] = self.grid.size[a] * n as f64 / m as f64;
                d.grid.dims[a] = m;
            }
        }
        d
    }
}
