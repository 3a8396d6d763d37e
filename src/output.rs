//! What a run leaves behind: the CSV time history, particle frames for ParaView, progress.
//!
//! Frames are VTK XML unstructured grids (`.vtu`, one vertex cell per particle, raw binary
//! appended data) tied into a time series by a `.pvd` collection, which ParaView opens
//! directly. Every alterable attribute the model declares is written under its own name.

use crate::attributes::Attributes;
use crate::model::Model;
use crate::particles::Particles;
use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

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

/// A time series of `.vtu` frames and the `.pvd` file that lists them.
pub struct Frames {
    dir: PathBuf,
    entries: Vec<(f64, String)>,
}

/// One array of a frame.
enum Array<'a> {
    F64(&'a str, usize, Vec<f64>),
    I32(&'a str, Vec<i32>),
}

/// One array per field of `records`, named as the model declares it.
fn push_fields<A: Attributes>(arrays: &mut Vec<Array<'static>>, records: &[A]) {
    let mut offset = 0;
    for f in A::FIELDS {
        let o = offset;
        arrays.push(Array::F64(
            f.name,
            f.len,
            records
                .iter()
                .flat_map(|r| r.as_slice()[o..o + f.len].to_vec())
                .collect(),
        ));
        offset += f.len;
    }
}

impl Frames {
    pub fn new(dir: &Path) -> std::io::Result<Frames> {
        std::fs::create_dir_all(dir.join("frames"))?;
        Ok(Frames {
            dir: dir.to_path_buf(),
            entries: Vec::new(),
        })
    }

    /// Writes the owned particles at `step`, then rewrites the `.pvd` index.
    pub fn write<M: Model>(
        &mut self,
        step: u64,
        time: f64,
        p: &Particles<M>,
        damage: &[f64],
    ) -> std::io::Result<PathBuf> {
        let n = p.n_owned;
        let name = format!("frames/frame_{step:08}.vtu");
        let path = self.dir.join(&name);
        let mut arrays = vec![
            Array::I32("id", p.gid[..n].iter().map(|&g| g as i32).collect()),
            Array::I32(
                "material",
                p.material[..n].iter().map(|&m| m as i32).collect(),
            ),
            Array::F64("damage", 1, damage[..n].to_vec()),
            Array::F64(
                "displacement",
                3,
                (0..n).flat_map(|i| p.displacement(i)).collect(),
            ),
            Array::F64("volume", 1, p.volume[..n].to_vec()),
        ];
        // Every declared per-particle attribute, by its declared name.
        push_fields(&mut arrays, &p.alter[..n]);
        push_fields(&mut arrays, &p.fixed[..n]);
        push_fields(&mut arrays, &p.state[..n]);
        push_fields(&mut arrays, &p.force[..n]);
        let points: Vec<f64> = (0..n).flat_map(|i| p.pos(i)).collect();
        write_vtu(&path, &points, &arrays)?;
        self.entries.push((time, name));
        self.write_index()?;
        Ok(path)
    }

    fn write_index(&self) -> std::io::Result<()> {
        let tmp = self.dir.join("frames.pvd.tmp");
        let mut f = BufWriter::new(File::create(&tmp)?);
        writeln!(f, "<?xml version=\"1.0\"?>")?;
        writeln!(
            f,
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"
        )?;
        writeln!(f, "  <Collection>")?;
        for (t, name) in &self.entries {
            writeln!(
                f,
                "    <DataSet timestep=\"{t:.10e}\" group=\"\" part=\"0\" file=\"{name}\"/>"
            )?;
        }
        writeln!(f, "  </Collection>\n</VTKFile>")?;
        f.flush()?;
        drop(f);
        std::fs::rename(tmp, self.dir.join("frames.pvd"))
    }
}

/// A VTK XML unstructured grid of vertices with raw appended little-endian data.
fn write_vtu(path: &Path, points: &[f64], arrays: &[Array]) -> std::io::Result<()> {
    let n = points.len() / 3;
    let mut f = BufWriter::new(File::create(path)?);
    let mut blocks: Vec<Vec<u8>> = Vec::new();
    let mut offset = 0usize;
    let mut header = String::new();
    let mut add = |bytes: Vec<u8>, blocks: &mut Vec<Vec<u8>>| -> usize {
        let at = offset;
        offset += 8 + bytes.len();
        blocks.push(bytes);
        at
    };
    header.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    header.push_str(&format!(
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">\n<PointData>\n"
    ));
    for a in arrays {
        match a {
            Array::F64(name, comps, v) => {
                let at = add(bytemuck::cast_slice(v).to_vec(), &mut blocks);
                header.push_str(&format!("<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{at}\"/>\n"));
            }
            Array::I32(name, v) => {
                let at = add(bytemuck::cast_slice(v).to_vec(), &mut blocks);
                header.push_str(&format!("<DataArray type=\"Int32\" Name=\"{name}\" NumberOfComponents=\"1\" format=\"appended\" offset=\"{at}\"/>\n"));
            }
        }
    }
    header.push_str("</PointData>\n<Points>\n");
    let at = add(bytemuck::cast_slice(points).to_vec(), &mut blocks);
    header.push_str(&format!("<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{at}\"/>\n</Points>\n<Cells>\n"));
    let conn: Vec<i64> = (0..n as i64).collect();
    let offs: Vec<i64> = (1..=n as i64).collect();
    let types: Vec<u8> = vec![1; n];
    let at = add(bytemuck::cast_slice(&conn).to_vec(), &mut blocks);
    header.push_str(&format!(
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{at}\"/>\n"
    ));
    let at = add(bytemuck::cast_slice(&offs).to_vec(), &mut blocks);
    header.push_str(&format!(
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{at}\"/>\n"
    ));
    let at = add(types, &mut blocks);
    header.push_str(&format!("<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{at}\"/>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_"));
    f.write_all(header.as_bytes())?;
    for b in &blocks {
        f.write_all(&(b.len() as u64).to_le_bytes())?;
        f.write_all(b)?;
    }
    f.write_all(b"\n</AppendedData>\n</VTKFile>\n")?;
    f.flush()
}

/// A progress bar with ETA on a terminal; a plain line every 10% otherwise.
pub struct Progress {
    total: u64,
    start: Instant,
    last: Instant,
    tty: bool,
    enabled: bool,
    next_tenth: u64,
}

impl Progress {
    pub fn new(total: u64, enabled: bool) -> Progress {
        Progress {
            total: total.max(1),
            start: Instant::now(),
            last: Instant::now(),
            tty: std::io::stderr().is_terminal(),
            enabled,
            next_tenth: 1,
        }
    }

    pub fn update(&mut self, done: u64, broken: usize) {
        if !self.enabled {
            return;
        }
        let elapsed = self.start.elapsed().as_secs_f64();
        let frac = done as f64 / self.total as f64;
        let eta = if done > 0 {
            elapsed * (1.0 - frac) / frac
        } else {
            0.0
        };
        if self.tty {
            if self.last.elapsed().as_secs_f64() < 0.25 && done < self.total {
                return;
            }
            self.last = Instant::now();
            let width = 30;
            let filled = (frac * width as f64) as usize;
            eprint!(
                "\r[{}{}] {:5.1}% step {}/{} broken {} ETA {:.0} s   ",
                "#".repeat(filled),
                " ".repeat(width - filled),
                100.0 * frac,
                done,
                self.total,
                broken,
                eta
            );
            if done >= self.total {
                eprintln!();
            }
        } else if done * 10 >= self.next_tenth * self.total {
            while done * 10 >= self.next_tenth * self.total {
                self.next_tenth += 1;
            }
            eprintln!(
                "step {done}/{} ({:.0}%), broken bonds {broken}, elapsed {:.1} s, ETA {:.1} s",
                self.total,
                100.0 * frac,
                elapsed,
                eta
            );
        }
    }
}
