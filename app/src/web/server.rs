//! The servers themselves (native only): the web viewer over HTTP, the gRPC proxy behind the
//! read-only door, the address students open and its QR code.

use super::{ServeArgs, read_only};
use anyhow::{Context, Result, bail};
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener, UdpSocket};
use std::path::PathBuf;

/// The web viewer's files (`app/build.rs`): a zip archive, empty when the build did not find
/// them.
static VIEWER_ARCHIVE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/web_viewer.zip"));

/// The web viewer's HTTP server and the data stream's read-only door; they stop when dropped.
/// The gRPC server behind the door lives in the recording stream's sink ([`serve_recording`])
/// or in [`serve_messages`]'s.
pub struct WebServer {
    _http: re_web_viewer_server::WebViewerServer,
    _door: read_only::ReadOnlyDoor,
    /// The port browsers read the data stream from (the door's).
    pub data_port: u16,
    /// What students open: the page with the data stream's address in it.
    pub url: String,
    /// The bound on the history kept for late browsers, bytes.
    pub history_bytes: u64,
}

/// A port to listen on: `port` itself if it is free on `ip`, any free one for 0; a clear error
/// otherwise.
fn free_port(ip: IpAddr, port: u16, what: &str, flag: &str) -> Result<u16> {
    Ok(port_of(&listen(ip, port, what, flag)?, port))
}

/// The port `listener` took (`asked` unless that was 0).
pub(super) fn port_of(listener: &TcpListener, asked: u16) -> u16 {
    listener.local_addr().map(|a| a.port()).unwrap_or(asked)
}

/// A listener on `ip`:`port` (any free port for 0), or a clear error naming the address, the
/// cause and the flag that chooses another.
pub(super) fn listen(ip: IpAddr, port: u16, what: &str, flag: &str) -> Result<TcpListener> {
    TcpListener::bind(SocketAddr::new(ip, port)).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::AddrInUse => "the port is in use (another hox, or another program)".to_string(),
            std::io::ErrorKind::AddrNotAvailable => format!("{ip} is not an address of this machine"),
            std::io::ErrorKind::PermissionDenied => "permission denied (ports below 1024 need root)".to_string(),
            _ => e.to_string(),
        };
        anyhow::anyhow!(
            "cannot serve the {what} on {ip}:{port}: {why}; choose another with {flag}, or 0 for any free port"
        )
    })
}

/// The host name browsers reach the servers by (module docs).
pub(super) fn public_host(bind: IpAddr) -> String {
    let ip = if bind.is_unspecified() { default_route_address().unwrap_or(bind) } else { bind };
    match ip {
        IpAddr::V4(v4) if v4.is_unspecified() => "127.0.0.1".into(),
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) if v6.is_unspecified() => "[::1]".into(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// This machine's address on the network of its default route: a UDP socket "connected" to a
/// public address sends nothing, but the system picks the local address it would use.
fn default_route_address() -> Option<IpAddr> {
    let socket = UdpSocket::bind("0.0.0.0:0").ok()?;
    socket.connect("192.0.2.1:9").ok()?;
    socket.local_addr().ok().map(|a| a.ip()).filter(|ip| !ip.is_unspecified())
}

/// `rerun+http://HOST:PORT/proxy` percent-encoded for the page's `url=` parameter (every byte
/// but ASCII letters and digits, as the web viewer's own helper does).
fn percent_encoded(s: &str) -> String {
    s.bytes().map(|b| if b.is_ascii_alphanumeric() { (b as char).to_string() } else { format!("%{b:02X}") }).collect()
}

/// The embedded archive written where the web server can read it (once per version and size).
fn viewer_archive() -> Result<PathBuf> {
    if VIEWER_ARCHIVE.is_empty() {
        bail!(
            "this hox was built without the Rerun web viewer's files (the build did not find \
             re_web_viewer_server-0.36.3/web_viewer; rebuild with HOX_WEB_VIEWER_DIR naming it)"
        );
    }
    let path =
        std::env::temp_dir().join(format!("hox-{}-web-viewer-{}.zip", env!("CARGO_PKG_VERSION"), VIEWER_ARCHIVE.len()));
    let current = std::fs::metadata(&path).map(|m| m.len() == VIEWER_ARCHIVE.len() as u64).unwrap_or(false);
    if !current {
        // unique per call: two servers starting at once in one process must not share it
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let partial = path.with_extension(format!("zip.{}.{call}", std::process::id()));
        std::fs::write(&partial, VIEWER_ARCHIVE)
            .and_then(|()| std::fs::rename(&partial, &path))
            .with_context(|| format!("cannot write the web viewer's files to {}", path.display()))?;
    }
    Ok(path)
}

/// The gRPC server's options: the history bound, and the page's origin allowed where it is not
/// the loopback address (the proxy admits only localhost's by default).
fn server_options(args: &ServeArgs, host: &str, web_port: u16) -> rerun::ServerOptions {
    let mut cors_allowed_origins = vec![format!("http://{host}:{web_port}")];
    if args.bind.is_unspecified() {
        // reached by another of this machine's names or addresses
        cors_allowed_origins.push(format!("http://*:{web_port}"));
    }
    rerun::ServerOptions {
        playback_behavior: rerun::PlaybackBehavior::OldestFirst,
        memory_limit: rerun::MemoryLimit::from_bytes(args.history_mb.saturating_mul(1_000_000)),
        cors_allowed_origins,
    }
}

/// Where Rerun's gRPC server listens: the loopback address only (the door forwards to it).
const UPSTREAM_IP: Ipv4Addr = Ipv4Addr::LOCALHOST;

/// Checks the ports, starts the web viewer's server and the data stream's read-only door, and
/// returns them with the loopback port Rerun's gRPC server is to listen on and its options.
fn start_http(args: &ServeArgs) -> Result<(WebServer, u16, rerun::ServerOptions)> {
    if args.history_mb == 0 {
        bail!("--history-mb must be at least 1 (the static data alone needs room)");
    }
    if args.grpc_port != 0 && args.grpc_port == args.web_port {
        bail!("--web-port and --grpc-port must differ (both are {})", args.web_port);
    }
    let archive = viewer_archive()?;
    let door_listener = listen(args.bind, args.grpc_port, "data stream", "--grpc-port")?;
    let grpc_port = port_of(&door_listener, args.grpc_port);
    let web_port = free_port(args.bind, args.web_port, "web page", "--web-port")?;
    let upstream_port = free_port(IpAddr::V4(UPSTREAM_IP), 0, "data stream's server", "--grpc-port")?;
    let upstream = SocketAddr::new(IpAddr::V4(UPSTREAM_IP), upstream_port);
    let door = read_only::start(door_listener, upstream)?;
    let http = re_web_viewer_server::WebViewerServer::with_archive(
        &args.bind.to_string(),
        re_web_viewer_server::WebViewerServerPort(web_port),
        Some(&archive),
    )
    .map_err(|e| anyhow::anyhow!("cannot serve the web page on {}:{web_port}: {e}", args.bind))?;
    let host = public_host(args.bind);
    let grpc = format!("rerun+http://{host}:{grpc_port}/proxy");
    let url = format!("http://{host}:{web_port}/?url={}", percent_encoded(&grpc));
    let options = server_options(args, &host, web_port);
    let history_bytes = options.memory_limit.as_bytes();
    Ok((WebServer { _http: http, _door: door, data_port: grpc_port, url, history_bytes }, upstream_port, options))
}

/// How often the served stream's rows are cut into messages (chunks, one per entity). Rerun's
/// default for a served stream is every 8 ms, a message per entity per frame: about 900 a second
/// for the P2 bending beam at 60 frames. A browser takes in messages for 10 ms per paint, and
/// one without a graphics card paints about twice a second, so it fell further behind the
/// stream with every second: 30 s after opening, such a page showed 0.9 s of the run. At 100 ms
/// a message carries several frames and the same page showed 6 s (docs/WEB.md); the view still
/// moves ten times a second.
pub const SERVED_FLUSH_TICK: std::time::Duration = std::time::Duration::from_millis(100);

/// The served stream's batching: [`SERVED_FLUSH_TICK`], Rerun's other limits; Rerun's
/// `RERUN_FLUSH_TICK_SECS` (and its other `RERUN_FLUSH_*` variables) still override it.
fn served_batcher_config() -> rerun::log::ChunkBatcherConfig {
    let config = rerun::log::ChunkBatcherConfig { flush_tick: SERVED_FLUSH_TICK, ..Default::default() };
    config.apply_env().unwrap_or(config)
}

/// A recording stream named `name` whose data every browser at [`WebServer::url`] sees live.
pub fn serve_recording(name: &str, args: &ServeArgs) -> Result<(rerun::RecordingStream, WebServer)> {
    let (web, upstream_port, options) = start_http(args)?;
    let rec = rerun::RecordingStreamBuilder::new("hox")
        .recording_name(name)
        .batcher_config(served_batcher_config())
        .serve_grpc_opts(UPSTREAM_IP.to_string(), upstream_port, options)
        .with_context(|| format!("cannot serve the data stream on {UPSTREAM_IP}:{upstream_port}"))?;
    Ok((rec, web))
}

/// A gRPC server holding `messages` (a recording read from a file), and the web viewer
/// pointing at it.
pub fn serve_messages(
    args: &ServeArgs,
    messages: Vec<rerun::log::LogMsg>,
) -> Result<(rerun::grpc_server::GrpcServerSink, WebServer)> {
    use rerun::sink::LogSink as _;
    let (web, upstream_port, options) = start_http(args)?;
    let sink = rerun::grpc_server::GrpcServerSink::new(&UPSTREAM_IP.to_string(), upstream_port, options)
        .with_context(|| format!("cannot serve the data stream on {UPSTREAM_IP}:{upstream_port}"))?;
    for msg in messages {
        sink.send(msg);
    }
    Ok((sink, web))
}

/// The URL as a QR code: `modules[row * width + column]` is dark.
pub fn qr_modules(url: &str) -> Option<(usize, Vec<bool>)> {
    let code = qrcode::QrCode::new(url.as_bytes()).ok()?;
    let width = code.width();
    let modules = code.to_colors().into_iter().map(|c| c == qrcode::Color::Dark).collect();
    Some((width, modules))
}

/// The URL as a QR code for a terminal: two rows of modules per line in half blocks, dark on a
/// light quiet zone of two modules (phones read it off a projected terminal too).
pub fn qr_text(url: &str) -> Option<String> {
    let (width, modules) = qr_modules(url)?;
    let quiet = 2;
    let dark = |r: isize, c: isize| {
        let (r, c) = (r - quiet, c - quiet);
        r >= 0 && c >= 0 && (r as usize) < width && (c as usize) < width && modules[r as usize * width + c as usize]
    };
    let size = (width as isize) + 2 * quiet;
    let mut text = String::new();
    for r in (0..size).step_by(2) {
        for c in 0..size {
            // light is drawn, dark is the terminal's background: works on dark terminals
            text.push(match (dark(r, c), dark(r + 1, c)) {
                (false, false) => '█',
                (false, true) => '▀',
                (true, false) => '▄',
                (true, true) => ' ',
            });
        }
        text.push('\n');
    }
    Some(text)
}

/// Waits for Ctrl-C (the servers keep running meanwhile).
pub fn wait_for_ctrl_c(what: &str) -> Result<()> {
    let (tx, rx) = std::sync::mpsc::channel();
    ctrlc::set_handler(move || {
        let _ = tx.send(());
    })
    .context("cannot watch for Ctrl-C")?;
    eprintln!("{what}: Ctrl-C to stop");
    let _ = rx.recv();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_port_in_use_is_refused_by_name() {
        let held = TcpListener::bind("127.0.0.1:0").unwrap();
        let port = held.local_addr().unwrap().port();
        let args = ServeArgs { web_port: port, grpc_port: 0, ..ServeArgs::default() };
        let e = start_http(&args).err().expect("a port in use").to_string();
        assert!(e.contains(&format!("127.0.0.1:{port}")) && e.contains("in use") && e.contains("--web-port"), "{e}");
    }

    #[test]
    fn an_address_not_of_this_machine_is_refused_by_name() {
        let args = ServeArgs { bind: "192.0.2.7".parse().unwrap(), web_port: 0, grpc_port: 0, ..ServeArgs::default() };
        let e = start_http(&args).err().expect("a foreign address").to_string();
        assert!(e.contains("192.0.2.7") && e.contains("not an address of this machine"), "{e}");
    }

    #[test]
    fn the_page_names_the_data_stream_it_reads() {
        let args = ServeArgs { web_port: 0, grpc_port: 0, ..ServeArgs::default() };
        let (web, upstream_port, options) = start_http(&args).unwrap();
        let expected = percent_encoded(&format!("rerun+http://127.0.0.1:{}/proxy", web.data_port));
        assert_ne!(upstream_port, web.data_port, "the page reads through the door, not from Rerun's server");
        assert!(web.url.starts_with("http://127.0.0.1:") && web.url.ends_with(&expected), "{}", web.url);
        assert_eq!(web.history_bytes, 256_000_000);
        assert_eq!(options.memory_limit.as_bytes(), 256_000_000);
    }

    #[test]
    fn the_url_fits_a_qr_code() {
        let (width, modules) =
            qr_modules("http://192.168.100.200:9090/?url=rerun%2Bhttp%3A%2F%2F192%2E168%2E100%2E200%3A9876%2Fproxy")
                .unwrap();
        assert_eq!(modules.len(), width * width);
        assert!(modules.iter().any(|&m| m) && modules.iter().any(|&m| !m));
    }
}
