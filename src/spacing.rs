//! Lines of the drawing closer together than the filament is wide (part of
//! stage 4, after sampling, spec section 3).
//!
//! The paper prints lines far apart; a drawing whose lines come closer than
//! the nozzle's inner diameter d (the filament's width, spec section 7) gets
//! one merged band there: for an antenna or a sensor, a short circuit (a
//! Hilbert loop of order 7 at 20 mm has lines 0.16 mm apart, and planned
//! without a word). Decision (ours, the spec is silent): the plan warns
//! when a sample of the drawn path lies within d of another part of the
//! path, in XY as placed, where "another part" is another subpath, or one
//! more than [`APART_PER_D`] d away along the same subpath (around its
//! closure, for a closed one): the neighbours along a line, and the two
//! legs of a corner blunter than about 40 degrees, are not other lines. It
//! is a warning, not an error: a filled area drawn as a raster overlaps its
//! lines on purpose. What that passes over, a piece (or the whole drawing)
//! folded up within a few d, is warned of as a blob ([`blobs`]).

use glam::DVec2;

/// How far apart along one subpath (in d) two places must be to count as
/// two lines: two legs of a corner of angle a, each longer than this, come
/// within d of each other where sin(a/2) < 1 / APART_PER_D.
pub const APART_PER_D: f64 = 3.0;

/// One sampled subpath as placed (printer mm).
pub struct Line<'a> {
    pub source: &'a str,
    /// Its samples: what the tests judge, as what prints.
    pub points: &'a [DVec2],
    pub closed: bool,
    /// The subpath as drawn (its flattened polyline, placed): the length
    /// and box a warning gives, those the user can measure in the drawing
    /// (QA round 7 F9: a drawing of 2.42 mm of line in a 0.27 x 0.31 mm
    /// box was said to be 1.13 mm in 0.18 x 0.24 mm, its samples' figures).
    pub drawn: &'a [DVec2],
}

/// The length of a polyline (closed: back to its first point too) and its
/// box.
fn extent(points: &[DVec2], closed: bool) -> (f64, DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    let mut length = 0.0;
    for (k, &p) in points.iter().enumerate() {
        if k > 0 {
            length += points[k - 1].distance(p);
        }
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if let (true, Some(first), Some(last)) = (closed, points.first(), points.last()) {
        length += last.distance(*first);
    }
    (length, lo, hi)
}

/// Where the drawing's lines come within d of each other.
#[derive(Debug, Clone, PartialEq)]
pub struct CloseLines {
    /// How many samples lie within d of another line.
    pub samples: usize,
    /// The path around them: half of each segment beside each (mm).
    pub length_mm: f64,
    /// The smallest distance found between a sample and another line
    /// (mm): exact among the first 256 samples flagged and every 16th
    /// after them, the others counting with the first line they found.
    pub closest_mm: f64,
    /// The first such sample (in drawing order) and its subpath.
    pub first: DVec2,
    pub source: String,
}

impl CloseLines {
    /// The plan's warning.
    pub fn message(&self, d: f64) -> String {
        // Under the G-code's resolution, "within 0.000 mm" would read as
        // nothing: lines that cross, touch or lie on each other.
        let how = if self.closest_mm < 5e-4 {
            "meet (cross, touch or lie on each other)".to_string()
        } else {
            format!("come within {:.3} mm of each other", self.closest_mm)
        };
        format!(
            "lines of the drawing {how}, less than the nozzle's inner diameter ({d:.3} mm, the \
             filament's width) apart, along about {:.1} mm of the path, the first at ({:.3}, \
             {:.3}) in '{}': their filaments will merge there (for an antenna or a sensor, a \
             short circuit); draw the lines further apart, or scale the drawing up, unless \
             the area is meant to be filled",
            self.length_mm, self.first.x, self.first.y, self.source
        )
    }
}

/// How much more filament a piece lays than the area around it can hold
/// side by side before it is a blob ([`blobs`]).
pub const BLOB_OVERLAP: f64 = 1.5;

/// Pieces of the drawing whose lines the filament cannot keep apart, seen
/// whole: [`close_lines`] passes over the neighbours along one subpath
/// (within [`APART_PER_D`] d of arc length), so a shape folded up inside a
/// few d (a zig-zag scaled to under a millimetre, a 0.4 mm circle) was
/// planned with no word and printed as a blob (QA round 4 F4). Decision
/// (ours): a piece of length L whose samples fill a W x H box is a blob
/// when it folds inside the filament's width (W and H under d, L more than
/// [`BLOB_OVERLAP`] times the larger), or when, no larger than
/// [`APART_PER_D`] d, its filament, L d, is more than [`BLOB_OVERLAP`]
/// times the area it can lie in, (W + d)(H + d): lines d or more apart
/// never lay more than that area.
#[derive(Debug, Clone, PartialEq)]
pub struct Blobs {
    /// Whether the drawing as a whole is one blob (QA round 5 N5: a
    /// drawing scaled by 0.002 instead of 0.2 was named by one of its
    /// pieces); then the place, length and box below are the whole
    /// drawing's, and `source` its first piece's.
    pub whole: bool,
    /// How many pieces: the blobs, or for a whole drawing its pieces.
    pub count: usize,
    /// The first one's subpath, place (its box's middle), length and box,
    /// as drawn ([`Line::drawn`]).
    pub source: String,
    pub at: DVec2,
    pub length_mm: f64,
    pub size_mm: DVec2,
}

impl Blobs {
    /// The blob with the figures of `drawn`, (length, box) as drawn.
    fn of(whole: bool, count: usize, source: String, drawn: (f64, DVec2, DVec2)) -> Blobs {
        let (length_mm, lo, hi) = drawn;
        Blobs {
            whole,
            count,
            source,
            at: 0.5 * (lo + hi),
            length_mm,
            size_mm: hi - lo,
        }
    }

    /// The plan's warning.
    pub fn message(&self, d: f64) -> String {
        let first = format!(
            "{:.2} mm of line in a {:.3} x {:.3} mm box at ({:.3}, {:.3}) in '{}'",
            self.length_mm, self.size_mm.x, self.size_mm.y, self.at.x, self.at.y, self.source
        );
        let filament = format!("({d:.3} mm wide, the nozzle's inner diameter)");
        if self.whole {
            let (length, w, h) = (self.length_mm, self.size_mm.x, self.size_mm.y);
            let (x, y) = (self.at.x, self.at.y);
            let pieces = match self.count {
                1 => "one piece".to_string(),
                n => format!("{n} pieces"),
            };
            format!(
                "the whole drawing, {length:.2} mm of line in {pieces} within a {w:.3} x {h:.3} \
                 mm box at ({x:.3}, {y:.3}), folds up tighter than the filament that prints it \
                 {filament} can keep apart: it will print as one blob; check the drawing's scale \
                 and units"
            )
        } else if self.count == 1 {
            format!(
                "a piece of the drawing, {first}, folds up tighter than the filament that \
                 prints it {filament} can keep apart: it will print as a blob; scale the \
                 drawing up, or leave out what is smaller than the filament"
            )
        } else {
            format!(
                "{} pieces of the drawing fold up tighter than the filament that prints them \
                 {filament} can keep apart, the first {first}: they will print as blobs; scale \
                 the drawing up, or leave out what is smaller than the filament",
                self.count
            )
        }
    }
}

/// The pieces of `lines` that are blobs at filament width `d` (see
/// [`Blobs`]), or `None`.
pub fn blobs(lines: &[Line], d: f64) -> Option<Blobs> {
    if !(d > 0.0 && d.is_finite()) {
        return None;
    }
    // The two tests of [`Blobs`] on a length and a box.
    let is_blob = |length: f64, size: DVec2| {
        let folded = size.max_element() < d && length > BLOB_OVERLAP * size.max_element();
        // (A larger piece's lines that overlap lie further apart along it
        // than `close_lines` passes over, and it names them: a raster
        // filling an area is not a blob.)
        let crowded = size.max_element() <= APART_PER_D * d
            && length * d > BLOB_OVERLAP * (size.x + d) * (size.y + d);
        folded || crowded
    };
    let mut found: Option<Blobs> = None;
    // The whole drawing: its pieces, then the length and box of its
    // samples and of it as drawn.
    type Extent = (f64, DVec2, DVec2);
    let mut all: Option<(usize, String, Extent, Extent)> = None;
    let joined = |(l0, lo0, hi0): Extent, (l1, lo1, hi1): Extent| -> Extent {
        (l0 + l1, lo0.min(lo1), hi0.max(hi1))
    };
    for line in lines {
        if line.points.len() < 2 {
            continue;
        }
        let sampled = extent(line.points, line.closed);
        let drawn = extent(line.drawn, line.closed);
        all = Some(match all.take() {
            Some((n, source, s, d)) => (n + 1, source, joined(s, sampled), joined(d, drawn)),
            None => (1, line.source.to_string(), sampled, drawn),
        });
        let (length, lo, hi) = sampled;
        if !is_blob(length, hi - lo) {
            continue;
        }
        match &mut found {
            Some(b) => b.count += 1,
            None => found = Some(Blobs::of(false, 1, line.source.to_string(), drawn)),
        }
    }
    match all {
        Some((count, source, (length, lo, hi), drawn)) if is_blob(length, hi - lo) => {
            Some(Blobs::of(true, count, source, drawn))
        }
        _ => found,
    }
}

/// The fraction t in [0, 1] of the point a + t (b - a) of segment a-b
/// nearest `p` (0 for a segment of no length).
#[inline]
pub(crate) fn nearest_on_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// How many of the flagged samples look for their nearest other line
/// among all those near (then every 16th); the others stop at the first.
const FULL_SCANS: usize = 256;

/// Most grid cells: the cells grow past d for a drawing very large next to
/// the nozzle.
const MAX_CELLS: usize = 1 << 22;

/// The samples of `lines` that lie within `d` of another line (see the
/// module comment), or `None` when none does.
pub fn close_lines(lines: &[Line], d: f64) -> Option<CloseLines> {
    if !(d > 0.0 && d.is_finite()) {
        return None;
    }
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in lines.iter().flat_map(|l| l.points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    // A uniform grid of cells at least d wide, each segment in the cells
    // its box meets; a sample then finds every segment within d of it in
    // the 3 x 3 cells around its own.
    let ext = (hi - lo).max(DVec2::splat(d));
    let mut cell = d;
    while (ext.x / cell).ceil() * (ext.y / cell).ceil() > MAX_CELLS as f64 {
        cell *= 2.0;
    }
    let nx = ((ext.x / cell).ceil() as usize).max(1);
    let ny = ((ext.y / cell).ceil() as usize).max(1);
    // (Not negative: `lo` is the least; `as` truncates, a floor here.)
    let at = |p: DVec2| {
        let c = (p - lo) / cell;
        ((c.x as usize).min(nx - 1), (c.y as usize).min(ny - 1))
    };
    // Segments (line, first point) by cell: counted, then placed.
    let mut count = vec![0u32; nx * ny + 1];
    let each_segment = |f: &mut dyn FnMut(usize, usize, usize)| {
        for (k, line) in lines.iter().enumerate() {
            for (i, w) in line.points.windows(2).enumerate() {
                let (a, b) = at(w[0].min(w[1]));
                let (c, e) = at(w[0].max(w[1]));
                for y in b..=e {
                    for x in a..=c {
                        f(y * nx + x, k, i);
                    }
                }
            }
        }
    };
    each_segment(&mut |c, _, _| count[c + 1] += 1);
    for c in 1..count.len() {
        count[c] += count[c - 1];
    }
    let start = count.clone();
    let mut items = vec![(0u32, 0u32); count[nx * ny] as usize];
    each_segment(&mut |c, k, i| {
        items[count[c] as usize] = (k as u32, i as u32);
        count[c] += 1;
    });
    // Arc length at each sample, per line.
    let arcs: Vec<Vec<f64>> = lines
        .iter()
        .map(|l| {
            let mut s = 0.0;
            let mut out = Vec::with_capacity(l.points.len());
            for (i, p) in l.points.iter().enumerate() {
                if i > 0 {
                    s += p.distance(l.points[i - 1]);
                }
                out.push(s);
            }
            out
        })
        .collect();
    let apart = APART_PER_D * d;
    // Lines drawn d apart are not closer than d for rounding's sake.
    let limit = d * (1.0 - 1e-9);
    let mut found: Option<CloseLines> = None;
    let mut samples = 0usize;
    let mut length = 0.0;
    let mut closest = f64::INFINITY;
    for (k, line) in lines.iter().enumerate() {
        let arc = &arcs[k];
        let total = arc.last().copied().unwrap_or(0.0);
        // The segments from..to of this line lie wholly within 3 d of the
        // sample along it (arc[from] >= s - 3 d, arc[to] <= s + 3 d): its
        // neighbours, passed over on their index alone (most of what a
        // sample finds near it; the closure's are left to the test below).
        let (mut from, mut to) = (0usize, 0usize);
        for (i, &p) in line.points.iter().enumerate() {
            let s = arc[i];
            while arc[from] < s - apart {
                from += 1;
            }
            while to + 1 < arc.len() && arc[to + 1] <= s + apart {
                to += 1;
            }
            let (cx, cy) = at(p);
            // Every sample stops at the first other line within d, but the
            // first flagged ones and every 16th after them look at all, for
            // the smallest distance (a raster's 100 k samples each have
            // dozens of segments near).
            let full = samples < FULL_SCANS || samples.is_multiple_of(16);
            let mut near = f64::INFINITY;
            'cells: for y in cy.saturating_sub(1)..=(cy + 1).min(ny - 1) {
                for x in cx.saturating_sub(1)..=(cx + 1).min(nx - 1) {
                    let c = y * nx + x;
                    for &(k2, j) in &items[start[c] as usize..start[c + 1] as usize] {
                        let (k2, j) = (k2 as usize, j as usize);
                        if k2 == k && j >= from && j < to {
                            continue;
                        }
                        let pts = lines[k2].points;
                        let (a, b) = (pts[j], pts[j + 1]);
                        let t = nearest_on_segment(p, a, b);
                        let dist = p.distance(a + t * (b - a));
                        if dist >= limit || dist >= near {
                            continue;
                        }
                        if k2 == k {
                            let s2 = arcs[k][j] + t * (arcs[k][j + 1] - arcs[k][j]);
                            let mut along = (s - s2).abs();
                            if line.closed {
                                along = along.min(total - along);
                            }
                            if along <= apart {
                                continue;
                            }
                        }
                        near = dist;
                        if !full {
                            break 'cells;
                        }
                    }
                }
            }
            if near < limit {
                samples += 1;
                length += 0.5 * (arc[(i + 1).min(arc.len() - 1)] - arc[i.saturating_sub(1)]);
                closest = closest.min(near);
                found.get_or_insert_with(|| CloseLines {
                    samples: 0,
                    length_mm: 0.0,
                    closest_mm: 0.0,
                    first: p,
                    source: line.source.to_string(),
                });
            }
        }
    }
    found.map(|f| CloseLines {
        samples,
        length_mm: length,
        closest_mm: closest,
        ..f
    })
}

#[cfg(test)]
mod tests {

    /// QA round 4 F4: a zig-zag scaled under a millimetre and a circle
    /// narrower than the filament are blobs; a raster d apart, a short dash
    /// and a wide spiral are not.
    #[test]
    fn blobs_are_pieces_folded_up_smaller_than_the_filament() {
        let d = 0.603;
        let zigzag: Vec<DVec2> = (0..32)
            .map(|k| DVec2::new(if k % 2 == 0 { 0.0 } else { 0.7 }, 0.8 * k as f64 / 31.0))
            .collect();
        let circle: Vec<DVec2> = (0..12)
            .map(|k| 0.2 * DVec2::from_angle(k as f64 * std::f64::consts::TAU / 12.0))
            .collect();
        // A raster d apart, and one filling an area (0.27 mm apart, as W3:
        // `close_lines` names it).
        let raster: Vec<DVec2> = (0..20)
            .flat_map(|k| {
                let y = k as f64 * d;
                let (a, b) = if k % 2 == 0 { (0.0, 10.0) } else { (10.0, 0.0) };
                [DVec2::new(a, y), DVec2::new(b, y)]
            })
            .collect();
        let dash = [DVec2::ZERO, DVec2::new(0.4, 0.0)];
        let spiral: Vec<DVec2> = (0..400)
            .map(|k| {
                let t = k as f64 * 0.05;
                (1.0 + 0.3 * t) * DVec2::from_angle(t)
            })
            .collect();
        let line = |source, points: &'static [DVec2], closed| Line {
            source,
            points,
            closed,
            drawn: points,
        };
        let leak = |v: Vec<DVec2>| -> &'static [DVec2] { Box::leak(v.into_boxed_slice()) };
        let (zigzag, circle, raster, spiral) =
            (leak(zigzag), leak(circle), leak(raster), leak(spiral));
        // Beside a wide spiral, the drawing as a whole is no blob: its
        // pieces are named.
        let b = blobs(
            &[line("zigzag", zigzag, false), line("spiral", spiral, false)],
            d,
        )
        .expect("a blob");
        assert_eq!((b.whole, b.count, b.source.as_str()), (false, 1, "zigzag"));
        assert!((b.size_mm - DVec2::new(0.7, 0.8)).length() < 1e-12, "{b:?}");
        let message = b.message(d);
        assert!(
            message.starts_with(
                "a piece of the drawing, 21.71 mm of line in a 0.700 x 0.800 mm box at (0.350, \
                 0.400) in 'zigzag', folds up tighter than the filament"
            ),
            "{message}"
        );
        let b = blobs(
            &[line("circle", circle, true), line("spiral", spiral, false)],
            d,
        )
        .expect("a blob");
        assert_eq!((b.whole, b.source.as_str()), (false, "circle"));
        let b = blobs(
            &[
                line("circle", circle, true),
                line("zigzag", zigzag, false),
                line("spiral", spiral, false),
            ],
            d,
        )
        .expect("blobs");
        assert_eq!((b.whole, b.count), (false, 2));
        assert!(
            b.message(d).starts_with("2 pieces of the drawing fold up"),
            "{}",
            b.message(d)
        );
        // Alone, the zig-zag is the whole drawing, and is called that.
        let b = blobs(&[line("zigzag", zigzag, false)], d).expect("a blob");
        assert_eq!((b.whole, b.count), (true, 1));
        assert!(
            b.message(d).starts_with(
                "the whole drawing, 21.71 mm of line in one piece within a 0.700 x 0.800 mm box \
                 at (0.350, 0.400), folds up tighter than the filament"
            ),
            "{}",
            b.message(d)
        );
        let fill: Vec<DVec2> = (0..40)
            .flat_map(|k| {
                let y = k as f64 * 0.27;
                let (a, b) = if k % 2 == 0 { (0.0, 10.0) } else { (10.0, 0.0) };
                [DVec2::new(a, y), DVec2::new(b, y)]
            })
            .collect();
        let fill = leak(fill);
        for (name, points, closed) in [
            ("raster", raster, false),
            ("fill", fill, false),
            ("dash", &dash[..], false),
            ("spiral", spiral, false),
        ] {
            let points: &'static [DVec2] = leak(points.to_vec());
            assert_eq!(blobs(&[line(name, points, closed)], d), None, "{name}");
        }
    }
    /// QA round 5 N5: a snowflake scaled by 0.002, twelve short strokes
    /// none of them a blob on its own, is one blob as a whole, and said to
    /// be, with its whole length and box.
    #[test]
    fn a_drawing_smaller_than_the_filament_is_one_blob_as_a_whole() {
        let d = 0.603;
        let strokes: Vec<Vec<DVec2>> = (0..12)
            .map(|k| {
                let dir = DVec2::from_angle(k as f64 * std::f64::consts::TAU / 12.0);
                vec![0.02 * dir, 0.15 * dir]
            })
            .collect();
        let pieces: Vec<Line> = strokes
            .iter()
            .map(|points| Line {
                source: "flake",
                points,
                closed: false,
                drawn: points,
            })
            .collect();
        for piece in &pieces {
            assert_eq!(blobs(std::slice::from_ref(piece), d), None);
        }
        let b = blobs(&pieces, d).expect("one blob");
        assert_eq!((b.whole, b.count), (true, 12));
        assert!((b.length_mm - 12.0 * 0.13).abs() < 1e-9, "{b:?}");
        assert!(b.size_mm.max_element() <= 0.3 + 1e-12, "{b:?}");
        let message = b.message(d);
        assert!(
            message.starts_with("the whole drawing, 1.56 mm of line in 12 pieces within a ")
                && message.contains("it will print as one blob; check the drawing's scale"),
            "{message}"
        );
    }

    use super::*;

    fn line(points: &[DVec2], closed: bool) -> Line<'_> {
        Line {
            source: "p",
            points,
            closed,
            drawn: points,
        }
    }

    /// Points along a polyline, at most `step` apart.
    fn sampled(corners: &[DVec2], step: f64) -> Vec<DVec2> {
        let mut out = vec![corners[0]];
        for w in corners.windows(2) {
            let n = (w[0].distance(w[1]) / step).ceil().max(1.0) as usize;
            for i in 1..=n {
                out.push(w[0].lerp(w[1], i as f64 / n as f64));
            }
        }
        out
    }

    #[test]
    fn a_serpentine_closer_than_d_is_found_and_one_as_wide_is_not() {
        let d = 0.6;
        for (gap, close) in [
            (0.3, true),
            (0.59, true),
            (0.6, false),
            (0.61, false),
            (1.0, false),
        ] {
            let mut corners = Vec::new();
            for r in 0..6 {
                let y = r as f64 * gap;
                let (a, b) = if r % 2 == 0 { (0.0, 10.0) } else { (10.0, 0.0) };
                corners.push(DVec2::new(a, y));
                corners.push(DVec2::new(b, y));
            }
            let pts = sampled(&corners, d / 2.0);
            let got = close_lines(&[line(&pts, false)], d);
            assert_eq!(got.is_some(), close, "gap {gap}: {got:?}");
            if let Some(c) = got {
                assert!((c.closest_mm - gap).abs() < 1e-9, "{c:?}");
                // Nearly every sample has a line beside it.
                assert!(c.samples > pts.len() / 2, "{c:?}");
                assert_eq!(c.first, pts[0]);
            }
        }
    }

    #[test]
    fn corners_and_neighbours_are_not_other_lines_but_a_sharp_spike_is() {
        let d = 0.6;
        // A square and a right-angled zig-zag: nothing.
        let square = sampled(
            &[
                DVec2::ZERO,
                DVec2::new(5.0, 0.0),
                DVec2::new(5.0, 5.0),
                DVec2::new(0.0, 5.0),
                DVec2::ZERO,
            ],
            d / 2.0,
        );
        assert_eq!(close_lines(&[line(&square, true)], d), None);
        let zig: Vec<DVec2> = (0..20)
            .map(|i| DVec2::new(i as f64, if i % 2 == 0 { 0.0 } else { 1.0 }))
            .collect();
        assert_eq!(
            close_lines(&[line(&sampled(&zig, d / 2.0), false)], d),
            None
        );
        // A small closed circle (its far side is near along the closure).
        let circle: Vec<DVec2> = (0..=16)
            .map(|i| {
                let a = i as f64 / 16.0 * std::f64::consts::TAU;
                0.25 * DVec2::new(a.cos(), a.sin())
            })
            .collect();
        assert_eq!(close_lines(&[line(&circle, true)], d), None);
        // A 10 degree spike with 5 mm legs: its legs merge.
        let tip = DVec2::new(5.0, 0.0);
        let back = tip + 5.0 * DVec2::new(-(10f64.to_radians().cos()), 10f64.to_radians().sin());
        let spike = sampled(&[DVec2::ZERO, tip, back], d / 2.0);
        assert!(close_lines(&[line(&spike, false)], d).is_some());
    }

    #[test]
    fn two_subpaths_side_by_side_are_two_lines() {
        let d = 0.6;
        let a = sampled(&[DVec2::ZERO, DVec2::new(0.0, 5.0)], d / 2.0);
        let b = sampled(&[DVec2::new(0.4, 0.0), DVec2::new(0.4, 5.0)], d / 2.0);
        let far = sampled(&[DVec2::new(2.0, 0.0), DVec2::new(2.0, 5.0)], d / 2.0);
        let got = close_lines(
            &[
                Line {
                    source: "a",
                    points: &a,
                    closed: false,
                    drawn: &a,
                },
                Line {
                    source: "b",
                    points: &b,
                    closed: false,
                    drawn: &b,
                },
            ],
            d,
        )
        .expect("0.4 mm apart");
        assert_eq!(got.samples, a.len() + b.len());
        assert!((got.length_mm - 10.0).abs() < 1e-9, "{got:?}");
        assert_eq!(got.source, "a");
        assert!((got.closest_mm - 0.4).abs() < 1e-12);
        assert_eq!(close_lines(&[line(&a, false), line(&far, false)], d), None);
        // Two lines that cross: they meet.
        let x1 = sampled(&[DVec2::new(-5.0, 0.0), DVec2::new(5.0, 0.0)], d / 2.0);
        let x2 = sampled(&[DVec2::new(0.0, -5.0), DVec2::new(0.0, 5.0)], d / 2.0);
        let got = close_lines(&[line(&x1, false), line(&x2, false)], d).expect("crossing");
        assert_eq!(got.closest_mm, 0.0);
        let m = got.message(d);
        assert!(
            m.starts_with("lines of the drawing meet (cross, touch or lie on each other), less")
                && m.contains("their filaments will merge"),
            "{m}"
        );
        // A single line, a single point, nothing: nothing.
        assert_eq!(close_lines(&[line(&a, false)], d), None);
        assert_eq!(close_lines(&[line(&a[..1], false)], d), None);
        assert_eq!(close_lines(&[], d), None);
    }
}
