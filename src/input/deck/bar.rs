//! `[[bar]]`: reinforcing and prestressing bars, lines of particles of their own spacing, and
//! the initial strain of a bar's own bonds.

use super::convert::{Converter, R};
use super::sections::BarSection;
use super::spec::BarSpec;
use crate::input::bars::Prestrain;
use crate::input::geometry::Bar;
use crate::model::{Dimension, Material};
use toml::Spanned;

impl Converter {
    /// The bars in deck order; `names` and `materials` are the deck's materials.
    pub(super) fn bars(
        &self,
        entries: &[Spanned<BarSection>],
        lattice_spacing: f64,
        names: &[String],
        materials: &[Material],
    ) -> R<Vec<BarSpec>> {
        let mut bars = Vec::new();
        for (k, b) in entries.iter().enumerate() {
            let line = self.line_of(b);
            let bar = self.bar(b.get_ref(), k, line, lattice_spacing, names)?;
            let prestrain =
                self.prestrain(b.get_ref(), k, line, &materials[bar.material as usize])?;
            bars.push(BarSpec {
                bar,
                prestrain,
                line,
            });
        }
        Ok(bars)
    }

    fn bar(
        &self,
        b: &BarSection,
        k: usize,
        line: usize,
        lattice_spacing: f64,
        names: &[String],
    ) -> R<Bar> {
        let sys = self.sys;
        let ctx = format!("bar {k}");
        let material = self.material_id(names, &b.material, line)?;
        let area = b.area.value(sys);
        if !(area.is_finite() && area > 0.0) {
            return self.err(line, format!("{ctx}: area must be > 0 (got {area})"));
        }
        let spacing = b.spacing.map(|s| s.value(sys)).unwrap_or(lattice_spacing);
        if !(spacing.is_finite() && spacing > 0.0) {
            return self.err(line, format!("{ctx}: spacing must be > 0 (got {spacing})"));
        }
        let from = b.from.value(sys);
        let length = b.length.map(|l| l.value(sys));
        let bar = match (b.to, b.direction, b.azimuth.is_some() || b.elevation.is_some(), length) {
            (Some(to), None, false, None) => Bar {
                from,
                to: to.value(sys),
                area,
                spacing,
                material,
            },
            (None, Some(dir), false, Some(len)) => {
                if dir.iter().all(|&c| c == 0.0) || dir.iter().any(|c| !c.is_finite()) {
                    return self.err(line, format!("{ctx}: direction must be a non-zero vector (got {dir:?})"));
                }
                Bar::along(from, dir, len, area, spacing, material)
            }
            (None, None, true, Some(len)) => Bar::at_angle(
                from,
                b.azimuth.unwrap_or(0.0),
                b.elevation.unwrap_or(0.0),
                len,
                area,
                spacing,
                material,
            ),
            _ => {
                return self.err(
                    line,
                    format!("{ctx}: give 'to', or 'direction' and 'length', or 'azimuth'/'elevation' (degrees) and 'length'"),
                )
            }
        };
        if let Some(len) = length {
            if !(len.is_finite() && len > 0.0) {
                return self.err(line, format!("{ctx}: length must be > 0 (got {len})"));
            }
        }
        Ok(bar)
    }

    /// A bar's initial strain, given as `prestrain` or as `prestress` over the material's E,
    /// with its transfer length.
    fn prestrain(
        &self,
        b: &BarSection,
        k: usize,
        line: usize,
        material: &Material,
    ) -> R<Prestrain> {
        let ctx = format!("bar {k}");
        let strain = match (b.prestrain, b.prestress) {
            (None, None) => {
                if b.transfer_length.is_some() {
                    return self.err(
                        line,
                        format!("{ctx}: transfer_length needs prestrain or prestress"),
                    );
                }
                return Ok(Prestrain::default());
            }
            (Some(e), None) => e,
            (None, Some(stress)) => match material
                .positive("youngs_modulus", Dimension::STRESS)
                .or_else(|e| self.err(line, e.to_string()))?
            {
                Some(e) => stress.value(self.sys) / e,
                None => {
                    return self.err(
                        line,
                        format!(
                        "{ctx}: prestress needs youngs_modulus on material '{}'; or give prestrain",
                        material.name
                    ),
                    )
                }
            },
            (Some(_), Some(_)) => {
                return self.err(
                    line,
                    format!("{ctx}: give prestrain or prestress, not both"),
                )
            }
        };
        if !(strain.is_finite() && strain.abs() < 0.1) {
            return self.err(
                line,
                format!(
                    "{ctx}: prestrain must be a finite strain below 0.1 in size (got {strain})"
                ),
            );
        }
        let transfer_length = b.transfer_length.map_or(0.0, |l| l.value(self.sys));
        if !(transfer_length.is_finite() && transfer_length >= 0.0) {
            return self.err(
                line,
                format!("{ctx}: transfer_length must be a length >= 0 (got {transfer_length})"),
            );
        }
        Ok(Prestrain {
            strain,
            transfer_length,
        })
    }
}
