//! The elastic constants of a 3D isotropic solid from any two of E, ν, K, G (as
//! Peridynamics.jl's `get_elastic_params`), so that a model reads whichever two a deck gives
//! and computes its bond constants from the ones it needs.
//!
//! Each formula is written once here, in the order of operations the models have always used
//! (G from E and ν goes through K, as LPS computes it), so a model that calls this gets the
//! same bits as its own formula did. It only computes: the ranges (K, G > 0, −1 < ν < ½) are
//! the model's to check, at the key that is wrong.

/// One elastic constant, as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElasticConstant {
    YoungsModulus(f64),
    PoissonRatio(f64),
    BulkModulus(f64),
    ShearModulus(f64),
}

/// All four constants of a 3D isotropic solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isotropic {
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub bulk_modulus: f64,
    pub shear_modulus: f64,
}

impl Isotropic {
    /// From two different constants, in either order; `None` if both are of one kind.
    pub fn from_any_two(a: ElasticConstant, b: ElasticConstant) -> Option<Self> {
        use ElasticConstant::*;
        let (e, nu, k, g) = match (a, b) {
            (YoungsModulus(e), PoissonRatio(nu)) | (PoissonRatio(nu), YoungsModulus(e)) => {
                let k = e / (3.0 * (1.0 - 2.0 * nu));
                (e, nu, k, shear_of(k, nu))
            }
            (BulkModulus(k), PoissonRatio(nu)) | (PoissonRatio(nu), BulkModulus(k)) => {
                (3.0 * k * (1.0 - 2.0 * nu), nu, k, shear_of(k, nu))
            }
            (ShearModulus(g), PoissonRatio(nu)) | (PoissonRatio(nu), ShearModulus(g)) => {
                let e = 2.0 * g * (1.0 + nu);
                (e, nu, e / (3.0 * (1.0 - 2.0 * nu)), g)
            }
            (YoungsModulus(e), BulkModulus(k)) | (BulkModulus(k), YoungsModulus(e)) => {
                (e, (3.0 * k - e) / (6.0 * k), k, 3.0 * k * e / (9.0 * k - e))
            }
            (YoungsModulus(e), ShearModulus(g)) | (ShearModulus(g), YoungsModulus(e)) => {
                (e, e / (2.0 * g) - 1.0, e * g / (3.0 * (3.0 * g - e)), g)
            }
            (BulkModulus(k), ShearModulus(g)) | (ShearModulus(g), BulkModulus(k)) => (
                9.0 * k * g / (3.0 * k + g),
                (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
                k,
                g,
            ),
            _ => return None,
        };
        Some(Isotropic {
            youngs_modulus: e,
            poisson_ratio: nu,
            bulk_modulus: k,
            shear_modulus: g,
        })
    }
}

/// G = 3K(1 − 2ν)/(2(1 + ν)).
fn shear_of(k: f64, nu: f64) -> f64 {
    3.0 * k * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu))
}

#[cfg(test)]
mod tests {
    use super::ElasticConstant::*;
    use super::*;

    /// Steel-like: E = 200, ν = 0.3, so K = 500/3 and G = 1000/13.
    const E: f64 = 200.0;
    const NU: f64 = 0.3;
    const K: f64 = 500.0 / 3.0;
    const G: f64 = 1000.0 / 13.0;

    #[test]
    fn any_two_give_the_other_two() {
        let given = [
            YoungsModulus(E),
            PoissonRatio(NU),
            BulkModulus(K),
            ShearModulus(G),
        ];
        for (i, &a) in given.iter().enumerate() {
            for (j, &b) in given.iter().enumerate() {
                let s = Isotropic::from_any_two(a, b);
                if i == j {
                    assert!(s.is_none(), "{a:?} twice");
                    continue;
                }
                let s = s.unwrap();
                let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs();
                assert!(
                    close(s.youngs_modulus, E)
                        && close(s.poisson_ratio, NU)
                        && close(s.bulk_modulus, K)
                        && close(s.shear_modulus, G),
                    "{a:?}, {b:?}: {s:?}"
                );
            }
        }
    }

    /// The order LPS computes K and G from E and ν in, bit for bit.
    #[test]
    fn from_youngs_modulus_and_poisson_ratio_as_lps_computes_it() {
        for (e, nu) in [(30e9, 0.2), (14.9e9, 0.125), (2.235e10, 0.3), (1.0, -0.5)] {
            let k = e / (3.0 * (1.0 - 2.0 * nu));
            let g = 3.0 * k * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu));
            let s = Isotropic::from_any_two(PoissonRatio(nu), YoungsModulus(e)).unwrap();
            assert_eq!((s.bulk_modulus, s.shear_modulus), (k, g));
        }
    }
}
