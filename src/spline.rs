//! Curve fit and local geometry (spec section 5): a cubic interpolating
//! B-spline through the points of each subpath with chord-length parameters
//! and averaged knots (The NURBS Book, section 9.2.1, eq. 9.5 and 9.8), and
//! at each point the tangent t, the horizontal printing direction V, the
//! profile normal N, the signed profile curvature kappa, the slope angle
//! alpha and the 3-D curvature.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A non-rational B-spline curve (unit weights) interpolating given points.
#[derive(Debug, Clone)]
pub struct Spline {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<DVec3>,
    params: Vec<f64>,
}

impl Spline {
    /// Interpolates `points` with a cubic (degree min(3, n-1) for fewer than
    /// four points). Consecutive points must be distinct.
    pub fn interpolate(points: &[DVec3]) -> Result<Spline> {
        let n = points.len();
        if n < 2 {
            return Err(Error::Plan(format!(
                "a spline needs at least 2 points, got {n}"
            )));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            let p = points[i];
            return Err(Error::Plan(format!(
                "point {i} of the path is not finite: ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        let p = 3.min(n - 1);
        // Chord-length parameters (NURBS Book eq. 9.5).
        let mut params = Vec::with_capacity(n);
        params.push(0.0);
        let mut total = 0.0;
        for w in points.windows(2) {
            total += w[0].distance(w[1]);
            params.push(total);
        }
        for (i, w) in params.windows(2).enumerate() {
            if w[1] - w[0] <= 1e-12 * total.max(1.0) {
                let p = points[i];
                return Err(Error::Plan(format!(
                    "points {i} and {} of the path coincide at ({:.4}, {:.4}, {:.4})",
                    i + 1,
                    p.x,
                    p.y,
                    p.z
                )));
            }
        }
        for u in &mut params {
            *u /= total;
        }
        params[n - 1] = 1.0;
        // Averaged knots (eq. 9.8).
        let mut knots = vec![0.0; n + p + 1];
        for j in 1..n - p {
            knots[j + p] = params[j..j + p].iter().sum::<f64>() / p as f64;
        }
        for k in &mut knots[n..] {
            *k = 1.0;
        }
        let mut s = Spline {
            degree: p,
            knots,
            ctrl: Vec::new(),
            params,
        };
        s.ctrl = s.solve_control_points(points)?;
        Ok(s)
    }

    /// The parameter u_k at which the spline passes through point k.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// Solves N P = Q (NURBS Book eq. 9.7): a banded, totally positive
    /// system, so Gaussian elimination without pivoting is stable (9.2.1).
    fn solve_control_points(&self, q: &[DVec3]) -> Result<Vec<DVec3>> {
        let n = q.len();
        let p = self.degree;
        // Band storage: a[k][c - k + p] for columns c in [k - p, k + p]
        // (2 p + 1 <= 7 of each row used).
        let mut a = vec![[0.0; 7]; n];
        let mut rhs = q.to_vec();
        let mut basis = [0.0; 4];
        // The points' parameters rise, so each one's knot span is found
        // from the one before by walking forward: the span holding u is
        // unique (`find_span`'s).
        let last = n - 1;
        let mut span = p;
        for (k, row) in a.iter_mut().enumerate() {
            let u = self.params[k];
            if u >= self.knots[last + 1] {
                span = last;
            } else {
                while span < last && u >= self.knots[span + 1] {
                    span += 1;
                }
            }
            debug_assert_eq!(span, self.find_span(u));
            self.basis_funs(span, u, &mut basis);
            for (r, &b) in basis.iter().enumerate().take(p + 1) {
                let off = (span + r)
                    .checked_sub(k)
                    .filter(|&o| o <= 2 * p)
                    .ok_or_else(|| Error::Plan("spline system is not banded".into()))?;
                row[off] = b;
            }
        }
        // The same operations in the same order as the textbook's loops
        // over the band (so the same bits), each row read as an array.
        for k in 0..n {
            let pivot = a[k][p];
            if pivot.abs() < 1e-300 {
                return Err(Error::Plan(format!(
                    "spline system is singular at point {k}"
                )));
            }
            let (done, below) = a.split_at_mut(k + 1);
            let top = &done[k];
            let rk = rhs[k];
            for (i, row) in below.iter_mut().enumerate().take(p) {
                // Row k + 1 + i; column c lies at c + p - (k + 1 + i).
                let f = row[p - 1 - i] / pivot;
                if f == 0.0 {
                    continue;
                }
                for c in 0..(p + 1).min(n - k) {
                    row[c + p - 1 - i] -= f * top[c + p];
                }
                rhs[k + 1 + i] -= rk * f;
            }
        }
        for k in (0..n).rev() {
            let mut v = rhs[k];
            for c in 1..(p + 1).min(n - k) {
                v -= rhs[k + c] * a[k][c + p];
            }
            rhs[k] = v / a[k][p];
        }
        Ok(rhs)
    }

    /// Knot span index (NURBS Book A2.1).
    fn find_span(&self, u: f64) -> usize {
        let p = self.degree;
        let n = self.ctrl.len().max(self.params.len()) - 1;
        if u >= self.knots[n + 1] {
            return n;
        }
        if u <= self.knots[p] {
            return p;
        }
        let (mut lo, mut hi) = (p, n + 1);
        let mut mid = (lo + hi) / 2;
        while u < self.knots[mid] || u >= self.knots[mid + 1] {
            if u < self.knots[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
            mid = (lo + hi) / 2;
        }
        mid
    }

    /// Non-vanishing basis functions (NURBS Book A2.2).
    #[inline]
    fn basis_funs(&self, span: usize, u: f64, out: &mut [f64; 4]) {
        if self.degree == 3 {
            // Every path of four points or more: the knots it reads taken
            // once, and the loops of a known length unrolled.
            let knots: &[f64; 6] = self.knots[span - 2..=span + 3]
                .try_into()
                .expect("six knots");
            cubic_basis_funs(knots, u, out);
        } else {
            self.any_basis_funs(span, u, out);
        }
    }

    /// [`Self::basis_funs`] of any degree: out of line, so the cubic's
    /// short path is inlined where the curve is evaluated.
    #[inline(never)]
    fn any_basis_funs(&self, span: usize, u: f64, out: &mut [f64; 4]) {
        let p = self.degree;
        let mut left = [0.0; 4];
        let mut right = [0.0; 4];
        out[0] = 1.0;
        for j in 1..=p {
            left[j] = u - self.knots[span + 1 - j];
            right[j] = self.knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = out[r] / (right[r + 1] + left[j - r]);
                out[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            out[j] = saved;
        }
    }

    /// Basis functions and their first two derivatives (NURBS Book A2.3).
    /// The degree is `P`, a constant, so the loops have known bounds and
    /// unroll (the same operations in the same order, so the same bits).
    fn ders_basis_funs<const P: usize>(&self, span: usize, u: f64) -> [[f64; 4]; 3] {
        debug_assert_eq!(self.degree, P);
        let p = P;
        let mut ndu = [[0.0; 4]; 4];
        let mut left = [0.0; 4];
        let mut right = [0.0; 4];
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = u - self.knots[span + 1 - j];
            right[j] = self.knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = ndu[r][j - 1] / ndu[j][r];
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        let mut ders = [[0.0; 4]; 3];
        for j in 0..=p {
            ders[0][j] = ndu[j][p];
        }
        let nd = 2.min(p);
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            let mut a = [[0.0; 4]; 2];
            a[0][0] = 1.0;
            for k in 1..=nd {
                let mut d = 0.0;
                let rk = r as isize - k as isize;
                let pk = p - k;
                if r >= k {
                    a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                    d = a[s2][0] * ndu[rk as usize][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if r as isize - 1 <= pk as isize {
                    k - 1
                } else {
                    p - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                    d += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                    d += a[s2][k] * ndu[r][pk];
                }
                ders[k][r] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut f = p as f64;
        for (k, row) in ders.iter_mut().enumerate().skip(1).take(nd) {
            for v in row.iter_mut().take(p + 1) {
                *v *= f;
            }
            f *= (p - k) as f64;
        }
        ders
    }

    /// The point at parameter `u` (clamped to [0, 1]).
    pub fn eval(&self, u: f64) -> DVec3 {
        self.eval_near(u, &std::cell::Cell::new(usize::MAX))
    }

    /// [`Self::eval`] that first tries the knot span in `hint` (and its
    /// neighbour) before searching, and leaves the span it used there: a
    /// root search evaluates many times within one or two spans.
    pub fn eval_near(&self, u: f64, hint: &std::cell::Cell<usize>) -> DVec3 {
        let u = u.clamp(0.0, 1.0);
        let p = self.degree;
        let span = self.span_near(u, hint);
        let mut basis = [0.0; 4];
        self.basis_funs(span, u, &mut basis);
        let ctrl = &self.ctrl[span - p..=span];
        // A cubic's four control points as an array: the sum unrolled (the
        // same sum, in the same order).
        if let Ok(ctrl) = <&[DVec3; 4]>::try_from(ctrl) {
            return ctrl
                .iter()
                .zip(&basis)
                .fold(DVec3::ZERO, |acc, (c, w)| acc + *c * *w);
        }
        ctrl.iter()
            .zip(&basis)
            .fold(DVec3::ZERO, |acc, (c, w)| acc + *c * *w)
    }

    /// The knot span of `u` in [0, 1] ([`Self::find_span`]'s), trying the
    /// one in `hint` and its neighbours first, and left there. The span
    /// holding u is unique (the one whose interval [u_k, u_k+1) is not
    /// empty and holds it, or an end's), so the hint changes no result.
    fn span_near(&self, u: f64, hint: &std::cell::Cell<usize>) -> usize {
        let p = self.degree;
        let n = self.ctrl.len().max(self.params.len()) - 1;
        let h = hint.get();
        let inside =
            |k: usize| k >= p && k <= n && u >= self.knots[k] && (u < self.knots[k + 1] || k == n);
        let span = if inside(h) {
            h
        } else if h < n && inside(h + 1) {
            h + 1
        } else if h > p && h != usize::MAX && inside(h - 1) {
            h - 1
        } else {
            self.find_span(u)
        };
        hint.set(span);
        span
    }

    /// C(u), C'(u), C''(u).
    pub fn derivs(&self, u: f64) -> [DVec3; 3] {
        self.derivs_near(u, &std::cell::Cell::new(usize::MAX))
    }

    /// [`Self::derivs`] with a span hint, as [`Self::eval_near`]: the
    /// points' parameters, taken in order, step a span at a time.
    pub fn derivs_near(&self, u: f64, hint: &std::cell::Cell<usize>) -> [DVec3; 3] {
        let u = u.clamp(0.0, 1.0);
        let p = self.degree;
        let span = self.span_near(u, hint);
        let d = match p {
            1 => self.ders_basis_funs::<1>(span, u),
            2 => self.ders_basis_funs::<2>(span, u),
            _ => self.ders_basis_funs::<3>(span, u),
        };
        let mut out = [DVec3::ZERO; 3];
        for (k, o) in out.iter_mut().enumerate() {
            for (c, w) in self.ctrl[span - p..=span].iter().zip(&d[k]) {
                *o += *c * *w;
            }
        }
        out
    }
}

/// [`Spline::basis_funs`] of a cubic, from the knots span - 2 to span + 3:
/// the same operations in the same order, so the same bits.
#[inline]
fn cubic_basis_funs(knots: &[f64; 6], u: f64, out: &mut [f64; 4]) {
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    out[0] = 1.0;
    for j in 1..=3 {
        left[j] = u - knots[3 - j];
        right[j] = knots[2 + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// The local geometry of a path at one of its points (spec section 5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LocalGeometry {
    /// Unit tangent t_j of the spline, in the printing direction.
    pub tangent: DVec3,
    /// Horizontal printing direction V_j (unit, z = 0).
    pub v: DVec3,
    /// Profile normal N_j: perpendicular to t_j in the vertical plane of V_j
    /// and Z, with N_j,z >= 0.
    pub n: DVec3,
    /// Signed curvature of the height profile along the horizontal arc
    /// length, 1/mm: positive concave-up, negative concave-down.
    pub kappa: f64,
    /// Slope angle alpha_j = atan2(t_z, |t_xy|), radians (negative = downhill).
    pub slope_rad: f64,
    /// Curvature of the 3-D curve |r' x r''| / |r'|^3, 1/mm.
    pub curvature_3d: f64,
}

/// A unit tangent's z at most this far below 0 is level: rounding. On a
/// level plate t_z comes out as +-1e-13 or so (the projected heights differ
/// in their last bits), and the paper's switches on its sign (section 6c's
/// case 3, section 7's back of the nozzle) then shifted points at random;
/// a real descent of 1e-9 rad drops a nanometre a metre.
pub const LEVEL_TZ: f64 = 1e-9;

impl LocalGeometry {
    /// Whether the path moves downward here (t_z < 0, sections 6c and 7)
    /// by more than rounding ([`LEVEL_TZ`]).
    pub fn descending(&self) -> bool {
        self.tangent.z < -LEVEL_TZ
    }
}

/// Fits the spline through `points` and evaluates the local geometry at
/// each of them.
pub fn local_geometry(points: &[DVec3]) -> Result<Vec<LocalGeometry>> {
    let spline = Spline::interpolate(points)?;
    let mut geometry = geometry_of(&spline);
    follow_the_drawing(points, &mut geometry);
    Ok(geometry)
}

/// Where the spline's horizontal direction runs against the drawn path's
/// (its chord through the neighbouring points, one-sided at an end), the
/// geometry is taken mirrored: V along the path, t and N turned with it,
/// the profile's curvature of the opposite sign. A cubic through a sudden
/// drop overshoots: at a piece's last point, 1.08 mm below the one before
/// it over 0.29 mm, C' pointed back along the path, V with it, and every
/// planner's shift along V went the wrong way (QA round 9 M1: `even`'s
/// last dispensing move 1.29 mm back over the line already printed).
/// V is the direction of travel (spec section 5).
fn follow_the_drawing(points: &[DVec3], geometry: &mut [LocalGeometry]) {
    let n = points.len().min(geometry.len());
    if n < 2 {
        return;
    }
    for (j, g) in geometry.iter_mut().enumerate().take(n) {
        let chord = (points[(j + 1).min(n - 1)] - points[j.saturating_sub(1)]).truncate();
        // Only a direction that runs against the chord, not one across it
        // (at a hairpin's apex the chord runs across the path, and out and
        // back along one line it is nothing: a cusp, whose geometry is its
        // neighbour's).
        // And not where the chord is short beside the steps either side
        // (a cusp's, made of rounding: which way it points is noise).
        let steps = (points[(j + 1).min(n - 1)] - points[j]).truncate().length()
            + (points[j] - points[j.saturating_sub(1)])
                .truncate()
                .length();
        if g.v.truncate().dot(chord) >= -0.5 * chord.length() || chord.length() < 0.25 * steps {
            continue;
        }
        g.v = -g.v;
        g.tangent = DVec3::new(-g.tangent.x, -g.tangent.y, g.tangent.z);
        let a = g.tangent.truncate().length();
        g.n = (-g.tangent.z * g.v + a * DVec3::Z).normalize_or(DVec3::Z);
        g.kappa = -g.kappa;
    }
}

/// The local geometry at each interpolated point of `spline`.
pub fn geometry_of(spline: &Spline) -> Vec<LocalGeometry> {
    let mut out: Vec<LocalGeometry> = Vec::with_capacity(spline.params.len());
    let mut vertical = Vec::new();
    // C' and C'' at each u_j, evaluated once for both passes.
    let hint = std::cell::Cell::new(usize::MAX);
    let ders: Vec<[DVec3; 2]> = spline
        .params
        .iter()
        .map(|&u| {
            let [_, d1, d2] = spline.derivs_near(u, &hint);
            [d1, d2]
        })
        .collect();
    // Where the drawn path turns straight back (out and back along one
    // line), the spline stops there: C' vanishes but for rounding, and the
    // direction, slope and curvature found from it are noise (a profile
    // curvature of 1e25/mm on a flat plate; the paper's forward shift then
    // threw a tool-path point 1e24 mm away). Such a point takes its
    // neighbour's geometry, as a vertical tangent takes its neighbour's V
    // (spec section 5): the one it arrives from.
    let speed = ders.iter().fold(0.0, |m: f64, d| m.max(d[0].length()));
    let mut cusps = Vec::new();
    for (j, &[d1, d2]) in ders.iter().enumerate() {
        let len = d1.length();
        if len <= CUSP * speed {
            cusps.push(j);
        }
        let tangent = if len > 0.0 { d1 / len } else { DVec3::Z };
        let h = d1.truncate().length();
        let v = if h > 1e-9 * len {
            DVec3::new(d1.x / h, d1.y / h, 0.0)
        } else {
            vertical.push(j);
            DVec3::X
        };
        out.push(LocalGeometry {
            tangent,
            v,
            n: DVec3::ZERO,
            kappa: 0.0,
            slope_rad: libm::atan2(tangent.z, tangent.truncate().length()),
            curvature_3d: if len > 0.0 {
                d1.cross(d2).length() / (len * len * len)
            } else {
                0.0
            },
        });
    }
    // Where t is vertical, V is the neighbour's (spec section 5).
    for &j in &vertical {
        if let Some(k) = neighbour_outside(j, &vertical, out.len()) {
            out[j].v = out[k].v;
        }
    }
    for (g, &[d1, d2]) in out.iter_mut().zip(&ders) {
        let a = g.tangent.truncate().length();
        g.n = (-g.tangent.z * g.v + a * DVec3::Z).normalize_or(DVec3::Z);
        // Signed curvature of the profile curve (s(u), z(u)) in the plane of V
        // and Z: (s' z'' - z' s'') / (s'^2 + z'^2)^(3/2), which equals
        // z_ss / (1 + z_s^2)^(3/2) of spec section 5 and stays finite where
        // the path is vertical.
        let (s1, z1) = (d1.dot(g.v), d1.z);
        let (s2, z2) = (d2.dot(g.v), d2.z);
        let q = s1 * s1 + z1 * z1;
        let den = q * q.sqrt();
        g.kappa = if den > 0.0 {
            (s1 * z2 - z1 * s2) / den
        } else {
            0.0
        };
    }
    for &j in &cusps {
        if let Some(k) = neighbour_outside(j, &cusps, out.len()) {
            let g = out[k];
            out[j] = LocalGeometry {
                curvature_3d: out[j].curvature_3d,
                ..g
            };
        }
    }
    out
}

/// The nearest point before `j` not in `listed` (sorted), else the nearest
/// after it, among `n` points: the one a point whose own geometry is
/// unusable borrows from (the one it arrives from, first).
fn neighbour_outside(j: usize, listed: &[usize], n: usize) -> Option<usize> {
    (0..j)
        .rev()
        .chain(j + 1..n)
        .find(|k| listed.binary_search(k).is_err())
}

/// |C'(u)| at most this share of its largest value along the spline marks
/// a point where the path turns straight back ([`geometry_of`]): with
/// chord-length parameters |C'| is about the path's length elsewhere, and
/// at an exact reversal it is rounding, some 1e-15 of it.
const CUSP: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;

    /// The span hint changes no bit: every parameter and knot, in order,
    /// backwards and from a hint far off, gives `find_span`'s span.
    #[test]
    fn a_span_hint_gives_the_searched_span() {
        let pts: Vec<DVec3> = (0..40)
            .map(|i| {
                let x = i as f64 * 0.25;
                DVec3::new(x, (x * 0.7).cos(), 0.05 * x * x)
            })
            .collect();
        let s = Spline::interpolate(&pts).unwrap();
        let mut us: Vec<f64> = s.params().to_vec();
        us.extend(s.knots.iter().copied());
        us.extend((0..=100).map(|i| i as f64 / 100.0));
        for order in [us.clone(), us.iter().rev().copied().collect()] {
            let hint = std::cell::Cell::new(usize::MAX);
            for &u in &order {
                assert_eq!(s.span_near(u, &hint), s.find_span(u), "u {u}");
                let far = std::cell::Cell::new(3);
                assert_eq!(s.span_near(u, &far), s.find_span(u), "u {u}");
                assert_eq!(s.derivs_near(u, &hint), s.derivs(u));
            }
        }
    }

    #[test]
    fn interpolates_its_points() {
        let pts: Vec<DVec3> = (0..20)
            .map(|i| {
                let x = i as f64 * 0.3;
                DVec3::new(x, 0.1 * x * x, (x * 1.3).sin())
            })
            .collect();
        let s = Spline::interpolate(&pts).unwrap();
        for (p, &u) in pts.iter().zip(s.params()) {
            assert!(
                (s.eval(u) - *p).length() < 1e-10,
                "{p:?} vs {:?}",
                s.eval(u)
            );
        }
    }

    #[test]
    fn two_and_three_points_work() {
        let g = local_geometry(&[DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)]).unwrap();
        assert!((g[0].slope_rad - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert_eq!(g[0].kappa, 0.0);
        let g = local_geometry(&[DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)]).unwrap();
        assert!(g.iter().all(|g| g.kappa.abs() < 1e-12));
    }

    /// QA round 9 M1: a piece whose last point lies 1.08 mm below the one
    /// before it, 0.29 mm on (snowden's feather): the spline overshoots
    /// and its C' there points back along the path. V follows the drawing,
    /// N leans forward off the drop, and the slope stays the spline's.
    #[test]
    fn a_sudden_drop_at_a_pieces_end_does_not_turn_v_back() {
        let dir = DVec3::new(-1.0, -1.0, 0.0).normalize();
        let mut pts: Vec<DVec3> = (0..13)
            .map(|i| DVec3::new(111.0, 111.0, 3.8) + dir * (0.29 * i as f64))
            .collect();
        pts.push(*pts.last().unwrap() + dir * 0.29 - DVec3::Z * 1.08);
        let raw = geometry_of(&Spline::interpolate(&pts).unwrap());
        let last = raw.len() - 1;
        // The spline's own direction there is backwards (what this mends).
        assert!(raw[last].v.dot(dir) < 0.0, "{:?}", raw[last].v);
        let g = local_geometry(&pts).unwrap();
        for (j, g) in g.iter().enumerate() {
            assert!(g.v.dot(dir) > 0.99, "{j}: {:?}", g.v);
        }
        let end = &g[last];
        assert!(
            end.descending() && end.n.dot(dir) > 0.5 && end.n.z > 0.0,
            "{end:?}"
        );
        assert_eq!(end.slope_rad, raw[last].slope_rad);
        assert_eq!(end.kappa, -raw[last].kappa);
        assert!((end.n.dot(end.tangent)).abs() < 1e-12);
    }

    fn arc(r: f64, concave_up: bool) -> Vec<DVec3> {
        // A circle of radius r in the x-z plane sampled every 0.3 mm of x.
        (0..=20)
            .map(|i| {
                let x = -3.0 + i as f64 * 0.3;
                let dz = r - (r * r - x * x).sqrt();
                DVec3::new(x, 2.0, if concave_up { dz } else { -dz })
            })
            .collect()
    }

    #[test]
    fn curvature_sign_and_size_on_circular_arcs() {
        for r in [5.0, 10.0] {
            let up = local_geometry(&arc(r, true)).unwrap();
            let down = local_geometry(&arc(r, false)).unwrap();
            // Interior points: within 1% of +-1/R.
            for j in 3..up.len() - 3 {
                assert!((up[j].kappa * r - 1.0).abs() < 0.01, "{}", up[j].kappa * r);
                assert!((down[j].kappa * r + 1.0).abs() < 0.01);
                assert!((up[j].curvature_3d * r - 1.0).abs() < 0.01);
                assert!(up[j].n.z > 0.0 && down[j].n.z > 0.0);
                assert!((up[j].n.dot(up[j].tangent)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn vertical_tangent_borrows_neighbours_direction() {
        let pts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(0.0, 2.0, 2.0),
        ];
        let g = local_geometry(&pts).unwrap();
        for gj in &g {
            assert!((gj.v.length() - 1.0).abs() < 1e-12);
            assert_eq!(gj.v.z, 0.0);
            assert!(gj.kappa.is_finite());
        }
    }

    #[test]
    fn a_path_turning_straight_back_keeps_the_direction_it_arrives_with() {
        // Out along a level line and back along it (a spike in a drawing):
        // the spline stops at the far end, where C' is rounding.
        let out: Vec<DVec3> = (0..=4)
            .map(|i| DVec3::new(12.413 + 1e-4 * i as f64, 178.08 - 0.23 * i as f64, 5.0))
            .collect();
        let pts: Vec<DVec3> = out
            .iter()
            .chain(out.iter().rev().skip(1))
            .copied()
            .collect();
        let g = local_geometry(&pts).unwrap();
        let turn = &g[4];
        assert_eq!(turn.v, g[3].v, "{turn:?}");
        assert_eq!(turn.kappa, g[3].kappa, "{turn:?}");
        assert_eq!(turn.slope_rad, g[3].slope_rad, "{turn:?}");
        for gj in &g {
            assert!(gj.kappa.abs() < 1e-6, "{gj:?}");
            assert!(gj.slope_rad.abs() < 1e-9, "{gj:?}");
            assert!(gj.v.y.abs() > 0.99, "{gj:?}");
        }
        // The apex moved by a rounding's worth either way: the chord of
        // rounding size through its neighbours does not turn its V (the
        // review of the direction's mend found it did).
        for dx in [1e-13, -1e-13, 1e-11] {
            let mut moved = pts.clone();
            moved[4].x += dx;
            let g = local_geometry(&moved).unwrap();
            assert_eq!(g[4].v, g[3].v, "{dx}: {:?}", g[4]);
        }
    }

    #[test]
    fn coincident_points_are_an_error() {
        let e = Spline::interpolate(&[DVec3::ZERO, DVec3::ZERO, DVec3::X]).unwrap_err();
        assert!(e.to_string().contains("coincide"), "{e}");
    }
}
