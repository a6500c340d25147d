//! Packs the Rerun web viewer's files (the pre-built WebAssembly viewer of the
//! `re_web_viewer_server` crate, version 0.36.3) into `$OUT_DIR/web_viewer.zip`, which the hox
//! binary embeds and serves (`hox app --serve-web`, `hox lesson --serve-web`, `hox serve`).
//!
//! Why an archive: the published crate lacks `web_viewer/sw.js` (a service worker its built-in
//! assets name), so hox switches the crate to reading its files from an archive at run time and
//! makes that archive here, with a service worker of its own (`app/web/sw.js`, which caches
//! nothing). The crate's directory is found in Cargo's registry sources (`$CARGO_HOME`, else
//! `~/.cargo`) or a `vendor/` directory, or named by `HOX_WEB_VIEWER_DIR`.
use std::io::Write;
use std::path::{Path, PathBuf};

const CRATE: &str = "re_web_viewer_server-0.36.3";
const FILES: [&str; 7] = [
    "index.html",
    "favicon.ico",
    "apple-touch-icon.png",
    "re_viewer.js",
    "re_viewer_bg.wasm",
    "signed-in.html",
    "signed-out.html",
];

fn candidates() -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(dir) = std::env::var("HOX_WEB_VIEWER_DIR") {
        out.push(PathBuf::from(dir));
    }
    let homes: Vec<PathBuf> =
        [std::env::var("CARGO_HOME").ok(), std::env::var("HOME").ok().map(|h| format!("{h}/.cargo"))]
            .into_iter()
            .flatten()
            .map(PathBuf::from)
            .collect();
    for home in homes {
        if let Ok(registries) = std::fs::read_dir(home.join("registry/src")) {
            for r in registries.flatten() {
                out.push(r.path().join(CRATE).join("web_viewer"));
            }
        }
    }
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    for up in manifest.ancestors().take(3) {
        out.push(up.join("vendor/re_web_viewer_server/web_viewer"));
        out.push(up.join("vendor").join(CRATE).join("web_viewer"));
    }
    out
}

fn found() -> Option<PathBuf> {
    candidates().into_iter().find(|d| FILES.iter().all(|f| d.join(f).is_file()))
}

fn main() {
    println!("cargo::rerun-if-env-changed=HOX_WEB_VIEWER_DIR");
    println!("cargo::rerun-if-changed=web/sw.js");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR")).join("web_viewer.zip");
    let Some(dir) = found() else {
        println!(
            "cargo::warning=the Rerun web viewer's files ({CRATE}/web_viewer) were not found: `--serve-web` and \
             `hox serve` will say so (set HOX_WEB_VIEWER_DIR to the directory)"
        );
        std::fs::write(&out, b"").expect("write the empty archive");
        return;
    };
    for f in FILES {
        println!("cargo::rerun-if-changed={}", dir.join(f).display());
    }
    write_archive(&dir, &out).expect("pack the web viewer's files");
}

fn write_archive(dir: &Path, out: &Path) -> std::io::Result<()> {
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
    // stored, not deflated: the binary grows by the files' size either way, and a build does not
    // spend seconds compressing 42 MB
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for f in FILES {
        zip.start_file(f, options)?;
        zip.write_all(&std::fs::read(dir.join(f))?)?;
    }
    zip.start_file("sw.js", options)?;
    zip.write_all(&std::fs::read("web/sw.js")?)?;
    zip.finish()?;
    Ok(())
}
