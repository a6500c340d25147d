//! Serving what hox shows to browsers (issue #38): the Rerun web viewer (the pre-built
//! WebAssembly viewer of rerun 0.36.3, packed by `app/build.rs` and embedded in the binary) over
//! HTTP, and the data over Rerun's gRPC proxy, to which each browser connects. Used by
//! `hox app --serve-web` (and the app's Rerun section), `hox lesson NAME --serve-web` and
//! `hox serve FILE.rrd`.
//!
//! - **Safe by default:** both servers listen on the loopback address (127.0.0.1) unless
//!   `--bind` names another (`0.0.0.0`: every network of this machine). The simulation never
//!   reads from the servers: a browser orbits, scrubs and hovers its own copy of the data.
//! - **Clear refusals:** a port in use or an address that is not this machine's is refused by
//!   name before anything starts; a browser that closes is nothing to the server.
//! - **Read-only for viewers:** Rerun's gRPC server runs on the loopback address only; the port
//!   students reach is [`read_only`]'s proxy, which forwards reads and refuses every write, so
//!   no browser or program on the network can push data into what the others see.
//! - **Bounded memory:** the gRPC proxy keeps at most [`ServeArgs::history_mb`] of history for
//!   browsers that connect late (Rerun's `ServerOptions::memory_limit`); beyond it the oldest
//!   frames are dropped (static data — topology, rest shape, labels, blueprint — never is).
//! - **The address students open:** on the loopback address, `http://127.0.0.1:PORT`; bound to
//!   every network, this machine's address on the network of its default route (found by
//!   asking the system which local address would reach a public one: nothing is sent).
use std::net::{IpAddr, Ipv4Addr};

// Serving is the desktop's: a page cannot listen on a port (issue #59).
#[cfg(not(target_arch = "wasm32"))]
pub mod read_only;
#[cfg(not(target_arch = "wasm32"))]
mod server;
#[cfg(not(target_arch = "wasm32"))]
pub mod site;
#[cfg(not(target_arch = "wasm32"))]
pub use server::*;

/// Where and how to serve (`--bind`, `--web-port`, `--grpc-port`, `--history-mb`).
#[derive(Clone, Debug, clap::Args)]
pub struct ServeArgs {
    /// Address to listen on: 127.0.0.1 (this machine only) unless another is named, e.g.
    /// 0.0.0.0 for every network of this machine (a classroom's).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// Port of the web page students open (0: any free port).
    #[arg(long, default_value_t = 9090)]
    pub web_port: u16,
    /// Port of the data stream the page connects to (0: any free port).
    #[arg(long, default_value_t = 9876)]
    pub grpc_port: u16,
    /// History kept for browsers that connect late, MB: beyond it the oldest frames are dropped
    /// (static data never is).
    #[arg(long, default_value_t = 256)]
    pub history_mb: u64,
}

impl Default for ServeArgs {
    fn default() -> Self {
        ServeArgs { bind: IpAddr::V4(Ipv4Addr::LOCALHOST), web_port: 9090, grpc_port: 9876, history_mb: 256 }
    }
}
