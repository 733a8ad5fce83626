//! # pcpp: point-cloud-based conformal tool-path planning
//!
//! Plans the tool path of a microextrusion nozzle on a 3-axis stage that
//! prints a flat drawn path (an SVG antenna, say) onto a scanned, non-flat
//! substrate, following the PCPP method (`pcpp-spec.md` in the shared folder,
//! after the paper's Algorithms 1-5).
//!
//! ## Features
//! - Scan import from bytes: OBJ, PLY (ascii and binary), STL (ascii and
//!   binary), glTF 2.0 (`.gltf` with embedded buffers or buffers in `.bin`
//!   files given as bytes by name, `.glb`), in mm, cm, m or inches
//!   ([`mesh`]).
//! - Fiducial holes found as boundary loops ([`fiducials`]) and rigid
//!   registration scanner -> printer, the paper's three-point construction or
//!   a least-squares fit ([`registration`]).
//! - SVG paths through `usvg`: every shape, transforms, `use`, physical units
//!   ([`svg`]); sampling at two points per nozzle diameter ([`sampling`]).
//! - Projection along -Z onto the highest surface ([`projection`]), cubic
//!   interpolating B-spline and local geometry ([`spline`]).
//! - Four planners side by side ([`planners`]) and the predicted print
//!   quality ([`quality`]) and path statistics ([`stats`]).
//! - Built-in demo inputs: the paper's test part and antenna generators
//!   ([`demo`]).
//!
//! ## Limitations
//! - A 3-axis stage only: the nozzle stays vertical, paths are projected along Z.
//! - The core takes bytes and never opens other files: a `.gltf`'s `.bin`
//!   buffers are handed over by the caller ([`mesh::ExternalFiles`]; the CLI
//!   reads them beside the `.gltf`, the page takes them from the files
//!   selected with it); remote and absolute buffer URIs are refused, and
//!   Draco- or meshopt-compressed meshes are not decoded.
//! - SVG text is not converted to paths (no fonts are loaded).
//!
//! The core takes bytes and `&str`, never file paths, and knows nothing of
//! the DOM; `src/wasm.rs` and `src/bin/pcpp/` are thin adapters over it.

pub mod demo;
mod error;
pub mod fiducials;
pub mod gcode;
pub mod job;
pub mod mesh;
pub mod motion;
mod parallel;
pub mod params;
pub mod pipeline;
pub mod placement;
pub mod planners;
pub mod preview;
pub mod projection;
pub mod quality;
pub mod registration;
#[cfg(target_arch = "wasm32")]
pub mod render;
pub mod sampling;
pub mod spacing;
pub mod spline;
pub mod stats;
pub mod surface;
pub mod svg;
#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use error::{Error, Result};
pub use glam::{DMat4, DVec2, DVec3};
pub use params::{Nozzle, Process};
