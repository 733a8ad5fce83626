//! The page's entry point (wasm32 only): the `#[wasm_bindgen]` bindings.
//!
//! One module in three files by concern, none over about 800 lines: this
//! one (limits, errors, settings, demo parts, profiles, placement helpers),
//! `wasm/session.rs` (the scan read into wasm memory and the [`Session`]
//! that plans, checks and previews G-code) and `wasm/view.rs` (the 3-D
//! [`Viewer`] and the preview's [`PreviewTimeline`]).
//!
//! Like usvg's C API it only converts types (serde-wasm-bindgen for
//! settings and results, `&[u8]` for file bytes) and flattens errors into a
//! JS `Error` carrying the core's message; every planning decision is made
//! by [`crate::job`], the same code the CLI runs, so the page's G-code and
//! report are the CLI's byte for byte.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

use crate::demo::{self, antennas, parts::DemoPart, test_part};
use crate::gcode::{GcodeError, MachineProfile, MAX_GCODE_BYTES};
use crate::job::{self, JobSettings, RegistrationSettings};
use crate::mesh::MAX_SCAN_BYTES;
use crate::pipeline::{self, PlanSettings};
use crate::placement::{self, Bed, ScanPlacement};
use crate::planners::PlannerKind;
use crate::sampling::{MAX_DRAWING_SAMPLES, MAX_SAMPLES};
use crate::svg::Placement;

mod scan;
mod session;
mod view;

pub use scan::{ScanBuffer, ScanImport, Sha256Stream};
use session::LoadedPath;
pub use session::Session;
pub use view::{PreviewTimeline, Viewer};

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
/// [`MAX_DRAWING_SAMPLES`] in a drawing, but a sample costs the page about 1.7 KB of
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
/// be read, `touching` for G-code refused by the motion check,
/// `whole-object` for G-code refused on a point cloud of a whole object,
/// `units`, `below-bed`, `too-large`, `far-above` and `mostly-off` for the
/// other refusals that accepting the risk lifts, `volume` for a tool path
/// out of the build volume (the scan outside it, its travel height above
/// it, or the tool path beside it), or `other`):
/// the page drops a file whose bytes could not be read but keeps one that
/// only failed to register. A `touching` error also carries `touching`, the
/// check's summary (`motion::MotionSummary`: the first touching moves with
/// their G-code lines).
fn core_err(e: crate::Error) -> JsValue {
    use crate::Error;
    // The other risks accepting this one would accept: the kind and fields
    // are the refusal's own, the message says them too.
    let message = e.to_string();
    if let Error::AlsoRisks { first, blocked, .. } = e {
        let err = core_err(*first);
        let _ = js_sys::Reflect::set(&err, &"message".into(), &message.into());
        // Accepting the risk would write no G-code either: the page does
        // not offer its box.
        let _ = js_sys::Reflect::set(&err, &"blocked".into(), &blocked.is_some().into());
        return err;
    }
    // `matches!` rather than a `match`, so a variant added to the core later
    // falls to "other" instead of breaking this adapter.
    let kind = if matches!(e, Error::Mesh(_)) {
        "mesh"
    } else if matches!(e, Error::Svg(_)) {
        "svg"
    } else if matches!(e, Error::Registration(_)) {
        "registration"
    } else if matches!(
        e,
        Error::GcodeRead(_) | Error::GcodeReadForOtherProfile { .. }
    ) {
        "gcode"
    } else if matches!(e, Error::Touching(_)) {
        "touching"
    } else if matches!(e, Error::WholeObjectCloud { .. }) {
        "whole-object"
    } else if matches!(e, Error::UnitsDoubt { .. }) {
        "units"
    } else if matches!(e, Error::BelowBed { .. }) {
        "below-bed"
    } else if matches!(e, Error::LargerThanVolume(_)) {
        "too-large"
    } else if matches!(e, Error::FarAbove { .. }) {
        "far-above"
    } else if matches!(e, Error::MostlyOffScan { .. }) {
        "mostly-off"
    } else if matches!(e, Error::OutsideVolume { .. }) {
        "volume"
    } else {
        "other"
    };
    let err = kind_err(kind, &message);
    if let Error::UnitsDoubt { stray: true, .. } = &e {
        // No units mend it: the page offers none.
        let _ = js_sys::Reflect::set(&err, &"stray".into(), &true.into());
    }
    if let Error::Gcode(GcodeError::ProfileField { file, field, .. }) = &e {
        // The machine profile's own doing (its end block homes, its start
        // moves into the part): the page does not take a profile on trial
        // that cannot write the job (web/main.js `profileRefused`).
        let o = js_sys::Object::new();
        set(&o, "file", &file.into());
        set(&o, "field", &field.into());
        let _ = js_sys::Reflect::set(&err, &"profile".into(), &o);
    }
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

/// Numbers the page receives as a typed array of their own type (copied
/// out of wasm memory, so the worker can transfer its buffer).
trait TypedArray: Sized {
    fn typed_array(data: &[Self]) -> JsValue;
}

macro_rules! typed_array {
    ($($t:ty => $array:ty),*) => {$(
        impl TypedArray for $t {
            fn typed_array(data: &[$t]) -> JsValue {
                <$array>::from(data).into()
            }
        }
    )*};
}

typed_array!(
    u8 => js_sys::Uint8Array,
    u32 => js_sys::Uint32Array,
    f32 => js_sys::Float32Array,
    f64 => js_sys::Float64Array
);

/// Sets `key` on a JS object to a typed array of `data`.
fn set_array<T: TypedArray>(obj: &js_sys::Object, key: &str, data: &[T]) {
    set(obj, key, &T::typed_array(data));
}

const MIB: f64 = (1u64 << 20) as f64;

/// The page's limits, for its messages and the README: `{scan_bytes,
/// svg_bytes, samples, core_scan_bytes, core_samples_per_subpath,
/// core_samples_per_drawing, gcode_bytes}` (the last: the largest G-code
/// file the reader checks).
#[wasm_bindgen(js_name = pageLimits)]
pub fn page_limits() -> JsValue {
    let o = js_sys::Object::new();
    set(&o, "scan_bytes", &(PAGE_MAX_SCAN_BYTES as f64).into());
    set(&o, "svg_bytes", &(PAGE_MAX_SVG_BYTES as f64).into());
    set(&o, "samples", &(PAGE_MAX_SAMPLES as f64).into());
    set(&o, "core_scan_bytes", &(MAX_SCAN_BYTES as f64).into());
    set(&o, "core_samples_per_subpath", &(MAX_SAMPLES as f64).into());
    set(
        &o,
        "core_samples_per_drawing",
        &(MAX_DRAWING_SAMPLES as f64).into(),
    );
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
    within_limit(
        name,
        size,
        PAGE_MAX_SVG_BYTES,
        "this page reads for a drawing",
        "is it the right file? Simplify the drawing (fewer nodes, no embedded images), or plan \
         it with the command line",
    )
}

/// Refuses a scan file of `size` bytes past [`PAGE_MAX_SCAN_BYTES`] with an
/// `Error` (kind `limit`) naming the file, its size and the limit. The page
/// calls this with `File.size`, before reading anything.
#[wasm_bindgen(js_name = checkScanSize)]
pub fn check_scan_size(name: &str, size: f64) -> Result<(), JsValue> {
    within_limit(
        name,
        size,
        PAGE_MAX_SCAN_BYTES,
        "this page reads (a browser tab's memory must also hold the mesh and its search \
         structure)",
        &format!(
            "decimate the scan (e.g. MeshLab's quadric edge collapse) or crop it to the printed \
             area, or plan it with the command line (pcpp plan reads up to {} MiB)",
            MAX_SCAN_BYTES >> 20
        ),
    )
}

/// Ok for a file of `size` bytes up to `limit`; past it (or a size that is
/// not one) an `Error` of kind `limit`: "NAME: the file is X MiB, more
/// than the N MiB `reads`; `advice`", before the page reads the file.
fn within_limit(
    name: &str,
    size: f64,
    limit: usize,
    reads: &str,
    advice: &str,
) -> Result<(), JsValue> {
    if size.is_finite() && (0.0..=limit as f64).contains(&size) {
        return Ok(());
    }
    Err(kind_err(
        "limit",
        &format!(
            "{name}: the file is {:.1} MiB, more than the {} MiB {reads}; {advice}",
            size / MIB,
            limit >> 20
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
/// (as in [`Session::plan`]), read in `units` (`mm`, `cm`, `m`, `in` or
/// `ft`; mm if not given): `placement::VolumeFit` with the sentence the
/// page shows in its banner.
#[wasm_bindgen(js_name = volumeFit)]
pub fn volume_fit(
    bbox: &[f64],
    dialect: &str,
    profile_file: Option<String>,
    units: Option<String>,
) -> Result<JsValue, JsValue> {
    let bbox = bounds("the scan's bounds", bbox)?;
    let p = profile(dialect, profile_file.as_deref())?;
    // The units the scan was read in (`info.units`); mm where not given.
    let read_in = match units.as_deref() {
        Some(u) => u.parse().map_err(|e: String| JsError::new(&e))?,
        None => crate::mesh::ScanUnits::Mm,
    };
    Ok(to_js(&placement::volume_fit(
        bbox,
        &p.build_volume,
        &p.name,
        read_in,
    ))?)
}

/// Whether a scan with bounds `bbox` (`[min x, y, z, max x, y, z]`,
/// printer frame) is seen edge-on from above ([`pipeline::edge_on`]): a
/// film or plate lying on its side in the file, whose refusals are the
/// scan's to mend (its up axis), not the drawing's.
#[wasm_bindgen(js_name = edgeOn)]
pub fn edge_on(bbox: &[f64]) -> Result<bool, JsError> {
    let (lo, hi) = bounds("the scan's bounds", bbox)?;
    let size = hi - lo;
    Ok(pipeline::edge_on(size.truncate(), size.z))
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

/// The drawing's placement after the scan's registration (`matrix` of
/// the session's info, row-major) changes from `from` to `to`, the drawing
/// lying at height `z_mm` ([`placement::carry_drawing_by`]).
#[wasm_bindgen(js_name = carryDrawingBy)]
pub fn carry_drawing_by(
    drawing: JsValue,
    z_mm: f64,
    from: JsValue,
    to: JsValue,
) -> Result<JsValue, JsError> {
    let drawing: Placement = from_js("drawing placement", drawing)?;
    let from: [[f64; 4]; 4] = from_js("registration matrix", from)?;
    let to: [[f64; 4]; 4] = from_js("registration matrix", to)?;
    if !z_mm.is_finite() || !from.iter().chain(&to).flatten().all(|v| v.is_finite()) {
        return Err(JsError::new(
            "the registration matrices and the height must be finite numbers",
        ));
    }
    to_js(&placement::carry_drawing_by(&drawing, z_mm, &from, &to))
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

fn arr(p: DVec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// Refuses a G-code file of `size` bytes past the size the reader checks
/// ([`MAX_GCODE_BYTES`]) with an `Error` of kind `limit`; the page calls
/// this with `File.size` before the worker reads the file.
#[wasm_bindgen(js_name = checkGcodeSize)]
pub fn check_gcode_size(name: &str, size: f64) -> Result<(), JsValue> {
    within_limit(
        name,
        size,
        MAX_GCODE_BYTES,
        "the G-code check reads",
        "split the program and check each part",
    )
}

/// A G-code file's text, or an `Error` of kind `limit` past the size the
/// reader checks ([`check_gcode_size`]), of kind `gcode` when it is not
/// UTF-8.
fn gcode_text<'a>(bytes: &'a [u8], name: &str) -> Result<&'a str, JsValue> {
    check_gcode_size(name, bytes.len() as f64)?;
    std::str::from_utf8(bytes).map_err(|e| {
        kind_err(
            "gcode",
            &format!(
                "{name}: not UTF-8 text (byte {}); is it a G-code program?",
                e.valid_up_to()
            ),
        )
    })
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
    /// The files it was read from besides itself (a `.gltf`'s buffers).
    external_files: &'a [crate::job::InputFile],
    format: crate::mesh::MeshFormat,
    units: crate::mesh::ScanUnits,
    /// The up axis it was read with ("z", "y" or "-z", as the page's Up
    /// axis list names them).
    up_axis: crate::mesh::UpAxis,
    triangles: usize,
    /// Printer frame (after the registration or placement on the bed).
    bbox_mm: [[f64; 3]; 2],
    /// Scanner frame, as imported (what a placement on the bed moves).
    scan_bbox_mm: [[f64; 3]; 2],
    warnings: &'a [String],
    /// For a point cloud: how it was meshed, and that as one line.
    cloud: Option<crate::mesh::CloudInfo>,
    cloud_text: Option<String>,
    /// Set when the scan is so small that its units are likely wrong
    /// (`given` false: no G-code until the user gives them).
    units_doubt: Option<UnitsDoubtView>,
    registration: RegistrationView<'a>,
    holes: Vec<HoleView>,
}

#[derive(Serialize)]
struct UnitsDoubtView {
    size_mm: [f64; 3],
    units: crate::mesh::ScanUnits,
    given: bool,
    /// Too large for its units rather than too small.
    too_large: bool,
    /// The core's warning, naming the file.
    message: String,
    /// A few stray vertices make it large ([`crate::mesh::StrayVertices`]):
    /// no units mend it, and none are offered.
    stray: bool,
    /// The units it may be in, each with the size it would have.
    offers: Vec<UnitsOffer>,
}

#[derive(Serialize)]
struct UnitsOffer {
    units: crate::mesh::ScanUnits,
    size_mm: [f64; 3],
}

impl UnitsDoubtView {
    fn new(d: &crate::mesh::UnitsDoubt, file: &str) -> UnitsDoubtView {
        UnitsDoubtView {
            size_mm: d.size_mm.to_array(),
            units: d.units,
            given: d.given,
            too_large: d.too_large,
            message: d.message(file),
            stray: d.stray.is_some(),
            offers: d
                .offers()
                .into_iter()
                .map(|(units, size)| UnitsOffer {
                    units,
                    size_mm: size.to_array(),
                })
                .collect(),
        }
    }
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

/// The page's sample limit ([`PAGE_MAX_SAMPLES`]) over the whole drawing,
/// after the core's own limit on a subpath, whose message (from
/// [`crate::sampling::try_sample_subpath`], which counts before it
/// allocates) the page shows as the CLI would.
fn check_samples(path: &LoadedPath, settings: &PlanSettings) -> Result<(), JsValue> {
    let placement = &settings.placement;
    // The page's limit, lower than the core's for a drawing, is the one
    // named.
    let size = crate::pipeline::drawing_size(&path.drawn.subpaths, &settings.nozzle, placement)
        .map_err(core_err)?;
    if size.samples > PAGE_MAX_SAMPLES as f64 {
        return Err(kind_err(
            "limit",
            &format!(
                "{}: about {:.2} million samples at {} mm spacing (d/2) after scaling by {}, \
                 more than the {} million this page plans in one drawing; shorten the path or \
                 scale it down, use a wider nozzle, or plan it with the command line (pcpp plan \
                 allows {} million)",
                path.file.name,
                size.samples / 1e6,
                size.spacing_mm,
                placement.scale,
                PAGE_MAX_SAMPLES / 1_000_000,
                MAX_DRAWING_SAMPLES / 1_000_000
            ),
        ));
    }
    Ok(())
}
