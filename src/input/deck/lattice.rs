//! `[lattice]`: the kind, spacing (or density), origin and jitter of the particle lattice, and
//! its periodic axes.

use super::convert::{Converter, R};
use super::sections::LatticeSection;
use crate::input::geometry::{Lattice, LatticeKind};
use toml::Spanned;

impl Converter {
    /// The lattice; refuses an unknown kind, a spacing or density that is not positive (or
    /// both, or neither) and jitter outside [0, 0.5) or on a periodic lattice.
    pub(super) fn lattice(&self, section: &Spanned<LatticeSection>) -> R<Lattice> {
        let line = self.line_of(section);
        let l = section.get_ref();
        let kind = match l.kind.as_deref().unwrap_or("sc") {
            "sc" => LatticeKind::Sc,
            "fcc" => LatticeKind::Fcc,
            "bcc" => LatticeKind::Bcc,
            other => {
                return self.err(
                    line,
                    format!("[lattice] unknown kind '{other}' (use \"sc\", \"fcc\" or \"bcc\")"),
                )
            }
        };
        let spacing = match (l.spacing, l.density) {
            (Some(s), None) => s.value(self.sys),
            (None, Some(rho)) => {
                let rho = rho.value(self.sys);
                if !(rho.is_finite() && rho > 0.0) {
                    return self.err(line, format!("[lattice] density must be > 0 (got {rho})"));
                }
                kind.cell_side(rho)
            }
            (Some(_), Some(_)) => {
                return self.err(
                    line,
                    "[lattice] give 'spacing' (the cubic cell side) or 'density' (sites per unit volume), not both",
                )
            }
            (None, None) => {
                return self.err(
                    line,
                    "[lattice] needs 'spacing' (the cubic cell side) or 'density' (sites per unit volume)",
                )
            }
        };
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
            kind,
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
