//! Lennard-Jones 12-6 with a cutoff: U(r) = 4ε[(σ/r)¹² − (σ/r)⁶] for r < r_c, optionally
//! shifted by −U(r_c) so that the energy is continuous (the force is not shifted), as LAMMPS's
//! `pair_style lj/cut` with `pair_modify shift yes|no`. The cutoff defaults to 2.5σ.

use crate::model::pair::{PairBuild, PairLaw};
use crate::model::{Dimension, ModelError, PairTable};

/// The 12-6 coefficients of one pair, as the kernel reads them: F/r = r⁻²·r⁻⁶(lj1·r⁻⁶ − lj2),
/// U = r⁻⁶(lj3·r⁻⁶ − lj4) − offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LjCoeff {
    pub cut2: f64,
    pub lj1: f64,
    pub lj2: f64,
    pub lj3: f64,
    pub lj4: f64,
    pub offset: f64,
}

impl LjCoeff {
    /// The coefficients of well depth `epsilon`, zero-crossing `sigma` and cutoff `cut`,
    /// shifted to U(cut) = 0 if `shift`.
    pub fn new(epsilon: f64, sigma: f64, cut: f64, shift: bool) -> LjCoeff {
        let s6 = sigma.powi(6);
        let mut c = LjCoeff {
            cut2: cut * cut,
            lj1: 48.0 * epsilon * s6 * s6,
            lj2: 24.0 * epsilon * s6,
            lj3: 4.0 * epsilon * s6 * s6,
            lj4: 4.0 * epsilon * s6,
            offset: 0.0,
        };
        if shift {
            let r6inv = 1.0 / (c.cut2 * c.cut2 * c.cut2);
            c.offset = r6inv * (c.lj3 * r6inv - c.lj4);
        }
        c
    }

    #[inline(always)]
    pub fn eval(&self, r2: f64) -> Option<(f64, f64)> {
        if r2 >= self.cut2 {
            return None;
        }
        let r2inv = 1.0 / r2;
        let r6inv = r2inv * r2inv * r2inv;
        let f = r6inv * (self.lj1 * r6inv - self.lj2) * r2inv;
        let u = r6inv * (self.lj3 * r6inv - self.lj4) - self.offset;
        Some((f, u))
    }
}

#[derive(Clone, Debug)]
pub struct LennardJones {
    table: PairTable<LjCoeff>,
    cutoff: f64,
}

impl PairLaw for LennardJones {
    const NAME: &'static str = "lj";
    const SUMMARY: &'static str =
        "Lennard-Jones 12-6 with a cutoff (default 2.5 sigma), energy shifted with shift = true";
    const KEYS: &'static [(&'static str, &'static str)] = &[
        ("epsilon", "well depth (energy)"),
        ("sigma", "distance where U = 0 (length)"),
        (
            "cutoff",
            "cutoff of this pair (length); default [pair] cutoff, else 2.5 sigma",
        ),
    ];
    const LAMMPS_PEER: Option<&'static str> = Some("lj/cut");
    type Coeff = LjCoeff;

    fn build(b: &PairBuild) -> Result<Self, ModelError> {
        b.only_uses(Self::NAME, Self::KEYS)?;
        let shift = b.shift.unwrap_or(false);
        let table = b.table(|m, n| {
            let eps = b.required(
                m,
                n,
                "epsilon",
                Dimension::ENERGY,
                |x, y| b.mixing.energy(x, y),
                Self::NAME,
            )?;
            let sigma = b.required(
                m,
                n,
                "sigma",
                Dimension::LENGTH,
                |x, y| b.mixing.length(x, y),
                Self::NAME,
            )?;
            // LAMMPS mixes an unset cutoff arithmetically too; here a pair without its own
            // takes the deck's global one or 2.5σ of the mixed σ.
            let cut = match b.value(m, n, "cutoff", Dimension::LENGTH, |x, y| 0.5 * (x + y))? {
                Some(c) => c,
                None => b.cutoff.unwrap_or(2.5 * sigma),
            };
            Ok(LjCoeff::new(eps, sigma, cut, shift))
        })?;
        let cutoff = table
            .all()
            .iter()
            .map(|c| c.cut2.sqrt())
            .fold(0.0, f64::max);
        Ok(LennardJones { table, cutoff })
    }

    #[inline(always)]
    fn coeff(&self, mi: u16, mj: u16) -> LjCoeff {
        self.table.get(mi, mj)
    }

    fn cutoff(&self) -> f64 {
        self.cutoff
    }

    #[inline(always)]
    fn eval(&self, c: &LjCoeff, r2: f64, _vv: f64) -> Option<(f64, f64)> {
        c.eval(r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_is_minus_the_energy_slope_and_zero_at_the_minimum() {
        let c = LjCoeff::new(1.3, 0.9, 2.5 * 0.9, false);
        let rmin = 2f64.powf(1.0 / 6.0) * 0.9;
        assert!(c.eval(rmin * rmin).unwrap().0.abs() < 1e-12);
        // U(rmin) = -ε.
        assert!((c.eval(rmin * rmin).unwrap().1 + 1.3).abs() < 1e-12);
        for r in [0.85, 1.0, 1.2, 1.7, 2.2] {
            let h = 1e-6;
            let u = |r: f64| c.eval(r * r).unwrap().1;
            let slope = (u(r + h) - u(r - h)) / (2.0 * h);
            let f = c.eval(r * r).unwrap().0 * r;
            assert!(
                (f + slope).abs() < 1e-6 * (1.0 + f.abs()),
                "r = {r}: F = {f}, -dU/dr = {}",
                -slope
            );
        }
        assert!(c.eval(2.25 * 2.25 * 1.0001).is_none());
    }

    #[test]
    fn shifted_energy_vanishes_at_the_cutoff() {
        let c = LjCoeff::new(1.0, 1.0, 2.5, true);
        let (_, u) = c.eval(2.5 * 2.5 * (1.0 - 1e-12)).unwrap();
        assert!(u.abs() < 1e-9, "{u}");
        // The force is not shifted: the same as unshifted.
        let p = LjCoeff::new(1.0, 1.0, 2.5, false);
        assert_eq!(c.eval(1.44).unwrap().0, p.eval(1.44).unwrap().0);
    }
}
