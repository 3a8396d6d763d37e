//! `[output]`, `[[probe]]` and `[[analysis]]`: where the run writes, how often, its
//! checkpoints, the points whose displacement is recorded (and may end the run), and the
//! voids and cracks analysed on the way.

use super::convert::{valid_name, Converter, R};
use super::sections::{AnalysisSection, OutputSection, ProbeSection};
use super::spec::{AnalysisKind, AnalysisSpec, Colouring, OutputSpec, ProbeSpec};
use std::path::PathBuf;
use toml::Spanned;

impl Converter {
    /// `[output]`, its defaults when the deck leaves it out; `stem` names the default directory.
    pub(super) fn output(
        &self,
        section: Option<&Spanned<OutputSection>>,
        stem: &str,
    ) -> R<OutputSpec> {
        let (out, line) = match section {
            Some(o) => (o.get_ref(), self.line_of(o)),
            None => (&OutputSection::default(), 1),
        };
        let history_every = out.history_every.unwrap_or(10);
        if history_every == 0 {
            return self.err(line, "[output] history_every must be ≥ 1");
        }
        let output = OutputSpec {
            directory: PathBuf::from(
                out.directory
                    .clone()
                    .unwrap_or_else(|| format!("out/{stem}")),
            ),
            history_every,
            frames_every: out.frames_every.unwrap_or(0),
            progress: out.progress.unwrap_or(true),
            final_state: out.final_state.unwrap_or(false),
            checkpoint_every: out.checkpoint_every.unwrap_or(0),
            checkpoint_minutes: out.checkpoint_minutes.unwrap_or(0.0),
            checkpoint_keep: out.checkpoint_keep.unwrap_or(3),
            restart: out.restart.as_ref().map(PathBuf::from),
            parts: out.parts,
            picture: match out.picture.as_deref() {
                None => Some(Colouring::Auto),
                Some("none") => None,
                Some(name) => Some(Colouring::parse(name).ok_or_else(|| {
                    self.error_at(
                        line,
                        format!(
                            "[output] picture '{name}' is not known (use {} or \"none\")",
                            Colouring::NAMES.map(|n| format!("\"{n}\"")).join(", ")
                        ),
                    )
                })?),
            },
        };
        if !(output.checkpoint_minutes.is_finite() && output.checkpoint_minutes >= 0.0) {
            return self.err(line, "[output] checkpoint_minutes must be ≥ 0");
        }
        if output.checkpoint_keep == 0 {
            return self.err(line, "[output] checkpoint_keep must be ≥ 1");
        }
        Ok(output)
    }

    /// The probes in deck order; names are unique (each is a history column).
    pub(super) fn probes(&self, entries: &[Spanned<ProbeSection>]) -> R<Vec<ProbeSpec>> {
        let mut probes: Vec<ProbeSpec> = Vec::new();
        for p in entries {
            let line = self.line_of(p);
            let name = p.get_ref().name.clone();
            if !valid_name(&name) {
                return self.err(
                    line,
                    format!("probe name '{name}' must be letters, digits, '_' or '-'"),
                );
            }
            if probes.iter().any(|p| p.name == name) {
                return self.err(line, format!("probe name '{name}' is used twice"));
            }
            let stop_beyond = match &p.get_ref().stop_beyond {
                None => f64::INFINITY,
                Some(d) => {
                    let d = d.value(self.sys);
                    if !(d.is_finite() && d > 0.0) {
                        return self.err(
                            line,
                            format!("probe '{name}': stop_beyond must be a length > 0 (got {d})"),
                        );
                    }
                    d
                }
            };
            probes.push(ProbeSpec {
                name,
                line,
                at: self.finite3(p.get_ref().at.value(self.sys), line, "probe: 'at'")?,
                stop_beyond,
            });
        }
        Ok(probes)
    }

    /// The analyses in deck order. `spacing` is the default voxel; `bondless`: the model has
    /// no bonds to crack; `bond_drops`: shuffles drop broken bonds from the bond list, out of a
    /// crack analysis's sight.
    pub(super) fn analyses(
        &self,
        entries: &[Spanned<AnalysisSection>],
        spacing: f64,
        bondless: bool,
        bond_drops: bool,
    ) -> R<Vec<AnalysisSpec>> {
        let mut analyses: Vec<AnalysisSpec> = Vec::new();
        for e in entries {
            let (a, line) = (e.get_ref(), self.line_of(e));
            let kind = match a.kind.as_str() {
                "voids" => AnalysisKind::Voids,
                "cracks" => AnalysisKind::Cracks,
                k => {
                    return self.err(
                        line,
                        format!(
                            "[[analysis]] kind '{k}' is not known (use \"voids\" or \"cracks\")"
                        ),
                    )
                }
            };
            let name = a.name.clone().unwrap_or_else(|| kind.name().to_string());
            if !valid_name(&name) {
                return self.err(
                    line,
                    format!("analysis name '{name}' must be letters, digits, '_' or '-'"),
                );
            }
            if analyses.iter().any(|x| x.name == name) {
                return self.err(
                    line,
                    format!("analysis name '{name}' is used twice (it names the analysis's files): give each [[analysis]] its own `name`"),
                );
            }
            if a.every < 1 {
                return self.err(
                    line,
                    format!(
                        "[[analysis]] every = {}: give a number of steps ≥ 1",
                        a.every
                    ),
                );
            }
            let voxel = a.voxel.as_ref().map_or(spacing, |v| v.value(self.sys));
            if !(voxel.is_finite() && voxel > 0.0) {
                return self.err(
                    line,
                    format!("[[analysis]] voxel must be a length > 0 (got {voxel})"),
                );
            }
            let all_neighbours = match a.connectivity.as_deref() {
                None => kind == AnalysisKind::Cracks,
                Some("face") => false,
                Some("all") => true,
                Some(c) => {
                    return self.err(
                        line,
                        format!("[[analysis]] connectivity '{c}' is not known (use \"face\": 6 neighbours, or \"all\": 26)"),
                    )
                }
            };
            let scheme = a.scheme.clone().unwrap_or_else(|| "boundary".into());
            if !["boundary", "min-label", "gather"].contains(&scheme.as_str()) {
                return self.err(
                    line,
                    format!("[[analysis]] scheme '{scheme}' is not known (use \"boundary\", \"min-label\" or \"gather\")"),
                );
            }
            if kind == AnalysisKind::Cracks && bondless {
                return self.err(
                    line,
                    "[[analysis]] kind = \"cracks\" looks for broken bonds, and this model has none (no horizon): use kind = \"voids\"",
                );
            }
            if kind == AnalysisKind::Cracks && bond_drops {
                return self.err(
                    line,
                    "[[analysis]] kind = \"cracks\" cannot run beside shuffles of a bonded scene ([parallel] shuffle_every, or a [pair] law with bonds): a shuffle drops broken bonds from the bond list, where the analysis would not see them",
                );
            }
            analyses.push(AnalysisSpec {
                name,
                line,
                kind,
                every: a.every as u64,
                voxel,
                all_neighbours,
                scheme,
            });
        }
        Ok(analyses)
    }
}
