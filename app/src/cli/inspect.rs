//! `hox inspect`: read a Rerun .rrd file back and check what it holds: its entities, the
//! configurations and the fields their surfaces are coloured by, and the layout (blueprint) it
//! opens in.

use anyhow::{Context, Result, bail};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct InspectArgs {
    /// The .rrd file to read.
    pub file: PathBuf,
    /// Fail unless every recorded configuration has its surface positions and colours, edges
    /// and probes at exactly this many frames.
    #[arg(long)]
    pub expect_frames: Option<usize>,
    #[arg(long)]
    pub json: bool,
}

/// The blueprint a recording carries: its views (kind and name) and containers.
#[derive(Debug, Default, serde::Serialize)]
pub struct BlueprintSummary {
    /// `(view class, name)` of every view, e.g. `("3D", "3D: von Mises stress")`.
    pub views: Vec<(String, String)>,
    pub containers: usize,
}

/// What an .rrd file holds.
#[derive(Debug, Default)]
pub struct Recording {
    pub entities: BTreeMap<String, EntitySummary>,
    pub blueprint: BlueprintSummary,
}

/// What an .rrd file holds, per entity.
#[derive(Debug, Default, serde::Serialize)]
pub struct EntitySummary {
    /// Components logged as static data.
    pub static_components: BTreeSet<String>,
    /// Components logged on the `frame` timeline, with the distinct frames they were logged at.
    pub frames_per_component: BTreeMap<String, BTreeSet<i64>>,
}

/// Reads every chunk of `path` with the Rerun decoder: the recording's entities, and the
/// blueprint's views apart.
pub fn read_recording(path: &Path) -> Result<Recording> {
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::external::re_log_types::StoreKind;
    let file = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut out = Recording::default();
    // view id → (class, name), filled from separate chunks
    let mut views: BTreeMap<String, (String, String)> = BTreeMap::new();
    let mut messages = 0usize;
    for msg in DecoderApp::decode_lazy(std::io::BufReader::new(file)) {
        let msg = msg.with_context(|| format!("{} is not a readable Rerun recording", path.display()))?;
        messages += 1;
        let rerun::external::re_log_types::LogMsg::ArrowMsg(store, arrow) = msg else { continue };
        let chunk = rerun::log::Chunk::from_arrow_msg(&arrow)
            .with_context(|| format!("{}: a chunk does not decode", path.display()))?;
        let entity = chunk.entity_path().to_string().trim_start_matches('/').to_string();
        if store.kind() == StoreKind::Blueprint {
            if entity.starts_with("container/") {
                out.blueprint.containers += 1;
            }
            let Some(id) = entity.strip_prefix("view/").filter(|id| !id.contains('/')) else { continue };
            let descriptors: Vec<_> = chunk.component_descriptors().cloned().collect();
            for d in descriptors {
                let name = d.component.to_string();
                let text: Option<String> =
                    chunk.iter_slices::<String>(d.component).flat_map(|v| v.into_iter()).map(|s| s.to_string()).next();
                let slot = views.entry(id.to_string()).or_default();
                match (name.rsplit(':').next(), text) {
                    (Some("class_identifier"), Some(t)) => slot.0 = t,
                    (Some("display_name"), Some(t)) => slot.1 = t,
                    _ => {}
                }
            }
            continue;
        }
        let summary = out.entities.entry(entity).or_default();
        let components: Vec<String> = chunk.component_descriptors().map(|d| d.component.to_string()).collect();
        if chunk.is_static() {
            summary.static_components.extend(components);
            continue;
        }
        let frames: Vec<i64> = chunk
            .timelines()
            .iter()
            .find(|(name, _)| name.as_str() == "frame")
            .map(|(_, t)| t.times_raw().to_vec())
            .unwrap_or_default();
        for c in components {
            summary.frames_per_component.entry(c).or_default().extend(frames.iter().copied());
        }
    }
    if messages == 0 {
        bail!("{} is not a readable Rerun recording: it holds no Rerun messages", path.display());
    }
    out.blueprint.views = views.into_values().collect();
    Ok(out)
}

/// The configurations (`world/<name>`) and the fields their surfaces are coloured by
/// (`world/<name>/surface/<field>`).
pub fn configurations_and_fields(entities: &BTreeMap<String, EntitySummary>) -> (Vec<String>, Vec<String>) {
    let mut configs = BTreeSet::new();
    let mut fields = BTreeSet::new();
    for e in entities.keys() {
        if let Some((c, f)) = e.strip_prefix("world/").and_then(|r| r.split_once("/surface/")) {
            configs.insert(c.to_string());
            fields.insert(f.to_string());
        }
    }
    (configs.into_iter().collect(), fields.into_iter().collect())
}

/// Checks that every configuration (`world/<name>/surface/<field>`, every field) was recorded
/// at `frames` frames.
pub fn check_frames(entities: &BTreeMap<String, EntitySummary>, frames: usize) -> Result<Vec<String>> {
    let (configs, fields) = configurations_and_fields(entities);
    if configs.is_empty() {
        bail!("no world/<configuration>/surface/<field> entity: not a hox recording");
    }
    for c in &configs {
        for f in &fields {
            let entity = format!("world/{c}/surface/{f}");
            let Some(surface) = entities.get(&entity) else { bail!("{entity} is missing") };
            if !surface.static_components.contains("Mesh3D:triangle_indices") {
                bail!("{entity} has no static triangle indices");
            }
            for component in ["Mesh3D:vertex_positions", "Mesh3D:vertex_colors"] {
                let n = surface.frames_per_component.get(component).map_or(0, BTreeSet::len);
                if n != frames {
                    bail!("{entity} has {component} at {n} frames, expected {frames}");
                }
            }
        }
        for (entity, component) in
            [(format!("world/{c}/edges"), "LineStrips3D:strips"), (format!("world/{c}/probes"), "Points3D:positions")]
        {
            let n = entities.get(&entity).and_then(|s| s.frames_per_component.get(component)).map_or(0, BTreeSet::len);
            if n != frames {
                bail!("{entity} has {component} at {n} frames, expected {frames}");
            }
        }
        // the paper's figure section, where recorded (the paper's scenes), at every frame too
        if let Some(section) = entities.get(&format!("world/{c}/section")) {
            let n = section.frames_per_component.get("Mesh3D:vertex_positions").map_or(0, BTreeSet::len);
            if n != frames {
                bail!("world/{c}/section has Mesh3D:vertex_positions at {n} frames, expected {frames}");
            }
        }
        for quantity in ["kinetic_energy_j", "elastic_energy_j", "min_det_f"] {
            let entity = format!("plots/{quantity}/{c}");
            let n = entities
                .get(&entity)
                .and_then(|s| s.frames_per_component.get("Scalars:scalars"))
                .map_or(0, BTreeSet::len);
            if n != frames {
                bail!("{entity} has {n} frames, expected {frames}");
            }
        }
    }
    Ok(configs)
}

pub fn inspect(args: &InspectArgs) -> Result<()> {
    let recording = read_recording(&args.file)?;
    let entities = &recording.entities;
    let configs = match args.expect_frames {
        Some(n) => Some(check_frames(entities, n).with_context(|| format!("{}", args.file.display()))?),
        None => None,
    };
    let (_, fields) = configurations_and_fields(entities);
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "entities": entities,
                "configurations": configs,
                "fields": fields,
                "blueprint": recording.blueprint,
            })
        );
        return Ok(());
    }
    for (entity, s) in entities {
        let frames = s.frames_per_component.values().map(BTreeSet::len).max().unwrap_or(0);
        let mut components: Vec<&str> = s.static_components.iter().map(|c| c.as_str()).collect();
        components.extend(s.frames_per_component.keys().map(|c| c.as_str()));
        println!("{entity:<48} {frames:>6} frames  {}", components.join(", "));
    }
    println!("fields: {}", if fields.is_empty() { "none".to_string() } else { fields.join(", ") });
    for f in &fields {
        if let Some(field) = hox_sim::measure::field::Field::from_name(f) {
            println!("  {f}: {}", field.description());
        }
    }
    let b = &recording.blueprint;
    if b.views.is_empty() {
        println!("blueprint: none (the viewer lays the recording out itself)");
    } else {
        println!("blueprint: {} views in {} containers", b.views.len(), b.containers);
        for (class, name) in &b.views {
            println!("  {class:<16} {name}");
        }
    }
    if let Some(configs) = configs {
        println!(
            "ok: {} configuration(s) ({}) recorded at {} frames each",
            configs.len(),
            configs.join(", "),
            args.expect_frames.unwrap_or_default()
        );
    }
    Ok(())
}
