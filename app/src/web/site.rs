//! The app's page served to a classroom (issue #59, `hox serve-app`): the static site
//! `scripts/build-web.sh` builds (index.html, hox.js, hox_bg.wasm), served over HTTP from the
//! teacher's machine. Each browser then runs the whole app itself: the server only hands out
//! files, so thirty students cost the laptop thirty downloads, not thirty simulations.
//!
//! - Loopback by default, like every server of hox (`--bind 0.0.0.0` for the classroom's
//!   network); a port in use or a foreign address is refused by name before anything starts.
//! - Files only from the site's folder: a path that leaves it (`..`) or names nothing is a 404.
//! - `hox_bg.wasm` goes out gzipped when the browser accepts it and the build wrote
//!   `hox_bg.wasm.gz` (a third of the bytes on the classroom's network).
//! - Every answer carries the cross-origin isolation headers (COOP `same-origin`, COEP
//!   `require-corp`) that shared memory in the page needs, and `no-cache`, so a rebuilt site
//!   is what the next reload gets.
//!
//! One thread with a single-threaded Tokio runtime; dropping [`SiteServer`] stops it.
use anyhow::{Context, Result, bail};
use bytes::Bytes;
use http_body_util::Full;
use hyper::{Request, Response, body::Incoming};
use hyper_util::rt::{TokioExecutor, TokioIo};
use std::net::IpAddr;
use std::path::{Path, PathBuf};

/// The files a built site has (scripts/build-web.sh).
pub const SITE_FILES: [&str; 3] = ["index.html", "hox.js", "hox_bg.wasm"];

/// The page's server; it stops when dropped.
pub struct SiteServer {
    _thread: super::read_only::ServerThread,
    /// What students open.
    pub url: String,
}

/// Checks that `dir` holds a built site: a clear error naming the missing file and the command
/// that builds it.
pub fn check_site(dir: &Path) -> Result<()> {
    for f in SITE_FILES {
        if !dir.join(f).is_file() {
            bail!(
                "{} is not a built hox site (no {f}): build it with `bash scripts/build-web.sh {}`",
                dir.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// Serves the site in `dir` on `bind`:`port` (0: any free port).
pub fn serve_site(dir: &Path, bind: IpAddr, port: u16) -> Result<SiteServer> {
    check_site(dir)?;
    let dir = dir.canonicalize().with_context(|| format!("cannot open {}", dir.display()))?;
    let listener = super::server::listen(bind, port, "app's page", "--web-port")?;
    let port = super::server::port_of(&listener, port);
    let url = format!("http://{}:{port}/", super::server::public_host(bind));
    listener.set_nonblocking(true).context("cannot set up the page's port")?;
    let runtime =
        tokio::runtime::Builder::new_current_thread().enable_io().build().context("cannot start the page's server")?;
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let thread = std::thread::Builder::new()
        .name("hox-site".into())
        .spawn(move || {
            runtime.block_on(async move {
                let Ok(listener) = tokio::net::TcpListener::from_std(listener) else { return };
                tokio::pin!(stopped);
                loop {
                    let accepted = tokio::select! {
                        _ = &mut stopped => break,
                        accepted = listener.accept() => accepted,
                    };
                    let Ok((stream, _peer)) = accepted else { continue };
                    let dir = dir.clone();
                    tokio::spawn(async move {
                        let service = hyper::service::service_fn(move |request| {
                            let answer = answer(&dir, &request);
                            async move { Ok::<_, std::convert::Infallible>(answer) }
                        });
                        // a browser that closes is nothing to the server
                        let _ = hyper_util::server::conn::auto::Builder::new(TokioExecutor::new())
                            .serve_connection(TokioIo::new(stream), service)
                            .await;
                    });
                }
            });
        })
        .context("cannot start the page's server thread")?;
    Ok(SiteServer { _thread: super::read_only::ServerThread::new(stop, thread), url })
}

/// The content type of a site file.
fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        Some("css") => "text/css; charset=utf-8",
        Some("png") => "image/png",
        Some("svg") => "image/svg+xml",
        Some("ico") => "image/x-icon",
        _ => "application/octet-stream",
    }
}

/// The file a request path names inside `dir` (`/` is index.html), if it is one of its files.
pub fn resolve(dir: &Path, path: &str) -> Option<PathBuf> {
    let rel = path.strip_prefix('/').unwrap_or(path);
    let rel = if rel.is_empty() { "index.html" } else { rel };
    if rel.split('/').any(|part| part.is_empty() || part == "." || part == ".." || part.contains('\\')) {
        return None;
    }
    let file = dir.join(rel);
    file.is_file().then_some(file)
}

/// The answer to one request.
fn answer(dir: &Path, request: &Request<Incoming>) -> Response<Full<Bytes>> {
    let plain = |status: hyper::StatusCode, text: &str| {
        let mut r = Response::new(Full::new(Bytes::from(text.to_string())));
        *r.status_mut() = status;
        r
    };
    if request.method() != hyper::Method::GET && request.method() != hyper::Method::HEAD {
        return plain(hyper::StatusCode::METHOD_NOT_ALLOWED, "hox serves its page read-only\n");
    }
    let Some(file) = resolve(dir, request.uri().path()) else {
        return plain(hyper::StatusCode::NOT_FOUND, "no such file in hox's page\n");
    };
    let accepts_gzip = request
        .headers()
        .get(hyper::header::ACCEPT_ENCODING)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.split(',').any(|e| e.trim().starts_with("gzip")));
    let gz = PathBuf::from(format!("{}.gz", file.display()));
    let (bytes, gzipped) = match (accepts_gzip && gz.is_file()).then(|| std::fs::read(&gz)) {
        Some(Ok(b)) => (b, true),
        _ => match std::fs::read(&file) {
            Ok(b) => (b, false),
            Err(e) => {
                return plain(
                    hyper::StatusCode::INTERNAL_SERVER_ERROR,
                    &format!("cannot read {}: {e}\n", file.display()),
                );
            }
        },
    };
    let body = if request.method() == hyper::Method::HEAD { Bytes::new() } else { Bytes::from(bytes) };
    let mut r = Response::new(Full::new(body));
    let h = r.headers_mut();
    h.insert(hyper::header::CONTENT_TYPE, hyper::header::HeaderValue::from_static(content_type(&file)));
    h.insert(hyper::header::CACHE_CONTROL, hyper::header::HeaderValue::from_static("no-cache"));
    h.insert("cross-origin-opener-policy", hyper::header::HeaderValue::from_static("same-origin"));
    h.insert("cross-origin-embedder-policy", hyper::header::HeaderValue::from_static("require-corp"));
    if gzipped {
        h.insert(hyper::header::CONTENT_ENCODING, hyper::header::HeaderValue::from_static("gzip"));
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Read, Write};

    /// A built site's files (their names as contents) in a fresh folder.
    fn site(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("hox-site-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for f in SITE_FILES {
            std::fs::write(dir.join(f), format!("the file {f}")).unwrap();
        }
        std::fs::write(dir.join("hox_bg.wasm.gz"), "gzipped").unwrap();
        dir
    }

    /// The raw answer to `GET path` with `headers`.
    fn get(url: &str, path: &str, headers: &str) -> String {
        let host = url.trim_start_matches("http://").trim_end_matches('/');
        let mut s = std::net::TcpStream::connect(host).unwrap();
        write!(s, "GET {path} HTTP/1.1\r\nHost: {host}\r\n{headers}Connection: close\r\n\r\n").unwrap();
        let mut out = String::new();
        s.read_to_string(&mut out).unwrap();
        out.to_lowercase()
    }

    #[test]
    fn the_page_its_module_and_its_wasm_are_served_with_their_types_and_isolation_headers() {
        let dir = site("types");
        let server = serve_site(&dir, IpAddr::from([127, 0, 0, 1]), 0).unwrap();
        assert!(server.url.starts_with("http://127.0.0.1:"), "{}", server.url);
        let page = get(&server.url, "/", "");
        assert!(page.starts_with("http/1.1 200") && page.contains("text/html") && page.contains("the file index.html"));
        assert!(page.contains("cross-origin-opener-policy: same-origin"), "{page}");
        assert!(page.contains("cross-origin-embedder-policy: require-corp"), "{page}");
        assert!(get(&server.url, "/hox.js", "").contains("text/javascript"));
        let wasm = get(&server.url, "/hox_bg.wasm", "");
        assert!(wasm.contains("application/wasm") && wasm.contains("the file hox_bg.wasm") && !wasm.contains("gzip"));
        let zipped = get(&server.url, "/hox_bg.wasm", "Accept-Encoding: gzip, deflate\r\n");
        assert!(zipped.contains("content-encoding: gzip") && zipped.ends_with("gzipped"), "{zipped}");
        // nothing outside the folder, nothing it lacks
        for path in ["/../etc/passwd", "/%2e%2e/x", "/nothing.js", "//index.html"] {
            assert!(get(&server.url, path, "").starts_with("http/1.1 404"), "{path}");
        }
        drop(server);
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_folder_without_a_built_site_is_refused_naming_the_file_and_the_build_command() {
        let dir = site("missing");
        std::fs::remove_file(dir.join("hox_bg.wasm")).unwrap();
        let e = serve_site(&dir, IpAddr::from([127, 0, 0, 1]), 0).err().unwrap().to_string();
        assert!(e.contains("no hox_bg.wasm") && e.contains("scripts/build-web.sh"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_port_in_use_is_refused_by_name() {
        let dir = site("port");
        let held = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = held.local_addr().unwrap().port();
        let e = serve_site(&dir, IpAddr::from([127, 0, 0, 1]), port).err().unwrap().to_string();
        assert!(e.contains("in use") && e.contains("--web-port"), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }
}
