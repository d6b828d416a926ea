//! `fields.h5` + `fields.xdmf`: particle and grid fields over time, for ParaView.
//!
//! Every output time `i` adds the HDF5 groups `/particles/<i>` (one dataset per particle field,
//! n or n × 3 values) and `/grid/<i>` (one dataset per nodal field, n_y × n_x or n_y × n_x × 3
//! values, x fastest); `/grid/x` and `/grid/y` hold the node coordinates [m]. `fields.xdmf` is a
//! temporal collection with one spatial collection per output time, holding the particles as a
//! `Polyvertex` point set and the grid as a `3DCoRectMesh` of one layer of nodes (z = 0) with
//! `ORIGIN_DXDYDZ` geometry: ParaView 5.11's XDMF reader reads scalars on a `2DCoRectMesh` but
//! fails on its vector attributes ("selection + offset not within extent"). The HDF5
//! file is opened, extended and closed for every output time. The XDMF file is replaced whole
//! (temporary file, sync, rename) after the first output time, then at most every
//! [`INDEX_INTERVAL`] of wall time, and at the end ([`FieldFiles::finish`], also on drop): it only
//! ever lists complete output times, and rewriting it for every output time would cost time
//! quadratic in their number (measured: 601 output times of Terzaghi took 7.7 s that way).

use hdf5_metno as h5;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Values of one field.
#[derive(Debug, Clone)]
pub enum Values {
    /// Floating-point values.
    Real(Vec<f64>),
    /// Integer values (identifiers, flags).
    Int(Vec<i32>),
}

impl Values {
    fn is_int(&self) -> bool {
        matches!(self, Values::Int(_))
    }

    fn len(&self) -> usize {
        match self {
            Values::Real(v) => v.len(),
            Values::Int(v) => v.len(),
        }
    }
}

/// A named field: scalar (1 component) or vector (3 components, z = 0 in plane strain).
#[derive(Debug, Clone)]
pub struct Field {
    /// Name in ParaView.
    pub name: &'static str,
    /// 1 or 3.
    pub components: usize,
    /// Point-major values.
    pub values: Values,
}

/// The structured background grid.
#[derive(Debug, Clone, Copy)]
pub struct GridGeometry {
    /// Lower-left node [m].
    pub origin: [f64; 2],
    /// Node spacing [m].
    pub spacing: [f64; 2],
    /// Nodes in x and y.
    pub nodes: [usize; 2],
}

/// The fields of one output time.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Simulated time [s].
    pub time: f64,
    /// Number of particles.
    pub particles: usize,
    /// Particle fields (the first must be `position`, 3 components).
    pub particle_fields: Vec<Field>,
    /// Nodal fields on the grid.
    pub grid_fields: Vec<Field>,
}

/// Shortest wall time between two rewrites of the XDMF file during a run.
pub const INDEX_INTERVAL: Duration = Duration::from_secs(2);

/// The field files of a run.
pub struct FieldFiles {
    h5: PathBuf,
    xdmf: PathBuf,
    grid: GridGeometry,
    /// Output times written to the HDF5 file.
    frames: usize,
    /// Their XDMF grids.
    body: String,
    /// When the XDMF file was last written, and whether it lacks output times.
    last_index: Option<Instant>,
    dirty: bool,
}

fn write_field(g: &h5::Group, f: &Field, shape: &[usize]) -> h5::Result<()> {
    let mut shape = shape.to_vec();
    if f.components > 1 {
        shape.push(f.components);
    }
    match &f.values {
        Values::Real(v) => g.new_dataset::<f64>().shape(shape).create(f.name)?.write_raw(&v[..]),
        Values::Int(v) => g.new_dataset::<i32>().shape(shape).create(f.name)?.write_raw(&v[..]),
    }
}

impl FieldFiles {
    /// Starts `fields.h5` (replacing an old one) in `dir`, with the grid's node coordinates.
    pub fn create(dir: &Path, grid: GridGeometry) -> Result<FieldFiles, String> {
        let h5 = dir.join("fields.h5");
        let xdmf = dir.join("fields.xdmf");
        for p in [&h5, &xdmf] {
            if p.exists() {
                fs::remove_file(p).map_err(|e| format!("cannot remove old {}: {e}", p.display()))?;
            }
        }
        let fail = |e: h5::Error| format!("cannot write {}: {e}", h5.display());
        let f = h5::File::create(&h5).map_err(fail)?;
        let g = f.create_group("grid").map_err(fail)?;
        let coords = |d: usize| -> Vec<f64> {
            (0..grid.nodes[d]).map(|i| grid.origin[d] + i as f64 * grid.spacing[d]).collect()
        };
        for (d, name) in ["x", "y"].iter().enumerate() {
            g.new_dataset::<f64>()
                .shape(grid.nodes[d])
                .create(*name)
                .and_then(|ds| ds.write_raw(&coords(d)[..]))
                .map_err(fail)?;
        }
        f.create_group("particles").map_err(fail)?;
        Ok(FieldFiles { h5, xdmf, grid, frames: 0, body: String::new(), last_index: None, dirty: false })
    }

    /// Appends one output time and rewrites the XDMF file.
    pub fn write(&mut self, frame: &Frame) -> Result<(), String> {
        let i = self.frames;
        let fail = |e: h5::Error| format!("cannot write {}: {e}", self.h5.display());
        let [nx, ny] = self.grid.nodes;
        if frame.particle_fields.first().map(|f| (f.name, f.components)) != Some(("position", 3)) {
            return Err("the first particle field must be `position` with 3 components".into());
        }
        for f in &frame.particle_fields {
            if f.values.len() != frame.particles * f.components {
                return Err(format!("particle field `{}` has {} values", f.name, f.values.len()));
            }
        }
        for f in &frame.grid_fields {
            if f.values.len() != nx * ny * f.components {
                return Err(format!("grid field `{}` has {} values", f.name, f.values.len()));
            }
        }
        {
            let file = h5::File::append(&self.h5).map_err(fail)?;
            let pg = file.group("particles").and_then(|g| g.create_group(&i.to_string())).map_err(fail)?;
            for f in &frame.particle_fields {
                write_field(&pg, f, &[frame.particles]).map_err(fail)?;
            }
            let gg = file.group("grid").and_then(|g| g.create_group(&i.to_string())).map_err(fail)?;
            for f in &frame.grid_fields {
                write_field(&gg, f, &[ny, nx]).map_err(fail)?;
            }
            file.flush().map_err(fail)?;
        }
        let text = self.frame_xml(i, frame);
        self.body.push_str(&text);
        self.frames += 1;
        self.dirty = true;
        if self.last_index.is_none_or(|t| t.elapsed() >= INDEX_INTERVAL) {
            self.finish()?;
        }
        Ok(())
    }

    /// Writes the XDMF file with every output time so far (if it lacks any).
    pub fn finish(&mut self) -> Result<(), String> {
        if !self.dirty {
            return Ok(());
        }
        let head = "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n  <Domain>\n    <Grid Name=\"porompm\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
        let tail = "    </Grid>\n  </Domain>\n</Xdmf>\n";
        super::write_atomic(&self.xdmf, format!("{head}{}{tail}", self.body).as_bytes())?;
        self.last_index = Some(Instant::now());
        self.dirty = false;
        Ok(())
    }

    /// The XDMF grids of output time `i`.
    fn frame_xml(&self, i: usize, frame: &Frame) -> String {
        let h5name = self.h5.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let [nx, ny] = self.grid.nodes;
        let item = |dims: &str, int: bool, path: String| {
            let (ty, prec) = if int { ("Int", 4) } else { ("Float", 8) };
            format!(
                "<DataItem Dimensions=\"{dims}\" NumberType=\"{ty}\" Precision=\"{prec}\" Format=\"HDF\">{h5name}:{path}</DataItem>"
            )
        };
        let attribute = |name: &str, comps: usize, int: bool, base: &str, dims: String| {
            let (kind, dims) = if comps == 1 { ("Scalar", dims) } else { ("Vector", format!("{dims} {comps}")) };
            format!(
                "        <Attribute Name=\"{name}\" AttributeType=\"{kind}\" Center=\"Node\">\n          {}\n        </Attribute>\n",
                item(&dims, int, format!("{base}/{name}"))
            )
        };
        let mut s = String::new();
        {
            let n = frame.particles;
            let _ = writeln!(s, "    <Grid Name=\"output_{i}\" GridType=\"Collection\" CollectionType=\"Spatial\">");
            let _ = writeln!(s, "      <Time Value=\"{:.17e}\"/>", frame.time);
            let _ = writeln!(s, "      <Grid Name=\"particles\" GridType=\"Uniform\">");
            let _ = writeln!(
                s,
                "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{n}\" NodesPerElement=\"1\"/>"
            );
            let base = format!("/particles/{i}");
            let _ = writeln!(
                s,
                "        <Geometry GeometryType=\"XYZ\">\n          {}\n        </Geometry>",
                item(&format!("{n} 3"), false, format!("{base}/position"))
            );
            for f in frame.particle_fields.iter().filter(|f| f.name != "position") {
                s.push_str(&attribute(f.name, f.components, f.values.is_int(), &base, n.to_string()));
            }
            s.push_str("      </Grid>\n");
            let _ = writeln!(s, "      <Grid Name=\"grid\" GridType=\"Uniform\">");
            let _ = writeln!(s, "        <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"1 {ny} {nx}\"/>");
            let g = &self.grid;
            // Order z, y, x; the single layer's spacing in z is arbitrary.
            let _ = writeln!(
                s,
                "        <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">0 {:.17e} {:.17e}</DataItem>\n          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">1 {:.17e} {:.17e}</DataItem>\n        </Geometry>",
                g.origin[1], g.origin[0], g.spacing[1], g.spacing[0]
            );
            let base = format!("/grid/{i}");
            for f in &frame.grid_fields {
                s.push_str(&attribute(f.name, f.components, f.values.is_int(), &base, format!("1 {ny} {nx}")));
            }
            s.push_str("      </Grid>\n    </Grid>\n");
        }
        s
    }
}

impl Drop for FieldFiles {
    /// Lists the last output times even if the run ends by an error.
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_appended_and_listed_in_the_xdmf_file() {
        let dir = std::env::temp_dir().join(format!("porompm-fields-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let grid = GridGeometry { origin: [0.0, -1.0], spacing: [0.5, 0.25], nodes: [3, 5] };
        let mut files = FieldFiles::create(&dir, grid).unwrap();
        for t in [0.0, 0.5] {
            let frame = Frame {
                time: t,
                particles: 2,
                particle_fields: vec![
                    Field { name: "position", components: 3, values: Values::Real(vec![0.1, 0.2, 0.0, 0.3, 0.4, 0.0]) },
                    Field { name: "p", components: 1, values: Values::Real(vec![t, 2.0 * t]) },
                    Field { name: "material_id", components: 1, values: Values::Int(vec![0, 1]) },
                ],
                grid_fields: vec![Field { name: "active", components: 1, values: Values::Int(vec![1; 15]) }],
            };
            files.write(&frame).unwrap();
        }
        files.finish().unwrap();
        let text = fs::read_to_string(dir.join("fields.xdmf")).unwrap();
        assert_eq!(text.matches("CollectionType=\"Spatial\"").count(), 2);
        assert!(text.contains("fields.h5:/particles/1/p<"));
        assert!(text.contains("Dimensions=\"1 5 3\""), "grid fields are n_y × n_x");
        assert!(text.contains(">0 -1.00000000000000000e0 0.00000000000000000e0<"), "origin is (z, y, x)");
        let f = h5::File::open(dir.join("fields.h5")).unwrap();
        assert_eq!(f.dataset("particles/1/p").unwrap().read_raw::<f64>().unwrap(), vec![0.5, 1.0]);
        assert_eq!(f.dataset("grid/y").unwrap().read_raw::<f64>().unwrap(), vec![-1.0, -0.75, -0.5, -0.25, 0.0]);
        // A wrong length is an error, not a broken file.
        let bad = Frame { time: 1.0, particles: 3, particle_fields: vec![], grid_fields: vec![] };
        assert!(files.write(&bad).unwrap_err().contains("`position`"));
        let bad = Frame {
            time: 1.0,
            particles: 3,
            particle_fields: vec![
                Field { name: "position", components: 3, values: Values::Real(vec![0.0; 9]) },
                Field { name: "p", components: 1, values: Values::Real(vec![1.0]) },
            ],
            grid_fields: vec![],
        };
        assert!(files.write(&bad).unwrap_err().contains("`p` has 1 values"));
        files.finish().unwrap();
        assert_eq!(fs::read_to_string(dir.join("fields.xdmf")).unwrap(), text, "the XDMF file lists complete frames");
        fs::remove_dir_all(&dir).unwrap();
    }
}
