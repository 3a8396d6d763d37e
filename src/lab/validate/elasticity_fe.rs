//! Linear 3D elasticity by finite elements, without peridynamics: Lagrange hexahedra of any
//! order on an axis-aligned box, isotropic, held on lines or faces of nodes and loaded by
//! uniform body forces. `fe_check.rs` uses it to check the beam formulas of the validation
//! cases against elasticity on the cases' own geometry (validation/README.md).
//!
//! The elements are the tensor products of 1D Lagrange polynomials on equispaced nodes,
//! integrated by (order + 1)³ Gauss points (exact for a box element's stiffness); the
//! stiffness is assembled as its lower triangle and factored by sparse Cholesky (`faer`).

use faer::prelude::Solve;
use faer::sparse::{SparseColMat, Triplet};
use std::collections::HashMap;

/// A body, its mesh, material, supports and loads.
pub struct Problem {
    /// Element boundaries along x, y and z, increasing; the first and last bound the body.
    pub planes: [Vec<f64>; 3],
    /// Polynomial order of the elements along each axis (1 = trilinear).
    pub order: usize,
    pub youngs: f64,
    pub poisson: f64,
    pub supports: Vec<Support>,
    pub loads: Vec<BodyLoad>,
}

/// Held nodes: every node whose coordinates equal `at` where it is given (`None`: any), held
/// in the components marked in `dofs`. `at` must lie on element boundaries.
pub struct Support {
    pub at: [Option<f64>; 3],
    pub dofs: [bool; 3],
}

/// A uniform body force over the box `lo`–`hi` (on element boundaries), `total` over the
/// part of the body inside it.
pub struct BodyLoad {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub total: [f64; 3],
}

/// The displacement field of a solved problem.
pub struct Solution {
    planes: [Vec<f64>; 3],
    order: usize,
    /// Nodes along each axis.
    nodes: [usize; 3],
    /// (u_x, u_y, u_z) of each node, x fastest.
    displacement: Vec<[f64; 3]>,
    /// Unknowns (free DOFs) of the solve.
    pub unknowns: usize,
}

/// 1D Lagrange basis of `order` on equispaced nodes over [−1, 1]: values and derivatives.
fn basis(order: usize, xi: f64) -> (Vec<f64>, Vec<f64>) {
    let node = |l: usize| -1.0 + 2.0 * l as f64 / order as f64;
    let mut value = vec![1.0; order + 1];
    let mut slope = vec![0.0; order + 1];
    for l in 0..=order {
        for m in (0..=order).filter(|&m| m != l) {
            let d = node(l) - node(m);
            slope[l] = slope[l] * (xi - node(m)) / d + value[l] / d;
            value[l] *= (xi - node(m)) / d;
        }
    }
    (value, slope)
}

/// Gauss–Legendre points and weights on [−1, 1] (Newton's method on P_n).
fn gauss(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                let p = if n == 0 { p0 } else { p1 };
                dp = n as f64 * (x * p - p0) / (x * x - 1.0);
                let step = p / dp;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The stiffness of a box element of sides `h`, (3·(order+1)³)², DOF 3a + i for local node
/// a = l + (p+1)(m + (p+1)n) and component i.
fn element_stiffness(order: usize, h: [f64; 3], lame: (f64, f64)) -> Vec<f64> {
    let q = order + 1;
    let n = q * q * q;
    let (lambda, mu) = lame;
    let points = gauss(q);
    let tables: Vec<(Vec<f64>, Vec<f64>)> = points.iter().map(|&(x, _)| basis(order, x)).collect();
    let det = h[0] * h[1] * h[2] / 8.0;
    let mut k = vec![0.0; 9 * n * n];
    let mut grad = vec![[0.0; 3]; n];
    for (g, &(_, wg)) in points.iter().enumerate() {
        for (s, &(_, ws)) in points.iter().enumerate() {
            for (t, &(_, wt)) in points.iter().enumerate() {
                let (v, d) = (
                    [&tables[g].0, &tables[s].0, &tables[t].0],
                    [&tables[g].1, &tables[s].1, &tables[t].1],
                );
                for (a, ga) in grad.iter_mut().enumerate() {
                    let (l, m, o) = (a % q, (a / q) % q, a / (q * q));
                    *ga = [
                        d[0][l] * v[1][m] * v[2][o] * 2.0 / h[0],
                        v[0][l] * d[1][m] * v[2][o] * 2.0 / h[1],
                        v[0][l] * v[1][m] * d[2][o] * 2.0 / h[2],
                    ];
                }
                let w = wg * ws * wt * det;
                for a in 0..n {
                    for b in 0..n {
                        let (ga, gb) = (grad[a], grad[b]);
                        let dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                        for i in 0..3 {
                            for j in 0..3 {
                                let mut e = lambda * ga[i] * gb[j] + mu * ga[j] * gb[i];
                                if i == j {
                                    e += mu * dot;
                                }
                                k[(3 * a + i) * 3 * n + 3 * b + j] += w * e;
                            }
                        }
                    }
                }
            }
        }
    }
    k
}

impl Problem {
    /// Node coordinates along `axis`.
    fn node_coordinates(&self, axis: usize) -> Vec<f64> {
        let p = &self.planes[axis];
        let mut c: Vec<f64> = (0..p.len() - 1)
            .flat_map(|e| {
                (0..self.order)
                    .map(move |l| p[e] + (p[e + 1] - p[e]) * l as f64 / self.order as f64)
            })
            .collect();
        c.push(p[p.len() - 1]);
        c
    }

    fn check(&self) -> Result<(), String> {
        if self.order == 0 || self.order > 6 {
            return Err(format!("element order {} (use 1 to 6)", self.order));
        }
        for (axis, p) in self.planes.iter().enumerate() {
            if p.len() < 2
                || p.windows(2)
                    .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
            {
                return Err(format!(
                    "the element planes along axis {axis} must increase: {p:?}"
                ));
            }
        }
        let moduli_ok = self.youngs > 0.0 && self.poisson > -1.0 && self.poisson < 0.5;
        if !moduli_ok {
            return Err(format!(
                "E = {} and ν = {}: need E > 0, −1 < ν < ½",
                self.youngs, self.poisson
            ));
        }
        Ok(())
    }

    /// Solves K u = f with the supports held.
    pub fn solve(&self) -> Result<Solution, String> {
        self.check()?;
        let coords = [0, 1, 2].map(|a| self.node_coordinates(a));
        let nodes = [0, 1, 2].map(|a| coords[a].len());
        let count = nodes[0] * nodes[1] * nodes[2];
        let free = self.free_dofs(&coords, count)?;
        let unknowns = free.iter().filter(|&&f| f != usize::MAX).count();
        let (triplets, force) = self.assemble(&free, nodes, unknowns);
        let k = SparseColMat::<usize, f64>::try_new_from_triplets(unknowns, unknowns, &triplets)
            .map_err(|e| format!("assembling the stiffness: {e:?}"))?;
        drop(triplets);
        let llt = k
            .sp_cholesky(faer::Side::Lower)
            .map_err(|e| format!("the stiffness is not positive definite ({e:?}): the supports leave a rigid-body motion free"))?;
        let mut rhs = faer::Mat::<f64>::zeros(unknowns, 1);
        for (r, f) in force.iter().enumerate() {
            rhs[(r, 0)] = *f;
        }
        llt.solve_in_place(rhs.as_mut());
        let displacement = (0..count)
            .map(|node| {
                [0, 1, 2].map(|i| match free[3 * node + i] {
                    usize::MAX => 0.0,
                    r => rhs[(r, 0)],
                })
            })
            .collect();
        Ok(Solution {
            planes: self.planes.clone(),
            order: self.order,
            nodes,
            displacement,
            unknowns,
        })
    }

    /// The unknown's index of each DOF (3·node + component), `usize::MAX` where held.
    fn free_dofs(&self, coords: &[Vec<f64>; 3], count: usize) -> Result<Vec<usize>, String> {
        let scale = (0..3)
            .map(|a| coords[a][coords[a].len() - 1] - coords[a][0])
            .fold(0.0, f64::max);
        let on = |c: f64, want: Option<f64>| want.is_none_or(|w| (c - w).abs() <= 1e-9 * scale);
        let mut held = vec![false; 3 * count];
        for (s, support) in self.supports.iter().enumerate() {
            let mut any = false;
            for (k, &z) in coords[2].iter().enumerate() {
                for (j, &y) in coords[1].iter().enumerate() {
                    for (i, &x) in coords[0].iter().enumerate() {
                        if on(x, support.at[0]) && on(y, support.at[1]) && on(z, support.at[2]) {
                            let node = i + coords[0].len() * (j + coords[1].len() * k);
                            (0..3)
                                .filter(|&c| support.dofs[c])
                                .for_each(|c| held[3 * node + c] = true);
                            any = true;
                        }
                    }
                }
            }
            if !any {
                return Err(format!(
                    "support {s} at {:?} holds no node (not on an element boundary?)",
                    support.at
                ));
            }
        }
        let mut next = 0;
        Ok(held
            .iter()
            .map(|&h| {
                if h {
                    usize::MAX
                } else {
                    next += 1;
                    next - 1
                }
            })
            .collect())
    }

    /// The stiffness's lower triangle over the unknowns, and the load vector.
    fn assemble(
        &self,
        free: &[usize],
        nodes: [usize; 3],
        unknowns: usize,
    ) -> (Vec<Triplet<usize, usize, f64>>, Vec<f64>) {
        let (p, q) = (self.order, self.order + 1);
        let n = q * q * q;
        let mu = self.youngs / (2.0 * (1.0 + self.poisson));
        let lambda =
            self.youngs * self.poisson / ((1.0 + self.poisson) * (1.0 - 2.0 * self.poisson));
        let points = gauss(q);
        // ∫ N_l over [−1, 1], for the body forces.
        let integral: Vec<f64> = (0..q)
            .map(|l| points.iter().map(|&(x, w)| w * basis(p, x).0[l]).sum())
            .collect();
        let mut cache: HashMap<[u64; 3], Vec<f64>> = HashMap::new();
        let mut triplets = Vec::new();
        let mut force = vec![0.0; unknowns];
        let planes = &self.planes;
        let density = self.densities();
        for ez in 0..planes[2].len() - 1 {
            for ey in 0..planes[1].len() - 1 {
                for ex in 0..planes[0].len() - 1 {
                    let e = [ex, ey, ez];
                    let h = [0, 1, 2].map(|a| planes[a][e[a] + 1] - planes[a][e[a]]);
                    let centre = [0, 1, 2].map(|a| planes[a][e[a]] + 0.5 * h[a]);
                    let ke = cache
                        .entry(h.map(f64::to_bits))
                        .or_insert_with(|| element_stiffness(p, h, (lambda, mu)));
                    let dof = |a: usize, i: usize| {
                        let (l, m, o) = (a % q, (a / q) % q, a / (q * q));
                        let node = ex * p + l + nodes[0] * (ey * p + m + nodes[1] * (ez * p + o));
                        free[3 * node + i]
                    };
                    let b = density.iter().filter(|(lo, hi, _)| {
                        (0..3).all(|a| centre[a] > lo[a] && centre[a] < hi[a])
                    });
                    let b = b.fold([0.0; 3], |s, (_, _, d)| {
                        [s[0] + d[0], s[1] + d[1], s[2] + d[2]]
                    });
                    for a in 0..n {
                        let (l, m, o) = (a % q, (a / q) % q, a / (q * q));
                        let weight =
                            integral[l] * integral[m] * integral[o] * h[0] * h[1] * h[2] / 8.0;
                        for i in 0..3 {
                            let r = dof(a, i);
                            if r == usize::MAX {
                                continue;
                            }
                            force[r] += b[i] * weight;
                            for bn in 0..n {
                                for j in 0..3 {
                                    let c = dof(bn, j);
                                    if c != usize::MAX && r >= c {
                                        triplets.push(Triplet::new(
                                            r,
                                            c,
                                            ke[(3 * a + i) * 3 * n + 3 * bn + j],
                                        ));
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        (triplets, force)
    }

    /// Each load's box clipped to the body, with its force per unit volume.
    fn densities(&self) -> Vec<([f64; 3], [f64; 3], [f64; 3])> {
        let bounds =
            [0, 1, 2].map(|a| (self.planes[a][0], self.planes[a][self.planes[a].len() - 1]));
        self.loads
            .iter()
            .map(|l| {
                let lo = [0, 1, 2].map(|a| l.lo[a].max(bounds[a].0));
                let hi = [0, 1, 2].map(|a| l.hi[a].min(bounds[a].1));
                let volume: f64 = (0..3).map(|a| (hi[a] - lo[a]).max(0.0)).product();
                (
                    lo,
                    hi,
                    l.total.map(|f| if volume > 0.0 { f / volume } else { 0.0 }),
                )
            })
            .collect()
    }
}

impl Solution {
    /// The displacement at `point` (inside the body or on its boundary).
    pub fn displacement_at(&self, point: [f64; 3]) -> Result<[f64; 3], String> {
        let (p, q) = (self.order, self.order + 1);
        let mut element = [0; 3];
        let mut values = Vec::new();
        for a in 0..3 {
            let planes = &self.planes[a];
            let (first, last) = (planes[0], planes[planes.len() - 1]);
            if !(point[a] >= first && point[a] <= last) {
                return Err(format!(
                    "point {point:?} is outside the body along axis {a} ({first} to {last})"
                ));
            }
            let e = planes
                .partition_point(|&c| c <= point[a])
                .clamp(1, planes.len() - 1)
                - 1;
            element[a] = e;
            let xi = 2.0 * (point[a] - planes[e]) / (planes[e + 1] - planes[e]) - 1.0;
            values.push(basis(p, xi).0);
        }
        let mut u = [0.0; 3];
        for o in 0..q {
            for m in 0..q {
                for l in 0..q {
                    let node = element[0] * p
                        + l
                        + self.nodes[0]
                            * (element[1] * p + m + self.nodes[1] * (element[2] * p + o));
                    let w = values[0][l] * values[1][m] * values[2][o];
                    (0..3).for_each(|i| u[i] += w * self.displacement[node][i]);
                }
            }
        }
        Ok(u)
    }
}

/// Element boundaries from `lo` to `hi` through every break in `breaks` that lies inside,
/// each interval divided into equal elements no longer than `longest`.
pub fn planes_through(lo: f64, hi: f64, breaks: &[f64], longest: f64) -> Vec<f64> {
    let tol = 1e-9 * (hi - lo).abs();
    let mut cuts: Vec<f64> = std::iter::once(lo)
        .chain(
            breaks
                .iter()
                .copied()
                .filter(|&b| b > lo + tol && b < hi - tol),
        )
        .chain(std::iter::once(hi))
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= tol);
    let mut planes = vec![lo];
    for w in cuts.windows(2) {
        let parts = ((w[1] - w[0]) / longest - 1e-9).ceil().max(1.0) as usize;
        planes.extend((1..=parts).map(|k| w[0] + (w[1] - w[0]) * k as f64 / parts as f64));
    }
    planes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_points_integrate_polynomials_exactly() {
        for n in 1..=6 {
            let points = gauss(n);
            for degree in 0..2 * n {
                let sum: f64 = points.iter().map(|&(x, w)| w * x.powi(degree as i32)).sum();
                let exact = if degree % 2 == 1 {
                    0.0
                } else {
                    2.0 / (degree as f64 + 1.0)
                };
                assert!(
                    (sum - exact).abs() < 1e-13,
                    "n = {n}, degree {degree}: {sum} against {exact}"
                );
            }
        }
    }

    /// A bar under a uniform body force along its axis, held at x = 0: u(x) = b(Lx − x²/2)/E
    /// with ν = 0, which quadratic and higher elements reproduce exactly.
    #[test]
    fn a_bar_under_its_own_weight_is_exact_from_order_two() {
        for order in [2, 3] {
            let problem = Problem {
                planes: [
                    planes_through(0.0, 4.0, &[], 1.0),
                    vec![0.0, 1.0],
                    vec![0.0, 1.0],
                ],
                order,
                youngs: 100.0,
                poisson: 0.0,
                supports: vec![
                    Support {
                        at: [Some(0.0), None, None],
                        dofs: [true, false, false],
                    },
                    Support {
                        at: [Some(0.0), Some(0.0), Some(0.0)],
                        dofs: [true, true, true],
                    },
                    Support {
                        at: [Some(0.0), Some(1.0), Some(0.0)],
                        dofs: [true, false, true],
                    },
                    Support {
                        at: [Some(0.0), Some(0.0), Some(1.0)],
                        dofs: [true, true, false],
                    },
                ],
                loads: vec![BodyLoad {
                    lo: [0.0; 3],
                    hi: [4.0, 1.0, 1.0],
                    total: [8.0, 0.0, 0.0],
                }],
            };
            let u = problem.solve().unwrap();
            for x in [0.3, 1.0, 2.5, 4.0] {
                let exact = 2.0 * (4.0 * x - x * x / 2.0) / 100.0;
                let got = u.displacement_at([x, 0.4, 0.7]).unwrap()[0];
                assert!(
                    (got - exact).abs() < 1e-12,
                    "order {order}, x = {x}: {got} against {exact}"
                );
            }
        }
    }
}
