//! Format detection and the shared import steps (placeholder until the
//! importers land).
use super::{ImportOptions, ImportedMesh, MeshError, MeshFormat};

pub fn detect_format(_bytes: &[u8], _file: &str) -> Option<MeshFormat> {
    None
}

pub fn import_mesh(
    bytes: &[u8],
    file: &str,
    _options: &ImportOptions,
) -> Result<ImportedMesh, MeshError> {
    let _ = bytes;
    Err(MeshError::UnknownFormat { file: file.into() })
}
