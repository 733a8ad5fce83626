//! The values of flags: typed values and the parsers clap calls on a flag's
//! text (`value_parser = ...` in `args.rs`). Their messages say what is
//! wrong and how to write it; clap puts the flag and value in front.

use std::ops::RangeInclusive;

use pcpp::gcode::MAX_COORDINATE_MM;
use pcpp::job::FiducialSource;
use pcpp::registration::parse_points;
use pcpp::svg::Placement;
use pcpp::{DVec2, DVec3};

// Bounds, as --tol and --speed have theirs: past them a number is a typo
// or garbage, and taking it only moved the failure to a later message
// that printed it in full (`--place 1e308,0` gave a 309-digit span).

/// Offsets and points in the printer frame, mm: the G-code reader's limit
/// (a kilometre), far past any build volume.
const MAX_PRINTER_MM: f64 = MAX_COORDINATE_MM;
/// Points in the scanner's frame, mm: 10 000 km, so that a georeferenced
/// scan's coordinates (millions of mm) are taken, in any frame on Earth.
const MAX_SCAN_MM: f64 = 1e10;
/// A rotation, degrees either way: one turn.
const MAX_ROTATION_DEG: f64 = 360.0;
/// The drawing's scale.
const SCALES: RangeInclusive<f64> = 1e-3..=1e3;
/// `--max-edge`, mm.
const MAX_EDGE_MM: f64 = 1e6;

/// `--place`: where the drawing goes, or centred on the scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaceArg {
    /// `centre`: the offset is found once the scan is read.
    pub centre: bool,
    /// A scale was given (`centre` then keeps it rather than fit the
    /// drawing to the scan).
    pub scale_given: bool,
    pub placement: Placement,
}

/// `--place-scan`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaceScanArg {
    AsScanned,
    /// On the bed, then moved and turned.
    OnBed {
        offset_mm: DVec3,
        rotation_deg: f64,
    },
}

/// A list of points `x,y,z;x,y,z;...` (one value, not a list of values).
#[derive(Debug, Clone, PartialEq)]
pub struct Points(pub Vec<DVec3>);

/// A finite number.
fn parse_number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

pub fn number(text: &str) -> Result<f64, String> {
    parse_number(text).ok_or_else(|| format!("'{text}' is not a number"))
}

/// `--max-edge`: the library refuses a non-positive one too, but naming
/// the scan, as bad input.
pub fn max_edge(text: &str) -> Result<f64, String> {
    let d = number(text)?;
    if d > 0.0 && d <= MAX_EDGE_MM {
        Ok(d)
    } else {
        Err(format!("must be above 0 and at most {MAX_EDGE_MM:e} mm"))
    }
}

pub fn dot_diameter(text: &str) -> Result<f64, String> {
    let d = number(text)?;
    if d > 0.0 && d <= 100.0 {
        Ok(d)
    } else {
        Err("must be above 0 and at most 100 mm".into())
    }
}

/// Points whose coordinates are at most `max` mm from the origin of
/// `frame`.
fn points_within(text: &str, max: f64, frame: &str) -> Result<Points, String> {
    let points = parse_points(text).map_err(|e| e.to_string())?;
    for (i, p) in points.iter().enumerate() {
        if let Some(v) = p.to_array().into_iter().find(|v| v.abs() > max) {
            return Err(format!(
                "point {} has a coordinate of {v:e} mm, beyond the {max:e} mm this program \
                 takes in the {frame} frame (check the units: points are in mm)",
                i + 1
            ));
        }
    }
    Ok(Points(points))
}

/// Points in the printer frame (`--printer-points`).
pub fn printer_points(text: &str) -> Result<Points, String> {
    points_within(text, MAX_PRINTER_MM, "printer")
}

/// Points in the scanner's frame (`--fiducials`, `register --scan-points`).
pub fn scan_points(text: &str) -> Result<Points, String> {
    points_within(text, MAX_SCAN_MM, "scanner's")
}

/// `--fiducials`: `auto` or points in the scanner's frame (never
/// [`FiducialSource::None`]: that is the flag left out).
pub fn fiducials(text: &str) -> Result<FiducialSource, String> {
    if text.trim().eq_ignore_ascii_case("auto") {
        Ok(FiducialSource::Auto)
    } else {
        scan_points(text).map(|p| FiducialSource::Points(p.0))
    }
}

/// A number of `field` (as typed in `text`, so a huge one is not printed
/// in full) within `range`.
fn bounded(
    text: &str,
    range: RangeInclusive<f64>,
    field: &str,
    unit: &str,
    write: &str,
) -> Result<f64, String> {
    let v = parse_number(text).ok_or_else(|| format!("'{text}' is not a number; {write}"))?;
    if range.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{field} '{text}' is not between {} and {}{unit}; {write}",
            short(*range.start()),
            short(*range.end())
        ))
    }
}

/// A bound as people write it: 360, 0.001, 1e6.
fn short(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e4).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// An offset in the printer frame, mm.
fn offset(text: &str, field: &str, write: &str) -> Result<f64, String> {
    bounded(text, -MAX_PRINTER_MM..=MAX_PRINTER_MM, field, " mm", write)
}

/// A rotation, degrees.
fn rotation(text: &str, write: &str) -> Result<f64, String> {
    bounded(
        text,
        -MAX_ROTATION_DEG..=MAX_ROTATION_DEG,
        "the rotation",
        " degrees",
        write,
    )
}

/// `X,Y[,ROT_DEG[,SCALE]]` or `centre[,ROT_DEG[,SCALE]]` (`center` too).
pub fn place(text: &str) -> Result<PlaceArg, String> {
    let (centre, fields, expected) = match centre_word(text) {
        Some(rest) => (true, rest, 0..=2),
        None => (false, text, 2..=4),
    };
    let parts: Vec<&str> = fields
        .split(',')
        .map(str::trim)
        .filter(|p| !(centre && p.is_empty()))
        .collect();
    let write = "write X,Y[,ROT_DEG[,SCALE]] or centre[,ROT_DEG[,SCALE]]";
    if !expected.contains(&parts.len()) {
        return Err(if centre {
            format!("centre takes at most a rotation and a scale; {write}")
        } else {
            format!("expected 2 to 4 numbers, got {}; {write}", parts.len())
        });
    }
    // Offset x, y, rotation, scale; `centre` gives only the last two.
    let mut v = [0.0, 0.0, 0.0, 1.0];
    let first = if centre { 2 } else { 0 };
    for (i, (slot, p)) in v[first..].iter_mut().zip(&parts).enumerate() {
        *slot = match first + i {
            0 => offset(p, "X", write)?,
            1 => offset(p, "Y", write)?,
            2 => rotation(p, write)?,
            _ => bounded(p, SCALES, "the scale", "", write)?,
        };
    }
    let placement = Placement {
        offset_mm: DVec2::new(v[0], v[1]),
        rotation_deg: v[2],
        scale: v[3],
    };
    placement.validate().map_err(|e| e.to_string())?;
    Ok(PlaceArg {
        centre,
        scale_given: first + parts.len() == 4,
        placement,
    })
}

/// `centre` or `center`, and what follows it.
fn centre_word(text: &str) -> Option<&str> {
    let t = text.trim();
    ["centre", "center"].iter().find_map(|w| {
        t.get(..w.len())
            .filter(|h| h.eq_ignore_ascii_case(w))
            .map(|_| t[w.len()..].trim_start_matches(','))
    })
}

/// `bed[,DX,DY,DZ[,ROT_DEG]]` or `as-is`.
pub fn place_scan(text: &str) -> Result<PlaceScanArg, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts[0].to_ascii_lowercase().as_str() {
        "as-is" | "asis" | "none" if parts.len() == 1 => Ok(PlaceScanArg::AsScanned),
        "bed" => {
            let write = "write bed or bed,DX,DY,DZ[,ROT_DEG]";
            if !matches!(parts.len(), 1 | 4 | 5) {
                return Err(format!(
                    "expected 1, 4 or 5 fields, got {}; {write}",
                    parts.len()
                ));
            }
            let mut v = [0.0; 4];
            for (i, (slot, p)) in v.iter_mut().zip(&parts[1..]).enumerate() {
                *slot = match i {
                    0 => offset(p, "DX", write)?,
                    1 => offset(p, "DY", write)?,
                    2 => offset(p, "DZ", write)?,
                    _ => rotation(p, write)?,
                };
            }
            Ok(PlaceScanArg::OnBed {
                offset_mm: DVec3::new(v[0], v[1], v[2]),
                rotation_deg: v[3],
            })
        }
        other => Err(format!(
            "'{other}' is not a placement; write bed, bed,DX,DY,DZ[,ROT_DEG] or as-is"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn place_takes_offsets_and_centre() {
        let p = place("0,80").unwrap();
        assert!(!p.centre);
        assert_eq!(p.placement.offset_mm, DVec2::new(0.0, 80.0));
        assert!(!p.scale_given && !place("0,80,10").unwrap().scale_given);
        assert!(place("0,80,10,2").unwrap().scale_given);
        assert!(!place("centre").unwrap().scale_given);
        assert!(!place("centre,90").unwrap().scale_given);
        let p = place(" centre,90,0.5").unwrap();
        assert!(p.centre && p.scale_given);
        assert_eq!((p.placement.rotation_deg, p.placement.scale), (90.0, 0.5));
        assert!(place("Center").unwrap().centre);
        assert!(place("1,y").unwrap_err().contains("'y' is not a number"));
        assert!(place("1").unwrap_err().contains("got 1"));
        assert!(place("centre,1,2,3").is_err());
        assert!(place("0,0,0,0").is_err(), "a zero scale");
    }

    #[test]
    fn place_scan_takes_bed_and_moves() {
        assert_eq!(place_scan("as-is"), Ok(PlaceScanArg::AsScanned));
        assert_eq!(
            place_scan("bed,1,2,-3,45"),
            Ok(PlaceScanArg::OnBed {
                offset_mm: DVec3::new(1.0, 2.0, -3.0),
                rotation_deg: 45.0
            })
        );
        assert!(place_scan("bed,1").unwrap_err().contains("got 2"));
        assert!(place_scan("floor").unwrap_err().contains("'floor'"));
    }

    #[test]
    fn placements_and_points_are_bounded() {
        let e = place("1e308,0").unwrap_err();
        assert!(
            e.contains("X '1e308' is not between -1e6 and 1e6 mm"),
            "{e}"
        );
        assert!(place("0,-1e6,-360,1e3").is_ok() && place("0,1e6,360,1e-3").is_ok());
        assert!(place("0,0,361")
            .unwrap_err()
            .contains("-360 and 360 degrees"));
        assert!(place("centre,0,1e-4")
            .unwrap_err()
            .contains("the scale '1e-4' is not between 0.001 and 1000;"));
        assert!(place_scan("bed,0,0,2e6").unwrap_err().contains("DZ '2e6'"));
        assert!(place_scan("bed,0,0,0,1e308")
            .unwrap_err()
            .contains("rotation"));
        let e = printer_points("1,2,3;4,5,1e308").unwrap_err();
        assert!(e.starts_with("point 2 has a coordinate of 1e308 mm"), "{e}");
        assert!(!e.contains("  "), "{e}");
        assert!(scan_points("2.4e6,1,0").is_ok());
        assert!(fiducials("1e11,0,0").is_err());
        assert!(max_edge("0").is_err() && max_edge("-1").is_err() && max_edge("2e6").is_err());
        assert_eq!(max_edge("2.5"), Ok(2.5));
    }

    #[test]
    fn numbers_are_finite() {
        assert_eq!(number(" 1.5"), Ok(1.5));
        assert!(number("inf").is_err());
        assert!(number("NaN").is_err());
        assert!(dot_diameter("0").is_err());
        assert!(dot_diameter("101").is_err());
    }
}
