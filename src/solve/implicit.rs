//! The factored tangent of the implicit static solve ([`crate::solve::Newton`]): the tangent
//! stiffness assembled as a sparse matrix and factored by `faer` (sparse Cholesky; once bonds
//! have broken, Cholesky with a slightly raised diagonal; LU if neither works), after checks
//! that the factor fits in memory, one before the assembly (from the particles' coupling
//! pattern) and one after it. For elastic states Newton reaches equilibrium with it in a
//! few force evaluations per load step where relaxation needs thousands. Where it does not fit,
//! or the layout has several procCubes, Newton solves matrix-free (`solve/krylov.rs`).
//!
//! The tangent is assembled from the engine's own force evaluation, for every model alike
//! (bond-based, state-based, micropolar): columns by central differences, many at once. Two
//! particles may be perturbed together when no particle's force depends on both: forces reach
//! one bond length for a bond-based model and two for a model with a state pass (a state sums
//! over a family), so particles more than twice that reach apart share a "colour". Each colour
//! costs 2 force evaluations per degree of freedom. Rotations are perturbed through the model's
//! own `drift`, so finite-rotation coordinates (quaternions) are handled as the integrator
//! handles them. Supported DOFs are eliminated. One procCube only: the matrix is assembled and
//! factored in one process.

use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::{second_order, Model, Side};
use crate::parallel::Cube;
use faer::prelude::Solve;
use faer::sparse::{SparseColMat, SymbolicSparseColMatRef, Triplet};
use std::time::Instant;

/// Relative size of the finite-difference perturbation: of the shortest bond for lengths, in
/// radians for rotations.
const PERTURBATION: f64 = 1e-6;

enum Factor {
    Cholesky(faer::sparse::linalg::solvers::Llt<usize, f64>),
    Lu(Box<faer::sparse::linalg::solvers::Lu<usize, f64>>),
}

/// The factored tangent stiffness over the free degrees of freedom.
pub struct Tangent {
    /// Free DOF index of (particle · n₂ + k), or `usize::MAX` for a supported one.
    index: Vec<usize>,
    free: usize,
    factor: Factor,
    /// Force evaluations the assembly took.
    pub evaluations: u64,
    pub nonzeros: usize,
    pub colours: usize,
    /// "Cholesky", "Cholesky, shifted" or "LU".
    pub method: &'static str,
    pub seconds: f64,
}

/// Particles in colours: no two of a colour within `2 × reach` of each other (reference
/// positions), greedily in store order.
fn colour(x0: &[[f64; 3]], reach: f64) -> Vec<Vec<usize>> {
    let d = 2.0 * reach * (1.0 + 1e-9);
    let lo = x0.iter().fold([f64::INFINITY; 3], |m, p| {
        [m[0].min(p[0]), m[1].min(p[1]), m[2].min(p[2])]
    });
    let key = |p: &[f64; 3]| [0, 1, 2].map(|a| ((p[a] - lo[a]) / d).floor() as i64);
    let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
    for (i, p) in x0.iter().enumerate() {
        cells.entry(key(p)).or_default().push(i);
    }
    let mut of = vec![usize::MAX; x0.len()];
    let mut colours: Vec<Vec<usize>> = Vec::new();
    let mut taken: Vec<bool> = Vec::new();
    for (i, p) in x0.iter().enumerate() {
        taken.iter_mut().for_each(|t| *t = false);
        let c = key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &j in list {
                        let q = x0[j];
                        let r2 = (0..3).map(|a| (q[a] - p[a]).powi(2)).sum::<f64>();
                        if of[j] != usize::MAX && r2 <= d * d {
                            taken[of[j]] = true;
                        }
                    }
                }
            }
        }
        let k = taken.iter().position(|t| !t).unwrap_or(colours.len());
        if k == colours.len() {
            colours.push(Vec::new());
            taken.push(false);
        }
        colours[k].push(i);
        of[i] = k;
    }
    colours
}

/// Moves DOF `k` of a particle by `amount` through the model's drift (a rotation composes).
fn nudge<M: Model>(model: &M, a: &mut M::Alter, k: usize, amount: f64) {
    let n2 = second_order::<M>();
    // A copy of the record, not a Vec: this runs 4·n₂ times per bond during assembly.
    let saved = *a;
    let s = a.as_mut_slice();
    s[n2..2 * n2].fill(0.0);
    s[n2 + k] = amount;
    model.drift(a, 1.0);
    a.as_mut_slice()[n2..2 * n2].copy_from_slice(&saved.as_slice()[n2..2 * n2]);
}

/// The tangent of a model without a state pass, bond by bond: each intact bond's forces on
/// its two ends depend on those two ends only, so central differences of `Model::pair` give
/// the bond's 2n₂ × 2n₂ block, 4n₂ bond calls per bond (as many as 4n₂ force passes). Lower
/// triangle, as triplets over the free DOFs.
fn bond_blocks<M: Model>(
    model: &M,
    p: &Particles<M>,
    bonds: &crate::engine::bonds::BondList<M::Bond>,
    index: &[usize],
    h_length: f64,
) -> Vec<Triplet<usize, usize, f64>> {
    let n2 = second_order::<M>();
    let w = 2 * n2;
    let mut diagonal = vec![0.0; p.n_owned * n2 * n2];
    let mut triplets = Vec::new();
    let mut block = vec![0.0; w * w];
    let (mut plus, mut minus) = (vec![0.0; w], vec![0.0; w]);
    'bonds: for (i, j, b) in bonds.iter() {
        if bonds.broken[b] {
            continue;
        }
        let law = model.law(p.material[i], p.material[j]);
        for col in 0..w {
            let (end, k) = (col / n2, col % n2);
            let h = if k < 3 { h_length } else { PERTURBATION };
            for (sign, out) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                let (mut ai, mut aj) = (p.alter[i], p.alter[j]);
                nudge(model, if end == 0 { &mut ai } else { &mut aj }, k, sign * h);
                let side = |e: usize, a| Side::<M> {
                    x0: &p.x0[e],
                    volume: p.volume[e],
                    material: p.material[e],
                    alter: a,
                    fixed: &p.fixed[e],
                    state: &p.state[e],
                };
                let mut history = bonds.history[b];
                // A bond that would break under a nudge is left out of the tangent: on the
                // verge of breaking, it carries no stiffness worth counting, and half a
                // difference (force on one side, none on the other) would be a huge entry
                // that spoils the matrix's definiteness.
                let Some((fi, fj)) = model.pair(
                    &law,
                    &side(i, &ai),
                    &side(j, &aj),
                    &bonds.geom[b],
                    &mut history,
                ) else {
                    continue 'bonds;
                };
                out[..n2].copy_from_slice(&fi.as_slice()[..n2]);
                out[n2..].copy_from_slice(&fj.as_slice()[..n2]);
            }
            for row in 0..w {
                block[row * w + col] = -(plus[row] - minus[row]) / (2.0 * h);
            }
        }
        let particle = [i, j];
        for row in 0..w {
            for col in 0..w {
                let (pr, pc) = (particle[row / n2], particle[col / n2]);
                let v = block[row * w + col];
                if pr == pc {
                    diagonal[(pr * n2 + row % n2) * n2 + col % n2] += v;
                    continue;
                }
                let (r, c) = (index[pr * n2 + row % n2], index[pc * n2 + col % n2]);
                if r != usize::MAX && c != usize::MAX && r >= c && v != 0.0 {
                    triplets.push(Triplet::new(r, c, v));
                }
            }
        }
    }
    for i in 0..p.n_owned {
        for k in 0..n2 {
            for l in 0..n2 {
                let (r, c) = (index[i * n2 + k], index[i * n2 + l]);
                let v = diagonal[(i * n2 + k) * n2 + l];
                if r != usize::MAX && c != usize::MAX && r >= c && v != 0.0 {
                    triplets.push(Triplet::new(r, c, v));
                }
            }
        }
    }
    triplets
}

/// Why the tangent was not factored.
#[derive(Debug)]
pub enum NoTangent {
    /// The factor would not fit in memory: the matrix-free solve needs none.
    WouldNotFit(String),
    Failed(String),
}

impl From<String> for NoTangent {
    fn from(e: String) -> Self {
        NoTangent::Failed(e)
    }
}

impl From<NoTangent> for String {
    fn from(e: NoTangent) -> Self {
        match e {
            NoTangent::WouldNotFit(e) | NoTangent::Failed(e) => e,
        }
    }
}

/// The factor may take at most this fraction of the memory the system reports available. The
/// estimate below is already generous (twice the factor's values: the full micropolar beam's
/// estimate was 26.5 GiB; the kernel killed it at 24 GiB), so all of it.
const FACTOR_MEMORY_SHARE: f64 = 1.0;

/// Refuses, with the sizes, a tangent whose Cholesky factor would not fit in memory: the
/// symbolic factorization (ordering and column counts, cheap) gives the factor's nonzeros
/// before any memory is spent on it. Without this check an oversized factor is not an error
/// but the kernel's out-of-memory kill, after an hour and with the run's results lost.
fn check_factor_memory(lower: &SparseColMat<usize, f64>, free: usize) -> Result<(), NoTangent> {
    let values = symbolic_values(lower.symbolic())?;
    let needed = FACTOR_BYTES_PER_VALUE * values as f64;
    refuse_beyond_available(needed, |gib| {
        format!("the implicit solve's factored tangent would need about {gib} ({values} nonzeros over {free} free DOFs)")
    })
}

/// Bytes per value of the factor: the value, and about as much again for row indices and the
/// numeric phase's workspace.
const FACTOR_BYTES_PER_VALUE: f64 = 2.0 * std::mem::size_of::<f64>() as f64;

/// Bytes per value of the tangent's lower triangle while it is factored: its triplet (kept for
/// the fallbacks) and its compressed column.
const TANGENT_BYTES_PER_VALUE: f64 = (std::mem::size_of::<Triplet<usize, usize, f64>>()
    + std::mem::size_of::<usize>()
    + std::mem::size_of::<f64>()) as f64;

/// The nonzeros of the Cholesky factor of the lower triangle `pattern`, in faer's ordering.
fn symbolic_values(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<usize, String> {
    let symbolic = faer::sparse::linalg::cholesky::factorize_symbolic_cholesky(
        pattern,
        faer::Side::Lower,
        Default::default(),
        Default::default(),
    )
    .map_err(|e| format!("ordering the tangent stiffness: {e:?}"))?;
    Ok(symbolic.len_val())
}

/// `Err(WouldNotFit)` when `needed` bytes exceed the memory available; `what(amount)` says
/// what needs them.
fn refuse_beyond_available(needed: f64, what: impl Fn(&str) -> String) -> Result<(), NoTangent> {
    let Some(available) = available_memory() else {
        return Ok(());
    };
    if needed <= FACTOR_MEMORY_SHARE * available {
        return Ok(());
    }
    let gib = |b: f64| format!("{:.1} GiB", b / (1u64 << 30) as f64);
    Err(NoTangent::WouldNotFit(format!(
        "{}, more than the {} of memory available",
        what(&gib(needed)),
        gib(FACTOR_MEMORY_SHARE * available)
    )))
}

/// Which particles' forces depend on which, as the lower triangle of a particle-by-particle
/// matrix (the diagonal included), compressed by column with rows sorted: the tangent's
/// pattern before any force is evaluated, each entry standing for an n₂ × n₂ block.
struct ParticlePattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl ParticlePattern {
    /// From each particle's coupled particles (`coupled(c, out)` fills `out`, in any order,
    /// possibly with repeats and with `c` itself); only those at or after `c` are kept.
    fn by_column(n: usize, mut coupled: impl FnMut(usize, &mut Vec<usize>)) -> Self {
        let (mut col_ptr, mut row_idx, mut rows) = (vec![0], Vec::new(), Vec::new());
        for c in 0..n {
            coupled(c, &mut rows);
            rows.retain(|&r| r > c);
            rows.push(c);
            rows.sort_unstable();
            rows.dedup();
            row_idx.extend_from_slice(&rows);
            col_ptr.push(row_idx.len());
        }
        ParticlePattern { col_ptr, row_idx }
    }

    /// From the pairs of a bond list (each bond once, from either end).
    fn of_bonds<H: Attributes>(n: usize, bonds: &crate::engine::bonds::BondList<H>) -> Self {
        let mut by_particle: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (i, j, b) in bonds.iter() {
            if !bonds.broken[b] && i != j {
                by_particle[i.min(j)].push(i.max(j) as u32);
            }
        }
        Self::by_column(n, |c, out| {
            out.clear();
            out.extend(by_particle[c].iter().map(|&r| r as usize));
            by_particle[c] = Vec::new();
        })
    }

    fn particles(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// Refuses, before the assembly, a tangent whose assembly and factor would not fit in
    /// memory: the particle pattern's symbolic factorization, each entry an n₂ × n₂ block
    /// (a triangle on the diagonal), estimates the factor's nonzeros as the check after the
    /// assembly counts them. A refusal after the assembly would come after a state-based
    /// model's colours of force evaluations (minutes to hours at 10⁵ particles), and the
    /// assembly's triplets alone can take the memory of a scene whose factor does not fit.
    fn check_memory(&self, n2: usize) -> Result<(), NoTangent> {
        let n = self.particles();
        let pattern =
            SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let blocks = |entries: usize| (n2 * n2 * (entries - n) + n2 * (n2 + 1) / 2 * n) as f64;
        // The estimate came out 2–6 % above the DOF pattern's own count on the test's cubes
        // and 27 % below it on the full micropolar beam (1.30e9 against 1.78e9: faer orders
        // the DOF pattern with more fill than the particle one). A tenth off it keeps this
        // check from refusing what the exact check would pass; an underestimate leaves the
        // refusal to that check.
        let factor = 0.9 * blocks(symbolic_values(pattern)?);
        let tangent = blocks(self.row_idx.len());
        let needed = FACTOR_BYTES_PER_VALUE * factor + TANGENT_BYTES_PER_VALUE * tangent;
        refuse_beyond_available(needed, |gib| {
            format!("the implicit solve's tangent and its factor would need about {gib} (about {factor:.3e} nonzeros in the factor, {n} particles of {n2} DOFs)")
        })
    }
}

/// Bytes of memory available to new allocations (Linux `MemAvailable`), if known.
fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// Relative shift of the diagonal that makes a nearly positive definite tangent factorable.
const DIAGONAL_SHIFT: f64 = 1e-6;

/// Cholesky of the lower triangle with each diagonal entry raised by [`DIAGONAL_SHIFT`] of
/// itself. A tangent loses definiteness when a bond on the verge of breaking breaks under one
/// finite-difference perturbation and not under the other; the shifted matrix is a slightly
/// stiffer tangent, which modified Newton converges with, where an LU of a 3D lattice's
/// matrix takes minutes (its column ordering alone).
pub(super) fn shifted_cholesky(
    triplets: &[Triplet<usize, usize, f64>],
    free: usize,
) -> Option<faer::sparse::linalg::solvers::Llt<usize, f64>> {
    let shifted: Vec<Triplet<usize, usize, f64>> = triplets
        .iter()
        .map(|t| {
            let v = if t.row == t.col {
                t.val + DIAGONAL_SHIFT * t.val.abs()
            } else {
                t.val
            };
            Triplet::new(t.row, t.col, v)
        })
        .collect();
    SparseColMat::<usize, f64>::try_new_from_triplets(free, free, &shifted)
        .ok()?
        .sp_cholesky(faer::Side::Lower)
        .ok()
}

/// Factors the lower triangle given as triplets: Cholesky, else (with `broken` bonds) Cholesky
/// with a slightly raised diagonal, else LU of the whole matrix.
fn factor(
    triplets: Vec<Triplet<usize, usize, f64>>,
    index: Vec<usize>,
    free: usize,
    broken: usize,
    evaluations: u64,
    colours: usize,
    start: Instant,
) -> Result<Tangent, NoTangent> {
    let nonzeros = triplets.len();
    let lower = SparseColMat::<usize, f64>::try_new_from_triplets(free, free, &triplets)
        .map_err(|e| format!("assembling the tangent stiffness: {e:?}"))?;
    check_factor_memory(&lower, free)?;
    let (factor, method) = match lower.sp_cholesky(faer::Side::Lower) {
        Ok(f) => (Factor::Cholesky(f), "Cholesky"),
        // Only once bonds have broken: an intact scene that is not positive definite has a
        // mechanism (supports leaving a rigid-body motion free), which a shift would hide.
        Err(_) => match shifted_cholesky(&triplets, free).filter(|_| broken > 0) {
            Some(f) => (Factor::Cholesky(f), "Cholesky, shifted"),
            None => {
                // Not positive definite (a model without a potential, or a mechanism): LU of
                // the whole matrix.
                let mut full = triplets.clone();
                full.extend(
                    triplets
                        .iter()
                        .filter(|t| t.row != t.col)
                        .map(|t| Triplet::new(t.col, t.row, t.val)),
                );
                let a = SparseColMat::<usize, f64>::try_new_from_triplets(free, free, &full)
                    .map_err(|e| format!("assembling the tangent stiffness: {e:?}"))?;
                let lu = a.sp_lu().map_err(|e| {
                    format!("the tangent stiffness is singular ({e:?}): the supports leave a rigid-body motion or a loose particle free; support the body")
                })?;
                (Factor::Lu(Box::new(lu)), "LU")
            }
        },
    };
    Ok(Tangent {
        index,
        free,
        factor,
        evaluations,
        nonzeros,
        colours,
        method,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Assembles and factors the tangent stiffness at the current state. Bonds, their
/// history and the forces are left as they were.
pub fn assemble_tangent<M: Model>(cube: &mut Cube<M>) -> Result<Tangent, NoTangent> {
    let start = Instant::now();
    let n2 = second_order::<M>();
    let n = cube.sim.particles.n_owned;
    if cube.layout.domain.periodic.iter().any(|&p| p) {
        return Err(NoTangent::Failed("the implicit solve does not handle periodic axes (it finds who feels whom from reference positions)".into()));
    }
    if cube.sim.particles.len() != n || cube.wall.transport().size() != 1 {
        return Err(NoTangent::Failed(
            "the factored tangent is assembled on one procCube (--threads 1, no mpirun)".into(),
        ));
    }
    // Supported DOFs.
    let mut free = 0;
    let index: Vec<usize> = (cube.sim.free_dofs().iter())
        .map(|&f| {
            if f {
                free += 1;
                free - 1
            } else {
                usize::MAX
            }
        })
        .collect();
    // Reach of a particle's force: the longest bond, twice over a state pass.
    let sim = &cube.sim;
    let (mut longest, mut shortest) = (0.0f64, f64::INFINITY);
    for g in sim.bonds.geom.iter() {
        longest = longest.max(g.length);
        shortest = shortest.min(g.length);
    }
    if longest == 0.0 {
        return Err(NoTangent::Failed(
            "the implicit solve needs bonds: the scene has none".into(),
        ));
    }
    if <M::State as Attributes>::LEN == 0 {
        ParticlePattern::of_bonds(n, &sim.bonds).check_memory(n2)?;
        let triplets = bond_blocks(
            &sim.model,
            &sim.particles,
            &sim.bonds,
            &index,
            PERTURBATION * shortest,
        );
        let broken = sim.bonds.broken_count();
        return factor(triplets, index, free, broken, 4 * n2 as u64, 0, start);
    }
    state_tangent(cube, index, free, shortest, 2.0 * longest, start)
}

/// The tangent of a state-based model by central differences of the force: particles of
/// one colour (farther apart than `reach`, which a force's dependence spans: a state sums
/// over a family, so two bond lengths) are nudged together, one DOF at a time.
fn state_tangent<M: Model>(
    cube: &mut Cube<M>,
    index: Vec<usize>,
    free: usize,
    shortest: f64,
    reach: f64,
    start: Instant,
) -> Result<Tangent, NoTangent> {
    let n2 = second_order::<M>();
    let n = cube.sim.particles.n_owned;
    let neighbours = Neighbours::new(&cube.sim.particles.x0[..n], reach);
    ParticlePattern::by_column(n, |c, out| neighbours.within(c, out)).check_memory(n2)?;
    let colours = colour(&cube.sim.particles.x0[..n], reach);
    let saved_alter = cube.sim.particles.alter.clone();
    let saved_broken = cube.sim.bonds.broken.clone();
    let broken = saved_broken.iter().filter(|&&b| b).count();
    let saved_history = cube.sim.bonds.history.clone();
    let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut plus = vec![0.0; n * n2];
    let mut rows = Vec::new();
    let mut evaluations = 0u64;
    let owned = |p: &Particles<M>, out: &mut Vec<f64>| {
        for (i, f) in p.force[..n].iter().enumerate() {
            out[i * n2..(i + 1) * n2].copy_from_slice(&f.as_slice()[..n2]);
        }
    };
    let mut minus = vec![0.0; n * n2];
    for members in &colours {
        for k in 0..n2 {
            let h = if k < 3 {
                PERTURBATION * shortest
            } else {
                PERTURBATION
            };
            let free_members: Vec<usize> = members
                .iter()
                .copied()
                .filter(|&i| index[i * n2 + k] != usize::MAX)
                .collect();
            if free_members.is_empty() {
                continue;
            }
            for (sign, out) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                let sim = &mut cube.sim;
                for &i in &free_members {
                    sim.particles.alter[i] = saved_alter[i];
                    nudge(&sim.model, &mut sim.particles.alter[i], k, sign * h);
                }
                sim.compute_forces_with(&mut cube.wall);
                evaluations += 1;
                owned(&sim.particles, out);
                for &i in &free_members {
                    sim.particles.alter[i] = saved_alter[i];
                }
            }
            for &i in &free_members {
                let col = index[i * n2 + k];
                neighbours.within(i, &mut rows);
                for &j in &rows {
                    for l in 0..n2 {
                        let row = index[j * n2 + l];
                        if row == usize::MAX || row < col {
                            continue; // the lower triangle is what Cholesky reads
                        }
                        // K = −∂F/∂u.
                        let v = -(plus[j * n2 + l] - minus[j * n2 + l]) / (2.0 * h);
                        if v != 0.0 {
                            triplets.push(Triplet::new(row, col, v));
                        }
                    }
                }
            }
        }
    }
    cube.sim.particles.alter = saved_alter;
    cube.sim.bonds.broken = saved_broken;
    cube.sim.bonds.history = saved_history;
    cube.compute_forces();
    factor(
        triplets,
        index,
        free,
        broken,
        evaluations,
        colours.len(),
        start,
    )
}

impl Tangent {
    /// δ = K⁻¹F on the owned DOFs in store order (`force`: F on them; zero at supported DOFs).
    pub fn solve(&self, force: &[f64]) -> Vec<f64> {
        let mut rhs = faer::Mat::<f64>::zeros(self.free, 1);
        for (idx, &f) in force.iter().enumerate() {
            let r = self.index[idx];
            if r != usize::MAX {
                rhs[(r, 0)] = f;
            }
        }
        match &self.factor {
            Factor::Cholesky(f) => f.solve_in_place(rhs.as_mut()),
            Factor::Lu(f) => f.solve_in_place(rhs.as_mut()),
        }
        (self.index.iter())
            .map(|&r| if r == usize::MAX { 0.0 } else { rhs[(r, 0)] })
            .collect()
    }
}

/// Who can feel a particle: the particles within `reach` of it (reference positions), found
/// through cells of that size.
struct Neighbours {
    x0: Vec<[f64; 3]>,
    cell: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<usize>>,
}

impl Neighbours {
    fn new(x0: &[[f64; 3]], reach: f64) -> Self {
        let cell = reach * (1.0 + 1e-9);
        let mut n = Neighbours {
            x0: x0.to_vec(),
            cell,
            cells: Default::default(),
        };
        for (i, p) in x0.iter().enumerate() {
            let k = n.key(p);
            n.cells.entry(k).or_default().push(i);
        }
        n
    }

    fn key(&self, p: &[f64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|a| (p[a] / self.cell).floor() as i64)
    }

    /// The particles within reach of `i` (itself included) into `out`.
    fn within(&self, i: usize, out: &mut Vec<usize>) {
        out.clear();
        let (p, c) = (self.x0[i], self.key(&self.x0[i]));
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &j in list {
                            let r2 = (0..3).map(|a| (self.x0[j][a] - p[a]).powi(2)).sum::<f64>();
                            if r2 <= self.cell * self.cell {
                                out.push(j);
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cube of `side`³ lattice sites, each coupled to the sites within `reach` spacings.
    fn lattice(side: usize, reach: f64) -> (Vec<[f64; 3]>, Neighbours) {
        let x0: Vec<[f64; 3]> = (0..side * side * side)
            .map(|i| [i % side, i / side % side, i / (side * side)].map(|c| c as f64))
            .collect();
        let neighbours = Neighbours::new(&x0, reach);
        (x0, neighbours)
    }

    /// The factor's nonzeros estimated from the particle pattern, against those of the
    /// DOF-level pattern that the assembly would give (every block full): the check before
    /// the assembly must not refuse what the check after it would let through.
    #[test]
    fn the_particle_pattern_estimates_the_factor_of_the_dof_pattern() {
        for (n2, side, reach) in [(3, 8, 3.0), (6, 8, 2.0), (3, 10, 2.0), (3, 7, 6.0)] {
            let (x0, neighbours) = lattice(side, reach);
            let n = x0.len();
            let pattern = ParticlePattern::by_column(n, |c, out| neighbours.within(c, out));
            let blocks = |entries: usize| n2 * n2 * (entries - n) + n2 * (n2 + 1) / 2 * n;
            let particles = SymbolicSparseColMatRef::new_checked(
                n,
                n,
                &pattern.col_ptr,
                None,
                &pattern.row_idx,
            );
            let estimate = blocks(symbolic_values(particles).unwrap());
            let (mut col_ptr, mut row_idx) = (vec![0], Vec::new());
            for c in 0..n * n2 {
                let (pc, k) = (c / n2, c % n2);
                for &pr in &pattern.row_idx[pattern.col_ptr[pc]..pattern.col_ptr[pc + 1]] {
                    let first = if pr == pc { k } else { 0 };
                    row_idx.extend((first..n2).map(|l| pr * n2 + l));
                }
                col_ptr.push(row_idx.len());
            }
            assert_eq!(row_idx.len(), blocks(pattern.row_idx.len()));
            let dofs =
                SymbolicSparseColMatRef::new_checked(n * n2, n * n2, &col_ptr, None, &row_idx);
            let exact = symbolic_values(dofs).unwrap();
            let ratio = estimate as f64 / exact as f64;
            // Measured 1.02 to 1.06 on these; below about 500 particles (a nearly dense factor)
            // the two orderings part more (0.70 at 6³ sites, n2 = 6).
            assert!(
                (0.9..=1.1).contains(&ratio),
                "n2 = {n2}, {side}³ sites, reach {reach}: estimate {estimate}, DOF pattern {exact} (ratio {ratio:.3})"
            );
        }
    }

    /// Pairs given from either end, repeated, or with the particle itself make one entry each,
    /// sorted, with the diagonal.
    #[test]
    fn a_particle_pattern_is_sorted_without_repeats() {
        let pairs = [vec![2, 1, 2, 0], vec![0, 3], vec![], vec![1, 3, 3]];
        let p = ParticlePattern::by_column(4, |c, out| {
            out.clear();
            out.extend(&pairs[c]);
        });
        assert_eq!(p.col_ptr, [0, 3, 5, 6, 7]);
        assert_eq!(p.row_idx, [0, 1, 2, 1, 3, 2, 3]);
    }
}
