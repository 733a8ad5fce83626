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
//! 2. Where the normal turns fast (steps, creases), N_j swings F_j back and
//!    forth along the path. The tip's position along the path is made to
//!    advance by at least [`MIN_ADVANCE`] of the sample spacing at every
//!    step: the least-squares closest such positions to the targets
//!    (isotonic regression, pool-adjacent-violators, O(n)).
//! 3. Where the tip at its target would come within tol of the surface
//!    (steep ascents, narrow valleys, the foot of a step), it is raised to
//!    the lowest height that keeps tol ([`Clearance::rise_needed`]): no
//!    sideways push, so it never leaves the path.
//!    Under section 7's model no other position does better on a straight
//!    ascent: with the tip as low as the clearance allows, D_j does not
//!    depend on where along the slope the tip sits.
//!
//! The moves between the points are then made safe with waypoints
//! ([`crate::motion::insert_waypoints`], applied to every guarded planner).
//! The same constants serve every part: nothing here is tuned per part.

use glam::DVec3;

use super::PlannedPoints;
use crate::motion::{Clearance, PLANNING_MARGIN_MM};
use crate::parallel;
use crate::params::{Nozzle, Process};
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

/// How far sideways (across the path, downhill) the tip may step where it
/// would otherwise have to rise, and in how many steps it is searched.
pub const LATERAL_MAX_MM: f64 = 0.2;
const LATERAL_STEPS: usize = 4;

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
    // advance by MIN_ADVANCE of each step (`advance`, summed in `floor`);
    // the closest such places in least squares are the nondecreasing fit
    // to w_j - floor_j, plus floor_j.
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
    let target: Vec<f64> = isotonic(&lowered)
        .into_iter()
        .zip(&floor)
        .map(|(w, f)| w + f)
        .collect();
    let c = Clearance::new(nozzle, process.tolerance_mm).with_margin(PLANNING_MARGIN_MM);
    let at =
        |j: usize, w: f64, z: f64| DVec3::new(ta[j].x, ta[j].y, z) + (w - u[j]) * geometry[j].v;
    // Where a target is too close to the surface, the tip may stay back at
    // its height instead of rising (up to do behind, as far forward as
    // clears): before a step up this keeps the nozzle on the floor until
    // the step rather than lifting it early into the air. Staying back by
    // D on a slope of angle a moves the back of the tip D sin(a) further
    // from the surface, rising by e moves it e cos(a): the tip stays back
    // only where that costs less than half the rise, so a plain slope is
    // still handled by rising.
    // (Each point on its own: on every core natively.)
    let steps = (nozzle.outer_diameter_mm / SLIDE_STEP_MM).ceil() as usize;
    let furthest = steps as f64 * SLIDE_STEP_MM;
    // With each cap, the rise the target itself needs when the query found
    // it whole (see below).
    let (low_cap, target_rise): (Vec<Option<f64>>, Vec<Option<f64>>) =
        parallel::map(n, MIN_CHUNK, |j| {
            let a = geometry[j].slope_rad;
            let worth =
                |back: f64, rise: f64| back * libm::sin(a).abs() < 0.5 * rise * libm::cos(a);
            // The rise matters only until it makes the whole slide worth
            // trying (`worth` grows with the rise): the query stops there.
            let rise = c.rise_until(surface, at(j, target[j], height[j]), |r| worth(furthest, r));
            if rise == 0.0 {
                return (Some(target[j]), None);
            }
            // Where the slide is not worth it, the query did not stop early
            // and `rise` is the rise needed, to the last bit: a point left
            // at its target is raised by it below without asking again.
            let whole = (!worth(furthest, rise)).then_some(rise);
            let cap = (1..=steps)
                .map(|k| k as f64 * SLIDE_STEP_MM)
                .take_while(|&back| worth(back, rise))
                .map(|back| target[j] - back)
                .find(|&w| c.is_clear(surface, at(j, w, height[j]), at(j, w, height[j])));
            (cap, whole)
        })
        .into_iter()
        .unzip();
    // Backward: every point at most its cap and at least one advance
    // behind the next; a point that cannot stay low within the slide is
    // raised where progress puts it.
    let mut w = vec![0.0; n];
    for j in (0..n).rev() {
        let next = if j + 1 < n {
            w[j + 1] - advance[j + 1]
        } else {
            f64::INFINITY
        };
        match low_cap[j] {
            Some(cap) if cap.min(next) >= target[j] - nozzle.outer_diameter_mm => {
                w[j] = cap.min(next);
            }
            _ => w[j] = target[j].min(next),
        }
    }
    // Each point raised on its own (on every core natively), then taken in
    // order: (the tool-path point, how far it was raised).
    let placed: Vec<(DVec3, f64)> = parallel::map(n, MIN_CHUNK, |j| {
        let t = at(j, w[j], height[j]);
        // Raise to the lowest height that keeps tol, where staying back
        // did not clear (or progress moved the point off its cap); on a
        // slope across the path a small step sideways, downhill, may need
        // much less rise (section 7 measures the filament's distance from
        // Ta_j, so a sideways offset w and a rise e give about
        // sqrt(w^2 + (d + e cos a)^2)). A point at its cap was found
        // clear when the cap was chosen.
        if low_cap[j] == Some(w[j]) {
            return (t, 0.0);
        }
        // The same point as the target's own query (the same bits of w, so
        // of t) when that query found the rise needed whole.
        let lift = match target_rise[j] {
            Some(rise) if w[j].to_bits() == target[j].to_bits() => rise,
            _ => c.rise_needed(surface, t),
        };
        if lift.is_nan() || lift <= 0.0 {
            return (t, 0.0);
        }
        let (mut t, rise) = sideways(surface, &c, t, lift, &geometry[j], d);
        if rise > 0.0 {
            t.z += rise;
        }
        (t, rise)
    });
    let mut out = PlannedPoints {
        toolpath: Vec::with_capacity(n),
        ..Default::default()
    };
    for (j, (t, lift)) in placed.into_iter().enumerate() {
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
/// itself, or a small step sideways (across the path, either way, up to
/// [`LATERAL_MAX_MM`]) where that costs less, with the rise needed there
/// ((point, rise)). The cost of a sideways offset w and a rise e is the
/// change of the filament's thickness measured from Ta_j on a slope of
/// `g.slope_rad` (see `plan`), for the thickness `d`; the first of equal
/// costs is kept.
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
    let mut best = (cost(0.0, lift), t, lift);
    for k in 1..=LATERAL_STEPS {
        let w = LATERAL_MAX_MM * k as f64 / LATERAL_STEPS as f64;
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
            }
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sideways` as it was before it left out the queries that could not
    /// change its answer: every offset asked.
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
        let mut best = (cost(0.0, lift), t, lift);
        for k in 1..=LATERAL_STEPS {
            let w = LATERAL_MAX_MM * k as f64 / LATERAL_STEPS as f64;
            for sgn in [-1.0, 1.0] {
                let q = t + sgn * w * side;
                let e = c.rise_until(surface, q, |e| cost(w, e) >= best.0);
                let cq = cost(w, e);
                if cq < best.0 {
                    best = (cq, q, e);
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
