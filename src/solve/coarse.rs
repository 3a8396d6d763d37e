//! The coarse level of the matrix-free solve's preconditioner: a two-level additive Schwarz
//! preconditioner, M⁻¹ = D⁻¹ + P K_c⁻¹ Pᵀ, over aggregates of the lattice.
//!
//! The diagonal D alone damps what varies from particle to particle, but a beam's bending
//! modes span its whole length, and diagonally preconditioned CG needs about √κ iterations for
//! them: thousands on a 1 in girder. The coarse level solves for those exactly, in a space
//! of rigid-body motions: the particles are grouped into cubes of edge H (6 lattice spacings,
//! or the tangent's reach if longer), and each group can translate along and rotate about
//! three axes (P: 6 columns per group, the rotations only where a group holds 4 particles or
//! more; micropolar particles turn with the rotation). K_c = Pᵀ K P is measured by the same
//! force differences as every product of the solve: groups farther apart than H share no
//! bond, so the groups of one of 27 colours (their cube index modulo 3 per axis) are moved
//! together, one of the six motions at a time: 162 force evaluations, whatever the scene's
//! size. K_c is small (6 per group) and factored by sparse Cholesky, the same on every
//! procCube; Pᵀr is summed over procCubes in rank order, so the same layout gives the same bits.
//!
//! The groups are cut from reference positions in a grid anchored at the scene's lowest
//! corner, so every layout and a restart cut the same groups. K_c is measured at the start of
//! every load step, a function of that step's state alone, so a resumed run builds the
//! preconditioner the uninterrupted run built. Within a load step bonds may break; the coarse
//! matrix then is a little stiffer than the tangent, which leaves it a preconditioner.

use crate::model::attributes::Attributes;
use crate::model::{second_order, Model};
use crate::parallel::comm::Reduce;
use crate::parallel::Cube;
use crate::solve::krylov::{tangent_times, Base};
use faer::prelude::Solve;
use faer::sparse::{SparseColMat, Triplet};

/// A group's edge in shortest bonds (about the lattice spacing), where the tangent's reach is
/// shorter: 216 particles a group on a cubic lattice, so the coarse matrix of a 300,000
/// particle scene has about 8,000 rows.
const GROUP_SPACINGS: f64 = 6.0;
/// Motions per group: three translations, three rotations.
const MOTIONS: usize = 6;
/// The 3 × 3 × 3 groups around a group (and itself), the only ones it shares bonds with.
const AROUND: usize = 27;

/// The coarse level (module comment).
pub struct Coarse {
    groups: Groups,
    /// Columns of P that move no free DOF (a group held by supports, a rotation of a group
    /// too small to turn): left out of K_c.
    dead: Vec<bool>,
    factor: faer::sparse::linalg::solvers::Llt<usize, f64>,
    /// Force evaluations the measurement of K_c took.
    pub evaluations: u64,
}

/// The groups and their motions (the columns of P).
struct Groups {
    n2: usize,
    /// The group of each owned particle (dense, the same numbers on every procCube).
    group: Vec<usize>,
    /// (x0 − the group's centroid) / H of each owned particle.
    offset: Vec<[f64; 3]>,
    /// 1 / H: a micropolar particle turns by this per unit of a rotation motion.
    inv_h: f64,
    /// Whether a group rotates (4 particles or more).
    rotates: Vec<bool>,
}

/// Where the groups are: the grid's corner, H, its size, and each owned particle's cell.
struct Grid {
    lo: [f64; 3],
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    fn cell(&self, x: &[f64; 3]) -> [usize; 3] {
        std::array::from_fn(|a| {
            (((x[a] - self.lo[a]) / self.h).floor().max(0.0) as usize).min(self.dims[a] - 1)
        })
    }
    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }
    fn cell_of_index(&self, k: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [k % nx, k / nx % ny, k / nx / ny]
    }
}

impl Coarse {
    /// Measures and factors the coarse level at the state `base` holds; `None` where the
    /// model's DOFs are not a displacement (and a rotation) or the coarse matrix cannot be
    /// factored: the preconditioner is then the diagonal alone. Every procCube calls it alike.
    pub(super) fn build<M: Model>(
        cube: &mut Cube<M>,
        base: &Base<M>,
        free: &[bool],
    ) -> Option<Coarse> {
        let n2 = second_order::<M>();
        if n2 != 3 && n2 != 6 {
            return None;
        }
        let grid = grid(cube)?;
        let (groups, cells, number, where_) = Groups::cut(cube, &grid, n2);
        let (measured, evaluations) = groups.measure(cube, base, free, &grid, &cells, &number);
        let (dead, factor) = groups.assemble(&measured, &grid, &where_, &number)?;
        Some(Coarse {
            groups,
            dead,
            factor,
            evaluations,
        })
    }

    /// z += P K_c⁻¹ Pᵀ r over the free owned DOFs (Pᵀ r summed over every procCube). Written
    /// out, not through [`Groups::motion`]: it runs at every CG iteration. A translation t and
    /// rotation θ of a group move its particle at offset d by t + θ × d (and turn a micropolar
    /// one by θ / H); so (Pᵀ r) of a group gathers Σ r and Σ d × r.
    pub fn correct<M: Model>(&self, cube: &mut Cube<M>, free: &[bool], r: &[f64], z: &mut [f64]) {
        let g = &self.groups;
        let n2 = g.n2;
        let mut rc = vec![0.0; self.dead.len()];
        for (i, (&b, d)) in g.group.iter().zip(&g.offset).enumerate() {
            let f = &r[i * n2..i * n2 + n2];
            let c = &mut rc[b * MOTIONS..b * MOTIONS + MOTIONS];
            let turn = cross(d, &[f[0], f[1], f[2]]);
            for a in 0..3 {
                c[a] += f[a];
                c[3 + a] += turn[a] + if n2 == 6 { g.inv_h * f[3 + a] } else { 0.0 };
            }
        }
        cube.team().reduce(&mut rc, Reduce::Sum);
        let mut y = faer::Mat::<f64>::zeros(rc.len(), 1);
        for (row, (&v, &dead)) in rc.iter().zip(&self.dead).enumerate() {
            // The dead rows are decoupled in K_c: a zero here stays zero.
            y[(row, 0)] = if dead { 0.0 } else { v };
        }
        self.factor.solve_in_place(y.as_mut());
        for (i, (&b, d)) in g.group.iter().zip(&g.offset).enumerate() {
            let c: [f64; MOTIONS] = std::array::from_fn(|m| y[(b * MOTIONS + m, 0)]);
            let turn = cross(&[c[3], c[4], c[5]], d);
            for a in 0..3 {
                if free[i * n2 + a] {
                    z[i * n2 + a] += c[a] + turn[a];
                }
                if n2 == 6 && free[i * n2 + 3 + a] {
                    z[i * n2 + 3 + a] += g.inv_h * c[3 + a];
                }
            }
        }
    }
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl Groups {
    /// Cuts the owned particles into groups: the groups, each particle's cell, the group
    /// number of each cell (`usize::MAX`: empty) and the cell of each group.
    fn cut<M: Model>(
        cube: &mut Cube<M>,
        grid: &Grid,
        n2: usize,
    ) -> (Groups, Vec<[usize; 3]>, Vec<usize>, Vec<usize>) {
        let n = cube.sim.particles.n_owned;
        let cells: Vec<[usize; 3]> = (cube.sim.particles.x0[..n].iter())
            .map(|x| grid.cell(x))
            .collect();
        // Counts and centroids of the cells, over every procCube.
        let n_cells = grid.dims.iter().product::<usize>();
        let mut sums = vec![0.0; 4 * n_cells];
        for (i, c) in cells.iter().enumerate() {
            let k = 4 * grid.index(*c);
            sums[k] += 1.0;
            for a in 0..3 {
                sums[k + 1 + a] += cube.sim.particles.x0[i][a];
            }
        }
        cube.team().reduce(&mut sums, Reduce::Sum);
        let mut number = vec![usize::MAX; n_cells];
        let (mut centroid, mut rotates, mut where_) = (Vec::new(), Vec::new(), Vec::new());
        for (k, s) in sums.chunks_exact(4).enumerate() {
            if s[0] > 0.0 {
                number[k] = centroid.len();
                centroid.push([s[1] / s[0], s[2] / s[0], s[3] / s[0]]);
                rotates.push(s[0] >= 4.0);
                where_.push(k);
            }
        }
        let inv_h = 1.0 / grid.h;
        let group: Vec<usize> = cells.iter().map(|c| number[grid.index(*c)]).collect();
        let offset = (0..n)
            .map(|i| {
                let (x, c) = (cube.sim.particles.x0[i], centroid[group[i]]);
                std::array::from_fn(|a| (x[a] - c[a]) * inv_h)
            })
            .collect();
        let groups = Groups {
            n2,
            group,
            offset,
            inv_h,
            rotates,
        };
        (groups, cells, number, where_)
    }

    /// The value of motion `m` of particle `i`'s group at its DOF `k`.
    fn motion(&self, i: usize, k: usize, m: usize) -> f64 {
        let d = &self.offset[i];
        match (m, k) {
            (0..=2, 0..=2) => f64::from(u8::from(m == k)),
            (0..=2, _) => 0.0,
            (_, 0..=2) => {
                // (e_a × d)_k with a = m − 3.
                let (p, q) = ((m + 1) % 3, (m + 2) % 3);
                if k == p {
                    -d[q]
                } else if k == q {
                    d[p]
                } else {
                    0.0
                }
            }
            _ => {
                if k == m {
                    self.inv_h
                } else {
                    0.0
                }
            }
        }
    }

    /// p_j · (K p_m) summed over each group's particles, for every group, the 27 groups
    /// around it and each pair of motions, over every procCube; and the products it took.
    fn measure<M: Model>(
        &self,
        cube: &mut Cube<M>,
        base: &Base<M>,
        free: &[bool],
        grid: &Grid,
        cells: &[[usize; 3]],
        number: &[usize],
    ) -> (Vec<f64>, u64) {
        let (n2, n) = (self.n2, self.group.len());
        let mut measured = vec![0.0; self.rotates.len() * AROUND * MOTIONS * MOTIONS];
        let (mut v, mut q) = (vec![0.0; n * n2], vec![0.0; n * n2]);
        let mut evaluations = 0;
        for colour in 0..AROUND {
            let tint = [colour % 3, colour / 3 % 3, colour / 9];
            // The group of this colour around each particle's group, as an offset 0..27.
            let around: Vec<Option<usize>> = cells
                .iter()
                .map(|c| of_colour(c, tint, grid, number))
                .collect();
            for m in 0..MOTIONS {
                for (i, cell) in cells.iter().enumerate() {
                    let moved = (0..3).all(|a| cell[a] % 3 == tint[a])
                        && (m < 3 || self.rotates[self.group[i]]);
                    for k in 0..n2 {
                        let idx = i * n2 + k;
                        v[idx] = if moved && free[idx] {
                            self.motion(i, k, m)
                        } else {
                            0.0
                        };
                    }
                }
                tangent_times(cube, base, &v, free, &mut q);
                evaluations += 1;
                for (i, o) in around.iter().enumerate() {
                    let Some(o) = *o else { continue };
                    let row = (self.group[i] * AROUND + o) * MOTIONS * MOTIONS;
                    for j in 0..MOTIONS {
                        let s: f64 = (0..n2).map(|k| self.motion(i, k, j) * q[i * n2 + k]).sum();
                        measured[row + j * MOTIONS + m] += s;
                    }
                }
            }
        }
        cube.team().reduce(&mut measured, Reduce::Sum);
        (measured, evaluations)
    }

    /// K_c from the measured products (symmetrized), its dead columns left out, factored:
    /// the dead columns and the factor.
    fn assemble(
        &self,
        measured: &[f64],
        grid: &Grid,
        where_: &[usize],
        number: &[usize],
    ) -> Option<(Vec<bool>, Llt)> {
        let size = self.rotates.len() * MOTIONS;
        let entry = |b: usize, o: usize, j: usize, m: usize| {
            measured[((b * AROUND + o) * MOTIONS + j) * MOTIONS + m]
        };
        const ITSELF: usize = AROUND / 2;
        let largest = (0..size)
            .map(|r| entry(r / MOTIONS, ITSELF, r % MOTIONS, r % MOTIONS))
            .fold(0.0f64, f64::max);
        let dead: Vec<bool> = (0..size)
            .map(|r| {
                let (b, j) = (r / MOTIONS, r % MOTIONS);
                (j >= 3 && !self.rotates[b]) || entry(b, ITSELF, j, j) <= 1e-12 * largest
            })
            .collect();
        let mut triplets = Vec::new();
        for (b, &k) in where_.iter().enumerate() {
            let c = grid.cell_of_index(k);
            for o in 0..AROUND {
                let step = [o % 3, o / 3 % 3, o / 9];
                let at: Option<Vec<usize>> = (0..3)
                    .map(|a| {
                        (c[a] + step[a])
                            .checked_sub(1)
                            .filter(|&x| x < grid.dims[a])
                    })
                    .collect();
                let Some(at) = at else { continue };
                let a = number[grid.index([at[0], at[1], at[2]])];
                if a == usize::MAX {
                    continue;
                }
                for j in 0..MOTIONS {
                    for m in 0..MOTIONS {
                        let (row, col) = (b * MOTIONS + j, a * MOTIONS + m);
                        if row < col || dead[row] || dead[col] {
                            continue;
                        }
                        let value = 0.5 * (entry(b, o, j, m) + entry(a, AROUND - 1 - o, m, j));
                        triplets.push(Triplet::new(row, col, value));
                    }
                }
            }
        }
        triplets.extend(
            (0..size)
                .filter(|&r| dead[r])
                .map(|r| Triplet::new(r, r, 1.0)),
        );
        let lower =
            SparseColMat::<usize, f64>::try_new_from_triplets(size, size, &triplets).ok()?;
        let factor = (lower.sp_cholesky(faer::Side::Lower).ok())
            .or_else(|| crate::solve::implicit::shifted_cholesky(&triplets, size))?;
        Some((dead, factor))
    }
}

type Llt = faer::sparse::linalg::solvers::Llt<usize, f64>;

/// The offset (0..27) of the group of colour `tint` among the 3 × 3 × 3 cells around `c`,
/// if that cell lies in the grid and holds particles.
fn of_colour(c: &[usize; 3], tint: [usize; 3], grid: &Grid, number: &[usize]) -> Option<usize> {
    let mut at = [0usize; 3];
    let mut o = 0;
    for a in (0..3).rev() {
        // Of c − 1, c, c + 1 the one ≡ tint (mod 3): c − 1 + s, with c + 2 ≡ c − 1.
        let s = (tint[a] + 3 - (c[a] + 2) % 3) % 3;
        let x = (c[a] + s).checked_sub(1)?;
        if x >= grid.dims[a] {
            return None;
        }
        at[a] = x;
        o = 3 * o + s;
    }
    (number[grid.index(at)] != usize::MAX).then_some(o)
}

/// The grid of groups: anchored at the scene's lowest corner (over every procCube), its edge
/// the longer of [`GROUP_SPACINGS`] shortest bonds and the tangent's reach (the longest bond,
/// twice over for a state-based model), just beyond it so that groups two apart share no bond.
fn grid<M: Model>(cube: &mut Cube<M>) -> Option<Grid> {
    let n = cube.sim.particles.n_owned;
    let mut lo = [f64::INFINITY; 3];
    let mut neg_hi = [f64::INFINITY; 3];
    for x in &cube.sim.particles.x0[..n] {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            neg_hi[a] = neg_hi[a].min(-x[a]);
        }
    }
    let (mut shortest, mut neg_longest) = (f64::INFINITY, f64::INFINITY);
    for g in cube.sim.bonds.geom.iter() {
        shortest = shortest.min(g.length);
        neg_longest = neg_longest.min(-g.length);
    }
    let mut all = [
        lo[0],
        lo[1],
        lo[2],
        neg_hi[0],
        neg_hi[1],
        neg_hi[2],
        shortest,
        neg_longest,
    ];
    cube.team().reduce(&mut all, Reduce::Min);
    let longest = -all[7];
    if !(all[6].is_finite() && longest > 0.0) {
        return None;
    }
    let reach = if <M::State as Attributes>::LEN > 0 {
        2.0 * longest
    } else {
        longest
    };
    let h = (GROUP_SPACINGS * all[6]).max(reach * (1.0 + 1e-6));
    let lo = [all[0], all[1], all[2]];
    let dims = std::array::from_fn(|a| ((-all[3 + a] - lo[a]) / h).floor() as usize + 1);
    Some(Grid { lo, h, dims })
}
