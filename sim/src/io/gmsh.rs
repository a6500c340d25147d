//! Gmsh `.msh` import: MSH 4.1 (ASCII and binary, parsed by the `mshio` crate) and MSH 2.2
//! (ASCII and binary, parsed here; `mshio` reads 4.1 only).
//!
//! What becomes what:
//! - **3D elements** become [`ElementBlock`]s, one per hox element type, in the order the types
//!   first appear: each registered element type reads the Gmsh type of its file
//!   ([`crate::element::ReferenceElement::gmsh_type`]: 4, 11, 29 → P1, P2, P3; 5, 12 → Q1, Q2;
//!   6 → prism; 7 → pyramid). hox's elements use Gmsh's node order, so connectivity is copied
//!   as it is. Any other 3D type (20-node hexahedra, 18-node prisms, …) is an error naming it
//!   and listing the registered ones.
//! - **Lower-dimensional elements** (points, lines, triangles, quadrangles of any order) are kept
//!   only for the physical groups they belong to.
//! - **Physical groups** become named node sets (every node of every element of the group, the
//!   high-order nodes included), for clamps and prescribed motion; 3D groups also become named
//!   element sets `(block, element)`. A group without a name is called by its number.
//! - **Nodes** not used by any 3D element (geometry points, …) are dropped and the rest
//!   renumbered compactly, in the order of the `$Nodes` section.
//!
//! Every rest element's `det J` is checked at its quadrature points ([`crate::fem::geometry`]); an
//! inverted or flat element is an error naming the file and the element's Gmsh tag. Every error
//! names the file and, where it can, the line (MSH 2.2 ASCII) or the element's tag.

use crate::Vec3;
use crate::element::ElementType;
use crate::fem::geometry::{GeometryError, precompute_block};
use crate::mesh::{ElementBlock, Mesh, MeshError};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// A mesh read from a `.msh` file with its physical groups.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedMesh {
    /// The file it came from (for error messages).
    pub source: String,
    pub mesh: Mesh,
    /// Physical group name → sorted, de-duplicated node indices of `mesh`.
    pub node_sets: BTreeMap<String, Vec<u32>>,
    /// 3D physical group name → `(block, element)` pairs of `mesh`.
    pub element_sets: BTreeMap<String, Vec<(usize, usize)>>,
    /// `element_tags[block][element]`: the element's tag in the file.
    pub element_tags: Vec<Vec<u64>>,
    /// `node_tags[node]`: the node's tag in the file.
    pub node_tags: Vec<u64>,
}

impl ImportedMesh {
    /// The nodes of physical group `name`; an unknown name is an error listing the groups.
    pub fn node_set(&self, name: &str) -> Result<&[u32], GmshError> {
        self.node_sets.get(name).map(Vec::as_slice).ok_or_else(|| GmshError::UnknownGroup {
            file: self.source.clone(),
            name: name.to_string(),
            available: self.group_names(),
        })
    }

    /// The comma-separated physical group names, for messages ("none" when there are none).
    pub fn group_names(&self) -> String {
        if self.node_sets.is_empty() {
            "none".into()
        } else {
            self.node_sets.keys().map(|k| format!("\"{k}\"")).collect::<Vec<_>>().join(", ")
        }
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GmshError {
    #[error("cannot read {file}: {message}")]
    Io { file: String, message: String },
    #[error("{file}: not a Gmsh mesh file: {message}")]
    NotMsh { file: String, message: String },
    #[error(
        "{file}: MSH format version {version} is not supported (hox reads 4.1 and 2.2; in Gmsh: File → Export, or -format msh41)"
    )]
    Version { file: String, version: String },
    #[error("{file}{at}: {message}")]
    Parse { file: String, at: String, message: String },
    #[error(
        "{file}{at}: element {element_tag} is a {description} (Gmsh type {gmsh_type}), which hox does not simulate; supported volume elements (Gmsh type: hox element): {supported}"
    )]
    UnsupportedElement {
        file: String,
        at: String,
        element_tag: u64,
        gmsh_type: u32,
        description: String,
        /// The registered element types: "4: p1, linear tetrahedron (4 nodes); …".
        supported: String,
    },
    #[error("{file}{at}: element {element_tag} has unknown Gmsh element type {gmsh_type}")]
    UnknownElementType { file: String, at: String, element_tag: u64, gmsh_type: u32 },
    #[error("{file}{at}: element {element_tag} refers to node {node_tag}, which the $Nodes section does not define")]
    MissingNode { file: String, at: String, element_tag: u64, node_tag: u64 },
    #[error("{file}{at}: element {element_tag} ({description}) lists {found} nodes, expected {expected}")]
    NodeCount { file: String, at: String, element_tag: u64, description: String, found: usize, expected: usize },
    #[error("{file}: node {node_tag} is defined twice")]
    DuplicateNode { file: String, node_tag: u64 },
    #[error("{file}: the mesh is empty: {what}")]
    Empty { file: String, what: String },
    #[error(
        "{file}: a surface-only mesh ({count} elements of dimension at most {max_dim}, no volume elements); hox simulates solids: mesh the volume too (Gmsh: Mesh → 3D, or gmsh -3) and save again"
    )]
    SurfaceOnly { file: String, count: usize, max_dim: u8 },
    /// `detail`: `det J` and where, and the element's nodes.
    #[error("{file}: element {element_tag} ({element_type}) is {what}: {detail}")]
    BadElement { file: String, element_tag: u64, element_type: String, what: &'static str, detail: String },
    #[error("{file}: {message}")]
    Mesh { file: String, message: String },
    #[error("{file}: physical group \"{name}\" does not exist (the file's groups: {available})")]
    UnknownGroup { file: String, name: String, available: String },
}

/// Reads a `.msh` file (MSH 4.1 or 2.2, ASCII or binary).
pub fn read_msh(path: &Path) -> Result<ImportedMesh, GmshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| GmshError::Io { file: file.clone(), message: e.to_string() })?;
    read_msh_bytes(&bytes, &file)
}

/// Parses the contents of a `.msh` file; `source` names it in errors.
pub fn read_msh_bytes(bytes: &[u8], source: &str) -> Result<ImportedMesh, GmshError> {
    let raw = parse_raw(bytes, source)?;
    build(raw, source)
}

/// Parses a `.msh` text (tests, inline meshes).
pub fn read_msh_str(text: &str, source: &str) -> Result<ImportedMesh, GmshError> {
    read_msh_bytes(text.as_bytes(), source)
}

// ---------------------------------------------------------------------------------------------
// Gmsh element types

/// The registered element types as Gmsh types, for messages.
fn supported_volume_elements() -> String {
    ElementType::all()
        .map(|e| format!("{}: {}, {}", e.gmsh_type(), e.name(), e.description()))
        .collect::<Vec<_>>()
        .join("; ")
}

/// What hox knows of a Gmsh element type: dimension, node count, description. A registered
/// element type whose Gmsh type the table below does not list is known by its own file.
fn gmsh_type_info(gmsh_type: u32) -> Option<(u8, usize, &'static str)> {
    gmsh_type_table(gmsh_type)
        .or_else(|| ElementType::from_gmsh_type(gmsh_type).map(|e| (3, e.num_nodes(), e.description())))
}

/// Gmsh's element types, as far as hox needs them.
fn gmsh_type_table(gmsh_type: u32) -> Option<(u8, usize, &'static str)> {
    Some(match gmsh_type {
        15 => (0, 1, "point"),
        1 => (1, 2, "2-node line"),
        8 => (1, 3, "3-node line"),
        26 => (1, 4, "4-node line"),
        27 => (1, 5, "5-node line"),
        28 => (1, 6, "6-node line"),
        2 => (2, 3, "3-node triangle"),
        9 => (2, 6, "6-node triangle"),
        20 => (2, 9, "9-node triangle"),
        21 => (2, 10, "10-node triangle"),
        22 => (2, 12, "12-node triangle"),
        23 => (2, 15, "15-node triangle"),
        24 => (2, 15, "15-node incomplete triangle"),
        25 => (2, 21, "21-node triangle"),
        3 => (2, 4, "4-node quadrangle"),
        16 => (2, 8, "8-node quadrangle"),
        10 => (2, 9, "9-node quadrangle"),
        36 => (2, 16, "16-node quadrangle"),
        37 => (2, 25, "25-node quadrangle"),
        4 => (3, 4, "4-node tetrahedron"),
        11 => (3, 10, "10-node tetrahedron"),
        29 => (3, 20, "20-node tetrahedron"),
        30 => (3, 35, "35-node tetrahedron"),
        31 => (3, 56, "56-node tetrahedron"),
        5 => (3, 8, "8-node hexahedron"),
        17 => (3, 20, "20-node hexahedron"),
        12 => (3, 27, "27-node hexahedron"),
        92 => (3, 64, "64-node hexahedron"),
        93 => (3, 125, "125-node hexahedron"),
        6 => (3, 6, "6-node prism"),
        18 => (3, 15, "15-node prism"),
        13 => (3, 18, "18-node prism"),
        7 => (3, 5, "5-node pyramid"),
        19 => (3, 13, "13-node pyramid"),
        14 => (3, 14, "14-node pyramid"),
        _ => return None,
    })
}

// ---------------------------------------------------------------------------------------------
// The format-independent content of a file

/// One element as read: its tag, Gmsh type, node tags, physical groups and where it was read.
#[derive(Debug)]
struct RawElement {
    tag: u64,
    gmsh_type: u32,
    nodes: Vec<u64>,
    /// Physical tags of the element's entity (MSH 4.1) or its own (MSH 2.2).
    physical: Vec<i32>,
    /// Line in the file (ASCII MSH 2.2), for messages.
    line: Option<usize>,
}

#[derive(Debug, Default)]
struct RawMsh {
    nodes: Vec<(u64, [f64; 3])>,
    elements: Vec<RawElement>,
    /// `(dimension, physical tag)` → name.
    physical_names: HashMap<(i32, i32), String>,
}

fn at(line: Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

/// Builds the hox mesh, groups and checks from what the file holds.
fn build(raw: RawMsh, file: &str) -> Result<ImportedMesh, GmshError> {
    let file_s = file.to_string();
    if raw.nodes.is_empty() {
        return Err(GmshError::Empty { file: file_s, what: "no nodes".into() });
    }
    if raw.elements.is_empty() {
        return Err(GmshError::Empty { file: file_s, what: "no elements".into() });
    }
    let mut index_of_tag: HashMap<u64, usize> = HashMap::with_capacity(raw.nodes.len());
    for (i, (tag, _)) in raw.nodes.iter().enumerate() {
        if index_of_tag.insert(*tag, i).is_some() {
            return Err(GmshError::DuplicateNode { file: file_s, node_tag: *tag });
        }
    }
    // classify and check every element
    let mut max_dim = 0;
    let mut num_volume = 0;
    for el in &raw.elements {
        let (dim, expected, description) =
            gmsh_type_info(el.gmsh_type).ok_or_else(|| GmshError::UnknownElementType {
                file: file_s.clone(),
                at: at(el.line),
                element_tag: el.tag,
                gmsh_type: el.gmsh_type,
            })?;
        if dim == 3 && ElementType::from_gmsh_type(el.gmsh_type).is_none() {
            return Err(GmshError::UnsupportedElement {
                file: file_s.clone(),
                at: at(el.line),
                element_tag: el.tag,
                gmsh_type: el.gmsh_type,
                description: description.into(),
                supported: supported_volume_elements(),
            });
        }
        if el.nodes.len() != expected {
            return Err(GmshError::NodeCount {
                file: file_s.clone(),
                at: at(el.line),
                element_tag: el.tag,
                description: description.into(),
                found: el.nodes.len(),
                expected,
            });
        }
        if let Some(&node_tag) = el.nodes.iter().find(|t| !index_of_tag.contains_key(t)) {
            return Err(GmshError::MissingNode {
                file: file_s.clone(),
                at: at(el.line),
                element_tag: el.tag,
                node_tag,
            });
        }
        max_dim = max_dim.max(dim);
        num_volume += usize::from(dim == 3);
    }
    if num_volume == 0 {
        return Err(GmshError::SurfaceOnly { file: file_s, count: raw.elements.len(), max_dim });
    }
    // nodes used by volume elements, renumbered in file order
    let mut used = vec![false; raw.nodes.len()];
    for el in raw.elements.iter().filter(|e| is_volume(e.gmsh_type)) {
        for t in &el.nodes {
            used[index_of_tag[t]] = true;
        }
    }
    let mut new_index = vec![u32::MAX; raw.nodes.len()];
    let mut rest_positions = Vec::new();
    let mut node_tags = Vec::new();
    for (i, (tag, p)) in raw.nodes.iter().enumerate() {
        if used[i] {
            new_index[i] = rest_positions.len() as u32;
            rest_positions.push(Vec3::from(*p));
            node_tags.push(*tag);
        }
    }
    let node = |tag: &u64| new_index[index_of_tag[tag]];
    // blocks, in order of first appearance
    let mut blocks: Vec<ElementBlock> = Vec::new();
    let mut element_tags: Vec<Vec<u64>> = Vec::new();
    let mut place: Vec<Option<(usize, usize)>> = Vec::with_capacity(raw.elements.len());
    for el in &raw.elements {
        let Some(et) = ElementType::from_gmsh_type(el.gmsh_type).filter(|_| is_volume(el.gmsh_type)) else {
            place.push(None);
            continue;
        };
        let b = match blocks.iter().position(|b| b.element_type == et) {
            Some(b) => b,
            None => {
                blocks.push(ElementBlock::new(et, Vec::new()));
                element_tags.push(Vec::new());
                blocks.len() - 1
            }
        };
        place.push(Some((b, element_tags[b].len())));
        blocks[b].connectivity.extend(el.nodes.iter().map(node));
        element_tags[b].push(el.tag);
    }
    let mesh = Mesh { rest_positions, blocks };
    mesh.validate().map_err(|e| GmshError::Mesh {
        file: file_s.clone(),
        message: describe_mesh_error(&e, &mesh.blocks, &element_tags, &node_tags),
    })?;
    // physical groups
    let name_of = |dim: i32, tag: i32| raw.physical_names.get(&(dim, tag)).cloned().unwrap_or_else(|| tag.to_string());
    let mut node_sets: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    let mut element_sets: BTreeMap<String, Vec<(usize, usize)>> = BTreeMap::new();
    for (el, place) in raw.elements.iter().zip(&place) {
        let dim = gmsh_type_info(el.gmsh_type).map_or(0, |i| i.0) as i32;
        for &p in &el.physical {
            let name = name_of(dim, p);
            let set = node_sets.entry(name.clone()).or_default();
            set.extend(el.nodes.iter().map(node).filter(|&n| n != u32::MAX));
            if let Some(be) = place {
                element_sets.entry(name).or_default().push(*be);
            }
        }
    }
    for set in node_sets.values_mut() {
        set.sort_unstable();
        set.dedup();
    }
    check_rest_shapes(&mesh, &element_tags, &node_tags, &file_s)?;
    Ok(ImportedMesh { source: file_s, mesh, node_sets, element_sets, element_tags, node_tags })
}

/// No inverted or flat rest element: an error naming the element and its nodes by their tags.
fn check_rest_shapes(mesh: &Mesh, element_tags: &[Vec<u64>], node_tags: &[u64], file: &str) -> Result<(), GmshError> {
    let file_s = file.to_string();
    for (b, block) in mesh.blocks.iter().enumerate() {
        if let Err(e) = precompute_block(&mesh.rest_positions, block, None) {
            return Err(match e {
                GeometryError::BadElement { element_type, element, point, reference, det_j, what, nodes } => {
                    GmshError::BadElement {
                        file: file_s,
                        element_tag: element_tags[b][element],
                        element_type,
                        what,
                        detail: format!(
                            "det J = {det_j:.3e} at quadrature point {point} (reference coordinates {reference:?}); its nodes (file tags) are {:?}",
                            nodes.iter().map(|&n| node_tags[n as usize]).collect::<Vec<_>>()
                        ),
                    }
                }
                other => GmshError::Mesh { file: file_s, message: other.to_string() },
            });
        }
    }
    Ok(())
}

impl ImportedMesh {
    /// A mesh given as arrays rather than read from a file (hox's Python package, issue #60):
    /// `mesh` in Gmsh's node order, with named node sets for clamps and prescribed motion. The
    /// reader's checks apply — structure ([`Mesh::validate`]) and rest shapes (no inverted or
    /// flat element) — and an error names elements and nodes by their index, from 0, in
    /// `source`'s arrays.
    pub fn from_arrays(
        source: &str,
        mesh: Mesh,
        mut node_sets: BTreeMap<String, Vec<u32>>,
    ) -> Result<ImportedMesh, GmshError> {
        let file = source.to_string();
        if mesh.blocks.iter().all(ElementBlock::is_empty) {
            return Err(GmshError::Empty { file, what: "no elements".into() });
        }
        let element_tags: Vec<Vec<u64>> = mesh.blocks.iter().map(|b| (0..b.len() as u64).collect()).collect();
        let node_tags: Vec<u64> = (0..mesh.num_nodes() as u64).collect();
        mesh.validate().map_err(|e| GmshError::Mesh {
            file: file.clone(),
            message: describe_mesh_error(&e, &mesh.blocks, &element_tags, &node_tags),
        })?;
        for (name, set) in &mut node_sets {
            if let Some(&n) = set.iter().find(|&&n| n as usize >= mesh.num_nodes()) {
                return Err(GmshError::Mesh {
                    file,
                    message: format!("group \"{name}\" names node {n}, but the mesh has {} nodes", mesh.num_nodes()),
                });
            }
            set.sort_unstable();
            set.dedup();
        }
        check_rest_shapes(&mesh, &element_tags, &node_tags, &file)?;
        Ok(ImportedMesh { source: file, mesh, node_sets, element_sets: BTreeMap::new(), element_tags, node_tags })
    }
}

fn is_volume(gmsh_type: u32) -> bool {
    gmsh_type_info(gmsh_type).is_some_and(|i| i.0 == 3)
}

/// A structural mesh error in the file's own numbering.
fn describe_mesh_error(e: &MeshError, blocks: &[ElementBlock], element_tags: &[Vec<u64>], node_tags: &[u64]) -> String {
    let node_tag = |n: usize| node_tags.get(n).copied().unwrap_or(n as u64);
    match e {
        MeshError::RepeatedNode { element_type, element, node } => {
            let tag = blocks
                .iter()
                .position(|b| b.element_type.name() == element_type)
                .and_then(|b| element_tags[b].get(*element).copied())
                .unwrap_or(*element as u64);
            format!("element {tag} ({element_type}) uses node {} twice", node_tag(*node as usize))
        }
        MeshError::NonFiniteNode { node, position } => {
            format!("node {} has a non-finite coordinate {position:?}", node_tag(*node))
        }
        other => other.to_string(),
    }
}

// ---------------------------------------------------------------------------------------------
// Reading the file: version dispatch, $PhysicalNames

fn parse_raw(bytes: &[u8], file: &str) -> Result<RawMsh, GmshError> {
    let not_msh = |m: &str| GmshError::NotMsh { file: file.to_string(), message: m.to_string() };
    let start = find(bytes, b"$MeshFormat").ok_or_else(|| not_msh("no $MeshFormat section"))?;
    let rest = &bytes[start + b"$MeshFormat".len()..];
    let header_line = rest
        .split(|&c| c == b'\n')
        .map(|l| String::from_utf8_lossy(l).trim().to_string())
        .find(|l| !l.is_empty())
        .ok_or_else(|| not_msh("empty $MeshFormat section"))?;
    let fields: Vec<&str> = header_line.split_whitespace().collect();
    let (version, file_type) = match fields.as_slice() {
        [v, t, _size] => (v.to_string(), *t),
        _ => return Err(not_msh(&format!("bad $MeshFormat line \"{header_line}\""))),
    };
    let binary = match file_type {
        "0" => false,
        "1" => true,
        _ => return Err(not_msh(&format!("bad file type {file_type} in $MeshFormat"))),
    };
    let mut raw = match version.as_str() {
        "4.1" => msh41::parse(bytes, file)?,
        "2.2" if binary => msh22::parse_binary(bytes, file)?,
        "2.2" => msh22::parse_ascii(bytes, file)?,
        _ => return Err(GmshError::Version { file: file.to_string(), version }),
    };
    raw.physical_names = physical_names(bytes, file)?;
    Ok(raw)
}

/// Position of `needle` in `haystack`.
fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// 1-based line number of byte offset `pos`.
fn line_of(bytes: &[u8], pos: usize) -> usize {
    1 + bytes[..pos.min(bytes.len())].iter().filter(|&&c| c == b'\n').count()
}

/// The `$PhysicalNames` section (text in ASCII and binary files alike): `dim tag "name"`.
fn physical_names(bytes: &[u8], file: &str) -> Result<HashMap<(i32, i32), String>, GmshError> {
    let mut names = HashMap::new();
    let Some(start) = find(bytes, b"$PhysicalNames") else {
        return Ok(names);
    };
    let body_start = start + b"$PhysicalNames".len();
    let end =
        find(&bytes[body_start..], b"$EndPhysicalNames").map(|e| body_start + e).ok_or_else(|| GmshError::Parse {
            file: file.into(),
            at: format!(":{}", line_of(bytes, start)),
            message: "$PhysicalNames is not closed by $EndPhysicalNames".into(),
        })?;
    let first_line = line_of(bytes, body_start);
    let text = String::from_utf8_lossy(&bytes[body_start..end]);
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || !line.contains('"') && line.parse::<usize>().is_ok() {
            continue; // the rest of the header line, or the count
        }
        let bad = || GmshError::Parse {
            file: file.into(),
            at: format!(":{}", first_line + k),
            message: format!("bad physical name line \"{line}\" (expected: dimension tag \"name\")"),
        };
        let mut parts = line.splitn(3, char::is_whitespace);
        let dim: i32 = parts.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = parts.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let name = parts.next().map(|s| s.trim().trim_matches('"').to_string()).ok_or_else(bad)?;
        names.insert((dim, tag), name);
    }
    Ok(names)
}

/// MSH 2.2, parsed by hand (ASCII and binary).
mod msh22;
/// MSH 4.1, parsed by the `mshio` crate.
mod msh41;

#[cfg(test)]
mod tests;
