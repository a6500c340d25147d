//! The words under the picture: what kind of node is selected and what its shape function does.

use hox_sim::element::ReferenceElement;

/// The kind of node `node` of `element`: corner, edge, face or interior.
pub(super) fn node_kind(element: &dyn ReferenceElement, node: usize) -> &'static str {
    if node < element.num_vertices() {
        return "corner node";
    }
    match element.faces().iter().filter(|f| f.nodes.contains(&node)).count() {
        0 => "interior node",
        1 => "face node",
        _ => "edge node",
    }
}

/// The polynomial space of `element`'s shape functions, in words.
fn function_kind(element: &dyn ReferenceElement) -> String {
    match element.name() {
        "p1" => "linear".into(),
        "p2" => "quadratic".into(),
        "p3" => "cubic".into(),
        "q1" => "trilinear".into(),
        "q2" => "triquadratic".into(),
        "prism" => "linear-times-linear".into(),
        "pyramid" => "rational".into(),
        _ => match element.order() {
            1 => "linear".into(),
            2 => "quadratic".into(),
            3 => "cubic".into(),
            k => format!("degree-{k}"),
        },
    }
}

/// The one-line explanation under the picture.
pub(super) fn explanation(element: &dyn ReferenceElement, node: usize, field_min: f64, on_surface: bool) -> String {
    let name = element.name().to_uppercase();
    let kind = function_kind(element);
    let mut s = format!("N_{node} of {name} ({}): 1 at node {node}, 0 at every other node; ", node_kind(element, node));
    if field_min < -1e-9 {
        s += &format!(
            "negative values (blue, down to {field_min:.3} here) show where a {kind} shape function dips below zero"
        );
    } else if element.order() == 1 {
        s += &format!("a {kind} shape function, never negative");
    } else {
        s += &format!("a {kind} shape function, not negative anywhere shown");
    }
    if !on_surface {
        s += &format!(
            ". Node {node} is inside the element, so N_{node} vanishes on every face: shown on the sections through it"
        );
    }
    s
}
