//! Weeks–Chandler–Andersen: the Lennard-Jones 12-6 cut at its minimum r = 2^(1/6)σ and shifted
//! up by ε, so that it is purely repulsive and both force and energy vanish at the cutoff
//! (LAMMPS `pair_style lj/cut` with cutoff 2^(1/6)σ and `pair_modify shift yes`; the
//! membrane's excluded volume in seed 003).

use super::lj::LjCoeff;
use crate::model::pair::{PairBuild, PairLaw};
use crate::model::{Dimension, ModelError, PairTable};

#[derive(Clone, Debug)]
pub struct Wca {
    table: PairTable<LjCoeff>,
    cutoff: f64,
}

impl PairLaw for Wca {
    const NAME: &'static str = "wca";
    const SUMMARY: &'static str =
        "Weeks-Chandler-Andersen: Lennard-Jones cut at 2^(1/6) sigma and shifted, purely repulsive";
    const KEYS: &'static [(&'static str, &'static str)] = &[
        ("epsilon", "energy scale (energy)"),
        ("sigma", "size (length); the cutoff is 2^(1/6) sigma"),
    ];
    const LAMMPS_PEER: Option<&'static str> = Some("lj/cut");
    type Coeff = LjCoeff;

    fn build(b: &PairBuild) -> Result<Self, ModelError> {
        b.only_uses(Self::NAME, Self::KEYS)?;
        if b.cutoff.is_some() || b.shift == Some(false) {
            return Err(
                "[pair] law \"wca\" sets its own cutoff (2^(1/6) sigma) and shift: remove 'cutoff' and 'shift'"
                    .into(),
            );
        }
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
            Ok(LjCoeff::new(eps, sigma, 2f64.powf(1.0 / 6.0) * sigma, true))
        })?;
        let cutoff = table
            .all()
            .iter()
            .map(|c| c.cut2.sqrt())
            .fold(0.0, f64::max);
        Ok(Wca { table, cutoff })
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
    fn repulsive_everywhere_and_zero_at_the_cutoff() {
        let rc = 2f64.powf(1.0 / 6.0);
        let c = LjCoeff::new(1.0, 1.0, rc, true);
        for k in 1..100 {
            let r = 0.8 + (rc - 0.8) * k as f64 / 100.0;
            let (f, u) = c.eval(r * r).unwrap();
            assert!(f >= -1e-12 && u >= -1e-12, "r = {r}: F/r = {f}, U = {u}");
        }
        let (f, u) = c.eval(rc * rc * (1.0 - 1e-12)).unwrap();
        assert!(f.abs() < 1e-9 && u.abs() < 1e-9, "{f} {u}");
        // ε above the unshifted LJ: U(σ) = ε.
        assert!((c.eval(1.0).unwrap().1 - 1.0).abs() < 1e-12);
    }
}
