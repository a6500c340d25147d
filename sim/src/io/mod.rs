//! Mesh files: [`gmsh`] imports Gmsh `.msh` files (MSH 2.2 and 4.1) with their physical groups,
//! checking every element's `det J` at rest ([`crate::fem::geometry`]); [`vtk`] writes VTU/PVD
//! series for ParaView (displacements, von Mises stress) and reads its own VTU back.
//!
//! It reads meshes ([`crate::mesh`]) and the finite-element model ([`crate::fem`]); nothing below
//! it reads files.

pub mod gmsh;
pub mod vtk;
