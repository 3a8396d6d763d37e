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
use crate::model::attributes::Attributes;
use crate::model::Model;
use crate::parallel::comm::f64s;
use crate::parallel::Cube;
use hdf5_pure::AttrValue;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What identifies the file as a PDQ checkpoint, and its layout version.
const FORMAT: &str = "pdq-checkpoint";
const VERSION: i64 = 1;

/// A run's state at the end of a step, by global id.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub integrator: String,
    pub model: String,
    /// `name:len` of each alterable field, `|`, the bond history's, `|`, the force's.
    pub schema: String,
    pub scene_hash: u64,
    /// The deck file the run was started from (informational).
    pub deck: String,
    pub x0: Vec<[f64; 3]>,
    /// Alterable records, `Alter::LEN` values per particle, by global id.
    pub alter: Vec<f64>,
    /// The generalized forces of the last evaluation, `Force::LEN` per particle, by global id:
    /// the integrator's state (velocity Verlet starts a step with them). Recomputing them would
    /// not do: an LPS bond that broke in the last pair pass still counted in its state pass.
    pub force: Vec<f64>,
    /// Broken bonds, (smaller, larger) global id, sorted.
    pub broken: Vec<(u32, u32)>,
    /// Bonds with a non-zero history, sorted, and their histories (`Bond::LEN` each).
    pub history_pairs: Vec<(u32, u32)>,
    pub history: Vec<f64>,
}

/// The names and lengths of the alterable and bond-history fields of `M`.
pub fn schema<M: Model>() -> String {
    let fields = |f: &[crate::model::attributes::Field]| {
        f.iter()
            .map(|f| format!("{}:{}", f.name, f.len))
            .collect::<Vec<_>>()
            .join(",")
    };
    format!(
        "{}|{}|{}",
        fields(<M::Alter as Attributes>::FIELDS),
        fields(<M::Bond as Attributes>::FIELDS),
        fields(<M::Force as Attributes>::FIELDS)
    )
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
    let mut h = Fnv::new();
    h.bytes(M::NAME.as_bytes());
    h.bytes(schema::<M>().as_bytes());
    h.bytes(format!("{:?}{:?}", scene.materials, scene.model_options).as_bytes());
    // Bars: which particle belongs to which (their own bonds are calibrated) and their
    // prestrain, which a restart must not change under bonds that already carry it.
    h.bytes(format!("{:?}{:?}", setup.bars.bar_of, scene.bar_prestrain).as_bytes());
    h.f64s(&[setup.horizon, setup.spacing]);
    h.bytes(&(p.len() as u64).to_le_bytes());
    for i in order {
        h.f64s(&p.x0[i]);
        h.f64s(&[p.volume[i]]);
        h.bytes(&p.material[i].to_le_bytes());
    }
    h.0
}

fn checksum(c: &Checkpoint) -> u64 {
    let mut h = Fnv::new();
    h.bytes(&c.step.to_le_bytes());
    h.f64s(&[c.time, c.dt]);
    for x in &c.x0 {
        h.f64s(x);
    }
    h.f64s(&c.alter);
    h.f64s(&c.force);
    for &(a, b) in c.broken.iter().chain(&c.history_pairs) {
        h.bytes(&a.to_le_bytes());
        h.bytes(&b.to_le_bytes());
    }
    h.f64s(&c.history);
    h.0
}

/// The file name of the checkpoint at `step`.
pub fn file_name(step: u64) -> String {
    format!("checkpoint_{step:08}.h5")
}

impl Checkpoint {
    /// Gathers the state of every procCube on the root, which gets the checkpoint; every
    /// worker must call it.
    pub fn gather<M: Model>(cube: &mut Cube<M>, scene_hash: u64, deck: &str) -> Option<Checkpoint> {
        let la = <M::Alter as Attributes>::LEN;
        let lb = <M::Bond as Attributes>::LEN;
        let lf = <M::Force as Attributes>::LEN;
        let p = &cube.sim.particles;
        let mut mine: Vec<f64> = Vec::with_capacity(p.n_owned * (4 + la + lf));
        for i in 0..p.n_owned {
            mine.push(p.gid[i] as f64);
            mine.extend_from_slice(&p.x0[i]);
            mine.extend_from_slice(p.alter[i].as_slice());
            mine.extend_from_slice(p.force[i].as_slice());
        }
        let b = &cube.sim.bonds;
        let mut bonds: Vec<f64> = Vec::new();
        for (i, j, k) in b.iter() {
            let h = b.history[k].as_slice();
            if b.broken[k] || h.iter().any(|&x| x != 0.0) {
                let (gi, gj) = (p.gid[i], p.gid[j]);
                bonds.push(gi.min(gj) as f64);
                bonds.push(gi.max(gj) as f64);
                bonds.push(if b.broken[k] { 1.0 } else { 0.0 });
                bonds.extend_from_slice(h);
            }
        }
        // Bonds a shuffle dropped once broken: broken, history no longer needed.
        for &(a, c) in &cube.dropped {
            bonds.extend_from_slice(&[a as f64, c as f64, 1.0]);
            bonds.extend(std::iter::repeat_n(0.0, lb));
        }
        let (step, time, dt) = (cube.sim.step, cube.sim.time, cube.sim.dt);
        let integrator = cube.sim.integrator.name().to_string();
        let n = cube.global_particles;
        let mut team = cube.team();
        let particles = team.gather(bytemuck::cast_slice(&mine));
        let bonds = team.gather(bytemuck::cast_slice(&bonds));
        let (particles, bonds) = (particles?, bonds?);
        let mut x0 = vec![[f64::NAN; 3]; n];
        let mut alter = vec![f64::NAN; n * la];
        let mut force = vec![f64::NAN; n * lf];
        for bytes in particles {
            for r in f64s(&bytes).chunks_exact(4 + la + lf) {
                let g = r[0] as usize;
                x0[g] = [r[1], r[2], r[3]];
                alter[g * la..(g + 1) * la].copy_from_slice(&r[4..4 + la]);
                force[g * lf..(g + 1) * lf].copy_from_slice(&r[4 + la..]);
            }
        }
        let mut rows: Vec<(u32, u32, bool, Vec<f64>)> = Vec::new();
        for bytes in bonds {
            for r in f64s(&bytes).chunks_exact(3 + lb) {
                rows.push((r[0] as u32, r[1] as u32, r[2] != 0.0, r[3..].to_vec()));
            }
        }
        rows.sort_by_key(|r| (r.0, r.1));
        let mut c = Checkpoint {
            step,
            time,
            dt,
            integrator,
            model: M::NAME.to_string(),
            schema: schema::<M>(),
            scene_hash,
            deck: deck.to_string(),
            x0,
            alter,
            force,
            broken: Vec::new(),
            history_pairs: Vec::new(),
            history: Vec::new(),
        };
        for (a, b, broken, h) in rows {
            if broken {
                c.broken.push((a, b));
            }
            if h.iter().any(|&x| x != 0.0) {
                c.history_pairs.push((a, b));
                c.history.extend_from_slice(&h);
            }
        }
        Some(c)
    }

    /// Writes the checkpoint as `dir/checkpoint_SSSSSSSS.h5` (atomically), then deletes all but
    /// the newest `keep` checkpoints in `dir`; returns the path and the size in bytes.
    pub fn write(&self, dir: &Path, keep: usize) -> std::io::Result<(PathBuf, u64)> {
        std::fs::create_dir_all(dir)?;
        let path = dir.join(file_name(self.step));
        let mut b = hdf5_pure::FileBuilder::new();
        let s = |v: &str| AttrValue::String(v.to_string());
        b.set_attr("format", s(FORMAT));
        b.set_attr("version", AttrValue::I64(VERSION));
        b.set_attr("step", AttrValue::U64(self.step));
        b.set_attr("time", AttrValue::F64(self.time));
        b.set_attr("dt", AttrValue::F64(self.dt));
        b.set_attr("integrator", s(&self.integrator));
        b.set_attr("model", s(&self.model));
        b.set_attr("schema", s(&self.schema));
        b.set_attr("scene_hash", AttrValue::U64(self.scene_hash));
        b.set_attr("deck", s(&self.deck));
        b.set_attr("particles", AttrValue::U64(self.x0.len() as u64));
        b.set_attr("broken_bonds", AttrValue::U64(self.broken.len() as u64));
        b.set_attr("checksum", AttrValue::U64(checksum(self)));
        let n = self.x0.len() as u64;
        let x0: Vec<f64> = self.x0.iter().flatten().copied().collect();
        b.create_dataset("x0")
            .with_f64_data(&x0)
            .with_shape(&[n, 3]);
        // One dataset per alterable field and per force field, by its declared name.
        let parts: Vec<&str> = self.schema.split('|').collect();
        for (prefix, fields, values) in [
            ("alter", parts.first(), &self.alter),
            ("force", parts.get(2), &self.force),
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
            .with_u32_data(&pairs(&self.broken))
            .with_shape(&[self.broken.len() as u64, 2]);
        let m = self.history_pairs.len() as u64;
        b.create_dataset("history_bonds")
            .with_u32_data(&pairs(&self.history_pairs))
            .with_shape(&[m, 2]);
        let lb = (self.history.len() as u64).checked_div(m).unwrap_or(0);
        b.create_dataset("history")
            .with_f64_data(&self.history)
            .with_shape(&[m, lb]);
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
        if self.model != M::NAME {
            return refuse(format!(
                "it is of model '{}', the deck uses '{}'",
                self.model,
                M::NAME
            ));
        }
        if self.schema != schema::<M>() {
            return refuse(format!(
                "its attributes are [{}], the model's are [{}]",
                self.schema,
                schema::<M>()
            ));
        }
        if self.x0.len() != n {
            return refuse(format!(
                "it holds {} particles, the deck builds {n}",
                self.x0.len()
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

    /// Puts the checkpoint's particles into a freshly built scene: reference positions (a
    /// shuffle may have wrapped some around a periodic box), alterable attributes, time and
    /// step. Bonds are marked per procCube by [`Checkpoint::restore_bonds`].
    pub fn restore_particles<M: Model>(&self, setup: &mut Setup<M>) {
        let la = <M::Alter as Attributes>::LEN;
        let sim = &mut setup.sim;
        let p = &mut sim.particles;
        for i in 0..p.len() {
            let g = p.gid[i] as usize;
            p.x0[i] = self.x0[g];
            p.alter[i]
                .as_mut_slice()
                .copy_from_slice(&self.alter[g * la..(g + 1) * la]);
        }
        sim.time = self.time;
        sim.step = self.step;
    }

    /// Marks the broken bonds of a procCube and sets bond histories, by global ids; sets its
    /// clock.
    pub fn restore_bonds<M: Model>(&self, cube: &mut Cube<M>) {
        let lb = <M::Bond as Attributes>::LEN;
        let sim = &mut cube.sim;
        sim.time = self.time;
        sim.step = self.step;
        let gid = &sim.particles.gid;
        let key = |i: usize, j: usize| (gid[i].min(gid[j]), gid[i].max(gid[j]));
        let b = &mut sim.bonds;
        let bonds: Vec<(usize, usize, usize)> = b.iter().collect();
        for (i, j, k) in bonds {
            let pair = key(i, j);
            if self.broken.binary_search(&pair).is_ok() {
                b.broken[k] = true;
            }
            if lb > 0 {
                if let Ok(at) = self.history_pairs.binary_search(&pair) {
                    b.history[k]
                        .as_mut_slice()
                        .copy_from_slice(&self.history[at * lb..(at + 1) * lb]);
                }
            }
        }
    }

    /// The forces of the last evaluation, over the ones a restarted procCube's first
    /// evaluation found (call after `Cube::start`).
    pub fn restore_forces<M: Model>(&self, cube: &mut Cube<M>) {
        let lf = <M::Force as Attributes>::LEN;
        let p = &mut cube.sim.particles;
        for i in 0..p.n_owned {
            let g = p.gid[i] as usize;
            p.force[i]
                .as_mut_slice()
                .copy_from_slice(&self.force[g * lf..(g + 1) * lf]);
        }
    }

    /// What `pdq info` prints.
    pub fn describe(&self) -> String {
        let fields = self.schema.replace('|', "; ");
        format!(
            "checkpoint of model '{}' from {}\nstep       {}\ntime       {:.10e} (dt {:.6e}, {})\nparticles  {}\nattributes {}\nbonds      {} broken, {} with history\n",
            self.model,
            self.deck,
            self.step,
            self.time,
            self.dt,
            self.integrator,
            self.x0.len(),
            fields,
            self.broken.len(),
            self.history_pairs.len()
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
        step: attr_u64(&a, "step")?,
        time: attr_f64(&a, "time")?,
        dt: attr_f64(&a, "dt")?,
        integrator: attr_string(&a, "integrator")?,
        model: attr_string(&a, "model")?,
        schema,
        scene_hash: attr_u64(&a, "scene_hash")?,
        deck: attr_string(&a, "deck")?,
        x0,
        alter,
        force,
        broken,
        history_pairs,
        history,
    };
    if checksum(&c) != attr_u64(&a, "checksum")? {
        return Err(
            "its data do not match the checksum written with them (the file is damaged)".into(),
        );
    }
    Ok(c)
}

/// The integrator a checkpoint names.
pub fn integrator(name: &str) -> Option<Integrator> {
    [Integrator::VelocityVerlet, Integrator::SemiImplicitEuler]
        .into_iter()
        .find(|i| i.name() == name)
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
            step,
            time: 1.25e-3,
            dt: 2.5e-7,
            integrator: "velocity-verlet".into(),
            model: "concrete".into(),
            schema: "pos:3,vel:3|plastic_stretch:1|force:3".into(),
            scene_hash: 0x0123_4567_89ab_cdef,
            deck: "beam.toml".into(),
            x0: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]],
            alter: (0..18).map(|k| k as f64 * 0.1 - 0.3).collect(),
            force: (0..9).map(|k| -(k as f64) * 1e3).collect(),
            broken: vec![(0, 2)],
            history_pairs: vec![(0, 1), (1, 2)],
            history: vec![1.5e-4, -2.0e-5],
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
        assert_eq!(newest.step, 40);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
