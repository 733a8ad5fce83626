//! Point clouds as text: XYZ, CSV, TXT, ASC and PTS files, one point a
//! line (spec "Inputs", raw point clouds).
//!
//! Values are separated by spaces, tabs, commas or semicolons; in a row
//! separated by semicolons or tabs whose numbers have commas and no point,
//! the commas are decimal commas (a European spreadsheet's CSV); `#` and
//! `//` start comments. x, y and z are the first three columns unless a
//! header line names them (`x,y,z,nx,ny,nz`, CloudCompare's `//X Y Z R G
//! B`); further columns (normals, colour, intensity) are skipped. A first
//! line holding a single integer (the point count of PTS files) is
//! skipped. A row with too few values, a value that is not a number or a
//! coordinate that is not finite is an error naming its line.

use glam::DVec3;

use super::obj::parse_f64;
use super::MeshError;

fn fields(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    fields_in(line, false)
}

/// The values of `line`: separated by spaces, tabs, semicolons and, unless
/// the commas are decimal commas, commas.
fn fields_in(line: &[u8], decimal_comma: bool) -> impl Iterator<Item = &[u8]> {
    line.split(move |&c| c == b' ' || c == b'\t' || c == b';' || (c == b',' && !decimal_comma))
        .filter(|t| !t.is_empty())
}

/// Whether the commas of a data line are decimal commas (spreadsheets in
/// most of Europe write CSV so: `0,0912;0,0896;1,0003`): values separated
/// by semicolons or tabs, and commas but no decimal point.
fn decimal_commas(line: &[u8]) -> bool {
    line.iter().any(|&c| c == b';' || c == b'\t') && line.contains(&b',') && !line.contains(&b'.')
}

/// A value, its decimal comma (if any) read as a point.
fn number(token: &[u8], decimal_comma: bool) -> Option<f64> {
    if !decimal_comma || !token.contains(&b',') {
        return parse_f64(token);
    }
    let mut buf = [0u8; 64];
    let digits = buf.get_mut(..token.len())?;
    for (d, &c) in digits.iter_mut().zip(token) {
        *d = if c == b',' { b'.' } else { c };
    }
    parse_f64(digits)
}

/// The columns of x, y and z named by a header line, if it names them.
fn header_columns(line: &[u8]) -> Option<[usize; 3]> {
    let names: Vec<String> = fields(line)
        .map(|t| {
            String::from_utf8_lossy(t)
                .trim_matches(|c| c == '"' || c == '\'' || c == '/')
                .to_ascii_lowercase()
        })
        .collect();
    let find = |want: &str| {
        names
            .iter()
            .position(|n| n == want || n == &format!("{want}_mm") || n == &format!("{want}[mm]"))
    };
    Some([find("x")?, find("y")?, find("z")?])
}

/// Reads the points of a text point cloud (file units and axes).
pub(super) fn parse(bytes: &[u8], file: &str) -> Result<Vec<DVec3>, MeshError> {
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut columns = [0usize, 1, 2];
    let mut named = false;
    let mut seen_data = false;
    let mut points = Vec::with_capacity(text.len() / 24);
    for (k, raw) in text.split(|&c| c == b'\n').enumerate() {
        let line_no = k + 1;
        let mut line = raw.strip_suffix(b"\r").unwrap_or(raw).trim_ascii();
        let comment = line.starts_with(b"#") || line.starts_with(b"//");
        if comment {
            // CloudCompare writes its header as a comment: "//X,Y,Z,R,G,B".
            if !seen_data && !named {
                if let Some(c) = header_columns(line.trim_ascii_start()) {
                    columns = c;
                    named = true;
                }
            }
            continue;
        }
        if let Some(at) = line.windows(2).position(|w| w == b"//") {
            line = line[..at].trim_ascii_end();
        }
        if let Some(at) = line.iter().position(|&c| c == b'#') {
            line = line[..at].trim_ascii_end();
        }
        if line.is_empty() {
            continue;
        }
        if !seen_data {
            seen_data = true;
            let mut it = fields(line);
            let first = it.next().unwrap_or_default();
            // PTS: the first line is the point count.
            if it.next().is_none() && first.iter().all(u8::is_ascii_digit) {
                continue;
            }
            let comma = decimal_commas(line);
            let numeric = fields_in(line, comma)
                .take(3)
                .all(|t| number(t, comma).is_some());
            if !numeric && !named {
                columns = header_columns(line).ok_or_else(|| MeshError::Syntax {
                    file: file.into(),
                    line: line_no,
                    message: "the first line is neither numbers (x y z) nor a header naming \
                              the columns x, y and z"
                        .into(),
                })?;
                named = true;
                continue;
            }
        }
        let mut p = [0.0f64; 3];
        let mut found = 0;
        let need = columns.iter().max().map_or(3, |m| m + 1);
        let comma = decimal_commas(line);
        for (col, tok) in fields_in(line, comma).enumerate().take(need) {
            let Some(slot) = columns.iter().position(|&c| c == col) else {
                continue;
            };
            let v = number(tok, comma).ok_or_else(|| MeshError::Syntax {
                file: file.into(),
                line: line_no,
                message: format!(
                    "'{}' in column {} is not a number",
                    String::from_utf8_lossy(&tok[..tok.len().min(40)]),
                    col + 1
                ),
            })?;
            if !v.is_finite() {
                return Err(MeshError::Syntax {
                    file: file.into(),
                    line: line_no,
                    message: format!(
                        "{} is {v}: every coordinate of a point must be a finite number",
                        ["x", "y", "z"][slot]
                    ),
                });
            }
            p[slot] = v;
            found += 1;
        }
        if found < 3 {
            return Err(MeshError::Syntax {
                file: file.into(),
                line: line_no,
                message: format!(
                    "{} value(s) where a point needs x, y and z (columns {}, {} and {})",
                    fields_in(line, comma).count(),
                    columns[0] + 1,
                    columns[1] + 1,
                    columns[2] + 1
                ),
            });
        }
        points.push(DVec3::from_array(p));
    }
    if points.is_empty() {
        return Err(MeshError::invalid(file, "the file holds no points"));
    }
    Ok(points)
}

/// Whether `text` looks like a text point cloud: its first data lines
/// (up to 8) hold three or more numbers each (a header line may come
/// first).
pub(super) fn looks_like_xyz(text: &[u8]) -> bool {
    let mut rows = 0;
    for line in text.split(|&c| c == b'\n').take(64) {
        let line = line.trim_ascii();
        if line.is_empty() || line.starts_with(b"#") || line.starts_with(b"//") {
            continue;
        }
        let n = fields(line).take_while(|t| parse_f64(t).is_some()).count();
        if n >= 3 {
            rows += 1;
        } else if rows > 0 || header_columns(line).is_none() {
            return false;
        }
        if rows == 8 {
            break;
        }
    }
    rows > 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_separators_headers_comments_and_extra_columns() {
        let text = b"# a scan\nx,y,z,nx,ny,nz\n1,2,3,0,0,1\n4.5, 5e-1 ,-6 ,0,0,1 // end\n";
        let p = parse(text, "a.csv").unwrap();
        assert_eq!(
            p,
            vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.5, 0.5, -6.0)]
        );
        let text = b"//X Y Z R G B\n1 2 3 255 0 0\n";
        assert_eq!(
            parse(text, "cc.txt").unwrap(),
            vec![DVec3::new(1.0, 2.0, 3.0)]
        );
        // Columns named in another order.
        let text = b"intensity;z;y;x\n9;3;2;1\n";
        assert_eq!(
            parse(text, "o.csv").unwrap(),
            vec![DVec3::new(1.0, 2.0, 3.0)]
        );
        // PTS: a count line first.
        let text = b"2\r\n1 2 3 10 1 2 3\r\n4 5 6 10 1 2 3\r\n";
        assert_eq!(parse(text, "s.pts").unwrap().len(), 2);
    }

    /// A European spreadsheet's CSV (semicolons between values, decimal
    /// commas) was read with its commas as separators: 0,0912 became the
    /// two values 0 and 912, silently. Tab-separated likewise; a row with
    /// decimal points keeps its commas as separators.
    #[test]
    fn regression_decimal_commas_were_separators() {
        let text = b"X;Y;Z\n0,0912;0,0896;1,0003\n-2,5;3;-1,25e1\n";
        assert_eq!(
            parse(text, "eu.csv").unwrap(),
            vec![
                DVec3::new(0.0912, 0.0896, 1.0003),
                DVec3::new(-2.5, 3.0, -12.5)
            ]
        );
        let text = b"1,5\t2,5\t3,5\t255\n";
        assert_eq!(
            parse(text, "eu.txt").unwrap(),
            vec![DVec3::new(1.5, 2.5, 3.5)]
        );
        let text = b"1.5;2;3,4\n";
        assert_eq!(
            parse(text, "mixed.csv").unwrap(),
            vec![DVec3::new(1.5, 2.0, 3.0)]
        );
        // A bad value is still named, as written.
        let e = parse(b"1,5;2;3\n1,5;x,5;3\n", "eu.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("eu.csv:2: 'x,5' in column 2"), "{e}");
    }

    #[test]
    fn bad_rows_are_named_by_line() {
        for (text, line, want) in [
            (&b"1 2 3\n1 2\n"[..], 2, "2 value(s)"),
            (b"1 2 3\n1 two 3\n", 2, "'two' in column 2"),
            (b"1 2 3\n\n1 2 nan\n", 3, "z is NaN"),
            (b"1 2 3\n1 inf 3\n", 2, "y is inf"),
            (b"hello world\n1 2 3\n", 1, "neither numbers"),
        ] {
            let e = parse(text, "p.xyz").unwrap_err().to_string();
            assert!(e.starts_with(&format!("p.xyz:{line}: ")), "{e}");
            assert!(e.contains(want), "{e}");
        }
        let e = parse(b"# nothing\n\n", "p.xyz").unwrap_err().to_string();
        assert!(e.contains("no points"), "{e}");
    }

    #[test]
    fn sniffing() {
        assert!(looks_like_xyz(b"1 2 3\n4 5 6\n"));
        assert!(looks_like_xyz(b"x,y,z\n1,2,3\n"));
        assert!(!looks_like_xyz(b"v 1 2 3\nf 1 2 3\n"));
        assert!(!looks_like_xyz(b"hello\n"));
    }
}
