//! Files that appear whole or not at all.

use std::fs::File;
use std::io::Write;
use std::path::Path;

/// Writes an HDF5 file under a temporary name, syncs it and renames it into place, so that a
/// reader (or a run killed while writing) never sees a partial file under the real name.
///
/// `pause_midway` stops halfway through the temporary file for that long: the tests use it to
/// kill a run in the middle of writing a checkpoint.
pub fn write_atomically(
    path: &Path,
    b: hdf5_pure::FileBuilder,
    pause_midway: Option<std::time::Duration>,
) -> std::io::Result<()> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    let bytes = b
        .finish()
        .map_err(|e| std::io::Error::other(format!("HDF5: {e}")))?;
    {
        let mut f = File::create(&tmp)?;
        match pause_midway {
            Some(pause) => {
                let half = bytes.len() / 2;
                f.write_all(&bytes[..half])?;
                f.sync_all()?;
                std::thread::sleep(pause);
                f.write_all(&bytes[half..])?;
            }
            None => f.write_all(&bytes)?,
        }
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)?;
    if let Some(dir) = path.parent() {
        // The rename itself reaches the disk with the directory.
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}
