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
const FORMAT: &str = "pdq-checkpoint";
const VERSION: i64 = 1;

/// A run's state at the end of a step, by global id, and what identifies its scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub state: Snapshot,
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

fn checksum(c: &Checkpoint) -> u64 {
    let mut h = Fnv::new();
    h.bytes(&c.state.step.to_le_bytes());
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
            scene_hash,
            deck: deck.to_string(),
        })
    }

    /// Writes the checkpoint as `dir/checkpoint_SSSSSSSS.h5` (atomically), then deletes all but
    /// the newest `keep` checkpoints in `dir`; returns the path and the size in bytes.
    pub fn write(&self, dir: &Path, keep: usize) -> std::io::Result<(PathBuf, u64)> {
        std::fs::create_dir_all(dir)?;
        let path = dir.join(file_name(self.state.step));
        let mut b = hdf5_pure::FileBuilder::new();
        let s = |v: &str| AttrValue::String(v.to_string());
        b.set_attr("format", s(FORMAT));
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
        b.set_attr(
            "broken_bonds",
            AttrValue::U64(self.state.broken.len() as u64),
        );
        b.set_attr("checksum", AttrValue::U64(checksum(self)));
        let n = self.state.x0.len() as u64;
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
        // A testing aid (tests/checkpoint.rs kills a run while it writes); not for users.
        let pause = std::env::var("PDQ_CHECKPOINT_PAUSE_MS")
            .ok()
            .and_then(|v| v.parse().ok())
            .map(std::time::Duration::from_millis);
        crate::output::write_atomically(&path, b, pause)?;
        let size = std::fs::metadata(&path)?.len();
        let mut old = list(dir);
        old.sort_unstable();
        if old.len() > keep.max(1) {
            for (_, p) in &old[..old.len() - keep.max(1)] {
                let _ = std::fs::remove_file(p);
            }
        }
        Ok((path, size))
    }

    /// Reads and verifies a checkpoint: a file that is not one, is truncated or damaged, or
    /// whose data do not match its checksum is refused with a message naming the file.
    pub fn read(path: &Path) -> Result<Checkpoint, String> {
        let what = |e: String| format!("checkpoint {}: {e}", path.display());
        // The HDF5 reader is asked to parse whatever the file holds; a damaged file must give
        // an error, so a panic inside it becomes one too.
        let read = quietly(|| read_file(path));
        match read {
            Ok(r) => r.map_err(what),
            Err(_) => Err(what(
                "the file is damaged (the HDF5 reader failed on it)".into(),
            )),
        }
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
        if self.state.x0.len() != n {
            return refuse(format!(
                "it holds {} particles, the deck builds {n}",
                self.state.x0.len()
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
            self.state.x0.len(),
            fields,
            self.state.broken.len(),
            self.state.history_pairs.len()
        )
    }
}

/// Runs `f`, turning a panic into `Err` without the panic message on stderr: the file readers
/// must answer a damaged file with an error of their own.
fn quietly<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
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
    if !path.is_dir() {
        if !path.exists() {
            return Err(format!("checkpoint {}: no such file", path.display()));
        }
        return Checkpoint::read(path).map(|c| (path.to_path_buf(), c));
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
        match Checkpoint::read(p) {
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

fn attr_u64(a: &HashMap<String, AttrValue>, name: &str) -> Result<u64, String> {
    match a.get(name) {
        Some(AttrValue::U64(v)) => Ok(*v),
        Some(AttrValue::I64(v)) if *v >= 0 => Ok(*v as u64),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

fn attr_f64(a: &HashMap<String, AttrValue>, name: &str) -> Result<f64, String> {
    match a.get(name) {
        Some(AttrValue::F64(v)) => Ok(*v),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

fn attr_string(a: &HashMap<String, AttrValue>, name: &str) -> Result<String, String> {
    match a.get(name) {
        Some(AttrValue::String(v)) | Some(AttrValue::AsciiString(v)) => Ok(v.clone()),
        Some(_) => Err(format!("attribute '{name}' has the wrong type")),
        None => Err(format!("attribute '{name}' is missing")),
    }
}

fn read_file(path: &Path) -> Result<Checkpoint, String> {
    let f = hdf5_pure::File::open(path).map_err(|e| format!("not a readable HDF5 file ({e})"))?;
    let a = f
        .root()
        .attrs()
        .map_err(|e| format!("cannot read its attributes ({e})"))?;
    if attr_string(&a, "format").ok().as_deref() != Some(FORMAT) {
        return Err(
            "not a PDQ checkpoint (no format = \"pdq-checkpoint\" attribute; a frame file?)".into(),
        );
    }
    let version = attr_u64(&a, "version")?;
    if version != VERSION as u64 {
        return Err(format!(
            "checkpoint format version {version}, this pdq reads {VERSION}"
        ));
    }
    let n = attr_u64(&a, "particles")? as usize;
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
    if broken
        .iter()
        .chain(&history_pairs)
        .any(|&(a, b)| a as usize >= n || b as usize >= n || a >= b)
        || broken.windows(2).any(|w| w[0] >= w[1])
        || history_pairs.windows(2).any(|w| w[0] >= w[1])
    {
        return Err("its bond lists name particles that do not exist or are out of order".into());
    }
    let c = Checkpoint {
        state: Snapshot {
            step: attr_u64(&a, "step")?,
            time: attr_f64(&a, "time")?,
            dt: attr_f64(&a, "dt")?,
            integrator: attr_string(&a, "integrator")?,
            model: attr_string(&a, "model")?,
            schema,
            x0,
            alter,
            force,
            broken,
            history_pairs,
            history,
            thermostat: thermostat_state(&f, &a)?,
        },
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

/// `pdq info FILE`: what a frame or checkpoint holds.
pub fn info(path: &Path) -> Result<String, String> {
    let f = quietly(|| hdf5_pure::File::open(path))
        .map_err(|_| format!("{}: the file is damaged", path.display()))?
        .map_err(|e| format!("{}: not a readable HDF5 file ({e})", path.display()))?;
    let attrs = f
        .root()
        .attrs()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if attr_string(&attrs, "format").ok().as_deref() == Some(FORMAT) {
        return Checkpoint::read(path).map(|c| c.describe());
    }
    // A frame: step, time, and its arrays.
    let step = attr_u64(&attrs, "step")
        .map_err(|e| format!("{}: not a PDQ frame or checkpoint ({e})", path.display()))?;
    let time = attr_f64(&attrs, "time").map_err(|e| format!("{}: {e}", path.display()))?;
    let model = attr_string(&attrs, "model").unwrap_or_default();
    let mut s = format!("frame of model '{model}'\nstep       {step}\ntime       {time:.10e}\n");
    let mut arrays = Vec::new();
    let mut particles = 0;
    let mut max_damage = 0.0f64;
    let mut names = f
        .root()
        .datasets()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    names.sort();
    for name in names {
        let d = f
            .dataset(&name)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let shape = d.shape().map_err(|e| format!("{}: {e}", path.display()))?;
        if name == "points" {
            particles = shape.first().copied().unwrap_or(0);
        }
        if name == "damage" {
            if let Ok(v) = d.read_f64() {
                max_damage = v.iter().cloned().fold(0.0, f64::max);
            }
        }
        if name != "points" && name != "cells" {
            arrays.push(format!("{name}[{}]", shape.get(1).copied().unwrap_or(1)));
        }
    }
    let broken = attr_u64(&attrs, "broken_bonds").map_or("?".to_string(), |b| b.to_string());
    s.push_str(&format!(
        "particles  {particles}\nattributes {}\nbonds      {broken} broken; damage max {max_damage:.4}\n",
        arrays.join(", ")
    ));
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(step: u64) -> Checkpoint {
        Checkpoint {
            state: Snapshot {
                step,
                time: 1.25e-3,
                dt: 2.5e-7,
                integrator: "velocity-verlet".into(),
                model: "concrete".into(),
                schema: "pos:3,vel:3|plastic_stretch:1|force:3".into(),
                x0: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]],
                alter: (0..18).map(|k| k as f64 * 0.1 - 0.3).collect(),
                force: (0..9).map(|k| -(k as f64) * 1e3).collect(),
                broken: vec![(0, 2)],
                history_pairs: vec![(0, 1), (1, 2)],
                history: vec![1.5e-4, -2.0e-5],
                thermostat: (step == 20).then(|| crate::engine::thermostat::Saved {
                    kind: "nose-hoover".into(),
                    values: vec![0.125, -3.5],
                }),
            },
            scene_hash: 0x0123_4567_89ab_cdef,
            deck: "beam.toml".into(),
        }
    }

    #[test]
    fn bond_histories_and_broken_bonds_round_trip_and_old_files_are_pruned() {
        let dir = std::env::temp_dir().join(format!("pdq-ckpt-unit-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for step in [10, 20, 30, 40] {
            let (path, size) = sample(step).write(&dir, 2).unwrap();
            assert!(size > 0);
            assert_eq!(Checkpoint::read(&path).unwrap(), sample(step));
        }
        let mut kept: Vec<u64> = list(&dir).into_iter().map(|(s, _)| s).collect();
        kept.sort_unstable();
        assert_eq!(kept, vec![30, 40], "the newest two are kept");
        let (_, newest) = resolve(&dir).unwrap();
        assert_eq!(newest.state.step, 40);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
