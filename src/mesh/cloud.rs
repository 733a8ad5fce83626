//! Raw point clouds meshed as a height field (spec "Inputs", raw point
//! clouds): a 2.5-D Delaunay triangulation over the printer's XY, with a
//! maximum edge length so that the scan's dropouts, its border and the
//! fiducial dots stay holes (fiducial detection then works on a cloud as
//! it does on a mesh).
//!
//! The limit is on each edge's XY length, not its 3-D length: a step's
//! wall seen from above is a few points close in XY and far apart in z,
//! and it must stay a surface (the nozzle has to see it), where a 3-D
//! limit would open it into a hole the nozzle could dip into.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::{MeshError, TriMesh};

/// The default maximum edge length is this many times the median distance
/// from a point to its nearest neighbour (in XY).
pub const EDGE_LIMIT_PER_SPACING: f64 = 3.0;

/// What meshing a point cloud did, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CloudInfo {
    /// Points read from the file.
    pub points: usize,
    /// Points merged into another with the same XY (the highest is kept).
    pub merged: usize,
    /// Triangles made.
    pub triangles: usize,
    /// The median XY distance from a point to its nearest neighbour, mm.
    pub spacing_mm: f64,
    /// The longest edge (XY) a triangle may have, mm.
    pub max_edge_mm: f64,
    /// Whether that limit was set by the user (else it is
    /// [`EDGE_LIMIT_PER_SPACING`] times the spacing).
    pub max_edge_given: bool,
}

impl std::fmt::Display for CloudInfo {
    /// One line for the CLI and the page: "point cloud: N points (M
    /// merged) meshed into T triangles, edges up to E mm (...)".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "point cloud: {} points", self.points)?;
        if self.merged > 0 {
            write!(f, " ({} merged: same XY)", self.merged)?;
        }
        write!(
            f,
            " meshed into {} triangles, edges up to {:.3} mm in XY ",
            self.triangles, self.max_edge_mm
        )?;
        if self.max_edge_given {
            write!(
                f,
                "(as set; median point spacing {:.3} mm)",
                self.spacing_mm
            )
        } else {
            write!(
                f,
                "({EDGE_LIMIT_PER_SPACING} x the median point spacing {:.3} mm)",
                self.spacing_mm
            )
        }
    }
}

/// A point for the triangulation: positioned by its XY, its height
/// carried along.
struct Vertex(DVec3);

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        Point2::new(self.0.x, self.0.y)
    }
}

/// Meshes `points` (mm, printer axes, all finite) as a height field over
/// XY: duplicates in XY merged keeping the highest (a height field has one
/// height per XY, and the nozzle must clear the highest), a Delaunay
/// triangulation of the rest, and the triangles with an XY edge longer
/// than `max_edge_mm` (default [`EDGE_LIMIT_PER_SPACING`] times the median
/// nearest-neighbour spacing) left out. Triangles are counter-clockwise
/// seen from +Z.
pub fn triangulate(
    mut points: Vec<DVec3>,
    max_edge_mm: Option<f64>,
    file: &str,
) -> Result<(TriMesh, CloudInfo), MeshError> {
    let read = points.len();
    if let Some(m) = max_edge_mm {
        if !(m.is_finite() && m > 0.0) {
            return Err(MeshError::invalid(
                file,
                format!("the maximum edge length must be a positive number of mm, not {m}"),
            ));
        }
    }
    if read < 3 {
        return Err(MeshError::invalid(
            file,
            format!("a point cloud needs at least 3 points to be meshed; the file has {read}"),
        ));
    }
    // Merge equal XY, keeping the highest; -0.0 and 0.0 are one place, and
    // values below spade's smallest magnitude are zero.
    for p in &mut points {
        for c in [&mut p.x, &mut p.y] {
            if c.abs() < 1e-30 {
                *c = 0.0;
            }
        }
    }
    points.sort_unstable_by(|a, b| {
        a.x.total_cmp(&b.x)
            .then(a.y.total_cmp(&b.y))
            .then(b.z.total_cmp(&a.z))
    });
    points.dedup_by(|later, kept| later.x == kept.x && later.y == kept.y);
    let merged = read - points.len();
    if points.len() < 3 {
        return Err(MeshError::invalid(
            file,
            format!(
                "the {read} points lie at only {} place(s) in XY; a surface needs at least 3",
                points.len()
            ),
        ));
    }
    // (Collected in place: the same memory as the points.)
    let vertices: Vec<Vertex> = points.into_iter().map(Vertex).collect();
    let t: DelaunayTriangulation<Vertex> =
        DelaunayTriangulation::bulk_load(vertices).map_err(|e| {
            MeshError::invalid(
                file,
                format!("the points cannot be triangulated ({e}: a coordinate is out of range)"),
            )
        })?;
    if t.num_inner_faces() == 0 {
        return Err(MeshError::invalid(
            file,
            "all points lie on one line in XY (seen from above): there is no surface to mesh",
        ));
    }
    let n = t.num_vertices();
    // In the triangulation's vertex order (its handles' indices).
    let pos: Vec<DVec3> = t.vertices().map(|v| v.data().0).collect();
    let len2 = |a: usize, b: usize| (pos[a] - pos[b]).truncate().length_squared();
    // The nearest neighbour of a point is joined to it by a Delaunay edge.
    let mut nearest = vec![f64::INFINITY; n];
    for e in t.undirected_edges() {
        let [a, b] = e.vertices().map(|v| v.fix().index());
        let d = len2(a, b);
        nearest[a] = nearest[a].min(d);
        nearest[b] = nearest[b].min(d);
    }
    let mid = n / 2;
    let (_, median, _) = nearest.select_nth_unstable_by(mid, f64::total_cmp);
    let spacing = median.sqrt();
    drop(nearest);
    let limit = max_edge_mm.unwrap_or(EDGE_LIMIT_PER_SPACING * spacing);
    let limit2 = limit * limit;
    let mut triangles = Vec::with_capacity(t.num_inner_faces());
    for f in t.inner_faces() {
        let [a, b, c] = f.vertices().map(|v| v.fix().index());
        if len2(a, b) <= limit2 && len2(b, c) <= limit2 && len2(c, a) <= limit2 {
            triangles.push([a as u32, b as u32, c as u32]);
        }
    }
    if triangles.is_empty() {
        return Err(MeshError::invalid(
            file,
            format!(
                "no triangle of the point cloud has all its edges within the maximum edge \
                 length {limit:.4} mm (median point spacing {spacing:.4} mm); set a larger \
                 maximum edge length"
            ),
        ));
    }
    let info = CloudInfo {
        points: read,
        merged,
        triangles: triangles.len(),
        spacing_mm: spacing,
        max_edge_mm: limit,
        max_edge_given: max_edge_mm.is_some(),
    };
    Ok((
        TriMesh {
            vertices: pos,
            triangles,
        },
        info,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, step: f64, f: impl Fn(f64, f64) -> f64) -> Vec<DVec3> {
        let mut v = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64 * step, j as f64 * step);
                v.push(DVec3::new(x, y, f(x, y)));
            }
        }
        v
    }

    #[test]
    fn a_grid_becomes_two_triangles_a_cell_facing_up() {
        let (m, info) =
            triangulate(grid(11, 0.5, |x, y| 0.1 * x + 0.2 * y), None, "g.xyz").unwrap();
        assert_eq!(m.triangles.len(), 2 * 10 * 10);
        assert!((info.spacing_mm - 0.5).abs() < 1e-12);
        assert!((info.max_edge_mm - 1.5).abs() < 1e-12);
        for i in 0..m.triangle_count() {
            let [a, b, c] = m.triangle(i);
            assert!((b - a).cross(c - a).z > 0.0, "triangle {i} faces down");
            // Heights kept with their points.
            for p in [a, b, c] {
                assert!((p.z - (0.1 * p.x + 0.2 * p.y)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn a_gap_wider_than_the_limit_stays_a_hole() {
        // A 2 x 2 cell dropout (1 mm) in a 0.25 mm grid: limit 0.75 mm.
        let pts: Vec<DVec3> = grid(21, 0.25, |_, _| 0.0)
            .into_iter()
            .filter(|p| !(p.x > 2.2 && p.x < 3.3 && p.y > 2.2 && p.y < 3.3))
            .collect();
        let (m, _) = triangulate(pts, None, "g.xyz").unwrap();
        for i in 0..m.triangle_count() {
            let c = m.triangle(i).iter().sum::<DVec3>() / 3.0;
            assert!(
                !(c.x > 2.3 && c.x < 3.2 && c.y > 2.3 && c.y < 3.2),
                "the dropout was bridged by triangle {i} at {c}"
            );
        }
        // With a limit larger than the gap, it is bridged.
        let pts: Vec<DVec3> = grid(21, 0.25, |_, _| 0.0)
            .into_iter()
            .filter(|p| !(p.x > 2.2 && p.x < 3.3 && p.y > 2.2 && p.y < 3.3))
            .collect();
        let (m, info) = triangulate(pts, Some(5.0), "g.xyz").unwrap();
        assert!(info.max_edge_given);
        let area: f64 = (0..m.triangle_count())
            .map(|i| {
                let [a, b, c] = m.triangle(i);
                0.5 * (b - a).cross(c - a).z
            })
            .sum();
        assert!((area - 25.0).abs() < 1e-9, "area {area}");
    }

    #[test]
    fn duplicates_keep_the_highest_point() {
        let mut pts = grid(3, 1.0, |_, _| 0.0);
        pts.push(DVec3::new(1.0, 1.0, 2.0));
        pts.push(DVec3::new(1.0, 1.0, -1.0));
        let (m, info) = triangulate(pts, None, "d.xyz").unwrap();
        assert_eq!(info.merged, 2);
        assert_eq!(m.vertices.len(), 9);
        assert!(m.vertices.contains(&DVec3::new(1.0, 1.0, 2.0)));
    }

    #[test]
    fn hostile_clouds_get_errors_that_name_the_file() {
        let one = vec![DVec3::ZERO];
        let line: Vec<DVec3> = (0..100)
            .map(|i| DVec3::new(i as f64, 2.0 * i as f64, 1.0))
            .collect();
        let same = vec![DVec3::new(1.0, 2.0, 3.0); 100_000];
        for (pts, want) in [
            (one, "at least 3 points"),
            (line, "one line"),
            (same, "only 1 place"),
        ] {
            let e = triangulate(pts, None, "bad.xyz").unwrap_err().to_string();
            assert!(e.contains("bad.xyz") && e.contains(want), "{e}");
        }
        let e = triangulate(grid(3, 1.0, |_, _| 0.0), Some(0.5), "g.xyz")
            .unwrap_err()
            .to_string();
        assert!(e.contains("maximum edge length"), "{e}");
        let e = triangulate(grid(3, 1.0, |_, _| 0.0), Some(f64::NAN), "g.xyz")
            .unwrap_err()
            .to_string();
        assert!(e.contains("positive"), "{e}");
    }
}
