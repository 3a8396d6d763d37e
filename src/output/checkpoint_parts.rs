//! Checkpoints in parts: on several MPI ranks each procCube writes its own file, and the root
//! then writes an index under the name a one-file checkpoint has. Nothing is gathered on one
//! rank, so a checkpoint costs each rank its own share of the scene.
//!
//! - `checkpoint_SSSSSSSS.parts/part_RRRR.h5`: one procCube's particles (global ids in `id`,
//!   ascending) with the broken bonds and bond histories it holds, written as a checkpoint of
//!   those particles (format `pdq-checkpoint-part`, with its own checksum).
//! - `checkpoint_SSSSSSSS.h5`: the index (format `pdq-checkpoint-parts`): step, time, scene,
//!   and each part's particle count and checksum.
//!
//! The index is written, atomically, only after every part is on disk, and the previous
//! checkpoint is deleted only after that. A run killed on the way leaves parts without an
//! index (not a checkpoint: the next one at that step overwrites them, pruning deletes them)
//! and the previous checkpoint whole. A restart reads the parts by global id, on any layout or
//! rank count: whole (`Checkpoint::read`), or a procCube's share a part at a time
//! (`Checkpoint::read_some`).

use super::checkpoint::{
    checksum, file_name, pause, prune, read_file, Checkpoint, PartOf, PART_FORMAT, VERSION,
};
use crate::parallel::snapshot::Snapshot;
use hdf5_pure::AttrValue;
use std::path::{Path, PathBuf};

/// The format attribute of an index.
pub const INDEX_FORMAT: &str = "pdq-checkpoint-parts";

/// The directory of the parts of the checkpoint at `step`, beside its index.
pub fn parts_dir(step: u64) -> String {
    format!("checkpoint_{step:08}.parts")
}

fn part_path(dir: &Path, step: u64, part: usize) -> PathBuf {
    dir.join(parts_dir(step)).join(format!("part_{part:04}.h5"))
}

/// What the index records of a part, and what the root learns of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PartRecord {
    pub checksum: u64,
    pub particles: u64,
    pub broken: u64,
    pub bytes: u64,
}

impl PartRecord {
    pub fn to_bytes(self) -> Vec<u8> {
        [self.checksum, self.particles, self.broken, self.bytes]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect()
    }

    /// A record from [`PartRecord::to_bytes`]; `None` for anything else (a part not written).
    pub fn from_bytes(b: &[u8]) -> Option<PartRecord> {
        let v: Vec<u64> = b
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect();
        (v.len() == 4).then(|| PartRecord {
            checksum: v[0],
            particles: v[1],
            broken: v[2],
            bytes: v[3],
        })
    }
}

/// Writes part `part` of the checkpoint at `c`'s step (atomically): `c` holds one procCube's
/// particles.
pub fn write_part(dir: &Path, c: &Checkpoint, part: usize) -> std::io::Result<PartRecord> {
    let path = part_path(dir, c.state.step, part);
    std::fs::create_dir_all(path.parent().unwrap_or(dir))?;
    crate::output::write_atomically(&path, c.builder(PART_FORMAT), pause("file"))?;
    Ok(PartRecord {
        checksum: checksum(c),
        particles: c.state.x0.len() as u64,
        broken: c.state.broken.len() as u64,
        bytes: std::fs::metadata(&path)?.len(),
    })
}

/// Writes the index of the checkpoint at `c`'s step once every part is on disk (the root;
/// `c`: its own part, for the header), deletes parts of an earlier attempt beyond these, and
/// keeps the newest `keep` checkpoints; returns the index's path and the bytes of the whole.
pub fn write_index(
    dir: &Path,
    c: &Checkpoint,
    parts: &[PartRecord],
    keep: usize,
) -> std::io::Result<(PathBuf, u64)> {
    let st = &c.state;
    let mut b = hdf5_pure::FileBuilder::new();
    let s = |v: &str| AttrValue::String(v.to_string());
    b.set_attr("format", s(INDEX_FORMAT));
    b.set_attr("version", AttrValue::I64(VERSION));
    b.set_attr("step", AttrValue::U64(st.step));
    b.set_attr("time", AttrValue::F64(st.time));
    b.set_attr("dt", AttrValue::F64(st.dt));
    b.set_attr("integrator", s(&st.integrator));
    b.set_attr("model", s(&st.model));
    b.set_attr("schema", s(&st.schema));
    b.set_attr("scene_hash", AttrValue::U64(c.scene_hash));
    b.set_attr("deck", s(&c.deck));
    b.set_attr("particles", AttrValue::U64(c.particles as u64));
    b.set_attr("parts", AttrValue::U64(parts.len() as u64));
    let broken: u64 = parts.iter().map(|p| p.broken).sum();
    b.set_attr("broken_bonds", AttrValue::U64(broken));
    let column = |f: fn(&PartRecord) -> u64| parts.iter().map(f).collect::<Vec<u64>>();
    b.create_dataset("part_checksums")
        .with_u64_data(&column(|p| p.checksum));
    b.create_dataset("part_particles")
        .with_u64_data(&column(|p| p.particles));
    let path = dir.join(file_name(st.step));
    if let Some(d) = pause("before-index") {
        std::thread::sleep(d);
    }
    crate::output::write_atomically(&path, b, pause("index"))?;
    // Parts left by an attempt on more ranks (a run killed before its index) are not this
    // checkpoint's.
    let mut k = parts.len();
    while std::fs::remove_file(part_path(dir, st.step, k)).is_ok() {
        k += 1;
    }
    let bytes = parts.iter().map(|p| p.bytes).sum::<u64>() + std::fs::metadata(&path)?.len();
    prune(dir, keep);
    Ok((path, bytes))
}

/// Whether `path` is the index of a checkpoint written in parts.
pub fn is_index(path: &Path) -> bool {
    let Ok(f) = hdf5_pure::File::open(path) else {
        return false;
    };
    let format = f.root().attrs().ok().and_then(|a| match a.get("format") {
        Some(AttrValue::String(v)) | Some(AttrValue::AsciiString(v)) => Some(v.clone()),
        _ => None,
    });
    format.as_deref() == Some(INDEX_FORMAT)
}

/// Reads the checkpoint whose index is `path`: every part, verified against the index; with
/// `keep`, only the particles it names and the bonds between two of them, a part at a time.
pub fn read(path: &Path, keep: Option<&dyn Fn(u32) -> bool>) -> Result<Checkpoint, String> {
    let f = hdf5_pure::File::open(path).map_err(|e| format!("not a readable HDF5 file ({e})"))?;
    let a = f
        .root()
        .attrs()
        .map_err(|e| format!("cannot read its attributes ({e})"))?;
    let attr = |name: &str| match a.get(name) {
        Some(AttrValue::U64(v)) => Ok(*v),
        Some(AttrValue::I64(v)) if *v >= 0 => Ok(*v as u64),
        _ => Err(format!(
            "attribute '{name}' is missing or has the wrong type"
        )),
    };
    if attr("version")? != VERSION as u64 {
        return Err(format!(
            "checkpoint format version {}, this pdq reads {VERSION}",
            attr("version")?
        ));
    }
    let (step, n, count) = (
        attr("step")?,
        attr("particles")? as usize,
        attr("parts")? as usize,
    );
    let column = |name: &str| {
        f.dataset(name)
            .and_then(|d| d.read_u64())
            .map_err(|e| format!("dataset '{name}' is missing or unreadable ({e})"))
    };
    let (sums, sizes) = (column("part_checksums")?, column("part_particles")?);
    if sums.len() != count || sizes.len() != count {
        return Err(format!(
            "the index lists {count} parts but {} checksums",
            sums.len()
        ));
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut states: Vec<Snapshot> = Vec::with_capacity(count);
    let mut header = None;
    for k in 0..count {
        let p = part_path(dir, step, k);
        let refuse = |e: String| format!("its part {}: {e}", p.display());
        let c = read_file(&p, PartOf::Part).map_err(refuse)?;
        if checksum(&c) != sums[k] || c.state.x0.len() as u64 != sizes[k] || c.state.step != step {
            return Err(refuse(
                "the part is not the one the index lists (another attempt at this step's checkpoint)".into(),
            ));
        }
        let c = match keep {
            Some(keep) => c.only(keep),
            None => c,
        };
        let Checkpoint {
            state,
            particles,
            scene_hash,
            deck,
        } = c;
        states.push(state);
        header.get_or_insert(Checkpoint {
            state: Snapshot::default(),
            particles,
            scene_hash,
            deck,
        });
    }
    let header = header.ok_or("the index lists no parts")?;
    let state = Snapshot::merge(states, keep.is_none().then_some(n)).ok_or("no parts")?;
    if keep.is_none() && state.ids.is_some() {
        return Err(format!(
            "its parts hold {} particles, not each of the scene's {n} once",
            state.x0.len()
        ));
    }
    Ok(Checkpoint { state, ..header })
}
