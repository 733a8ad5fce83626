//! Rigid registration scanner -> printer (spec section 1, paper eq. 1-5 and
//! Algorithm 1).
//!
//! [`register`] finds the rigid transform G with `G Sr_i ~ P_i` from fiducials
//! measured in both frames, by one of two methods:
//! - [`RegistrationMethod::Lsq`] (the default, beyond the paper): the
//!   least-squares rigid fit of all fiducials (Horn's closed-form quaternion
//!   method, no scaling, always a proper rotation);
//! - [`RegistrationMethod::Paper`]: the paper's three-point construction
//!   `G = t(P2) R2(v2, th2) R1(v1, th1) t(-S2r)`.
//!
//! Either way every fiducial's residual `|G Sr_i - P_i|` and their RMS are
//! reported, and fiducial sets that cannot define a rotation (coincident or
//! collinear points) are refused with an error naming the points.

use std::{fmt, str::FromStr};

use glam::{DMat3, DMat4, DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// Points closer than this fraction of the set's spread count as coincident.
pub const COINCIDENT_TOLERANCE: f64 = 1e-6;
/// A set whose largest triangle has an area below this fraction of the
/// spread squared is collinear: the rotation about that line is undefined.
pub const COLLINEAR_TOLERANCE: f64 = 1e-9;
/// Above this relative triangle area (but below 1e-3 of spread squared) the
/// set is accepted with a note: the rotation about the line is poorly
/// determined, so small measurement errors swing it widely.
pub const NEARLY_COLLINEAR_NOTE: f64 = 1e-3;
/// A pair of fiducials whose distances in the two frames differ by more than
/// this (plus [`DISTANCE_MISMATCH_RELATIVE`] of the distance) gets a note: a
/// rigid transform cannot fit it, so the points are likely mis-ordered,
/// mis-measured or in different units. The paper's Table S1 disagrees by
/// about 0.3 mm, which is normal.
pub const DISTANCE_MISMATCH_MM: f64 = 0.5;
/// Relative part of the distance-mismatch note threshold.
pub const DISTANCE_MISMATCH_RELATIVE: f64 = 0.01;

/// How [`register`] computes G.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RegistrationMethod {
    /// Least-squares rigid fit of all fiducials (Horn's quaternion method).
    #[default]
    Lsq,
    /// The paper's three-point construction (eq. 3-5); uses the first three
    /// fiducials only.
    Paper,
}

impl RegistrationMethod {
    /// The name accepted by [`FromStr`] and written in reports.
    pub fn name(self) -> &'static str {
        match self {
            RegistrationMethod::Lsq => "lsq",
            RegistrationMethod::Paper => "paper",
        }
    }
}

impl fmt::Display for RegistrationMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RegistrationMethod {
    type Err = RegistrationError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "lsq" => Ok(RegistrationMethod::Lsq),
            "paper" => Ok(RegistrationMethod::Paper),
            _ => Err(RegistrationError::UnknownMethod(s.to_string())),
        }
    }
}

/// A rigid transform scanner -> printer and how well it fits the fiducials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Registration {
    /// G: rotation and translation only (det of the 3x3 part is +1).
    pub matrix: DMat4,
    /// `|G Sr_i - P_i|` per fiducial, in input order, mm.
    pub residuals_mm: Vec<f64>,
    /// Root mean square of `residuals_mm`, mm.
    pub rms_mm: f64,
    /// Warnings for the user (distance mismatches, nearly collinear
    /// fiducials, fiducials the paper method ignored).
    #[serde(default)]
    pub notes: Vec<String>,
    /// How the scan came into the printer frame (registered, placed on the
    /// bed, or taken as it is).
    #[serde(default)]
    pub status: crate::placement::RegistrationStatus,
}

impl Default for Registration {
    fn default() -> Self {
        Self::identity()
    }
}

impl Registration {
    /// No transform (the scan is already in the printer frame).
    pub fn identity() -> Self {
        Registration {
            matrix: DMat4::IDENTITY,
            residuals_mm: Vec::new(),
            rms_mm: 0.0,
            notes: Vec::new(),
            status: crate::placement::RegistrationStatus::AsScanned,
        }
    }

    /// G as 4 x 4 rows (reports, the CLI, the page).
    pub fn matrix_row_major(&self) -> [[f64; 4]; 4] {
        let c = self.matrix.to_cols_array_2d();
        std::array::from_fn(|r| std::array::from_fn(|k| c[k][r]))
    }

    /// G^-1 p: maps a printer-frame point back into the scanner frame.
    pub fn apply_inverse(&self, p: DVec3) -> DVec3 {
        // G is rigid (rotation and translation), so its inverse is exact.
        self.matrix.inverse().transform_point3(p)
    }

    /// G p: maps a scanner-frame point into the printer frame.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.matrix.transform_point3(p)
    }

    /// The largest residual, mm (0 when there are none).
    pub fn max_residual_mm(&self) -> f64 {
        self.residuals_mm.iter().copied().fold(0.0, f64::max)
    }

    /// How far G tips the scan's up axis (its +Z as imported, after the
    /// up-axis choice) from the printer's +Z, degrees: 0 upright, 180
    /// upside down.
    pub fn up_tilt_deg(&self) -> f64 {
        let up = DMat3::from_mat4(self.matrix) * DVec3::Z;
        libm::acos((up.z / up.length()).clamp(-1.0, 1.0)).to_degrees()
    }

    /// Whether G turns the scan's up axis below the horizon: the nozzle,
    /// coming from above, would then meet the scan's underside
    /// ([`UPSIDE_DOWN_DEG`]).
    pub fn is_upside_down(&self) -> bool {
        self.up_tilt_deg() > UPSIDE_DOWN_DEG
    }

    /// The rotation angle of G, degrees (for reports).
    pub fn rotation_deg(&self) -> f64 {
        let r = DMat3::from_mat4(self.matrix);
        let c = ((r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0) * 0.5).clamp(-1.0, 1.0);
        libm::acos(c).to_degrees()
    }
}

/// A registration that tips the scan's up axis more than this from the
/// printer's +Z turns it upside down. A scan is taken from above, and
/// the part lies on the bed as it did under the scanner, give or take a
/// tilt; past 90 degrees the side the nozzle comes to is the side the
/// scanner did not see. With three fiducials (the paper's case) the
/// printer points listed in the other winding order are fitted exactly by
/// a half turn, residuals 0, so the residuals cannot tell; this can.
pub const UPSIDE_DOWN_DEG: f64 = 90.0;

/// Which of the two fiducial sets a point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PointSet {
    /// Sr, the scanner frame.
    Scan,
    /// P, the printer frame.
    Printer,
}

impl fmt::Display for PointSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PointSet::Scan => "scan",
            PointSet::Printer => "printer",
        })
    }
}

/// Why the fiducials do not define a rigid transform.
///
/// Point indices in the fields are 0-based; messages number fiducials from 1,
/// as the paper numbers S1r, S2r, S3r.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegistrationError {
    /// Fewer than three fiducials: pick or type at least three in each frame.
    #[error("registration needs at least 3 fiducials, got {0}: pick or type at least 3 points in each frame")]
    TooFew(usize),
    /// `auto` fiducials that cannot be chosen: too few printer points, or
    /// too few holes in the scan (the sentence says which).
    #[error("fiducials auto: {0}")]
    Auto(String),
    /// The two sets have different sizes: every scan fiducial needs its printer point.
    #[error("{scan} scan fiducials but {printer} printer fiducials: give the same points, in the same order, in both frames")]
    CountMismatch { scan: usize, printer: usize },
    /// A coordinate is NaN or infinite.
    #[error("{set} fiducial {} has a non-finite coordinate ({x}, {y}, {z})", .index + 1)]
    NonFinite {
        set: PointSet,
        index: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    /// Two fiducials of one set are (nearly) the same point.
    #[error("{set} fiducials {} and {} coincide ({}): each fiducial must be a distinct mark", .first + 1, .second + 1, apart(*.distance_mm))]
    Coincident {
        set: PointSet,
        first: usize,
        second: usize,
        distance_mm: f64,
    },
    /// The fiducials of one set lie on a line, so the rotation about it is undefined.
    #[error("{set} fiducials {} are collinear: use marks that span a triangle", list_1_based(.indices))]
    Collinear { set: PointSet, indices: Vec<usize> },
    /// `parse_points` could not read a point.
    #[error("point {} ({text:?}): {reason}; write points as \"x,y,z; x,y,z; ...\"", .index + 1)]
    Parse {
        index: usize,
        text: String,
        reason: String,
    },
    /// Not `lsq` or `paper`.
    #[error("unknown registration method {0:?}: use \"lsq\" or \"paper\"")]
    UnknownMethod(String),
    /// The fit leaves the fiducials farther from their printer points
    /// (RMS) than the nozzle's inner diameter: the scan is not where the
    /// printer is, so G-code on it is refused unless the risk is accepted
    /// (`job::refuse_bad_registration`).
    #[error(
        "the registration leaves the fiducials {rms_mm:.3} mm RMS from the printer points \
         (residuals [{}] mm), more than the nozzle's inner diameter d = {d_mm} mm: the scan is \
         not where the printer is, so neither where the path lands nor the clearance along the \
         moves can be trusted; check the printer points (their order, values and units) and \
         the scan's units; no G-code written",
        .residuals_mm.iter().map(|r| format!("{r:.3}")).collect::<Vec<_>>().join(", ")
    )]
    TooFarOff {
        rms_mm: f64,
        residuals_mm: Vec<f64>,
        d_mm: f64,
    },
    /// The fit turns the scan upside down ([`Registration::is_upside_down`]):
    /// the nozzle would come to the side the scanner did not see, so G-code
    /// on it is refused unless the risk is accepted
    /// (`job::refuse_bad_registration`).
    #[error(
        "the registration turns the scan upside down: its up axis ends {tilt_deg:.1} deg from \
         the printer's +Z (rms {rms_mm:.3} mm), so the path would be planned on the side the \
         scanner did not see; fiducials that lie in a plane (three always do), with the printer \
         points listed the other way round, fit a half turn as well as the right order \
         (residuals near 0): list the printer points in the same order as the scan's fiducials, or check the scan's \
         up axis (--up-axis; a depth camera's frame, z the distance from the camera, is -z); \
         no G-code written"
    )]
    UpsideDown { tilt_deg: f64, rms_mm: f64 },
}

/// How far apart two coincident fiducials are, as a person reads it: "the
/// same point", "3.2e-7 mm apart" (it printed "0e0 mm apart").
fn apart(distance_mm: f64) -> String {
    if distance_mm == 0.0 {
        "the same point".into()
    } else if distance_mm >= 0.001 {
        format!("{distance_mm:.3} mm apart")
    } else {
        format!("{distance_mm:.1e} mm apart")
    }
}

fn list_1_based(indices: &[usize]) -> String {
    let v: Vec<String> = indices.iter().map(|i| (i + 1).to_string()).collect();
    v.join(", ")
}

/// Reads points written as `x,y,z; x,y,z; ...` (mm). Points are separated by
/// `;` or line breaks, coordinates by `,` or spaces; empty points are skipped.
pub fn parse_points(text: &str) -> Result<Vec<DVec3>, RegistrationError> {
    let mut out = Vec::new();
    for chunk in text.split([';', '\n']) {
        let chunk = chunk.trim();
        if chunk.is_empty() {
            continue;
        }
        let index = out.len();
        let err = |reason: String| RegistrationError::Parse {
            index,
            text: chunk.to_string(),
            reason,
        };
        let coords: Vec<&str> = chunk
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if coords.len() != 3 {
            return Err(err(format!(
                "expected 3 coordinates, found {}",
                coords.len()
            )));
        }
        let mut xyz = [0.0; 3];
        for (slot, c) in xyz.iter_mut().zip(&coords) {
            let v: f64 = c
                .parse()
                .map_err(|_| err(format!("{c:?} is not a number")))?;
            if !v.is_finite() {
                return Err(err(format!("{c:?} is not finite")));
            }
            *slot = v;
        }
        out.push(DVec3::from_array(xyz));
    }
    Ok(out)
}

/// Finds G with `G scan_i ~ printer_i` (spec section 1).
///
/// `scan` holds Sr (fiducials in the scanner frame), `printer` holds P (the
/// same fiducials in the printer frame, same order). With
/// [`RegistrationMethod::Paper`] only the first three points determine G (the
/// paper's construction is defined for exactly three); the rest still get
/// residuals, and a note says they were not used.
///
/// # Errors
/// Fewer than 3 points, different counts, non-finite coordinates, coincident
/// or collinear points in either set (for the paper method: among the first
/// three).
pub fn register(
    scan: &[DVec3],
    printer: &[DVec3],
    method: RegistrationMethod,
) -> Result<Registration, RegistrationError> {
    if scan.len() != printer.len() {
        return Err(RegistrationError::CountMismatch {
            scan: scan.len(),
            printer: printer.len(),
        });
    }
    if scan.len() < 3 {
        return Err(RegistrationError::TooFew(scan.len()));
    }
    let mut notes = Vec::new();
    for (set, pts) in [(PointSet::Scan, scan), (PointSet::Printer, printer)] {
        check_finite(set, pts)?;
        check_coincident(set, pts)?;
    }
    // The paper method sees only the first three points, so only they must
    // span a triangle; the least-squares fit needs the whole set to.
    let used = match method {
        RegistrationMethod::Lsq => scan.len(),
        RegistrationMethod::Paper => 3,
    };
    for (set, pts) in [(PointSet::Scan, scan), (PointSet::Printer, printer)] {
        let rel = check_collinear(set, &pts[..used])?;
        if rel < NEARLY_COLLINEAR_NOTE {
            notes.push(format!(
                "{set} fiducials are nearly collinear (triangle area {rel:.1e} of spread squared): \
                 the rotation about their line is poorly determined"
            ));
        }
    }
    distance_notes(scan, printer, &mut notes);
    if method == RegistrationMethod::Paper && scan.len() > 3 {
        notes.push(format!(
            "paper registration uses fiducials 1-3 only; fiducials 4-{} are checked but not fitted",
            scan.len()
        ));
    }

    let matrix = match method {
        RegistrationMethod::Lsq => fit_lsq(scan, printer),
        RegistrationMethod::Paper => fit_paper(
            [scan[0], scan[1], scan[2]],
            [printer[0], printer[1], printer[2]],
        ),
    };
    let residuals_mm: Vec<f64> = scan
        .iter()
        .zip(printer)
        .map(|(s, p)| matrix.transform_point3(*s).distance(*p))
        .collect();
    let rms_mm =
        (residuals_mm.iter().map(|r| r * r).sum::<f64>() / residuals_mm.len() as f64).sqrt();
    let status = crate::placement::RegistrationStatus::Registered {
        method,
        fiducials: scan.len(),
        rms_mm,
    };
    let mut registration = Registration {
        matrix,
        residuals_mm,
        rms_mm,
        notes,
        status,
    };
    if registration.is_upside_down() {
        registration.notes.push(format!(
            "the registration turns the scan upside down (its up axis ends {:.1} deg from the \
             printer's +Z): are the printer points in the same order as the scan's fiducials? \
             G-code on it is refused unless the risk is accepted",
            registration.up_tilt_deg()
        ));
    }
    Ok(registration)
}

fn check_finite(set: PointSet, pts: &[DVec3]) -> Result<(), RegistrationError> {
    match pts.iter().position(|p| !p.is_finite()) {
        Some(index) => Err(RegistrationError::NonFinite {
            set,
            index,
            x: pts[index].x,
            y: pts[index].y,
            z: pts[index].z,
        }),
        None => Ok(()),
    }
}

/// The largest pairwise distance (the set's spread) and its pair.
fn spread(pts: &[DVec3]) -> (f64, usize, usize) {
    let mut best = (0.0, 0, 1.min(pts.len().saturating_sub(1)));
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let d = pts[i].distance(pts[j]);
            if d > best.0 {
                best = (d, i, j);
            }
        }
    }
    best
}

fn check_coincident(set: PointSet, pts: &[DVec3]) -> Result<(), RegistrationError> {
    let (s, _, _) = spread(pts);
    let tol = COINCIDENT_TOLERANCE * s;
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let d = pts[i].distance(pts[j]);
            // `<=` so that a set of identical points (spread 0) is refused too.
            if d <= tol {
                return Err(RegistrationError::Coincident {
                    set,
                    first: i,
                    second: j,
                    distance_mm: d,
                });
            }
        }
    }
    Ok(())
}

/// Refuses a collinear set; returns the largest triangle's area relative to
/// the spread squared (at most sqrt(3)/4, for an equilateral triangle).
fn check_collinear(set: PointSet, pts: &[DVec3]) -> Result<f64, RegistrationError> {
    let (s, i, j) = spread(pts);
    let axis = pts[j] - pts[i];
    // The point farthest from the line through the two extreme points spans
    // the largest triangle with them (within a factor of 2 of the largest).
    let area = pts
        .iter()
        .map(|p| 0.5 * axis.cross(*p - pts[i]).length())
        .fold(0.0, f64::max);
    let rel = if s > 0.0 { area / (s * s) } else { 0.0 };
    if rel < COLLINEAR_TOLERANCE || !rel.is_finite() {
        return Err(RegistrationError::Collinear {
            set,
            indices: (0..pts.len()).collect(),
        });
    }
    Ok(rel)
}

fn distance_notes(scan: &[DVec3], printer: &[DVec3], notes: &mut Vec<String>) {
    let mut worst: Option<(f64, usize, usize, f64, f64)> = None;
    let mut count = 0usize;
    for i in 0..scan.len() {
        for j in i + 1..scan.len() {
            let ds = scan[i].distance(scan[j]);
            let dp = printer[i].distance(printer[j]);
            let diff = (ds - dp).abs();
            if diff > DISTANCE_MISMATCH_MM + DISTANCE_MISMATCH_RELATIVE * dp {
                count += 1;
                if worst.is_none_or(|w| diff > w.0) {
                    worst = Some((diff, i, j, ds, dp));
                }
            }
        }
    }
    if let Some((diff, i, j, ds, dp)) = worst {
        let mut note = format!(
            "fiducials {} and {} are {ds:.3} mm apart in the scan but {dp:.3} mm on the printer \
             (differ by {diff:.3} mm; {count} pair(s) over {DISTANCE_MISMATCH_MM} mm + {}%): \
             check the order of the points and the scan's units",
            i + 1,
            j + 1,
            DISTANCE_MISMATCH_RELATIVE * 100.0
        );
        if dp > 0.0 {
            note.push_str(&format!(" (scan/printer ratio {:.4})", ds / dp));
        }
        notes.push(note);
    }
}

fn rigid(rotation: DMat3, from: DVec3, to: DVec3) -> DMat4 {
    // G x = R (x - from) + to, i.e. t(to) R t(-from) as in eq. 3.
    DMat4::from_mat3_translation(rotation, to - rotation * from)
}

/// The paper's construction (eq. 3-5), with the spec's decisions: th2 is the
/// signed angle between the parts of R1 a2 and b2 perpendicular to v2, and
/// a1 parallel or anti-parallel to b1 gets th1 = 0 or pi (any perpendicular
/// axis turns a1 onto -a1 then).
fn fit_paper(s: [DVec3; 3], p: [DVec3; 3]) -> DMat4 {
    let a1 = (s[0] - s[1]).normalize();
    let b1 = (p[0] - p[1]).normalize();
    let a2 = s[2] - s[1];
    let b2 = p[2] - p[1];

    let cross = a1.cross(b1);
    let sin1 = cross.length();
    let cos1 = a1.dot(b1);
    let r1 = if sin1 > 1e-14 {
        // Re-orthogonalising v1 against a1 keeps R1 a1 = b1 to rounding even
        // when th1 is near pi, where the direction of a tiny cross product is
        // poor but any axis perpendicular to a1 works.
        let v1 = cross / sin1;
        let v1 = (v1 - v1.dot(a1) * a1).normalize();
        axis_angle(v1, libm::atan2(sin1, cos1))
    } else if cos1 > 0.0 {
        DMat3::IDENTITY
    } else {
        axis_angle(a1.any_orthonormal_vector(), std::f64::consts::PI)
    };

    let v2 = (r1 * a1).normalize();
    let ra2 = r1 * a2;
    let u = ra2 - ra2.dot(v2) * v2;
    let w = b2 - b2.dot(v2) * v2;
    let th2 = libm::atan2(v2.dot(u.cross(w)), u.dot(w));
    let r2 = axis_angle(v2, th2);
    rigid(r2 * r1, s[1], p[1])
}

/// Horn (1987) closed-form absolute orientation with unit quaternions: the
/// rotation is the eigenvector of the largest eigenvalue of a symmetric 4x4
/// matrix built from the cross-covariance, so it is always proper (det +1);
/// the translation matches the centroids.
fn fit_lsq(scan: &[DVec3], printer: &[DVec3]) -> DMat4 {
    let n = scan.len() as f64;
    let cs = scan.iter().copied().sum::<DVec3>() / n;
    let cp = printer.iter().copied().sum::<DVec3>() / n;
    let mut m = [[0.0f64; 3]; 3];
    for (s, p) in scan.iter().zip(printer) {
        let a = (*s - cs).to_array();
        let b = (*p - cp).to_array();
        for (row, ai) in m.iter_mut().zip(a) {
            for (cell, bj) in row.iter_mut().zip(b) {
                *cell += ai * bj;
            }
        }
    }
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = m;
    let nmat = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (values, vectors) = symmetric_eigen4(nmat);
    let mut k = 0;
    for i in 1..4 {
        if values[i] > values[k] {
            k = i;
        }
    }
    let q = DQuat::from_xyzw(vectors[1][k], vectors[2][k], vectors[3][k], vectors[0][k]);
    let q = if q.length_squared() > 0.0 {
        q.normalize()
    } else {
        DQuat::IDENTITY
    };
    rigid(DMat3::from_quat(q), cs, cp)
}

/// Eigen-decomposition of a symmetric 4x4 matrix by cyclic Jacobi rotations:
/// returns the eigenvalues and the eigenvectors as the columns of the second
/// matrix. Jacobi is accurate to rounding for small symmetric matrices, which
/// keeps the recovered rotation at ~1e-15.
fn symmetric_eigen4(mut a: [[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let norm: f64 = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _sweep in 0..64 {
        let off: f64 = PAIRS.iter().map(|&(p, q)| a[p][q] * a[p][q]).sum();
        if off.sqrt() <= 1e-18 * norm || off == 0.0 {
            break;
        }
        for &(p, q) in &PAIRS {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
            for row in v.iter_mut() {
                let (vkp, vkq) = (row[p], row[q]);
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], v)
}

/// R(u, th): the axis-angle (Rodrigues) rotation of spec section 1, through
/// libm so it has the same bits natively and in wasm.
fn axis_angle(axis: DVec3, angle: f64) -> DMat3 {
    let (s, c) = (libm::sin(angle), libm::cos(angle));
    let (x, y, z) = (axis.x, axis.y, axis.z);
    let t = 1.0 - c;
    DMat3::from_cols(
        DVec3::new(t * x * x + c, t * x * y + s * z, t * x * z - s * y),
        DVec3::new(t * x * y - s * z, t * y * y + c, t * y * z + s * x),
        DVec3::new(t * x * z + s * y, t * y * z - s * x, t * z * z + c),
    )
}

/// The paper's Table S1 example (its 3 x 3 matrices hold the points as
/// columns): (Sr, P), scanner and printer frame. Its pairwise distances
/// disagree by ~0.3 mm, so residuals of that size are real (spec section 1).
pub fn paper_table_s1() -> (Vec<DVec3>, Vec<DVec3>) {
    let sr = [
        [-58.4037, -88.5714, -57.0373],
        [86.5977, 153.855, 153.469],
        [-39.1942, -53.3039, -124.727],
    ];
    let p = [
        [88.1799, 13.4989, 10.1549],
        [14.0904, 11.1944, 89.0994],
        [-50.7744, -50.7974, -50.7314],
    ];
    let cols = |m: [[f64; 3]; 3]| -> Vec<DVec3> {
        (0..3)
            .map(|j| DVec3::new(m[0][j], m[1][j], m[2][j]))
            .collect()
    };
    (cols(sr), cols(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen4_reconstructs_matrix() {
        let a = [
            [4.0, 1.0, -2.0, 0.5],
            [1.0, 3.0, 0.0, 1.5],
            [-2.0, 0.0, -1.0, 2.0],
            [0.5, 1.5, 2.0, 0.0],
        ];
        let (d, v) = symmetric_eigen4(a);
        for i in 0..4 {
            for j in 0..4 {
                let r: f64 = (0..4).map(|k| v[i][k] * d[k] * v[j][k]).sum();
                assert!((r - a[i][j]).abs() < 1e-13, "{i} {j}: {r} vs {}", a[i][j]);
                let o: f64 = (0..4).map(|k| v[k][i] * v[k][j]).sum();
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((o - e).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn table_s1_columns_are_points() {
        let (s, p) = paper_table_s1();
        // Read as columns, the printer points share z (a flat stage) and the
        // pairwise distances agree to ~0.3 mm; read as rows they would not.
        assert!(p.iter().all(|q| (q.z + 50.77).abs() < 0.05));
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            let d = (s[i].distance(s[j]) - p[i].distance(p[j])).abs();
            assert!(d < 0.4, "pair {i},{j} differs by {d}");
        }
    }

    #[test]
    fn table_s1_residuals() {
        let (s, p) = paper_table_s1();
        let lsq = register(&s, &p, RegistrationMethod::Lsq).unwrap();
        let paper = register(&s, &p, RegistrationMethod::Paper).unwrap();
        assert!(lsq.rms_mm <= paper.rms_mm + 1e-12);
        assert!((0.05..=0.35).contains(&lsq.rms_mm), "{}", lsq.rms_mm);
        assert!(lsq.notes.is_empty(), "{:?}", lsq.notes);
    }

    #[test]
    fn method_parses() {
        assert_eq!(
            "Paper".parse::<RegistrationMethod>().unwrap(),
            RegistrationMethod::Paper
        );
        assert_eq!(
            "lsq".parse::<RegistrationMethod>().unwrap(),
            RegistrationMethod::Lsq
        );
        assert!("kabsch".parse::<RegistrationMethod>().is_err());
    }

    #[test]
    fn parse_points_forms() {
        let pts = parse_points("1,2,3; 4 5 6\n7, 8, 9;").unwrap();
        assert_eq!(
            pts,
            vec![
                DVec3::new(1.0, 2.0, 3.0),
                DVec3::new(4.0, 5.0, 6.0),
                DVec3::new(7.0, 8.0, 9.0)
            ]
        );
        let e = parse_points("1,2,3;4,5").unwrap_err().to_string();
        assert!(e.contains("point 2") && e.contains("expected 3"), "{e}");
        let e = parse_points("1,2,x").unwrap_err().to_string();
        assert!(e.contains("\"x\" is not a number"), "{e}");
        let e = parse_points("1,2,inf").unwrap_err().to_string();
        assert!(e.contains("not finite"), "{e}");
    }
}
