//! Particle frames for ParaView.
//!
//! Frames are HDF5 files (the points, then one dataset per array, every attribute the model
//! declares under its own name) tied into a time series by an XDMF file, `frames.xdmf`, which
//! ParaView opens directly (choose the "Xdmf3 Reader" if it asks).
//!
//! One process writes one file per frame, `frames/frame_SSSSSSSS.h5`. A run on several MPI
//! ranks writes each frame in parts, one file per procCube, `frames/frame_SSSSSSSS/
//! part_RRRR.h5`, never gathering the scene on one rank; `frames.xdmf` then lists each step as
//! a spatial collection of its parts, which ParaView shows as one body.

use crate::engine::particles::Particles;
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::output::write_atomically;
use std::path::{Path, PathBuf};

/// A time series of HDF5 frames and the XDMF file that lists them.
pub struct Frames {
    dir: PathBuf,
    /// Step, time, particle count and arrays of each frame written, for the XDMF index.
    entries: Vec<FrameEntry>,
}

struct FrameEntry {
    step: u64,
    time: f64,
    n: usize,
    arrays: Vec<Listed>,
    /// The particles of each part of a frame written in parts (empty: one file).
    parts: Vec<usize>,
}

/// An array as the XDMF index lists it: name, components per particle, number type.
pub type Listed = (String, usize, &'static str);

/// One array of a frame: name, components per particle, values (particle-major).
enum Array {
    F64(String, usize, Vec<f64>),
    I32(String, Vec<i32>),
}

impl Array {
    fn name(&self) -> &str {
        match self {
            Array::F64(n, _, _) | Array::I32(n, _) => n,
        }
    }
}

/// One array per field of `records`, named as the model declares it.
fn push_fields<A: Attributes>(arrays: &mut Vec<Array>, records: &[A]) {
    let mut offset = 0;
    for f in A::FIELDS {
        let o = offset;
        arrays.push(Array::F64(
            f.name.to_string(),
            f.len,
            records
                .iter()
                .flat_map(|r| r.as_slice()[o..o + f.len].to_vec())
                .collect(),
        ));
        offset += f.len;
    }
}

/// The file name of the frame at `step`, relative to the output directory.
pub fn frame_name(step: u64) -> String {
    format!("frames/frame_{step:08}.h5")
}

/// The file name of part `part` of the frame at `step` written in parts, relative to the
/// output directory.
pub fn part_name(step: u64, part: usize) -> String {
    format!("frames/frame_{step:08}/part_{part:04}.h5")
}

/// The frame at `step` in output directory `dir`: its file, or the directory of its parts.
pub fn frame_path(dir: &Path, step: u64) -> PathBuf {
    let file = dir.join(frame_name(step));
    if file.exists() {
        file
    } else {
        dir.join(format!("frames/frame_{step:08}"))
    }
}

/// The steps of the frames in `dir/frames/` (files, or directories of parts), in order.
pub fn frame_steps(dir: &Path) -> Result<Vec<u64>, String> {
    let mut steps: Vec<u64> = std::fs::read_dir(dir.join("frames"))
        .map_err(|e| format!("{}: {e}", dir.join("frames").display()))?
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            let s = name.strip_prefix("frame_")?;
            s.strip_suffix(".h5").unwrap_or(s).parse().ok()
        })
        .collect();
    steps.sort_unstable();
    steps.dedup();
    Ok(steps)
}

/// The part files of a frame written in parts, in part order.
pub fn part_files(frame_dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut parts: Vec<(usize, PathBuf)> = std::fs::read_dir(frame_dir)
        .map_err(|e| format!("{}: {e}", frame_dir.display()))?
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().into_string().ok()?;
            let k = name
                .strip_prefix("part_")?
                .strip_suffix(".h5")?
                .parse()
                .ok()?;
            Some((k, e.path()))
        })
        .collect();
    parts.sort_unstable();
    Ok(parts.into_iter().map(|p| p.1).collect())
}

/// The particles of a frame file: ids and current positions, with its step and time.
pub struct FramePoints {
    pub step: u64,
    pub time: f64,
    pub ids: Vec<i32>,
    pub points: Vec<[f64; 3]>,
}

/// Reads a frame's ids and positions, from its file or the directory of its parts; a damaged
/// or foreign file is an error naming it.
pub fn read_points(path: &Path) -> Result<FramePoints, String> {
    if !path.is_dir() {
        return read_file_points(path);
    }
    let files = part_files(path)?;
    let mut all: Option<FramePoints> = None;
    for f in &files {
        let part = read_file_points(f)?;
        match &mut all {
            None => all = Some(part),
            Some(a) => {
                if (a.step, a.time) != (part.step, part.time) {
                    return Err(format!(
                        "{}: step {} at t = {:e}, its frame's other parts are at step {}",
                        f.display(),
                        part.step,
                        part.time,
                        a.step
                    ));
                }
                a.ids.extend(part.ids);
                a.points.extend(part.points);
            }
        }
    }
    all.ok_or_else(|| format!("{}: a frame directory without parts", path.display()))
}

fn read_file_points(path: &Path) -> Result<FramePoints, String> {
    let read = || -> Result<FramePoints, String> {
        let f =
            hdf5_pure::File::open(path).map_err(|e| format!("not a readable HDF5 file ({e})"))?;
        let a = f
            .root()
            .attrs()
            .map_err(|e| format!("cannot read its attributes ({e})"))?;
        let step = match a.get("step") {
            Some(hdf5_pure::AttrValue::U64(s)) => *s,
            _ => return Err("no 'step' attribute: not a PDQ frame".into()),
        };
        let time = match a.get("time") {
            Some(hdf5_pure::AttrValue::F64(t)) => *t,
            _ => return Err("no 'time' attribute: not a PDQ frame".into()),
        };
        let data = |name: &str| {
            f.dataset(name)
                .map_err(|e| format!("dataset '{name}' is missing or unreadable ({e})"))
        };
        let flat = data("points")?
            .read_f64()
            .map_err(|e| format!("dataset 'points': {e}"))?;
        let ids = data("id")?
            .read_i32()
            .map_err(|e| format!("dataset 'id': {e}"))?;
        if flat.len() != 3 * ids.len() {
            return Err(format!(
                "{} points for {} ids: the frame is damaged",
                flat.len() / 3,
                ids.len()
            ));
        }
        let points = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Ok(FramePoints {
            step,
            time,
            ids,
            points,
        })
    };
    // The HDF5 reader may panic on a damaged file: that is an error here, not a crash.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(read);
    std::panic::set_hook(hook);
    r.unwrap_or_else(|_| Err("the HDF5 reader failed on it: the file is damaged".into()))
        .map_err(|e| format!("{}: {e}", path.display()))
}

impl Frames {
    pub fn new(dir: &Path) -> std::io::Result<Frames> {
        std::fs::create_dir_all(dir.join("frames"))?;
        Ok(Frames {
            dir: dir.to_path_buf(),
            entries: Vec::new(),
        })
    }

    /// Continues the time series of a restarted run: the frames on the schedule (multiples of
    /// `every`) up to `step` that are on disk are listed again; later ones (written after the
    /// checkpoint the run resumes from) are left out and overwritten when reached.
    pub fn resume(dir: &Path, step: u64, every: u64) -> Result<Frames, String> {
        let mut frames = Frames::new(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let steps = frame_steps(dir)?
            .into_iter()
            .filter(|&s: &u64| s <= step && s.is_multiple_of(every.max(1)));
        for s in steps {
            // A frame that cannot be read is left out of the series, not fatal.
            if let Ok(entry) = read_entry(&frame_path(dir, s), s) {
                frames.entries.push(entry);
            }
        }
        Ok(frames)
    }

    /// Writes the owned particles at `step` as one file, then rewrites the XDMF index.
    pub fn write<M: Model>(
        &mut self,
        step: u64,
        time: f64,
        p: &Particles<M>,
        damage: &[f64],
        broken_bonds: usize,
    ) -> std::io::Result<PathBuf> {
        let path = self.dir.join(frame_name(step));
        let arrays = write_frame_file(&path, (step, time, broken_bonds), p, damage, None)?;
        self.list(FrameEntry {
            step,
            time,
            n: p.n_owned,
            arrays,
            parts: Vec::new(),
        })?;
        Ok(path)
    }

    /// Writes part `part` of `parts` of the frame at `step`: the owned particles of one
    /// procCube. Every procCube writes its part; the root then lists the frame with
    /// [`Frames::list_parts`]. Returns the file, the particles written and the arrays.
    pub fn write_part<M: Model>(
        dir: &Path,
        step: u64,
        time: f64,
        (part, parts): (usize, usize),
        p: &Particles<M>,
        (damage, broken_bonds): (&[f64], usize),
    ) -> std::io::Result<(PathBuf, Vec<Listed>)> {
        let path = dir.join(part_name(step, part));
        std::fs::create_dir_all(path.parent().unwrap_or(dir))?;
        let arrays = write_frame_file(
            &path,
            (step, time, broken_bonds),
            p,
            damage,
            Some((part, parts)),
        )?;
        Ok((path, arrays))
    }

    /// Lists the frame at `step`, written in parts of `counts` particles each, and rewrites
    /// the XDMF index (the root, after every part is on disk).
    pub fn list_parts(
        &mut self,
        step: u64,
        time: f64,
        counts: Vec<usize>,
        arrays: Vec<Listed>,
    ) -> std::io::Result<()> {
        // Parts left from an earlier run on more ranks are not this frame's.
        let frame_dir = self.dir.join(format!("frames/frame_{step:08}"));
        for f in part_files(&frame_dir).unwrap_or_default() {
            let k = f
                .file_stem()
                .and_then(|n| n.to_str())
                .and_then(|n| n.strip_prefix("part_")?.parse::<usize>().ok());
            if k.is_some_and(|k| k >= counts.len()) {
                std::fs::remove_file(f)?;
            }
        }
        self.list(FrameEntry {
            step,
            time,
            n: counts.iter().sum(),
            arrays,
            parts: counts,
        })
    }

    fn list(&mut self, entry: FrameEntry) -> std::io::Result<()> {
        self.entries.retain(|e| e.step < entry.step);
        self.entries.push(entry);
        self.write_index()
    }

    /// `frames.xdmf`: a temporal collection of point clouds, one HDF5 file per frame or a
    /// spatial collection of its parts.
    fn write_index(&self) -> std::io::Result<()> {
        let mut x = String::new();
        x.push_str("<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n");
        x.push_str("<Grid Name=\"frames\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
        for e in &self.entries {
            let time = format!("<Time Value=\"{:.17e}\"/>\n", e.time);
            if e.parts.is_empty() {
                x.push_str(&format!(
                    "<Grid Name=\"step_{}\" GridType=\"Uniform\">\n{time}",
                    e.step
                ));
                x.push_str(&uniform_body(&frame_name(e.step), e.n, &e.arrays));
                x.push_str("</Grid>\n");
                continue;
            }
            x.push_str(&format!(
                "<Grid Name=\"step_{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n{time}",
                e.step
            ));
            // An empty part (a procCube without particles) is on disk but not listed: XDMF
            // readers refuse zero-sized data items.
            for (k, &n) in e.parts.iter().enumerate().filter(|p| *p.1 > 0) {
                x.push_str(&format!(
                    "<Grid Name=\"step_{}_part_{k}\" GridType=\"Uniform\">\n",
                    e.step
                ));
                x.push_str(&uniform_body(&part_name(e.step, k), n, &e.arrays));
                x.push_str("</Grid>\n");
            }
            x.push_str("</Grid>\n");
        }
        x.push_str("</Grid>\n</Domain>\n</Xdmf>\n");
        let tmp = self.dir.join("frames.xdmf.tmp");
        std::fs::write(&tmp, x)?;
        std::fs::rename(tmp, self.dir.join("frames.xdmf"))
    }
}

/// The topology, geometry and attributes of a point cloud of `n` particles in `file`.
fn uniform_body(file: &str, n: usize, arrays: &[Listed]) -> String {
    let item = |name: &str, dims: &str, ty: &str| {
        format!("<DataItem Dimensions=\"{dims}\" NumberType=\"{ty}\" Format=\"HDF\">{file}:/{name}</DataItem>")
    };
    let mut x = format!(
        "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{n}\" NodesPerElement=\"1\">{}</Topology>\n",
        item("cells", &format!("{n}"), "Int\" Precision=\"4")
    );
    x.push_str(&format!(
        "<Geometry GeometryType=\"XYZ\">{}</Geometry>\n",
        item("points", &format!("{n} 3"), "Float\" Precision=\"8")
    ));
    for (name, comps, ty) in arrays {
        let (kind, dims) = match comps {
            1 => ("Scalar", format!("{n}")),
            3 => ("Vector", format!("{n} 3")),
            9 => ("Tensor", format!("{n} 9")),
            c => ("Matrix", format!("{n} {c}")),
        };
        x.push_str(&format!(
            "<Attribute Name=\"{name}\" AttributeType=\"{kind}\" Center=\"Node\">{}</Attribute>\n",
            item(name, &dims, ty)
        ));
    }
    x
}

/// Writes the owned particles of `p` with their damage as one frame file (atomically); `part`:
/// which part of how many, for a frame written in parts. Returns the arrays as listed.
fn write_frame_file<M: Model>(
    path: &Path,
    (step, time, broken_bonds): (u64, f64, usize),
    p: &Particles<M>,
    damage: &[f64],
    part: Option<(usize, usize)>,
) -> std::io::Result<Vec<Listed>> {
    let n = p.n_owned;
    let mut arrays = vec![
        Array::I32("id".into(), p.gid[..n].iter().map(|&g| g as i32).collect()),
        Array::I32(
            "material".into(),
            p.material[..n].iter().map(|&m| m as i32).collect(),
        ),
        Array::F64("damage".into(), 1, damage[..n].to_vec()),
        Array::F64(
            "displacement".into(),
            3,
            (0..n).flat_map(|i| p.displacement(i)).collect(),
        ),
        Array::F64("volume".into(), 1, p.volume[..n].to_vec()),
    ];
    // Every declared per-particle attribute, by its declared name.
    push_fields(&mut arrays, &p.alter[..n]);
    push_fields(&mut arrays, &p.fixed[..n]);
    push_fields(&mut arrays, &p.state[..n]);
    push_fields(&mut arrays, &p.force[..n]);
    let mut b = hdf5_pure::FileBuilder::new();
    b.set_attr("step", hdf5_pure::AttrValue::U64(step));
    b.set_attr("time", hdf5_pure::AttrValue::F64(time));
    b.set_attr("model", hdf5_pure::AttrValue::String(M::NAME.into()));
    b.set_attr(
        "broken_bonds",
        hdf5_pure::AttrValue::U64(broken_bonds as u64),
    );
    if let Some((k, parts)) = part {
        b.set_attr("part", hdf5_pure::AttrValue::U64(k as u64));
        b.set_attr("parts", hdf5_pure::AttrValue::U64(parts as u64));
    }
    let points: Vec<f64> = (0..n).flat_map(|i| p.pos(i)).collect();
    b.create_dataset("points")
        .with_f64_data(&points)
        .with_shape(&[n as u64, 3]);
    // Polyvertex connectivity: ParaView does without it, other XDMF readers need it.
    let cells: Vec<i32> = (0..n as i32).collect();
    b.create_dataset("cells").with_i32_data(&cells);
    let mut listed = Vec::new();
    for a in &arrays {
        match a {
            Array::F64(name, comps, v) => {
                let d = b.create_dataset(name).with_f64_data(v);
                if *comps > 1 {
                    d.with_shape(&[n as u64, *comps as u64]);
                }
                listed.push((name.clone(), *comps, "Float\" Precision=\"8"));
            }
            Array::I32(name, v) => {
                b.create_dataset(name).with_i32_data(v);
                listed.push((name.clone(), 1, "Int\" Precision=\"4"));
            }
        }
    }
    debug_assert!(arrays.iter().all(|a| !a.name().is_empty()));
    write_atomically(path, b, None)?;
    Ok(listed)
}

/// The XDMF entry of a frame on disk, a file or a directory of parts (a restarted run lists
/// the frames it keeps).
fn read_entry(path: &Path, step: u64) -> Result<FrameEntry, String> {
    if !path.is_dir() {
        return read_file_entry(path, step);
    }
    let mut entry: Option<FrameEntry> = None;
    for f in part_files(path)? {
        let part = read_file_entry(&f, step)?;
        let n = part.n;
        let e = entry.get_or_insert(FrameEntry {
            parts: Vec::new(),
            n: 0,
            ..part
        });
        e.n += n;
        e.parts.push(n);
    }
    entry.ok_or_else(|| "no parts".into())
}

fn read_file_entry(path: &Path, step: u64) -> Result<FrameEntry, String> {
    let f = hdf5_pure::File::open(path).map_err(|e| e.to_string())?;
    let attrs = f.root().attrs().map_err(|e| e.to_string())?;
    let time = match attrs.get("time") {
        Some(hdf5_pure::AttrValue::F64(t)) => *t,
        _ => return Err("no time".into()),
    };
    let n = f
        .dataset("points")
        .and_then(|d| d.shape())
        .map_err(|e| e.to_string())?
        .first()
        .copied()
        .unwrap_or(0) as usize;
    let mut arrays = Vec::new();
    for name in f.root().datasets().map_err(|e| e.to_string())? {
        if name == "points" || name == "cells" {
            continue;
        }
        let d = f.dataset(&name).map_err(|e| e.to_string())?;
        let shape = d.shape().map_err(|e| e.to_string())?;
        let comps = shape.get(1).copied().unwrap_or(1) as usize;
        let ty = if name == "id" || name == "material" {
            "Int\" Precision=\"4"
        } else {
            "Float\" Precision=\"8"
        };
        arrays.push((name, comps, ty));
    }
    Ok(FrameEntry {
        step,
        time,
        n,
        arrays,
        parts: Vec::new(),
    })
}
