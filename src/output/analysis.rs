//! The tables of an `[[analysis]]` (voids or cracks on voxels): `NAME.csv`, one row per
//! analysis; `NAME_clusters.csv`, one row per cluster and analysis; `NAME_events.csv`, what
//! happened to the clusters between analyses. Rows reach the file as they are written, so a
//! run that is killed keeps what it found.

use crate::voids::tracking::Event;
use crate::voids::{Cluster, VoxelGrid};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// What the analysis looks for, which decides the summary's columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Looking {
    Voids,
    Cracks,
}

const VOIDS: &str = "step,time,count,volume,largest_volume,largest_radius,surface,porosity,rounds";
const CRACKS: &str = "step,time,count,voxels,area,largest_area,bonds,mean_opening,rounds";
const CLUSTERS: &str = "step,time,id,voxels,volume,surface,area,x,y,z,equivalent_radius,min_x,min_y,min_z,max_x,max_y,max_z,bonds,opening";
const EVENTS: &str = "step,time,event,id,parents,volume";

/// One analysis, as the summary row tells it.
pub struct Found<'a> {
    pub step: u64,
    pub time: f64,
    pub grid: &'a VoxelGrid,
    pub clusters: &'a [Cluster],
    /// Each cluster's id (by label).
    pub ids: &'a [u32],
    /// Marked voxels joined to the outside (voids).
    pub outside: u64,
    pub rounds: u32,
    pub events: &'a [Event],
}

/// The three files of one analysis.
pub struct AnalysisFiles {
    looking: Looking,
    summary: BufWriter<File>,
    clusters: BufWriter<File>,
    events: BufWriter<File>,
}

impl AnalysisFiles {
    /// New files `NAME*.csv` in `dir`; after a restart from `resume` (the checkpoint's step),
    /// the existing files keep their rows up to that step. Returns the files and the largest
    /// id used before.
    pub fn open(
        dir: &Path,
        name: &str,
        looking: Looking,
        resume: Option<u64>,
    ) -> std::io::Result<(AnalysisFiles, u32)> {
        let summary = if looking == Looking::Voids {
            VOIDS
        } else {
            CRACKS
        };
        let path = |suffix: &str| dir.join(format!("{name}{suffix}.csv"));
        let mut used = 0;
        let mut open = |suffix: &str, header: &str| -> std::io::Result<BufWriter<File>> {
            let p = path(suffix);
            match resume {
                Some(step) => {
                    let kept = rows_up_to(&p, header, step);
                    if suffix == "_events" {
                        used = largest_id(&kept);
                    }
                    std::fs::write(&p, kept)?;
                    Ok(BufWriter::new(File::options().append(true).open(&p)?))
                }
                None => {
                    let mut f = BufWriter::new(File::create(&p)?);
                    writeln!(f, "{header}")?;
                    f.flush()?;
                    Ok(f)
                }
            }
        };
        let files = AnalysisFiles {
            looking,
            summary: open("", summary)?,
            clusters: open("_clusters", CLUSTERS)?,
            events: open("_events", EVENTS)?,
        };
        Ok((files, used))
    }

    /// The rows of one analysis.
    pub fn write(&mut self, f: &Found) -> std::io::Result<()> {
        let (step, time) = (f.step, f.time);
        let count = f.clusters.len();
        // Folded from +0.0: an empty sum is 0, not -0.
        let sum = |g: fn(&Cluster) -> f64| f.clusters.iter().map(g).fold(0.0, |a, b| a + b);
        let largest = |g: fn(&Cluster) -> f64| {
            f.clusters
                .iter()
                .max_by(|a, b| g(a).total_cmp(&g(b)))
                .cloned()
        };
        match self.looking {
            Looking::Voids => {
                let big = largest(|c| c.volume);
                let volume = sum(|c| c.volume);
                let body = (f.grid.len() as u64 - f.outside) as f64 * f.grid.voxel_volume();
                writeln!(
                    self.summary,
                    "{step},{time:.10e},{count},{volume:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{}",
                    big.as_ref().map_or(0.0, |c| c.volume),
                    big.as_ref().map_or(0.0, |c| c.equivalent_radius),
                    sum(|c| c.surface),
                    if body > 0.0 { volume / body } else { 0.0 },
                    f.rounds
                )?;
            }
            Looking::Cracks => {
                let big = largest(|c| c.area);
                let bonds = sum(|c| c.bonds as f64);
                let opening = sum(|c| c.opening * c.bonds as f64);
                writeln!(
                    self.summary,
                    "{step},{time:.10e},{count},{},{:.10e},{:.10e},{},{:.10e},{}",
                    f.clusters.iter().map(|c| c.voxels).sum::<u64>(),
                    sum(|c| c.area),
                    big.as_ref().map_or(0.0, |c| c.area),
                    bonds as u64,
                    if bonds > 0.0 { opening / bonds } else { 0.0 },
                    f.rounds
                )?;
            }
        }
        for (c, id) in f.clusters.iter().zip(f.ids) {
            let lo = f.grid.centre(c.first.map(|x| x as f64 - 0.5));
            let hi = f.grid.centre(c.last.map(|x| x as f64 + 0.5));
            let [x, y, z] = c.centroid;
            writeln!(
                self.clusters,
                "{step},{time:.10e},{id},{},{:.10e},{:.10e},{:.10e},{x:.10e},{y:.10e},{z:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{},{:.10e}",
                c.voxels,
                c.volume,
                c.surface,
                c.area,
                c.equivalent_radius,
                lo[0],
                lo[1],
                lo[2],
                hi[0],
                hi[1],
                hi[2],
                c.bonds,
                c.opening
            )?;
        }
        for e in f.events {
            let parents: Vec<String> = e.parents.iter().map(|p| p.to_string()).collect();
            writeln!(
                self.events,
                "{step},{time:.10e},{},{},{},{:.10e}",
                e.kind.name(),
                e.id,
                parents.join(";"),
                e.volume
            )?;
        }
        for w in [&mut self.summary, &mut self.clusters, &mut self.events] {
            w.flush()?;
        }
        Ok(())
    }
}

/// The header and the rows of `path` up to `step` (the rows a restarted run keeps).
fn rows_up_to(path: &Path, header: &str, step: u64) -> String {
    let old = std::fs::read_to_string(path).unwrap_or_default();
    let mut kept = format!("{header}\n");
    for line in old.lines().skip(1) {
        match line.split(',').next().and_then(|v| v.parse::<u64>().ok()) {
            Some(s) if s <= step => {
                kept.push_str(line);
                kept.push('\n');
            }
            _ => break,
        }
    }
    kept
}

/// The largest id in an events table.
fn largest_id(events: &str) -> u32 {
    events
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(3)?.parse::<u32>().ok())
        .max()
        .unwrap_or(0)
}
