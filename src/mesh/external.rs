//! Files a scan names besides itself: a `.gltf`'s buffers kept in separate
//! files (`"uri": "scene.bin"`, as Blender's "glTF Separate" export and
//! Sketchfab's downloads write them). The core opens no files: the CLI
//! reads them from the `.gltf`'s folder, the page from the files selected
//! with it, and both hand them over here as bytes, by name.

use std::fmt;

use serde::Serialize;

use super::MeshError;

/// The files given with a scan, as bytes by name: the name is the relative
/// path the scan refers to (`scene.bin`, `buffers/scene.bin`) or only its
/// last component (a browser gives file names without folders).
///
/// Each file's bytes are any owner (a `Vec<u8>`, the CLI's mapping of the
/// file), dropped with this value.
#[derive(Default)]
pub struct ExternalFiles {
    files: Vec<(String, Owner)>,
}

/// Any owner of a file's bytes.
type Owner = Box<dyn AsRef<[u8]> + Send + Sync>;

impl ExternalFiles {
    /// No files: what a scan that names none needs.
    pub fn new() -> Self {
        ExternalFiles::default()
    }

    /// Adds the file `name` with its bytes.
    pub fn add(
        &mut self,
        name: impl Into<String>,
        bytes: impl AsRef<[u8]> + Send + Sync + 'static,
    ) {
        self.files.push((name.into(), Box::new(bytes)));
    }

    /// [`ExternalFiles::add`] by value, for building in one expression.
    pub fn with(
        mut self,
        name: impl Into<String>,
        bytes: impl AsRef<[u8]> + Send + Sync + 'static,
    ) -> Self {
        self.add(name, bytes);
        self
    }

    /// The files as given, in order: (name, bytes).
    pub fn iter(&self) -> impl Iterator<Item = (&str, &[u8])> {
        self.files.iter().map(|(n, b)| (n.as_str(), (**b).as_ref()))
    }

    /// The index of the file a relative path names: the file given under
    /// that path, else the first whose last component is the path's.
    pub fn position(&self, path: &str) -> Option<usize> {
        let path = normalized(path);
        let last = last_component(&path);
        let names: Vec<String> = self.files.iter().map(|(n, _)| normalized(n)).collect();
        names
            .iter()
            .position(|n| *n == path)
            .or_else(|| names.iter().position(|n| last_component(n) == last))
    }

    /// The file a relative path names ([`ExternalFiles::position`]):
    /// (name as given, bytes).
    pub fn find(&self, path: &str) -> Option<(&str, &[u8])> {
        self.position(path).and_then(|i| self.iter().nth(i))
    }
}

impl fmt::Debug for ExternalFiles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries(self.iter().map(|(n, b)| (n, b.len())))
            .finish()
    }
}

/// A file a scan needs besides itself: glTF buffer `buffer`, whose `uri`
/// decodes to the relative `path`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ExternalRef {
    pub buffer: usize,
    /// As the file writes it (percent-encoded).
    pub uri: String,
    /// Decoded, relative to the scan's folder (`my scan.bin`).
    pub path: String,
}

impl ExternalRef {
    /// The last component of the path: the name of the file to select.
    pub fn file_name(&self) -> &str {
        last_component(&self.path)
    }
}

/// `./a/b.bin` and `a\b.bin` as `a/b.bin`.
fn normalized(path: &str) -> String {
    let path = path.replace('\\', "/");
    let mut rest = path.as_str();
    while let Some(r) = rest.strip_prefix("./") {
        rest = r;
    }
    rest.to_string()
}

fn last_component(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

/// The relative path glTF buffer `buffer` of `file` refers to with `uri`:
/// percent-decoded, and refused when it is not relative to the `.gltf`
/// (a remote or `file:` URI, an absolute path, a drive letter), since only
/// files given beside the scan are read.
pub(super) fn relative_path(uri: &str, file: &str, buffer: usize) -> Result<String, MeshError> {
    let refused = |reason: String| MeshError::ExternalUri {
        file: file.into(),
        buffer,
        uri: uri.into(),
        reason,
    };
    if let Some(reason) = not_relative(uri) {
        return Err(refused(reason));
    }
    let path = percent_decoded(uri).map_err(refused)?;
    // Checked again decoded: `%2Fetc` is an absolute path once decoded.
    if let Some(reason) = not_relative(&path) {
        return Err(refused(reason));
    }
    let path = normalized(&path);
    if path.is_empty() || path.ends_with('/') {
        return Err(refused("which names no file".into()));
    }
    Ok(path)
}

/// Why a reference is not a path relative to the scan, if it is not.
fn not_relative(uri: &str) -> Option<String> {
    if uri.starts_with('/') || uri.starts_with('\\') {
        return Some("an absolute path".into());
    }
    // RFC 3986: a scheme is a letter then letters, digits, `+`, `-`, `.`,
    // up to the first `:`; a relative reference has no `:` before its
    // first `/`.
    let (scheme, _) = uri.split_once(':')?;
    let is_scheme = scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    if !is_scheme {
        return None;
    }
    Some(match scheme.to_ascii_lowercase().as_str() {
        s if s.len() == 1 => "an absolute path with a drive letter".into(),
        "file" => "a file: URI (an absolute path)".into(),
        "http" | "https" | "ftp" => "a remote URI".into(),
        s => format!("a URI of the scheme '{s}:', not a relative path"),
    })
}

/// `uri` with its `%XX` escapes decoded (RFC 3986 2.1), as UTF-8.
fn percent_decoded(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("a bad percent-escape at character {}", i + 1))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "which decodes to no UTF-8 name".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_are_decoded() {
        assert_eq!(
            relative_path("my%20scan.bin", "s.gltf", 0).unwrap(),
            "my scan.bin"
        );
        assert_eq!(
            relative_path("./buffers/%C3%A9t%C3%A9.bin", "s.gltf", 0).unwrap(),
            "buffers/été.bin"
        );
        assert_eq!(
            relative_path("../up.bin", "s.gltf", 0).unwrap(),
            "../up.bin"
        );
    }

    #[test]
    fn references_outside_the_folder_are_refused_by_name() {
        for (uri, why) in [
            ("/etc/scan.bin", "absolute path"),
            ("\\\\server\\share\\scan.bin", "absolute path"),
            ("C:\\scans\\scan.bin", "drive letter"),
            ("c:/scans/scan.bin", "drive letter"),
            ("file:///home/scan.bin", "file: URI"),
            ("http://example.com/scan.bin", "remote URI"),
            ("HTTPS://example.com/scan.bin", "remote URI"),
            ("blob:abc", "scheme 'blob:'"),
            ("%2Fetc%2Fscan.bin", "absolute path"),
            ("scan%zz.bin", "bad percent-escape"),
            ("scan%ff.bin", "UTF-8"),
            ("", "names no file"),
            ("buffers/", "names no file"),
        ] {
            let e = relative_path(uri, "part.gltf", 2).unwrap_err().to_string();
            assert!(
                e.starts_with("part.gltf: buffer 2 ")
                    && e.contains(&format!("'{uri}'"))
                    && e.contains(why)
                    // `../up.bin` is read (above): not "beside" (QA round 18 F4).
                    && e.contains("only files named relative to the .gltf's folder are read"),
                "{uri}: {e}"
            );
        }
        // A colon after the first slash is part of a relative path.
        assert_eq!(
            relative_path("a/b:c.bin", "s.gltf", 0).unwrap(),
            "a/b:c.bin"
        );
    }

    /// Hostile references give a path or an error naming the URI, never a
    /// panic (a cut escape, a lone `%`, a cut UTF-8 sequence, odd schemes).
    #[test]
    fn hostile_uris_never_panic() {
        for uri in [
            "%", "%%", "%4", "a%", "%e2%82", "%00", ":", "a:", "1:/x", ".", "./", "..", "./.",
            "C:", "\\", "é%", "%C3", "ab%C3%", "\u{0}", "?", "#", "a/b/",
        ] {
            match relative_path(uri, "h.gltf", 7) {
                Ok(path) => assert!(!path.is_empty() && !path.starts_with('/'), "{uri}: {path}"),
                Err(e) => assert!(e.to_string().contains(&format!("'{uri}'")), "{uri}: {e}"),
            }
        }
    }

    #[test]
    fn files_match_by_path_then_by_file_name() {
        let files = ExternalFiles::new()
            .with("other/scan.bin", vec![1u8])
            .with("buffers/scan.bin", vec![2u8])
            .with("plain.bin", vec![3u8]);
        assert_eq!(files.find("buffers/scan.bin").unwrap().1, &[2]);
        assert_eq!(files.find("./buffers/scan.bin").unwrap().1, &[2]);
        // By its last component, the first given wins.
        assert_eq!(files.find("elsewhere/scan.bin").unwrap().1, &[1]);
        assert_eq!(
            files.find("sub/plain.bin").unwrap(),
            ("plain.bin", &[3u8][..])
        );
        assert_eq!(files.find("missing.bin"), None);
        assert_eq!(
            format!("{files:?}"),
            r#"{"other/scan.bin": 1, "buffers/scan.bin": 1, "plain.bin": 1}"#
        );
    }
}
