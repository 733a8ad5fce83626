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
//!
//! A scan of a whole object (a turntable or hand-held scanner's cloud)
//! also has points under its top: its underside, overhangs, a body under
//! an ear. Triangulated together with the top they would pull the height
//! field down between the top's points, to a surface below the part the
//! nozzle would then be checked against. So before meshing, the points
//! the nozzle cannot see from above are left out ([`hidden_points`]): a
//! point is hidden when much higher points lie around it on every side
//! (in each quadrant of a small disk around it, higher than an
//! [`HIDDEN_SLOPE_DEG`] slope from it, and by more than the noise). A
//! step's foot, a trench or a dimple has higher points on one or two
//! sides, or rising gently, and keeps its points; only a slot narrower
//! than the disk with walls steeper than that slope is filled, which the
//! nozzle could not enter anyway.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use spade::handles::FixedVertexHandle;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::{MeshError, TriMesh};

/// The default maximum edge length is this many times the median distance
/// from a point to its nearest neighbour (in XY).
pub const EDGE_LIMIT_PER_SPACING: f64 = 3.0;

/// Points spread unevenly: the default edge limit is this many times the
/// longest edge of 99 % of the triangles between them (see
/// [`triangulate`]).
pub const UNEVEN_LIMIT_PER_P99: f64 = 1.5;

/// A point is hidden under higher points that rise from it more steeply
/// than this, on every side ([`hidden_points`]).
pub const HIDDEN_SLOPE_DEG: f64 = 80.0;

/// The radius of the disk searched for the points that hide a point, in
/// 3-D point spacings (the median distance from a point to its nearest
/// neighbour in 3-D, which the layers of a whole object's scan do not
/// shrink as they shrink the XY spacing).
const HIDDEN_DISK_PER_SPACING: f64 = 3.0;

/// How much higher than the slope a hiding point must be, in 3-D point
/// spacings: the scanner's noise does not hide a point.
const HIDDEN_NOISE_PER_SPACING: f64 = 2.0;

/// What meshing a point cloud did, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CloudInfo {
    /// Points read from the file.
    pub points: usize,
    /// Points merged into another with the same XY (the highest is kept).
    pub merged: usize,
    /// Points left out because they lie under the surface seen from
    /// above (the underside and overhangs of a whole object's scan).
    #[serde(default)]
    pub hidden: usize,
    /// The lowest of the points left out under others (hidden, or merged
    /// with a higher one of the same XY), mm (printer axes, as imported):
    /// the part rests on its lowest point when it is placed on the bed,
    /// though the surface meshed from above may not reach down to it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lowest_left_out_mm: Option<f64>,
    /// Triangles made.
    pub triangles: usize,
    /// The median XY distance from a point to its nearest neighbour, mm.
    pub spacing_mm: f64,
    /// The longest edge (XY) a triangle may have, mm.
    pub max_edge_mm: f64,
    /// Whether that limit was set by the user (else it is
    /// [`EDGE_LIMIT_PER_SPACING`] times the spacing).
    pub max_edge_given: bool,
    /// Whether the default limit was raised for points spread unevenly
    /// (to keep 99 % of the triangles between them) from
    /// [`EDGE_LIMIT_PER_SPACING`] times the spacing.
    #[serde(default)]
    pub uneven: bool,
    /// Points that stand more than [`SPIKE_PER_SPACING`] spacings above
    /// every point they share a triangle with (a depth camera's flying
    /// pixels, a scanner's stray returns): how many, and the highest
    /// above its neighbours, (where, how far above them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spikes: Option<Spikes>,
}

/// See [`CloudInfo::spikes`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spikes {
    pub count: usize,
    /// The point (mm, printer axes) that stands highest above its
    /// neighbours, and by how much.
    pub worst_mm: [f64; 3],
    pub above_mm: f64,
}

/// A point more than this many median spacings above every neighbour in
/// the meshed cloud is a spike: no real surface rises that steeply on all
/// sides of one sample (a slope of 84 degrees all round).
pub const SPIKE_PER_SPACING: f64 = 10.0;

/// And at least this high (mm): scanner noise on points spaced closer than
/// its own amplitude (two passes a few micrometres apart in XY, a review
/// found) is not a spike, and a flying pixel that matters to the nozzle
/// stands millimetres off.
pub const SPIKE_FLOOR_MM: f64 = 1.0;

/// How far above every neighbour a spike stands, for the median spacing.
pub fn spike_limit(spacing: f64) -> f64 {
    f64::max(SPIKE_PER_SPACING * spacing, SPIKE_FLOOR_MM)
}

/// The spikes of a meshed cloud ([`CloudInfo::spikes`]).
fn spikes(vertices: &[DVec3], triangles: &[[u32; 3]], spacing: f64) -> Option<Spikes> {
    // The highest neighbour of each vertex, and whether it has any.
    let mut top = vec![f64::NEG_INFINITY; vertices.len()];
    for t in triangles {
        for k in 0..3 {
            let (v, a, b) = (
                t[k] as usize,
                t[(k + 1) % 3] as usize,
                t[(k + 2) % 3] as usize,
            );
            top[v] = top[v].max(vertices[a].z).max(vertices[b].z);
        }
    }
    let limit = spike_limit(spacing);
    let mut out: Option<Spikes> = None;
    for (v, &t) in vertices.iter().zip(&top) {
        let above = v.z - t;
        if t.is_finite() && above > limit {
            let s = out.get_or_insert(Spikes {
                count: 0,
                worst_mm: v.to_array(),
                above_mm: above,
            });
            s.count += 1;
            if above > s.above_mm {
                s.worst_mm = v.to_array();
                s.above_mm = above;
            }
        }
    }
    out
}

impl std::fmt::Display for CloudInfo {
    /// One line for the CLI and the page: "point cloud: N points (M
    /// merged) meshed into T triangles, edges up to E mm (...)".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "point cloud: {} points", self.points)?;
        if self.merged > 0 {
            write!(f, " ({} merged: same XY)", self.merged)?;
        }
        if self.hidden > 0 {
            write!(
                f,
                " ({} under the surface seen from above left out: the nozzle prints from \
                 above)",
                self.hidden
            )?;
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
        } else if self.uneven {
            write!(
                f,
                "({UNEVEN_LIMIT_PER_P99} x the longest edge of 99% of the triangles between \
                 the points, which are spread unevenly: {EDGE_LIMIT_PER_SPACING} x their median \
                 spacing {:.3} mm left out more than a tenth)",
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
/// height per XY, and the nozzle must clear the highest), the points under
/// the surface seen from above left out (`hidden_points`), a Delaunay
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
    let mut lowest_left_out = f64::INFINITY;
    points.dedup_by(|later, kept| {
        let same = later.x == kept.x && later.y == kept.y;
        if same {
            lowest_left_out = lowest_left_out.min(later.z);
        }
        same
    });
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
    let mut t = delaunay(vertices, file)?;
    // In the triangulation's vertex order (its handles' indices).
    let mut pos: Vec<DVec3> = t.vertices().map(|v| v.data().0).collect();
    // The points under the surface seen from above, found on the 3-D
    // spacing (the nearest neighbour of a point is joined to it by a
    // Delaunay edge in XY, not always in 3-D: the median over the edges
    // is a fair estimate, and it only sets the search's scale).
    let (mut spacing, spacing_3d) = spacings(&t, &pos);
    let hidden = hidden_points(&t, &pos, spacing_3d);
    let hidden_count = hidden.iter().filter(|&&h| h).count();
    let lowest_left_out = pos
        .iter()
        .zip(&hidden)
        .filter(|(_, &h)| h)
        .fold(lowest_left_out, |m, (p, _)| m.min(p.z));
    if hidden_count > 0 {
        let seen: Vec<Vertex> = pos
            .iter()
            .zip(&hidden)
            .filter(|(_, &h)| !h)
            .map(|(&p, _)| Vertex(p))
            .collect();
        drop((t, pos, hidden));
        t = delaunay(seen, file)?;
        pos = t.vertices().map(|v| v.data().0).collect();
        spacing = spacings(&t, &pos).0.max(spacing_3d);
    }
    let len2 = |a: usize, b: usize| (pos[a] - pos[b]).truncate().length_squared();
    // The default edge limit is from the spacing of the points meshed, in
    // XY; where points under the surface were left out, from the 3-D
    // spacing of all points if that is larger: seen from above, the top of
    // a whole object's scan has its points spread unevenly (close on its
    // steep sides, where the points under them were), and a limit from the
    // closest would open holes the nozzle would be let into.
    // A face's corners, and its longest XY edge squared.
    let face = |f: spade::handles::FixedFaceHandle<spade::handles::InnerTag>| {
        let [a, b, c] = t.face(f).vertices().map(|v| v.fix().index());
        ([a, b, c], len2(a, b).max(len2(b, c)).max(len2(c, a)))
    };
    let kept = |limit: f64| {
        let limit2 = limit * limit;
        let mut triangles = Vec::with_capacity(t.num_inner_faces());
        for f in t.fixed_inner_faces() {
            let ([a, b, c], longest2) = face(f);
            if longest2 <= limit2 {
                triangles.push([a as u32, b as u32, c as u32]);
            }
        }
        triangles
    };
    let mut limit = max_edge_mm.unwrap_or(EDGE_LIMIT_PER_SPACING * spacing);
    let mut triangles = kept(limit);
    // Points spread unevenly (a random sampling, a photogrammetric or
    // lidar cloud) are often farther apart than a few nearest-neighbour
    // spacings: where the default left out more than a tenth of the
    // triangulation, it is raised to 1.5 times the longest edge of 99 %
    // of it (each triangle's longest edge, the 99th percentile), which
    // keeps nearly all. The scan's holes stay: the triangles across them
    // are the last percent, and longer still. A regular grid's limit is
    // never raised (its triangles' longest edges are its diagonals, under
    // 3 spacings).
    let mut uneven = false;
    if max_edge_mm.is_none() && (t.num_inner_faces() - triangles.len()) * 10 > t.num_inner_faces() {
        let mut longest: Vec<f64> = t.fixed_inner_faces().map(|f| face(f).1).collect();
        let k = (longest.len() * 99 / 100).min(longest.len() - 1);
        let p99 = longest.select_nth_unstable_by(k, f64::total_cmp).1.sqrt();
        if UNEVEN_LIMIT_PER_P99 * p99 > limit {
            limit = UNEVEN_LIMIT_PER_P99 * p99;
            uneven = true;
            triangles = kept(limit);
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
        hidden: hidden_count,
        lowest_left_out_mm: lowest_left_out.is_finite().then_some(lowest_left_out),
        triangles: triangles.len(),
        spacing_mm: spacing,
        max_edge_mm: limit,
        max_edge_given: max_edge_mm.is_some(),
        uneven,
        spikes: spikes(&pos, &triangles, spacing),
    };
    Ok((
        TriMesh {
            vertices: pos,
            triangles,
        },
        info,
    ))
}

/// The Delaunay triangulation of `vertices` in XY, refused when it has no
/// triangle (every point on one line).
fn delaunay(vertices: Vec<Vertex>, file: &str) -> Result<DelaunayTriangulation<Vertex>, MeshError> {
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
    Ok(t)
}

/// The medians over the vertices of `t` (at `pos`) of their shortest
/// edge, in XY and in 3-D, in one pass over the edges.
fn spacings(t: &DelaunayTriangulation<Vertex>, pos: &[DVec3]) -> (f64, f64) {
    let mut xy = vec![f64::INFINITY; t.num_vertices()];
    // (Single precision for the 3-D one: it only sets a scale.)
    let mut d3 = vec![f32::INFINITY; t.num_vertices()];
    for e in t.undirected_edges() {
        let [a, b] = e.vertices().map(|v| v.fix().index());
        let d = pos[a] - pos[b];
        let (h, l) = (d.truncate().length_squared(), d.length_squared() as f32);
        xy[a] = xy[a].min(h);
        xy[b] = xy[b].min(h);
        d3[a] = d3[a].min(l);
        d3[b] = d3[b].min(l);
    }
    let mid = xy.len() / 2;
    let xy = xy.select_nth_unstable_by(mid, f64::total_cmp).1.sqrt();
    let d3 = f64::from(*d3.select_nth_unstable_by(mid, f32::total_cmp).1).sqrt();
    (xy, d3)
}

/// Which of the vertices of `t` (at `pos`) lie under the surface seen from
/// above, `spacing` being the cloud's 3-D point spacing: those that have,
/// in each of the four quadrants around them within
/// [`HIDDEN_DISK_PER_SPACING`] spacings in XY, a point higher than the
/// [`HIDDEN_SLOPE_DEG`] slope from them by more than
/// [`HIDDEN_NOISE_PER_SPACING`] spacings. Points on one side of a line
/// through a point (a wall beside it) never fill all four quadrants, so a
/// step's foot keeps its points. Tried are the points with such a higher
/// point among their Delaunay neighbours, and the neighbours of every
/// point found hidden (an underside is reached from its edge inwards).
///
/// (Tried and left: hiding a point under a single much higher point
/// within one spacing, to drop the columns of points on a near-vertical
/// sheet such as an ear. On a scanned bunny it thinned those features
/// until the edge limit opened holes in them, and the plan on the cloud
/// came 5 to 8 mm into the real part instead of 0.4 mm.)
fn hidden_points(t: &DelaunayTriangulation<Vertex>, pos: &[DVec3], spacing: f64) -> Vec<bool> {
    let n = pos.len();
    let mut hidden = vec![false; n];
    if !(spacing.is_finite() && spacing > 0.0) || n < 3 {
        return hidden;
    }
    let slope = HIDDEN_SLOPE_DEG.to_radians().tan();
    let radius = HIDDEN_DISK_PER_SPACING * spacing;
    let noise = HIDDEN_NOISE_PER_SPACING * spacing;
    let above = |p: DVec3, q: DVec3| q.z - p.z > slope * (q - p).truncate().length() + noise;
    // Only points next to such a higher point (a Delaunay neighbour), and
    // then the neighbours of those found hidden, are tried: on a height
    // field nothing is, and nothing more is built.
    let mut queued = vec![false; n];
    let mut queue: Vec<u32> = Vec::new();
    for e in t.undirected_edges() {
        let [a, b] = e.vertices().map(|v| v.fix().index());
        for (i, j) in [(a, b), (b, a)] {
            if !queued[i] && above(pos[i], pos[j]) {
                queued[i] = true;
                queue.push(i as u32);
            }
        }
    }
    if queue.is_empty() {
        return hidden;
    }
    let (lo, hi) = pos.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.truncate()), hi.max(p.truncate())),
    );
    // Cells of half the disk's radius: the 5 x 5 cells around a point's
    // cell hold its disk, and a cell whose top is too low for the slope
    // at its distance is passed over whole. Wider where far outliers would
    // ask for more than about two cells a point.
    let mut cell = 0.5 * radius;
    let dims = |cell: f64| ((hi - lo) / cell).floor() + DVec2::ONE;
    while dims(cell).x * dims(cell).y > 2.0 * n as f64 + 16.0 {
        cell *= 2.0;
    }
    let (nx, ny) = (dims(cell).x as usize, dims(cell).y as usize);
    let cell_of = |p: DVec3| {
        let c = ((p.truncate() - lo) / cell).floor();
        ((c.x as usize).min(nx - 1), (c.y as usize).min(ny - 1))
    };
    // The points sorted by cell (counting sort), and each cell's top.
    let mut start = vec![0u32; nx * ny + 1];
    let mut top = vec![f64::NEG_INFINITY; nx * ny];
    for &p in pos {
        let (x, y) = cell_of(p);
        start[y * nx + x + 1] += 1;
        top[y * nx + x] = top[y * nx + x].max(p.z);
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    let mut order = vec![0u32; n];
    let mut fill = start.clone();
    for (i, &p) in pos.iter().enumerate() {
        let (x, y) = cell_of(p);
        order[fill[y * nx + x] as usize] = i as u32;
        fill[y * nx + x] += 1;
    }
    drop(fill);
    let r2 = radius * radius;
    let top = &top;
    let reach = (radius / cell).ceil() as usize;
    while let Some(i) = queue.pop() {
        let i = i as usize;
        let p = pos[i];
        let (x, y) = cell_of(p);
        // The cells that can hold a point above p: within the disk, and
        // with a top above the slope at their nearest to p; nearest first
        // (a hidden point is settled by a few points near it).
        let mut cells = [(0.0f64, 0usize); 25];
        let mut k = 0;
        for cy in y.saturating_sub(reach)..=(y + reach).min(ny - 1) {
            for cx in x.saturating_sub(reach)..=(x + reach).min(nx - 1) {
                let c0 = lo + DVec2::new(cx as f64, cy as f64) * cell;
                let gap = (c0 - p.truncate())
                    .max(p.truncate() - (c0 + DVec2::splat(cell)))
                    .max(DVec2::ZERO);
                let near = gap.length();
                if k < cells.len()
                    && near <= radius
                    && top[cy * nx + cx] > p.z + slope * near + noise
                {
                    cells[k] = (near, cy * nx + cx);
                    k += 1;
                }
            }
        }
        let cells = &mut cells[..k];
        cells.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut sides = 0u8;
        'cells: for &(_, c) in cells.iter() {
            for &j in &order[start[c] as usize..start[c + 1] as usize] {
                let q = pos[j as usize];
                let d = q.truncate() - p.truncate();
                if d.length_squared() > r2 || !above(p, q) {
                    continue;
                }
                sides |= 1 << (usize::from(d.x >= 0.0) + 2 * usize::from(d.y >= 0.0));
                if sides == 0b1111 {
                    hidden[i] = true;
                    break 'cells;
                }
            }
        }
        if hidden[i] {
            for e in t.vertex(FixedVertexHandle::from_index(i)).out_edges() {
                let j = e.to().fix().index();
                if !queued[j] {
                    queued[j] = true;
                    queue.push(j as u32);
                }
            }
        }
    }
    hidden
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

    /// A depth camera's flying pixel (one point 58 mm above a flat
    /// cloud) was only found by the planner's refusal, which blamed "a
    /// feature" or "a wall" (a QA finding): the import names it. Steep but
    /// real surfaces (a 60-degree cone, a step, a ridge of one row) are not
    /// spikes.
    #[test]
    fn a_point_far_above_all_its_neighbours_is_a_spike() {
        let mut pts = grid(41, 0.5, |_, _| 2.0);
        pts.push(DVec3::new(10.1, 10.1, 60.0));
        let (_, info) = triangulate(pts, None, "c.xyz").unwrap();
        let s = info.spikes.expect("the flying pixel");
        assert_eq!(s.count, 1);
        assert_eq!(s.worst_mm, [10.1, 10.1, 60.0]);
        assert!((s.above_mm - 58.0).abs() < 1e-9, "{s:?}");
        let real: [&dyn Fn(f64, f64) -> f64; 3] = [
            &|x, y| 10.0 - 1.7 * ((x - 10.0).powi(2) + (y - 10.0).powi(2)).sqrt(),
            &|x, _| if x > 10.0 { 5.0 } else { 0.0 },
            &|x, _| if (x - 10.0).abs() < 0.1 { 3.0 } else { 0.0 },
        ];
        for f in real {
            let (_, info) = triangulate(grid(41, 0.5, f), None, "c.xyz").unwrap();
            assert_eq!(info.spikes, None);
        }
        // Two passes of a scan 2 um apart in XY, each with 0.03 mm of
        // noise (a review's case): the median spacing is 2 um, so ten
        // spacings is less than the noise; the floor is not.
        let noise = |x: f64, y: f64| 0.03 * (123.4 * x + 567.8 * y).sin() * (91.0 * x * y).cos();
        let mut twin = grid(41, 0.5, noise);
        twin.extend(
            grid(41, 0.5, |x, y| -noise(x, y))
                .into_iter()
                .map(|p| p + DVec3::X * 0.002),
        );
        let (_, info) = triangulate(twin, None, "c.xyz").unwrap();
        assert!(SPIKE_PER_SPACING * info.spacing_mm < 0.03, "{info:?}");
        assert_eq!(info.spikes, None);
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
    fn a_whole_objects_underside_is_left_out_and_the_top_is_meshed() {
        let (a, c) = crate::demo::PEBBLE_MM;
        let pts = crate::demo::pebble_cloud(0.25);
        let inside = |p: &DVec3| p.x * p.x + p.y * p.y < (a - 0.5) * (a - 0.5);
        let under = pts.iter().filter(|p| p.z < c && inside(p)).count();
        let (m, info) = triangulate(pts, None, "pebble.xyz").unwrap();
        // The underside is hidden but for a band within 0.5 mm of the
        // silhouette (where the top is near-vertical), and the part rests
        // on its lowest point.
        assert!(info.hidden >= under, "{info:?}, {under} under");
        assert_eq!(info.lowest_left_out_mm, Some(0.0));
        assert!(info
            .to_string()
            .contains("under the surface seen from above"));
        // The mesh is the top: inside that band every vertex is on it, and
        // it covers the top without holes: its heights inside the
        // silhouette are the ellipsoid's top, to the sag of a chord.
        let top = |x: f64, y: f64| c + c * (1.0 - (x * x + y * y) / (a * a)).max(0.0).sqrt();
        for v in m.vertices.iter().filter(|v| inside(v)) {
            assert!(
                (v.z - top(v.x, v.y)).abs() < 1e-9,
                "vertex {v} is not on the top"
            );
        }
        let s = crate::surface::Surface::new(m).unwrap();
        for k in 0..400 {
            let (r, t) = (0.9 * a * (k as f64 / 400.0).sqrt(), k as f64 * 2.399);
            let (x, y) = (r * t.cos(), r * t.sin());
            let z = s.highest_hit(DVec2::new(x, y)).expect("a hole in the top");
            assert!(
                (z - top(x, y)).abs() < 0.02,
                "at ({x}, {y}): {z} for {}",
                top(x, y)
            );
        }
        // The edge limit is set from the 3-D spacing, not from the XY
        // spacing of the top and the underside together.
        assert!(info.max_edge_mm > 0.6, "{info:?}");
    }

    #[test]
    fn a_height_field_with_steps_trenches_and_dimples_keeps_every_point() {
        // 0.1 mm grid: a 2 mm vertical step, a 1 mm wide trench 1.5 mm
        // deep, a dimple of radius 1.5 mm 0.6 mm deep, and noise.
        let pts = grid(81, 0.1, |x, y| {
            // A hash of the place as noise, +-0.005 mm.
            let h = ((x * 7919.0 + y * 104_729.0).sin() * 43_758.545).fract();
            let noise = 0.01 * (h.abs() - 0.5);
            let step = if x > 4.0 { 2.0 } else { 0.0 };
            let trench = if (y - 2.0).abs() <= 0.5 { -1.5 } else { 0.0 };
            let r2 = (x - 6.0).powi(2) + (y - 6.0).powi(2);
            let dimple = if r2 < 2.25 {
                -0.6 * (1.0 - r2 / 2.25)
            } else {
                0.0
            };
            step + trench + dimple + noise
        });
        let (_, info) = triangulate(pts, None, "steps.xyz").unwrap();
        assert_eq!(info.hidden, 0, "{info:?}");
        assert_eq!(info.lowest_left_out_mm, None);
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
