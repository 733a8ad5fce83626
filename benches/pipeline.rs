//! Criterion benchmarks of the native stages on the generated workloads
//! W1-W3 (src/demo/workloads.rs), single-threaded:
//! - `import/W1 binary PLY + index`: what a Session does with the scan's
//!   bytes (`job::prepare_scan`: import, fiducial holes, registration and
//!   the surface's acceleration structure);
//! - `import/W1 OBJ text`: the OBJ importer alone (throughput in bytes);
//! - `import/W1 OBJ + index`: the OBJ's `prepare_scan`, what the wasm script
//!   can time (its API imports only through a Session);
//! - `plan/W2 ...`, `plan/W3 ...`: the planning stages (project, spline,
//!   the default planner with its safe-motion stage, quality:
//!   `pipeline::plan`) of the paper's spiral and a 100k-point raster on the
//!   2 M triangle film;
//! - `job/W2 ...`, `job/W3 ...`: the whole `job::run_on` (SVG read, plan,
//!   report, G-code), what the wasm `Session.plan` runs;
//! - `motion/demo ...`: the demo test part's lines planned by `even` (the
//!   default) and `pcpp-guarded`, each without and with the safe-motion
//!   stage (waypoints and the swept check of every move, spec section 6f)
//!   (issue 11: with the check within 1.5x of without; issue 12: `even`
//!   within 2x of `pcpp-guarded`).
//!
//! - `cloud/W4 ...`: a million raw points (W4) meshed (issue 14: under
//!   2 s natively), read from XYZ text, and with the holes and index.
//!
//! `PCPP_BENCH_N` shrinks the film (grid cells per side, default 1000), and
//! W4 with it.
//! `PCPP_BENCH_CLOCK=cpu` times the bench thread's CPU time instead of wall
//! time (see [`Clock`]). `scripts/bench.sh` runs these with the wasm timings
//! and prints the table.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, SamplingMode, Throughput};
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

/// Wall time (the default), or with `PCPP_BENCH_CLOCK=cpu` the CPU time of
/// the benchmark's own thread (Linux `/proc/thread-self/schedstat`, ns): on
/// a shared machine the time other processes take from this single-threaded
/// code is then left out. Criterion runs the routine on the thread that
/// starts and ends each sample.
struct Clock {
    cpu: bool,
    epoch: Instant,
    formatter: WallTime,
}

impl Clock {
    fn from_env() -> Clock {
        let want_cpu = std::env::var("PCPP_BENCH_CLOCK").is_ok_and(|v| v == "cpu");
        let cpu = want_cpu && thread_cpu_ns().is_some();
        if want_cpu && !cpu {
            eprintln!(
                "PCPP_BENCH_CLOCK=cpu: no /proc/thread-self/schedstat here, timing wall time"
            );
        }
        Clock {
            cpu,
            epoch: Instant::now(),
            formatter: WallTime,
        }
    }
}

/// Nanoseconds this thread has run on a CPU (the first field of schedstat).
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

impl Measurement for Clock {
    type Intermediate = u64;
    type Value = Duration;

    fn start(&self) -> u64 {
        if self.cpu {
            thread_cpu_ns().unwrap_or(0)
        } else {
            self.epoch.elapsed().as_nanos() as u64
        }
    }
    fn end(&self, start: u64) -> Duration {
        Duration::from_nanos(self.start().saturating_sub(start))
    }
    fn add(&self, a: &Duration, b: &Duration) -> Duration {
        *a + *b
    }
    fn zero(&self) -> Duration {
        Duration::ZERO
    }
    fn to_f64(&self, v: &Duration) -> f64 {
        v.as_nanos() as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        // Nanoseconds either way: criterion's own time formatter.
        self.formatter.formatter()
    }
}

fn motion_benches(c: &mut Criterion<Clock>) {
    use pcpp::demo::test_part;
    use pcpp::planners::PlannerKind;
    let surface = pcpp::surface::Surface::new(test_part::test_part()).unwrap();
    let drawn = pipeline::load_path(test_part::test_part_svg().as_bytes(), "demo.svg").unwrap();
    let settings = pipeline::PlanSettings {
        placement: test_part::placement(),
        ..Default::default()
    };
    let (nozzle, process) = (&settings.nozzle, &settings.process);
    let sp =
        pipeline::surface_path(&surface, &drawn.subpaths, nozzle, &settings.placement).unwrap();
    let mut g = c.benchmark_group("motion");
    g.sample_size(20);
    // The default planner first: the demo workload as `pcpp demo` plans it.
    for k in [PlannerKind::Even, PlannerKind::PcppGuarded] {
        g.bench_function(format!("demo {k} without motion check"), |b| {
            b.iter(|| {
                pipeline::plan_surface_path_without_motion(
                    &surface,
                    black_box(&sp),
                    k,
                    nozzle,
                    process,
                )
            })
        });
        g.bench_function(format!("demo {k} with motion check"), |b| {
            b.iter(|| pipeline::plan_surface_path(&surface, black_box(&sp), k, nozzle, process))
        });
    }
    g.finish();
}

/// Issue 14: W4, a million raw points, read and meshed (target: under 2 s
/// natively).
fn cloud_benches(c: &mut Criterion<Clock>) {
    // As examples/workloads.rs writes W4.
    let points = workloads::film_cloud(n());
    let xyz = workloads::to_xyz(&points);
    let mut g = c.benchmark_group("cloud");
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    g.bench_function("W4 points: triangulate", |b| {
        b.iter_batched(
            || points.clone(),
            |p| pcpp::mesh::triangulate(p, None, "W4").unwrap(),
            BatchSize::LargeInput,
        )
    });
    g.throughput(Throughput::Bytes(xyz.len() as u64));
    g.bench_function("W4 points: XYZ import + mesh", |b| {
        b.iter(|| {
            pcpp::mesh::import_mesh(
                black_box(xyz.as_bytes()),
                workloads::W4_XYZ,
                &pcpp::mesh::ImportOptions::DEFAULT,
            )
            .unwrap()
        })
    });
    // What the page's Session does with it: also the holes and the index.
    let w2 = workloads::w2_settings();
    g.bench_function("W4 points: XYZ + index", |b| {
        b.iter(|| {
            prepare_scan(
                black_box(xyz.as_bytes()),
                workloads::W4_XYZ,
                &w2.scan,
                &w2.registration,
            )
            .unwrap()
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion<Clock>) {
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
    g.bench_function("W1 binary PLY + index", |b| {
        b.iter(|| prepare(black_box(&ply), "W1.ply", &w2))
    });
    g.throughput(Throughput::Bytes(obj.len() as u64));
    g.bench_function("W1 OBJ text", |b| {
        b.iter(|| pcpp::mesh::import_mesh(black_box(obj.as_bytes()), "W1.obj", &w2.scan).unwrap())
    });
    g.bench_function("W1 OBJ + index", |b| {
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
    g.bench_function("W2 spiral on W1 (default planner + quality)", |b| {
        b.iter(|| pipeline::plan(&scan.surface, black_box(&spiral.subpaths), &w2.plan).unwrap())
    });
    g.sampling_mode(SamplingMode::Flat);
    g.bench_function("W3 raster on W1 (default planner + quality)", |b| {
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

criterion_group! {
    name = pipeline_benches;
    config = Criterion::default().with_measurement(Clock::from_env());
    targets = motion_benches, cloud_benches, benches
}
criterion_main!(pipeline_benches);
