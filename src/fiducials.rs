//! Fiducial holes as boundary loops (spec section 2).
//!
//! The ~1 mm black fiducial dots leave holes in a structured-light scan. A hole
//! is a closed loop of boundary edges (edges used by exactly one triangle);
//! its point is the loop polygon's **area centroid**, which, unlike the mean
//! of the loop's vertices, does not drift toward the densely sampled side.
//!
//! Robustness: edges used by three or more triangles (non-manifold) are not
//! boundary; a vertex where several loops touch (a pinch vertex) is split so
//! each loop comes out simple; dangling chains are dropped. Nothing here
//! panics on a malformed mesh: triangles with out-of-range or repeated
//! indices are skipped.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::buckets::Buckets;
use crate::mesh::topology::valid_triangle;
use crate::mesh::{Topology, TriMesh, MAX_TOPOLOGY_TRIANGLES};

/// A loop is taken as a boundary of the scan (not a hole) when its area is at
/// least this fraction of the largest loop's area ...
pub const BOUNDARY_AREA_FRACTION: f64 = 0.25;
/// ... and its bounding-box diagonal is at least this fraction of the whole
/// mesh's. The extent test keeps the holes of a closed scan (all loops small,
/// none bounding the scan), the area test keeps long thin slits.
pub const BOUNDARY_EXTENT_FRACTION: f64 = 0.25;
/// Holes at least this round sort before less round ones. Roundness is
/// 4 pi A / perimeter^2: 1 for a circle, 0.785 for a square, 0.4-0.6 for a
/// dot that dropped out of a scanner's pixel grid (its rim is a staircase,
/// which lengthens the perimeter), about 0.26 for a 10:1 slit.
pub const ROUND_ENOUGH: f64 = 0.3;

/// The fiducial dot diameter expected by default (the paper's ~1 mm dots).
pub const DEFAULT_DOT_DIAMETER_MM: f64 = 1.0;

/// Holes scoring below this are left out of the candidates: border notches,
/// slits, scanner dropouts far smaller or larger than the dots (see
/// [`score`]).
pub const MIN_SCORE: f64 = 0.01;

/// How well a hole of equivalent diameter `diameter_mm` and `roundness`
/// matches a dot of `expected_mm`, from 0 to 1: the size factor
/// exp(-(ln(D / E) / ln 1.6)^2) (1.6 times too large or too small halves
/// it, about; three times scores under 0.01) times the roundness factor,
/// 0 at roundness 0.2 (a 15:1 slit) rising to 1 at 0.6 (a dot that dropped
/// out of a scanner's pixel grid has 0.4-0.6, its rim a staircase).
pub fn score(diameter_mm: f64, roundness: f64, expected_mm: f64) -> f64 {
    if !(diameter_mm > 0.0 && expected_mm > 0.0) {
        return 0.0;
    }
    let size = (diameter_mm / expected_mm).ln() / 1.6f64.ln();
    let round = ((roundness - 0.2) / 0.4).clamp(0.0, 1.0);
    (-size * size).exp() * round
}

/// A candidate fiducial: one hole of the scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fiducial {
    /// Area centroid of the hole's loop polygon (scan frame, mm).
    pub centroid: DVec3,
    /// Equivalent diameter 2 sqrt(A / pi), mm.
    pub diameter_mm: f64,
    /// Number of vertices on the hole's loop.
    pub loop_len: usize,
    /// Loop polygon area A (fan from the vertex mean, projected on the
    /// loop's mean plane), mm^2.
    #[serde(default)]
    pub area_mm2: f64,
    /// Loop length, mm.
    #[serde(default)]
    pub perimeter_mm: f64,
    /// 4 pi A / perimeter^2: 1 for a circle, near 0 for a slit.
    #[serde(default)]
    pub roundness: f64,
    /// How well it matches the expected dot ([`score`]), 0 to 1.
    #[serde(default)]
    pub score: f64,
}

impl Fiducial {
    /// Whether it could be a fiducial dot at all (score >= [`MIN_SCORE`]).
    pub fn is_candidate(&self) -> bool {
        self.score >= MIN_SCORE
    }
}

/// One closed loop of boundary edges.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryLoop {
    /// Vertex indices in loop order (the closing edge is implied).
    pub vertices: Vec<u32>,
    /// Area centroid, mm.
    pub centroid: DVec3,
    /// Vector area of the fan polygon (its length is the area), mm^2.
    pub vector_area: DVec3,
    /// Loop length, mm.
    pub perimeter_mm: f64,
    /// Diagonal of the loop's bounding box, mm.
    pub extent_mm: f64,
}

impl BoundaryLoop {
    /// Area of the loop polygon, mm^2.
    pub fn area_mm2(&self) -> f64 {
        self.vector_area.length()
    }

    /// 4 pi A / perimeter^2.
    pub fn roundness(&self) -> f64 {
        if self.perimeter_mm > 0.0 {
            4.0 * std::f64::consts::PI * self.area_mm2() / (self.perimeter_mm * self.perimeter_mm)
        } else {
            0.0
        }
    }
}

/// The holes of a scan, best fiducial candidates first.
///
/// Loops that bound the scan are left out: those with an area of at least
/// [`BOUNDARY_AREA_FRACTION`] of the largest loop's and a bounding-box
/// diagonal of at least [`BOUNDARY_EXTENT_FRACTION`] of the mesh's (so the
/// outer edge of an open scan, and any comparably large cut-out, go; a closed
/// scan's small holes all stay). Loops of fewer than 3 vertices or zero area
/// are dropped.
///
/// Ranked for dots of [`DEFAULT_DOT_DIAMETER_MM`]: see
/// [`find_fiducials_sized`].
pub fn find_fiducials(mesh: &TriMesh) -> Vec<Fiducial> {
    find_fiducials_sized(mesh, DEFAULT_DOT_DIAMETER_MM)
}

/// The holes of a scan that could be fiducial dots of `dot_diameter_mm`,
/// best first.
///
/// Loops that bound the scan are left out (see [`find_fiducials`]). Every
/// other hole is listed with its [`score`] for the expected dot; those
/// below [`MIN_SCORE`] (a ragged border's notches, slits, tiny dropouts,
/// large gaps) come last, and the page and `auto` registration leave them
/// out ([`Fiducial::is_candidate`]). Order: by score, ties by roundness >=
/// [`ROUND_ENOUGH`] first, then ascending diameter, then centroid x, y, z
/// for a deterministic order.
pub fn find_fiducials_sized(mesh: &TriMesh, dot_diameter_mm: f64) -> Vec<Fiducial> {
    topology_of(mesh).map_or_else(Vec::new, |t| find_fiducials_in(mesh, &t, dot_diameter_mm))
}

/// The mesh's topology, `None` past [`MAX_TOPOLOGY_TRIANGLES`] (no
/// importer keeps that many; such a mesh has no holes listed).
fn topology_of(mesh: &TriMesh) -> Option<Topology> {
    (mesh.triangles.len() <= MAX_TOPOLOGY_TRIANGLES).then(|| Topology::of(mesh))
}

/// [`find_fiducials_sized`] with the mesh's [`Topology`] already found
/// (the surface's index needs it too: one pass serves both).
pub fn find_fiducials_in(
    mesh: &TriMesh,
    topology: &Topology,
    dot_diameter_mm: f64,
) -> Vec<Fiducial> {
    let loops = loops_of(mesh, &topology.boundary_edges);
    let Some(mesh_extent) = mesh_extent(mesh) else {
        return Vec::new();
    };
    let max_area = loops.iter().map(BoundaryLoop::area_mm2).fold(0.0, f64::max);
    let mut out: Vec<Fiducial> = loops
        .iter()
        .filter(|l| {
            let bounds_scan = l.area_mm2() >= BOUNDARY_AREA_FRACTION * max_area
                && l.extent_mm >= BOUNDARY_EXTENT_FRACTION * mesh_extent;
            !bounds_scan
        })
        .map(|l| {
            let a = l.area_mm2();
            Fiducial {
                centroid: l.centroid,
                diameter_mm: 2.0 * (a / std::f64::consts::PI).sqrt(),
                loop_len: l.vertices.len(),
                area_mm2: a,
                perimeter_mm: l.perimeter_mm,
                roundness: l.roundness(),
                score: 0.0,
            }
        })
        .map(|mut f| {
            f.score = score(f.diameter_mm, f.roundness, dot_diameter_mm);
            f
        })
        .collect();
    out.sort_by(|a, b| {
        let ra = a.roundness < ROUND_ENOUGH;
        let rb = b.roundness < ROUND_ENOUGH;
        b.score
            .total_cmp(&a.score)
            .then(ra.cmp(&rb))
            .then(a.diameter_mm.total_cmp(&b.diameter_mm))
            .then(a.centroid.x.total_cmp(&b.centroid.x))
            .then(a.centroid.y.total_cmp(&b.centroid.y))
            .then(a.centroid.z.total_cmp(&b.centroid.z))
    });
    out
}

/// Bounding-box diagonal of the vertices of valid triangles.
fn mesh_extent(mesh: &TriMesh) -> Option<f64> {
    let n = mesh.vertices.len();
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for t in mesh.triangles.iter().filter(|t| valid_triangle(t, n)) {
        for &i in t {
            let v = mesh.vertices[i as usize];
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo.x <= hi.x).then(|| lo.distance(hi))
}

/// Every closed loop of boundary edges, in no particular order.
///
/// The boundary edges come from [`Topology::of`]: edges used exactly once;
/// twice is interior; three or more times is non-manifold, neither a
/// hole's rim nor interior, and left out (spec 2).
pub fn boundary_loops(mesh: &TriMesh) -> Vec<BoundaryLoop> {
    topology_of(mesh).map_or_else(Vec::new, |t| loops_of(mesh, &t.boundary_edges))
}

/// The closed loops of `edges`, boundary edges of `mesh`.
fn loops_of(mesh: &TriMesh, edges: &[[u32; 2]]) -> Vec<BoundaryLoop> {
    if edges.is_empty() {
        return Vec::new();
    }
    let graph = Graph::new(mesh.vertices.len(), edges);
    let raw = graph.loops(edges);
    raw.into_iter()
        .filter(|l| l.len() >= 3)
        .filter_map(|l| measure(mesh, l))
        .collect()
}

/// Boundary edges as a compressed adjacency list over all vertices.
struct Graph {
    offsets: Vec<u32>,
    incident: Vec<u32>,
}

impl Graph {
    fn new(n: usize, edges: &[[u32; 2]]) -> Graph {
        let Buckets {
            start: offsets,
            items: incident,
        } = Buckets::new(n, || {
            (0u32..)
                .zip(edges)
                .flat_map(|(ei, e)| [(e[0], ei), (e[1], ei)])
        });
        Graph { offsets, incident }
    }

    /// Walks the boundary edges into simple closed loops.
    ///
    /// Dangling chains are peeled off first (they can never close). A walk
    /// that returns to a vertex already on its path closes the loop between
    /// the two visits, which splits loops meeting at a pinch vertex into
    /// simple ones. Every step uses up one edge, so the walk ends.
    fn loops(&self, edges: &[[u32; 2]]) -> Vec<Vec<u32>> {
        const NONE: u32 = u32::MAX;
        let n = self.offsets.len() - 1;
        let mut used = vec![false; edges.len()];
        let mut degree: Vec<u32> = (0..n)
            .map(|v| self.offsets[v + 1] - self.offsets[v])
            .collect();

        let mut stack: Vec<u32> = (0..n as u32).filter(|&v| degree[v as usize] == 1).collect();
        while let Some(v) = stack.pop() {
            for &e in self.edges_of(v) {
                if used[e as usize] {
                    continue;
                }
                used[e as usize] = true;
                let w = other(edges[e as usize], v);
                degree[v as usize] -= 1;
                degree[w as usize] -= 1;
                if degree[w as usize] == 1 {
                    stack.push(w);
                }
            }
        }

        let mut cursor: Vec<u32> = self.offsets[..n].to_vec();
        let mut pos = vec![NONE; n];
        let mut path: Vec<u32> = Vec::new();
        let mut out = Vec::new();
        for start in 0..edges.len() {
            if used[start] {
                continue;
            }
            used[start] = true;
            let [a, b] = edges[start];
            path.clear();
            path.push(a);
            pos[a as usize] = 0;
            let mut cur = b;
            loop {
                let p = pos[cur as usize];
                if p != NONE {
                    let p = p as usize;
                    out.push(path[p..].to_vec());
                    for &v in &path[p + 1..] {
                        pos[v as usize] = NONE;
                    }
                    path.truncate(p + 1);
                } else {
                    pos[cur as usize] = path.len() as u32;
                    path.push(cur);
                }
                match self.next_unused(cur, &mut cursor, &used) {
                    Some(e) => {
                        used[e as usize] = true;
                        cur = other(edges[e as usize], cur);
                    }
                    None => break,
                }
            }
            for &v in &path {
                pos[v as usize] = NONE;
            }
        }
        out
    }

    fn edges_of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.incident[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    fn next_unused(&self, v: u32, cursor: &mut [u32], used: &[bool]) -> Option<u32> {
        let end = self.offsets[v as usize + 1];
        let c = &mut cursor[v as usize];
        while *c < end {
            let e = self.incident[*c as usize];
            if !used[e as usize] {
                return Some(e);
            }
            *c += 1;
        }
        None
    }
}

fn other(e: [u32; 2], v: u32) -> u32 {
    if e[0] == v {
        e[1]
    } else {
        e[0]
    }
}

/// Area centroid of a (possibly non-planar) loop: fan triangles from the
/// vertex mean, each weighted by its signed area projected on the loop's
/// mean plane (the direction of the total vector area), so a concave loop's
/// back-folding triangles subtract as they should and the result does not
/// depend on how densely each side is sampled.
fn measure(mesh: &TriMesh, vertices: Vec<u32>) -> Option<BoundaryLoop> {
    let pts: Vec<DVec3> = vertices
        .iter()
        .map(|&i| mesh.vertices[i as usize])
        .collect();
    let m = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
    let mut vector_area = DVec3::ZERO;
    let mut perimeter_mm = 0.0;
    let (mut lo, mut hi) = (pts[0], pts[0]);
    for (k, &a) in pts.iter().enumerate() {
        let b = pts[(k + 1) % pts.len()];
        vector_area += 0.5 * (a - m).cross(b - m);
        perimeter_mm += a.distance(b);
        lo = lo.min(a);
        hi = hi.max(a);
    }
    let area = vector_area.length();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let normal = vector_area / area;
    let mut weighted = DVec3::ZERO;
    let mut total = 0.0;
    for (k, &a) in pts.iter().enumerate() {
        let b = pts[(k + 1) % pts.len()];
        let w = 0.5 * (a - m).cross(b - m).dot(normal);
        weighted += w * (m + a + b) / 3.0;
        total += w;
    }
    if total <= 0.0 {
        return None;
    }
    Some(BoundaryLoop {
        vertices,
        centroid: weighted / total,
        vector_area,
        perimeter_mm,
        extent_mm: lo.distance(hi),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_with_square_hole() -> TriMesh {
        // 3x3 grid of unit squares, the middle one missing.
        let mut vertices = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                vertices.push(DVec3::new(x as f64, y as f64, 0.0));
            }
        }
        let mut triangles = Vec::new();
        for y in 0..3u32 {
            for x in 0..3u32 {
                if (x, y) == (1, 1) {
                    continue;
                }
                let i = y * 4 + x;
                triangles.push([i, i + 1, i + 5]);
                triangles.push([i, i + 5, i + 4]);
            }
        }
        TriMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn square_hole_loops() {
        let mesh = square_with_square_hole();
        let loops = boundary_loops(&mesh);
        assert_eq!(loops.len(), 2);
        let mut areas: Vec<f64> = loops.iter().map(BoundaryLoop::area_mm2).collect();
        areas.sort_by(f64::total_cmp);
        assert!((areas[0] - 1.0).abs() < 1e-12 && (areas[1] - 9.0).abs() < 1e-12);
        let f = find_fiducials(&mesh);
        assert_eq!(f.len(), 1);
        assert!(f[0].centroid.distance(DVec3::new(1.5, 1.5, 0.0)) < 1e-12);
        assert_eq!(f[0].loop_len, 4);
        assert!((f[0].roundness - std::f64::consts::PI / 4.0).abs() < 1e-12);
    }

    #[test]
    fn empty_and_malformed() {
        assert!(find_fiducials(&TriMesh::default()).is_empty());
        let mesh = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 7], [0, 0, 1], [0, 1, 2]],
        };
        // The one valid triangle is its own outer boundary.
        assert!(find_fiducials(&mesh).is_empty());
        assert_eq!(boundary_loops(&mesh).len(), 1);
    }

    #[test]
    fn pinch_vertex_splits_loops() {
        // The hole's rim plus a fin triangle hanging off one rim vertex by a
        // single vertex: the fin is its own loop sharing the pinch vertex.
        let mut mesh = square_with_square_hole();
        let tip = mesh.vertices.len() as u32;
        mesh.vertices.push(DVec3::new(1.5, 1.5, 1.0));
        mesh.vertices.push(DVec3::new(1.5, 1.2, 1.0));
        mesh.triangles.push([5, tip, tip + 1]);
        let loops = boundary_loops(&mesh);
        assert_eq!(loops.len(), 3, "{loops:?}");
    }
}
