//! The page's 3-D view (wasm32 only): WebGL2 through web-sys.
//!
//! Draws the registered scan shaded, the surface path Ta and the tool path
//! T* as lines (T* coloured by predicted defect), fiducial markers, and for
//! the print preview a G-code program's moves (coloured by clearance or by
//! predicted defect) with the nozzle drawn to scale at the preview's
//! moment, with an orbit camera (`render/camera.rs`). Moving the nozzle
//! changes one transform; the path is uploaded once per program and
//! colouring. The WebGL plumbing (shaders, buffers, the mesh image cache)
//! is in `render/gl.rs`. It only draws what the page hands it: no planning
//! happens here (house style: rendering code holds no planning logic).

use glam::{DMat4, DVec3};
use serde::Deserialize;
use wasm_bindgen::{JsCast, JsValue};
use web_sys::{
    HtmlCanvasElement, WebGl2RenderingContext as Gl, WebGlBuffer, WebGlVertexArrayObject,
};

use crate::preview::defect_of_code;
use crate::quality::Defect;

/// Background, mesh and line colours, linear 0-1. The browser tests find
/// the mesh and the path by these colours in the read-back pixels.
pub const BACKGROUND: [f32; 3] = [0.09, 0.10, 0.13];
pub const MESH: [f32; 3] = [0.62, 0.68, 0.78];
/// Ta: light, so that it reads on the shaded mesh under T*.
pub const SURFACE_PATH: [f32; 3] = [0.95, 0.95, 0.95];
pub const HOLE_MARKER: [f32; 3] = [1.0, 0.85, 0.1];
pub const PRINTER_MARKER: [f32; 3] = [0.9, 0.2, 0.9];
/// Points picked on the mesh (scan points Sr chosen by clicking): cyan.
pub const PICK_MARKER: [f32; 3] = [0.1, 0.9, 0.95];
/// A checked G-code program's moves: feed moves light, rapid moves dim,
/// moves that come closer than tol in the contact colour.
pub const FEED_MOVE: [f32; 3] = SURFACE_PATH;
pub const RAPID_MOVE: [f32; 3] = [0.45, 0.5, 0.6];
/// The nozzle of the print preview: the tip's end bright violet (a colour
/// no path or marker uses), the body above it a muted violet.
pub const NOZZLE_TIP: [f32; 3] = [0.72, 0.38, 1.0];
pub const NOZZLE_BODY: [f32; 3] = [0.52, 0.42, 0.72];
/// Length of the tip's end drawn in the tip colour, and of the body above
/// it, mm. The motion check models the body as a cylinder of the tip's
/// diameter reaching up indefinitely (`motion::Clearance`); 12 mm of it
/// shows it without hiding the part.
pub const NOZZLE_TIP_MM: f64 = 1.0;
pub const NOZZLE_BODY_MM: f64 = 11.0;

/// The preview's colour codes for a move (`Viewer.setPreviewPath`): by
/// clearance 0 clear (green), 1 near (orange), 2 closer than tol (red); by
/// predicted defect 10 + the defect code (good, contact, flattening,
/// floating, as the plan's colours); 255 a move that prints nothing.
pub fn preview_rgb8(code: u8) -> [u8; 3] {
    match code {
        0 => defect_rgb8("good"),
        1 => defect_rgb8("flattening"),
        2 => defect_rgb8("contact"),
        10..=13 => defect_rgb8(defect_name(defect_of_code(code - 10))),
        _ => RAPID_MOVE.map(|c| (c * 255.0).round() as u8),
    }
}

fn defect_name(d: Defect) -> &'static str {
    match d {
        Defect::Contact => "contact",
        Defect::Flattening => "flattening",
        Defect::Floating => "floating",
        Defect::Good => "good",
    }
}

/// Defect colours (the legend): contact red, flattening orange,
/// floating blue, good green.
pub fn defect_rgb8(name: &str) -> [u8; 3] {
    match name {
        "contact" => [230, 40, 40],
        "flattening" => [255, 150, 20],
        "floating" => [40, 120, 255],
        _ => [40, 210, 70],
    }
}

fn defect_rgb(d: Defect) -> [f32; 3] {
    defect_rgb8(defect_name(d)).map(|c| f32::from(c) / 255.0)
}

/// The parts of a report the view draws (other fields are ignored).
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct ViewPaths {
    pub surface_path: Vec<Vec<[f64; 3]>>,
    pub toolpath: Vec<Vec<[f64; 3]>>,
    pub defects: Vec<Vec<Defect>>,
}

/// A plan's paths as flat arrays (the page's live re-planning hands these
/// over without a JSON report): points per piece, Ta and T* as xyz, and a
/// defect code per point (0 good, 1 contact, 2 flattening, 3 floating).
#[derive(Debug, Clone, Copy)]
pub struct PathArrays<'a> {
    pub pieces: &'a [u32],
    pub ta: &'a [f32],
    pub tool: &'a [f32],
    pub defects: &'a [u8],
}

/// Fiducial markers, printer frame.
#[derive(Debug, Default)]
pub struct Markers {
    pub holes: Vec<[f64; 3]>,
    pub printer: Vec<[f64; 3]>,
    /// Scan points picked on the mesh, drawn in the mesh's (printer) frame.
    pub picked: Vec<[f64; 3]>,
}

mod camera;
mod gl;

pub use camera::Camera;
use gl::{
    attrib, colored, unit_cylinder, Drawable, MeshCache, Program, BLIT_FS, BLIT_VS, LINE_FS,
    LINE_VS, MESH_FS, MESH_VS, NOZZLE_VS,
};

/// The WebGL2 state of one canvas.
pub struct Renderer {
    gl: Gl,
    mesh_prog: Program,
    line_prog: Program,
    blit_prog: Program,
    /// No attributes: the blit makes its triangle from gl_VertexID.
    blit_vao: WebGlVertexArrayObject,
    /// The mesh image; None until first drawn, or when the browser cannot
    /// render to a depth texture (then the mesh is drawn every frame).
    cache: Option<MeshCache>,
    cache_failed: bool,
    mesh: Option<(Drawable, WebGlBuffer)>,
    lines: Option<Drawable>,
    /// The tool path's contact points (section 7), drawn as markers over
    /// the lines: a few short red segments among hundreds were a few
    /// pixels (QA round 8 F6); moved with the paths by `path_offset`.
    contacts: Option<Drawable>,
    /// Holes found in the scan, and the printer points P drawn smaller on
    /// top (after a good registration they coincide).
    holes: Option<Drawable>,
    printer: Option<Drawable>,
    picked: Option<Drawable>,
    /// The preview's nozzle: a unit cylinder, and one point at the origin
    /// (moved by u_offset) marking the tip over everything.
    nozzle_prog: Program,
    cylinder: Drawable,
    tip_point: Drawable,
    /// Where the nozzle's tip is and its outer diameter; None: not drawn.
    nozzle: Option<(DVec3, f64)>,
    bounds: (DVec3, DVec3),
    /// Where the paths are drawn relative to where they were planned.
    pub path_offset: DVec3,
    width: u32,
    height: u32,
    pub camera: Camera,
}

impl Renderer {
    pub fn new(canvas: HtmlCanvasElement) -> Result<Renderer, String> {
        let opts = js_sys::Object::new();
        // Tests read the pixels back after the frame is presented.
        js_sys::Reflect::set(&opts, &"preserveDrawingBuffer".into(), &JsValue::TRUE)
            .map_err(|_| "could not set WebGL options")?;
        js_sys::Reflect::set(&opts, &"antialias".into(), &JsValue::TRUE)
            .map_err(|_| "could not set WebGL options")?;
        let gl: Gl = canvas
            .get_context_with_context_options("webgl2", &opts)
            .map_err(|_| "WebGL2 is not available in this browser")?
            .ok_or("WebGL2 is not available in this browser")?
            .dyn_into()
            .map_err(|_| "the canvas did not give a WebGL2 context")?;
        let mesh_prog = Program::new(&gl, MESH_VS, MESH_FS)?;
        let line_prog = Program::new(&gl, LINE_VS, LINE_FS)?;
        let blit_prog = Program::new(&gl, BLIT_VS, BLIT_FS)?;
        let nozzle_prog = Program::new(&gl, NOZZLE_VS, MESH_FS)?;
        let cylinder = unit_cylinder();
        let cylinder = colored(&gl, &cylinder, &vec![0.0; cylinder.len()])?;
        let tip_point = colored(&gl, &[0.0; 3], &NOZZLE_TIP)?;
        let blit_vao = gl
            .create_vertex_array()
            .ok_or("WebGL could not create a vertex array")?;
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let bounds = (DVec3::splat(-50.0), DVec3::splat(50.0));
        let aspect = f64::from(width) / f64::from(height);
        Ok(Renderer {
            gl,
            mesh_prog,
            line_prog,
            blit_prog,
            blit_vao,
            cache: None,
            cache_failed: false,
            mesh: None,
            lines: None,
            contacts: None,
            holes: None,
            printer: None,
            picked: None,
            nozzle_prog,
            cylinder,
            tip_point,
            nozzle: None,
            bounds,
            path_offset: DVec3::ZERO,
            width,
            height,
            camera: Camera::framing(bounds.0, bounds.1, aspect, f64::from(height)),
        })
    }

    pub fn resize(&mut self, width: u32, height: u32) {
        self.width = width.max(1);
        self.height = height.max(1);
        self.camera.aspect = f64::from(self.width) / f64::from(self.height);
        self.camera.height_px = f64::from(self.height);
    }

    pub fn pan(&mut self, dx: f64, dy: f64) {
        self.camera.pan(dx, dy);
    }

    /// The camera ray through a pixel of the drawing buffer (see
    /// [`Camera::ray`]).
    pub fn pick_ray(&self, x_px: f64, y_px: f64) -> Option<(DVec3, DVec3)> {
        self.camera
            .ray(x_px, y_px, f64::from(self.width), f64::from(self.height))
    }

    pub fn reset_view(&mut self) {
        self.camera = Camera::framing(
            self.bounds.0,
            self.bounds.1,
            self.camera.aspect,
            self.camera.height_px,
        );
    }

    /// Uploads a mesh and frames it.
    pub fn set_mesh(&mut self, positions: &[f32], indices: &[u32]) -> Result<(), String> {
        if !positions.len().is_multiple_of(3) || !indices.len().is_multiple_of(3) {
            return Err("mesh arrays must hold whole points and triangles".into());
        }
        let n = (positions.len() / 3) as u32;
        if indices.iter().any(|&i| i >= n) {
            return Err("a mesh index is past the last vertex".into());
        }
        let gl = &self.gl;
        if let Some((d, ib)) = self.mesh.take() {
            d.delete(gl);
            gl.delete_buffer(Some(&ib));
        }
        if let Some(c) = &mut self.cache {
            c.mvp = None;
        }
        let vao = gl
            .create_vertex_array()
            .ok_or("WebGL could not create a vertex array")?;
        gl.bind_vertex_array(Some(&vao));
        let vb = attrib(gl, 0, positions)?;
        let ib = gl
            .create_buffer()
            .ok_or("WebGL could not create a buffer")?;
        gl.bind_buffer(Gl::ELEMENT_ARRAY_BUFFER, Some(&ib));
        let view = js_sys::Uint32Array::from(indices);
        gl.buffer_data_with_array_buffer_view(Gl::ELEMENT_ARRAY_BUFFER, &view, Gl::STATIC_DRAW);
        gl.bind_vertex_array(None);
        self.mesh = Some((
            Drawable {
                vao,
                buffers: vec![vb],
                count: indices.len() as i32,
            },
            ib,
        ));
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in positions.chunks_exact(3) {
            let v = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo.is_finite() && hi.is_finite() {
            self.bounds = (lo, hi);
        }
        self.reset_view();
        Ok(())
    }

    /// Uploads Ta (one colour) and T* (coloured per point by its defect) as
    /// line segments.
    pub fn set_paths(&mut self, paths: &ViewPaths) -> Result<(), String> {
        let mut pos: Vec<f32> = Vec::new();
        let mut col: Vec<f32> = Vec::new();
        let mut push = |p: &[f64; 3], c: [f32; 3]| {
            pos.extend(p.iter().map(|&v| v as f32));
            col.extend(c);
        };
        for piece in &paths.surface_path {
            for w in piece.windows(2) {
                push(&w[0], SURFACE_PATH);
                push(&w[1], SURFACE_PATH);
            }
        }
        let mut contacts: Vec<f32> = Vec::new();
        for (k, piece) in paths.toolpath.iter().enumerate() {
            let defects = paths.defects.get(k);
            for (j, p) in piece.iter().enumerate() {
                if defects.and_then(|d| d.get(j)) == Some(&Defect::Contact) {
                    contacts.extend(p.iter().map(|&v| v as f32));
                }
            }
            let color = |j: usize| {
                defects
                    .and_then(|d| d.get(j))
                    .map_or(defect_rgb(Defect::Good), |&d| defect_rgb(d))
            };
            // Each segment takes the colour of its start point.
            for (j, w) in piece.windows(2).enumerate() {
                let c = color(j);
                push(&w[0], c);
                push(&w[1], c);
            }
        }
        self.set_lines(&pos, &col, &contacts)
    }

    /// [`Renderer::set_paths`] from flat arrays; the lengths must agree.
    pub fn set_path_arrays(&mut self, a: &PathArrays) -> Result<(), String> {
        let n: usize = a.pieces.iter().map(|&k| k as usize).sum();
        if a.ta.len() != 3 * n || a.tool.len() != 3 * n || a.defects.len() != n {
            return Err(format!(
                "path arrays disagree: {n} points in the pieces, {} Ta and {} T* coordinates, \
                 {} defects",
                a.ta.len(),
                a.tool.len(),
                a.defects.len()
            ));
        }
        let segments = n.saturating_sub(a.pieces.len());
        let mut pos: Vec<f32> = Vec::with_capacity(12 * segments);
        let mut col: Vec<f32> = Vec::with_capacity(12 * segments);
        let contacts: Vec<f32> = (0..n)
            .filter(|&j| defect_of_code(a.defects[j]) == Defect::Contact)
            .flat_map(|j| a.tool[3 * j..3 * j + 3].iter().copied())
            .collect();
        let mut start = 0;
        for &k in a.pieces {
            let (lo, hi) = (start, start + k as usize);
            for j in lo..hi.saturating_sub(1) {
                pos.extend_from_slice(&a.ta[3 * j..3 * j + 6]);
                col.extend(SURFACE_PATH);
                col.extend(SURFACE_PATH);
            }
            // Each segment takes the colour of its start point.
            for j in lo..hi.saturating_sub(1) {
                let c = defect_rgb(defect_of_code(a.defects[j]));
                pos.extend_from_slice(&a.tool[3 * j..3 * j + 6]);
                col.extend(c);
                col.extend(c);
            }
            start = hi;
        }
        self.set_lines(&pos, &col, &contacts)
    }

    /// A G-code program's straight moves in place of the paths: `moves`
    /// holds xyz from and to per move (6 floats), `kinds` one code per
    /// move (0 feed, 1 rapid, 2 too close to the surface).
    pub fn set_moves(&mut self, moves: &[f32], kinds: &[u8]) -> Result<(), String> {
        self.set_move_lines("move", moves, kinds, |k| match k {
            0 => FEED_MOVE,
            1 => RAPID_MOVE,
            _ => defect_rgb(Defect::Contact),
        })
    }

    /// A program's moves for the print preview, in place of the paths:
    /// `moves` holds xyz from and to per move (6 floats), `codes` one
    /// colour code per move ([`preview_rgb8`]). Uploaded once per program
    /// and colouring; the nozzle moves without touching it.
    pub fn set_preview_path(&mut self, moves: &[f32], codes: &[u8]) -> Result<(), String> {
        self.set_move_lines("preview", moves, codes, |k| {
            preview_rgb8(k).map(|c| f32::from(c) / 255.0)
        })
    }

    /// Moves (6 floats each) as lines in the colour of their code; `what`
    /// names the arrays when their lengths disagree.
    fn set_move_lines(
        &mut self,
        what: &str,
        moves: &[f32],
        codes: &[u8],
        colour: impl Fn(u8) -> [f32; 3],
    ) -> Result<(), String> {
        if moves.len() != 6 * codes.len() {
            return Err(format!(
                "{what} arrays disagree: {} coordinates for {} moves",
                moves.len(),
                codes.len()
            ));
        }
        let mut col: Vec<f32> = Vec::with_capacity(moves.len());
        for &k in codes {
            let c = colour(k);
            col.extend(c);
            col.extend(c);
        }
        self.set_lines(moves, &col, &[])
    }

    /// Puts the preview's nozzle with its tip at `tip` (outer diameter
    /// `outer_diameter_mm`), or takes it away (`None`).
    pub fn set_nozzle(&mut self, nozzle: Option<(DVec3, f64)>) {
        self.nozzle = nozzle.filter(|(p, d)| p.is_finite() && d.is_finite() && *d > 0.0);
    }

    /// The drawing-buffer pixel where `p` is drawn (see [`Camera::project`]).
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        self.camera
            .project(p, f64::from(self.width), f64::from(self.height))
    }

    /// The nozzle at its place: the tip's end and the body above it.
    fn draw_nozzle(&self, mvp: &[f32; 16]) {
        let Some((tip, diameter)) = self.nozzle else {
            return;
        };
        let gl = &self.gl;
        let p = &self.nozzle_prog;
        self.use_shaded(p, mvp);
        let r = 0.5 * diameter;
        gl.bind_vertex_array(Some(&self.cylinder.vao));
        for (z0, height, [cr, cg, cb]) in [
            (0.0, NOZZLE_TIP_MM, NOZZLE_TIP),
            (NOZZLE_TIP_MM, NOZZLE_BODY_MM, NOZZLE_BODY),
        ] {
            let model = DMat4::from_translation(tip + DVec3::new(0.0, 0.0, z0))
                * DMat4::from_scale(DVec3::new(r, r, height));
            gl.uniform_matrix4fv_with_f32_array(
                p.model.as_ref(),
                false,
                &model.as_mat4().to_cols_array(),
            );
            gl.uniform3f(p.color.as_ref(), cr, cg, cb);
            gl.draw_arrays(Gl::TRIANGLES, 0, self.cylinder.count);
        }
    }

    /// The lines in view, and the contact points marked over them.
    fn set_lines(&mut self, pos: &[f32], col: &[f32], contacts: &[f32]) -> Result<(), String> {
        for d in [self.lines.take(), self.contacts.take()]
            .into_iter()
            .flatten()
        {
            d.delete(&self.gl);
        }
        self.path_offset = DVec3::ZERO;
        if !pos.is_empty() {
            self.lines = Some(colored(&self.gl, pos, col)?);
        }
        if !contacts.is_empty() {
            let c = defect_rgb(Defect::Contact);
            let col: Vec<f32> = contacts.chunks(3).flat_map(|_| c).collect();
            self.contacts = Some(colored(&self.gl, contacts, &col)?);
        }
        Ok(())
    }

    pub fn set_markers(&mut self, m: &Markers) -> Result<(), String> {
        let points = |list: &[[f64; 3]], c: [f32; 3]| -> Result<Option<Drawable>, String> {
            if list.is_empty() {
                return Ok(None);
            }
            let pos: Vec<f32> = list.iter().flatten().map(|&v| v as f32).collect();
            let col: Vec<f32> = list.iter().flat_map(|_| c).collect();
            colored(&self.gl, &pos, &col).map(Some)
        };
        let holes = points(&m.holes, HOLE_MARKER)?;
        let printer = points(&m.printer, PRINTER_MARKER)?;
        let picked = points(&m.picked, PICK_MARKER)?;
        for d in [self.holes.take(), self.printer.take(), self.picked.take()]
            .into_iter()
            .flatten()
        {
            d.delete(&self.gl);
        }
        self.holes = holes;
        self.printer = printer;
        self.picked = picked;
        Ok(())
    }

    /// Uses a program of `MESH_FS` (the mesh's or the nozzle's) with the
    /// camera's `mvp` and its light.
    fn use_shaded(&self, p: &Program, mvp: &[f32; 16]) {
        let gl = &self.gl;
        gl.use_program(Some(&p.program));
        gl.uniform_matrix4fv_with_f32_array(p.mvp.as_ref(), false, mvp);
        // A headlight, a little above and left of the eye, so faces
        // turned to the viewer are lit from any orbit angle.
        let eye = self.camera.eye() - self.camera.target;
        let l = (eye.normalize_or_zero() + 0.3 * DVec3::Z).normalize_or_zero();
        gl.uniform3f(p.light.as_ref(), l.x as f32, l.y as f32, l.z as f32);
    }

    /// Draws the mesh with the camera's `mvp` into the bound framebuffer.
    fn draw_mesh(&self, mesh: &Drawable, mvp: &[f32; 16]) {
        let gl = &self.gl;
        let p = &self.mesh_prog;
        self.use_shaded(p, mvp);
        let [r, g, b] = MESH;
        gl.uniform3f(p.color.as_ref(), r, g, b);
        // Push the surface back in depth so Ta, which lies on it, wins.
        gl.enable(Gl::POLYGON_OFFSET_FILL);
        gl.polygon_offset(1.0, 2.0);
        gl.bind_vertex_array(Some(&mesh.vao));
        gl.draw_elements_with_i32(Gl::TRIANGLES, mesh.count, Gl::UNSIGNED_INT, 0);
        gl.disable(Gl::POLYGON_OFFSET_FILL);
    }

    /// The mesh image for `mvp`, drawn into the cache if it holds another
    /// view; false when there is no cache (draw the mesh directly).
    fn cached_mesh(&mut self, mesh: &Drawable, mvp: &[f32; 16]) -> bool {
        if self.cache_failed {
            return false;
        }
        let (w, h) = (self.width, self.height);
        if self
            .cache
            .as_ref()
            .is_some_and(|c| c.width != w || c.height != h)
        {
            if let Some(c) = self.cache.take() {
                c.delete(&self.gl);
            }
        }
        if self.cache.is_none() {
            match MeshCache::new(&self.gl, w, h) {
                Ok(c) => self.cache = Some(c),
                Err(_) => {
                    self.cache_failed = true;
                    return false;
                }
            }
        }
        let Some(cache) = &self.cache else {
            return false;
        };
        if cache.mvp.as_ref() == Some(mvp) {
            return true;
        }
        self.gl
            .bind_framebuffer(Gl::FRAMEBUFFER, Some(&cache.framebuffer));
        let gl = &self.gl;
        let [r, g, b] = BACKGROUND;
        gl.clear_color(r, g, b, 1.0);
        gl.clear(Gl::COLOR_BUFFER_BIT | Gl::DEPTH_BUFFER_BIT);
        self.draw_mesh(mesh, mvp);
        self.gl.bind_framebuffer(Gl::FRAMEBUFFER, None);
        if let Some(c) = &mut self.cache {
            c.mvp = Some(*mvp);
        }
        true
    }

    /// Copies the cached mesh image, colour and depth, to the canvas.
    fn blit_mesh(&self) -> Result<(), String> {
        let (gl, p) = (&self.gl, &self.blit_prog);
        let Some(cache) = &self.cache else {
            return Err("no mesh image".into());
        };
        gl.use_program(Some(&p.program));
        gl.active_texture(Gl::TEXTURE0);
        gl.bind_texture(Gl::TEXTURE_2D, Some(&cache.color));
        gl.active_texture(Gl::TEXTURE1);
        gl.bind_texture(Gl::TEXTURE_2D, Some(&cache.depth));
        gl.uniform1i(p.color_tex.as_ref(), 0);
        gl.uniform1i(p.depth_tex.as_ref(), 1);
        gl.depth_func(Gl::ALWAYS);
        gl.bind_vertex_array(Some(&self.blit_vao));
        gl.draw_arrays(Gl::TRIANGLES, 0, 3);
        gl.depth_func(Gl::LESS);
        gl.bind_texture(Gl::TEXTURE_2D, None);
        gl.active_texture(Gl::TEXTURE0);
        gl.bind_texture(Gl::TEXTURE_2D, None);
        Ok(())
    }

    pub fn draw(&mut self) {
        let gl = self.gl.clone();
        gl.viewport(0, 0, self.width as i32, self.height as i32);
        gl.enable(Gl::DEPTH_TEST);
        gl.depth_func(Gl::LESS);
        let mvp = self.camera.view_proj().as_mat4().to_cols_array();
        let mesh = self.mesh.take();
        let cached = match &mesh {
            Some((m, _)) => self.cached_mesh(m, &mvp),
            None => false,
        };
        gl.viewport(0, 0, self.width as i32, self.height as i32);
        let [r, g, b] = BACKGROUND;
        gl.clear_color(r, g, b, 1.0);
        gl.clear(Gl::COLOR_BUFFER_BIT | Gl::DEPTH_BUFFER_BIT);
        if let Some((m, _)) = &mesh {
            if !(cached && self.blit_mesh().is_ok()) {
                self.draw_mesh(m, &mvp);
            }
        }
        self.mesh = mesh;
        let gl = &self.gl;
        let p = &self.line_prog;
        gl.use_program(Some(&p.program));
        gl.uniform_matrix4fv_with_f32_array(p.mvp.as_ref(), false, &mvp);
        if let Some(lines) = &self.lines {
            let o = self.path_offset.as_vec3();
            gl.uniform3f(p.offset.as_ref(), o.x, o.y, o.z);
            gl.bind_vertex_array(Some(&lines.vao));
            gl.draw_arrays(Gl::LINES, 0, lines.count);
        }
        gl.uniform3f(p.offset.as_ref(), 0.0, 0.0, 0.0);
        self.draw_nozzle(&mvp);
        let gl = &self.gl;
        let p = &self.line_prog;
        gl.use_program(Some(&p.program));
        // Markers sit in holes: draw them over the surface.
        gl.disable(Gl::DEPTH_TEST);
        if let Some((tip, _)) = self.nozzle {
            // The tip's place, seen even where the part hides the nozzle.
            let o = tip.as_vec3();
            gl.uniform3f(p.offset.as_ref(), o.x, o.y, o.z);
            gl.uniform1f(p.point_size.as_ref(), 7.0);
            gl.bind_vertex_array(Some(&self.tip_point.vao));
            gl.draw_arrays(Gl::POINTS, 0, 1);
            gl.uniform3f(p.offset.as_ref(), 0.0, 0.0, 0.0);
        }
        for (m, size) in [
            (&self.holes, 13.0),
            (&self.printer, 6.0),
            (&self.picked, 9.0),
        ] {
            if let Some(m) = m {
                gl.uniform1f(p.point_size.as_ref(), size);
                gl.bind_vertex_array(Some(&m.vao));
                gl.draw_arrays(Gl::POINTS, 0, m.count);
            }
        }
        if let Some(c) = &self.contacts {
            // Where the nozzle meets the part, seen wherever it is, over
            // every other marker too.
            let o = self.path_offset.as_vec3();
            gl.uniform3f(p.offset.as_ref(), o.x, o.y, o.z);
            gl.uniform1f(p.point_size.as_ref(), 6.0);
            gl.bind_vertex_array(Some(&c.vao));
            gl.draw_arrays(Gl::POINTS, 0, c.count);
            gl.uniform3f(p.offset.as_ref(), 0.0, 0.0, 0.0);
        }
        gl.bind_vertex_array(None);
    }
}
