//! Bars as one-dimensional members (docs/theory.md §8): each bar's own bonds are scaled so that the
//! bar carries E·A·ε under a uniform stretch ε, and a bar may be prestrained.
//!
//! A line of particles of volume A·ds bonded with a 3D micromodulus c carries an axial force
//! N = c·ε·A²·ds²·Σₖ k·βₖ (k·ds the bond spans within the horizon): it grows with A/ds² and the
//! horizon, not with E·A. For the thesis's steel at m = 3 that is 0.35·E·A·(A/dx²), so the same
//! bar was 2.3 times too stiff at the thesis's 1 in lattice and 2.7 times too soft at 2.5 in. The factor γ
//! found here multiplies the β of every bond between two particles of the same bar so that N =
//! E·A·ε whatever the lattice. Bonds from a bar to the concrete around it, and between two bars,
//! keep the model's law: they are the interface, not the bar.
//!
//! γ comes from the model's own bond energy (so it holds for every bond-based model): the bar is
//! stretched uniformly by a small strain and the energy of its own bonds at particles at least a
//! horizon from both of its ends is compared with ½·E·ε²·A·ds per particle. State-based models
//! (LPS) keep their bars uncalibrated: a bond's energy there is not its own.

use crate::engine::bonds::BondList;
use crate::engine::particles::Particles;
use crate::input::geometry::{Bar, NOT_A_BAR};
use crate::model::attributes::Attributes;
use crate::model::Model;

/// The strain of the probing stretch (the bond laws are linear there).
const PROBE_STRAIN: f64 = 1e-4;

/// A bar's prestrain: `strain` on its own bonds, reached `transfer_length` from either end
/// and growing linearly from zero at the end over that length (0: in full up to the ends).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Prestrain {
    pub strain: f64,
    pub transfer_length: f64,
}

impl Prestrain {
    /// The strain of a bond whose midpoint lies `from_end` from the nearer end of its bar.
    pub fn at(&self, from_end: f64) -> f64 {
        if self.transfer_length > 0.0 {
            self.strain * (from_end / self.transfer_length).min(1.0)
        } else {
            self.strain
        }
    }
}

/// What the setup applies to the bonds between two particles of one bar.
#[derive(Clone, Debug, Default)]
pub struct BarBonds {
    /// Bar index of each particle by global id ([`NOT_A_BAR`] for lattice particles).
    pub bar_of: Vec<u32>,
    /// Multiplier of the β of each bar's own bonds.
    pub factor: Vec<f64>,
    /// Each bar, for where a bond lies along it.
    pub bars: Vec<Bar>,
    /// Each bar's prestrain (zero strain: none).
    pub prestrain: Vec<Prestrain>,
}

impl BarBonds {
    /// Whether the particles with global ids `a` and `b` are two particles of one bar.
    pub fn same_bar(&self, a: u32, b: u32) -> bool {
        !self.bar_of.is_empty() && {
            let bar = self.bar_of[a as usize];
            bar != NOT_A_BAR && bar == self.bar_of[b as usize]
        }
    }

    /// Applies the factors and prestrains to a store whose particle `l` has global id `gid(l)`.
    /// Run on freshly found bonds, once. The setup has checked that the model accepts each
    /// bar's full prestrain; a model accepts the smaller ones of a transfer length too.
    pub fn apply<M: Model>(
        &self,
        model: &M,
        bonds: &mut BondList<M::Bond>,
        x0: &[[f64; 3]],
        gid: impl Fn(usize) -> u32,
    ) {
        if self.bar_of.is_empty() {
            return;
        }
        self.apply_by_store(model, bonds, x0, |l| self.bar_of[gid(l) as usize]);
    }

    /// [`BarBonds::apply`] to a store whose particle `l` belongs to bar `bar(l)` ([`NOT_A_BAR`]
    /// for a lattice particle): a procCube built on its own knows its particles' bars, not the
    /// scene's.
    pub fn apply_by_store<M: Model>(
        &self,
        model: &M,
        bonds: &mut BondList<M::Bond>,
        x0: &[[f64; 3]],
        bar: impl Fn(usize) -> u32,
    ) {
        if self.factor.is_empty() {
            return;
        }
        for i in 0..bonds.owners() {
            for b in bonds.family(i) {
                let j = bonds.partners()[b] as usize;
                let k = bar(i);
                if k == NOT_A_BAR || k != bar(j) {
                    continue;
                }
                let k = k as usize;
                bonds.geom.scale_beta(b, self.factor[k]);
                let prestrain = self.prestrain[k];
                if prestrain.strain != 0.0 {
                    let (bar, mid) = (
                        &self.bars[k],
                        [0, 1, 2].map(|e| 0.5 * (x0[i][e] + x0[j][e])),
                    );
                    // A periodic image can project outside the bar: never a negative distance.
                    let s = along(bar, &mid).clamp(0.0, bar.length());
                    let strain = prestrain.at(s.min(bar.length() - s));
                    let law = model.law(bar.material, bar.material);
                    if let Ok(h) = model.prestrained(&law, strain) {
                        bonds.history[b] = h;
                    }
                }
            }
        }
    }
}

/// Distance of the projection of `x` on the bar's line from the bar's start.
fn along(bar: &Bar, x: &[f64; 3]) -> f64 {
    let l = bar.length();
    (0..3)
        .map(|k| (x[k] - bar.from[k]) * (bar.to[k] - bar.from[k]) / l)
        .sum()
}

/// How a store takes part in the calibration: the bar of each store particle, and the
/// completion of sums that other procCubes share.
pub struct Share<'a> {
    /// Bar of store particle `l` ([`NOT_A_BAR`] for a lattice particle).
    pub bar: &'a dyn Fn(usize) -> u32,
    /// Adds what ghosts received into their owners (a procCube's reverse messages; nothing for
    /// the whole scene).
    pub complete: &'a mut dyn FnMut(&mut [f64]),
    /// Sums values over every procCube (nothing for the whole scene).
    pub sum: &'a mut dyn FnMut(&mut [f64]),
}

/// γ of each bar (1 for a bar without own bonds): the factor that makes a bar of Young's
/// modulus `modulus[b]` carry E·A·ε. The store holds the families of its owned particles with
/// the bonds' β already final otherwise (partial volume, surface correction).
pub fn calibrate<M: Model>(
    model: &M,
    p: &mut Particles<M>,
    bonds: &BondList<M::Bond>,
    bars: &[Bar],
    modulus: &[f64],
    share: Share,
    horizon: f64,
) -> Vec<f64> {
    let n = p.len();
    let bar = share.bar;
    let axis = |b: &Bar| {
        let l = b.length();
        [0, 1, 2].map(|k| (b.to[k] - b.from[k]) / l)
    };
    let saved = p.alter.clone();
    for i in 0..n {
        if bar(i) == NOT_A_BAR {
            continue;
        }
        let t = axis(&bars[bar(i) as usize]);
        let s = along(&bars[bar(i) as usize], &p.x0[i]);
        let a = p.alter[i].as_mut_slice();
        for k in 0..3 {
            a[k] = p.x0[i][k] + PROBE_STRAIN * s * t[k];
        }
    }
    let mut w = crate::engine::correction::particle_energies(model, p, bonds, |i, j| {
        bar(i) != NOT_A_BAR && bar(i) == bar(j)
    });
    p.alter.clone_from(&saved);
    (share.complete)(&mut w);

    // Per bar: (discrete, continuum) energy over its interior particles and over all of them.
    let mut interior = vec![(0.0, 0.0); bars.len()];
    let mut whole = vec![(0.0, 0.0); bars.len()];
    for (i, &wi) in w.iter().enumerate().take(p.n_owned) {
        let b = bar(i);
        if b == NOT_A_BAR {
            continue;
        }
        let continuum = 0.5 * modulus[b as usize] * PROBE_STRAIN * PROBE_STRAIN * p.volume[i];
        let s = along(&bars[b as usize], &p.x0[i]);
        let sums = if s >= horizon && s <= bars[b as usize].length() - horizon {
            &mut interior[b as usize]
        } else {
            &mut whole[b as usize]
        };
        sums.0 += wi;
        sums.1 += continuum;
    }
    let mut sums: Vec<f64> = interior
        .iter()
        .chain(&whole)
        .flat_map(|&(d, c)| [d, c])
        .collect();
    (share.sum)(&mut sums);
    let pair = |k: usize| (sums[2 * k], sums[2 * k + 1]);
    let (interior, whole): (Vec<_>, Vec<_>) = (
        (0..bars.len()).map(pair).collect(),
        (bars.len()..2 * bars.len()).map(pair).collect(),
    );
    interior
        .iter()
        .zip(&whole)
        .map(|(&inner, &outer)| {
            // A bar shorter than two horizons has no interior: use all of it.
            let (discrete, continuum) = if inner.0 > 0.0 {
                inner
            } else {
                (inner.0 + outer.0, inner.1 + outer.1)
            };
            if discrete > 0.0 {
                continuum / discrete
            } else {
                1.0
            }
        })
        .collect()
}
