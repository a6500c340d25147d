use super::*;
use crate::element::ElementType;
use crate::fem::energy::mixed::patch;
use crate::material::{MaterialModel, VolumeMeasure};
use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

/// A 3×2×2 box of five tetrahedra per cell, and a deformed state of it (a stretch, a shear and a
/// wobble of every node).
fn deformed_box() -> (Mesh, Vec<BlockGeometry>, Vec<Vec3>) {
    let mesh = BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(0.6, 0.4, 0.4), cells: [3, 2, 2] },
        element_type: ElementType::from_name("p1").unwrap(),
        split: TetSplit::Five,
        refine: 0,
    }
    .build()
    .unwrap();
    let geometry = crate::fem::geometry::precompute(&mesh, None).unwrap();
    let x = mesh
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let k = i as f64;
            Vec3::new(1.1 * p.x + 0.2 * p.y, 0.95 * p.y - 0.1 * p.z, p.z + 0.3 * p.x * p.y)
                + 0.01 * Vec3::new((1.3 * k).sin(), (2.1 * k).cos(), (0.7 * k).sin())
        })
        .collect();
    (mesh, geometry, x)
}

/// StVK and Neo-Hookean at ν = 0.45, measured per element (per node patch on P1).
fn materials() -> Vec<Material> {
    [MaterialModel::StVenantKirchhoff, MaterialModel::NeoHookean]
        .into_iter()
        .map(|m| Material::new(m, 1.0e5, 0.45, 1000.0).unwrap().with_volume_measure(VolumeMeasure::Element).unwrap())
        .collect()
}

fn input<'a>(mesh: &'a Mesh, geometry: &'a [BlockGeometry], material: &'a Material, w: &'a [f64]) -> PatchInput<'a> {
    PatchInput { mesh, geometry, material, inv_mass: w, inv_dt2: 3600.0 }
}

#[test]
fn every_node_has_one_patch_and_patches_of_one_colour_share_no_node() {
    let (mesh, geometry, _) = deformed_box();
    let patches = Patches::new(&mesh, &geometry, &materials()[0]).unwrap();
    assert_eq!(patches.len(), mesh.num_nodes());
    let mut seen = vec![0; patches.len()];
    for colour in &patches.colours {
        let mut owner = vec![false; mesh.num_nodes()];
        for &p in colour {
            seen[p as usize] += 1;
            for &i in patches.nodes(p as usize) {
                assert!(!owner[i as usize], "node {i} in two patches of one colour");
                owner[i as usize] = true;
            }
        }
    }
    assert!(seen.iter().all(|&s| s == 1));
    // a patch is the node and its neighbours through the elements around it
    let centre = patches.centre[7] as usize;
    assert!(patches.nodes(7).contains(&(centre as u32)));
    // the pointwise measure has no patches
    let plain = materials()[0].with_volume_measure(VolumeMeasure::Point).unwrap();
    assert!(Patches::new(&mesh, &geometry, &plain).is_none());
}

/// Checks the gradient of patch term `term` (0: the hydrostatic `C_a`, 1: the deviatoric `U_a`)
/// against central finite differences on a few patches of the deformed box, after `nonzero`
/// holds for its value.
fn term_gradient_matches_finite_differences(term: usize, nonzero: impl Fn(f64) -> bool, what: &str) {
    let (mesh, geometry, x) = deformed_box();
    let w = vec![1.0; mesh.num_nodes()];
    for material in materials() {
        let patches = Patches::new(&mesh, &geometry, &material).unwrap();
        let input = input(&mesh, &geometry, &material, &w);
        // the term's value and its gradient at the patch positions `xs`
        let eval = |p: usize, xs: &[Vec3]| {
            let mut grads = [vec![Vec3::zeros(); xs.len()], vec![Vec3::zeros(); xs.len()]];
            let [gh, gd] = &mut grads;
            let values = patches.terms(p, &input, xs, gh, gd);
            let [gh, gd] = grads;
            if term == 0 { (values.0, gh) } else { (values.1, gd) }
        };
        for p in [0, 5, 17, patches.len() - 1] {
            let xp: Vec<Vec3> = patches.nodes(p).iter().map(|&i| x[i as usize]).collect();
            let (value, grad) = eval(p, &xp);
            assert!(nonzero(value), "the deformed patch has {what}: {value}");
            let scale = grad.iter().map(|g| g.amax()).fold(0.0, f64::max);
            let h = 1e-6;
            for d in 0..3 * xp.len() {
                let at = |s: f64| {
                    let mut xs = xp.clone();
                    xs[d / 3][d % 3] += s;
                    eval(p, &xs).0
                };
                let fd = (at(h) - at(-h)) / (2.0 * h);
                assert!((fd - grad[d / 3][d % 3]).abs() < 1e-6 * scale, "patch {p}, dof {d}: {fd} vs {grad:?}");
            }
        }
    }
}

/// The deviatoric term at the averaged `F̄_a`: its gradient matches finite differences.
#[test]
fn the_patch_deviatoric_gradient_matches_finite_differences() {
    term_gradient_matches_finite_differences(1, |u| u > 0.0, "a deviatoric energy");
}

#[test]
fn the_patch_constraint_gradient_matches_finite_differences() {
    term_gradient_matches_finite_differences(0, |c| c.abs() > 1e-3, "a volume change");
}

/// The constraints' potential, every element's `β V_e ψ_d` plus every patch's `C_a²/(2α_a) +
/// D_a²/2`, is the patch energy of the static and Newton solvers: XPBD settles where they do.
#[test]
fn the_constraints_potential_is_the_patch_energy() {
    let (mesh, geometry, x) = deformed_box();
    let w = vec![1.0; mesh.num_nodes()];
    for material in materials() {
        let patches = Patches::new(&mesh, &geometry, &material).unwrap();
        let input = input(&mesh, &geometry, &material, &w);
        let block = &mesh.blocks[0];
        let deviatoric: f64 = block
            .elements()
            .enumerate()
            .map(|(e, nodes)| {
                let (mut xl, mut rest, mut g) = ([Vec3::zeros(); 4], [Vec3::zeros(); 4], [Vec3::zeros(); 4]);
                gather(&x, nodes, &mut xl);
                gather(&mesh.rest_positions, nodes, &mut rest);
                crate::fem::energy::mixed::deviatoric_energy_and_gradient(
                    &xl,
                    &rest,
                    element_grads(&geometry[0], e),
                    geometry[0].volumes(e),
                    &material,
                    &mut g,
                )
            })
            .sum();
        let potential = ELEMENT_DEVIATORIC_SHARE * deviatoric + patches.potential_j(&input, &x);
        let energy = patch::energy_and_gradient(&mesh, &geometry, &material, &x, None);
        assert!((potential / energy - 1.0).abs() < 1e-12, "{:?}: {potential} J vs {energy} J", material.model);
    }
}

/// One sweep lowers the patch constraints' potential, leaves pinned nodes where they are and
/// gives the same positions whatever the thread count.
#[test]
fn a_sweep_lowers_the_patch_potential_keeps_pins_and_does_not_depend_on_threads() {
    let (mesh, geometry, x) = deformed_box();
    let material = materials()[1];
    let mut w = vec![1.0; mesh.num_nodes()];
    let pinned = mesh.nodes_where(|p| p.x < 1e-12);
    for &i in &pinned {
        w[i as usize] = 0.0;
    }
    let patches = Patches::new(&mesh, &geometry, &material).unwrap();
    let input = input(&mesh, &geometry, &material, &w);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (mut y, mut lambdas) = (x.clone(), vec![0.0; 2 * patches.len()]);
            let projected = patches.sweep(&input, &mut y, &mut lambdas).unwrap();
            assert_eq!(projected, patches.len());
            y
        })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one, two, "the sweep depends on the thread count");
    // the hydrostatic and deviatoric terms solved together: their potential falls (the volume
    // change alone need not: the deformed box's shear dominates, and its projection moves the
    // volumes of the neighbouring patches)
    let potential = |y: &[Vec3]| patches.potential_j(&input, y);
    assert!(potential(&one) < 0.9 * potential(&x), "{} J → {} J", potential(&x), potential(&one));
    for &i in &pinned {
        assert_eq!(one[i as usize], x[i as usize]);
    }
}
