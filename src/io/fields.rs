//! `fields.h5` + `fields.xdmf`: particle and grid fields over time, for ParaView.
//!
//! Every output time `i` adds the HDF5 groups `/particles/<i>` (one dataset per particle field,
//! n or n × 3 values) and `/grid/<i>` (one dataset per nodal field, n_y × n_x or n_y × n_x × 3
//! values in two dimensions, n_z × n_y × n_x (× 3) in three, x fastest); `/grid/x`, `/grid/y`
//! (and `/grid/z`) hold the node coordinates [m]. All ranks write the
//! HDF5 file together (HDF5's MPI-I/O driver): they create its groups and datasets together, and
//! each writes its own rows: its slab of the particles sorted by id and the block of grid nodes it
//! owns (see [`Frame`]). No rank holds the fields of all particles, and the file written on any
//! number of ranks is the one written on one. `fields.xdmf` is a
//! temporal collection with one spatial collection per output time, holding the particles as a
//! `Polyvertex` point set and the grid as a `3DCoRectMesh` (of one layer of nodes, z = 0, in two
//! dimensions) with `ORIGIN_DXDYDZ` geometry: ParaView 5.11's XDMF reader reads scalars on a `2DCoRectMesh` but
//! fails on its vector attributes ("selection + offset not within extent"). The HDF5
//! file is opened, extended and closed for every output time. The XDMF file is replaced whole
//! (temporary file, sync, rename) after the first output time, then at most every
//! [`INDEX_INTERVAL`] of wall time, and at the end ([`FieldFiles::finish`], also on drop): it only
//! ever lists complete output times, and rewriting it for every output time would cost time
//! quadratic in their number (measured: 601 output times of Terzaghi took 7.7 s that way).

use hdf5_metno as h5;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, CommunicatorCollectives};
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

/// The structured background grid, in three dimensions or (one layer of nodes) in two.
#[derive(Debug, Clone, Copy)]
pub struct GridGeometry {
    /// Lower-left (-back) node [m].
    pub origin: [f64; 3],
    /// Node spacing [m].
    pub spacing: [f64; 3],
    /// Nodes in x, y and z (1 in two dimensions).
    pub nodes: [usize; 3],
}

impl GridGeometry {
    /// The geometry of a grid of dimension `D` (2 or 3) with its lower-left node at `origin`,
    /// spacing `spacing` and `nodes` nodes per direction.
    pub fn of<const D: usize>(origin: [f64; D], spacing: [f64; D], nodes: [usize; D]) -> GridGeometry {
        let pick = |a: &[f64], plane: f64| std::array::from_fn(|d| a.get(d).copied().unwrap_or(plane));
        GridGeometry {
            origin: pick(&origin, 0.0),
            spacing: pick(&spacing, 1.0),
            nodes: std::array::from_fn(|d| nodes.get(d).copied().unwrap_or(1)),
        }
    }

    /// Whether the grid is three-dimensional.
    fn solid(&self) -> bool {
        self.nodes[2] > 1
    }

    /// The shape of a nodal dataset: n_y × n_x in two dimensions, n_z × n_y × n_x in three.
    fn shape(&self) -> Vec<usize> {
        let [nx, ny, nz] = self.nodes;
        if self.solid() {
            vec![nz, ny, nx]
        } else {
            vec![ny, nx]
        }
    }
}

/// One rank's share of the fields of one output time.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Simulated time [s].
    pub time: f64,
    /// Number of particles of all ranks.
    pub particles: usize,
    /// The place of this rank's first particle in the list of all particles sorted by id; its
    /// particle fields hold the next rows of that list.
    pub first_particle: usize,
    /// This rank's rows of the particle fields (the first must be `position`, 3 components).
    pub particle_fields: Vec<Field>,
    /// The block of grid nodes this rank writes: its first node (i, j, k) and its nodes along x,
    /// y and z (k = 0 and one node along z in two dimensions).
    pub node_block: ([usize; 3], [usize; 3]),
    /// This rank's nodal fields on its block of nodes, x fastest.
    pub grid_fields: Vec<Field>,
}

impl Frame {
    /// This rank's number of particle rows.
    fn rows(&self) -> usize {
        self.particle_fields.first().map_or(0, |f| f.values.len() / f.components.max(1))
    }
}

/// Shortest wall time between two rewrites of the XDMF file during a run.
pub const INDEX_INTERVAL: Duration = Duration::from_secs(2);

/// The field files of a run (every rank holds one; only the writing rank writes the XDMF index).
pub struct FieldFiles {
    h5: PathBuf,
    xdmf: PathBuf,
    grid: GridGeometry,
    /// The ranks writing the HDF5 file (MPI_COMM_WORLD's handle; MPI outlives the run).
    comm: mpi::ffi::MPI_Comm,
    /// Whether this rank writes the XDMF index.
    writer: bool,
    /// Output times written to the HDF5 file.
    frames: usize,
    /// Their XDMF grids.
    body: String,
    /// When the XDMF file was last written, and whether it lacks output times.
    last_index: Option<Instant>,
    dirty: bool,
}

/// Creates the dataset `f.name` of `shape` (times the field's components) in `g` (collective) and
/// writes this rank's values at `start` along the leading dimensions, `count` long.
fn write_field(g: &h5::Group, f: &Field, shape: &[usize], start: &[usize], count: &[usize]) -> h5::Result<()> {
    let mut full = shape.to_vec();
    let mut local = count.to_vec();
    if f.components > 1 {
        full.push(f.components);
        local.push(f.components);
    }
    let empty = local.contains(&0);
    match &f.values {
        Values::Real(v) => {
            let ds = g.new_dataset::<f64>().shape(full).create(f.name)?;
            if !empty {
                write_block(&ds, v, start, &local)?;
            }
        }
        Values::Int(v) => {
            let ds = g.new_dataset::<i32>().shape(full).create(f.name)?;
            if !empty {
                write_block(&ds, v, start, &local)?;
            }
        }
    }
    Ok(())
}

/// Writes `v` (row-major, `local` long in each dimension) into `ds` at `start` along its first
/// one, two or three dimensions.
pub(super) fn write_block<T: h5::H5Type>(
    ds: &h5::Dataset,
    v: &[T],
    start: &[usize],
    local: &[usize],
) -> h5::Result<()> {
    let view =
        ndarray::ArrayView::from_shape(local.to_vec(), v).map_err(|e| h5::Error::from(e.to_string().as_str()))?;
    match (start, local.len()) {
        ([a], 1) => ds.write_slice(view, (*a..*a + local[0],)),
        ([a], 2) => ds.write_slice(view, (*a..*a + local[0], ..)),
        ([a, b], 2) => ds.write_slice(view, (*a..*a + local[0], *b..*b + local[1])),
        ([a, b], 3) => ds.write_slice(view, (*a..*a + local[0], *b..*b + local[1], ..)),
        ([a, b, c], 3) => ds.write_slice(view, (*a..*a + local[0], *b..*b + local[1], *c..*c + local[2])),
        ([a, b, c], 4) => ds.write_slice(view, (*a..*a + local[0], *b..*b + local[1], *c..*c + local[2], ..)),
        _ => Err(h5::Error::from("unexpected field shape")),
    }
}

impl FieldFiles {
    /// Starts `fields.h5` (replacing an old one) in `dir`, with the grid's node coordinates.
    /// Collective over `comm`; `writer` is the rank that writes the XDMF index (and removes old
    /// files first).
    pub fn create(
        dir: &Path,
        grid: GridGeometry,
        comm: &SimpleCommunicator,
        writer: bool,
    ) -> Result<FieldFiles, String> {
        let h5 = dir.join("fields.h5");
        let xdmf = dir.join("fields.xdmf");
        let removed = if writer {
            [&h5, &xdmf]
                .into_iter()
                .filter(|p| p.exists())
                .try_for_each(|p| fs::remove_file(p).map_err(|e| format!("cannot remove old {}: {e}", p.display())))
        } else {
            Ok(())
        };
        // The other ranks open the file only once the writing rank has made the directory and
        // removed the old files.
        comm.barrier();
        removed?;
        let files = FieldFiles {
            h5,
            xdmf,
            grid,
            comm: comm.as_raw(),
            writer,
            frames: 0,
            body: String::new(),
            last_index: None,
            dirty: false,
        };
        let fail = |e: h5::Error| format!("cannot write {}: {e}", files.h5.display());
        {
            // Every handle closes before the file does (at the end of this block).
            let f = files.open(true).map_err(fail)?;
            let coords = |d: usize| -> Vec<f64> {
                (0..grid.nodes[d]).map(|i| grid.origin[d] + i as f64 * grid.spacing[d]).collect()
            };
            {
                let g = f.create_group("grid").map_err(fail)?;
                let names: &[&str] = if grid.solid() { &["x", "y", "z"] } else { &["x", "y"] };
                for (d, name) in names.iter().enumerate() {
                    let ds = g.new_dataset::<f64>().shape(grid.nodes[d]).create(*name).map_err(fail)?;
                    if writer {
                        ds.write_raw(&coords(d)[..]).map_err(fail)?;
                    }
                }
                f.create_group("particles").map_err(fail)?;
            }
            f.flush().map_err(fail)?;
        }
        Ok(files)
    }

    /// Opens the HDF5 file on all ranks (MPI-I/O), new or to append to.
    fn open(&self, create: bool) -> h5::Result<h5::File> {
        let comm = self.comm;
        let mut b = h5::File::with_options();
        b.with_fapl(|p| p.mpio(comm, None));
        if create {
            b.create(&self.h5)
        } else {
            b.append(&self.h5)
        }
    }

    /// The size of `frame` in the HDF5 file [B], about: its numbers over all ranks and the
    /// metadata of its datasets.
    fn size_of(&self, frame: &Frame) -> u64 {
        let nodes: usize = self.grid.nodes.iter().product();
        let per_point: usize = frame.particle_fields.iter().map(|f| f.components).sum();
        let per_node: usize = frame.grid_fields.iter().map(|f| f.components).sum();
        let datasets = frame.particle_fields.len() + frame.grid_fields.len();
        8 * (frame.particles * per_point + nodes * per_node) as u64 + 2048 * datasets as u64
    }

    /// Appends one output time (collective over `comm`, the ranks the files were created on) and,
    /// on the writing rank, rewrites the XDMF file. A disk without room for the output time is
    /// refused on every rank before HDF5 writes anything.
    pub fn write(&mut self, frame: &Frame, comm: &SimpleCommunicator) -> Result<(), String> {
        let room = if self.writer { super::check_room(&self.h5, self.size_of(frame)) } else { Ok(()) };
        super::agree(comm, room, "another rank could not write the fields")?;
        let i = self.frames;
        let fail = |e: h5::Error| format!("cannot write {}: {e}", self.h5.display());
        let [nx, ny, nz] = self.grid.nodes;
        if frame.particle_fields.first().map(|f| (f.name, f.components)) != Some(("position", 3)) {
            return Err("the first particle field must be `position` with 3 components".into());
        }
        let rows = frame.rows();
        for f in &frame.particle_fields {
            if f.values.len() != rows * f.components {
                return Err(format!("particle field `{}` has {} values", f.name, f.values.len()));
            }
        }
        let ([i0, j0, k0], [ni, nj, nk]) = frame.node_block;
        if i0 + ni > nx || j0 + nj > ny || k0 + nk > nz || frame.first_particle + rows > frame.particles {
            return Err("this rank's block of the fields lies outside the grid or the particle list".into());
        }
        for f in &frame.grid_fields {
            if f.values.len() != ni * nj * nk * f.components {
                return Err(format!("grid field `{}` has {} values", f.name, f.values.len()));
            }
        }
        {
            let file = self.open(false).map_err(fail)?;
            let pg = file.group("particles").and_then(|g| g.create_group(&i.to_string())).map_err(fail)?;
            for f in &frame.particle_fields {
                write_field(&pg, f, &[frame.particles], &[frame.first_particle], &[rows]).map_err(fail)?;
            }
            let gg = file.group("grid").and_then(|g| g.create_group(&i.to_string())).map_err(fail)?;
            let (start, count) =
                if self.grid.solid() { (vec![k0, j0, i0], vec![nk, nj, ni]) } else { (vec![j0, i0], vec![nj, ni]) };
            for f in &frame.grid_fields {
                write_field(&gg, f, &self.grid.shape(), &start, &count).map_err(fail)?;
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
        if !self.dirty || !self.writer {
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
        let [nx, ny, nz] = self.grid.nodes;
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
            let _ = writeln!(s, "        <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{nz} {ny} {nx}\"/>");
            let g = &self.grid;
            // Order z, y, x; in two dimensions the single layer's origin is 0 and its spacing in z
            // (arbitrary) 1.
            let (oz, dz) = if g.solid() {
                (format!("{:.17e}", g.origin[2]), format!("{:.17e}", g.spacing[2]))
            } else {
                ("0".to_string(), "1".to_string())
            };
            let _ = writeln!(
                s,
                "        <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">{oz} {:.17e} {:.17e}</DataItem>\n          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">{dz} {:.17e} {:.17e}</DataItem>\n        </Geometry>",
                g.origin[1], g.origin[0], g.spacing[1], g.spacing[0]
            );
            let base = format!("/grid/{i}");
            for f in &frame.grid_fields {
                s.push_str(&attribute(f.name, f.components, f.values.is_int(), &base, format!("{nz} {ny} {nx}")));
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
        let (_lock, world) = crate::io::test_world();
        let dir = std::env::temp_dir().join(format!("porompm-fields-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let grid = GridGeometry::of([0.0, -1.0], [0.5, 0.25], [3, 5]);
        let mut files = FieldFiles::create(&dir, grid, &world, true).unwrap();
        for t in [0.0, 0.5] {
            let frame = Frame {
                time: t,
                particles: 2,
                first_particle: 0,
                particle_fields: vec![
                    Field { name: "position", components: 3, values: Values::Real(vec![0.1, 0.2, 0.0, 0.3, 0.4, 0.0]) },
                    Field { name: "p", components: 1, values: Values::Real(vec![t, 2.0 * t]) },
                    Field { name: "material_id", components: 1, values: Values::Int(vec![0, 1]) },
                ],
                node_block: ([0, 0, 0], [3, 5, 1]),
                grid_fields: vec![Field { name: "active", components: 1, values: Values::Int(vec![1; 15]) }],
            };
            files.write(&frame, &world).unwrap();
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
        let bad = Frame {
            time: 1.0,
            particles: 3,
            first_particle: 0,
            particle_fields: vec![],
            node_block: ([0, 0, 0], [3, 5, 1]),
            grid_fields: vec![],
        };
        assert!(files.write(&bad, &world).unwrap_err().contains("`position`"));
        let bad = Frame {
            time: 1.0,
            particles: 3,
            first_particle: 0,
            particle_fields: vec![
                Field { name: "position", components: 3, values: Values::Real(vec![0.0; 9]) },
                Field { name: "p", components: 1, values: Values::Real(vec![1.0]) },
            ],
            node_block: ([0, 0, 0], [3, 5, 1]),
            grid_fields: vec![],
        };
        assert!(files.write(&bad, &world).unwrap_err().contains("`p` has 1 values"));
        let bad = Frame { first_particle: 2, particle_fields: bad.particle_fields[..1].to_vec(), ..bad.clone() };
        assert!(files.write(&bad, &world).unwrap_err().contains("outside"), "rows 2..5 of 3 particles");
        files.finish().unwrap();
        assert_eq!(fs::read_to_string(dir.join("fields.xdmf")).unwrap(), text, "the XDMF file lists complete frames");
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A three-dimensional grid: nodal datasets n_z × n_y × n_x, the node coordinates along z, and
    /// the XDMF mesh with its z extent and origin; a rank's block placed at its (i, j, k).
    #[test]
    fn a_three_dimensional_grid_is_written_as_such() {
        let (_lock, world) = crate::io::test_world();
        let dir = std::env::temp_dir().join(format!("porompm-fields-3d-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let grid = GridGeometry::of([0.0, -1.0, 2.0], [0.5, 0.25, 0.1], [3, 5, 2]);
        let mut files = FieldFiles::create(&dir, grid, &world, true).unwrap();
        let frame = Frame {
            time: 0.0,
            particles: 1,
            first_particle: 0,
            particle_fields: vec![Field {
                name: "position",
                components: 3,
                values: Values::Real(vec![0.1, 0.2, 2.05]),
            }],
            node_block: ([1, 0, 1], [2, 5, 1]),
            grid_fields: vec![
                Field { name: "active", components: 1, values: Values::Int((0..10).collect()) },
                Field { name: "du", components: 3, values: Values::Real((0..30).map(f64::from).collect()) },
            ],
        };
        files.write(&frame, &world).unwrap();
        files.finish().unwrap();
        let text = fs::read_to_string(dir.join("fields.xdmf")).unwrap();
        assert!(text.contains("TopologyType=\"3DCoRectMesh\" Dimensions=\"2 5 3\""), "{text}");
        assert!(text.contains(">2.00000000000000000e0 -1.00000000000000000e0 0.00000000000000000e0<"), "{text}");
        assert!(text.contains(">1.00000000000000006e-1 2.50000000000000000e-1 5.00000000000000000e-1<"), "{text}");
        assert!(text.contains("Dimensions=\"2 5 3 3\""), "vector fields are n_z × n_y × n_x × 3");
        let f = h5::File::open(dir.join("fields.h5")).unwrap();
        assert_eq!(f.dataset("grid/z").unwrap().read_raw::<f64>().unwrap(), vec![2.0, 2.1]);
        let active = f.dataset("grid/0/active").unwrap();
        assert_eq!(active.shape(), vec![2, 5, 3]);
        let a = active.read_raw::<i32>().unwrap();
        // The block of nodes i = 1, 2; all j; k = 1, x fastest.
        assert_eq!((a[15 + 1], a[15 + 2], a[15 + 3 + 1], a[15 + 14]), (0, 1, 2, 9));
        assert!(a[..15].iter().all(|&v| v == 0));
        let du = f.dataset("grid/0/du").unwrap();
        assert_eq!(du.shape(), vec![2, 5, 3, 3]);
        // A block outside the grid along z is refused.
        let bad = Frame { node_block: ([0, 0, 1], [3, 5, 2]), ..frame.clone() };
        assert!(files.write(&bad, &world).unwrap_err().contains("outside"));
        fs::remove_dir_all(&dir).unwrap();
    }
}
