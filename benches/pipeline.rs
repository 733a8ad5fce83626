//! Criterion benchmarks of the native stages on the generated workloads
//! W1-W3 (src/demo/workloads.rs): import + BVH, OBJ import, planning the
//! paper's spiral (W2) and a 100k-point raster (W3) on the 2 M triangle film.
//! `PCPP_BENCH_N` shrinks the film (grid cells per side, default 1000).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcpp::demo::{antennas, to_binary_ply, workloads};
use pcpp::job::{prepare_scan, RegistrationSettings};
use pcpp::mesh::ImportOptions;
use pcpp::pipeline::{self, PlanSettings};
use pcpp::svg::Placement;
use pcpp::DVec2;

fn n() -> usize {
    std::env::var("PCPP_BENCH_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000)
}

fn benches(c: &mut Criterion) {
    let film = workloads::wrinkled_film(n());
    let ply = to_binary_ply(&film);
    let obj = workloads::to_obj(&film);
    drop(film);
    let reg = RegistrationSettings::default();

    let mut g = c.benchmark_group("import");
    g.sample_size(10);
    g.bench_function("W1 binary PLY + BVH", |b| {
        b.iter(|| prepare_scan(black_box(&ply), "w1.ply", &ImportOptions::DEFAULT, &reg).unwrap())
    });
    g.throughput(Throughput::Bytes(obj.len() as u64));
    g.bench_function("W1 OBJ text", |b| {
        b.iter(|| {
            pcpp::mesh::import_mesh(black_box(obj.as_bytes()), "w1.obj", &ImportOptions::DEFAULT)
                .unwrap()
        })
    });
    g.finish();

    let scan = prepare_scan(&ply, "w1.ply", &ImportOptions::DEFAULT, &reg).unwrap();
    let spiral = pipeline::load_path(antennas::paper_spiral_svg().as_bytes(), "w2.svg").unwrap();
    let raster = pipeline::load_path(workloads::serpentine_svg(335).as_bytes(), "w3.svg").unwrap();
    // The spiral's drawing is centred on its own page: put it mid-film.
    let w2 = PlanSettings {
        placement: Placement {
            offset_mm: DVec2::new(20.0, 80.0),
            ..Placement::IDENTITY
        },
        ..Default::default()
    };
    let w3 = PlanSettings {
        placement: Placement {
            offset_mm: DVec2::new(0.0, 100.0),
            ..Placement::IDENTITY
        },
        ..Default::default()
    };
    let mut g = c.benchmark_group("plan");
    g.sample_size(10);
    g.bench_function("W2 spiral on W1 (pcpp-guarded + quality)", |b| {
        b.iter(|| pipeline::plan(&scan.surface, black_box(&spiral.subpaths), &w2).unwrap())
    });
    g.bench_function("W3 raster on W1 (pcpp-guarded + quality)", |b| {
        b.iter(|| pipeline::plan(&scan.surface, black_box(&raster.subpaths), &w3).unwrap())
    });
    g.finish();
}

criterion_group!(pipeline_benches, benches);
criterion_main!(pipeline_benches);
