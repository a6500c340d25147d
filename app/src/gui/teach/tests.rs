//! Tests of the reference-element view: the field, the colour map, sections, picking, rendering.

use super::explain::node_kind;
use super::field::shape_function_field;
use super::geometry::{polygon_area, same_point, section_polygon};
use super::*;

#[test]
fn every_node_on_a_face_is_a_display_vertex() {
    for e in ElementType::all() {
        let g = ElementGeometry::new(e);
        for i in 0..e.num_nodes() {
            let on_a_face = e.faces().iter().any(|f| f.nodes.contains(&i));
            assert_eq!(g.node_vertex[i].is_some(), on_a_face, "{} node {i}", e.name());
        }
    }
}

#[test]
fn the_field_of_node_i_is_one_at_node_i_and_zero_at_every_other_node() {
    for e in ElementType::all() {
        let g = ElementGeometry::new(e);
        for i in 0..e.num_nodes() {
            let field = shape_function_field(e.reference(), &g.vertex_reference, i);
            assert_eq!(field.len(), g.surface.num_vertices());
            for (j, v) in g.node_vertex.iter().enumerate() {
                let Some(v) = v else { continue };
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((field[*v] - want).abs() < 1e-9, "{} N_{i} at node {j}: {}", e.name(), field[*v]);
            }
            assert!(field.iter().all(|v| v.is_finite()), "{} N_{i}", e.name());
        }
    }
}

#[test]
fn the_field_mesh_carries_the_same_values_at_the_nodes() {
    // the flat sub-triangles the picture is drawn with (P1 subdivided, sections) agree too
    for e in ElementType::all() {
        let g = ElementGeometry::new(e);
        for sections in [false, true] {
            let i = e.num_nodes() - 1;
            let f = FieldMesh::new(&g, i, sections);
            assert!(!f.triangles.is_empty(), "{} sections {sections}", e.name());
            for (p, v) in f.points.iter().zip(&f.values) {
                if let Some(j) = e.nodes().iter().position(|r| same_point(r, p)) {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-9, "{} N_{i} at node {j}: {v}", e.name());
                }
            }
            assert!(f.max <= 1.2 && f.min >= -0.5, "{} {} {}", e.name(), f.min, f.max);
        }
    }
}

#[test]
fn sections_through_the_centre_have_the_expected_area() {
    for (shape, axis, value, area) in [
        (ReferenceShape::Hexahedron, 2, 0.0, 4.0),
        (ReferenceShape::Tetrahedron, 2, 0.5, 0.125),
        (ReferenceShape::Pyramid, 2, 0.5, 1.0),
        (ReferenceShape::Prism, 2, 0.0, 0.5),
        (ReferenceShape::Prism, 0, 0.5, 1.0),
    ] {
        let p = section_polygon(shape, axis, value).expect("a section");
        assert!((polygon_area(&p, axis) - area).abs() < 1e-12, "{shape:?} {axis} {value}: {p:?}");
    }
    assert!(section_polygon(ReferenceShape::Tetrahedron, 0, 1.0).is_none(), "a vertex only");
    assert!(section_polygon(ReferenceShape::Hexahedron, 1, 2.0).is_none(), "outside");
}

#[test]
fn the_colour_map_is_white_at_zero_red_at_one_and_blue_below_zero() {
    assert_eq!(field_colour(0.0), [247, 247, 247]);
    let one = field_colour(1.0);
    assert!(one[0] > 150 && one[1] < 50 && one[2] < 60, "{one:?}");
    let below = field_colour(-0.2);
    assert!(below[2] > below[0] + 80, "{below:?}");
    assert_eq!(field_colour(-3.0), field_colour(FIELD_MIN_SHOWN));
    assert_eq!(field_colour(7.0), field_colour(1.0));
    assert_eq!(field_colour(f64::NAN), [128, 128, 128]);
}

#[test]
fn explanation_names_the_node_and_says_whether_it_dips_below_zero() {
    let p2 = ElementType::from_name("p2").unwrap();
    let s = explanation(p2.reference(), 5, -0.125, true);
    assert!(s.starts_with("N_5 of P2 (edge node): 1 at node 5, 0 at every other node"), "{s}");
    assert!(s.contains("quadratic shape function dips below zero"), "{s}");
    let q1 = ElementType::from_name("q1").unwrap();
    assert!(explanation(q1.reference(), 0, 0.0, true).contains("never negative"));
    let q2 = ElementType::from_name("q2").unwrap();
    let s = explanation(q2.reference(), 26, -0.0, false);
    assert!(s.contains("interior node") && s.contains("inside the element"), "{s}");
    assert_eq!(node_kind(q2.reference(), 20), "face node");
}

#[test]
fn picking_takes_the_nearest_visible_node_within_the_radius() {
    let marks = [
        Some(NodeMark { px: [10.0, 10.0], visible: true }),
        Some(NodeMark { px: [14.0, 10.0], visible: false }),
        None,
        Some(NodeMark { px: [40.0, 40.0], visible: true }),
    ];
    assert_eq!(nearest_node(&marks, [13.0, 10.0], 12.0), Some(0), "visible first");
    assert_eq!(nearest_node(&marks, [38.0, 41.0], 12.0), Some(3));
    assert_eq!(nearest_node(&marks, [100.0, 100.0], 12.0), None);
    let hidden_only = [None, Some(NodeMark { px: [0.0, 0.0], visible: false })];
    assert_eq!(nearest_node(&hidden_only, [3.0, 4.0], 12.0), Some(1));
}

#[test]
fn the_near_corner_of_the_default_view_is_seen_and_the_far_one_is_not() {
    let camera = framing_camera(ReferenceShape::Hexahedron);
    let eye = camera.eye();
    let eye = [eye.x, eye.y, eye.z];
    // the default camera looks from +x, −y, +z
    assert!(seen_from(ReferenceShape::Hexahedron, &[1.0, -1.0, 1.0], eye));
    assert!(!seen_from(ReferenceShape::Hexahedron, &[-1.0, 1.0, -1.0], eye));
}

#[test]
fn rendering_draws_the_colour_field_over_the_background() {
    let background = Image::new(1, 1).rgba[0];
    for name in ["p1", "p2", "q2", "pyramid"] {
        let e = ElementType::from_name(name).unwrap();
        let g = ElementGeometry::new(e);
        let field = FieldMesh::new(&g, 0, false);
        let mut image = Image::new(160, 120);
        render_field(&field, &framing_camera(e.shape()), &mut image);
        let drawn = image.rgba.iter().filter(|c| **c != background).count();
        assert!(drawn > image.rgba.len() / 20, "{name}: {drawn} px drawn");
        let reddish = image.rgba.iter().filter(|c| c[0] > 120 && c[0] as i32 > c[2] as i32 + 60).count();
        assert!(reddish > 0, "{name}: the field rises to 1 somewhere in view");
        if name == "p2" {
            let bluish = image.rgba.iter().filter(|c| c[2] as i32 > c[0] as i32 + 40).count();
            assert!(bluish > 20, "P2 corner function dips below zero in view ({bluish} px)");
        }
    }
}
