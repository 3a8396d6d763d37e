//! `[lattice]`: the spacing, origin and jitter of the particle lattice, and its periodic axes.

use super::convert::{Converter, R};
use super::sections::LatticeSection;
use crate::input::geometry::Lattice;
use toml::Spanned;

impl Converter {
    /// The lattice; refuses a spacing that is not positive and jitter outside [0, 0.5) or on a
    /// periodic lattice.
    pub(super) fn lattice(&self, section: &Spanned<LatticeSection>) -> R<Lattice> {
        let line = self.line_of(section);
        let l = section.get_ref();
        let spacing = l.spacing.value(self.sys);
        if !(spacing.is_finite() && spacing > 0.0) {
            return self.err(line, format!("lattice spacing must be > 0 (got {spacing})"));
        }
        let jitter = l.jitter;
        if !(0.0..0.5).contains(&jitter) {
            return self.err(
                line,
                format!("[lattice] jitter = {jitter}: give a fraction of the spacing in [0, 0.5)"),
            );
        }
        if jitter > 0.0 && !l.periodic.is_empty() {
            return self.err(
                line,
                "[lattice] jitter with periodic axes is not supported (the period is taken from the particles' extent)",
            );
        }
        Ok(Lattice {
            spacing,
            origin: l.origin.map(|o| o.value(self.sys)).unwrap_or([0.0; 3]),
            jitter,
            seed: l.seed,
        })
    }

    /// The axes named in `[lattice] periodic`.
    pub(super) fn periodic(&self, section: &Spanned<LatticeSection>) -> R<[bool; 3]> {
        let mut periodic = [false; 3];
        for a in &section.get_ref().periodic {
            match a.as_str() {
                "x" => periodic[0] = true,
                "y" => periodic[1] = true,
                "z" => periodic[2] = true,
                other => {
                    return self.err(
                        self.line_of(section),
                        format!(
                            "[lattice] periodic: unknown axis '{other}' (use \"x\", \"y\" or \"z\")"
                        ),
                    )
                }
            }
        }
        Ok(periodic)
    }
}
