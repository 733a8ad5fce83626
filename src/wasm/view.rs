//! The page's 3-D view bindings: [`Viewer`] (orbit, pan, zoom, picking,
//! the paths, the markers and the preview's nozzle, drawn by
//! [`crate::render`]) and [`PreviewTimeline`] (a previewed program's
//! timeline on the page's thread, [`crate::preview`]). Part of
//! [`crate::wasm`]: they only convert types.

use glam::DVec3;
use serde::Serialize;
use wasm_bindgen::prelude::*;

use super::{arr, from_js, to_js};
use crate::preview::{self, TimedMove, Timeline};
use crate::render::{Markers, PathArrays, Renderer, ViewPaths};

/// A previewed program's timeline on the page's thread (built from the
/// arrays of [`Session::preview_gcode`]): where the nozzle is at a moment,
/// the move under a click, the defect each move prints
/// ([`preview::Timeline`]).
#[wasm_bindgen]
pub struct PreviewTimeline {
    t: Timeline,
}

#[derive(Serialize)]
struct CursorView {
    index: usize,
    line: usize,
    fraction: f64,
    position: [f64; 3],
}

#[derive(Serialize)]
struct PickedMove {
    index: usize,
    fraction: f64,
    time_s: f64,
    distance_mm: f64,
}

#[wasm_bindgen]
impl PreviewTimeline {
    /// `moves` (6 per move), `starts`, `durations`, `lines` and `rapid`
    /// as [`Session::preview_gcode`] returns them.
    #[wasm_bindgen(constructor)]
    pub fn new(
        moves: &[f64],
        starts: &[f64],
        durations: &[f64],
        lines: &[u32],
        rapid: &[u8],
    ) -> Result<PreviewTimeline, JsError> {
        let n = starts.len();
        if moves.len() != 6 * n || durations.len() != n || lines.len() != n || rapid.len() != n {
            return Err(JsError::new(&format!(
                "preview arrays disagree: {} coordinates, {n} starts, {} durations, {} lines, \
                 {} rapid flags",
                moves.len(),
                durations.len(),
                lines.len(),
                rapid.len()
            )));
        }
        let timed = (0..n)
            .map(|i| {
                let c = &moves[6 * i..6 * i + 6];
                TimedMove {
                    line: lines[i] as usize,
                    from: DVec3::new(c[0], c[1], c[2]),
                    to: DVec3::new(c[3], c[4], c[5]),
                    rapid: rapid[i] != 0,
                    start_s: starts[i],
                    duration_s: durations[i],
                }
            })
            .collect();
        Ok(PreviewTimeline {
            t: Timeline::new(timed),
        })
    }

    /// The program's time, s.
    #[wasm_bindgen(getter, js_name = totalS)]
    pub fn total_s(&self) -> f64 {
        self.t.total_s()
    }

    /// Where the nozzle is at `t_s`: `{index, line, fraction, position}`,
    /// or null for a program without moves.
    pub fn at(&self, t_s: f64) -> Result<JsValue, JsError> {
        match self.t.at(t_s) {
            Some(c) => to_js(&CursorView {
                index: c.index,
                line: c.line,
                fraction: c.fraction,
                position: arr(c.position),
            }),
            None => Ok(JsValue::NULL),
        }
    }

    /// The moment the nozzle is `fraction` along move `index`.
    #[wasm_bindgen(js_name = timeOf)]
    pub fn time_of(&self, index: usize, fraction: f64) -> Option<f64> {
        self.t.time_of(index, fraction)
    }

    /// The path's point under the view's ray `[ox, oy, oz, dx, dy, dz]`
    /// ([`Viewer::pick_ray`]) within `max_angle_rad`:
    /// `{index, fraction, time_s, distance_mm}`, or null.
    #[wasm_bindgen(js_name = nearestToRay)]
    pub fn nearest_to_ray(&self, ray: &[f64], max_angle_rad: f64) -> Result<JsValue, JsError> {
        let [ox, oy, oz, dx, dy, dz] = ray else {
            return Err(JsError::new("the ray must be six numbers"));
        };
        let pick = self.t.nearest_to_ray(
            DVec3::new(*ox, *oy, *oz),
            DVec3::new(*dx, *dy, *dz),
            max_angle_rad,
        );
        match pick {
            Some(p) => to_js(&PickedMove {
                index: p.index,
                fraction: p.fraction,
                time_s: p.time_s,
                distance_mm: p.distance_mm,
            }),
            None => Ok(JsValue::NULL),
        }
    }

    /// The predicted defect each move prints ([`preview::move_defects`])
    /// from a plan's `tool` points (xyz) and their `defects` codes: one
    /// code per move, 255 where it prints none of the plan's points.
    #[wasm_bindgen(js_name = moveDefects)]
    pub fn move_defects(&self, tool: &[f32], defects: &[u8], radius_mm: f64) -> Vec<u8> {
        let points: Vec<DVec3> = tool
            .chunks_exact(3)
            .map(|p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
            .collect();
        let defects: Vec<_> = defects
            .iter()
            .map(|&c| preview::defect_of_code(c))
            .collect();
        preview::move_defects(self.t.moves(), &points, &defects, radius_mm)
            .into_iter()
            .map(|d| d.map_or(255, preview::defect_code))
            .collect()
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

    /// A previewed program's moves in place of the paths: `moves` xyz from
    /// and to (6 floats per move), `codes` a colour per move
    /// ([`crate::render::preview_rgb8`]: 0 clear, 1 near, 2 closer than
    /// tol, 10 + a defect code, 255 prints nothing).
    #[wasm_bindgen(js_name = setPreviewPath)]
    pub fn set_preview_path(&mut self, moves: &[f32], codes: &[u8]) -> Result<(), JsError> {
        self.r
            .set_preview_path(moves, codes)
            .map_err(|e| JsError::new(&e))
    }

    /// The preview's nozzle with its tip at (x, y, z), drawn to scale with
    /// its outer diameter; a diameter of 0 (or anything not finite) takes
    /// it away.
    #[wasm_bindgen(js_name = setNozzle)]
    pub fn set_nozzle(&mut self, x: f64, y: f64, z: f64, outer_diameter_mm: f64) {
        self.r
            .set_nozzle(Some((DVec3::new(x, y, z), outer_diameter_mm)));
    }

    /// Where the point (x, y, z) is drawn: `[x, y]` drawing-buffer pixels
    /// from the top-left, or an error when it is behind the camera.
    #[wasm_bindgen(js_name = projectPoint)]
    pub fn project_point(&self, x: f64, y: f64, z: f64) -> Result<Vec<f64>, JsError> {
        let (px, py) = self
            .r
            .project(DVec3::new(x, y, z))
            .ok_or_else(|| JsError::new("the point is behind the camera"))?;
        Ok(vec![px, py])
    }

    /// The angle (rad) one drawing-buffer pixel spans: a click's tolerance.
    #[wasm_bindgen(js_name = pixelAngle)]
    pub fn pixel_angle(&self) -> f64 {
        self.r.camera.pixel_angle()
    }

    /// The preview's colour for a code of [`Viewer::set_preview_path`],
    /// `[r, g, b]` 0-255 (legend and tests).
    #[wasm_bindgen(js_name = previewColor)]
    pub fn preview_color(code: u8) -> Vec<u8> {
        crate::render::preview_rgb8(code).to_vec()
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
