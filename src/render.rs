//! The page's 3-D view (wasm32 only): WebGL2 through web-sys.
//!
//! Draws the registered scan shaded, the surface path Ta and the tool path
//! T* as lines (T* coloured by predicted defect), fiducial markers, and for
//! the print preview a G-code program's moves (coloured by clearance or by
//! predicted defect) with the nozzle drawn to scale at the preview's
//! moment, with an orbit camera. Moving the nozzle changes one transform;
//! the path is uploaded once per program and colouring. It only draws what the page hands it: no planning
//! happens here (house style: rendering code holds no planning logic).

use glam::{DMat4, DVec3};
use serde::Deserialize;
use wasm_bindgen::{JsCast, JsValue};
use web_sys::{
    HtmlCanvasElement, WebGl2RenderingContext as Gl, WebGlBuffer, WebGlFramebuffer, WebGlProgram,
    WebGlShader, WebGlTexture, WebGlUniformLocation, WebGlVertexArrayObject,
};

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
        10..=13 => defect_rgb8(defect_name(crate::preview::defect_of_code(code - 10))),
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

/// Defect colours (the issue's legend): contact red, flattening orange,
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

use crate::preview::defect_of_code;

/// Fiducial markers, printer frame.
#[derive(Debug, Default)]
pub struct Markers {
    pub holes: Vec<[f64; 3]>,
    pub printer: Vec<[f64; 3]>,
    /// Scan points picked on the mesh, drawn in the mesh's (printer) frame.
    pub picked: Vec<[f64; 3]>,
}

const MESH_VS: &str = r#"#version 300 es
uniform mat4 u_mvp;
layout(location = 0) in vec3 a_pos;
out vec3 v_pos;
void main() {
  v_pos = a_pos;
  gl_Position = u_mvp * vec4(a_pos, 1.0);
}
"#;

// Flat shading from screen-space derivatives: the scan needs no normals
// uploaded, and its facets (the scanner's resolution) stay visible.
const MESH_FS: &str = r#"#version 300 es
precision highp float;
uniform vec3 u_light;
uniform vec3 u_color;
in vec3 v_pos;
out vec4 o_color;
void main() {
  vec3 n = normalize(cross(dFdx(v_pos), dFdy(v_pos)));
  float l = abs(dot(n, u_light));
  o_color = vec4(u_color * (0.35 + 0.65 * l), 1.0);
}
"#;

// The nozzle: a unit cylinder placed by u_model, shaded as the mesh is
// (MESH_FS, from the world position's derivatives).
const NOZZLE_VS: &str = r#"#version 300 es
uniform mat4 u_mvp;
uniform mat4 u_model;
layout(location = 0) in vec3 a_pos;
out vec3 v_pos;
void main() {
  v_pos = (u_model * vec4(a_pos, 1.0)).xyz;
  gl_Position = u_mvp * vec4(v_pos, 1.0);
}
"#;

// u_offset moves the paths while the user drags them, until the re-plan
// at the new placement arrives (zero for markers).
const LINE_VS: &str = r#"#version 300 es
uniform mat4 u_mvp;
uniform float u_point_size;
uniform vec3 u_offset;
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_color;
out vec3 v_color;
void main() {
  v_color = a_color;
  gl_PointSize = u_point_size;
  gl_Position = u_mvp * vec4(a_pos + u_offset, 1.0);
}
"#;

const LINE_FS: &str = r#"#version 300 es
precision mediump float;
in vec3 v_color;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0); }
"#;

// Copies the cached mesh image (colour and depth) to the canvas: one
// triangle covering the viewport, texel for pixel, writing the mesh's depth
// so the paths drawn next are hidden behind the surface as before.
const BLIT_VS: &str = r#"#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"#;

const BLIT_FS: &str = r#"#version 300 es
precision highp float;
uniform sampler2D u_color_tex;
uniform highp sampler2D u_depth_tex;
out vec4 o_color;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  o_color = texelFetch(u_color_tex, px, 0);
  gl_FragDepth = texelFetch(u_depth_tex, px, 0).r;
}
"#;

/// The mesh drawn once into textures (colour and depth) and reused while
/// the camera and the canvas size stay: moving the path, or a new plan,
/// then redraws only the lines. A scan of a few million triangles costs
/// a software renderer (or a weak GPU) hundreds of milliseconds a frame.
struct MeshCache {
    framebuffer: WebGlFramebuffer,
    color: WebGlTexture,
    depth: WebGlTexture,
    width: u32,
    height: u32,
    /// The camera matrix the textures hold the mesh for; None: stale.
    mvp: Option<[f32; 16]>,
}

impl MeshCache {
    fn new(gl: &Gl, width: u32, height: u32) -> Result<MeshCache, String> {
        let texture = |internal: u32, format: u32, kind: u32| -> Result<WebGlTexture, String> {
            let t = gl
                .create_texture()
                .ok_or("WebGL could not create a texture")?;
            gl.bind_texture(Gl::TEXTURE_2D, Some(&t));
            gl.tex_image_2d_with_i32_and_i32_and_i32_and_format_and_type_and_opt_u8_array(
                Gl::TEXTURE_2D,
                0,
                internal as i32,
                width as i32,
                height as i32,
                0,
                format,
                kind,
                None,
            )
            .map_err(|e| format!("WebGL texImage2D failed: {e:?}"))?;
            for p in [Gl::TEXTURE_MIN_FILTER, Gl::TEXTURE_MAG_FILTER] {
                gl.tex_parameteri(Gl::TEXTURE_2D, p, Gl::NEAREST as i32);
            }
            Ok(t)
        };
        let color = texture(Gl::RGBA8, Gl::RGBA, Gl::UNSIGNED_BYTE)?;
        let depth = texture(Gl::DEPTH_COMPONENT24, Gl::DEPTH_COMPONENT, Gl::UNSIGNED_INT)?;
        gl.bind_texture(Gl::TEXTURE_2D, None);
        let framebuffer = gl
            .create_framebuffer()
            .ok_or("WebGL could not create a framebuffer")?;
        gl.bind_framebuffer(Gl::FRAMEBUFFER, Some(&framebuffer));
        for (attachment, t) in [
            (Gl::COLOR_ATTACHMENT0, &color),
            (Gl::DEPTH_ATTACHMENT, &depth),
        ] {
            gl.framebuffer_texture_2d(Gl::FRAMEBUFFER, attachment, Gl::TEXTURE_2D, Some(t), 0);
        }
        let complete = gl.check_framebuffer_status(Gl::FRAMEBUFFER) == Gl::FRAMEBUFFER_COMPLETE;
        gl.bind_framebuffer(Gl::FRAMEBUFFER, None);
        let cache = MeshCache {
            framebuffer,
            color,
            depth,
            width,
            height,
            mvp: None,
        };
        if complete {
            Ok(cache)
        } else {
            cache.delete(gl);
            Err("the mesh cache framebuffer is incomplete".into())
        }
    }

    fn delete(self, gl: &Gl) {
        gl.delete_framebuffer(Some(&self.framebuffer));
        gl.delete_texture(Some(&self.color));
        gl.delete_texture(Some(&self.depth));
    }
}

fn compile(gl: &Gl, kind: u32, src: &str) -> Result<WebGlShader, String> {
    let shader = gl
        .create_shader(kind)
        .ok_or("WebGL could not create a shader")?;
    gl.shader_source(&shader, src);
    gl.compile_shader(&shader);
    if gl
        .get_shader_parameter(&shader, Gl::COMPILE_STATUS)
        .as_bool()
        .unwrap_or(false)
    {
        Ok(shader)
    } else {
        let log = gl.get_shader_info_log(&shader).unwrap_or_default();
        gl.delete_shader(Some(&shader));
        Err(format!("shader did not compile: {log}"))
    }
}

fn link(gl: &Gl, vs: &str, fs: &str) -> Result<WebGlProgram, String> {
    let v = compile(gl, Gl::VERTEX_SHADER, vs)?;
    let f = compile(gl, Gl::FRAGMENT_SHADER, fs)?;
    let p = gl
        .create_program()
        .ok_or("WebGL could not create a program")?;
    gl.attach_shader(&p, &v);
    gl.attach_shader(&p, &f);
    gl.link_program(&p);
    // Shaders are no longer needed once linked (or failed).
    gl.delete_shader(Some(&v));
    gl.delete_shader(Some(&f));
    if gl
        .get_program_parameter(&p, Gl::LINK_STATUS)
        .as_bool()
        .unwrap_or(false)
    {
        Ok(p)
    } else {
        let log = gl.get_program_info_log(&p).unwrap_or_default();
        gl.delete_program(Some(&p));
        Err(format!("shader program did not link: {log}"))
    }
}

struct Program {
    program: WebGlProgram,
    mvp: Option<WebGlUniformLocation>,
    light: Option<WebGlUniformLocation>,
    color: Option<WebGlUniformLocation>,
    point_size: Option<WebGlUniformLocation>,
    offset: Option<WebGlUniformLocation>,
    model: Option<WebGlUniformLocation>,
    color_tex: Option<WebGlUniformLocation>,
    depth_tex: Option<WebGlUniformLocation>,
}

impl Program {
    fn new(gl: &Gl, vs: &str, fs: &str) -> Result<Program, String> {
        let program = link(gl, vs, fs)?;
        Ok(Program {
            mvp: gl.get_uniform_location(&program, "u_mvp"),
            light: gl.get_uniform_location(&program, "u_light"),
            color: gl.get_uniform_location(&program, "u_color"),
            point_size: gl.get_uniform_location(&program, "u_point_size"),
            offset: gl.get_uniform_location(&program, "u_offset"),
            model: gl.get_uniform_location(&program, "u_model"),
            color_tex: gl.get_uniform_location(&program, "u_color_tex"),
            depth_tex: gl.get_uniform_location(&program, "u_depth_tex"),
            program,
        })
    }
}

/// One uploaded vertex array and its buffers (deleted on replacement).
struct Drawable {
    vao: WebGlVertexArrayObject,
    buffers: Vec<WebGlBuffer>,
    count: i32,
}

impl Drawable {
    fn delete(self, gl: &Gl) {
        gl.delete_vertex_array(Some(&self.vao));
        for b in &self.buffers {
            gl.delete_buffer(Some(b));
        }
    }
}

fn upload_f32(gl: &Gl, target: u32, data: &[f32]) -> Result<WebGlBuffer, String> {
    let b = gl
        .create_buffer()
        .ok_or("WebGL could not create a buffer")?;
    gl.bind_buffer(target, Some(&b));
    let view = js_sys::Float32Array::from(data);
    gl.buffer_data_with_array_buffer_view(target, &view, Gl::STATIC_DRAW);
    Ok(b)
}

fn attrib(gl: &Gl, location: u32, data: &[f32]) -> Result<WebGlBuffer, String> {
    let b = upload_f32(gl, Gl::ARRAY_BUFFER, data)?;
    gl.enable_vertex_attrib_array(location);
    gl.vertex_attrib_pointer_with_i32(location, 3, Gl::FLOAT, false, 0, 0);
    Ok(b)
}

/// Line or point vertices with a colour each.
fn colored(gl: &Gl, pos: &[f32], col: &[f32]) -> Result<Drawable, String> {
    let vao = gl
        .create_vertex_array()
        .ok_or("WebGL could not create a vertex array")?;
    gl.bind_vertex_array(Some(&vao));
    let buffers = vec![attrib(gl, 0, pos)?, attrib(gl, 1, col)?];
    gl.bind_vertex_array(None);
    Ok(Drawable {
        vao,
        buffers,
        count: (pos.len() / 3) as i32,
    })
}

/// Segments around the nozzle's cylinder.
const NOZZLE_SEGMENTS: usize = 24;

/// A cylinder of radius 1 from z = 0 to z = 1, closed at both ends, as
/// plain triangles (positions only).
fn unit_cylinder() -> Vec<f32> {
    let ring = |k: usize| {
        let a = std::f32::consts::TAU * k as f32 / NOZZLE_SEGMENTS as f32;
        (a.cos(), a.sin())
    };
    let mut pos = Vec::with_capacity(NOZZLE_SEGMENTS * 36);
    for k in 0..NOZZLE_SEGMENTS {
        let (c0, s0) = ring(k);
        let (c1, s1) = ring(k + 1);
        pos.extend([c0, s0, 0.0, c1, s1, 0.0, c1, s1, 1.0]);
        pos.extend([c0, s0, 0.0, c1, s1, 1.0, c0, s0, 1.0]);
        pos.extend([0.0, 0.0, 1.0, c0, s0, 1.0, c1, s1, 1.0]);
        pos.extend([0.0, 0.0, 0.0, c1, s1, 0.0, c0, s0, 0.0]);
    }
    pos
}

/// An orbit camera around a target, +Z up (the printer's).
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub target: DVec3,
    pub distance: f64,
    /// Azimuth about +Z and elevation above the XY plane, radians.
    pub yaw: f64,
    pub pitch: f64,
    /// Radius of the scene's bounding sphere (near/far planes, pan speed).
    pub radius: f64,
    pub aspect: f64,
    pub height_px: f64,
}

/// Vertical field of view: 40 degrees.
const FOV: f64 = 0.698;
/// Elevation stops short of the poles, where look-at has no "up".
const MAX_PITCH: f64 = 1.5690;

impl Camera {
    fn framing(lo: DVec3, hi: DVec3, aspect: f64, height_px: f64) -> Camera {
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        let fit = radius / (0.5 * FOV).sin() / aspect.min(1.0);
        Camera {
            target: 0.5 * (lo + hi),
            distance: 1.05 * fit,
            yaw: -1.9,
            pitch: 0.6,
            radius,
            aspect,
            height_px,
        }
    }

    fn eye(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * DVec3::new(cp * cy, cp * sy, sp)
    }

    fn view_proj(&self) -> DMat4 {
        let near = (self.distance - 2.0 * self.radius).max(self.distance * 1e-3);
        let far = self.distance + 2.0 * self.radius;
        glam::dcamera::rh::proj::opengl::perspective(FOV, self.aspect, near, far)
            * glam::dcamera::rh::view::look_at_mat4(self.eye(), self.target, DVec3::Z)
    }

    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * 0.008;
        self.pitch = (self.pitch + dy * 0.008).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target so the scene follows the pointer.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let per_px = 2.0 * self.distance * (0.5 * FOV).tan() / self.height_px.max(1.0);
        let f = (self.target - self.eye()).normalize();
        let right = f.cross(DVec3::Z).normalize_or_zero();
        let up = right.cross(f);
        self.target += (-dx * right + dy * up) * per_px;
    }

    pub fn zoom(&mut self, delta: f64) {
        let k = (delta * 0.0015).clamp(-1.0, 1.0).exp();
        self.distance = (self.distance * k).clamp(self.radius * 0.02, self.radius * 50.0);
    }

    /// The ray through the pixel (x, y) of a `width` x `height` drawing
    /// buffer (device pixels from the top-left corner): its origin on the
    /// near plane and its unit direction, in the frame the mesh is drawn in.
    /// `None` when the camera matrix cannot be inverted.
    pub fn ray(&self, x_px: f64, y_px: f64, width: f64, height: f64) -> Option<(DVec3, DVec3)> {
        let ndc_x = 2.0 * x_px / width.max(1.0) - 1.0;
        let ndc_y = 1.0 - 2.0 * y_px / height.max(1.0);
        let inv = self.view_proj().inverse();
        let near = inv.project_point3(DVec3::new(ndc_x, ndc_y, -1.0));
        let far = inv.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
        let dir = (far - near).normalize_or_zero();
        (near.is_finite() && dir != DVec3::ZERO).then_some((near, dir))
    }

    pub fn top(&mut self) {
        self.yaw = -std::f64::consts::FRAC_PI_2;
        self.pitch = MAX_PITCH;
    }

    /// The drawing-buffer pixel (from the top-left) where `p` is drawn, or
    /// `None` when it lies behind the camera.
    pub fn project(&self, p: DVec3, width: f64, height: f64) -> Option<(f64, f64)> {
        let clip = self.view_proj() * p.extend(1.0);
        if clip.w <= 0.0 || !clip.is_finite() {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(((ndc.x + 1.0) * 0.5 * width, (1.0 - ndc.y) * 0.5 * height))
    }

    /// The angle one pixel of the drawing buffer spans at its centre.
    pub fn pixel_angle(&self) -> f64 {
        FOV / self.height_px.max(1.0)
    }
}

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
        for (k, piece) in paths.toolpath.iter().enumerate() {
            let defects = paths.defects.get(k);
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
        self.set_lines(&pos, &col)
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
        self.set_lines(&pos, &col)
    }

    /// A G-code program's straight moves in place of the paths: `moves`
    /// holds xyz from and to per move (6 floats), `kinds` one code per
    /// move (0 feed, 1 rapid, 2 too close to the surface).
    pub fn set_moves(&mut self, moves: &[f32], kinds: &[u8]) -> Result<(), String> {
        if moves.len() != 6 * kinds.len() {
            return Err(format!(
                "move arrays disagree: {} coordinates for {} moves",
                moves.len(),
                kinds.len()
            ));
        }
        let mut col: Vec<f32> = Vec::with_capacity(moves.len());
        for &k in kinds {
            let c = match k {
                0 => FEED_MOVE,
                1 => RAPID_MOVE,
                _ => defect_rgb(Defect::Contact),
            };
            col.extend(c);
            col.extend(c);
        }
        self.set_lines(moves, &col)
    }

    /// A program's moves for the print preview, in place of the paths:
    /// `moves` holds xyz from and to per move (6 floats), `codes` one
    /// colour code per move ([`preview_rgb8`]). Uploaded once per program
    /// and colouring; the nozzle moves without touching it.
    pub fn set_preview_path(&mut self, moves: &[f32], codes: &[u8]) -> Result<(), String> {
        if moves.len() != 6 * codes.len() {
            return Err(format!(
                "preview arrays disagree: {} coordinates for {} moves",
                moves.len(),
                codes.len()
            ));
        }
        let mut col: Vec<f32> = Vec::with_capacity(moves.len());
        for &k in codes {
            let c = preview_rgb8(k).map(|c| f32::from(c) / 255.0);
            col.extend(c);
            col.extend(c);
        }
        self.set_lines(moves, &col)
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
        gl.use_program(Some(&p.program));
        gl.uniform_matrix4fv_with_f32_array(p.mvp.as_ref(), false, mvp);
        let eye = self.camera.eye() - self.camera.target;
        let l = (eye.normalize_or_zero() + 0.3 * DVec3::Z).normalize_or_zero();
        gl.uniform3f(p.light.as_ref(), l.x as f32, l.y as f32, l.z as f32);
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

    fn set_lines(&mut self, pos: &[f32], col: &[f32]) -> Result<(), String> {
        if let Some(d) = self.lines.take() {
            d.delete(&self.gl);
        }
        self.path_offset = DVec3::ZERO;
        if !pos.is_empty() {
            self.lines = Some(colored(&self.gl, pos, col)?);
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

    /// Draws the mesh with the camera's `mvp` into the bound framebuffer.
    fn draw_mesh(&self, mesh: &Drawable, mvp: &[f32; 16]) {
        let gl = &self.gl;
        let p = &self.mesh_prog;
        gl.use_program(Some(&p.program));
        gl.uniform_matrix4fv_with_f32_array(p.mvp.as_ref(), false, mvp);
        // A headlight, a little above and left of the eye, so faces
        // turned to the viewer are lit from any orbit angle.
        let eye = self.camera.eye() - self.camera.target;
        let l = (eye.normalize_or_zero() + 0.3 * DVec3::Z).normalize_or_zero();
        gl.uniform3f(p.light.as_ref(), l.x as f32, l.y as f32, l.z as f32);
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
        gl.bind_vertex_array(None);
    }
}
