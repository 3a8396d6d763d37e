//! What a validation case measures (`[validation.measure] kind = …`): the value read from the
//! run's history or last frame, and the curve drawn against the reference.

use super::{CurveReader, Extractor};
use crate::driver::run::Summary;
use crate::input::deck::{Region, Scene};
use crate::input::geometry::Shape;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A measured value and the names of the history columns it reads.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Measure {
    /// The deflection (downward positive) under a load: minus the mean of these probes' u_z.
    DeflectionAt { probes: Vec<String> },
    /// The deflection of `mid` relative to the mean of `ends` (downward positive): the ends
    /// sit above the supports, so this removes the supports' local indentation.
    DeflectionBetween { mid: String, ends: [String; 2] },
    /// The load's value at the step where the run stopped on its broken-bond count
    /// (`[time] stop_at_broken_bonds`), per length of the loaded region if asked.
    LoadAtBrokenBonds {
        load: String,
        probe: String,
        #[serde(default)]
        per_length: bool,
    },
    /// The load's value at the step where `probe` moved beyond its `stop_beyond`.
    LoadAtProbeStop {
        load: String,
        probe: String,
        #[serde(default)]
        per_length: bool,
    },
    /// The largest pull force of a pullout: `grip`'s support reaction along x, over the run,
    /// drawn against the separation of the two probes `ends` (the gripped bar ends; u_x of
    /// the second less the first).
    PeakPull { grip: String, ends: [String; 2] },
}

impl Measure {
    /// The extractor and the measured curve of a case run from `scene`.
    pub fn prepare(&self, scene: &Scene) -> Result<(Extractor, CurveReader), String> {
        Ok(match self.clone() {
            Measure::DeflectionAt { probes } => {
                let columns: Vec<String> = probes.iter().map(|p| format!("{p}_uz")).collect();
                let extract: Extractor = Box::new(move |_, dir| {
                    let mut sum = 0.0;
                    for c in &columns {
                        sum += last_of(dir, c)?;
                    }
                    Ok(-sum / columns.len() as f64)
                });
                (extract, Box::new(axis_deflection))
            }
            Measure::DeflectionBetween { mid, ends } => {
                let extract: Extractor = Box::new(move |_, dir| {
                    let mid = last_of(dir, &format!("{mid}_uz"))?;
                    let left = last_of(dir, &format!("{}_uz", ends[0]))?;
                    let right = last_of(dir, &format!("{}_uz", ends[1]))?;
                    Ok(0.5 * (left + right) - mid)
                });
                (extract, Box::new(axis_deflection))
            }
            Measure::LoadAtBrokenBonds {
                load,
                probe,
                per_length,
            } => {
                let per = divisor(scene, &load, per_length)?;
                let column = format!("load_{load}");
                let extract: Extractor = Box::new(move |summary: &Summary, dir: &Path| {
                    if !summary.stopped_at_broken {
                        return Err(format!(
                            "the beam did not fail within the ramp: {} broken bonds at the end",
                            summary.broken
                        ));
                    }
                    Ok(last_of(dir, &column)? / per)
                });
                (extract, load_against(&load, &probe))
            }
            Measure::LoadAtProbeStop {
                load,
                probe,
                per_length,
            } => {
                let per = divisor(scene, &load, per_length)?;
                let limit = scene
                    .probes
                    .iter()
                    .find(|p| p.name == probe)
                    .map(|p| p.stop_beyond)
                    .ok_or_else(|| {
                        format!(
                            "the measure reads a [[probe]] named '{probe}', and the deck has none"
                        )
                    })?;
                let (column, name) = (format!("load_{load}"), probe.clone());
                let extract: Extractor = Box::new(move |summary: &Summary, dir: &Path| {
                    if summary.stopped_at_probe.as_deref() == Some(name.as_str()) {
                        return Ok(last_of(dir, &column)? / per);
                    }
                    Err(format!(
                        "the beam did not collapse within the ramp: the deflection of '{name}' stayed below {limit:.4}"
                    ))
                });
                (extract, load_against(&load, &probe))
            }
            Measure::PeakPull { grip, ends } => {
                let curve = pull_against_separation(&grip, &ends);
                let extract: Extractor = Box::new(move |_, dir| peak_pull(&curve, dir));
                (extract, pull_against_separation(&grip, &ends))
            }
        })
    }
}

/// The largest force of the (separation, force) curve; an error if one is not finite.
fn peak_pull(curve: &CurveReader, dir: &Path) -> Result<f64, String> {
    let curve = curve(dir)?;
    if let Some(&(_, f)) = curve.iter().find(|(_, f)| !f.is_finite()) {
        return Err(format!("the pull force in history.csv is not finite ({f})"));
    }
    curve
        .iter()
        .map(|&(_, f)| f)
        .reduce(f64::max)
        .ok_or_else(|| "history.csv has no rows".to_string())
}

/// (separation of the two gripped bar ends, the grip's reaction along x) over the rows.
fn pull_against_separation(grip: &str, ends: &[String; 2]) -> CurveReader {
    let force = format!("reaction_{grip}_x");
    let (left, right) = (format!("{}_ux", ends[0]), format!("{}_ux", ends[1]));
    Box::new(move |dir| {
        let (header, rows) = read_history(dir)?;
        let col = |name: &str| column(&header, name);
        let (f, r, l) = (col(&force)?, col(&right)?, col(&left)?);
        Ok(rows.iter().map(|row| (row[r] - row[l], row[f])).collect())
    })
}

/// The length of the loaded region along x when the measure is per length, else 1.
fn divisor(scene: &Scene, load: &str, per_length: bool) -> Result<f64, String> {
    if !per_length {
        return Ok(1.0);
    }
    let region = scene
        .loads
        .iter()
        .find(|l| l.name == load)
        .map(|l| &l.region)
        .ok_or_else(|| {
            format!("the measure reads a [[load]] named '{load}', and the deck has none")
        })?;
    match region {
        Region::Shape(Shape::Box { min, max }) => Ok(max[0] - min[0]),
        Region::Shape(Shape::Slab { axis: 0, from, to }) => Ok(to - from),
        _ => Err(format!(
            "load '{load}': per_length needs a box or a slab across x"
        )),
    }
}

/// (deflection of `probe`, the applied `load`) over the history rows.
fn load_against(load: &str, probe: &str) -> CurveReader {
    let (load, uz) = (format!("load_{load}"), format!("{probe}_uz"));
    Box::new(move |dir| {
        let (header, rows) = read_history(dir)?;
        let (l, u) = (column(&header, &load)?, column(&header, &uz)?);
        Ok(rows.iter().map(|r| (-r[u], r[l])).collect())
    })
}

/// The columns of `history.csv` by name, and its rows.
pub fn read_history(dir: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let path = dir.join("history.csv");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| format!("{}: empty", path.display()))?
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| {
                    v.parse::<f64>()
                        .map_err(|e| format!("{}: {e}", path.display()))
                })
                .collect::<Result<Vec<f64>, String>>()
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((header, rows))
}

/// The index of a history column.
pub(super) fn column(header: &[String], name: &str) -> Result<usize, String> {
    header
        .iter()
        .position(|h| h == name)
        .ok_or_else(|| format!("history.csv has no column '{name}'"))
}

/// The last value of a history column.
pub fn last_of(dir: &Path, name: &str) -> Result<f64, String> {
    let (header, rows) = read_history(dir)?;
    let c = column(&header, name)?;
    rows.last()
        .map(|r| r[c])
        .ok_or_else(|| "history.csv has no rows".to_string())
}

/// The particles of a run's last frame: reference positions, displacements, damage and volumes.
pub(super) struct Frame {
    pub x0: Vec<[f64; 3]>,
    pub u: Vec<[f64; 3]>,
    pub damage: Vec<f64>,
    pub volume: Vec<f64>,
}

/// The last frame of the run in `dir`.
pub(super) fn last_frame(dir: &Path) -> Result<Frame, String> {
    let frames = dir.join("frames");
    // Frame files are named frame_<step>.h5; the step is zero-padded to 8 digits only.
    let step_of = |p: &PathBuf| {
        p.file_stem()
            .and_then(|s| s.to_str())
            .and_then(|s| s.strip_prefix("frame_"))
            .and_then(|s| s.parse::<u64>().ok())
    };
    let last = std::fs::read_dir(&frames)
        .map_err(|e| format!("{}: {e}", frames.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "h5"))
        .filter_map(|p| step_of(&p).map(|s| (s, p)))
        .max_by_key(|(s, _)| *s)
        .map(|(_, p)| p)
        .ok_or_else(|| format!("{}: no frames", frames.display()))?;
    let f = hdf5_pure::File::open(&last).map_err(|e| format!("{}: {e}", last.display()))?;
    let read = |name: &str| {
        f.dataset(name)
            .and_then(|d| d.read_f64())
            .map_err(|e| format!("{}: {name}: {e}", last.display()))
    };
    let vectors =
        |v: Vec<f64>| -> Vec<[f64; 3]> { v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() };
    let (points, u) = (vectors(read("points")?), vectors(read("displacement")?));
    let x0 = points
        .iter()
        .zip(&u)
        .map(|(p, u)| [p[0] - u[0], p[1] - u[1], p[2] - u[2]])
        .collect();
    Ok(Frame {
        x0,
        u,
        damage: read("damage")?,
        volume: read("volume")?,
    })
}

/// (x₀, u_z) of the particles on the beam's axis in the last frame (those nearest the line
/// through the section's centre along x).
pub(super) fn axis_deflection(dir: &Path) -> Result<Vec<(f64, f64)>, String> {
    let Frame { x0, u, .. } = last_frame(dir)?;
    let centre = |k: usize| {
        let (lo, hi) = x0
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x[k]), b.max(x[k])));
        0.5 * (lo + hi)
    };
    let (yc, zc) = (centre(1), centre(2));
    let off = |x: &[f64; 3]| (x[1] - yc).hypot(x[2] - zc);
    let nearest = x0.iter().map(off).fold(f64::MAX, f64::min);
    let mut line: Vec<(f64, f64)> = x0
        .iter()
        .zip(&u)
        .filter(|(x, _)| off(x) <= nearest + 1e-9)
        .map(|(x, u)| (x[0], u[2]))
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(line)
}

/// Draws the last frame of the run in `dir` coloured by damage into `path`, the displacements
/// magnified (never shrunk) so that the largest is 4 % of the body's length.
pub(super) fn draw_damage_views(dir: &Path, path: &Path, title: &str) -> Result<(), String> {
    let frame = last_frame(dir)?;
    let extent = (0..3)
        .map(|k| {
            let (lo, hi) = frame
                .x0
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x[k]), b.max(x[k])));
            hi - lo
        })
        .fold(0.0, f64::max);
    let largest = frame
        .u
        .iter()
        .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    let magnify = if largest > 0.0 {
        (0.04 * extent / largest).max(1.0)
    } else {
        1.0
    };
    // Lattice particles fill a cube of their volume; bar particles are drawn at that size too.
    let mut volumes = frame.volume.clone();
    volumes.sort_by(f64::total_cmp);
    let spacing = volumes
        .get(volumes.len() / 2)
        .ok_or_else(|| format!("{}: the last frame has no particles", dir.display()))?
        .cbrt();
    crate::output::plot::particle_views(
        path,
        &format!("{title}; displacements × {magnify:.1}"),
        &crate::output::plot::Body {
            x0: &frame.x0,
            displacement: &frame.u,
            value: &frame.damage,
            spacing,
            scale: crate::output::plot::damage_scale(),
        },
        magnify,
    )
}
