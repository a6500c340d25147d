use super::*;
use crate::element::ElementType;
use crate::material::MaterialModel;
use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

fn box_mesh(element: ElementType) -> Mesh {
    BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 1.0, 0.5), cells: [2, 1, 1] },
        element_type: element,
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap()
}

fn steel_like() -> Material {
    Material::new(MaterialModel::StVenantKirchhoff, 1.0e6, 0.3, 1000.0).unwrap()
}

/// Every element reproduces an affine motion `x = A X + c` exactly, so every display vertex of
/// every element type sees `F = A` — at corners, on edges, inside faces, at a pyramid's apex.
#[test]
fn an_affine_motion_gives_its_gradient_at_every_vertex_of_every_element_type() {
    let a = Matrix3::new(1.1, 0.05, 0.0, -0.02, 0.95, 0.03, 0.0, 0.04, 1.02);
    let c = Vec3::new(0.3, -0.1, 0.2);
    for et in ElementType::all() {
        let mesh = box_mesh(et);
        let surface = Surface::new(&mesh, 3);
        let grads = SurfaceGradients::new(&mesh, &surface);
        assert_eq!(grads.num_vertices(), surface.num_vertices(), "{et}");
        let x: Vec<Vec3> = mesh.rest_positions.iter().map(|p| a * p + c).collect();
        for v in 0..grads.num_vertices() {
            let fs = grads.deformation_gradients(v, &x, &mesh.rest_positions);
            assert!(!fs.is_empty(), "{et}: vertex {v} has no element");
            for f in fs {
                assert!((f - a).norm() < 1e-9, "{et}: vertex {v}: F = {f}");
            }
        }
        let mut det = Vec::new();
        grads.values_into(Field::DetF, &steel_like(), &x, &mesh.rest_positions, &mut det);
        assert!(det.iter().all(|d| (d - a.determinant()).abs() < 1e-9), "{et}");
    }
}

/// At rest every field is its neutral value: no stress, strain or energy, det F = 1.
#[test]
fn a_body_at_rest_has_no_stress_strain_or_energy() {
    let material = steel_like();
    for et in [ElementType::from_name("p2").unwrap(), ElementType::from_name("q2").unwrap()] {
        let mesh = box_mesh(et);
        let surface = Surface::new(&mesh, 2);
        let grads = SurfaceGradients::new(&mesh, &surface);
        for field in Field::ALL.into_iter().filter(|f| f.needs_gradient()) {
            let mut v = Vec::new();
            grads.values_into(field, &material, &mesh.rest_positions, &mesh.rest_positions, &mut v);
            assert!(v.iter().all(|x| (x - field.neutral()).abs() < 1e-12), "{et} {field}: {v:?}");
        }
    }
}

/// A small uniaxial stretch ε with the lateral contraction ν ε is uniaxial stress σ = E ε, so
/// σ_vM = E ε; the strain deviator of diag(ε, −νε, −νε) has e:e = ⅔ (1 + ν)² ε², so the
/// equivalent strain is ⅔ (1 + ν) ε (to first order in ε).
#[test]
fn a_small_uniaxial_stretch_gives_von_mises_e_epsilon() {
    let (e_pa, nu, eps) = (1.0e6, 0.3, 1e-5);
    let material = Material::new(MaterialModel::StVenantKirchhoff, e_pa, nu, 1000.0).unwrap();
    let f = Matrix3::from_diagonal(&Vec3::new(1.0 + eps, 1.0 - nu * eps, 1.0 - nu * eps));
    let vm = von_mises_pa(&material, &f);
    assert!((vm / (e_pa * eps) - 1.0).abs() < 1e-3, "σ_vM = {vm}, E ε = {}", e_pa * eps);
    let want = (2.0f64 / 3.0).sqrt() * (2.0f64 / 3.0).sqrt() * (1.0 + nu) * eps;
    let got = equivalent_strain(&f);
    assert!((got / want - 1.0).abs() < 1e-3, "strain {got} vs {want}");
    // a pure volume change has no deviatoric stress or strain
    let g = Matrix3::identity() * 1.01;
    assert!(equivalent_strain(&g) < 1e-15 && von_mises_pa(&material, &g) < 1e-6);
    // an inverted point has no stress
    assert!(von_mises_pa(&material, &Matrix3::from_diagonal(&Vec3::new(-1.0, 1.0, 1.0))).is_nan());
}

#[test]
fn field_names_round_trip_and_units_are_stated() {
    for f in Field::ALL {
        assert_eq!(Field::from_name(f.name()), Some(f));
        assert!(!f.title().is_empty() && !f.description().is_empty());
    }
    assert_eq!(Field::from_name("stress"), None);
    assert_eq!(Field::VonMises.unit(), "Pa");
    assert_eq!(Field::EnergyDensity.unit(), "J/m³");
    assert!(Field::names().contains("von-mises"));
}
