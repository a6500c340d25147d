//! VTK export: the (deformed) mesh as a VTU file (VTK XML unstructured grid, ASCII), a
//! [`PvdSeries`] of such files with a `.pvd` index for ParaView, and a small VTU reader that
//! reads these files back (round-trip tests).
//!
//! Cell types and node orders. hox stores elements in Gmsh node order; VTK's orders differ for
//! some types. Each element type's file gives its VTK cell type and Gmsh → VTK permutation `P`
//! ([`crate::element::ReferenceElement::vtk_cell_type`] and `vtk_node_order`; the table is in
//! `docs/MESHES.md`), and each cell is written as `vtk[i] = gmsh[P[i]]`.
//!
//! Points are the current positions; point data holds `displacement_m` (current − rest) and any
//! further arrays the caller passes; cell data may hold, e.g., the von Mises stress
//! ([`von_mises_stress_pa`]). Numbers are written with Rust's shortest round-trip formatting, so
//! reading a file back gives the same `f64`s.

use crate::Vec3;
use crate::element::ElementType;
use crate::fem::geometry::BlockGeometry;
use crate::material::Material;
use crate::mesh::Mesh;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    #[error("cannot write {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: {message}")]
    Read { path: String, message: String },
    #[error("{0}")]
    Invalid(String),
}

/// VTK cell type and Gmsh → VTK node permutation of a hox element type (its file's).
pub fn vtk_cell(element_type: ElementType) -> (u8, &'static [usize]) {
    (element_type.vtk_cell_type(), element_type.vtk_node_order())
}

/// The hox element type of a VTK cell type (the inverse of [`vtk_cell`]).
pub fn element_type_of_vtk(cell_type: u8) -> Option<ElementType> {
    ElementType::from_vtk_cell_type(cell_type)
}

/// A named data array: `components` values per point (or cell), flattened.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
}

impl DataArray {
    pub fn vectors(name: &str, v: &[Vec3]) -> Self {
        Self { name: name.into(), components: 3, values: v.iter().flat_map(|p| [p.x, p.y, p.z]).collect() }
    }
    pub fn scalars(name: &str, v: Vec<f64>) -> Self {
        Self { name: name.into(), components: 1, values: v }
    }
}

/// Writes `mesh` at `positions` (the current positions; the rest positions for the undeformed
/// mesh) as VTU text, with `displacement_m` = positions − rest and the extra arrays.
pub fn vtu_string(
    mesh: &Mesh,
    positions: &[Vec3],
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<String, VtkError> {
    let n = mesh.num_nodes();
    if positions.len() != n {
        return Err(VtkError::Invalid(format!("{} positions for a mesh of {n} nodes", positions.len())));
    }
    for a in point_data {
        if a.values.len() != a.components * n {
            return Err(VtkError::Invalid(format!(
                "point array {} has {} values, expected {}",
                a.name,
                a.values.len(),
                a.components * n
            )));
        }
    }
    let num_cells = mesh.num_elements();
    for a in cell_data {
        if a.values.len() != a.components * num_cells {
            return Err(VtkError::Invalid(format!(
                "cell array {} has {} values, expected {}",
                a.name,
                a.values.len(),
                a.components * num_cells
            )));
        }
    }
    let mut s = String::with_capacity(64 * n + 64 * num_cells);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    s.push_str("  <UnstructuredGrid>\n");
    let _ = writeln!(s, "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{num_cells}\">");
    s.push_str("      <Points>\n");
    write_array(&mut s, "Float64", "Points", 3, positions.iter().flat_map(|p| [p.x, p.y, p.z]));
    s.push_str("      </Points>\n");
    // cells
    let mut connectivity: Vec<u32> = Vec::new();
    let mut offsets = Vec::with_capacity(num_cells);
    let mut types = Vec::with_capacity(num_cells);
    for b in &mesh.blocks {
        let (cell_type, perm) = vtk_cell(b.element_type);
        for el in b.elements() {
            connectivity.extend(perm.iter().map(|&i| el[i]));
            offsets.push(connectivity.len());
            types.push(cell_type);
        }
    }
    s.push_str("      <Cells>\n");
    write_array(&mut s, "Int64", "connectivity", 1, connectivity.iter());
    write_array(&mut s, "Int64", "offsets", 1, offsets.iter());
    write_array(&mut s, "UInt8", "types", 1, types.iter());
    s.push_str("      </Cells>\n");
    s.push_str("      <PointData Vectors=\"displacement_m\">\n");
    write_array(
        &mut s,
        "Float64",
        "displacement_m",
        3,
        positions.iter().zip(&mesh.rest_positions).flat_map(|(x, x0)| {
            let u = x - x0;
            [u.x, u.y, u.z]
        }),
    );
    for a in point_data {
        write_array(&mut s, "Float64", &a.name, a.components, a.values.iter());
    }
    s.push_str("      </PointData>\n");
    if !cell_data.is_empty() {
        s.push_str("      <CellData>\n");
        for a in cell_data {
            write_array(&mut s, "Float64", &a.name, a.components, a.values.iter());
        }
        s.push_str("      </CellData>\n");
    }
    s.push_str("    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    Ok(s)
}

fn write_array<T: std::fmt::Display>(
    s: &mut String,
    ty: &str,
    name: &str,
    components: usize,
    values: impl Iterator<Item = T>,
) {
    let _ = writeln!(
        s,
        "        <DataArray type=\"{ty}\" Name=\"{}\" NumberOfComponents=\"{components}\" format=\"ascii\">",
        xml_escape(name)
    );
    let per_line = if components > 1 { components } else { 12 };
    for (k, v) in values.enumerate() {
        s.push_str(if k % per_line == 0 { "          " } else { " " });
        let _ = write!(s, "{v}");
        if k % per_line == per_line - 1 {
            s.push('\n');
        }
    }
    if !s.ends_with('\n') {
        s.push('\n');
    }
    s.push_str("        </DataArray>\n");
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Writes one VTU file.
pub fn write_vtu(
    path: &Path,
    mesh: &Mesh,
    positions: &[Vec3],
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), VtkError> {
    let text = vtu_string(mesh, positions, point_data, cell_data)?;
    std::fs::write(path, text).map_err(|source| VtkError::Io { path: path.display().to_string(), source })
}

/// Volume-averaged von Mises stress of every element (cell order of the VTU file: block by
/// block), from the Cauchy stress `σ = P Fᵀ / det F` at the quadrature points; Pa.
pub fn von_mises_stress_pa(
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    positions: &[Vec3],
) -> Vec<f64> {
    crate::measure::field::element_means(crate::measure::field::Field::VonMises, mesh, geometry, material, positions)
}

/// A time series of VTU files with a ParaView `.pvd` index: `DIR/NAME_000000.vtu`, … and
/// `DIR/NAME.pvd`. The index is rewritten after every frame, so a run stopped early still leaves
/// a valid series.
#[derive(Debug)]
pub struct PvdSeries {
    dir: PathBuf,
    name: String,
    frames: Vec<(f64, String)>,
}

impl PvdSeries {
    /// Creates `dir` if needed and checks that it is writable (an error now rather than after a
    /// long simulation).
    pub fn create(dir: &Path, name: &str) -> Result<PvdSeries, VtkError> {
        let io = |source| VtkError::Io { path: dir.display().to_string(), source };
        std::fs::create_dir_all(dir).map_err(io)?;
        let probe = dir.join(format!(".{name}.write-test"));
        std::fs::write(&probe, b"").map_err(io)?;
        let _ = std::fs::remove_file(&probe);
        let series = PvdSeries { dir: dir.to_path_buf(), name: name.to_string(), frames: Vec::new() };
        series.write_index()?;
        Ok(series)
    }

    /// The `.pvd` index file.
    pub fn index_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.name))
    }

    /// Number of frames written.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Writes the next frame at `time_secs` and rewrites the index; returns the VTU's path.
    pub fn write_frame(
        &mut self,
        time_secs: f64,
        mesh: &Mesh,
        positions: &[Vec3],
        point_data: &[DataArray],
        cell_data: &[DataArray],
    ) -> Result<PathBuf, VtkError> {
        let file = format!("{}_{:06}.vtu", self.name, self.frames.len());
        let path = self.dir.join(&file);
        write_vtu(&path, mesh, positions, point_data, cell_data)?;
        self.frames.push((time_secs, file));
        self.write_index()?;
        Ok(path)
    }

    fn write_index(&self) -> Result<(), VtkError> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, file) in &self.frames {
            let _ = writeln!(s, "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{}\"/>", xml_escape(file));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        // write then rename, so a reader never sees half an index
        let path = self.index_path();
        let tmp = self.dir.join(format!(".{}.pvd.tmp", self.name));
        let io = |source| VtkError::Io { path: path.display().to_string(), source };
        std::fs::write(&tmp, s).map_err(io)?;
        std::fs::rename(&tmp, &path).map_err(io)
    }
}

/// What [`read_vtu`] finds in a VTU file written by [`vtu_string`].
#[derive(Clone, Debug, PartialEq)]
pub struct VtuData {
    pub points: Vec<[f64; 3]>,
    /// `(VTK cell type, VTK-ordered connectivity)` per cell.
    pub cells: Vec<(u8, Vec<u32>)>,
    pub point_data: BTreeMap<String, DataArray>,
    pub cell_data: BTreeMap<String, DataArray>,
}

impl VtuData {
    /// The cells as a hox mesh (Gmsh node order), blocks in order of first appearance, with the
    /// file's points as rest positions.
    pub fn to_mesh(&self) -> Result<Mesh, VtkError> {
        let mut blocks: Vec<crate::mesh::ElementBlock> = Vec::new();
        for (k, (cell_type, conn)) in self.cells.iter().enumerate() {
            let et = element_type_of_vtk(*cell_type).ok_or_else(|| {
                VtkError::Invalid(format!("cell {k}: VTK cell type {cell_type} is not one hox writes"))
            })?;
            let (_, perm) = vtk_cell(et);
            if conn.len() != perm.len() {
                return Err(VtkError::Invalid(format!("cell {k}: {} nodes for a {et}", conn.len())));
            }
            let mut gmsh = vec![0; perm.len()];
            for (i, &p) in perm.iter().enumerate() {
                gmsh[p] = conn[i];
            }
            match blocks.iter_mut().find(|b| b.element_type == et) {
                Some(b) => b.connectivity.extend(gmsh),
                None => blocks.push(crate::mesh::ElementBlock::new(et, gmsh)),
            }
        }
        Ok(Mesh { rest_positions: self.points.iter().map(|p| Vec3::from(*p)).collect(), blocks })
    }
}

/// Reads a VTU file written by [`write_vtu`] (ASCII data arrays; not a general VTU reader).
pub fn read_vtu(path: &Path) -> Result<VtuData, VtkError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| VtkError::Read { path: path.display().to_string(), message: e.to_string() })?;
    parse_vtu(&text).map_err(|message| VtkError::Read { path: path.display().to_string(), message })
}

/// Parses the text of a VTU file written by [`vtu_string`].
pub fn parse_vtu(text: &str) -> Result<VtuData, String> {
    let section = |tag: &str| -> &str {
        let open = format!("<{tag}");
        let close = format!("</{tag}>");
        match (text.find(&open), text.find(&close)) {
            (Some(a), Some(b)) if b > a => &text[a..b],
            _ => "",
        }
    };
    let points_arrays = arrays(section("Points"))?;
    let p = points_arrays.values().next().ok_or("no Points array")?;
    if p.components != 3 || p.values.len() % 3 != 0 {
        return Err("the Points array is not 3-component".into());
    }
    let points: Vec<[f64; 3]> = p.values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let cells = arrays(section("Cells"))?;
    let get = |name: &str| cells.get(name).ok_or_else(|| format!("no {name} array in <Cells>"));
    let (conn, offsets, types) = (get("connectivity")?, get("offsets")?, get("types")?);
    if offsets.values.len() != types.values.len() {
        return Err("offsets and types differ in length".into());
    }
    let mut out_cells = Vec::with_capacity(types.values.len());
    let mut start = 0;
    for (&end, &ty) in offsets.values.iter().zip(&types.values) {
        let end = end as usize;
        if end < start || end > conn.values.len() {
            return Err(format!("bad offset {end}"));
        }
        out_cells.push((ty as u8, conn.values[start..end].iter().map(|&v| v as u32).collect()));
        start = end;
    }
    Ok(VtuData {
        points,
        cells: out_cells,
        point_data: arrays(section("PointData"))?,
        cell_data: arrays(section("CellData"))?,
    })
}

/// The `<DataArray>`s in `xml`, by name.
fn arrays(xml: &str) -> Result<BTreeMap<String, DataArray>, String> {
    let mut out = BTreeMap::new();
    let mut rest = xml;
    while let Some(a) = rest.find("<DataArray") {
        let head_end = rest[a..].find('>').ok_or("unclosed <DataArray")? + a;
        let head = &rest[a..head_end];
        let body_end = rest[head_end..].find("</DataArray>").ok_or("unclosed <DataArray>")? + head_end;
        let attr = |key: &str| -> Option<&str> {
            let k = format!("{key}=\"");
            let s = head.find(&k)? + k.len();
            let e = head[s..].find('"')? + s;
            Some(&head[s..e])
        };
        let name = attr("Name").unwrap_or("").to_string();
        let components = attr("NumberOfComponents").and_then(|c| c.parse().ok()).unwrap_or(1);
        let values = rest[head_end + 1..body_end]
            .split_whitespace()
            .map(|v| v.parse::<f64>().map_err(|_| format!("bad number {v:?} in array {name}")))
            .collect::<Result<Vec<_>, _>>()?;
        out.insert(name.clone(), DataArray { name, components, values });
        rest = &rest[body_end + "</DataArray>".len()..];
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::ReferenceShape;

    /// Each permutation is a permutation, and maps every Gmsh node to the VTK node at the same
    /// reference point (VTK's reference coordinates, on [0,1]³ for the hexahedra).
    #[test]
    fn permutations_match_vtk_reference_coordinates() {
        for et in ElementType::all() {
            let (_, perm) = vtk_cell(et);
            let mut seen = perm.to_vec();
            seen.sort_unstable();
            assert_eq!(seen, (0..et.num_nodes()).collect::<Vec<_>>(), "{et}");
        }
        // VTK's own coordinates of the quadratic tet (vtkQuadraticTetra) and the P3 tet
        let h = 0.5;
        let vtk_tet10 = [
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [h, 0., 0.],
            [h, h, 0.],
            [0., h, 0.],
            [0., 0., h],
            [h, 0., h],
            [0., h, h],
        ];
        check(ElementType::from_name("p2").unwrap(), &vtk_tet10, |r| r);
        let (a, b) = (1.0 / 3.0, 2.0 / 3.0);
        let vtk_tet20 = [
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [a, 0., 0.],
            [b, 0., 0.],
            [b, a, 0.],
            [a, b, 0.],
            [0., b, 0.],
            [0., a, 0.],
            [0., 0., a],
            [0., 0., b],
            [b, 0., a],
            [a, 0., b],
            [0., b, a],
            [0., a, b],
            [a, 0., a],
            [a, a, a],
            [0., a, a],
            [a, a, 0.],
        ];
        check(ElementType::from_name("p3").unwrap(), &vtk_tet20, |r| r);
        // vtkTriQuadraticHexahedron on [0,1]³: Gmsh's [-1,1]³ maps by (r + 1) / 2
        let vtk_hex27 = [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
            [h, 0., 0.],
            [1., h, 0.],
            [h, 1., 0.],
            [0., h, 0.],
            [h, 0., 1.],
            [1., h, 1.],
            [h, 1., 1.],
            [0., h, 1.],
            [0., 0., h],
            [1., 0., h],
            [1., 1., h],
            [0., 1., h],
            [0., h, h],
            [1., h, h],
            [h, 0., h],
            [h, 1., h],
            [h, h, 0.],
            [h, h, 1.],
            [h, h, h],
        ];
        check(ElementType::from_name("q2").unwrap(), &vtk_hex27, |r| r.map(|c| (c + 1.0) / 2.0));
        let vtk_hex8 = &vtk_hex27[..8];
        check(ElementType::from_name("q1").unwrap(), vtk_hex8, |r| r.map(|c| (c + 1.0) / 2.0));
        assert_eq!(ElementType::from_name("pyramid").unwrap().shape(), ReferenceShape::Pyramid);
    }

    fn check(et: ElementType, vtk_nodes: &[[f64; 3]], to_vtk: impl Fn([f64; 3]) -> [f64; 3]) {
        let (_, perm) = vtk_cell(et);
        for (i, &p) in perm.iter().enumerate() {
            let r = to_vtk(et.nodes()[p]);
            assert!(
                (0..3).all(|d| (r[d] - vtk_nodes[i][d]).abs() < 1e-12),
                "{et}: VTK node {i} is Gmsh node {p} at {r:?}, VTK has {:?}",
                vtk_nodes[i]
            );
        }
    }

    /// VTK (checked with VTK 9.7: vtkCellSizeFilter, vtkMeshQuality and vtkCellValidator) takes
    /// the wedge in Gmsh's order, the first triangle (0,1,2) turning counter-clockwise seen from
    /// the second (3,4,5); Gmsh's own legacy VTK table (0 2 1 3 5 4) makes VTK report it
    /// inverted. Likewise the pyramid's base turns counter-clockwise seen from the apex.
    #[test]
    fn wedges_and_pyramids_keep_gmsh_order_with_the_base_facing_the_rest_of_the_cell() {
        for name in ["prism", "pyramid"] {
            let et = ElementType::from_name(name).unwrap();
            let (_, perm) = vtk_cell(et);
            assert!(perm.iter().enumerate().all(|(i, &p)| i == p), "{name}");
            let x: Vec<Vec3> = et.nodes().iter().map(|&r| Vec3::from(r)).collect();
            let normal = (x[1] - x[0]).cross(&(x[2] - x[0]));
            let rest: Vec3 = x[3..].iter().sum::<Vec3>() / (x.len() - 3) as f64;
            assert!(normal.dot(&(rest - x[0])) > 0.0, "{name}");
        }
    }

    #[test]
    fn a_vtu_reads_back_with_the_same_points_cells_and_data() {
        use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
        for et in ElementType::all() {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [2, 1, 1] },
                element_type: et,
                split: TetSplit::Five,
                refine: 0,
            }
            .build()
            .unwrap();
            let positions: Vec<Vec3> =
                mesh.rest_positions.iter().map(|p| p + Vec3::new(0.1 * p.x * p.x, 1.0 / 3.0, -0.2)).collect();
            let temp = DataArray::scalars("temperature_k", (0..mesh.num_nodes()).map(|i| i as f64 * 0.1).collect());
            let cell = DataArray::scalars("cell_id", (0..mesh.num_elements()).map(|i| i as f64).collect());
            let text = vtu_string(&mesh, &positions, std::slice::from_ref(&temp), std::slice::from_ref(&cell)).unwrap();
            let back = parse_vtu(&text).unwrap();
            let as_mesh = back.to_mesh().unwrap();
            assert_eq!(as_mesh.blocks, mesh.blocks, "{et}");
            assert_eq!(as_mesh.rest_positions, positions, "{et}: points are the current positions, bit for bit");
            let u = &back.point_data["displacement_m"];
            for (i, (x, x0)) in positions.iter().zip(&mesh.rest_positions).enumerate() {
                let d = x - x0;
                assert_eq!(&u.values[3 * i..3 * i + 3], &[d.x, d.y, d.z]);
            }
            assert_eq!(back.point_data["temperature_k"], temp);
            assert_eq!(back.cell_data["cell_id"], cell);
        }
    }

    #[test]
    fn a_series_rewrites_its_index_after_every_frame() {
        let dir = std::env::temp_dir().join(format!("hox-pvd-test-{}", std::process::id()));
        let mesh = crate::mesh::structured::BoxMeshSpec {
            grid: crate::mesh::structured::BoxGrid {
                min_m: Vec3::zeros(),
                max_m: Vec3::new(1.0, 1.0, 1.0),
                cells: [1, 1, 1],
            },
            element_type: ElementType::from_name("q1").unwrap(),
            split: crate::mesh::structured::TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        let mut series = PvdSeries::create(&dir, "run").unwrap();
        assert!(series.index_path().exists());
        for k in 0..3 {
            let path = series.write_frame(k as f64 / 60.0, &mesh, &mesh.rest_positions, &[], &[]).unwrap();
            assert!(path.ends_with(format!("run_{k:06}.vtu")));
            let index = std::fs::read_to_string(series.index_path()).unwrap();
            assert_eq!(index.matches("<DataSet").count(), k + 1);
        }
        assert_eq!(series.len(), 3);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unwritable_series_folder_is_an_error() {
        let file = std::env::temp_dir().join(format!("hox-pvd-not-a-dir-{}", std::process::id()));
        std::fs::write(&file, b"x").unwrap();
        let err = PvdSeries::create(&file.join("sub"), "run").unwrap_err();
        assert!(err.to_string().contains("cannot write"), "{err}");
        std::fs::remove_file(&file).unwrap();
    }
}
