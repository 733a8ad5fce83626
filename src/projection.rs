//! Projection (spec section 4): each sample (x, y) goes down along -Z onto
//! the highest intersection with the registered scan, giving the
//! zero-standoff path Ta.
//!
//! Decision (spec section 4): a sample over no surface is never silently
//! dropped. Gaps shorter than the nozzle's outer diameter are bridged by
//! interpolating z from the neighbours; longer gaps split the path. Every
//! bridged or split place becomes a warning with its coordinates.

use glam::{DVec2, DVec3};

use crate::surface::Surface;

/// One continuous piece of projected path, ready for the spline.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectedPiece {
    /// The drawn subpath it comes from (for messages).
    pub source: String,
    /// Ta: points on the surface.
    pub points: Vec<DVec3>,
}

fn fmt_xy(p: DVec2) -> String {
    format!("({:.3}, {:.3})", p.x, p.y)
}

/// Projects one sampled subpath. `bridge_max_mm` is the outer diameter do:
/// a gap between two hit samples shorter than that is bridged. `None` when
/// no sample lies over the surface.
pub fn project_subpath(
    surface: &Surface,
    source: &str,
    samples: &[DVec2],
    bridge_max_mm: f64,
    warnings: &mut Vec<String>,
) -> Option<Vec<ProjectedPiece>> {
    let hits: Vec<Option<f64>> = samples.iter().map(|&p| surface.highest_hit(p)).collect();
    let mut arc = Vec::with_capacity(samples.len());
    let mut s = 0.0;
    for (i, p) in samples.iter().enumerate() {
        if i > 0 {
            s += p.distance(samples[i - 1]);
        }
        arc.push(s);
    }
    let n = samples.len();
    // A subpath that misses the scan entirely (`None`) is the caller's to
    // tell (one warning a path: a dashed circle's 268 dashes off a bunny
    // gave 268, QA round 20 F1).
    let first = hits.iter().position(Option::is_some)?;
    let last = hits.iter().rposition(Option::is_some).unwrap_or(first);
    // (One sample off the scan is a point, not a stretch of 0 mm.)
    if first == 1 {
        warnings.push(format!(
            "path '{source}': its first point {} lies off the scan; not printed",
            fmt_xy(samples[0])
        ));
    } else if first > 0 {
        warnings.push(format!(
            "path '{source}': its start from {} to {} ({:.3} mm) lies off the scan; not printed",
            fmt_xy(samples[0]),
            fmt_xy(samples[first - 1]),
            arc[first - 1] - arc[0]
        ));
    }
    if last + 2 == n {
        warnings.push(format!(
            "path '{source}': its last point {} lies off the scan; not printed",
            fmt_xy(samples[n - 1])
        ));
    } else if last + 1 < n {
        warnings.push(format!(
            "path '{source}': its end from {} to {} ({:.3} mm) lies off the scan; not printed",
            fmt_xy(samples[last + 1]),
            fmt_xy(samples[n - 1]),
            arc[n - 1] - arc[last + 1]
        ));
    }

    let mut pieces = Vec::new();
    let mut current: Vec<DVec3> = Vec::new();
    let mut i = first;
    while i <= last {
        if let Some(z) = hits[i] {
            current.push(samples[i].extend(z));
            i += 1;
            continue;
        }
        // A run of misses [i, k) between hits i-1 and k.
        let k = (i..=last).find(|&k| hits[k].is_some()).unwrap_or(last + 1);
        let (a, b) = (i - 1, k.min(last));
        let gap = arc[b] - arc[a];
        match (hits[a], hits[b]) {
            (Some(za), Some(zb)) if gap < bridge_max_mm => {
                for m in i..k {
                    let w = (arc[m] - arc[a]) / gap;
                    current.push(samples[m].extend(za + (zb - za) * w));
                }
                warnings.push(format!(
                    "path '{source}': bridged a {gap:.3} mm gap in the scan at {} (z interpolated)",
                    fmt_xy(samples[i])
                ));
            }
            _ => {
                warnings.push(format!(
                    "path '{source}': no surface under {} to {} ({gap:.3} mm, longer than the \
                     nozzle's outer diameter {bridge_max_mm:.3} mm); the path is split there",
                    fmt_xy(samples[i]),
                    fmt_xy(samples[k - 1])
                ));
                pieces.push(std::mem::take(&mut current));
            }
        }
        i = k;
    }
    pieces.push(current);
    let mut out = Vec::new();
    for points in pieces {
        match points.len() {
            0 => {}
            1 => warnings.push(format!(
                "path '{source}': a piece of one point at {} between gaps is not printed",
                fmt_xy(points[0].truncate())
            )),
            _ => out.push(ProjectedPiece {
                source: source.to_string(),
                points,
            }),
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;

    fn sine_grid(n: usize, size: f64) -> TriMesh {
        let axis: Vec<f64> = (0..=n).map(|i| i as f64 * size / n as f64).collect();
        TriMesh::height_field(&axis, &axis, |x, _| (x / 2.0).sin())
    }

    #[test]
    fn projected_points_lie_on_the_mesh() {
        let s = Surface::new(sine_grid(40, 20.0)).unwrap();
        let samples: Vec<DVec2> = (0..50).map(|i| DVec2::new(0.37 * i as f64, 7.3)).collect();
        let mut w = Vec::new();
        let pieces = project_subpath(&s, "line", &samples, 0.908, &mut w).unwrap();
        assert_eq!(pieces.len(), 1);
        assert!(w.is_empty(), "{w:?}");
        for p in &pieces[0].points {
            // On the mesh: equals the linear interpolation of the grid cell.
            let z = s.highest_hit(p.truncate()).unwrap();
            assert!((p.z - z).abs() < 1e-12);
        }
    }

    fn grid_with_hole(hole: (f64, f64)) -> TriMesh {
        let mut m = sine_grid(40, 20.0);
        m.triangles.retain(|t| {
            let c = t.iter().map(|&k| m.vertices[k as usize]).sum::<DVec3>() / 3.0;
            !(c.x > hole.0 && c.x < hole.1 && c.y > 5.0 && c.y < 9.0)
        });
        m
    }

    #[test]
    fn short_gaps_are_bridged_and_long_ones_split() {
        let samples: Vec<DVec2> = (0..60).map(|i| DVec2::new(0.3 * i as f64, 7.2)).collect();
        // A 0.5 mm wide hole: bridged.
        let s = Surface::new(grid_with_hole((5.0, 5.5))).unwrap();
        let mut w = Vec::new();
        let pieces = project_subpath(&s, "a", &samples, 0.908, &mut w).unwrap();
        assert_eq!(pieces.len(), 1);
        assert_eq!(pieces[0].points.len(), 60);
        assert!(w.len() == 1 && w[0].contains("bridged"), "{w:?}");
        // A 3 mm wide hole: split into two, reported with coordinates.
        let s = Surface::new(grid_with_hole((5.0, 8.0))).unwrap();
        let mut w = Vec::new();
        let pieces = project_subpath(&s, "a", &samples, 0.908, &mut w).unwrap();
        assert_eq!(pieces.len(), 2);
        assert!(
            w.len() == 1 && w[0].contains("split") && w[0].contains("(5.1"),
            "{w:?}"
        );
    }

    #[test]
    fn off_scan_ends_are_trimmed_and_reported() {
        let s = Surface::new(sine_grid(10, 10.0)).unwrap();
        let samples: Vec<DVec2> = (0..20).map(|i| DVec2::new(-2.0 + i as f64, 5.0)).collect();
        let mut w = Vec::new();
        let pieces = project_subpath(&s, "a", &samples, 0.908, &mut w).unwrap();
        assert_eq!(pieces.len(), 1);
        assert_eq!(pieces[0].points.len(), 11);
        assert_eq!(w.len(), 2, "{w:?}");
        let mut w = Vec::new();
        let far: Vec<DVec2> = samples
            .iter()
            .map(|p| *p + DVec2::new(100.0, 0.0))
            .collect();
        assert!(project_subpath(&s, "a", &far, 0.908, &mut w).is_none());
        // (Told by the caller, once for all such subpaths.)
        assert!(w.is_empty(), "{w:?}");
        // One sample off at each end: a point, not a stretch of 0 mm.
        let mut w = Vec::new();
        let one: Vec<DVec2> = (0..12).map(|i| DVec2::new(-0.5 + i as f64, 5.0)).collect();
        assert_eq!(
            project_subpath(&s, "a", &one, 0.908, &mut w).unwrap().len(),
            1
        );
        assert_eq!(
            w,
            [
                "path 'a': its first point (-0.500, 5.000) lies off the scan; not printed",
                "path 'a': its last point (10.500, 5.000) lies off the scan; not printed"
            ]
        );
    }
}
