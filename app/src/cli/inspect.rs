//! `hox inspect`: read a Rerun .rrd file back and check what it holds.

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

/// What an .rrd file holds, per entity.
#[derive(Debug, Default, serde::Serialize)]
pub struct EntitySummary {
    /// Components logged as static data.
    pub static_components: BTreeSet<String>,
    /// Components logged on the `frame` timeline, with the distinct frames they were logged at.
    pub frames_per_component: BTreeMap<String, BTreeSet<i64>>,
}

/// Reads every chunk of `path` with the Rerun decoder.
pub fn read_rrd(path: &Path) -> Result<BTreeMap<String, EntitySummary>> {
    use rerun::external::re_log_encoding::DecoderApp;
    let file = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut entities: BTreeMap<String, EntitySummary> = BTreeMap::new();
    let mut messages = 0usize;
    for msg in DecoderApp::decode_lazy(std::io::BufReader::new(file)) {
        let msg = msg.with_context(|| format!("{} is not a readable Rerun recording", path.display()))?;
        messages += 1;
        let rerun::external::re_log_types::LogMsg::ArrowMsg(_, arrow) = msg else { continue };
        let chunk = rerun::log::Chunk::from_arrow_msg(&arrow)
            .with_context(|| format!("{}: a chunk does not decode", path.display()))?;
        let entity = chunk.entity_path().to_string().trim_start_matches('/').to_string();
        let summary = entities.entry(entity).or_default();
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
    Ok(entities)
}

/// Checks that every configuration (`world/<name>/surface`) was recorded at `frames` frames.
pub fn check_frames(entities: &BTreeMap<String, EntitySummary>, frames: usize) -> Result<Vec<String>> {
    let configs: Vec<String> = entities
        .keys()
        .filter_map(|e| e.strip_prefix("world/").and_then(|r| r.strip_suffix("/surface")))
        .map(str::to_string)
        .collect();
    if configs.is_empty() {
        bail!("no world/<configuration>/surface entity: not a hox recording");
    }
    for c in &configs {
        let surface = &entities[&format!("world/{c}/surface")];
        if !surface.static_components.contains("Mesh3D:triangle_indices") {
            bail!("world/{c}/surface has no static triangle indices");
        }
        for component in ["Mesh3D:vertex_positions", "Mesh3D:vertex_colors"] {
            let n = surface.frames_per_component.get(component).map_or(0, BTreeSet::len);
            if n != frames {
                bail!("world/{c}/surface has {component} at {n} frames, expected {frames}");
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
    let entities = read_rrd(&args.file)?;
    let configs = match args.expect_frames {
        Some(n) => Some(check_frames(&entities, n).with_context(|| format!("{}", args.file.display()))?),
        None => None,
    };
    if args.json {
        println!("{}", serde_json::json!({ "entities": entities, "configurations": configs }));
        return Ok(());
    }
    for (entity, s) in &entities {
        let frames = s.frames_per_component.values().map(BTreeSet::len).max().unwrap_or(0);
        let mut components: Vec<&str> = s.static_components.iter().map(|c| c.as_str()).collect();
        components.extend(s.frames_per_component.keys().map(|c| c.as_str()));
        println!("{entity:<48} {frames:>6} frames  {}", components.join(", "));
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
