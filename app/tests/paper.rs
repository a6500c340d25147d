//! `hox paper --quick`, run as a researcher would: every file written, the figures' pictures
//! holding what their captions say they hold (the reference's outline in red, the field's
//! colours, a panel per case), PAPER.md checking the captions' claims, and a folder it cannot
//! write refused before any work.

use std::process::Command;

fn hox(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hox")).args(args).env_remove("RUST_BACKTRACE").output().expect("hox runs")
}

/// RGBA pixels of a PNG file.
fn pixels(path: &std::path::Path) -> (u32, u32, Vec<[u8; 4]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).expect("the PNG exists")));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buffer = vec![0; reader.output_buffer_size().expect("a size")];
    let info = reader.next_frame(&mut buffer).expect("one frame");
    assert_eq!(info.color_type, png::ColorType::Rgba, "{}", path.display());
    let data = &buffer[..info.buffer_size()];
    (info.width, info.height, data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
}

/// The reference's red (`#e00000`, give or take the antialiasing).
fn is_red(p: &[u8; 4]) -> bool {
    p[0] > 180 && p[1] < 60 && p[2] < 60
}

/// A colour of the viridis map away from its ends (neither grey, white, black nor red).
fn is_field_colour(p: &[u8; 4]) -> bool {
    let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
    let spread = r.max(g).max(b) - r.min(g).min(b);
    spread > 60 && g > r && !(r > 180 && g < 60)
}

#[test]
fn paper_quick_writes_the_table_the_figures_and_the_claims() {
    let out = std::env::temp_dir().join(format!("hox-paper-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = hox(&["paper", "--quick", "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "hox paper --quick failed: {err}");
    for figure in ["fig1-tension", "fig2-torsion", "fig3-bending"] {
        let svg = std::fs::read_to_string(out.join(format!("{figure}.svg"))).expect("the SVG");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{figure}: not a whole SVG");
        assert!(svg.contains(r##"stroke="#e00000""##), "{figure}: the reference is not drawn in red");
        let cells = svg.matches("<polygon").count() + svg.matches("<rect").count();
        assert!(cells > 100, "{figure}: only {cells} shapes: the field is not drawn");
        let (w, h, px) = pixels(&out.join(format!("{figure}.png")));
        assert!(w > 800 && h > 800, "{figure}: {w}×{h}");
        let red = px.iter().filter(|p| is_red(p)).count();
        let field = px.iter().filter(|p| is_field_colour(p)).count();
        let distinct: std::collections::BTreeSet<[u8; 4]> = px.iter().filter(|p| is_field_colour(p)).copied().collect();
        assert!(red > 2_000, "{figure}: {red} red pixels: the reference's outline is missing");
        assert!(field > px.len() / 10, "{figure}: {field} of {} pixels in the field's colours", px.len());
        assert!(distinct.len() > 30, "{figure}: only {} field colours: one flat colour is no field", distinct.len());
    }
    // one panel per case with its measure, the reference's without
    let torsion = std::fs::read_to_string(out.join("fig2-torsion.svg")).unwrap();
    for case in
        ["P1 2592 biased", "P2 324 biased", "P3 96 biased", "P1 2160 unbiased", "P2 270 unbiased", "P3 80 unbiased"]
    {
        assert!(torsion.contains(&format!(">{case}<")), "fig2: no panel {case}");
    }
    let paper = std::fs::read_to_string(out.join("PAPER.md")).expect("PAPER.md");
    for needle in [
        "| Fig. 1:",
        "| Fig. 2 (biased):",
        "| Fig. 2 (unbiased):",
        "| Fig. 3: the coarse P1 beam",
        "| P1 1280 | 425 | 1280 | 43.6 |",
        "| P2 160 | 393 | 160 | 20.9 |",
        "| P3 80 | 573 | 80 | 28.1 |",
        "Intel",
        "![fig2-torsion](fig2-torsion.png)",
    ] {
        assert!(
            paper.contains(needle) || (needle == "Intel" && paper.contains("logical cores")),
            "PAPER.md lacks '{needle}'"
        );
    }
    // every claim measured says whether it holds; the 81,920 beam is left out of --quick, and says so
    let claims = paper.lines().filter(|l| l.starts_with("| Fig.")).collect::<Vec<_>>();
    assert_eq!(claims.len(), 6, "{claims:#?}");
    assert!(
        claims.iter().all(|l| l.ends_with("| yes |") || l.ends_with("| **no** |") || l.ends_with("| not measured |"))
    );
    assert!(claims.iter().any(|l| l.contains("not run (--quick")), "{claims:#?}");
    let table = std::fs::read_to_string(out.join("table1.md")).expect("table1.md");
    assert!(table.contains("--quick"), "the quick table says it is quick");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn paper_refuses_a_folder_it_cannot_write_before_any_work() {
    let file = std::env::temp_dir().join(format!("hox-paper-not-a-folder-{}", std::process::id()));
    std::fs::write(&file, b"kept").unwrap();
    let target = file.join("out");
    let run = hox(&["paper", "--quick", "--out", target.to_str().unwrap()]);
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("cannot create the output folder"), "{err}");
    assert!(!err.contains("XPBD"), "work started before the folder was checked: {err}");
    assert_eq!(std::fs::read(&file).unwrap(), b"kept", "nothing already written is lost");
    let _ = std::fs::remove_file(&file);
}
