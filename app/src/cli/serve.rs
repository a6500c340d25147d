//! `hox serve FILE.rrd`: a saved recording served to browsers (`web.rs`): the file is read and
//! checked whole first (a file that is not a Rerun recording is refused before any port opens),
//! then handed to the gRPC proxy, which every browser that opens the printed URL plays from.

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
