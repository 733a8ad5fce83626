//! SVG drawn paths through usvg (spec "Inputs", T2D). Placeholder: the SVG
//! helper replaces this file, keeping these public names.
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// One continuous drawn stroke, flattened finely, in mm with y up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Subpath2 {
    pub points: Vec<DVec2>,
    /// `corner[i]`: the drawn tangent is discontinuous at `points[i]`.
    pub corner: Vec<bool>,
    pub closed: bool,
    /// Where it came from, for messages (element id or index).
    pub source: String,
}

/// Where the drawing goes in printer XY (mm): rotated by `rotation_deg` and
/// scaled uniformly about the SVG origin, then moved by `offset_mm`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    pub offset_mm: DVec2,
    pub rotation_deg: f64,
    pub scale: f64,
}

impl Placement {
    pub const IDENTITY: Placement = Placement {
        offset_mm: DVec2::ZERO,
        rotation_deg: 0.0,
        scale: 1.0,
    };
}

impl Default for Placement {
    fn default() -> Self {
        Self::IDENTITY
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SvgError {
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
}

pub fn import_svg(_text: &[u8], file: &str) -> Result<Vec<Subpath2>, SvgError> {
    Err(SvgError::Parse {
        file: file.into(),
        message: "not yet".into(),
    })
}
