//! `pdq info FILE`: what a frame, a checkpoint, or a part of either holds.

use crate::output::checkpoint::{
    attr_f64, attr_string, attr_u64, quietly, read_file, Checkpoint, PartOf, FORMAT, PART_FORMAT,
};
use std::path::Path;

/// `pdq info FILE`: what a frame or checkpoint holds.
pub fn info(path: &Path) -> Result<String, String> {
    let f = quietly(|| hdf5_pure::File::open(path))
        .map_err(|_| format!("{}: the file is damaged", path.display()))?
        .map_err(|e| format!("{}: not a readable HDF5 file ({e})", path.display()))?;
    let attrs = f
        .root()
        .attrs()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    match attr_string(&attrs, "format").ok().as_deref() {
        Some(FORMAT) | Some(crate::output::checkpoint_parts::INDEX_FORMAT) => {
            return Checkpoint::read(path).map(|c| c.describe())
        }
        Some(PART_FORMAT) => {
            let c = quietly(|| read_file(path, PartOf::Part))
                .map_err(|_| format!("{}: the file is damaged", path.display()))?
                .map_err(|e| format!("checkpoint part {}: {e}", path.display()))?;
            return Ok(format!(
                "part of a checkpoint: {} of its particles
{}",
                c.state.x0.len(),
                c.describe()
            ));
        }
        _ => {}
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
