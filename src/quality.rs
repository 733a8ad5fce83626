//! Predicted print quality (spec section 7, the paper's Algorithm 5): per
//! point tool-surface contact, filament thickness D_j and error e_j = D_j - d,
//! with flattening and floating flags, and a summary per planner (the paper's
//! Figure 3e-f).

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::gcode::format::fixed;
use crate::params::{Nozzle, Process};
use crate::spline::{LocalGeometry, Spline};
use crate::surface::Surface;

/// The predicted defect at a point, worst first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Defect {
    /// The tip disk C_j meets the surface.
    Contact,
    /// D_j < d - tol.
    Flattening,
    /// D_j > d + tol (or no filament reaches the surface within 2d).
    Floating,
    Good,
}

/// The prediction at one point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointQuality {
    pub defect: Defect,
    /// Filament thickness D_j; `None` at a contact (no estimate) or where the
    /// filament curve does not meet the normal within 2d (floating).
    pub thickness_mm: Option<f64>,
    /// e_j = D_j - d; `None` at a contact. Where no intersection exists the
    /// error is counted as d (its lower bound D_j > 2d), see [`predict`].
    pub error_mm: Option<f64>,
}

/// A planner's summary over all its points (the paper's Figure 3e-f).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct QualitySummary {
    pub points: usize,
    /// Mean |e| over the points with an estimate (no contact).
    pub mean_abs_error_mm: f64,
    /// Mean of the negative errors (0 if none).
    pub mean_negative_error_mm: f64,
    /// Mean of the positive errors (0 if none).
    pub mean_positive_error_mm: f64,
    pub contact_pct: f64,
    pub flattening_pct: f64,
    pub floating_pct: f64,
}

/// One line, as the G-code header and the CLI print it.
impl std::fmt::Display for QualitySummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "mean |e| {} mm, mean e- {} mm, mean e+ {} mm, contact {}%, flattening {}%, \
             floating {}%",
            fixed(self.mean_abs_error_mm, 4),
            fixed(self.mean_negative_error_mm, 4),
            fixed(self.mean_positive_error_mm, 4),
            fixed(self.contact_pct, 2),
            fixed(self.flattening_pct, 2),
            fixed(self.floating_pct, 2)
        )
    }
}

impl QualitySummary {
    /// Defective points (contact, flattening or floating), in percent.
    pub fn defect_pct(&self) -> f64 {
        self.contact_pct + self.flattening_pct + self.floating_pct
    }
}

/// The back of the nozzle tip F_j (spec section 7, decision: the text's
/// "back of the nozzle", not Algorithm 5's + (d/2) V_j).
fn nozzle_back(t: DVec3, g: &LocalGeometry, nozzle: &Nozzle) -> DVec3 {
    let k = if g.descending() {
        0.5 * nozzle.outer_diameter_mm
    } else {
        0.5 * nozzle.inner_diameter_mm
    };
    t - k * g.v
}

/// An F_k this close to the plane of a crossing lies on it (mm).
const ON_PLANE_MM: f64 = 1e-9;

/// How many neighbours either side are searched for the crossing of the
/// filament curve with the normal line; F_j lies at most do/2 + d behind
/// T*_j, a few samples at d/2 spacing.
pub(crate) const SEARCH: usize = 8;

/// Points a thread takes at least at a time.
const CHUNK: usize = 256;

/// Predicts the quality along one subpath planned as `toolpath`.
pub fn predict(
    surface: &Surface,
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    toolpath: &[DVec3],
    nozzle: &Nozzle,
    process: &Process,
) -> Vec<PointQuality> {
    let all = predict_asking(
        surface,
        ta,
        geometry,
        toolpath,
        nozzle,
        process,
        |_| true,
        None,
    );
    all.unwrap_or_default() // (with no bound, always a prediction)
}

/// [`predict`], asking the tip disk's contact only at the points `ask`
/// names: a point the nozzle is known to clear by tol has none (its tip
/// disk is tol away from the surface), so a guarded planner asks only of
/// the points it could not clear. The same prediction, to the last bit;
/// `None` as soon as `below` points have a defect, where given (a run
/// that must predict fewer defects than that stops as soon as it cannot).
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict_asking(
    surface: &Surface,
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    toolpath: &[DVec3],
    nozzle: &Nozzle,
    process: &Process,
    ask: impl Fn(usize) -> bool + Sync,
    below: Option<usize>,
) -> Option<Vec<PointQuality>> {
    let r = 0.5 * nozzle.outer_diameter_mm;
    let contact = crate::parallel::map(toolpath.len(), CHUNK, |j| {
        ask(j) && surface.disk_contact(toolpath[j], r).is_some()
    });
    predict_below(ta, geometry, toolpath, &contact, nozzle, process, below)
}

/// The points where the nozzle runs into the part beyond what section 7's
/// disk test sees (spec 6d: the whole nozzle, tip disk and body; 6f: the
/// moves, not only the points), to be counted as contacts: a point `point(j)`
/// asks whose nozzle lies below the surface within its radius (the body
/// buried under a sheet the tip's plane does not cut: QA round 9, the
/// paper's `pcpp` 1.8 mm under a teapot's lid, "contact 0.00%"), and each
/// straight move j -> j + 1 that `commanded(j)` says the G-code makes as
/// planned whose nozzle goes into the surface, at the end nearer its deepest
/// place. A planner whose moves gouge the part is not shown printing even
/// filament there. Contact means the nozzle meets the surface (clearance
/// below 0), not within tol of it, as the disk test does.
pub fn nozzle_contacts(
    surface: &Surface,
    toolpath: &[DVec3],
    radius: f64,
    point: impl Fn(usize) -> bool + Sync,
    commanded: impl Fn(usize) -> bool + Sync,
) -> Vec<usize> {
    let n = toolpath.len();
    let into = |a: DVec3, b: DVec3| surface.nozzle_gap(a, b, radius, 0.0, 0.0);
    let mut touched = crate::parallel::map(n, 256, |j| {
        let t = toolpath[j];
        point(j) && t.is_finite() && into(t, t).is_some()
    });
    // Each move asked once, its contact given to the nearer end.
    let moves = crate::parallel::map(n.saturating_sub(1), 256, |j| {
        if !commanded(j) {
            return None;
        }
        let (a, b) = (toolpath[j], toolpath[j + 1]);
        if !(a.is_finite() && b.is_finite()) {
            return None;
        }
        into(a, b).map(|g| j + usize::from(g.at >= 0.5))
    });
    for j in moves.into_iter().flatten() {
        touched[j] = true;
    }
    (0..n).filter(|&j| touched[j]).collect()
}

/// [`predict`] where it is known which points the tip disk touches the
/// surface at (`contact`, one per point): a planner that has cleared its
/// points by tol already knows there is no contact anywhere.
pub(crate) fn predict_given_contact(
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    toolpath: &[DVec3],
    contact: &[bool],
    nozzle: &Nozzle,
    process: &Process,
) -> Vec<PointQuality> {
    let all = predict_below(ta, geometry, toolpath, contact, nozzle, process, None);
    all.unwrap_or_default() // (with no bound, always a prediction)
}

/// [`predict_given_contact`], or `None` as soon as `below` points have a
/// defect, where given. Each point's prediction is its own, so stopping
/// changes none: `Some` is the same prediction.
fn predict_below(
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    toolpath: &[DVec3],
    contact: &[bool],
    nozzle: &Nozzle,
    process: &Process,
    below: Option<usize>,
) -> Option<Vec<PointQuality>> {
    let d = nozzle.inner_diameter_mm;
    let tol = process.tolerance_mm;
    // c(t) runs through the F_j of the points without contact only
    // (Algorithm 5 sets F_j <- [ ] at a contact, spec section 7): the
    // simulated filament does not pass where the nozzle hits the surface.
    let kept: Vec<usize> = (0..toolpath.len()).filter(|&j| !contact[j]).collect();
    let back: Vec<DVec3> = kept
        .iter()
        .map(|&j| nozzle_back(toolpath[j], &geometry[j], nozzle))
        .collect();
    // Where consecutive F_j coincide (the planner stopped the tip), fall
    // back to the polyline.
    let curve = (back.len() >= 2)
        .then(|| Spline::interpolate(&back).ok())
        .flatten();
    let params: Vec<f64> = match &curve {
        Some(c) => c.params().to_vec(),
        None => (0..back.len()).map(|i| i as f64).collect(),
    };
    // Each point's crossing on its own, on every core natively; the span
    // hint and the last point evaluated are each chunk's own (neither
    // changes a result), and the chunks come back in order. The defects
    // are counted over all chunks only where there is a bound.
    let defects = std::sync::atomic::AtomicUsize::new(0);
    let bound = below.unwrap_or(usize::MAX);
    let stopped = || defects.load(std::sync::atomic::Ordering::Relaxed) >= bound;
    let chunks = crate::parallel::map_chunks(ta.len(), CHUNK, |range| {
        let hint = std::cell::Cell::new(usize::MAX);
        // The last point evaluated: a root search's last step is usually the
        // root, which is then evaluated again for the crossing (the same u,
        // so the same point).
        let last: std::cell::Cell<Option<(u64, DVec3)>> = std::cell::Cell::new(None);
        let eval = |u: f64| -> DVec3 {
            match &curve {
                Some(c) => match last.get() {
                    Some((bits, at)) if bits == u.to_bits() => at,
                    _ => {
                        let at = c.eval_near(u, &hint);
                        last.set(Some((u.to_bits(), at)));
                        at
                    }
                },
                None => {
                    let i = (u.floor().max(0.0) as usize).min(back.len().saturating_sub(2));
                    let f = u - i as f64;
                    back[i].lerp(back[(i + 1).min(back.len() - 1)], f)
                }
            }
        };

        let mut out = Vec::with_capacity(range.len());
        // The position of each kept point in `back`.
        let mut slot = kept.partition_point(|&k| k < range.start);
        for j in range {
            if below.is_some() && stopped() {
                return None;
            }
            let q = if contact[j] {
                PointQuality {
                    defect: Defect::Contact,
                    thickness_mm: None,
                    error_mm: None,
                }
            } else {
                let pj = slot;
                slot += 1;
                let (a, g) = (ta[j], &geometry[j]);
                let crossing = if back.len() < 2 {
                    None
                } else {
                    crossing_near(&back, &params, &eval, pj, a, g.tangent)
                };
                let thickness = crossing.and_then(|p| {
                    let lambda = (p - a).dot(g.n);
                    // The crossing lies on the normal line only within 2d of Ta_j
                    // (section 7): one further away, up the line or off it to the
                    // side (where the path turns, the curve may cross the plane
                    // normal to t_j far from the line), is no intersection.
                    if lambda > 2.0 * d || p.distance(a) > 2.0 * d {
                        None
                    } else if lambda < 0.0 {
                        Some(0.0) // the filament's top is under the surface: crushed
                    } else {
                        Some(p.distance(a))
                    }
                });
                let (defect, error) = match thickness {
                    None => (Defect::Floating, d),
                    Some(t) if t < d - tol => (Defect::Flattening, t - d),
                    Some(t) if t > d + tol => (Defect::Floating, t - d),
                    Some(t) => (Defect::Good, t - d),
                };
                PointQuality {
                    defect,
                    thickness_mm: thickness,
                    error_mm: Some(error),
                }
            };
            if below.is_some() && q.defect != Defect::Good {
                defects.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
            out.push(q);
        }
        Some(out)
    });
    if stopped() {
        return None;
    }
    let mut out = Vec::with_capacity(ta.len());
    for chunk in chunks {
        out.extend(chunk?);
    }
    Some(out)
}

/// p_j: where the filament curve c (through `back`, parameters `params`,
/// evaluated by `eval`) crosses the plane through `a` = Ta_j normal to the
/// tangent t_j, which holds the normal line {Ta_j + lambda N_j}; the
/// crossing nearest to `pj`, the point's own place among the F_k.
fn crossing_near(
    back: &[DVec3],
    params: &[f64],
    eval: &impl Fn(f64) -> DVec3,
    pj: usize,
    a: DVec3,
    tangent: DVec3,
) -> Option<DVec3> {
    let f = |u: f64| (eval(u) - a).dot(tangent);
    let lo = pj.saturating_sub(SEARCH);
    let hi = (pj + SEARCH).min(back.len() - 1);
    // The crossing span nearest to j (the first found on a tie), then
    // its root: one root search per point.
    // The curve passes through F_k at u_k, so the window is scanned on
    // the F_k themselves; only the crossing span is searched. Where the
    // curve crosses three times within one span (the spline overshoots
    // at a vertical step) any of them is a crossing; regula falsi starts
    // from the chord's crossing and usually ends at the one nearest it.
    // An F_k within a nanometre of the plane lies on it: its distance is
    // rounding (even puts F_j on the normal line, so (F_j - Ta_j) . t_j is
    // d t_z, some 1e-14 mm on a level plate), and where the path turns
    // sharply at k the curve touches the plane there without a change of
    // sign, so that crossing was missed.
    let fk = |k: usize| {
        let f = (back[k] - a).dot(tangent);
        if f.abs() <= ON_PLANE_MM {
            0.0
        } else {
            f
        }
    };
    // The span k (from F_k to F_k+1) lies min(|k - j|, |k + 1 - j|) from
    // point j: the spans m away are k = j - 1 - m and k = j + m, tried in
    // that order outwards, so the first crossing found is the nearest,
    // the lower on a tie (the window's spans in order, keeping only a
    // nearer one, found the same), and most points look at the two spans
    // beside them only.
    let crossing = |k: usize| {
        let (f0, f1) = (fk(k), fk(k + 1));
        (f0 == 0.0 || (f0 < 0.0) != (f1 < 0.0)).then_some((k, f0, f1))
    };
    for m in 0..=SEARCH {
        let below = (pj >= lo + 1 + m).then(|| crossing(pj - 1 - m)).flatten();
        let found = below.or_else(|| (pj + m < hi).then(|| crossing(pj + m)).flatten());
        if let Some((k, f0, f1)) = found {
            return Some(eval(find_root(&f, params[k], params[k + 1], f0, f1)));
        }
    }
    // At the path's end the curve of F_j stops short of the last normals:
    // the filament runs on to the tip, so extend c along its last chord.
    if pj + SEARCH < back.len() {
        return None;
    }
    let m = back.len();
    let last = back[m - 1];
    let dir = last - back[m - 2];
    let den = dir.dot(tangent);
    let s = (a - last).dot(tangent) / den;
    (den.abs() > 1e-12 && s > 0.0 && s.is_finite()).then(|| last + dir * s)
}

/// The root of `f` on [a, b], given f(a) = `fa` and f(b) = `fb` of opposite
/// signs (or one of them zero): the Illinois variant of regula falsi, which
/// converges superlinearly on the smooth filament curve (a few evaluations
/// where bisection took 48), with a bisection step whenever the secant
/// leaves the bracket. Stops at |f| <= 1e-12 mm or a bracket a few ulps
/// wide.
fn find_root(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64, mut fa: f64, mut fb: f64) -> f64 {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    // A bracket a few ulps wide is as narrow as f64 gets.
    let width = 4.0 * f64::EPSILON * a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
    let mut side = 0i8;
    for _ in 0..100 {
        let mut m = (a * fb - b * fa) / (fb - fa);
        if !(m > a.min(b) && m < a.max(b)) {
            m = 0.5 * (a + b);
        }
        let fm = f(m);
        if fm.abs() <= 1e-12 || (b - a).abs() <= width {
            return m;
        }
        if (fm < 0.0) == (fb < 0.0) {
            b = m;
            fb = fm;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = m;
            fa = fm;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

/// Summarises predictions (spec section 7).
pub fn summarize<'a>(points: impl IntoIterator<Item = &'a PointQuality>) -> QualitySummary {
    let (mut n, mut contact, mut flat, mut float) = (0usize, 0usize, 0usize, 0usize);
    let (mut abs_sum, mut est) = (0.0, 0usize);
    let (mut neg_sum, mut neg) = (0.0, 0usize);
    let (mut pos_sum, mut pos) = (0.0, 0usize);
    for q in points {
        n += 1;
        match q.defect {
            Defect::Contact => contact += 1,
            Defect::Flattening => flat += 1,
            Defect::Floating => float += 1,
            Defect::Good => {}
        }
        if let Some(e) = q.error_mm {
            abs_sum += e.abs();
            est += 1;
            if e < 0.0 {
                neg_sum += e;
                neg += 1;
            } else if e > 0.0 {
                pos_sum += e;
                pos += 1;
            }
        }
    }
    let pct = |k: usize| {
        if n == 0 {
            0.0
        } else {
            100.0 * k as f64 / n as f64
        }
    };
    let mean = |s: f64, k: usize| if k == 0 { 0.0 } else { s / k as f64 };
    QualitySummary {
        points: n,
        mean_abs_error_mm: mean(abs_sum, est),
        mean_negative_error_mm: mean(neg_sum, neg),
        mean_positive_error_mm: mean(pos_sum, pos),
        contact_pct: pct(contact),
        flattening_pct: pct(flat),
        floating_pct: pct(float),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_root_converges_on_smooth_and_kinked_functions() {
        let f = |u: f64| u * u * u - 2.0;
        let r = find_root(&f, 0.0, 2.0, -2.0, 6.0);
        assert!((r - 2f64.cbrt()).abs() < 1e-12, "{r}");
        // Reversed bracket and a root at an end.
        let g = |u: f64| 0.5 - u;
        assert!((find_root(&g, 1.0, 0.0, -0.5, 0.5) - 0.5).abs() < 1e-12);
        assert_eq!(find_root(&g, 0.5, 1.0, 0.0, -0.5), 0.5);
        // A kink that stalls plain regula falsi.
        let h = |u: f64| {
            if u < 0.3 {
                -1e-3
            } else {
                (u - 0.3) * 50.0 + 1e-9
            }
        };
        let r = find_root(&h, 0.0, 1.0, -1e-3, h(1.0));
        assert!((r - 0.3).abs() < 1e-9, "{r}");
    }

    /// The crossing nearest to a point, the lower span on a tie, as the
    /// scan of every span of the window in order found it (the search
    /// now looks outwards from the point and stops at the first).
    #[test]
    fn the_nearest_crossing_is_the_one_a_scan_of_the_window_finds() {
        // The scan it replaced: every span of the window in order, a
        // nearer one kept.
        fn scanned(back: &[DVec3], pj: usize, a: DVec3, t: DVec3) -> Option<usize> {
            let fk = |k: usize| {
                let f = (back[k] - a).dot(t);
                if f.abs() <= ON_PLANE_MM {
                    0.0
                } else {
                    f
                }
            };
            let (lo, hi) = (pj.saturating_sub(SEARCH), (pj + SEARCH).min(back.len() - 1));
            let mut nearest: Option<(usize, usize)> = None;
            for k in lo..hi {
                let (f0, f1) = (fk(k), fk(k + 1));
                if f0 == 0.0 || (f0 < 0.0) != (f1 < 0.0) {
                    let dist = k.abs_diff(pj).min((k + 1).abs_diff(pj));
                    if nearest.is_none_or(|(bd, _)| dist < bd) {
                        nearest = Some((dist, k));
                    }
                }
            }
            nearest.map(|(_, k)| k)
        }
        // Points wandering about a plane (x = 0), some on it exactly, so
        // that crossings come on both sides, at ties and not at all.
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut found = [0usize; 2];
        for _ in 0..300 {
            let n = 2 + (next() * 40.0) as usize;
            let back: Vec<DVec3> = (0..n)
                .map(|k| {
                    let x = if next() < 0.1 { 0.0 } else { next() - 0.3 };
                    DVec3::new(x, k as f64, 0.0)
                })
                .collect();
            let params: Vec<f64> = (0..n).map(|k| k as f64).collect();
            // The polyline through them: its span k is a straight segment.
            let eval = |u: f64| {
                let k = (u.floor().max(0.0) as usize).min(n - 2);
                back[k].lerp(back[k + 1], u - k as f64)
            };
            for pj in 0..n {
                let got = crossing_near(&back, &params, &eval, pj, DVec3::ZERO, DVec3::X);
                match scanned(&back, pj, DVec3::ZERO, DVec3::X) {
                    Some(k) => {
                        let p = got.expect("a crossing");
                        assert!(
                            p.y >= k as f64 && p.y <= (k + 1) as f64,
                            "{pj}: {p} not in {k}"
                        );
                        found[0] += 1;
                    }
                    // None in the window: only the path's end extends.
                    None => {
                        assert!(got.is_none() || pj + SEARCH >= n, "{pj}");
                        found[1] += 1;
                    }
                }
            }
        }
        assert!(found[0] > 1000 && found[1] > 10, "{found:?}");
    }

    use crate::planners::{plan_points, PlannerKind};

    use crate::surface::tests::flat;

    fn line() -> Vec<DVec3> {
        (0..20)
            .map(|i| DVec3::new(-3.0 + i as f64 * 0.3, 0.0, 0.0))
            .collect()
    }

    #[test]
    fn constant_offset_on_flat_is_exact() {
        let s = flat();
        let ta = line();
        let g = crate::spline::local_geometry(&ta).unwrap();
        let (n, p) = (Nozzle::DEFAULT, Process::DEFAULT);
        let tp = plan_points(PlannerKind::Constant, &s, &ta, &g, &n, &p).toolpath;
        let q = predict(&s, &ta, &g, &tp, &n, &p);
        // Interior points: D = d exactly (the back of the tip is at height d).
        for qj in &q[3..q.len() - 3] {
            assert_eq!(qj.defect, Defect::Good);
            assert!(qj.error_mm.unwrap().abs() < 1e-9, "{qj:?}");
        }
    }

    #[test]
    fn too_low_flattens_too_high_floats_below_contacts() {
        let s = flat();
        let ta = line();
        let g = crate::spline::local_geometry(&ta).unwrap();
        let (n, p) = (Nozzle::DEFAULT, Process::DEFAULT);
        let at = |h: f64| -> Vec<PointQuality> {
            let tp: Vec<DVec3> = ta.iter().map(|a| *a + h * DVec3::Z).collect();
            predict(&s, &ta, &g, &tp, &n, &p)
        };
        assert_eq!(at(0.3)[10].defect, Defect::Flattening);
        assert_eq!(at(0.9)[10].defect, Defect::Floating);
        assert_eq!(at(2.0)[10].defect, Defect::Floating);
        assert_eq!(at(2.0)[10].thickness_mm, None);
        assert_eq!(at(0.0)[10].defect, Defect::Contact);
        let s = summarize(&at(0.3));
        assert_eq!(s.points, 20);
        assert!(s.mean_negative_error_mm < -0.2 && s.mean_positive_error_mm == 0.0);
        assert!(s.flattening_pct > 50.0);
    }

    /// A run that must predict fewer defects than a bar stops as soon as
    /// it cannot (`below`): `None` exactly when the whole prediction has at
    /// least that many defects, that prediction otherwise (over several
    /// chunks natively); and the tip disk's contact asked only where it is
    /// named gives the same prediction when the others have none.
    #[test]
    fn a_prediction_below_a_bar_stops_exactly_when_it_cannot_be_below() {
        let s = Surface::new(crate::mesh::TriMesh::height_field(
            &[-110.0, 110.0],
            &[-10.0, 10.0],
            |_, y| 0.001 * y, // (a plane the tip disk at z = 0 cuts)
        ))
        .unwrap();
        let ta: Vec<DVec3> = (0..700)
            .map(|i| DVec3::new(-105.0 + i as f64 * 0.3, 0.0, 0.0))
            .collect();
        let g = crate::spline::local_geometry(&ta).unwrap();
        let (n, p) = (Nozzle::DEFAULT, Process::DEFAULT);
        let tp: Vec<DVec3> = ta
            .iter()
            .enumerate()
            .map(|(j, a)| {
                let h = if j % 97 == 0 {
                    0.0
                } else {
                    0.6 + 0.25 * (j as f64 * 0.1).sin()
                };
                *a + h * DVec3::Z
            })
            .collect();
        let full = predict(&s, &ta, &g, &tp, &n, &p);
        let defects = full.iter().filter(|q| q.defect != Defect::Good).count();
        assert!(defects > 20 && defects + 20 < full.len(), "{defects}");
        for below in [
            0,
            1,
            defects / 2,
            defects - 1,
            defects,
            defects + 1,
            usize::MAX,
        ] {
            let got = predict_asking(&s, &ta, &g, &tp, &n, &p, |_| true, Some(below));
            assert_eq!(got.is_none(), defects >= below, "below {below}");
            if let Some(got) = got {
                assert_eq!(got, full, "below {below}");
            }
        }
        let contact: Vec<usize> = (0..ta.len())
            .filter(|&j| full[j].defect == Defect::Contact)
            .collect();
        assert_eq!(contact.len(), 8);
        let asked = predict_asking(&s, &ta, &g, &tp, &n, &p, |j| contact.contains(&j), None);
        assert_eq!(asked, Some(full));
    }

    /// A plate with a sheet (a lid's rim) held 1.5 mm above it from
    /// y = 0.3 on, and a strip 0.1 mm wide 3 mm above it across x = 4 (a
    /// thin wall's top, its sides left out: only the nozzle's body passing
    /// through it meets it).
    fn lid_and_wall() -> Surface {
        let mut m = crate::mesh::TriMesh::height_field(&[-10.0, 10.0], &[-10.0, 10.0], |_, _| 0.0);
        for (x0, x1, y0, y1, z) in [
            (-10.0, 10.0, 0.3, 10.0, 1.5),
            (3.95, 4.05, -10.0, -1.0, 3.0),
        ] {
            let k = m.vertices.len() as u32;
            m.vertices.extend([
                DVec3::new(x0, y0, z),
                DVec3::new(x1, y0, z),
                DVec3::new(x1, y1, z),
                DVec3::new(x0, y1, z),
            ]);
            m.triangles.extend([[k, k + 1, k + 2], [k, k + 2, k + 3]]);
        }
        Surface::new(m).unwrap()
    }

    /// QA round 9: the paper's `pcpp` ran the nozzle 1.8 mm under a
    /// teapot's lid and through features between its points, and section
    /// 7's disk test said "contact 0.00%". The whole nozzle at a point, and
    /// the moves the G-code makes as planned, are asked too.
    #[test]
    fn a_nozzle_buried_under_a_sheet_or_gouging_between_points_is_a_contact() {
        let s = lid_and_wall();
        let r = 0.5 * Nozzle::DEFAULT.outer_diameter_mm;
        // Under the lid's rim (0.3 mm from the axis, 0.9 mm above the
        // tip): the tip's plane cuts nothing within the disk.
        let under = [DVec3::new(-1.0, 0.0, 0.6), DVec3::new(1.0, 0.0, 0.6)];
        assert!(s.disk_contact(under[0], r).is_none());
        assert_eq!(nozzle_contacts(&s, &under, r, |_| true, |_| false), [0, 1]);
        // Asked of no point and no move: nothing.
        assert!(nozzle_contacts(&s, &under, r, |_| false, |_| false).is_empty());
        // Clear points at x 3 and 7, the move between them through the
        // wall at x 4: its deepest place is nearer the first.
        let across = [
            DVec3::new(3.0, -5.0, 0.6),
            DVec3::new(7.0, -5.0, 0.6),
            DVec3::new(9.0, -5.0, 0.6),
        ];
        for t in across {
            assert!(s.disk_contact(t, r).is_none() && s.nozzle_gap(t, t, r, 0.0, 0.0).is_none());
        }
        assert_eq!(nozzle_contacts(&s, &across, r, |_| true, |_| true), [0]);
        // A move the G-code does not make as planned (a guarded planner's,
        // given waypoints) is not asked.
        assert!(nozzle_contacts(&s, &across, r, |_| true, |j| j != 0).is_empty());
        // Reversed, the deepest place is nearer the move's end.
        let back: Vec<DVec3> = across.iter().rev().copied().collect();
        assert_eq!(nozzle_contacts(&s, &back, r, |_| true, |_| true), [2]);
    }
}
