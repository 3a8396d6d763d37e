//! `[pair]`: the non-bonded pair law, its parameters per material and per pair of materials,
//! the neighbour-list skin and which pairs are left out.

use super::convert::{Converter, R};
use super::sections::PairSection;
use super::spec::PairSpec;
use crate::input::materials::{self, MaterialLines};
use crate::model::pair::Mixing;
use crate::model::Material;
use toml::Spanned;

impl Converter {
    /// The pair law of the deck, if any: its name checked against `pairs/`, the tables read
    /// with units (the law itself checks their keys when it is built).
    pub(super) fn pair(
        &self,
        section: Option<&Spanned<PairSection>>,
        names: &[String],
    ) -> R<Option<PairSpec>> {
        let Some(section) = section else {
            return Ok(None);
        };
        let line = self.line_of(section);
        let s = section.get_ref();
        // "none" switches a deck's pair law off without deleting its tables (the cyclic bar's
        // run without contact).
        if s.law == "none" {
            return Ok(None);
        }
        if !crate::pairs::names().contains(&s.law.as_str()) {
            return self.err(
                line,
                format!(
                    "[pair] unknown law '{}' (known laws: {}, or none)",
                    s.law,
                    crate::pairs::names().join(", ")
                ),
            );
        }
        let length = |v: Option<&crate::input::units::Length>, what: &str| -> R<Option<f64>> {
            match v.map(|l| l.value(self.sys)) {
                Some(x) if !(x.is_finite() && x > 0.0) => {
                    self.err(line, format!("[pair] {what} must be > 0 (got {x})"))
                }
                v => Ok(v),
            }
        };
        let cutoff = length(s.cutoff.as_ref(), "cutoff")?;
        let skin = length(s.skin.as_ref(), "skin")?;
        let mixing = match s.mixing.as_deref() {
            None | Some("geometric") => Mixing::Geometric,
            Some("arithmetic") => Mixing::Arithmetic,
            Some(other) => {
                return self.err(
                    line,
                    format!("[pair] mixing = \"{other}\": use \"geometric\" or \"arithmetic\""),
                )
            }
        };
        let exclude_bonded = match s.exclude.as_deref() {
            None | Some("none") => false,
            Some("bonded") => true,
            Some(other) => {
                return self.err(
                    line,
                    format!("[pair] exclude = \"{other}\": use \"bonded\" or \"none\""),
                )
            }
        };
        let (own, between, lines) = self.pair_tables(s, names, line)?;
        Ok(Some(PairSpec {
            law: s.law.clone(),
            cutoff,
            skin,
            shift: s.shift,
            mixing,
            exclude_bonded,
            own,
            between,
            lines,
            line,
        }))
    }

    /// Each material's table (empty where the deck gives none) and the `[[pair.between]]`
    /// tables, with where their keys are.
    #[allow(clippy::type_complexity)]
    fn pair_tables(
        &self,
        s: &PairSection,
        names: &[String],
        line: usize,
    ) -> R<(Vec<Material>, Vec<(u16, u16, Material)>, Vec<MaterialLines>)> {
        let line_of = |v: &Spanned<_>| self.line_of(v);
        let read = |name: &str,
                    index: u16,
                    table: &materials::MaterialSection,
                    skip: &[&str],
                    at: usize| {
            materials::read_keys(name, index, table, skip, at, self.sys, &line_of)
                .map_err(|(l, m)| self.error_at(l, format!("[pair] {m}")))
        };
        for (name, t) in &s.materials {
            if !names.contains(name) {
                return self.err(
                    self.line_of(t),
                    format!(
                        "[pair.materials.{name}]: no material '{name}' in [materials] (materials: {})",
                        names.join(", ")
                    ),
                );
            }
        }
        let empty = materials::MaterialSection::default();
        let (mut own, mut lines) = (Vec::new(), Vec::new());
        for (k, name) in names.iter().enumerate() {
            let (table, at) = match s.materials.get(name) {
                Some(t) => (t.get_ref(), self.line_of(t)),
                None => (&empty, line),
            };
            let (m, l) = read(name, k as u16, table, &[], at)?;
            own.push(m);
            lines.push(l);
        }
        let mut between = Vec::new();
        for (k, t) in s.between.iter().enumerate() {
            let at = self.line_of(t);
            let Some([a, b]) = materials::pair_names(t.get_ref()) else {
                return self.err(
                    at,
                    "[[pair.between]] needs materials = [\"NAME\", \"NAME\"] (two material names)",
                );
            };
            let (ia, ib) = (
                self.material_id(names, &a, at)?,
                self.material_id(names, &b, at)?,
            );
            let index = (names.len() + k) as u16;
            let (m, l) = read(&format!("{a}-{b}"), index, t.get_ref(), &["materials"], at)?;
            between.push((ia, ib, m));
            lines.push(l);
        }
        Ok((own, between, lines))
    }
}
