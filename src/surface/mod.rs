//! The registered scan Sa with its spatial index (a grid or parry3d's BVH,
//! see `index.rs`), built once and shared by projection (spec section 4),
//! the planners' disk and segment tests (section 6) and the quality
//! prediction (section 7).
//!
//! The index holds f32 boxes rounded outward, so it only ever prunes; every
//! exact test runs in f64 on the mesh's own vertices (projection must land
//! within 1e-6 mm of the surface).

mod index;
mod sweep;

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::mesh::{Topology, TriMesh, MAX_TOPOLOGY_TRIANGLES};
pub use index::SpatialIndex;
use index::{Index, QueryBox};
pub use sweep::{SweepGap, RIM_STEPS};

/// A scan in the printer frame, ready for queries.
pub struct Surface {
    mesh: TriMesh,
    index: Index,
    bbox: (DVec3, DVec3),
    /// Per triangle, which of its corners (bits 0-2) and edges (bits 3-5,
    /// edge k from corner k to k + 1) it owns ([`Topology::owned`]). The
    /// swept query tries each corner and edge in its owner only (see
    /// `sweep.rs`).
    owned: Vec<u8>,
}

/// A scan's bounds and spatial index, built on the borrowed mesh: the
/// other half of a [`Surface`], with its [`Topology`]
/// ([`Surface::from_index`]).
pub(crate) struct Indexed {
    index: Index,
    bbox: (DVec3, DVec3),
    triangles: usize,
}

impl Indexed {
    /// Checks `mesh` ([`Surface::check`]) and builds its index.
    pub(crate) fn build(mesh: &TriMesh, kind: SpatialIndex) -> Result<Indexed> {
        let bbox = Surface::check(mesh)?;
        Ok(Indexed::with_bounds(mesh, bbox, kind))
    }

    /// [`Self::build`] for an imported mesh whose used vertices' bounds
    /// the importer found (`mesh::Unwelded::used_bounds`; the importer
    /// checks what [`Surface::check`] checks but the triangle count, which
    /// is checked here): the check's pass is not made again.
    pub(crate) fn build_imported(
        mesh: &TriMesh,
        bounds: Option<(DVec3, DVec3)>,
        kind: SpatialIndex,
    ) -> Result<Indexed> {
        match bounds {
            // (Finite bounds only: a non-finite one is the check's to name.)
            Some(bbox)
                if !mesh.triangles.is_empty()
                    && mesh.triangles.len() <= MAX_TOPOLOGY_TRIANGLES
                    && bbox.0.is_finite()
                    && bbox.1.is_finite() =>
            {
                Ok(Indexed::with_bounds(mesh, bbox, kind))
            }
            _ => Indexed::build(mesh, kind),
        }
    }

    /// The index of a checked mesh whose bounds are `bbox`.
    fn with_bounds(mesh: &TriMesh, bbox: (DVec3, DVec3), kind: SpatialIndex) -> Indexed {
        Indexed {
            index: Index::build(mesh, bbox, kind),
            bbox,
            triangles: mesh.triangles.len(),
        }
    }
}

/// Where the horizontal tip disk C_j cuts the surface (spec section 6c).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiskContact {
    /// The length-weighted centroid p_j of C_j ∩ S (lies in the disk's plane).
    pub centroid: DVec3,
    /// Total length of the cut inside the disk (0 for a touch at one point).
    pub length_mm: f64,
}

impl std::fmt::Debug for Surface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Surface")
            .field("triangles", &self.mesh.triangles.len())
            .field("bbox", &self.bbox)
            .field("index", &self.index.kind())
            .finish()
    }
}

impl Surface {
    /// Builds the spatial index. The mesh must be non-empty with finite vertices (the
    /// importers guarantee both; this re-checks for meshes built in code).
    pub fn new(mesh: TriMesh) -> Result<Surface> {
        Surface::with_index(mesh, SpatialIndex::Auto)
    }

    /// [`Self::new`] with a chosen spatial index (tests and benchmarks
    /// compare them; results agree to the last bit but for summation order).
    pub fn with_index(mesh: TriMesh, kind: SpatialIndex) -> Result<Surface> {
        let bbox = Surface::check(&mesh)?;
        // First: its transient arrays are freed before the index's grow.
        let topology = Topology::of(&mesh);
        let indexed = Indexed::with_bounds(&mesh, bbox, kind);
        Surface::from_index(mesh, indexed, topology)
    }

    /// [`Self::new`] with the mesh's [`Topology`] already found (the
    /// fiducials need it too: one pass serves both). A topology of another
    /// mesh is refused when its triangle count differs; one of a mesh with
    /// the same triangles moved (the registration) is the same.
    pub fn with_topology(mesh: TriMesh, topology: Topology) -> Result<Surface> {
        let indexed = Indexed::build(&mesh, SpatialIndex::Auto)?;
        Surface::from_index(mesh, indexed, topology)
    }

    /// The surface of `mesh` from its index, built on `mesh` (borrowed,
    /// so that its topology could be found at the same time), and its
    /// topology.
    pub(crate) fn from_index(
        mesh: TriMesh,
        indexed: Indexed,
        topology: Topology,
    ) -> Result<Surface> {
        for (what, count) in [
            ("index", indexed.triangles),
            ("topology", topology.owned.len()),
        ] {
            if count != mesh.triangles.len() {
                return Err(Error::Plan(format!(
                    "the {what} given is of {count} triangles, the scan has {}",
                    mesh.triangles.len()
                )));
            }
        }
        Ok(Surface {
            mesh,
            index: indexed.index,
            bbox: indexed.bbox,
            owned: topology.owned,
        })
    }

    /// What the surface's queries rely on (triangles, finite vertices,
    /// indices in range, not too many to number their edges): the bounds.
    fn check(mesh: &TriMesh) -> Result<(DVec3, DVec3)> {
        // Each triangle's indices checked before any vertex is read; then
        // the vertices the triangles use, in vertex order (a pass over the
        // corners, gathering a vertex each, cost 184 M instructions on a
        // 2 M triangle scan; marking them and reading the vertices in
        // order, a fifth of that: issue 15).
        let n = mesh.vertices.len();
        let corners = mesh.triangles.as_flattened();
        let past = corners.iter().copied().max().unwrap_or_default();
        if past as usize >= n {
            let i = mesh
                .triangles
                .iter()
                .position(|t| t.iter().any(|&k| k as usize >= n))
                .unwrap_or_default();
            return Err(Error::Plan(format!(
                "triangle {i} refers to a vertex past the {n} the scan has"
            )));
        }
        let mut used = vec![false; n];
        for &k in corners {
            used[k as usize] = true;
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for (k, &v) in mesh.vertices.iter().enumerate() {
            if !used[k] {
                continue;
            }
            if !v.is_finite() {
                return Err(Error::Plan(format!(
                    "vertex {k} of the scan has a non-finite coordinate"
                )));
            }
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if mesh.triangles.is_empty() {
            return Err(Error::Plan("the scan has no triangles".into()));
        }
        let bbox = (lo, hi);
        if mesh.triangles.len() > MAX_TOPOLOGY_TRIANGLES {
            return Err(Error::Plan(format!(
                "the scan has {} triangles, more than the {MAX_TOPOLOGY_TRIANGLES} this program \
                 indexes",
                mesh.triangles.len()
            )));
        }
        Ok(bbox)
    }

    /// Which spatial index the scan got.
    pub fn spatial_index(&self) -> SpatialIndex {
        self.index.kind()
    }

    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// Bounds of the scan in the printer frame.
    pub fn bbox(&self) -> (DVec3, DVec3) {
        self.bbox
    }

    /// Highest point of the scan: the G-code's safe height builds on it.
    pub fn top_z(&self) -> f64 {
        self.bbox.1.z
    }

    /// The point of the scan's triangles, seen from above, nearest `to` (in
    /// XY; `None` for a scan with none). For an error message or a drawing
    /// placed once: every triangle is tried.
    pub fn nearest_in_xy(&self, to: DVec2) -> Option<DVec2> {
        let mesh = &self.mesh;
        let on_segment =
            |a: DVec2, b: DVec2| a + crate::spacing::nearest_on_segment(to, a, b) * (b - a);
        let nearer =
            |p: &DVec2, q: &DVec2| p.distance_squared(to).total_cmp(&q.distance_squared(to));
        mesh.triangles
            .iter()
            .map(|t| t.map(|i| mesh.vertices[i as usize].truncate()))
            .map(|[a, b, c]| {
                // Inside (either winding): the point itself.
                let side = |p: DVec2, q: DVec2| (q - p).perp_dot(to - p);
                let (s0, s1, s2) = (side(a, b), side(b, c), side(c, a));
                if (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0) {
                    return to;
                }
                [on_segment(a, b), on_segment(b, c), on_segment(c, a)]
                    .into_iter()
                    .min_by(nearer)
                    .unwrap_or(a)
            })
            .min_by(nearer)
    }

    /// z of the highest intersection of the vertical line through `xy` with
    /// the scan (spec section 4), `None` if the line misses it.
    pub fn highest_hit(&self, xy: DVec2) -> Option<f64> {
        let q = QueryBox {
            lo: DVec3::new(xy.x, xy.y, f64::NEG_INFINITY),
            hi: DVec3::new(xy.x, xy.y, f64::INFINITY),
        };
        let mut best: Option<f64> = None;
        self.index.visit(&q, |i| {
            let t = self.mesh.triangle(i);
            if !meets(&t, &q) {
                return;
            }
            if let Some(z) = vertical_hit(t, xy) {
                best = Some(best.map_or(z, |b: f64| b.max(z)));
            }
        });
        best
    }

    /// The cut of the horizontal disk (centre `center`, `radius`) with the
    /// scan: `None` when they do not meet (spec section 6c, C_j ∩ S).
    pub fn disk_contact(&self, center: DVec3, radius: f64) -> Option<DiskContact> {
        let q = QueryBox {
            lo: center - DVec3::new(radius, radius, 0.0),
            hi: center + DVec3::new(radius, radius, 0.0),
        };
        let mut weighted = DVec3::ZERO;
        let mut length = 0.0;
        let mut touches = DVec3::ZERO;
        let mut touch_count = 0usize;
        self.index.visit(&q, |i| {
            let t = self.mesh.triangle(i);
            if !meets(&t, &q) || !box_near_disk(&t, center.truncate(), radius) {
                return;
            }
            for (p, s, w) in plane_cut(t, center.z) {
                if let Some((a, b)) = clip_to_circle(p, s, center, radius) {
                    let l = a.distance(b) * w;
                    weighted += (a + b) * 0.5 * l;
                    length += l;
                    touches += a;
                    touch_count += 1;
                }
            }
        });
        if touch_count == 0 {
            return None;
        }
        let centroid = if length > 1e-12 {
            weighted / length
        } else {
            touches / touch_count as f64
        };
        Some(DiskContact {
            centroid,
            length_mm: length,
        })
    }

    /// The intersection of the segment [a, b] with the scan nearest to `a`
    /// (spec eq. 12).
    pub fn segment_first_hit(&self, a: DVec3, b: DVec3) -> Option<DVec3> {
        let q = QueryBox {
            lo: a.min(b),
            hi: a.max(b),
        };
        let dir = b - a;
        let mut best: Option<f64> = None;
        self.index.visit(&q, |i| {
            let tri = self.mesh.triangle(i);
            if !meets(&tri, &q) {
                return;
            }
            if let Some(t) = segment_triangle(a, dir, tri) {
                if best.is_none_or(|b| t < b) {
                    best = Some(t);
                }
            }
        });
        best.map(|t| a + dir * t)
    }
}

/// Whether the triangle's box meets the query box (exact, in f64): the index
/// prunes by cells or leaves, this by the triangle itself.
#[inline]
fn meets(t: &[DVec3; 3], q: &QueryBox) -> bool {
    let (lo, hi) = corner_box(t);
    box_meets(lo, hi, q)
}

/// [`meets`] for the triangle's box (lo, hi) found by [`corner_box`].
#[inline]
fn box_meets(lo: DVec3, hi: DVec3, q: &QueryBox) -> bool {
    lo.x <= q.hi.x
        && hi.x >= q.lo.x
        && lo.y <= q.hi.y
        && hi.y >= q.lo.y
        && lo.z <= q.hi.z
        && hi.z >= q.lo.z
}

/// The box of a triangle's corners: (lo, hi). Plain comparisons rather than
/// `f64::min` and `max`, which also have to pass over a NaN and take several
/// instructions each where a comparison takes one: this box is found for
/// every triangle the index hands to a query. For the finite vertices of a
/// surface the two differ only in which zero they give of -0 and +0, which
/// compare equal, and no sum, difference or square taken of the box's
/// coordinates in its uses tells them apart.
#[inline]
fn corner_box(t: &[DVec3; 3]) -> (DVec3, DVec3) {
    #[inline]
    fn lo(a: f64, b: f64, c: f64) -> f64 {
        let m = if b < a { b } else { a };
        if c < m {
            c
        } else {
            m
        }
    }
    #[inline]
    fn hi(a: f64, b: f64, c: f64) -> f64 {
        let m = if b > a { b } else { a };
        if c > m {
            c
        } else {
            m
        }
    }
    let [a, b, c] = t;
    (
        DVec3::new(lo(a.x, b.x, c.x), lo(a.y, b.y, c.y), lo(a.z, b.z, c.z)),
        DVec3::new(hi(a.x, b.x, c.x), hi(a.y, b.y, c.y), hi(a.z, b.z, c.z)),
    )
}

/// Whether the triangle's XY box comes within `r` of `c` (with a hair of
/// slack: this only skips triangles that cannot meet the disk).
#[inline]
fn box_near_disk(t: &[DVec3; 3], c: DVec2, r: f64) -> bool {
    let lo = t[0].truncate().min(t[1].truncate()).min(t[2].truncate());
    let hi = t[0].truncate().max(t[1].truncate()).max(t[2].truncate());
    let gap = (lo - c).max(c - hi).max(DVec2::ZERO);
    gap.length_squared() <= r * r * (1.0 + 1e-9)
}

/// Relative tolerance of the inclusive point-in-triangle tests, so a line
/// through a shared edge or vertex is caught by at least one triangle.
const EDGE_EPS: f64 = 1e-12;

/// Barycentric weights of `p` in the XY projection of the triangle, `None`
/// outside it or when the projection is degenerate (vertical triangle).
fn barycentric_xy(t: [DVec3; 3], p: DVec2) -> Option<[f64; 3]> {
    let [a, b, c] = t.map(|v| v.truncate());
    let area = (b - a).perp_dot(c - a);
    let scale = (b - a).length_squared().max((c - a).length_squared());
    if area.abs() <= 1e-14 * scale || scale == 0.0 {
        return None;
    }
    let w0 = (b - p).perp_dot(c - p) / area;
    let w1 = (c - p).perp_dot(a - p) / area;
    let w2 = 1.0 - w0 - w1;
    let eps = EDGE_EPS * (1.0 + scale.sqrt());
    (w0 >= -eps && w1 >= -eps && w2 >= -eps).then_some([w0, w1, w2])
}

fn vertical_hit(t: [DVec3; 3], xy: DVec2) -> Option<f64> {
    let w = barycentric_xy(t, xy)?;
    // Clamp so an inclusive edge hit never extrapolates past the edge.
    let w = w.map(|x| x.clamp(0.0, 1.0));
    let s = w[0] + w[1] + w[2];
    Some((w[0] * t[0].z + w[1] * t[1].z + w[2] * t[2].z) / s)
}

/// The cut of a triangle by the plane z = `z`: zero, one point (a touch) or
/// one segment, with a weight. An edge lying in the plane is cut by both
/// triangles that share it, so each counts it half; a triangle lying in the
/// plane gives its three edges, each at half weight.
fn plane_cut(t: [DVec3; 3], z: f64) -> impl Iterator<Item = (DVec3, DVec3, f64)> {
    let d = t.map(|v| v.z - z);
    let mut out: [Option<(DVec3, DVec3, f64)>; 3] = [None; 3];
    if d.iter().all(|&x| x == 0.0) {
        for (k, slot) in out.iter_mut().enumerate() {
            *slot = Some((t[k], t[(k + 1) % 3], 0.5));
        }
    } else if !(d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0)) {
        let mut pts: [DVec3; 3] = [DVec3::ZERO; 3];
        let mut n = 0;
        let on_plane = d.iter().filter(|&&x| x == 0.0).count();
        for k in 0..3 {
            let (i, j) = (k, (k + 1) % 3);
            if d[i] == 0.0 {
                pts[n] = t[i];
                n += 1;
            } else if (d[i] < 0.0) != (d[j] < 0.0) && d[j] != 0.0 {
                let s = d[i] / (d[i] - d[j]);
                let mut p = t[i] + (t[j] - t[i]) * s;
                p.z = z;
                pts[n] = p;
                n += 1;
            }
            if n == 3 {
                break;
            }
        }
        let w = if on_plane == 2 { 0.5 } else { 1.0 };
        match n {
            1 => out[0] = Some((pts[0], pts[0], 1.0)),
            2 | 3 => out[0] = Some((pts[0], pts[1], w)),
            _ => {}
        }
    }
    out.into_iter().flatten()
}

/// The part of the horizontal segment [p, q] within `radius` of `c` in XY.
fn clip_to_circle(p: DVec3, q: DVec3, c: DVec3, radius: f64) -> Option<(DVec3, DVec3)> {
    let d = (q - p).truncate();
    let f = (p - c).truncate();
    let a = d.length_squared();
    if a == 0.0 {
        return (f.length_squared() <= radius * radius).then_some((p, p));
    }
    let b = 2.0 * f.dot(d);
    let cc = f.length_squared() - radius * radius;
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let t0 = ((-b - sq) / (2.0 * a)).max(0.0);
    let t1 = ((-b + sq) / (2.0 * a)).min(1.0);
    if t0 > t1 {
        return None;
    }
    Some((p + (q - p) * t0, p + (q - p) * t1))
}

/// Two-sided Möller-Trumbore: parameter t in [0, 1] along `dir` from `o`.
fn segment_triangle(o: DVec3, dir: DVec3, t: [DVec3; 3]) -> Option<f64> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    let scale = e1.length() * e2.length() * dir.length();
    if det.abs() <= 1e-14 * scale || scale == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = s.dot(p) * inv;
    let qv = s.cross(e1);
    let v = dir.dot(qv) * inv;
    let eps = 1e-12;
    if u < -eps || v < -eps || u + v > 1.0 + eps {
        return None;
    }
    let tt = e2.dot(qv) * inv;
    (-eps..=1.0 + eps).contains(&tt).then(|| tt.clamp(0.0, 1.0))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn each_corner_and_edge_is_owned_by_its_first_triangle() {
        // A 6 x 5 grid of vertices, its triangles in a scrambled order.
        let mut m = TriMesh::default();
        for y in 0..5 {
            for x in 0..6 {
                m.vertices.push(DVec3::new(x as f64, y as f64, 0.0));
            }
        }
        for y in 0..4u32 {
            for x in 0..5u32 {
                let v = y * 6 + x;
                m.triangles.push([v, v + 1, v + 7]);
                m.triangles.push([v, v + 7, v + 6]);
            }
        }
        let n = m.triangles.len();
        m.triangles = (0..n).map(|i| m.triangles[(i * 7) % n]).collect();
        let owned = Topology::of(&m).owned;
        let first_with = |has: &dyn Fn(&[u32; 3]) -> bool| m.triangles.iter().position(has);
        for (t, tri) in m.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let corner = first_with(&|u| u.contains(&a)) == Some(t);
                let edge = first_with(&|u| u.contains(&a) && u.contains(&b)) == Some(t);
                assert_eq!(owned[t] & (1 << k) != 0, corner, "corner {a} of {t}");
                assert_eq!(owned[t] & (8 << k) != 0, edge, "edge {a}-{b} of {t}");
            }
        }
    }

    /// The highest z of the scan over the XY disk, by its own exact
    /// per-triangle geometry (independent of the sweep's): the reference
    /// the sweep's tests sample against.
    pub(crate) fn reference_max_height_in_disk(s: &Surface, c: DVec2, r: f64) -> Option<f64> {
        let q = QueryBox {
            lo: DVec3::new(c.x - r, c.y - r, f64::NEG_INFINITY),
            hi: DVec3::new(c.x + r, c.y + r, f64::INFINITY),
        };
        let mut best: Option<f64> = None;
        s.index.visit(&q, |i| {
            if let Some(z) = triangle_max_z_in_disk(s.mesh.triangle(i), c, r) {
                best = Some(best.map_or(z, |b: f64| b.max(z)));
            }
        });
        best
    }

    /// Highest z of the triangle over the XY disk: a linear function on the
    /// convex set triangle ∩ cylinder peaks at a triangle vertex inside the disk,
    /// where an edge crosses the circle, or where the circle meets the plane's
    /// steepest ascent (if that point lies in the triangle).
    fn triangle_max_z_in_disk(t: [DVec3; 3], c: DVec2, r: f64) -> Option<f64> {
        let r2 = r * r;
        let mut best: Option<f64> = None;
        let mut take = |z: f64| best = Some(best.map_or(z, |b: f64| b.max(z)));
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if (a.truncate() - c).length_squared() <= r2 {
                take(a.z);
            }
            let d = (b - a).truncate();
            let f = a.truncate() - c;
            let qa = d.length_squared();
            if qa > 0.0 {
                let qb = 2.0 * f.dot(d);
                let qc = f.length_squared() - r2;
                let disc = qb * qb - 4.0 * qa * qc;
                if disc >= 0.0 {
                    let sq = disc.sqrt();
                    for s in [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] {
                        if (0.0..=1.0).contains(&s) {
                            take(a.z + (b.z - a.z) * s);
                        }
                    }
                }
            }
        }
        // Interior candidates need a non-vertical plane z = g . xy + z0.
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.z.abs() > 1e-14 * n.length() {
            let g = DVec2::new(-n.x / n.z, -n.y / n.z);
            let z_at = |p: DVec2| t[0].z + g.dot(p - t[0].truncate());
            if barycentric_xy(t, c).is_some() {
                take(z_at(c));
            }
            let gl = g.length();
            if gl > 0.0 {
                let p = c + g / gl * r;
                if barycentric_xy(t, p).is_some() {
                    take(z_at(p));
                }
            }
        }
        best
    }

    /// The highest z over the disk by the sweep's point case (a flat
    /// cutter standing above the scan): what the planners' point queries
    /// rest on.
    fn max_height_in_disk(s: &Surface, xy: DVec2, radius: f64) -> Option<f64> {
        let p = xy.extend(s.top_z() + 1.0);
        s.sweep_gap(p, p, radius, f64::INFINITY)
            .map(|g| p.z - g.gap_mm)
    }

    #[test]
    fn the_flat_footprint_query_matches_the_reference() {
        let s = Surface::new(grid(40, 10.0, |x, y| (x * 1.7).sin() + 0.3 * y)).unwrap();
        for k in 0..200 {
            let c = DVec2::new(0.5 + 0.045 * k as f64, 2.0 + 0.03 * k as f64);
            let a = max_height_in_disk(&s, c, 0.45).unwrap();
            let b = reference_max_height_in_disk(&s, c, 0.45).unwrap();
            assert!((a - b).abs() < 1e-9, "{c}: {a} vs {b}");
        }
    }

    /// The plane z = 0 over [-10, 10]^2, for the planners' and quality tests.
    pub(crate) fn flat() -> Surface {
        Surface::new(TriMesh {
            vertices: vec![
                DVec3::new(-10.0, -10.0, 0.0),
                DVec3::new(10.0, -10.0, 0.0),
                DVec3::new(10.0, 10.0, 0.0),
                DVec3::new(-10.0, 10.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        })
        .unwrap()
    }

    /// A height field z = f(x, y) on a regular n x n grid, for tests.
    pub(crate) fn grid(n: usize, size: f64, f: impl Fn(f64, f64) -> f64) -> TriMesh {
        let axis: Vec<f64> = (0..=n).map(|i| i as f64 * size / n as f64).collect();
        TriMesh::height_field(&axis, &axis, f)
    }

    #[test]
    fn highest_hit_on_a_plane_and_outside() {
        let s = Surface::new(grid(10, 10.0, |x, y| 0.5 * x + 0.25 * y + 1.0)).unwrap();
        let z = s.highest_hit(DVec2::new(3.3, 4.4)).unwrap();
        assert!((z - (0.5 * 3.3 + 0.25 * 4.4 + 1.0)).abs() < 1e-12);
        // On a grid vertex and on shared edges: still hit.
        assert!(s.highest_hit(DVec2::new(5.0, 5.0)).is_some());
        assert!(s.highest_hit(DVec2::new(5.0, 2.5)).is_some());
        assert!(s.highest_hit(DVec2::new(-0.1, 5.0)).is_none());
    }

    #[test]
    fn highest_of_two_layers_wins() {
        let mut m = grid(2, 2.0, |_, _| 0.0);
        let top = grid(2, 2.0, |_, _| 3.0);
        let off = m.vertices.len() as u32;
        m.vertices.extend(top.vertices);
        m.triangles
            .extend(top.triangles.iter().map(|t| t.map(|k| k + off)));
        let s = Surface::new(m).unwrap();
        assert_eq!(s.highest_hit(DVec2::new(1.2, 0.7)), Some(3.0));
    }

    #[test]
    fn disk_contact_centroid_on_a_slope() {
        // z = x: the plane z = 5 cuts along x = 5, a chord through a disk
        // centred at (5.3, 5): centroid at x = 5, y = 5.
        let s = Surface::new(grid(20, 10.0, |x, _| x)).unwrap();
        let c = s.disk_contact(DVec3::new(5.3, 5.0, 5.0), 0.45).unwrap();
        assert!((c.centroid - DVec3::new(5.0, 5.0, 5.0)).length() < 1e-9);
        let chord = 2.0 * (0.45f64 * 0.45 - 0.3 * 0.3).sqrt();
        assert!((c.length_mm - chord).abs() < 1e-9, "{}", c.length_mm);
        assert!(s.disk_contact(DVec3::new(5.5, 5.0, 5.0), 0.45).is_none());
    }

    #[test]
    fn segment_hit_nearest_first() {
        let s = Surface::new(grid(10, 10.0, |x, _| x)).unwrap();
        let p = s
            .segment_first_hit(DVec3::new(2.0, 5.0, 5.0), DVec3::new(8.0, 5.0, 5.0))
            .unwrap();
        assert!((p - DVec3::new(5.0, 5.0, 5.0)).length() < 1e-9);
        assert!(s
            .segment_first_hit(DVec3::new(2.0, 5.0, 5.0), DVec3::new(4.0, 5.0, 5.0))
            .is_none());
    }

    #[test]
    fn max_height_over_a_footprint() {
        let s = Surface::new(grid(20, 10.0, |x, y| 0.5 * x + 0.0 * y)).unwrap();
        let z = max_height_in_disk(&s, DVec2::new(5.0, 5.0), 1.0).unwrap();
        assert!((z - 3.0).abs() < 1e-9, "{z}");
        // A cone-ish bump: peak inside the disk dominates.
        let s = Surface::new(grid(40, 10.0, |x, y| {
            2.0 - ((x - 5.0).powi(2) + (y - 5.0).powi(2)).sqrt()
        }))
        .unwrap();
        let z = max_height_in_disk(&s, DVec2::new(5.2, 5.0), 0.5).unwrap();
        assert!((z - 2.0).abs() < 1e-9, "{z}");
    }

    #[test]
    fn empty_mesh_is_an_error() {
        assert!(Surface::new(TriMesh::default()).is_err());
    }

    /// The bounds the importer finds while reading (and the surface's
    /// check is then not run for) are the check's: in other units, +Y up,
    /// with a far vertex no triangle uses, and a cloud's mesh has none.
    #[test]
    fn the_importers_bounds_are_the_checks() {
        use crate::mesh::{import_mesh_unwelded, ExternalFiles, ImportOptions, ScanUnits, UpAxis};
        let obj = "v 0 0 0\nv 1.5 0 0.25\nv 0 1 2\nv 1 1 -3\nv 500 -500 500\nf 1 2 3\nf 2 4 3\n";
        for (units, up_axis) in [
            (None, None),
            (Some(ScanUnits::Cm), Some(UpAxis::Y)),
            (Some(ScanUnits::In), Some(UpAxis::Z)),
        ] {
            let options = ImportOptions {
                units,
                up_axis,
                ..ImportOptions::DEFAULT
            };
            let u = import_mesh_unwelded(obj.as_bytes(), "a.obj", &options, &ExternalFiles::new())
                .unwrap();
            let checked = Surface::check(&u.imported().mesh).unwrap();
            assert_eq!(u.used_bounds(), Some(checked), "{units:?} {up_axis:?}");
            assert!(checked.1.max_element() < 100.0);
        }
        // A coordinate finite in metres, infinite in mm, is refused.
        let far = "v 0 0 0\nv 1 0 0\nv 0 1 -1e306\nf 1 2 3\n";
        let m = ImportOptions {
            units: Some(ScanUnits::M),
            ..ImportOptions::DEFAULT
        };
        let e = import_mesh_unwelded(far.as_bytes(), "far.obj", &m, &ExternalFiles::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("vertex 2 has a non-finite coordinate"), "{e}");
        let xyz = "0 0 0\n1 0 0\n0 1 0\n1 1 0.5\n";
        let u = import_mesh_unwelded(
            xyz.as_bytes(),
            "c.xyz",
            &ImportOptions::DEFAULT,
            &ExternalFiles::new(),
        )
        .unwrap();
        assert_eq!(u.used_bounds(), None);
    }

    #[test]
    fn bad_meshes_built_in_code_are_errors_not_panics() {
        let good = grid(3, 1.0, |_, _| 0.0);
        let mut past = good.clone();
        past.triangles[4][2] = 99;
        let e = Surface::new(past).unwrap_err().to_string();
        assert!(e.contains("triangle 4 refers to a vertex past"), "{e}");
        let mut nan = good.clone();
        let k = nan.triangles[3][1];
        nan.vertices[k as usize].z = f64::NAN;
        let e = Surface::new(nan).unwrap_err().to_string();
        assert!(e.contains(&format!("vertex {k} ")), "{e}");
        // Vertices no triangle uses bound nothing, even non-finite ones.
        let mut spare = good.clone();
        spare.vertices.push(DVec3::splat(1000.0));
        spare.vertices.push(DVec3::splat(f64::NAN));
        let bbox = Surface::new(spare).unwrap().bbox;
        assert_eq!(bbox, Surface::new(good.clone()).unwrap().bbox);
        // A topology of another mesh.
        let other = Topology::of(&grid(4, 1.0, |_, _| 0.0));
        let e = Surface::with_topology(good.clone(), other)
            .unwrap_err()
            .to_string();
        assert!(e.contains("the topology given is of"), "{e}");
        // The mesh's own, found before, gives the surface Surface::new gives.
        let own = Topology::of(&good);
        let with = Surface::with_topology(good.clone(), own).unwrap();
        let new = Surface::new(good).unwrap();
        assert_eq!(with.owned, new.owned);
        assert_eq!(with.bbox, new.bbox);
    }
}
