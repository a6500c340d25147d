//! One configuration of a scene as the app's controls see it (every value resolved), and what a
//! change of it invalidates.

use hox_scenes::{Scene, SceneOverrides};
use serde::{Deserialize, Serialize};

/// Every live control of one simulation. Persisted across runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    pub element: String,
    /// `five` (unbiased) or `six` (biased) tetrahedra per cell.
    pub split: String,
    pub grid: [usize; 3],
    pub refine: usize,
    pub material: String,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub density_kg_m3: f64,
    pub formulation: String,
    /// None: each element type's default degree.
    pub quadrature_degree: Option<usize>,
    pub substeps: u32,
    pub iterations: u32,
    pub frames_per_second: f64,
    /// More substeps where the stiffest element needs them (`hox_sim::solver::stability`).
    #[serde(default = "guard_on")]
    pub stability_guard: bool,
}

fn guard_on() -> bool {
    true
}

/// How much of a running simulation a configuration change invalidates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Invalidates {
    Nothing,
    /// Solver settings: kept state, new time stepping (a quadrature change re-precomputes the
    /// element geometry).
    Settings,
    /// Material: kept positions and velocities, new constitutive law (and masses if ρ changed).
    Material,
    /// Mesh: element type, split, grid or refinement — the simulation is rebuilt from rest.
    Mesh,
}

impl Config {
    /// The values a validated scene resolves to.
    pub fn from_scene(scene: &Scene) -> Config {
        let s = &scene.settings;
        let m = &scene.material;
        let (element, split, grid, refine) = match scene.mesh.as_box() {
            Some(b) => (b.element_type.name().to_string(), b.split.name().to_string(), b.grid.cells, b.refine),
            None => (String::from("file"), String::from("five"), [1, 1, 1], 0),
        };
        Config {
            element,
            split,
            grid,
            refine,
            material: m.model.name().to_string(),
            youngs_modulus_pa: m.youngs_modulus_pa,
            poisson_ratio: m.poisson_ratio,
            density_kg_m3: m.density_kg_m3,
            formulation: s.formulation.name().to_string(),
            quadrature_degree: s.quadrature_degree,
            substeps: s.substeps,
            iterations: s.iterations,
            frames_per_second: s.frames_per_second,
            stability_guard: s.stability_guard,
        }
    }

    /// Whether the scene's mesh is a structured box (element, split, grid and refinement apply).
    pub fn is_box(&self) -> bool {
        self.element != "file"
    }

    pub fn overrides(&self) -> SceneOverrides {
        let boxed = self.is_box();
        SceneOverrides {
            element: boxed.then(|| self.element.clone()),
            grid: boxed.then_some(self.grid),
            split: boxed.then(|| self.split.clone()),
            refine: boxed.then_some(self.refine),
            material: Some(self.material.clone()),
            youngs_modulus_pa: Some(self.youngs_modulus_pa),
            poisson_ratio: Some(self.poisson_ratio),
            density_kg_m3: Some(self.density_kg_m3),
            formulation: Some(self.formulation.clone()),
            quadrature_degree: self.quadrature_degree,
            substeps: Some(self.substeps),
            iterations: Some(self.iterations),
            frames_per_second: Some(self.frames_per_second),
            parallel: None,
            stability_guard: Some(self.stability_guard),
        }
    }

    /// Validates this configuration of `base`: the scene it gives, or the reason it is refused.
    pub fn resolve(&self, base: &Scene) -> Result<Scene, String> {
        let mut o = self.overrides();
        // "use the element's default" must reset an explicit degree of the scene file
        if self.quadrature_degree.is_none() && base.file.solver.quadrature_degree.is_some() {
            o.quadrature_degree = None;
        }
        let mut scene = base.with_overrides(&o).map_err(|e| e.to_string())?;
        if self.quadrature_degree.is_none() {
            scene.settings.quadrature_degree = None;
        }
        Ok(scene)
    }

    /// What changing from `self` to `new` invalidates.
    pub fn invalidated_by(&self, new: &Config) -> Invalidates {
        if (&self.element, &self.split, self.grid, self.refine) != (&new.element, &new.split, new.grid, new.refine) {
            Invalidates::Mesh
        } else if (&self.material, self.youngs_modulus_pa, self.poisson_ratio, self.density_kg_m3)
            != (&new.material, new.youngs_modulus_pa, new.poisson_ratio, new.density_kg_m3)
        {
            Invalidates::Material
        } else if self != new {
            Invalidates::Settings
        } else {
            Invalidates::Nothing
        }
    }

    /// A short label, e.g. `P2 8×2×2 five`.
    pub fn label(&self) -> String {
        if !self.is_box() {
            return "mesh file".into();
        }
        let [x, y, z] = self.grid;
        let tets = ["p1", "p2", "p3"].contains(&self.element.as_str());
        let mut s = format!("{} {x}×{y}×{z}", self.element.to_uppercase());
        if tets {
            s += &format!(" {}", self.split);
            if self.refine > 0 {
                s += &format!(" r{}", self.refine);
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_invalidation() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let c = Config::from_scene(&scene);
        assert_eq!((c.element.as_str(), c.grid, c.substeps), ("p2", [8, 2, 2], 50));
        let again = Config::from_scene(&c.resolve(&scene).unwrap());
        assert_eq!(again, c);
        let mut e = c.clone();
        e.youngs_modulus_pa = 1e7;
        assert_eq!(c.invalidated_by(&e), Invalidates::Material);
        e.element = "q2".into();
        assert_eq!(c.invalidated_by(&e), Invalidates::Mesh);
        let mut s = c.clone();
        s.substeps = 10;
        assert_eq!(c.invalidated_by(&s), Invalidates::Settings);
        assert_eq!(c.invalidated_by(&c.clone()), Invalidates::Nothing);
    }

    #[test]
    fn bad_values_are_refused_with_the_reason() {
        let scene = hox_scenes::by_name("bending").unwrap();
        let mut c = Config::from_scene(&scene);
        c.poisson_ratio = 0.5;
        let reason = c.resolve(&scene).unwrap_err();
        assert!(reason.to_lowercase().contains("poisson"), "{reason}");
        let mut c = Config::from_scene(&scene);
        c.youngs_modulus_pa = -1.0;
        assert!(c.resolve(&scene).unwrap_err().to_lowercase().contains("young"));
        let mut c = Config::from_scene(&scene);
        c.element = "p7".into();
        assert!(c.resolve(&scene).is_err());
    }
}
