//! The nozzle swept along a straight move (spec section 6f): the stage
//! moves in straight lines, so safety is a property of every move, not of
//! the planned points.
//!
//! The nozzle is the tip disk of radius r at the tip's height and the body
//! above it (a vertical cylinder of the same radius). It keeps a distance
//! of at least tol from a surface point x exactly when the tip is at least
//! x_z + psi(rho) high, where rho is x's horizontal distance from the axis
//! and psi(rho) = tol for rho <= r, sqrt(tol^2 - (rho - r)^2) up to
//! rho = r + tol, and nothing beyond (the nozzle grown by a ball of radius
//! tol: a flat disk with a rounded rim, CAM's bull-nose cutter). Over a
//! straight move from `a` to `b` (the tip height varying linearly), the
//! question is the smallest value of z(s) - x_z - psi(rho_s(x)) over every
//! fraction s of the move and every surface point x: the move keeps tol
//! from the surface when it is not negative. [`Surface::nozzle_gap`]
//! returns it plus tol, the *clearance*: the tip's height over the surface
//! where the surface nearest the nozzle lies under the tip, and tol plus
//! how far the nozzle could sink before it came within tol otherwise.
//!
//! It is computed triangle by triangle, from three kinds of contact:
//! - a facet: the rounded rim touches a tilted plane where the rim's
//!   ball centre lies r + tol sin(theta) from the axis in the direction of
//!   steepest ascent, tol cos(theta) below the tip (theta the tilt). That
//!   point moves in a straight line as s runs, so the s for which it lies
//!   in the triangle form an interval over which the value is linear: its
//!   minimum is at an end. Exact.
//! - a corner, and an edge: the rim's profile psi is replaced by a
//!   staircase above it ([`RIM_STEPS`]): flat cutters of radius r + a_i whose
//!   bottom lies h_i = psi(r + a_(i-1)) below the tip. For a flat cutter, a
//!   corner stays under the disk over an interval of s (worst at an end, the
//!   tip height being linear), and an edge crossing is a point (t, s) on the
//!   boundary of the ellipse |e(t) - p(s)| <= radius in the (t, s) square,
//!   where the value is linear in (t, s): its minimum lies on the square's
//!   sides (a corner's interval, or the edge's chord at s = 0 or s = 1) or
//!   at the one point of the ellipse where the value's gradient is normal
//!   to it, which has a closed form. Exact for the staircase, which is
//!   conservative by at most tol (a_i - a_(i-1)) times the slope at the
//!   contact.
//!
//! Vertical triangles need no facet term: their highest point over any XY
//! region lies on their edges. The coverage tests take a relative hair of
//! slack so rounding can only make the clearance smaller. With tol = 0 the
//! nozzle is a plain flat cutter of radius r and the result is exact.

use glam::{DVec2, DVec3};

use super::index::QueryBox;
use super::{meets, Surface};

/// The clearance of a move (see the module comment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepGap {
    /// The smallest clearance along the move: at least tol when the
    /// nozzle keeps tol from the surface everywhere on it; tol minus it is
    /// how far the tip would have to rise at the worst place.
    pub gap_mm: f64,
    /// The fraction of the move (0 at its start, 1 at its end) where the
    /// clearance is smallest.
    pub at: f64,
    /// The surface point that sets it.
    pub surface_point: DVec3,
}

/// The rim's staircase for corner and edge contacts: angles theta_i with
/// a_i = tol sin(theta_i); the first step's bottom lies tol below the tip,
/// step i's psi(r + a_(i-1)) = tol cos(theta_(i-1)). On a contact where the
/// surface rises at 45 degrees away from the axis it asks at most 0.15 tol
/// more height than the exact rim.
pub const RIM_STEPS: [f64; 5] = [20.0, 40.0, 55.0, 70.0, 90.0];

/// Relative slack of the coverage tests: a point this close to the disk's
/// edge counts as under it, so rounding never hides a surface point.
const SLACK: f64 = 1e-9;

impl Surface {
    /// The smallest clearance (see the module comment) of the nozzle of
    /// tip radius `radius` kept `tol` from the surface, along the straight
    /// move of its tip from `a` to `b`.
    ///
    /// Guarantee: exact for facet contacts, conservative for corners and
    /// edges by the staircase of [`RIM_STEPS`] (never a larger clearance
    /// than the true one), up to floating-point rounding, which the
    /// coverage tests bias towards a smaller clearance. `None` when the
    /// clearance is at least `limit` (no surface near the move, or all of
    /// it far enough below); pass `f64::INFINITY` to have it whatever it is.
    pub fn nozzle_gap(
        &self,
        a: DVec3,
        b: DVec3,
        radius: f64,
        tol: f64,
        limit: f64,
    ) -> Option<SweepGap> {
        let d = (b - a).truncate();
        let dz = b.z - a.z;
        let reach = radius + tol;
        let lo_xy = a.truncate().min(b.truncate()) - DVec2::splat(reach);
        let hi_xy = a.truncate().max(b.truncate()) + DVec2::splat(reach);
        // A surface point lower than the lowest tip position by `limit`
        // leaves a clearance of at least `limit`.
        let floor = a.z.min(b.z) - limit;
        let q = QueryBox {
            lo: lo_xy.extend(floor),
            hi: hi_xy.extend(f64::INFINITY),
        };
        // Values are z(s) - x_z - h; the clearance is the value plus tol.
        let mut best = Best {
            gap: limit - tol,
            found: None,
        };
        let steps = rim_steps(radius, tol);
        let move_ = Move {
            a,
            d,
            dz,
            r: radius,
            tol,
        };
        let low_tip = a.z.min(b.z);
        self.index.visit(&q, |i| {
            let t = self.mesh.triangle(i);
            if !meets(&t, &q) {
                return;
            }
            // No point of this triangle can beat the best value so far
            // (every contact's h is at most tol).
            let top = t[0].z.max(t[1].z).max(t[2].z);
            if low_tip - top - tol >= best.gap {
                return;
            }
            move_.triangle(t, &steps, &mut best);
        });
        best.found.map(|(at, surface_point)| SweepGap {
            gap_mm: best.gap + tol,
            at,
            surface_point,
        })
    }

    /// The smallest gap along the move between the tip and the highest
    /// surface point within `radius` of its axis (a flat cutter of that
    /// radius; [`Self::nozzle_gap`] with tol = 0).
    pub fn sweep_gap(&self, a: DVec3, b: DVec3, radius: f64, limit: f64) -> Option<SweepGap> {
        self.nozzle_gap(a, b, radius, 0.0, limit)
    }
}

/// The staircase (radius, depth of its bottom below the tip) for the rim.
fn rim_steps(r: f64, tol: f64) -> Vec<(f64, f64)> {
    if tol <= 0.0 {
        return vec![(r, 0.0)];
    }
    let mut out = Vec::with_capacity(RIM_STEPS.len());
    let mut prev = 0.0f64;
    for deg in RIM_STEPS {
        let th = deg.to_radians();
        out.push((r + tol * libm::sin(th), tol * libm::cos(prev)));
        prev = th;
    }
    out
}

struct Best {
    gap: f64,
    found: Option<(f64, DVec3)>,
}

/// A move in the form the candidates need: tip XY p(s) = a_xy + s d,
/// tip height z(s) = a_z + s dz, tip radius r, tolerance tol.
struct Move {
    a: DVec3,
    d: DVec2,
    dz: f64,
    r: f64,
    tol: f64,
}

impl Move {
    /// Takes the value z(s) - q_z - h of a contact of surface point `q`
    /// whose cutter bottom lies `h` below the tip.
    #[inline]
    fn consider(&self, s: f64, q: DVec3, h: f64, best: &mut Best) {
        let s = s.clamp(0.0, 1.0);
        let gap = self.a.z + s * self.dz - q.z - h;
        if gap < best.gap {
            best.gap = gap;
            best.found = Some((s, q));
        }
    }

    /// The s in [0, 1] for which the XY point `v` lies within `radius` of
    /// the axis, `None` if there are none.
    fn covered(&self, v: DVec2, radius: f64) -> Option<(f64, f64)> {
        let w = v - self.a.truncate();
        let r2 = radius * radius * (1.0 + SLACK);
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

    fn triangle(&self, t: [DVec3; 3], steps: &[(f64, f64)], best: &mut Best) {
        for &(radius, h) in steps {
            // Corners: the worst s of each corner's interval is its lower
            // end when the tip rises, its upper end when it descends.
            for v in t {
                if let Some((s0, s1)) = self.covered(v.truncate(), radius) {
                    self.consider(if self.dz >= 0.0 { s0 } else { s1 }, v, h, best);
                }
            }
            for k in 0..3 {
                self.edge(t[k], t[(k + 1) % 3], radius, h, best);
            }
        }
        self.facet(t, best);
    }

    /// Edge crossings of the flat cutter of `radius` whose bottom lies `h`
    /// below the tip: the chords at s = 0 and s = 1, and the point of the
    /// (t, s) ellipse where the value is smallest.
    fn edge(&self, p: DVec3, q: DVec3, radius: f64, h: f64, best: &mut Best) {
        let e = (q - p).truncate();
        let ee = e.length_squared();
        if ee <= 1e-30 {
            return; // a vertical edge: its top corner is a corner above
        }
        let r2 = radius * radius * (1.0 + SLACK);
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
                    self.consider(s, p + (q - p) * t, h, best);
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
        let y = -radius * g / gl - (p.truncate() - a_xy);
        // v = M^-1 y, M^-1 = [[-d.y, d.x], [-e.y, e.x]] / det.
        let t = (-d.y * y.x + d.x * y.y) * inv;
        let s = (-e.y * y.x + e.x * y.y) * inv;
        let eps = 1e-12;
        if (-eps..=1.0 + eps).contains(&t) && (-eps..=1.0 + eps).contains(&s) {
            self.consider(s, p + (q - p) * t.clamp(0.0, 1.0), h, best);
        }
    }

    /// The facet term: the rim's ball centre on the plane, r + tol
    /// sin(theta) from the axis along the steepest ascent, its top
    /// tol cos(theta) over the plane (for a level triangle any point under
    /// the disk will do: p(s) itself).
    fn facet(&self, t: [DVec3; 3], best: &mut Best) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.z.abs() <= 1e-12 * n.length() {
            return;
        }
        let grad = DVec2::new(-n.x / n.z, -n.y / n.z);
        let gl = grad.length();
        let dir = if gl > 1e-15 { grad / gl } else { DVec2::ZERO };
        // tan(theta) = |grad|.
        let cos_t = 1.0 / (1.0 + gl * gl).sqrt();
        let sin_t = gl * cos_t;
        let (reach, h) = (self.r + self.tol * sin_t, self.tol * cos_t);
        let q0 = self.a.truncate() + reach * dir;
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
            let slack = SLACK * e.length() * (reach + (q0 - pi).length() + self.d.length());
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
            self.consider(s, xy.extend(z_at(s)), h, best);
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
