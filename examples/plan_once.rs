//! One plan of W2 or W3 on W1 (a scan file written by `examples/workloads.rs`),
//! for profilers (`valgrind --tool=callgrind`, `perf`): imports the scan,
//! then plans the drawing `repeat` times with the workload's settings.
//!
//! ```text
//! PCPP_THREADS=1 cargo run --release --example plan_once -- target/workloads W3 [repeat]
//! ```

use std::process::ExitCode;

use pcpp::demo::workloads;
use pcpp::job::prepare_scan_owned;
use pcpp::pipeline;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let (Some(dir), Some(which)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: plan_once <workload folder> <W2|W3> [repeat]");
        return ExitCode::from(2);
    };
    let repeat: usize = args.get(3).and_then(|r| r.parse().ok()).unwrap_or(1);
    let (svg, name, settings) = match which.as_str() {
        "W2" => (
            workloads::w2_svg(),
            workloads::W2_SVG,
            workloads::w2_settings(),
        ),
        "W3" => (
            workloads::w3_svg(),
            workloads::W3_SVG,
            workloads::w3_settings(),
        ),
        _ => {
            eprintln!("plan_once: the workload is W2 or W3, not {which}");
            return ExitCode::from(2);
        }
    };
    let scan_path = format!("{dir}/W1.ply");
    let bytes = match std::fs::read(&scan_path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("plan_once: cannot read {scan_path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let scan = match prepare_scan_owned(bytes, &scan_path, &settings.scan, &settings.registration) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("plan_once: {e}");
            return ExitCode::FAILURE;
        }
    };
    let drawn = pipeline::load_path(svg.as_bytes(), name).expect("the workload's drawing reads");
    for _ in 0..repeat {
        match pipeline::plan(&scan.surface, &drawn.subpaths, &settings.plan) {
            Ok(plan) => println!("{} points planned", plan.stats.points),
            Err(e) => {
                eprintln!("plan_once: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
