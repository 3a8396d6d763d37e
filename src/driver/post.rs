//! `pdq voids DIR`: the voids analysis of `[[analysis]]` run afterwards on a run's saved
//! frames (Hemani et al.'s post-processing path, against which the in-situ analysis is
//! measured). One process, the whole grid per frame; the same tables as in situ, and the voxel
//! labels as an XDMF/HDF5 series for ParaView.
//!
//! Frames do not record the periodic box, so every axis is taken as bounded (a scene that is
//! periodic along an axis has no outside there: analyse it in situ).

use crate::output::analysis::{AnalysisFiles, Found, Looking};
use crate::output::frames::{frame_path, frame_steps, part_files, read_points};
use crate::output::pictures::{largest_clusters, LargestOf};
use crate::output::voxels::VoxelSeries;
use crate::parallel::comm::{Solo, Team};
use crate::voids::largest::{largest, SHOWN};
use crate::voids::tracking::Tracker;
use crate::voids::{deposit, label, Connectivity, Extent, Region, Scheme, VoxelGrid, OCCUPIED};
use std::path::Path;
use std::time::Instant;

/// What `pdq voids` is asked.
pub struct PostVoids {
    /// The voxel side, in the run's units.
    pub voxel: f64,
    pub connectivity: Connectivity,
    /// Names the tables (`NAME.csv`, …) and the voxel series.
    pub name: String,
    /// Also write the voxel labels.
    pub labels: bool,
}

/// What the analysis of the frames took.
pub struct PostSummary {
    pub frames: usize,
    pub bytes_read: u64,
    pub seconds: f64,
    /// Voids at the last frame.
    pub voids: usize,
}

/// Analyses every frame of the run in `dir`, in step order.
pub fn voids_from_frames(dir: &Path, ask: &PostVoids) -> Result<PostSummary, String> {
    let start = Instant::now();
    let steps = frame_steps(dir)?;
    if steps.is_empty() {
        return Err(format!(
            "{} has no frames: run the deck with [output] frames_every, or analyse in situ with [[analysis]]",
            dir.join("frames").display()
        ));
    }
    let io = |e: std::io::Error| format!("writing in {}: {e}", dir.display());
    let (mut files, _) = AnalysisFiles::open(dir, &ask.name, Looking::Voids, None).map_err(io)?;
    let mut series = if ask.labels {
        Some(VoxelSeries::new(dir, &ask.name).map_err(io)?)
    } else {
        None
    };
    let mut tracker = Tracker::new(1, false);
    let mut team = Team::new(Solo::new());
    let mut bytes_read = 0;
    let mut voids = 0;
    for &step in &steps {
        // A frame's file, or the directory of its parts.
        let path = frame_path(dir, step);
        let on_disk = if path.is_dir() {
            part_files(&path)?
        } else {
            vec![path.clone()]
        };
        bytes_read += on_disk
            .iter()
            .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
            .sum::<u64>();
        let frame = read_points(&path)?;
        // Voxels centred on the lattice of the particle with id 0 (as in situ).
        let anchor = frame
            .ids
            .iter()
            .position(|&i| i == 0)
            .map_or(frame.points.first().copied(), |k| Some(frame.points[k]))
            .ok_or_else(|| format!("{}: the frame has no particles", path.display()))?;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &frame.points {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let extent = [0, 1, 2].map(|a| Extent::Bounded {
            lo: lo[a],
            hi: hi[a],
        });
        let grid = VoxelGrid::spanning(anchor, extent, [ask.voxel; 3])
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let region = Region::whole(grid);
        let (occupied, _) = deposit(&mut team, &region, &frame.points, None);
        let empty: Vec<bool> = occupied.iter().map(|o| !o).collect();
        let found = label(
            &mut team,
            &region,
            &empty,
            &[],
            ask.connectivity,
            Scheme::Boundary,
        );
        let (events, ids) = tracker.follow(&mut team, &region, &found);
        files
            .write(&Found {
                step: frame.step,
                time: frame.time,
                grid: &region.grid,
                clusters: &found.clusters,
                ids: &ids,
                outside: found.outside,
                rounds: found.rounds,
                events: &events,
            })
            .map_err(io)?;
        if let Some(s) = &mut series {
            let labels: Vec<i32> = occupied
                .iter()
                .zip(&found.labels)
                .map(|(&o, &l)| match (o, l) {
                    (true, _) => OCCUPIED as i32,
                    (false, 0) => 0,
                    (false, l) => ids[l as usize - 1] as i32,
                })
                .collect();
            s.write(frame.step, frame.time, &region.grid, &labels)
                .map_err(io)?;
        }
        voids = found.clusters.len();
        if Some(&frame.step) == steps.last() {
            let of = LargestOf {
                name: &ask.name,
                title: &dir.display().to_string(),
                what: "voids",
                step: frame.step,
                total: voids,
            };
            let shown = largest(&mut team, &region, &found, SHOWN).unwrap_or_default();
            largest_clusters(dir, &of, &region.grid, &shown)?;
        }
    }
    Ok(PostSummary {
        frames: steps.len(),
        bytes_read,
        seconds: start.elapsed().as_secs_f64(),
        voids,
    })
}
