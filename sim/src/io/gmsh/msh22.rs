//! MSH 2.2 (ASCII and binary), parsed by hand (`mshio` reads 4.1 only) into the raw elements and
//! nodes [`super::build`] turns into a mesh; errors name the line (ASCII).

use super::*;

/// The body of section `name` (between its header line and `$End…`) and the line its body
/// starts on; None when the file has no such section.
fn section<'a>(bytes: &'a [u8], name: &str, file: &str) -> Result<Option<(&'a [u8], usize)>, GmshError> {
    let open = format!("${name}");
    let close = format!("$End{name}");
    let Some(start) = find_line(bytes, open.as_bytes()) else {
        return Ok(None);
    };
    // the body starts on the line after the section's name
    let body = bytes[start..].iter().position(|&c| c == b'\n').map_or(bytes.len(), |nl| start + nl + 1);
    let end = find(&bytes[body..], close.as_bytes()).map(|e| body + e).ok_or_else(|| GmshError::Parse {
        file: file.into(),
        at: format!(":{}", line_of(bytes, start)),
        message: format!("${name} is not closed by {close}"),
    })?;
    Ok(Some((&bytes[body..end], line_of(bytes, body))))
}

/// A `$Name` at the start of a line (not inside, e.g., `$EndName`).
fn find_line(bytes: &[u8], needle: &[u8]) -> Option<usize> {
    let mut from = 0;
    while let Some(p) = find(&bytes[from..], needle) {
        let p = from + p;
        let at_line_start = p == 0 || bytes[p - 1] == b'\n';
        let followed = bytes.get(p + needle.len()).is_none_or(|c| c.is_ascii_whitespace());
        if at_line_start && followed {
            return Some(p);
        }
        from = p + 1;
    }
    None
}

pub(super) fn parse_ascii(bytes: &[u8], file: &str) -> Result<RawMsh, GmshError> {
    let mut raw = RawMsh::default();
    let err = |line: usize, message: String| GmshError::Parse { file: file.into(), at: format!(":{line}"), message };
    if let Some((body, first)) = section(bytes, "Nodes", file)? {
        let text = String::from_utf8_lossy(body);
        let mut lines = text.lines().enumerate().map(|(k, l)| (first + k, l.trim())).filter(|(_, l)| !l.is_empty());
        let (count_line, count) = lines.next().ok_or_else(|| err(first, "$Nodes has no node count".into()))?;
        let count: usize = count.parse().map_err(|_| err(count_line, format!("bad node count \"{count}\"")))?;
        for (line, l) in lines {
            let v: Vec<&str> = l.split_whitespace().collect();
            let bad = || err(line, format!("bad node line \"{l}\" (expected: tag x y z)"));
            if v.len() != 4 {
                return Err(bad());
            }
            let tag: u64 = v[0].parse().map_err(|_| bad())?;
            let mut p = [0.0; 3];
            for d in 0..3 {
                p[d] = v[d + 1].parse().map_err(|_| bad())?;
            }
            raw.nodes.push((tag, p));
        }
        if raw.nodes.len() != count {
            return Err(err(count_line, format!("$Nodes announces {count} nodes but lists {}", raw.nodes.len())));
        }
    }
    if let Some((body, first)) = section(bytes, "Elements", file)? {
        let text = String::from_utf8_lossy(body);
        let mut lines = text.lines().enumerate().map(|(k, l)| (first + k, l.trim())).filter(|(_, l)| !l.is_empty());
        let (count_line, count) = lines.next().ok_or_else(|| err(first, "$Elements has no element count".into()))?;
        let count: usize = count.parse().map_err(|_| err(count_line, format!("bad element count \"{count}\"")))?;
        for (line, l) in lines {
            let bad =
                || err(line, format!("bad element line \"{l}\" (expected: tag type number-of-tags tags… nodes…)"));
            let v: Vec<u64> =
                l.split_whitespace().map(|s| s.parse::<u64>()).collect::<Result<_, _>>().map_err(|_| bad())?;
            if v.len() < 3 || v.len() < 3 + v[2] as usize {
                return Err(bad());
            }
            let ntags = v[2] as usize;
            let tags = &v[3..3 + ntags];
            raw.elements.push(RawElement {
                tag: v[0],
                gmsh_type: u32::try_from(v[1]).map_err(|_| bad())?,
                nodes: v[3 + ntags..].to_vec(),
                physical: tags.first().filter(|&&t| t != 0).map(|&t| t as i32).into_iter().collect(),
                line: Some(line),
            });
        }
        if raw.elements.len() != count {
            return Err(err(
                count_line,
                format!("$Elements announces {count} elements but lists {}", raw.elements.len()),
            ));
        }
    }
    Ok(raw)
}

/// A little-endian/native reader over a binary section body.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    swap: bool,
}

impl Cursor<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let mut out: [u8; N] = self.bytes.get(self.pos..self.pos + N)?.try_into().ok()?;
        self.pos += N;
        if self.swap {
            out.reverse();
        }
        Some(out)
    }
    fn i32(&mut self) -> Option<i32> {
        self.take::<4>().map(i32::from_ne_bytes)
    }
    fn f64(&mut self) -> Option<f64> {
        self.take::<8>().map(f64::from_ne_bytes)
    }
    /// The ASCII count line at the start of a binary section.
    fn count_line(&mut self) -> Option<usize> {
        let end = self.bytes[self.pos..].iter().position(|&c| c == b'\n')?;
        let s = std::str::from_utf8(&self.bytes[self.pos..self.pos + end]).ok()?.trim().parse().ok()?;
        self.pos += end + 1;
        Some(s)
    }
}

pub(super) fn parse_binary(bytes: &[u8], file: &str) -> Result<RawMsh, GmshError> {
    let err = |message: &str| GmshError::Parse {
        file: file.into(),
        at: String::new(),
        message: format!("MSH 2.2 binary: {message}"),
    };
    // the header line is followed by the integer 1 written in the file's byte order
    let (format_body, _) = section(bytes, "MeshFormat", file)?.ok_or_else(|| err("no $MeshFormat"))?;
    let nl = format_body.iter().position(|&c| c == b'\n').ok_or_else(|| err("truncated $MeshFormat"))?;
    let one: [u8; 4] =
        format_body.get(nl + 1..nl + 5).and_then(|s| s.try_into().ok()).ok_or_else(|| err("truncated $MeshFormat"))?;
    let swap = match i32::from_ne_bytes(one) {
        1 => false,
        x if x.swap_bytes() == 1 => true,
        _ => return Err(err("bad byte-order mark in $MeshFormat")),
    };
    let mut raw = RawMsh::default();
    if let Some((body, _)) = section(bytes, "Nodes", file)? {
        let mut c = Cursor { bytes: body, pos: 0, swap };
        let n = c.count_line().ok_or_else(|| err("bad node count"))?;
        for _ in 0..n {
            let tag = c.i32().ok_or_else(|| err("truncated $Nodes"))?;
            let p = [c.f64(), c.f64(), c.f64()];
            let [Some(x), Some(y), Some(z)] = p else { return Err(err("truncated $Nodes")) };
            raw.nodes.push((tag as u64, [x, y, z]));
        }
    }
    if let Some((body, _)) = section(bytes, "Elements", file)? {
        let mut c = Cursor { bytes: body, pos: 0, swap };
        let n = c.count_line().ok_or_else(|| err("bad element count"))?;
        let truncated = || err("truncated $Elements");
        while raw.elements.len() < n {
            let gmsh_type = c.i32().ok_or_else(truncated)?;
            let following = c.i32().ok_or_else(truncated)?;
            let ntags = c.i32().ok_or_else(truncated)?;
            let nodes_per =
                gmsh_type_info(gmsh_type as u32).map(|i| i.1).ok_or_else(|| GmshError::UnknownElementType {
                    file: file.into(),
                    at: String::new(),
                    element_tag: 0,
                    gmsh_type: gmsh_type as u32,
                })?;
            if following <= 0 || ntags < 0 {
                return Err(err("bad element block header"));
            }
            for _ in 0..following {
                let tag = c.i32().ok_or_else(truncated)?;
                let tags: Vec<i32> = (0..ntags).map(|_| c.i32()).collect::<Option<_>>().ok_or_else(truncated)?;
                let nodes: Vec<u64> =
                    (0..nodes_per).map(|_| c.i32().map(|t| t as u64)).collect::<Option<_>>().ok_or_else(truncated)?;
                raw.elements.push(RawElement {
                    tag: tag as u64,
                    gmsh_type: gmsh_type as u32,
                    nodes,
                    physical: tags.first().filter(|&&t| t != 0).copied().into_iter().collect(),
                    line: None,
                });
            }
        }
    }
    Ok(raw)
}
