//! The page's planning bindings: [`Session`] (a prepared scan that plans,
//! checks G-code and previews it), made by [`super::scan`]'s staged steps
//! or at once from a file's bytes. Part of [`crate::wasm`]: they only
//! convert types; every decision is made by [`crate::job`] and the core.

use glam::DVec3;
use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::{
    arr, check_samples, core_err, from_js, gcode_text, js_err, kind_err, profile, set, set_array,
    to_js, vec3, HoleView, PickView, RegistrationView, ScanView, TypedArray, UnitsDoubtView,
    PAGE_MAX_DRAWN_MOVES,
};
use crate::job::{self, InputFile, PreparedScan, RegistrationSettings};
use crate::mesh::ImportOptions;
use crate::params::Nozzle;
use crate::pipeline::{self, DrawnPath, Plan, PlanSettings, SurfacePath};
use crate::placement;
use crate::planners::PlannerKind;
use crate::preview::{self, FeedRules, PlanArrays, Timeline};
use crate::svg::Placement;

/// The drawing the session plans, read once per file.
pub(super) struct LoadedPath {
    pub(super) file: InputFile,
    pub(super) drawn: DrawnPath,
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
    /// The report of the last plan that left its JSON for later
    /// (`with_report` false): its number and the report, until the next such plan. The
    /// JSON of a large drawing's report runs to tens of MB (35.6 MB for the
    /// 100 k point raster W3), and a page that re-plans as the user drags
    /// needs it only when the user downloads it.
    kept_report: Option<(u32, job::Report)>,
}

/// Reports kept so far by every session of this wasm instance: a report's
/// number, so one session's number never names another session's report.
static REPORTS_KEPT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

#[derive(Serialize)]
struct PlanResult {
    gcode: String,
    /// Pretty JSON, exactly what the CLI's `--report` writes (left out when
    /// it was left for later, see [`Session::report_json`]).
    report_json: Option<String>,
    /// The report kept for [`Session::report_json`] instead.
    report_id: Option<u32>,
    warnings: Vec<String>,
}

/// Pretty JSON and a final newline: what the CLI's `--report` writes.
fn report_bytes(report: &job::Report) -> Result<Vec<u8>, JsValue> {
    let mut json = serde_json::to_vec_pretty(report).map_err(js_err)?;
    json.push(b'\n');
    Ok(json)
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
    /// What the quality figures describe, as the header's quality line
    /// says it (`Report::quality_scope`).
    quality_scope: String,
}

impl Session {
    /// Ok once the scan's SHA-256 is known (see [`Session::set_scan_sha256`]).
    fn digest_known(&self) -> Result<(), JsValue> {
        if self.scan.file.sha256.is_empty() {
            return Err(JsError::new(&format!(
                "{}: its SHA-256 (which the G-code and the report name it by) is not found yet; \
                 plan again",
                self.scan.file.name
            ))
            .into());
        }
        Ok(())
    }

    /// Keeps `report` for [`Session::report_json`] in place of the last one
    /// kept, and returns its number.
    fn keep_report(&mut self, report: job::Report) -> u32 {
        // The old report goes first: memory for one, not two.
        self.kept_report = None;
        let id = REPORTS_KEPT.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        self.kept_report = Some((id, report));
        id
    }

    /// `scan_bbox`: the import's bounds (scanner frame); without them they
    /// are found by taking the registered mesh back (G is rigid).
    pub(super) fn from_prepared(scan: PreparedScan, scan_bbox: Option<(DVec3, DVec3)>) -> Session {
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
            kept_report: None,
        }
    }

    /// Projects the drawing for the nozzle and placement of `settings`
    /// unless the cache already holds that surface path; its refusal says
    /// the units of a scan implausibly large in them for `profile`, as
    /// [`job::run_on`]'s does.
    fn ensure_surface_path(
        &mut self,
        settings: &PlanSettings,
        profile: &crate::gcode::MachineProfile,
    ) -> Result<(), JsValue> {
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
            .map_err(|e| core_err(job::with_units_hint(e, &self.scan, profile)))?;
            self.cache = Some(PathCache {
                nozzle: settings.nozzle,
                placement: settings.placement,
                surface_path,
            });
        }
        Ok(())
    }
}

/// The per-point arrays of a plan as typed arrays ([`PlanArrays`]):
/// `pieces`, `ta`, `tool`, `defects`, `slope` (deg), `kappa` (1/mm) and
/// `error` (mm, NaN at a contact), for the view and the plot without
/// parsing the JSON report.
fn plan_arrays(plan: &Plan) -> js_sys::Object {
    let a = PlanArrays::of(plan);
    let o = js_sys::Object::new();
    set_array(&o, "pieces", &a.pieces);
    set_array(&o, "ta", &a.ta);
    set_array(&o, "tool", &a.tool);
    set_array(&o, "defects", &a.defects);
    set_array(&o, "slope", &a.slope_deg);
    set_array(&o, "kappa", &a.kappa);
    set_array(&o, "error", &a.error_mm);
    o
}

/// One planner's per-point errors and defect codes for the plot beside the
/// others: `{planner, error, defects}` ([`preview::plan_errors`]).
fn plan_series(plan: &Plan) -> Result<js_sys::Object, JsError> {
    let (error, defects) = preview::plan_errors(plan);
    let o = js_sys::Object::new();
    set(&o, "planner", &to_js(&plan.planner)?);
    set_array(&o, "error", &error);
    set_array(&o, "defects", &defects);
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
            external_files: &s.file.external_files,
            format: s.format,
            units: s.units,
            up_axis: s.up_axis,
            triangles: s.triangle_count(),
            bbox_mm: [arr(lo), arr(hi)],
            scan_bbox_mm: [arr(slo), arr(shi)],
            warnings: &s.warnings,
            cloud: s.cloud,
            cloud_text: s.cloud.map(|c| c.to_string()),
            units_doubt: s
                .units_doubt
                .as_ref()
                .map(|d| UnitsDoubtView::new(d, &s.file.name)),
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
    /// `{gcode, report_json, warnings}`. With `with_report` false,
    /// `report_json` is left out and `report_id` names the report kept for
    /// [`Session::report_json`] (see [`Session::plan_live`]).
    // A JS call's positional arguments, the last one optional.
    #[allow(clippy::too_many_arguments)]
    pub fn plan(
        &mut self,
        svg: &[u8],
        svg_name: &str,
        settings: JsValue,
        dialect: &str,
        accept_risk: bool,
        profile_file: Option<String>,
        with_report: Option<bool>,
    ) -> Result<JsValue, JsValue> {
        self.digest_known()?;
        let settings: PlanSettings = from_js("plan settings", settings)?;
        let profile = profile(dialect, profile_file.as_deref())?;
        let out = job::run_on(&self.scan, svg, svg_name, &settings, &profile, accept_risk)
            .map_err(core_err)?;
        let warnings = out.report.warnings.clone();
        let (report_json, report_id) = if with_report.unwrap_or(true) {
            (Some(report_bytes(&out.report)?), None)
        } else {
            (None, Some(self.keep_report(out.report)))
        };
        Ok(to_js(&PlanResult {
            gcode: out.gcode,
            report_json: report_json.map(|b| String::from_utf8(b).expect("JSON is UTF-8")),
            report_id,
            warnings,
        })?)
    }

    /// The JSON report (UTF-8 bytes, exactly what the CLI's `--report`
    /// writes) of the plan `id` made with `with_report` false, while it is the
    /// last such plan; an error otherwise.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self, id: u32) -> Result<Vec<u8>, JsValue> {
        match &self.kept_report {
            Some((kept, report)) if *kept == id => report_bytes(report),
            _ => Err(JsError::new(
                "the report of that plan is no longer kept (a later plan replaced it): plan again",
            )
            .into()),
        }
    }

    /// Gives the scan's SHA-256 (32 bytes) found beside its import (a
    /// `ScanBuffer` made with `hashed` false, [`super::Sha256Stream`]): the
    /// G-code header and the report name the scan by it, and a check
    /// compares a program's header with it, so until it is given the
    /// session neither plans nor checks.
    #[wasm_bindgen(js_name = setScanSha256)]
    pub fn set_scan_sha256(&mut self, digest: &[u8]) -> Result<(), JsError> {
        if digest.len() != 32 {
            return Err(JsError::new(&format!(
                "a SHA-256 has 32 bytes, this one {}",
                digest.len()
            )));
        }
        self.scan.file.set_digest(digest);
        Ok(())
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
    /// (printer XY), or on its surface nearest the footprint's middle when
    /// that is a gap, keeping the rotation and scale of `placement` and
    /// scaling it down when it does not fit ([`placement::centre_on_surface`]),
    /// unless `fit` is false: then the scale is kept whatever the size, as
    /// `pcpp plan --place centre,ROT,SCALE` keeps a scale given (QA round
    /// 17 F7). `{placement, note}` (`note` says how it was scaled, or is
    /// null), or null for a drawing without points.
    #[wasm_bindgen(js_name = centreDrawing)]
    pub fn centre_drawing(
        &self,
        placement: JsValue,
        fit: Option<bool>,
    ) -> Result<JsValue, JsValue> {
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
        let centred = placement::centre_on_surface(
            &path.drawn.subpaths,
            &self.scan.surface,
            &current,
            fit.unwrap_or(true),
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
    /// planner, or null), `comparisonNotes` (`job::comparison_notes` of
    /// those rows, the notes `pcpp compare` prints under its table, or
    /// null) and `series` (per planner, see [`plan_series`], or null).
    /// With `with_report` false, `report` is left out and `reportId`
    /// names the report kept for [`Session::report_json`]: its JSON is
    /// written only if asked for (a page re-planning as the user drags
    /// would write tens of MB per plan of a large drawing for nothing).
    ///
    /// G-code whose moves come closer to the surface than tol is refused
    /// unless `accept_risk` (an `Error` of kind `touching`, see
    /// [`core_err`]); that error also carries the `comparison`, its notes
    /// and `series` when they were asked for, so the page can compare the planners on the
    /// settings that failed. Every refusal of a plan made (touching, far
    /// above, mostly beside the scan, out of the volume, ...) carries its
    /// `view` (as a plan's) and the `placement` it was planned at.
    #[wasm_bindgen(js_name = planLive)]
    pub fn plan_live(
        &mut self,
        settings: JsValue,
        dialect: &str,
        accept_risk: bool,
        profile_file: Option<String>,
        compare: bool,
        with_report: Option<bool>,
    ) -> Result<JsValue, JsValue> {
        self.digest_known()?;
        let settings: PlanSettings = from_js("plan settings", settings)?;
        // As job::run_on: bad settings and profiles fail before any work.
        settings.validate().map_err(core_err)?;
        job::refuse_unit_doubt(&self.scan, accept_risk).map_err(core_err)?;
        let profile = profile(dialect, profile_file.as_deref())?;
        job::refuse_blocking_strays(&self.scan, &profile).map_err(core_err)?;
        job::refuse_bad_registration(&self.scan.registration, &settings.nozzle, accept_risk)
            .map_err(core_err)?;
        if let Err(err) = self.ensure_surface_path(&settings, &profile) {
            // The drawing's notes go with a failure of its surface path
            // as with a refusal, and as `pcpp plan` prints them (a
            // drawing read at 90 px per inch may be why it misses the
            // scan), less what the failure says itself.
            if let Some(path) = &self.path {
                let said = js_sys::Reflect::get(&err, &"message".into())
                    .ok()
                    .and_then(|m| m.as_string())
                    .unwrap_or_default();
                if let Ok(w) = to_js(&job::warnings_not_said(&said, &path.drawn.notes)) {
                    let _ = js_sys::Reflect::set(&err, &"warnings".into(), &w);
                }
            }
            return Err(err);
        }
        let Some(cache) = &self.cache else {
            return Err(JsError::new("the surface path was not kept").into());
        };
        let sp = &cache.surface_path;
        let surface = &self.scan.surface;
        let plan_with = |k: PlannerKind| {
            pipeline::plan_surface_path(surface, sp, k, &settings.nozzle, &settings.process)
        };
        let plan = plan_with(settings.planner);
        let (comparison, series, notes) = if compare {
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
            // The notes `pcpp compare` prints under its table, in the
            // core's words (QA round 12 H1).
            let notes = to_js(&job::comparison_notes(&table))?;
            (JsValue::from(rows), JsValue::from(series), notes)
        } else {
            (JsValue::NULL, JsValue::NULL, JsValue::NULL)
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
                // What the report would have warned of about the drawing
                // and the plan, less what the refusal says (QA round 15 F2).
                let noted: Vec<String> = (path.drawn.notes.iter())
                    .chain(&plan.warnings)
                    .cloned()
                    .collect();
                let e = job::advise_off_scan(e, &path.drawn.subpaths, surface, &settings.placement);
                let warnings = job::refused_plan_warnings(&e, &noted);
                let err = core_err(e);
                if let Ok(w) = to_js(&warnings) {
                    let _ = js_sys::Reflect::set(&err, &"warnings".into(), &w);
                }
                // The refused tool path, and where the drawing was placed,
                // so that the page shows what was refused where it lies
                // (QA round 7 F3: "move the drawing off that feature" was
                // to be done blind).
                let _ = js_sys::Reflect::set(&err, &"view".into(), &plan_arrays(&plan).into());
                if let Ok(placement) = to_js(&settings.placement) {
                    let _ = js_sys::Reflect::set(&err, &"placement".into(), &placement);
                }
                if compare {
                    let _ = js_sys::Reflect::set(&err, &"comparison".into(), &comparison);
                    let _ = js_sys::Reflect::set(&err, &"comparisonNotes".into(), &notes);
                    let _ = js_sys::Reflect::set(&err, &"series".into(), &series);
                }
                return Err(err);
            }
        };
        let out = js_sys::Object::new();
        set_array(&out, "gcode", gcode.as_bytes());
        let summary = PlanSummary {
            planner: plan.planner,
            settings: &settings,
            quality: plan.quality,
            stats: plan.stats,
            warnings: &report.warnings,
            registration_rms_mm: report.registration.rms_mm,
            motion: &report.motion,
            motion_line: report.motion.summary_line(),
            quality_scope: report.quality_scope(),
        };
        set(&out, "summary", &to_js(&summary)?);
        set(&out, "view", &plan_arrays(&plan).into());
        set(&out, "comparison", &comparison);
        set(&out, "comparisonNotes", &notes);
        set(&out, "series", &series);
        if with_report.unwrap_or(true) {
            set_array(&out, "report", &report_bytes(&report)?);
        } else {
            set(&out, "reportId", &self.keep_report(report).into());
        }
        Ok(out.into())
    }

    /// Checks a G-code file (`bytes`, UTF-8 text, any program: ours or
    /// another tool's) against this scan ([`job::check_gcode`]): every
    /// straight move along its length, the nozzle `nozzle` (`{inner_diameter_mm,
    /// outer_diameter_mm}`) kept `tol_mm` from the surface, the program
    /// read for the machine profile named `dialect` (its name, built-in or
    /// the user's; Marlin's when none: [`job::check_gcode_as`]). Returns the
    /// `job::GcodeCheck` with `clear` (no move closer than tol),
    /// `clear_verdict` (its words, or null) and, for
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
        dialect: Option<String>,
    ) -> Result<JsValue, JsValue> {
        let nozzle: Nozzle = from_js("nozzle", nozzle)?;
        let text = gcode_text(bytes, name)?;
        self.digest_known()?;
        // Read for the profile named (the grbl profile's programs as Grbl
        // reads them); the default dialect's when none is named.
        let profile = dialect.as_deref().unwrap_or("marlin");
        let check = job::check_gcode_as(&self.scan, text, name, &nozzle, tol_mm, profile)
            .map_err(core_err)?;
        let out = to_js(&check)?;
        let o: &js_sys::Object = out.unchecked_ref();
        set(o, "clear", &JsValue::from_bool(check.is_clear()));
        // The CLI's words for a clear check.
        let verdict = check.clear_verdict();
        set(
            o,
            "clear_verdict",
            &verdict.map_or(JsValue::NULL, JsValue::from),
        );
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
            moves = f32::typed_array(&xyz);
            kinds = u8::typed_array(&k);
        }
        set(o, "moves", &moves);
        set(o, "kinds", &kinds);
        Ok(out)
    }

    /// The print preview of a G-code file (`bytes`; the plan's own or one
    /// being checked) on this scan: its straight moves timed at the file's
    /// feeds with the machine profile `dialect` (as [`Session::plan_live`];
    /// `print_speed_mm_s` until the file sets a feed,
    /// [`preview::time_moves`]) and each move's clearance along its length
    /// for `nozzle` and `tol_mm` (the motion check's, found up to tol +
    /// [`preview::PREVIEW_CLEARANCE_CAP_ABOVE_TOL_MM`]). Returns `moves`
    /// (xyz from and to, Float64Array), `lines` (Uint32Array), `rapid`,
    /// `starts` and `durations` (s), `clearance` (Float32Array, NaN above
    /// the cap), `classes` (0 clear, 1 near, 2 closer than tol),
    /// `total_s`, `tol_mm`, `near_mm`, `cap_mm`. Errors as
    /// [`Session::check_gcode`]'s; more than [`PAGE_MAX_DRAWN_MOVES`]
    /// moves is an error of kind `limit`.
    #[wasm_bindgen(js_name = previewGcode)]
    #[allow(clippy::too_many_arguments)]
    pub fn preview_gcode(
        &self,
        bytes: &[u8],
        name: &str,
        nozzle: JsValue,
        tol_mm: f64,
        dialect: &str,
        profile_file: Option<String>,
        print_speed_mm_s: f64,
    ) -> Result<JsValue, JsValue> {
        let nozzle: Nozzle = from_js("nozzle", nozzle)?;
        nozzle.validate().map_err(core_err)?;
        crate::params::Process::DEFAULT
            .with_tolerance_mm(tol_mm)
            .validate()
            .map_err(core_err)?;
        let profile = profile(dialect, profile_file.as_deref())?;
        let text = gcode_text(bytes, name)?;
        let program = crate::gcode::read_gcode(text, name).map_err(|e| core_err(e.into()))?;
        if program.moves.len() > PAGE_MAX_DRAWN_MOVES {
            return Err(kind_err(
                "limit",
                &format!(
                    "{name}: {} moves, more than the {} the page previews; check it, or \
                     preview a part of it",
                    program.moves.len(),
                    PAGE_MAX_DRAWN_MOVES
                ),
            ));
        }
        let rules = FeedRules::of_profile(&profile, print_speed_mm_s);
        let timeline = Timeline::new(preview::time_moves(text, &program.moves, &rules));
        let moves = timeline.moves();
        let cap = tol_mm + preview::PREVIEW_CLEARANCE_CAP_ABOVE_TOL_MM;
        let clearance = crate::motion::Clearance::new(&nozzle, tol_mm);
        let gaps = preview::move_clearances(&self.scan.surface, moves, &clearance, cap);
        let near = preview::DEFAULT_NEAR_MM;
        let classes: Vec<u8> = gaps
            .iter()
            .map(|&g| preview::ClearanceClass::of(g, tol_mm, near).code())
            .collect();
        let gaps: Vec<f32> = gaps
            .iter()
            .map(|g| g.map_or(f32::NAN, |g| g as f32))
            .collect();
        let xyz: Vec<f64> = moves
            .iter()
            .flat_map(|m| [m.from.x, m.from.y, m.from.z, m.to.x, m.to.y, m.to.z])
            .collect();
        let lines: Vec<u32> = moves.iter().map(|m| m.line as u32).collect();
        let rapid: Vec<u8> = moves.iter().map(|m| u8::from(m.rapid)).collect();
        let starts: Vec<f64> = moves.iter().map(|m| m.start_s).collect();
        let durations: Vec<f64> = moves.iter().map(|m| m.duration_s).collect();
        let o = js_sys::Object::new();
        set_array(&o, "moves", &xyz);
        set_array(&o, "lines", &lines);
        set_array(&o, "rapid", &rapid);
        set_array(&o, "starts", &starts);
        set_array(&o, "durations", &durations);
        set_array(&o, "clearance", &gaps);
        set_array(&o, "classes", &classes);
        set(&o, "total_s", &timeline.total_s().into());
        set(&o, "tol_mm", &tol_mm.into());
        set(&o, "near_mm", &near.into());
        set(&o, "cap_mm", &cap.into());
        Ok(o.into())
    }

    /// Every planner's quality and motion summaries side by side
    /// ([`job::compare_on`], which refuses stray vertices and gives the
    /// units advice as `pcpp compare` does), for the machine profile
    /// `dialect` (a built-in name or a profile's JSON text, `profile_file`
    /// naming it; marlin when not given).
    pub fn compare(
        &self,
        svg: &[u8],
        svg_name: &str,
        settings: JsValue,
        dialect: Option<String>,
        profile_file: Option<String>,
    ) -> Result<JsValue, JsValue> {
        let settings: PlanSettings = from_js("plan settings", settings)?;
        let profile = profile(
            dialect.as_deref().unwrap_or("marlin"),
            profile_file.as_deref(),
        )?;
        let comparison =
            job::compare_on(&self.scan, svg, svg_name, &settings, &profile).map_err(core_err)?;
        to_js(&comparison.rows).map_err(JsValue::from)
    }
}
