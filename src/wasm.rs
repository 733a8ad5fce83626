//! The page's entry point (wasm32 only): the one `#[wasm_bindgen]` file.
//!
//! Like usvg's C API it only converts types (serde-wasm-bindgen for
//! settings and results, `&[u8]` for file bytes) and flattens errors into a
//! JS `Error` carrying the core's message; every planning decision is made
//! by [`crate::job`], the same code the CLI runs, so the page's G-code and
//! report are the CLI's byte for byte.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

use crate::demo::{self, antennas, test_part};
use crate::gcode::MachineProfile;
use crate::job::{self, JobSettings, PreparedScan, RegistrationSettings};
use crate::mesh::ImportOptions;
use crate::pipeline::PlanSettings;
use crate::render::{Markers, Renderer, ViewPaths};

/// A core error as the JS `Error` the page shows: its message names the
/// file, line or point at fault.
fn js_err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// A core error as a JS `Error` with a `kind` naming the stage that failed
/// (`mesh`, `svg`, `registration` or `other`): the page drops a file whose
/// bytes could not be read but keeps one that only failed to register.
fn core_err(e: crate::Error) -> JsValue {
    use crate::Error;
    // `matches!` rather than a `match`, so a variant added to the core later
    // falls to "other" instead of breaking this adapter.
    let kind = if matches!(e, Error::Mesh(_)) {
        "mesh"
    } else if matches!(e, Error::Svg(_)) {
        "svg"
    } else if matches!(e, Error::Registration(_)) {
        "registration"
    } else {
        "other"
    };
    let err = js_sys::Error::new(&e.to_string());
    // Setting a property on a fresh Error cannot fail; if it did, the
    // message alone still reaches the page.
    let _ = js_sys::Reflect::set(&err, &"kind".into(), &kind.into());
    err.into()
}

fn from_js<T: for<'de> Deserialize<'de>>(what: &str, v: JsValue) -> Result<T, JsError> {
    serde_wasm_bindgen::from_value(v).map_err(|e| JsError::new(&format!("invalid {what}: {e}")))
}

fn to_js<T: Serialize + ?Sized>(v: &T) -> Result<JsValue, JsError> {
    // Maps as plain objects, so the page reads `x.field`, not `x.get(..)`.
    let s = serde_wasm_bindgen::Serializer::new().serialize_maps_as_objects(true);
    v.serialize(&s).map_err(js_err)
}

/// Installs the panic hook: a bug in the core then reaches the console
/// with its message instead of an opaque "unreachable" trap.
#[wasm_bindgen(js_name = initPanicHook)]
pub fn init_panic_hook() {
    console_error_panic_hook::set_once();
}

/// The crate version (shown in the page footer).
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Default job settings (the paper's), as the settings object the page edits.
#[wasm_bindgen(js_name = defaultSettings)]
pub fn default_settings() -> Result<JsValue, JsError> {
    to_js(&JobSettings::default())
}

/// The names of the built-in machine profiles (G-code dialects).
#[wasm_bindgen]
pub fn dialects() -> Vec<String> {
    MachineProfile::builtin_names()
        .into_iter()
        .map(String::from)
        .collect()
}

/// The demo scan (the paper's test part) as the binary PLY a user could load.
#[wasm_bindgen(js_name = demoScan)]
pub fn demo_scan() -> Vec<u8> {
    demo::demo_scan_bytes()
}

#[wasm_bindgen(js_name = demoScanName)]
pub fn demo_scan_name() -> String {
    demo::DEMO_SCAN_NAME.to_string()
}

/// The demo's drawn line paths, as SVG text.
#[wasm_bindgen(js_name = demoPathSvg)]
pub fn demo_path_svg() -> String {
    test_part::test_part_svg()
}

#[wasm_bindgen(js_name = demoPathName)]
pub fn demo_path_name() -> String {
    demo::DEMO_PATH_NAME.to_string()
}

/// The demo's settings: its placement, and auto fiducials against the
/// part's three holes (already in the printer frame, so G is ~identity).
#[wasm_bindgen(js_name = demoSettings)]
pub fn demo_settings() -> Result<JsValue, JsError> {
    let mut s = JobSettings::default();
    s.plan.placement = test_part::placement();
    s.registration = RegistrationSettings {
        fiducials: job::FiducialSource::Auto,
        printer_points: test_part::FIDUCIALS_MM.to_vec(),
        ..RegistrationSettings::default()
    };
    to_js(&s)
}

/// Points typed as `x,y,z; x,y,z` or one per line (the registration's
/// parser, so the page and the CLI read the same text the same way).
#[wasm_bindgen(js_name = parsePoints)]
pub fn parse_points(text: &str) -> Result<JsValue, JsError> {
    let points = crate::registration::parse_points(text).map_err(js_err)?;
    let points: Vec<[f64; 3]> = points.into_iter().map(arr).collect();
    to_js(&points)
}

/// Bounds of a drawing as imported (mm, y up, before placement):
/// `[min x, min y, max x, max y]`. The page centres a path on the scan with
/// it, without reading SVG geometry in JS.
#[wasm_bindgen(js_name = pathBounds)]
pub fn path_bounds(svg: &[u8], name: &str) -> Result<Vec<f64>, JsValue> {
    let drawn = crate::pipeline::load_path(svg, name).map_err(core_err)?;
    let mut points = drawn.subpaths.iter().flat_map(|s| s.points.iter());
    let Some(&first) = points.next() else {
        return Err(JsError::new(&format!("{name}: the drawing has no paths")).into());
    };
    let (lo, hi) = points.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    Ok(vec![lo.x, lo.y, hi.x, hi.y])
}

/// Parameters of the built-in antenna generators; absent fields take the
/// paper's values.
#[derive(Deserialize)]
#[serde(default)]
struct AntennaParams {
    turns: Option<f64>,
    pitch_mm: f64,
    inner_radius_mm: f64,
    order: u32,
    size_mm: f64,
    height_mm: f64,
    base_mm: f64,
    feed_mm: f64,
}

impl Default for AntennaParams {
    fn default() -> Self {
        AntennaParams {
            turns: None,
            pitch_mm: antennas::PAPER_SPIRAL_PITCH_MM,
            inner_radius_mm: antennas::PAPER_SPIRAL_INNER_RADIUS_MM,
            order: 3,
            size_mm: 20.0,
            height_mm: 20.0,
            base_mm: 15.0,
            feed_mm: 5.0,
        }
    }
}

/// SVG text of a built-in antenna: `kind` is `spiral` (no `turns`: the
/// paper's 556 mm spiral), `hilbert` or `monopole`.
#[wasm_bindgen(js_name = antennaSvg)]
pub fn antenna_svg(kind: &str, params: JsValue) -> Result<String, JsError> {
    let p: AntennaParams = if params.is_undefined() || params.is_null() {
        AntennaParams::default()
    } else {
        from_js("antenna parameters", params)?
    };
    match kind {
        "spiral" => match p.turns {
            None => Ok(antennas::paper_spiral_svg()),
            Some(t) => {
                antennas::archimedean_spiral_svg(t, p.pitch_mm, p.inner_radius_mm).map_err(js_err)
            }
        },
        "hilbert" => antennas::hilbert_loop_svg(p.order, p.size_mm).map_err(js_err),
        "monopole" => {
            antennas::triangular_monopole_svg(p.height_mm, p.base_mm, p.feed_mm).map_err(js_err)
        }
        other => Err(JsError::new(&format!(
            "unknown antenna '{other}' (expected spiral, hilbert or monopole)"
        ))),
    }
}

/// The machine profile to write with: a built-in name (`marlin`, ...) or a
/// user's profile as JSON text, validated by the core; `file_name` labels
/// the JSON's errors (which then name the file and the field).
fn profile(dialect: &str, file_name: Option<&str>) -> Result<MachineProfile, JsValue> {
    if let Some(p) = MachineProfile::builtin(dialect) {
        return Ok(p);
    }
    if dialect.trim_start().starts_with('{') {
        let name = file_name.unwrap_or("machine profile");
        return MachineProfile::from_json(dialect, name).map_err(|e| core_err(e.into()));
    }
    Err(JsError::new(&format!(
        "unknown G-code dialect '{dialect}' (expected one of {}, or a machine profile as JSON)",
        MachineProfile::builtin_names().join(", ")
    ))
    .into())
}

/// A user's machine profile checked before the page offers it: returns
/// its `name`, or an `Error` whose message names `file_name` and the field.
#[wasm_bindgen(js_name = checkProfile)]
pub fn check_profile(text: &str, file_name: &str) -> Result<String, JsValue> {
    let p = MachineProfile::from_json(text, file_name).map_err(|e| core_err(e.into()))?;
    Ok(p.name)
}

/// Three finite numbers from the page, or an error naming `what`.
fn vec3(what: &str, v: &[f64]) -> Result<DVec3, JsError> {
    match v {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(JsError::new(&format!(
            "{what} must be three finite numbers, got {v:?}"
        ))),
    }
}

/// A point picked on the scan, in both frames.
#[derive(Serialize)]
struct PickView {
    /// Printer frame: where the view draws it.
    printer: [f64; 3],
    /// Scanner frame: what the registration reads as a scan point Sr.
    scan: [f64; 3],
}

/// A fiducial hole as the page lists and draws it.
#[derive(Serialize)]
struct HoleView {
    /// Scanner frame, mm (what the user would type as scan points).
    scan: [f64; 3],
    /// After the registration, printer frame (where the 3-D view draws it).
    printer: [f64; 3],
    diameter_mm: f64,
    roundness: f64,
}

#[derive(Serialize)]
struct ScanView<'a> {
    name: &'a str,
    bytes: usize,
    format: crate::mesh::MeshFormat,
    units: crate::mesh::ScanUnits,
    triangles: usize,
    bbox_mm: [[f64; 3]; 2],
    warnings: &'a [String],
    registration: RegistrationView<'a>,
    holes: Vec<HoleView>,
}

#[derive(Serialize)]
struct RegistrationView<'a> {
    method: crate::registration::RegistrationMethod,
    matrix: [[f64; 4]; 4],
    residuals_mm: &'a [f64],
    rms_mm: f64,
    notes: &'a [String],
}

fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// A scan loaded, registered and indexed, kept while only the path or the
/// plan settings change (re-planning then skips import and BVH build).
#[wasm_bindgen]
pub struct Session {
    scan: PreparedScan,
}

#[derive(Serialize)]
struct PlanResult {
    gcode: String,
    /// Pretty JSON, exactly what the CLI's `--report` writes.
    report_json: String,
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct CompareRow {
    planner: crate::planners::PlannerKind,
    quality: crate::quality::QualitySummary,
}

#[wasm_bindgen]
impl Session {
    /// Imports the scan (`bytes` from the file, never through a JS string),
    /// applies `scan` (ImportOptions) and registers it (RegistrationSettings).
    #[wasm_bindgen(constructor)]
    pub fn new(
        bytes: &[u8],
        name: &str,
        scan: JsValue,
        registration: JsValue,
    ) -> Result<Session, JsValue> {
        let scan: ImportOptions = from_js("scan settings", scan)?;
        let registration: RegistrationSettings = from_js("registration settings", registration)?;
        let scan = job::prepare_scan(bytes, name, &scan, &registration).map_err(core_err)?;
        Ok(Session { scan })
    }

    /// Vertices of the registered mesh, printer frame, xyz f32 (for drawing).
    #[wasm_bindgen(js_name = meshPositions)]
    pub fn mesh_positions(&self) -> Vec<f32> {
        self.scan
            .surface
            .mesh()
            .vertices
            .iter()
            .flat_map(|v| [v.x as f32, v.y as f32, v.z as f32])
            .collect()
    }

    /// Triangle vertex indices (three per triangle).
    #[wasm_bindgen(js_name = meshIndices)]
    pub fn mesh_indices(&self) -> Vec<u32> {
        self.scan
            .surface
            .mesh()
            .triangles
            .iter()
            .flatten()
            .copied()
            .collect()
    }

    /// What the page shows about the scan: size, format, registration
    /// (residuals, RMS) and the fiducial holes found in it.
    pub fn info(&self) -> Result<JsValue, JsError> {
        let s = &self.scan;
        let (lo, hi) = s.surface.bbox();
        let holes = s
            .fiducials
            .iter()
            .map(|f| HoleView {
                scan: arr(f.centroid),
                printer: arr(s.registration.apply(f.centroid)),
                diameter_mm: f.diameter_mm,
                roundness: f.roundness,
            })
            .collect();
        to_js(&ScanView {
            name: &s.file.name,
            bytes: s.file.bytes,
            format: s.format,
            units: s.units,
            triangles: s.triangle_count(),
            bbox_mm: [arr(lo), arr(hi)],
            warnings: &s.warnings,
            registration: RegistrationView {
                method: s.method,
                matrix: s.registration.matrix_row_major(),
                residuals_mm: &s.registration.residuals_mm,
                rms_mm: s.registration.rms_mm,
                notes: &s.registration.notes,
            },
            holes,
        })
    }

    /// The surface point the view shows first along the ray from `origin`
    /// in `direction` (printer frame, as [`Viewer::pick_ray`] gives it), as
    /// `{printer, scan}`, or `null` when the ray misses the scan. The view
    /// draws the registered mesh, so the hit is found on the registered
    /// surface and taken back to the scanner frame by the inverse of G.
    pub fn pick(&self, origin: &[f64], direction: &[f64]) -> Result<JsValue, JsError> {
        let a = vec3("the ray origin", origin)?;
        let dir = vec3("the ray direction", direction)?.normalize_or_zero();
        if dir == DVec3::ZERO {
            return Err(JsError::new("the ray direction must not be zero"));
        }
        let (lo, hi) = self.scan.surface.bbox();
        // Long enough to pass the whole scan from wherever the ray starts.
        let reach = (a - 0.5 * (lo + hi)).length() + (hi - lo).length() + 1.0;
        let Some(hit) = self.scan.surface.segment_first_hit(a, a + reach * dir) else {
            return Ok(JsValue::NULL);
        };
        let scan = self.scan.registration.apply_inverse(hit);
        to_js(&PickView {
            printer: arr(hit),
            scan: arr(scan),
        })
    }

    /// Plans `svg` on this scan ([`job::run_on`]) and writes G-code with the
    /// machine profile `dialect`: a built-in name or a profile's JSON text
    /// (`profile_file` then names the file in errors); returns
    /// `{gcode, report_json, warnings}`.
    pub fn plan(
        &self,
        svg: &[u8],
        svg_name: &str,
        settings: JsValue,
        dialect: &str,
        accept_risk: bool,
        profile_file: Option<String>,
    ) -> Result<JsValue, JsValue> {
        let settings: PlanSettings = from_js("plan settings", settings)?;
        let profile = profile(dialect, profile_file.as_deref())?;
        let out = job::run_on(&self.scan, svg, svg_name, &settings, &profile, accept_risk)
            .map_err(core_err)?;
        // Pretty JSON and a final newline: what the CLI's `--report` writes.
        let mut report_json = serde_json::to_string_pretty(&out.report).map_err(js_err)?;
        report_json.push('\n');
        Ok(to_js(&PlanResult {
            gcode: out.gcode,
            report_json,
            warnings: out.report.warnings,
        })?)
    }

    /// The four planners' quality summaries side by side ([`job::compare_on`]).
    pub fn compare(
        &self,
        svg: &[u8],
        svg_name: &str,
        settings: JsValue,
    ) -> Result<JsValue, JsValue> {
        let settings: PlanSettings = from_js("plan settings", settings)?;
        let comparison = job::compare_on(&self.scan, svg, svg_name, &settings).map_err(core_err)?;
        let rows: Vec<CompareRow> = comparison
            .rows
            .into_iter()
            .map(|(planner, quality)| CompareRow { planner, quality })
            .collect();
        to_js(&rows).map_err(JsValue::from)
    }
}

/// The 3-D view on a canvas (WebGL2, drawn by [`crate::render`]). The page
/// forwards pointer input as orbit/pan/zoom calls.
#[wasm_bindgen]
pub struct Viewer {
    r: Renderer,
}

#[wasm_bindgen]
impl Viewer {
    #[wasm_bindgen(constructor)]
    pub fn new(canvas: web_sys::HtmlCanvasElement) -> Result<Viewer, JsError> {
        Ok(Viewer {
            r: Renderer::new(canvas).map_err(|e| JsError::new(&e))?,
        })
    }

    /// The mesh to draw: xyz f32 positions and triangle indices.
    #[wasm_bindgen(js_name = setMesh)]
    pub fn set_mesh(&mut self, positions: &[f32], indices: &[u32]) -> Result<(), JsError> {
        self.r
            .set_mesh(positions, indices)
            .map_err(|e| JsError::new(&e))
    }

    /// The paths to draw, read from a report object (`surface_path`,
    /// `toolpath`, `defects`); `null` clears them.
    #[wasm_bindgen(js_name = setPaths)]
    pub fn set_paths(&mut self, report: JsValue) -> Result<(), JsError> {
        let paths: ViewPaths = if report.is_null() || report.is_undefined() {
            ViewPaths::default()
        } else {
            from_js("report", report)?
        };
        self.r.set_paths(&paths).map_err(|e| JsError::new(&e))
    }

    /// Fiducial markers: holes found in the scan, the printer points P and
    /// (optional) the points picked on the mesh, each `[[x, y, z], ...]` in
    /// the printer frame.
    #[wasm_bindgen(js_name = setMarkers)]
    pub fn set_markers(
        &mut self,
        holes: JsValue,
        printer: JsValue,
        picked: JsValue,
    ) -> Result<(), JsError> {
        let holes: Vec<[f64; 3]> = from_js("hole markers", holes)?;
        let printer: Vec<[f64; 3]> = from_js("printer points", printer)?;
        let picked: Vec<[f64; 3]> = if picked.is_undefined() || picked.is_null() {
            Vec::new()
        } else {
            from_js("picked points", picked)?
        };
        self.r
            .set_markers(&Markers {
                holes,
                printer,
                picked,
            })
            .map_err(|e| JsError::new(&e))
    }

    /// The camera ray through the drawing-buffer pixel (x, y) (device
    /// pixels from the top-left): `[ox, oy, oz, dx, dy, dz]`, origin on the
    /// near plane and unit direction, printer frame (the mesh's).
    #[wasm_bindgen(js_name = pickRay)]
    pub fn pick_ray(&self, x: f64, y: f64) -> Result<Vec<f64>, JsError> {
        if !x.is_finite() || !y.is_finite() {
            return Err(JsError::new("the pixel position must be finite"));
        }
        let (o, d) = self
            .r
            .pick_ray(x, y)
            .ok_or_else(|| JsError::new("the camera has no ray through that pixel"))?;
        Ok(vec![o.x, o.y, o.z, d.x, d.y, d.z])
    }

    /// Sets the drawing-buffer size in device pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.r.resize(width, height);
    }

    /// Turns the camera by a drag of (dx, dy) device pixels.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.r.camera.orbit(dx, dy);
    }

    /// Moves the camera target by a drag of (dx, dy) device pixels.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        self.r.pan(dx, dy);
    }

    /// Zooms by a wheel delta (positive: away).
    pub fn zoom(&mut self, delta: f64) {
        self.r.camera.zoom(delta);
    }

    /// Back to the view that frames the whole scan.
    #[wasm_bindgen(js_name = resetView)]
    pub fn reset_view(&mut self) {
        self.r.reset_view();
    }

    /// Looking straight down -Z, x to the right, y up.
    #[wasm_bindgen(js_name = topView)]
    pub fn top_view(&mut self) {
        self.r.camera.top();
    }

    pub fn draw(&self) {
        self.r.draw();
    }

    /// The colour a defect is drawn in, `[r, g, b]` 0-255 (legend and tests).
    #[wasm_bindgen(js_name = defectColor)]
    pub fn defect_color(name: &str) -> Vec<u8> {
        crate::render::defect_rgb8(name).to_vec()
    }
}
