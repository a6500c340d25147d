//! `hox serve FILE.rrd`: a saved recording served to browsers (`web.rs`): the file is read and
//! checked whole first (a file that is not a Rerun recording is refused before any port opens),
//! then handed to the gRPC proxy, which every browser that opens the printed URL plays from.
//!
//! `hox serve-app`: the app's own page (`web/site.rs`), which each browser runs itself.

use crate::web::{ServeArgs, serve_messages, wait_for_ctrl_c};
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct ServeFileArgs {
    /// The recording to serve (.rrd).
    pub file: PathBuf,
    #[command(flatten)]
    pub serve: ServeArgs,
    /// Serve for this many seconds, then stop (default: until Ctrl-C).
    #[arg(long)]
    pub seconds: Option<f64>,
}

pub fn serve(args: &ServeFileArgs) -> Result<()> {
    use rerun::external::re_log_encoding::DecoderApp;
    let path = &args.file;
    if let Some(s) = args.seconds
        && !(s.is_finite() && s >= 0.0)
    {
        bail!("--seconds must be a finite, non-negative number of seconds, got {s}");
    }
    let file = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let messages: Vec<_> = DecoderApp::decode_lazy(std::io::BufReader::new(file))
        .map(|m| m.with_context(|| format!("{} is not a readable Rerun recording", path.display())))
        .collect::<Result<_>>()?;
    if messages.is_empty() {
        bail!("{} holds no Rerun messages", path.display());
    }
    let count = messages.len();
    let (_sink, web) = serve_messages(&args.serve, messages)?;
    println!("{}", web.url);
    eprintln!(
        "serving {} ({count} messages) to browsers at the URL above (history bound {} MB; the data \
         stream on port {} is read-only)",
        path.display(),
        web.history_bytes / 1_000_000,
        web.data_port
    );
    match args.seconds {
        Some(s) => std::thread::sleep(std::time::Duration::from_secs_f64(s)),
        None => wait_for_ctrl_c("serving")?,
    }
    Ok(())
}

/// The site folder `scripts/build-web.sh` writes by default: `site/` in the repository.
fn default_site() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../site"))
}

#[derive(clap::Args)]
pub struct ServeAppArgs {
    /// The built site (default: site/ in the repository, where scripts/build-web.sh writes it).
    #[arg(long)]
    pub site: Option<PathBuf>,
    /// Address to listen on: 127.0.0.1 (this machine only) unless another is named, e.g.
    /// 0.0.0.0 for every network of this machine (a classroom's).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: std::net::IpAddr,
    /// Port of the page (0: any free port).
    #[arg(long, default_value_t = 9090)]
    pub web_port: u16,
    /// What the printed address and its QR code open, as a link's query: a lesson step
    /// (`lesson=locking&step=2`) or a configuration (`element=p2&nu=0.49`).
    #[arg(long, value_name = "KEY=VALUE&...")]
    pub link: Option<String>,
    /// Serve for this many seconds, then stop (default: until Ctrl-C).
    #[arg(long)]
    pub seconds: Option<f64>,
}

/// The query a `--link` gives, checked key by key: the link keys and the parameter table's.
fn link_query(link: &str) -> Result<String> {
    let link = link.trim_start_matches('?');
    for pair in link.split('&').filter(|p| !p.is_empty()) {
        let key = pair.split_once('=').map_or(pair, |(k, _)| k);
        if !crate::config::LINK_KEYS.contains(&key) && hox_scenes::params::by_key(key).is_none_or(|p| !p.surfaces.cli) {
            bail!(
                "--link: unknown key '{key}': a link takes {} and the parameters ({})",
                crate::config::LINK_KEYS.join(", "),
                hox_scenes::params::compare_keys()
            );
        }
    }
    Ok(if link.is_empty() { String::new() } else { format!("?{link}") })
}

pub fn serve_app(args: &ServeAppArgs) -> Result<()> {
    if let Some(s) = args.seconds
        && !(s.is_finite() && s >= 0.0)
    {
        bail!("--seconds must be a finite, non-negative number of seconds, got {s}");
    }
    let query = args.link.as_deref().map(link_query).transpose()?.unwrap_or_default();
    let site = args.site.clone().unwrap_or_else(default_site);
    let server = crate::web::site::serve_site(&site, args.bind, args.web_port)?;
    let url = format!("{}{query}", server.url);
    println!("{url}");
    if let Some(qr) = crate::web::qr_text(&url) {
        eprint!("{qr}");
    }
    eprintln!("serving hox's page from {}: each browser that opens the URL above runs the app itself", site.display());
    if args.bind.is_loopback() {
        eprintln!("(this machine only: --bind 0.0.0.0 serves the classroom's network)");
    }
    match args.seconds {
        Some(s) => std::thread::sleep(std::time::Duration::from_secs_f64(s)),
        None => wait_for_ctrl_c("serving")?,
    }
    Ok(())
}
