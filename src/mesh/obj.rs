//! Wavefront OBJ: `v` and `f` statements only; everything else (texture
//! coordinates, normals, groups, materials, lines) says nothing about the
//! surface the nozzle follows and is skipped.
//!
//! Byte-level on purpose: scans run to millions of triangles, so no line is
//! copied into a `String` and numbers are parsed from borrowed slices.

use glam::DVec3;

use super::import::Parsed;
use super::MeshError;

pub(super) fn parse(bytes: &[u8], file: &str) -> Result<Parsed, MeshError> {
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut polygon: Vec<u32> = Vec::with_capacity(8);
    let mut faces = 0usize;
    let mut line_no = 0usize;
    let mut rest = bytes;
    while !rest.is_empty() {
        line_no += 1;
        let (line, next) = match rest.iter().position(|&c| c == b'\n') {
            Some(i) => rest.split_at(i + 1),
            None => (rest, &[][..]),
        };
        rest = next;
        let mut cur = Cursor { line, pos: 0 };
        cur.skip_space();
        match (cur.peek(0), cur.peek(1)) {
            (Some(b'v'), Some(c)) if is_space(c) => {
                cur.pos += 1;
                let mut xyz = [0.0f64; 3];
                for (axis, slot) in xyz.iter_mut().enumerate() {
                    let token = cur.token().ok_or_else(|| {
                        MeshError::syntax(
                            file,
                            line_no,
                            format!("vertex has {axis} coordinate(s), needs x y z"),
                        )
                    })?;
                    *slot = parse_f64(token).ok_or_else(|| {
                        MeshError::syntax(
                            file,
                            line_no,
                            format!("'{}' is not a number", String::from_utf8_lossy(token)),
                        )
                    })?;
                }
                // Extra values (w, or the vertex colours some scanners
                // append) carry no geometry.
                let v = DVec3::from_array(xyz);
                if !v.is_finite() {
                    return Err(MeshError::NonFiniteVertex {
                        file: file.into(),
                        vertex: vertices.len() + 1,
                        line: Some(line_no),
                        value: xyz.into_iter().find(|c| !c.is_finite()).unwrap_or(f64::NAN),
                    });
                }
                vertices.push(v);
            }
            (Some(b'f'), Some(c)) if is_space(c) => {
                cur.pos += 1;
                polygon.clear();
                while let Some(token) = cur.token() {
                    let index = resolve(token, vertices.len()).map_err(|e| match e {
                        IndexError::Syntax(message) => MeshError::syntax(file, line_no, message),
                        IndexError::Range(index) => MeshError::IndexOutOfRange {
                            file: file.into(),
                            face: faces,
                            line: Some(line_no),
                            index,
                            vertex_count: vertices.len(),
                        },
                    })?;
                    polygon.push(index);
                }
                if polygon.len() < 3 {
                    return Err(MeshError::syntax(
                        file,
                        line_no,
                        format!("face has {} vertices, needs at least 3", polygon.len()),
                    ));
                }
                triangulate(&polygon, &vertices, &mut triangles);
                faces += 1;
            }
            _ => {}
        }
    }
    Ok(Parsed {
        vertices,
        triangles,
        warnings: Vec::new(),
    })
}

/// Polygons above this many corners are fanned without the ear test (its
/// cost grows with the square of the corner count).
const MAX_EAR_CLIP: usize = 1024;

/// Triangulates a face: a fan when the polygon is convex (every scanner
/// quad), ear clipping in the polygon's own plane (Newell normal) when it is
/// not, so a concave face is covered exactly once with one orientation.
fn triangulate(polygon: &[u32], vertices: &[DVec3], out: &mut Vec<[u32; 3]>) {
    let fan = |out: &mut Vec<[u32; 3]>| {
        for pair in polygon.windows(2).skip(1) {
            out.push([polygon[0], pair[0], pair[1]]);
        }
    };
    let n = polygon.len();
    if n == 3 || n > MAX_EAR_CLIP {
        return fan(out);
    }
    let p: Vec<DVec3> = polygon.iter().map(|&i| vertices[i as usize]).collect();
    let mut normal = DVec3::ZERO;
    for k in 0..n {
        let (a, b) = (p[k], p[(k + 1) % n]);
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let Some(normal) = normal.try_normalize() else {
        return fan(out);
    };
    let turn = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - b).dot(normal);
    if (0..n).all(|k| turn(p[k], p[(k + 1) % n], p[(k + 2) % n]) >= 0.0) {
        return fan(out);
    }
    // Ear clipping over the remaining corners.
    let mut idx: Vec<usize> = (0..n).collect();
    let inside = |q: DVec3, a: DVec3, b: DVec3, c: DVec3| {
        turn(a, b, q) >= 0.0 && turn(b, c, q) >= 0.0 && turn(c, a, q) >= 0.0
    };
    let mut guard = 0;
    while idx.len() > 3 && guard < n * n {
        guard += 1;
        let m = idx.len();
        let ear = (0..m).find(|&k| {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (p[ia], p[ib], p[ic]);
            turn(a, b, c) > 0.0
                && idx
                    .iter()
                    // A corner visited twice (a face that bridges to an
                    // inner outline) sits on the ear's own corners: skip it.
                    .all(|&j| {
                        let q = p[j];
                        q == a || q == b || q == c || !inside(q, a, b, c)
                    })
        });
        let Some(k) = ear else { break };
        let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
        out.push([polygon[ia], polygon[ib], polygon[ic]]);
        idx.remove(k);
    }
    // What is left (a last triangle, or a degenerate remainder) is fanned.
    for pair in idx.windows(2).skip(1) {
        out.push([polygon[idx[0]], polygon[pair[0]], polygon[pair[1]]]);
    }
}

enum IndexError {
    Syntax(String),
    Range(i64),
}

/// A face corner `v`, `v/vt`, `v/vt/vn` or `v//vn` to a 0-based vertex index.
/// Negative indices count back from the last vertex defined so far.
fn resolve(token: &[u8], defined: usize) -> Result<u32, IndexError> {
    let head = token.split(|&c| c == b'/').next().unwrap_or_default();
    let index = parse_i64(head).ok_or_else(|| {
        IndexError::Syntax(format!(
            "'{}' is not a vertex index",
            String::from_utf8_lossy(token)
        ))
    })?;
    let resolved = match index {
        0 => {
            return Err(IndexError::Syntax(
                "vertex index 0 is invalid (OBJ counts vertices from 1)".into(),
            ))
        }
        i if i > 0 => i - 1,
        i => i64::try_from(defined).unwrap_or(i64::MAX).saturating_add(i),
    };
    // OBJ refers to vertices defined before the face; forward references
    // are rejected like other readers do.
    if resolved < 0 || resolved >= i64::try_from(defined).unwrap_or(i64::MAX) {
        return Err(IndexError::Range(index));
    }
    u32::try_from(resolved).map_err(|_| IndexError::Range(index))
}

fn is_space(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | b'\n' | b'\x0c' | b'\x0b')
}

struct Cursor<'a> {
    line: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn peek(&self, ahead: usize) -> Option<u8> {
        self.line.get(self.pos + ahead).copied()
    }

    fn skip_space(&mut self) {
        while self.peek(0).is_some_and(is_space) {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated token; `None` at the end of the line
    /// or at a trailing comment.
    fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_space();
        let start = self.pos;
        if self.peek(0).is_none_or(|c| c == b'#') {
            return None;
        }
        while self.peek(0).is_some_and(|c| !is_space(c)) {
            self.pos += 1;
        }
        self.line.get(start..self.pos)
    }
}

/// A decimal number as Rust's `str::parse::<f64>` reads it (correctly
/// rounded), with a fast path for the plain decimals scanners write.
pub(super) fn parse_f64(token: &[u8]) -> Option<f64> {
    plain_decimal(token).or_else(|| std::str::from_utf8(token).ok()?.parse().ok())
}

/// `[+-]digits[.digits]` (at least one digit) whose digits, read as one
/// integer m, stay below 2^53, with at most 22 after the point: m and
/// 10^k are then exact doubles and m / 10^k is one correctly rounded
/// division, the value `str::parse` gives (Clinger's fast path, which it
/// takes too). `None` for anything else (exponents, long mantissas, inf,
/// nan), which `str::parse` reads.
fn plain_decimal(token: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, body) = match token {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, token),
    };
    let (mut m, mut digits, mut fraction) = (0u64, 0usize, None::<usize>);
    for &c in body {
        match c {
            b'0'..=b'9' => {
                m = m * 10 + u64::from(c - b'0');
                if m >= 1 << 53 {
                    return None;
                }
                digits += 1;
                if let Some(k) = fraction.as_mut() {
                    *k += 1;
                }
            }
            b'.' if fraction.is_none() => fraction = Some(0),
            _ => return None,
        }
    }
    let k = fraction.unwrap_or(0);
    if digits == 0 || k >= POW10.len() {
        return None;
    }
    let v = m as f64 / POW10[k];
    Some(if negative { -v } else { v })
}

/// A signed decimal integer, `None` on anything else or overflow.
pub(super) fn parse_i64(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d - b'0'))?;
    }
    Some(if negative { -value } else { value })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// What `str::parse` reads, bit for bit (NaN as NaN).
    fn std_f64(token: &[u8]) -> Option<u64> {
        let v: f64 = std::str::from_utf8(token).ok()?.parse().ok()?;
        Some(if v.is_nan() { 0 } else { v.to_bits() })
    }

    fn ours(token: &[u8]) -> Option<u64> {
        parse_f64(token).map(|v| if v.is_nan() { 0 } else { v.to_bits() })
    }

    #[test]
    fn numbers_read_as_str_parse_reads_them() {
        let fixed = [
            "0",
            "-0",
            "+0",
            "-0.0",
            "1",
            "1.",
            ".5",
            "-.5",
            "0.1",
            "0.3",
            "-12.345678",
            "9007199254740991",
            "9007199254740992",
            "123456789012.345",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "1e3",
            "1E-3",
            "-2.5e+10",
            "inf",
            "-inf",
            "NaN",
            "infinity",
            ".",
            "-",
            "+",
            "",
            "1.2.3",
            "1-2",
            "0x10",
            " 1",
            "1 ",
            "--1",
            "١",
        ];
        for t in fixed {
            assert_eq!(ours(t.as_bytes()), std_f64(t.as_bytes()), "{t:?}");
        }
        // The fast path takes the plain decimals (and only where it is exact).
        assert_eq!(plain_decimal(b"-12.345678"), Some(-12.345678));
        assert_eq!(plain_decimal(b"1e3"), None);
        assert_eq!(plain_decimal(b"9007199254740992"), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn printed_doubles_read_back_alike(v in proptest::num::f64::NORMAL, k in 0usize..25) {
            let t = format!("{v:.k$}");
            prop_assert_eq!(ours(t.as_bytes()), std_f64(t.as_bytes()), "{}", t);
        }

        #[test]
        fn digit_strings_read_alike(t in "[-+]?[0-9]{0,20}(\\.[0-9]{0,24})?") {
            prop_assert_eq!(ours(t.as_bytes()), std_f64(t.as_bytes()), "{}", t);
        }
    }

    fn parse_str(s: &str) -> Result<Parsed, MeshError> {
        parse(s.as_bytes(), "t.obj")
    }

    #[test]
    fn faces_in_every_corner_form() {
        let p = parse_str(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
             f 1/1/1 2/1/1 3/1/1\nf 1//1 3//1 4//1\nf 1/1 2/1 3/1\n",
        )
        .unwrap();
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    #[test]
    fn negative_indices_count_back_from_the_last_vertex() {
        let p = parse_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 0 1 0\nf -4 -2 -1\n").unwrap();
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn quads_and_pentagons_are_fanned() {
        let p = parse_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nf 1 2 3 4 5 # pentagon\n")
            .unwrap();
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn other_statements_are_ignored() {
        let p = parse_str(
            "mtllib a.mtl\no thing\ng grp\nusemtl red\ns 1\n\tv 0 0 0 1\r\nv 1 0 0\r\n\
             v 0 1 0 0.5 0.5 0.5\nl 1 2\nvp 0.1\nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(p.vertices.len(), 3);
        assert_eq!(p.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_str("v 0 0 0\nv 1 0\n").unwrap_err().to_string();
        assert!(
            e.starts_with("t.obj:2:") && e.contains("needs x y z"),
            "{e}"
        );
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.obj:4:") && e.contains("vertex index 5"),
            "{e}"
        );
        let e = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("vertex index -4"), "{e}");
        let e = parse_str("v 0 0 0\nf 0 1 1\n").unwrap_err().to_string();
        assert!(e.contains("index 0 is invalid"), "{e}");
        let e = parse_str("v 0 nan 0\n").unwrap_err().to_string();
        assert!(e.starts_with("t.obj:1:") && e.contains("non-finite"), "{e}");
        let e = parse_str("v 0 0 0\nv 1 x 0\n").unwrap_err().to_string();
        assert!(e.contains("'x' is not a number"), "{e}");
        let e = parse_str("v 0 0 0\nf 1 1\n").unwrap_err().to_string();
        assert!(e.contains("needs at least 3"), "{e}");
        let e = parse_str("v 0 0 0\nf 1 a 1\n").unwrap_err().to_string();
        assert!(e.contains("not a vertex index"), "{e}");
        let e = parse_str("v 0 0 0\nf 99999999999999999999 1 1\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a vertex index"), "{e}");
    }

    #[test]
    fn integers() {
        assert_eq!(parse_i64(b"-12"), Some(-12));
        assert_eq!(parse_i64(b"+7"), Some(7));
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b"1.5"), None);
    }
}
