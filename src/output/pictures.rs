//! Pictures of a run's history, drawn at the end of every `pdq run` and by `pdq pictures DIR`
//! from the output directory's `history.csv`: energies, broken bonds, each moving grip's load
//! against its displacement, each held grip's reaction, each probe's displacement, and for
//! molecular dynamics temperature and pressure; each applied load against time; and for each
//! `[[analysis]]` its clusters' count and size against time. They go to `DIR/pictures/`.

use super::curves::Columns;
use super::plot::{xy, Mark, Series};
use std::path::{Path, PathBuf};

/// One picture: its file name, title, axis labels and curves (name, column of y).
struct Picture {
    file: String,
    title: String,
    x: String,
    y: String,
    curves: Vec<(String, Vec<(f64, f64)>)>,
}

/// Draws the history pictures of the run in `dir`; returns the files written.
pub fn history_pictures(dir: &Path, title: &str) -> Result<Vec<PathBuf>, String> {
    let path = dir.join("history.csv");
    let h = Columns::read(&path)?;
    if h.rows.len() < 2 {
        // One row is a point, not a history.
        return Ok(Vec::new());
    }
    let out = dir.join("pictures");
    std::fs::create_dir_all(&out).map_err(|e| format!("creating {}: {e}", out.display()))?;
    let mut written = Vec::new();
    for p in pictures(&h, &path, title)? {
        let file = out.join(&p.file);
        let series: Vec<Series> = p
            .curves
            .iter()
            .map(|(name, points)| Series {
                name,
                points,
                mark: Mark::Line,
            })
            .collect();
        xy(&file, &p.title, &p.x, &p.y, &series)?;
        written.push(file);
    }
    written.extend(analysis_pictures(dir, title)?);
    Ok(written)
}

/// For each analysis table (`NAME.csv` beside `NAME_events.csv`): its clusters' count, and
/// their total and largest volume (voids) or area (cracks), against time.
fn analysis_pictures(dir: &Path, title: &str) -> Result<Vec<PathBuf>, String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| {
            let f = e.ok()?.file_name().into_string().ok()?;
            Some(f.strip_suffix("_events.csv")?.to_string())
        })
        .collect();
    names.sort();
    let mut written = Vec::new();
    for name in names {
        let path = dir.join(format!("{name}.csv"));
        let Ok(t) = Columns::read(&path) else {
            continue;
        };
        if t.rows.len() < 2 {
            continue;
        }
        let col = |c: &str| t.column(c, 1.0, &path);
        let time = col("time")?;
        let against = |y: Vec<f64>| time.iter().copied().zip(y).collect::<Vec<_>>();
        let (what, total, largest) = if t.names.iter().any(|n| n == "porosity") {
            ("volume", "volume", "largest_volume")
        } else {
            ("area", "area", "largest_area")
        };
        let count = [(name.clone(), against(col("count")?))];
        let sizes = [
            (format!("total {what}"), against(col(total)?)),
            (format!("largest {what}"), against(col(largest)?)),
        ];
        for (file, y, curves) in [
            (format!("{name}_count.png"), "count".to_string(), &count[..]),
            (format!("{name}_{what}.png"), what.to_string(), &sizes[..]),
        ] {
            let file = dir.join("pictures").join(file);
            let series: Vec<Series> = curves
                .iter()
                .map(|(n, points)| Series {
                    name: n,
                    points,
                    mark: Mark::Line,
                })
                .collect();
            xy(&file, &format!("{title}: {name}"), "time", &y, &series)?;
            written.push(file);
        }
    }
    Ok(written)
}

/// `pdq pictures DIR`: the history pictures, and the body from `final_positions.csv` if the
/// run wrote it; the files written.
pub fn redraw(dir: &Path, title: &str) -> Result<Vec<PathBuf>, String> {
    if !dir.join("history.csv").exists() {
        return Err(format!(
            "{} has no history.csv: give the output directory of a run",
            dir.display()
        ));
    }
    let mut files = history_pictures(dir, title)?;
    let last = dir.join("final_positions.csv");
    if last.exists() {
        let f = Columns::read(&last)?;
        let col = |name: &str| f.column(name, 1.0, &last);
        let (x, y, z) = (col("x")?, col("y")?, col("z")?);
        let position: Vec<[f64; 3]> = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
        let damage = col("damage")?;
        let (value, scale, what) = if damage.iter().any(|&d| d > 0.0) {
            (damage, super::plot::damage_scale(), "damage")
        } else {
            let (vx, vy, vz) = (col("vx")?, col("vy")?, col("vz")?);
            let speed: Vec<f64> = (0..vx.len())
                .map(|i| (vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i]).sqrt())
                .collect();
            let top = speed.iter().cloned().fold(0.0, f64::max).max(1e-300);
            let scaled = speed.iter().map(|s| s / top).collect();
            (scaled, ["speed 0".into(), format!("{top:.3e}")], "speed")
        };
        let file = dir.join("pictures").join("body.png");
        super::plot::particle_views(
            &file,
            &format!("{title}: final state, coloured by {what}"),
            &super::plot::Body {
                x0: &position,
                displacement: &vec![[0.0; 3]; position.len()],
                value: &value,
                spacing: typical_spacing(&position),
                scale,
            },
            1.0,
        )?;
        files.push(file);
    }
    Ok(files)
}

/// What a picture of the largest clusters shows: which analysis, of what, at which step.
pub struct LargestOf<'a> {
    /// The analysis's name: the picture is `pictures/NAME_largest.png`.
    pub name: &'a str,
    /// The run's title.
    pub title: &'a str,
    /// "voids" or "cracks".
    pub what: &'a str,
    pub step: u64,
    /// Clusters found at that step.
    pub total: usize,
}

/// Where the largest clusters are, in `dir/pictures/NAME_largest.png`: `voxels` (centre,
/// place: 0 for the largest) drawn as cubes of the voxel's side, the largest dark red, the
/// next ones through yellow to light blue, with the eight corners of the grid as dark blue
/// cubes so that the view spans it. Side and oblique views, as the body's picture.
pub fn largest_clusters(
    dir: &Path,
    of: &LargestOf,
    grid: &crate::voids::VoxelGrid,
    voxels: &[([f64; 3], usize)],
) -> Result<PathBuf, String> {
    const SHADE: [f64; 5] = [1.0, 0.8, 0.6, 0.4, 0.25];
    let out = dir.join("pictures");
    std::fs::create_dir_all(&out).map_err(|e| format!("creating {}: {e}", out.display()))?;
    let (lo, side) = (grid.origin, grid.size);
    let hi = [0, 1, 2].map(|a| lo[a] + grid.dims[a] as f64 * side[a]);
    let mut x0: Vec<[f64; 3]> = (0..8)
        .map(|k| [0, 1, 2].map(|a| if k >> a & 1 == 0 { lo[a] } else { hi[a] }))
        .collect();
    let mut value = vec![0.0; 8];
    for (c, place) in voxels {
        x0.push(*c);
        value.push(SHADE[(*place).min(SHADE.len() - 1)]);
    }
    let side = side.iter().fold(f64::INFINITY, |m, &s| m.min(s));
    let shown = voxels.iter().map(|v| v.1 + 1).max().unwrap_or(0);
    let title = format!(
        "{}: {} at step {}, the {shown} largest of {} (dark red: largest), voxels of {side:.3e}",
        of.title, of.what, of.step, of.total
    );
    let path = out.join(format!("{}_largest.png", of.name));
    super::plot::particle_views(
        &path,
        &title,
        &super::plot::Body {
            x0: &x0,
            displacement: &vec![[0.0; 3]; x0.len()],
            value: &value,
            spacing: side,
            scale: ["grid corners".into(), "largest".into()],
        },
        1.0,
    )?;
    Ok(path)
}

/// The spacing of `n` particles filling their bounding box (a particle's square in a picture).
fn typical_spacing(position: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in position {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let extent: Vec<f64> = (0..3).map(|a| hi[a] - lo[a]).filter(|&e| e > 0.0).collect();
    let volume: f64 = extent.iter().product();
    (volume / position.len().max(1) as f64).powf(1.0 / extent.len().max(1) as f64)
}

/// What the history holds worth a picture.
fn pictures(h: &Columns, path: &Path, title: &str) -> Result<Vec<Picture>, String> {
    let col = |name: &str| h.column(name, 1.0, path);
    let has = |name: &str| h.names.iter().any(|n| n == name);
    let time = col("time")?;
    let against = |x: &[f64], y: Vec<f64>| x.iter().copied().zip(y).collect::<Vec<_>>();
    let varies = |v: &[f64]| v.iter().any(|&a| a != v[0]);
    let mut all = Vec::new();

    let mut energies = Vec::new();
    for name in [
        "kinetic_energy",
        "strain_energy",
        "pair_energy",
        "total_energy",
        "conserved_energy",
    ] {
        if has(name) {
            energies.push((name.replace('_', " "), against(&time, col(name)?)));
        }
    }
    all.push(Picture {
        file: "energy.png".into(),
        title: format!("{title}: energies"),
        x: "time".into(),
        y: "energy".into(),
        curves: energies,
    });

    let broken = col("broken_bonds")?;
    if varies(&broken) {
        all.push(Picture {
            file: "broken_bonds.png".into(),
            title: format!("{title}: broken bonds"),
            x: "time".into(),
            y: "broken bonds".into(),
            curves: vec![("broken bonds".into(), against(&time, broken))],
        });
    }

    // Grips: reaction against the grip's own displacement where it moves, against time where
    // it holds still.
    for name in h.names.iter().filter(|n| n.starts_with("reaction_")) {
        let rest = &name["reaction_".len()..];
        let reaction = col(name)?;
        let moved = format!("displacement_{rest}");
        let (x, label, curve) = match has(&moved).then(|| col(&moved)).transpose()? {
            Some(u) if varies(&u) => (
                format!("displacement {rest}"),
                "load_displacement",
                u.into_iter().zip(reaction).collect(),
            ),
            _ => ("time".to_string(), "reaction", against(&time, reaction)),
        };
        all.push(Picture {
            file: format!("{label}_{rest}.png"),
            title: format!("{title}: {} {rest}", label.replace('_', "–")),
            x,
            y: format!("reaction {rest}"),
            curves: vec![(format!("reaction {rest}"), curve)],
        });
    }

    // Loads applied by the deck, against time.
    for name in h.names.iter().filter_map(|n| n.strip_prefix("load_")) {
        all.push(Picture {
            file: format!("applied_load_{name}.png"),
            title: format!("{title}: applied load {name}"),
            x: "time".into(),
            y: "load".into(),
            curves: vec![(
                name.to_string(),
                against(&time, col(&format!("load_{name}"))?),
            )],
        });
    }

    // Probes: their displacement components against time.
    for name in h.names.iter().filter_map(|n| n.strip_suffix("_ux")) {
        let parts = ["ux", "uy", "uz"].map(|k| format!("{name}_{k}"));
        if !parts.iter().all(|p| has(p)) || name.starts_with("displacement_") {
            continue;
        }
        let mut curves = Vec::new();
        for p in &parts {
            curves.push((p.clone(), against(&time, col(p)?)));
        }
        all.push(Picture {
            file: format!("probe_{name}.png"),
            title: format!("{title}: probe {name}"),
            x: "time".into(),
            y: "displacement".into(),
            curves,
        });
    }

    for (name, file) in [
        ("temperature", "temperature.png"),
        ("pressure", "pressure.png"),
    ] {
        if has(name) {
            all.push(Picture {
                file: file.into(),
                title: format!("{title}: {name}"),
                x: "time".into(),
                y: name.into(),
                curves: vec![(name.into(), against(&time, col(name)?))],
            });
        }
    }
    Ok(all)
}
