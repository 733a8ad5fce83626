//! Safe motion (spec section 6f): the stage moves in straight lines between
//! consecutive points, so safety is a property of every move, not of the
//! planned points.
//!
//! One check serves the planners, the G-code writer's output, `pcpp check`
//! and the page: [`Clearance::gap`], the swept test of
//! [`Surface::nozzle_gap`]. The nozzle is the tip disk of diameter do and
//! the body above it (a vertical cylinder of the same diameter); a move is
//! clear when the nozzle keeps at least tol from the surface at every
//! position along it, in every direction (exact where the nearest surface
//! is a facet; at corners and edges conservative by up to tol (cos
//! theta_(i-1) - cos theta_i) of the rim's step a contact falls under:
//! 0.09, 0.20, 0.28 and 0.42 tol from the rim's inner ring out, so a
//! clearance there may read that much below the true one, never above
//! it; QA round 6 measured up to 0.28 tol on real scans; see the sweep's
//! module comment).
//!
//! Where a straight move between two planned points would come closer, the
//! guarded planners add waypoints on it ([`insert_waypoints`]): at the
//! place where the move is worst, as high as the footprint there needs and
//! no higher, recursively, so a move up a step rises before the step and a
//! move down one passes the edge before it descends.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::gcode::WrittenMove;
use crate::parallel;
use crate::params::Nozzle;
use crate::surface::{Surface, SweepGap};

/// The safe-motion criterion for one nozzle and tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// The tip's radius, do/2.
    pub radius_mm: f64,
    /// The distance the nozzle keeps from the surface: tol.
    pub tol_mm: f64,
}

/// The margin the planners keep beyond [`Clearance`], so that rounding the
/// coordinates to the G-code's decimals (0.0005 mm at 3 decimals) never
/// turns a clear move into a touching one.
pub const PLANNING_MARGIN_MM: f64 = 0.002;

/// Gaps this close below tol count as tol: a planned point set at exactly
/// tol must not fail on rounding (the planning margin is what absorbs the
/// G-code's rounding).
const TIE_MM: f64 = 1e-9;

/// Most waypoints added to one move before falling back to rising over the
/// whole move at once.
const MAX_WAYPOINTS_PER_MOVE: usize = 12;

impl Clearance {
    /// The check of spec section 6(f) for `nozzle` and tolerance `tol_mm`.
    pub fn new(nozzle: &Nozzle, tol_mm: f64) -> Clearance {
        Clearance {
            radius_mm: 0.5 * nozzle.outer_diameter_mm,
            tol_mm,
        }
    }

    /// The same check, keeping `margin` more distance.
    pub fn with_margin(self, margin: f64) -> Clearance {
        Clearance {
            tol_mm: self.tol_mm + margin,
            ..self
        }
    }

    /// The clearance of the straight move `a` -> `b` (at least tol when
    /// the nozzle keeps tol from the surface all along it; see
    /// [`Surface::nozzle_gap`]), or `None` when it is at least `limit`.
    pub fn gap(&self, surface: &Surface, a: DVec3, b: DVec3, limit: f64) -> Option<SweepGap> {
        surface.nozzle_gap(a, b, self.radius_mm, self.tol_mm, limit)
    }

    /// Whether the straight move `a` -> `b` stays clear (the first
    /// contact found answers it: no smallest clearance is sought, and the
    /// triangles are tried as their bounds let them through,
    /// [`Surface::nozzle_touches`]).
    pub fn is_clear(&self, surface: &Surface, a: DVec3, b: DVec3) -> bool {
        !surface.nozzle_touches(a, b, self.radius_mm, self.tol_mm, self.touch_limit())
    }

    /// The clearance below which a move touches: tol, less a hair so an
    /// exact tie with rounding is not a contact.
    fn touch_limit(&self) -> f64 {
        self.tol_mm - TIE_MM
    }

    /// The gap of the move `a` -> `b` if it is below tol.
    pub fn touching(&self, surface: &Surface, a: DVec3, b: DVec3) -> Option<SweepGap> {
        self.touching_until(surface, a, b, |_| false)
    }

    /// [`Self::touching`], stopping at a gap for which `enough` holds (see
    /// [`Surface::nozzle_gap_until`]: `enough` must hold for every gap
    /// below one it holds for).
    fn touching_until(
        &self,
        surface: &Surface,
        a: DVec3,
        b: DVec3,
        enough: impl Fn(f64) -> bool,
    ) -> Option<SweepGap> {
        let limit = self.touch_limit();
        surface.nozzle_gap_until(a, b, self.radius_mm, self.tol_mm, limit, &enough)
    }

    /// How far the tip at `p` must rise to keep tol from the surface (0
    /// when it does), with a hair more so that the raised point's own
    /// moves never fail on an exact tie with rounding.
    pub fn rise_needed(&self, surface: &Surface, p: DVec3) -> f64 {
        self.rise_until(surface, p, |_| false)
    }

    /// [`Self::rise_needed`] for a caller that needs it only while
    /// `enough` does not hold for it: where `enough` holds for the rise
    /// needed, the value returned may be smaller, but `enough` holds for it
    /// too (and it is positive); otherwise it is the rise needed. `enough`
    /// must be monotone: true for a rise, true for every larger one.
    pub fn rise_until(&self, surface: &Surface, p: DVec3, enough: impl Fn(f64) -> bool) -> f64 {
        // The rise of a gap falls as the gap grows, so a gap below one
        // whose rise is enough has a rise that is enough too.
        let rise = |gap: f64| self.tol_mm - gap + 1e-6;
        match self.touching_until(surface, p, p, |gap| enough(rise(gap))) {
            Some(g) => rise(g.gap_mm),
            None => 0.0,
        }
    }
}

/// A planned piece with the waypoints that make its moves safe.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SafePath {
    /// The points the nozzle visits: the planned points with waypoints
    /// between them.
    pub points: Vec<DVec3>,
    /// Waypoints added.
    pub waypoints: usize,
    /// Length added to the path by the waypoints, mm.
    pub extra_length_mm: f64,
    /// Planned points j whose move to j + 1 could not be made safe (the
    /// planned point itself does not clear).
    pub unresolved: Vec<usize>,
    /// The smallest clearance of the moves between planned points that
    /// needed no waypoint (by `clearance`, so with its margin: a lower
    /// bound of the clearance without it), and tol for the moves made by
    /// waypoints; `None` when no move passes near the scan.
    pub min_clearance_mm: Option<f64>,
}

/// Adds waypoints where a straight move between consecutive `planned`
/// points would come closer than `clearance` allows (spec section 6f):
/// at the worst place of the move, raised to the lowest safe height there,
/// then the two halves checked again. A move that needs more than
/// `MAX_WAYPOINTS_PER_MOVE` rises over its whole footprint at once
/// (vertical rise, level move, vertical descent), which is always safe
/// when its two ends are.
pub fn insert_waypoints(surface: &Surface, planned: &[DVec3], clearance: &Clearance) -> SafePath {
    insert_waypoints_capped(surface, planned, clearance, f64::INFINITY)
}

/// [`insert_waypoints`], finding the smallest clearance only below `cap`
/// (above it, `min_clearance_mm` stays `None`): far fewer triangles are
/// visited when the nozzle is well clear.
pub fn insert_waypoints_capped(
    surface: &Surface,
    planned: &[DVec3],
    clearance: &Clearance,
    cap: f64,
) -> SafePath {
    let mut out = SafePath {
        points: Vec::with_capacity(planned.len()),
        ..Default::default()
    };
    let Some(&first) = planned.first() else {
        return out;
    };
    out.points.push(first);
    let cap = cap.max(clearance.tol_mm);
    // The moves are independent: each chunk of them is made safe on its
    // own (on every core natively), and the results are taken in order, so
    // the path and its sums do not depend on how the moves were cut.
    let chunks = parallel::map_chunks(planned.len() - 1, MIN_CHUNK, |moves| {
        let mut fixes: Vec<MoveFix> = Vec::new();
        let mut min = f64::INFINITY;
        for j in moves {
            let (p, q) = (planned[j], planned[j + 1]);
            // The move's clearance matters only below the smallest so far
            // and the cap (and always below tol); the smallest over all
            // chunks is the same as over one.
            let gap = clearance.gap(surface, p, q, min.min(cap).max(clearance.tol_mm));
            if let Some(g) = gap {
                min = min.min(g.gap_mm.max(clearance.touch_limit()));
            }
            if gap.is_none_or(|g| g.gap_mm >= clearance.touch_limit()) {
                continue;
            }
            let mut added = Vec::new();
            let mut unresolved = false;
            if !resolve(surface, clearance, p, q, gap, &mut added, &mut 0) {
                added = rise_over(surface, clearance, p, q);
                if added.is_empty() || !path_clear(surface, clearance, p, &added, q) {
                    unresolved = true;
                    added.clear();
                }
            }
            fixes.push(MoveFix {
                j,
                added,
                unresolved,
            });
        }
        (fixes, min)
    });
    let mut min = f64::INFINITY;
    let mut next = 1;
    for (fixes, chunk_min) in chunks {
        min = min.min(chunk_min);
        for fix in fixes {
            let (p, q) = (planned[fix.j], planned[fix.j + 1]);
            out.points.extend_from_slice(&planned[next..=fix.j]);
            next = fix.j + 1;
            if fix.unresolved {
                out.unresolved.push(fix.j);
            }
            if !fix.added.is_empty() {
                let before = p.distance(q);
                let mut after = 0.0;
                let mut prev = p;
                for &w in fix.added.iter().chain(std::iter::once(&q)) {
                    after += prev.distance(w);
                    prev = w;
                }
                out.extra_length_mm += after - before;
                out.waypoints += fix.added.len();
                out.points.extend_from_slice(&fix.added);
            }
        }
    }
    out.points.extend_from_slice(&planned[next..]);
    out.min_clearance_mm = min.is_finite().then_some(min);
    out
}

/// The waypoints one move needed (`added`), or that it could not be made
/// safe.
struct MoveFix {
    /// The move from planned point j to j + 1.
    j: usize,
    added: Vec<DVec3>,
    unresolved: bool,
}

/// The fewest moves a thread checks at once (each is one swept query, a
/// few microseconds).
const MIN_CHUNK: usize = 256;

fn path_clear(surface: &Surface, c: &Clearance, p: DVec3, mid: &[DVec3], q: DVec3) -> bool {
    let mut prev = p;
    for &w in mid.iter().chain(std::iter::once(&q)) {
        if !c.is_clear(surface, prev, w) {
            return false;
        }
        prev = w;
    }
    true
}

/// Waypoints for p -> q by recursive splitting at the worst place; false
/// when that did not succeed within the budget. `known` is the move's
/// clearance when the caller has just found it below tol (the same query
/// with a larger limit finds the same worst place). `made` counts the
/// waypoints made for the move so far, those still waiting on the
/// recursion's stack too: counting only those already in `out` bounded
/// nothing while the first half kept splitting (a fuzzed scan recursed
/// until the stack overflowed).
fn resolve(
    surface: &Surface,
    c: &Clearance,
    p: DVec3,
    q: DVec3,
    known: Option<SweepGap>,
    out: &mut Vec<DVec3>,
    made: &mut usize,
) -> bool {
    // Most sub-moves clear: that is asked first, of the first contact
    // (`is_clear`, no smallest clearance sought), and the worst place only
    // of those that touch; the same answer, as `touching` is `None`
    // exactly when `is_clear` holds (both ask below `touch_limit`).
    let worst = match known {
        Some(g) => Some(g),
        None if c.is_clear(surface, p, q) => None,
        None => c.touching(surface, p, q),
    };
    let Some(worst) = worst else {
        return true;
    };
    if *made >= MAX_WAYPOINTS_PER_MOVE {
        return false;
    }
    *made += 1;
    let x = p.lerp(q, worst.at);
    // As high as the footprint there needs: the nozzle standing at x has
    // the move's smallest clearance (the worst place is where the move's
    // clearance, a minimum over its positions, is reached), so it must
    // rise by tol less that, and a hair more so that the raised point's
    // own moves never fail on an exact tie with rounding. And at least tol
    // over the surface point that sets the worst clearance: that point
    // usually enters the rounded rim there and then the flat tip as the
    // move goes on (a step's edge), and clearing it by the full tol at
    // once spares a waypoint per step of the rim for a few hundredths of a
    // mm.
    let need = x.z + (c.tol_mm - worst.gap_mm).max(0.0) + 1e-6;
    let w = DVec3::new(x.x, x.y, need.max(worst.surface_point.z + c.tol_mm + 1e-6));
    // A waypoint that coincides with an end changes nothing: the end
    // itself does not clear.
    if w.distance(p) < 1e-9 || w.distance(q) < 1e-9 {
        return false;
    }
    resolve(surface, c, p, w, None, out, made) && {
        out.push(w);
        resolve(surface, c, w, q, None, out, made)
    }
}

/// Rise, level move and descent over the whole footprint of p -> q.
fn rise_over(surface: &Surface, c: &Clearance, p: DVec3, q: DVec3) -> Vec<DVec3> {
    let probe = surface.top_z() + 1.0;
    let (a, b) = (DVec3::new(p.x, p.y, probe), DVec3::new(q.x, q.y, probe));
    // The level move at `probe` clears by gap: the lowest level that keeps
    // tol lies gap - tol below it.
    let top = match c.gap(surface, a, b, f64::INFINITY) {
        Some(g) => probe - g.gap_mm,
        None => return Vec::new(),
    };
    // The clearance of a level move is tol plus the slack over the
    // highest need under it: rising by tol - clearance clears all of it.
    let z = (top + c.tol_mm + 1e-6).max(p.z).max(q.z);
    let mut mid = Vec::with_capacity(2);
    if z > p.z {
        mid.push(DVec3::new(p.x, p.y, z));
    }
    if z > q.z {
        mid.push(DVec3::new(q.x, q.y, z));
    }
    mid
}

/// Counts the tool-path points that move backwards along the drawn path:
/// where the drawn sample nearest (in XY) to a tool-path point falls back
/// by 2 or more samples from the furthest one reached before it. `ta` and
/// `toolpath` have one point per sample.
pub fn backward_moves(ta: &[DVec3], toolpath: &[DVec3]) -> usize {
    backward_points(ta, toolpath).len()
}

/// The tool-path points [`backward_moves`] counts, in order.
pub fn backward_points(ta: &[DVec3], toolpath: &[DVec3]) -> Vec<usize> {
    // The nearest sample is searched near the last one found: a point
    // further back than the window still counts as a step back.
    const WINDOW: usize = 8;
    let mut back = Vec::new();
    let mut reached = 0usize;
    let mut prev = 0usize;
    for (j, t) in toolpath.iter().enumerate() {
        let lo = prev.saturating_sub(WINDOW);
        let hi = (prev + WINDOW).min(ta.len().saturating_sub(1));
        let nearest = (lo..=hi)
            .min_by(|&a, &b| {
                let da = (ta[a] - *t).truncate().length_squared();
                let db = (ta[b] - *t).truncate().length_squared();
                da.total_cmp(&db)
            })
            .unwrap_or(0);
        if j > 0 && nearest + 2 <= reached {
            back.push(j);
        }
        reached = reached.max(nearest);
        prev = nearest;
    }
    back
}

/// What the motion check found over a set of moves.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionSummary {
    /// Moves checked.
    pub moves: usize,
    /// The smallest clearance over all moves (`None` if no move passes
    /// near the scan).
    pub min_clearance_mm: Option<f64>,
    /// Where it is smallest: the tip's position.
    pub min_clearance_at: Option<[f64; 3]>,
    /// G-code line of that move, where known.
    pub min_clearance_line: Option<usize>,
    /// Moves whose clearance is below tol.
    pub touching_moves: usize,
    /// Of those, the moves closest at their start, where the move before
    /// them ended too close: the contact that move was counted for (a
    /// retract straight up out of it, say), which they may or may not come
    /// near again.
    #[serde(default)]
    pub touching_from_previous: usize,
    /// The first touching moves (at most [`MAX_LISTED`]), in order.
    pub touching: Vec<Touch>,
}

/// How many touching moves a summary lists.
pub const MAX_LISTED: usize = 20;

/// A move that comes closer than tol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Touch {
    /// Which move (index into the checked list), and its G-code line
    /// where known.
    pub index: usize,
    pub line: Option<usize>,
    pub from: [f64; 3],
    pub to: [f64; 3],
    /// The tip's position where the move is worst.
    pub at: [f64; 3],
    /// The clearance there (see [`Surface::nozzle_gap`]).
    pub clearance_mm: f64,
    /// How much higher the tip would have to be there to keep tol: the
    /// depth of the violation.
    pub rise_mm: f64,
    /// Whether the move is closest at its start, where the move before it
    /// ended (that move is listed too: it comes at least as close there),
    /// and that move's G-code line where known.
    #[serde(default)]
    pub from_previous: bool,
    #[serde(default)]
    pub previous_line: Option<usize>,
}

fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

impl std::fmt::Display for Touch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(line) = self.line {
            write!(f, "line {line}: ")?;
        }
        let [a, b, c] = self.from;
        let [x, y, z] = self.to;
        let [px, py, pz] = self.at;
        if self.from_previous {
            // Not a contact of its own making (QA: a retract straight up out
            // of a collision read as a second collision, to be fixed by
            // raising a move that moves away from the part).
            let before = match self.previous_line {
                Some(line) => format!("the move before it (line {line})"),
                None => "the move before it".to_string(),
            };
            return write!(
                f,
                "the move ({a:.3}, {b:.3}, {c:.3}) -> ({x:.3}, {y:.3}, {z:.3}) is closest at its \
                 start, where {before} ended too close: the nozzle would have to be {:.3} mm \
                 higher there",
                self.rise_mm
            );
        }
        write!(
            f,
            "the move ({a:.3}, {b:.3}, {c:.3}) -> ({x:.3}, {y:.3}, {z:.3}) comes too close at \
             ({px:.3}, {py:.3}, {pz:.3}): the nozzle would have to be {:.3} mm higher there",
            self.rise_mm
        )
    }
}

/// Checks every move (`from`, `to`, G-code line where known) against the
/// surface: the smallest clearance, and every move below tol.
pub fn check_moves(
    surface: &Surface,
    moves: impl IntoIterator<Item = (DVec3, DVec3, Option<usize>)>,
    clearance: &Clearance,
) -> MotionSummary {
    check_moves_capped(surface, moves, clearance, f64::INFINITY)
}

/// [`check_moves`], finding the smallest clearance only below `cap` (above
/// it, `min_clearance_mm` stays `None`); every move below tol is found
/// whatever the cap.
pub fn check_moves_capped(
    surface: &Surface,
    moves: impl IntoIterator<Item = (DVec3, DVec3, Option<usize>)>,
    clearance: &Clearance,
    cap: f64,
) -> MotionSummary {
    let moves: Vec<(DVec3, DVec3, Option<usize>)> = moves.into_iter().collect();
    let cap = cap.max(clearance.tol_mm);
    // Chunks of moves checked on their own (on every core natively), their
    // summaries joined in order: the same summary as one pass.
    let chunks = parallel::map_chunks(moves.len(), MIN_CHUNK, |range| {
        let mut s = MotionSummary::default();
        let mut min = f64::INFINITY;
        for index in range {
            let (a, b, line) = moves[index];
            s.moves += 1;
            // Only a clearance below tol, or below the smallest so far and
            // the cap, matters.
            let Some(g) = clearance.gap(surface, a, b, min.min(cap).max(clearance.tol_mm)) else {
                continue;
            };
            let at = a.lerp(b, g.at);
            if g.gap_mm < min {
                min = g.gap_mm;
                s.min_clearance_mm = Some(g.gap_mm);
                s.min_clearance_at = Some(arr(at));
                s.min_clearance_line = line;
            }
            if g.gap_mm < clearance.touch_limit() {
                s.touching_moves += 1;
                // Closest at its start, which ends the move before it: that
                // move comes at least as close there (its end is one of its
                // positions).
                let previous = index
                    .checked_sub(1)
                    .map(|k| moves[k])
                    .filter(|&(_, end, _)| g.at == 0.0 && end == a);
                s.touching_from_previous += usize::from(previous.is_some());
                if s.touching.len() < MAX_LISTED {
                    s.touching.push(Touch {
                        index,
                        line,
                        from: arr(a),
                        to: arr(b),
                        at: arr(at),
                        clearance_mm: g.gap_mm,
                        rise_mm: clearance.tol_mm - g.gap_mm,
                        from_previous: previous.is_some(),
                        previous_line: previous.and_then(|(.., line)| line),
                    });
                }
            }
        }
        s
    });
    let mut s = MotionSummary::default();
    for c in chunks {
        s.moves += c.moves;
        // The first move with the smallest clearance, as in one pass.
        if c.min_clearance_mm
            .is_some_and(|m| s.min_clearance_mm.is_none_or(|least| m < least))
        {
            s.min_clearance_mm = c.min_clearance_mm;
            s.min_clearance_at = c.min_clearance_at;
            s.min_clearance_line = c.min_clearance_line;
        }
        s.touching_moves += c.touching_moves;
        s.touching_from_previous += c.touching_from_previous;
        let room = MAX_LISTED - s.touching.len();
        s.touching.extend(c.touching.into_iter().take(room));
    }
    s
}

/// Checks the moves a G-code program commands (spec section 6f): every
/// move whose start is known along its length, a move from an unknown
/// start (the program's first travel) at its end. Only the former are
/// counted in [`MotionSummary::moves`], as `pcpp check` counts them (the
/// plan said 1444 moves where the check of its G-code said 1443).
pub fn check_program(
    surface: &Surface,
    moves: &[WrittenMove],
    clearance: &Clearance,
) -> MotionSummary {
    let mut summary = check_moves(
        surface,
        moves
            .iter()
            .filter(|m| m.to.is_finite())
            .map(|m| (m.from.unwrap_or(m.to), m.to, Some(m.line))),
        clearance,
    );
    summary.moves -= moves
        .iter()
        .filter(|m| m.to.is_finite() && m.from.is_none())
        .count();
    summary
}

/// G-code whose moves come closer to the surface than tol (spec section
/// 6f): refused unless the user accepts the risk.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{count} G-code move(s) of planner {planner} would bring the nozzle (outer diameter \
     {outer_diameter_mm} mm) closer to the surface than tol = {tol_mm} mm, checked along each \
     straight move; {first}; no G-code written. Plan with a guarded planner (even, the \
     default, or pcpp-guarded), or accept the risk (--accept-risk) to write it anyway",
    count = .summary.touching_moves,
    first = .summary.touching.iter().take(3).map(|t| format!("G-code {t}")).collect::<Vec<_>>().join("; ")
)]
pub struct TouchingMoves {
    pub planner: String,
    pub outer_diameter_mm: f64,
    pub tol_mm: f64,
    pub summary: MotionSummary,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::mesh::TriMesh;

    /// A block 2 mm high from x = 5 on, true vertical wall (also the
    /// preview's tests' step).
    pub(crate) fn step() -> Surface {
        let xs = [0.0, 5.0, 5.0, 10.0];
        let ys = [0.0, 10.0];
        let mut m = TriMesh::default();
        for &y in &ys {
            for (i, &x) in xs.iter().enumerate() {
                m.vertices
                    .push(DVec3::new(x, y, if i >= 2 { 2.0 } else { 0.0 }));
            }
        }
        for i in 0..3u32 {
            m.triangles.push([i, i + 1, i + 5]);
            m.triangles.push([i, i + 5, i + 4]);
        }
        Surface::new(m).unwrap()
    }

    #[test]
    fn waypoints_rise_before_a_step_up_and_pass_a_step_down() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        // Up: the low point clears, the high one too; the line between cuts.
        let p = DVec3::new(4.0, 5.0, 0.7);
        let q = DVec3::new(4.6, 5.0, 2.2);
        assert!(c.gap(&s, p, p, f64::INFINITY).unwrap().gap_mm >= 0.1);
        assert!(c.gap(&s, q, q, f64::INFINITY).unwrap().gap_mm >= 0.1);
        assert!(!c.is_clear(&s, p, q));
        let safe = insert_waypoints(&s, &[p, q], &c);
        assert!(safe.unresolved.is_empty());
        assert!(safe.waypoints >= 1, "{safe:?}");
        for w in safe.points.windows(2) {
            assert!(c.is_clear(&s, w[0], w[1]), "{safe:?}");
        }
        // The waypoint is where the wall's edge first comes within reach
        // of the rim, as low as keeping tol from the edge allows there.
        let w = safe.points[1];
        assert!(
            w.x > 5.0 - c.radius_mm - c.tol_mm - 1e-9 && w.x < 5.0 - c.radius_mm,
            "{w}"
        );
        assert!(w.z > 2.0 && w.z < 2.1 + 1e-5, "{w}");
        assert!(safe.extra_length_mm > 0.0);
        // Down: the mirror image; the rounded rim passing the edge can take
        // a few waypoints, all between the two points and none above the
        // higher one.
        let safe = insert_waypoints(&s, &[q, p], &c);
        for w in safe.points.windows(2) {
            assert!(c.is_clear(&s, w[0], w[1]), "{safe:?}");
            assert!(w[1].x <= w[0].x + 1e-12, "{safe:?}");
        }
        assert!((1..=3).contains(&safe.waypoints), "{safe:?}");
        assert!(safe.points.iter().all(|w| w.z <= q.z + 1e-9), "{safe:?}");
    }

    #[test]
    fn a_clear_path_gets_no_waypoints_and_an_unclear_point_is_reported() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let pts: Vec<DVec3> = (0..10)
            .map(|i| DVec3::new(0.5 + 0.3 * i as f64, 5.0, 0.7))
            .collect();
        let safe = insert_waypoints(&s, &pts, &c);
        assert_eq!(safe.points, pts);
        assert_eq!(safe.waypoints, 0);
        // A point inside the block cannot be fixed by waypoints.
        let bad = [DVec3::new(3.0, 5.0, 0.7), DVec3::new(6.0, 5.0, 1.0)];
        let safe = insert_waypoints(&s, &bad, &c);
        assert_eq!(safe.unresolved, vec![0]);
    }

    /// Moves along the step's wall, each point well clear of the surface
    /// (over the floor, or over the block's top), the side switched every
    /// 63 or so: the moves that switch cut the wall's top edge, and
    /// waypoints make them safe (QA round 6 F0: the points wandered within
    /// reach of the edge themselves, and moves down to them were made
    /// "safe" only because a plunge's edge contact was taken at its top).
    /// Every 700th point lies inside the block: its moves cannot be made
    /// safe. Thousands, so that the work is cut into many chunks.
    fn wandering_moves(n: usize) -> Vec<DVec3> {
        (0..=n)
            .map(|i| {
                let t = i as f64;
                let over = (0.05 * t + 1.0).sin() > 0.0;
                let (x, z) = if i % 700 == 350 {
                    (6.2, 1.0)
                } else if over {
                    (6.2, 2.5)
                } else {
                    (3.8, 0.5)
                };
                DVec3::new(
                    x + 0.2 * (0.013 * t).sin(),
                    1.0 + 8.0 * i as f64 / n as f64,
                    z + 0.2 * (0.071 * t).sin().abs(),
                )
            })
            .collect()
    }

    #[test]
    fn chunked_checks_agree_with_one_move_at_a_time() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let pts = wandering_moves(5000);
        let moves: Vec<_> = pts.windows(2).map(|w| (w[0], w[1], None)).collect();
        let sum = check_moves(&s, moves.clone(), &c);
        // The oracle: each move's clearance on its own, taken in order.
        let gaps: Vec<Option<SweepGap>> = moves
            .iter()
            .map(|&(a, b, _)| c.gap(&s, a, b, f64::INFINITY))
            .collect();
        let touching: Vec<usize> = (0..moves.len())
            .filter(|&i| gaps[i].is_some_and(|g| g.gap_mm < c.touch_limit()))
            .collect();
        assert!(touching.len() > MAX_LISTED, "{}", touching.len());
        assert!(touching[0] > 0 && *touching.last().unwrap() > 2500);
        assert_eq!(sum.moves, moves.len());
        assert_eq!(sum.touching_moves, touching.len());
        let listed: Vec<usize> = sum.touching.iter().map(|t| t.index).collect();
        assert_eq!(listed, touching[..MAX_LISTED]);
        let least = (0..moves.len())
            .filter(|&i| gaps[i].is_some())
            .min_by(|&i, &j| gaps[i].unwrap().gap_mm.total_cmp(&gaps[j].unwrap().gap_mm))
            .unwrap();
        let g = gaps[least].unwrap();
        assert_eq!(sum.min_clearance_mm, Some(g.gap_mm));
        let (a, b, _) = moves[least];
        assert_eq!(sum.min_clearance_at, Some(arr(a.lerp(b, g.at))));
        // Waypoints: the same as making each move safe on its own.
        let safe = insert_waypoints(&s, &pts, &c);
        let mut points = vec![pts[0]];
        let mut unresolved = Vec::new();
        for (j, w) in pts.windows(2).enumerate() {
            let one = insert_waypoints(&s, w, &c);
            points.extend_from_slice(&one.points[1..]);
            unresolved.extend(one.unresolved.iter().map(|_| j));
        }
        assert!(safe.waypoints > 0);
        assert!(safe.unresolved.len() >= 14, "{:?}", safe.unresolved);
        assert_eq!(safe.points, points);
        assert_eq!(safe.unresolved, unresolved);
    }

    #[test]
    fn a_rise_asked_only_up_to_a_threshold_is_exact_below_it() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let (mut needed, mut short) = (0, 0);
        for i in 0..400 {
            let t = i as f64;
            let p = DVec3::new(
                3.0 + 3.0 * (0.37 * t).sin().abs(),
                1.0 + 8.0 * (0.11 * t).cos().abs(),
                (0.013 * t * t).sin() * 1.5 + 1.0,
            );
            let rise = c.rise_needed(&s, p);
            assert_eq!(c.rise_until(&s, p, |_| false), rise);
            assert_eq!(c.is_clear(&s, p, p), rise == 0.0);
            if rise == 0.0 {
                continue;
            }
            needed += 1;
            for x in [0.5 * rise, rise, 1.5 * rise] {
                let got = c.rise_until(&s, p, |r| r >= x);
                if rise >= x {
                    assert!(
                        got >= x && got <= rise && got > 0.0,
                        "{p}: {got} for {rise}"
                    );
                    short += usize::from(got < rise);
                } else {
                    assert_eq!(got, rise, "{p}");
                }
            }
        }
        assert!(needed > 50, "{needed}");
        assert!(short > 0, "the query never stopped short");
    }

    #[test]
    fn check_moves_lists_the_touching_ones() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let moves = vec![
            (
                DVec3::new(1.0, 5.0, 1.0),
                DVec3::new(2.0, 5.0, 1.0),
                Some(10),
            ),
            (
                DVec3::new(4.0, 5.0, 0.7),
                DVec3::new(4.6, 5.0, 2.2),
                Some(11),
            ),
            (
                DVec3::new(6.0, 5.0, 3.0),
                DVec3::new(8.0, 5.0, 3.0),
                Some(12),
            ),
        ];
        let sum = check_moves(&s, moves, &c);
        assert_eq!(sum.moves, 3);
        assert_eq!(sum.touching_moves, 1);
        assert_eq!(sum.touching[0].line, Some(11));
        assert!(sum.touching[0].clearance_mm < 0.0);
        assert!(sum.touching[0].rise_mm > 0.1);
        assert!(sum.min_clearance_mm.unwrap() < 0.0);
        assert_eq!(sum.min_clearance_line, Some(11));
        let text = sum.touching[0].to_string();
        assert!(
            text.starts_with("line 11: the move (4.000, 5.000, 0.700)"),
            "{text}"
        );
    }

    /// QA: a retract straight up out of a collision was listed as a second
    /// collision, asking to raise a move that moves away from the part.
    #[test]
    fn a_move_closest_where_the_move_before_ended_is_said_to_be() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let p = DVec3::new;
        let moves = vec![
            // Into the block (its top at z = 2), then straight up out of it.
            (p(3.0, 5.0, 3.0), p(6.0, 5.0, 1.5), Some(5)),
            (p(6.0, 5.0, 1.5), p(6.0, 5.0, 5.0), Some(6)),
            // Up out of the block too, but from elsewhere: its own contact.
            (p(8.0, 5.0, 1.0), p(8.0, 5.0, 5.0), Some(7)),
        ];
        let sum = check_moves(&s, moves, &c);
        assert_eq!(sum.touching_moves, 3);
        assert_eq!(sum.touching_from_previous, 1);
        let flags: Vec<(bool, Option<usize>)> = sum
            .touching
            .iter()
            .map(|t| (t.from_previous, t.previous_line))
            .collect();
        assert_eq!(flags, [(false, None), (true, Some(5)), (false, None)]);
        let text = sum.touching[1].to_string();
        assert_eq!(
            text,
            "line 6: the move (6.000, 5.000, 1.500) -> (6.000, 5.000, 5.000) is closest at its \
             start, where the move before it (line 5) ended too close: the nozzle would have to \
             be 0.600 mm higher there"
        );
        assert!(sum.touching[2]
            .to_string()
            .contains("comes too close at (8.000, 5.000, 1.000)"));
    }

    #[test]
    fn backward_moves_count_falls_back_by_two_or_more() {
        let ta: Vec<DVec3> = (0..20)
            .map(|i| DVec3::new(i as f64 * 0.3, 0.0, 0.0))
            .collect();
        let mut tp = ta.clone();
        assert_eq!(backward_moves(&ta, &tp), 0);
        // One point thrown back three samples.
        tp[10] = ta[7];
        assert_eq!(backward_moves(&ta, &tp), 1);
        // One sample back is noise, not counted.
        let mut tp = ta.clone();
        tp[10] = ta[9];
        assert_eq!(backward_moves(&ta, &tp), 0);
    }
}
