//! Morse: U(r) = D₀[e^(−2α(r − r₀)) − 2e^(−α(r − r₀))] for r < r_c (LAMMPS `pair_style
//! morse`, with its D₀, α, r₀), optionally shifted to U(r_c) = 0.

use crate::model::pair::{PairBuild, PairLaw};
use crate::model::{Dimension, ModelError, PairTable};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MorseCoeff {
    pub cut2: f64,
    pub d0: f64,
    pub alpha: f64,
    pub r0: f64,
    pub offset: f64,
}

impl MorseCoeff {
    fn new(d0: f64, alpha: f64, r0: f64, cut: f64, shift: bool) -> MorseCoeff {
        let mut c = MorseCoeff {
            cut2: cut * cut,
            d0,
            alpha,
            r0,
            offset: 0.0,
        };
        if shift {
            let e = (-alpha * (cut - r0)).exp();
            c.offset = d0 * (e * e - 2.0 * e);
        }
        c
    }

    #[inline(always)]
    fn eval(&self, r2: f64) -> Option<(f64, f64)> {
        if r2 >= self.cut2 {
            return None;
        }
        let r = r2.sqrt();
        let e = (-self.alpha * (r - self.r0)).exp();
        // F = −dU/dr = 2αD₀(e² − e), positive (repulsive) inside r₀.
        let f = 2.0 * self.alpha * self.d0 * (e * e - e) / r;
        Some((f, self.d0 * (e * e - 2.0 * e) - self.offset))
    }
}

#[derive(Clone, Debug)]
pub struct Morse {
    table: PairTable<MorseCoeff>,
    cutoff: f64,
}

impl PairLaw for Morse {
    const NAME: &'static str = "morse";
    const SUMMARY: &'static str =
        "Morse potential D0[exp(-2a(r-r0)) - 2exp(-a(r-r0))] with a cutoff";
    const KEYS: &'static [(&'static str, &'static str)] = &[
        ("well_depth", "D0 (energy)"),
        ("alpha", "width parameter (1/length)"),
        ("r0", "equilibrium distance (length)"),
        (
            "cutoff",
            "cutoff of this pair (length); default [pair] cutoff",
        ),
    ];
    const LAMMPS_PEER: Option<&'static str> = Some("morse");
    type Coeff = MorseCoeff;

    fn build(b: &PairBuild) -> Result<Self, ModelError> {
        b.only_uses(Self::NAME, Self::KEYS)?;
        let shift = b.shift.unwrap_or(false);
        let table = b.table(|m, n| {
            let d0 = b.required(m, n, "well_depth", Dimension::ENERGY, |x, y| b.mixing.energy(x, y), Self::NAME)?;
            let alpha = b.required(m, n, "alpha", Dimension::INVERSE_LENGTH, |x, y| 0.5 * (x + y), Self::NAME)?;
            let r0 = b.required(m, n, "r0", Dimension::LENGTH, |x, y| b.mixing.length(x, y), Self::NAME)?;
            let cut = match b.value(m, n, "cutoff", Dimension::LENGTH, |x, y| 0.5 * (x + y))? {
                Some(c) => c,
                None => b.cutoff.ok_or_else(|| {
                    ModelError::from("pair law 'morse' needs a cutoff: give [pair] cutoff or 'cutoff' per material")
                })?,
            };
            Ok(MorseCoeff::new(d0, alpha, r0, cut, shift))
        })?;
        let cutoff = table
            .all()
            .iter()
            .map(|c| c.cut2.sqrt())
            .fold(0.0, f64::max);
        Ok(Morse { table, cutoff })
    }

    #[inline(always)]
    fn coeff(&self, mi: u16, mj: u16) -> MorseCoeff {
        self.table.get(mi, mj)
    }

    fn cutoff(&self) -> f64 {
        self.cutoff
    }

    #[inline(always)]
    fn eval(&self, c: &MorseCoeff, r2: f64, _vv: f64) -> Option<(f64, f64)> {
        c.eval(r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_at_r0_and_force_is_minus_the_slope() {
        let c = MorseCoeff::new(0.7, 1.8, 1.1, 3.0, false);
        let (f, u) = c.eval(1.1 * 1.1).unwrap();
        assert!(f.abs() < 1e-12 && (u + 0.7).abs() < 1e-12);
        for r in [0.8, 1.0, 1.3, 2.0, 2.9] {
            let h = 1e-6;
            let u = |r: f64| c.eval(r * r).unwrap().1;
            let slope = (u(r + h) - u(r - h)) / (2.0 * h);
            let f = c.eval(r * r).unwrap().0 * r;
            assert!((f + slope).abs() < 1e-6 * (1.0 + f.abs()), "r = {r}");
        }
        let s = MorseCoeff::new(0.7, 1.8, 1.1, 3.0, true);
        assert!(s.eval(9.0 * (1.0 - 1e-12)).unwrap().1.abs() < 1e-9);
    }
}
