//! Peridynamic short-range contact: particles closer than a contact distance d that are not
//! joined by an intact bond repel with the force density
//!
//!   f = c_s (d − r)/δ,  c_s = k·c,  c = 18K/(πδ⁴),
//!
//! times both volumes, along the line between them (energy ½ c_s/δ (d − r)² V_i V_j).
//! Source: Silling & Askari (2005), "A meshfree method based on the peridynamic model of solid
//! mechanics", Comput. Struct. 83, §5 (short-range forces), who take c_s = 15c and
//! d = min(0.9|x_j − x_i|, 1.35(r_i + r_j)) — on a lattice 0.9 of the spacing, the defaults
//! here. Peridigm's `Short Range Force` contact computes the same form, c = 9k/(πδ⁴) with a
//! user spring constant k (so k = 2K gives our c), and Peridynamics.jl's contact likewise
//! leaves the stiffness to the user. Tying it to the bonds' c makes the contact as stiff as
//! the material's own bonds times k, whatever the units; the factor 15 is Silling and
//! Askari's choice, not derived. A pair of materials takes the series stiffness
//! 2c_a c_b/(c_a + c_b), as PMB bonds between materials do.

use crate::model::pair::{PairBuild, PairLaw};
use crate::model::{Dimension, ModelError, PairTable};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactCoeff {
    /// d².
    pub cut2: f64,
    pub d: f64,
    /// c_s / δ.
    pub k: f64,
}

#[derive(Clone, Debug)]
pub struct Contact {
    table: PairTable<ContactCoeff>,
    cutoff: f64,
}

impl PairLaw for Contact {
    const NAME: &'static str = "contact";
    const SUMMARY: &'static str =
        "peridynamic short-range contact (Silling & Askari 2005): repulsion below a contact distance between particles not joined by an intact bond";
    const KEYS: &'static [(&'static str, &'static str)] = &[
        (
            "contact_distance",
            "distance below which particles repel (length); default 0.9 x spacing",
        ),
        (
            "stiffness_factor",
            "c_s / c, the contact's micromodulus over the bonds' 18K/(pi delta^4); default 15",
        ),
    ];
    const SKIPS_BONDED: bool = true;
    const VOLUMES: bool = true;
    type Coeff = ContactCoeff;

    fn build(b: &PairBuild) -> Result<Self, ModelError> {
        b.only_uses(Self::NAME, Self::KEYS)?;
        if b.shift.is_some() {
            return Err("[pair] law \"contact\" has no energy shift: remove 'shift'".into());
        }
        if b.horizon <= 0.0 || b.horizon.is_nan() {
            return Err("pair law 'contact' is tied to the bonds' stiffness: it needs a bonded model with a horizon".into());
        }
        let delta = b.horizon;
        let c_of = |m: u16| 18.0 * b.bulk_modulus[m as usize] / (PI * delta.powi(4));
        let table = b.table(|m, n| {
            let d = b
                .value(m, n, "contact_distance", Dimension::LENGTH, |x, y| 0.5 * (x + y))?
                .or(b.cutoff)
                .unwrap_or(0.9 * b.spacing);
            let factor = b.value(m, n, "stiffness_factor", Dimension::NUMBER, |x, y| (x * y).sqrt())?.unwrap_or(15.0);
            let (ca, cb) = (c_of(m), c_of(n));
            let c = 2.0 * ca * cb / (ca + cb);
            if !(c.is_finite() && c > 0.0) {
                return Err(ModelError::from(format!(
                    "pair law 'contact': the bonds of materials {m} and {n} have no stiffness to tie the contact to"
                )));
            }
            Ok(ContactCoeff { cut2: d * d, d, k: factor * c / delta })
        })?;
        let cutoff = table.all().iter().map(|c| c.d).fold(0.0, f64::max);
        Ok(Contact { table, cutoff })
    }

    #[inline(always)]
    fn coeff(&self, mi: u16, mj: u16) -> ContactCoeff {
        self.table.get(mi, mj)
    }

    fn cutoff(&self) -> f64 {
        self.cutoff
    }

    #[inline(always)]
    fn eval(&self, c: &ContactCoeff, r2: f64, vv: f64) -> Option<(f64, f64)> {
        if r2 >= c.cut2 {
            return None;
        }
        let r = r2.sqrt();
        let gap = c.d - r;
        Some((c.k * gap * vv / r, 0.5 * c.k * gap * gap * vv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_repulsion_inside_the_contact_distance() {
        let law = Contact {
            table: PairTable::new(&[0u16], |_, _| ContactCoeff {
                cut2: 0.81,
                d: 0.9,
                k: 2.0,
            }),
            cutoff: 0.9,
        };
        let c = law.coeff(0, 0);
        let (f, u) = law.eval(&c, 0.25, 3.0).unwrap();
        // F = k (d − r) V_i V_j = 2 · 0.4 · 3 at r = 0.5.
        assert!((f * 0.5 - 2.4).abs() < 1e-12 && (u - 0.5 * 2.0 * 0.16 * 3.0).abs() < 1e-12);
        assert!(law.eval(&c, 0.81, 3.0).is_none());
    }
}
