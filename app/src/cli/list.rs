//! `hox scenes`, `hox elements` and `hox solvers`: what the registries hold.

use anyhow::Result;
use hox_sim::element::ElementType;
use hox_sim::fem::quadrature;
use hox_sim::solver::{Integrator, Method};

pub fn scenes(json: bool) -> Result<()> {
    let all = hox_scenes::registry()?;
    if json {
        let rows: Vec<_> = all
            .iter()
            .map(|s| serde_json::json!({"name": s.name(), "description": s.file.description, "effects": s.file.effects.iter().map(|e| e.kind()).collect::<Vec<_>>()}))
            .collect();
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        for s in &all {
            let effects: Vec<&str> = s.file.effects.iter().map(|e| e.kind()).collect();
            println!("{:<8} {} [{}]", s.name(), s.file.description, effects.join(", "));
        }
    }
    Ok(())
}

pub fn elements(json: bool) -> Result<()> {
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

/// The solvers of the registry ([`Method::ALL`]) and the implicit solvers' integrators
/// ([`Integrator::ALL`]), each from its own entry.
pub fn solvers(json: bool) -> Result<()> {
    let solvers: Vec<serde_json::Value> = Method::ALL
        .iter()
        .map(|m| {
            let i = m.info();
            serde_json::json!({
                "name": i.name,
                "long_name": i.long_name,
                "implicit": i.implicit,
                "parameters": i.parameters,
                "honours": i.honours.iter().map(|r| format!("{r:?}").to_lowercase()).collect::<Vec<_>>(),
                "motion": i.motion,
            })
        })
        .collect();
    let integrators: Vec<serde_json::Value> = Integrator::ALL
        .iter()
        .map(|g| {
            let i = g.info();
            serde_json::json!({"name": i.name, "long_name": i.long_name, "order": i.order, "motion": i.motion})
        })
        .collect();
    if json {
        let all = serde_json::json!({"solvers": solvers, "integrators": integrators});
        println!("{}", serde_json::to_string_pretty(&all)?);
        return Ok(());
    }
    let text = |v: &serde_json::Value, k: &str| v[k].as_str().unwrap_or("").to_string();
    for (s, m) in solvers.iter().zip(Method::ALL) {
        let kind = if m.is_implicit() { "implicit step" } else { "small steps" };
        println!("{:<10} {} ({kind}; reads {})", text(s, "name"), text(s, "long_name"), m.info().parameters.join(", "));
        println!("{:<10} {}", "", text(s, "motion"));
    }
    println!("\nintegrators of the implicit solvers (--integrator):");
    for g in &integrators {
        println!("{:<10} {}: {}", text(g, "name"), text(g, "long_name"), text(g, "motion"));
    }
    Ok(())
}
