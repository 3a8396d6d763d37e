//! `[[boundary]]`, `[[load]]`, `[[initial]]` and `[velocity]`: what is held or moved, what
//! pushes or heats, and the state at the start, each on a region and (boundaries and loads)
//! with a history.

use super::convert::{valid_name, Converter, R};
use super::sections::{BoundarySection, HistorySpec, InitialSection, LoadSection, VelocitySection};
use super::spec::{BoundarySpec, InitialSpec, LoadKind, LoadSpec, Region, VelocitySpec};
use crate::engine::boundary::{History, Motion, TEMPERATURE};
use toml::Spanned;

impl Converter {
    /// The boundaries in deck order; names are unique.
    pub(super) fn boundaries(&self, entries: &[Spanned<BoundarySection>]) -> R<Vec<BoundarySpec>> {
        let mut boundaries: Vec<BoundarySpec> = Vec::new();
        for b in entries {
            let line = self.line_of(b);
            let spec = self.boundary(b.get_ref(), line)?;
            if boundaries.iter().any(|o| o.name == spec.name) {
                return self.err(line, format!("boundary name '{}' is used twice", spec.name));
            }
            boundaries.push(spec);
        }
        Ok(boundaries)
    }

    /// The loads in deck order; a name may not repeat a load's or a boundary's.
    pub(super) fn loads(
        &self,
        entries: &[Spanned<LoadSection>],
        boundaries: &[BoundarySpec],
    ) -> R<Vec<LoadSpec>> {
        let mut names: Vec<String> = boundaries.iter().map(|b| b.name.clone()).collect();
        let mut loads = Vec::new();
        for l in entries {
            let line = self.line_of(l);
            let spec = self.load(l.get_ref(), line)?;
            if names.contains(&spec.name) {
                return self.err(line, format!("load name '{}' is used twice", spec.name));
            }
            names.push(spec.name.clone());
            loads.push(spec);
        }
        Ok(loads)
    }

    /// The initial velocities, angular velocities and temperatures, in deck order.
    pub(super) fn initial(&self, entries: &[Spanned<InitialSection>]) -> R<Vec<InitialSpec>> {
        let mut initial = Vec::new();
        for i in entries {
            let line = self.line_of(i);
            let s = i.get_ref();
            let region = match &s.region {
                Some(r) => self.region(r, line, "initial")?,
                None => Region::All,
            };
            let vector = |v: Option<[f64; 3]>, what: &str| -> R<Option<[f64; 3]>> {
                v.map(|v| self.finite3(v, line, &format!("initial: {what}")))
                    .transpose()
            };
            let spec = InitialSpec {
                line,
                region,
                velocity: vector(s.velocity.map(|v| v.value(self.sys)), "velocity")?,
                angular_velocity: vector(
                    s.angular_velocity.map(|v| v.value(self.sys)),
                    "angular_velocity",
                )?,
                temperature: s.temperature,
            };
            if let Some(t) = spec.temperature {
                if !t.is_finite() {
                    return self.err(
                        line,
                        format!("initial: temperature must be finite (got {t})"),
                    );
                }
            }
            if spec.velocity.is_none()
                && spec.angular_velocity.is_none()
                && spec.temperature.is_none()
            {
                return self.err(
                    line,
                    "initial: give 'velocity', 'angular_velocity' or 'temperature'",
                );
            }
            initial.push(spec);
        }
        Ok(initial)
    }

    /// `[velocity]`: a temperature ≥ 0 and a seed ≥ 0, on a region (default: every particle).
    pub(super) fn velocity(
        &self,
        section: Option<&Spanned<VelocitySection>>,
    ) -> R<Option<VelocitySpec>> {
        let Some(section) = section else {
            return Ok(None);
        };
        let line = self.line_of(section);
        let v = section.get_ref();
        if !(v.temperature.is_finite() && v.temperature >= 0.0) {
            return self.err(
                line,
                format!("[velocity] temperature must be ≥ 0 (got {})", v.temperature),
            );
        }
        if v.seed < 0 {
            return self.err(
                line,
                format!("[velocity] seed must be an integer ≥ 0 (got {})", v.seed),
            );
        }
        let region = match &v.region {
            Some(r) => self.region(r, line, "[velocity]")?,
            None => Region::All,
        };
        Ok(Some(VelocitySpec {
            line,
            temperature: v.temperature,
            seed: v.seed as u64,
            region,
        }))
    }

    fn history(&self, h: &Option<HistorySpec>, line: usize, ctx: &str) -> R<History> {
        let hist = match h {
            None => History::Constant,
            Some(HistorySpec {
                ramp: Some(r),
                table: None,
            }) => History::Ramp {
                duration: r.value(self.sys),
            },
            Some(HistorySpec {
                ramp: None,
                table: Some(t),
            }) => History::Table(t.iter().map(|(t, f)| (t.value(self.sys), *f)).collect()),
            Some(_) => {
                return self.err(
                    line,
                    format!("{ctx}: history takes one of 'ramp' or 'table'"),
                )
            }
        };
        hist.validate()
            .or_else(|e| self.err(line, format!("{ctx}: {e}")))?;
        Ok(hist)
    }

    fn components(&self, names: &[String], line: usize, ctx: &str) -> R<Vec<usize>> {
        let mut dofs = Vec::new();
        for n in names {
            let more: &[usize] = match n.as_str() {
                "x" => &[0],
                "y" => &[1],
                "z" => &[2],
                "all" => &[0, 1, 2],
                "rx" => &[3],
                "ry" => &[4],
                "rz" => &[5],
                "rotation" => &[3, 4, 5],
                "temperature" => &[TEMPERATURE],
                other => {
                    return self.err(
                        line,
                        format!(
                        "{ctx}: unknown component '{other}' (use \"x\", \"y\", \"z\", \"all\", \"rx\", \"ry\", \"rz\", \"rotation\" or \"temperature\")"
                    ),
                    )
                }
            };
            for d in more {
                if !dofs.contains(d) {
                    dofs.push(*d);
                }
            }
        }
        if dofs.is_empty() {
            return self.err(line, format!("{ctx}: no component selected"));
        }
        dofs.sort_unstable();
        Ok(dofs)
    }

    fn boundary(&self, b: &BoundarySection, line: usize) -> R<BoundarySpec> {
        let ctx = format!("boundary '{}'", b.name);
        if !valid_name(&b.name) {
            return self.err(
                line,
                format!("{ctx}: names are letters, digits, '_' or '-'"),
            );
        }
        let region = self.region(&b.region, line, &ctx)?;
        let history = self.history(&b.history, line, &ctx)?;
        let comps = |c: &Option<Vec<String>>| -> R<Vec<usize>> {
            match c {
                Some(c) => self.components(c, line, &ctx),
                None => Ok(vec![0, 1, 2]),
            }
        };
        let (dofs, motion) = match (&b.fixed, b.velocity, b.displacement) {
            _ if b.temperature.is_some() => {
                if b.fixed.is_some() || b.velocity.is_some() || b.displacement.is_some() {
                    return self.err(
                        line,
                        format!("{ctx}: give exactly one of 'fixed', 'velocity', 'displacement' or 'temperature'"),
                    );
                }
                if b.components.is_some() {
                    return self.err(line, format!("{ctx}: 'temperature' takes no components"));
                }
                let t = b.temperature.unwrap_or_default();
                if !t.is_finite() {
                    return self.err(line, format!("{ctx}: temperature must be finite (got {t})"));
                }
                (vec![TEMPERATURE], Motion::Displacement(vec![t]))
            }
            (Some(f), None, None) => {
                if b.components.is_some() {
                    return self.err(line, format!("{ctx}: 'fixed' lists its own components"));
                }
                (self.components(f, line, &ctx)?, Motion::Fixed)
            }
            (None, Some(v), None) => {
                let dofs = comps(&b.components)?;
                if dofs.iter().any(|&d| d > 2) {
                    return self.err(line, format!("{ctx}: 'velocity' prescribes x, y, z only"));
                }
                let v = self.finite3(v.value(self.sys), line, &format!("{ctx}: velocity"))?;
                (
                    dofs.clone(),
                    Motion::Velocity(dofs.iter().map(|&d| v[d]).collect()),
                )
            }
            (None, None, Some(u)) => {
                let dofs = comps(&b.components)?;
                if dofs.iter().any(|&d| d > 2) {
                    return self.err(
                        line,
                        format!("{ctx}: 'displacement' prescribes x, y, z only"),
                    );
                }
                let u = self.finite3(u.value(self.sys), line, &format!("{ctx}: displacement"))?;
                (
                    dofs.clone(),
                    Motion::Displacement(dofs.iter().map(|&d| u[d]).collect()),
                )
            }
            _ => {
                return self.err(
                    line,
                    format!("{ctx}: give exactly one of 'fixed', 'velocity', 'displacement' or 'temperature'"),
                )
            }
        };
        Ok(BoundarySpec {
            name: b.name.clone(),
            line,
            region,
            dofs,
            motion,
            history,
        })
    }

    fn load(&self, l: &LoadSection, line: usize) -> R<LoadSpec> {
        let ctx = format!("load '{}'", l.name);
        if !valid_name(&l.name) {
            return self.err(
                line,
                format!("{ctx}: names are letters, digits, '_' or '-'"),
            );
        }
        let sys = self.sys;
        let kinds: Vec<LoadKind> = [
            l.force_per_particle
                .map(|v| LoadKind::PerParticle(v.value(sys))),
            l.total_force.map(|v| LoadKind::Total(v.value(sys))),
            l.body_force.map(|v| LoadKind::BodyForce(v.value(sys))),
            l.gravity.map(|v| LoadKind::Gravity(v.value(sys))),
            l.heat_flux.map(LoadKind::HeatFlux),
            l.heat_source.map(LoadKind::HeatSource),
            l.total_heat.map(LoadKind::TotalHeat),
        ]
        .into_iter()
        .flatten()
        .collect();
        if kinds.len() != 1 {
            return self.err(
                line,
                format!("{ctx}: give exactly one of 'force_per_particle', 'total_force', 'body_force', 'gravity', 'heat_flux', 'heat_source' or 'total_heat'"),
            );
        }
        match kinds[0] {
            LoadKind::PerParticle(v)
            | LoadKind::Total(v)
            | LoadKind::BodyForce(v)
            | LoadKind::Gravity(v) => {
                self.finite3(v, line, &format!("{ctx}: the load vector"))?;
            }
            LoadKind::HeatFlux(q) | LoadKind::HeatSource(q) | LoadKind::TotalHeat(q) => {
                if !q.is_finite() {
                    return self.err(line, format!("{ctx}: the heat must be finite (got {q})"));
                }
            }
        }
        let region = match &l.region {
            Some(r) => self.region(r, line, &ctx)?,
            None => Region::All,
        };
        Ok(LoadSpec {
            name: l.name.clone(),
            line,
            region,
            kind: kinds[0],
            history: self.history(&l.history, line, &ctx)?,
        })
    }
}
