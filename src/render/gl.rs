//! WebGL2 plumbing of the 3-D view: shader sources, compile and link
//! (returning `Result`), programs with their uniforms, vertex arrays, the
//! cached mesh image and the nozzle's unit cylinder. Part of
//! [`crate::render`].

use web_sys::{
    WebGl2RenderingContext as Gl, WebGlBuffer, WebGlFramebuffer, WebGlProgram, WebGlShader,
    WebGlTexture, WebGlUniformLocation, WebGlVertexArrayObject,
};

pub(super) const MESH_VS: &str = r#"#version 300 es
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
pub(super) const MESH_FS: &str = r#"#version 300 es
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
pub(super) const NOZZLE_VS: &str = r#"#version 300 es
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
pub(super) const LINE_VS: &str = r#"#version 300 es
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

pub(super) const LINE_FS: &str = r#"#version 300 es
precision mediump float;
in vec3 v_color;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0); }
"#;

// Copies the cached mesh image (colour and depth) to the canvas: one
// triangle covering the viewport, texel for pixel, writing the mesh's depth
// so the paths drawn next are hidden behind the surface as before.
pub(super) const BLIT_VS: &str = r#"#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"#;

pub(super) const BLIT_FS: &str = r#"#version 300 es
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
pub(super) struct MeshCache {
    pub(super) framebuffer: WebGlFramebuffer,
    pub(super) color: WebGlTexture,
    pub(super) depth: WebGlTexture,
    pub(super) width: u32,
    pub(super) height: u32,
    /// The camera matrix the textures hold the mesh for; None: stale.
    pub(super) mvp: Option<[f32; 16]>,
}

impl MeshCache {
    pub(super) fn new(gl: &Gl, width: u32, height: u32) -> Result<MeshCache, String> {
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

    pub(super) fn delete(self, gl: &Gl) {
        gl.delete_framebuffer(Some(&self.framebuffer));
        gl.delete_texture(Some(&self.color));
        gl.delete_texture(Some(&self.depth));
    }
}

pub(super) fn compile(gl: &Gl, kind: u32, src: &str) -> Result<WebGlShader, String> {
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

pub(super) fn link(gl: &Gl, vs: &str, fs: &str) -> Result<WebGlProgram, String> {
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

pub(super) struct Program {
    pub(super) program: WebGlProgram,
    pub(super) mvp: Option<WebGlUniformLocation>,
    pub(super) light: Option<WebGlUniformLocation>,
    pub(super) color: Option<WebGlUniformLocation>,
    pub(super) point_size: Option<WebGlUniformLocation>,
    pub(super) offset: Option<WebGlUniformLocation>,
    pub(super) model: Option<WebGlUniformLocation>,
    pub(super) color_tex: Option<WebGlUniformLocation>,
    pub(super) depth_tex: Option<WebGlUniformLocation>,
}

impl Program {
    pub(super) fn new(gl: &Gl, vs: &str, fs: &str) -> Result<Program, String> {
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
pub(super) struct Drawable {
    pub(super) vao: WebGlVertexArrayObject,
    pub(super) buffers: Vec<WebGlBuffer>,
    pub(super) count: i32,
}

impl Drawable {
    pub(super) fn delete(self, gl: &Gl) {
        gl.delete_vertex_array(Some(&self.vao));
        for b in &self.buffers {
            gl.delete_buffer(Some(b));
        }
    }
}

pub(super) fn upload_f32(gl: &Gl, target: u32, data: &[f32]) -> Result<WebGlBuffer, String> {
    let b = gl
        .create_buffer()
        .ok_or("WebGL could not create a buffer")?;
    gl.bind_buffer(target, Some(&b));
    let view = js_sys::Float32Array::from(data);
    gl.buffer_data_with_array_buffer_view(target, &view, Gl::STATIC_DRAW);
    Ok(b)
}

pub(super) fn attrib(gl: &Gl, location: u32, data: &[f32]) -> Result<WebGlBuffer, String> {
    let b = upload_f32(gl, Gl::ARRAY_BUFFER, data)?;
    gl.enable_vertex_attrib_array(location);
    gl.vertex_attrib_pointer_with_i32(location, 3, Gl::FLOAT, false, 0, 0);
    Ok(b)
}

/// Line or point vertices with a colour each.
pub(super) fn colored(gl: &Gl, pos: &[f32], col: &[f32]) -> Result<Drawable, String> {
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
pub(super) const NOZZLE_SEGMENTS: usize = 24;

/// A cylinder of radius 1 from z = 0 to z = 1, closed at both ends, as
/// plain triangles (positions only).
pub(super) fn unit_cylinder() -> Vec<f32> {
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
