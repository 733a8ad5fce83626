//! Inputs from fuzzing (`fuzz/`, `scripts/fuzz.sh`), replayed through the
//! same entry points as the fuzz targets: each call must return Ok or Err,
//! never panic.
//!
//! - Every file in `tests/data/fuzz/` is replayed by the prefix of its name,
//!   which is the fuzz target that found it (`import_obj-`, `import_ply-`,
//!   `import_stl-`, `import_gltf-`, `load_svg-`, `pipeline-`, `read_gcode-`).
//!   A case found by the fuzzer goes there, minimised (`cargo fuzz tmin`),
//!   and gets a named test below as well, named after the bug it pins
//!   (ripgrep style).
//! - The committed seed corpora (`fuzz/seeds/<target>/`) are replayed too:
//!   they keep the fuzz crate's input layout (`fuzz/src/lib.rs`, compiled
//!   here as a module) building against the library as it changes.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use pcpp::gcode::read_gcode;
use pcpp::mesh::{import_mesh, ImportOptions};
use pcpp::pipeline::load_path;

#[path = "../fuzz/src/lib.rs"]
mod fuzz_input;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `data` as the fuzz target `target` does. Panics propagate (the
/// test fails); Ok and Err are both fine.
fn replay(target: &str, data: &[u8]) {
    match target {
        "import_obj" => drop(import_mesh(data, "fuzz.obj", &ImportOptions::DEFAULT)),
        "import_ply" => drop(import_mesh(data, "fuzz.ply", &ImportOptions::DEFAULT)),
        "import_stl" => drop(import_mesh(data, "fuzz.stl", &ImportOptions::DEFAULT)),
        "import_gltf" => {
            drop(import_mesh(data, "fuzz.gltf", &ImportOptions::DEFAULT));
            drop(import_mesh(data, "fuzz.glb", &ImportOptions::DEFAULT));
        }
        "load_svg" => drop(load_path(data, "fuzz.svg")),
        "pipeline" => drop(fuzz_input::run(&fuzz_input::decode(data))),
        "read_gcode" => drop(read_gcode(&String::from_utf8_lossy(data), "fuzz.gcode")),
        other => panic!("no fuzz target '{other}'"),
    }
}

const TARGETS: [&str; 7] = [
    "import_obj",
    "import_ply",
    "import_stl",
    "import_gltf",
    "load_svg",
    "pipeline",
    "read_gcode",
];

/// The fuzz targets' time limit: an input slower than this is a hang.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// Saved cases of bugs not fixed yet: skipped by the replay below, each
/// pinned by an ignored named test instead (drop it from here when fixed).
const KNOWN_BUGS: [&str; 0] = [];

/// Replays on a thread and fails if it panics or takes longer than the
/// fuzzers allow (a hung thread is left behind; the test has failed).
fn replay_within_limit(target: &'static str, data: Vec<u8>, what: &str) {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        replay(target, &data);
        let _ = tx.send(());
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(()) => {}
        Err(mpsc::RecvTimeoutError::Timeout) => {
            panic!("{what}: still running after {TIME_LIMIT:?} (a hang)")
        }
        Err(mpsc::RecvTimeoutError::Disconnected) => panic!("{what}: panicked"),
    }
}

fn saved(name: &str) -> PathBuf {
    repo().join("tests/data/fuzz").join(name)
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    v.retain(|p| p.is_file());
    v.sort();
    v
}

/// One saved case, replayed by the target its name starts with.
fn replay_file(path: &Path) {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let target = TARGETS
        .iter()
        .find(|t| name.starts_with(&format!("{t}-")))
        .unwrap_or_else(|| panic!("{name}: name must start with a fuzz target and '-'"));
    let data = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    replay_within_limit(target, data, name);
}

#[test]
fn saved_fuzz_cases_do_not_panic() {
    for path in files(&repo().join("tests/data/fuzz")) {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if KNOWN_BUGS.contains(&name) {
            continue;
        }
        replay_file(&path);
    }
}

#[test]
fn fuzz_seed_corpora_do_not_panic() {
    let mut replayed = 0;
    for target in TARGETS {
        for path in files(&repo().join("fuzz/seeds").join(target)) {
            let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            replay(target, &data);
            replayed += 1;
        }
    }
    assert!(replayed > 0, "no seeds under fuzz/seeds/");
}

/// The pipeline seeds are valid jobs: each plans and writes G-code, so the
/// fuzzer starts from inputs that reach the planners and the writer.
#[test]
fn pipeline_seeds_reach_the_gcode_writer() {
    for path in files(&repo().join("fuzz/seeds/pipeline")) {
        let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let case = fuzz_input::decode(&data);
        let gcode = fuzz_input::run(&case).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            gcode.contains("M106 S255"),
            "{}: nothing printed",
            path.display()
        );
    }
}

/// An elliptical arc to an endpoint at 1e40 made usvg (svgtypes -> kurbo
/// `Arc::to_cubic_beziers`) emit cubic segments without bound before
/// pcpp's own point limit applied: > 20 s, and with 1e70 more than 7 GB,
/// from an 81-byte SVG. Such numbers are now refused before usvg sees them.
#[test]
fn svg_arc_to_a_huge_endpoint_returns_in_time() {
    for name in [
        "load_svg-arc-endpoint-1e40-hangs.svg",
        "load_svg-arc-endpoint-2e32-timeout-tmin.svg",
    ] {
        replay_file(&saved(name));
        let bytes = std::fs::read(saved(name)).unwrap();
        let e = pcpp::pipeline::load_path(&bytes, name)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line") && e.contains("beyond the 1e7 user units"),
            "{e}"
        );
    }
}

/// A fuzzed scan (a PLY grid) whose move kept splitting its first half:
/// the waypoint search counted only the waypoints already placed, not
/// those waiting on its recursion, and recursed until the stack
/// overflowed. Now it gives up after its budget and the move rises over
/// its footprint instead; the job ends either way.
#[test]
fn regression_waypoint_search_overflowed_the_stack() {
    let bytes = std::fs::read(saved("pipeline-waypoint-recursion-overflowed-the-stack")).unwrap();
    // On a thread with the harness's own stack size, where it overflowed.
    let result = std::thread::spawn(move || {
        let case = fuzz_input::decode(&bytes);
        (
            case.settings.planner,
            fuzz_input::run(&case).map_err(|e| e.to_string()),
        )
    })
    .join()
    .expect("the job panicked or overflowed its stack");
    // pcpp-guarded on a spiky grid (coordinates up to 1e299): refused,
    // for points it cannot clear or, since the drawing's mm scale is exact
    // in f64 (5cb2f36: it had been 1 + 2.8e-8 too large), for a cleared
    // point outside the build volume, or (since the G-code is refused
    // where it dispenses more than 10 d above the surface) for that, or
    // (since a scan over 2 m across is doubted for its units) for that. What
    // this test guards is that the job ends.
    let (planner, outcome) = result;
    assert_eq!(planner, pcpp::planners::PlannerKind::PcppGuarded);
    let e = outcome.unwrap_err();
    assert!(
        e.contains("would still touch the surface")
            || e.contains("outside the build volume")
            || e.contains("would dispense")
            || e.contains("larger than any printer's stage"),
        "{e}"
    );
}
