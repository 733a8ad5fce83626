//! STL, ascii and binary. STL stores every facet's corners separately;
//! bit-identical corners are welded into one indexed vertex so edges shared
//! by two facets are not mistaken for hole boundaries downstream.

use glam::DVec3;

use super::import::{Parsed, Welder};
use super::obj::parse_f64;
use super::ply::Tokens;
use super::MeshError;

const HEADER: usize = 80;
const PREAMBLE: usize = HEADER + 4;
const FACET: usize = 50;

fn declared_triangles(bytes: &[u8]) -> Option<u32> {
    let count: [u8; 4] = bytes.get(HEADER..PREAMBLE)?.try_into().ok()?;
    Some(u32::from_le_bytes(count))
}

fn binary_size(triangles: u32) -> u64 {
    PREAMBLE as u64 + FACET as u64 * u64::from(triangles)
}

/// The file is exactly as long as its binary header says: the only reliable
/// sign of binary STL, whose free 80-byte header may itself begin "solid".
pub(super) fn is_binary_size(bytes: &[u8]) -> bool {
    declared_triangles(bytes).is_some_and(|n| binary_size(n) == bytes.len() as u64)
}

pub(super) fn parse(bytes: &[u8], file: &str) -> Result<Parsed, MeshError> {
    let start = bytes
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    if bytes.get(start..).is_some_and(starts_solid) {
        return match parse_ascii(bytes, file) {
            Err(_) if is_binary_size(bytes) || looks_binary(bytes) => parse_binary(bytes, file),
            result => result,
        };
    }
    parse_binary(bytes, file)
}

/// Whether `text` opens with the keyword `solid`, in any case: some CAD
/// exporters write ASCII STL's keywords in capitals (`SOLID`, `FACET
/// NORMAL`), which readers accept (a QA run's file was read as binary and
/// refused as truncated).
pub(super) fn starts_solid(text: &[u8]) -> bool {
    text.get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
}

/// An ASCII STL keyword, in any case.
fn is(w: &[u8], keyword: &str) -> bool {
    w.eq_ignore_ascii_case(keyword.as_bytes())
}

/// NUL bytes never occur in ascii STL but fill most binary facets; this
/// names the real problem (a size mismatch) for a damaged binary file whose
/// header says "solid".
fn looks_binary(bytes: &[u8]) -> bool {
    bytes.iter().take(4096).any(|&b| b == 0)
}

fn parse_binary(bytes: &[u8], file: &str) -> Result<Parsed, MeshError> {
    // A text-mode copy writes three bytes for each it cannot decode, so
    // the size no longer fits the count: a file that fits is not scanned.
    if !is_binary_size(bytes) {
        let rest = bytes.get(PREAMBLE..).unwrap_or_default();
        if let Some(e) = super::error::text_mode_damage(rest, file, "binary STL") {
            return Err(e);
        }
    }
    let n = declared_triangles(bytes).ok_or_else(|| {
        MeshError::invalid(
            file,
            format!(
                "binary STL is truncated: {} bytes, the header alone needs {PREAMBLE}",
                bytes.len()
            ),
        )
    })?;
    let mut warnings = Vec::new();
    let body = bytes.len().saturating_sub(PREAMBLE) as u64;
    let needed = binary_size(n);
    if (bytes.len() as u64) < needed {
        return Err(MeshError::invalid(
            file,
            format!(
                "binary STL header declares {n} triangles, which need {needed} bytes, \
                 but the file has {} bytes (truncated file or wrong count?)",
                bytes.len()
            ),
        ));
    }
    // Bytes after the declared facets: fewer than a facet's are ignored
    // (a writer's padding); whole facets mean the count is wrong, and are
    // read (a streaming writer that never went back to fill it in leaves
    // 0: QA, "the mesh has no triangles"; QA round 16 F1: a count halved
    // read half the scan with only a warning that bytes were ignored, and
    // its G-code drove the nozzle 3.7 mm into the real part), since
    // triangles left out could be under the nozzle while any read in
    // excess only make the plan more careful (stray or broken ones are
    // refused downstream as ever); more than a facet that are not whole
    // facets are not guessed at.
    let extra = bytes.len() as u64 - needed;
    let n = if extra < FACET as u64 {
        if extra > 0 {
            warnings.push(format!(
                "{file}: ignored {extra} bytes after the {n} triangles the binary STL header \
                 declares"
            ));
        }
        n
    } else if extra.is_multiple_of(FACET as u64) {
        let whole = u32::try_from(body / FACET as u64).map_err(|_| {
            MeshError::invalid(
                file,
                format!("{body} bytes of facets: more than 2^32 of them"),
            )
        })?;
        warnings.push(if n == 0 {
            format!(
                "{file}: the binary STL header declares 0 triangles, but {whole} whole facets \
                 ({body} bytes) follow it (a writer that never filled in the count): read them"
            )
        } else {
            format!(
                "{file}: the binary STL header declares {n} triangles, but {whole} whole facets \
                 follow it (a wrong count, or a damaged file): all {whole} read; check the scan"
            )
        });
        whole
    } else {
        return Err(MeshError::invalid(
            file,
            format!(
                "{extra} bytes follow the {n} triangles the binary STL header declares: more \
                 than a facet ({FACET} bytes), but not whole facets (a wrong count, or a damaged \
                 file); not read, since the scan would lack part of its surface"
            ),
        ));
    };
    // The size check above bounds `n` by the bytes present, so these
    // allocations are proportional to the input.
    let n = n as usize;
    let mut welder = Welder::with_capacity(n);
    let mut triangles = Vec::with_capacity(n);
    let facets = bytes
        .get(PREAMBLE..)
        .unwrap_or_default()
        .chunks_exact(FACET);
    for (facet, chunk) in facets.take(n).enumerate() {
        let mut tri = [0u32; 3];
        for (corner, slot) in tri.iter_mut().enumerate() {
            // 12 bytes of facet normal first, which is recomputed downstream.
            let at = 12 + 12 * corner;
            let mut xyz = [0.0f64; 3];
            for (axis, c) in xyz.iter_mut().enumerate() {
                let b = chunk
                    .get(at + 4 * axis..at + 4 * axis + 4)
                    .and_then(|b| <[u8; 4]>::try_from(b).ok())
                    .unwrap_or_default();
                *c = f64::from(f32::from_le_bytes(b));
            }
            *slot = weld(&mut welder, xyz, file, facet, corner, None)?;
        }
        triangles.push(tri);
    }
    Ok(Parsed {
        vertices: welder.vertices,
        triangles,
        warnings,
        rounding: None,
    })
}

fn weld(
    welder: &mut Welder,
    xyz: [f64; 3],
    file: &str,
    facet: usize,
    corner: usize,
    line: Option<usize>,
) -> Result<u32, MeshError> {
    let p = DVec3::from_array(xyz);
    if !p.is_finite() {
        let message = format!("facet {facet} vertex {corner} has a non-finite coordinate ({p})");
        return Err(match line {
            Some(line) => MeshError::syntax(file, line, message),
            None => MeshError::invalid(file, message),
        });
    }
    welder
        .index(p)
        .ok_or_else(|| MeshError::invalid(file, "more than 2^32 distinct vertices"))
}

fn parse_ascii(bytes: &[u8], file: &str) -> Result<Parsed, MeshError> {
    let mut t = Tokens::new(bytes, 1);
    let mut welder = Welder::default();
    let mut triangles = Vec::new();
    let mut polygon: Vec<u32> = Vec::with_capacity(3);
    let mut facet = 0usize;
    // Facets of more than 3 vertices, which STL does not have (a broken
    // writer's, or a polygon): (how many, the first's facet, line and count).
    let mut polygons = (0usize, None::<(usize, usize, usize)>);
    let expect = |t: &mut Tokens, word: &str| -> Result<(), MeshError> {
        match t.next() {
            Some(w) if is(w, word) => Ok(()),
            Some(w) => Err(MeshError::syntax(
                file,
                t.line,
                format!("expected '{word}', found '{}'", String::from_utf8_lossy(w)),
            )),
            None => Err(MeshError::syntax(
                file,
                t.line,
                format!("file ends where '{word}' was expected (truncated file?)"),
            )),
        }
    };
    // Some exporters write several solids into one file: read them all.
    while let Some(word) = t.next() {
        if !is(word, "solid") {
            return Err(MeshError::syntax(
                file,
                t.line,
                format!(
                    "expected 'solid', found '{}'",
                    String::from_utf8_lossy(word)
                ),
            ));
        }
        t.skip_line();
        loop {
            match t.next() {
                Some(w) if is(w, "endsolid") => {
                    t.skip_line();
                    break;
                }
                Some(w) if is(w, "facet") => {}
                Some(w) => {
                    return Err(MeshError::syntax(
                        file,
                        t.line,
                        format!(
                            "expected 'facet' or 'endsolid', found '{}'",
                            String::from_utf8_lossy(w)
                        ),
                    ))
                }
                None => {
                    return Err(MeshError::syntax(
                        file,
                        t.line,
                        "file ends before 'endsolid' (truncated file? if the file is whole, its \
                         last line 'endsolid' is missing: add it)",
                    ))
                }
            }
            expect(&mut t, "normal")?;
            for _ in 0..3 {
                number(&mut t, file)?;
            }
            expect(&mut t, "outer")?;
            expect(&mut t, "loop")?;
            let loop_line = t.line;
            polygon.clear();
            loop {
                match t.next() {
                    Some(w) if is(w, "vertex") => {
                        let line = t.line;
                        let xyz = [
                            number(&mut t, file)?,
                            number(&mut t, file)?,
                            number(&mut t, file)?,
                        ];
                        let corner = polygon.len();
                        polygon.push(weld(&mut welder, xyz, file, facet, corner, Some(line))?);
                    }
                    Some(w) if is(w, "endloop") => break,
                    Some(w) => {
                        return Err(MeshError::syntax(
                            file,
                            t.line,
                            format!(
                                "expected 'vertex' or 'endloop', found '{}'",
                                String::from_utf8_lossy(w)
                            ),
                        ))
                    }
                    None => {
                        return Err(MeshError::syntax(
                            file,
                            t.line,
                            "file ends inside a facet (truncated file?)",
                        ))
                    }
                }
            }
            expect(&mut t, "endfacet")?;
            if polygon.len() < 3 {
                return Err(MeshError::syntax(
                    file,
                    t.line,
                    format!("facet {facet} has {} vertices, needs 3", polygon.len()),
                ));
            }
            if polygon.len() > 3 {
                polygons.0 += 1;
                polygons.1.get_or_insert((facet, loop_line, polygon.len()));
            }
            for pair in polygon.windows(2).skip(1) {
                triangles.push([polygon[0], pair[0], pair[1]]);
            }
            facet += 1;
        }
    }
    // QA round 13 F5: OpenSCAD's test of a 4-vertex facet was read
    // silently as a quad.
    let warnings = match polygons {
        (n, Some((facet, line, k))) => vec![format!(
            "{file}:{line}: facet {facet} has {k} vertices where an STL facet has 3{}: read as a \
             polygon cut into triangles from its first vertex; if the file was written by a \
             broken exporter, check the part in a viewer",
            if n > 1 {
                format!(" ({n} such facets, this the first)")
            } else {
                String::new()
            }
        )],
        _ => Vec::new(),
    };
    Ok(Parsed {
        vertices: welder.vertices,
        triangles,
        warnings,
        rounding: None,
    })
}

fn number(t: &mut Tokens, file: &str) -> Result<f64, MeshError> {
    let token = t.next().ok_or_else(|| {
        MeshError::syntax(
            file,
            t.line,
            "file ends where a number was expected (truncated file?)",
        )
    })?;
    parse_f64(token).ok_or_else(|| {
        MeshError::syntax(
            file,
            t.line,
            format!("'{}' is not a number", super::import::shown_token(token)),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = "solid two\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   \
        vertex 1 0 0\n   vertex 1 1 0\n  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n   \
        vertex 0 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid two\n";

    #[test]
    fn ascii_is_welded() {
        let p = parse(TWO.as_bytes(), "t.stl").unwrap();
        assert_eq!(p.vertices.len(), 4);
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    }

    /// QA round 13 F5: a facet of 4 vertices (OpenSCAD's own test file of
    /// a broken writer, `toomanyvertices.stl`) was read as a quad without a
    /// word. It is still read (as the polygon it is), with a warning naming
    /// its line.
    #[test]
    fn a_facet_of_more_than_three_vertices_is_warned_of() {
        let quad =
            "solid q\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   \
             vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid q\n";
        let p = parse(quad.as_bytes(), "q.stl").unwrap();
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(
            p.warnings,
            [
                "q.stl:3: facet 0 has 4 vertices where an STL facet has 3: read as a polygon cut \
                 into triangles from its first vertex; if the file was written by a broken \
                 exporter, check the part in a viewer"
            ]
        );
        let two = format!("{TWO}{}", quad.replace("solid q", "solid r"));
        let p = parse(
            two.replace(
                "vertex 0 1 0\n  endloop",
                "vertex 0 1 0\n vertex 0 2 0\n  endloop",
            )
            .as_bytes(),
            "t.stl",
        )
        .unwrap();
        assert!(
            p.warnings[0].starts_with(
                "t.stl:10: facet 1 has 4 vertices where an STL facet has 3 (2 such facets, \
                 this the first)"
            ),
            "{:?}",
            p.warnings
        );
    }

    /// ASCII STL with its keywords in capitals (some CAD exporters), or
    /// just its first word (a QA run's `SOLID` file was read as binary and
    /// refused as a truncated file of 537538848 triangles), reads as the
    /// lower-case file does, and is sniffed as STL without its name.
    #[test]
    fn ascii_keywords_in_any_case() {
        let want = parse(TWO.as_bytes(), "t.stl").unwrap();
        for text in [
            TWO.to_uppercase(),
            TWO.replacen("solid", "SOLID", 1),
            TWO.replace("facet", "Facet"),
        ] {
            let p = parse(text.as_bytes(), "t.stl").unwrap();
            assert_eq!(
                (&p.vertices, &p.triangles),
                (&want.vertices, &want.triangles),
                "{text}"
            );
            assert_eq!(
                crate::mesh::detect_format(text.as_bytes(), ""),
                Some(crate::mesh::MeshFormat::Stl)
            );
        }
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let e = parse(
            TWO.replace("vertex 1 0 0", "vertex 1 inf 0").as_bytes(),
            "t.stl",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("t.stl:5:") && e.contains("non-finite"), "{e}");
        let e = parse(&TWO.as_bytes()[..100], "t.stl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
        let e = parse(TWO.replace("outer loop", "outer lop").as_bytes(), "t.stl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected 'loop', found 'lop'"), "{e}");
        // A stray control byte (openscad's unparseable.stl) was "'' is not
        // a number".
        let e = parse(
            TWO.replace("vertex 1 0 0", "vertex 1 \x10 0").as_bytes(),
            "t.stl",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("t.stl:5:") && e.contains("'\\x10' is not a number"),
            "{e}"
        );
    }

    /// Two facets after a header whose count was left at 0 (found by QA: a
    /// streaming writer's file was "the mesh has no triangles"); a body
    /// that is not whole facets is not guessed at.
    /// One binary facet: a zero normal, the corners, no attribute.
    fn facet(tri: [[f32; 3]; 3]) -> Vec<u8> {
        let mut f = vec![0u8; 12];
        for c in tri {
            f.extend(c.iter().flat_map(|v| v.to_le_bytes()));
        }
        f.extend([0u8; 2]);
        f
    }

    #[test]
    fn a_binary_count_left_at_zero_reads_the_whole_facets_after_it() {
        let mut b = vec![0u8; 84];
        for tri in [
            [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ] {
            b.extend(facet(tri));
        }
        let p = parse(&b, "s.stl").unwrap();
        assert_eq!(p.triangles.len(), 2);
        assert_eq!(p.vertices.len(), 4);
        assert!(
            p.warnings[0].contains("declares 0 triangles, but 2 whole facets (100 bytes) follow"),
            "{:?}",
            p.warnings
        );
        // Not whole facets, and more than one: not guessed at.
        b.push(0);
        let e = parse(&b, "s.stl").unwrap_err().to_string();
        assert!(e.contains("101 bytes follow the 0 triangles"), "{e}");
    }

    /// QA round 16 F1: a count halved in the header read half of a real
    /// scan, with only a warning that bytes were ignored. Whole facets
    /// past the count are read; more than a facet's bytes that are not
    /// whole facets are an error; fewer, a warning.
    #[test]
    fn whole_facets_past_the_declared_count_are_read() {
        let mut b = vec![0u8; 84];
        b[80..84].copy_from_slice(&1u32.to_le_bytes());
        b.extend(facet([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
        b.extend(facet([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]));
        let p = parse(&b, "s.stl").unwrap();
        assert_eq!(p.triangles.len(), 2);
        assert!(
            p.warnings[0].contains("declares 1 triangles, but 2 whole facets follow it"),
            "{:?}",
            p.warnings
        );
        let mut odd = b.clone();
        odd.extend([1u8; 10]);
        let e = parse(&odd, "s.stl").unwrap_err().to_string();
        assert!(
            e.contains("60 bytes follow the 1 triangles") && e.contains("not whole facets"),
            "{e}"
        );
        let mut pad = b[..134].to_vec();
        pad.extend([1u8; 3]);
        let p = parse(&pad, "s.stl").unwrap();
        assert_eq!(p.triangles.len(), 1);
        assert!(
            p.warnings[0].contains("ignored 3 bytes"),
            "{:?}",
            p.warnings
        );
    }

    #[test]
    fn a_text_mode_copy_is_named() {
        let mut b = vec![0u8; 84];
        b[80..84].copy_from_slice(&4u32.to_le_bytes());
        let sound: Vec<u8> = (0..4)
            .flat_map(|k| facet([[k as f32, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, -2.5]]))
            .collect();
        let mut good = b.clone();
        good.extend(&sound);
        assert!(parse(&good, "t.stl").is_ok());
        // Each byte from 0x80 up written as EF BF BD, as a UTF-8 round
        // trip does.
        let mut mangled = b;
        mangled.extend(super::super::error::text_mode_copy(&sound));
        let e = parse(&mangled, "t.stl").unwrap_err().to_string();
        assert!(
            e.starts_with("t.stl: the binary STL looks damaged by a text-mode copy"),
            "{e}"
        );
    }

    #[test]
    fn binary_size_must_match() {
        let mut b = vec![0u8; 84];
        b[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = parse(&b, "t.stl").unwrap_err().to_string();
        assert!(e.contains("declares 4294967295 triangles"), "{e}");
        let e = parse(&b[..40], "t.stl").unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
    }
}
