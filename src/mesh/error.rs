//! Errors of scan import. Every variant names the file and, where there is
//! one, the line, element or index at fault.

/// A scan that cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("{file}: not a mesh this program reads (expected OBJ, PLY, STL, glTF or GLB)")]
    UnknownFormat { file: String },
    /// Text formats: a line that cannot be parsed.
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    /// Binary or structural problems (truncation, bad header, wrong counts).
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("{file}: the mesh has no triangles")]
    Empty { file: String },
}
