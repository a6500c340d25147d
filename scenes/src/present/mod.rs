//! Presentation: how hox shows numbers — the colour map and colour ranges ([`colour`]) and the
//! SVG drawing of figures and charts ([`svg`]). The lab's figures (`hox paper`, `hox study`) and
//! the app (its viewport, recordings and charts) use it; it knows no scene. Its files, lowest
//! first: `colour` → `svg`. This file is its front: `mod` lines only.

pub mod colour;
pub mod svg;
