//! The paper's antenna paths as SVG text (spec "The paper's test part and
//! prints"): a spiral (556 mm), a Hilbert-curve loop and a triangular
//! monopole. Each is drawn in mm (`width="..mm"` with a viewBox in mm, so one
//! user unit is one mm), stroked and unfilled. The viewBox is centred on the
//! antenna's reference point (the spiral's and loop's centre, the monopole's
//! apex); as with any SVG, import measures from the page's top-left corner,
//! so that point lands at (`x`, -`y`) mm with `x`, `y` its distances from
//! the page's left and top edges, and a [`crate::svg::Placement`] moves it
//! onto the part.
use std::f64::consts::TAU;
use std::fmt::Write as _;

/// Stroke width drawn in the SVGs: the paper's 20 gauge nozzle (0.603 mm);
/// it only affects how the file looks in a viewer.
const STROKE_MM: f64 = 0.603;

/// Length of the paper's spiral antenna (mm).
pub const PAPER_SPIRAL_LENGTH_MM: f64 = 556.0;
/// Pitch of the built-in spiral: 1.5 mm between turns leaves 0.9 mm between
/// 0.6 mm lines, and 556 mm then fits in ~33 mm, on the paper's R 27 mm
/// hemisphere.
pub const PAPER_SPIRAL_PITCH_MM: f64 = 1.5;
pub const PAPER_SPIRAL_INNER_RADIUS_MM: f64 = 1.0;

const MAX_TURNS: f64 = 1000.0;
const MAX_SIZE_MM: f64 = 10_000.0;

/// A generator argument out of range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AntennaError {
    #[error("invalid antenna parameter {name} = {value}: {reason}")]
    Parameter {
        name: &'static str,
        value: String,
        reason: String,
    },
}

fn check_size(name: &'static str, value: f64, allow_zero: bool) -> Result<(), AntennaError> {
    let ok =
        value.is_finite() && value <= MAX_SIZE_MM && (value > 0.0 || allow_zero && value == 0.0);
    if ok {
        Ok(())
    } else {
        Err(AntennaError::Parameter {
            name,
            value: crate::params::shown(value),
            reason: format!(
                "must be a finite length above {} and at most {MAX_SIZE_MM} mm",
                if allow_zero { "or equal to 0" } else { "0" }
            ),
        })
    }
}

/// Length (mm) of the Archimedean spiral r = a + b theta, b = pitch / 2 pi,
/// over `turns` turns from radius `a`: the closed form of
/// integral sqrt(r^2 + b^2) dtheta = (1/b) integral sqrt(r^2 + b^2) dr.
pub fn archimedean_spiral_length_mm(turns: f64, pitch_mm: f64, inner_radius_mm: f64) -> f64 {
    let b = pitch_mm / TAU;
    let f = |r: f64| {
        let h = (r * r + b * b).sqrt();
        0.5 * r * h + 0.5 * b * b * libm::log(r + h)
    };
    let outer = inner_radius_mm + pitch_mm * turns;
    (f(outer) - f(inner_radius_mm)) / b
}

/// Turns of the built-in spiral that make it [`PAPER_SPIRAL_LENGTH_MM`] long.
pub fn paper_spiral_turns() -> f64 {
    // Length grows monotonically with turns: bisection on a bracket.
    let (mut lo, mut hi) = (0.0, 100.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        let len =
            archimedean_spiral_length_mm(mid, PAPER_SPIRAL_PITCH_MM, PAPER_SPIRAL_INNER_RADIUS_MM);
        if len < PAPER_SPIRAL_LENGTH_MM {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The paper's spiral antenna: 556 mm long (1853 points at d = 0.603 mm in
/// the paper, n = 2 Lp / d).
pub fn paper_spiral_svg() -> String {
    spiral_svg(
        paper_spiral_turns(),
        PAPER_SPIRAL_PITCH_MM,
        PAPER_SPIRAL_INNER_RADIUS_MM,
    )
}

/// An Archimedean spiral r = inner + pitch * theta / 2 pi over `turns`
/// turns, centred on the origin, as one smooth path of cubic Beziers.
pub fn archimedean_spiral_svg(
    turns: f64,
    pitch_mm: f64,
    inner_radius_mm: f64,
) -> Result<String, AntennaError> {
    if !(turns.is_finite() && turns > 0.0 && turns <= MAX_TURNS) {
        return Err(AntennaError::Parameter {
            name: "turns",
            value: crate::params::shown(turns),
            reason: format!("must be a finite number above 0 and at most {MAX_TURNS}"),
        });
    }
    check_size("pitch_mm", pitch_mm, false)?;
    check_size("inner_radius_mm", inner_radius_mm, true)?;
    Ok(spiral_svg(turns, pitch_mm, inner_radius_mm))
}

fn spiral_svg(turns: f64, pitch_mm: f64, inner_radius_mm: f64) -> String {
    let b = pitch_mm / TAU;
    let total = turns * TAU;
    // Sixteen cubics per turn, end points and tangent directions exact (so
    // joins are smooth), handles of length (4/3) tan(step/4) |P'|: the
    // circle's best cubic, within ~1e-7 r of the spiral at this step.
    let n = (turns * 16.0).ceil().max(1.0) as usize;
    let step = total / n as f64;
    let handle = 4.0 / 3.0 * libm::tan(step / 4.0);
    // SVG y points down; drawing (x, -y) makes the imported spiral turn
    // counter-clockwise in the printer frame.
    let point = |t: f64| {
        let r = inner_radius_mm + b * t;
        (r * libm::cos(t), -(r * libm::sin(t)))
    };
    let deriv = |t: f64| {
        let r = inner_radius_mm + b * t;
        (
            b * libm::cos(t) - r * libm::sin(t),
            -(b * libm::sin(t) + r * libm::cos(t)),
        )
    };
    let mut d = String::new();
    let (x0, y0) = point(0.0);
    let _ = write!(d, "M {} {}", num(x0), num(y0));
    for k in 0..n {
        let (t0, t1) = (step * k as f64, step * (k + 1) as f64);
        let (p0, p1) = (point(t0), point(t1));
        let (d0, d1) = (deriv(t0), deriv(t1));
        let h = handle;
        let _ = write!(
            d,
            " C {} {} {} {} {} {}",
            num(p0.0 + d0.0 * h),
            num(p0.1 + d0.1 * h),
            num(p1.0 - d1.0 * h),
            num(p1.1 - d1.1 * h),
            num(p1.0),
            num(p1.1)
        );
    }
    let half = inner_radius_mm + pitch_mm * turns + 2.0 * STROKE_MM;
    document(-half, -half, 2.0 * half, 2.0 * half, &path("spiral", &d))
}

/// A Hilbert-curve loop antenna of the given order: the Moore curve, the
/// closed variant of the Hilbert curve (four order n-1 Hilbert curves joined
/// into a loop), on a 2^order x 2^order grid of cells filling a
/// `size_mm` square centred on the origin.
pub fn hilbert_loop_svg(order: u32, size_mm: f64) -> Result<String, AntennaError> {
    if !(1..=8).contains(&order) {
        return Err(AntennaError::Parameter {
            name: "order",
            value: order.to_string(),
            reason: "must be 1 to 8".into(),
        });
    }
    check_size("size_mm", size_mm, false)?;
    let cells = moore_curve(order);
    let n = f64::from(1u32 << order);
    let cell = size_mm / n;
    let at = |(i, j): (i64, i64)| {
        let x = (i as f64 + 0.5) * cell - 0.5 * size_mm;
        let y = (j as f64 + 0.5) * cell - 0.5 * size_mm;
        (x, -y)
    };
    let mut d = String::new();
    for (k, &c) in cells.iter().enumerate() {
        // Only turning cells are written; straight runs need no vertex.
        let straight = k > 0
            && k + 1 < cells.len()
            && (c.0 - cells[k - 1].0, c.1 - cells[k - 1].1)
                == (cells[k + 1].0 - c.0, cells[k + 1].1 - c.1);
        if straight {
            continue;
        }
        let (x, y) = at(c);
        let _ = write!(
            d,
            "{}{} {} ",
            if k == 0 { "M " } else { "L " },
            num(x),
            num(y)
        );
    }
    d.push('Z');
    let half = 0.5 * size_mm + STROKE_MM;
    Ok(document(
        -half,
        -half,
        2.0 * half,
        2.0 * half,
        &path("hilbert-loop", &d),
    ))
}

/// Cells of the Moore curve of `order` (4^order cells, each adjacent to the
/// next and the last adjacent to the first), from its L-system:
/// axiom LFL+F+LFL, L -> -RF+LFL+FR-, R -> +LF-RFR-FL+, 90 degree turns.
fn moore_curve(order: u32) -> Vec<(i64, i64)> {
    let mut program = b"LFL+F+LFL".to_vec();
    for _ in 1..order {
        let mut next = Vec::with_capacity(program.len() * 4);
        for &c in &program {
            match c {
                b'L' => next.extend_from_slice(b"-RF+LFL+FR-"),
                b'R' => next.extend_from_slice(b"+LF-RFR-FL+"),
                other => next.push(other),
            }
        }
        program = next;
    }
    let mut pos = (0i64, 0i64);
    let mut dir = (0i64, 1i64);
    let mut cells = vec![pos];
    for c in program {
        match c {
            b'F' => {
                pos = (pos.0 + dir.0, pos.1 + dir.1);
                cells.push(pos);
            }
            b'+' => dir = (-dir.1, dir.0),
            b'-' => dir = (dir.1, -dir.0),
            _ => {}
        }
    }
    let min_x = cells.iter().map(|c| c.0).min().unwrap_or(0);
    let min_y = cells.iter().map(|c| c.1).min().unwrap_or(0);
    cells.iter().map(|c| (c.0 - min_x, c.1 - min_y)).collect()
}

/// A triangular monopole: an isosceles triangle outline `height_mm` tall on
/// a `base_mm` top edge, its apex at the origin, and a straight feed line
/// `feed_mm` long from the apex away from the triangle (to the connector).
pub fn triangular_monopole_svg(
    height_mm: f64,
    base_mm: f64,
    feed_mm: f64,
) -> Result<String, AntennaError> {
    check_size("height_mm", height_mm, false)?;
    check_size("base_mm", base_mm, false)?;
    check_size("feed_mm", feed_mm, false)?;
    let (h, w) = (height_mm, 0.5 * base_mm);
    // Printer y up: the triangle above the apex, the feed below (SVG y = -y).
    let triangle = format!("M 0 0 L {} {} L {} {} Z", num(-w), num(-h), num(w), num(-h));
    let feed = format!("M 0 0 L 0 {}", num(feed_mm));
    let m = 2.0 * STROKE_MM;
    let body = format!("{}{}", path("feed", &feed), path("triangle", &triangle));
    Ok(document(
        -w - m,
        -h - m,
        2.0 * (w + m),
        h + feed_mm + 2.0 * m,
        &body,
    ))
}

fn num(v: f64) -> String {
    // Nine decimals: far below the flattening tolerance, and never "-0".
    let s = format!("{v:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" | "" => "0".to_string(),
        s => s.to_string(),
    }
}

fn path(id: &str, d: &str) -> String {
    format!(
        "  <path id=\"{id}\" d=\"{d}\" fill=\"none\" stroke=\"#b87333\" stroke-width=\"{STROKE_MM}\" \
         stroke-linecap=\"round\" stroke-linejoin=\"round\"/>\n"
    )
}

fn document(x: f64, y: f64, w: f64, h: f64, body: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}mm\" height=\"{h}mm\" \
         viewBox=\"{x} {y} {w} {h}\">\n{body}</svg>\n",
        x = num(x),
        y = num(y),
        w = num(w),
        h = num(h),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spiral_length_closed_form_matches_a_sum() {
        let (turns, pitch, a) = (3.0, 2.0, 1.0);
        let b = pitch / TAU;
        let n = 200_000;
        let mut len = 0.0;
        let mut prev = (a, 0.0);
        for k in 1..=n {
            let t = turns * TAU * k as f64 / n as f64;
            let r = a + b * t;
            let p = (r * libm::cos(t), r * libm::sin(t));
            len += ((p.0 - prev.0).powi(2) + (p.1 - prev.1).powi(2)).sqrt();
            prev = p;
        }
        assert!((archimedean_spiral_length_mm(turns, pitch, a) - len).abs() < 1e-6);
    }

    #[test]
    fn moore_curve_is_a_loop_of_adjacent_cells() {
        for order in 1..=5 {
            let cells = moore_curve(order);
            assert_eq!(cells.len(), 1 << (2 * order));
            let step = |a: (i64, i64), b: (i64, i64)| (a.0 - b.0).abs() + (a.1 - b.1).abs();
            assert!(cells.windows(2).all(|w| step(w[0], w[1]) == 1));
            assert_eq!(step(cells[0], cells[cells.len() - 1]), 1);
        }
    }

    #[test]
    fn bad_arguments_are_errors() {
        assert!(archimedean_spiral_svg(f64::NAN, 1.0, 1.0).is_err());
        assert!(archimedean_spiral_svg(3.0, 0.0, 1.0).is_err());
        assert!(archimedean_spiral_svg(3.0, 1.0, -1.0).is_err());
        assert!(archimedean_spiral_svg(3.0, 1.0, 0.0).is_ok());
        assert!(hilbert_loop_svg(0, 10.0).is_err());
        assert!(hilbert_loop_svg(9, 10.0).is_err());
        assert!(hilbert_loop_svg(3, f64::INFINITY).is_err());
        assert!(triangular_monopole_svg(10.0, 5.0, -1.0).is_err());
        assert!(num(-0.0000000001) == "0" && num(2.5) == "2.5" && num(-3.0) == "-3");
    }
}
