//! Files: reading inputs, naming them in messages, and writing outputs
//! through temporary files renamed only once everything succeeded, so a
//! failed run leaves no partial file behind.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::{CliResult, Failure};

pub fn read_bytes(path: &Path, what: &str) -> CliResult<Vec<u8>> {
    std::fs::read(path)
        .map_err(|e| Failure::Input(format!("cannot read {what} {}: {e}", path.display())))
}

pub fn read_text(path: &Path, what: &str) -> CliResult<String> {
    let bytes = read_bytes(path, what)?;
    String::from_utf8(bytes).map_err(|e| {
        Failure::Input(format!(
            "{}: {what} is not UTF-8 text (byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}

/// The name the library sees: the file name alone, so that reports and
/// G-code headers do not depend on where the file was read from.
pub fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Puts the path in front of a library message. The library names files by
/// the name it was given; where a message starts with that name, the path
/// replaces it, and the library's `name:12: ...` line form reads
/// "dir/scan.obj, line 12: ...".
pub fn in_file(path: &Path, name: &str, message: &str) -> String {
    let Some(rest) = message.strip_prefix(name).and_then(|r| r.strip_prefix(':')) else {
        return format!("{}: {message}", path.display());
    };
    let line = rest
        .split_once(':')
        .filter(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    match line {
        Some((n, tail)) => format!("{}, line {n}:{tail}", path.display()),
        None => format!("{}:{rest}", path.display()),
    }
}

/// Outputs staged as temporary files beside their targets, renamed into
/// place only when all of them were written.
#[derive(Default)]
pub struct Staged {
    files: Vec<(PathBuf, PathBuf)>,
}

impl Staged {
    pub fn add(&mut self, target: &Path, bytes: &[u8]) -> CliResult<()> {
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = dir.join(format!(
            ".{}.pcpp-tmp-{}",
            file_name(target),
            std::process::id()
        ));
        let result = std::fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(Failure::Input(format!(
                "cannot write {}: {e}",
                target.display()
            )));
        }
        self.files.push((tmp, target.to_path_buf()));
        Ok(())
    }

    pub fn commit(mut self) -> CliResult<()> {
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
    }
}
