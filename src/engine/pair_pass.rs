//! The non-bonded pass: pairs of particles within a pair law's cutoff, found from current
//! positions, beside the bond passes (thesis §2.2, §3.10: Verlet lists with a skin).
//!
//! A half neighbour list (each pair once, from its owned end) holds every pair closer than
//! cutoff + skin when it is built; it stays valid until some particle has moved more than half
//! the skin since (Fincham & Ralston 1981), when the procCube rebuilds it. The list is built
//! from the procCube's cells: each owned cell with itself and its 13 half-shell neighbours,
//! owned or ghost, exactly as bonds are found, so that a pair across a procCube face is found
//! once, on one side. Forces on ghosts go home with the bonds' force return. Buffers keep
//! their capacity from build to build: after the first builds, a step allocates nothing.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::pair::PairLaw;
use crate::model::Model;
use std::ops::Range;

/// Where a list build finds the pairs: the particles of each held cell (owned cells first)
/// and, for each owned cell, the held cells of its 13 half-shell neighbours (`u32::MAX`: none).
pub struct CellPairs<'a> {
    pub cell_range: &'a [Range<usize>],
    pub half_shell: &'a [[u32; 13]],
}

/// What the last evaluation summed over this procCube's pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairTally {
    pub energy: f64,
    /// Σ r·F over pairs (the pairs' part of the virial; pressure P = (2 KE + W)/(3V)).
    pub virial: f64,
    /// Pairs within their cutoff.
    pub pairs: u64,
}

/// The non-bonded forces of a run, whatever its law: one boxed value per procCube, called once
/// per step (no dispatch per pair).
pub trait NonBonded<M: Model>: Send {
    /// Adds every listed pair's force to both ends (ghost ends included), leaving out pairs
    /// whose bond (when the law skips bonded pairs) is still intact.
    fn add_forces(&mut self, p: &mut Particles<M>, bonds: &BondList<M::Bond>);
    /// Whether some owned particle moved more than half the skin since the last build.
    fn moved_too_far(&self, p: &Particles<M>) -> bool;
    /// Rebuilds the list from the current positions.
    fn rebuild(&mut self, p: &Particles<M>, cells: &CellPairs, bonds: &BondList<M::Bond>);
    /// Cutoff + skin: the cells must be at least this wide.
    fn reach(&self) -> f64;
    fn tally(&self) -> PairTally;
    /// Builds so far.
    fn builds(&self) -> u64;
    fn law(&self) -> &'static str;
    /// A copy with an empty list (one per procCube).
    fn fresh(&self) -> Box<dyn NonBonded<M>>;
    /// Forgets where particles were at the last build, so that the next step rebuilds (after a
    /// restart put them elsewhere).
    fn invalidate(&mut self);
    /// The box was stretched by `by` along each axis about `centre` (`[deform]`): the
    /// positions at the last build are mapped along, so that only motion relative to the box
    /// counts against the skin.
    fn deformed(&mut self, centre: [f64; 3], by: [f64; 3]);
}

/// A half neighbour list with its skin, and the law it is evaluated with.
pub struct PairPass<L: PairLaw> {
    law: L,
    skin: f64,
    /// Leave out pairs joined by an intact bond (contact; the membrane's WCA).
    skip_bonded: bool,
    offsets: Vec<u32>,
    partner: Vec<u32>,
    /// For each listed pair, the bond joining it when it was built (`NO_BOND`: none): the pair
    /// acts from the step its bond breaks, so that new crack faces touch without a rebuild.
    bond_of: Vec<u32>,
    /// Owned positions at the last build (mapped with a deforming box).
    at_build: Vec<[f64; 3]>,
    /// How much a deforming box has stretched each axis since the last build.
    stretched: [f64; 3],
    /// Scratch of the build: bond partners of each particle, both ways, with the bond's index.
    bonded_start: Vec<u32>,
    bonded: Vec<(u32, u32)>,
    mark: Vec<u32>,
    mark_bond: Vec<u32>,
    /// Scratch of the build: held positions by coordinate, and one particle's candidates.
    packed: [Vec<f64>; 3],
    found: Vec<u32>,
    /// Scratch of the sweep: one particle's pairs within the cutoff (as many slots as the
    /// longest row of the list).
    near: Vec<Near>,
    tally: PairTally,
    builds: u64,
    /// The material of every particle at the last build, if there is only one.
    single: Option<u16>,
}

impl<L: PairLaw> PairPass<L> {
    pub fn new(law: L, skin: f64, exclude_bonded: bool) -> Self {
        PairPass {
            skip_bonded: exclude_bonded || L::SKIPS_BONDED,
            law,
            skin,
            offsets: vec![0],
            partner: Vec::new(),
            bond_of: Vec::new(),
            at_build: Vec::new(),
            stretched: [1.0; 3],
            bonded_start: Vec::new(),
            bonded: Vec::new(),
            mark: Vec::new(),
            mark_bond: Vec::new(),
            packed: Default::default(),
            found: Vec::new(),
            near: Vec::new(),
            tally: PairTally::default(),
            builds: 0,
            single: None,
        }
    }

    /// Listed partners of owned particle `i`.
    pub fn partners(&self, i: usize) -> &[u32] {
        &self.partner[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Every listed pair's force on both ends; with `SKIP`, not while the pair's bond is intact.
    /// The pairs of a particle within the law's largest cutoff are picked first, without a
    /// branch, and only they are evaluated: listed pairs fall on either side of the cutoff
    /// unpredictably (the skin holds about a third of them), and a mispredicted branch per
    /// pair would cost more than the force.
    fn sweep<M: Model, const SKIP: bool>(
        &mut self,
        p: &mut Particles<M>,
        broken: &[bool],
    ) -> PairTally {
        let single = self.single;
        // The largest cutoff squared, a hair wide: every pair's own cutoff² must lie below it.
        let cut2 = self.law.cutoff() * self.law.cutoff() * (1.0 + 1e-12);
        let mut t = PairTally::default();
        let near = &mut self.near;
        for i in 0..p.n_owned {
            let xi = pos(p, i);
            let mi = p.material[i];
            let listed = self.offsets[i] as usize..self.offsets[i + 1] as usize;
            let mut m = 0;
            for (k, &j) in listed.clone().zip(&self.partner[listed]) {
                if SKIP {
                    let b = self.bond_of[k];
                    if b != NO_BOND && !broken[b as usize] {
                        continue;
                    }
                }
                let xj = pos(p, j as usize);
                let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                near[m] = Near { j, d, r2 };
                m += (r2 < cut2) as usize;
            }
            let mut fi = [0.0; 3];
            for &Near { j, d, r2 } in &near[..m] {
                let j = j as usize;
                let c = match single {
                    Some(s) => self.law.coeff(s, s),
                    None => self.law.coeff(mi, p.material[j]),
                };
                let vv = if L::VOLUMES {
                    p.volume[i] * p.volume[j]
                } else {
                    1.0
                };
                let Some((fr, u)) = self.law.eval(&c, r2, vv) else {
                    continue;
                };
                let f = [fr * d[0], fr * d[1], fr * d[2]];
                let fj = p.force[j].as_mut_slice();
                for k in 0..3 {
                    fi[k] -= f[k];
                    fj[k] += f[k];
                }
                t.energy += u;
                t.virial += fr * r2;
                t.pairs += 1;
            }
            let f = p.force[i].as_mut_slice();
            for k in 0..3 {
                f[k] += fi[k];
            }
        }
        t
    }

    /// Appends owned particle `i`'s partners (`found`) to the list, with the bond joining each
    /// when bonded pairs are skipped.
    fn list(&mut self, i: usize) {
        self.partner.extend_from_slice(&self.found);
        if self.skip_bonded {
            let s = self.bonded_start[i] as usize..self.bonded_start[i + 1] as usize;
            for &(j, k) in &self.bonded[s] {
                self.mark[j as usize] = i as u32;
                self.mark_bond[j as usize] = k;
            }
            let (mark, mark_bond) = (&self.mark, &self.mark_bond);
            self.bond_of.extend(self.found.iter().map(|&j| {
                let bonded = mark[j as usize] == i as u32;
                if bonded {
                    mark_bond[j as usize]
                } else {
                    NO_BOND
                }
            }));
        }
        self.offsets[i + 1] = self.partner.len() as u32;
    }

    /// Every intact bond's two ends, as lists per particle (owned and ghost).
    fn index_bonds<H: Attributes>(&mut self, n: usize, bonds: &BondList<H>) {
        self.bonded_start.clear();
        self.bonded_start.resize(n + 1, 0);
        for (i, j, k) in bonds.iter() {
            if !bonds.broken[k] {
                self.bonded_start[i + 1] += 1;
                self.bonded_start[j + 1] += 1;
            }
        }
        for i in 0..n {
            self.bonded_start[i + 1] += self.bonded_start[i];
        }
        self.bonded.clear();
        self.bonded.resize(self.bonded_start[n] as usize, (0, 0));
        // `mark` doubles as the fill cursor here; it is reset below.
        self.mark.clear();
        self.mark.extend_from_slice(&self.bonded_start[..n]);
        for (i, j, k) in bonds.iter() {
            if !bonds.broken[k] {
                self.bonded[self.mark[i] as usize] = (j as u32, k as u32);
                self.mark[i] += 1;
                self.bonded[self.mark[j] as usize] = (i as u32, k as u32);
                self.mark[j] += 1;
            }
        }
        self.mark.iter_mut().for_each(|m| *m = u32::MAX);
        self.mark_bond.clear();
        self.mark_bond.resize(n, NO_BOND);
    }
}

#[inline(always)]
fn pos<M: Model>(p: &Particles<M>, i: usize) -> [f64; 3] {
    let a = p.alter[i].as_slice();
    [a[0], a[1], a[2]]
}

/// A listed pair in the sweep: the partner, x_j − x_i and its square length.
#[derive(Clone, Copy, Debug, Default)]
struct Near {
    j: u32,
    d: [f64; 3],
    r2: f64,
}

/// No bond joins the pair.
const NO_BOND: u32 = u32::MAX;

impl<M: Model, L: PairLaw> NonBonded<M> for PairPass<L> {
    fn add_forces(&mut self, p: &mut Particles<M>, bonds: &BondList<M::Bond>) {
        assert_eq!(
            self.offsets.len(),
            p.n_owned + 1,
            "the neighbour list was not built for these particles"
        );
        // Laws that never skip bonded pairs (LJ and friends) read no bond index per pair.
        self.tally = if self.skip_bonded {
            self.sweep::<M, true>(p, &bonds.broken)
        } else {
            self.sweep::<M, false>(p, &[])
        };
    }

    fn moved_too_far(&self, p: &Particles<M>) -> bool {
        if self.at_build.len() != p.n_owned {
            return true;
        }
        // A box shrunk by λ < 1 since the build brought pairs closer by up to (1 − λ)·reach
        // on top of their own motion: that much less skin is left for it.
        let lambda = self.stretched.iter().fold(1.0f64, |m, &s| m.min(s));
        let reach = self.law.cutoff() + self.skin;
        let margin = self.skin - (1.0 - lambda) * reach;
        if margin <= 0.0 {
            return true;
        }
        let limit = 0.25 * margin * margin;
        (0..p.n_owned).any(|i| {
            let (a, b) = (pos(p, i), self.at_build[i]);
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > limit
        })
    }

    fn rebuild(&mut self, p: &Particles<M>, cells: &CellPairs, bonds: &BondList<M::Bond>) {
        let n = p.len();
        if self.skip_bonded {
            self.index_bonds(n, bonds);
        }
        let reach = <Self as NonBonded<M>>::reach(self);
        self.single = single_material(&p.material);
        // Coordinates apart and contiguous, so that the distance test runs in vector lanes.
        for (a, xs) in self.packed.iter_mut().enumerate() {
            xs.clear();
            xs.extend((0..n).map(|i| p.alter[i].as_slice()[a]));
        }
        self.offsets.clear();
        self.offsets.resize(p.n_owned + 1, 0);
        self.partner.clear();
        self.bond_of.clear();
        let mut runs: Vec<Range<usize>> = Vec::with_capacity(14);
        for (k, shell) in cells.half_shell.iter().enumerate() {
            let own = cells.cell_range[k].clone();
            // The half shell's cells as runs of the store: neighbours along a row of cells
            // are usually adjacent there, and longer runs fill the vector lanes better.
            runs.clear();
            runs.extend(
                shell
                    .iter()
                    .filter(|&&q| q != u32::MAX)
                    .map(|&q| cells.cell_range[q as usize].clone())
                    .filter(|r| !r.is_empty()),
            );
            runs.sort_unstable_by_key(|r| r.start);
            merge_runs(&mut runs);
            // The run that continues this cell, if any, is scanned with its rest.
            let after = runs.iter().position(|r| r.start == own.end);
            for i in own.clone() {
                self.found.clear();
                let mut rest = i + 1..own.end;
                if let Some(a) = after {
                    rest.end = runs[a].end;
                }
                within(&self.packed, i, rest, reach, &mut self.found);
                for (n, r) in runs.iter().enumerate() {
                    if Some(n) != after {
                        within(&self.packed, i, r.clone(), reach, &mut self.found);
                    }
                }
                self.list(i);
            }
        }
        let longest = self
            .offsets
            .windows(2)
            .map(|w| w[1] - w[0])
            .max()
            .unwrap_or(0);
        self.near.resize(longest as usize, Near::default());
        self.at_build.clear();
        self.at_build.extend((0..p.n_owned).map(|i| pos(p, i)));
        self.stretched = [1.0; 3];
        self.builds += 1;
    }

    fn reach(&self) -> f64 {
        self.law.cutoff() + self.skin
    }

    fn tally(&self) -> PairTally {
        self.tally
    }

    fn builds(&self) -> u64 {
        self.builds
    }

    fn law(&self) -> &'static str {
        L::NAME
    }

    fn invalidate(&mut self) {
        self.at_build.clear();
    }

    fn deformed(&mut self, centre: [f64; 3], by: [f64; 3]) {
        for x in &mut self.at_build {
            for a in 0..3 {
                x[a] = centre[a] + (x[a] - centre[a]) * by[a];
            }
        }
        for (s, b) in self.stretched.iter_mut().zip(by) {
            *s *= b;
        }
    }

    fn fresh(&self) -> Box<dyn NonBonded<M>> {
        Box::new(PairPass::new(self.law.clone(), self.skin, self.skip_bonded))
    }
}

/// Appends to `found` the particles of `range` closer to particle `i` than `reach`. The
/// distances of a block are computed first and the hits written without a branch: most
/// candidates miss, and a branch per candidate would be mispredicted at every hit.
fn within(xs: &[Vec<f64>; 3], i: usize, range: Range<usize>, reach: f64, found: &mut Vec<u32>) {
    const BLOCK: usize = 32;
    let r2max = reach * reach;
    let xi = [xs[0][i], xs[1][i], xs[2][i]];
    let mut start = range.start;
    while start < range.end {
        let len = BLOCK.min(range.end - start);
        let (x, y, z) = (
            &xs[0][start..start + len],
            &xs[1][start..start + len],
            &xs[2][start..start + len],
        );
        let mut hits = 0u32;
        for t in 0..len {
            let d = [x[t] - xi[0], y[t] - xi[1], z[t] - xi[2]];
            let hit = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < r2max;
            hits |= (hit as u32) << t;
        }
        // Only the hits cost from here on.
        while hits != 0 {
            found.push(start as u32 + hits.trailing_zeros());
            hits &= hits - 1;
        }
        start += len;
    }
}

/// Joins runs (sorted by start) that follow one another.
fn merge_runs(runs: &mut Vec<Range<usize>>) {
    let mut kept = 0;
    for n in 0..runs.len() {
        if kept > 0 && runs[kept - 1].end == runs[n].start {
            runs[kept - 1].end = runs[n].end;
        } else {
            runs[kept] = runs[n].clone();
            kept += 1;
        }
    }
    runs.truncate(kept);
}

/// The material of every particle, if there is only one.
fn single_material(material: &[u16]) -> Option<u16> {
    let first = *material.first()?;
    material.iter().all(|&m| m == first).then_some(first)
}
