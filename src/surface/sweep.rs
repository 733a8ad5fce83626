//! The nozzle swept along a straight move (spec section 6f): the stage
//! moves in straight lines, so safety is a property of every move, not of
//! the planned points.
//!
//! The question asked of a move from `a` to `b` (tip positions, the tip
//! height varying linearly) is the one CAM's drop-cutter asks of a
//! flat-end cutter, asked along the whole move at once: over every
//! position of the tip on the move, how far does the tip stay above the
//! highest surface point within `radius` of its axis in XY? This is the
//! smallest value of `z(s) - q_z` over every pair (s, q) of a fraction s of
//! the move and a surface point q with |q_xy - p_xy(s)| <= radius.
//!
//! It is computed exactly, triangle by triangle. For one triangle and a
//! fixed s, the highest point of the triangle inside the disk lies at a
//! corner inside the disk, where an edge crosses the circle, or where the
//! circle meets the plane's steepest ascent (inside the triangle). As s
//! runs over [0, 1]:
//! - a corner stays inside the disk over an interval of s, and z(s) is
//!   linear, so its worst s is an end of that interval;
//! - the steepest-ascent point moves in a straight line, so the s over
//!   which it lies in the triangle form an interval, over which the gap is
//!   linear: again an end;
//! - an edge crossing is a point (t, s) on the boundary of the ellipse
//!   |e(t) - p(s)| <= radius in the (t, s) square, where the gap is
//!   linear in (t, s): its minimum lies on the square's sides (a corner's
//!   interval, or the chord of the edge at s = 0 or s = 1) or at the one
//!   point of the ellipse where the gap's gradient is normal to it, which
//!   has a closed form.
//!
//! So the few candidates per triangle contain the exact minimum; only
//! rounding (about 1e-12 mm) separates the result from it, and the coverage
//! tests take a relative hair of slack so that rounding can only make the
//! gap smaller. Vertical triangles need no facet term: their highest point
//! over any XY region lies on their edges.

use glam::{DVec2, DVec3};

use super::index::QueryBox;
use super::{meets, Surface};

/// The smallest gap of a move (see the module comment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepGap {
    /// The smallest height of the tip over the highest surface point
    /// within the radius of its axis, along the move (negative: the
    /// surface rises above the tip).
    pub gap_mm: f64,
    /// The fraction of the move (0 at its start, 1 at its end) where the
    /// gap is smallest.
    pub at: f64,
    /// The surface point that sets the gap there.
    pub surface_point: DVec3,
}

/// Relative slack of the coverage tests: a point this close to the disk's
/// edge counts as under it, so rounding never hides a surface point.
const SLACK: f64 = 1e-9;

impl Surface {
    /// The smallest gap along the straight move of the tip from `a` to `b`
    /// between the tip and the highest surface point within `radius` (in
    /// XY) of the nozzle's axis (see the module comment for the method).
    ///
    /// Guarantee: exact up to floating-point rounding (the coverage tests
    /// lean towards counting a point, so rounding errs on the side of a
    /// smaller gap). `None` when no surface point within `radius` of the
    /// move lies less than `limit` below the tip at any position (so the
    /// gap is at least `limit`); pass `f64::INFINITY` for the gap whatever
    /// it is.
    pub fn sweep_gap(&self, a: DVec3, b: DVec3, radius: f64, limit: f64) -> Option<SweepGap> {
        let d = (b - a).truncate();
        let dz = b.z - a.z;
        let lo_xy = a.truncate().min(b.truncate()) - DVec2::splat(radius);
        let hi_xy = a.truncate().max(b.truncate()) + DVec2::splat(radius);
        // A triangle wholly lower than the lowest tip position by `limit`
        // cannot make the gap smaller than `limit`.
        let floor = a.z.min(b.z) - limit;
        let q = QueryBox {
            lo: lo_xy.extend(floor),
            hi: hi_xy.extend(f64::INFINITY),
        };
        let mut best = Best {
            gap: limit,
            found: None,
        };
        let move_ = Move {
            a,
            d,
            dz,
            r: radius,
        };
        let low_tip = a.z.min(b.z);
        self.index.visit(&q, |i| {
            let t = self.mesh.triangle(i);
            if !meets(&t, &q) {
                return;
            }
            // No point of this triangle can beat the best gap so far.
            let top = t[0].z.max(t[1].z).max(t[2].z);
            if low_tip - top >= best.gap {
                return;
            }
            move_.triangle(t, &mut best);
        });
        best.found.map(|(at, surface_point)| SweepGap {
            gap_mm: best.gap,
            at,
            surface_point,
        })
    }
}

struct Best {
    gap: f64,
    found: Option<(f64, DVec3)>,
}

/// A move in the form the candidates need: tip XY p(s) = a_xy + s d,
/// tip height z(s) = a_z + s dz, disk radius r.
struct Move {
    a: DVec3,
    d: DVec2,
    dz: f64,
    r: f64,
}

impl Move {
    #[inline]
    fn consider(&self, s: f64, q: DVec3, best: &mut Best) {
        let s = s.clamp(0.0, 1.0);
        let gap = self.a.z + s * self.dz - q.z;
        if gap < best.gap {
            best.gap = gap;
            best.found = Some((s, q));
        }
    }

    /// The s in [0, 1] for which the XY point `v` lies within the disk,
    /// `None` if there are none.
    fn covered(&self, v: DVec2) -> Option<(f64, f64)> {
        let w = v - self.a.truncate();
        let r2 = self.r * self.r * (1.0 + SLACK);
        let dd = self.d.length_squared();
        if dd <= 1e-30 {
            return (w.length_squared() <= r2).then_some((0.0, 1.0));
        }
        let wd = w.dot(self.d);
        let disc = wd * wd - dd * (w.length_squared() - r2);
        if disc < 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        let (s0, s1) = (((wd - sq) / dd).max(0.0), ((wd + sq) / dd).min(1.0));
        (s0 <= s1).then_some((s0, s1))
    }

    fn triangle(&self, t: [DVec3; 3], best: &mut Best) {
        // Corners: the worst s of each corner's interval is its lower end
        // when the tip rises, its upper end when it descends.
        for v in t {
            if let Some((s0, s1)) = self.covered(v.truncate()) {
                self.consider(if self.dz >= 0.0 { s0 } else { s1 }, v, best);
            }
        }
        for k in 0..3 {
            self.edge(t[k], t[(k + 1) % 3], best);
        }
        self.facet(t, best);
    }

    /// Edge crossings: the chords at s = 0 and s = 1, and the point of the
    /// (t, s) ellipse where the gap is smallest.
    fn edge(&self, p: DVec3, q: DVec3, best: &mut Best) {
        let e = (q - p).truncate();
        let ee = e.length_squared();
        if ee <= 1e-30 {
            return; // a vertical edge: its top corner is a corner above
        }
        let r2 = self.r * self.r * (1.0 + SLACK);
        let a_xy = self.a.truncate();
        for s in [0.0, 1.0] {
            let f = p.truncate() - (a_xy + s * self.d);
            let b = f.dot(e);
            let disc = b * b - ee * (f.length_squared() - r2);
            if disc < 0.0 {
                continue;
            }
            let sq = disc.sqrt();
            for t in [(-b - sq) / ee, (-b + sq) / ee] {
                if (0.0..=1.0).contains(&t) {
                    self.consider(s, p + (q - p) * t, best);
                }
            }
        }
        // y = w0 + M v with v = (t, s), M = [e | -d]: the ellipse is
        // |y| <= r. The gap is c . v + const with c = (-(q_z - p_z), dz);
        // over |y| = r its minimum is at y = -r g / |g|, g = M^-T c.
        let det = self.d.perp_dot(e);
        if det.abs() <= 1e-12 * self.d.length() * ee.sqrt() {
            return; // e parallel to the move: the square's sides suffice
        }
        let c = DVec2::new(-(q.z - p.z), self.dz);
        let (d, inv) = (self.d, 1.0 / det);
        let g = DVec2::new(-d.y * c.x - e.y * c.y, d.x * c.x + e.x * c.y) * inv;
        let gl = g.length();
        if gl <= 1e-300 {
            return; // the gap is constant on the ellipse: the sides suffice
        }
        let y = -self.r * g / gl - (p.truncate() - a_xy);
        // v = M^-1 y, M^-1 = [[-d.y, d.x], [-e.y, e.x]] / det.
        let t = (-d.y * y.x + d.x * y.y) * inv;
        let s = (-e.y * y.x + e.x * y.y) * inv;
        let eps = 1e-12;
        if (-eps..=1.0 + eps).contains(&t) && (-eps..=1.0 + eps).contains(&s) {
            self.consider(s, p + (q - p) * t.clamp(0.0, 1.0), best);
        }
    }

    /// The facet term: where the plane's steepest ascent meets the circle,
    /// p(s) + r g^ (for a level triangle any point will do: p(s) itself).
    fn facet(&self, t: [DVec3; 3], best: &mut Best) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.z.abs() <= 1e-12 * n.length() {
            return;
        }
        let grad = DVec2::new(-n.x / n.z, -n.y / n.z);
        let gl = grad.length();
        let dir = if gl > 1e-15 { grad / gl } else { DVec2::ZERO };
        let q0 = self.a.truncate() + self.r * dir;
        // Inside the triangle's XY projection: three half-planes, each
        // linear in s.
        let orient = n.z.signum();
        let (mut s0, mut s1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let (pi, pj) = (t[k].truncate(), t[(k + 1) % 3].truncate());
            let e = pj - pi;
            let f0 = orient * e.perp_dot(q0 - pi);
            let f1 = orient * e.perp_dot(self.d);
            // f0 + s f1 >= -slack
            let slack = SLACK * e.length() * (self.r + (q0 - pi).length() + self.d.length());
            if f1.abs() <= 1e-300 {
                if f0 < -slack {
                    return;
                }
            } else if f1 > 0.0 {
                s0 = s0.max((-slack - f0) / f1);
            } else {
                s1 = s1.min((-slack - f0) / f1);
            }
        }
        if s0 > s1 {
            return;
        }
        let z_at = |s: f64| {
            let xy = q0 + s * self.d;
            t[0].z + grad.dot(xy - t[0].truncate())
        };
        for s in [s0, s1] {
            let xy = q0 + s * self.d;
            self.consider(s, xy.extend(z_at(s)), best);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::grid;
    use super::*;
    use crate::mesh::TriMesh;

    /// The gap by dense sampling of the move with the point query: never
    /// below the exact gap, and close to it when the sampling is fine.
    fn sampled(s: &Surface, a: DVec3, b: DVec3, r: f64, n: usize) -> f64 {
        (0..=n)
            .map(|i| {
                let p = a.lerp(b, i as f64 / n as f64);
                s.max_height_in_disk(p.truncate(), r)
                    .map_or(f64::INFINITY, |h| p.z - h)
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn step_block() -> Surface {
        // A 2 mm step at x = 5 with a true vertical wall.
        let xs: Vec<f64> = (0..=100).map(|i| i as f64 * 0.1).collect();
        let mut xs2 = xs.clone();
        xs2.push(5.0);
        xs2.sort_by(f64::total_cmp);
        let ys: Vec<f64> = (0..=20).map(|i| i as f64 * 0.5).collect();
        let mut m = TriMesh::default();
        let w = xs2.len();
        for &y in &ys {
            for (i, &x) in xs2.iter().enumerate() {
                let past = i > 0 && xs2[i - 1] == x;
                let z = if x > 5.0 || (x == 5.0 && past) { 2.0 } else { 0.0 };
                m.vertices.push(DVec3::new(x, y, z));
            }
        }
        for j in 0..ys.len() - 1 {
            for i in 0..w - 1 {
                let (a, b) = ((j * w + i) as u32, (j * w + i + 1) as u32);
                let (c, d) = (b + w as u32, a + w as u32);
                // Between the two copies of x = 5: the wall's two
                // vertical triangles.
                m.triangles.push([a, b, c]);
                m.triangles.push([a, c, d]);
            }
        }
        Surface::new(m).unwrap()
    }

    #[test]
    fn a_move_that_cuts_a_step_corner_is_caught() {
        let s = step_block();
        let r = 0.554;
        // Both ends clear the step by 0.5 mm, the straight line between
        // them cuts its corner.
        let a = DVec3::new(3.9, 5.0, 0.5);
        let b = DVec3::new(5.7, 5.0, 2.5);
        let ga = s.sweep_gap(a, a, r, f64::INFINITY).unwrap().gap_mm;
        let gb = s.sweep_gap(b, b, r, f64::INFINITY).unwrap().gap_mm;
        assert!((ga - 0.5).abs() < 1e-9 && (gb - 0.5).abs() < 1e-9, "{ga} {gb}");
        let g = s.sweep_gap(a, b, r, f64::INFINITY).unwrap();
        // The wall's top edge enters the disk when the axis reaches
        // x = 5 - r: s = (5 - r - 3.9) / 1.8, z there = 0.5 + 2 s.
        let s_in = (5.0 - r - 3.9) / 1.8;
        assert!((g.at - s_in).abs() < 1e-9, "{g:?}");
        assert!((g.gap_mm - (0.5 + 2.0 * s_in - 2.0)).abs() < 1e-9, "{g:?}");
        assert!((g.surface_point.z - 2.0).abs() < 1e-12);
        // Raised, the same move clears.
        let up = DVec3::new(0.0, 0.0, 2.0);
        let g = s.sweep_gap(a + up, b + up, r, f64::INFINITY).unwrap();
        assert!((g.gap_mm - (2.5 + 2.0 * s_in - 2.0)).abs() < 1e-9, "{g:?}");
        // With a limit below the true gap: nothing reported.
        assert!(s.sweep_gap(a + up, b + up, r, 0.4).is_none());
    }

    #[test]
    fn descending_past_a_step_is_worst_where_the_edge_leaves() {
        let s = step_block();
        let r = 0.5;
        let a = DVec3::new(6.0, 5.0, 2.6);
        let b = DVec3::new(4.0, 5.0, 0.6);
        let g = s.sweep_gap(a, b, r, f64::INFINITY).unwrap();
        // The top edge (x = 5) leaves the disk when the axis passes 4.5:
        // s = 0.75, z = 2.6 - 1.5 = 1.1: gap -0.9.
        assert!((g.at - 0.75).abs() < 1e-9, "{g:?}");
        assert!((g.gap_mm + 0.9).abs() < 1e-9, "{g:?}");
    }

    #[test]
    fn exact_gap_matches_dense_sampling_on_curved_surfaces() {
        let surf = Surface::new(grid(60, 6.0, |x, y| {
            (1.3 * x).sin() * 0.8 + (0.9 * y).cos() * 0.5 + 0.2 * x
        }))
        .unwrap();
        let r = 0.454;
        let mut seed = 7u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let a = DVec3::new(1.0 + 4.0 * rnd(), 1.0 + 4.0 * rnd(), 1.0 + 2.0 * rnd());
            let len = 0.05 + 1.5 * rnd();
            let ang = std::f64::consts::TAU * rnd();
            let b = a + DVec3::new(len * ang.cos(), len * ang.sin(), 2.0 * rnd() - 1.0);
            let exact = surf.sweep_gap(a, b, r, f64::INFINITY).unwrap();
            let dense = sampled(&surf, a, b, r, 4000);
            // Sampling can only miss the worst point: it is never below
            // the exact gap, and within a sample step's worth above it.
            assert!(exact.gap_mm <= dense + 1e-9, "{a} {b}: {exact:?} vs {dense}");
            assert!(dense - exact.gap_mm < 2e-3, "{a} {b}: {exact:?} vs {dense}");
            // The reported place is consistent with the gap.
            let p = a.lerp(b, exact.at);
            assert!((p.z - exact.surface_point.z - exact.gap_mm).abs() < 1e-9);
            let off = (exact.surface_point.truncate() - p.truncate()).length();
            assert!(off <= r * (1.0 + 1e-6), "{off}");
        }
    }

    #[test]
    fn a_point_move_equals_the_point_query() {
        let surf = Surface::new(grid(30, 3.0, |x, y| (x * 2.0).sin() + y * 0.3)).unwrap();
        for k in 0..50 {
            let p = DVec3::new(0.5 + 0.04 * k as f64, 1.5, 2.0);
            let g = surf.sweep_gap(p, p, 0.4, f64::INFINITY).unwrap().gap_mm;
            let h = surf.max_height_in_disk(p.truncate(), 0.4).unwrap();
            assert!((g - (p.z - h)).abs() < 1e-9, "{g} vs {}", p.z - h);
        }
    }
}
