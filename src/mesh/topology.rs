//! The scan's topology in one pass over its edges: which edges are
//! boundary edges (the fiducial holes' rims, spec section 2) and which
//! triangle owns each corner and edge (the swept query tries each once,
//! `surface/sweep.rs`).
//!
//! Both come from the same grouping: every triangle's edge `k` (from corner
//! `k` to `k + 1`) is bucketed by its lower vertex ([`Buckets`], a counting
//! sort, O(n)), and each bucket is sorted by the higher vertex, then by
//! triangle. A run of equal higher vertices is one undirected edge:
//! its first entry is the lowest-numbered triangle holding it, the edge's
//! owner, and a run of one valid triangle is a boundary edge. The pass was
//! two (the fiducials' and the surface's), each bucketing all 6 M edge ends
//! of a 2 M triangle scan (issue 15).

use super::buckets::Buckets;
use super::TriMesh;

/// The most triangles [`Topology::of`] takes: each edge is numbered
/// `3 t + k` in 32 bits. Importers keep far fewer
/// ([`super::MAX_TRIANGLES`]).
pub const MAX_TOPOLOGY_TRIANGLES: usize = (u32::MAX / 3) as usize;

/// What [`Topology::of`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topology {
    /// Per triangle, which of its corners (bits 0-2) and edges (bits 3-5,
    /// edge k from corner k to k + 1) it owns: the lowest-numbered
    /// triangle holding a vertex or an edge owns it.
    pub owned: Vec<u8>,
    /// The edges used by exactly one valid triangle (indices in range,
    /// three distinct), each as (lower, higher) vertex, ordered by lower
    /// then higher vertex. Edges of three or more triangles (non-manifold)
    /// are neither boundary nor interior and are not listed (spec 2).
    pub boundary_edges: Vec<[u32; 2]>,
}

/// Whether a triangle's indices are in range for `n` vertices and distinct:
/// the fiducials count only such triangles' edges.
pub(crate) fn valid_triangle(t: &[u32; 3], n: usize) -> bool {
    in_range(t, n) && distinct(t)
}

/// Whether a triangle's indices are all below `n`: only such triangles own
/// or bound anything.
fn in_range(t: &[u32; 3], n: usize) -> bool {
    t.iter().all(|&i| (i as usize) < n)
}

impl Topology {
    /// The topology of `mesh`. Triangles with an index out of range own
    /// nothing and bound nothing. `mesh` has at most
    /// [`MAX_TOPOLOGY_TRIANGLES`] triangles (callers check; past it, this
    /// panics).
    pub fn of(mesh: &TriMesh) -> Topology {
        Topology::build::<true>(mesh)
    }

    /// [`Topology::of`] without the boundary edges (left empty): the
    /// owners alone, all a surface needs when no fiducial hole is looked
    /// for (`pcpp plan` without `auto` fiducials: the count of each edge's
    /// valid triangles is then not taken).
    pub fn owners(mesh: &TriMesh) -> Topology {
        Topology::build::<false>(mesh)
    }

    fn build<const BOUNDARY: bool>(mesh: &TriMesh) -> Topology {
        let n = mesh.vertices.len();
        let tris = &mesh.triangles;
        assert!(
            tris.len() <= MAX_TOPOLOGY_TRIANGLES,
            "Topology::of takes at most {MAX_TOPOLOGY_TRIANGLES} triangles"
        );
        let mut owned = vec![0u8; tris.len()];

        // A vertex's owner: the first triangle to hold it. (And whether
        // every in-range triangle has three distinct corners, as nearly
        // every scan's do: then no edge needs its triangle checked again.)
        let mut seen = vec![0u64; n.div_ceil(64)];
        let mut all_valid = true;
        for (t, tri) in tris.iter().enumerate().filter(|(_, t)| in_range(t, n)) {
            all_valid &= distinct(tri);
            for (k, &v) in tri.iter().enumerate() {
                let (word, bit) = (v as usize / 64, 1u64 << (v % 64));
                if seen[word] & bit == 0 {
                    seen[word] |= bit;
                    owned[t] |= 1 << k;
                }
            }
        }
        drop(seen);

        // Edge `k` of triangle `t` is `3 t + k`, bucketed by its lower end,
        // in edge order within a bucket (the counting sort keeps it).
        let by_lower = edges_by_lower(n, tris);
        let mut boundary_edges = Vec::new();
        // A bucket's edges' higher ends and whether their triangles are
        // valid; all valid when every triangle is.
        let mut his = [0u32; SMALL_RUN];
        let mut valid = [true; SMALL_RUN];
        let mut run: Vec<(u32, u32, bool)> = Vec::new();
        for lo in 0..n as u32 {
            let edges = by_lower.get(lo);
            if edges.len() > SMALL_RUN {
                let boundary = BOUNDARY.then_some(&mut boundary_edges);
                big_run(lo, edges, (tris, n), &mut run, &mut owned, boundary);
                continue;
            }
            for (j, &e) in edges.iter().enumerate() {
                let tri = &tris[e as usize / 3];
                let k = e as usize % 3;
                his[j] = tri[k].max(tri[if k == 2 { 0 } else { k + 1 }]);
                if !all_valid {
                    valid[j] = distinct(tri);
                }
            }
            // An edge's first entry is its lowest-numbered triangle, the
            // owner; an edge of exactly one valid triangle is a boundary
            // edge. (A few entries a bucket: comparing them all costs less
            // than sorting them.)
            let listed = boundary_edges.len();
            let m = edges.len();
            'entries: for j in 0..m {
                let hi = his[j];
                for &earlier in &his[..j] {
                    if earlier == hi {
                        continue 'entries;
                    }
                }
                let e = edges[j];
                owned[e as usize / 3] |= 8 << (e % 3);
                if !BOUNDARY {
                    continue;
                }
                let mut holders = 0;
                for i in j..m {
                    holders += usize::from(his[i] == hi && valid[i]);
                }
                if holders == 1 {
                    boundary_edges.push([lo, hi]);
                }
            }
            // Listed by lower, then higher end.
            if boundary_edges.len() > listed + 1 {
                boundary_edges[listed..].sort_unstable();
            }
        }
        Topology {
            owned,
            boundary_edges,
        }
    }
}

/// The most edges at a vertex [`Topology::of`] compares pairwise; a
/// vertex with more (a fan's centre, a cloud's mesh) has its edges sorted
/// ([`big_run`]).
const SMALL_RUN: usize = 16;

/// Whether a triangle's corners are distinct (an in-range one is then
/// valid, [`valid_triangle`]).
fn distinct(t: &[u32; 3]) -> bool {
    t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
}

/// [`Topology::of`] for the edges of a bucket too large to compare
/// pairwise: sorted by (higher end, edge), a run of equal higher ends is
/// one undirected edge, its first entry the owner.
/// The mesh is given as its triangles and vertex count; `boundary_edges`
/// only where the boundary edges are wanted.
fn big_run(
    lo: u32,
    edges: &[u32],
    (tris, n): (&[[u32; 3]], usize),
    run: &mut Vec<(u32, u32, bool)>,
    owned: &mut [u8],
    mut boundary_edges: Option<&mut Vec<[u32; 2]>>,
) {
    run.clear();
    run.extend(edges.iter().map(|&e| {
        let tri = &tris[e as usize / 3];
        let k = e as usize % 3;
        (tri[k].max(tri[(k + 1) % 3]), e, valid_triangle(tri, n))
    }));
    run.sort_unstable_by_key(|&(hi, e, _)| (hi, e));
    for edge in run.chunk_by(|a, b| a.0 == b.0) {
        let (hi, first, _) = edge[0];
        owned[first as usize / 3] |= 8 << (first % 3);
        let Some(boundary_edges) = boundary_edges.as_deref_mut() else {
            continue;
        };
        let mut valid = edge.iter().filter(|&&(_, _, valid)| valid);
        if valid.next().is_some() && valid.next().is_none() {
            boundary_edges.push([lo, hi]);
        }
    }
}

/// Every in-range triangle's edges (`3 t + k`), bucketed by their lower
/// end, in a plain loop ([`Buckets::group`]): the scan's largest grouping,
/// 6 M edges for 2 M triangles.
fn edges_by_lower(n: usize, tris: &[[u32; 3]]) -> Buckets {
    Buckets::group(n, |emit| {
        for (e, t) in (0u32..).step_by(3).zip(tris) {
            if in_range(t, n) {
                emit(t[0].min(t[1]), e);
                emit(t[1].min(t[2]), e + 1);
                emit(t[2].min(t[0]), e + 2);
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// What the two passes this one replaced computed, by brute force:
    /// owners as the first triangle holding the vertex or both ends of the
    /// edge, boundary edges as those of exactly one valid triangle.
    fn by_brute_force(mesh: &TriMesh) -> Topology {
        let n = mesh.vertices.len();
        let tris = &mesh.triangles;
        let in_range = |t: &[u32; 3]| t.iter().all(|&i| (i as usize) < n);
        let mut owned = vec![0u8; tris.len()];
        for (t, tri) in tris.iter().enumerate().filter(|(_, t)| in_range(t)) {
            for k in 0..3 {
                let holds = |u: &[u32; 3], v: u32| in_range(u) && u.contains(&v);
                if !tris[..t].iter().any(|u| holds(u, tri[k])) {
                    owned[t] |= 1 << k;
                }
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let edge_of = |u: &[u32; 3]| {
                    (0..3).any(|m| {
                        let (c, d) = (u[m], u[(m + 1) % 3]);
                        (c.min(d), c.max(d)) == (a.min(b), a.max(b))
                    })
                };
                if !tris[..t].iter().any(|u| in_range(u) && edge_of(u)) {
                    owned[t] |= 8 << k;
                }
            }
        }
        let mut count = std::collections::BTreeMap::new();
        for tri in tris.iter().filter(|t| valid_triangle(t, n)) {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                *count.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
            }
        }
        let boundary_edges = count
            .into_iter()
            .filter(|&(_, c)| c == 1)
            .map(|(e, _)| e)
            .collect();
        Topology {
            owned,
            boundary_edges,
        }
    }

    #[test]
    fn one_pass_finds_the_owners_and_boundary_the_brute_force_finds() {
        // A 6 x 6 grid of squares with one square missing (a hole), a
        // fin on one edge (non-manifold), a triangle with an index past the
        // vertices and one with a repeated index.
        let mut m = TriMesh::default();
        for j in 0..7 {
            for i in 0..7 {
                m.vertices.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        for j in 0..6u32 {
            for i in 0..6u32 {
                if (i, j) == (2, 3) {
                    continue;
                }
                let a = j * 7 + i;
                // Alternate the diagonal, and the corners' order, so edges
                // run both ways.
                if (i + j) % 2 == 0 {
                    m.triangles.push([a, a + 1, a + 8]);
                    m.triangles.push([a + 8, a + 7, a]);
                } else {
                    m.triangles.push([a + 1, a + 8, a + 7]);
                    m.triangles.push([a, a + 1, a + 7]);
                }
            }
        }
        m.vertices.push(DVec3::new(0.5, 0.0, 1.0));
        m.vertices.push(DVec3::new(0.5, 0.0, -1.0));
        m.triangles.push([0, 1, 49]);
        m.triangles.push([1, 0, 50]);
        m.triangles.push([3, 4, 99]);
        m.triangles.push([5, 5, 12]);
        let got = Topology::of(&m);
        assert_eq!(got, by_brute_force(&m));
        assert_eq!(Topology::owners(&m).owned, got.owned);
        // The grid's rim (24 edges) but edge 0-1, which the grid and the
        // two fins hold (non-manifold, not listed); the hole (4); the fins'
        // free edges (4).
        assert_eq!(got.boundary_edges.len(), 23 + 4 + 4);
        assert!(!got.boundary_edges.contains(&[0, 1]));
        // The out-of-range triangle owns nothing.
        assert_eq!(got.owned[m.triangles.len() - 2], 0);
    }

    /// A vertex with more edges than are compared pairwise (a fan's
    /// centre: sorted instead), with and without an invalid triangle
    /// elsewhere, and a mesh whose triangles are all valid.
    #[test]
    fn fans_and_all_valid_meshes_agree_with_the_brute_force() {
        for (spokes, bad) in [(5, false), (SMALL_RUN + 7, false), (SMALL_RUN + 7, true)] {
            let mut m = TriMesh::default();
            m.vertices.push(DVec3::ZERO);
            for i in 0..spokes {
                let a = i as f64 / spokes as f64 * std::f64::consts::TAU;
                m.vertices.push(DVec3::new(a.cos(), a.sin(), 0.0));
            }
            let s = spokes as u32;
            // The fan, one spoke left open (a boundary through the centre),
            // each wedge twice in a row: a doubled edge at every spoke.
            for i in 1..s {
                m.triangles.push([0, i, i + 1]);
                if i % 3 == 0 {
                    m.triangles.push([i + 1, 0, i]);
                }
            }
            if bad {
                m.triangles.push([1, 2, 2]);
            }
            let got = Topology::of(&m);
            assert_eq!(got, by_brute_force(&m), "{spokes} spokes, bad {bad}");
            assert!(!got.boundary_edges.is_empty());
            let owners = Topology::owners(&m);
            assert_eq!(owners.owned, got.owned);
            assert!(owners.boundary_edges.is_empty());
        }
    }
}
