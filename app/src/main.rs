//! `hox`: the command-line entry point. Subcommands are added issue by issue; today:
//! `hox elements` lists the element types with their nodes, faces and quadrature.

use anyhow::Result;
use clap::{Parser, Subcommand};
use hox_sim::element::ElementType;
use hox_sim::quadrature;

#[derive(Parser)]
#[command(name = "hox", version, about = "hox: see, measure and teach high-order finite elements in XPBD")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// List the element types: nodes, faces, default quadrature (degree and points).
    Elements {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command.unwrap_or(Command::Elements { json: false }) {
        Command::Elements { json } => elements(json),
    }
}

fn elements(json: bool) -> Result<()> {
    let rows: Vec<serde_json::Value> = ElementType::all()
        .map(|e| -> Result<serde_json::Value> {
            let degree = e.default_quadrature_degree();
            let rule = quadrature::rule(e.shape(), degree)?;
            Ok(serde_json::json!({
                "element": e.name(),
                "description": e.description(),
                "gmsh_type": e.gmsh_type(),
                "nodes": e.num_nodes(),
                "faces": e.faces().len(),
                "quadrature_degree": degree,
                "quadrature_points": rule.len(),
            }))
        })
        .collect::<Result<_>>()?;
    if json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!("{:<8} {:<38} {:>5} {:>5} {:>6} {:>7}", "element", "description", "gmsh", "nodes", "degree", "points");
    for r in &rows {
        println!(
            "{:<8} {:<38} {:>5} {:>5} {:>6} {:>7}",
            r["element"].as_str().unwrap_or(""),
            r["description"].as_str().unwrap_or(""),
            r["gmsh_type"].to_string(),
            r["nodes"].to_string(),
            r["quadrature_degree"].to_string(),
            r["quadrature_points"].to_string()
        );
    }
    Ok(())
}
