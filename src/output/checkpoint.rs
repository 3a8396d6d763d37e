//! Checkpoints: everything a run needs to continue, in one HDF5 file.
//!
//! A checkpoint holds, by global particle id, the reference position and every alterable
//! attribute (under its declared name); the broken bonds as pairs of global ids, and the
//! history of every bond whose history is not zero, keyed the same way, so a restart on another
//! layout or rank count finds them again; the step, time, time step and integrator; a hash of
//! the scene (model, attribute schema, reference positions, volumes, materials) that a restart
//! must match; and a checksum of all the data, so a damaged file is refused, never half-read.
//! Loads and supports are functions of time, so the time is their whole state.
//!
//! Files are written under a temporary name, synced and renamed (`output::write_atomically`):
//! a run killed while writing leaves the previous checkpoint whole.
//!
//! A run on several MPI ranks writes its checkpoints in parts (`checkpoint_parts`): each
//! procCube its own file, and an index, under the name a one-file checkpoint would have,
//! written last.

use crate::engine::simulation::Integrator;
use crate::input::setup::Setup;
use crate::model::Model;
use crate::parallel::snapshot::schema;
pub use crate::parallel::snapshot::Snapshot;
use crate::parallel::Cube;
use hdf5_pure::AttrValue;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What identifies the file as a PDQ checkpoint, and its layout version.
pub(crate) const FORMAT: &str = "pdq-checkpoint";
/// One procCube's part of a checkpoint written in parts: a checkpoint of the particles it
/// lists in its `id` dataset.
pub(crate) const PART_FORMAT: &str = "pdq-checkpoint-part";
pub(crate) const VERSION: i64 = 1;

/// A run's state at the end of a step, by global id, and what identifies its scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub state: Snapshot,
    /// Particles in the scene (the snapshot may hold only some).
    pub particles: usize,
    pub scene_hash: u64,
    /// The deck file the run was started from (informational).
    pub deck: String,
}

/// 64-bit FNV-1a: a fixed, documented hash (Rust's `Hasher`s may change between releases).
#[derive(Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn f64s(&mut self, v: &[f64]) {
        for x in v {
            self.bytes(&x.to_le_bytes());
        }
    }
}

/// The scene a checkpoint belongs to: model, schema, materials, horizon, and the reference
/// state of every particle by global id, as the deck builds it (before a restart changes
/// anything). Steps, output and layout may change between a run and its restart.
pub fn scene_hash<M: Model>(setup: &Setup<M>, scene: &crate::input::deck::Scene) -> u64 {
    let p = &setup.sim.particles;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_unstable_by_key(|&i| p.gid[i]);
    scene_hash_of::<M>(scene, &setup.bars.bar_of, p.len(), |each| {
        for i in order {
            each(&p.x0[i], p.volume[i], p.material[i]);
        }
    })
}

/// [`scene_hash`] of a scene of `n` particles whose reference positions, volumes and materials
/// `particles` hands out in global id order (each procCube of a per-rank setup streams them from
/// the geometry), with `bar_of` each particle's bar by global id (empty without bars).
pub fn scene_hash_of<M: Model>(
    scene: &crate::input::deck::Scene,
    bar_of: &[u32],
    n: usize,
    particles: impl FnOnce(&mut dyn FnMut(&[f64; 3], f64, u16)),
) -> u64 {
    let mut h = Fnv::new();
    h.bytes(M::NAME.as_bytes());
    h.bytes(schema::<M>().as_bytes());
    h.bytes(format!("{:?}{:?}", scene.materials, scene.model_options).as_bytes());
    // Bars: which particle belongs to which (their own bonds are calibrated) and their
    // prestrain, which a restart must not change under bonds that already carry it.
    h.bytes(format!("{:?}{:?}", bar_of, scene.bar_prestrain()).as_bytes());
    h.f64s(&[scene.horizon, scene.spacing]);
    h.bytes(&(n as u64).to_le_bytes());
    particles(&mut |x0, volume, material| {
        h.f64s(x0);
        h.f64s(&[volume]);
        h.bytes(&material.to_le_bytes());
    });
    h.0
}

pub(crate) fn checksum(c: &Checkpoint) -> u64 {
    let mut h = Fnv::new();
    h.bytes(&c.state.step.to_le_bytes());
    // Only in parts, whose checksums cover which particles they hold.
    if let Some(ids) = &c.state.ids {
        for g in ids {
            h.bytes(&g.to_le_bytes());
        }
    }
    h.f64s(&[c.state.time, c.state.dt]);
    for x in &c.state.x0 {
        h.f64s(x);
    }
    h.f64s(&c.state.alter);
    h.f64s(&c.state.force);
    for &(a, b) in c.state.broken.iter().chain(&c.state.history_pairs) {
        h.bytes(&a.to_le_bytes());
        h.bytes(&b.to_le_bytes());
    }
    h.f64s(&c.state.history);
    // Absent in runs without a thermostat, whose checksums stay what they were.
    if let Some(t) = &c.state.thermostat {
        h.bytes(t.kind.as_bytes());
        h.f64s(&t.values);
    }
    h.0
}

/// The file name of the checkpoint at `step`.
pub fn file_name(step: u64) -> String {
    format!("checkpoint_{step:08}.h5")
}

impl Checkpoint {
    /// The state of every procCube gathered on the root, which gets the checkpoint; every
    /// worker must call it.
    pub fn gather<M: Model>(cube: &mut Cube<M>, scene_hash: u64, deck: &str) -> Option<Checkpoint> {
        Some(Checkpoint {
            state: Snapshot::gather(cube)?,
            particles: cube.global_particles,
            scene_hash,
            deck: deck.to_string(),
        })
    }

    /// Writes the checkpoint as `dir/checkpoint_SSSSSSSS.h5` (atomically), then deletes all but
    /// the newest `keep` checkpoints in `dir`; returns the path and the size in bytes.
    pub fn write(&self, dir: &Path, keep: usize) -> std::io::Result<(PathBuf, u64)> {
        std::fs::create_dir_all(dir)?;
        let path = dir.join(file_name(self.state.step));
        crate::output::write_atomically(&path, self.builder(FORMAT), pause("file"))?;
        let size = std::fs::metadata(&path)?.len();
        prune(dir, keep);
        Ok((path, size))
    }

    /// The HDF5 file of the checkpoint, marked as `format`; a snapshot of some particles
    /// lists them in an `id` dataset.
    pub(crate) fn builder(&self, format: &str) -> hdf5_pure::FileBuilder {
        let mut b = hdf5_pure::FileBuilder::new();
        let s = |v: &str| AttrValue::String(v.to_string());
        b.set_attr("format", s(format));
        b.set_attr("version", AttrValue::I64(VERSION));
        b.set_attr("step", AttrValue::U64(self.state.step));
        b.set_attr("time", AttrValue::F64(self.state.time));
        b.set_attr("dt", AttrValue::F64(self.state.dt));
        b.set_attr("integrator", s(&self.state.integrator));
        b.set_attr("model", s(&self.state.model));
        b.set_attr("schema", s(&self.state.schema));
        b.set_attr("scene_hash", AttrValue::U64(self.scene_hash));
        b.set_attr("deck", s(&self.deck));
        b.set_attr("particles", AttrValue::U64(self.state.x0.len() as u64));
        b.set_attr("scene_particles", AttrValue::U64(self.particles as u64));
        b.set_attr(
            "broken_bonds",
            AttrValue::U64(self.state.broken.len() as u64),
        );
        b.set_attr("checksum", AttrValue::U64(checksum(self)));
        let n = self.state.x0.len() as u64;
        if let Some(ids) = &self.state.ids {
            b.create_dataset("id").with_u32_data(ids);
        }
        let x0: Vec<f64> = self.state.x0.iter().flatten().copied().collect();
        b.create_dataset("x0")
            .with_f64_data(&x0)
            .with_shape(&[n, 3]);
        // One dataset per alterable field and per force field, by its declared name.
        let parts: Vec<&str> = self.state.schema.split('|').collect();
        for (prefix, fields, values) in [
            ("alter", parts.first(), &self.state.alter),
            ("force", parts.get(2), &self.state.force),
        ] {
            let fields = parse_fields(fields.copied().unwrap_or(""));
            let len: usize = fields.iter().map(|f| f.1).sum();
            let mut at = 0;
            for (name, l) in &fields {
                let v: Vec<f64> = values
                    .chunks_exact(len.max(1))
                    .flat_map(|r| r[at..at + l].to_vec())
                    .collect();
                b.create_dataset(&format!("{prefix}_{name}"))
                    .with_f64_data(&v)
                    .with_shape(&[n, *l as u64]);
                at += l;
            }
        }
        let pairs =
            |p: &[(u32, u32)]| -> Vec<u32> { p.iter().flat_map(|&(a, b)| [a, b]).collect() };
        b.create_dataset("broken_bonds")
            .with_u32_data(&pairs(&self.state.broken))
            .with_shape(&[self.state.broken.len() as u64, 2]);
        let m = self.state.history_pairs.len() as u64;
        b.create_dataset("history_bonds")
            .with_u32_data(&pairs(&self.state.history_pairs))
            .with_shape(&[m, 2]);
        let lb = (self.state.history.len() as u64)
            .checked_div(m)
            .unwrap_or(0);
        b.create_dataset("history")
            .with_f64_data(&self.state.history)
            .with_shape(&[m, lb]);
        // Optional, so that checkpoints of runs without a thermostat read as before.
        if let Some(t) = &self.state.thermostat {
            b.set_attr("thermostat", s(&t.kind));
            b.create_dataset("thermostat_state")
                .with_f64_data(&t.values)
                .with_shape(&[t.values.len() as u64, 1]);
        }
        b
    }

    /// Reads and verifies a checkpoint: a file that is not one, is truncated or damaged, or
    /// whose data do not match its checksum is refused with a message naming the file. A
    /// checkpoint written in parts is read whole.
    pub fn read(path: &Path) -> Result<Checkpoint, String> {
        Checkpoint::read_some(path, None)
    }

    /// [`Checkpoint::read`] of the particles `keep` names, and the bonds between two of them
    /// (a procCube set up on its own reads its share, a part at a time); all with `None`.
    pub fn read_some(
        path: &Path,
        keep: Option<&dyn Fn(u32) -> bool>,
    ) -> Result<Checkpoint, String> {
        let what = |e: String| format!("checkpoint {}: {e}", path.display());
        let read = quietly(|| match crate::output::checkpoint_parts::is_index(path) {
            true => crate::output::checkpoint_parts::read(path, keep),
            false => read_file(path, PartOf::Whole).map(|c| match keep {
                Some(keep) => c.only(keep),
                None => c,
            }),
        });
        match read {
            Ok(r) => r.map_err(what),
            Err(_) => Err(what(
                "the file is damaged (the HDF5 reader failed on it)".into(),
            )),
        }
    }

    /// The particles `keep` names and the bonds between two of them, ascending by id.
    pub fn only(self, keep: &dyn Fn(u32) -> bool) -> Checkpoint {
        let st = self.state;
        let kept = (0..st.x0.len() as u32)
            .map(|r| st.ids.as_ref().map_or(r, |ids| ids[r as usize]))
            .filter(|&g| keep(g));
        let rows: Vec<(u32, usize)> = kept.map(|g| (g, st.row(g).unwrap_or(0))).collect();
        let (la, lf) = (
            st.alter.len() / st.x0.len().max(1),
            st.force.len() / st.x0.len().max(1),
        );
        let both = |&(a, b): &(u32, u32)| keep(a) && keep(b);
        let lb = st.history.len() / st.history_pairs.len().max(1);
        let mut history = Vec::new();
        let mut history_pairs = Vec::new();
        for (t, p) in st.history_pairs.iter().enumerate().filter(|(_, p)| both(p)) {
            history_pairs.push(*p);
            history.extend_from_slice(&st.history[t * lb..(t + 1) * lb]);
        }
        let state = Snapshot {
            ids: Some(rows.iter().map(|r| r.0).collect()),
            x0: rows.iter().map(|r| st.x0[r.1]).collect(),
            alter: rows
                .iter()
                .flat_map(|r| st.alter[r.1 * la..(r.1 + 1) * la].to_vec())
                .collect(),
            force: rows
                .iter()
                .flat_map(|r| st.force[r.1 * lf..(r.1 + 1) * lf].to_vec())
                .collect(),
            broken: st.broken.iter().copied().filter(both).collect(),
            history_pairs,
            history,
            ..st
        };
        Checkpoint { state, ..self }
    }

    /// Refuses a checkpoint written by another deck or model.
    pub fn check_matches<M: Model>(
        &self,
        path: &Path,
        scene_hash: u64,
        n: usize,
    ) -> Result<(), String> {
        let refuse = |e: String| {
            Err(format!(
                "checkpoint {} does not belong to this deck: {e}",
                path.display()
            ))
        };
        if self.state.model != M::NAME {
            return refuse(format!(
                "it is of model '{}', the deck uses '{}'",
                self.state.model,
                M::NAME
            ));
        }
        if self.state.schema != schema::<M>() {
            return refuse(format!(
                "its attributes are [{}], the model's are [{}]",
                self.state.schema,
                schema::<M>()
            ));
        }
        if self.particles != n {
            return refuse(format!(
                "it holds {} particles, the deck builds {n}",
                self.particles
            ));
        }
        if self.scene_hash != scene_hash {
            return refuse(format!(
                "the deck's geometry, materials or model options differ (scene hash {:016x}, the deck gives {scene_hash:016x}; written from {})",
                self.scene_hash, self.deck
            ));
        }
        Ok(())
    }

    /// What `pdq info` prints.
    pub fn describe(&self) -> String {
        let fields = self.state.schema.replace('|', "; ");
        format!(
            "checkpoint of model '{}' from {}\nstep       {}\ntime       {:.10e} (dt {:.6e}, {})\nparticles  {}\nattributes {}\nbonds      {} broken, {} with history\n",
            self.state.model,
            self.deck,
            self.state.step,
            self.state.time,
            self.state.dt,
            self.state.integrator,
            self.particles,
            fields,
            self.state.broken.len(),
            self.state.history_pairs.len()
        )
    }
}

/// Runs `f`, turning a panic into `Err` without the panic message on stderr: the file readers
/// must answer a damaged file with an error of their own.
pub(crate) fn quietly<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    std::panic::set_hook(hook);
    r
}

fn parse_fields(s: &str) -> Vec<(String, usize)> {
    s.split(',')
        .filter(|f| !f.is_empty())
        .filter_map(|f| {
            let (n, l) = f.split_once(':')?;
            Some((n.to_string(), l.parse().ok()?))
        })
        .collect()
}

/// Checkpoints in `dir` by step (temporary files of an interrupted write are not listed).
fn list(dir: &Path) -> Vec<(u64, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().into_string().ok()?;
            let step = name
                .strip_prefix("checkpoint_")?
                .strip_suffix(".h5")?
                .parse()
                .ok()?;
            Some((step, e.path()))
        })
        .collect()
}

/// The checkpoint to resume from: `path` itself if it is a file; if it is a directory (an
/// output directory or its `checkpoints/`), the newest checkpoint in it that reads whole.
pub fn resolve(path: &Path) -> Result<(PathBuf, Checkpoint), String> {
    resolve_some(path, None)
}

/// [`resolve`], reading only the particles `keep` names and the bonds between two of them
/// ([`Checkpoint::read_some`]).
pub fn resolve_some(
    path: &Path,
    keep: Option<&dyn Fn(u32) -> bool>,
) -> Result<(PathBuf, Checkpoint), String> {
    if !path.is_dir() {
        if !path.exists() {
            return Err(format!("checkpoint {}: no such file", path.display()));
        }
        return Checkpoint::read_some(path, keep).map(|c| (path.to_path_buf(), c));
    }
    let dir = if path.join("checkpoints").is_dir() {
        path.join("checkpoints")
    } else {
        path.to_path_buf()
    };
    let mut found = list(&dir);
    found.sort_unstable();
    let mut problems = Vec::new();
    for (_, p) in found.iter().rev() {
        match Checkpoint::read_some(p, keep) {
            Ok(c) => return Ok((p.clone(), c)),
            Err(e) => problems.push(e),
        }
    }
    if problems.is_empty() {
        Err(format!(
            "no checkpoint (checkpoint_*.h5) in {}",
            dir.display()
        ))
    } else {
        Err(format!(
            "no readable checkpoint in {}: {}",
            dir.display(),
            problems.join("; ")
        ))
    }
}

pub(crate) fn attr_u64(a: &HashMap<String, AttrValue>, name: &str) -> Result<u64, String> {
    match a.get(name) {
        Some(AttrValue::U64(v)) => Ok(*v),
        Some(AttrValue::I64(v)) if *v >= 0 => Ok(*v as u64),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

pub(crate) fn attr_f64(a: &HashMap<String, AttrValue>, name: &str) -> Result<f64, String> {
    match a.get(name) {
        Some(AttrValue::F64(v)) => Ok(*v),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

pub(crate) fn attr_string(a: &HashMap<String, AttrValue>, name: &str) -> Result<String, String> {
    match a.get(name) {
        Some(AttrValue::String(v)) | Some(AttrValue::AsciiString(v)) => Ok(v.clone()),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

/// What a checkpoint file is expected to be: a whole checkpoint, or a part of one.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum PartOf {
    Whole,
    Part,
}

/// Refuses a file that is not a checkpoint of this `kind` and of this pdq's format version.
fn check_format(a: &HashMap<String, AttrValue>, kind: PartOf) -> Result<(), String> {
    let format = if kind == PartOf::Whole {
        FORMAT
    } else {
        PART_FORMAT
    };
    if attr_string(a, "format").ok().as_deref() != Some(format) {
        return Err(format!(
            "not a PDQ checkpoint{} (no format = \"{format}\" attribute; a frame file?)",
            if kind == PartOf::Part { " part" } else { "" }
        ));
    }
    let version = attr_u64(a, "version")?;
    if version != VERSION as u64 {
        return Err(format!(
            "checkpoint format version {version}, this pdq reads {VERSION}"
        ));
    }
    Ok(())
}

/// Refuses bond lists that name particles beyond the scene's `n`, or are out of order.
fn check_bond_lists(broken: &[(u32, u32)], history: &[(u32, u32)], n: usize) -> Result<(), String> {
    if broken
        .iter()
        .chain(history)
        .any(|&(a, b)| a as usize >= n || b as usize >= n || a >= b)
        || broken.windows(2).any(|w| w[0] >= w[1])
        || history.windows(2).any(|w| w[0] >= w[1])
    {
        return Err("its bond lists name particles that do not exist or are out of order".into());
    }
    Ok(())
}

/// Reads and verifies one checkpoint file (panics of the HDF5 reader are the caller's).
pub(crate) fn read_file(path: &Path, kind: PartOf) -> Result<Checkpoint, String> {
    let f = hdf5_pure::File::open(path).map_err(|e| format!("not a readable HDF5 file ({e})"))?;
    let a = f
        .root()
        .attrs()
        .map_err(|e| format!("cannot read its attributes ({e})"))?;
    check_format(&a, kind)?;
    let n = attr_u64(&a, "particles")? as usize;
    // Written since checkpoints come in parts; a whole one holds every particle.
    let scene_n = attr_u64(&a, "scene_particles").map_or(n, |v| v as usize);
    let schema = attr_string(&a, "schema")?;
    let dataset = |name: &str, cols: Option<u64>| -> Result<hdf5_pure::Dataset, String> {
        let d = f
            .dataset(name)
            .map_err(|e| format!("dataset '{name}' is missing or unreadable ({e})"))?;
        let shape = d.shape().map_err(|e| format!("dataset '{name}': {e}"))?;
        if let Some(c) = cols {
            if shape.len() != 2 || shape[1] != c {
                return Err(format!(
                    "dataset '{name}' has shape {shape:?}, expected [_, {c}]"
                ));
            }
        }
        Ok(d)
    };
    let read_f64 = |name: &str, cols: u64, rows: Option<usize>| -> Result<Vec<f64>, String> {
        let v = dataset(name, Some(cols))?
            .read_f64()
            .map_err(|e| format!("dataset '{name}': {e}"))?;
        if let Some(r) = rows {
            if v.len() != r * cols as usize {
                return Err(format!(
                    "dataset '{name}' holds {} values, expected {}",
                    v.len(),
                    r * cols as usize
                ));
            }
        }
        Ok(v)
    };
    let read_pairs = |name: &str| -> Result<Vec<(u32, u32)>, String> {
        let v = dataset(name, Some(2))?
            .read_u32()
            .map_err(|e| format!("dataset '{name}': {e}"))?;
        Ok(v.chunks_exact(2).map(|c| (c[0], c[1])).collect())
    };
    let x0 = read_f64("x0", 3, Some(n))?
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let parts: Vec<&str> = schema.split('|').collect();
    if parts.len() != 3 {
        return Err("attribute 'schema' is malformed".into());
    }
    let (bond_fields, records) = (parts[1], |prefix: &str, fields: &str| {
        let fields = parse_fields(fields);
        let len: usize = fields.iter().map(|f| f.1).sum();
        let mut all = vec![0.0; n * len];
        let mut at = 0;
        for (name, l) in &fields {
            let v = read_f64(&format!("{prefix}_{name}"), *l as u64, Some(n))?;
            for (g, chunk) in v.chunks_exact(*l).enumerate() {
                all[g * len + at..g * len + at + l].copy_from_slice(chunk);
            }
            at += l;
        }
        Ok::<_, String>(all)
    });
    let alter = records("alter", parts[0])?;
    let force = records("force", parts[2])?;
    let lb: usize = parse_fields(bond_fields).iter().map(|f| f.1).sum();
    let broken = read_pairs("broken_bonds")?;
    let history_pairs = read_pairs("history_bonds")?;
    let history = if history_pairs.is_empty() {
        Vec::new()
    } else {
        read_f64("history", lb as u64, Some(history_pairs.len()))?
    };
    check_bond_lists(&broken, &history_pairs, scene_n)?;
    let c = Checkpoint {
        state: Snapshot {
            step: attr_u64(&a, "step")?,
            time: attr_f64(&a, "time")?,
            dt: attr_f64(&a, "dt")?,
            integrator: attr_string(&a, "integrator")?,
            model: attr_string(&a, "model")?,
            schema,
            ids: match kind {
                PartOf::Whole => None,
                PartOf::Part => Some(read_ids(&f, n, scene_n)?),
            },
            x0,
            alter,
            force,
            broken,
            history_pairs,
            history,
            thermostat: thermostat_state(&f, &a)?,
        },
        particles: scene_n,
        scene_hash: attr_u64(&a, "scene_hash")?,
        deck: attr_string(&a, "deck")?,
    };
    if checksum(&c) != attr_u64(&a, "checksum")? {
        return Err(
            "its data do not match the checksum written with them (the file is damaged)".into(),
        );
    }
    Ok(c)
}

/// The global ids of a part's `n` particles: ascending, below the scene's `scene_n`.
fn read_ids(f: &hdf5_pure::File, n: usize, scene_n: usize) -> Result<Vec<u32>, String> {
    let ids = f
        .dataset("id")
        .and_then(|d| d.read_u32())
        .map_err(|e| format!("dataset 'id' is missing or unreadable ({e})"))?;
    if ids.len() != n
        || ids.windows(2).any(|w| w[0] >= w[1])
        || ids.last().is_some_and(|&g| g as usize >= scene_n)
    {
        return Err(format!(
            "dataset 'id' holds {} ids for {n} particles, or ids out of order or beyond the scene's {scene_n}",
            ids.len()
        ));
    }
    Ok(ids)
}

/// The testing aid `PDQ_CHECKPOINT_PAUSE_MS`: tests/checkpoint.rs kills a run while it writes
/// a checkpoint; not for users. `PDQ_CHECKPOINT_PAUSE_AT` says where the pause is: `file` (the
/// default: halfway through each checkpoint file, or each part), `before-index` (every part
/// on disk, the index not begun) or `index` (halfway through the index).
pub(crate) fn pause(at: &str) -> Option<std::time::Duration> {
    let point = std::env::var("PDQ_CHECKPOINT_PAUSE_AT").unwrap_or_else(|_| "file".into());
    std::env::var("PDQ_CHECKPOINT_PAUSE_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|_| point == at)
        .map(std::time::Duration::from_millis)
}

/// Deletes all but the newest `keep` checkpoints in `dir`, with their parts.
pub(crate) fn prune(dir: &Path, keep: usize) {
    let mut old = list(dir);
    old.sort_unstable();
    if old.len() > keep.max(1) {
        for (step, p) in &old[..old.len() - keep.max(1)] {
            // The index first: a checkpoint without its index is no longer listed.
            let _ = std::fs::remove_file(p);
            let _ = std::fs::remove_dir_all(
                dir.join(crate::output::checkpoint_parts::parts_dir(*step)),
            );
        }
    }
}

/// The thermostat's state, in checkpoints of runs that have one.
fn thermostat_state(
    f: &hdf5_pure::File,
    a: &HashMap<String, AttrValue>,
) -> Result<Option<crate::engine::thermostat::Saved>, String> {
    let Ok(kind) = attr_string(a, "thermostat") else {
        return Ok(None);
    };
    let unreadable =
        |e: String| format!("dataset 'thermostat_state' is missing or unreadable ({e})");
    let values = f
        .dataset("thermostat_state")
        .map_err(|e| unreadable(e.to_string()))?
        .read_f64()
        .map_err(|e| unreadable(e.to_string()))?;
    Ok(Some(crate::engine::thermostat::Saved { kind, values }))
}

/// The integrator a checkpoint names (older ones name the leapfrog "semi-implicit-euler").
pub fn integrator(name: &str) -> Option<Integrator> {
    Integrator::from_name(name)
}

#[cfg(test)]
#[path = "checkpoint_tests.rs"]
mod tests;
