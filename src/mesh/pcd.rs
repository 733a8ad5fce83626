//! PCD, the Point Cloud Library's format (v0.6/v0.7): DATA ascii, binary
//! and binary_compressed (LZF), fields x, y and z of a float type; every
//! other field (rgb, normals, intensity) is skipped by its size. Points
//! with a NaN coordinate are the format's mark of a missing point in an
//! organized cloud: they are skipped and counted in a warning. An infinite
//! coordinate is an error: named by its line in ascii data, by the
//! import's shared check of every point otherwise.

use glam::DVec3;

use super::obj::parse_f64;
use super::MeshError;

struct Field {
    name: String,
    size: usize,
    kind: u8,
    count: usize,
}

enum Data {
    Ascii,
    Binary,
    Compressed,
}

struct Header {
    fields: Vec<Field>,
    points: usize,
    data: Data,
    /// Byte offset of the data, and the number of header lines.
    body: usize,
    lines: usize,
}

fn syntax(file: &str, line: usize, message: impl Into<String>) -> MeshError {
    MeshError::Syntax {
        file: file.into(),
        line,
        message: message.into(),
    }
}

fn parse_header(bytes: &[u8], file: &str) -> Result<Header, MeshError> {
    let mut names: Vec<String> = Vec::new();
    let (mut sizes, mut types, mut counts) = (Vec::new(), Vec::new(), Vec::new());
    let (mut width, mut height, mut points) = (None, None, None);
    let mut pos = 0usize;
    let mut line_no = 0usize;
    loop {
        line_no += 1;
        let rest = &bytes[pos.min(bytes.len())..];
        if rest.is_empty() {
            return Err(MeshError::invalid(file, "the PCD header has no DATA line"));
        }
        let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
        pos += end + 1;
        let line = rest[..end].trim_ascii();
        if line.is_empty() || line.starts_with(b"#") {
            continue;
        }
        let text = String::from_utf8_lossy(line);
        let mut words = text.split_ascii_whitespace();
        let key = words.next().unwrap_or_default().to_ascii_uppercase();
        let values: Vec<&str> = words.collect();
        let count = |what: &str| -> Result<usize, MeshError> {
            values
                .first()
                .and_then(|v| v.parse::<usize>().ok())
                .ok_or_else(|| syntax(file, line_no, format!("{what} must be a whole number")))
        };
        match key.as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => names = values.iter().map(|s| s.to_ascii_lowercase()).collect(),
            "SIZE" => {
                sizes = values
                    .iter()
                    .map(|v| {
                        v.parse::<usize>()
                            .ok()
                            .filter(|s| matches!(s, 1 | 2 | 4 | 8))
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| syntax(file, line_no, "SIZE values must be 1, 2, 4 or 8"))?
            }
            "TYPE" => {
                types = values
                    .iter()
                    .map(|v| match v.as_bytes() {
                        [c @ (b'F' | b'I' | b'U')] => Some(*c),
                        _ => None,
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| syntax(file, line_no, "TYPE values must be F, I or U"))?
            }
            "COUNT" => {
                counts = values
                    .iter()
                    .map(|v| {
                        v.parse::<usize>()
                            .ok()
                            .filter(|&c| (1..=1 << 16).contains(&c))
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| syntax(file, line_no, "COUNT values must be 1 or more"))?
            }
            "WIDTH" => width = Some(count("WIDTH")?),
            "HEIGHT" => height = Some(count("HEIGHT")?),
            "POINTS" => points = Some(count("POINTS")?),
            "DATA" => {
                let data = match values.first().map(|v| v.to_ascii_lowercase()).as_deref() {
                    Some("ascii") => Data::Ascii,
                    Some("binary") => Data::Binary,
                    Some("binary_compressed") => Data::Compressed,
                    other => {
                        return Err(syntax(
                            file,
                            line_no,
                            format!(
                                "DATA {} is not one of ascii, binary, binary_compressed",
                                other.unwrap_or("")
                            ),
                        ))
                    }
                };
                if counts.is_empty() {
                    counts = vec![1; names.len()];
                }
                if names.is_empty() || sizes.len() != names.len() || types.len() != names.len() {
                    return Err(MeshError::invalid(
                        file,
                        format!(
                            "the PCD header names {} field(s) but gives {} SIZE and {} TYPE \
                             value(s)",
                            names.len(),
                            sizes.len(),
                            types.len()
                        ),
                    ));
                }
                if counts.len() != names.len() {
                    return Err(MeshError::invalid(
                        file,
                        "the PCD header's COUNT does not match its FIELDS",
                    ));
                }
                let points = match (points, width, height) {
                    // QA round 17: a POINTS count changed by hand read the
                    // data to the end without a word; PCL requires both.
                    (Some(p), Some(w), Some(h)) if w.checked_mul(h) != Some(p) => {
                        return Err(MeshError::invalid(
                            file,
                            format!(
                                "the PCD header declares POINTS {p}, but WIDTH x HEIGHT is \
                                 {w} x {h} = {}: one of them is wrong (a damaged file?)",
                                w.saturating_mul(h)
                            ),
                        ))
                    }
                    (Some(p), _, _) => p,
                    (None, Some(w), Some(h)) => w.saturating_mul(h),
                    _ => {
                        return Err(MeshError::invalid(
                            file,
                            "the PCD header gives neither POINTS nor WIDTH and HEIGHT",
                        ))
                    }
                };
                let fields = names
                    .into_iter()
                    .zip(sizes)
                    .zip(types)
                    .zip(counts)
                    .map(|(((name, size), kind), count)| Field {
                        name,
                        size,
                        kind,
                        count,
                    })
                    .collect();
                return Ok(Header {
                    fields,
                    points,
                    data,
                    body: pos.min(bytes.len()),
                    lines: line_no,
                });
            }
            _ => {
                return Err(syntax(
                    file,
                    line_no,
                    format!("'{key}' is not a PCD header keyword"),
                ))
            }
        }
    }
}

/// Where x, y and z are: (field index, byte offset in a point, size).
fn xyz_fields(h: &Header, file: &str) -> Result<[(usize, usize, usize); 3], MeshError> {
    let mut out = [None; 3];
    let mut offset = 0;
    for (k, f) in h.fields.iter().enumerate() {
        if let Some(slot) = ["x", "y", "z"].iter().position(|n| *n == f.name) {
            if f.kind != b'F' || !(f.size == 4 || f.size == 8) {
                return Err(MeshError::invalid(
                    file,
                    format!(
                        "PCD field {} is of type {}{}; x, y and z must be floats (F 4 or F 8)",
                        f.name, f.kind as char, f.size
                    ),
                ));
            }
            out[slot] = Some((k, offset, f.size));
        }
        offset += f.size * f.count;
    }
    match out {
        [Some(x), Some(y), Some(z)] => Ok([x, y, z]),
        _ => Err(MeshError::invalid(
            file,
            "the PCD file has no x, y and z fields (FIELDS must name x y z)",
        )),
    }
}

fn float(b: &[u8], size: usize) -> f64 {
    if size == 4 {
        f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    } else {
        f64::from_le_bytes(b[..8].try_into().unwrap_or([0; 8]))
    }
}

/// Reads the points of a PCD file (file units and axes) and the warnings.
pub(super) fn parse(bytes: &[u8], file: &str) -> Result<(Vec<DVec3>, Vec<String>), MeshError> {
    let h = parse_header(bytes, file)?;
    let xyz = xyz_fields(&h, file)?;
    let step: usize = h.fields.iter().map(|f| f.size * f.count).sum();
    let body = &bytes[h.body..];
    let mut points = Vec::new();
    let mut missing = 0usize;
    let mut ignored_tail = 0usize;
    let mut push = |p: [f64; 3], points: &mut Vec<DVec3>| {
        if p.iter().any(|v| v.is_nan()) {
            missing += 1;
        } else {
            points.push(DVec3::from_array(p));
        }
    };
    match h.data {
        Data::Ascii => {
            // Token index of each field's first value.
            let mut first = Vec::with_capacity(h.fields.len());
            let mut at = 0;
            for f in &h.fields {
                first.push(at);
                at += f.count;
            }
            let tokens_per_point = at;
            let cols = xyz.map(|(k, _, _)| first[k]);
            // One buffer for every line's values.
            let mut toks: Vec<&[u8]> = Vec::with_capacity(tokens_per_point);
            // Records read, NaN ones included (QA round 17: a cloud cut
            // short at a line's end, its last rows lost, read without a
            // word): checked against the header's count both ways.
            let mut records = 0usize;
            let mut last_line = h.lines;
            for (k, raw) in body.split(|&c| c == b'\n').enumerate() {
                let line = raw.trim_ascii();
                if line.is_empty() || line.starts_with(b"#") {
                    continue;
                }
                let line_no = h.lines + k + 1;
                if records == h.points {
                    return Err(syntax(
                        file,
                        line_no,
                        format!(
                            "data after the {} points the PCD header declares: a wrong count \
                             in the header (POINTS, WIDTH x HEIGHT), or a damaged file; not \
                             read, since the scan would lack part of its surface",
                            h.points
                        ),
                    ));
                }
                records += 1;
                last_line = line_no;
                toks.clear();
                toks.extend(
                    line.split(|c| c.is_ascii_whitespace())
                        .filter(|t| !t.is_empty()),
                );
                // Too few values or too many: the header does not describe
                // the line (PCL skips such a point with a warning; a joined
                // or damaged line, or a header that lost a field, would
                // give points from the wrong values: QA round 23 F8).
                if toks.len() != tokens_per_point {
                    return Err(syntax(
                        file,
                        line_no,
                        format!(
                            "{} value(s) where the header's fields need {tokens_per_point}{}",
                            toks.len(),
                            if toks.len() > tokens_per_point {
                                ": a damaged line, or a header whose FIELDS, SIZE, TYPE and COUNT \
                                 describe fewer values than the data holds"
                            } else {
                                ""
                            }
                        ),
                    ));
                }
                let mut p = [0.0; 3];
                for (slot, &c) in cols.iter().enumerate() {
                    let v = parse_f64(toks[c]).ok_or_else(|| {
                        syntax(
                            file,
                            line_no,
                            format!(
                                "'{}' is not a number",
                                String::from_utf8_lossy(&toks[c][..toks[c].len().min(40)])
                            ),
                        )
                    })?;
                    if v.is_infinite() {
                        return Err(syntax(
                            file,
                            line_no,
                            format!(
                                "{} is {v}: coordinates must be finite",
                                ["x", "y", "z"][slot]
                            ),
                        ));
                    }
                    p[slot] = v;
                }
                push(p, &mut points);
            }
            if records < h.points {
                return Err(MeshError::invalid(
                    file,
                    format!(
                        "the PCD header declares {} points, but its data ends after {records} \
                         (line {last_line}): the file is cut short, or the count is wrong",
                        h.points
                    ),
                ));
            }
        }
        Data::Binary => {
            let need = h.points.checked_mul(step).filter(|&n| n <= body.len());
            let Some(need) = need else {
                return Err(MeshError::invalid(
                    file,
                    format!(
                        "the PCD header declares {} points of {step} bytes, but only {} bytes \
                         follow it (the file is cut short)",
                        h.points,
                        body.len()
                    ),
                ));
            };
            // Bytes past the declared points: a writer's padding (NULs,
            // white space, less than a point) is ignored, a point's worth
            // or more is a wrong count (QA round 17, as PLY's since 16).
            let tail = &body[need..];
            if !tail.iter().all(|&b| b == 0 || b.is_ascii_whitespace()) {
                if tail.len() >= step {
                    return Err(MeshError::invalid(
                        file,
                        format!(
                            "{} bytes of data follow the {} points the PCD header declares, \
                             room for {} more (a wrong count in the header, or a damaged \
                             file); not read, since the scan would lack part of its surface",
                            tail.len(),
                            h.points,
                            tail.len() / step.max(1)
                        ),
                    ));
                }
                ignored_tail = tail.len();
            }
            points.reserve(h.points);
            for row in body[..need].chunks_exact(step.max(1)) {
                let p = xyz.map(|(_, off, size)| float(&row[off..], size));
                push(p, &mut points);
            }
        }
        Data::Compressed => {
            let raw = decompress(body, h.points, step, file)?;
            // Column-major: all values of field 0, then field 1, ...
            let mut starts = Vec::with_capacity(h.fields.len());
            let mut at = 0;
            for f in &h.fields {
                starts.push(at);
                at += f.size * f.count * h.points;
            }
            points.reserve(h.points);
            for i in 0..h.points {
                let p = xyz.map(|(k, _, size)| {
                    let f = &h.fields[k];
                    float(&raw[starts[k] + i * size * f.count..], size)
                });
                push(p, &mut points);
            }
        }
    }
    let mut warnings = Vec::new();
    if missing > 0 {
        warnings.push(format!(
            "{file}: skipped {missing} point(s) with NaN coordinates (missing points of the scan)"
        ));
    }
    if ignored_tail > 0 {
        warnings.push(format!(
            "{file}: ignored {ignored_tail} byte(s) after the points the PCD header declares"
        ));
    }
    if points.is_empty() {
        return Err(MeshError::invalid(file, "the file holds no points"));
    }
    Ok((points, warnings))
}

/// binary_compressed: compressed size and uncompressed size (u32 little
/// endian), then the LZF-compressed fields, column by column.
fn decompress(body: &[u8], points: usize, step: usize, file: &str) -> Result<Vec<u8>, MeshError> {
    let bad = |why: &str| MeshError::invalid(file, format!("the compressed PCD data {why}"));
    if body.len() < 8 {
        return Err(bad("is cut short"));
    }
    let csize = u32::from_le_bytes([body[0], body[1], body[2], body[3]]) as usize;
    let usize_ = u32::from_le_bytes([body[4], body[5], body[6], body[7]]) as usize;
    let expected = points
        .checked_mul(step)
        .ok_or_else(|| bad("is too large"))?;
    if usize_ != expected {
        return Err(bad(&format!(
            "unpacks to {usize_} bytes, but {points} points of {step} bytes need {expected}"
        )));
    }
    let input = body.get(8..8 + csize).ok_or_else(|| bad("is cut short"))?;
    // LZF's best ratio: a 3-byte back reference copies at most 264 bytes.
    if expected > 88 * input.len() + 32 {
        return Err(bad(&format!(
            "declares {expected} bytes, more than {} compressed bytes can unpack to",
            input.len()
        )));
    }
    let mut out = Vec::with_capacity(expected);
    let mut i = 0;
    while i < input.len() {
        let ctrl = input[i] as usize;
        i += 1;
        if ctrl < 32 {
            let run = input
                .get(i..i + ctrl + 1)
                .ok_or_else(|| bad("is corrupt"))?;
            out.extend_from_slice(run);
            i += ctrl + 1;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += *input.get(i).ok_or_else(|| bad("is corrupt"))? as usize;
                i += 1;
            }
            let low = *input.get(i).ok_or_else(|| bad("is corrupt"))? as usize;
            i += 1;
            let back = ((ctrl & 0x1f) << 8) + low + 1;
            let from = out
                .len()
                .checked_sub(back)
                .ok_or_else(|| bad("is corrupt"))?;
            for k in 0..len + 2 {
                let b = out[from + k];
                out.push(b);
            }
        }
        if out.len() > expected {
            return Err(bad("unpacks to more bytes than it declares"));
        }
    }
    if out.len() != expected {
        return Err(bad("unpacks to fewer bytes than it declares"));
    }
    Ok(out)
}

/// Whether the bytes start like a PCD header.
pub(super) fn looks_like_pcd(text: &[u8]) -> bool {
    text.starts_with(b"# .PCD") || text.starts_with(b"VERSION") || text.starts_with(b"FIELDS")
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// LZF with literal runs only (valid LZF that any reader must take).
    pub(crate) fn lzf_literal(data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        for chunk in data.chunks(32) {
            out.push((chunk.len() - 1) as u8);
            out.extend_from_slice(chunk);
        }
        out
    }

    const HEAD: &str =
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\n\
                        SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n\
                        VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n";

    fn pts() -> [[f32; 3]; 3] {
        [
            [1.0, 2.0, 3.0],
            [4.0, 5.0, 6.0],
            [f32::NAN, f32::NAN, f32::NAN],
        ]
    }

    #[test]
    fn ascii_binary_and_compressed_read_the_same() {
        let mut ascii = format!("{HEAD}DATA ascii\n");
        for p in pts() {
            ascii += &format!("{} {} {} 4278190080\n", p[0], p[1], p[2]);
        }
        let mut binary = format!("{HEAD}DATA binary\n").into_bytes();
        for p in pts() {
            for v in p {
                binary.extend_from_slice(&v.to_le_bytes());
            }
            binary.extend_from_slice(&7u32.to_le_bytes());
        }
        let mut columns = Vec::new();
        for k in 0..3 {
            for p in pts() {
                columns.extend_from_slice(&p[k].to_le_bytes());
            }
        }
        for _ in pts() {
            columns.extend_from_slice(&7u32.to_le_bytes());
        }
        let packed = lzf_literal(&columns);
        let mut compressed = format!("{HEAD}DATA binary_compressed\n").into_bytes();
        compressed.extend_from_slice(&(packed.len() as u32).to_le_bytes());
        compressed.extend_from_slice(&(columns.len() as u32).to_le_bytes());
        compressed.extend_from_slice(&packed);
        let want = vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)];
        for bytes in [ascii.into_bytes(), binary, compressed] {
            let (p, w) = parse(&bytes, "c.pcd").unwrap();
            assert_eq!(p, want);
            assert!(w[0].contains("skipped 1 point"), "{w:?}");
        }
    }

    #[test]
    fn binary_data_past_the_declared_points() {
        let mut binary = format!("{HEAD}DATA binary\n").into_bytes();
        for p in pts() {
            for v in p {
                binary.extend_from_slice(&v.to_le_bytes());
            }
            binary.extend_from_slice(&7u32.to_le_bytes());
        }
        // A point's worth or more: an error; less: a warning; padding: nothing.
        let mut more = binary.clone();
        more.extend_from_slice(&[1u8; 33]);
        let e = parse(&more, "c.pcd").unwrap_err().to_string();
        assert!(
            e.contains("33 bytes of data follow the 3 points") && e.contains("room for 2 more"),
            "{e}"
        );
        let mut odd = binary.clone();
        odd.extend_from_slice(&[1u8; 5]);
        let (_, w) = parse(&odd, "c.pcd").unwrap();
        assert!(w.iter().any(|w| w.contains("ignored 5 byte(s)")), "{w:?}");
        let mut padded = binary;
        padded.extend_from_slice(&[0u8; 40]);
        let (_, w) = parse(&padded, "c.pcd").unwrap();
        assert_eq!(w.len(), 1, "{w:?}");
    }

    #[test]
    fn lzf_back_references_are_followed() {
        // "abcabcabc": literal "abc", then a back reference of 6 bytes at
        // distance 3 (len - 2 = 4 in the top bits, offset 2).
        let input = [2u8, b'a', b'b', b'c', (4 << 5), 2];
        let mut body = (input.len() as u32).to_le_bytes().to_vec();
        body.extend_from_slice(&9u32.to_le_bytes());
        body.extend_from_slice(&input);
        assert_eq!(decompress(&body, 9, 1, "f").unwrap(), b"abcabcabc");
        // A reference before the start is corrupt, not a panic.
        let mut body = 2u32.to_le_bytes().to_vec();
        body.extend_from_slice(&9u32.to_le_bytes());
        body.extend_from_slice(&[(4 << 5), 9]);
        assert!(decompress(&body, 9, 1, "f").is_err());
    }

    #[test]
    fn hostile_headers_and_bodies_get_errors() {
        for (text, want) in [
            (
                "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n",
                "no x, y and z",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE I I I\nPOINTS 1\nDATA ascii\n1 2 3\n",
                "must be floats",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 10\nDATA binary\n",
                "cut short",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 x 3\n",
                "'x' is not a number",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2\n",
                "2 value(s)",
            ),
            // QA round 23 F8: too many values was read without a word.
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6 7 8 9\n",
                "h.pcd:7: 6 value(s) where the header's fields need 3: a damaged line, or a header",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA zip\n",
                "DATA zip",
            ),
            (
                "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n",
                "SIZE",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\n",
                "no DATA",
            ),
            ("FIELDS x y z\nBOGUS 1\n", "'BOGUS'"),
            // QA round 17: counts checked against the data both ways.
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n",
                "declares 3 points, but its data ends after 2 (line 7): the file is cut short",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n\n4 5 6\n",
                "h.pcd:8: data after the 1 points the PCD header declares",
            ),
            (
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 5\nHEIGHT 2\nPOINTS 9\n\
                 DATA ascii\n1 2 3\n",
                "POINTS 9, but WIDTH x HEIGHT is 5 x 2 = 10",
            ),
        ] {
            let e = match parse(text.as_bytes(), "h.pcd") {
                Err(e) => e.to_string(),
                Ok(p) => panic!("{text:?} read as {p:?}"),
            };
            assert!(e.contains("h.pcd") && e.contains(want), "{text:?}: {e}");
        }
    }
}
