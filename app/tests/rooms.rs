//! The app's rooms — its top-level modules, `app/src/NAME.rs` or `app/src/NAME/` — use each
//! other in one order ([`ORDER`], stated the same in docs/ARCHITECTURE.md): a room may use the
//! rooms of the layers before its own, never one of a later layer nor another of its own layer
//! (`cli` and `gui` share what both need through `config`). This test reads every `.rs` file
//! under `app/src/` as text and fails naming the file, line and path of each use against the
//! order.
//!
//! A use is a `crate::ROOM` path anywhere in the code (in `use` lines, grouped as
//! `crate::{ROOM::…, …}`, or inline), and `super::ROOM` in a room's own top file (`NAME.rs`,
//! `NAME/mod.rs`), where `super` is the crate root. Comments (`//`, `//!`, `///`, `/* */`),
//! strings and characters are not code and are skipped.

use std::path::{Path, PathBuf};

/// The rooms in their order, lowest first: each layer may use the layers before it. `main.rs`
/// declares the rooms and so comes last.
const ORDER: &[&[&str]] =
    &[&["colour", "output"], &["config"], &["display"], &["recording"], &["cli", "gui"], &["main"]];

/// The order as the docs write it: "`colour`, `output` → `config` → … → `main`".
fn order_text() -> String {
    let layer = |rooms: &&[&str]| rooms.iter().map(|r| format!("`{r}`")).collect::<Vec<_>>().join(", ");
    ORDER.iter().map(layer).collect::<Vec<_>>().join(" → ")
}

/// The layer of `room` in [`ORDER`].
fn layer(room: &str) -> Option<usize> {
    ORDER.iter().position(|rooms| rooms.contains(&room))
}

/// Every `.rs` file under `dir`, as paths relative to it (with `/`), sorted.
fn rust_files(dir: &Path) -> Vec<String> {
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

/// The room of a file (relative to `src/`): its first folder, or its name without `.rs`.
fn room_of(rel: &str) -> &str {
    let first = rel.split('/').next().unwrap_or(rel);
    first.strip_suffix(".rs").unwrap_or(first)
}

/// Whether a file is its room's top file, where `super` is the crate root.
fn is_room_top(rel: &str) -> bool {
    !rel.contains('/') || (rel.matches('/').count() == 1 && rel.ends_with("/mod.rs"))
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// `src` with its comments, strings and character literals blanked (newlines kept), so that the
/// text left is code and every character keeps its line and column.
fn code_only(src: &str) -> Vec<char> {
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
    out
}

/// One use of a room: the line (1-based) and the room named.
#[derive(Debug, PartialEq)]
struct Use {
    line: usize,
    room: String,
}

/// The rooms `src`'s code names: `crate::ROOM` (also each `ROOM` of a `crate::{…}` group) and,
/// with `super_is_root`, `super::ROOM`.
fn room_uses(src: &str, super_is_root: bool) -> Vec<Use> {
    let code = code_only(src);
    let line_at = |i: usize| 1 + code[..i].iter().filter(|&&c| c == '\n').count();
    let ident_at = |i: usize| code[i..].iter().take_while(|&&c| is_ident(c)).collect::<String>();
    let skip_space = |mut i: usize| {
        while i < code.len() && code[i].is_whitespace() {
            i += 1;
        }
        i
    };
    let mut uses = Vec::new();
    let prefixes: &[&str] = if super_is_root { &["crate::", "super::"] } else { &["crate::"] };
    for prefix in prefixes {
        let p: Vec<char> = prefix.chars().collect();
        for i in 0..code.len() {
            if !code[i..].starts_with(&p) || (i > 0 && (is_ident(code[i - 1]) || code[i - 1] == '$')) {
                continue;
            }
            let after = i + p.len();
            if code.get(after) == Some(&'{') {
                // a group: the first name of each item at its top level
                let (mut depth, mut j, mut item_start) = (0, after, true);
                while j < code.len() {
                    match code[j] {
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
                            let name = ident_at(j);
                            let end = skip_space(j + name.len());
                            // `crate::{self, …}` and a bare name (`crate::{f, …}`) are the root's
                            if name != "self" && code.get(end) == Some(&':') {
                                uses.push(Use { line: line_at(j), room: name.clone() });
                            }
                            item_start = false;
                            j += name.len();
                            continue;
                        }
                        _ => {}
                    }
                    j += 1;
                }
            } else {
                let name = ident_at(after);
                // `crate::NAME` without a further `::` names an item of the root (in main.rs)
                if !name.is_empty() && code.get(after + name.len()) == Some(&':') {
                    uses.push(Use { line: line_at(after), room: name });
                }
            }
        }
    }
    uses.sort_by_key(|u| u.line);
    uses
}

/// The uses against [`ORDER`] in `files` (path relative to `src/`, text), one message each.
fn violations(files: &[(String, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (rel, text) in files {
        let room = room_of(rel);
        let Some(own) = layer(room) else {
            found.push(format!("app/src/{rel}: the room `{room}` is not in ORDER (app/tests/rooms.rs) — place it"));
            continue;
        };
        let lines: Vec<&str> = text.lines().collect();
        for u in room_uses(text, is_room_top(rel)) {
            if u.room == room {
                continue;
            }
            // a name that is no room (e.g. `super::x` in a test module) is not a room's use
            let Some(used) = layer(&u.room) else { continue };
            if used >= own {
                let why = if used == own { "is in the same layer of the order" } else { "comes later in the order" };
                found.push(format!(
                    "app/src/{rel}:{}: the room `{room}` uses `{}`, which {why}\n    {}",
                    u.line,
                    u.room,
                    lines.get(u.line - 1).map_or("", |l| l.trim()),
                ));
            }
        }
    }
    found
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn every_room_uses_only_rooms_before_it() {
    let src = src_dir();
    let files: Vec<(String, String)> = rust_files(&src)
        .into_iter()
        .map(|rel| {
            let text = std::fs::read_to_string(src.join(&rel)).unwrap_or_else(|e| panic!("cannot read {rel}: {e}"));
            (rel, text)
        })
        .collect();
    assert!(files.iter().any(|(rel, _)| rel == "main.rs"), "no app/src/main.rs under {}", src.display());
    // the scanner sees the uses the order allows too (a scanner that finds nothing passes anything)
    let recording = &files.iter().find(|(rel, _)| rel == "recording.rs").expect("app/src/recording.rs").1;
    assert!(room_uses(recording, true).iter().any(|u| u.room == "display"), "recording.rs's use of display not found");
    let found = violations(&files);
    assert!(
        found.is_empty(),
        "{} use(s) against the room order {} (docs/ARCHITECTURE.md, `app/`; ORDER in app/tests/rooms.rs):\n{}",
        found.len(),
        order_text(),
        found.join("\n")
    );
}

#[test]
fn every_room_is_in_the_order_and_on_disk() {
    let mut on_disk: Vec<String> = rust_files(&src_dir()).iter().map(|rel| room_of(rel).to_string()).collect();
    on_disk.dedup();
    let mut in_order: Vec<String> = ORDER.iter().flat_map(|l| l.iter().map(|r| r.to_string())).collect();
    in_order.sort();
    on_disk.sort();
    assert_eq!(on_disk, in_order, "the rooms under app/src/ and those in ORDER differ");
}

#[test]
fn the_docs_state_the_same_order() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/ARCHITECTURE.md");
    let text = std::fs::read_to_string(&docs).unwrap_or_else(|e| panic!("cannot read {}: {e}", docs.display()));
    let order = order_text();
    assert!(text.contains(&order), "docs/ARCHITECTURE.md does not state the room order {order}");
}

#[test]
fn the_scanner_finds_uses_in_code_only() {
    let src = r##"//! A doc that names crate::gui::run.
use crate::config::MeshArgs;
use crate::{
    display::f32s,
    gui::{AppArgs, run},
    self,
};
/// crate::cli in a doc comment, /* and */ in a block: /* crate::cli */
fn f<'a>(x: &'a str) -> char {
    let _ = "crate::cli::run in a string";
    let _ = r#"crate::cli"#;
    crate::recording::format_metres(1.0);
    super::gui::run();
    '"'
}
"##;
    let rooms = |super_is_root| room_uses(src, super_is_root).into_iter().map(|u| (u.line, u.room)).collect::<Vec<_>>();
    let want = vec![(2, "config".to_string()), (4, "display".into()), (5, "gui".into()), (12, "recording".into())];
    assert_eq!(rooms(false), want);
    let mut with_super = want;
    with_super.insert(4, (13, "gui".into()));
    assert_eq!(rooms(true), with_super);
}

#[test]
fn a_use_against_the_order_is_named_with_its_file_and_line() {
    let files = vec![
        ("cli/record.rs".to_string(), "//! Recording.\n\nuse crate::gui::AppArgs;\n".to_string()),
        ("display.rs".to_string(), "fn f() {\n    crate::recording::format_metres(1.0);\n}\n".to_string()),
        ("gui/mod.rs".to_string(), "use super::cli::Command;\nuse crate::config::MeshArgs;\n".to_string()),
        ("extra.rs".to_string(), String::new()),
    ];
    let found = violations(&files);
    assert_eq!(found.len(), 4, "{found:#?}");
    assert!(found[0].starts_with("app/src/cli/record.rs:3: the room `cli` uses `gui`, which is in the same layer"));
    assert!(found[0].ends_with("use crate::gui::AppArgs;"), "{}", found[0]);
    assert!(found[1].starts_with("app/src/display.rs:2: the room `display` uses `recording`, which comes later"));
    assert!(found[2].starts_with("app/src/gui/mod.rs:1: the room `gui` uses `cli`"));
    assert!(found[3].contains("`extra` is not in ORDER"));
}
