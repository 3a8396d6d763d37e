//! Four bonds at once: a number type for bond laws written once and run either on one bond
//! (`f64`) or on four side by side ([`F4`], one bond per lane).
//!
//! A model with much arithmetic per bond (micropolar) writes its law generic over [`Real`] and
//! sets [`crate::model::Model::BOND_LANES`]; the bond sweep then hands it four intact bonds of a
//! particle at a time ([`crate::model::Model::pair_lanes`]). Each `F4` operation is four
//! independent IEEE operations in the order the law writes them, with no fused multiply-add,
//! so a bond gives bit-identical results whether it ran in a lane or alone.
//!
//! Built for a CPU with AVX (the project builds for the CPU it is built on:
//! `.cargo/config.toml`), an `F4` is one 256-bit register and each operation one instruction.
//! Otherwise it is four `f64`s in an array. The compiler's vectorizer alone did not turn the
//! array form into 256-bit instructions (most of the micropolar law stayed scalar), which is
//! why the register form is written out.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// How many bonds a lane group holds.
pub const LANES: usize = 4;

/// The arithmetic a bond law needs, on one bond or on a lane group.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The same value in every lane.
    fn splat(x: f64) -> Self;
    fn sqrt(self) -> Self;
    /// `f` on each lane: for functions with no vector form (`exp`), the same bits as on
    /// single values.
    fn lanewise(self, f: impl Fn(f64) -> f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn lanewise(self, f: impl Fn(f64) -> f64) -> Self {
        f(self)
    }
}

/// Most generalized-force components a model with lanes may have (micropolar: 6).
pub const MAX_COMPONENTS: usize = 8;

/// The generalized forces of a lane group on its two ends: element k holds component k of the
/// force record (the model's `Force` viewed as `f64`s) of each bond, one bond per lane.
/// Elements past the record's length are ignored. With `opposite`, the forces on j are those
/// on i negated and `j` is not read (bond-based laws: one transpose instead of two).
#[derive(Clone, Copy, Debug)]
pub struct LaneForces {
    pub i: [F4; MAX_COMPONENTS],
    pub j: [F4; MAX_COMPONENTS],
    pub opposite: bool,
}

impl LaneForces {
    /// Forces `i` on the owners and their negatives on the partners.
    #[inline(always)]
    pub fn opposite(i: [F4; MAX_COMPONENTS]) -> LaneForces {
        LaneForces {
            i,
            j: i,
            opposite: true,
        }
    }

    /// The central forces of four bonds: `f`·`y` on each owner (y the bond vector, f the
    /// force per unit of it) and its negative on each partner.
    #[inline(always)]
    pub fn central(f: F4, y: &[F4; 3]) -> LaneForces {
        let mut i = [F4::splat(0.0); MAX_COMPONENTS];
        for (c, yc) in i.iter_mut().zip(y) {
            *c = f * *yc;
        }
        LaneForces::opposite(i)
    }
}

/// Methods both forms of `F4` build from their `load`, `store`, `gather` and `transpose`.
macro_rules! shared_methods {
    () => {
        /// Values `AT..AT + 4` of four records (one per lane) as four lane vectors: the rows
        /// loaded whole and transposed, cheaper than gathering each value.
        #[inline(always)]
        pub fn columns<const AT: usize>(rows: [&[f64]; LANES]) -> [F4; LANES] {
            F4::transpose([
                F4::load(&rows[0][AT..AT + LANES]),
                F4::load(&rows[1][AT..AT + LANES]),
                F4::load(&rows[2][AT..AT + LANES]),
                F4::load(&rows[3][AT..AT + LANES]),
            ])
        }

        /// Up to four values from `s`, zero in the lanes past its end.
        #[inline(always)]
        pub fn load_partial(s: &[f64]) -> F4 {
            if s.len() >= LANES {
                F4::load(&s[..LANES])
            } else {
                F4::gather(|l| if l < s.len() { s[l] } else { 0.0 })
            }
        }

        /// Writes the first `s.len()` (at most four) lanes to `s`.
        #[inline(always)]
        pub fn store_partial(self, s: &mut [f64]) {
            if s.len() >= LANES {
                self.store(&mut s[..LANES]);
            } else {
                let a = self.to_array();
                let n = s.len();
                s.copy_from_slice(&a[..n]);
            }
        }
    };
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
pub use register::F4;

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
pub use array::F4;

#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod register {
    use super::{Real, LANES};
    use std::arch::x86_64::*;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Four `f64` lanes in one AVX register.
    ///
    /// Every `unsafe` block below calls an AVX intrinsic. This module is compiled only when the
    /// build enables AVX for every function (`target_feature = "avx"` above), so a binary that
    /// contains it is one built for CPUs with AVX.
    #[derive(Clone, Copy, Debug)]
    pub struct F4(__m256d);

    impl F4 {
        shared_methods!();

        /// Lane `l` from `f(l)`.
        #[inline(always)]
        pub fn gather(f: impl Fn(usize) -> f64) -> Self {
            // `_mm256_set_pd` takes the lanes from the highest.
            // SAFETY: AVX is enabled for the whole build (see the type).
            F4(unsafe { _mm256_set_pd(f(3), f(2), f(1), f(0)) })
        }

        /// The value in lane `l`.
        #[inline(always)]
        pub fn lane(self, l: usize) -> f64 {
            self.to_array()[l]
        }

        #[inline(always)]
        pub fn to_array(self) -> [f64; LANES] {
            let mut out = [0.0; LANES];
            self.store(&mut out);
            out
        }

        /// Four values from a slice of at least four.
        #[inline(always)]
        pub fn load(s: &[f64]) -> F4 {
            assert!(s.len() >= LANES);
            // SAFETY: AVX as above; `s` holds at least four f64s, the load is unaligned.
            F4(unsafe { _mm256_loadu_pd(s.as_ptr()) })
        }

        /// The four lanes into a slice of at least four.
        #[inline(always)]
        pub fn store(self, s: &mut [f64]) {
            assert!(s.len() >= LANES);
            // SAFETY: AVX as above; `s` holds at least four f64s, the store is unaligned.
            unsafe { _mm256_storeu_pd(s.as_mut_ptr(), self.0) };
        }

        /// Rows to columns: lane l of output k is lane k of input l.
        #[inline(always)]
        pub fn transpose(r: [F4; LANES]) -> [F4; LANES] {
            // SAFETY: AVX as above.
            unsafe {
                let lo01 = _mm256_unpacklo_pd(r[0].0, r[1].0); // r0[0] r1[0] r0[2] r1[2]
                let hi01 = _mm256_unpackhi_pd(r[0].0, r[1].0); // r0[1] r1[1] r0[3] r1[3]
                let lo23 = _mm256_unpacklo_pd(r[2].0, r[3].0);
                let hi23 = _mm256_unpackhi_pd(r[2].0, r[3].0);
                [
                    F4(_mm256_permute2f128_pd(lo01, lo23, 0x20)),
                    F4(_mm256_permute2f128_pd(hi01, hi23, 0x20)),
                    F4(_mm256_permute2f128_pd(lo01, lo23, 0x31)),
                    F4(_mm256_permute2f128_pd(hi01, hi23, 0x31)),
                ]
            }
        }

        /// Whether any lane is above `hi` or below `lo` (lane by lane; NaN counts as neither).
        #[inline(always)]
        pub fn any_outside(self, lo: F4, hi: F4) -> bool {
            // SAFETY: AVX as above.
            unsafe {
                let above = _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, hi.0);
                let below = _mm256_cmp_pd::<_CMP_LT_OQ>(self.0, lo.0);
                _mm256_movemask_pd(_mm256_or_pd(above, below)) != 0
            }
        }
    }

    macro_rules! op {
        ($trait:ident, $method:ident, $intrinsic:ident) => {
            impl $trait for F4 {
                type Output = F4;
                #[inline(always)]
                fn $method(self, o: F4) -> F4 {
                    // SAFETY: AVX is enabled for the whole build (see the type).
                    F4(unsafe { $intrinsic(self.0, o.0) })
                }
            }
        };
    }

    op!(Add, add, _mm256_add_pd);
    op!(Sub, sub, _mm256_sub_pd);
    op!(Mul, mul, _mm256_mul_pd);
    op!(Div, div, _mm256_div_pd);

    impl Neg for F4 {
        type Output = F4;
        #[inline(always)]
        fn neg(self) -> F4 {
            // Flipping the sign bit is IEEE negation.
            // SAFETY: AVX is enabled for the whole build (see the type).
            F4(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
        }
    }

    impl Real for F4 {
        #[inline(always)]
        fn splat(x: f64) -> Self {
            // SAFETY: AVX is enabled for the whole build (see the type).
            F4(unsafe { _mm256_set1_pd(x) })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            // Correctly rounded, as f64::sqrt.
            // SAFETY: AVX is enabled for the whole build (see the type).
            F4(unsafe { _mm256_sqrt_pd(self.0) })
        }
        #[inline(always)]
        fn lanewise(self, f: impl Fn(f64) -> f64) -> Self {
            let a = self.to_array();
            F4::gather(|l| f(a[l]))
        }
    }
}

/// The portable form, compiled on every build so that its tests run everywhere.
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx"), allow(dead_code))]
mod array {
    use super::{Real, LANES};
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Four `f64`s, one per bond of a lane group.
    #[derive(Clone, Copy, Debug)]
    #[repr(C, align(32))]
    pub struct F4([f64; LANES]);

    impl F4 {
        shared_methods!();

        /// Lane `l` from `f(l)`. Written out (not `array::from_fn`): a call the inliner may
        /// keep out of line would cost more than the law.
        #[inline(always)]
        pub fn gather(f: impl Fn(usize) -> f64) -> Self {
            F4([f(0), f(1), f(2), f(3)])
        }

        /// The value in lane `l`.
        #[inline(always)]
        pub fn lane(self, l: usize) -> f64 {
            self.0[l]
        }

        #[inline(always)]
        pub fn to_array(self) -> [f64; LANES] {
            self.0
        }

        /// Four values from a slice of at least four.
        #[inline(always)]
        pub fn load(s: &[f64]) -> F4 {
            F4([s[0], s[1], s[2], s[3]])
        }

        /// The four lanes into a slice of at least four.
        #[inline(always)]
        pub fn store(self, s: &mut [f64]) {
            s[..LANES].copy_from_slice(&self.0);
        }

        /// Rows to columns: lane l of output k is lane k of input l.
        #[inline(always)]
        pub fn transpose(r: [F4; LANES]) -> [F4; LANES] {
            let c = |k: usize| F4([r[0].0[k], r[1].0[k], r[2].0[k], r[3].0[k]]);
            [c(0), c(1), c(2), c(3)]
        }

        /// Whether any lane is above `hi` or below `lo` (lane by lane; NaN counts as neither).
        #[inline(always)]
        pub fn any_outside(self, lo: F4, hi: F4) -> bool {
            (0..LANES).any(|l| self.0[l] > hi.0[l] || self.0[l] < lo.0[l])
        }
    }

    macro_rules! lanewise {
        ($trait:ident, $method:ident, $op:tt) => {
            impl $trait for F4 {
                type Output = F4;
                #[inline(always)]
                fn $method(self, o: F4) -> F4 {
                    let (a, b) = (self.0, o.0);
                    F4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
                }
            }
        };
    }

    lanewise!(Add, add, +);
    lanewise!(Sub, sub, -);
    lanewise!(Mul, mul, *);
    lanewise!(Div, div, /);

    impl Neg for F4 {
        type Output = F4;
        #[inline(always)]
        fn neg(self) -> F4 {
            let a = self.0;
            F4([-a[0], -a[1], -a[2], -a[3]])
        }
    }

    impl Real for F4 {
        #[inline(always)]
        fn splat(x: f64) -> Self {
            F4([x; LANES])
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            let a = self.0;
            F4([a[0].sqrt(), a[1].sqrt(), a[2].sqrt(), a[3].sqrt()])
        }
        #[inline(always)]
        fn lanewise(self, f: impl Fn(f64) -> f64) -> Self {
            let a = self.0;
            F4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
        }
    }
}

/// Five particles for the models' lane tests: particle 0 bonded to 1–4.
#[cfg(test)]
pub(crate) mod fixture {
    use super::{LaneForces, LANES};
    use crate::model::BondGeom;

    /// Reference positions (spacing 1 mm).
    pub const X0: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [1e-3, 0.0, 0.0],
        [0.0, 2e-3, 1e-3],
        [1e-3, 1e-3, 1e-3],
        [-2e-3, 1e-3, 0.0],
    ];

    /// Current positions: displacements of a few parts in a thousand of the spacing, both
    /// signs, so that some bonds stretch and some shorten.
    pub fn moved(p: usize) -> [f64; 3] {
        std::array::from_fn(|k| X0[p][k] + 1e-6 * ((7 * p + 3 * k) % 5) as f64 - 2e-6)
    }

    /// Particle p's volume.
    pub fn volume(p: usize) -> f64 {
        1e-9 * (1.0 + p as f64 / 10.0)
    }

    /// The geometry of bond 0–p (p = 1..=4), with a volume correction below one.
    pub fn geom(p: usize) -> BondGeom {
        let d: [f64; 3] = std::array::from_fn(|k| X0[p][k] - X0[0][k]);
        BondGeom {
            length: (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(),
            beta: 1.0 - p as f64 / 20.0,
        }
    }

    /// Lane l of `lanes` is `single[l]` (the two ends' records) bit for bit.
    pub fn assert_same_bits(lanes: &LaneForces, single: [(&[f64], &[f64]); LANES], what: &str) {
        for (l, (i, j)) in single.iter().enumerate() {
            for (c, (x, y)) in i.iter().zip(j.iter()).enumerate() {
                let on_j = if lanes.opposite {
                    -lanes.i[c]
                } else {
                    lanes.j[c]
                };
                assert_eq!(
                    lanes.i[c].lane(l).to_bits(),
                    x.to_bits(),
                    "{what}: lane {l} i {c}"
                );
                assert_eq!(
                    on_j.lane(l).to_bits(),
                    y.to_bits(),
                    "{what}: lane {l} j {c}"
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    /// The same tests for the form in use and, where that is the register form, for the
    /// portable one.
    macro_rules! lane_tests {
        ($name:ident, $f4:ty) => {
            mod $name {
                use super::super::{Real, LANES};
                type F4 = $f4;

                /// The same expression on lanes and on single values gives the same bits.
                #[test]
                fn lanes_match_single_values_bit_for_bit() {
                    let x = [0.1, -3.7e-5, 12.5, 7.0 / 3.0];
                    let y = [1.0 / 7.0, 2.2e8, -0.3, 1e-300];
                    fn law<T: Real>(a: T, b: T) -> T {
                        ((a * b + T::splat(0.5)) / (a - b)).sqrt() + -(a / b).lanewise(f64::exp)
                    }
                    let v = law(F4::gather(|l| x[l]), F4::gather(|l| y[l]));
                    for l in 0..LANES {
                        let s = law(x[l], y[l]);
                        assert!(
                            v.lane(l).to_bits() == s.to_bits()
                                || (v.lane(l).is_nan() && s.is_nan()),
                            "lane {l}"
                        );
                    }
                }

                #[test]
                fn columns_transpose_and_partial_loads() {
                    let rows: Vec<Vec<f64>> = (0..4)
                        .map(|r| (0..7).map(|c| (10 * r + c) as f64).collect())
                        .collect();
                    let cols = F4::columns::<2>([&rows[0], &rows[1], &rows[2], &rows[3]]);
                    for (k, col) in cols.iter().enumerate() {
                        assert_eq!(col.to_array(), [0, 10, 20, 30].map(|r| (r + 2 + k) as f64));
                    }
                    let back = F4::transpose(cols);
                    assert_eq!(back[1].to_array(), [12.0, 13.0, 14.0, 15.0]);
                    let p = F4::load_partial(&[1.0, 2.0]);
                    assert_eq!(p.to_array(), [1.0, 2.0, 0.0, 0.0]);
                    let mut out = [9.0; 3];
                    F4::gather(|l| l as f64).store_partial(&mut out);
                    assert_eq!(out, [0.0, 1.0, 2.0]);
                    let s = F4::gather(|l| [0.1, -0.2, 0.3, f64::NAN][l]);
                    assert!(!s.any_outside(F4::splat(-0.5), F4::splat(0.5)));
                    assert!(s.any_outside(F4::splat(-0.1), F4::splat(0.5)));
                    assert!(s.any_outside(F4::splat(-0.5), F4::splat(0.25)));
                    assert_eq!((-F4::splat(0.0)).lane(3).to_bits(), (-0.0f64).to_bits());
                }
            }
        };
    }

    lane_tests!(in_use, super::super::F4);
    lane_tests!(portable, super::super::array::F4);
}
