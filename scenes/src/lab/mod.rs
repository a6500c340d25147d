//! The lab: what is done with scenes once loaded — measured, studied, reported, timed, taught.
//! Scene loading (`params`, `scene`, `instance`, `run`) never uses it. Its files, lowest first
//! (each uses only those before it; `tests/tests/rooms.rs` keeps the order):
//! - [`claim`] — what a lesson step's answer claims of its numbers, judged as measured;
//! - [`reference`] — what an error is measured against: committed, computed or own-mesh
//!   references, Richardson's estimates, the cache;
//! - [`study`] — the accuracy-versus-time study (`hox study`);
//! - [`paper`] — `hox paper`: the paper's three experiments, Table 1 and Figs. 1–3;
//! - [`bench`] — `hox bench`: the Table 1 cases timed;
//! - [`lesson`] — lessons: steps of scenes compared and measured (`hox lesson`, the app).
//!
//! This file is the lab's front: `mod` lines only. The crate root re-exports each file under its
//! own name (`hox_scenes::study`, …).

pub mod bench;
pub mod claim;
pub mod lesson;
pub mod paper;
pub mod reference;
pub mod study;
