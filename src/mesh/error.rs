//! Errors of scan import. Every variant names the file and, where there is
//! one, the line, element or index at fault.

/// U+FFFD in UTF-8 (EF BF BD): what a text-mode copy (an editor, a
/// paste, a tool reading the file as UTF-8) writes for each byte of a
/// binary file it cannot decode.
const REPLACEMENT: [u8; 3] = [0xEF, 0xBF, 0xBD];

/// A binary file (`what`: "binary STL", "GLB") whose bytes hold U+FFFD far
/// more often than chance would put it there (about once in 16 M bytes):
/// damaged by a text-mode copy (QA round 17 F10: an STL read as 4 garbage
/// triangles 1e29 mm across and asked for its units; QA round 18 F8: a
/// GLB twice its size called "truncated"). `None` for a sound file.
pub(super) fn text_mode_damage(bytes: &[u8], file: &str, what: &str) -> Option<MeshError> {
    let found = bytes.windows(3).filter(|w| *w == REPLACEMENT).count();
    // Three or more, and one in 1000 bytes: chance gives neither.
    (found >= 3 && found * 1000 >= bytes.len()).then(|| {
        MeshError::invalid(
            file,
            format!(
                "the {what} looks damaged by a text-mode copy: {found} of its byte runs are \
                 U+FFFD, the replacement character written for bytes a text tool could not \
                 read; copy or download it again as a binary file (or export it again)"
            ),
        )
    })
}

/// `bytes` as a text-mode copy leaves them: each byte from 0x80 up written
/// as U+FFFD, as a UTF-8 round trip does.
#[cfg(test)]
pub(super) fn text_mode_copy(bytes: &[u8]) -> Vec<u8> {
    bytes
        .iter()
        .flat_map(|&b| {
            if b >= 0x80 {
                REPLACEMENT.to_vec()
            } else {
                vec![b]
            }
        })
        .collect()
}

/// A scan that cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("{file}: not a scan this program reads (expected a mesh: OBJ, PLY, STL, glTF, GLB; or a point cloud: XYZ/CSV/TXT, PLY, PCD){hint}")]
    UnknownFormat {
        file: String,
        /// How to convert a format known by its extension, after "; ", or
        /// nothing.
        hint: String,
    },
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
    /// A vertex coordinate is NaN or infinite; fix or remove that vertex in
    /// the scanning software (lyon's `PositionIsNaN`: never plan on it).
    #[error(
        "{file}{}: vertex {vertex} has a non-finite coordinate ({value})",
        line_suffix(*.line)
    )]
    NonFiniteVertex {
        file: String,
        /// The vertex as the file numbers it (1-based for OBJ, else 0-based).
        vertex: usize,
        line: Option<usize>,
        value: f64,
    },
    /// A face or a strip record refers to a vertex that does not exist.
    #[error(
        "{file}{}: {} refers to vertex index {index}, but only {vertex_count} vertices are defined",
        line_suffix(*.line),
        record_name(element, *.record)
    )]
    IndexOutOfRange {
        file: String,
        /// The element the record belongs to: `face`, or a PLY's
        /// `tristrips` (one record holds many strips).
        element: &'static str,
        /// The record as the file numbers it (0-based; OBJ names its line
        /// instead): a face, or a strip record.
        record: usize,
        line: Option<usize>,
        index: i64,
        vertex_count: usize,
    },
    /// A glTF buffer stored in a separate file (`"uri": "scene.bin"`) that
    /// was not given with the scan: the CLI reads it from the `.gltf`'s
    /// folder, the page needs both files selected together.
    #[error(
        "{file}: buffer {buffer} is stored in the external file '{path}', which was not given: \
         keep it {} (command line) or select both files together (page), or export the scan \
         as one .glb",
        beside(file)
    )]
    MissingExternalFile {
        file: String,
        buffer: usize,
        /// The reference as written (percent-encoded).
        uri: String,
        /// The file it names, decoded and relative to the `.gltf`.
        path: String,
    },
    /// A glTF buffer's URI that is not a path relative to the `.gltf`
    /// (remote, `file:`, absolute, a drive letter, a bad escape): only
    /// files given beside the scan are read.
    #[error(
        "{file}: buffer {buffer} refers to '{uri}', {reason}; only files named relative to the \
         .gltf's folder are read (a relative reference such as \"scene.bin\" or \
         \"../buffers/scene.bin\"): re-export the scan with its buffers beside it, or as one \
         .glb"
    )]
    ExternalUri {
        file: String,
        buffer: usize,
        uri: String,
        /// Why it is refused ("a remote URI", ...).
        reason: String,
    },
    /// A glTF that could not be read after one of its buffers was read
    /// from a file that may not be its own: one outside the `.gltf`'s
    /// folder, or longer than the buffer's byteLength. The refusal names
    /// that file (QA round 20 F5: bytes of `../../../../etc/passwd` were
    /// refused as a damaged POSITION accessor, and the file they came
    /// from was named only in a warning that a failed import never shows).
    #[error("{error}; {doubt}")]
    DoubtfulBuffer {
        /// The failure, as it would be said of any file.
        error: Box<MeshError>,
        /// Which buffer was read from which file, and why it is doubted.
        doubt: String,
    },
}

fn line_suffix(line: Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

impl MeshError {
    pub(crate) fn invalid(file: &str, message: impl Into<String>) -> Self {
        MeshError::Invalid {
            file: file.into(),
            message: message.into(),
        }
    }

    pub(crate) fn syntax(file: &str, line: usize, message: impl Into<String>) -> Self {
        MeshError::Syntax {
            file: file.into(),
            line,
            message: message.into(),
        }
    }

    /// The error with `doubt` about the files the scan's buffers were read
    /// from ([`MeshError::DoubtfulBuffer`]), where there is one.
    pub(crate) fn with_doubt(self, doubt: Option<&str>) -> Self {
        match doubt {
            Some(doubt) => MeshError::DoubtfulBuffer {
                error: Box::new(self),
                doubt: doubt.into(),
            },
            None => self,
        }
    }

    /// The error with the line it names (if any) mapped by `to_file`: an
    /// error found in a rewritten text, named at the file's line.
    pub(crate) fn with_line_mapped(mut self, to_file: impl Fn(usize) -> usize) -> Self {
        match &mut self {
            MeshError::Syntax { line, .. } => *line = to_file(*line),
            MeshError::NonFiniteVertex { line, .. } | MeshError::IndexOutOfRange { line, .. } => {
                *line = line.map(&to_file);
            }
            _ => {}
        }
        self
    }
}

/// A record of a mesh's surface element as errors name it: "face 2", or
/// "'tristrips' element 2" (a strip record is no face).
fn record_name(element: &str, i: usize) -> String {
    if element == "face" {
        format!("face {i}")
    } else {
        format!("'{element}' element {i}")
    }
}

/// Where the CLI looks for a `.gltf`'s separate files: beside it, or in the
/// current folder for one read from standard input (a QA run was told to
/// keep the file "next to standard input").
fn beside(file: &str) -> String {
    if matches!(file, "standard input" | "stdin" | "-") {
        "in the current folder (a .gltf read from standard input finds its files there)".into()
    } else {
        format!("next to {file}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_file_and_line_when_known() {
        let e = MeshError::NonFiniteVertex {
            file: "a.obj".into(),
            vertex: 3,
            line: Some(7),
            value: f64::NAN,
        };
        assert_eq!(
            e.to_string(),
            "a.obj:7: vertex 3 has a non-finite coordinate (NaN)"
        );
        let e = MeshError::IndexOutOfRange {
            file: "a.ply".into(),
            element: "face",
            record: 2,
            line: None,
            index: 9,
            vertex_count: 4,
        };
        assert_eq!(
            e.to_string(),
            "a.ply: face 2 refers to vertex index 9, but only 4 vertices are defined"
        );
    }
}
