//! MSH 4.1 (ASCII and binary), parsed by the `mshio` crate into the raw elements and nodes
//! [`super::build`] turns into a mesh.

use super::*;

pub(super) fn parse(bytes: &[u8], file: &str) -> Result<RawMsh, GmshError> {
    // mshio still has a few `unimplemented!`s for inputs it does not handle: turn those
    // panics into errors too
    let parsed = std::panic::catch_unwind(|| mshio::parse_msh_bytes(bytes).map_err(|e| e.to_string()));
    let msh = match parsed {
        Ok(Ok(msh)) => msh,
        Ok(Err(message)) => return Err(parse_error(file, &message)),
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "malformed file".into());
            return Err(parse_error(file, &message));
        }
    };
    let mut raw = RawMsh::default();
    // physical tags of each entity
    let mut physical: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &msh.data.entities {
        for p in &ent.points {
            physical.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &ent.curves {
            physical.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &ent.surfaces {
            physical.insert((2, s.tag), s.physical_tags.clone());
        }
        for v in &ent.volumes {
            physical.insert((3, v.tag), v.physical_tags.clone());
        }
    }
    if let Some(nodes) = &msh.data.nodes {
        let mut next_tag = nodes.min_node_tag;
        for block in &nodes.node_blocks {
            let tags: Vec<u64> = match &block.node_tags {
                Some(map) => {
                    let mut t = vec![0; block.nodes.len()];
                    for (&tag, &i) in map {
                        t[i] = tag;
                    }
                    t
                }
                None => (0..block.nodes.len() as u64).map(|i| next_tag + i).collect(),
            };
            next_tag += block.nodes.len() as u64;
            for (tag, n) in tags.into_iter().zip(&block.nodes) {
                raw.nodes.push((tag, [n.x, n.y, n.z]));
            }
        }
    }
    if let Some(elements) = &msh.data.elements {
        for block in &elements.element_blocks {
            let gmsh_type = block.element_type as u32;
            let phys = physical.get(&(block.entity_dim, block.entity_tag)).cloned().unwrap_or_default();
            for el in &block.elements {
                raw.elements.push(RawElement {
                    tag: el.element_tag,
                    gmsh_type,
                    nodes: el.nodes.clone(),
                    physical: phys.clone(),
                    line: None,
                });
            }
        }
    }
    Ok(raw)
}

fn parse_error(file: &str, message: &str) -> GmshError {
    // mshio's messages can quote a long stretch of the input: keep the first lines
    let short: Vec<&str> = message.lines().take(6).collect();
    GmshError::Parse {
        file: file.into(),
        at: String::new(),
        message: format!("malformed MSH 4.1 file: {}", short.join(" / ")),
    }
}
