//! The page's entry point (wasm32 only): the one `#[wasm_bindgen]` file.
//!
//! Like usvg's C API it only converts types (serde-wasm-bindgen for
//! settings and results, `&[u8]` for file bytes) and flattens errors into a
//! JS `Error` carrying the core's message; every planning decision is made
//! by [`crate::job`], the same code the CLI runs, so the page's G-code and
//! report are the CLI's byte for byte.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use wasm_bindgen::prelude::*;

use crate::demo::{self, antennas, parts::DemoPart, test_part};
use crate::fiducials::{find_fiducials, find_fiducials_sized, Fiducial};
use crate::gcode::{MachineProfile, MAX_GCODE_BYTES};
use crate::job::{self, InputFile, JobSettings, PreparedScan, RegistrationSettings};
use crate::mesh::{ImportOptions, ImportedMesh, MAX_SCAN_BYTES};
use crate::params::Nozzle;
use crate::pipeline::{self, DrawnPath, Plan, PlanSettings, SurfacePath};
use crate::placement::{self, Bed, ScanPlacement};
use crate::planners::PlannerKind;
use crate::quality::Defect;
use crate::registration::{Registration, RegistrationMethod};
use crate::render::{Markers, PathArrays, Renderer, ViewPaths};
use crate::sampling::{try_sample_subpath, MAX_SAMPLES};
use crate::svg::Placement;

/// Largest scan file the page reads: 512 MiB. The core reads up to
/// [`MAX_SCAN_BYTES`] (1 GiB), but a wasm32 tab has at most 4 GiB of
/// memory, which must hold the file's bytes while they are parsed, the mesh
/// in f64, its BVH and the copy drawn by WebGL; wasm memory never shrinks,
/// so the peak of one import stays. The page checks this before it reads a
/// byte (`checkScanSize`), so a file past it leaves the loaded scan alone.
pub const PAGE_MAX_SCAN_BYTES: usize = 512 << 20;
// The page's limit is the tighter one, so its message is the one users see.
const _: () = assert!(PAGE_MAX_SCAN_BYTES < MAX_SCAN_BYTES);

/// Most samples the page plans for one drawing, all subpaths together: one
/// million (300 m of path at the 20-gauge tip's d/2). The core allows
/// [`MAX_SAMPLES`] per subpath, but a sample costs the page about 1.7 KB of
/// wasm memory at the peak of a plan (measured: a raster of 838 k points on
/// the demo part took the worker from 25 to 1407 MiB; its JSON report alone
/// is 281 MiB), so ten million would not fit a tab's 4 GiB.
pub const PAGE_MAX_SAMPLES: usize = 1_000_000;

/// Most moves of a checked G-code program the page draws in the 3-D view
/// (24 bytes each, twice: in wasm memory and in WebGL's buffer).
pub const PAGE_MAX_DRAWN_MOVES: usize = 1_000_000;

/// A core error as the JS `Error` the page shows: its message names the
/// file, line or point at fault.
fn js_err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// A core error as a JS `Error` with a `kind` naming the stage that failed
/// (`mesh`, `svg`, `registration`, `gcode` for a G-code file that could not
/// be read, `touching` for G-code refused by the motion check, or `other`):
/// the page drops a file whose bytes could not be read but keeps one that
/// only failed to register. A `touching` error also carries `touching`, the
/// check's summary (`motion::MotionSummary`: the first touching moves with
/// their G-code lines).
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
    } else if matches!(e, Error::GcodeRead(_)) {
        "gcode"
    } else if matches!(e, Error::Touching(_)) {
        "touching"
    } else {
        "other"
    };
    let err = kind_err(kind, &e.to_string());
    if let Error::Touching(t) = &e {
        // Without it the message alone still names the first moves.
        if let Ok(summary) = to_js(&t.summary) {
            let _ = js_sys::Reflect::set(&err, &"touching".into(), &summary);
        }
    }
    err
}

/// A JS `Error` with `message` and a `kind` the page branches on (`limit`
/// for the page's own size limits, or a core stage as in [`core_err`]).
fn kind_err(kind: &str, message: &str) -> JsValue {
    let err = js_sys::Error::new(message);
    // Setting a property on a fresh Error cannot fail; if it did, the
    // message alone still reaches the page.
    let _ = js_sys::Reflect::set(&err, &"kind".into(), &kind.into());
    err.into()
}

/// Sets `key` on a JS object (a fresh one: cannot fail).
fn set(obj: &js_sys::Object, key: &str, value: &JsValue) {
    let _ = js_sys::Reflect::set(obj, &key.into(), value);
}

const MIB: f64 = (1u64 << 20) as f64;

/// The page's limits, for its messages and the README: `{scan_bytes,
/// svg_bytes, samples, core_scan_bytes, core_samples_per_subpath,
/// gcode_bytes}` (the last: the largest G-code file the reader checks).
#[wasm_bindgen(js_name = pageLimits)]
pub fn page_limits() -> JsValue {
    let o = js_sys::Object::new();
    set(&o, "scan_bytes", &(PAGE_MAX_SCAN_BYTES as f64).into());
    set(&o, "svg_bytes", &(PAGE_MAX_SVG_BYTES as f64).into());
    set(&o, "samples", &(PAGE_MAX_SAMPLES as f64).into());
    set(&o, "core_scan_bytes", &(MAX_SCAN_BYTES as f64).into());
    set(&o, "core_samples_per_subpath", &(MAX_SAMPLES as f64).into());
    set(&o, "gcode_bytes", &(MAX_GCODE_BYTES as f64).into());
    o.into()
}

/// Largest SVG file the page reads: 64 MiB. The page reads a drawing on its
/// main thread (to centre it) and usvg holds its whole tree; a drawing
/// this size is far past the core's own limit of flattened points
/// ([`crate::svg::MAX_POINTS`]) for any real antenna.
pub const PAGE_MAX_SVG_BYTES: usize = 64 << 20;

/// Refuses an SVG file of `size` bytes past [`PAGE_MAX_SVG_BYTES`] (kind
/// `limit`), before the page reads it.
#[wasm_bindgen(js_name = checkSvgSize)]
pub fn check_svg_size(name: &str, size: f64) -> Result<(), JsValue> {
    if size.is_finite() && (0.0..=PAGE_MAX_SVG_BYTES as f64).contains(&size) {
        return Ok(());
    }
    Err(kind_err(
        "limit",
        &format!(
            "{name}: the file is {:.1} MiB, more than the {} MiB this page reads for a \
             drawing; is it the right file? Simplify the drawing (fewer nodes, no embedded \
             images), or plan it with the command line",
            size / MIB,
            PAGE_MAX_SVG_BYTES >> 20
        ),
    ))
}

/// Refuses a scan file of `size` bytes past [`PAGE_MAX_SCAN_BYTES`] with an
/// `Error` (kind `limit`) naming the file, its size and the limit. The page
/// calls this with `File.size`, before reading anything.
#[wasm_bindgen(js_name = checkScanSize)]
pub fn check_scan_size(name: &str, size: f64) -> Result<(), JsValue> {
    if size.is_finite() && (0.0..=PAGE_MAX_SCAN_BYTES as f64).contains(&size) {
        return Ok(());
    }
    Err(kind_err(
        "limit",
        &format!(
            "{name}: the file is {:.1} MiB, more than the {} MiB this page reads (a browser \
             tab's memory must also hold the mesh and its search structure); decimate the scan \
             (e.g. MeshLab's quadric edge collapse) or crop it to the printed area, or plan it \
             with the command line (pcpp plan reads up to {} MiB)",
            size / MIB,
            PAGE_MAX_SCAN_BYTES >> 20,
            MAX_SCAN_BYTES >> 20
        ),
    ))
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

/// Bytes of this thread's wasm memory: it grows to the peak of what was
/// held (a scan's file, mesh and BVH at once) and never shrinks; wasm32
/// allows 4 GiB.
#[wasm_bindgen(js_name = memoryBytes)]
pub fn memory_bytes() -> f64 {
    wasm_bindgen::memory()
        .dyn_into::<js_sys::WebAssembly::Memory>()
        .map_or(0.0, |m| {
            m.buffer()
                .dyn_into::<js_sys::ArrayBuffer>()
                .map_or(0.0, |b| f64::from(b.byte_length()))
        })
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

/// The planners' names, the comparison's order ([`PlannerKind::ALL`]).
#[wasm_bindgen]
pub fn planners() -> Vec<String> {
    PlannerKind::ALL
        .iter()
        .map(|k| k.name().to_string())
        .collect()
}

/// A comparison row's `min_clearance_mm` is `null` when every print move
/// clears by more than tol plus this (mm,
/// [`pipeline::CLEARANCE_CAP_ABOVE_TOL_MM`]): the table shows `>` that sum.
#[wasm_bindgen(js_name = clearanceCapAboveTolMm)]
pub fn clearance_cap_above_tol_mm() -> f64 {
    pipeline::CLEARANCE_CAP_ABOVE_TOL_MM
}

/// A built-in part by name, or an error listing the names.
fn demo_part_named(name: &str) -> Result<DemoPart, JsError> {
    name.parse::<DemoPart>().map_err(|e| JsError::new(&e))
}

/// The generated demo parts for the page's menu: `[{name, description}]`,
/// the test part first.
#[wasm_bindgen(js_name = demoParts)]
pub fn demo_parts() -> Result<JsValue, JsError> {
    #[derive(Serialize)]
    struct Entry {
        name: &'static str,
        description: &'static str,
    }
    let list: Vec<Entry> = DemoPart::ALL
        .iter()
        .map(|p| Entry {
            name: p.name(),
            description: p.description(),
        })
        .collect();
    to_js(&list)
}

/// A demo part's drawing and settings, as `pcpp demo --part NAME` plans
/// it: `{name, description, scan_name, path_name, svg, settings}`, where
/// `settings` (JobSettings) has the part's placement and, for the test
/// part, auto fiducials against its three holes (the other parts have none:
/// they are generated in the printer frame). Its scan's bytes come from
/// [`demo_part_scan`] (the worker makes them with [`ScanBuffer::demo_part`]).
#[wasm_bindgen(js_name = demoPart)]
pub fn demo_part(name: &str) -> Result<JsValue, JsError> {
    #[derive(Serialize)]
    struct PartView {
        name: &'static str,
        description: &'static str,
        scan_name: String,
        path_name: String,
        svg: String,
        settings: JobSettings,
    }
    let part = demo_part_named(name)?;
    let mut settings = JobSettings::default();
    settings.plan.placement = part.placement();
    if part == DemoPart::TestPart {
        settings.registration = RegistrationSettings {
            fiducials: job::FiducialSource::Auto,
            printer_points: test_part::FIDUCIALS_MM.to_vec(),
            ..RegistrationSettings::default()
        };
    }
    to_js(&PartView {
        name: part.name(),
        description: part.description(),
        scan_name: part.scan_name(),
        path_name: part.path_name(),
        svg: part.svg(),
        settings,
    })
}

/// A demo part's scan as the binary PLY a user could load (what
/// `pcpp demo --part NAME` writes).
#[wasm_bindgen(js_name = demoPartScan)]
pub fn demo_part_scan(name: &str) -> Result<Vec<u8>, JsError> {
    Ok(demo::to_binary_ply(&demo_part_named(name)?.mesh()))
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

/// Six finite numbers `[min x, min y, min z, max x, max y, max z]` (mm) as
/// bounds, or an error naming `what`.
fn bounds(what: &str, v: &[f64]) -> Result<(DVec3, DVec3), JsError> {
    match v {
        [a, b, c, d, e, f] if v.iter().all(|x| x.is_finite()) => {
            Ok((DVec3::new(*a, *b, *c), DVec3::new(*d, *e, *f)))
        }
        _ => Err(JsError::new(&format!(
            "{what} must be six finite numbers (min x, y, z, max x, y, z), got {v:?}"
        ))),
    }
}

/// Where a scan with bounds `bbox` (`[min x, y, z, max x, y, z]`, printer
/// frame) lies against the build volume of the machine profile `dialect`
/// (as in [`Session::plan`]): `placement::VolumeFit` with the sentence the
/// page shows in its banner.
#[wasm_bindgen(js_name = volumeFit)]
pub fn volume_fit(
    bbox: &[f64],
    dialect: &str,
    profile_file: Option<String>,
) -> Result<JsValue, JsValue> {
    let bbox = bounds("the scan's bounds", bbox)?;
    let p = profile(dialect, profile_file.as_deref())?;
    Ok(to_js(&placement::volume_fit(
        bbox,
        &p.build_volume,
        &p.name,
    ))?)
}

/// The bed of the machine profile `dialect` (`{centre_mm, z_mm}`), for a
/// scan placement `{mode: "on-bed", bed, rotation_deg, offset_mm}`.
#[wasm_bindgen(js_name = bedOf)]
pub fn bed_of(dialect: &str, profile_file: Option<String>) -> Result<JsValue, JsValue> {
    let p = profile(dialect, profile_file.as_deref())?;
    Ok(to_js(&Bed::of_profile(&p))?)
}

/// The drawing's placement after the scan (scanner-frame bounds `scan_bbox`,
/// `[min x, y, z, max x, y, z]`) moves from the scan placement `from` to
/// `to` ([`placement::carry_drawing`]).
#[wasm_bindgen(js_name = carryDrawing)]
pub fn carry_drawing(
    drawing: JsValue,
    scan_bbox: &[f64],
    from: JsValue,
    to: JsValue,
) -> Result<JsValue, JsError> {
    let drawing: Placement = from_js("drawing placement", drawing)?;
    let bbox = bounds("the scan's bounds", scan_bbox)?;
    let from: ScanPlacement = from_js("scan placement", from)?;
    let to: ScanPlacement = from_js("scan placement", to)?;
    to_js(&placement::carry_drawing(&drawing, bbox, &from, &to))
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
    /// How well it matches the expected dot, 0 to 1 ([`Fiducial::score`]).
    score: f64,
    /// Whether it could be a dot at all ([`Fiducial::is_candidate`]):
    /// border notches, slits and tiny dropouts are not.
    candidate: bool,
}

#[derive(Serialize)]
struct ScanView<'a> {
    name: &'a str,
    bytes: usize,
    format: crate::mesh::MeshFormat,
    units: crate::mesh::ScanUnits,
    triangles: usize,
    /// Printer frame (after the registration or placement on the bed).
    bbox_mm: [[f64; 3]; 2],
    /// Scanner frame, as imported (what a placement on the bed moves).
    scan_bbox_mm: [[f64; 3]; 2],
    warnings: &'a [String],
    /// For a point cloud: how it was meshed, and that as one line.
    cloud: Option<crate::mesh::CloudInfo>,
    cloud_text: Option<String>,
    registration: RegistrationView<'a>,
    holes: Vec<HoleView>,
}

#[derive(Serialize)]
struct RegistrationView<'a> {
    /// How the scan got into the printer frame, and its sentence
    /// ([`placement::RegistrationStatus`]'s Display, as in the G-code header).
    status: placement::RegistrationStatus,
    status_text: String,
    method: crate::registration::RegistrationMethod,
    matrix: [[f64; 4]; 4],
    residuals_mm: &'a [f64],
    rms_mm: f64,
    notes: &'a [String],
}

fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// A scan file's bytes, written into wasm memory chunk by chunk as the
/// worker reads the file (`Blob.slice().arrayBuffer()`), so a large scan is
/// never held whole by JS nor passed through a string. The first of the
/// staged steps that [`job::prepare_scan`] runs in one call; the page shows
/// progress between them: [`ScanBuffer::import_scan`], [`ScanImport::register`],
/// [`ScanImport::index`].
#[wasm_bindgen]
pub struct ScanBuffer {
    name: String,
    size: usize,
    bytes: Vec<u8>,
    /// The report's sha256, chunk by chunk as the bytes arrive: V8 runs a
    /// long single call in its baseline tier (no on-stack replacement for
    /// wasm), where hashing a large file at once took 16 times longer.
    sha256: Sha256,
}

#[wasm_bindgen]
impl ScanBuffer {
    /// Room for a file of `size` bytes; refuses sizes past the page's limit
    /// ([`check_scan_size`]) and, without aborting, sizes the tab's memory
    /// cannot hold.
    #[wasm_bindgen(constructor)]
    pub fn new(name: &str, size: f64) -> Result<ScanBuffer, JsValue> {
        check_scan_size(name, size)?;
        let size = size as usize;
        let mut bytes = Vec::new();
        bytes.try_reserve_exact(size).map_err(|_| {
            kind_err(
                "limit",
                &format!(
                    "{name}: this tab has no room for the file's {:.1} MiB; close other tabs \
                     or reload the page (its memory only grows), decimate the scan, or plan it \
                     with the command line",
                    size as f64 / MIB
                ),
            )
        })?;
        Ok(ScanBuffer {
            name: name.to_string(),
            size,
            bytes,
            sha256: Sha256::new(),
        })
    }

    /// The demo scan (the paper's test part as binary PLY), already full.
    pub fn demo() -> ScanBuffer {
        ScanBuffer::full(DemoPart::TestPart)
    }

    /// A generated demo part's scan ([`demo_part_scan`]), already full.
    #[wasm_bindgen(js_name = demoPart)]
    pub fn demo_part(name: &str) -> Result<ScanBuffer, JsError> {
        Ok(ScanBuffer::full(demo_part_named(name)?))
    }

    /// Appends the next chunk of the file.
    pub fn write(&mut self, chunk: &[u8]) -> Result<(), JsError> {
        if self.bytes.len() + chunk.len() > self.size {
            return Err(JsError::new(&format!(
                "{}: the file grew while it was read (more than its {} bytes); open it again",
                self.name, self.size
            )));
        }
        self.bytes.extend_from_slice(chunk);
        self.sha256.update(chunk);
        Ok(())
    }

    /// Bytes written so far.
    pub fn received(&self) -> usize {
        self.bytes.len()
    }

    /// Imports the bytes ([`pipeline::load_scan`]) with `scan`
    /// (ImportOptions); the bytes are freed once read, before the next step
    /// allocates the search structure.
    #[wasm_bindgen(js_name = importScan)]
    pub fn import_scan(self, scan: JsValue) -> Result<ScanImport, JsValue> {
        if self.bytes.len() != self.size {
            return Err(JsError::new(&format!(
                "{}: only {} of {} bytes were read; open the file again",
                self.name,
                self.bytes.len(),
                self.size
            ))
            .into());
        }
        let options: ImportOptions = from_js("scan settings", scan)?;
        let imported = pipeline::load_scan(&self.bytes, &self.name, &options).map_err(core_err)?;
        let file = InputFile::from_digest(&self.name, self.bytes.len(), &self.sha256.finalize());
        Ok(ScanImport {
            file,
            imported,
            fiducials: None,
            registration: None,
        })
    }
}

impl ScanBuffer {
    /// A demo part's scan as the binary PLY `pcpp demo --part` writes.
    fn full(part: DemoPart) -> ScanBuffer {
        let bytes = demo::to_binary_ply(&part.mesh());
        let mut sha256 = Sha256::new();
        sha256.update(&bytes);
        ScanBuffer {
            name: part.scan_name(),
            size: bytes.len(),
            bytes,
            sha256,
        }
    }
}

/// A scan imported (scanner frame), not yet registered or indexed.
#[wasm_bindgen]
pub struct ScanImport {
    file: InputFile,
    imported: ImportedMesh,
    fiducials: Option<Vec<Fiducial>>,
    registration: Option<(Registration, RegistrationMethod)>,
}

#[wasm_bindgen]
impl ScanImport {
    pub fn triangles(&self) -> usize {
        self.imported.mesh.triangle_count()
    }

    /// Finds the fiducial holes (once, in the scanner frame) and registers
    /// with `registration` (RegistrationSettings), as [`job::prepare_scan`]
    /// does. A failure (kind `registration`) leaves the import usable.
    pub fn register(&mut self, registration: JsValue) -> Result<(), JsValue> {
        let settings: RegistrationSettings = from_js("registration settings", registration)?;
        let mesh = &self.imported.mesh;
        let holes = self
            .fiducials
            .get_or_insert_with(|| find_fiducials_sized(mesh, settings.dot_diameter_mm));
        // Placement on the bed included, as job::prepare_scan does.
        let reg = job::registration_for_scan(mesh, holes, &settings).map_err(core_err)?;
        self.registration = Some((reg, settings.method));
        Ok(())
    }

    /// Builds the registered surface and its spatial index: the [`Session`]
    /// that plans. Call [`ScanImport::register`] first.
    pub fn index(self) -> Result<Session, JsValue> {
        let Some((registration, method)) = self.registration else {
            return Err(JsError::new("the scan must be registered before it is indexed").into());
        };
        let fiducials = self
            .fiducials
            .unwrap_or_else(|| find_fiducials(&self.imported.mesh));
        let scan_bbox = self.imported.mesh.bbox();
        let prepared =
            PreparedScan::assemble(self.file, self.imported, fiducials, registration, method)
                .map_err(core_err)?;
        Ok(Session::from_prepared(prepared, scan_bbox))
    }
}

/// The drawing the session plans, read once per file.
struct LoadedPath {
    file: InputFile,
    drawn: DrawnPath,
}

/// The planner-independent surface path of the last placement and nozzle:
/// a change of planner, tolerance, speed or dwell, or the comparison after
/// a drag, re-plans without projecting again.
struct PathCache {
    nozzle: Nozzle,
    placement: Placement,
    surface_path: SurfacePath,
}

/// A scan loaded, registered and indexed, kept while only the path or the
/// plan settings change (re-planning then skips import and BVH build).
#[wasm_bindgen]
pub struct Session {
    scan: PreparedScan,
    /// The scan's bounds in the scanner frame, as imported.
    scan_bbox: (DVec3, DVec3),
    path: Option<LoadedPath>,
    cache: Option<PathCache>,
}

#[derive(Serialize)]
struct PlanResult {
    gcode: String,
    /// Pretty JSON, exactly what the CLI's `--report` writes.
    report_json: String,
    warnings: Vec<String>,
}

/// What the page shows of a plan besides the per-point arrays.
#[derive(Serialize)]
struct PlanSummary<'a> {
    planner: PlannerKind,
    settings: &'a PlanSettings,
    quality: crate::quality::QualitySummary,
    stats: crate::stats::PathStats,
    warnings: &'a [String],
    registration_rms_mm: f64,
    /// The report's safe-motion part: the check of every move the G-code
    /// commands, waypoints, backward moves, sideways offset.
    motion: &'a job::MotionReport,
    /// Its line in the G-code header (`safe motion: ...`; it starts with
    /// `WARNING` when the risk was accepted for touching moves).
    motion_line: String,
}

/// The page's code for a defect (the view's and the plot's colour index).
fn defect_code(d: Defect) -> u8 {
    match d {
        Defect::Good => 0,
        Defect::Contact => 1,
        Defect::Flattening => 2,
        Defect::Floating => 3,
    }
}

/// Samples a drawing would need at `spacing` after `placement`, estimated
/// from its drawn length (each corner adds at most one).
fn estimated_samples(sub: &crate::svg::Subpath2, placement: &Placement, spacing: f64) -> f64 {
    (sub.length_mm() * placement.scale.abs() / spacing).ceil() + sub.points.len() as f64
}

/// The page's sample limit ([`PAGE_MAX_SAMPLES`]) over the whole drawing,
/// after the core's own per-subpath limit, whose message (from
/// [`try_sample_subpath`], which counts before it allocates) the page shows
/// as the CLI would.
fn check_samples(path: &LoadedPath, settings: &PlanSettings) -> Result<(), JsValue> {
    let spacing = 0.5 * settings.nozzle.inner_diameter_mm;
    let placement = &settings.placement;
    let mut total = 0.0;
    for sub in &path.drawn.subpaths {
        let n = estimated_samples(sub, placement, spacing);
        if n > MAX_SAMPLES as f64 {
            try_sample_subpath(&placement.apply_subpath(sub), spacing)
                .map_err(|e| core_err(e.into()))?;
        }
        total += n;
    }
    if total > PAGE_MAX_SAMPLES as f64 {
        return Err(kind_err(
            "limit",
            &format!(
                "{}: about {:.2} million samples at {} mm spacing (d/2) after scaling by {}, \
                 more than the {} million this page plans in one drawing; shorten the path or \
                 scale it down, use a wider nozzle, or plan it with the command line (pcpp plan \
                 allows {} million per subpath)",
                path.file.name,
                total / 1e6,
                spacing,
                placement.scale,
                PAGE_MAX_SAMPLES / 1_000_000,
                MAX_SAMPLES / 1_000_000
            ),
        ));
    }
    Ok(())
}

impl Session {
    /// `scan_bbox`: the import's bounds (scanner frame); without them they
    /// are found by taking the registered mesh back (G is rigid).
    fn from_prepared(scan: PreparedScan, scan_bbox: Option<(DVec3, DVec3)>) -> Session {
        let scan_bbox = scan_bbox.unwrap_or_else(|| {
            let reg = &scan.registration;
            let back = scan
                .surface
                .mesh()
                .vertices
                .iter()
                .map(|&v| reg.apply_inverse(v));
            back.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
        });
        Session {
            scan,
            scan_bbox,
            path: None,
            cache: None,
        }
    }

    /// Projects the drawing for the nozzle and placement of `settings`
    /// unless the cache already holds that surface path.
    fn ensure_surface_path(&mut self, settings: &PlanSettings) -> Result<(), JsValue> {
        let path = self
            .path
            .as_ref()
            .ok_or_else(|| JsError::new("no drawing to plan: set a path first"))?;
        let hit = self
            .cache
            .as_ref()
            .is_some_and(|c| c.nozzle == settings.nozzle && c.placement == settings.placement);
        if !hit {
            // The old surface path goes first: memory for one, not two.
            self.cache = None;
            check_samples(path, settings)?;
            let surface_path = pipeline::surface_path(
                &self.scan.surface,
                &path.drawn.subpaths,
                &settings.nozzle,
                &settings.placement,
            )
            .map_err(core_err)?;
            self.cache = Some(PathCache {
                nozzle: settings.nozzle,
                placement: settings.placement,
                surface_path,
            });
        }
        Ok(())
    }
}

/// The per-point arrays of a plan as typed arrays: `pieces` (points per
/// piece), `ta` and `tool` (xyz f32, printer frame), `defects` (codes of
/// [`defect_code`]), `slope` (deg), `kappa` (1/mm) and `error` (mm, NaN at a
/// contact), for the view and the plot without parsing the JSON report.
fn plan_arrays(plan: &Plan) -> js_sys::Object {
    let n: usize = plan.pieces.iter().map(|p| p.toolpath.len()).sum();
    let mut pieces = Vec::with_capacity(plan.pieces.len());
    let mut ta = Vec::with_capacity(3 * n);
    let mut tool = Vec::with_capacity(3 * n);
    let mut defects = Vec::with_capacity(n);
    let (mut slope, mut kappa, mut error) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for p in &plan.pieces {
        pieces.push(p.toolpath.len() as u32);
        ta.extend(
            p.surface_path
                .iter()
                .flat_map(|v| [v.x as f32, v.y as f32, v.z as f32]),
        );
        tool.extend(
            p.toolpath
                .iter()
                .flat_map(|v| [v.x as f32, v.y as f32, v.z as f32]),
        );
        for (g, q) in p.geometry.iter().zip(&p.quality) {
            defects.push(defect_code(q.defect));
            slope.push(g.slope_rad.to_degrees() as f32);
            kappa.push(g.kappa as f32);
            error.push(q.error_mm.map_or(f32::NAN, |e| e as f32));
        }
    }
    let o = js_sys::Object::new();
    set(&o, "pieces", &js_sys::Uint32Array::from(&pieces[..]).into());
    set(&o, "ta", &js_sys::Float32Array::from(&ta[..]).into());
    set(&o, "tool", &js_sys::Float32Array::from(&tool[..]).into());
    set(
        &o,
        "defects",
        &js_sys::Uint8Array::from(&defects[..]).into(),
    );
    set(&o, "slope", &js_sys::Float32Array::from(&slope[..]).into());
    set(&o, "kappa", &js_sys::Float32Array::from(&kappa[..]).into());
    set(&o, "error", &js_sys::Float32Array::from(&error[..]).into());
    o
}

/// One planner's per-point errors and defect codes for the plot beside the
/// others: `{planner, error, defects}` in the order of [`plan_arrays`] (the
/// planners share the surface path, so its slope and curvature arrays hold
/// for every planner).
fn plan_series(plan: &Plan) -> Result<js_sys::Object, JsError> {
    let n: usize = plan.pieces.iter().map(|p| p.quality.len()).sum();
    let mut defects = Vec::with_capacity(n);
    let mut error = Vec::with_capacity(n);
    for q in plan.pieces.iter().flat_map(|p| &p.quality) {
        defects.push(defect_code(q.defect));
        error.push(q.error_mm.map_or(f32::NAN, |e| e as f32));
    }
    let o = js_sys::Object::new();
    set(&o, "planner", &to_js(&plan.planner)?);
    set(&o, "error", &js_sys::Float32Array::from(&error[..]).into());
    set(
        &o,
        "defects",
        &js_sys::Uint8Array::from(&defects[..]).into(),
    );
    Ok(o)
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
        Ok(Session::from_prepared(scan, None))
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
                score: f.score,
                candidate: f.is_candidate(),
            })
            .collect();
        let (slo, shi) = self.scan_bbox;
        to_js(&ScanView {
            name: &s.file.name,
            bytes: s.file.bytes,
            format: s.format,
            units: s.units,
            triangles: s.triangle_count(),
            bbox_mm: [arr(lo), arr(hi)],
            scan_bbox_mm: [arr(slo), arr(shi)],
            warnings: &s.warnings,
            cloud: s.cloud,
            cloud_text: s.cloud.map(|c| c.to_string()),
            registration: RegistrationView {
                status: s.registration.status,
                status_text: s.registration.status.to_string(),
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

    /// Reads the drawing the next plans use (an error, kind `svg`, names
    /// the file and keeps the previous drawing).
    #[wasm_bindgen(js_name = setPath)]
    pub fn set_path(&mut self, svg: &[u8], svg_name: &str) -> Result<(), JsValue> {
        let drawn = pipeline::load_path(svg, svg_name).map_err(core_err)?;
        self.cache = None;
        self.path = Some(LoadedPath {
            file: InputFile::new(svg_name, svg),
            drawn,
        });
        Ok(())
    }

    /// The drawing of [`Session::set_path`] centred on this scan's footprint
    /// (printer XY), keeping the rotation and scale of `placement` and
    /// scaling it down when it does not fit ([`placement::centre_drawing`]):
    /// `{placement, note}` (`note` says how it was scaled, or is null), or
    /// null for a drawing without points.
    #[wasm_bindgen(js_name = centreDrawing)]
    pub fn centre_drawing(&self, placement: JsValue) -> Result<JsValue, JsValue> {
        #[derive(Serialize)]
        struct Centred {
            placement: Placement,
            note: Option<String>,
        }
        let current: Placement = from_js("drawing placement", placement)?;
        let path = self
            .path
            .as_ref()
            .ok_or_else(|| JsError::new("no drawing to centre: set a path first"))?;
        let (lo, hi) = self.scan.surface.bbox();
        let centred = placement::centre_drawing(
            &path.drawn.subpaths,
            (lo.truncate(), hi.truncate()),
            &current,
        );
        Ok(match centred {
            Some((placement, note)) => to_js(&Centred { placement, note })?,
            None => JsValue::NULL,
        })
    }

    /// One call for a live re-plan: plans the drawing of [`Session::set_path`]
    /// with `settings` and writes G-code with `dialect` (as
    /// [`Session::plan`]: the same G-code and report bytes as
    /// [`job::run_on`] and the CLI), projecting the drawing once (reused
    /// while the nozzle and placement stay) and, when `compare`, also
    /// plans every other planner on that one surface path. Returns
    /// `{gcode, report}` (UTF-8 bytes, Uint8Array), `summary` (planner,
    /// settings, quality, stats, warnings, registration RMS, the report's
    /// `motion` and its header line `motion_line`), `view` (see
    /// [`plan_arrays`]), `comparison` (`[job::ComparisonRow]`, every
    /// planner, or null) and `series` (per planner, see [`plan_series`],
    /// or null).
    ///
    /// G-code whose moves come closer to the surface than tol is refused
    /// unless `accept_risk` (an `Error` of kind `touching`, see
    /// [`core_err`]); that error also carries the `comparison` and `series`
    /// when they were asked for, so the page can compare the planners on the
    /// settings that failed.
    #[wasm_bindgen(js_name = planLive)]
    pub fn plan_live(
        &mut self,
        settings: JsValue,
        dialect: &str,
        accept_risk: bool,
        profile_file: Option<String>,
        compare: bool,
    ) -> Result<JsValue, JsValue> {
        let settings: PlanSettings = from_js("plan settings", settings)?;
        // As job::run_on: bad settings and profiles fail before any work.
        settings.validate().map_err(core_err)?;
        let profile = profile(dialect, profile_file.as_deref())?;
        self.ensure_surface_path(&settings)?;
        let Some(cache) = &self.cache else {
            return Err(JsError::new("the surface path was not kept").into());
        };
        let sp = &cache.surface_path;
        let surface = &self.scan.surface;
        let plan_with = |k: PlannerKind| {
            pipeline::plan_surface_path(surface, sp, k, &settings.nozzle, &settings.process)
        };
        let plan = plan_with(settings.planner);
        let (comparison, series) = if compare {
            let rows = js_sys::Array::new();
            let series = js_sys::Array::new();
            let mut table = Vec::with_capacity(PlannerKind::ALL.len());
            for &k in &PlannerKind::ALL {
                // One planner at a time: its plan is dropped before the next.
                let other;
                let p = if k == settings.planner {
                    &plan
                } else {
                    other = plan_with(k);
                    &other
                };
                table.push(job::ComparisonRow::of(p));
                series.push(&plan_series(p)?.into());
            }
            for r in &table {
                rows.push(&to_js(r)?);
            }
            (JsValue::from(rows), JsValue::from(series))
        } else {
            (JsValue::NULL, JsValue::NULL)
        };
        let path = self
            .path
            .as_ref()
            .ok_or_else(|| JsError::new("no drawing to plan: set a path first"))?;
        // The core's own refusal and writer, so the bytes are the CLI's.
        let written = job::refuse_uncleared(&plan, accept_risk).and_then(|()| {
            job::write_outputs(
                &self.scan,
                &path.file,
                &path.drawn.notes,
                &plan,
                &settings,
                &profile,
                accept_risk,
            )
        });
        let (report, gcode) = match written {
            Ok(w) => w,
            Err(e) => {
                let err = core_err(e);
                if compare {
                    let _ = js_sys::Reflect::set(&err, &"comparison".into(), &comparison);
                    let _ = js_sys::Reflect::set(&err, &"series".into(), &series);
                }
                return Err(err);
            }
        };
        let mut report_json = serde_json::to_vec_pretty(&report).map_err(js_err)?;
        report_json.push(b'\n');
        let out = js_sys::Object::new();
        set(
            &out,
            "gcode",
            &js_sys::Uint8Array::from(gcode.as_bytes()).into(),
        );
        set(
            &out,
            "report",
            &js_sys::Uint8Array::from(&report_json[..]).into(),
        );
        let summary = PlanSummary {
            planner: plan.planner,
            settings: &settings,
            quality: plan.quality,
            stats: plan.stats,
            warnings: &report.warnings,
            registration_rms_mm: report.registration.rms_mm,
            motion: &report.motion,
            motion_line: report.motion.summary_line(),
        };
        set(&out, "summary", &to_js(&summary)?);
        set(&out, "view", &plan_arrays(&plan).into());
        set(&out, "comparison", &comparison);
        set(&out, "series", &series);
        Ok(out.into())
    }

    /// Checks a G-code file (`bytes`, UTF-8 text, any program: ours or
    /// another tool's) against this scan ([`job::check_gcode`]): every
    /// straight move along its length, the nozzle `nozzle` (`{inner_diameter_mm,
    /// outer_diameter_mm}`) kept `tol_mm` from the surface. Returns the
    /// `job::GcodeCheck` with `clear` (no move closer than tol) and, for
    /// the view, up to [`PAGE_MAX_DRAWN_MOVES`] of the moves checked:
    /// `moves` (xyz from and to, Float32Array) and `kinds` (0 feed, 1 rapid,
    /// 2 listed as too close; only the check's first
    /// [`crate::motion::MAX_LISTED`] are known), or null for more. A file
    /// that cannot be read (an arc, a bad number, ...) is an `Error` of kind
    /// `gcode` naming the file and the line, one past the page's size limit
    /// of kind `limit`.
    #[wasm_bindgen(js_name = checkGcode)]
    pub fn check_gcode(
        &self,
        bytes: &[u8],
        name: &str,
        nozzle: JsValue,
        tol_mm: f64,
    ) -> Result<JsValue, JsValue> {
        let nozzle: Nozzle = from_js("nozzle", nozzle)?;
        if bytes.len() > MAX_GCODE_BYTES {
            return Err(kind_err(
                "limit",
                &format!(
                    "{name}: the file is {:.1} MiB, more than the {} MiB the G-code check \
                     reads; split the program and check each part",
                    bytes.len() as f64 / MIB,
                    MAX_GCODE_BYTES >> 20
                ),
            ));
        }
        let text = std::str::from_utf8(bytes).map_err(|e| {
            kind_err(
                "gcode",
                &format!(
                    "{name}: not UTF-8 text (byte {}); is it a G-code program?",
                    e.valid_up_to()
                ),
            )
        })?;
        let check = job::check_gcode(&self.scan, text, name, &nozzle, tol_mm).map_err(core_err)?;
        let out = to_js(&check)?;
        let o: &js_sys::Object = out.unchecked_ref();
        set(o, "clear", &JsValue::from_bool(check.is_clear()));
        let (mut moves, mut kinds) = (JsValue::NULL, JsValue::NULL);
        if check.summary.moves <= PAGE_MAX_DRAWN_MOVES {
            // The check's own moves: its touching moves index into them.
            let mut xyz = Vec::with_capacity(6 * check.moves.len());
            let mut k: Vec<u8> = check.moves.iter().map(|m| u8::from(m.rapid)).collect();
            for m in &check.moves {
                xyz.extend(
                    [m.from, m.to]
                        .iter()
                        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]),
                );
            }
            for t in &check.summary.touching {
                if let Some(c) = k.get_mut(t.index) {
                    *c = 2;
                }
            }
            moves = js_sys::Float32Array::from(&xyz[..]).into();
            kinds = js_sys::Uint8Array::from(&k[..]).into();
        }
        set(o, "moves", &moves);
        set(o, "kinds", &kinds);
        Ok(out)
    }

    /// Every planner's quality and motion summaries side by side
    /// ([`job::compare_on`]).
    pub fn compare(
        &self,
        svg: &[u8],
        svg_name: &str,
        settings: JsValue,
    ) -> Result<JsValue, JsValue> {
        let settings: PlanSettings = from_js("plan settings", settings)?;
        let comparison = job::compare_on(&self.scan, svg, svg_name, &settings).map_err(core_err)?;
        to_js(&comparison.rows).map_err(JsValue::from)
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

    /// The paths from the flat arrays of a live plan (`view` of
    /// [`Session::plan_live`]); resets the drag offset.
    #[wasm_bindgen(js_name = setPathArrays)]
    pub fn set_path_arrays(
        &mut self,
        pieces: &[u32],
        ta: &[f32],
        tool: &[f32],
        defects: &[u8],
    ) -> Result<(), JsError> {
        self.r
            .set_path_arrays(&PathArrays {
                pieces,
                ta,
                tool,
                defects,
            })
            .map_err(|e| JsError::new(&e))
    }

    /// A checked G-code program's moves in place of the paths (`moves` and
    /// `kinds` of [`Session::check_gcode`]); a plan's paths replace them.
    #[wasm_bindgen(js_name = setMoves)]
    pub fn set_moves(&mut self, moves: &[f32], kinds: &[u8]) -> Result<(), JsError> {
        self.r.set_moves(moves, kinds).map_err(|e| JsError::new(&e))
    }

    /// Draws the paths moved by (dx, dy, dz) mm, printer frame: while the
    /// user drags the drawing, the last plan follows the pointer until the
    /// plan at the new placement replaces it.
    #[wasm_bindgen(js_name = setPathOffset)]
    pub fn set_path_offset(&mut self, dx: f64, dy: f64, dz: f64) {
        let o = DVec3::new(dx, dy, dz);
        self.r.path_offset = if o.is_finite() { o } else { DVec3::ZERO };
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

    pub fn draw(&mut self) {
        self.r.draw();
    }

    /// The colour a defect is drawn in, `[r, g, b]` 0-255 (legend and tests).
    #[wasm_bindgen(js_name = defectColor)]
    pub fn defect_color(name: &str) -> Vec<u8> {
        crate::render::defect_rgb8(name).to_vec()
    }
}
