//! Writes the benchmark workloads of issue 5 (src/demo/workloads.rs) to a
//! folder, for the wasm benchmark (scripts/bench-wasm.mjs), the peak-memory
//! measure (examples/peak_memory.rs) or a user's own timing:
//!
//! ```text
//! cargo run --release --example workloads -- <outdir> [cells]
//! ```
//!
//! - `W1.ply`: the wrinkled film, binary little-endian PLY (double xyz);
//! - `W1.obj`: the same mesh as OBJ text;
//! - `W2.svg`: the paper's 556 mm spiral antenna;
//! - `W3.svg`: the serpentine raster (~100,000 points);
//! - `W2.settings.json`, `W3.settings.json`: the job settings each is planned
//!   with, in the form `defaultSettings()` of the wasm API returns (`scan`
//!   and `registration` for the Session, `plan` for `Session.plan`);
//! - `workloads.json`: what was written (sizes, triangles, points per path).
//!
//! `cells` (grid cells per side, default 1000 = 2 M triangles) shrinks W1
//! for a quick try; `PCPP_BENCH_N` does the same.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use pcpp::demo::{to_binary_ply, workloads};
use pcpp::job::JobSettings;
use pcpp::pipeline;
use pcpp::surface::Surface;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("workloads: {e}");
            ExitCode::FAILURE
        }
    }
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), String> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn json<T: serde::Serialize>(v: &T) -> Result<String, String> {
    serde_json::to_string_pretty(v)
        .map(|s| s + "\n")
        .map_err(|e| e.to_string())
}

/// Points and length of a drawing planned on the surface with `settings`
/// (the planner-independent part: sampling at d/2 and projection).
fn path_summary(
    surface: &Surface,
    svg: &str,
    name: &str,
    settings: &JobSettings,
) -> Result<serde_json::Value, String> {
    let drawn = pipeline::load_path(svg.as_bytes(), name).map_err(|e| e.to_string())?;
    let sp = pipeline::surface_path(
        surface,
        &drawn.subpaths,
        &settings.plan.nozzle,
        &settings.plan.placement,
    )
    .map_err(|e| e.to_string())?;
    let points: usize = sp.pieces.iter().map(|p| p.ta.len()).sum();
    let length_mm: f64 = sp
        .pieces
        .iter()
        .flat_map(|p| p.ta.windows(2).map(|w| w[0].distance(w[1])))
        .sum();
    Ok(serde_json::json!({
        "file": name,
        "bytes": svg.len(),
        "pieces": sp.pieces.len(),
        "points": points,
        "surface_length_mm": (length_mm * 1000.0).round() / 1000.0,
        "warnings": sp.warnings.len(),
    }))
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().ok_or(
        "usage: cargo run --release --example workloads -- <outdir> [cells per side, default 1000]",
    )?);
    let cells = args
        .next()
        .or_else(|| std::env::var("PCPP_BENCH_N").ok())
        .map(|s| {
            s.parse::<usize>()
                .ok()
                .filter(|&n| (1..=4000).contains(&n))
                .ok_or(format!("cells must be a whole number 1..=4000, got '{s}'"))
        })
        .transpose()?
        .unwrap_or(workloads::FILM_CELLS);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;

    let film = workloads::wrinkled_film(cells);
    let triangles = film.triangles.len();
    let vertices = film.vertices.len();
    let ply = to_binary_ply(&film);
    write(&dir, workloads::W1_PLY, &ply)?;
    let ply_bytes = ply.len();
    drop(ply);
    let obj = workloads::to_obj(&film);
    write(&dir, workloads::W1_OBJ, obj.as_bytes())?;
    let obj_bytes = obj.len();
    drop(obj);

    // W4: the film as a million raw points (fewer with a smaller film).
    let points = workloads::film_cloud(cells);
    let cloud_points = points.len();
    let cloud = workloads::to_xyz(&points);
    drop(points);
    write(&dir, workloads::W4_XYZ, cloud.as_bytes())?;
    let cloud_bytes = cloud.len();
    drop(cloud);

    let (w2, w3) = (workloads::w2_svg(), workloads::w3_svg());
    let (s2, s3) = (workloads::w2_settings(), workloads::w3_settings());
    write(&dir, workloads::W2_SVG, w2.as_bytes())?;
    write(&dir, workloads::W3_SVG, w3.as_bytes())?;
    write(&dir, "W2.settings.json", json(&s2)?.as_bytes())?;
    write(&dir, "W3.settings.json", json(&s3)?.as_bytes())?;

    // The film is generated in the printer frame (no registration), so the
    // paths' point counts can be checked on it directly.
    let surface = Surface::new(film).map_err(|e| e.to_string())?;
    let manifest = serde_json::json!({
        "cells": cells,
        "W1": {
            "vertices": vertices,
            "triangles": triangles,
            "ply_bytes": ply_bytes,
            "obj_bytes": obj_bytes,
        },
        "W2": path_summary(&surface, &w2, workloads::W2_SVG, &s2)?,
        "W3": path_summary(&surface, &w3, workloads::W3_SVG, &s3)?,
        "W4": { "points": cloud_points, "xyz_bytes": cloud_bytes },
    });
    write(&dir, "workloads.json", json(&manifest)?.as_bytes())?;
    println!(
        "wrote {}: W1 {} triangles ({:.1} MB PLY, {:.1} MB OBJ), W2 {} points, W3 {} points",
        dir.display(),
        triangles,
        ply_bytes as f64 / 1e6,
        obj_bytes as f64 / 1e6,
        manifest["W2"]["points"],
        manifest["W3"]["points"],
    );
    Ok(())
}
