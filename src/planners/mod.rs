//! Tool-path planners (spec section 6): from the surface path Ta and its
//! local geometry to the points T* the nozzle follows.
//!
//! - `constant`: T* = Ta + d Z (paper Algorithm 2).
//! - `slope`: T* = Ta + d N + (do/2) V (Algorithm 3, eq. 2).
//! - `pcpp`: the paper's one-pass correction (Algorithm 4, eq. 6-14).
//! - `pcpp-guarded` (beyond the paper, section 6d): `pcpp`, then re-tested
//!   until the nozzle clears the surface by at least tol.
//! - `even` (ours, section 6e, module `even`): the filament thickness of
//!   section 7 as close to d as the surface allows, with no contact along
//!   any move and a tool path that always progresses.
//!
//! The two guarded planners (`pcpp-guarded`, `even`) then get waypoints
//! wherever a straight move between two of their points would come closer
//! to the surface than tol ([`crate::motion`], section 6f).

mod even;

use std::{fmt, str::FromStr};

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::motion::{Clearance, PLANNING_MARGIN_MM};
use crate::params::{Nozzle, Process};
use crate::quality::PointQuality;
use crate::spline::LocalGeometry;
use crate::surface::Surface;

/// Which planner computes T*.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlannerKind {
    Constant,
    Slope,
    Pcpp,
    PcppGuarded,
    #[default]
    Even,
}

impl PlannerKind {
    /// All five: the paper's three in the order it compares them, then
    /// the two guarded ones.
    pub const ALL: [PlannerKind; 5] = [
        PlannerKind::Constant,
        PlannerKind::Slope,
        PlannerKind::Pcpp,
        PlannerKind::PcppGuarded,
        PlannerKind::Even,
    ];

    /// Whether the planner makes every move safe with waypoints (spec
    /// section 6f); the paper's three are planned as the paper plans them.
    pub fn is_guarded(self) -> bool {
        matches!(self, PlannerKind::PcppGuarded | PlannerKind::Even)
    }

    pub fn name(self) -> &'static str {
        match self {
            PlannerKind::Constant => "constant",
            PlannerKind::Slope => "slope",
            PlannerKind::Pcpp => "pcpp",
            PlannerKind::PcppGuarded => "pcpp-guarded",
            PlannerKind::Even => "even",
        }
    }
}

impl fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PlannerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        PlannerKind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                format!(
                    "unknown planner '{s}' (expected even, pcpp-guarded, pcpp, slope or constant)"
                )
            })
    }
}

/// The guarded planner's push iterations before it falls back to lifting.
pub const GUARD_MAX_PUSHES: usize = 4;

/// T* of one subpath, with what the guarded planner had to do.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlannedPoints {
    pub toolpath: Vec<DVec3>,
    /// Points the guarded planner had to lift above the paper's correction,
    /// with the lift in mm (the nozzle is wider than the feature there).
    pub lifted: Vec<(usize, f64)>,
    /// Points the guarded planner could not clear.
    pub uncleared: Vec<usize>,
    /// The planner's own section 7 prediction for these points, where it
    /// made one to plan them (`even`): what [`crate::quality::predict`]
    /// gives, to the last bit, without asking it again.
    pub quality: Option<Vec<PointQuality>>,
}

/// M_j of eq. 8-9: the forward shift on descents, from the profile curvature.
/// The equations give 0.5 d (1 + d kappa) up to kappa = 1/d, which runs from
/// 0 at kappa = -1/d to d; below -1/d (a crest sharper than radius d) they
/// would turn the forward shift backwards, without bound as the crest
/// sharpens, so it stays 0 there (decision: the paper is silent on it).
fn forward_shift(d: f64, kappa: f64) -> f64 {
    if kappa <= -1.0 / d {
        0.0
    } else if kappa <= 1.0 / d {
        0.5 * d * (1.0 + d * kappa)
    } else {
        d
    }
}

/// One point of the paper's Algorithm 4.
fn pcpp_point(surface: &Surface, ta: DVec3, g: &LocalGeometry, nozzle: &Nozzle, tol: f64) -> DVec3 {
    let d = nozzle.inner_diameter_mm;
    let r = 0.5 * nozzle.outer_diameter_mm;
    let mut t = ta + d * DVec3::Z;
    let descending = g.descending();
    let m = forward_shift(d, g.kappa);
    if let Some(c) = surface.disk_contact(t, r) {
        // Cases 1-2: push away from the centroid of C ∩ S (eq. 6-7, 10).
        let away = t - c.centroid;
        let dist = away.length();
        let q = if dist > 1e-9 { away / dist } else { g.n };
        t += (r - dist + tol) * q;
        if descending {
            t += m * g.v; // eq. 11
        }
    } else if descending {
        // Case 3 (eq. 12-14, spec decision "revised"): the segment
        // [Ta_j, Ta_j - d V_j] starts at the surface point, as the main
        // text's eq. 12-13 write it, so its first point on S is Ta_j itself
        // (q_j = Ta_j) and M'_j = do/2 - |Ta_j - q_j| + M_j = do/2 + M_j.
        t += (r + m) * g.v;
    }
    t
}

/// One point of `pcpp-guarded` (spec section 6d): the `pcpp` point, pushed
/// again by eq. 6-10 with the clearance radius do/2 + tol until the nozzle
/// (tip disk and body) keeps tol from the surface ([`Clearance`]), and lifted
/// clear where pushing does not do it.
fn guarded_point(
    surface: &Surface,
    p: DVec3,
    g: &LocalGeometry,
    nozzle: &Nozzle,
    tol: f64,
) -> PointPlanned {
    let c = Clearance::new(nozzle, tol).with_margin(PLANNING_MARGIN_MM);
    let r_clear = c.radius_mm + c.tol_mm;
    let start = pcpp_point(surface, p, g, nozzle, tol);
    let mut t = start;
    let mut clear = c.is_clear(surface, t, t);
    for _ in 0..GUARD_MAX_PUSHES {
        if clear {
            break;
        }
        // Re-apply eq. 6-10 with the clearance radius.
        let Some(contact) = surface.disk_contact(t, r_clear) else {
            break;
        };
        let away = t - contact.centroid;
        let dist = away.length();
        let q = if dist > 1e-9 { away / dist } else { g.n };
        t += (r_clear - dist + 1e-6) * q;
        clear = c.is_clear(surface, t, t);
    }
    // Pushing sideways must not carry the tip off the path.
    if (t - p).truncate().length() > nozzle.outer_diameter_mm {
        t = start;
        clear = false;
    }
    let lift = if clear {
        0.0
    } else {
        c.rise_needed(surface, t)
    };
    if lift > 0.0 {
        t.z += lift;
    }
    // Checked again where lifted, so rounding can never pass an uncleared
    // point (a point found clear as it stands was just asked that, of the
    // same t).
    let cleared = t.is_finite() && (clear || c.is_clear(surface, t, t));
    PointPlanned { t, lift, cleared }
}

/// One point planned on its own: T*, the lift the guarded planner added,
/// and whether it clears.
struct PointPlanned {
    t: DVec3,
    lift: f64,
    cleared: bool,
}

impl PointPlanned {
    fn at(t: DVec3) -> PointPlanned {
        PointPlanned {
            t,
            lift: 0.0,
            cleared: true,
        }
    }
}

/// Points a thread takes at least at a time, for the planners whose point
/// asks the surface (`pcpp`, `pcpp-guarded`).
const MIN_CHUNK: usize = 256;

/// Plans one subpath's points (one per sample; the guarded planners'
/// waypoints come after, see [`crate::motion::insert_waypoints`]). `ta`
/// and `geometry` have the same length.
pub fn plan_points(
    kind: PlannerKind,
    surface: &Surface,
    ta: &[DVec3],
    geometry: &[LocalGeometry],
    nozzle: &Nozzle,
    process: &Process,
) -> PlannedPoints {
    let d = nozzle.inner_diameter_mm;
    let r = 0.5 * nozzle.outer_diameter_mm;
    let tol = process.tolerance_mm;
    // The paper's planners place each point on its own (Algorithms 2-4,
    // section 6d), so those that ask the surface do it on every core
    // natively; the points come back in order, the same for any number
    // of threads.
    type Place<'a> = &'a (dyn Fn(DVec3, &LocalGeometry) -> PointPlanned + Sync);
    let (place, min_chunk): (Place, usize) = match kind {
        PlannerKind::Constant => (&|p, _| PointPlanned::at(p + d * DVec3::Z), ta.len()),
        PlannerKind::Slope => (&|p, g| PointPlanned::at(p + d * g.n + r * g.v), ta.len()),
        PlannerKind::Pcpp => (
            &|p, g| PointPlanned::at(pcpp_point(surface, p, g, nozzle, tol)),
            MIN_CHUNK,
        ),
        PlannerKind::PcppGuarded => (&|p, g| guarded_point(surface, p, g, nozzle, tol), MIN_CHUNK),
        // Planned as a whole, not point by point.
        PlannerKind::Even => return even::plan(surface, ta, geometry, nozzle, process),
    };
    let n = ta.len().min(geometry.len());
    let points = crate::parallel::map(n, min_chunk, |j| place(ta[j], &geometry[j]));
    let mut out = PlannedPoints {
        toolpath: Vec::with_capacity(points.len()),
        ..Default::default()
    };
    for (j, point) in points.into_iter().enumerate() {
        if point.lift > 0.0 {
            out.lifted.push((j, point.lift));
        }
        if !point.cleared {
            out.uncleared.push(j);
        }
        out.toolpath.push(point.t);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for k in PlannerKind::ALL {
            assert_eq!(k.name().parse::<PlannerKind>().unwrap(), k);
        }
        assert!("fast".parse::<PlannerKind>().is_err());
    }

    #[test]
    fn forward_shift_follows_eq_8_9() {
        let d = 0.603;
        assert!((forward_shift(d, 0.0) - 0.3015).abs() < 1e-12);
        assert_eq!(forward_shift(d, 10.0), d);
        assert!(forward_shift(d, -1.0) < 0.3015);
        // Below kappa = -1/d (a crest sharper than radius d) no shift, not
        // a backward one.
        assert_eq!(forward_shift(d, -1.0 / d), 0.0);
        assert_eq!(forward_shift(d, -10.0), 0.0);
        assert_eq!(forward_shift(d, -1e25), 0.0);
    }

    use crate::surface::tests::flat;

    #[test]
    fn all_planners_agree_on_a_flat_surface() {
        let s = flat();
        let ta: Vec<DVec3> = (0..5)
            .map(|i| DVec3::new(i as f64 * 0.3, 0.0, 0.0))
            .collect();
        let g = crate::spline::local_geometry(&ta).unwrap();
        let n = Nozzle::DEFAULT;
        for k in [
            PlannerKind::Constant,
            PlannerKind::Pcpp,
            PlannerKind::PcppGuarded,
        ] {
            let p = plan_points(k, &s, &ta, &g, &n, &Process::DEFAULT);
            for (t, a) in p.toolpath.iter().zip(&ta) {
                assert!((*t - (*a + 0.603 * DVec3::Z)).length() < 1e-12, "{k}");
            }
            assert!(p.lifted.is_empty() && p.uncleared.is_empty());
        }
        let p = plan_points(PlannerKind::Slope, &s, &ta, &g, &n, &Process::DEFAULT);
        assert!((p.toolpath[2] - (ta[2] + DVec3::new(0.454, 0.0, 0.603))).length() < 1e-12);
    }
}
