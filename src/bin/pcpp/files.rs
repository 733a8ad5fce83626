//! Files: reading inputs, naming them in messages, and writing outputs
//! through temporary files renamed only once everything succeeded, so a
//! failed run leaves no partial file behind.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use pcpp::mesh::{ExternalFiles, MeshError};

use crate::outputs::Outputs;
use crate::{CliResult, Failure};

/// The most the CLI reads of a drawing (the page reads up to 64 MiB).
pub const MAX_SVG_BYTES: usize = 256 << 20;
/// The most the CLI reads of a machine profile or a settings file.
pub const MAX_SETTINGS_BYTES: usize = 16 << 20;

/// Reads an input of at most `max` bytes: a larger one is refused once
/// `max` bytes are read, so a pipe or a device (`/dev/zero`, a stream
/// that never ends) cannot fill the memory first (QA round 19 F14).
pub fn read_bytes(path: &Path, what: &str, max: usize) -> CliResult<Vec<u8>> {
    if is_stdin(path) {
        return read_stdin(what, max);
    }
    let file = std::fs::File::open(path).map_err(|e| cannot_read(path, what, e))?;
    read_at_most(file, max, path, what)
}

fn read_at_most(
    reader: impl std::io::Read,
    max: usize,
    path: &Path,
    what: &str,
) -> CliResult<Vec<u8>> {
    use std::io::Read as _;
    let mut bytes = Vec::new();
    reader
        .take(max as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| {
            Failure::Input(format!(
                "cannot read {what} from {}: {e}",
                input_shown(path)
            ))
        })?;
    if bytes.len() > max {
        return Err(Failure::Input(format!(
            "{}: the {what} is more than {:.0} MB, the most pcpp reads of one (a file that \
             large, or a stream or device that does not end?)",
            input_shown(path),
            max as f64 / 1e6
        )));
    }
    Ok(bytes)
}

/// An input as messages name it: its path, or "standard input" for `-`.
pub fn input_shown(path: &Path) -> String {
    if is_stdin(path) {
        "standard input".into()
    } else {
        path.display().to_string()
    }
}

/// Whether `path` (an input) is `-`, standard input (and an output `-`,
/// standard output: [`is_stdout`]).
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

fn read_stdin(what: &str, max: usize) -> CliResult<Vec<u8>> {
    read_at_most(std::io::stdin().lock(), max, Path::new("-"), what)
}

fn cannot_read(path: &Path, what: &str, e: std::io::Error) -> Failure {
    Failure::Input(format!("cannot read {what} {}: {e}", path.display()))
}

/// A scan's bytes: the file mapped into memory where that works (a regular,
/// non-empty file on Linux), else read into memory.
///
/// A 50 MB scan takes about 18 ms to read (the kernel clears fresh pages
/// and copies the page cache into them) and 4 ms to map with its pages
/// populated, on the path every later stage waits for (issue 15). The
/// mapping is private and read-only, and is dropped once the scan is
/// imported. As with ripgrep's maps, a program that truncates the file
/// while it is being read ends this one (SIGBUS); one that rewrites it in
/// place may have part of the new bytes read.
pub enum ScanBytes {
    Read(Vec<u8>),
    #[cfg(target_os = "linux")]
    Mapped(mapped::Mapped),
}

impl AsRef<[u8]> for ScanBytes {
    fn as_ref(&self) -> &[u8] {
        match self {
            ScanBytes::Read(v) => v,
            #[cfg(target_os = "linux")]
            ScanBytes::Mapped(m) => m.bytes(),
        }
    }
}

/// Maps `path` where it can, else reads it ([`ScanBytes`]): the file is
/// opened once either way.
pub fn read_scan(path: &Path, what: &str) -> CliResult<ScanBytes> {
    // A byte more than the importer takes, so that it names the size.
    let max = pcpp::mesh::MAX_SCAN_BYTES + 1;
    if is_stdin(path) {
        return read_stdin(what, max).map(ScanBytes::Read);
    }
    let file = std::fs::File::open(path).map_err(|e| cannot_read(path, what, e))?;
    #[cfg(target_os = "linux")]
    if let Some(m) = mapped::Mapped::of(&file) {
        return Ok(ScanBytes::Mapped(m));
    }
    read_at_most(file, max, path, what).map(ScanBytes::Read)
}

/// The external files a scan names that are not in its folder: (the path
/// the scan names, where it was looked for).
pub struct Missing(Vec<(String, PathBuf)>);

impl Missing {
    /// The library's message for `e`, with where a missing external file
    /// was looked for.
    pub fn explain(&self, message: String, e: &pcpp::Error) -> String {
        let pcpp::Error::Mesh(MeshError::MissingExternalFile { path, .. }) = e else {
            return message;
        };
        match self.0.iter().find(|(p, _)| p == path) {
            Some((_, looked)) => format!("{message} (not found: {})", looked.display()),
            None => message,
        }
    }
}

/// Reads the external files the scan at `scan_path` (its bytes `bytes`,
/// `name` in the library's messages) names ([`pcpp::mesh::external_files_needed`],
/// a `.gltf`'s `.bin` buffers), relative to its folder. One that is not
/// there is left out, in [`Missing`]: the import then names it, unless it
/// stops first for a reason of its own (a compressed mesh). One that is
/// also an output of the command is refused before it is read.
pub fn read_external(
    scan_path: &Path,
    name: &str,
    bytes: &[u8],
    outputs: &Outputs,
) -> CliResult<(ExternalFiles, Missing)> {
    let needed = pcpp::mesh::external_files_needed(bytes, name)
        .map_err(|e| Failure::Input(in_file(scan_path, name, &e.to_string())))?;
    let dir = match scan_path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut files = ExternalFiles::new();
    let mut missing = Vec::new();
    let mut seen: Vec<&str> = Vec::new();
    for r in &needed {
        if seen.contains(&r.path.as_str()) {
            continue;
        }
        seen.push(&r.path);
        let path = dir.join(&r.path);
        outputs.refuse_read(&path, || {
            format!(
                "{} (buffer {} of --scan {})",
                path.display(),
                r.buffer,
                scan_path.display()
            )
        })?;
        match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                missing.push((r.path.clone(), path));
            }
            _ => {
                let bytes = read_scan(&path, "external file").map_err(|f| match f {
                    Failure::Input(m) => Failure::Input(format!(
                        "{m} (buffer {} of {})",
                        r.buffer,
                        scan_path.display()
                    )),
                    other => other,
                })?;
                files.add(r.path.clone(), bytes);
            }
        }
    }
    Ok((files, Missing(missing)))
}

#[cfg(target_os = "linux")]
mod mapped {
    use std::fs::File;
    use std::os::fd::AsRawFd as _;

    /// A private, read-only mapping of a whole regular file.
    pub struct Mapped {
        ptr: *mut libc::c_void,
        len: usize,
    }

    // SAFETY: the mapping is read-only and owned by this value alone;
    // reading it from several threads is reading shared immutable memory.
    unsafe impl Send for Mapped {}
    unsafe impl Sync for Mapped {}

    impl Mapped {
        /// The mapping of `file`, or `None` where it cannot be mapped (not
        /// a regular file, empty, or the kernel refused): the caller reads
        /// it instead.
        pub fn of(file: &File) -> Option<Mapped> {
            let meta = file.metadata().ok()?;
            let len = usize::try_from(meta.len()).ok()?;
            if !meta.is_file() || len == 0 {
                return None;
            }
            // SAFETY: a fresh mapping chosen by the kernel (no fixed
            // address), of a file descriptor that is open for reading; the
            // result is checked against MAP_FAILED. The mapping outlives
            // the descriptor, as mmap(2) allows.
            let ptr = unsafe {
                libc::mmap(
                    std::ptr::null_mut(),
                    len,
                    libc::PROT_READ,
                    libc::MAP_PRIVATE | libc::MAP_POPULATE,
                    file.as_raw_fd(),
                    0,
                )
            };
            (ptr != libc::MAP_FAILED).then_some(Mapped { ptr, len })
        }

        pub fn bytes(&self) -> &[u8] {
            // SAFETY: `ptr` maps `len` readable bytes until `self` drops.
            unsafe { std::slice::from_raw_parts(self.ptr as *const u8, self.len) }
        }
    }

    impl Drop for Mapped {
        fn drop(&mut self) {
            // SAFETY: the mapping made in `of`, unmapped once; no slice of
            // it outlives `self` (`bytes` borrows it).
            unsafe {
                libc::munmap(self.ptr, self.len);
            }
        }
    }
}

pub fn read_text(path: &Path, what: &str, max: usize) -> CliResult<String> {
    let bytes = read_bytes(path, what, max)?;
    String::from_utf8(bytes).map_err(|e| {
        Failure::Input(format!(
            "{}, {}: the {what} is not UTF-8 text",
            path.display(),
            not_utf8_at(e.as_bytes(), e.utf8_error().valid_up_to())
        ))
    })
}

/// Where the first byte that is not UTF-8 is: "line L, column C (byte
/// 0xE9)", columns in characters.
fn not_utf8_at(bytes: &[u8], at: usize) -> String {
    let before = &bytes[..at];
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    // Valid UTF-8 up to `at`, so this counts characters.
    let column = std::str::from_utf8(&before[line_start..]).map_or(0, |t| t.chars().count()) + 1;
    format!("line {line}, column {column} (byte 0x{:02X})", bytes[at])
}

/// A G-code program as text: bytes that are not UTF-8 (a Latin-1 `é` or
/// `°` in a comment, written by older Windows tools) are read as U+FFFD,
/// with a warning naming the first; outside a comment the reader then
/// names their line as not G-code. (The whole file was refused.)
pub fn read_gcode_text(path: &Path) -> CliResult<(String, Option<String>)> {
    // A byte more than the reader takes, so that it names the size.
    let bytes = read_bytes(path, "G-code", pcpp::gcode::MAX_GCODE_BYTES + 1)?;
    match String::from_utf8(bytes) {
        Ok(text) => Ok((text, None)),
        Err(e) => {
            let at = not_utf8_at(e.as_bytes(), e.utf8_error().valid_up_to());
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            let note = format!(
                "{}, {at}: bytes that are not UTF-8 (Latin-1 or another legacy encoding?) read \
                 as U+FFFD; in a comment they change nothing",
                input_shown(path)
            );
            Ok((text, Some(note)))
        }
    }
}

/// The name the library sees: the file name alone, so that reports and
/// G-code headers do not depend on where the file was read from.
pub fn file_name(path: &Path) -> String {
    if is_stdin(path) {
        return "stdin".into();
    }
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Puts the path in front of a library message. The library names files by
/// the name it was given; where a message starts with that name, the path
/// replaces it, and the library's `name:12: ...` line form reads
/// "dir/scan.obj, line 12: ..." (the G-code reader's `name, line 12: ...`
/// already does).
pub fn in_file(path: &Path, name: &str, message: &str) -> String {
    let shown = input_shown(path);
    let rest = message.strip_prefix(name);
    if let Some(line) = rest.filter(|r| r.starts_with(", line ")) {
        return format!("{shown}{line}");
    }
    let Some(rest) = rest.and_then(|r| r.strip_prefix(':')) else {
        return format!("{shown}: {message}");
    };
    let line = rest
        .split_once(':')
        .filter(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    match line {
        Some((n, tail)) => format!("{shown}, line {n}:{tail}"),
        None => format!("{shown}:{rest}"),
    }
}

/// Outputs staged as temporary files beside their targets, renamed into
/// place only when all of them were written. An output that is not a
/// regular file is written into, as a shell's `>` would, when the rest
/// were staged: `-` (standard output), a device (`/dev/null`) or a pipe.
/// A symbolic link to a file is followed and its target replaced; the
/// link stays. (Renaming over any of these replaced the device, the pipe
/// or the link itself with a regular file.)
#[derive(Default)]
pub struct Staged {
    files: Vec<(PathBuf, PathBuf)>,
    streams: Vec<(Stream, Vec<u8>)>,
}

/// An output written into rather than replaced.
enum Stream {
    Stdout,
    /// A device, pipe or socket, as named.
    Special(PathBuf),
}

/// Whether `path` (an output) is `-`, standard output.
pub fn is_stdout(path: &Path) -> bool {
    is_stdin(path)
}

impl Staged {
    pub fn add(&mut self, target: &Path, bytes: &[u8]) -> CliResult<()> {
        let cannot =
            |why: String| Failure::Input(format!("cannot write {}: {why}", target.display()));
        if is_stdout(target) {
            self.streams.push((Stream::Stdout, bytes.to_vec()));
            return Ok(());
        }
        let followed = std::fs::metadata(target);
        let is_link = std::fs::symlink_metadata(target).is_ok_and(|m| m.file_type().is_symlink());
        let real = match (&followed, is_link) {
            (Ok(m), _) if !m.is_file() => {
                self.streams
                    .push((Stream::Special(target.to_path_buf()), bytes.to_vec()));
                return Ok(());
            }
            (Ok(_), true) => std::fs::canonicalize(target).map_err(|e| cannot(e.to_string()))?,
            (Err(_), true) => {
                let to = std::fs::read_link(target)
                    .map_or_else(|_| "?".into(), |t| t.display().to_string());
                return Err(cannot(format!(
                    "it is a symbolic link to {to}, which does not exist; give the file itself"
                )));
            }
            (_, false) => target.to_path_buf(),
        };
        let dir = match real.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = dir.join(format!(
            ".{}.pcpp-tmp-{}",
            file_name(&real),
            std::process::id()
        ));
        let result = std::fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(cannot(e.to_string()));
        }
        self.files.push((tmp, real));
        Ok(())
    }

    /// Writes the streams, then, if they all took their bytes, renames the
    /// staged files into place.
    pub fn commit(mut self) -> CliResult<()> {
        for (stream, bytes) in std::mem::take(&mut self.streams) {
            let (name, result) = match &stream {
                Stream::Stdout => {
                    let mut out = std::io::stdout().lock();
                    (
                        "standard output".to_string(),
                        out.write_all(&bytes).and_then(|_| out.flush()),
                    )
                }
                Stream::Special(path) => (
                    path.display().to_string(),
                    std::fs::OpenOptions::new()
                        .write(true)
                        .open(path)
                        .and_then(|mut f| f.write_all(&bytes)),
                ),
            };
            // Drop removes the staged files.
            result.map_err(|e| Failure::Input(format!("cannot write {name}: {e}")))?;
        }
        let files = std::mem::take(&mut self.files);
        let mut failed = None;
        for (tmp, target) in &files {
            if failed.is_some() {
                let _ = std::fs::remove_file(tmp);
            } else if let Err(e) = std::fs::rename(tmp, target) {
                let _ = std::fs::remove_file(tmp);
                failed = Some(format!("cannot write {}: {e}", target.display()));
            }
        }
        failed.map_or(Ok(()), |m| Err(Failure::Input(m)))
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in &self.files {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// One file written alone (a `--report`), through [`Staged`].
pub fn write_one(target: &Path, bytes: &[u8]) -> CliResult<()> {
    let mut staged = Staged::default();
    staged.add(target, bytes)?;
    staged.commit()
}

pub fn to_json<T: serde::Serialize>(value: &T) -> CliResult<String> {
    serde_json::to_string_pretty(value)
        .map(|mut s| {
            s.push('\n');
            s
        })
        .map_err(|e| Failure::Input(format!("cannot write JSON: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_replace_the_library_file_name() {
        let p = Path::new("dir/scan.obj");
        assert_eq!(
            in_file(p, "scan.obj", "scan.obj:12: bad vertex"),
            "dir/scan.obj, line 12: bad vertex"
        );
        assert_eq!(
            in_file(p, "scan.obj", "scan.obj: truncated"),
            "dir/scan.obj: truncated"
        );
        assert_eq!(
            in_file(p, "scan.obj", "the path misses"),
            "dir/scan.obj: the path misses"
        );
        // The G-code reader's form, named once.
        let g = Path::new("dir/p.gcode");
        assert_eq!(
            in_file(g, "p.gcode", "p.gcode, line 4: arcs"),
            "dir/p.gcode, line 4: arcs"
        );
        assert_eq!(
            in_file(g, "p.gcode", "p.gcode, more"),
            "dir/p.gcode: p.gcode, more"
        );
    }

    /// A file of its own in the system's temporary directory.
    fn temp_file(tag: &str, bytes: &[u8]) -> PathBuf {
        let p = std::env::temp_dir().join(format!("pcpp-files-{tag}-{}", std::process::id()));
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn a_scan_reads_the_same_bytes_mapped_or_not() {
        // Not a multiple of the page size, so the mapping's last page is
        // partly past the file's end.
        let bytes: Vec<u8> = (0..10_000u32).map(|i| (i * 7 % 251) as u8).collect();
        let p = temp_file("map", &bytes);
        let got = read_scan(&p, "scan").unwrap();
        #[cfg(target_os = "linux")]
        assert!(
            matches!(got, ScanBytes::Mapped(_)),
            "a regular file is mapped"
        );
        assert_eq!(got.as_ref(), &bytes[..]);
        // Still whole after the file is gone (the map holds its pages).
        std::fs::remove_file(&p).unwrap();
        assert_eq!(got.as_ref(), &bytes[..]);
        drop(got);
        // An empty file cannot be mapped: it is read, and is empty.
        let p = temp_file("empty", b"");
        let got = read_scan(&p, "scan").unwrap();
        assert!(matches!(got, ScanBytes::Read(_)) && got.as_ref().is_empty());
        std::fs::remove_file(&p).unwrap();
    }

    /// QA round 19 F14: `/dev/zero` or a pipe that never ends read until
    /// the memory ran out; now the read stops a byte past the limit.
    #[test]
    fn an_endless_input_stops_at_its_limit() {
        let e = read_at_most(std::io::repeat(0), 1000, Path::new("-"), "path").unwrap_err();
        let Failure::Input(said) = e else {
            panic!("not an input error")
        };
        assert!(
            said.starts_with("standard input: the path is more than 0 MB"),
            "{said}"
        );
        let e = read_at_most(
            std::io::repeat(0),
            5_000_000,
            Path::new("/dev/zero"),
            "scan",
        );
        assert!(
            matches!(e, Err(Failure::Input(s)) if s.contains("/dev/zero: the scan is more than 5 MB"))
        );
        let exact = read_at_most(&[7u8; 1000][..], 1000, Path::new("a.svg"), "path").unwrap();
        assert_eq!(exact.len(), 1000);
    }

    #[test]
    fn a_missing_or_unmappable_scan_is_named_or_read() {
        let missing = std::env::temp_dir().join("pcpp-files-no-such-scan.ply");
        let Err(Failure::Input(m)) = read_scan(&missing, "scan") else {
            panic!("a missing file is an input error");
        };
        assert!(
            m.starts_with("cannot read scan ") && m.contains("no-such-scan.ply"),
            "{m}"
        );
        // A directory opens but is no regular file: it is not mapped, and
        // reading it names it.
        let Err(Failure::Input(m)) = read_scan(&std::env::temp_dir(), "scan") else {
            panic!("a directory is an input error");
        };
        assert!(m.starts_with("cannot read scan "), "{m}");
    }
}
