//! Path statistics as the paper reports them per print (spec section 8).

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::spline::LocalGeometry;

/// Curvature (1/mm) at or below which a path counts as straight (a radius
/// of a kilometre or more).
pub const STRAIGHT_CURVATURE: f64 = 1e-6;

#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PathStats {
    pub subpaths: usize,
    pub points: usize,
    /// Length of the tool path T*, summed over subpaths.
    pub length_mm: f64,
    /// max z - min z of T*.
    pub height_change_mm: f64,
    /// Largest |slope angle| of the surface path, degrees.
    pub max_inclination_deg: f64,
    /// Smallest radius of curvature of the 3-D surface path (inf if straight).
    pub min_radius_mm: f64,
    /// Printing time at the print speed (travel not included).
    pub print_time_s: f64,
}

impl PathStats {
    /// The smallest radius of curvature as the summaries print it: in mm,
    /// or "none (straight)" for a path of straight lines (inf, which read
    /// as "min radius inf mm").
    pub fn min_radius_text(&self) -> String {
        if self.min_radius_mm.is_finite() {
            format!("{:.3} mm", self.min_radius_mm)
        } else {
            "none (straight)".into()
        }
    }
}

/// Statistics over subpaths given as (T*, geometry of Ta) pairs.
pub fn path_stats<'a>(
    subpaths: impl IntoIterator<Item = (&'a [DVec3], &'a [LocalGeometry])>,
    speed_mm_s: f64,
) -> PathStats {
    let mut s = PathStats {
        min_radius_mm: f64::INFINITY,
        ..Default::default()
    };
    let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut max_curv: f64 = 0.0;
    for (toolpath, geometry) in subpaths {
        s.subpaths += 1;
        s.points += toolpath.len();
        s.length_mm += toolpath
            .windows(2)
            .map(|w| w[0].distance(w[1]))
            .sum::<f64>();
        for p in toolpath {
            zmin = zmin.min(p.z);
            zmax = zmax.max(p.z);
        }
        for g in geometry {
            s.max_inclination_deg = s.max_inclination_deg.max(g.slope_rad.abs().to_degrees());
            max_curv = max_curv.max(g.curvature_3d);
        }
    }
    if s.points > 0 {
        s.height_change_mm = zmax - zmin;
    }
    // A straight path's spline has curvature at the level of rounding
    // (radii of 1e11 mm): straight, as a radius of over a kilometre is.
    if max_curv > STRAIGHT_CURVATURE {
        s.min_radius_mm = 1.0 / max_curv;
    }
    if speed_mm_s > 0.0 {
        s.print_time_s = s.length_mm / speed_mm_s;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_a_ramp() {
        let pts: Vec<DVec3> = (0..11)
            .map(|i| DVec3::new(i as f64, 0.0, i as f64))
            .collect();
        let g = crate::spline::local_geometry(&pts).unwrap();
        let s = path_stats([(&pts[..], &g[..])], 5.0);
        assert_eq!(s.points, 11);
        assert!((s.length_mm - 10.0 * 2f64.sqrt()).abs() < 1e-9);
        assert!((s.height_change_mm - 10.0).abs() < 1e-12);
        assert!((s.max_inclination_deg - 45.0).abs() < 1e-6);
        // Straight: infinite, not the 1e11 mm of the spline's rounding.
        assert_eq!(s.min_radius_mm, f64::INFINITY);
        // Said as such, not "inf mm" (the G-code header printed that).
        assert_eq!(s.min_radius_text(), "none (straight)");
        assert_eq!(
            PathStats {
                min_radius_mm: 0.1454,
                ..s
            }
            .min_radius_text(),
            "0.145 mm"
        );
        assert!((s.print_time_s - s.length_mm / 5.0).abs() < 1e-12);
    }
}
