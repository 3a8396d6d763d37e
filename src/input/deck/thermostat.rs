//! `[thermostat]`: which kind, its target temperature and time constant, and the group of
//! particles it holds at that temperature.

use super::convert::{Converter, R};
use super::sections::ThermostatSection;
use super::spec::{Located, Region, SolverSpec, ThermostatKind, ThermostatSpec, TimeSpec};
use crate::engine::simulation::Integrator;
use toml::Spanned;

const KINDS: &str = "\"rescale\", \"berendsen\", \"langevin\" or \"nose-hoover\"";

impl Converter {
    /// `[thermostat]`, checked against the materials' `names`, the integrator and the solver.
    pub(super) fn thermostat(
        &self,
        section: Option<&Spanned<ThermostatSection>>,
        names: &[String],
        time: &TimeSpec,
        solver: &Located<SolverSpec>,
    ) -> R<Option<ThermostatSpec>> {
        let Some(section) = section else {
            return Ok(None);
        };
        let line = self.line_of(section);
        let t = section.get_ref();
        if solver.item != SolverSpec::Explicit {
            return self.err(
                line,
                "[thermostat] acts in explicit time stepping only (a temperature needs the particles' motion); remove [solver] or the [thermostat] section",
            );
        }
        let temperature = *t.temperature.get_ref();
        if !(temperature.is_finite() && temperature >= 0.0) {
            return self.err(
                self.line_of(&t.temperature),
                format!("[thermostat] temperature must be ≥ 0 (got {temperature})"),
            );
        }
        let kind = self.thermostat_kind(t, line)?;
        if let (ThermostatKind::NoseHoover { .. }, Integrator::Leapfrog) = (kind, time.integrator) {
            return self.err(
                self.line_of(&t.kind),
                "[thermostat] kind = \"nose-hoover\" is integrated in the velocity-Verlet step; use [time] integrator = \"verlet\" (the default)",
            );
        }
        if matches!(kind, ThermostatKind::NoseHoover { .. }) && temperature == 0.0 {
            return self.err(
                self.line_of(&t.temperature),
                "[thermostat] kind = \"nose-hoover\" needs a temperature > 0 (its mass Q = dof·k_B·T·damping² would be 0); use \"berendsen\" or \"langevin\" to cool to rest",
            );
        }
        let region = match &t.region {
            Some(r) => self.region(r, line, "[thermostat]")?,
            None => Region::All,
        };
        let mut materials = Vec::new();
        if let Some(m) = &t.materials {
            let at = self.line_of(m);
            if m.get_ref().is_empty() {
                return self.err(at, "[thermostat] materials is empty: name at least one material, or leave the key out for every material");
            }
            for name in m.get_ref() {
                let id = self.material_id(names, name, at).map_err(|e| {
                    self.error_at(at, format!("[thermostat] materials: {}", e.message))
                })?;
                if !materials.contains(&id) {
                    materials.push(id);
                }
            }
        }
        Ok(Some(ThermostatSpec {
            line,
            kind,
            temperature,
            region,
            materials,
        }))
    }

    /// The kind and the keys it takes: `damping` (all but rescale), `seed` (langevin),
    /// `every` (rescale); a key another kind takes is refused, not ignored.
    fn thermostat_kind(&self, t: &ThermostatSection, line: usize) -> R<ThermostatKind> {
        let name = t.kind.get_ref().as_str();
        let takes = match name {
            "rescale" => ["every"].as_slice(),
            "berendsen" | "nose-hoover" => ["damping"].as_slice(),
            "langevin" => ["damping", "seed"].as_slice(),
            other => {
                return self.err(
                    self.line_of(&t.kind),
                    format!("[thermostat] unknown kind '{other}' (use {KINDS})"),
                )
            }
        };
        let given = [
            ("damping", t.damping.as_ref().map(|d| self.line_of(d))),
            ("seed", t.seed.as_ref().map(|s| self.line_of(s))),
            ("every", t.every.as_ref().map(|e| self.line_of(e))),
        ];
        for (key, at) in given {
            if let (Some(at), false) = (at, takes.contains(&key)) {
                return self.err(
                    at,
                    format!(
                        "[thermostat] kind = \"{name}\" takes no '{key}' (it reads {})",
                        takes.join(", ")
                    ),
                );
            }
            if let (None, true) = (at, takes.contains(&key) && key != "every") {
                return self.err(
                    line,
                    format!("[thermostat] kind = \"{name}\" needs '{key}'"),
                );
            }
        }
        let damping = match &t.damping {
            Some(d) => {
                let v = d.get_ref().value(self.sys);
                if !(v.is_finite() && v > 0.0) {
                    return self.err(
                        self.line_of(d),
                        format!("[thermostat] damping must be a time > 0 (got {v})"),
                    );
                }
                v
            }
            None => 0.0,
        };
        Ok(match name {
            "rescale" => {
                let every = t.every.as_ref().map_or(1, |e| *e.get_ref());
                if every < 1 {
                    let at = t.every.as_ref().map_or(line, |e| self.line_of(e));
                    return self.err(
                        at,
                        format!("[thermostat] every must be a number of steps ≥ 1 (got {every})"),
                    );
                }
                ThermostatKind::Rescale {
                    every: every as u64,
                }
            }
            "berendsen" => ThermostatKind::Berendsen { damping },
            "langevin" => {
                let seed = t.seed.as_ref().map_or(0, |s| *s.get_ref());
                if seed < 0 {
                    let at = t.seed.as_ref().map_or(line, |s| self.line_of(s));
                    return self.err(
                        at,
                        format!("[thermostat] seed must be an integer ≥ 0 (got {seed})"),
                    );
                }
                ThermostatKind::Langevin {
                    damping,
                    seed: seed as u64,
                }
            }
            _ => ThermostatKind::NoseHoover { damping },
        })
    }
}
