//! Integration tests: bruteforce. An independent safety oracle for the
//! promise "the nozzle never touches the part along any move": it reads
//! G-code text with its own minimal interpreter, follows every straight move
//! in small steps and measures, with its own geometry, the Euclidean
//! distance between the nozzle and the mesh's triangles.
//!
//! It shares no code with the planner (only glam's `DVec3` and the plain
//! `TriMesh` data struct), so it can judge the planner's own exact motion
//! check.
//!
//! Nozzle model: the tip is the commanded point; the solid is the closed
//! horizontal disk of radius r at the tip plus the solid vertical cylinder of
//! that radius above it (a 1000 mm tall body, taken as infinite here: no scan
//! rises a metre above the tip).

use std::time::Instant;

use pcpp::mesh::TriMesh;
use pcpp::DVec3;

/// Default spacing of the samples along a move; both ends are always sampled.
pub(crate) const STEP_MM: f64 = 0.05;

/// The search stops once the best distance found is within this of a
/// certified lower bound, so a reported distance exceeds the true one by at
/// most this much (the brief allows 0.001 mm).
const GAP_MM: f64 = 1e-4;

/// Samples whose coarse bounds straddle the tolerance are settled again with
/// this gap, so that a too-close sample is not called clear for want of the
/// last 0.1 um.
const FINE_GAP_MM: f64 = 1e-9;

/// Sub-triangles the fine pass may visit per sample before it gives up and
/// reports its (conservative) lower bound instead.
const FINE_BUDGET: usize = 1 << 20;

/// Distances of this much or more (or of twice the tolerance, if that is
/// more) are not measured: the sample reports infinity ("nothing is near"). Travel at a safe height then costs almost
/// nothing, and everything that could be too close is far below it.
const NEAR_MM: f64 = 3.0;

/// One point of a move where the nozzle was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sample {
    /// 1-based line of the move in the G-code.
    pub line: usize,
    /// The tip, machine frame, mm.
    pub position: DVec3,
    /// Euclidean distance between the nozzle solid and the nearest
    /// triangle, at most [`GAP_MM`] above the true one; infinite when
    /// nothing is within [`NEAR_MM`].
    pub distance_mm: f64,
    /// How far the surface rises above the tip inside the tip's disk.
    pub depth_mm: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SafetyReport {
    /// G0/G1 moves followed (lines that move at least one axis).
    pub moves: usize,
    /// Moves whose start was not fully known: checked at their end only
    /// (and not at all while the end is unknown too).
    pub unknown_start: usize,
    pub samples: usize,
    /// Over all samples; infinite if nothing is near.
    pub min_distance_mm: f64,
    /// The sample with the smallest distance (the deepest among equals,
    /// then the first).
    pub worst: Option<Sample>,
    /// Samples with a distance below the tolerance.
    pub too_close: usize,
    /// The first [`FIRST_TOO_CLOSE`] of them, in file order.
    pub first_too_close: Vec<Sample>,
    /// Largest depth over all samples, 0 if none.
    pub deepest_mm: f64,
}

/// How many too-close samples a report lists.
pub(crate) const FIRST_TOO_CLOSE: usize = 20;

/// Follows every G0/G1 move of `gcode` in steps of [`STEP_MM`] and measures
/// the nozzle of `outer_diameter_mm` against `mesh`.
pub(crate) fn check_gcode(
    gcode: &str,
    mesh: &TriMesh,
    outer_diameter_mm: f64,
    tol_mm: f64,
) -> SafetyReport {
    check_gcode_with_step(gcode, mesh, outer_diameter_mm, tol_mm, STEP_MM)
}

/// [`check_gcode`] with samples at most `step_mm` apart along each move.
pub(crate) fn check_gcode_with_step(
    gcode: &str,
    mesh: &TriMesh,
    outer_diameter_mm: f64,
    tol_mm: f64,
    step_mm: f64,
) -> SafetyReport {
    assert!(
        outer_diameter_mm.is_finite() && outer_diameter_mm >= 0.0,
        "outer diameter {outer_diameter_mm} mm is not a size"
    );
    assert!(
        tol_mm.is_finite() && tol_mm >= 0.0,
        "tolerance {tol_mm} mm is not a distance"
    );
    let mut oracle = Oracle::new(mesh, outer_diameter_mm / 2.0, tol_mm);
    let mut report = SafetyReport {
        moves: 0,
        unknown_start: 0,
        samples: 0,
        min_distance_mm: f64::INFINITY,
        worst: None,
        too_close: 0,
        first_too_close: Vec::new(),
        deepest_mm: 0.0,
    };
    let counts = for_each_sample(gcode, step_mm, |line, position| {
        let (distance_mm, depth_mm) = oracle.measure(position);
        let sample = Sample {
            line,
            position,
            distance_mm,
            depth_mm,
        };
        report.samples += 1;
        report.deepest_mm = report.deepest_mm.max(depth_mm);
        let worse = report.worst.is_none_or(|w| {
            distance_mm < w.distance_mm || (distance_mm == w.distance_mm && depth_mm > w.depth_mm)
        });
        if worse && distance_mm.is_finite() {
            report.worst = Some(sample);
            report.min_distance_mm = distance_mm;
        }
        if distance_mm < tol_mm {
            report.too_close += 1;
            if report.first_too_close.len() < FIRST_TOO_CLOSE {
                report.first_too_close.push(sample);
            }
        }
    });
    report.moves = counts.moves;
    report.unknown_start = counts.unknown_start;
    report
}

// ---------------------------------------------------------------------------
// G-code: a minimal interpreter of its own.

/// Moves followed, as counted while sampling.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
struct MoveCounts {
    moves: usize,
    unknown_start: usize,
}

/// One straight move as the program commands it, machine frame in mm;
/// `None` where an axis has not been set yet.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Move {
    line: usize,
    from: [Option<f64>; 3],
    to: [Option<f64>; 3],
}

/// Calls `visit(line, tip)` for each sample of each move, in file order:
/// points at most `step_mm` apart from just after the start to the end
/// (the start was the previous move's end, already sampled). A move from an
/// unknown start is sampled at its end only.
fn for_each_sample(gcode: &str, step_mm: f64, mut visit: impl FnMut(usize, DVec3)) -> MoveCounts {
    assert!(
        step_mm.is_finite() && step_mm > 0.0,
        "sample step {step_mm} mm must be positive"
    );
    let mut counts = MoveCounts::default();
    let known = |p: [Option<f64>; 3]| Some(DVec3::new(p[0]?, p[1]?, p[2]?));
    walk(gcode, |m| {
        counts.moves += 1;
        let from = known(m.from);
        if from.is_none() {
            counts.unknown_start += 1;
        }
        match (from, known(m.to)) {
            (_, None) => {}
            (None, Some(end)) => visit(m.line, end),
            (Some(start), Some(end)) => {
                // The slack keeps a length that is a whole number of steps
                // from gaining a sample through rounding, so programs that
                // differ only in units or offsets sample the same points.
                let steps = ((end - start).length() / step_mm - 1e-9).ceil().max(1.0) as usize;
                for i in 1..=steps {
                    let t = i as f64 / steps as f64;
                    visit(m.line, if i == steps { end } else { start.lerp(end, t) });
                }
            }
        }
    });
    counts
}

/// What a line's axis words mean.
#[derive(Debug, Clone, Copy, PartialEq)]
enum AxisWords {
    /// The target of a G0/G1 move.
    Motion,
    /// G92: new coordinates for the current position.
    SetPosition,
    /// G28/G30: a trip home, to a place the program does not state.
    Home,
    /// Parameters of another command (G4's dwell, G10's data).
    Data,
}

/// Interprets `gcode` and calls `visit` for every G0/G1 move: one with at
/// least one axis word. Panics, naming the line, on what it cannot follow
/// safely (arcs, machine-coordinate moves, unreadable words).
fn walk(gcode: &str, mut visit: impl FnMut(&Move)) {
    // machine = programmed + offset; G92 changes the offset.
    let mut machine: [Option<f64>; 3] = [None; 3];
    let mut offset: [Option<f64>; 3] = [Some(0.0); 3];
    let mut inches = false;
    let mut relative = false;
    let mut rapid_or_linear: Option<u8> = None;
    for (index, raw) in gcode.lines().enumerate() {
        let line = index + 1;
        let Some(words) = words_of(raw, line) else {
            continue;
        };
        let mut axis_words = AxisWords::Motion;
        let mut axes: [Option<Option<f64>>; 3] = [None; 3];
        for &(letter, value) in &words {
            match letter {
                'G' => {
                    let Some(value) = value else {
                        panic!("line {line}: G without a number: {raw:?}");
                    };
                    // Tenths, so G92.1 is not G92.
                    match (value * 10.0).round() as i64 {
                        0 => rapid_or_linear = Some(0),
                        10 => rapid_or_linear = Some(1),
                        20 | 30 => panic!("line {line}: arcs (G2/G3) are not followed: {raw:?}"),
                        200 | 700 => inches = true,
                        210 | 710 => inches = false,
                        900 => relative = false,
                        910 => relative = true,
                        920 => axis_words = AxisWords::SetPosition,
                        280 | 300 => axis_words = AxisWords::Home,
                        40 | 100 => axis_words = AxisWords::Data,
                        code @ (530 | 921 | 922 | 923) => panic!(
                            "line {line}: G{} (machine coordinates or offset reset) is not followed: {raw:?}",
                            code as f64 / 10.0
                        ),
                        _ => {}
                    }
                }
                'X' | 'Y' | 'Z' => {
                    let axis = (letter as u8 - b'X') as usize;
                    axes[axis] = Some(value);
                }
                _ => {}
            }
        }
        let scale = if inches { 25.4 } else { 1.0 };
        let number = |axis: usize, v: Option<f64>| -> f64 {
            match v {
                Some(v) => v * scale,
                None => panic!(
                    "line {line}: axis word {} without a number: {raw:?}",
                    char::from(b'X' + axis as u8)
                ),
            }
        };
        let any_axis = axes.iter().any(Option::is_some);
        match axis_words {
            AxisWords::Home => machine = [None; 3],
            AxisWords::Data => {}
            AxisWords::SetPosition => {
                assert!(
                    any_axis,
                    "line {line}: G92 without axis words means different things to different controllers: {raw:?}"
                );
                for (axis, word) in axes.iter().enumerate() {
                    if let Some(v) = *word {
                        let v = number(axis, v);
                        // At an unknown machine position the new frame is
                        // unknown too.
                        offset[axis] = machine[axis].map(|m| m - v);
                    }
                }
            }
            AxisWords::Motion if any_axis => {
                assert!(
                    rapid_or_linear.is_some(),
                    "line {line}: axis words before any G0/G1: {raw:?}"
                );
                let from = machine;
                let mut to = machine;
                for (axis, word) in axes.iter().enumerate() {
                    if let Some(v) = *word {
                        let v = number(axis, v);
                        to[axis] = if relative {
                            machine[axis].map(|m| m + v)
                        } else {
                            offset[axis].map(|o| v + o)
                        };
                    }
                }
                visit(&Move { line, from, to });
                machine = to;
            }
            AxisWords::Motion => {}
        }
    }
}

/// The words of one line, letters upper-cased, or `None` for a line without
/// any: blank, comment, a controller statement (Aerotech's `$DO[0].X = 1`,
/// `DWELL 0.5`) or an M-code line (whose words may be free text, M117).
fn words_of(raw: &str, line: usize) -> Option<Vec<(char, Option<f64>)>> {
    let trimmed = raw.trim_start();
    if trimmed.starts_with('\'') || trimmed.starts_with('%') {
        return None;
    }
    let mut text = String::with_capacity(raw.len());
    let mut in_comment = false;
    for ch in raw.chars() {
        match ch {
            _ if in_comment => in_comment = ch != ')',
            '(' => in_comment = true,
            ';' => break,
            _ => text.push(ch),
        }
    }
    if let Some(star) = text.find('*') {
        text.truncate(star);
    }
    let mut body = text.trim();
    // A line number first: N followed by digits.
    if let Some(rest) = body.strip_prefix(['N', 'n']) {
        let digits = rest.len() - rest.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        if digits > 0 {
            body = rest[digits..].trim_start();
        }
    }
    let mut chars = body.chars();
    match (chars.next(), chars.next()) {
        (None, _) => return None,
        (Some('$'), _) => return None,
        (Some(a), Some(b)) if a.is_ascii_alphabetic() && b.is_ascii_alphabetic() => return None,
        (Some('M' | 'm'), _) => return None,
        _ => {}
    }
    let bytes = body.as_bytes();
    let mut words = Vec::new();
    let mut i = 0;
    let skip_blanks = |i: &mut usize| {
        while *i < bytes.len() && bytes[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    loop {
        skip_blanks(&mut i);
        if i == bytes.len() {
            return Some(words);
        }
        let letter = bytes[i];
        assert!(
            letter.is_ascii_alphabetic(),
            "line {line}: cannot read {body:?} as G-code words (at byte {i})"
        );
        i += 1;
        skip_blanks(&mut i);
        let start = i;
        if i < bytes.len() && (bytes[i] == b'+' || bytes[i] == b'-') {
            i += 1;
        }
        let digits_from = i;
        while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
            i += 1;
        }
        let value = if i > digits_from {
            let s = &body[start..i];
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Some(v),
                _ => panic!("line {line}: bad number {s:?} in {body:?}"),
            }
        } else {
            assert!(
                i == start,
                "line {line}: a sign without a number in {body:?}"
            );
            None
        };
        words.push((char::from(letter.to_ascii_uppercase()), value));
    }
}

// ---------------------------------------------------------------------------
// Geometry: the nozzle solid against triangles.

/// Distance from `q` to the nozzle solid S of the tip `p` and radius `r`,
/// and its gradient (zero inside S).
///
/// S = D x [p.z, inf) with D the disk of radius r around p.xy: a product of
/// sets in orthogonal subspaces, so its squared distance splits into the
/// squared distance to D in xy, max(|q.xy - p.xy| - r, 0), and the squared
/// distance to [p.z, inf) in z, max(p.z - q.z, 0). This covers every region:
/// under the disk (vertical distance), beside the body above the tip
/// (horizontal), and below and outside (to the disk's rim).
///
/// Being the distance to a closed convex set, it is convex and 1-Lipschitz,
/// and outside S differentiable with gradient (q - proj(q)) / distance,
/// which is what the second value is.
fn solid_distance(p: DVec3, r: f64, q: DVec3) -> (f64, DVec3) {
    let (ux, uy) = (q.x - p.x, q.y - p.y);
    let rho = ux.hypot(uy);
    let h = (rho - r).max(0.0);
    let v = (p.z - q.z).max(0.0);
    let d = h.hypot(v);
    if d == 0.0 {
        return (0.0, DVec3::ZERO);
    }
    // h > 0 implies rho > r >= 0, so the division is safe.
    let radial = if h > 0.0 { h / (d * rho) } else { 0.0 };
    (d, DVec3::new(ux * radial, uy * radial, -v / d))
}

/// Exact distance between an axis-aligned box and the solid: the box is
/// also a product (rectangle x interval), so the same split applies.
fn box_distance(lo: DVec3, hi: DVec3, p: DVec3, r: f64) -> f64 {
    let dx = (lo.x - p.x).max(p.x - hi.x).max(0.0);
    let dy = (lo.y - p.y).max(p.y - hi.y).max(0.0);
    let h = (dx.hypot(dy) - r).max(0.0);
    let v = (p.z - hi.z).max(0.0);
    h.hypot(v)
}

/// A lower bound on the solid's distance over the triangle `t`, and the
/// distance at its centroid.
///
/// With f the distance, c the centroid and R = max |t_i - c|, every q in
/// the triangle satisfies both
///  (i)  f(q) >= f(c) - |q - c| >= f(c) - R, as f is 1-Lipschitz and the
///       triangle lies in the ball of radius R around c (a convex set that
///       holds its corners);
///  (ii) f(q) >= f(c) + g.(q - c) >= f(c) + min_i g.(t_i - c), as f is
///       convex with (sub)gradient g at c and a linear function is least
///       over a triangle at a corner.
/// (i) shrinks with R, so subdivision always ends; (ii) is off by only
/// O(R^2 / f) where f is smooth, so it ends after few levels.
fn node_bound(p: DVec3, r: f64, t: &[DVec3; 3]) -> (f64, f64) {
    let c = (t[0] + t[1] + t[2]) / 3.0;
    let (fc, g) = solid_distance(p, r, c);
    let reach = t.iter().map(|v| v.distance(c)).fold(0.0, f64::max);
    let linear = t
        .iter()
        .map(|v| g.dot(*v - c))
        .fold(f64::INFINITY, f64::min);
    let lower = (fc - reach).max(fc + linear).max(0.0);
    (lower, fc)
}

/// Highest point of the triangle `t` whose xy lies within `r` of `p.xy`.
///
/// The part of the triangle inside the vertical cylinder is compact and
/// convex and z is linear on it, so its maximum is at an extreme point:
/// a corner inside the cylinder, a crossing of an edge with the cylinder's
/// wall, or a point inside the triangle on the wall. Where the plane is not
/// vertical, the last is the top of the ellipse cut by the wall, above
/// p.xy + r * (uphill direction), or any point if the plane is level (its
/// centre serves: the disk then lies inside the triangle or an edge
/// crosses it); on a vertical plane such points lie on vertical lines whose
/// tops are edge crossings.
fn highest_in_disk(t: &[DVec3; 3], p: DVec3, r: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut take = |z: f64| best = Some(best.map_or(z, |b: f64| b.max(z)));
    let r2 = r * r;
    for v in t {
        if (v.x - p.x).powi(2) + (v.y - p.y).powi(2) <= r2 {
            take(v.z);
        }
    }
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let (wx, wy) = (a.x - p.x, a.y - p.y);
        let qa = dx * dx + dy * dy;
        if qa == 0.0 {
            continue; // a vertical edge: its ends are corners
        }
        let qb = wx * dx + wy * dy;
        let qc = wx * wx + wy * wy - r2;
        let disc = qb * qb - qa * qc;
        if disc < 0.0 {
            continue;
        }
        for s in [(-qb - disc.sqrt()) / qa, (-qb + disc.sqrt()) / qa] {
            if (0.0..=1.0).contains(&s) {
                take(a.z + s * (b.z - a.z));
            }
        }
    }
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    if n.z.abs() > 1e-12 * n.length() {
        // z = z0 - (n.x (x - x0) + n.y (y - y0)) / n.z on the plane.
        let (gx, gy) = (-n.x / n.z, -n.y / n.z);
        let slope = gx.hypot(gy);
        let (x, y) = if slope > 0.0 {
            (p.x + r * gx / slope, p.y + r * gy / slope)
        } else {
            (p.x, p.y)
        };
        if let Some(z) = height_inside(t, x, y) {
            take(z);
        }
    }
    best
}

/// z of the non-vertical triangle `t` above (x, y), if that lies inside its
/// projection (clamped to the triangle's z range against rounding).
fn height_inside(t: &[DVec3; 3], x: f64, y: f64) -> Option<f64> {
    let area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
    if area == 0.0 {
        return None;
    }
    let w = |a: DVec3, b: DVec3| ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / area;
    let (w0, w1, w2) = (w(t[1], t[2]), w(t[2], t[0]), w(t[0], t[1]));
    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
        return None;
    }
    let z = w0 * t[0].z + w1 * t[1].z + w2 * t[2].z;
    let lo = t[0].z.min(t[1].z).min(t[2].z);
    let hi = t[0].z.max(t[1].z).max(t[2].z);
    Some(z.clamp(lo, hi))
}

/// What one nearest-triangle search established.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    /// The solid's distance at a real point of the mesh (or the starting
    /// bound, when nothing closer was found).
    upper: f64,
    /// Certified: no point of the mesh is closer than this.
    lower: f64,
    /// False when the budget ran out before upper - lower <= gap.
    converged: bool,
}

/// A uniform xy grid of buckets over the mesh, each holding the triangles
/// whose boxes overlap it, with the box of those triangles.
struct Grid {
    origin: (f64, f64),
    cell_mm: f64,
    cells: (usize, usize),
    /// Bucket b holds `items[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Box of the triangles of each bucket (an inverted box when empty).
    cell_boxes: Vec<(DVec3, DVec3)>,
}

impl Grid {
    fn new(boxes: &[(DVec3, DVec3)]) -> Grid {
        let (lo, hi) = boxes
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.0), hi.max(b.1))
            });
        let (origin, width, depth) = if boxes.is_empty() {
            ((0.0, 0.0), 0.0, 0.0)
        } else {
            ((lo.x, lo.y), hi.x - lo.x, hi.y - lo.y)
        };
        // About ten triangles a bucket on a height field; at most 2048
        // buckets a side.
        let n = boxes.len().max(1) as f64;
        let cell_mm = (width.max(1e-3) * depth.max(1e-3) * 5.0 / n)
            .sqrt()
            .max(width / 2048.0)
            .max(depth / 2048.0);
        let cells = (
            (width / cell_mm).floor() as usize + 1,
            (depth / cell_mm).floor() as usize + 1,
        );
        let mut grid = Grid {
            origin,
            cell_mm,
            cells,
            starts: vec![0; cells.0 * cells.1 + 1],
            items: Vec::new(),
            cell_boxes: vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); cells.0 * cells.1],
        };
        // Two passes, count then fill: one flat array of indices.
        let mut count = vec![0u32; cells.0 * cells.1];
        for b in boxes {
            grid.for_cells(b.0.x, b.1.x, b.0.y, b.1.y, |c| count[c] += 1);
        }
        let mut total = 0u32;
        for (c, k) in count.iter().enumerate() {
            grid.starts[c] = total;
            total += k;
        }
        grid.starts[cells.0 * cells.1] = total;
        let mut items = vec![0u32; total as usize];
        let mut fill = grid.starts.clone();
        let mut cell_boxes = std::mem::take(&mut grid.cell_boxes);
        for (i, b) in boxes.iter().enumerate() {
            grid.for_cells(b.0.x, b.1.x, b.0.y, b.1.y, |c| {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
                cell_boxes[c] = (cell_boxes[c].0.min(b.0), cell_boxes[c].1.max(b.1));
            });
        }
        grid.items = items;
        grid.cell_boxes = cell_boxes;
        grid
    }

    /// Calls `f` with every bucket that the xy rectangle overlaps, clamped
    /// to the grid (the rim buckets hold whatever lies beyond).
    fn for_cells(&self, x0: f64, x1: f64, y0: f64, y1: f64, mut f: impl FnMut(usize)) {
        let index = |v: f64, o: f64, n: usize| -> usize {
            (((v - o) / self.cell_mm).floor().max(0.0) as usize).min(n - 1)
        };
        let (i0, i1) = (
            index(x0, self.origin.0, self.cells.0),
            index(x1, self.origin.0, self.cells.0),
        );
        let (j0, j1) = (
            index(y0, self.origin.1, self.cells.1),
            index(y1, self.origin.1, self.cells.1),
        );
        for j in j0..=j1 {
            for i in i0..=i1 {
                f(j * self.cells.0 + i);
            }
        }
    }

    fn bucket(&self, c: usize) -> &[u32] {
        &self.items[self.starts[c] as usize..self.starts[c + 1] as usize]
    }
}

/// The mesh's triangles in a [`Grid`] and a nozzle to measure with.
struct Oracle {
    triangles: Vec<[DVec3; 3]>,
    boxes: Vec<(DVec3, DVec3)>,
    grid: Grid,
    radius_mm: f64,
    tol_mm: f64,
    /// Distances from here on are not measured.
    cutoff_mm: f64,
    /// Per-triangle mark of the last search that looked at it.
    seen: Vec<u32>,
    search: u32,
    stack: Vec<[DVec3; 3]>,
    order: Vec<(f64, u32)>,
}

impl Oracle {
    fn new(mesh: &TriMesh, radius_mm: f64, tol_mm: f64) -> Oracle {
        let corner = |i: u32| -> DVec3 {
            let v = *mesh
                .vertices
                .get(i as usize)
                .unwrap_or_else(|| panic!("triangle corner {i} is not a vertex"));
            assert!(v.is_finite(), "vertex {i} is not finite: {v}");
            v
        };
        let triangles: Vec<[DVec3; 3]> = mesh.triangles.iter().map(|t| t.map(corner)).collect();
        let boxes: Vec<(DVec3, DVec3)> = triangles
            .iter()
            .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
            .collect();
        Oracle {
            seen: vec![0; triangles.len()],
            grid: Grid::new(&boxes),
            triangles,
            boxes,
            radius_mm,
            tol_mm,
            cutoff_mm: NEAR_MM.max(2.0 * tol_mm),
            search: 0,
            stack: Vec::new(),
            order: Vec::new(),
        }
    }

    fn next_search(&mut self) -> u32 {
        if self.search == u32::MAX {
            self.seen.fill(0);
            self.search = 0;
        }
        self.search += 1;
        self.search
    }

    /// Distance and depth of the nozzle with its tip at `p`.
    fn measure(&mut self, p: DVec3) -> (f64, f64) {
        let coarse = self.nearest(p, GAP_MM, self.cutoff_mm, usize::MAX);
        let mut distance = if coarse.upper >= self.cutoff_mm {
            f64::INFINITY
        } else {
            coarse.upper
        };
        if coarse.lower < self.tol_mm && self.tol_mm <= coarse.upper {
            let fine = self.nearest(p, FINE_GAP_MM, coarse.upper, FINE_BUDGET);
            // Unsettled: report what is certain, which errs towards too close.
            distance = if fine.converged {
                fine.upper
            } else {
                fine.lower
            };
        }
        // A mesh point above the tip inside its disk lies in the solid, so
        // any depth means a distance of 0 (reported as at most GAP_MM).
        let depth = if coarse.upper <= GAP_MM {
            self.depth(p)
        } else {
            0.0
        };
        (distance, depth)
    }

    /// Branch and bound over the triangles near `p`, each subdivided
    /// recursively, keeping the smallest distance found (`upper`, starting
    /// at `start`) and pruning only where [`box_distance`] or
    /// [`node_bound`] proves nothing closer than `upper - gap`.
    ///
    /// When it ends with the budget unspent, every part of every triangle
    /// was pruned against a value at least the final `upper`, so the true
    /// distance is at least `upper - gap`; `upper` is a real distance, so
    /// it is at most the true one plus `gap`.
    fn nearest(&mut self, p: DVec3, gap: f64, start: f64, mut budget: usize) -> Bounds {
        let r = self.radius_mm;
        let search = self.next_search();
        let mut best = start;
        let mut low = f64::INFINITY;
        let mut converged = true;
        // Buckets outside this square only hold triangles whose boxes are
        // at least `start` away from the disk in xy.
        let reach = r + start;
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        let grid = &self.grid;
        grid.for_cells(p.x - reach, p.x + reach, p.y - reach, p.y + reach, |c| {
            let (lo, hi) = grid.cell_boxes[c];
            if lo.x <= hi.x {
                order.push((box_distance(lo, hi, p, r), c as u32));
            }
        });
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut stack = std::mem::take(&mut self.stack);
        'cells: for &(cell_bound, c) in &order {
            if cell_bound >= best - gap {
                low = low.min(cell_bound);
                break; // sorted: the rest are no nearer
            }
            let c = c as usize;
            for &i in self.grid.bucket(c) {
                let i = i as usize;
                if self.seen[i] == search {
                    continue;
                }
                self.seen[i] = search;
                let (lo, hi) = self.boxes[i];
                let tri_bound = box_distance(lo, hi, p, r);
                if tri_bound >= best - gap {
                    low = low.min(tri_bound);
                    continue;
                }
                let t = self.triangles[i];
                for v in t {
                    best = best.min(solid_distance(p, r, v).0);
                }
                stack.clear();
                stack.push(t);
                while let Some(node) = stack.pop() {
                    let (lower, fc) = node_bound(p, r, &node);
                    best = best.min(fc);
                    if best == 0.0 {
                        // Nothing is nearer than touching.
                        low = 0.0;
                        break 'cells;
                    }
                    if lower >= best - gap {
                        low = low.min(lower);
                        continue;
                    }
                    if budget == 0 {
                        converged = false;
                        low = low.min(lower);
                        continue;
                    }
                    budget -= 1;
                    let [a, b, d] = node;
                    let (ab, bd, da) = ((a + b) / 2.0, (b + d) / 2.0, (d + a) / 2.0);
                    for m in [ab, bd, da] {
                        best = best.min(solid_distance(p, r, m).0);
                    }
                    stack.extend([[a, ab, da], [ab, b, bd], [da, bd, d], [ab, bd, da]]);
                }
            }
        }
        self.stack = stack;
        self.order = order;
        Bounds {
            upper: best,
            lower: low.min(best),
            converged,
        }
    }

    /// max(0, highest mesh point within r of p in xy minus p.z).
    fn depth(&mut self, p: DVec3) -> f64 {
        let r = self.radius_mm;
        let search = self.next_search();
        let mut top = p.z;
        let mut seen = std::mem::take(&mut self.seen);
        let grid = &self.grid;
        grid.for_cells(p.x - r, p.x + r, p.y - r, p.y + r, |c| {
            if grid.cell_boxes[c].1.z <= top {
                return;
            }
            for &i in grid.bucket(c) {
                let i = i as usize;
                if seen[i] == search {
                    continue;
                }
                seen[i] = search;
                let (lo, hi) = self.boxes[i];
                let dx = (lo.x - p.x).max(p.x - hi.x).max(0.0);
                let dy = (lo.y - p.y).max(p.y - hi.y).max(0.0);
                if hi.z <= top || dx.hypot(dy) > r {
                    continue;
                }
                if let Some(z) = highest_in_disk(&self.triangles[i], p, r) {
                    top = top.max(z);
                }
            }
        });
        self.seen = seen;
        top - p.z
    }
}

// ---------------------------------------------------------------------------
// Tests of the oracle itself.

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn mesh_of(triangles: &[[DVec3; 3]]) -> TriMesh {
    let mut mesh = TriMesh::default();
    for t in triangles {
        let k = mesh.vertices.len() as u32;
        mesh.vertices.extend_from_slice(t);
        mesh.triangles.push([k, k + 1, k + 2]);
    }
    mesh
}

/// The quadrilateral a b c d as two triangles.
fn quad(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> [[DVec3; 3]; 2] {
    [[a, b, c], [a, c, d]]
}

/// A level square of half-size `half` around the origin at height `z`.
fn ground(z: f64, half: f64) -> [[DVec3; 3]; 2] {
    quad(
        v(-half, -half, z),
        v(half, -half, z),
        v(half, half, z),
        v(-half, half, z),
    )
}

/// The top and the four vertical walls of the box from `lo` to `hi`.
fn block(lo: DVec3, hi: DVec3) -> Vec<[DVec3; 3]> {
    let corner = |x: f64, y: f64, z: f64| v(x, y, z);
    let (x0, y0, z0, x1, y1, z1) = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let mut t = Vec::new();
    t.extend(quad(
        corner(x0, y0, z1),
        corner(x1, y0, z1),
        corner(x1, y1, z1),
        corner(x0, y1, z1),
    ));
    t.extend(quad(
        corner(x0, y0, z0),
        corner(x1, y0, z0),
        corner(x1, y0, z1),
        corner(x0, y0, z1),
    ));
    t.extend(quad(
        corner(x1, y0, z0),
        corner(x1, y1, z0),
        corner(x1, y1, z1),
        corner(x1, y0, z1),
    ));
    t.extend(quad(
        corner(x1, y1, z0),
        corner(x0, y1, z0),
        corner(x0, y1, z1),
        corner(x1, y1, z1),
    ));
    t.extend(quad(
        corner(x0, y1, z0),
        corner(x0, y0, z0),
        corner(x0, y0, z1),
        corner(x0, y1, z1),
    ));
    t
}

/// Every sample of `gcode`, measured.
fn measured(gcode: &str, mesh: &TriMesh, outer_diameter_mm: f64, tol_mm: f64) -> Vec<Sample> {
    let mut oracle = Oracle::new(mesh, outer_diameter_mm / 2.0, tol_mm);
    let mut samples = Vec::new();
    for_each_sample(gcode, STEP_MM, |line, position| {
        let (distance_mm, depth_mm) = oracle.measure(position);
        samples.push(Sample {
            line,
            position,
            distance_mm,
            depth_mm,
        });
    });
    samples
}

/// Every move of `gcode` as the interpreter reads it.
fn moves(gcode: &str) -> Vec<Move> {
    let mut out = Vec::new();
    walk(gcode, |m| out.push(*m));
    out
}

/// A reported distance must lie in [truth, truth + GAP_MM].
fn assert_distance(sample: &Sample, truth: f64) {
    assert!(
        sample.distance_mm >= truth - 1e-9 && sample.distance_mm <= truth + GAP_MM + 1e-9,
        "line {} at {}: distance {} where {truth} is exact",
        sample.line,
        sample.position,
        sample.distance_mm
    );
}

/// xorshift64*: reproducible random numbers without a dependency (also
/// the point-cloud tests' noise).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn point(&mut self, half: f64) -> DVec3 {
        v(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
}

/// Points of `t` on a barycentric grid of `n` divisions, and how far any
/// point of `t` can be from the nearest of them (a point lies in a small
/// triangle of the grid, whose edges are the edges of `t` over n).
fn dense_points(t: &[DVec3; 3], n: usize) -> (Vec<DVec3>, f64) {
    let mut points = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for i in 0..=n {
        for j in 0..=n - i {
            let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
            points.push(t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b);
        }
    }
    let longest = (0..3)
        .map(|k| t[k].distance(t[(k + 1) % 3]))
        .fold(0.0, f64::max);
    (points, longest / n as f64)
}

#[test]
fn solid_distance_in_each_region() {
    let (p, r) = (v(1.0, 2.0, 3.0), 1.0);
    let cases = [
        (v(1.5, 2.0, 1.0), 2.0),              // under the disk: straight down
        (v(4.0, 2.0, 8.0), 2.0),              // beside the body, above the tip
        (v(1.0, 6.0, 0.0), 3f64.hypot(3.0)),  // below and outside: to the rim
        (v(1.0 + 0.6, 2.0 + 0.8, 50.0), 0.0), // inside the body
        (v(1.0, 3.0, 3.0), 0.0),              // on the rim
        (v(1.0, 2.0, 3.0 - 1e-3), 1e-3),      // just under the tip
    ];
    for (q, want) in cases {
        let (d, g) = solid_distance(p, r, q);
        assert!((d - want).abs() < 1e-12, "{q}: {d} instead of {want}");
        if d > 0.0 {
            // The gradient of a distance has unit length and matches the
            // finite differences.
            assert!((g.length() - 1.0).abs() < 1e-12, "{q}: gradient {g}");
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let h = 1e-7;
                let slope = (solid_distance(p, r, q + axis * h).0
                    - solid_distance(p, r, q - axis * h).0)
                    / (2.0 * h);
                assert!((slope - g.dot(axis)).abs() < 1e-6, "{q}: {slope} vs {g}");
            }
        }
    }
    // A box shrunk to a point is that point.
    let mut rng = Rng(7);
    for _ in 0..1000 {
        let q = rng.point(4.0) + p;
        assert!((box_distance(q, q, p, r) - solid_distance(p, r, q).0).abs() < 1e-12);
    }
}

#[test]
fn box_distance_is_no_more_than_any_point_of_the_box() {
    let (p, r) = (v(0.0, 0.0, 0.0), 0.4);
    let mut rng = Rng(11);
    for _ in 0..300 {
        let (a, b) = (rng.point(3.0), rng.point(3.0));
        let (lo, hi) = (a.min(b), a.max(b));
        let bound = box_distance(lo, hi, p, r);
        let mut least = f64::INFINITY;
        let n = 12;
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    let s = DVec3::new(i as f64, j as f64, k as f64) / n as f64;
                    least = least.min(solid_distance(p, r, lo + (hi - lo) * s).0);
                }
            }
        }
        let cover = (hi - lo).length() / n as f64;
        assert!(bound <= least + 1e-12, "box {lo}..{hi}: {bound} > {least}");
        assert!(bound >= least - cover, "box {lo}..{hi}: {bound} << {least}");
    }
}

#[test]
fn node_bounds_never_exceed_the_distance_anywhere_on_the_node() {
    let mut rng = Rng(3);
    for case in 0..400 {
        let p = rng.point(1.0);
        let r = rng.range(0.0, 0.6);
        // Triangles of every size, from needles to broad ones, near the tip.
        let size = [0.01, 0.1, 1.0, 3.0][case % 4];
        let c = p + rng.point(1.5);
        let t = [
            c + rng.point(size),
            c + rng.point(size),
            c + rng.point(size),
        ];
        let (lower, at_centroid) = node_bound(p, r, &t);
        let (points, _) = dense_points(&t, 60);
        let least = points
            .iter()
            .map(|&q| solid_distance(p, r, q).0)
            .fold(f64::INFINITY, f64::min);
        assert!(
            lower <= least + 1e-12,
            "case {case}: bound {lower} above {least}"
        );
        assert!(lower <= at_centroid);
    }
}

#[test]
fn triangle_distance_agrees_with_dense_sampling() {
    let mut rng = Rng(5);
    let mut measured_cases = 0;
    for case in 0..300 {
        let p = rng.point(1.0);
        let r = rng.range(0.05, 0.6);
        let size = [0.05, 0.3, 1.0, 2.5][case % 4];
        let c = p + rng.point(1.2);
        let mut t = [
            c + rng.point(size),
            c + rng.point(size),
            c + rng.point(size),
        ];
        if case % 5 == 0 {
            // A vertical triangle, as on a scanned wall.
            t[2] = v(t[1].x, t[1].y, t[0].z + size);
        }
        let mut oracle = Oracle::new(&mesh_of(&[t]), r, 0.0);
        let (distance, _) = oracle.measure(p);
        let (points, cover) = dense_points(&t, 400);
        let least = points
            .iter()
            .map(|&q| solid_distance(p, r, q).0)
            .fold(f64::INFINITY, f64::min);
        if least - cover >= NEAR_MM {
            assert!(distance.is_infinite(), "case {case}: {distance} far away");
            continue;
        }
        if least < NEAR_MM - 0.01 {
            measured_cases += 1;
            assert!(
                distance <= least + GAP_MM + 1e-12,
                "case {case}: {distance} above sampled {least}"
            );
            assert!(
                distance >= least - cover - 1e-12,
                "case {case}: {distance} below sampled {least} - {cover}"
            );
        }
    }
    assert!(
        measured_cases > 200,
        "only {measured_cases} cases near enough"
    );
}

#[test]
fn highest_point_in_the_disk_agrees_with_dense_sampling() {
    let mut rng = Rng(9);
    let mut found = 0;
    for case in 0..300 {
        let p = rng.point(1.0);
        let r = rng.range(0.05, 0.8);
        let size = [0.1, 0.5, 2.0][case % 3];
        let c = p + rng.point(0.6);
        let mut t = [
            c + rng.point(size),
            c + rng.point(size),
            c + rng.point(size),
        ];
        if case % 4 == 0 {
            t[2] = v(t[1].x, t[1].y, t[0].z + size);
        }
        let exact = highest_in_disk(&t, p, r);
        let (points, cover) = dense_points(&t, 300);
        let xy = |q: &DVec3| (q.x - p.x).hypot(q.y - p.y);
        let inside = points
            .iter()
            .filter(|q| xy(q) <= r)
            .map(|q| q.z)
            .fold(f64::NEG_INFINITY, f64::max);
        let near = points
            .iter()
            .filter(|q| xy(q) <= r + cover)
            .map(|q| q.z)
            .fold(f64::NEG_INFINITY, f64::max);
        match exact {
            None => assert!(inside.is_infinite(), "case {case}: missed z {inside}"),
            Some(z) => {
                found += 1;
                assert!(
                    z >= inside - 1e-12,
                    "case {case}: {z} below sampled {inside}"
                );
                assert!(z <= near + cover + 1e-12, "case {case}: {z} above {near}");
            }
        }
    }
    assert!(found > 100, "only {found} triangles reached the disk");
}

#[test]
fn reads_every_comment_style_line_number_and_mode() {
    let gcode = "\
; a Marlin comment, G1 X100
N10 G21 G90 *71
G0 X1 Y2 Z3 ; unknown start
(a grbl comment G1 X100) G1 X2 (inline; still a comment) Y2
  ' an Aerotech comment G1 X100
$DO[0].X = 1
DWELL 0.5
G76
M106 S255
G4 P500
x3
G91
Z-1
G90 G20
X1
G71
N20 G92 X0
X1
G0 F3000
Y5
G01 X-.5 Y+1.
G28
G1 X0 Y0 Z0
";
    let known = |x: f64, y: f64, z: f64| [Some(x), Some(y), Some(z)];
    let want = [
        (3, [None; 3], known(1.0, 2.0, 3.0)),
        (4, known(1.0, 2.0, 3.0), known(2.0, 2.0, 3.0)),
        (11, known(2.0, 2.0, 3.0), known(3.0, 2.0, 3.0)),
        (13, known(3.0, 2.0, 3.0), known(3.0, 2.0, 2.0)),
        (15, known(3.0, 2.0, 2.0), known(25.4, 2.0, 2.0)),
        (18, known(25.4, 2.0, 2.0), known(26.4, 2.0, 2.0)),
        (20, known(26.4, 2.0, 2.0), known(26.4, 5.0, 2.0)),
        (21, known(26.4, 5.0, 2.0), known(24.9, 1.0, 2.0)),
        // G28 forgets the position but not G92's offset.
        (23, [None; 3], known(25.4, 0.0, 0.0)),
    ];
    let got = moves(gcode);
    assert_eq!(got.len(), want.len(), "{got:#?}");
    let close = |a: [Option<f64>; 3], b: [Option<f64>; 3]| {
        a.iter().zip(&b).all(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => (a - b).abs() < 1e-12,
            (None, None) => true,
            _ => false,
        })
    };
    for (m, (line, from, to)) in got.iter().zip(want) {
        assert_eq!(m.line, line, "{m:?}");
        assert!(close(m.from, from) && close(m.to, to), "line {line}: {m:?}");
    }
    // Only the unknown starts are sampled at their end alone.
    let mut sampled_lines = Vec::new();
    let counts = for_each_sample(gcode, 0.25, |line, _| sampled_lines.push(line));
    assert_eq!(
        counts,
        MoveCounts {
            moves: 9,
            unknown_start: 2
        }
    );
    assert_eq!(sampled_lines.iter().filter(|&&l| l == 3).count(), 1);
    assert_eq!(sampled_lines.iter().filter(|&&l| l == 4).count(), 4);
    assert_eq!(sampled_lines.iter().filter(|&&l| l == 15).count(), 90); // 22.4 mm
}

#[test]
fn positions_set_before_anything_is_known_stay_unknown() {
    // G92 at an unknown position leaves the frame unknown on that axis; an
    // end with an unknown axis cannot be sampled.
    let got = moves("G92 X0\nG1 X5 Y1 Z1\nG1 Z0\n");
    assert_eq!(got[0].to, [None, Some(1.0), Some(1.0)]);
    assert_eq!(got[1].to, [None, Some(1.0), Some(0.0)]);
    let mut samples = 0;
    let counts = for_each_sample("G92 X0\nG1 X5 Y1 Z1\nG1 Z0\n", STEP_MM, |_, _| samples += 1);
    assert_eq!((counts.moves, counts.unknown_start, samples), (2, 2, 0));
}

#[test]
#[should_panic(expected = "line 3: arcs")]
fn arcs_are_refused_with_their_line() {
    moves("G90\nG1 X0 Y0 Z1\nG2 X1 Y1 I1 J0\n");
}

#[test]
#[should_panic(expected = "line 2: cannot read")]
fn unreadable_words_are_refused_with_their_line() {
    moves("G1 X0 Y0 Z1\nG1 X1 #5\n");
}

#[test]
#[should_panic(expected = "line 1: axis words before any G0/G1")]
fn axis_words_without_a_motion_mode_are_refused() {
    moves("X1 Y1 Z1\n");
}

#[test]
fn flat_plane_under_a_tip_at_0_2() {
    let mesh = mesh_of(&ground(0.0, 50.0));
    let gcode = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0.2\nG1 X10 Y3\nG1 X-7 Y12\n";
    let report = check_gcode(gcode, &mesh, 0.5, 0.1);
    assert!((report.min_distance_mm - 0.2).abs() <= 1e-3, "{report:?}");
    assert_eq!((report.moves, report.unknown_start), (4, 1));
    assert_eq!((report.too_close, report.deepest_mm), (0, 0.0));
    // The plane is level, so every sample is its height away, or not near.
    for s in measured(gcode, &mesh, 0.5, 0.1) {
        if s.position.z < NEAR_MM - 1e-6 {
            assert_distance(&s, s.position.z);
        } else if s.position.z > NEAR_MM + 1e-6 {
            assert!(s.distance_mm.is_infinite(), "{s:?}");
        }
    }
    // A larger tolerance: exactly the samples at 0.2 are too close, which
    // is every sample of lines 4 and 5 and the end of line 3.
    let strict = check_gcode(gcode, &mesh, 0.5, 0.25);
    let at_height = measured(gcode, &mesh, 0.5, 0.25)
        .iter()
        .filter(|s| s.position.z < 0.25)
        .count();
    assert_eq!(strict.too_close, at_height);
    assert!(at_height > 400, "{at_height}");
    let first: Vec<(usize, DVec3)> = measured(gcode, &mesh, 0.5, 0.25)
        .iter()
        .filter(|s| s.position.z < 0.25)
        .take(FIRST_TOO_CLOSE)
        .map(|s| (s.line, s.position))
        .collect();
    let listed: Vec<(usize, DVec3)> = strict
        .first_too_close
        .iter()
        .map(|s| (s.line, s.position))
        .collect();
    assert_eq!(listed, first);
    assert_eq!(listed.len(), FIRST_TOO_CLOSE);
    assert_eq!(listed[0].0, 3);
    assert_eq!(listed[FIRST_TOO_CLOSE - 1].0, 4);
}

/// The 2 mm block on the ground used by the corner and dialect tests.
fn block_scene() -> TriMesh {
    let mut t = block(v(0.0, 0.0, 0.0), v(10.0, 10.0, 2.0));
    t.extend(ground(0.0, 30.0));
    mesh_of(&t)
}

/// Horizontal distance from (x, y) to the block's footprint.
fn to_footprint(x: f64, y: f64) -> f64 {
    let dx = (-x).max(x - 10.0).max(0.0);
    let dy = (-y).max(y - 10.0).max(0.0);
    dx.hypot(dy)
}

#[test]
fn a_move_between_clear_ends_that_cuts_the_block_corner_is_too_close() {
    let mesh = block_scene();
    let (od, tol) = (0.5, 0.1);
    // Both ends are 1 mm from the block in xy (0.75 from the nozzle's
    // side); the straight line between them passes over the corner (0, 10),
    // 0.5 mm below the top.
    let low = "G90 G21\nG0 X-1 Y9 Z1.5\nG1 X1 Y11 Z1.5\nG0 Z6\n";
    let report = check_gcode(low, &mesh, od, tol);
    assert!(report.too_close > 0, "{report:?}");
    assert!(
        report.first_too_close.iter().all(|s| s.line == 3),
        "{report:?}"
    );
    let worst = report.worst.expect("samples near the block");
    assert_eq!(worst.line, 3);
    assert!(
        worst.distance_mm <= GAP_MM && worst.depth_mm > 0.0,
        "{worst:?}"
    );
    assert!((report.deepest_mm - 0.5).abs() < 1e-9, "{report:?}");
    let samples = measured(low, &mesh, od, tol);
    let ends: Vec<&Sample> = samples
        .iter()
        .filter(|s| s.line == 2 || (s.line == 3 && s.position.x == 1.0))
        .collect();
    assert_eq!(ends.len(), 2);
    for end in ends {
        assert!(end.distance_mm > tol, "{end:?}");
    }
    // Below the top, the walls beside the body are nearest: the distance
    // is the xy gap to the footprint less the radius.
    for s in samples.iter().filter(|s| s.line == 3) {
        assert_distance(
            s,
            (to_footprint(s.position.x, s.position.y) - od / 2.0).max(0.0),
        );
        assert_eq!(
            s.depth_mm > 0.0,
            to_footprint(s.position.x, s.position.y) < od / 2.0
        );
    }

    // 2.5 mm higher, the same move clears the top by 2 mm.
    let high = "G90 G21\nG0 X-1 Y9 Z4\nG1 X1 Y11 Z4\nG0 Z6\n";
    let report = check_gcode(high, &mesh, od, tol);
    assert_eq!(report.too_close, 0, "{report:?}");
    assert_eq!(report.deepest_mm, 0.0);
    assert!((report.min_distance_mm - 2.0).abs() <= GAP_MM, "{report:?}");
}

#[test]
fn a_wall_beside_a_descending_move_is_the_gap_less_the_radius_away() {
    // The wall x = 0 rises from z = 0 to 5; the tip descends 0.9 mm from
    // it, from 2 mm above the wall's top to 1 mm above its foot.
    let mesh = mesh_of(&quad(
        v(0.0, -5.0, 0.0),
        v(0.0, 5.0, 0.0),
        v(0.0, 5.0, 5.0),
        v(0.0, -5.0, 5.0),
    ));
    let (od, gap) = (0.6, 0.9);
    let gcode = "G0 X-0.9 Y0.3 Z7\nG1 Z1\n";
    let samples = measured(gcode, &mesh, od, 0.1);
    assert_eq!(samples.len(), 1 + 120);
    for s in &samples {
        let above_top = (s.position.z - 5.0).max(0.0);
        // Above the top the rim is nearest.
        let truth = (gap - od / 2.0).hypot(above_top);
        if truth < NEAR_MM {
            assert_distance(s, truth);
        }
    }
    let report = check_gcode(gcode, &mesh, od, 0.1);
    assert!((report.min_distance_mm - 0.6).abs() <= GAP_MM, "{report:?}");
}

#[test]
fn a_tilted_plane_is_as_near_as_the_disks_uphill_rim() {
    let r = 0.3;
    for degrees in [10.0f64, 30.0, 60.0] {
        let (s, c) = degrees.to_radians().sin_cos();
        for (k, heading) in [0.0f64, 0.7, 2.0, 4.5].into_iter().enumerate() {
            // z = x tan(theta) in a frame turned by `heading` about z,
            // through the point below the tip.
            let base = v(3.0, -2.0, 1.0);
            let (hs, hc) = heading.sin_cos();
            let at = |u: f64, w: f64| base + v(u * hc - w * hs, u * hs + w * hc, u * s / c);
            let mesh = mesh_of(&quad(
                at(-20.0, -20.0),
                at(20.0, -20.0),
                at(20.0, 20.0),
                at(-20.0, 20.0),
            ));
            let mut oracle = Oracle::new(&mesh, r, 0.1);
            for h in [0.05, 0.2, 0.5, 1.0, 1.5] {
                let tip = base + v(0.0, 0.0, h);
                let (distance, depth) = oracle.measure(tip);
                // The rim point uphill is r tan(theta) higher on the plane.
                let rise = r * s / c;
                let truth = ((h - rise) * c).max(0.0);
                let sample = Sample {
                    line: k,
                    position: tip,
                    distance_mm: distance,
                    depth_mm: depth,
                };
                if truth < NEAR_MM {
                    assert_distance(&sample, truth);
                }
                let want_depth = (rise - h).max(0.0);
                assert!(
                    (depth - want_depth).abs() < 1e-9,
                    "{degrees} deg, h {h}: depth {depth} vs {want_depth}"
                );
            }
        }
    }
}

/// The moves of the dialect test: absolute millimetres, dyadic so that
/// decimal text and differences are exact.
const DIALECT_POINTS: [[f64; 3]; 7] = [
    [-2.0, 5.0, 1.5],
    [-0.125, 5.0, 1.5],
    [-0.625, 10.5, 1.5],
    [5.0, 10.375, 2.125],
    [5.0, 5.0, 2.25],
    [12.0, -3.0, 0.75],
    [10.25, 11.5, 0.5],
];

/// The same program in four dialects with the same line layout.
fn dialect_programs() -> Vec<String> {
    let word = |p: [f64; 3], scale: f64| {
        format!(
            "X{:.12} Y{:.12} Z{:.12}",
            p[0] / scale,
            p[1] / scale,
            p[2] / scale
        )
    };
    let p = DIALECT_POINTS;
    let minus = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let mut programs = Vec::new();
    for dialect in 0..4 {
        let (header, switch) = match dialect {
            0 => ("G90 G21", "; absolute millimetres"),
            1 => ("G90 G21", "G91"),
            2 => ("G90 G20", "(absolute inches)"),
            _ => ("G21 G90", "G92 X0 Y0 Z0"),
        };
        let scale = if dialect == 2 { 25.4 } else { 1.0 };
        let mut text = format!("{header}\nG0 {}\n{switch}\n", word(p[0], scale));
        for k in 1..p.len() {
            let target = match dialect {
                1 => minus(p[k], p[k - 1]),
                3 => minus(p[k], p[0]),
                _ => p[k],
            };
            text.push_str(&format!("G1 {}\n", word(target, scale)));
        }
        programs.push(text);
    }
    programs
}

#[test]
fn units_distance_modes_and_offsets_give_the_same_samples() {
    let mesh = block_scene();
    let programs = dialect_programs();
    let reference = measured(&programs[0], &mesh, 0.5, 0.1);
    let reference_report = check_gcode(&programs[0], &mesh, 0.5, 0.1);
    assert!(reference_report.too_close > 0 && reference_report.min_distance_mm < 0.1);
    for program in &programs[1..] {
        let samples = measured(program, &mesh, 0.5, 0.1);
        assert_eq!(samples.len(), reference.len(), "{program}");
        for (a, b) in samples.iter().zip(&reference) {
            assert_eq!(a.line, b.line);
            assert!(a.position.distance(b.position) < 1e-9, "{a:?} vs {b:?}");
            assert!(
                (a.distance_mm - b.distance_mm).abs() < 1e-9,
                "{a:?} vs {b:?}"
            );
            assert!((a.depth_mm - b.depth_mm).abs() < 1e-9, "{a:?} vs {b:?}");
        }
        let report = check_gcode(program, &mesh, 0.5, 0.1);
        assert_eq!(
            (
                report.moves,
                report.unknown_start,
                report.samples,
                report.too_close
            ),
            (
                reference_report.moves,
                reference_report.unknown_start,
                reference_report.samples,
                reference_report.too_close
            ),
            "{program}"
        );
        assert!((report.min_distance_mm - reference_report.min_distance_mm).abs() < 1e-9);
        assert!((report.deepest_mm - reference_report.deepest_mm).abs() < 1e-9);
    }
}

#[test]
fn demo_part_region_one_clear_above_and_too_close_through_the_block() {
    use pcpp::demo::test_part;
    let built = Instant::now();
    let part = test_part::test_part();
    let made_in = built.elapsed();
    // The nozzle of the demo's report (do 0.908 mm), tol 0.1 mm. Region 1
    // tops out at z = 8 on its staircase (x 56..60), so the clear pass
    // runs at z = 9 and the pass at z = 8 touches the staircase only.
    let (od, tol, r) = (0.908, 0.1, 0.454);
    let gcode = "\
G21 G90
G0 X10 Y16 Z9
G1 X70
G0 Z8
G1 X10
G0 Z5.7
G1 X25
G0 Z9
";
    let started = Instant::now();
    let report = check_gcode(gcode, &part, od, tol);
    let took = started.elapsed();
    eprintln!(
        "bruteforce: demo part ({} triangles, made in {made_in:.2?}): {} moves, {} samples \
         checked in {took:.2?}; min distance {:.4} mm, {} too close, deepest {:.4} mm",
        part.triangles.len(),
        report.moves,
        report.samples,
        report.min_distance_mm,
        report.too_close,
        report.deepest_mm
    );
    assert_eq!((report.moves, report.unknown_start), (7, 1));
    let samples = measured(gcode, &part, od, tol);
    // At z = 9 everything is at least 1 mm away; the staircase top is
    // exactly 1 mm below.
    let high: Vec<&Sample> = samples.iter().filter(|s| s.line == 3).collect();
    let least = high
        .iter()
        .map(|s| s.distance_mm)
        .fold(f64::INFINITY, f64::min);
    assert!((least - 1.0).abs() <= GAP_MM, "z 9: {least}");
    // At z = 8 the staircase top touches the disk; its wall at x = 56 is
    // the gap less the radius away from the side.
    for s in samples.iter().filter(|s| s.line == 5) {
        let x = s.position.x;
        let near_stairs = x > 56.0 - r - tol && x < 60.0 + r + tol;
        assert_eq!(s.distance_mm < tol, near_stairs, "{s:?}");
        assert!(s.depth_mm < 1e-9, "{s:?}");
        if (53.0..56.0 - r).contains(&x) {
            // The step below (top z = 7), or the next one's wall.
            assert_distance(s, (56.0 - x - r).min(1.0));
        }
    }
    // At z = 5.7 the 2 mm block (top z = 7, x 16..22) is 1.3 mm deep.
    let through: Vec<&Sample> = samples.iter().filter(|s| s.line == 7).collect();
    for s in &through {
        let x = s.position.x;
        assert_eq!(
            s.distance_mm < tol,
            x > 16.0 - r - tol && x < 22.0 + r + tol,
            "{s:?}"
        );
        if x < 16.0 - r - 1e-9 {
            // The level base 0.7 mm below, or the block's wall.
            assert_distance(s, 0.7f64.min(16.0 - x - r));
        }
    }
    let deepest = through.iter().map(|s| s.depth_mm).fold(0.0, f64::max);
    assert!((deepest - 1.3).abs() < 1e-6, "{deepest}");
    assert!((report.deepest_mm - 1.3).abs() < 1e-6, "{report:?}");
    let first = report.first_too_close[0];
    assert_eq!(first.line, 5, "the staircase comes first in the file");
    assert!(report.too_close > 0 && report.min_distance_mm <= GAP_MM);
    assert!(took.as_secs_f64() < 20.0, "{took:?}");
}

#[test]
fn golden_demo_programs_read_alike_in_every_dialect() {
    use pcpp::demo::test_part;
    let part = test_part::test_part();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let mut reports = Vec::new();
    for dialect in ["aerotech", "grbl", "marlin"] {
        let path = dir.join(format!("demo-{dialect}.gcode"));
        let gcode = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let started = Instant::now();
        let report = check_gcode(&gcode, &part, 0.908, 0.1);
        eprintln!(
            "bruteforce: golden {dialect}: {} moves ({} from an unknown start), {} samples in \
             {:.2?}; min distance {:.4} mm at {:?}, {} too close, deepest {:.4} mm",
            report.moves,
            report.unknown_start,
            report.samples,
            started.elapsed(),
            report.min_distance_mm,
            report.worst.map(|w| (w.line, w.position)),
            report.too_close,
            report.deepest_mm
        );
        reports.push(report);
    }
    // The writer starts with a pure rise and then one travel to the first
    // point, both from an unknown start.
    for r in &reports {
        assert_eq!(r.unknown_start, 2, "{r:?}");
        assert_eq!(r.moves, reports[0].moves);
        assert!(
            r.samples > 9000,
            "465 mm of print alone is 9300 steps: {r:?}"
        );
        // Coordinates differ by the rounding of 3 or 4 decimals.
        assert!((r.min_distance_mm - reports[0].min_distance_mm).abs() < 1e-3);
    }
}

#[test]
fn buckets_and_pruning_agree_with_every_triangle_alone() {
    // Small, large and needle-like triangles, so that many straddle
    // buckets, and tips among them at every height.
    let mut rng = Rng(13);
    let mut triangles = Vec::new();
    for k in 0..400 {
        let c = v(
            rng.range(0.0, 12.0),
            rng.range(0.0, 12.0),
            rng.range(0.0, 3.0),
        );
        let size = [0.1, 0.4, 1.5, 6.0][k % 4];
        let mut t = [
            c + rng.point(size),
            c + rng.point(size),
            c + rng.point(size),
        ];
        if k % 7 == 0 {
            t[2] = t[1] + v(0.0, 0.0, size);
        }
        triangles.push(t);
    }
    let r = 0.3;
    let mut oracle = Oracle::new(&mesh_of(&triangles), r, 0.1);
    let mut alone: Vec<Oracle> = triangles
        .iter()
        .map(|t| Oracle::new(&mesh_of(&[*t]), r, 0.1))
        .collect();
    let mut checked = 0;
    for _ in 0..300 {
        let p = v(
            rng.range(-1.0, 13.0),
            rng.range(-1.0, 13.0),
            rng.range(-0.5, 4.5),
        );
        let (distance, depth) = oracle.measure(p);
        let least = alone
            .iter_mut()
            .map(|o| o.measure(p).0)
            .fold(f64::INFINITY, f64::min);
        let top = triangles
            .iter()
            .filter_map(|t| highest_in_disk(t, p, r))
            .fold(p.z, f64::max);
        if least.is_finite() {
            checked += 1;
            assert!(
                (distance - least).abs() <= GAP_MM,
                "{p}: {distance} vs {least}"
            );
        } else {
            assert!(distance.is_infinite(), "{p}: {distance}");
        }
        assert!(
            (depth - (top - p.z)).abs() < 1e-12,
            "{p}: depth {depth} vs {}",
            top - p.z
        );
    }
    assert!(checked > 200, "{checked}");
}
