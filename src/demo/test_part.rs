//! The paper's test part (spec "The paper's test part"), generated: an
//! 80 x 80 mm block top with three regions of features and three ~1 mm
//! fiducial holes near the perimeter, and straight parallel line paths
//! across each region.
//!
//! - Region 1 (y 12-26 mm): steps with vertical walls, a sharp V-groove, a
//!   sharp peak, a rectangular groove, a staircase and a steep ridge.
//! - Region 2 (y 34-48 mm): smooth cosine bumps and dips whose crest and
//!   trough radii of curvature run from 0.4 d (0.24 mm) to 4 mm, and flats.
//! - Region 3 (y 56-70 mm): trapezoids whose flanks have constant slopes of
//!   15, 30, 45, 60 and 75 degrees.
//!
//! Every profile varies along x only; vertical walls are true vertical
//! faces (the grid repeats the x of each wall). The part is already in the
//! printer frame: the fiducial centres are also the printer points P.

use std::f64::consts::PI;

use glam::DVec3;

use crate::mesh::TriMesh;

pub const SIZE_MM: f64 = 80.0;
pub const BASE_Z_MM: f64 = 5.0;
/// Fiducial hole diameter.
pub const FIDUCIAL_DIAMETER_MM: f64 = 1.0;
/// Centres of the three fiducial holes, printer frame.
pub const FIDUCIALS_MM: [DVec3; 3] = [
    DVec3::new(4.0, 4.0, BASE_Z_MM),
    DVec3::new(76.0, 4.0, BASE_Z_MM),
    DVec3::new(4.0, 76.0, BASE_Z_MM),
];
/// (name, y from, y to) of the three regions.
pub const REGIONS: [(&str, f64, f64); 3] = [
    ("steps and sharp features", 12.0, 26.0),
    ("smooth bumps and dips", 34.0, 48.0),
    ("constant slopes", 56.0, 70.0),
];
/// x of every vertical wall of region 1.
const WALLS_X: [f64; 8] = [16.0, 22.0, 41.0, 44.0, 50.0, 53.0, 56.0, 60.0];
/// y of the region edges (walls along x where a profile meets the base).
const EDGES_Y: [f64; 6] = [12.0, 26.0, 34.0, 48.0, 56.0, 70.0];

fn tri(x: f64, c: f64, half: f64, h: f64) -> f64 {
    (h * (1.0 - (x - c).abs() / half)).max(0.0)
}

/// A cosine bump of amplitude `a` whose crest radius of curvature is `r`:
/// h = a (1 + cos(pi u / w)) / 2 has h'' = -a pi^2 / (2 w^2) at its crest.
fn cos_bump(x: f64, c: f64, r: f64, a: f64) -> f64 {
    let w = PI * (r * a / 2.0).sqrt();
    if (x - c).abs() < w {
        a * (1.0 + libm::cos(PI * (x - c) / w)) / 2.0
    } else {
        0.0
    }
}

/// Height of region 1's profile above the base (right-continuous at walls).
fn region1(x: f64) -> f64 {
    let mut h = 0.0;
    if (16.0..22.0).contains(&x) {
        h += 2.0; // a raised block: a step up and a step down
    }
    h -= tri(x, 28.0, 2.0, 1.5); // sharp V-groove
    h += tri(x, 35.0, 2.0, 2.0); // sharp peak
    if (41.0..44.0).contains(&x) {
        h -= 1.5; // rectangular groove
    }
    if (50.0..60.0).contains(&x) {
        h += 1.0 + f64::from(x >= 53.0) + f64::from(x >= 56.0); // staircase
    }
    h + tri(x, 66.0, 1.0, 1.5) // steep ridge (56 deg flanks)
}

/// Region 2: bumps then dips with radii 0.24 (0.4 d), 0.6, 1.5 and 4 mm.
fn region2(x: f64) -> f64 {
    let bumps = [(11.5, 0.24), (16.0, 0.6), (22.0, 1.5), (31.0, 4.0)];
    let dips = [(42.0, 4.0), (51.0, 1.5), (57.0, 0.6), (62.0, 0.24)];
    bumps
        .iter()
        .map(|&(c, r)| cos_bump(x, c, r, 1.0))
        .sum::<f64>()
        - dips
            .iter()
            .map(|&(c, r)| cos_bump(x, c, r, 1.0))
            .sum::<f64>()
}

/// Region 3: trapezoids 2 mm high with flanks at 15..75 degrees.
fn region3(x: f64) -> f64 {
    let mut start = 12.0;
    for deg in [15.0f64, 30.0, 45.0, 60.0, 75.0] {
        let run = 2.0 / libm::tan(deg.to_radians());
        let (top0, top1, end) = (start + run, start + run + 2.0, start + 2.0 * run + 2.0);
        if x >= start && x < end {
            return if x < top0 {
                (x - start) / run * 2.0
            } else if x < top1 {
                2.0
            } else {
                (end - x) / run * 2.0
            };
        }
        start = end + 1.5;
    }
    0.0
}

/// Height of the part's top at (x, y), right-continuous at every wall.
pub fn height(x: f64, y: f64) -> f64 {
    let feature = if (REGIONS[0].1..REGIONS[0].2).contains(&y) {
        region1(x)
    } else if (REGIONS[1].1..REGIONS[1].2).contains(&y) {
        region2(x)
    } else if (REGIONS[2].1..REGIONS[2].2).contains(&y) {
        region3(x)
    } else {
        0.0
    };
    BASE_Z_MM + feature
}

/// Grid coordinates from 0 to SIZE in steps, with each wall coordinate
/// repeated; the flag marks the second copy (evaluate just past the wall).
fn axis(bands: &[(f64, f64, f64)], walls: &[f64]) -> Vec<(f64, bool)> {
    let mut v: Vec<f64> = Vec::new();
    for &(from, to, step) in bands {
        let n = ((to - from) / step).round() as usize;
        // Snapped to 1e-6 mm so grid lines and walls compare exactly.
        v.extend((0..=n).map(|i| ((from + i as f64 * step) * 1e6).round() / 1e6));
    }
    v.sort_by(f64::total_cmp);
    v.dedup();
    for &w in walls {
        if !v.contains(&w) {
            v.push(w);
        }
        v.push(w);
    }
    v.sort_by(f64::total_cmp);
    let mut out: Vec<(f64, bool)> = Vec::with_capacity(v.len());
    for x in v {
        let again = out.last().is_some_and(|&(p, _)| p == x);
        out.push((x, again));
    }
    out
}

/// The test part's top surface as a mesh, printer frame, mm.
pub fn test_part() -> TriMesh {
    let xs = axis(&[(0.0, SIZE_MM, 0.1)], &WALLS_X);
    let ys = axis(
        &[
            (0.0, 2.0, 1.0),
            (2.0, 6.0, 0.1),
            (6.0, 74.0, 1.0),
            (74.0, 78.0, 0.1),
            (78.0, 80.0, 1.0),
        ],
        &EDGES_Y,
    );
    const NUDGE: f64 = 1e-7;
    let w = xs.len();
    let mut m = TriMesh::default();
    // Vertex ids: a repeated grid line reuses the neighbour's vertex where
    // the heights agree, so collapsed columns vanish and the mesh stays
    // manifold (its only boundaries are the rim and the holes).
    let mut ids = vec![0u32; w * ys.len()];
    for (j, &(y, y_past)) in ys.iter().enumerate() {
        let ye = if y_past { y + NUDGE } else { y - NUDGE };
        for (i, &(x, x_past)) in xs.iter().enumerate() {
            let xe = if x_past { x + NUDGE } else { x - NUDGE };
            let z = height(xe.clamp(0.0, SIZE_MM), ye.clamp(0.0, SIZE_MM));
            let p = DVec3::new(x, y, z);
            let reuse = [
                (x_past && i > 0).then(|| ids[j * w + i - 1]),
                (y_past && j > 0).then(|| ids[(j - 1) * w + i]),
            ]
            .into_iter()
            .flatten()
            .find(|&k| m.vertices[k as usize] == p);
            ids[j * w + i] = reuse.unwrap_or_else(|| {
                m.vertices.push(p);
                (m.vertices.len() - 1) as u32
            });
        }
    }
    let r2 = (FIDUCIAL_DIAMETER_MM / 2.0).powi(2);
    for j in 0..ys.len() - 1 {
        for i in 0..w - 1 {
            let a = ids[j * w + i];
            let b = ids[j * w + i + 1];
            let c = ids[(j + 1) * w + i + 1];
            let d = ids[(j + 1) * w + i];
            for t in [[a, b, c], [a, c, d]] {
                if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                    continue;
                }
                // Zero-area triangles are left out, as the importers leave
                // them out: where a wall along x meets one along y this
                // leaves a zero-area slit in the boundary, which fiducial
                // detection ranks last (roundness 0).
                let [p, q, r] = t.map(|k| m.vertices[k as usize]);
                if (q - p).cross(r - p).length_squared() < 1e-18 {
                    continue;
                }
                let centre = (p + q + r) / 3.0;
                let in_hole = FIDUCIALS_MM
                    .iter()
                    .any(|f| (centre.truncate() - f.truncate()).length_squared() < r2);
                if !in_hole {
                    m.triangles.push(t);
                }
            }
        }
    }
    m
}

/// y of the straight line paths: two per region, 3 mm either side of its middle.
pub fn line_ys() -> Vec<f64> {
    REGIONS
        .iter()
        .flat_map(|&(_, a, b)| {
            let c = 0.5 * (a + b);
            [c - 3.0, c + 3.0]
        })
        .collect()
}

/// Lines run from x = 6 to x = 74 mm.
pub const LINE_X_MM: (f64, f64) = (6.0, 74.0);

/// The demo's drawn paths as SVG: an 80 x 80 mm drawing whose user unit is
/// the millimetre. With SVG's y pointing down, place it with an offset of
/// (0, 80) mm to lay it over the part ([`placement`]).
pub fn test_part_svg() -> String {
    let mut s = String::from(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"80mm\" height=\"80mm\" \
         viewBox=\"0 0 80 80\">\n",
    );
    for (k, y) in line_ys().into_iter().enumerate() {
        let region = k / 2 + 1;
        s.push_str(&format!(
            "  <line id=\"region{region}-line{}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" \
             stroke=\"black\" stroke-width=\"0.6\"/>\n",
            k % 2 + 1,
            LINE_X_MM.0,
            SIZE_MM - y,
            LINE_X_MM.1,
            SIZE_MM - y
        ));
    }
    s.push_str("</svg>\n");
    s
}

/// Which region (index into [`REGIONS`]) a point of the part lies in, by
/// its y.
pub fn region_of(y: f64) -> Option<usize> {
    REGIONS.iter().position(|&(_, a, b)| (a..b).contains(&y))
}

/// A plan's quality summary per region of the part (the paper compares the
/// planners region by region), from the pieces' surface points.
pub fn region_summaries(
    plan: &crate::pipeline::Plan,
) -> Vec<(&'static str, crate::quality::QualitySummary)> {
    REGIONS
        .iter()
        .enumerate()
        .map(|(k, &(name, _, _))| {
            let points = plan.pieces.iter().flat_map(|p| {
                p.surface_path
                    .iter()
                    .zip(&p.quality)
                    .filter(move |(a, _)| region_of(a.y) == Some(k))
                    .map(|(_, q)| q)
            });
            (name, crate::quality::summarize(points))
        })
        .collect()
}

/// Where [`test_part_svg`] goes in printer XY.
pub fn placement() -> crate::svg::Placement {
    crate::svg::Placement {
        offset_mm: glam::DVec2::new(0.0, SIZE_MM),
        ..crate::svg::Placement::IDENTITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn profiles_have_the_promised_features() {
        // Radius of curvature at the smallest bump's crest is 0.4 d.
        let h = 1e-4;
        let k = (region2(11.5 + h) - 2.0 * region2(11.5) + region2(11.5 - h)) / (h * h);
        assert!((1.0 / -k - 0.24).abs() < 1e-3, "{}", 1.0 / -k);
        // Flanks at 15, 30, 45, 60 and 75 degrees.
        let mut slopes: Vec<i64> = (1200..6000)
            .map(|i| {
                let x = i as f64 * 0.01;
                ((region3(x + 0.001) - region3(x)) / 0.001)
                    .atan()
                    .to_degrees()
                    .round() as i64
            })
            .collect();
        slopes.sort();
        slopes.dedup();
        assert_eq!(slopes, vec![-75, -60, -45, -30, -15, 0, 15, 30, 45, 60, 75]);
        assert_eq!(region1(16.0), 2.0);
        assert_eq!(region1(15.999), 0.0);
    }

    #[test]
    fn mesh_is_manifold_with_rim_and_three_holes() {
        let m = test_part();
        assert!(m.triangles.len() > 100_000);
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&c| c <= 2), "non-manifold edge");
        // The boundary is the rim, the three holes and zero-area slits.
        let loops = crate::fiducials::boundary_loops(&m);
        let real: Vec<_> = loops.iter().filter(|l| l.area_mm2() > 1e-9).collect();
        assert_eq!(real.len(), 4, "rim + 3 holes");
        for f in FIDUCIALS_MM {
            assert!(real.iter().any(|l| l.centroid.distance(f) < 0.05), "{f:?}");
        }
        // Vertical walls exist: a triangle with a horizontal normal.
        assert!(m.triangles.iter().any(|t| {
            let [p, q, r] = t.map(|k| m.vertices[k as usize]);
            let n = (q - p).cross(r - p);
            n.z.abs() < 1e-12 && n.x.abs() > 1e-6
        }));
    }
}
