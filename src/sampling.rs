//! Path sampling (spec section 3): each subpath is discretised at two points
//! per nozzle diameter (spacing at most d/2; the paper's n = 2 Lp / d).
//!
//! Decision (spec section 3): every corner of the drawn path is kept as a
//! sample, and each smooth piece between corners is sampled uniformly by arc
//! length, with `n = ceil(len / max_spacing)` intervals.
use glam::DVec2;

use crate::svg::Subpath2;

/// The finest spacing [`sample_subpath`] clamps to (mm): a hundredth of the
/// finest nozzles in use, far below anything a printer resolves.
pub const MIN_SPACING_MM: f64 = 1e-3;

/// Most samples per subpath: ten million at d/2 = 0.3 mm is 3 km of path.
pub const MAX_SAMPLES: usize = 10_000_000;

/// Most samples of one drawing, all its subpaths together (QA round 19
/// F11: vpype's 500-polyline benchmark SVG, 500 subpaths each under the
/// per-subpath limit, scaled to 9.7 M samples, ran 7.6 min, peaked at
/// 5.3 GB and wrote a week of print with no word first).
pub const MAX_DRAWING_SAMPLES: usize = MAX_SAMPLES;

/// From this many samples a drawing is large: the command line says so
/// before it plans (minutes, and gigabytes: [`BYTES_PER_SAMPLE`]); the
/// page plans no more than about this many in one drawing.
pub const LARGE_DRAWING_SAMPLES: usize = 1_000_000;

/// Peak memory a planned sample costs natively, about (QA round 19 F11:
/// 5.28 GB at 9.7 M samples on the demo part, 545 bytes a sample).
pub const BYTES_PER_SAMPLE: f64 = 550.0;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SamplingError {
    /// The spacing is NaN, infinite, zero or negative.
    #[error(
        "sample spacing {value} mm must be a positive finite number (the pipeline uses d/2, \
         spec section 3)"
    )]
    Spacing { value: f64 },
    /// A point of the drawn path is NaN or infinite.
    #[error("{element}: point {index} is not finite")]
    NonFinitePoint { element: String, index: usize },
    /// The path is so long, or the spacing so fine, that the samples would
    /// exceed [`MAX_SAMPLES`].
    #[error(
        "{element}: {count:.0} samples needed at {spacing_mm} mm spacing, more than {MAX_SAMPLES}; \
         check the drawing's units or the nozzle diameter"
    )]
    TooManySamples {
        element: String,
        count: f64,
        spacing_mm: f64,
    },
    /// The drawing as a whole would exceed [`MAX_DRAWING_SAMPLES`] (its
    /// subpaths each within [`MAX_SAMPLES`]).
    #[error(
        "the drawing needs about {:.1} million samples ({:.1} m of path at {spacing_mm} mm \
         spacing, d/2), more than the {} million planned in one drawing; check the drawing's \
         units and scale, or split it into several drawings",
        .count / 1e6,
        .length_mm / 1e3,
        MAX_DRAWING_SAMPLES / 1_000_000
    )]
    DrawingTooLarge {
        count: f64,
        length_mm: f64,
        spacing_mm: f64,
    },
}

/// How large a drawing is as the planner samples it: its length and
/// samples estimated from its drawn length, before any is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawingSize {
    /// At most this many samples (each subpath's length over the spacing,
    /// rounded up, plus one per drawn point: each corner adds at most one).
    pub samples: f64,
    /// The drawn length, scaled (mm).
    pub length_mm: f64,
    /// The spacing it was counted at (mm).
    pub spacing_mm: f64,
}

impl DrawingSize {
    /// The size of `subpaths` scaled by `scale` (the placement's, which
    /// alone changes lengths) and sampled at `spacing_mm` (spec section 3:
    /// d/2).
    pub fn of(subpaths: &[Subpath2], scale: f64, spacing_mm: f64) -> DrawingSize {
        let mut size = DrawingSize {
            samples: 0.0,
            length_mm: 0.0,
            spacing_mm,
        };
        for sub in subpaths {
            let length = sub.length_mm() * scale.abs();
            size.length_mm += length;
            size.samples += estimated_samples(length, sub.points.len(), spacing_mm);
        }
        size
    }

    /// Refuses a drawing past [`MAX_DRAWING_SAMPLES`] (or whose size is
    /// NaN), before a sample is made.
    pub fn check(&self) -> Result<(), SamplingError> {
        if self.samples.is_nan() || self.samples > MAX_DRAWING_SAMPLES as f64 {
            return Err(SamplingError::DrawingTooLarge {
                count: self.samples,
                length_mm: self.length_mm,
                spacing_mm: self.spacing_mm,
            });
        }
        Ok(())
    }

    /// Whether the drawing is large enough to be told of before it is
    /// planned ([`LARGE_DRAWING_SAMPLES`]).
    pub fn is_large(&self) -> bool {
        self.samples >= LARGE_DRAWING_SAMPLES as f64
    }

    /// What a user is told before a large drawing is planned (see
    /// [`Self::is_large`]): its length, its samples, the memory they take
    /// ([`BYTES_PER_SAMPLE`]) and how long it prints at `speed_mm_s`.
    pub fn large_note(&self, speed_mm_s: f64) -> Option<String> {
        if !self.is_large() {
            return None;
        }
        let print = if speed_mm_s > 0.0 && speed_mm_s.is_finite() {
            format!(
                ", and it would print for about {} at {speed_mm_s} mm/s",
                duration_text(self.length_mm / speed_mm_s)
            )
        } else {
            String::new()
        };
        Some(format!(
            "a large drawing: {:.1} m of path, about {:.1} million samples at {} mm spacing \
             (d/2): planning it may take minutes and about {:.1} GB of memory{print}; check the \
             drawing's units and scale (Ctrl-C stops)",
            self.length_mm / 1e3,
            self.samples / 1e6,
            self.spacing_mm,
            self.samples * BYTES_PER_SAMPLE / 1e9,
        ))
    }
}

/// `s` seconds in hours, or in days from two days on.
fn duration_text(s: f64) -> String {
    let hours = s / 3600.0;
    if hours >= 48.0 {
        format!("{:.1} days", hours / 24.0)
    } else {
        format!("{hours:.1} h")
    }
}

/// Samples a subpath of `length_mm` with `points` drawn points needs at
/// `spacing_mm`, at most (see [`DrawingSize::samples`]).
fn estimated_samples(length_mm: f64, points: usize, spacing_mm: f64) -> f64 {
    (length_mm / spacing_mm).ceil() + points as f64
}

/// Samples of one subpath, with the drawn corners marked.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    pub points: Vec<DVec2>,
    /// `corner[i]`: `points[i]` is a corner of the drawn path (or an end of
    /// an open one).
    pub corner: Vec<bool>,
}

/// Samples `sub` at spacing at most `max_spacing_mm` (see the module docs).
///
/// Never fails: a spacing that is NaN, zero, negative or below
/// [`MIN_SPACING_MM`] is clamped to [`MIN_SPACING_MM`] (an infinite one keeps
/// only corners and ends), non-finite points are skipped, and the spacing is
/// widened if the samples would exceed [`MAX_SAMPLES`]. Use
/// [`try_sample_subpath`] to get those cases as errors instead.
pub fn sample_subpath(sub: &Subpath2, max_spacing_mm: f64) -> Vec<DVec2> {
    let spacing = if max_spacing_mm >= MIN_SPACING_MM {
        max_spacing_mm
    } else {
        MIN_SPACING_MM // also catches NaN
    };
    let (points, corner): (Vec<DVec2>, Vec<bool>) = sub
        .points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_finite())
        .map(|(i, &p)| (p, corner_flag(sub, i)))
        .unzip();
    let (points, corner) = merge_close(&points, &corner, spacing);
    let Some(pieces) = pieces(&points, &corner) else {
        return Vec::new();
    };
    let total: f64 = pieces.iter().map(|p| p.len).sum();
    let mut spacing = spacing;
    // Widening keeps memory bounded on absurd inputs; the count of pieces
    // (corners) still bounds what remains.
    if count(&points, &pieces, spacing) > MAX_SAMPLES as f64 {
        spacing = total / (MAX_SAMPLES as f64 - pieces.len() as f64).max(1.0);
    }
    if count(&points, &pieces, spacing) > MAX_SAMPLES as f64 {
        spacing = f64::INFINITY;
    }
    emit(&points, &corner, &pieces, spacing).points
}

/// [`sample_subpath`] that reports a bad spacing, a non-finite point or too
/// many samples as an error.
pub fn try_sample_subpath(
    sub: &Subpath2,
    max_spacing_mm: f64,
) -> Result<Vec<DVec2>, SamplingError> {
    try_sample_subpath_marked(sub, max_spacing_mm).map(|s| s.points)
}

/// [`try_sample_subpath`], also telling which samples are drawn corners.
pub fn try_sample_subpath_marked(
    sub: &Subpath2,
    max_spacing_mm: f64,
) -> Result<Samples, SamplingError> {
    if !(max_spacing_mm.is_finite() && max_spacing_mm > 0.0) {
        return Err(SamplingError::Spacing {
            value: max_spacing_mm,
        });
    }
    if let Some(index) = sub.points.iter().position(|p| !p.is_finite()) {
        return Err(SamplingError::NonFinitePoint {
            element: sub.source.clone(),
            index,
        });
    }
    let corner: Vec<bool> = (0..sub.points.len()).map(|i| corner_flag(sub, i)).collect();
    let (points, corner) = merge_close(&sub.points, &corner, max_spacing_mm);
    let Some(pieces) = pieces(&points, &corner) else {
        return Ok(Samples {
            points: Vec::new(),
            corner: Vec::new(),
        });
    };
    let n = count(&points, &pieces, max_spacing_mm);
    if n.is_nan() || n > MAX_SAMPLES as f64 {
        return Err(SamplingError::TooManySamples {
            element: sub.source.clone(),
            count: n,
            spacing_mm: max_spacing_mm,
        });
    }
    Ok(emit(&points, &corner, &pieces, max_spacing_mm))
}

/// Drawn points closer together than this share of the spacing are one
/// point (at most [`MAX_MERGE_MM`] apart): a drawing's zero-length and
/// near-zero-length segments (an exporter's `v 0`, a curve of 0.001 units
/// that ends where it began, a circle far smaller than the nozzle) would
/// otherwise give samples that coincide, which no spline passes through,
/// or a tangent taken from a micrometre of drawing.
pub const MERGE_FRACTION: f64 = 0.01;

/// The most [`MERGE_FRACTION`] merges over, whatever the spacing (an
/// infinite spacing keeps only the corners).
pub const MAX_MERGE_MM: f64 = 0.01;

/// Points closer than this are one (see [`MERGE_FRACTION`]).
fn merge_distance(spacing: f64) -> f64 {
    (MERGE_FRACTION * spacing).min(MAX_MERGE_MM)
}

/// The drawn polyline with each run of points within the merge distance
/// of the first one kept taken as one point, a corner if any of them is:
/// at the last of them where that is a corner and the one kept is not, or
/// where it ends the path (so the ends, and the corners, stay where they
/// were drawn). Sampling the merged polyline keeps the spacing and the
/// corners exactly.
fn merge_close(points: &[DVec2], corner: &[bool], spacing: f64) -> (Vec<DVec2>, Vec<bool>) {
    let merge = merge_distance(spacing);
    let mut out: Vec<DVec2> = Vec::with_capacity(points.len());
    let mut flags: Vec<bool> = Vec::with_capacity(points.len());
    let last = points.len().saturating_sub(1);
    for (i, &p) in points.iter().enumerate() {
        let c = corner.get(i).copied().unwrap_or(false);
        match (out.last_mut(), flags.last_mut()) {
            (Some(q), Some(f)) if q.distance(p) < merge => {
                if i == last || (c && !*f) {
                    *q = p;
                }
                *f |= c;
            }
            _ => {
                out.push(p);
                flags.push(c);
            }
        }
    }
    (out, flags)
}

/// Ends of open subpaths are always corners; a missing flag (a hand-made
/// Subpath2 with a short `corner`) counts as smooth.
fn corner_flag(sub: &Subpath2, i: usize) -> bool {
    let last = sub.points.len().saturating_sub(1);
    (!sub.closed && (i == 0 || i == last)) || sub.corner.get(i).copied().unwrap_or(false)
}

/// A smooth run of the polyline between two corners: `points[a..=b]`.
struct Piece {
    a: usize,
    b: usize,
    len: f64,
}

/// Splits at corners; the last point always ends a piece (a closed smooth
/// loop is cut at its drawn start).
fn pieces(points: &[DVec2], corner: &[bool]) -> Option<Vec<Piece>> {
    let last = points.len().checked_sub(1)?;
    let mut out = Vec::new();
    let mut a = 0;
    for i in 1..=last {
        let is_corner = i == last || corner.get(i).copied().unwrap_or(false);
        if is_corner {
            let len = points[a..=i].windows(2).map(|w| w[0].distance(w[1])).sum();
            out.push(Piece { a, b: i, len });
            a = i;
        }
    }
    Some(out)
}

/// Samples the pieces would produce (the start point included).
fn count(points: &[DVec2], pieces: &[Piece], spacing: f64) -> f64 {
    1.0 + pieces
        .iter()
        .map(|p| piece_intervals(points, p, spacing))
        .sum::<f64>()
}

/// The fewest intervals a piece that ends where it starts is sampled with
/// (a drawn loop smaller than the spacing, a circle far smaller than the
/// nozzle): one interval would give two samples at the same place, two a
/// move out and back.
const LOOP_INTERVALS: f64 = 3.0;

/// Intervals of `piece` (see [`intervals`]), at least [`LOOP_INTERVALS`]
/// for a loop.
fn piece_intervals(points: &[DVec2], piece: &Piece, spacing: f64) -> f64 {
    let n = intervals(piece.len, spacing);
    let ends = points[piece.a].distance(points[piece.b]);
    if n > 0.0 && ends < merge_distance(spacing) {
        n.max(LOOP_INTERVALS)
    } else {
        n
    }
}

fn intervals(len: f64, spacing: f64) -> f64 {
    if len > 0.0 {
        let n = (len / spacing).ceil().max(1.0);
        // Rounding in len / n must not leave an interval above the spacing.
        if len / n > spacing {
            n + 1.0
        } else {
            n
        }
    } else {
        0.0
    }
}

fn emit(points: &[DVec2], corner: &[bool], pieces: &[Piece], spacing: f64) -> Samples {
    let mut out = Samples {
        points: Vec::new(),
        corner: Vec::new(),
    };
    let Some(&first) = points.first() else {
        return out;
    };
    out.points.push(first);
    out.corner.push(corner.first().copied().unwrap_or(true));
    // A piece that ends where it began, shorter than a spacing (a curve
    // out and back within a few hundredths of a mm, as icon sets draw
    // one), would put its end sample on its start: a sample within the
    // merge distance of the one before is that one, a corner if either is.
    let merge = merge_distance(spacing);
    let push = |out: &mut Samples, p: DVec2, c: bool| match out.points.last() {
        Some(q) if q.distance(p) < merge => {
            if let Some(f) = out.corner.last_mut() {
                *f |= c;
            }
        }
        _ => {
            out.points.push(p);
            out.corner.push(c);
        }
    };
    for piece in pieces {
        let n = piece_intervals(points, piece, spacing);
        if n == 0.0 {
            continue; // coincident corners: one sample already stands there
        }
        let n = n as usize;
        let step = piece.len / n as f64;
        // Walk the polyline once: `j` is the segment holding arc length `s`.
        let mut j = piece.a;
        let mut seg_start = 0.0;
        for k in 1..n {
            let s = step * k as f64;
            while j + 1 < piece.b && seg_start + points[j].distance(points[j + 1]) < s {
                seg_start += points[j].distance(points[j + 1]);
                j += 1;
            }
            let seg_len = points[j].distance(points[j + 1]);
            let t = if seg_len > 0.0 {
                ((s - seg_start) / seg_len).clamp(0.0, 1.0)
            } else {
                0.0
            };
            push(&mut out, points[j].lerp(points[j + 1], t), false);
        }
        let c = corner.get(piece.b).copied().unwrap_or(true);
        push(&mut out, points[piece.b], c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sub(points: &[(f64, f64)], corner: &[bool], closed: bool) -> Subpath2 {
        Subpath2 {
            points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            corner: corner.to_vec(),
            closed,
            source: "test".into(),
        }
    }

    /// A small deterministic generator for the tests.
    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn a_drawings_size_bounds_its_samples_from_above() {
        // Random polylines, some with sharp corners, some curves with
        // points closer than the spacing, scaled up and down: the size
        // counted before sampling is never below what sampling makes.
        let mut seed = 7u64;
        for case in 0..200 {
            let n = 2 + (lcg(&mut seed) * 40.0) as usize;
            let step = [0.01, 0.2, 3.0][case % 3];
            let mut p = (0.0, 0.0);
            let pts: Vec<(f64, f64)> = (0..n)
                .map(|_| {
                    p.0 += (lcg(&mut seed) - 0.5) * step;
                    p.1 += (lcg(&mut seed) - 0.5) * step;
                    p
                })
                .collect();
            let corner: Vec<bool> = (0..n)
                .map(|i| i == 0 || i == n - 1 || lcg(&mut seed) < 0.3)
                .collect();
            let drawn = sub(&pts, &corner, false);
            let scale = [0.5, 1.0, 2.5][case % 3];
            let spacing = 0.3015;
            let scaled = Subpath2 {
                points: drawn.points.iter().map(|&q| q * scale).collect(),
                ..drawn.clone()
            };
            let made = try_sample_subpath(&scaled, spacing).unwrap().len() as f64;
            let size = DrawingSize::of(std::slice::from_ref(&drawn), -scale, spacing);
            assert!(
                made <= size.samples,
                "case {case}: {made} > {}",
                size.samples
            );
            assert!((size.length_mm - scaled.length_mm()).abs() < 1e-9 * size.length_mm.max(1.0));
        }
    }

    #[test]
    fn a_drawing_past_its_limit_is_refused_and_a_large_one_is_told_of() {
        let spacing = 0.3;
        // Subpaths each within the limit for one, together past the one
        // for a drawing (QA round 19 F11: 500 of them made 9.7 M samples).
        let line = sub(&[(0.0, 0.0), (1.8e6, 0.0)], &[true, true], false);
        let one = DrawingSize::of(std::slice::from_ref(&line), 1.0, spacing);
        assert!(one.samples < MAX_SAMPLES as f64 && one.check().is_ok());
        let two = DrawingSize::of(&[line.clone(), line.clone()], 1.0, spacing);
        match two.check() {
            Err(e @ SamplingError::DrawingTooLarge { .. }) => {
                let m = e.to_string();
                assert!(
                    m.contains("about 12.0 million samples (3600.0 m of path"),
                    "{m}"
                );
                assert!(m.contains("more than the 10 million"), "{m}");
            }
            other => panic!("{other:?}"),
        }
        // The placement's scale counts: halved, the two fit.
        assert!(DrawingSize::of(&[line.clone(), line], 0.5, spacing)
            .check()
            .is_ok());

        // Told of from LARGE_DRAWING_SAMPLES on, with its memory and print.
        let short = sub(&[(0.0, 0.0), (299_000.0, 0.0)], &[true, true], false);
        let size = DrawingSize::of(std::slice::from_ref(&short), 1.0, spacing);
        assert!(!size.is_large() && size.large_note(5.0).is_none());
        let long = sub(&[(0.0, 0.0), (3.0e6, 0.0)], &[true, true], false);
        let size = DrawingSize::of(std::slice::from_ref(&long), 1.0, spacing);
        assert!(size.is_large());
        let note = size.large_note(5.0).unwrap();
        assert!(
            note.starts_with("a large drawing: 3000.0 m of path, about 10.0 million samples"),
            "{note}"
        );
        assert!(note.contains("about 5.5 GB of memory"), "{note}");
        assert!(
            note.contains("print for about 6.9 days at 5 mm/s"),
            "{note}"
        );
        let hours = DrawingSize::of(std::slice::from_ref(&short), 1.1, spacing);
        let note = hours.large_note(5.0).unwrap();
        assert!(note.contains("print for about 18.3 h at 5 mm/s"), "{note}");
        // A NaN size (a NaN scale) is refused, not passed.
        assert!(
            DrawingSize::of(std::slice::from_ref(&short), f64::NAN, spacing)
                .check()
                .is_err()
        );
    }

    #[test]
    fn a_curve_out_and_back_shorter_than_a_spacing_gives_no_coincident_samples() {
        // mdi's wrench-clock icon: "M16 8C16 8 15.9 8 16 8C12.1 8.1 ...",
        // a curve that leaves its start by 0.03 units and returns to it,
        // flattened, at 0.2646 mm a unit, then the path goes on.
        let mm = 0.2646;
        let pts = [
            (16.0, 8.0),
            (15.97, 8.0),
            (16.0, 8.0),
            (12.1, 8.1),
            (9.0, 11.2),
        ];
        let s = sub(
            &pts.map(|(x, y)| (x * mm, y * mm)),
            &[true, false, true, false, true],
            false,
        );
        let got = try_sample_subpath_marked(&s, 0.3015).unwrap();
        for w in got.points.windows(2) {
            assert!(
                w[0].distance(w[1]) >= merge_distance(0.3015),
                "{:?}",
                got.points
            );
        }
        assert_eq!(got.points.len(), got.corner.len());
        assert_eq!(got.points[0], DVec2::new(16.0 * mm, 8.0 * mm));
        assert_eq!(*got.points.last().unwrap(), DVec2::new(9.0 * mm, 11.2 * mm));
    }

    #[test]
    fn straight_line_is_uniform() {
        let s = sub(
            &[(0.0, 0.0), (3.0, 0.0), (10.0, 0.0)],
            &[true, false, true],
            false,
        );
        let out = sample_subpath(&s, 0.3);
        assert_eq!(out.len(), 35); // ceil(10 / 0.3) = 34 intervals
        let d: Vec<f64> = out.windows(2).map(|w| w[0].distance(w[1])).collect();
        let (lo, hi) = d
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(hi <= 0.3 && (hi / lo - 1.0).abs() < 1e-9);
    }

    #[test]
    fn corners_are_samples() {
        let s = sub(
            &[(0.0, 0.0), (1.05, 0.0), (1.05, 1.05)],
            &[true, true, true],
            false,
        );
        let out = sample_subpath(&s, 0.5);
        assert!(out.contains(&DVec2::new(1.05, 0.0)));
        assert_eq!(out.len(), 7);
    }

    /// No two consecutive samples closer than a hundredth of the spacing,
    /// and a spline through them.
    fn assert_apart(points: &[DVec2], spacing: f64) {
        if points.len() >= 2 {
            let flat: Vec<glam::DVec3> = points.iter().map(|p| p.extend(0.0)).collect();
            crate::spline::local_geometry(&flat).unwrap();
        }
        for (i, w) in points.windows(2).enumerate() {
            assert!(
                w[0].distance(w[1]) >= 0.01 * spacing,
                "samples {i} and {} at {} and {}",
                i + 1,
                w[0],
                w[1]
            );
        }
    }

    #[test]
    fn regression_a_tiny_curve_that_ends_where_it_began_gave_coincident_samples() {
        // An exporter's `M 5,10 c 0,0.001 0.001,0.001 0,0 L 35,10` (and
        // Illustrator's `v 0 c 0,1e-3 1e-3,1e-3 0,0`): a corner, a 0.001 mm
        // loop, a corner at the same place, then a line.
        let s = sub(
            &[
                (5.0, 10.0),
                (5.0, 10.0007),
                (5.0008, 10.0007),
                (5.0, 10.0),
                (5.0, 10.0),
                (35.0, 10.0),
            ],
            &[true, false, false, true, true, true],
            false,
        );
        for spacing in [0.3015, 0.05] {
            let out = try_sample_subpath(&s, spacing).unwrap();
            assert_apart(&out, spacing);
            assert_eq!(out[0], DVec2::new(5.0, 10.0));
            assert_eq!(*out.last().unwrap(), DVec2::new(35.0, 10.0));
            let widest = out
                .windows(2)
                .map(|w| w[0].distance(w[1]))
                .fold(0.0, f64::max);
            assert!(widest <= spacing * (1.0 + 1e-12), "{widest} for {spacing}");
            assert_apart(&sample_subpath(&s, spacing), spacing);
        }
    }

    #[test]
    fn a_loop_smaller_than_the_spacing_keeps_its_shape() {
        // A closed circle of radius 0.036 mm (a footprint's via): 0.23 mm
        // around, less than d/2; one interval would put both samples at
        // its start.
        let n = 64;
        let pts: Vec<(f64, f64)> = (0..=n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                (1.0 + 0.036 * a.cos(), 2.0 + 0.036 * a.sin())
            })
            .collect();
        let s = sub(&pts, &[], true);
        let out = try_sample_subpath(&s, 0.3015).unwrap();
        assert_eq!(out.len(), 4, "{out:?}");
        assert_apart(&out, 0.3015);
        assert_eq!(out[0], out[3]);
        // A dot (all its points within the merge distance) is one sample.
        let dot = sub(&[(1.0, 1.0), (1.001, 1.0), (1.0, 1.0)], &[], true);
        assert_eq!(try_sample_subpath(&dot, 0.3015).unwrap().len(), 1);
    }

    #[test]
    fn points_closer_than_the_merge_distance_are_one_keeping_corners_and_ends() {
        // A corner 2 um past a smooth point, and an end 1 um past another.
        let s = sub(
            &[
                (0.0, 0.0),
                (1.0, 0.0),
                (1.000002, 0.0),
                (1.0, 1.0),
                (1.0, 1.000001),
            ],
            &[true, false, true, false, true],
            false,
        );
        let m = merge_close(&s.points, &[true, false, true, false, true], 0.3);
        assert_eq!(
            m.0,
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.000002, 0.0),
                DVec2::new(1.0, 1.000001)
            ]
        );
        assert_eq!(m.1, vec![true, true, true]);
        let out = try_sample_subpath(&s, 0.3).unwrap();
        assert!(out.contains(&DVec2::new(1.000002, 0.0)));
        assert_eq!(*out.last().unwrap(), DVec2::new(1.0, 1.000001));
        assert_apart(&out, 0.3);
    }

    #[test]
    fn degenerate_and_bad_spacing_do_not_hang() {
        let dot = sub(&[(1.0, 1.0), (1.0, 1.0)], &[true, true], false);
        assert_eq!(sample_subpath(&dot, 0.3), vec![DVec2::new(1.0, 1.0)]);
        let line = sub(&[(0.0, 0.0), (1.0, 0.0)], &[], false);
        for bad in [f64::NAN, 0.0, -1.0, f64::NEG_INFINITY] {
            assert!(try_sample_subpath(&line, bad).is_err());
            assert_eq!(sample_subpath(&line, bad).len(), 1001);
        }
        assert_eq!(sample_subpath(&line, f64::INFINITY).len(), 2);
        let huge = sub(&[(0.0, 0.0), (1e300, 0.0)], &[], false);
        assert!(try_sample_subpath(&huge, 0.3).is_err());
        assert!(sample_subpath(&huge, 0.3).len() <= MAX_SAMPLES);
        assert!(sample_subpath(&sub(&[], &[], false), 0.3).is_empty());
    }
}
