//! The data stream's public door (issue #38, "viewers cannot change the simulation"): a
//! reverse proxy in front of Rerun's gRPC server that passes reads through and refuses writes.
//!
//! Rerun's message proxy (`re_grpc_server`) accepts `WriteMessages` and `WriteTable` from any
//! client that reaches its port, so on a classroom network any student could push data into
//! what every other browser shows. hox therefore runs Rerun's server on the loopback address
//! only, on a port of its own, and puts this proxy on the port students reach (`--bind`,
//! `--grpc-port`):
//! - a request whose gRPC method (the last segment of its path) starts with `Write` is answered
//!   here, never forwarded: gRPC status 7, `PERMISSION_DENIED`, with a message naming why;
//! - every other request (the viewer's `ReadMessages`, the browser's CORS preflight) is
//!   forwarded unchanged over the same protocol it came in on: HTTP/1.1 (gRPC-web, browsers)
//!   or HTTP/2 (gRPC, the native viewer), its body and the answer's streamed both ways;
//! - hox itself writes in-process (the recording stream's sink), never through this door.
//!
//! One thread with a single-threaded Tokio runtime; dropping [`ReadOnlyDoor`] stops it and
//! closes every connection it holds.
use anyhow::{Context, Result};
use bytes::Bytes;
use http_body_util::{BodyExt, Empty, combinators::BoxBody};
use hyper::{Request, Response, body::Incoming};
use hyper_util::client::legacy::{Client, connect::HttpConnector};
use hyper_util::rt::{TokioExecutor, TokioIo};
use std::net::{SocketAddr, TcpListener};

/// The gRPC status code for "the caller may not do this" (`PERMISSION_DENIED`).
pub const GRPC_PERMISSION_DENIED: &str = "7";

/// Why a write is refused, as the client reads it (`grpc-message`).
pub const REFUSAL: &str = "hox serves this stream read-only: viewers cannot write to it";

/// Headers that belong to one connection and are not forwarded (RFC 9110 §7.6.1).
const HOP_BY_HOP: [&str; 7] = [
    "connection",
    "keep-alive",
    "proxy-connection",
    "transfer-encoding",
    "upgrade",
    "proxy-authenticate",
    "proxy-authorization",
];

/// A server on a thread of its own, told to stop and joined when dropped (the door, the app's
/// page of `site.rs`).
pub struct ServerThread {
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl ServerThread {
    pub fn new(stop: tokio::sync::oneshot::Sender<()>, thread: std::thread::JoinHandle<()>) -> ServerThread {
        ServerThread { stop: Some(stop), thread: Some(thread) }
    }
}

impl Drop for ServerThread {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The proxy; it stops when dropped (the thread is held for its `Drop`).
pub struct ReadOnlyDoor(#[allow(dead_code)] ServerThread);

/// Whether a request path names a gRPC method that writes (`/package.Service/WriteSomething`).
pub fn is_write(path: &str) -> bool {
    path.rsplit('/').next().is_some_and(|method| method.starts_with("Write"))
}

type ProxyBody = BoxBody<Bytes, hyper::Error>;

/// Serves `listener` (already bound: its errors were reported by name), forwarding reads to
/// Rerun's server at `upstream`.
pub fn start(listener: TcpListener, upstream: SocketAddr) -> Result<ReadOnlyDoor> {
    listener.set_nonblocking(true).context("cannot set up the data stream's port")?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .enable_time()
        .build()
        .context("cannot start the data stream's proxy")?;
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let upstream_up = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let thread = std::thread::Builder::new()
        .name("hox-read-only-door".into())
        .spawn(move || {
            runtime.block_on(async move {
                let Ok(listener) = tokio::net::TcpListener::from_std(listener) else { return };
                let http1 = Client::builder(TokioExecutor::new()).build(HttpConnector::new());
                let http2 = Client::builder(TokioExecutor::new()).http2_only(true).build(HttpConnector::new());
                tokio::pin!(stopped);
                loop {
                    let accepted = tokio::select! {
                        _ = &mut stopped => break,
                        accepted = listener.accept() => accepted,
                    };
                    // a failed accept (a client gone before it was taken) concerns that client only
                    let Ok((stream, _peer)) = accepted else { continue };
                    let _ = stream.set_nodelay(true);
                    let (http1, http2, upstream_up) = (http1.clone(), http2.clone(), upstream_up.clone());
                    tokio::spawn(async move {
                        let service = hyper::service::service_fn(move |request| {
                            let client = if request.version() == hyper::Version::HTTP_2 { &http2 } else { &http1 };
                            forward(client.clone(), upstream, upstream_up.clone(), request)
                        });
                        // a browser that closes is nothing to the server: the error is its own
                        let _ = hyper_util::server::conn::auto::Builder::new(TokioExecutor::new())
                            .serve_connection(TokioIo::new(stream), service)
                            .await;
                    });
                }
            });
            // the connections still open are dropped with the runtime
        })
        .context("cannot start the data stream's proxy thread")?;
    Ok(ReadOnlyDoor(ServerThread::new(stop, thread)))
}

/// How long a request waits for Rerun's server to listen when the door opened first (the
/// server starts on its own thread): a browser opened at once is served, not turned away.
const UPSTREAM_START_SECS: f64 = 10.0;

/// Waits until Rerun's server at `upstream` accepts connections (once: `up` remembers it), for
/// at most [`UPSTREAM_START_SECS`].
async fn wait_for_upstream(upstream: SocketAddr, up: &std::sync::atomic::AtomicBool) {
    use std::sync::atomic::Ordering;
    let deadline = tokio::time::Instant::now() + std::time::Duration::from_secs_f64(UPSTREAM_START_SECS);
    while !up.load(Ordering::Relaxed) {
        if tokio::net::TcpStream::connect(upstream).await.is_ok() {
            up.store(true, Ordering::Relaxed);
        } else if tokio::time::Instant::now() >= deadline {
            return;
        } else {
            tokio::time::sleep(std::time::Duration::from_millis(50)).await;
        }
    }
}

/// One request: refused here if it writes, else forwarded to `upstream`.
async fn forward(
    client: Client<HttpConnector, Incoming>,
    upstream: SocketAddr,
    upstream_up: std::sync::Arc<std::sync::atomic::AtomicBool>,
    request: Request<Incoming>,
) -> Result<Response<ProxyBody>, std::convert::Infallible> {
    if is_write(request.uri().path()) {
        return Ok(refusal(&request));
    }
    wait_for_upstream(upstream, &upstream_up).await;
    let (mut parts, body) = request.into_parts();
    let path = parts.uri.path_and_query().map_or("/", |p| p.as_str());
    let Ok(uri) = format!("http://{upstream}{path}").parse() else {
        return Ok(status_only(hyper::StatusCode::BAD_REQUEST));
    };
    parts.uri = uri;
    strip_hop_by_hop(&mut parts.headers);
    match client.request(Request::from_parts(parts, body)).await {
        Ok(answer) => {
            let (mut parts, body) = answer.into_parts();
            strip_hop_by_hop(&mut parts.headers);
            Ok(Response::from_parts(parts, body.boxed()))
        }
        // Rerun's server gone, or not up within UPSTREAM_START_SECS: the viewer retries
        Err(_) => Ok(status_only(hyper::StatusCode::BAD_GATEWAY)),
    }
}

fn strip_hop_by_hop(headers: &mut hyper::HeaderMap) {
    for name in HOP_BY_HOP {
        headers.remove(name);
    }
}

fn status_only(status: hyper::StatusCode) -> Response<ProxyBody> {
    let mut response = Response::new(Empty::new().map_err(|never| match never {}).boxed());
    *response.status_mut() = status;
    response
}

/// A gRPC "trailers-only" answer: HTTP 200 whose headers carry the status, for gRPC (HTTP/2)
/// and gRPC-web (HTTP/1.1, which also needs the page's origin allowed to read it).
fn refusal(request: &Request<Incoming>) -> Response<ProxyBody> {
    let mut response = status_only(hyper::StatusCode::OK);
    let headers = response.headers_mut();
    let content_type = request
        .headers()
        .get(hyper::header::CONTENT_TYPE)
        .cloned()
        .unwrap_or(hyper::header::HeaderValue::from_static("application/grpc"));
    headers.insert(hyper::header::CONTENT_TYPE, content_type);
    headers.insert("grpc-status", hyper::header::HeaderValue::from_static(GRPC_PERMISSION_DENIED));
    // gRPC percent-encodes the message; the refusal's only such characters are spaces and a colon
    let message = REFUSAL.replace(' ', "%20").replace(':', "%3A");
    if let Ok(message) = hyper::header::HeaderValue::from_str(&message) {
        headers.insert("grpc-message", message);
    }
    if let Some(origin) = request.headers().get(hyper::header::ORIGIN) {
        headers.insert(hyper::header::ACCESS_CONTROL_ALLOW_ORIGIN, origin.clone());
        headers.insert(
            hyper::header::ACCESS_CONTROL_EXPOSE_HEADERS,
            hyper::header::HeaderValue::from_static("grpc-status,grpc-message"),
        );
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_are_told_from_reads_by_their_method() {
        assert!(is_write("/rerun.sdk_comms.v1alpha1.MessageProxyService/WriteMessages"));
        assert!(is_write("/rerun.sdk_comms.v1alpha1.MessageProxyService/WriteTable"));
        assert!(!is_write("/rerun.sdk_comms.v1alpha1.MessageProxyService/ReadMessages"));
        assert!(!is_write("/rerun.sdk_comms.v1alpha1.MessageProxyService/ReadTables"));
        assert!(!is_write("/"));
    }

    const SERVICE: &str = "/rerun.sdk_comms.v1alpha1.MessageProxyService";

    /// A served (empty) recording, as `hox serve` starts it.
    fn served() -> (rerun::grpc_server::GrpcServerSink, crate::web::WebServer) {
        let args = crate::web::ServeArgs { web_port: 0, grpc_port: 0, ..Default::default() };
        crate::web::serve_messages(&args, Vec::new()).expect("serving on free loopback ports")
    }

    /// The head of the answer to a gRPC-web call over HTTP/1.1, as a browser makes it: an empty
    /// message (a five-byte frame) to `method`.
    fn grpc_web_head(port: u16, method: &str) -> String {
        use std::io::{Read, Write};
        let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
        stream.set_read_timeout(Some(std::time::Duration::from_secs(10))).unwrap();
        let frame = [0u8; 5];
        let head = format!(
            "POST {SERVICE}/{method} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/grpc-web+proto\r\n\
             X-Grpc-Web: 1\r\nContent-Length: {}\r\n\r\n",
            frame.len()
        );
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(&frame).unwrap();
        let mut answer = Vec::new();
        let mut buf = [0u8; 4096];
        // the head only: a read's answer streams on for as long as the recording is served
        while !answer.windows(4).any(|w| w == b"\r\n\r\n") {
            match stream.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => answer.extend_from_slice(&buf[..n]),
            }
        }
        String::from_utf8_lossy(&answer).to_lowercase()
    }

    #[test]
    fn a_browser_reads_the_stream_through_the_door_but_cannot_write_to_it() {
        let (_sink, web) = served();
        let read = grpc_web_head(web.data_port, "ReadMessages");
        assert!(read.starts_with("http/1.1 200"), "{read}");
        assert!(read.contains("content-type: application/grpc-web+proto"), "{read}");
        assert!(!read.contains("grpc-status: 7"), "a read refused: {read}");
        for method in ["WriteMessages", "WriteTable"] {
            let write = grpc_web_head(web.data_port, method);
            assert!(write.starts_with("http/1.1 200") && write.contains("grpc-status: 7"), "{method}: {write}");
            assert!(write.contains("read-only%3a%20viewers%20cannot%20write"), "{method}: {write}");
        }
    }

    /// Seen in CI: the door answered 502 to a browser that came before Rerun's server (started
    /// on its own thread) listened.
    #[test]
    fn a_browser_that_comes_before_the_data_server_listens_is_served_not_turned_away() {
        let door_listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let port = door_listener.local_addr().unwrap().port();
        let upstream_port = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
        let _door = start(door_listener, SocketAddr::from(([127, 0, 0, 1], upstream_port))).unwrap();
        let late_server = std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(700));
            rerun::grpc_server::GrpcServerSink::new("127.0.0.1", upstream_port, rerun::ServerOptions::default())
                .unwrap()
        });
        let read = grpc_web_head(port, "ReadMessages");
        let _sink = late_server.join().unwrap();
        assert!(read.starts_with("http/1.1 200"), "{read}");
    }

    #[test]
    fn a_native_grpc_client_cannot_write_through_the_door() {
        let (_sink, web) = served();
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let status = runtime.block_on(async {
            let client = Client::builder(TokioExecutor::new()).http2_only(true).build(HttpConnector::new());
            let request = Request::post(format!("http://127.0.0.1:{}{SERVICE}/WriteMessages", web.data_port))
                .header("content-type", "application/grpc")
                .header("te", "trailers")
                .body(http_body_util::Full::new(Bytes::from_static(&[0u8; 5])))
                .unwrap();
            let answer = client.request(request).await.expect("an answer over HTTP/2");
            assert_eq!(answer.version(), hyper::Version::HTTP_2);
            answer.headers().get("grpc-status").map(|v| v.to_str().unwrap().to_string())
        });
        assert_eq!(status.as_deref(), Some(GRPC_PERMISSION_DENIED));
    }
}
