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
//!   conservative: a contact under step i, whose rim height there lies
//!   between tol cos(theta_i) and tol cos(theta_(i-1)), is taken at the
//!   latter, up to tol (cos(theta_(i-1)) - cos(theta_i)) too high: 0.09,
//!   0.20, 0.28 and 0.42 tol from the inner ring out (QA round 6 measured
//!   up to 0.28 tol on real scans).
//!
//! Vertical triangles need no facet term: their highest point over any XY
//! region lies on their edges. The coverage tests take a relative hair of
//! slack so rounding can only make the clearance smaller. With tol = 0 the
//! nozzle is a plain flat cutter of radius r and the result is exact.
//!
//! Most queries only prove that nothing comes closer than the limit, and
//! the exact tests cost most. So a query first bounds each triangle from
//! below (its box's top and distance from the move, and its plane:
//! [`Sweep::bound`]), drops those that cannot come under the limit, and
//! tries the rest lowest bound first, stopping at the first whose bound
//! cannot beat or tie the best value found: on the wrinkled 2 M triangle
//! film, 5 of the 41 triangles the grid hands over get the exact test
//! (19 before). Ties are broken as the index's order would break them, so
//! the result, to the last bit and the reported place, is that of trying
//! every triangle in that order.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::{DVec2, DVec3};

use super::index::{Box32, QueryBox};
use super::{box_meets, corner_box, Surface};

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
/// step i's psi(r + a_(i-1)) = tol cos(theta_(i-1)). A corner or edge
/// contact is asked at most tol (cos(theta_(i-1)) - cos(theta_i)) more
/// height than the exact rim: 0.09, 0.20, 0.28 or 0.42 tol, by step.
pub const RIM_STEPS: [f64; 4] = [25.0, 45.0, 65.0, 90.0];

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
        self.nozzle_gap_until(a, b, radius, tol, limit, &|_| false)
    }

    /// [`Self::nozzle_gap`] for a caller that needs the clearance only
    /// while `enough` does not hold for it: the query stops at the first
    /// clearance it finds below `limit` for which `enough` holds, and
    /// returns that one, which may be larger than the smallest (the
    /// triangles not yet tried could lower it). `enough` must be monotone:
    /// true for a clearance, true for every smaller one; then `enough`
    /// holds for the smallest clearance exactly when it holds for the one
    /// returned, and where it does not hold, the one returned is the
    /// smallest, to the last bit and the reported place.
    ///
    /// For the questions the planners ask many times over about points
    /// that touch: whether a rise is more than some amount, and whether a
    /// point clears at all (`|_| true`: the first contact found answers
    /// it; [`Self::nozzle_touches`] answers that one for less).
    pub fn nozzle_gap_until(
        &self,
        a: DVec3,
        b: DVec3,
        radius: f64,
        tol: f64,
        limit: f64,
        enough: &dyn Fn(f64) -> bool,
    ) -> Option<SweepGap> {
        self.query::<false>(&Sweep::new(a, b, radius, tol, limit), enough)
    }

    /// Whether [`Self::nozzle_gap`] finds a clearance below `limit`: the
    /// question the planners ask most about points that touch
    /// ([`Self::nozzle_gap_until`] with `|_| true` answers it too).
    ///
    /// The answer does not depend on the order the triangles are tried
    /// in (a triangle with a contact below the limit has a bound below it
    /// too, and is tried, in either order, unless another contact is found
    /// first), so each is tried as soon as its bound lets it through, in
    /// the index's order, rather than queued lowest bound first: the first
    /// contact found stops the query before the bounds of the triangles
    /// after it are taken. On W3 the even planner's slide search (points
    /// slid back along the path, low over the surface: 14,201 queries) had
    /// 51 triangles handed over and 31 queued a query, and 97 % found a
    /// contact, by the 2nd or 3rd triangle tried: trying them at once took
    /// its queries from 256 M instructions to 112 M, and W3's plan from
    /// 4.22 G to 4.04 G (W2's from 67.0 M to 63.2 M), with the same G-code.
    pub fn nozzle_touches(&self, a: DVec3, b: DVec3, radius: f64, tol: f64, limit: f64) -> bool {
        let sweep = Sweep::new(a, b, radius, tol, limit);
        self.query::<true>(&sweep, &|_| true).is_some()
    }

    /// [`Self::nozzle_gap_until`] of the move `sweep`, trying each
    /// triangle at once when `EAGER` (only for `enough` always true, see
    /// [`Self::nozzle_touches`]).
    #[inline(always)]
    fn query<const EAGER: bool>(
        &self,
        sweep: &Sweep,
        enough: &dyn Fn(f64) -> bool,
    ) -> Option<SweepGap> {
        let q = &sweep.q;
        let mut best = sweep.start();
        // Set once `enough` holds for the best clearance found (when
        // `EAGER`, once a contact is found): nothing more is tried.
        let done = std::cell::Cell::new(false);
        QUEUE.with_borrow_mut(|queue| {
            queue.clear();
            // How many triangles the index has handed over: the next one's
            // rank, its place in the index's order, which breaks exact ties
            // (see `Best`).
            let mut handed = 0u32;
            // A cell all of whose triangles are bounded above the value a
            // finding must beat is left out whole.
            let start = best.gap;
            // Once done, every cell left is left out: the rest of the walk
            // reads only the cells' z ranges and XY boxes (on W3 the eager
            // queries of `nozzle_touches` stop at their first contact,
            // which most find; leaving out the cells after it took 0.9 %
            // of the instructions off).
            let keep =
                |b: &Box32| !done.get() && sweep.box_bound(b).is_some_and(|low| low <= start);
            // Inlined into the index's loop over a cell's triangles, with
            // the bound and its box part: called once per triangle handed
            // over (about 24 a query), a call's entry and exit cost more
            // than a tenth of what is done for a triangle.
            self.index.visit_pruned(
                q,
                keep,
                #[inline(always)]
                |i| {
                    if done.get() {
                        return;
                    }
                    let rank = handed;
                    handed += 1;
                    let t = self.mesh.triangle(i);
                    let (lo, hi) = corner_box(&t);
                    if !box_meets(lo, hi, q) {
                        return;
                    }
                    let Some(low) = sweep.bound(&t, lo, hi, best.gap) else {
                        return;
                    };
                    if low > best.gap {
                        return;
                    }
                    if EAGER {
                        // Nothing found yet (else `done`): `best` still
                        // holds the limit, as when the triangle is queued.
                        best.trying = rank;
                        sweep.visit(t, self.owned[i], &mut best);
                        done.set(best.found.is_some());
                        return;
                    }
                    if queue.len() == QUEUE_LEN {
                        done.set(self.drain(sweep, queue, &mut best, enough));
                    }
                    queue.push(Reverse(queued(low, i as u32, rank)));
                },
            );
            if !EAGER && !done.get() {
                self.drain(sweep, queue, &mut best, enough);
            }
        });
        sweep.finish(best)
    }

    /// Tries the queued triangles lowest bound first: those set a small
    /// best value early, and once a triangle's bound cannot beat or tie it,
    /// neither can any after it. True when it stopped because `enough`
    /// holds for the best clearance found.
    ///
    /// Most queries try a few of the triangles they queue (3 of 10 on
    /// average on the wrinkled film, but some queue a hundred and more): a
    /// heap puts them in order in linear time and then hands over only
    /// those tried, where sorting them all cost twice as much.
    fn drain(
        &self,
        sweep: &Sweep,
        queue: &mut Vec<Reverse<u128>>,
        best: &mut Best,
        enough: &dyn Fn(f64) -> bool,
    ) -> bool {
        let mut heap = BinaryHeap::from(std::mem::take(queue));
        let mut done = false;
        while let Some(Reverse(e)) = heap.pop() {
            let (low, i, rank) = unqueued(e);
            if low > best.gap {
                break;
            }
            let i = i as usize;
            best.trying = rank;
            let before = best.gap;
            sweep.visit(self.mesh.triangle(i), self.owned[i], best);
            if best.gap < before && enough(best.gap + sweep.m.tol) {
                done = true;
                break;
            }
        }
        *queue = heap.into_vec();
        queue.clear();
        done
    }

    /// The smallest gap along the move between the tip and the highest
    /// surface point within `radius` of its axis (a flat cutter of that
    /// radius; [`Self::nozzle_gap`] with tol = 0).
    pub fn sweep_gap(&self, a: DVec3, b: DVec3, radius: f64, limit: f64) -> Option<SweepGap> {
        self.nozzle_gap(a, b, radius, 0.0, limit)
    }
}

/// The query box of a move: its XY box grown by `reach`, from `limit`
/// below its lowest tip position up.
fn move_box(a: DVec3, b: DVec3, reach: f64, limit: f64) -> (DVec3, DVec3) {
    let lo_xy = a.truncate().min(b.truncate()) - DVec2::splat(reach);
    let hi_xy = a.truncate().max(b.truncate()) + DVec2::splat(reach);
    // A surface point lower than the lowest tip position by `limit` leaves
    // a clearance of at least `limit`.
    (
        lo_xy.extend(fmin(a.z, b.z) - limit),
        hi_xy.extend(f64::INFINITY),
    )
}

/// sin(theta_i) and cos(theta_(i-1)) of [`RIM_STEPS`] (25, 45, 65, 90
/// degrees).
const RIM_SIN_COS: [(f64, f64); 4] = [
    (0.422_618_261_740_699_4, 1.0),
    (std::f64::consts::FRAC_1_SQRT_2, 0.906_307_787_036_649_9),
    (0.906_307_787_036_649_9, std::f64::consts::FRAC_1_SQRT_2),
    (1.0, 0.422_618_261_740_699_4),
];

/// The staircase (radius, depth of its bottom below the tip) for the rim;
/// one flat cutter when tol is 0.
fn rim_steps(r: f64, tol: f64) -> ([(f64, f64); 4], usize) {
    if tol <= 0.0 {
        return ([(r, 0.0); 4], 1);
    }
    (RIM_SIN_COS.map(|(s, c)| (r + tol * s, tol * c)), 4)
}

/// Triangles a query gathers before it tries them, lowest bound first.
const QUEUE_LEN: usize = 256;

thread_local! {
    /// The triangles waiting for their exact test ([`queued`]). One per
    /// thread, kept between queries so a query allocates nothing.
    static QUEUE: std::cell::RefCell<Vec<Reverse<u128>>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// A triangle waiting for its exact test, as one integer whose order is
/// the order the triangles are tried in: its bound `low` (in the order of
/// `f64::total_cmp`) in the high 64 bits, then its rank (its place in the
/// index's order, which breaks ties), then the triangle. Sorting these
/// plain integers costs a fraction of ordering (bound, triangle, rank)
/// tuples with `total_cmp` and a tie-break, and gives the same order.
#[inline]
fn queued(low: f64, i: u32, rank: u32) -> u128 {
    // What `f64::total_cmp` compares: the bits as a signed integer, those
    // of the magnitude flipped for negative values; then the sign bit
    // flipped, for the order of unsigned integers.
    let bits = low.to_bits() as i64;
    let key = (bits ^ (((bits >> 63) as u64) >> 1) as i64) as u64 ^ (1 << 63);
    (key as u128) << 64 | (rank as u128) << 32 | i as u128
}

/// The bound, triangle and rank of a [`queued`] triangle.
#[inline]
fn unqueued(e: u128) -> (f64, u32, u32) {
    // The flips of `queued` undone (the second is its own inverse).
    let key = ((e >> 64) as u64 ^ (1 << 63)) as i64;
    let bits = key ^ (((key >> 63) as u64) >> 1) as i64;
    (f64::from_bits(bits as u64), e as u32, (e >> 32) as u32)
}

/// One move's query.
struct Sweep {
    m: Move,
    /// The box a triangle must meet to matter ([`move_box`]).
    q: QueryBox,
    /// The rim's staircase ([`rim_steps`]): the steps and how many there
    /// are; with tol = 0, one, and the others copies of it.
    steps: ([(f64, f64); 4], usize),
    /// The move's XY segment for [`dist2_to_segment`]: its start, the
    /// step to its end, and that step's squared length.
    seg: (DVec2, DVec2, f64),
    low_tip: f64,
    limit: f64,
    /// What [`Sweep::bound`] gives up of a distance for rounding.
    hair: f64,
    /// 1 / |d|^2 and 1 / |d| of the move in XY (0 for a move that does
    /// not move in XY).
    inv_dd: f64,
    inv_len: f64,
    /// |d| of the move in XY, for [`Sweep::bound`]'s hair.
    d_len: f64,
}

/// What [`Sweep::within_reach`] widens its interval by on each side at
/// least.
const REACH_HAIR: f64 = 1e-9;

impl Sweep {
    fn new(a: DVec3, b: DVec3, radius: f64, tol: f64, limit: f64) -> Sweep {
        let (lo, hi) = move_box(a, b, radius + tol, limit);
        let dd = (b - a).truncate().length_squared();
        // As `point_segment_dist2` finds them from the two ends.
        let ab = (a.truncate() + (b - a).truncate()) - a.truncate();
        Sweep {
            seg: (a.truncate(), ab, ab.length_squared()),
            q: QueryBox { lo, hi },
            m: Move {
                a,
                d: (b - a).truncate(),
                dz: b.z - a.z,
                r: radius,
                tol,
            },
            steps: rim_steps(radius, tol),
            low_tip: fmin(a.z, b.z),
            limit,
            hair: 1e-8 * (1.0 + (b - a).truncate().length() + radius + tol),
            inv_dd: if dd > 1e-30 { 1.0 / dd } else { 0.0 },
            inv_len: if dd > 1e-30 { 1.0 / dd.sqrt() } else { 0.0 },
            d_len: (b - a).truncate().length(),
        }
    }

    /// Values are z(s) - x_z - h; the clearance is the value plus tol.
    fn start(&self) -> Best {
        Best {
            gap: self.limit - self.m.tol,
            found: None,
            rank: 0,
            trying: 0,
        }
    }

    /// A lower bound of every candidate value of triangle `t`, or `None`
    /// when no point of it comes within the rim's reach of the move. The
    /// larger of two:
    /// - from its box: no point of it lies higher than the box's top, nor
    ///   nearer the move (in XY) than the box's centre less its half
    ///   diagonal, and a contact that far out has at most the h of the
    ///   first step that reaches it (the staircase lies above the rim, and
    ///   a facet's contact has the rim's own h);
    /// - from its plane (gradient g): a point of it within step i's radius
    ///   R_i of the tip's axis lies at most |g| R_i above the plane under
    ///   the axis, so every contact's x_z + h is at most that plane height
    ///   plus the largest |g| R_i + h_i, and z(s) less the plane height
    ///   under p(s) is linear in s.
    ///
    /// A hair is given up of each, more than the coverage tests' slack and
    /// the rounding. The box bound alone when it is above `enough`.
    /// `lo` and `hi` are the triangle's box ([`corner_box`]).
    #[inline(always)]
    fn bound(&self, t: &[DVec3; 3], lo: DVec3, hi: DVec3, enough: f64) -> Option<f64> {
        let c = 0.5 * (lo.truncate() + hi.truncate());
        let half = 0.5 * (hi.truncate() - lo.truncate()).length();
        let (by_box, s0, s1) = self.box_part(c, half, hi.z)?;
        let a = self.m.a.truncate();
        // All four steps: with tol = 0 they are four copies of the one
        // (see `Sweep::steps`), and a fixed count spares the loop's checks.
        let steps = &self.steps.0;
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        // The plane is not needed when the box bound alone is enough, and
        // steep planes give nothing better than the box.
        if by_box > enough || n.z.abs() <= 1e-3 * (n.x.abs() + n.y.abs()) {
            return Some(by_box);
        }
        let g = DVec2::new(-n.x / n.z, -n.y / n.z);
        let gl = g.length();
        // (A comparison, not `f64::max`: the terms are finite.)
        let rise = steps.iter().fold(f64::NEG_INFINITY, |m, &(radius, h)| {
            let v = gl * radius + h;
            if v > m {
                v
            } else {
                m
            }
        });
        let off = a - t[0].truncate();
        let v0 = self.m.a.z - t[0].z - g.dot(off) - rise;
        let v1 = v0 + self.m.dz - g.dot(self.m.d);
        // Linear in s: least at an end of the part within reach.
        let (v0, v1) = (v0 + s0 * (v1 - v0), v0 + s1 * (v1 - v0));
        let hair = 1e-9
            * (1.0
                + self.m.a.z.abs()
                + t[0].z.abs()
                + self.m.dz.abs()
                + gl * (steps[steps.len() - 1].0 + off.length() + self.d_len));
        Some(fmax(by_box, fmin(v0, v1) - hair))
    }

    /// A lower bound of every candidate value of every surface point in
    /// the box `b` (of a cell of the index: lo xyz, hi xyz), from the box
    /// alone as in [`Self::bound`], or `None` when no point of it comes
    /// within the rim's reach of the move.
    #[inline]
    fn box_bound(&self, b: &Box32) -> Option<f64> {
        let lo = DVec2::new(b[0] as f64, b[1] as f64);
        let hi = DVec2::new(b[3] as f64, b[4] as f64);
        let (by_box, ..) = self.box_part(0.5 * (lo + hi), 0.5 * (hi - lo).length(), b[5] as f64)?;
        Some(by_box - self.hair)
    }

    /// The box part of [`Self::bound`] for an XY box of centre `c` and
    /// half-diagonal `half` whose points lie no higher than `top`: the
    /// bound, and the part (s0, s1) of the move within reach of the box
    /// ([`Self::within_reach`]); `None` when no point of the box comes
    /// within the widest step's reach.
    #[inline(always)]
    fn box_part(&self, c: DVec2, half: f64, top: f64) -> Option<(f64, f64, f64)> {
        let (a, ab, l) = self.seg;
        let d = dist2_to_segment(c, a, ab, l).sqrt() - half;
        let d = d - self.hair - 1e-8 * half;
        // All four steps, as in `bound`.
        let steps = &self.steps.0;
        let h = steps.iter().find(|&&(radius, _)| d <= radius)?.1;
        // The part of the move where the box can be within the widest
        // step's reach (its circle, of radius `half` around `c`, meets
        // that step's disk around p(s)); the tip's lowest height there.
        let (s0, s1) = self.within_reach(c, half, steps[steps.len() - 1].0);
        let low = self.m.a.z + if self.m.dz >= 0.0 { s0 } else { s1 } * self.m.dz;
        Some((low - top - h, s0, s1))
    }

    /// The fractions s of the move at which a circle of radius `half`
    /// around `c` can come within `radius` of the tip's axis: an interval
    /// that holds all of them (widened past every rounding, so it may hold
    /// a little more), [0, 1] for a move too short in XY to tell.
    ///
    /// Found from the circle's closest approach to the move's line, at
    /// fraction `along`, and its distance `e` from it there: within reach
    /// for |s - along| |d| <= sqrt((radius + half)^2 - e^2). The reach
    /// gets the margin of the distance test in [`Self::bound`] (more than
    /// the exact tests' slack lets in) and more than the rounding of `e`,
    /// so the square root is never taken of less than the true room (near
    /// a tangency a small error in `e` would move the ends far); the ends
    /// get a slack larger than the rounding of `along` and of the root,
    /// which grows as the move shortens. An interval too wide only weakens
    /// the bound.
    #[inline]
    fn within_reach(&self, c: DVec2, half: f64, radius: f64) -> (f64, f64) {
        if self.inv_dd == 0.0 {
            return (0.0, 1.0);
        }
        let w = c - self.m.a.truncate();
        let along = w.dot(self.m.d) * self.inv_dd;
        let e2 = (w - self.m.d * along).length_squared();
        let wl = w.x.abs() + w.y.abs();
        // As far as the distance test in `bound` reaches (which holds the
        // exact tests' slack), and past the rounding of `e`.
        let r = radius + half + self.hair + 1e-8 * half + 1e-12 * (1.0 + wl);
        let room = r * r - e2;
        if room.is_nan() || room < 0.0 {
            return (0.0, 1.0);
        }
        let spread = room.sqrt() * self.inv_len;
        let slack = REACH_HAIR + 1e-12 * (wl + r) * self.inv_len;
        let s0 = fmax(along - spread - slack, 0.0);
        let s1 = fmin(along + spread + slack, 1.0);
        if s0 > s1 {
            return (0.0, 1.0);
        }
        (s0, s1)
    }

    #[inline]
    fn visit(&self, t: [DVec3; 3], owned: u8, best: &mut Best) {
        let steps = &self.steps.0[..self.steps.1];
        self.m.triangle(t, owned, self.low_tip, steps, best);
    }

    fn finish(&self, best: Best) -> Option<SweepGap> {
        best.found.map(|(at, surface_point)| SweepGap {
            gap_mm: best.gap + self.m.tol,
            at,
            surface_point,
        })
    }
}

/// The best (smallest) value so far and where. Triangles are tried in an
/// order of their own (lowest bound first), but the result is that of trying
/// them in the index's order: of two candidates with the same value, the
/// one of the triangle the index hands over first (the lower rank) wins,
/// and within a triangle the one tried first. So the prunes let a
/// candidate that could tie the best value through.
struct Best {
    gap: f64,
    found: Option<(f64, DVec3)>,
    /// The rank of the triangle that gave `found` (0 while there is none:
    /// a tie with the limit is not a finding).
    rank: u32,
    /// The rank of the triangle being tried.
    trying: u32,
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
        let gap = self.value(s, q, h);
        if gap < best.gap || (gap == best.gap && best.trying < best.rank) {
            best.gap = gap;
            best.found = Some((s, q));
            best.rank = best.trying;
        }
    }

    /// The value z(s) - q_z - h (s in [0, 1]).
    #[inline]
    fn value(&self, s: f64, q: DVec3, h: f64) -> f64 {
        self.a.z + s.clamp(0.0, 1.0) * self.dz - q.z - h
    }

    /// The corners, edges and facet of triangle `t` for the move whose
    /// lowest tip height is `low_tip`.
    ///
    /// A corner or edge whose top lies `room` below `low_tip` has no
    /// contact with a value below `room - h` under a step whose bottom
    /// lies `h` below the tip: only the steps that could still beat or
    /// tie the best value are tried ([`live_steps`]), and a corner's or
    /// edge's distance from the move is found only when a step is left.
    /// Skipping a candidate that can neither beat nor tie the best value
    /// leaves the result as it was.
    ///
    /// A corner or edge is tried only in the triangle that owns it
    /// (`owned`, see `Surface::owned`): the owner holds it, so while it is
    /// near enough to the move and high enough to matter, the owner's box
    /// meets the query box and the owner's bound ([`Sweep::bound`], which
    /// holds for every point of the owner) lets it through; the owner is
    /// tried, and the candidates are tried
    /// there once instead of in each of the (about six, or two) triangles
    /// that share them. The smallest value is the same (to the last bits:
    /// an edge is tried from its owner's side); where two candidates tie
    /// exactly, the one reported may be another.
    #[inline(always)]
    fn triangle(
        &self,
        t: [DVec3; 3],
        owned: u8,
        low_tip: f64,
        steps: &[(f64, f64)],
        best: &mut Best,
    ) {
        let (a, b) = (self.a.truncate(), self.a.truncate() + self.d);
        // Squared XY distances of the corners from the move, once found.
        let mut dv = [f64::NAN; 3];
        for k in 0..3 {
            if owned & (1 << k) == 0 {
                continue;
            }
            let live = live_steps(low_tip - t[k].z, steps, best.gap);
            if !live.is_empty() {
                dv[k] = point_segment_dist2(t[k].truncate(), a, b);
                self.corner(t[k], dv[k], live, best);
            }
        }
        for k in 0..3 {
            if owned & (8 << k) == 0 {
                continue;
            }
            let (i, j) = (k, (k + 1) % 3);
            let live = live_steps(low_tip - fmax(t[i].z, t[j].z), steps, best.gap);
            if live.is_empty() {
                continue;
            }
            let (p, q) = (t[i].truncate(), t[j].truncate());
            let d2 = if segments_cross(p, q, a, b) {
                0.0
            } else {
                let mut end = |k: usize, v: DVec2| {
                    if dv[k].is_nan() {
                        dv[k] = point_segment_dist2(v, a, b);
                    }
                    dv[k]
                };
                let ends = fmin(fmin(end(i, p), end(j, q)), point_segment_dist2(a, p, q));
                // A tip standing still (b is a then, to the bit: a point
                // query) has the one distance already taken.
                if self.d == DVec2::ZERO {
                    ends
                } else {
                    fmin(ends, point_segment_dist2(b, p, q))
                }
            };
            self.edge(t[i], t[j], d2, live, best);
        }
        self.facet(t, best);
    }

    /// A corner under each live step that reaches it ([`reaching`]): the
    /// worst s of its interval is its lower end when the tip rises, its
    /// upper end when it descends.
    ///
    /// No bound first (the widest step's interval with the largest h, which
    /// holds every step's candidate): on the wrinkled film it let most
    /// corners through, and cost about what it spared.
    fn corner(&self, v: DVec3, d2: f64, steps: &[(f64, f64)], best: &mut Best) {
        for &(radius, h) in reaching(d2, steps) {
            if let Some(s) = self.corner_s(v, d2, radius) {
                self.consider(s, v, h, best);
            }
        }
    }

    /// The worst s at which corner `v` (squared XY distance `d2` from the
    /// move) lies under a flat cutter of `radius`, if it ever does.
    #[inline]
    fn corner_s(&self, v: DVec3, d2: f64, radius: f64) -> Option<f64> {
        let r2 = radius * radius * (1.0 + SLACK);
        if d2 > r2 {
            return None;
        }
        let w = v.truncate() - self.a.truncate();
        let (ww, dd) = (w.length_squared(), self.d.length_squared());
        let (s0, s1) = if dd <= 1e-30 {
            if ww > r2 {
                return None;
            }
            (0.0, 1.0)
        } else {
            let wd = w.dot(self.d);
            let disc = wd * wd - dd * (ww - r2);
            if disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            let (s0, s1) = (fmax((wd - sq) / dd, 0.0), fmin((wd + sq) / dd, 1.0));
            if s0 > s1 {
                return None;
            }
            (s0, s1)
        };
        Some(if self.dz >= 0.0 { s0 } else { s1 })
    }

    /// Edge crossings under each live step (a flat cutter of its radius
    /// whose bottom lies its h below the tip): the chords at s = 0 and
    /// s = 1, and the point of the (t, s) ellipse where the value is
    /// smallest, under the live steps that reach the edge ([`reaching`]).
    ///
    /// No bound first: the widest step with the largest h bounds them all
    /// (its region of (t, s) holds theirs, so their candidates are no lower
    /// than its smallest value over its region's boundary: its candidates
    /// and the edge's ends, the sides t = 0 and t = 1), but most edges that
    /// reach the disk straddle its rim, their ends inside it, and the ends'
    /// values let two in three of the edges bounded through on the wrinkled
    /// film (W3): the bound (its own candidates and two corner intervals)
    /// cost more than the steps it spared. Leaving it out changes nothing
    /// but the work: it only ever skipped candidates that could neither
    /// beat nor tie the best value.
    fn edge(&self, p: DVec3, q: DVec3, d2: f64, steps: &[(f64, f64)], best: &mut Best) {
        let steps = reaching(d2, steps);
        if steps.is_empty() {
            return;
        }
        let Some(e) = EdgeSweep::new(self, p, q) else {
            return; // a vertical edge: its top corner is a corner above
        };
        for &(radius, h) in steps {
            e.candidates(self, d2, radius, |s, x| self.consider(s, x, h, best));
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
        // The value at the contact is linear in s, on the triangle's plane
        // as on the triangle: when it cannot beat or tie the best value at
        // either end of the move, it cannot where the contact lies in the
        // triangle either.
        let v0 = self.a.z - t[0].z - grad.dot(q0 - t[0].truncate()) - h;
        let v1 = v0 + self.dz - grad.dot(self.d);
        if fmin(v0, v1) > best.gap + BOUND_EPS {
            return;
        }
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
                s0 = fmax(s0, (-slack - f0) / f1);
            } else {
                s1 = fmin(s1, (-slack - f0) / f1);
            }
        }
        if s0 > s1 {
            return;
        }
        // The coverage tests' slack may put the contact a hair outside the
        // triangle, where its plane may rise above it: no point of the
        // triangle lies above its highest corner (which the bounds rely
        // on).
        let top = fmax(fmax(t[0].z, t[1].z), t[2].z);
        let z_at = |s: f64| {
            let xy = q0 + s * self.d;
            fmin(t[0].z + grad.dot(xy - t[0].truncate()), top)
        };
        for s in [s0, s1] {
            let xy = q0 + s * self.d;
            self.consider(s, xy.extend(z_at(s)), h, best);
        }
    }
}

/// `f64::min` as libm's `fmin` computes it (the other operand when one is
/// NaN), inlined: wasm has no instruction for it, and the calls LLVM makes
/// to `fmin` and `fmax` instead took a twentieth of a plan's time in the page.
/// The same value as `f64::min` wherever that one is specified.
#[inline(always)]
fn fmin(x: f64, y: f64) -> f64 {
    if y.is_nan() || x < y {
        x
    } else {
        y
    }
}

/// `f64::max` as libm's `fmax` computes it, inlined (see [`fmin`]).
#[inline(always)]
fn fmax(x: f64, y: f64) -> f64 {
    if x.is_nan() || x < y {
        y
    } else {
        x
    }
}

/// The steps whose contacts with a point `room` below the lowest tip could
/// still beat or tie the value `best`: room - h <= best. The steps' h fall
/// from the first to the last ([`RIM_SIN_COS`]: cos 0, 25, 45, 65
/// degrees), so they are the steps from the first to the last one for
/// which it holds.
#[inline]
fn live_steps(room: f64, steps: &[(f64, f64)], best: f64) -> &[(f64, f64)] {
    let mut n = 0;
    while n < steps.len() && room - steps[n].1 <= best {
        n += 1;
    }
    &steps[..n]
}

/// The steps of `steps` (live ones, in their order) that reach a corner or
/// edge `d2` (squared) from the move in XY: the others have no candidate
/// there, by the very test of [`Move::corner_s`] and
/// [`EdgeSweep::candidates`], which are then not called for them. The
/// radii grow from the first step to the last, so these are the last ones.
#[inline]
fn reaching(d2: f64, steps: &[(f64, f64)]) -> &[(f64, f64)] {
    let mut k = 0;
    while k < steps.len() && d2 > steps[k].0 * steps[k].0 * (1.0 + SLACK) {
        k += 1;
    }
    &steps[k..]
}

/// Squared distance from `p` to the segment [a, b] (2-D).
#[inline]
fn point_segment_dist2(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    dist2_to_segment(p, a, ab, ab.length_squared())
}

/// [`point_segment_dist2`] for the segment from `a` along `ab`, of squared
/// length `l`, found once for many points.
#[inline]
fn dist2_to_segment(p: DVec2, a: DVec2, ab: DVec2, l: f64) -> f64 {
    let t = if l > 0.0 {
        ((p - a).dot(ab) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).length_squared()
}

/// What an edge's candidates share across the steps: y = w0 + M v with
/// v = (t, s), M = [e | -d], the ellipse |y| <= r of a flat cutter of
/// radius r; the value is c . v + const with c = (-(q_z - p_z), dz), and
/// over |y| = r its minimum is at y = -r g / |g|, g = M^-T c.
struct EdgeSweep {
    p: DVec3,
    q: DVec3,
    e: DVec2,
    ee: f64,
    w0: DVec2,
    /// The chords' quadratics at s = 0 and s = 1 (for a tip that does not
    /// move in XY, one, at its lowest end).
    ends: [(f64, f64, f64); 2],
    n_ends: usize,
    /// g / |g| and 1 / det M, unless the value is constant on the ellipse
    /// or e is parallel to the move (the square's sides suffice then).
    ellipse: Option<(DVec2, f64)>,
}

impl EdgeSweep {
    fn new(m: &Move, p: DVec3, q: DVec3) -> Option<EdgeSweep> {
        let e = (q - p).truncate();
        let ee = e.length_squared();
        if ee <= 1e-30 {
            return None;
        }
        let w0 = p.truncate() - m.a.truncate();
        let d = m.d;
        let moving = d.length_squared() > 1e-30;
        // A tip that does not move in XY (a plunge, a lift) has one chord
        // for every s, and its worst s is the lowest end: the end the tip
        // descends to (QA round 6 F0: taken at s = 0, the top of a
        // descent, a wall's edge across the disk at its bottom was missed).
        let still = if m.dz < 0.0 { 1.0 } else { 0.0 };
        let ends = (if moving { [0.0, 1.0] } else { [still; 2] }).map(|s| {
            let f = w0 - s * d;
            (s, f.dot(e), f.length_squared())
        });
        let det = d.perp_dot(e);
        let ellipse = if moving && det.abs() > 1e-12 * d.length() * ee.sqrt() {
            let c = DVec2::new(-(q.z - p.z), m.dz);
            let inv = 1.0 / det;
            let g = DVec2::new(-d.y * c.x - e.y * c.y, d.x * c.x + e.x * c.y) * inv;
            let gl = g.length();
            (gl > 1e-300).then_some((g / gl, inv))
        } else {
            None
        };
        Some(EdgeSweep {
            p,
            q,
            e,
            ee,
            w0,
            ends,
            n_ends: if moving { 2 } else { 1 },
            ellipse,
        })
    }

    /// Calls `f(s, x)` with each candidate under a flat cutter of `radius`
    /// (none when the edge lies `d2` away, beyond it).
    #[inline]
    fn candidates(&self, m: &Move, d2: f64, radius: f64, mut f: impl FnMut(f64, DVec3)) {
        let r2 = radius * radius * (1.0 + SLACK);
        if d2 > r2 {
            return;
        }
        let (p, q, ee) = (self.p, self.q, self.ee);
        for &(s, b, ff) in &self.ends[..self.n_ends] {
            let disc = b * b - ee * (ff - r2);
            if disc < 0.0 {
                continue;
            }
            let sq = disc.sqrt();
            for t in [(-b - sq) / ee, (-b + sq) / ee] {
                if (0.0..=1.0).contains(&t) {
                    f(s, p + (q - p) * t);
                }
            }
        }
        if let Some((gn, inv)) = self.ellipse {
            let (d, e) = (m.d, self.e);
            let y = -radius * gn - self.w0;
            // v = M^-1 y, M^-1 = [[-d.y, d.x], [-e.y, e.x]] / det.
            let t = (-d.y * y.x + d.x * y.y) * inv;
            let s = (-e.y * y.x + e.x * y.y) * inv;
            let eps = 1e-12;
            if (-eps..=1.0 + eps).contains(&t) && (-eps..=1.0 + eps).contains(&s) {
                f(s, p + (q - p) * t.clamp(0.0, 1.0));
            }
        }
    }
}

/// A bound must clear the best value by this much before the candidates
/// under it are skipped, so rounding in the bound never hides one.
const BOUND_EPS: f64 = 1e-12;

/// Whether the segments [p, q] and [a, b] cross (2-D; parallel ones never
/// do here: their distance is then that of an end to the other segment).
fn segments_cross(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> bool {
    let (r, s) = (q - p, b - a);
    let den = r.perp_dot(s);
    if den == 0.0 {
        return false;
    }
    let t = (a - p).perp_dot(s) / den;
    let u = (a - p).perp_dot(r) / den;
    (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)
}

#[cfg(test)]
mod tests {
    use super::super::meets;
    use super::super::tests::{grid, reference_max_height_in_disk};
    use super::*;
    use crate::mesh::TriMesh;

    /// The gap by dense sampling of the move with the point query: never
    /// below the exact gap, and close to it when the sampling is fine.
    fn sampled(s: &Surface, a: DVec3, b: DVec3, r: f64, n: usize) -> f64 {
        (0..=n)
            .map(|i| {
                let p = a.lerp(b, i as f64 / n as f64);
                reference_max_height_in_disk(s, p.truncate(), r).map_or(f64::INFINITY, |h| p.z - h)
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
                let z = if x > 5.0 || (x == 5.0 && past) {
                    2.0
                } else {
                    0.0
                };
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
        assert!(
            (ga - 0.5).abs() < 1e-9 && (gb - 0.5).abs() < 1e-9,
            "{ga} {gb}"
        );
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

    /// QA round 6 F0: a tip that moves only up or down (a plunge) beside a
    /// wall whose top edge crosses the disk, no corner under it: the edge
    /// was taken at the move's start, so a descent into the step was
    /// called clear by the height it started from.
    #[test]
    fn a_vertical_move_is_worst_at_its_lowest_end() {
        let s = step_block();
        let r = 0.35;
        // The wall's top edge (x = 5, z = 2) lies 0.3 mm from the axis;
        // its corners at y = 5 and 5.5 lie 0.39 mm away, beyond r.
        let (top, bottom) = (DVec3::new(4.7, 5.25, 5.0), DVec3::new(4.7, 5.25, 1.0));
        for (a, b, at) in [(top, bottom, 1.0), (bottom, top, 0.0)] {
            let g = s.sweep_gap(a, b, r, f64::INFINITY).unwrap();
            assert!((g.gap_mm + 1.0).abs() < 1e-9, "{a} -> {b}: {g:?}");
            assert_eq!(g.at, at);
            assert!((g.surface_point.z - 2.0).abs() < 1e-12, "{g:?}");
            // With tol, the same as the point query at the lowest end.
            let tol = 0.1;
            let moved = s.nozzle_gap(a, b, r, tol, f64::INFINITY).unwrap();
            let point = s.nozzle_gap(bottom, bottom, r, tol, f64::INFINITY).unwrap();
            assert_eq!(moved.gap_mm, point.gap_mm, "{a} -> {b}");
        }
        // On a curved surface, every vertical move agrees with dense
        // sampling.
        let surf = Surface::new(grid(60, 6.0, |x, y| {
            (1.3 * x).sin() * 0.8 + (0.9 * y).cos() * 0.5 + 0.2 * x
        }))
        .unwrap();
        let r = 0.454;
        for k in 0..200 {
            let (u, v) = ((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.414_214) % 1.0);
            let a = DVec3::new(1.0 + 4.0 * u, 1.0 + 4.0 * v, 3.0);
            let b = DVec3::new(a.x, a.y, -1.5 + 2.0 * v);
            for (a, b) in [(a, b), (b, a)] {
                let exact = surf.sweep_gap(a, b, r, f64::INFINITY).unwrap();
                let dense = sampled(&surf, a, b, r, 50);
                assert!(
                    exact.gap_mm <= dense + 1e-9,
                    "{a} {b}: {exact:?} vs {dense}"
                );
                assert!(dense - exact.gap_mm < 1e-9, "{a} {b}: {exact:?} vs {dense}");
            }
        }
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
            assert!(
                exact.gap_mm <= dense + 1e-9,
                "{a} {b}: {exact:?} vs {dense}"
            );
            assert!(dense - exact.gap_mm < 2e-3, "{a} {b}: {exact:?} vs {dense}");
            // The reported place is consistent with the gap.
            let p = a.lerp(b, exact.at);
            assert!((p.z - exact.surface_point.z - exact.gap_mm).abs() < 1e-9);
            let off = (exact.surface_point.truncate() - p.truncate()).length();
            assert!(off <= r * (1.0 + 1e-6), "{off}");
        }
    }

    #[test]
    fn queued_triangles_keep_their_bound_and_the_order_of_total_cmp() {
        let lows = [
            f64::NEG_INFINITY,
            -1e300,
            -2.5,
            -f64::MIN_POSITIVE,
            -5e-324,
            -0.0,
            0.0,
            5e-324,
            f64::MIN_POSITIVE,
            1e-12,
            0.1,
            0.1 + 1e-17,
            2.5,
            1e300,
            f64::INFINITY,
            f64::NAN,
            -f64::NAN,
        ];
        let mut all = Vec::new();
        for (k, &low) in lows.iter().enumerate() {
            for rank in [0, 1, 7, u32::MAX] {
                let i = (k as u32).wrapping_mul(0x9E37_79B9) ^ rank;
                let e = queued(low, i, rank);
                let (l, j, r) = unqueued(e);
                assert_eq!((l.to_bits(), j, r), (low.to_bits(), i, rank));
                all.push((low, i, rank, e));
            }
        }
        for x in &all {
            for y in &all {
                let want = x.0.total_cmp(&y.0).then(x.2.cmp(&y.2));
                if x.2 != y.2 || x.0.to_bits() != y.0.to_bits() {
                    assert_eq!(x.3.cmp(&y.3), want, "{x:?} {y:?}");
                }
            }
        }
    }

    #[test]
    fn rim_table_is_the_steps_sines_and_cosines() {
        let mut prev = 0.0f64;
        for (deg, (s, c)) in RIM_STEPS.iter().zip(RIM_SIN_COS) {
            assert!((deg.to_radians().sin() - s).abs() < 1e-15);
            assert!((prev.to_radians().cos() - c).abs() < 1e-15);
            prev = *deg;
        }
    }

    #[test]
    fn a_point_move_equals_the_point_query() {
        let surf = Surface::new(grid(30, 3.0, |x, y| (x * 2.0).sin() + y * 0.3)).unwrap();
        for k in 0..50 {
            let p = DVec3::new(0.5 + 0.04 * k as f64, 1.5, 2.0);
            let g = surf.sweep_gap(p, p, 0.4, f64::INFINITY).unwrap().gap_mm;
            let h = reference_max_height_in_disk(&surf, p.truncate(), 0.4).unwrap();
            assert!((g - (p.z - h)).abs() < 1e-9, "{g} vs {}", p.z - h);
        }
    }

    #[test]
    fn a_corner_the_exact_tests_reach_by_their_slack_is_not_bounded_away() {
        // A descent almost straight down (1e-7 mm in XY over 5 mm) away
        // from a tiny triangle's corner about the widest step's reach
        // behind its start: the corner test's slack takes the corner in
        // for the first thousandths of the move, the tip lowest at their
        // end. Ground set to clear by a hair more than that corner: the
        // bound of the corner's triangle must not be taken from a part of
        // the move that stops short of that end (a hundredth of a mm
        // higher), or the ground would win.
        let (r, tol) = (0.45, 0.1);
        let reach = r + tol;
        let (a, b) = (DVec3::new(0.0, 0.0, 5.0), DVec3::new(1e-7, 0.0, 0.0));
        let surface = |v: DVec3, ground: Option<f64>| {
            let mut m = TriMesh {
                vertices: vec![
                    v,
                    v + DVec3::new(1e-12, 1e-12, 0.0),
                    v + DVec3::new(0.0, 2e-12, 0.0),
                ],
                triangles: vec![[0, 1, 2]],
            };
            if let Some(z) = ground {
                m.vertices.extend([
                    DVec3::new(-20.0, -20.0, z),
                    DVec3::new(20.0, -20.0, z),
                    DVec3::new(0.0, 20.0, z),
                ]);
                m.triangles.push([3, 4, 5]);
            }
            Surface::new(m).unwrap()
        };
        let mut tested = 0;
        for k in -20..20 {
            let v = DVec3::new(-reach * (1.0 + 1e-12 * k as f64), 0.0, -0.2);
            let Some(alone) = surface(v, None).nozzle_gap(a, b, r, tol, f64::INFINITY) else {
                continue;
            };
            tested += 1;
            let s = surface(v, Some(-(alone.gap_mm + 5e-6)));
            let got = s.nozzle_gap(a, b, r, tol, f64::INFINITY);
            assert_eq!(got, in_index_order(&s, a, b, r, tol, f64::INFINITY), "{k}");
            assert_eq!(got, Some(alone), "{k}");
        }
        assert!(tested > 10, "{tested}");
    }

    #[test]
    fn a_query_stops_where_the_answer_is_known() {
        let bumpy = grid(40, 8.0, |x, y| {
            (x * 1.7).sin() * 0.4 + (y * 2.3).cos() * 0.3
        });
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut stopped, mut found) = (0, 0);
        for surf in [Surface::new(bumpy).unwrap(), step_block()] {
            let (lo, hi) = surf.bbox();
            for k in 0..400 {
                let mut at = || {
                    DVec3::new(
                        lo.x + (hi.x - lo.x) * unit(),
                        lo.y + (hi.y - lo.y) * unit(),
                        hi.z + 0.3 - 2.5 * unit(),
                    )
                };
                let a = at();
                let b = if k % 2 == 0 { a } else { a + (at() - a) * 0.2 };
                for limit in [f64::INFINITY, 0.1] {
                    let full = surf.nozzle_gap(a, b, 0.45, 0.1, limit);
                    // Whether there is any clearance below the limit.
                    let any = surf.nozzle_gap_until(a, b, 0.45, 0.1, limit, &|_| true);
                    assert_eq!(any.is_some(), full.is_some(), "{a} -> {b}");
                    // And the eager query that answers only that.
                    let touches = surf.nozzle_touches(a, b, 0.45, 0.1, limit);
                    assert_eq!(touches, full.is_some(), "{a} -> {b}");
                    let Some(f) = full else { continue };
                    found += 1;
                    let x = any.unwrap();
                    assert!(x.gap_mm >= f.gap_mm, "{a} -> {b}: {x:?} below {f:?}");
                    stopped += usize::from(x.gap_mm > f.gap_mm);
                    // Whether it is below a threshold: the smallest
                    // whenever it is not.
                    for thr in [f.gap_mm - 0.05, f.gap_mm, f.gap_mm + 1e-12, f.gap_mm + 0.05] {
                        let got = surf.nozzle_gap_until(a, b, 0.45, 0.1, limit, &|g| g < thr);
                        let g = got.unwrap();
                        if f.gap_mm < thr {
                            assert!(g.gap_mm < thr && g.gap_mm >= f.gap_mm, "{a} -> {b}");
                        } else {
                            assert_eq!(got, full, "{a} -> {b}, threshold {thr}");
                        }
                    }
                }
            }
        }
        assert!(found > 300, "{found}");
        // Stopping at the first clearance found does happen.
        assert!(stopped > found / 10, "{stopped} of {found}");
    }

    /// The query as it was before the bounds and the order: every
    /// triangle the index hands over whose box meets the query box, tried
    /// in the index's order with nothing skipped.
    fn in_index_order(
        s: &Surface,
        a: DVec3,
        b: DVec3,
        r: f64,
        tol: f64,
        limit: f64,
    ) -> Option<SweepGap> {
        let sweep = Sweep::new(a, b, r, tol, limit);
        let mut best = sweep.start();
        let mut rank = 0;
        s.index.visit(&sweep.q, |i| {
            best.trying = rank;
            rank += 1;
            let t = s.mesh.triangle(i);
            if meets(&t, &sweep.q) {
                sweep.visit(t, s.owned[i], &mut best);
            }
        });
        sweep.finish(best)
    }

    #[test]
    fn bounds_and_order_give_what_the_index_order_gives() {
        // Curved ground, a step with flat tops (exact ties everywhere on
        // them), and a terraced field whose level triangles tie across
        // cells: gap, place and surface point must be the same bits.
        let bumpy = grid(40, 8.0, |x, y| {
            (x * 1.7).sin() * 0.4 + (y * 2.3).cos() * 0.3 + if x > 3.0 { 1.0 } else { 0.0 }
        });
        let terraces = grid(32, 8.0, |x, y| ((x + 0.5 * y) * 1.5).floor() * 0.25);
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut found = 0;
        for surf in [
            Surface::new(bumpy).unwrap(),
            step_block(),
            Surface::new(terraces).unwrap(),
        ] {
            let (lo, hi) = surf.bbox();
            for k in 0..600 {
                let mut at = |z: f64| {
                    DVec3::new(
                        lo.x + (hi.x - lo.x) * unit(),
                        lo.y + (hi.y - lo.y) * unit(),
                        hi.z + 0.3 - z * unit(),
                    )
                };
                let a = at(2.5);
                let b = match k % 6 {
                    0 => a,
                    // Level moves: ties along the whole move on a flat top.
                    1 => DVec3::new(a.x + 0.7, a.y - 0.2, a.z),
                    2 => a + (at(2.5) - a) * 0.15,
                    3 => a + (at(2.5) - a) * 0.6,
                    // Descents and rises almost straight down or up: the
                    // part of the move within a triangle's reach is
                    // ill-conditioned, and the height changes fast in it.
                    4 => a + DVec3::new(1e-9 * unit(), 1e-9, -2.0 * unit()),
                    _ => a + DVec3::new(3e-6, -2e-6 * unit(), 2.0 * unit() - 1.0),
                };
                for (tol, limit) in [
                    (0.0, f64::INFINITY),
                    (0.1, f64::INFINITY),
                    (0.1, 0.3),
                    (0.1, 0.1),
                ] {
                    let got = surf.nozzle_gap(a, b, 0.45, tol, limit);
                    let want = in_index_order(&surf, a, b, 0.45, tol, limit);
                    assert_eq!(got, want, "move {a} -> {b}, tol {tol}, limit {limit}");
                    found += usize::from(got.is_some());
                }
            }
        }
        assert!(found > 2000, "too few queries found a contact: {found}");
    }

    /// Trying each corner and edge in its owner only gives the same
    /// smallest clearance (to 1e-12 mm) as trying it in every triangle that
    /// holds it:
    /// random moves (rising, level, descending, and standing still) over a
    /// bumpy field with a step and over the step block.
    #[test]
    fn owners_only_give_the_same_clearance_as_every_triangle() {
        let bumpy = grid(24, 6.0, |x, y| {
            (x * 1.7).sin() * 0.4 + (y * 2.3).cos() * 0.3 + if x > 3.0 { 1.0 } else { 0.0 }
        });
        for surf in [Surface::new(bumpy).unwrap(), step_block()] {
            let mut all = Surface::new(surf.mesh().clone()).unwrap();
            all.owned.iter_mut().for_each(|o| *o = 0x3f);
            assert!(surf.owned.iter().any(|&o| o != 0x3f), "nothing is shared");
            let (lo, hi) = surf.bbox();
            let mut seed = 0x2545_F491_4F6C_DD1Du64;
            let mut unit = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64
            };
            for k in 0..400 {
                let mut at = |z: f64| {
                    DVec3::new(
                        lo.x + (hi.x - lo.x) * unit(),
                        lo.y + (hi.y - lo.y) * unit(),
                        hi.z - z,
                    )
                };
                let a = at(0.5 * (k % 7) as f64);
                let b = if k % 5 == 0 {
                    a
                } else {
                    a + (at(0.0) - a) * 0.1
                };
                for tol in [0.0, 0.1] {
                    let g = surf.nozzle_gap(a, b, 0.45, tol, f64::INFINITY);
                    let h = all.nozzle_gap(a, b, 0.45, tol, f64::INFINITY);
                    // The same, but for the last bits of an edge tried from
                    // its other end.
                    match (g, h) {
                        (Some(g), Some(h)) => assert!(
                            (g.gap_mm - h.gap_mm).abs() <= 1e-12,
                            "move {a} -> {b}, tol {tol}: {} vs {}",
                            g.gap_mm,
                            h.gap_mm
                        ),
                        (g, h) => assert_eq!(g, h, "move {a} -> {b}, tol {tol}"),
                    }
                }
            }
        }
    }
}
