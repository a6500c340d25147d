//! The rooms of each crate in one stated order (docs/ARCHITECTURE.md): a room may use only the
//! rooms before it. The test reads every source file (not test files, nor inline `#[cfg(test)]`
//! modules), resolves each `crate::`, `super::` and `self::` path to the room it names, and fails
//! naming the file, the line and the import that runs against the order. Within the solver room
//! the same holds for its files, and a file of the room must name the file it uses, not the
//! room's re-export (`super::error::SimError`, not `super::SimError`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// hox-sim's rooms, bottom first. `lib` is the crate root's own items (`Vec3`).
const SIM_ROOMS: &[&str] =
    &["lib", "math", "element", "material", "mesh", "fem", "measure", "io", "xpbd", "effect", "solver"];

/// The files of `sim/src/solver/`, bottom first (`mod` is the room's front: declarations and
/// re-exports only).
const SOLVER_FILES: &[&str] = &[
    "method",
    "error",
    "settings",
    "nan_guard",
    "step",
    "residual",
    "sparse",
    "stability",
    "potential",
    "newton_core",
    "xpbd",
    "vbd",
    "newton",
    "statics",
    "registry",
    "simulation",
    "newmark",
];

/// hox-scenes' rooms, bottom first. `lib` is the crate root's own items: the scene registry
/// (`BUILTIN`, `by_name`), `Instance`, `SceneError`, `solve_static`.
const SCENES_ROOMS: &[&str] = &["params", "scene", "lib", "run", "reference", "study", "bench", "lesson"];

fn root(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(dir).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).expect("read source dir").map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Test files: `tests.rs`, `*_tests.rs`, `testing.rs` (helpers of tests), anything under `tests/`.
fn is_test_file(rel: &Path) -> bool {
    let name = rel.file_stem().unwrap().to_string_lossy();
    name == "tests" || name.ends_with("_tests") || name == "testing" || rel.components().any(|c| c.as_os_str() == "tests")
}

/// The module path of a file relative to `src/` (`solver/vbd/coarse.rs` → solver, vbd, coarse).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs");
    if stem != "mod" && stem != "lib" && stem != "main" {
        parts.push(stem.to_string());
    }
    parts
}

/// The lines that are code: comments cut, inline test modules and `pub use`/`mod` lines of a
/// room's front left out. Each with its line number.
fn code_lines(text: &str, front: bool) -> Vec<(usize, String)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim_start();
        if t.starts_with("#[cfg(test)]") {
            let next = lines.get(i + 1).map(|l| l.trim()).unwrap_or("");
            if next.starts_with("mod ") && next.ends_with('{') {
                break; // the inline test module closes the file
            }
            i += 2;
            continue;
        }
        let code = match t.find("//") {
            Some(k) => &t[..k],
            None => t,
        };
        let skip = front && (code.starts_with("pub use ") || code.starts_with("pub mod ") || code.starts_with("mod "));
        if !code.trim().is_empty() && !skip {
            out.push((i + 1, code.to_string()));
        }
        i += 1;
    }
    out
}

/// Every path a line names through `crate::`, `super::` or `self::`, resolved to an absolute
/// module path from `module`; a group `crate::{A, b::C}` gives one path per member.
fn paths_in(line: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let bytes = line.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(k) = line[from..].find(start) {
            let at = from + k;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_' || bytes[at - 1] == b':') {
                continue; // `foo::super::`, part of a longer path already seen
            }
            // read the whole path: idents and `::`, possibly `super::super::`
            let rest = &line[at..];
            let end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':')).unwrap_or(rest.len());
            let path_text = rest[..end].trim_end_matches(':');
            let mut segs: Vec<&str> = path_text.split("::").collect();
            let mut base: Vec<String> = match segs[0] {
                "crate" => Vec::new(),
                "self" => module.to_vec(),
                _ => {
                    let mut m = module.to_vec();
                    while segs.first() == Some(&"super") {
                        m.pop();
                        segs.remove(0);
                    }
                    segs.insert(0, "super");
                    m
                }
            };
            segs.remove(0);
            base.extend(segs.iter().filter(|s| !s.is_empty()).map(|s| s.to_string()));
            if rest[end..].starts_with('{') {
                let group_end = rest[end..].find('}').map(|e| end + e).unwrap_or(rest.len());
                for member in rest[end + 1..group_end].split(',') {
                    let member = member.trim();
                    if member.is_empty() {
                        continue;
                    }
                    let mut p = base.clone();
                    p.extend(member.split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty() && s != "self"));
                    found.push(p);
                }
            } else {
                found.push(base);
            }
        }
    }
    found
}

struct Violation(String);

/// Checks one crate: every file's references against `rooms` (bottom first), and the files of
/// `sub_room` against `sub_files`.
fn check_crate(dir: &str, rooms: &[&str], sub: Option<(&str, &[&str])>) -> (Vec<Violation>, usize) {
    let src = root(dir);
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let room_names: BTreeSet<&str> = rooms.iter().copied().filter(|r| *r != "lib").collect();
    let room_of = |path: &[String]| -> &str {
        match path.first() {
            Some(first) if room_names.contains(first.as_str()) => room_names.get(first.as_str()).unwrap(),
            _ => "lib",
        }
    };
    let index = |room: &str| rooms.iter().position(|r| *r == room).expect("a listed room");
    let mut violations = Vec::new();
    let mut checked = 0;
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        if is_test_file(rel) {
            continue;
        }
        checked += 1;
        let module = module_path(rel);
        let here = room_of(&module);
        let stem = rel.file_stem().unwrap().to_string_lossy();
        let front = stem == "mod" || stem == "lib";
        let text = std::fs::read_to_string(file).unwrap();
        for (line_no, code) in code_lines(&text, front) {
            for path in paths_in(&code, &module) {
                let there = room_of(&path);
                if there != here && index(there) > index(here) {
                    violations.push(Violation(format!(
                        "{dir}/src/{}:{line_no}: room `{here}` uses `{}` (room `{there}`, which comes after it in the order {rooms:?}): `{}`",
                        rel.display(),
                        path.join("::"),
                        code.trim()
                    )));
                }
                let Some((sub_room, sub_files)) = sub else { continue };
                if here != sub_room || there != sub_room || module.len() < 2 {
                    continue;
                }
                let file_here = module[1].as_str();
                let Some(file_there) = path.get(1).map(String::as_str) else { continue };
                if file_here == file_there {
                    continue;
                }
                let Some(i_there) = sub_files.iter().position(|f| *f == file_there) else {
                    violations.push(Violation(format!(
                        "{dir}/src/{}:{line_no}: `{}` reaches `{sub_room}` through its front (a re-export of `{sub_room}/mod.rs`); name the file: `{}`",
                        rel.display(),
                        path.join("::"),
                        code.trim()
                    )));
                    continue;
                };
                let i_here = sub_files.iter().position(|f| *f == file_here).unwrap_or_else(|| {
                    panic!("{dir}/src/{}: the file `{file_here}` is not in the stated order {sub_files:?}", rel.display())
                });
                if i_there > i_here {
                    violations.push(Violation(format!(
                        "{dir}/src/{}:{line_no}: `{file_here}` uses `{}` (`{file_there}`, which comes after it in the order {sub_files:?}): `{}`",
                        rel.display(),
                        path.join("::"),
                        code.trim()
                    )));
                }
            }
        }
    }
    (violations, checked)
}

fn assert_clean(dir: &str, rooms: &[&str], sub: Option<(&str, &[&str])>) {
    let (violations, checked) = check_crate(dir, rooms, sub);
    assert!(checked > 10, "{dir}: only {checked} source files found");
    let text: Vec<String> = violations.into_iter().map(|v| v.0).collect();
    assert!(text.is_empty(), "{} import(s) against the room order:\n{}", text.len(), text.join("\n"));
}

#[test]
fn sim_rooms_import_only_the_rooms_before_them() {
    assert_clean("sim", SIM_ROOMS, Some(("solver", SOLVER_FILES)));
}

#[test]
fn scenes_rooms_import_only_the_rooms_before_them() {
    assert_clean("scenes", SCENES_ROOMS, None);
}

#[test]
fn every_room_and_solver_file_on_disk_is_in_the_stated_order() {
    let listed = |dir: PathBuf, names: &[&str]| {
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter_map(|p| {
                let stem = p.file_stem()?.to_string_lossy().into_owned();
                (p.is_dir() || p.extension().is_some_and(|e| e == "rs")).then_some(stem)
            })
            .filter(|s| !matches!(s.as_str(), "lib" | "mod" | "tests") && !s.ends_with("_tests") && s != "testing")
            .collect();
        on_disk.sort();
        on_disk.dedup();
        for name in on_disk {
            assert!(names.contains(&name.as_str()), "{}/{name} is in no stated order {names:?}", dir.display());
        }
    };
    listed(root("sim"), SIM_ROOMS);
    listed(root("sim").join("solver"), SOLVER_FILES);
    listed(root("scenes"), SCENES_ROOMS);
}

/// The checker itself: an import against the order is found, with file and line, through
/// `crate::`, `super::` and a group.
#[test]
fn the_checker_finds_an_import_against_the_order() {
    let m = |s: &str| s.split('/').map(String::from).collect::<Vec<_>>();
    assert_eq!(paths_in("use crate::xpbd::kernels::F64x4;", &m("material/stvk")), vec![m("xpbd/kernels/F64x4")]);
    assert_eq!(paths_in("use super::newton::Potential;", &m("solver/vbd/coarse")), vec![m("solver/vbd/newton/Potential")]);
    assert_eq!(paths_in("use super::super::newton::Potential;", &m("solver/vbd/coarse")), vec![m("solver/newton/Potential")]);
    assert_eq!(paths_in("use crate::{Instance, run};", &m("study")), vec![m("Instance"), m("run")]);
    assert_eq!(
        code_lines("use a; // crate::x\n#[cfg(test)]\nmod tests {\nuse crate::y;\n}", false),
        vec![(1, "use a; ".to_string())]
    );
}
