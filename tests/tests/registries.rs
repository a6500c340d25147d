//! The registries, proved by iterating them: every registered element type
//! (`hox_sim::element::REGISTRY`) and every registered material model
//! (`hox_sim::material::MaterialModel::ALL`) goes through everything that reads the registries —
//! the parameter table (the scene file's `mesh.element` and `material.model`, `--element` and
//! `--material`, the app's menus), the bending scene's box mesh, both sweeps of the kernels
//! with both formulations, the display surface, VTK export and Gmsh import into a mesh-file
//! scene. Adding an element type or a material model is its own file and one registry entry
//! (the registries' comments say which); these tests then run it everywhere, with nothing else
//! to edit. Small grids and few frames keep them fast in debug builds.

use hox_scenes::params::{self, Kind, Value};
use hox_scenes::{Instance, Scene, SceneOverrides};
use hox_sim::Vec3;
use hox_sim::element::{ElementType, ReferenceShape};
use hox_sim::io::{gmsh, vtk};
use hox_sim::material::MaterialModel;
use hox_sim::measure::surface::Surface;
use hox_sim::mesh::Mesh;
use hox_sim::xpbd::constraint::Formulation;
use std::path::PathBuf;

/// The bending beam [0,2]×[0,0.5]×[0,0.5] m: its volume and surface area.
const VOLUME_M3: f64 = 0.5;
const AREA_M2: f64 = 4.5;

/// The options of a choice parameter of the table, by value.
fn choices(key: &str) -> Vec<&'static str> {
    let p = params::by_key(key).unwrap_or_else(|| panic!("no parameter {key}"));
    let Kind::Choice(options) = p.kind else { panic!("{key} is not a choice") };
    options().into_iter().map(|(name, _)| name).collect()
}

#[test]
fn the_parameter_table_offers_exactly_the_registered_element_types_and_material_models() {
    // the scene file's choices, which the command line's flags and the app's menus read
    let elements: Vec<&str> = ElementType::all().map(|e| e.name()).collect();
    let models: Vec<&str> = MaterialModel::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(choices("element"), elements);
    assert_eq!(choices("material"), models);
    for (key, names) in [("element", &elements), ("material", &models)] {
        let p = params::by_key(key).unwrap();
        assert!(p.surfaces.cli && p.surfaces.app, "{key}: on the command line and in the app");
        for name in names {
            // as `--element NAME` or `--compare element=NAME` gives it
            let v = p.kind.parse(&name.to_uppercase()).unwrap_or_else(|e| panic!("{key} {name}: {e}"));
            assert_eq!(v, Value::Text(name.to_string()));
            p.kind.check(&v).unwrap_or_else(|e| panic!("{key} {name}: {e}"));
            assert!(p.kind.expected().contains(name), "{key}: the help names {name}");
        }
        assert!(p.kind.check(&Value::Text("no-such-thing".into())).is_err(), "{key}");
    }
}

/// The built-in bending scene on a 2×1×1 grid of `element`, with `material`, 10 substeps per
/// frame and the given sweep and formulation, through the scene's overrides.
fn bending(element: ElementType, material: MaterialModel, parallel: bool, formulation: Formulation) -> Scene {
    let base = hox_scenes::by_name("bending").unwrap();
    let overrides = SceneOverrides {
        element: Some(element),
        material: Some(material),
        grid: Some([2, 1, 1]),
        substeps: Some(10),
        sweep: Some(if parallel { hox_sim::solver::Sweep::Colour } else { hox_sim::solver::Sweep::Element }),
        formulation: Some(formulation),
        ..SceneOverrides::default()
    };
    base.with_overrides(&overrides).unwrap_or_else(|e| panic!("{element} {material}: {e}"))
}

fn all_finite(points: &[Vec3]) -> bool {
    points.iter().all(|p| p.iter().all(|c| c.is_finite()))
}

/// Steps `instance` three frames; the positions stay finite and the tip probe goes down.
fn steps_and_sags(instance: &mut Instance, what: &str) {
    for _ in 0..3 {
        instance.sim.step_frame().unwrap_or_else(|e| panic!("{what}: {e}"));
    }
    assert!(all_finite(&instance.sim.positions), "{what}: non-finite positions");
    let (name, tip) = &instance.probe_displacements()[0];
    assert_eq!(name, "tip");
    assert!(tip[2] < -1e-4, "{what}: the tip moved {tip:?} m, not down");
}

/// The display surface of the rest mesh covers the box: outward triangles whose area is the
/// box's and whose enclosed volume (divergence theorem) is the box's; it follows the deformed
/// positions with finite points.
fn check_surface(mesh: &Mesh, positions: &[Vec3], what: &str) {
    let surface = Surface::new(mesh, 3);
    let mut rest = Vec::new();
    surface.vertices.eval_into(&mesh.rest_positions, &mut rest);
    let (mut area, mut volume) = (0.0, 0.0);
    for t in &surface.triangles {
        let [a, b, c] = t.map(|i| rest[i as usize]);
        area += 0.5 * (b - a).cross(&(c - a)).norm();
        volume += a.dot(&b.cross(&c)) / 6.0;
    }
    assert!((area - AREA_M2).abs() < 1e-9, "{what}: surface area {area}");
    assert!((volume - VOLUME_M3).abs() < 1e-9, "{what}: enclosed volume {volume} (inward triangles?)");
    let mut deformed = Vec::new();
    surface.vertices.eval_into(positions, &mut deformed);
    assert!(all_finite(&deformed), "{what}: non-finite surface");
}

/// Writes the instance's state as a VTK frame (what `hox simulate --vtk` writes) and reads it
/// back: one cell of the element's VTK type per element, the same cells and points.
fn check_vtk(instance: &Instance, dir: &std::path::Path, what: &str) {
    let et = instance.sim.mesh().blocks[0].element_type;
    let mut series = vtk::PvdSeries::create(dir, et.name()).unwrap();
    let path = instance.write_vtk_frame(&mut series).unwrap_or_else(|e| panic!("{what}: {e}"));
    let back = vtk::read_vtu(&path).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mesh = instance.sim.mesh();
    assert_eq!(back.cells.len(), mesh.num_elements(), "{what}");
    for (cell_type, nodes) in &back.cells {
        assert_eq!((*cell_type, nodes.len()), (et.vtk_cell_type(), et.num_nodes()), "{what}");
        assert_eq!(vtk::element_type_of_vtk(*cell_type), Some(et), "{what}");
    }
    let as_mesh = back.to_mesh().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(as_mesh.blocks, mesh.blocks, "{what}: the same cells in Gmsh order");
    assert_eq!(as_mesh.rest_positions, instance.sim.positions, "{what}: the points are the positions");
    let stress = &back.cell_data["von_mises_stress_pa"].values;
    assert!(stress.len() == mesh.num_elements() && stress.iter().all(|s| s.is_finite()), "{what}");
}

/// `mesh` as MSH 2.2 text: its nodes; its elements by their Gmsh type in physical group "body";
/// and the nodes at x = 0 as points in physical group "clamp".
fn msh22(mesh: &Mesh) -> String {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    s += "$PhysicalNames\n2\n0 1 \"clamp\"\n3 2 \"body\"\n$EndPhysicalNames\n";
    s += &format!("$Nodes\n{}\n", mesh.num_nodes());
    for (i, p) in mesh.rest_positions.iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p.x, p.y, p.z);
    }
    let clamp = mesh.nodes_where(|p| p.x == 0.0);
    let mut lines = Vec::new();
    for b in &mesh.blocks {
        for el in b.elements() {
            let nodes: Vec<String> = el.iter().map(|n| (n + 1).to_string()).collect();
            lines.push(format!("{} 2 2 1 {}", b.element_type.gmsh_type(), nodes.join(" ")));
        }
    }
    lines.extend(clamp.iter().map(|n| format!("15 2 1 1 {}", n + 1)));
    s += &format!("$EndNodes\n$Elements\n{}\n", lines.len());
    for (k, line) in lines.iter().enumerate() {
        s += &format!("{} {line}\n", k + 1);
    }
    s + "$EndElements\n"
}

/// The box mesh written as a Gmsh file reads back as the same mesh, and a mesh-file scene on it
/// (what `hox simulate --mesh FILE --clamp clamp` runs) sags under gravity.
fn check_gmsh(mesh: &Mesh, dir: &std::path::Path, what: &str) {
    let et = mesh.blocks[0].element_type;
    let text = msh22(mesh);
    let imported = gmsh::read_msh_str(&text, what).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(imported.mesh, *mesh, "{what}: the same nodes and elements");
    assert_eq!(imported.node_set("clamp").unwrap(), mesh.nodes_where(|p| p.x == 0.0).as_slice(), "{what}");
    let path: PathBuf = dir.join(format!("{}.msh", et.name()));
    std::fs::write(&path, text).unwrap();
    let scene = Scene::from_mesh_file(&path, &["clamp".into()], &[], true).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(scene.mesh.element_names(), et.name());
    let mut instance = Instance::new(scene).unwrap_or_else(|e| panic!("{what}: {e}"));
    for _ in 0..3 {
        instance.sim.step_frame().unwrap_or_else(|e| panic!("{what}: {e}"));
    }
    assert!(all_finite(&instance.sim.positions), "{what}");
    let far = mesh.nodes_where(|p| p.x == 2.0);
    let sag: f64 = far.iter().map(|&n| instance.sim.positions[n as usize].z - mesh.rest_positions[n as usize].z).sum();
    assert!(sag < 0.0, "{what}: the free end moved {sag} m");
}

/// Every registered element type with every registered material model, both sweeps (serial, and
/// parallel colour by colour) and both formulations (the energy formulation's specialised sweep
/// where there is one, the generic kernels otherwise and for the split formulation): the
/// bending scene's box meshes with the element type, steps and sags; then, per element type,
/// its display surface covers the box, its VTK cells read back, and its Gmsh file reads back and
/// runs as a mesh-file scene.
#[test]
fn every_registered_element_and_material_meshes_steps_and_exports() {
    let dir = std::env::temp_dir().join(format!("hox-registries-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for et in ElementType::all() {
        let mut last = None;
        for &model in MaterialModel::ALL {
            for formulation in Formulation::ALL {
                for parallel in [false, true] {
                    let what = format!("{et} {model} {formulation} {}", if parallel { "parallel" } else { "serial" });
                    let built = Instance::new(bending(et, model, parallel, formulation));
                    // the mixed formulation runs the tetrahedra and the high orders with stvk or nh
                    // under XPBD (the scene's solver; P1 with its node patches' pressures), and
                    // refuses the rest (Q1, the prism, the pyramid; the other models) by name
                    let inf_sup = et.order() >= 2 || et.shape() == ReferenceShape::Tetrahedron;
                    if formulation == Formulation::Mixed && (!inf_sup || !["stvk", "nh"].contains(&model.name())) {
                        let refused = built.err().unwrap_or_else(|| panic!("{what}: not refused")).to_string();
                        assert!(refused.contains("mixed formulation"), "{what}: {refused}");
                        continue;
                    }
                    let mut instance = built.unwrap_or_else(|e| panic!("{what}: {e}"));
                    let mesh = instance.sim.mesh();
                    assert!(mesh.blocks.len() == 1 && mesh.blocks[0].element_type == et, "{what}: a box of {et}");
                    assert_eq!(instance.sim.material().model, model, "{what}");
                    steps_and_sags(&mut instance, &what);
                    last = Some(instance);
                }
            }
        }
        let instance = last.expect("a registered material");
        let mesh = instance.sim.mesh();
        check_surface(mesh, &instance.sim.positions, et.name());
        check_vtk(&instance, &dir, et.name());
        check_gmsh(mesh, &dir, et.name());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
