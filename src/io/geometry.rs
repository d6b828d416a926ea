//! Geometry files a body is made from: Gmsh meshes (MSH 4.1, ASCII or binary, by the `mshio`
//! crate) and STL surfaces (ASCII or binary, by the `stl_io` crate), read into
//! [`crate::geometry`]'s types.

use crate::geometry::{CellKind, FileCell, MeshFile, PointFields, PointRows, Triangles};
use hdf5_metno as h5;
use mshio::mshfile::ElementType;
use std::collections::HashMap;
use std::path::Path;

/// Reads a Gmsh mesh: its nodes, its first-order cells of dimension 2 and 3 with the physical
/// groups of their entities, and the groups' names.
pub fn read_msh(path: &Path) -> Result<MeshFile, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]).into_owned();
    let version = text.strip_prefix("$MeshFormat").and_then(|r| r.split_whitespace().next());
    match version {
        Some("4.1") => {}
        Some(v) => {
            return Err(format!(
                "{} is a Gmsh mesh of format {v}; porompm reads format 4.1 (save it with `gmsh -format msh41`, or \
                 Mesh.MshFileVersion = 4.1)",
                path.display()
            ))
        }
        None => return Err(format!("{} is not a Gmsh mesh: it does not start with $MeshFormat", path.display())),
    }
    let msh = mshio::parse_msh_bytes(&bytes).map_err(|e| {
        // mshio's chain of contexts, without the hex dump of the bytes it stopped at.
        let text = e.to_string();
        let why: Vec<&str> = (text.lines().map(str::trim))
            .take_while(|l| !l.starts_with("Hex dump"))
            .filter(|l| !l.is_empty() && *l != "During parsing...")
            .map(|l| l.trim_end_matches(','))
            .collect();
        format!("{} is not a readable Gmsh MSH 4.1 file: {}", path.display(), why.join("; "))
    })?;
    let data = msh.data;
    let mut out = MeshFile { names: physical_names(&bytes), ..MeshFile::default() };
    let mut index: HashMap<u64, usize> = HashMap::new();
    if let Some(nodes) = &data.nodes {
        let dense = nodes.max_node_tag - nodes.min_node_tag + 1 == nodes.num_nodes;
        for block in &nodes.node_blocks {
            let tags: Vec<u64> = match &block.node_tags {
                Some(map) => {
                    let mut t = vec![0; block.nodes.len()];
                    for (&tag, &k) in map {
                        t[k] = tag;
                    }
                    t
                }
                None if dense => {
                    (0..block.nodes.len()).map(|k| nodes.min_node_tag + (out.nodes.len() + k) as u64).collect()
                }
                None => return Err(format!("{}: a node block without its node tags", path.display())),
            };
            for (n, tag) in block.nodes.iter().zip(tags) {
                index.insert(tag, out.nodes.len());
                out.nodes.push([n.x, n.y, n.z]);
            }
        }
    }
    let mut groups: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(e) = &data.entities {
        groups.extend(e.curves.iter().map(|c| ((1, c.tag), c.physical_tags.clone())));
        groups.extend(e.surfaces.iter().map(|s| ((2, s.tag), s.physical_tags.clone())));
        groups.extend(e.volumes.iter().map(|v| ((3, v.tag), v.physical_tags.clone())));
    }
    let mut other: HashMap<(usize, String), usize> = HashMap::new();
    for block in data.elements.iter().flat_map(|e| &e.element_blocks) {
        let dim = block.entity_dim as usize;
        if dim < 1 {
            continue;
        }
        let kind = match block.element_type {
            ElementType::Lin2 => CellKind::Line,
            ElementType::Tri3 => CellKind::Triangle,
            ElementType::Qua4 => CellKind::Quadrangle,
            ElementType::Tet4 => CellKind::Tetrahedron,
            ElementType::Hex8 => CellKind::Hexahedron,
            ElementType::Pri6 => CellKind::Prism,
            t => {
                *other.entry((dim, format!("{t:?}"))).or_default() += block.elements.len();
                continue;
            }
        };
        let entity_groups = groups.get(&(block.entity_dim, block.entity_tag)).cloned().unwrap_or_default();
        for el in &block.elements {
            let nodes = (el.nodes.iter().take(kind.nodes()))
                .map(|t| {
                    index.get(t).copied().ok_or_else(|| {
                        format!(
                            "{}: element {} names node {t}, which the file does not hold",
                            path.display(),
                            el.element_tag
                        )
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            out.cells.push(FileCell { kind, nodes, groups: entity_groups.clone() });
        }
    }
    out.other_cells = other.into_iter().map(|((d, k), n)| (d, k, n)).collect();
    out.other_cells.sort();
    Ok(out)
}

/// The `$PhysicalNames` section's (dimension, tag, name) (a section `mshio` skips; it is text in
/// binary files too).
fn physical_names(bytes: &[u8]) -> Vec<(usize, i32, String)> {
    let text = String::from_utf8_lossy(bytes);
    let Some(start) = text.find("$PhysicalNames") else {
        return Vec::new();
    };
    let section = &text[start..];
    let end = section.find("$EndPhysicalNames").unwrap_or(section.len());
    section[..end]
        .lines()
        .skip(2)
        .filter_map(|line| {
            let mut parts = line.splitn(3, char::is_whitespace);
            let dim = parts.next()?.parse().ok()?;
            let tag = parts.next()?.parse().ok()?;
            Some((dim, tag, parts.next()?.trim().trim_matches('"').to_string()))
        })
        .collect()
}

/// Reads an STL surface: its vertices [file units] and its triangles (indices into them).
pub fn read_stl(path: &Path) -> Result<Triangles, String> {
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mesh = stl_io::read_stl(&mut file).map_err(|e| format!("{} is not an STL file: {e}", path.display()))?;
    let vertices = mesh.vertices.iter().map(|v| v.0.map(f64::from)).collect();
    let triangles = mesh.faces.iter().map(|f| f.vertices).collect();
    Ok(Triangles { vertices, triangles })
}

/// The rows of a particle file: a CSV table whose header names its columns, or an HDF5 file
/// (told by its signature) whose root group holds one-dimensional datasets of numbers named as the
/// CSV's columns, all of one length. The columns: `x`, `y` (and `z` in three dimensions, `dim = 3`)
/// [m] and `volume` [m³], and optionally the initial velocity `vx`, `vy` (`vz`) [m/s], effective
/// stress `sxx`, `syy`, `sxy`, `szz` (and `syz`, `szx`) [Pa] and pore pressure `p` [Pa], in any
/// order among others, which are skipped; in a CSV file lines starting with `#` and empty lines
/// are skipped. An error names the line, or the column a field lacks.
pub fn read_points(path: &Path, dim: usize) -> Result<PointRows, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if bytes.starts_with(b"\x89HDF\r\n\x1a\n") {
        let file = h5::File::open(path).map_err(|e| format!("cannot read {} as HDF5: {e}", path.display()))?;
        rows_of(path, dim, "dataset", |name| hdf5_column(&file, name).map_err(|e| format!("{}: {e}", path.display())))
    } else {
        let text = String::from_utf8(bytes)
            .map_err(|_| format!("{}: neither a CSV (UTF-8) nor an HDF5 file", path.display()))?;
        let table = CsvTable::new(&text).ok_or_else(|| format!("{}: no header line", path.display()))?;
        rows_of(path, dim, "column", |name| table.column(name).map_err(|e| format!("{} {e}", path.display())))
    }
}

/// The particle file's rows from its columns, which `column` gives by name (`None` where the file
/// has none of that name); `kind` is what the file calls a column.
fn rows_of(
    path: &Path,
    dim: usize,
    kind: &str,
    column: impl Fn(&str) -> Result<Option<Vec<f64>>, String>,
) -> Result<PointRows, String> {
    // The columns of a group: all of `wanted` or none; `optional` ones are zero where missing.
    let group = |wanted: &[&str], optional: &[&str]| -> Result<Option<Vec<Vec<f64>>>, String> {
        let found = wanted.iter().map(|w| column(w)).collect::<Result<Vec<_>, _>>()?;
        if found.iter().all(Option::is_none) {
            return Ok(None);
        }
        if let Some(k) = found.iter().position(Option::is_none) {
            let (head, what) = if kind == "column" { ("its header", "column") } else { ("it", "dataset") };
            return Err(format!(
                "{}: {head} has no {what} `{}` (it needs {})",
                path.display(),
                wanted[k],
                wanted.join(", ")
            ));
        }
        let mut out: Vec<Vec<f64>> = found.into_iter().flatten().collect();
        for w in optional {
            let n = out[0].len();
            out.push(column(w)?.unwrap_or_else(|| vec![0.0; n]));
        }
        Ok(Some(out))
    };
    let position: &[&str] = if dim == 3 { &["x", "y", "z", "volume"] } else { &["x", "y", "volume"] };
    let place = group(position, &[])?.ok_or_else(|| {
        let head = if kind == "column" { "its header has no column" } else { "it has no dataset" };
        format!("{}: {head} `x` (it needs {})", path.display(), position.join(", "))
    })?;
    let velocity = group(if dim == 3 { &["vx", "vy", "vz"] } else { &["vx", "vy"] }, &[])?;
    let stress = group(&["sxx", "syy", "sxy", "szz"], if dim == 3 { &["syz", "szx"] } else { &[] })?;
    let pressure = group(&["p"], &[])?;
    let n = place[0].len();
    let all = [&place].into_iter().chain([&velocity, &stress, &pressure].into_iter().flatten());
    if let Some(c) = all.flatten().find(|c| c.len() != n) {
        return Err(format!(
            "{}: its {kind}s are of {n} and {} values; give each point a value in each",
            path.display(),
            c.len()
        ));
    }
    let row = |cols: &Vec<Vec<f64>>, k: usize| -> Vec<f64> { cols.iter().map(|c| c[k]).collect() };
    let mut rows = PointRows {
        x: (0..n).map(|k| [place[0][k], place[1][k], if dim == 3 { place[2][k] } else { 0.0 }]).collect(),
        volume: place[dim].clone(),
        ..PointRows::default()
    };
    rows.fields = PointFields {
        velocity: velocity
            .map(|v| (0..n).map(|k| std::array::from_fn(|d| row(&v, k).get(d).copied().unwrap_or(0.0))).collect()),
        stress: stress
            .map(|s| (0..n).map(|k| std::array::from_fn(|c| row(&s, k).get(c).copied().unwrap_or(0.0))).collect()),
        pore_pressure: pressure.map(|p| p[0].clone()),
    };
    Ok(rows)
}

/// A CSV file's lines (without comments and empty lines, numbered from 1) under its header.
struct CsvTable<'a> {
    names: Vec<&'a str>,
    lines: Vec<(usize, Vec<&'a str>)>,
}

impl<'a> CsvTable<'a> {
    /// The table of `text`; `None` without a header line.
    fn new(text: &'a str) -> Option<CsvTable<'a>> {
        let mut lines = (text.lines().enumerate())
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
            .map(|(i, l)| (i + 1, l.split(',').map(str::trim).collect::<Vec<_>>()));
        let (_, names) = lines.next()?;
        Some(CsvTable { names, lines: lines.collect() })
    }

    /// The numbers of column `name` (`None` if the header has no such column); an error names
    /// the line of a cell that is not a number.
    fn column(&self, name: &str) -> Result<Option<Vec<f64>>, String> {
        let Some(c) = self.names.iter().position(|n| *n == name) else { return Ok(None) };
        (self.lines.iter())
            .map(|(i, cells)| {
                let text = cells.get(c).copied().unwrap_or("");
                text.parse().map_err(|_| format!("line {i}: `{text}` in column `{name}` is not a number"))
            })
            .collect::<Result<Vec<f64>, String>>()
            .map(Some)
    }
}

/// The numbers of the one-dimensional dataset `name` in the root group of `file` (`None` if it has
/// none of that name), converted to f64.
fn hdf5_column(file: &h5::File, name: &str) -> Result<Option<Vec<f64>>, String> {
    if !file.link_exists(name) {
        return Ok(None);
    }
    let ds = file.dataset(name).map_err(|e| format!("`{name}` is not a dataset: {e}"))?;
    if ds.ndim() != 1 {
        return Err(format!("its dataset `{name}` has {} dimensions; a column has one", ds.ndim()));
    }
    ds.read_raw::<f64>().map(Some).map_err(|e| format!("its dataset `{name}` is not of numbers: {e}"))
}
