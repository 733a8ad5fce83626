//! Native peak memory holding W1 ready to plan (issue 5: <= 250 MB):
//! reads the scan file, imports, registers and indexes it (the same
//! `job::prepare_scan_owned` the CLI runs, which frees the file's bytes once
//! they are read), checks the surface answers a query, and prints the process's peak
//! resident set (VmHWM, Linux `/proc/self/status`) and its resident set now:
//!
//! ```text
//! cargo run --release --example peak_memory -- target/workloads/W1.ply
//! peak_rss_bytes=... rss_bytes=... triangles=...
//! ```
//!
//! The peak includes the file's bytes while they are imported (the page
//! holds them throughout; its peak is measured in wasm). Write W1 with
//! `examples/workloads.rs` first.

use std::process::ExitCode;

use pcpp::job::{prepare_scan_owned, RegistrationSettings};
use pcpp::mesh::ImportOptions;
use pcpp::DVec3;

/// A field of /proc/self/status in bytes (the kernel reports kB).
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line[field.len()..]
        .trim_start_matches(':')
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

fn main() -> ExitCode {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: cargo run --release --example peak_memory -- <W1.ply|W1.obj>");
        return ExitCode::from(2);
    };
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("peak_memory: cannot read {path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let scan = match prepare_scan_owned(
        bytes,
        &path,
        &ImportOptions::DEFAULT,
        &RegistrationSettings::default(),
    ) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("peak_memory: {e}");
            return ExitCode::FAILURE;
        }
    };
    // Ready to plan: one query through the surface's index.
    let (lo, hi) = scan.surface.bbox();
    let mid = 0.5 * (lo + hi);
    let hit = scan.surface.segment_first_hit(
        DVec3::new(mid.x, mid.y, hi.z + 1.0),
        DVec3::new(mid.x, mid.y, lo.z - 1.0),
    );
    if hit.is_none() {
        eprintln!("peak_memory: no surface under the middle of {path}");
        return ExitCode::FAILURE;
    }
    let (Some(peak), Some(now)) = (status_bytes("VmHWM"), status_bytes("VmRSS")) else {
        eprintln!("peak_memory: /proc/self/status has no VmHWM/VmRSS (Linux only)");
        return ExitCode::FAILURE;
    };
    println!(
        "peak_rss_bytes={peak} rss_bytes={now} triangles={}",
        scan.triangle_count()
    );
    ExitCode::SUCCESS
}
