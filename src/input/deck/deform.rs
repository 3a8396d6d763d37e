//! `[deform]`: a periodic box that stretches (or shrinks) at a constant engineering strain
//! rate along each axis, as LAMMPS's `fix deform … erate … remap x`.

use super::convert::{Converter, R};
use super::sections::DeformSection;
use super::spec::DeformSpec;
use toml::Spanned;

impl Converter {
    /// `[deform]`, checked against the periodic axes and the scene: bondless particles with a
    /// pair law, stepped explicitly (`pair`: the line of `[pair]`, if any).
    pub(super) fn deform(
        &self,
        section: Option<&Spanned<DeformSection>>,
        periodic: [bool; 3],
        bondless: bool,
        pair: Option<usize>,
    ) -> R<Option<DeformSpec>> {
        let Some(section) = section else {
            return Ok(None);
        };
        let line = self.line_of(section);
        let d = section.get_ref();
        let at = self.line_of(&d.strain_rate);
        let rate = self.finite3(*d.strain_rate.get_ref(), at, "[deform] strain_rate")?;
        for (a, &r) in rate.iter().enumerate() {
            if r != 0.0 && !periodic[a] {
                return self.err(
                    at,
                    format!(
                        "[deform] strain_rate along {} is {r}, but that axis is not periodic: only a periodic box deforms (add \"{}\" to [lattice] periodic, or give 0)",
                        ["x", "y", "z"][a],
                        ["x", "y", "z"][a]
                    ),
                );
            }
        }
        if !bondless {
            return self.err(
                line,
                "[deform] maps bondless particles with the box (name = \"point\" with a [pair] law); a bonded body would need its bonds' images remapped, which PDQ does not do",
            );
        }
        if pair.is_none() {
            return self.err(
                line,
                "[deform] needs a [pair] law: the box is deformed between neighbour-list rebuilds",
            );
        }
        let every = match &d.every {
            Some(e) if *e.get_ref() < 1 => {
                return self.err(
                    self.line_of(e),
                    format!("[deform] every must be ≥ 1 (got {})", e.get_ref()),
                )
            }
            Some(e) => *e.get_ref() as u64,
            None => 1,
        };
        Ok(Some(DeformSpec { line, rate, every }))
    }
}
