//! Voxel labels for ParaView: one HDF5 file per analysis (`NAME_voxels/voxels_STEP.h5`, a
//! `labels` dataset of nz × ny × nx 32-bit integers: -1 occupied, 0 outside, k the k-th
//! cluster's id) tied into a time series by `NAME_voxels.xdmf`, a 3DCoRectMesh with the labels
//! as cell data (open it with the "Xdmf3 Reader" and threshold `labels` ≥ 1 to see the voids).

use crate::output::write_atomically;
use crate::voids::VoxelGrid;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A time series of voxel-label files and its XDMF index.
pub struct VoxelSeries {
    dir: PathBuf,
    name: String,
    /// Step, time and grid of each file written.
    entries: Vec<(u64, f64, VoxelGrid)>,
}

impl VoxelSeries {
    pub fn new(dir: &Path, name: &str) -> std::io::Result<VoxelSeries> {
        std::fs::create_dir_all(dir.join(format!("{name}_voxels")))?;
        Ok(VoxelSeries {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            entries: Vec::new(),
        })
    }

    fn file(&self, step: u64) -> String {
        format!("{}_voxels/voxels_{step:08}.h5", self.name)
    }

    /// Writes one grid's labels (x fastest, one per voxel), then rewrites the index.
    pub fn write(
        &mut self,
        step: u64,
        time: f64,
        grid: &VoxelGrid,
        labels: &[i32],
    ) -> std::io::Result<()> {
        assert_eq!(labels.len(), grid.len(), "one label per voxel");
        let mut b = hdf5_pure::FileBuilder::new();
        b.set_attr("step", hdf5_pure::AttrValue::U64(step));
        b.set_attr("time", hdf5_pure::AttrValue::F64(time));
        let [nx, ny, nz] = grid.dims.map(|n| n as u64);
        b.create_dataset("labels")
            .with_i32_data(labels)
            .with_shape(&[nz, ny, nx]);
        write_atomically(&self.dir.join(self.file(step)), b, None)?;
        self.entries.retain(|e| e.0 < step);
        self.entries.push((step, time, grid.clone()));
        self.write_index()
    }

    fn write_index(&self) -> std::io::Result<()> {
        let mut x = String::new();
        x.push_str("<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n");
        let _ = writeln!(
            x,
            "<Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">",
            self.name
        );
        for (step, time, g) in &self.entries {
            let [nx, ny, nz] = g.dims;
            // Points are one more than cells along each axis; XDMF lists z first.
            let _ = writeln!(
                x,
                "<Grid Name=\"step_{step}\" GridType=\"Uniform\">\n<Time Value=\"{time:.17e}\"/>\n<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{} {} {}\"/>\n<Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n<DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">{:.17e} {:.17e} {:.17e}</DataItem>\n<DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">{:.17e} {:.17e} {:.17e}</DataItem>\n</Geometry>\n<Attribute Name=\"labels\" AttributeType=\"Scalar\" Center=\"Cell\">\n<DataItem Dimensions=\"{nz} {ny} {nx}\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">{}:/labels</DataItem>\n</Attribute>\n</Grid>",
                nz + 1,
                ny + 1,
                nx + 1,
                g.origin[2],
                g.origin[1],
                g.origin[0],
                g.size[2],
                g.size[1],
                g.size[0],
                self.file(*step)
            );
        }
        x.push_str("</Grid>\n</Domain>\n</Xdmf>\n");
        std::fs::write(self.dir.join(format!("{}_voxels.xdmf", self.name)), x)
    }
}
