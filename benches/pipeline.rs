//! Criterion benchmarks of the native stages on the generated workloads
//! W1-W3 (src/demo/workloads.rs), single-threaded:
//! - `import/W1 binary PLY + BVH`: what a Session does with the scan's bytes
//!   (`job::prepare_scan`: import, fiducial holes, registration, BVH);
//! - `import/W1 OBJ text`: the OBJ importer alone (throughput in bytes);
//! - `import/W1 OBJ + BVH`: the OBJ's `prepare_scan`, what the wasm script
//!   can time (its API imports only through a Session);
//! - `plan/W2 ...`, `plan/W3 ...`: the planning stages (project, spline,
//!   pcpp-guarded, quality: `pipeline::plan`) of the paper's spiral and a
//!   100k-point raster on the 2 M triangle film;
//! - `job/W2 ...`, `job/W3 ...`: the whole `job::run_on` (SVG read, plan,
//!   report, G-code), what the wasm `Session.plan` runs.
//!
//! `PCPP_BENCH_N` shrinks the film (grid cells per side, default 1000).
//! `scripts/bench.sh` runs these with the wasm timings and prints the table.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use pcpp::demo::{to_binary_ply, workloads};
use pcpp::gcode::MachineProfile;
use pcpp::job::{self, prepare_scan, JobSettings};
use pcpp::pipeline;

fn n() -> usize {
    std::env::var("PCPP_BENCH_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(workloads::FILM_CELLS)
}

fn benches(c: &mut Criterion) {
    let film = workloads::wrinkled_film(n());
    let ply = to_binary_ply(&film);
    let obj = workloads::to_obj(&film);
    drop(film);
    let (w2, w3) = (workloads::w2_settings(), workloads::w3_settings());
    let prepare = |bytes: &[u8], name: &str, s: &JobSettings| {
        prepare_scan(bytes, name, &s.scan, &s.registration).unwrap()
    };

    // Runs of a second or so: one iteration per sample (flat sampling), so
    // ten samples take ten runs rather than criterion's linear 55.
    let mut g = c.benchmark_group("import");
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    g.bench_function("W1 binary PLY + BVH", |b| {
        b.iter(|| prepare(black_box(&ply), "W1.ply", &w2))
    });
    g.throughput(Throughput::Bytes(obj.len() as u64));
    g.bench_function("W1 OBJ text", |b| {
        b.iter(|| pcpp::mesh::import_mesh(black_box(obj.as_bytes()), "W1.obj", &w2.scan).unwrap())
    });
    g.bench_function("W1 OBJ + BVH", |b| {
        b.iter(|| prepare(black_box(obj.as_bytes()), "W1.obj", &w2))
    });
    g.finish();
    drop(obj);

    let scan = prepare(&ply, "W1.ply", &w2);
    drop(ply);
    let (svg2, svg3) = (workloads::w2_svg(), workloads::w3_svg());
    let spiral = pipeline::load_path(svg2.as_bytes(), workloads::W2_SVG).unwrap();
    let raster = pipeline::load_path(svg3.as_bytes(), workloads::W3_SVG).unwrap();

    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    g.bench_function("W2 spiral on W1 (pcpp-guarded + quality)", |b| {
        b.iter(|| pipeline::plan(&scan.surface, black_box(&spiral.subpaths), &w2.plan).unwrap())
    });
    g.sampling_mode(SamplingMode::Flat);
    g.bench_function("W3 raster on W1 (pcpp-guarded + quality)", |b| {
        b.iter(|| pipeline::plan(&scan.surface, black_box(&raster.subpaths), &w3.plan).unwrap())
    });
    g.finish();

    // Accept risk: the timing must not depend on whether some raster point
    // could not be cleared (the wasm script plans the same way).
    let marlin = MachineProfile::builtin("marlin").unwrap();
    let run = |svg: &str, name: &str, s: &JobSettings| {
        job::run_on(&scan, svg.as_bytes(), name, &s.plan, &marlin, true).unwrap()
    };
    let mut g = c.benchmark_group("job");
    g.sample_size(10);
    g.bench_function("W2 plan + report + G-code", |b| {
        b.iter(|| run(black_box(&svg2), workloads::W2_SVG, &w2))
    });
    g.sampling_mode(SamplingMode::Flat);
    g.bench_function("W3 plan + report + G-code", |b| {
        b.iter(|| run(black_box(&svg3), workloads::W3_SVG, &w3))
    });
    g.finish();
}

criterion_group!(pipeline_benches, benches);
criterion_main!(pipeline_benches);
