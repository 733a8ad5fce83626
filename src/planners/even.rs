//! `even`, our own planner (spec section 6e): the filament thickness of
//! section 7 as close to d as the surface allows at every point, with no
//! contact anywhere along the motion (section 6f) and a tool path that is
//! smooth and always progresses along the drawn path.
//!
//! Section 7 measures the filament at the back of the nozzle, F_j, on the
//! normal line of the surface point Ta_j. So the target is the slope
//! planner's principle carried to its end: F_j = Ta_j + d N_j exactly, and
//! the tip T*_j = F_j + k_j V_j, where k_j is how far the back of the tip
//! lies behind its centre (do/2 on descents, d/2 otherwise, section 7).
//! Then the filament curve c passes through Ta_j + d N_j and D_j = d.
//!
//! Three things stand between that target and the tool path, each resolved
//! with the least change:
//! 1. k_j switches with the sign of t_z, so a noise-level slope would make
//!    the tip jump by (do - d)/2 back and forth. k_j blends smoothly from
//!    d/2 to do/2 over slopes from +[`BLEND_DEG`] to -[`BLEND_DEG`]; on
//!    such slopes the horizontal difference moves F_j along a nearly level
//!    surface, which changes D_j by at most (do - d)/2 sin(3 deg), 0.008 mm
//!    for the paper's tip.
//! 2. Where the normal turns fast (valleys, creases) or the drawing turns
//!    sharply, N_j swings F_j back along the path. The tip's position along
//!    the path is made to advance by at least [`MIN_ADVANCE`] of the sample
//!    spacing at every step, and where the targets fall back no such tool
//!    path meets them all. Three compromises, each nondecreasing: the
//!    least-squares closest positions (isotonic regression,
//!    pool-adjacent-violators, O(n)), which pools the points on both sides
//!    of the fall; the points before the fall kept and those after it
//!    pushed on; those after it kept and those before it held back. Which
//!    prints best depends on the surface (the pooled points of a sharp
//!    valley all float; pushing on floats the ascent's first points, holding
//!    back flattens the descent's last ones), so every stretch where the
//!    least-squares fit leaves a defect within reach is planned with each,
//!    and keeps the one section 7 predicts the fewest defects for, then the
//!    least error: the planner is measured by the same code as the paper's
//!    planners, and the rule is the same on every part.
//! 3. Where the tip at its target would come within tol of the surface
//!    (steep ascents, narrow valleys, the foot of a step), it stays back
//!    where that costs less than rising, else it is raised to the lowest
//!    height that keeps tol ([`Clearance::rise_needed`]) or, where that
//!    costs less, stepped sideways by at most [`lateral_reach`] (the offset
//!    whose filament, measured from Ta_j, is still within tol of d; beside
//!    a wall it clears with no rise).
//!    Under section 7's model no other position does better on a straight
//!    ascent: with the tip as low as the clearance allows, D_j does not
//!    depend on where along the slope the tip sits.
//!
//! The moves between the points are then made safe with waypoints
//! ([`crate::motion::insert_waypoints`], applied to every guarded planner).
//! The same constants serve every part: nothing here is tuned per part.

use std::ops::Range;

use glam::DVec3;

use super::PlannedPoints;
use crate::motion::{Clearance, PLANNING_MARGIN_MM};
use crate::parallel;
use crate::params::{Nozzle, Process};
use crate::quality::{predict_given_contact, Defect, PointQuality};
use crate::spline::LocalGeometry;
use crate::surface::Surface;

/// Descents gentler than this many degrees blend the back offset k_j
/// between its ascent and descent values (level keeps the ascent's, as
/// section 7 does for t_z = 0).
pub const BLEND_DEG: f64 = 6.0;

/// The least advance of the tip along the path at each step, as a share of
/// the drawn samples' spacing there.
pub const MIN_ADVANCE: f64 = 0.25;

/// How far the back of the tip lies behind its centre (section 7: do/2
/// moving down, d/2 otherwise), blended smoothly over gentle descents.
fn back_offset(nozzle: &Nozzle, slope_rad: f64) -> f64 {
    let half_d = 0.5 * nozzle.inner_diameter_mm;
    let half_do = 0.5 * nozzle.outer_diameter_mm;
    // smoothstep from 0 (level or ascending) to 1 (descending by BLEND_DEG)
    let u = (-slope_rad.to_degrees() / BLEND_DEG).clamp(0.0, 1.0);
    let w = u * u * (3.0 - 2.0 * u);
    half_d + (half_do - half_d) * w
}

/// Section 7's own back offset (its switch on the sign of t_z).
fn model_back_offset(nozzle: &Nozzle, g: &LocalGeometry) -> f64 {
    if g.descending() {
        0.5 * nozzle.outer_diameter_mm
    } else {
        0.5 * nozzle.inner_diameter_mm
    }
}

/// The sideways search (across the path, either way) where the tip would
/// otherwise have to rise: in this many steps out to [`lateral_reach`],
/// then narrowed to the smallest offset that clears in this many halvings.
const LATERAL_STEPS: usize = 4;
const LATERAL_HALVINGS: usize = 4;

/// How far sideways the tip may go: the offset w whose filament, measured
/// from Ta_j as section 7 does, is sqrt(w^2 + d^2) = d + tol thick, the
/// most that still counts as good. Beyond it a rise is no worse.
fn lateral_reach(d: f64, tol: f64) -> f64 {
    ((d + tol) * (d + tol) - d * d).max(0.0).sqrt()
}

/// The step of the search for a place behind the target that clears (the
/// slide goes back at most do).
const SLIDE_STEP_MM: f64 = 0.02;

/// The fewest points a thread takes at once (each costs a few point
/// queries, a few microseconds).
const MIN_CHUNK: usize = 256;

/// How far behind the first surface point the back of the tip starts: the
/// filament starts at the back of the tip, so a start ahead of Ta_0 would
/// leave Ta_0 without filament (section 7 finds no crossing there).
const START_BEHIND_MM: f64 = 1e-4;

/// Around a stretch where the places must be fitted (see [`plan`]), the
/// points whose predicted filament the choice of fit can change: the
/// filament curve's crossing is searched this many samples either side
/// (section 7), and the cubic spline through the F_j settles within a few.
const REACH: usize = crate::quality::SEARCH;

pub(super) fn plan(
    surface: &Surface,
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    nozzle: &Nozzle,
    process: &Process,
) -> PlannedPoints {
    let d = nozzle.inner_diameter_mm;
    let n = ta.len();
    // The target of every point: its shift along V_j and its height.
    let mut shift = Vec::with_capacity(n);
    let mut height = Vec::with_capacity(n);
    for (j, (&a, g)) in ta.iter().zip(geometry).enumerate() {
        let f = a + d * g.n;
        let k = if j == 0 {
            model_back_offset(nozzle, g) - START_BEHIND_MM
        } else {
            back_offset(nozzle, g.slope_rad)
        };
        shift.push(d * g.n.dot(g.v) + k);
        height.push(f.z);
    }
    // Progress: the tip's place along the path, w_j = u_j + shift_j, must
    // advance by MIN_ADVANCE of each step (`advance`, summed in `floor`):
    // the places minus `floor` must not decrease.
    let mut u = Vec::with_capacity(n);
    let mut advance = vec![0.0; n];
    let mut floor = Vec::with_capacity(n);
    let (mut acc, mut least) = (0.0, 0.0);
    for j in 0..n {
        if j > 0 {
            let step = (ta[j] - ta[j - 1]).truncate().length();
            acc += step;
            advance[j] = MIN_ADVANCE * step;
            least += advance[j];
        }
        u.push(acc);
        floor.push(least);
    }
    let lowered: Vec<f64> = (0..n).map(|j| u[j] + shift[j] - floor[j]).collect();
    let placer = Placer {
        surface,
        ta,
        geometry,
        u: &u,
        height: &height,
        advance: &advance,
        nozzle,
        clearance: Clearance::new(nozzle, process.tolerance_mm).with_margin(PLANNING_MARGIN_MM),
    };
    let mut memo = Memo::default();
    // Where the targets fall back, three nondecreasing compromises (module
    // docs, item 2), tried where the first leaves a defect.
    let fits = [
        isotonic(&lowered),
        clamp_forward(&lowered),
        clamp_backward(&lowered),
    ];
    let targets: Vec<Vec<f64>> = fits
        .iter()
        .map(|f| f.iter().zip(&floor).map(|(w, fl)| w + fl).collect())
        .collect();
    let stretches = refitted(&lowered, &fits);
    if stretches.is_empty() {
        // Every fit is the targets themselves.
        let placed = placer.place(&targets[0], &mut memo);
        let quality = placed.predict(0..n, surface, ta, geometry, nozzle, process);
        return placed.into_planned(quality);
    }
    // The least-squares fit first, its filament predicted along the whole
    // piece; the other fits are tried only on the stretches where it leaves
    // a defect within reach.
    let first = placer.place(&targets[0], &mut memo);
    let predicted = first.predict(0..n, surface, ta, geometry, nozzle, process);
    let reach = |r: &Range<usize>| r.start.saturating_sub(REACH)..(r.end + REACH).min(n);
    let open: Vec<Range<usize>> = stretches
        .into_iter()
        .filter(|r| predicted[reach(r)].iter().any(|q| q.defect != Defect::Good))
        .collect();
    if open.is_empty() {
        return first.into_planned(predicted);
    }
    // Each other fit on those stretches, the least-squares one elsewhere.
    let mut tried = vec![first];
    for fit in &targets[1..] {
        let mut t = targets[0].clone();
        for r in &open {
            t[r.clone()].copy_from_slice(&fit[r.clone()]);
        }
        tried.push(placer.place(&t, &mut memo));
    }
    // Each stretch takes the fit with the fewest defects among the points
    // it can change, then the least error (predicted over a window around
    // them, so that the filament curve there is the same for every fit).
    let mut chosen = targets[0].clone();
    let mut switched = false;
    for r in &open {
        let core = reach(r);
        let window = r.start.saturating_sub(2 * REACH)..(r.end + 2 * REACH).min(n);
        let inner = core.start - window.start..core.end - window.start;
        let score = |p: &Placed| {
            p.predict(window.clone(), surface, ta, geometry, nozzle, process)[inner.clone()]
                .iter()
                .fold((0usize, 0.0), |(bad, err), q| {
                    (
                        bad + usize::from(q.defect != Defect::Good),
                        err + q.error_mm.map_or(0.0, f64::abs),
                    )
                })
        };
        let mut best = (0, score(&tried[0]));
        for (k, p) in tried.iter().enumerate().skip(1) {
            let s = score(p);
            if s < best.1 {
                best = (k, s);
            }
        }
        chosen[r.clone()].copy_from_slice(&targets[best.0][r.clone()]);
        switched |= best.0 != 0;
    }
    if !switched {
        // The least-squares fit is kept everywhere: placed and predicted.
        let mut tried = tried;
        return tried.swap_remove(0).into_planned(predicted);
    }
    let placed = placer.place(&chosen, &mut memo);
    let quality = placed.predict(0..n, surface, ta, geometry, nozzle, process);
    placed.into_planned(quality)
}

/// The stretches where some fit moves a place off its target (one choice
/// each).
fn refitted(lowered: &[f64], fits: &[Vec<f64>]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for j in 0..lowered.len() {
        if fits.iter().all(|f| f[j].to_bits() == lowered[j].to_bits()) {
            continue;
        }
        match out.last_mut() {
            Some(r) if j == r.end => r.end = j + 1,
            _ => out.push(j..j + 1),
        }
    }
    out
}

/// The sequence raised where it falls back: each value at least the one
/// before (the points after a fall are pushed on).
fn clamp_forward(y: &[f64]) -> Vec<f64> {
    let mut out = y.to_vec();
    for j in 1..out.len() {
        out[j] = out[j].max(out[j - 1]);
    }
    out
}

/// The sequence lowered where it falls back: each value at most the one
/// after (the points before a fall are held back).
fn clamp_backward(y: &[f64]) -> Vec<f64> {
    let mut out = y.to_vec();
    for j in (0..out.len().saturating_sub(1)).rev() {
        out[j] = out[j].min(out[j + 1]);
    }
    out
}

/// What the placement of one set of targets found: the tool-path points
/// and how far each was raised (NaN where the query could not tell whether
/// the point clears).
struct Placed {
    points: Vec<DVec3>,
    lifts: Vec<f64>,
}

impl Placed {
    /// Section 7's prediction for the points in `range`, as if the piece
    /// were those points alone: [`crate::quality::predict`]'s, to the last
    /// bit. A point placed where the nozzle keeps tol from the surface has
    /// no contact (the tip disk is tol away from it), so the contact test
    /// is asked only of the others.
    fn predict(
        &self,
        range: Range<usize>,
        surface: &Surface,
        ta: &[DVec3],
        geometry: &[LocalGeometry],
        nozzle: &Nozzle,
        process: &Process,
    ) -> Vec<PointQuality> {
        let radius = 0.5 * nozzle.outer_diameter_mm;
        let contact: Vec<bool> = range
            .clone()
            .map(|j| {
                let t = self.points[j];
                (self.lifts[j].is_nan() || !t.is_finite())
                    && surface.disk_contact(t, radius).is_some()
            })
            .collect();
        predict_given_contact(
            &ta[range.clone()],
            &geometry[range.clone()],
            &self.points[range],
            &contact,
            nozzle,
            process,
        )
    }

    /// The planned points, with their predicted `quality`.
    fn into_planned(self, quality: Vec<PointQuality>) -> PlannedPoints {
        let mut out = PlannedPoints {
            toolpath: Vec::with_capacity(self.points.len()),
            quality: Some(quality),
            ..Default::default()
        };
        for (j, (t, lift)) in self.points.into_iter().zip(self.lifts).enumerate() {
            if lift > 0.0 {
                out.lifted.push((j, lift));
            }
            if !t.is_finite() {
                out.uncleared.push(j);
            }
            out.toolpath.push(t);
        }
        out
    }
}

/// The point queries' answers, kept across the fits: each depends only on
/// the point and its target place (the caps) or on the place it gets too
/// (the raised point), so a place two fits share is asked once. The first
/// placement fills the arrays; the others' few different places go to the
/// maps.
#[derive(Default)]
struct Memo {
    caps: Vec<(u64, Cap)>,
    caps_more: std::collections::HashMap<(usize, u64), Cap>,
    raised: Vec<((u64, u64), (DVec3, f64))>,
    raised_more: std::collections::HashMap<(usize, (u64, u64)), (DVec3, f64)>,
}

/// A point's cap (the furthest place forward, at most its target, where
/// the tip clears at the target's height, if staying back is worth it)
/// and the rise its target needs where that query found it whole.
type Cap = (Option<f64>, Option<f64>);

impl Memo {
    /// The answers of `ask` for every point at `key(j)`, asking only those
    /// not known (on every core natively, in order).
    fn fill<K: Copy + Eq + std::hash::Hash + Send + Sync, V: Copy + Send>(
        base: &mut Vec<(K, V)>,
        more: &mut std::collections::HashMap<(usize, K), V>,
        n: usize,
        key: impl Fn(usize) -> K + Sync,
        ask: impl Fn(usize) -> V + Sync,
    ) -> Vec<V> {
        if base.is_empty() {
            *base = parallel::map(n, MIN_CHUNK, |j| (key(j), ask(j)));
            return base.iter().map(|&(_, v)| v).collect();
        }
        let missing: Vec<usize> = (0..n)
            .filter(|&j| base[j].0 != key(j) && !more.contains_key(&(j, key(j))))
            .collect();
        let found = parallel::map(missing.len(), MIN_CHUNK, |i| ask(missing[i]));
        for (&j, v) in missing.iter().zip(found) {
            more.insert((j, key(j)), v);
        }
        (0..n)
            .map(|j| {
                let k = key(j);
                if base[j].0 == k {
                    base[j].1
                } else {
                    more[&(j, k)]
                }
            })
            .collect()
    }
}

/// Places the tool path for given target places: the part of `even` that
/// asks the surface.
struct Placer<'a> {
    surface: &'a Surface,
    ta: &'a [DVec3],
    geometry: &'a [LocalGeometry],
    u: &'a [f64],
    height: &'a [f64],
    advance: &'a [f64],
    nozzle: &'a Nozzle,
    clearance: Clearance,
}

impl Placer<'_> {
    /// The tip at place `w` along the path of point j, at height `z`.
    fn at(&self, j: usize, w: f64, z: f64) -> DVec3 {
        let a = self.ta[j];
        DVec3::new(a.x, a.y, z) + (w - self.u[j]) * self.geometry[j].v
    }

    /// The tool path for the places `target` (nondecreasing after the
    /// advance floor): each point kept low where it clears, staying back
    /// where that costs less than rising, and raised (or stepped sideways)
    /// to keep tol.
    fn place(&self, target: &[f64], memo: &mut Memo) -> Placed {
        let n = target.len();
        let (surface, c, height) = (self.surface, &self.clearance, self.height);
        // Where a target is too close to the surface, the tip may stay
        // back at its height instead of rising (up to do behind, as far
        // forward as clears): before a step up this keeps the nozzle on
        // the floor until the step rather than lifting it early into the
        // air. Staying back by D on a slope of angle a moves the back of
        // the tip D sin(a) further from the surface, rising by e moves it
        // e cos(a): the tip stays back only where that costs less than
        // half the rise, so a plain slope is still handled by rising.
        let steps = (self.nozzle.outer_diameter_mm / SLIDE_STEP_MM).ceil() as usize;
        let furthest = steps as f64 * SLIDE_STEP_MM;
        // With each cap, the rise the target itself needs when the query
        // found it whole (see below).
        let caps = Memo::fill(
            &mut memo.caps,
            &mut memo.caps_more,
            n,
            |j| target[j].to_bits(),
            |j| {
                let a = self.geometry[j].slope_rad;
                let worth =
                    |back: f64, rise: f64| back * libm::sin(a).abs() < 0.5 * rise * libm::cos(a);
                // The rise matters only until it makes the whole slide
                // worth trying (`worth` grows with the rise): the query
                // stops there.
                let rise = c.rise_until(surface, self.at(j, target[j], height[j]), |r| {
                    worth(furthest, r)
                });
                if rise == 0.0 {
                    return (Some(target[j]), None);
                }
                // Where the slide is not worth it, the query did not stop
                // early and `rise` is the rise needed, to the last bit: a
                // point left at its target is raised by it below without
                // asking again.
                let whole = (!worth(furthest, rise)).then_some(rise);
                let cap = (1..=steps)
                    .map(|k| k as f64 * SLIDE_STEP_MM)
                    .take_while(|&back| worth(back, rise))
                    .map(|back| target[j] - back)
                    .find(|&w| {
                        let t = self.at(j, w, height[j]);
                        c.is_clear(surface, t, t)
                    });
                (cap, whole)
            },
        );
        // Backward: every point at most its cap and at least one advance
        // behind the next; a point that cannot stay low within the slide
        // is raised where progress puts it.
        let mut w = vec![0.0; n];
        for j in (0..n).rev() {
            let next = if j + 1 < n {
                w[j + 1] - self.advance[j + 1]
            } else {
                f64::INFINITY
            };
            match caps[j].0 {
                Some(cap) if cap.min(next) >= target[j] - self.nozzle.outer_diameter_mm => {
                    w[j] = cap.min(next);
                }
                _ => w[j] = target[j].min(next),
            }
        }
        // Each point raised on its own: (the tool-path point, how far it
        // was raised).
        let d = self.nozzle.inner_diameter_mm;
        let raised = Memo::fill(
            &mut memo.raised,
            &mut memo.raised_more,
            n,
            |j| (w[j].to_bits(), target[j].to_bits()),
            |j| {
                let (low_cap, target_rise) = caps[j];
                let t = self.at(j, w[j], height[j]);
                // Raise to the lowest height that keeps tol, where staying
                // back did not clear (or progress moved the point off its
                // cap); on a slope across the path a small step sideways
                // may need much less rise (section 7 measures the
                // filament's distance from Ta_j, so a sideways offset w and
                // a rise e give about sqrt(w^2 + (d + e cos a)^2)). A point
                // at its cap was found clear when the cap was chosen.
                if low_cap == Some(w[j]) {
                    return (t, 0.0);
                }
                // The same point as the target's own query (the same bits
                // of w, so of t) when that query found the rise needed
                // whole.
                let lift = match target_rise {
                    Some(rise) if w[j].to_bits() == target[j].to_bits() => rise,
                    _ => c.rise_needed(surface, t),
                };
                // (NaN: the query could not tell; kept as the mark of a
                // point not known to clear.)
                if lift.is_nan() || lift <= 0.0 {
                    return (t, if lift.is_nan() { lift } else { 0.0 });
                }
                let (mut t, rise) = sideways(surface, c, t, lift, &self.geometry[j], d);
                if rise > 0.0 {
                    t.z += rise;
                }
                (t, rise)
            },
        );
        let (points, lifts) = raised.into_iter().unzip();
        Placed { points, lifts }
    }
}

/// The nondecreasing sequence closest to `y` in least squares
/// (pool-adjacent-violators).
fn isotonic(y: &[f64]) -> Vec<f64> {
    // Blocks of (mean, count).
    let mut blocks: Vec<(f64, usize)> = Vec::with_capacity(y.len());
    for &v in y {
        let mut cur = (v, 1usize);
        while let Some(&(m, k)) = blocks.last() {
            if m <= cur.0 {
                break;
            }
            blocks.pop();
            let total = k + cur.1;
            cur = ((m * k as f64 + cur.0 * cur.1 as f64) / total as f64, total);
        }
        blocks.push(cur);
    }
    let mut out = Vec::with_capacity(y.len());
    for (m, k) in blocks {
        out.extend(std::iter::repeat_n(m, k));
    }
    out
}

/// Where the tip `t` that must rise by `lift` (positive) to keep tol goes:
/// itself, or a step sideways (across the path, either way, up to
/// [`lateral_reach`]) where that costs less, with the rise needed there
/// ((point, rise)). The cost of a sideways offset w and a rise e is the
/// change of the filament's thickness measured from Ta_j on a slope of
/// `g.slope_rad` (see `plan`), for the thickness `d`; the first of equal
/// costs is kept. Where a step clears with no rise, the offset is narrowed
/// to the smallest that clears between it and the step before.
fn sideways(
    surface: &Surface,
    c: &Clearance,
    t: DVec3,
    lift: f64,
    g: &LocalGeometry,
    d: f64,
) -> (DVec3, f64) {
    let side = DVec3::new(-g.v.y, g.v.x, 0.0);
    let cos_a = libm::cos(g.slope_rad);
    let cost = |w: f64, e: f64| ((w * w + (d + e * cos_a).powi(2)).sqrt() - d).abs();
    let reach = lateral_reach(d, c.tol_mm);
    let offset = |k: usize| reach * k as f64 / LATERAL_STEPS as f64;
    let mut best = (cost(0.0, lift), t, lift);
    for k in 1..=LATERAL_STEPS {
        let w = offset(k);
        for sgn in [-1.0, 1.0] {
            // Off the path (w > 0) the cost grows with the rise e: e and
            // cos a are not negative, so d + e cos a is at least d, each
            // operation of `cost` keeps the order of its operands, and the
            // root is at least d, so the absolute value changes nothing.
            // So no rise costs less than none: when the cost of none
            // cannot beat the best, the query could not change it, and it
            // is not asked.
            if cost(w, 0.0) >= best.0 {
                continue;
            }
            let q = t + sgn * w * side;
            // The query stops once the rise is too much to beat the best.
            let e = c.rise_until(surface, q, |e| cost(w, e) >= best.0);
            let cq = cost(w, e);
            if cq < best.0 {
                best = (cq, q, e);
                if e == 0.0 {
                    let (mut near, mut far) = (offset(k - 1), w);
                    for _ in 0..LATERAL_HALVINGS {
                        let mid = 0.5 * (near + far);
                        let p = t + sgn * mid * side;
                        if c.is_clear(surface, p, p) {
                            far = mid;
                        } else {
                            near = mid;
                        }
                    }
                    best = (cost(far, 0.0), t + sgn * far * side, 0.0);
                }
            }
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sideways` without leaving out the queries that cannot change its
    /// answer: every offset asked.
    fn sideways_asking_all(
        surface: &Surface,
        c: &Clearance,
        t: DVec3,
        lift: f64,
        g: &LocalGeometry,
        d: f64,
    ) -> (DVec3, f64) {
        let side = DVec3::new(-g.v.y, g.v.x, 0.0);
        let cos_a = libm::cos(g.slope_rad);
        let cost = |w: f64, e: f64| ((w * w + (d + e * cos_a).powi(2)).sqrt() - d).abs();
        let reach = lateral_reach(d, c.tol_mm);
        let offset = |k: usize| reach * k as f64 / LATERAL_STEPS as f64;
        let mut best = (cost(0.0, lift), t, lift);
        for k in 1..=LATERAL_STEPS {
            let w = offset(k);
            for sgn in [-1.0, 1.0] {
                let q = t + sgn * w * side;
                let e = c.rise_needed(surface, q);
                let cq = cost(w, e);
                if cq < best.0 {
                    best = (cq, q, e);
                    if e == 0.0 {
                        let (mut near, mut far) = (offset(k - 1), w);
                        for _ in 0..LATERAL_HALVINGS {
                            let mid = 0.5 * (near + far);
                            let p = t + sgn * mid * side;
                            if c.rise_needed(surface, p) == 0.0 {
                                far = mid;
                            } else {
                                near = mid;
                            }
                        }
                        best = (cost(far, 0.0), t + sgn * far * side, 0.0);
                    }
                }
            }
        }
        (best.1, best.2)
    }

    #[test]
    fn sideways_skips_only_queries_that_cannot_change_its_answer() {
        // Ridges across x with slopes across y: tips set low over them need
        // rises of all sizes, and a step sideways often needs less.
        let axis: Vec<f64> = (0..=120).map(|i| i as f64 * 0.05).collect();
        let mesh = crate::mesh::TriMesh::height_field(&axis, &axis, |x, y| {
            0.4 * (3.0 * x).sin() * (1.7 * y).cos() + 0.15 * y
        });
        let surface = Surface::new(mesh).unwrap();
        let nozzle = Nozzle {
            inner_diameter_mm: 0.603,
            outer_diameter_mm: 0.908,
        };
        let c = Clearance::new(&nozzle, 0.1).with_margin(PLANNING_MARGIN_MM);
        let d = nozzle.inner_diameter_mm;
        let mut rng = crate::demo::workloads::Rng(0x2545_F491_4F6C_DD1D);
        let mut unit = move || rng.next_f64();
        let (mut lifted, mut moved) = (0, 0);
        for _ in 0..600 {
            let (x, y) = (1.0 + 4.0 * unit(), 1.0 + 4.0 * unit());
            let z = surface.highest_hit(glam::DVec2::new(x, y)).unwrap() + 0.6 * unit();
            let t = DVec3::new(x, y, z);
            let ang = std::f64::consts::TAU * unit();
            let slope = 0.8 * (unit() - 0.5);
            let v = DVec3::new(ang.cos(), ang.sin(), 0.0);
            let g = LocalGeometry {
                tangent: (v * slope.cos()).with_z(slope.sin()),
                v,
                n: DVec3::Z,
                kappa: 0.0,
                slope_rad: slope,
                curvature_3d: 0.0,
            };
            let lift = c.rise_needed(&surface, t);
            if lift.is_nan() || lift <= 0.0 {
                continue;
            }
            lifted += 1;
            let got = sideways(&surface, &c, t, lift, &g, d);
            let want = sideways_asking_all(&surface, &c, t, lift, &g, d);
            assert_eq!(
                (got.0.to_array().map(f64::to_bits), got.1.to_bits()),
                (want.0.to_array().map(f64::to_bits), want.1.to_bits()),
                "{t} {g:?}"
            );
            moved += usize::from(got.0 != t);
        }
        // Enough tips needed a rise, and enough of them went sideways.
        assert!(lifted > 200 && moved > 50, "{lifted} lifted, {moved} moved");
    }

    #[test]
    fn clamps_keep_one_side_of_a_fall() {
        let y = [0.0, 1.0, 2.0, 0.5, 1.5, 3.0];
        assert_eq!(clamp_forward(&y), vec![0.0, 1.0, 2.0, 2.0, 2.0, 3.0]);
        assert_eq!(clamp_backward(&y), vec![0.0, 0.5, 0.5, 0.5, 1.5, 3.0]);
        for f in [clamp_forward(&y), clamp_backward(&y), isotonic(&y)] {
            assert!(f.windows(2).all(|w| w[0] <= w[1]), "{f:?}");
        }
        // Where nothing falls, every fit is the sequence itself, bit for
        // bit, and there is nothing to choose.
        let up = [0.0, 0.1, 0.30000000000000004, 0.7];
        let fits = [isotonic(&up), clamp_forward(&up), clamp_backward(&up)];
        assert!(fits.iter().all(|f| f == &up));
        assert!(refitted(&up, &fits).is_empty());
        let fits = [isotonic(&y), clamp_forward(&y), clamp_backward(&y)];
        assert_eq!(refitted(&y, &fits), vec![1..5]);
        // Two falls apart are two stretches, each chosen on its own.
        let two = [0.0, 2.0, 1.0, 3.0, 4.0, 5.0, 7.0, 6.0, 8.0];
        let fits = [isotonic(&two), clamp_forward(&two), clamp_backward(&two)];
        assert_eq!(refitted(&two, &fits), vec![1..3, 6..8]);
    }

    #[test]
    fn lateral_reach_keeps_the_filament_within_tol() {
        let (d, tol) = (0.603, 0.1);
        let w = lateral_reach(d, tol);
        assert!(((w * w + d * d).sqrt() - (d + tol)).abs() < 1e-12);
        assert_eq!(lateral_reach(d, 0.0), 0.0);
    }

    #[test]
    fn isotonic_pools_violators() {
        assert_eq!(isotonic(&[1.0, 2.0, 3.0]), vec![1.0, 2.0, 3.0]);
        assert_eq!(isotonic(&[1.0, 3.0, 2.0, 4.0]), vec![1.0, 2.5, 2.5, 4.0]);
        assert_eq!(isotonic(&[3.0, 2.0, 1.0]), vec![2.0, 2.0, 2.0]);
        assert!(isotonic(&[]).is_empty());
    }

    #[test]
    fn back_offset_blends_across_level() {
        let n = Nozzle::DEFAULT;
        let up = back_offset(&n, 10f64.to_radians());
        let down = back_offset(&n, -10f64.to_radians());
        assert!((up - 0.3015).abs() < 1e-12 && (down - 0.454).abs() < 1e-12);
        assert_eq!(back_offset(&n, 0.0), 0.3015);
        let mid = back_offset(&n, -3f64.to_radians());
        assert!((mid - 0.5 * (0.3015 + 0.454)).abs() < 1e-12);
        // Continuous: no jump anywhere, in particular not at level.
        for k in -1000..1000 {
            let a = back_offset(&n, (k as f64 * 0.01).to_radians());
            let b = back_offset(&n, ((k + 1) as f64 * 0.01).to_radians());
            assert!((a - b).abs() < 1e-3, "{k}");
        }
    }
}
