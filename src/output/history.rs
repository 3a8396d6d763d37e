//! The time history: one CSV row every `history_every` steps.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The time history: one CSV row every `history_every` steps.
pub struct History {
    out: BufWriter<File>,
    pub path: PathBuf,
}

impl History {
    pub fn create(path: &Path, columns: &[String]) -> std::io::Result<History> {
        let mut out = BufWriter::new(File::create(path)?);
        writeln!(out, "{}", columns.join(","))?;
        Ok(History {
            out,
            path: path.to_path_buf(),
        })
    }

    /// Continues the history of a restarted run: the rows of steps up to `step` that are on
    /// the schedule (multiples of `every`) are kept, so that the file ends up as an
    /// uninterrupted run's would be (rows written after the checkpoint, and the final row of a
    /// run that was then extended, are dropped); new rows follow them.
    pub fn resume(
        path: &Path,
        columns: &[String],
        step: u64,
        every: u64,
    ) -> std::io::Result<History> {
        let old = std::fs::read_to_string(path).unwrap_or_default();
        let mut kept = format!("{}\n", columns.join(","));
        for line in old.lines().skip(1) {
            let s: Option<f64> = line.split(',').next().and_then(|v| v.parse().ok());
            match s {
                Some(s) if s <= step as f64 => {
                    if (s as u64).is_multiple_of(every.max(1)) {
                        kept.push_str(line);
                        kept.push('\n');
                    }
                }
                _ => break,
            }
        }
        std::fs::write(path, kept)?;
        let out = BufWriter::new(File::options().append(true).open(path)?);
        Ok(History {
            out,
            path: path.to_path_buf(),
        })
    }

    pub fn row(&mut self, values: &[f64]) -> std::io::Result<()> {
        let mut first = true;
        for v in values {
            if !first {
                self.out.write_all(b",")?;
            }
            first = false;
            write!(self.out, "{v:.10e}")?;
        }
        self.out.write_all(b"\n")?;
        // Each row reaches the file at once: a run that is killed keeps its history.
        self.out.flush()
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}
