use super::*;

pub(crate) fn beam(element: &str, cells: [usize; 3], split: TetSplit, refine: usize, length_m: f64) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(length_m, 0.5, 0.5), cells },
        element_type: ElementType::from_name(element).unwrap(),
        split,
        refine,
    }
    .build()
    .unwrap()
}

/// The element and node counts of the paper's meshes (ERRATA.md table).
#[test]
fn the_paper_meshes_have_the_paper_counts() {
    use TetSplit::*;
    let cases: &[(&str, [usize; 3], TetSplit, usize, f64, usize, usize)] = &[
        ("p1", [16, 4, 4], Five, 0, 2.0, 1_280, 425),
        ("p1", [16, 4, 4], Five, 1, 2.0, 10_240, 2_417),
        ("p1", [16, 4, 4], Five, 2, 2.0, 81_920, 16_225),
        ("q1", [64, 16, 16], Five, 0, 2.0, 16_384, 18_785),
        ("p2", [8, 2, 2], Five, 0, 2.0, 160, 393),
        ("p3", [4, 2, 2], Five, 0, 2.0, 80, 573),
        ("p1", [12, 6, 6], Six, 0, 1.0, 2_592, 637),
        ("p2", [6, 3, 3], Six, 0, 1.0, 324, 637),
        ("p3", [4, 2, 2], Six, 0, 1.0, 96, 637),
    ];
    for &(e, cells, split, refine, len, elements, nodes) in cases {
        let m = beam(e, cells, split, refine, len);
        assert_eq!((m.num_elements(), m.num_nodes()), (elements, nodes), "{e} {cells:?} {split:?} refine {refine}");
        // every element has det J > 0 at every quadrature point (precompute checks it) and the
        // element volumes add up to the box
        let geo = crate::fem::geometry::precompute(&m, None).unwrap_or_else(|err| panic!("{e} {cells:?}: {err}"));
        let v = crate::fem::geometry::total_volume_m3(&geo);
        assert!((v - len * 0.25).abs() < 1e-10, "{e} {cells:?}: volume {v}");
    }
}

#[test]
fn no_two_nodes_share_a_position_and_every_cell_holds_its_shapes_element_count() {
    for e in ElementType::all().map(|e| e.name()) {
        let m = beam(e, [3, 2, 2], TetSplit::Five, 0, 1.5);
        let shape = ElementType::from_name(e).unwrap().shape();
        assert_eq!(m.num_elements(), 12 * elements_per_cell(shape, TetSplit::Five), "{e}");
        let mut keys: Vec<[i64; 3]> =
            m.rest_positions.iter().map(|p| [p.x, p.y, p.z].map(|c| (c * 1e9).round() as i64)).collect();
        keys.sort_unstable();
        let n = keys.len();
        keys.dedup();
        assert_eq!(keys.len(), n, "{e}: duplicate node coordinates");
    }
}

#[test]
fn high_order_meshes_are_conforming_every_interior_face_is_shared_by_two_elements() {
    for e in ElementType::all().map(|e| e.name()) {
        for split in [TetSplit::Five, TetSplit::Six] {
            let m = beam(e, [3, 2, 2], split, 0, 1.5);
            let shape = ElementType::from_name(e).unwrap().shape();
            assert_eq!(m.num_elements(), 12 * elements_per_cell(shape, split), "{e} {split:?}");
            // A conforming box mesh has boundary faces only on the box surface.
            let (lo, hi) = m.bounding_box();
            for (b, el, f) in m.boundary_faces() {
                let block = &m.blocks[b];
                let face = &block.element_type.faces()[f];
                let pts: Vec<Vec3> =
                    face.nodes.iter().map(|&l| m.rest_positions[block.element(el)[l] as usize]).collect();
                let on_box = (0..3).any(|d| {
                    pts.iter().all(|p| (p[d] - lo[d]).abs() < 1e-12) || pts.iter().all(|p| (p[d] - hi[d]).abs() < 1e-12)
                });
                assert!(on_box, "{e} {split:?}: unmatched interior face {:?}", face.nodes);
            }
        }
    }
}

#[test]
fn bad_requests_are_errors() {
    let spec = |cells, e: &str, refine| BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(1.0, 1.0, 1.0), cells },
        element_type: ElementType::from_name(e).unwrap(),
        split: TetSplit::Five,
        refine,
    };
    assert!(spec([0, 1, 1], "p1", 0).build().unwrap_err().to_string().contains("empty direction"));
    assert!(spec([1, 1, 1], "q1", 1).build().unwrap_err().to_string().contains("tetrahedra only"));
    let mut flat = spec([1, 1, 1], "p1", 0);
    flat.grid.max_m.z = 0.0;
    assert!(flat.build().unwrap_err().to_string().contains("positive finite size"));
}

/// The nodes of every box mesh are numbered along its longest axis, where the colour sweep cuts
/// its slabs (`Mesh::with_nodes_along_longest_axis`), and renumbering moves no element: each
/// element keeps its node positions in its node order.
#[test]
fn box_nodes_are_numbered_along_the_longest_axis_and_each_element_keeps_its_nodes() {
    for et in ElementType::all() {
        let refine = usize::from(et.shape() == ReferenceShape::Tetrahedron && et.order() == 1);
        let m = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [6, 2, 3] },
            element_type: et,
            split: TetSplit::Five,
            refine,
        }
        .build()
        .unwrap();
        assert!(m.rest_positions.windows(2).all(|w| w[0].x <= w[1].x), "{et}: nodes not in order of x");
        // along y when y is the longest side
        let tall = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(0.3, 2.0, 0.5), cells: [2, 6, 2] },
            element_type: et,
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        assert!(tall.rest_positions.windows(2).all(|w| w[0].y <= w[1].y), "{et}: nodes not in order of y");
    }
    // the same elements in the same order, each with the same node positions
    let m = beam("p2", [4, 2, 2], TetSplit::Six, 0, 2.0);
    let shuffled = Mesh {
        rest_positions: m.rest_positions.iter().rev().copied().collect(),
        blocks: m
            .blocks
            .iter()
            .map(|b| {
                let last = m.num_nodes() as u32 - 1;
                ElementBlock::new(b.element_type, b.connectivity.iter().map(|&n| last - n).collect())
            })
            .collect(),
    };
    let renumbered = shuffled.clone().with_nodes_along_longest_axis();
    assert_eq!(renumbered.num_nodes(), shuffled.num_nodes());
    for (b, (before, after)) in shuffled.blocks.iter().zip(&renumbered.blocks).enumerate() {
        assert_eq!(before.len(), after.len(), "block {b}");
        for (e, (x, y)) in before.elements().zip(after.elements()).enumerate() {
            for (&old, &new) in x.iter().zip(y) {
                assert_eq!(
                    shuffled.rest_positions[old as usize], renumbered.rest_positions[new as usize],
                    "block {b} element {e}"
                );
            }
        }
    }
}
