use super::*;

/// One tetrahedron (nodes 1–4) with its bottom triangle in group "bottom", the tetrahedron in
/// group "solid", and node 5 used by nothing. `tet` is the tetrahedron's element line after the
/// tag (type, tags, nodes), so tests can break it.
fn msh22(tet: &str) -> String {
    format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"bottom\"\n3 2 \"solid\"\n$EndPhysicalNames\n\
         $Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 5 5 5\n$EndNodes\n\
         $Elements\n2\n1 2 2 1 1 1 3 2\n2 {tet}\n$EndElements\n"
    )
}

/// The same content in MSH 4.1, with the tetrahedron's node tags given.
fn msh41(tet_nodes: &str) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"bottom\"\n3 2 \"solid\"\n$EndPhysicalNames\n\
         $Entities\n0 0 1 1\n1 0 0 0 1 1 0 1 1 0\n1 0 0 0 1 1 1 1 2 0\n$EndEntities\n\
         $Nodes\n2 5 1 5\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n3 1 0 2\n4\n5\n0 0 1\n5 5 5\n$EndNodes\n\
         $Elements\n2 2 1 2\n2 1 2 1\n1 1 3 2\n3 1 4 1\n2 {tet_nodes}\n$EndElements\n"
    )
}

fn check_one_tet(m: &ImportedMesh) {
    assert_eq!(m.mesh.num_nodes(), 4, "node 5 is used by no volume element and is dropped");
    assert_eq!(m.node_tags, [1, 2, 3, 4]);
    assert_eq!(m.mesh.blocks.len(), 1);
    assert_eq!(m.mesh.blocks[0].element_type.name(), "p1");
    assert_eq!(m.mesh.blocks[0].connectivity, [0, 1, 2, 3]);
    assert_eq!(m.element_tags, [vec![2]]);
    assert_eq!(m.node_set("bottom").unwrap(), &[0, 1, 2]);
    assert_eq!(m.node_set("solid").unwrap(), &[0, 1, 2, 3]);
    assert_eq!(m.element_sets.get("solid"), Some(&vec![(0, 0)]));
    assert!(!m.element_sets.contains_key("bottom"), "only volume groups are element sets");
}

#[test]
fn msh22_ascii_reads_nodes_elements_and_groups() {
    check_one_tet(&read_msh_str(&msh22("4 2 2 1 1 2 3 4"), "t.msh").unwrap());
}

#[test]
fn msh41_ascii_reads_nodes_elements_and_groups() {
    check_one_tet(&read_msh_str(&msh41("1 2 3 4"), "t.msh").unwrap());
}

#[test]
fn an_unknown_group_is_an_error_listing_the_groups() {
    let m = read_msh_str(&msh41("1 2 3 4"), "t.msh").unwrap();
    let e = m.node_set("clamp").unwrap_err().to_string();
    assert!(
        e.contains("t.msh") && e.contains("\"clamp\" does not exist") && e.contains("\"bottom\", \"solid\""),
        "{e}"
    );
}

#[test]
fn an_unnamed_group_is_called_by_its_number() {
    let text =
        msh22("4 2 7 1 1 2 3 4").replace("$PhysicalNames\n2\n2 1 \"bottom\"\n3 2 \"solid\"\n$EndPhysicalNames\n", "");
    let m = read_msh_str(&text, "t.msh").unwrap();
    assert_eq!(m.node_set("7").unwrap(), &[0, 1, 2, 3]);
    assert_eq!(m.node_set("1").unwrap(), &[0, 1, 2]);
}

fn error(text: &str) -> String {
    read_msh_str(text, "bad.msh").unwrap_err().to_string()
}

#[test]
fn an_inverted_element_names_the_file_and_the_tag() {
    for e in [error(&msh22("4 2 2 1 2 1 3 4")), error(&msh41("2 1 3 4"))] {
        assert!(e.starts_with("bad.msh") && e.contains("element 2 (p1) is inverted"), "{e}");
    }
}

#[test]
fn a_flat_element_is_an_error() {
    let text = msh22("4 2 2 1 1 2 3 4").replace("4 0 0 1\n", "4 0.5 0.5 0\n");
    let e = error(&text);
    assert!(e.contains("element 2 (p1) is flat"), "{e}");
}

#[test]
fn a_node_out_of_range_names_the_line_and_the_node() {
    let e = error(&msh22("4 2 2 1 1 2 3 9"));
    assert!(e.starts_with("bad.msh:20:") && e.contains("element 2 refers to node 9"), "{e}");
    let e = error(&msh41("1 2 3 9"));
    assert!(e.contains("element 2 refers to node 9"), "{e}");
}

#[test]
fn unknown_and_unsupported_element_types_are_named() {
    let e = error(&msh22("200 2 2 1 1 2 3 4"));
    assert!(e.starts_with("bad.msh:20:") && e.contains("unknown Gmsh element type 200"), "{e}");
    let hex20 = msh22(&format!("17 2 2 1 {}", (1..=20).map(|_| "1").collect::<Vec<_>>().join(" ")));
    let e = error(&hex20);
    assert!(e.contains("20-node hexahedron (Gmsh type 17)") && e.contains("which hox does not simulate"), "{e}");
    // the supported types are the registry's
    for et in ElementType::all() {
        assert!(e.contains(&format!("{}: {}, {}", et.gmsh_type(), et.name(), et.description())), "{et}: {e}");
    }
}

#[test]
fn a_wrong_node_count_is_an_error() {
    let e = error(&msh22("4 2 2 1 1 2 3"));
    assert!(e.contains("bad.msh:20:") && e.contains("lists 3 nodes, expected 4"), "{e}");
}

#[test]
fn empty_and_surface_only_meshes_are_errors() {
    let empty = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n$Elements\n0\n$EndElements\n";
    assert!(error(empty).contains("the mesh is empty: no nodes"), "{}", error(empty));
    let no_elements =
        msh22("4 2 2 1 1 2 3 4").replace("$Elements\n2\n1 2 2 1 1 1 3 2\n2 4 2 2 1 1 2 3 4\n", "$Elements\n0\n");
    assert!(error(&no_elements).contains("no elements"), "{}", error(&no_elements));
    let surface = msh22("2 2 1 1 1 2 4");
    let e = error(&surface);
    assert!(e.contains("surface-only mesh (2 elements of dimension at most 2"), "{e}");
}

#[test]
fn other_versions_and_non_msh_files_are_refused() {
    let e = error(&msh22("4 2 2 1 1 2 3 4").replace("2.2 0 8", "3.0 0 8"));
    assert!(e.contains("MSH format version 3.0 is not supported"), "{e}");
    let e = error("solid cube\nendsolid\n");
    assert!(e.contains("not a Gmsh mesh file: no $MeshFormat section"), "{e}");
    let e = error("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 3\n$EndNodes\n");
    assert!(e.starts_with("bad.msh: malformed MSH 4.1 file"), "{e}");
}

#[test]
fn duplicate_and_bad_node_lines_are_errors() {
    let e = error(&msh22("4 2 2 1 1 2 3 4").replace("5 5 5 5\n", "4 5 5 5\n"));
    assert!(e.contains("node 4 is defined twice"), "{e}");
    let e = error(&msh22("4 2 2 1 1 2 3 4").replace("5 5 5 5\n", "5 5 five 5\n"));
    assert!(e.starts_with("bad.msh:15:") && e.contains("bad node line"), "{e}");
}

#[test]
fn a_mesh_given_as_arrays_is_checked_as_a_file_is_and_named_by_its_rows() {
    let read = read_msh_str(&msh22("4 2 1 2 1 2 3 4"), "one.msh").unwrap();
    let groups: BTreeMap<String, Vec<u32>> = [("bottom".to_string(), vec![2, 0, 1, 0])].into();
    let arrays = ImportedMesh::from_arrays("arrays", read.mesh.clone(), groups.clone()).unwrap();
    assert_eq!(arrays.mesh, read.mesh);
    assert_eq!(arrays.node_sets["bottom"], [0, 1, 2], "sorted and de-duplicated");
    // an inverted tetrahedron: two nodes swapped, named by its row
    let mut inverted = read.mesh.clone();
    inverted.blocks[0].connectivity.swap(0, 1);
    let e = ImportedMesh::from_arrays("arrays", inverted, BTreeMap::new()).unwrap_err().to_string();
    assert!(e.contains("arrays") && e.contains("element 0") && e.contains("inverted"), "{e}");
    let mut out_of_range = read.mesh.clone();
    out_of_range.blocks[0].connectivity[3] = 9;
    let e = ImportedMesh::from_arrays("arrays", out_of_range, BTreeMap::new()).unwrap_err().to_string();
    assert!(e.contains("node 9"), "{e}");
    let bad_group: BTreeMap<String, Vec<u32>> = [("clamp".to_string(), vec![7])].into();
    let e = ImportedMesh::from_arrays("arrays", read.mesh.clone(), bad_group).unwrap_err().to_string();
    assert!(e.contains("\"clamp\"") && e.contains("node 7") && e.contains("4 nodes"), "{e}");
    let empty = Mesh { rest_positions: read.mesh.rest_positions.clone(), blocks: vec![] };
    assert!(ImportedMesh::from_arrays("arrays", empty, BTreeMap::new()).is_err());
}
