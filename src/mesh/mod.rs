//! Scan import: OBJ, PLY, STL and glTF/GLB meshes, and raw point clouds
//! (XYZ/CSV text, vertex-only PLY, PCD) meshed as a height field, bytes
//! into one [`TriMesh`] in millimetres, printer convention +Z up (spec
//! "Inputs").
//!
//! Each format has its own parser file that reads the file's own units and
//! axes; [`import_mesh`] sniffs the format, validates (finite coordinates,
//! indices in range), drops degenerate triangles with a warning, and applies
//! the scan units and up axis. A `.gltf` whose buffers are separate files
//! names them ([`external_files_needed`]); the caller hands them over as
//! bytes by name ([`ExternalFiles`], [`import_mesh_with`]).

use std::{fmt, str::FromStr};

use glam::{DMat4, DVec3};
use serde::{Deserialize, Serialize};

pub(crate) mod buckets;
mod cloud;
mod error;
mod external;
mod gltf;
mod import;
mod meshopt;
mod obj;
mod pcd;
mod ply;
mod stl;
pub(crate) mod topology;
mod upright;
mod xyz;

pub use cloud::{triangulate, CloudInfo, EDGE_LIMIT_PER_SPACING};
pub use error::MeshError;
pub use external::{ExternalFiles, ExternalRef};
pub use import::{
    detect_format, external_files_needed, import_mesh, import_mesh_unwelded, import_mesh_with,
    StrayVertices, UnitsDoubt, Unwelded, WeldMap, LARGE_SCAN_MM, SMALL_SCAN_MM,
};
pub(crate) use import::{is_dxf, other_file_kind};
pub use topology::{Topology, MAX_TOPOLOGY_TRIANGLES};

/// Largest scan file read (bytes). A 20 M triangle binary STL is 1 GB; a
/// browser tab cannot hold much more than this plus its mesh in wasm memory.
pub const MAX_SCAN_BYTES: usize = 1 << 30;
/// Most triangles kept after import: ~1 GB of mesh and index at this count.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// An indexed triangle mesh, f64 millimetres once imported.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    pub vertices: Vec<DVec3>,
    /// Counter-clockwise vertex indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Axis-aligned bounds of the vertices used by triangles, `None` when empty.
    pub fn bbox(&self) -> Option<(DVec3, DVec3)> {
        let mut it = self.triangles.iter().flatten();
        let first = self.vertices[*it.next()? as usize];
        let (mut lo, mut hi) = (first, first);
        for &i in it {
            let v = self.vertices[i as usize];
            lo = lo.min(v);
            hi = hi.max(v);
        }
        Some((lo, hi))
    }

    /// A height field z = f(x, y) over the grid `xs` x `ys` (row by row, y
    /// outer), two counter-clockwise triangles a cell: test surfaces and the
    /// generated workloads.
    pub fn height_field(xs: &[f64], ys: &[f64], mut f: impl FnMut(f64, f64) -> f64) -> TriMesh {
        let mut m = TriMesh {
            vertices: Vec::with_capacity(xs.len() * ys.len()),
            triangles: Vec::with_capacity(
                2 * xs.len().saturating_sub(1) * ys.len().saturating_sub(1),
            ),
        };
        for &y in ys {
            for &x in xs {
                m.vertices.push(DVec3::new(x, y, f(x, y)));
            }
        }
        let w = xs.len() as u32;
        for j in 0..(ys.len() as u32).saturating_sub(1) {
            for i in 0..w.saturating_sub(1) {
                let a = j * w + i;
                m.triangles.push([a, a + 1, a + w + 1]);
                m.triangles.push([a, a + w + 1, a + w]);
            }
        }
        m
    }

    /// Applies an affine transform to every vertex.
    pub fn transform(&mut self, m: &DMat4) {
        for v in &mut self.vertices {
            *v = m.transform_point3(*v);
        }
    }
}

/// Length unit of a scan file's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScanUnits {
    Mm,
    Cm,
    M,
    In,
    /// The international foot, 304.8 mm (a survey scanner's US survey foot
    /// differs by 2 parts in a million).
    Ft,
}

impl ScanUnits {
    /// The units in words, as a sentence names them ("in inches", where
    /// "in in" would not read).
    pub fn words(self) -> &'static str {
        match self {
            ScanUnits::Mm => "millimetres",
            ScanUnits::Cm => "centimetres",
            ScanUnits::M => "metres",
            ScanUnits::In => "inches",
            ScanUnits::Ft => "feet",
        }
    }

    pub fn to_mm(self) -> f64 {
        match self {
            ScanUnits::Mm => 1.0,
            ScanUnits::Cm => 10.0,
            ScanUnits::M => 1000.0,
            ScanUnits::In => 25.4,
            ScanUnits::Ft => 304.8,
        }
    }
}

impl FromStr for ScanUnits {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" => Ok(ScanUnits::Mm),
            "cm" => Ok(ScanUnits::Cm),
            "m" => Ok(ScanUnits::M),
            "in" | "inch" | "inches" => Ok(ScanUnits::In),
            "ft" | "foot" | "feet" => Ok(ScanUnits::Ft),
            other => Err(format!(
                "unknown scan units '{other}' (expected mm, cm, m, in or ft)"
            )),
        }
    }
}

impl fmt::Display for ScanUnits {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ScanUnits::Mm => "mm",
            ScanUnits::Cm => "cm",
            ScanUnits::M => "m",
            ScanUnits::In => "in",
            ScanUnits::Ft => "ft",
        })
    }
}

/// Which axis of the scan file points up (becomes the printer's +Z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    Z,
    /// +Y up (glTF's convention): turned +90 deg about X, (x, y, z) -> (x, -z, y).
    Y,
    /// -Z up: a depth camera's or a scanner's own frame, z the distance
    /// from the camera looking down, so the part's top has the smallest z
    /// (RealSense, Kinect, many structured-light scanners). Turned half a
    /// turn about X, (x, y, z) -> (x, -y, -z).
    #[serde(rename = "-z")]
    NegZ,
}

impl FromStr for UpAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "z" | "+z" => Ok(UpAxis::Z),
            "y" | "+y" => Ok(UpAxis::Y),
            "-z" => Ok(UpAxis::NegZ),
            other => Err(format!("unknown up axis '{other}' (expected z, y or -z)")),
        }
    }
}

impl fmt::Display for UpAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            UpAxis::Z => "+Z",
            UpAxis::Y => "+Y",
            UpAxis::NegZ => "-Z",
        })
    }
}

/// The file formats [`import_mesh`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MeshFormat {
    Obj,
    Ply,
    Stl,
    Gltf,
    Glb,
    /// A text point cloud: XYZ, CSV, TXT, ASC, PTS.
    Xyz,
    /// The Point Cloud Library's PCD.
    Pcd,
}

impl MeshFormat {
    /// glTF is metres and +Y up by its specification; the others carry no
    /// convention and default to mm, +Z up (spec "Inputs").
    pub fn default_units(self) -> ScanUnits {
        match self {
            MeshFormat::Gltf | MeshFormat::Glb => ScanUnits::M,
            _ => ScanUnits::Mm,
        }
    }

    pub fn default_up_axis(self) -> UpAxis {
        match self {
            MeshFormat::Gltf | MeshFormat::Glb => UpAxis::Y,
            _ => UpAxis::Z,
        }
    }
}

/// Options of [`import_mesh`]; `None` means the format's default.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ImportOptions {
    pub units: Option<ScanUnits>,
    pub up_axis: Option<UpAxis>,
    /// Point clouds: the longest edge (in XY, mm after units) a triangle
    /// of the meshed cloud may have; `None`: [`EDGE_LIMIT_PER_SPACING`]
    /// times the median point spacing.
    #[serde(default)]
    pub max_edge_mm: Option<f64>,
}

impl ImportOptions {
    pub const DEFAULT: ImportOptions = ImportOptions {
        units: None,
        up_axis: None,
        max_edge_mm: None,
    };
}

/// A scan read into millimetres, +Z up, with what was noticed on the way.
#[derive(Debug, Clone)]
pub struct ImportedMesh {
    pub mesh: TriMesh,
    pub format: MeshFormat,
    pub units: ScanUnits,
    pub up_axis: UpAxis,
    /// Recoverable oddities (degenerate triangles skipped, ...), for the report.
    pub warnings: Vec<String>,
    /// For a point cloud, how it was meshed.
    pub cloud: Option<CloudInfo>,
    /// Set when the scan is so small in the units it was read in that
    /// they are likely wrong (its warning is among `warnings`).
    pub units_doubt: Option<UnitsDoubt>,
    /// The external files the scan was read from besides its own bytes (a
    /// `.gltf`'s buffers), by the relative paths it names them with, each
    /// once.
    pub external_files: Vec<String>,
}

impl ImportedMesh {
    /// The extent of the scanned part: the mesh's bounds, reaching down to
    /// the points of a cloud left out under others (the part rests on its
    /// lowest point, meshed or not). `None` when empty.
    pub fn extent(&self) -> Option<(DVec3, DVec3)> {
        let (mut lo, hi) = self.mesh.bbox()?;
        if let Some(floor) = self.cloud.and_then(|c| c.lowest_left_out_mm) {
            lo.z = lo.z.min(floor);
        }
        Some((lo, hi))
    }
}
