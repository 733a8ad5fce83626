//! Property tests (proptest, 64 cases each so `cargo test` stays quick):
//! registration, projection, the guarded planner's clearance, the paper
//! planner's stand-off and the G-code writer, each checked against a
//! reference written here that shares no code with the library.

use pcpp::gcode::{write_gcode, GcodeJob, MachineProfile};
use pcpp::mesh::TriMesh;
use pcpp::pipeline::{self, Plan, PlanSettings};
use pcpp::planners::PlannerKind;
use pcpp::registration::{register, RegistrationMethod};
use pcpp::surface::{SpatialIndex, Surface};
use pcpp::svg::{Placement, Subpath2};
use pcpp::{DMat4, DVec2, DVec3, Nozzle, Process};
use proptest::prelude::*;

const CASES: u32 = 64;

// ---------------------------------------------------------------------------
// Registration
// ---------------------------------------------------------------------------

/// Rotation by `angle` about `axis` (Rodrigues), written out so the test
/// does not lean on glam's quaternions as the library does.
fn rigid(axis: DVec3, angle: f64, t: DVec3) -> DMat4 {
    let k = axis.normalize();
    let (s, c) = angle.sin_cos();
    let v = 1.0 - c;
    let r = [
        [
            c + k.x * k.x * v,
            k.x * k.y * v - k.z * s,
            k.x * k.z * v + k.y * s,
        ],
        [
            k.y * k.x * v + k.z * s,
            c + k.y * k.y * v,
            k.y * k.z * v - k.x * s,
        ],
        [
            k.z * k.x * v - k.y * s,
            k.z * k.y * v + k.x * s,
            c + k.z * k.z * v,
        ],
    ];
    // Column-major, as DMat4 stores it.
    DMat4::from_cols_array(&[
        r[0][0], r[1][0], r[2][0], 0.0, //
        r[0][1], r[1][1], r[2][1], 0.0, //
        r[0][2], r[1][2], r[2][2], 0.0, //
        t.x, t.y, t.z, 1.0,
    ])
}

fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// The first three points span a well-shaped triangle and no two points
/// are close: the fit is then well determined.
fn well_conditioned(pts: &[DVec3]) -> bool {
    let spread = pts
        .iter()
        .flat_map(|a| pts.iter().map(move |b| a.distance(*b)))
        .fold(0.0, f64::max);
    let close = pts
        .iter()
        .enumerate()
        .any(|(i, a)| pts[i + 1..].iter().any(|b| a.distance(*b) < 0.05 * spread));
    let area = 0.5 * (pts[1] - pts[0]).cross(pts[2] - pts[0]).length();
    !close && area > 0.02 * spread * spread
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// Both methods recover any rigid transform from exact fiducials.
    #[test]
    fn registration_recovers_any_rigid_transform(
        scan in prop::collection::vec(vec3(60.0), 3..8),
        axis in vec3(1.0),
        angle in -std::f64::consts::PI..std::f64::consts::PI,
        shift in vec3(150.0),
        paper in any::<bool>(),
    ) {
        prop_assume!(axis.length() > 0.1);
        prop_assume!(well_conditioned(&scan));
        let g = rigid(axis, angle, shift);
        let printer: Vec<DVec3> = scan.iter().map(|p| g.transform_point3(*p)).collect();
        let method = if paper { RegistrationMethod::Paper } else { RegistrationMethod::Lsq };
        let reg = register(&scan, &printer, method)
            .map_err(|e| TestCaseError::fail(format!("{method}: {e}")))?;
        let (got, want) = (reg.matrix.to_cols_array(), g.to_cols_array());
        for k in 0..16 {
            // Rotation entries are unitless, translation entries in mm.
            prop_assert!(
                (got[k] - want[k]).abs() < 1e-6,
                "{method}: entry {k}: {} vs {}\n got {:?}\nwant {:?}", got[k], want[k], reg.matrix, g
            );
        }
        for (s, p) in scan.iter().zip(&printer) {
            prop_assert!(reg.apply(*s).distance(*p) < 1e-6);
        }
        prop_assert!(reg.rms_mm < 1e-6, "{method}: rms {}", reg.rms_mm);
    }
}

// ---------------------------------------------------------------------------
// Surfaces built in the test
// ---------------------------------------------------------------------------

/// A height field on an n x n grid of spacing h from (0, 0); `z[j * n + i]`
/// is the height at (i h, j h). Cells are split along their rising diagonal.
#[derive(Debug, Clone)]
struct Field {
    n: usize,
    h: f64,
    z: Vec<f64>,
}

impl Field {
    fn size(&self) -> f64 {
        self.h * (self.n - 1) as f64
    }

    fn mesh(&self) -> TriMesh {
        let n = self.n;
        let mut m = TriMesh::default();
        for j in 0..n {
            for i in 0..n {
                m.vertices.push(DVec3::new(
                    i as f64 * self.h,
                    j as f64 * self.h,
                    self.z[j * n + i],
                ));
            }
        }
        let w = n as u32;
        for j in 0..w - 1 {
            for i in 0..w - 1 {
                let a = j * w + i;
                m.triangles.push([a, a + 1, a + w + 1]);
                m.triangles.push([a, a + w + 1, a + w]);
            }
        }
        m
    }

    /// z of the triangle under (x, y), by barycentric interpolation of its
    /// corners.
    fn height(&self, x: f64, y: f64) -> f64 {
        let n = self.n;
        let i = ((x / self.h).floor() as usize).min(n - 2);
        let j = ((y / self.h).floor() as usize).min(n - 2);
        let (u, v) = (x / self.h - i as f64, y / self.h - j as f64);
        let z = |di: usize, dj: usize| self.z[(j + dj) * n + i + di];
        let (za, zb, zc, zd) = (z(0, 0), z(1, 0), z(1, 1), z(0, 1));
        // Lower triangle a b c holds u >= v, upper a c d holds u <= v; the
        // weights of a, b, c are (1 - u, u - v, v) and of a, c, d (1 - v, u, v - u).
        if u >= v {
            (1.0 - u) * za + (u - v) * zb + v * zc
        } else {
            (1.0 - v) * za + u * zc + (v - u) * zd
        }
    }
}

/// A bumpy height field: random heights at 5-10 grid points a side.
fn field(amplitude: f64) -> impl Strategy<Value = Field> {
    (5usize..11, 0.8f64..3.0).prop_flat_map(move |(n, h)| {
        prop::collection::vec(-amplitude..amplitude, n * n).prop_map(move |z| Field { n, h, z })
    })
}

/// Steps with true vertical walls across x: the grid repeats each wall's x,
/// once at the level on its left and once at the level on its right, so
/// the wall is a strip of vertical triangles.
#[derive(Debug, Clone)]
struct Steps {
    size: f64,
    walls: Vec<f64>,
    levels: Vec<f64>,
}

impl Steps {
    fn mesh(&self) -> TriMesh {
        // Columns (x, level index), walls doubled.
        let mut cols: Vec<(f64, usize)> = Vec::new();
        let nx = 24;
        let mut wall = 0;
        for k in 0..=nx {
            let x = self.size * k as f64 / nx as f64;
            while wall < self.walls.len() && self.walls[wall] <= x {
                let w = self.walls[wall];
                if cols.last().is_none_or(|c| c.0 < w) {
                    cols.push((w, wall));
                }
                cols.push((w, wall + 1));
                wall += 1;
            }
            if cols.last().is_none_or(|c| c.0 < x) {
                cols.push((x, wall));
            }
        }
        let ny = 12;
        let mut m = TriMesh::default();
        for j in 0..=ny {
            let y = self.size * j as f64 / ny as f64;
            for &(x, l) in &cols {
                m.vertices
                    .push(DVec3::new(x, y, self.levels[l] + 0.2 * (y * 0.7).sin()));
            }
        }
        let w = cols.len() as u32;
        for j in 0..ny as u32 {
            for i in 0..w - 1 {
                let a = j * w + i;
                m.triangles.push([a, a + 1, a + w + 1]);
                m.triangles.push([a, a + w + 1, a + w]);
            }
        }
        m
    }
}

fn steps() -> impl Strategy<Value = Steps> {
    (
        8.0f64..20.0,
        prop::collection::vec(0.1f64..0.9, 1..4),
        prop::collection::vec(0.0f64..4.0, 4),
    )
        .prop_map(|(size, mut walls, mut levels)| {
            walls.sort_by(f64::total_cmp);
            walls.dedup_by(|a, b| (*a - *b).abs() < 0.05);
            // Walls of at least 0.3 mm, both up and down.
            for k in 1..levels.len() {
                if (levels[k] - levels[k - 1]).abs() < 0.3 {
                    levels[k] = levels[k - 1] + if k % 2 == 0 { 0.5 } else { -0.5 };
                }
            }
            Steps {
                size,
                walls: walls.into_iter().map(|w| w * size).collect(),
                levels,
            }
        })
}

/// A drawn polyline of 2-5 points inside [m, size - m]^2 (unit square
/// coordinates scaled by the caller).
fn polyline() -> impl Strategy<Value = Vec<DVec2>> {
    prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 2..6)
        .prop_map(|v| v.into_iter().map(|(x, y)| DVec2::new(x, y)).collect())
}

/// The drawing in printer mm (identity placement; the SVG stage is tested
/// on its own).
fn drawing(unit: &[DVec2], lo: f64, hi: f64) -> Option<Subpath2> {
    let points: Vec<DVec2> = unit.iter().map(|p| lo + (hi - lo) * *p).collect();
    // Repeated points make a zero-length segment, which is not what is tested.
    if points.windows(2).any(|w| w[0].distance(w[1]) < 0.05) {
        return None;
    }
    Some(Subpath2 {
        corner: vec![true; points.len()],
        points,
        closed: false,
        source: "property".into(),
    })
}

fn plan(surface: &Surface, sub: &Subpath2, settings: &PlanSettings) -> Result<Plan, TestCaseError> {
    pipeline::plan(surface, std::slice::from_ref(sub), settings)
        .map_err(|e| TestCaseError::fail(format!("plan failed: {e}")))
}

fn nozzle_and_process() -> impl Strategy<Value = (Nozzle, Process)> {
    (0.2f64..1.0, 1.2f64..2.0, 0.02f64..0.3).prop_map(|(d, ratio, tol)| {
        (
            Nozzle {
                inner_diameter_mm: d,
                outer_diameter_mm: d * ratio,
            },
            Process::DEFAULT.with_tolerance_mm(tol),
        )
    })
}

// ---------------------------------------------------------------------------
// Brute-force clearance
// ---------------------------------------------------------------------------

/// Closest point of segment ab to p.
fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// Closest point of triangle abc to p: the foot of the perpendicular on the
/// triangle's plane when it falls inside (barycentric signs), else the
/// nearest of the three edges. Degenerate triangles reduce to their edges.
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2 > 1e-24 {
        let foot = p - n * ((p - a).dot(n) / n2);
        let wa = (c - b).cross(foot - b).dot(n);
        let wb = (a - c).cross(foot - c).dot(n);
        let wc = (b - a).cross(foot - a).dot(n);
        if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
            return foot;
        }
    }
    [
        closest_on_segment(p, a, b),
        closest_on_segment(p, b, c),
        closest_on_segment(p, c, a),
    ]
    .into_iter()
    .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
    .unwrap_or(a)
}

/// Points of the nozzle at tip `t`: the tip disk (rings of radius up to
/// `r`) and the rim of the body, a vertical cylinder of radius `r`, up to
/// 2 mm above the tip.
fn nozzle_samples(t: DVec3, r: f64) -> Vec<DVec3> {
    let mut s = vec![t];
    for ring in 1..=6 {
        let rr = r * ring as f64 / 6.0;
        let n = 10 * ring;
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            s.push(t + DVec3::new(rr * a.cos(), rr * a.sin(), 0.0));
        }
    }
    for level in 1..=8 {
        for k in 0..24 {
            let a = std::f64::consts::TAU * k as f64 / 24.0;
            s.push(t + DVec3::new(r * a.cos(), r * a.sin(), 0.25 * level as f64));
        }
    }
    s
}

/// Smallest distance from the sampled nozzle to any triangle, by brute
/// force (a triangle whose box is farther than `limit` from the samples'
/// box cannot be nearer than `limit`, and is skipped). The samples are a
/// subset of the nozzle, so this is never below the true clearance.
fn clearance(m: &TriMesh, samples: &[DVec3], limit: f64) -> (f64, DVec3) {
    let lo = samples.iter().fold(DVec3::INFINITY, |a, p| a.min(*p)) - limit;
    let hi = samples.iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(*p)) + limit;
    let mut best = (f64::INFINITY, DVec3::ZERO);
    for tri in &m.triangles {
        let [a, b, c] = tri.map(|k| m.vertices[k as usize]);
        if a.max(b).max(c).cmplt(lo).any() || a.min(b).min(c).cmpgt(hi).any() {
            continue;
        }
        for &p in samples {
            let q = closest_on_triangle(p, a, b, c);
            let d = p.distance(q);
            if d < best.0 {
                best = (d, p);
            }
        }
    }
    best
}

/// Every point of a guarded plan clears the surface by tol, by brute force.
fn assert_guarded_clears(
    mesh: &TriMesh,
    plan: &Plan,
    nozzle: &Nozzle,
    tol: f64,
) -> Result<(), TestCaseError> {
    prop_assert!(plan.uncleared.is_empty(), "uncleared {:?}", plan.uncleared);
    let r = 0.5 * nozzle.outer_diameter_mm;
    for piece in &plan.pieces {
        for (j, t) in piece.toolpath.iter().enumerate() {
            let (d, at) = clearance(mesh, &nozzle_samples(*t, r), tol + 0.01);
            // The guarded test makes the true clearance >= tol exactly
            // (surface within do/2 + tol of the axis lies tol below the tip);
            // samples can only over-estimate it, so the slack is rounding.
            prop_assert!(
                d >= tol - 1e-6,
                "point {j} T* {t:?} (Ta {:?}): clearance {d} < tol {tol} at nozzle point {at:?}",
                piece.surface_path[j]
            );
        }
    }
    Ok(())
}

/// The paper's planner never puts T* below the point Ta it was planned
/// from.
fn assert_pcpp_above(plan: &Plan) -> Result<(), TestCaseError> {
    for piece in &plan.pieces {
        for (j, (t, a)) in piece.toolpath.iter().zip(&piece.surface_path).enumerate() {
            prop_assert!(t.z >= a.z, "point {j}: T* {t:?} below Ta {a:?}");
        }
    }
    Ok(())
}

/// Either spatial index: every query property must hold for both.
fn index_kind() -> impl Strategy<Value = SpatialIndex> {
    prop_oneof![Just(SpatialIndex::Grid), Just(SpatialIndex::Bvh)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// The highest hit of a vertical line is the height of the triangle
    /// under it, anywhere on a bumpy field.
    #[test]
    fn highest_hit_is_the_barycentric_height(
        f in field(3.0),
        xy in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 20),
        index in index_kind(),
    ) {
        let s = Surface::with_index(f.mesh(), index).map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (u, v) in xy {
            let (x, y) = (u * f.size(), v * f.size());
            let z = s.highest_hit(DVec2::new(x, y));
            prop_assert!(z.is_some(), "({x}, {y}) missed the field");
            let want = f.height(x, y);
            prop_assert!((z.unwrap_or(f64::NAN) - want).abs() < 1e-6, "({x}, {y}): {z:?} vs {want}");
        }
    }

    /// Every projected point Ta of a drawn path lies on the mesh.
    #[test]
    fn projected_points_lie_on_the_mesh(
        f in field(3.0),
        line in polyline(),
        index in index_kind(),
    ) {
        let size = f.size();
        let Some(sub) = drawing(&line, 0.02 * size, 0.98 * size) else {
            return Ok(());
        };
        let s = Surface::with_index(f.mesh(), index)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let sp = pipeline::surface_path(&s, &[sub], &Nozzle::DEFAULT, &Placement::IDENTITY)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(!sp.pieces.is_empty());
        for piece in &sp.pieces {
            for p in &piece.ta {
                let want = f.height(p.x, p.y);
                prop_assert!((p.z - want).abs() < 1e-6, "Ta {p:?}: surface z {want}");
            }
        }
    }

    /// pcpp-guarded clears bumpy fields by tol; pcpp stays above Ta.
    #[test]
    fn guarded_clears_bumpy_fields(
        f in field(1.5),
        line in polyline(),
        (nozzle, process) in nozzle_and_process(),
        index in index_kind(),
    ) {
        let size = f.size();
        let Some(sub) = drawing(&line, 0.05 * size, 0.95 * size) else {
            return Ok(());
        };
        let mesh = f.mesh();
        let s = Surface::with_index(mesh.clone(), index)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let mut settings = PlanSettings { nozzle, process, ..Default::default() };
        settings.planner = PlannerKind::PcppGuarded;
        assert_guarded_clears(&mesh, &plan(&s, &sub, &settings)?, &nozzle, process.tolerance_mm)?;
        settings.planner = PlannerKind::Pcpp;
        assert_pcpp_above(&plan(&s, &sub, &settings)?)?;
    }

    /// The same on steps with vertical walls, crossed at any angle.
    #[test]
    fn guarded_clears_vertical_walls(
        st in steps(),
        line in polyline(),
        (nozzle, process) in nozzle_and_process(),
        index in index_kind(),
    ) {
        let Some(sub) = drawing(&line, 0.05 * st.size, 0.95 * st.size) else {
            return Ok(());
        };
        let mesh = st.mesh();
        let s = Surface::with_index(mesh.clone(), index)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let mut settings = PlanSettings { nozzle, process, ..Default::default() };
        settings.planner = PlannerKind::PcppGuarded;
        assert_guarded_clears(&mesh, &plan(&s, &sub, &settings)?, &nozzle, process.tolerance_mm)?;
        settings.planner = PlannerKind::Pcpp;
        assert_pcpp_above(&plan(&s, &sub, &settings)?)?;
    }
}

// ---------------------------------------------------------------------------
// G-code read back
// ---------------------------------------------------------------------------

/// Reads the printed pieces back from a Marlin program: the head position
/// follows every G0/G1 (modal axes), a piece starts where the valve opens
/// (M106) and takes each G1 until it closes (M107).
fn read_marlin(text: &str) -> Result<Vec<Vec<DVec3>>, String> {
    let mut at = [f64::NAN; 3];
    let mut open: Option<Vec<DVec3>> = None;
    let mut pieces = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split(';').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let Some(cmd) = words.next() else { continue };
        match cmd {
            "G0" | "G1" => {
                for w in words {
                    let axis = match w.as_bytes()[0] {
                        b'X' => 0,
                        b'Y' => 1,
                        b'Z' => 2,
                        b'F' => continue,
                        _ => return Err(format!("line {}: unknown word {w}", n + 1)),
                    };
                    at[axis] = w[1..]
                        .parse()
                        .map_err(|e| format!("line {}: {w}: {e}", n + 1))?;
                }
                if let Some(piece) = open.as_mut() {
                    if cmd == "G0" {
                        return Err(format!("line {}: rapid move while dispensing", n + 1));
                    }
                    piece.push(DVec3::from_array(at));
                }
            }
            "M106" => open = Some(vec![DVec3::from_array(at)]),
            "M107" => pieces.extend(open.take()),
            _ => {}
        }
    }
    Ok(pieces)
}

fn toolpaths() -> impl Strategy<Value = Vec<Vec<DVec3>>> {
    let point =
        (1.0f64..219.0, 1.0f64..219.0, 0.0f64..200.0).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    prop::collection::vec(prop::collection::vec(point, 0..30), 1..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    /// The Marlin program, read back, gives the tool path to 0.0005 mm
    /// (three decimals), piece by piece, empty pieces left out.
    #[test]
    fn gcode_reads_back_as_the_toolpath(
        paths in toolpaths(),
        speed in 0.5f64..50.0,
        dwell in prop_oneof![Just(0.0), 0.0f64..2.0],
        top in 0.0f64..10.0,
    ) {
        let profile = MachineProfile::builtin("marlin")
            .ok_or_else(|| TestCaseError::fail("no marlin profile"))?;
        let header = vec![("test".to_string(), "properties".to_string())];
        let text = write_gcode(
            &GcodeJob {
                toolpaths: &paths,
                speed_mm_s: speed,
                dwell_s: dwell,
                header: &header,
                scan_top_z_mm: top,
            },
            &profile,
        )
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = read_marlin(&text).map_err(TestCaseError::fail)?;
        let want: Vec<&Vec<DVec3>> = paths.iter().filter(|p| !p.is_empty()).collect();
        prop_assert_eq!(back.len(), want.len());
        for (k, (got, want)) in back.iter().zip(want).enumerate() {
            prop_assert_eq!(got.len(), want.len(), "piece {}", k);
            for (j, (g, w)) in got.iter().zip(want).enumerate() {
                prop_assert!(
                    (*g - *w).abs().max_element() <= 0.0005 + 1e-9,
                    "piece {k} point {j}: read {g:?}, planned {w:?}"
                );
            }
        }
    }
}
