//! The scan's spatial index: which triangles can meet a query box. Every
//! query of the planner (projection, disk cuts, segment hits, footprint
//! heights; spec sections 4, 6 and 7) asks it first and then runs its exact
//! f64 test only on the triangles it names.
//!
//! Two structures, one chosen per scan when it is prepared:
//! - a uniform grid over XY (a "loose" grid: each triangle sits in the one
//!   cell holding the centre of its XY box, each cell keeps the box of its
//!   triangles). Scans are close to height fields with triangles of similar
//!   size, so a footprint query reads a handful of cells by index and drops
//!   most of them on the z range alone: this is what makes planning fast;
//! - parry3d's BVH over Morton-ordered leaves of four triangles, for meshes
//!   a grid suits badly (triangle sizes that vary by orders of magnitude,
//!   many layers stacked over the same XY).
//!
//! Both keep boxes in f32 rounded outward, so they only ever prune: a
//! triangle whose box meets the query box is always visited.

use glam::{DVec2, DVec3, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhNode};

use crate::mesh::TriMesh;

/// Which spatial index a [`super::Surface`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpatialIndex {
    /// The grid when the scan suits it, else the BVH (the default).
    #[default]
    Auto,
    /// The uniform XY grid, whatever the scan (tests and benchmarks).
    Grid,
    /// parry3d's BVH, whatever the scan.
    Bvh,
}

/// A query box in f64 (either bound may be infinite).
#[derive(Clone, Copy, Debug)]
pub(super) struct QueryBox {
    pub lo: DVec3,
    pub hi: DVec3,
}

/// An f32 box rounded outward: lo xyz, hi xyz.
pub(super) type Box32 = [f32; 6];

impl QueryBox {
    #[inline]
    fn hits(&self, b: &Box32) -> bool {
        (b[2] as f64) <= self.hi.z
            && (b[5] as f64) >= self.lo.z
            && (b[0] as f64) <= self.hi.x
            && (b[3] as f64) >= self.lo.x
            && (b[1] as f64) <= self.hi.y
            && (b[4] as f64) >= self.lo.y
    }

    #[inline]
    fn hits_node(&self, node: &BvhNode) -> bool {
        let (mins, maxs) = (node.mins(), node.maxs());
        (mins.x as f64) <= self.hi.x
            && (maxs.x as f64) >= self.lo.x
            && (mins.y as f64) <= self.hi.y
            && (maxs.y as f64) >= self.lo.y
            && (mins.z as f64) <= self.hi.z
            && (maxs.z as f64) >= self.lo.z
    }
}

/// f64 -> f32 rounded towards -inf / +inf, so an f32 box always contains
/// the f64 triangle.
fn f32_down(v: f64) -> f32 {
    let f = v as f32;
    if f as f64 > v {
        f.next_down()
    } else {
        f
    }
}

fn f32_up(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v {
        f.next_up()
    } else {
        f
    }
}

fn box32(lo: DVec3, hi: DVec3) -> Box32 {
    [
        f32_down(lo.x),
        f32_down(lo.y),
        f32_down(lo.z),
        f32_up(hi.x),
        f32_up(hi.y),
        f32_up(hi.z),
    ]
}

fn triangle_box(mesh: &TriMesh, i: usize) -> (DVec3, DVec3) {
    let [a, b, c] = mesh.triangle(i);
    (a.min(b).min(c), a.max(b).max(c))
}

pub(super) enum Index {
    Grid(Grid),
    Bvh(BvhIndex),
}

impl Index {
    /// Builds the index `kind` asks for over a non-empty mesh with finite
    /// vertices and valid indices (the caller checks).
    pub fn build(mesh: &TriMesh, bbox: (DVec3, DVec3), kind: SpatialIndex) -> Index {
        match kind {
            SpatialIndex::Bvh => Index::Bvh(BvhIndex::build(mesh, bbox)),
            SpatialIndex::Grid => Index::Grid(Grid::build(mesh, bbox, false).expect("forced")),
            SpatialIndex::Auto => match Grid::build(mesh, bbox, true) {
                Some(g) => Index::Grid(g),
                None => Index::Bvh(BvhIndex::build(mesh, bbox)),
            },
        }
    }

    pub fn kind(&self) -> SpatialIndex {
        match self {
            Index::Grid(_) => SpatialIndex::Grid,
            Index::Bvh(_) => SpatialIndex::Bvh,
        }
    }

    /// Calls `f` with every triangle whose box meets `q` (and maybe a few
    /// more), each once.
    #[inline]
    pub fn visit(&self, q: &QueryBox, f: impl FnMut(usize)) {
        self.visit_pruned(q, |_| true, f)
    }

    /// [`Self::visit`], leaving out the triangles of the grid's cells
    /// whose box (lo x, lo y, lo z, hi x, hi y, hi z; holding every
    /// triangle of the cell) `keep` refuses. The triangles still come in
    /// the index's order.
    #[inline]
    pub fn visit_pruned(&self, q: &QueryBox, keep: impl Fn(&Box32) -> bool, f: impl FnMut(usize)) {
        match self {
            Index::Grid(g) => g.visit(q, keep, f),
            Index::Bvh(b) => b.visit(q, f),
        }
    }
}

/// The uniform XY grid (see the module comment).
pub(super) struct Grid {
    origin: DVec2,
    /// 1 / the cell's size in x and y (cells take the triangles' aspect).
    inv_cell: DVec2,
    nx: usize,
    ny: usize,
    /// Cell c holds `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// The top of each item's triangle (f32 rounded up), beside `items`:
    /// most triangles of a cell that a footprint query reads lie below it,
    /// and are passed over without reading their vertices.
    tops: Vec<f32>,
    /// The z range of each cell's triangles (lo > hi when it has none),
    /// apart from their XY box: a footprint query drops most cells on z.
    zs: Vec<[f32; 2]>,
    /// The XY box of each cell's triangles: lo x, lo y, hi x, hi y.
    xys: Vec<[f32; 4]>,
    /// How far a triangle's box reaches out of its home cell, at most, in x
    /// and in y.
    reach: DVec2,
    /// The z range of each block of BLOCK x BLOCK cells (row-major, `bnx`
    /// blocks to a row): one test drops a block's cells from a query.
    block_zs: Vec<[f32; 2]>,
    bnx: usize,
    /// Triangles wider than 1.5 cells in X or Y, tested by their own box.
    big: Vec<(u32, Box32)>,
}

/// Cells per side of a block (see [`Grid::block_zs`]).
const BLOCK: usize = 4;

/// Largest grid, in cells.
const MAX_CELLS: usize = 1 << 22;

/// In `Auto`, the grid is refused when a triangle's cell holds this many
/// triangles on average (stacked layers, walls), or when more than
/// 1/`MAX_BIG_SHARE` of the triangles are too wide for their cell.
const MAX_MEAN_OCCUPANCY: f64 = 48.0;
const MAX_BIG_SHARE: usize = 64;

impl Grid {
    /// The grid over `mesh`, or `None` when `picky` and the mesh suits a
    /// grid badly.
    fn build(mesh: &TriMesh, bbox: (DVec3, DVec3), picky: bool) -> Option<Grid> {
        let n = mesh.triangles.len();
        // Triangle boxes are recomputed where needed rather than stored: a
        // 2 M triangle scan's boxes would add 96 MB to the peak.
        let ext = (bbox.1 - bbox.0).truncate().max(DVec2::splat(1e-9));
        // About nine triangles to a cell on a height field (the fewest
        // instructions per footprint query on W1 among 2, 4.5, 9, 16 and
        // 36), never a cell narrower than the typical triangle in either
        // direction (the upper quartile of the widths of up to 65,536
        // evenly spread triangles): cells take the triangles' aspect, so a
        // line scanner's grid, fine across its lines and coarse along its
        // travel, still gets a few triangles to a cell.
        let stride = n.div_ceil(1 << 16).max(1);
        let (mut wx, mut wy): (Vec<f64>, Vec<f64>) = (0..n)
            .step_by(stride)
            .map(|i| {
                let (lo, hi) = triangle_box(mesh, i);
                (hi.x - lo.x, hi.y - lo.y)
            })
            .unzip();
        let upper = |w: &mut Vec<f64>| {
            let k = w.len() * 3 / 4;
            (*w.select_nth_unstable_by(k, f64::total_cmp).1).max(1e-9)
        };
        let (qx, qy) = (upper(&mut wx), upper(&mut wy));
        drop((wx, wy));
        // A cell of area 9 A / n with the quartiles' aspect, grown to them.
        let aspect = (qx / qy).clamp(1e-3, 1e3);
        let side = 3.0 * (ext.x * ext.y / n as f64 / aspect).sqrt();
        let mut cell = DVec2::new((side * aspect).max(qx), side.max(qy));
        let dims = |cell: DVec2| {
            (
                ((ext.x / cell.x).ceil() as usize).max(1),
                ((ext.y / cell.y).ceil() as usize).max(1),
            )
        };
        let max_cells = (2 * n).clamp(1, MAX_CELLS);
        let (mut nx, mut ny) = dims(cell);
        while nx.saturating_mul(ny) > max_cells {
            cell *= 1.25;
            (nx, ny) = dims(cell);
        }
        let origin = bbox.0.truncate();
        let inv_cell = DVec2::ONE / cell;
        // One pass over the triangles: each one's home cell (where its box's
        // centre lies), counted for the sort, and the cells' z ranges, XY
        // boxes and the reach out of them, so no triangle's box is found
        // twice. A cell's f32 bound is rounded outwards from the f64 value
        // only when that value extends it: the same bits as rounding every
        // triangle's box (the rounding is monotone).
        let wide = 1.5 * cell;
        let mut home = vec![u32::MAX; n];
        // Each triangle's top, found with its box, for `tops`.
        let mut top = vec![0f32; n];
        let mut count = vec![0u32; nx * ny + 1];
        let mut big = Vec::new();
        let mut zs = vec![[f32::INFINITY, f32::NEG_INFINITY]; nx * ny];
        let mut xys = vec![
            [
                f32::INFINITY,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NEG_INFINITY
            ];
            nx * ny
        ];
        let mut reach = DVec2::ZERO;
        for (i, (slot, top)) in home.iter_mut().zip(&mut top).enumerate() {
            let (lo, hi) = triangle_box(mesh, i);
            *top = f32_up(hi.z);
            if hi.x - lo.x > wide.x || hi.y - lo.y > wide.y {
                big.push((i as u32, box32(lo, hi)));
                continue;
            }
            let mid = 0.5 * (lo.truncate() + hi.truncate());
            let cx = (((mid.x - origin.x) * inv_cell.x) as usize).min(nx - 1);
            let cy = (((mid.y - origin.y) * inv_cell.y) as usize).min(ny - 1);
            let c = cy * nx + cx;
            *slot = c as u32;
            count[c + 1] += 1;
            let (z, xy) = (&mut zs[c], &mut xys[c]);
            if lo.z < z[0] as f64 {
                z[0] = f32_down(lo.z);
            }
            if hi.z > z[1] as f64 {
                z[1] = f32_up(hi.z);
            }
            if lo.x < xy[0] as f64 {
                xy[0] = f32_down(lo.x);
            }
            if lo.y < xy[1] as f64 {
                xy[1] = f32_down(lo.y);
            }
            if hi.x > xy[2] as f64 {
                xy[2] = f32_up(hi.x);
            }
            if hi.y > xy[3] as f64 {
                xy[3] = f32_up(hi.y);
            }
            let cell_lo = origin + DVec2::new(cx as f64, cy as f64) * cell;
            let cell_hi = cell_lo + cell;
            let out = (cell_lo - lo.truncate()).max(hi.truncate() - cell_hi);
            reach = reach.max(out);
        }
        if picky && big.len() > (n / MAX_BIG_SHARE).max(64) {
            return None;
        }
        if picky {
            // The mean number of cell-mates a triangle has.
            let sq: f64 = count.iter().map(|&c| c as f64 * c as f64).sum();
            let placed = (n - big.len()).max(1) as f64;
            if sq / placed > MAX_MEAN_OCCUPANCY {
                return None;
            }
        }
        // Counting sort of the triangles by cell, in index order within one.
        for c in 1..count.len() {
            count[c] += count[c - 1];
        }
        let start = count.clone();
        let mut items = vec![0u32; n - big.len()];
        let mut tops = vec![0f32; n - big.len()];
        for (i, &c) in home.iter().enumerate() {
            if c == u32::MAX {
                continue;
            }
            let c = c as usize;
            let k = count[c] as usize;
            items[k] = i as u32;
            tops[k] = top[i];
            count[c] += 1;
        }
        drop(top);
        drop(home);
        // Rounding in the home cell's index: a hair more.
        let reach = reach * (1.0 + 1e-9) + 1e-9 * cell;
        let bnx = nx.div_ceil(BLOCK);
        let mut block_zs = vec![[f32::INFINITY, f32::NEG_INFINITY]; bnx * ny.div_ceil(BLOCK)];
        for (c, z) in zs.iter().enumerate() {
            let b = &mut block_zs[(c / nx / BLOCK) * bnx + (c % nx) / BLOCK];
            b[0] = b[0].min(z[0]);
            b[1] = b[1].max(z[1]);
        }
        Some(Grid {
            origin,
            inv_cell,
            nx,
            ny,
            start,
            items,
            tops,
            zs,
            xys,
            reach,
            block_zs,
            bnx,
            big,
        })
    }

    /// The cell range (inclusive) whose triangles can reach into the
    /// coordinate range [lo, hi].
    #[inline]
    fn range(
        &self,
        lo: f64,
        hi: f64,
        origin: f64,
        n: usize,
        reach: f64,
        inv_cell: f64,
    ) -> Option<(usize, usize)> {
        // The cells' indices are the floors of these, but no `floor` is
        // taken: it is a call to libm on x86-64 without SSE4.1 (four a
        // query, 1.5 M on W3: 0.8 % of its instructions), and for the tests
        // and conversions here truncation does as well. floor(b) >= 0
        // exactly when b >= 0, floor(a) <= n - 1 exactly when a < n (n is
        // far below 2^53), and `as usize` truncates a non-negative value,
        // which is its floor (saturating past usize, as the floor did).
        let a = (lo - reach - origin) * inv_cell;
        let b = (hi + reach - origin) * inv_cell;
        // NaN fails both tests and so visits nothing.
        if !(b >= 0.0 && a < n as f64) {
            return None;
        }
        Some((a.max(0.0) as usize, (b as usize).min(n - 1)))
    }

    #[inline]
    fn visit(&self, q: &QueryBox, keep: impl Fn(&Box32) -> bool, mut f: impl FnMut(usize)) {
        for (i, b) in &self.big {
            if q.hits(b) {
                f(*i as usize);
            }
        }
        let Some((x0, x1)) = self.range(
            q.lo.x,
            q.hi.x,
            self.origin.x,
            self.nx,
            self.reach.x,
            self.inv_cell.x,
        ) else {
            return;
        };
        let Some((y0, y1)) = self.range(
            q.lo.y,
            q.hi.y,
            self.origin.y,
            self.ny,
            self.reach.y,
            self.inv_cell.y,
        ) else {
            return;
        };
        // Row by row (the order the exact tests sum in stays fixed), a
        // block's run of cells in the row skipped on the block's z range.
        let z_out = |z: &[f32; 2]| (z[0] as f64) > q.hi.z || (z[1] as f64) < q.lo.z;
        for cy in y0..=y1 {
            let row = cy * self.nx;
            let brow = (cy / BLOCK) * self.bnx;
            for bx in x0 / BLOCK..=x1 / BLOCK {
                if z_out(&self.block_zs[brow + bx]) {
                    continue;
                }
                let cx0 = x0.max(bx * BLOCK);
                let cx1 = x1.min(bx * BLOCK + BLOCK - 1);
                for c in row + cx0..=row + cx1 {
                    self.visit_cell(c, q, &keep, &mut f);
                }
            }
        }
    }

    #[inline]
    fn visit_cell(
        &self,
        c: usize,
        q: &QueryBox,
        keep: &impl Fn(&Box32) -> bool,
        f: &mut impl FnMut(usize),
    ) {
        let [zlo, zhi] = self.zs[c];
        if (zlo as f64) > q.hi.z || (zhi as f64) < q.lo.z {
            return;
        }
        let [xlo, ylo, xhi, yhi] = self.xys[c];
        if (xlo as f64) > q.hi.x
            || (xhi as f64) < q.lo.x
            || (ylo as f64) > q.hi.y
            || (yhi as f64) < q.lo.y
        {
            return;
        }
        if !keep(&[xlo, ylo, zlo, xhi, yhi, zhi]) {
            return;
        }
        let (s, e) = (self.start[c] as usize, self.start[c + 1] as usize);
        for (&i, &top) in self.items[s..e].iter().zip(&self.tops[s..e]) {
            if top as f64 >= q.lo.z {
                f(i as usize);
            }
        }
    }
}

/// Triangles per BVH leaf.
const LEAF_SIZE: usize = 4;

/// parry3d's BVH over Morton-ordered leaves of [`LEAF_SIZE`] triangles.
pub(super) struct BvhIndex {
    bvh: Bvh,
    /// Triangle indices in leaf order: leaf k holds
    /// `order[k * LEAF_SIZE..][..LEAF_SIZE]`.
    order: Vec<u32>,
}

/// Interleaves the low 21 bits of x, y and z (a Morton / Z-order code).
fn morton3(x: u64, y: u64, z: u64) -> u64 {
    fn spread(v: u64) -> u64 {
        let mut v = v & 0x1f_ffff;
        v = (v | v << 32) & 0x1f_0000_0000_ffff;
        v = (v | v << 16) & 0x1f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        (v | v << 2) & 0x1249_2492_4924_9249
    }
    spread(x) | spread(y) << 1 | spread(z) << 2
}

impl BvhIndex {
    fn build(mesh: &TriMesh, bbox: (DVec3, DVec3)) -> BvhIndex {
        // Triangles in Morton order of their centroids, LEAF_SIZE to a BVH
        // leaf: a quarter of the leaves to build over (parry's binned build
        // dominates loading a 2 M triangle scan), each leaf still compact
        // whatever order the file listed its triangles in.
        let extent = (bbox.1 - bbox.0).max(DVec3::splat(1e-12));
        let mut keyed: Vec<(u64, u32)> = (0..mesh.triangles.len())
            .map(|i| {
                let [a, b, c] = mesh.triangle(i);
                let q = ((a + b + c) / 3.0 - bbox.0) / extent * 2_097_151.0;
                (morton3(q.x as u64, q.y as u64, q.z as u64), i as u32)
            })
            .collect();
        keyed.sort_unstable_by_key(|&(k, _)| k);
        let order: Vec<u32> = keyed.into_iter().map(|(_, i)| i).collect();
        let leaves: Vec<Aabb> = order
            .chunks(LEAF_SIZE)
            .map(|chunk| {
                let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for &i in chunk {
                    let (a, b) = triangle_box(mesh, i as usize);
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                let b = box32(lo, hi);
                Aabb::new(Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]))
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        BvhIndex { bvh, order }
    }

    #[inline]
    fn visit(&self, q: &QueryBox, mut f: impl FnMut(usize)) {
        for leaf in self.bvh.leaves(|n| q.hits_node(n)) {
            let start = (leaf as usize * LEAF_SIZE).min(self.order.len());
            let end = (start + LEAF_SIZE).min(self.order.len());
            for &i in &self.order[start..end] {
                f(i as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator for the tests.
    struct Lcg(u64);
    impl Lcg {
        fn f(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Random triangles of sizes over three orders of magnitude, some
    /// vertical, some spanning the whole mesh.
    fn soup(seed: u64, n: usize) -> TriMesh {
        let mut r = Lcg(seed);
        let mut m = TriMesh::default();
        for i in 0..n {
            let size = match i % 10 {
                0 => 20.0 * r.f(),
                1..=3 => 2.0 * r.f(),
                _ => 0.2 * r.f(),
            };
            let c = DVec3::new(20.0 * r.f() - 5.0, 10.0 * r.f(), 3.0 * r.f());
            let k = m.vertices.len() as u32;
            for _ in 0..3 {
                let mut v = c + size * DVec3::new(r.f() - 0.5, r.f() - 0.5, r.f() - 0.5);
                if i % 7 == 0 {
                    v.x = c.x; // a vertical triangle: no XY area
                }
                m.vertices.push(v);
            }
            m.triangles.push([k, k + 1, k + 2]);
        }
        m
    }

    /// Every triangle whose box meets `q`, by the surface's own exact box
    /// test, over all triangles.
    fn brute(mesh: &TriMesh, q: &QueryBox) -> Vec<usize> {
        (0..mesh.triangles.len())
            .filter(|&i| crate::surface::meets(&mesh.triangle(i), q))
            .collect()
    }

    #[test]
    fn both_indexes_visit_every_triangle_whose_box_meets_the_query_once() {
        for seed in 1..6 {
            let mesh = soup(seed, 3000);
            let bbox = mesh.bbox().unwrap();
            let mut r = Lcg(seed * 77);
            for kind in [SpatialIndex::Grid, SpatialIndex::Bvh] {
                let index = Index::build(&mesh, bbox, kind);
                assert_eq!(index.kind(), kind);
                for k in 0..300 {
                    let c = DVec3::new(24.0 * r.f() - 7.0, 14.0 * r.f() - 2.0, 4.0 * r.f() - 0.5);
                    let h = DVec3::new(r.f(), r.f(), r.f()) * if k % 3 == 0 { 5.0 } else { 0.3 };
                    let mut q = QueryBox {
                        lo: c - h,
                        hi: c + h,
                    };
                    match k % 5 {
                        0 => (q.lo.z, q.hi.z) = (f64::NEG_INFINITY, f64::INFINITY),
                        1 => q.hi = q.lo, // a point
                        2 => q.hi.z = f64::INFINITY,
                        _ => {}
                    }
                    let mut seen = vec![0u8; mesh.triangles.len()];
                    index.visit(&q, |i| seen[i] += 1);
                    for i in brute(&mesh, &q) {
                        assert!(seen[i] > 0, "{kind:?} seed {seed} query {k}: missed {i}");
                    }
                    assert!(seen.iter().all(|&s| s <= 1), "{kind:?}: a triangle twice");
                }
            }
        }
    }

    #[test]
    fn nan_and_far_queries_visit_nothing() {
        let mesh = soup(9, 500);
        let bbox = mesh.bbox().unwrap();
        let index = Index::build(&mesh, bbox, SpatialIndex::Grid);
        for (lo, hi) in [
            (DVec3::splat(f64::NAN), DVec3::splat(f64::NAN)),
            (DVec3::splat(1e300), DVec3::splat(1e301)),
            (DVec3::splat(-1e301), DVec3::splat(-1e300)),
        ] {
            let mut n = 0;
            index.visit(&QueryBox { lo, hi }, |_| n += 1);
            assert_eq!(n, 0);
        }
    }

    #[test]
    fn auto_picks_the_grid_for_a_height_field_and_the_bvh_for_a_soup() {
        let axis: Vec<f64> = (0..=50).map(|i| i as f64 * 0.1).collect();
        let film = TriMesh::height_field(&axis, &axis, |x, y| (x * 3.0).sin() + y);
        let b = film.bbox().unwrap();
        assert_eq!(
            Index::build(&film, b, SpatialIndex::Auto).kind(),
            SpatialIndex::Grid
        );
        // Every triangle spanning the whole XY range: no grid helps.
        let mut wide = TriMesh::default();
        for k in 0..200 {
            let z = k as f64 * 0.01;
            let v = wide.vertices.len() as u32;
            wide.vertices.extend([
                DVec3::new(0.0, 0.0, z),
                DVec3::new(10.0, 0.0, z),
                DVec3::new(0.0, 10.0, z),
            ]);
            wide.triangles.push([v, v + 1, v + 2]);
        }
        let b = wide.bbox().unwrap();
        assert_eq!(
            Index::build(&wide, b, SpatialIndex::Auto).kind(),
            SpatialIndex::Bvh
        );
    }
}
