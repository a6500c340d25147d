//! The room-order checker (`tests/tests/rooms.rs`): a crate's rooms — its top-level modules,
//! `src/NAME.rs` or `src/NAME/` — use each other in one stated order of layers: a room may use
//! the rooms of the layers before its own, never one of a later layer nor another of its own layer.
//! A room may also state an order of its own files (hox-sim's `solver/`, hox-scenes' `lab/` and
//! `present/`, the app's `gui/`), checked the same way, where a file must name the file it uses,
//! not the room's re-export; the room's front (`mod.rs`) is `mod` in that order when it holds
//! code its files use ([`violations`] says how a front is treated).
//!
//! A use is a path through `crate::`, `super::` (any number) or `self::`, anywhere in the code —
//! in `use` lines, grouped (`crate::{ROOM::…, …}`), or inline — resolved against the file's own
//! module path; in a front, a bare path to one of its own modules (`scene::Scene` in `lib.rs`)
//! too. The root (`lib.rs`, `main.rs`) is the crate's front, declaring the rooms, re-exporting and
//! holding the few items all share; its own `mod`/`pub use` lines are not uses. A path to an item
//! the root re-exports (`crate::Instance`, where `lib.rs` has `pub use instance::Instance`) is a
//! use of the room that defines it; a path to an item the root defines itself (`crate::Vec3`) names
//! no room. Comments (`//`, `//!`, `///`, `/* */`), strings, characters, test files (`tests.rs`,
//! `*_tests.rs`, `testing.rs`) and inline `#[cfg(test)] mod … { … }` modules are not counted.

use std::path::{Path, PathBuf};

/// A stated order: a crate's source folder and its layers, lowest first.
pub struct Order<'a> {
    /// The crate's folder under the workspace (`sim`, `scenes`, `app`).
    pub crate_dir: &'a str,
    pub layers: &'a [&'a [&'a str]],
    /// The rooms whose files have an order of their own: (room, files' layers), where `mod`
    /// ([`FRONT`]) is the room's front when it holds code its files use.
    pub files_of: &'a [(&'a str, &'a [&'a [&'a str]])],
}

/// The order as the docs write it: "`a`, `b` → `c` → …".
pub fn order_text(layers: &[&[&str]]) -> String {
    let layer = |rooms: &&[&str]| rooms.iter().map(|r| format!("`{r}`")).collect::<Vec<_>>().join(", ");
    layers.iter().map(layer).collect::<Vec<_>>().join(" → ")
}

fn layer_of(layers: &[&[&str]], name: &str) -> Option<usize> {
    layers.iter().position(|rooms| rooms.contains(&name))
}

/// The workspace's folder (the parent of `tests/`).
pub fn workspace_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `.rs` file under `dir`, relative to it with `/`, sorted.
pub fn rust_files(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                walk(root, &path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).expect("under the root");
                out.push(rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Test files and folders are not rooms' code.
pub fn is_test_file(rel: &str) -> bool {
    let name = rel.rsplit('/').next().unwrap_or(rel).trim_end_matches(".rs");
    name == "tests" || name.ends_with("_tests") || name == "testing" || rel.split('/').any(|p| p == "tests")
}

/// The module path of a file relative to `src/` (`solver/vbd/coarse.rs` → solver, vbd, coarse).
pub fn module_path(rel: &str) -> Vec<String> {
    let mut parts: Vec<String> = rel.split('/').map(String::from).collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// `src` with its comments, strings, character literals and inline test modules blanked
/// (newlines kept), so that what is left is code and every character keeps its line.
pub fn code_only(src: &str) -> Vec<char> {
    let s: Vec<char> = src.chars().collect();
    let mut out = s.clone();
    let blank = |out: &mut Vec<char>, from: usize, to: usize| {
        for c in &mut out[from..to.min(s.len())] {
            if *c != '\n' {
                *c = ' ';
            }
        }
    };
    let at = |i: usize| s.get(i).copied().unwrap_or('\0');
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        if c == '/' && at(i + 1) == '/' {
            let end = (i..s.len()).find(|&j| s[j] == '\n').unwrap_or(s.len());
            blank(&mut out, i, end);
            i = end;
        } else if c == '/' && at(i + 1) == '*' {
            let (mut depth, mut j) = (1, i + 2);
            while j < s.len() && depth > 0 {
                if s[j] == '/' && at(j + 1) == '*' {
                    depth += 1;
                    j += 2;
                } else if s[j] == '*' && at(j + 1) == '/' {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if c == 'r'
            && (i == 0 || !is_ident(s[i - 1]) || (s[i - 1] == 'b' && (i < 2 || !is_ident(s[i - 2]))))
            && {
                let hashes = (i + 1..s.len()).take_while(|&j| s[j] == '#').count();
                at(i + 1 + hashes) == '"'
            }
        {
            // a raw string: r"…", r#"…"#, br"…"
            let hashes = (i + 1..s.len()).take_while(|&j| s[j] == '#').count();
            let mut j = i + 2 + hashes;
            while j < s.len() && !(s[j] == '"' && (1..=hashes).all(|h| at(j + h) == '#')) {
                j += 1;
            }
            let end = j + 1 + hashes;
            blank(&mut out, i, end);
            i = end;
        } else if c == '"' {
            let mut j = i + 1;
            while j < s.len() && s[j] != '"' {
                j += if s[j] == '\\' { 2 } else { 1 };
            }
            blank(&mut out, i, j + 1);
            i = j + 1;
        } else if c == '\'' && at(i + 1) == '\\' {
            // an escaped character: '\n', '\'', '\u{…}'
            let end = (i + 3..s.len()).find(|&j| s[j] == '\'').unwrap_or(s.len());
            blank(&mut out, i, end + 1);
            i = end + 1;
        } else if c == '\'' && at(i + 2) == '\'' {
            blank(&mut out, i, i + 3);
            i += 3;
        } else {
            // code, or a lifetime's quote
            i += 1;
        }
    }
    blank_test_modules(&mut out);
    out
}

/// Blanks every inline test module, `#[cfg(test)] mod NAME { … }` up to its closing brace, in
/// code whose comments and strings are already blank (so every brace left is code's).
fn blank_test_modules(code: &mut [char]) {
    const ATTR: [char; 12] = ['#', '[', 'c', 'f', 'g', '(', 't', 'e', 's', 't', ')', ']'];
    let mut i = 0;
    while i + ATTR.len() <= code.len() {
        if !code[i..].starts_with(&ATTR) {
            i += 1;
            continue;
        }
        let mut j = i + ATTR.len();
        while j < code.len() && code[j].is_whitespace() {
            j += 1;
        }
        let is_mod = code[j..].starts_with(&['m', 'o', 'd', ' ']);
        let brace = (j..code.len()).find(|&k| code[k] == '{' || code[k] == ';');
        match brace {
            Some(k) if is_mod && code[k] == '{' => {
                let mut depth = 0;
                let mut end = k;
                while end < code.len() {
                    match code[end] {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        _ => {}
                    }
                    end += 1;
                }
                let stop = (end + 1).min(code.len());
                for c in &mut code[i..stop] {
                    if *c != '\n' {
                        *c = ' ';
                    }
                }
                i = end + 1;
            }
            _ => i += ATTR.len(),
        }
    }
}

/// One use: the line (1-based) and the absolute module path named (`["solver", "step", …]`).
#[derive(Debug, PartialEq)]
pub struct Use {
    pub line: usize,
    pub path: Vec<String>,
}

/// The paths `src`'s code names through `crate::`, `super::` and `self::`, resolved from the
/// module `module`; each member of a group (`crate::{a::B, c}`) is one path. With `front`
/// (the crate root or a room's `mod.rs`), `mod` and `pub use` lines are skipped.
pub fn uses(src: &str, module: &[String], front: bool) -> Vec<Use> {
    uses_in(src, module, front, &[])
}

/// [`uses`], and in a front also the bare paths to its own `children` (`window::Panel` in
/// `gui/mod.rs`, `scene::EffectSpec` in `lib.rs`): a module names its children without
/// `self::`, so a front with code reaches its files that way.
pub fn uses_in(src: &str, module: &[String], front: bool, children: &[&str]) -> Vec<Use> {
    let mut code = code_only(src);
    if front {
        // blank `mod …;` and `pub use …;` statements: declarations and re-exports
        let text: String = code.iter().collect();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let t = line.trim_start();
            if t.starts_with("mod ") || t.starts_with("pub mod ") || t.starts_with("pub use ") {
                let start = offset + line.chars().count() - t.chars().count();
                let mut j = start;
                while j < code.len() && code[j] != ';' {
                    if code[j] != '\n' {
                        code[j] = ' ';
                    }
                    j += 1;
                }
            }
            offset += line.chars().count();
        }
    }
    let line_at = |i: usize| 1 + code[..i].iter().filter(|&&c| c == '\n').count();
    let path_at = |mut i: usize| -> (Vec<String>, usize) {
        // idents joined by `::`, stopping before a `{`
        let mut segs = Vec::new();
        loop {
            let name: String = code[i..].iter().take_while(|&&c| is_ident(c)).collect();
            if name.is_empty() {
                break;
            }
            i += name.chars().count();
            segs.push(name);
            if code.get(i) == Some(&':')
                && code.get(i + 1) == Some(&':')
                && code.get(i + 2).is_some_and(|&c| is_ident(c))
            {
                i += 2;
            } else {
                break;
            }
        }
        (segs, i)
    };
    let mut found = Vec::new();
    let mut i = 0;
    while i < code.len() {
        let starts = |w: &str| code[i..].iter().take(w.len()).copied().eq(w.chars());
        let boundary = i == 0 || !(is_ident(code[i - 1]) || code[i - 1] == ':' || code[i - 1] == '$');
        let prefix = ["crate::", "super::", "self::"].into_iter().find(|p| starts(p));
        let bare = || {
            let name: String = code[i..].iter().take_while(|&&c| is_ident(c)).collect();
            let after = i + name.chars().count();
            (i == 0 || code[i - 1] != '.')
                && children.contains(&name.as_str())
                && code.get(after) == Some(&':')
                && code.get(after + 1) == Some(&':')
        };
        let prefix = match prefix {
            Some(p) => Some(p),
            None if front && boundary && bare() => Some(""),
            None => None,
        };
        let (Some(prefix), true) = (prefix, boundary) else {
            i += 1;
            continue;
        };
        // the base module: the crate root, the parent for each `super`, or this module
        let mut base: Vec<String> = match prefix {
            "crate::" => Vec::new(),
            _ => module.to_vec(),
        };
        let mut j = i + prefix.len();
        if prefix == "super::" {
            base.pop();
            while code[j..].iter().take(7).copied().eq("super::".chars()) {
                base.pop();
                j += 7;
            }
        }
        let line = line_at(i);
        if code.get(j) == Some(&'{') {
            // a group: each top-level member's leading path
            let (mut depth, mut k, mut item_start) = (0, j, true);
            while k < code.len() {
                match code[k] {
                    '{' => {
                        depth += 1;
                        if depth == 1 {
                            item_start = true;
                        }
                    }
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    ',' if depth == 1 => item_start = true,
                    c if item_start && depth == 1 && is_ident(c) => {
                        let (segs, end) = path_at(k);
                        if segs.first().is_some_and(|s| s != "self") {
                            let mut p = base.clone();
                            p.extend(segs);
                            found.push(Use { line, path: p });
                        }
                        item_start = false;
                        k = end;
                        continue;
                    }
                    _ => {}
                }
                k += 1;
            }
            i = k + 1;
        } else {
            let (segs, end) = path_at(j);
            let mut p = base;
            p.extend(segs);
            found.push(Use { line, path: p });
            i = end.max(j);
        }
    }
    found
}

/// The names a front (`lib.rs`, `main.rs`, a room's `mod.rs`) brings in with `use`: each item
/// as (the name it is known by, the path it names from the front's module, a leading `crate::` or
/// `self::` dropped), groups and `as` unfolded (`pub use run::{run as go, Settler}` → `go` ↦
/// `run::run`, `Settler` ↦ `run::Settler`); globs name nothing. A `pub use` re-exports; a private
/// `use` is seen by the front's own modules all the same (`super::Session` in `gui/figure.rs`).
pub fn front_names(src: &str) -> Vec<(String, Vec<String>)> {
    #[derive(PartialEq)]
    enum Tok {
        Ident(String),
        Sep,
        Open,
        Close,
        Comma,
        Other,
    }
    fn tree(toks: &[Tok], i: &mut usize, prefix: &[String], out: &mut Vec<(String, Vec<String>)>) {
        let mut path = prefix.to_vec();
        loop {
            match toks.get(*i) {
                Some(Tok::Ident(name)) => {
                    *i += 1;
                    if toks.get(*i) == Some(&Tok::Sep) {
                        path.push(name.clone());
                        *i += 1;
                        continue;
                    }
                    let mut known_as = name.clone();
                    if name == "self" {
                        known_as = path.last().cloned().unwrap_or_default();
                    } else {
                        path.push(name.clone());
                    }
                    if toks.get(*i) == Some(&Tok::Ident("as".into())) {
                        if let Some(Tok::Ident(alias)) = toks.get(*i + 1) {
                            known_as = alias.clone();
                        }
                        *i += 2;
                    }
                    if matches!(path.first().map(String::as_str), Some("crate" | "self")) {
                        path.remove(0);
                    }
                    if !known_as.is_empty() && known_as != "_" {
                        out.push((known_as, path));
                    }
                    return;
                }
                Some(Tok::Open) => {
                    *i += 1;
                    while *i < toks.len() && toks[*i] != Tok::Close {
                        tree(toks, i, &path, out);
                        while *i < toks.len() && !matches!(toks[*i], Tok::Comma | Tok::Close) {
                            *i += 1;
                        }
                        if toks.get(*i) == Some(&Tok::Comma) {
                            *i += 1;
                        }
                    }
                    *i += 1;
                    return;
                }
                _ => return,
            }
        }
    }
    let code = code_only(src);
    let mut out = Vec::new();
    let word_at = |k: usize, w: &str| {
        code[k..].iter().take(w.len()).copied().eq(w.chars())
            && (k == 0 || !is_ident(code[k - 1]))
            && !code.get(k + w.len()).is_some_and(|&c| is_ident(c))
    };
    for k in 0..code.len() {
        if !word_at(k, "use") {
            continue;
        }
        let mut toks = Vec::new();
        let mut j = k + 3;
        while j < code.len() && code[j] != ';' {
            let c = code[j];
            if is_ident(c) {
                let name: String = code[j..].iter().take_while(|&&c| is_ident(c)).collect();
                j += name.chars().count();
                toks.push(Tok::Ident(name));
                continue;
            }
            match c {
                ':' if code.get(j + 1) == Some(&':') => {
                    toks.push(Tok::Sep);
                    j += 1;
                }
                '{' => toks.push(Tok::Open),
                '}' => toks.push(Tok::Close),
                ',' => toks.push(Tok::Comma),
                c if c.is_whitespace() => {}
                _ => toks.push(Tok::Other),
            }
            j += 1;
        }
        tree(&toks, &mut 0, &[], &mut out);
    }
    out
}

/// The name the files' order of a room gives its front (`ROOM/mod.rs` or `ROOM.rs`).
pub const FRONT: &str = "mod";

/// The uses against `order` in `files` (path relative to `src/`, text), one message each.
///
/// A path is first resolved through what the crate root brings in (its re-exports):
/// `crate::Instance`, where `lib.rs` has `pub use instance::Instance`, is a use of the room
/// `instance`, checked as `crate::instance::Instance`; an item the root defines itself names no
/// room. In a room with an order of its own files ([`Order::files_of`]) a file names the file it
/// uses, and a path to an item of the room's front is a use of the front, [`FRONT`] (`mod`):
/// - a pure front (`mod` lines and re-exports) is no file's dependency: a path through a name it
///   brings in (`pub use` or `use`) fails, naming the file to use instead;
/// - a front with code that files import from must be placed in the files' order as `mod`, and is
///   checked like any file there: low if the files build on it, last if it builds on them (then a
///   file using it is a back-arrow); unplaced, it is the room's top, and a use of its code fails.
///
/// The front's own uses of its files (`window::X`, no `self::` needed) count too.
pub fn violations(order: &Order<'_>, files: &[(String, String)]) -> Vec<String> {
    let dir = order.crate_dir;
    let room_names: Vec<&str> = order.layers.iter().flat_map(|l| l.iter().copied()).collect();
    let is_front_of = |rel: &str, room: &str| rel == format!("{room}/mod.rs") || rel == format!("{room}.rs");
    let root_items: Vec<(String, Vec<String>)> =
        files.iter().filter(|(rel, _)| rel == "lib.rs" || rel == "main.rs").flat_map(|(_, t)| front_names(t)).collect();
    // each ordered room: its files on disk and its front's re-exports
    let ordered: Vec<(&str, &[&[&str]], Vec<String>, Vec<(String, Vec<String>)>)> = order
        .files_of
        .iter()
        .map(|&(room, layers)| {
            let mut on_disk: Vec<String> = files
                .iter()
                .filter(|(rel, _)| !is_test_file(rel))
                .map(|(rel, _)| module_path(rel))
                .filter(|m| m.len() >= 2 && m[0] == room)
                .map(|m| m[1].clone())
                .collect();
            on_disk.sort();
            on_disk.dedup();
            let front = files.iter().filter(|(rel, _)| is_front_of(rel, room)).flat_map(|(_, t)| front_names(t));
            (room, layers, on_disk, front.collect())
        })
        .collect();
    let mut found = Vec::new();
    for (rel, text) in files {
        if is_test_file(rel) {
            continue;
        }
        let module = module_path(rel);
        let room = module.first().map_or("lib", |m| m.as_str());
        let room = if module.is_empty() { rel.trim_end_matches(".rs") } else { room };
        let Some(own) = layer_of(order.layers, room) else {
            found.push(format!("{dir}/src/{rel}: the room `{room}` is in no layer of the stated order — place it"));
            continue;
        };
        let front = module.len() <= 1 && (rel.ends_with("mod.rs") || !rel.contains('/'));
        let own_order = ordered.iter().find(|o| o.0 == room);
        let children: Vec<&str> = match (module.is_empty(), own_order) {
            (true, _) => room_names.clone(),
            (false, Some(o)) if front => o.2.iter().map(String::as_str).collect(),
            _ => Vec::new(),
        };
        let lines: Vec<&str> = text.lines().collect();
        let show = |line: usize| lines.get(line - 1).map_or("", |l| l.trim());
        for u in uses_in(text, &module, front, &children) {
            // through the root's re-exports: `crate::Item` is `crate::ROOM::…::Item`
            let mut path = u.path.clone();
            if let Some(first) = path.first().filter(|f| !room_names.contains(&f.as_str()))
                && let Some((_, target)) = root_items.iter().find(|(name, _)| name == first)
            {
                path.splice(0..1, target.iter().cloned());
            }
            let shown =
                if path == u.path { path.join("::") } else { format!("{} = {}", u.path.join("::"), path.join("::")) };
            let Some(used_room) = path.first().filter(|r| room_names.contains(&r.as_str())) else { continue };
            if used_room != room {
                let used = layer_of(order.layers, used_room).expect("a listed room");
                if used >= own {
                    let why =
                        if used == own { "is in the same layer of the order" } else { "comes later in the order" };
                    found.push(format!(
                        "{dir}/src/{rel}:{}: the room `{room}` uses `{used_room}` ({shown}), which {why}\n    {}",
                        u.line,
                        show(u.line)
                    ));
                }
                continue;
            }
            let Some((_, file_layers, on_disk, front_items)) = own_order else { continue };
            let here = module.get(1).map_or(FRONT, String::as_str);
            let Some(there) = path.get(1).map(String::as_str) else { continue };
            if there == here {
                continue;
            }
            let target = if on_disk.iter().any(|f| f == there) || layer_of(file_layers, there).is_some() {
                there
            } else if let Some((_, via)) = front_items.iter().find(|(name, _)| name == there) {
                found.push(format!(
                    "{dir}/src/{rel}:{}: `{shown}` reaches `{room}` through its front (`{room}/mod.rs` brings in `{}`); name the file\n    {}",
                    u.line,
                    via.join("::"),
                    show(u.line)
                ));
                continue;
            } else if layer_of(file_layers, FRONT).is_none() {
                found.push(format!(
                    "{dir}/src/{rel}:{}: `{shown}` reaches `{room}` through its front (`{room}/mod.rs`); name the file\n    {}",
                    u.line,
                    show(u.line)
                ));
                continue;
            } else {
                FRONT
            };
            if here == FRONT && layer_of(file_layers, FRONT).is_none() {
                continue; // an unplaced front is the room's top
            }
            let Some(own_file) = layer_of(file_layers, here) else {
                found.push(format!(
                    "{dir}/src/{rel}: the file `{here}` of `{room}` is in no layer of its order — place it"
                ));
                break;
            };
            let Some(used) = layer_of(file_layers, target) else {
                found.push(format!(
                    "{dir}/src/{rel}:{}: `{room}/{here}` uses `{target}` ({shown}), which is in no layer of the files' order — place it\n    {}",
                    u.line,
                    show(u.line)
                ));
                continue;
            };
            if used >= own_file {
                let what = if target == FRONT {
                    format!("`{FRONT}` (the front, `{room}/mod.rs`)")
                } else {
                    format!("`{target}`")
                };
                let why = if used == own_file {
                    "is in the same layer of the files' order"
                } else {
                    "comes later in the files' order"
                };
                found.push(format!(
                    "{dir}/src/{rel}:{}: `{room}/{here}` uses {what} ({shown}), which {why}\n    {}",
                    u.line,
                    show(u.line)
                ));
            }
        }
    }
    found
}

/// Reads `order`'s crate and returns its files (relative path, text).
pub fn read_crate(crate_dir: &str) -> Vec<(String, String)> {
    let src = workspace_dir().join(crate_dir).join("src");
    rust_files(&src)
        .into_iter()
        .map(|rel| {
            let text = std::fs::read_to_string(src.join(&rel)).unwrap_or_else(|e| panic!("cannot read {rel}: {e}"));
            (rel, text)
        })
        .collect()
}
