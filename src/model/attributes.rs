//! Declared per-particle and per-bond data.
//!
//! A model declares what it stores as plain `#[repr(C)]` structs of `f64` fields through the
//! [`attributes!`](crate::attributes!) macro. Because every field is `f64` (or an array of them)
//! the engine can view any record as a flat `&[f64]`: it sends records in messages, sums
//! generalized forces, integrates degrees of freedom and writes fields to output files by name,
//! all without knowing the model. This replaces the thesis's ParticleAlterAttrsFile /
//! ParticleFixedAttrsFile column bookkeeping.

/// One named field of an attribute record (`len` is 1 for a scalar, 3 for a vector …).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub len: usize,
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f64 {}
    impl<const N: usize> Sealed for [f64; N] {}
}

/// A field type allowed in an attribute record: `f64` or `[f64; N]`, nothing else (sealed).
pub trait Component: sealed::Sealed {
    const LEN: usize;
}
impl Component for f64 {
    const LEN: usize = 1;
}
impl<const N: usize> Component for [f64; N] {
    const LEN: usize = N;
}

/// Plain-data record whose fields are known by name at run time.
///
/// # Safety
/// The type must be `#[repr(C)]` and consist of `f64` fields only (scalars or arrays), so that
/// it is exactly `LEN` contiguous, 8-byte aligned `f64`s. The [`attributes!`](crate::attributes!)
/// macro guarantees this (and checks size and alignment at compile time); implement the trait
/// by hand only under the same rule, and never override `LEN`.
pub unsafe trait Attributes:
    bytemuck::Pod + Default + PartialEq + std::fmt::Debug + Send + Sync + 'static
{
    /// Fields in declaration order; their lengths add up to [`Attributes::LEN`].
    const FIELDS: &'static [Field];
    /// Number of `f64` values in one record.
    const LEN: usize = std::mem::size_of::<Self>() / 8;

    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        if Self::LEN == 0 {
            return &[];
        }
        // SAFETY: the trait's contract makes `Self` exactly `LEN` aligned `f64`s. A raw cast
        // (rather than bytemuck's checked one) keeps a run-time alignment test out of the
        // force loop.
        unsafe { std::slice::from_raw_parts(self as *const Self as *const f64, Self::LEN) }
    }

    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        if Self::LEN == 0 {
            return &mut [];
        }
        // SAFETY: as in `as_slice`.
        unsafe { std::slice::from_raw_parts_mut(self as *mut Self as *mut f64, Self::LEN) }
    }

    /// Offset (in `f64`s) and length of the field called `name`.
    fn field(name: &str) -> Option<(usize, usize)> {
        let mut offset = 0;
        for f in Self::FIELDS {
            if f.name == name {
                return Some((offset, f.len));
            }
            offset += f.len;
        }
        None
    }
}

/// `()` declares "nothing": no memory, no pass, no message.
// SAFETY: zero-sized; `LEN` is 0.
unsafe impl Attributes for () {
    const FIELDS: &'static [Field] = &[];
    const LEN: usize = 0;
}

/// `a += b`, component-wise. Monomorphized to straight-line code for small records.
#[inline(always)]
pub fn add_assign<A: Attributes>(a: &mut A, b: &A) {
    let (a, b) = (a.as_mut_slice(), b.as_slice());
    for k in 0..A::LEN {
        a[k] += b[k];
    }
}

/// Declares an attribute record: `#[repr(C)]`, `Pod`, and its field names for the engine.
///
/// ```
/// pdq::attributes! {
///     /// Position and velocity.
///     pub struct Motion { pub pos: [f64; 3], pub vel: [f64; 3] }
/// }
/// use pdq::model::attributes::Attributes;
/// assert_eq!(Motion::LEN, 6);
/// assert_eq!(Motion::field("vel"), Some((3, 3)));
/// ```
#[macro_export]
macro_rules! attributes {
    ($(#[$meta:meta])* $vis:vis struct $name:ident {
        $($(#[$fmeta:meta])* $fvis:vis $field:ident : $ty:ty),* $(,)?
    }) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name { $($(#[$fmeta])* $fvis $field: $ty),* }

        // SAFETY: `#[repr(C)]`, every field is `f64` or `[f64; N]` (`Component` is sealed to
        // those), and the assertion below checks size and alignment at compile time, so the
        // record is `LEN` contiguous aligned `f64`s.
        unsafe impl $crate::model::attributes::Attributes for $name {
            const FIELDS: &'static [$crate::model::attributes::Field] = &[$(
                $crate::model::attributes::Field {
                    name: stringify!($field),
                    len: <$ty as $crate::model::attributes::Component>::LEN,
                }
            ),*];
        }
        const _: () = assert!(
            std::mem::align_of::<$name>() == 8
                && std::mem::size_of::<$name>() == 8 * (0 $(+ <$ty as $crate::model::attributes::Component>::LEN)*)
        );
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::attributes! {
        struct Probe { pos: [f64; 3], temperature: f64, rot: [f64; 3] }
    }

    #[test]
    fn fields_are_flat_and_named() {
        assert_eq!(Probe::LEN, 7);
        let lens: usize = Probe::FIELDS.iter().map(|f| f.len).sum();
        assert_eq!(lens, Probe::LEN);
        assert_eq!(Probe::field("temperature"), Some((3, 1)));
        assert_eq!(Probe::field("rot"), Some((4, 3)));
        assert_eq!(Probe::field("nope"), None);
        let mut p = Probe::default();
        p.as_mut_slice()[3] = 5.0;
        assert_eq!(p.temperature, 5.0);
    }

    #[test]
    fn unit_record_is_empty() {
        assert_eq!(<() as Attributes>::LEN, 0);
        assert!(().as_slice().is_empty());
        let mut a = ();
        add_assign(&mut a, &());
    }

    #[test]
    fn add_assign_sums_components() {
        let mut a = Probe {
            pos: [1.0, 2.0, 3.0],
            temperature: 4.0,
            rot: [0.0; 3],
        };
        let b = a;
        add_assign(&mut a, &b);
        assert_eq!(a.pos, [2.0, 4.0, 6.0]);
        assert_eq!(a.temperature, 8.0);
    }
}
