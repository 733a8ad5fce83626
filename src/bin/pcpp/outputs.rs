//! The files a command writes, checked before anything is read: none may
//! be a file the command reads, under any spelling (`./x`, `a/../x`, a
//! symbolic or hard link), nor another of its outputs, and each one's
//! folder must exist.
//!
//! Outputs are renamed into place only once everything succeeded
//! ([`crate::files::Staged`]), so without these checks `-o teapot.obj`
//! replaced the scan it had just planned on, two outputs naming one file
//! were staged as one temporary file (the second rename failed, the first
//! had landed), and a missing folder was found only after the whole plan
//! (found by exploratory runs with real inputs).

use std::path::{Component, Path, PathBuf};

use crate::{usage, CliResult, Failure};

/// A file named on the command line, and the flag that names it.
#[derive(Debug, Clone, Copy)]
pub struct Flagged<'a> {
    pub flag: &'static str,
    pub path: &'a Path,
}

impl<'a> Flagged<'a> {
    pub fn new(flag: &'static str, path: &'a Path) -> Self {
        Flagged { flag, path }
    }
}

/// A command's outputs, each with the file it names; made by
/// [`Outputs::check`]. [`Outputs::default`] has none (a command that
/// writes only to stdout).
#[derive(Default)]
pub struct Outputs<'a> {
    command: &'static str,
    files: Vec<(Flagged<'a>, FileId)>,
}

impl<'a> Outputs<'a> {
    /// Checks `outputs` against each other and against the files the
    /// command reads (`inputs`; one that does not exist is skipped, reading
    /// it will say so): the same file twice is a usage error naming both
    /// flags. Then each output's folder must exist (bad input, as a missing
    /// input file is). Nothing is read but the file system's entries.
    pub fn check<'b>(
        command: &'static str,
        outputs: impl IntoIterator<Item = Flagged<'a>>,
        inputs: impl IntoIterator<Item = Flagged<'b>>,
    ) -> CliResult<Outputs<'a>> {
        let mut checked = Outputs {
            command,
            files: Vec::new(),
        };
        for out in outputs {
            let id = FileId::of_output(out.path);
            if let Some((first, _)) = checked.files.iter().find(|(_, o)| *o == id) {
                return Err(usage(
                    command,
                    format!(
                        "{} {} and {} {} name the same file; give each output a file of its own",
                        out.flag,
                        out.path.display(),
                        first.flag,
                        first.path.display()
                    ),
                ));
            }
            checked.files.push((out, id));
        }
        let mut stdin: Option<Flagged> = None;
        for input in inputs {
            if crate::files::is_stdin(input.path) {
                if let Some(first) = stdin {
                    return Err(usage(
                        command,
                        format!(
                            "{} - and {} - both read standard input; give one of them a file",
                            first.flag, input.flag
                        ),
                    ));
                }
                stdin = Some(input);
                continue;
            }
            checked.refuse_read(input.path, || {
                format!("{} {}", input.flag, input.path.display())
            })?;
        }
        for (out, _) in &checked.files {
            folder_exists(out)?;
        }
        Ok(checked)
    }

    /// Refuses to go on where an output is the file at `path`, which the
    /// command reads (`described` names it for the message, with its
    /// flag): writing the output would replace it. For the files only
    /// reading shows (a `.gltf`'s buffers), checked before they are read.
    pub fn refuse_read(&self, path: &Path, described: impl FnOnce() -> String) -> CliResult<()> {
        let Some(id) = FileId::of_existing(path) else {
            return Ok(());
        };
        match self.files.iter().find(|(_, o)| *o == id) {
            None => Ok(()),
            Some((out, _)) => Err(usage(
                self.command,
                format!(
                    "{} {} and {} name the same file: writing it would replace an input of \
                     this command; give {} another file",
                    out.flag,
                    out.path.display(),
                    described(),
                    out.flag
                ),
            )),
        }
    }
}

/// What makes two paths one file.
#[derive(Debug, PartialEq, Eq)]
enum FileId {
    /// A file that exists: its device and inode, which every spelling of
    /// it, every symbolic link to it and every hard link of it share.
    #[cfg(unix)]
    Inode { device: u64, inode: u64 },
    /// A file that exists, elsewhere: its canonical path (symbolic links
    /// resolved; hard links are not told apart).
    #[cfg(not(unix))]
    Canonical(PathBuf),
    /// A file not there yet: where it would be created, its folder's
    /// canonical path and its name.
    New(PathBuf),
}

impl FileId {
    fn of_existing(path: &Path) -> Option<FileId> {
        let meta = std::fs::metadata(path).ok()?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt as _;
            Some(FileId::Inode {
                device: meta.dev(),
                inode: meta.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            std::fs::canonicalize(path).ok().map(FileId::Canonical)
        }
    }

    fn of_output(path: &Path) -> FileId {
        FileId::of_existing(path).unwrap_or_else(|| FileId::New(where_created(path)))
    }
}

/// The folder a file is created in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Where a file not yet there would be created: its folder canonicalised,
/// then its name; where the folder cannot be (it does not exist), the path
/// made absolute with `.` and `..` taken as written.
fn where_created(path: &Path) -> PathBuf {
    match (std::fs::canonicalize(folder_of(path)), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => {
            let full = std::env::current_dir()
                .map(|d| d.join(path))
                .unwrap_or_else(|_| path.to_path_buf());
            let mut out = PathBuf::new();
            for c in full.components() {
                match c {
                    Component::CurDir => {}
                    Component::ParentDir => {
                        out.pop();
                    }
                    other => out.push(other),
                }
            }
            out
        }
    }
}

/// The output's folder exists and the output is not itself a folder.
fn folder_exists(out: &Flagged) -> CliResult<()> {
    let folder = folder_of(out.path);
    let problem = match std::fs::metadata(folder) {
        Ok(m) if m.is_dir() => match std::fs::metadata(out.path) {
            Ok(m) if m.is_dir() => format!("it is a folder; give {} a file name", out.flag),
            _ => return Ok(()),
        },
        Ok(_) => format!(
            "{} is not a folder; give {} a path in a folder",
            folder.display(),
            out.flag
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => format!(
            "the folder {} does not exist; create it first, or give {} a path in a folder \
             that exists",
            folder.display(),
            out.flag
        ),
        Err(e) => format!("the folder {}: {e}", folder.display()),
    };
    Err(Failure::Input(format!(
        "cannot write {} ({}): {problem}",
        out.path.display(),
        out.flag
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder of its own in the system's temporary directory.
    fn temp_dir(tag: &str) -> PathBuf {
        let p = std::env::temp_dir().join(format!("pcpp-outputs-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(p.join("sub")).unwrap();
        p
    }

    #[test]
    fn spellings_of_one_file_are_one_file() {
        let dir = temp_dir("ids");
        let x = dir.join("x");
        std::fs::write(&x, b"x").unwrap();
        let id = FileId::of_output(&x);
        assert_eq!(FileId::of_output(&dir.join("./x")), id);
        assert_eq!(FileId::of_output(&dir.join("sub/../x")), id);
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&x, dir.join("link")).unwrap();
            std::fs::hard_link(&x, dir.join("hard")).unwrap();
            assert_eq!(FileId::of_output(&dir.join("link")), id);
            assert_eq!(FileId::of_output(&dir.join("hard")), id);
        }
        assert_ne!(FileId::of_output(&dir.join("sub/x")), id);
        // Not yet there: its folder and name.
        let new = FileId::of_output(&dir.join("new"));
        assert_eq!(FileId::of_output(&dir.join("sub/../new")), new);
        assert_ne!(FileId::of_output(&dir.join("sub/new")), new);
        assert!(FileId::of_existing(&dir.join("new")).is_none());
        // In a folder that does not exist: as written.
        let nodir = FileId::of_output(&dir.join("nodir/new"));
        assert_eq!(FileId::of_output(&dir.join("nodir/./new")), nodir);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
