//! Geometry files a body is made from: Gmsh meshes (MSH 4.1, ASCII or binary, by the `mshio`
//! crate) and STL surfaces (ASCII or binary, by the `stl_io` crate), read into
//! [`crate::geometry`]'s types.

use crate::geometry::{CellKind, FileCell, MeshFile, PointFields, PointRows, Triangles};
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

/// The rows of a particle file: a CSV table whose header names its columns, `x`, `y` (and `z` in
/// three dimensions, `dim = 3`) [m] and `volume` [m³], and optionally the initial velocity `vx`,
/// `vy` (`vz`) [m/s], effective stress `sxx`, `syy`, `sxy`, `szz` (and `syz`, `szx`) [Pa] and pore
/// pressure `p` [Pa], in any order among others, which are skipped; lines starting with `#` and
/// empty lines are skipped. An error names the line, or the column a field lacks.
pub fn read_points(path: &Path, dim: usize) -> Result<PointRows, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| format!("{}: no header line", path.display()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |w: &str| names.iter().position(|n| *n == w);
    let group = |wanted: &[&str], optional: &[&str]| -> Result<Option<Vec<Option<usize>>>, String> {
        let found: Vec<Option<usize>> = wanted.iter().map(|w| find(w)).collect();
        if found.iter().all(Option::is_none) {
            return Ok(None);
        }
        if let Some(k) = found.iter().position(Option::is_none) {
            return Err(format!(
                "{}: its header has no column `{}` (it needs {})",
                path.display(),
                wanted[k],
                wanted.join(", ")
            ));
        }
        Ok(Some(found.into_iter().chain(optional.iter().map(|w| find(w))).collect()))
    };
    let position: &[&str] = if dim == 3 { &["x", "y", "z", "volume"] } else { &["x", "y", "volume"] };
    let place = group(position, &[])?.ok_or_else(|| {
        format!("{}: its header has no column `x` (it needs {})", path.display(), position.join(", "))
    })?;
    let velocity = group(if dim == 3 { &["vx", "vy", "vz"] } else { &["vx", "vy"] }, &[])?;
    let stress = group(&["sxx", "syy", "sxy", "szz"], if dim == 3 { &["syz", "szx"] } else { &[] })?;
    let pressure = group(&["p"], &[])?;
    let mut rows = PointRows::default();
    let mut fields: [Vec<Vec<f64>>; 3] = Default::default();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let values = |columns: &[Option<usize>]| -> Result<Vec<f64>, String> {
            (columns.iter())
                .map(|c| match c {
                    None => Ok(0.0),
                    Some(c) => {
                        let text = cells.get(*c).copied().unwrap_or("");
                        text.parse().map_err(|_| {
                            format!(
                                "{} line {}: `{text}` in column `{}` is not a number",
                                path.display(),
                                i + 1,
                                names[*c]
                            )
                        })
                    }
                })
                .collect()
        };
        let v = values(&place)?;
        rows.x.push([v[0], v[1], if dim == 3 { v[2] } else { 0.0 }]);
        rows.volume.push(v[dim]);
        for (k, columns) in [&velocity, &stress, &pressure].into_iter().enumerate() {
            if let Some(columns) = columns {
                fields[k].push(values(columns)?);
            }
        }
    }
    let [v, s, p] = fields;
    rows.fields = PointFields {
        velocity: velocity
            .map(|_| v.iter().map(|r| std::array::from_fn(|d| r.get(d).copied().unwrap_or(0.0))).collect()),
        stress: stress.map(|_| s.iter().map(|r| std::array::from_fn(|c| r.get(c).copied().unwrap_or(0.0))).collect()),
        pore_pressure: pressure.map(|_| p.iter().map(|r| r[0]).collect()),
    };
    Ok(rows)
}
