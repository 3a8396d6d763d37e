//! `[model]` and `[materials]`: which model, its horizon and options, and each material with
//! the line of every key (the model reads the keys; `input/materials.rs`).

use super::convert::{Converter, R};
use super::sections::{ModelSection, OptionSpec};
use crate::input::materials::{self, MaterialLines, MaterialSection};
use crate::model::{Material, OptionValue};
use std::collections::BTreeMap;
use toml::Spanned;

/// `[model]` checked: the name, horizon and options, and where it is written.
pub(super) struct ModelChoice {
    pub(super) name: String,
    pub(super) line: usize,
    pub(super) options: Vec<(String, OptionValue)>,
    /// 0 for a bondless model ([`crate::model::Model::BONDED`]).
    pub(super) horizon: f64,
    pub(super) bonded: bool,
    pub(super) partial_volume: bool,
    pub(super) surface_correction: bool,
}

impl Converter {
    /// The model, with the horizon given directly or as `m` lattice spacings.
    pub(super) fn model(
        &self,
        section: Spanned<ModelSection>,
        spacing: f64,
        any_periodic: bool,
    ) -> R<ModelChoice> {
        let line = self.line_of(&section);
        let ms = section.into_inner();
        let surface_correction = match ms.surface_correction.as_deref() {
            None | Some("none") => false,
            Some("energy") => true,
            Some(other) => {
                return self.err(
                    line,
                    format!(
                        "[model] unknown surface_correction '{other}' (use \"none\" or \"energy\")"
                    ),
                )
            }
        };
        if surface_correction && any_periodic {
            return self.err(
                line,
                "[model] surface_correction = \"energy\" needs a body without periodic axes (the correction is found on the scene without its images)",
            );
        }
        // An unknown name is reported when the model is built; until then it is taken to have
        // bonds, so that its horizon is checked as always.
        let bonded = crate::models::find(&ms.name).is_none_or(|m| m.bonded);
        let horizon = if bonded {
            self.horizon(&ms, line, spacing)?
        } else {
            self.no_horizon(&ms, line, surface_correction)?
        };
        Ok(ModelChoice {
            name: ms.name,
            line,
            options: ms
                .options
                .into_iter()
                .map(|(k, v)| {
                    let v = match v {
                        OptionSpec::Number(x) => OptionValue::Number(x),
                        OptionSpec::Integer(x) => OptionValue::Number(x as f64),
                        OptionSpec::Word(w) => OptionValue::Word(w),
                    };
                    (k, v)
                })
                .collect(),
            horizon,
            bonded,
            partial_volume: ms.partial_volume.unwrap_or(true),
            surface_correction,
        })
    }

    /// `horizon`, or `m` times the spacing; positive and at least one spacing.
    fn horizon(&self, ms: &ModelSection, line: usize, spacing: f64) -> R<f64> {
        let horizon = match (ms.horizon, ms.m) {
            (Some(h), None) => h.value(self.sys),
            (None, Some(m)) => m * spacing,
            (None, None) => {
                return self.err(line, "[model] needs 'horizon' or 'm' (horizon / spacing)")
            }
            (Some(_), Some(_)) => return self.err(line, "[model] give 'horizon' or 'm', not both"),
        };
        if !(horizon.is_finite() && horizon > 0.0) {
            return self.err(line, format!("[model] horizon must be > 0 (got {horizon})"));
        }
        if horizon < spacing {
            return self.err(
                line,
                format!("[model] horizon {horizon} is smaller than the lattice spacing {spacing}: particles would have no bonds"),
            );
        }
        Ok(horizon)
    }

    /// A bondless model's horizon, 0: it finds no bonds, so the deck gives none, nor a
    /// surface correction of bonds.
    fn no_horizon(&self, ms: &ModelSection, line: usize, surface_correction: bool) -> R<f64> {
        let name = &ms.name;
        if ms.horizon.is_some() || ms.m.is_some() {
            return self.err(
                line,
                format!("[model] model '{name}' has no bonds, so no horizon: leave out 'horizon' and 'm'"),
            );
        }
        if surface_correction {
            return self.err(
                line,
                format!(
                    "[model] model '{name}' has no bonds to correct: leave out surface_correction"
                ),
            );
        }
        Ok(0.0)
    }

    /// The materials in name order (their index is the material id), with where each key is.
    pub(super) fn materials(
        &self,
        section: &Spanned<BTreeMap<String, Spanned<MaterialSection>>>,
    ) -> R<(Vec<String>, Vec<Material>, Vec<MaterialLines>)> {
        let names: Vec<String> = section.get_ref().keys().cloned().collect();
        if names.is_empty() {
            return self.err(self.line_of(section), "[materials] defines no material");
        }
        if names.len() > u16::MAX as usize {
            return self.err(self.line_of(section), "too many materials");
        }
        let line_of = |v: &Spanned<_>| self.line_of(v);
        let (mut materials, mut lines) = (Vec::new(), Vec::new());
        for (k, (name, m)) in section.get_ref().iter().enumerate() {
            let (material, at) = materials::read(
                name,
                k as u16,
                m.get_ref(),
                self.line_of(m),
                self.sys,
                &line_of,
            )
            .map_err(|(line, message)| self.error_at(line, message))?;
            materials.push(material);
            lines.push(at);
        }
        Ok((names, materials, lines))
    }
}
