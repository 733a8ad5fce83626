//! Benchmark workloads, generated reproducibly (never checked in):
//! - W1: a wrinkled film scan, 100 x 100 mm, folds and fine noise, about
//!   2,000,000 triangles (1001 x 1001 vertices) at the default size.
//! - W2: the paper's spiral antenna (556 mm, 1853 points at d = 0.603 mm)
//!   placed on W1.
//! - W3: a dense serpentine raster of about 100,000 points on W1.
//! - W4: W1's film as a raw point cloud of 1,000,000 points (XYZ text),
//!   as a laser line scanner gives it: a 0.1 mm grid with jitter in XY.

use glam::DVec2;

use crate::job::JobSettings;
use crate::mesh::TriMesh;
use crate::svg::Placement;

/// A small deterministic generator (xorshift64*), so workloads (and the
/// tests' random inputs) are the same on every machine without a
/// dependency. The seed must not be 0.
pub(crate) struct Rng(pub u64);

impl Rng {
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Side of the film, mm.
pub const FILM_MM: f64 = 100.0;

/// Grid cells per side of W1 at full size (2,000,000 triangles).
pub const FILM_CELLS: usize = 1000;

/// Passes of the W3 raster: 335 passes of 90 mm sampled at d/2 = 0.3015 mm
/// give about 100,000 points.
pub const W3_LINES: usize = 335;

/// File names of the workloads, as `examples/workloads.rs` writes them and
/// the benchmark scripts read them.
pub const W1_PLY: &str = "W1.ply";
pub const W1_OBJ: &str = "W1.obj";
pub const W2_SVG: &str = "W2.svg";
pub const W3_SVG: &str = "W3.svg";
pub const W4_XYZ: &str = "W4.xyz";

/// Points per side of W4 at full size (1,000,000 points).
pub const CLOUD_SIDE: usize = 1000;

/// W4 for the film of `cells` cells a side: its grid's heights, at most
/// [`CLOUD_SIDE`] points a side over 100 mm, each moved by up to 0.2 of
/// the spacing in x and y (deterministic).
pub fn film_cloud(cells: usize) -> Vec<glam::DVec3> {
    let side = (cells + 1).min(CLOUD_SIDE);
    let film = wrinkled_film(side.max(2) - 1);
    let spacing = FILM_MM / (side.max(2) - 1) as f64;
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    film.vertices
        .into_iter()
        .map(|v| {
            let dx = 0.2 * spacing * (2.0 * rng.next_f64() - 1.0);
            let dy = 0.2 * spacing * (2.0 * rng.next_f64() - 1.0);
            glam::DVec3::new(v.x + dx, v.y + dy, v.z)
        })
        .collect()
}

/// Points as XYZ text, one "x y z" line each.
pub fn to_xyz(points: &[glam::DVec3]) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(points.len() * 28);
    for p in points {
        let _ = writeln!(s, "{:.4} {:.4} {:.4}", p.x, p.y, p.z);
    }
    s
}

/// W2's drawing: the paper's 556 mm spiral antenna.
pub fn w2_svg() -> String {
    super::antennas::paper_spiral_svg()
}

/// W3's drawing: the serpentine raster of [`W3_LINES`] passes.
pub fn w3_svg() -> String {
    serpentine_svg(W3_LINES)
}

/// W2's job settings (the paper's defaults, pcpp-guarded): the spiral's
/// drawing is centred on its own page, the offset puts it mid-film.
pub fn w2_settings() -> JobSettings {
    with_offset(DVec2::new(20.0, 80.0))
}

/// W3's job settings: the raster's SVG is the film's 100 mm square with y
/// down, so the offset (0, 100) lays it onto the film.
pub fn w3_settings() -> JobSettings {
    with_offset(DVec2::new(0.0, FILM_MM))
}

fn with_offset(offset_mm: DVec2) -> JobSettings {
    let mut s = JobSettings::default();
    s.plan.placement = Placement {
        offset_mm,
        ..Placement::IDENTITY
    };
    s
}

/// The wrinkled film's height: wrinkles in a few directions, two sharp
/// folds (creases of |sin|) and fine noise from `noise`, 0-6 mm.
fn film_height(x: f64, y: f64, waves: &[(f64, f64, f64, f64)], noise: f64) -> f64 {
    let mut z = 3.0;
    for &(kx, ky, amp, phase) in waves {
        z += amp * (kx * x + ky * y + phase).sin();
    }
    // Folds: sharp ridges along two lines.
    z += 1.5 * (0.9 - ((x - 0.6 * y - 20.0) / 9.0).sin().abs()).max(0.0);
    z += 1.0 * (0.8 - ((0.3 * x + y - 70.0) / 7.0).sin().abs()).max(0.0);
    z + noise
}

/// W1 with `n` x `n` grid cells (2 n^2 triangles); n = 1000 gives the
/// ~2 M triangle scan of the benchmarks.
pub fn wrinkled_film(n: usize) -> TriMesh {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let waves: Vec<(f64, f64, f64, f64)> = (0..6)
        .map(|_| {
            let ang = rng.next_f64() * std::f64::consts::PI;
            let k = 2.0 * std::f64::consts::PI / (4.0 + 12.0 * rng.next_f64());
            (
                k * ang.cos(),
                k * ang.sin(),
                0.15 + 0.35 * rng.next_f64(),
                6.3 * rng.next_f64(),
            )
        })
        .collect();
    let axis: Vec<f64> = (0..=n).map(|i| i as f64 * FILM_MM / n as f64).collect();
    TriMesh::height_field(&axis, &axis, |x, y| {
        let noise = 0.01 * (rng.next_f64() - 0.5);
        film_height(x, y, &waves, noise)
    })
}

/// The mesh as OBJ text (for the OBJ import benchmark).
pub fn to_obj(mesh: &TriMesh) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(mesh.vertices.len() * 36 + mesh.triangles.len() * 24);
    for v in &mesh.vertices {
        let _ = writeln!(s, "v {:.5} {:.5} {:.5}", v.x, v.y, v.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// W3: a serpentine raster over the film's middle, `lines` passes 90 mm long,
/// as SVG in mm (place it with an offset of (0, 100) mm: SVG y points down).
pub fn serpentine_svg(lines: usize) -> String {
    let pitch = 90.0 / lines.max(1) as f64;
    let mut d = String::from("M 5 5");
    for k in 0..lines {
        let y = 5.0 + k as f64 * pitch;
        let x = if k % 2 == 0 { 95.0 } else { 5.0 };
        d.push_str(&format!(" L {x} {y:.4}"));
        if k + 1 < lines {
            d.push_str(&format!(" L {x} {:.4}", y + pitch));
        }
    }
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100mm\" height=\"100mm\" \
         viewBox=\"0 0 100 100\"><path d=\"{d}\" fill=\"none\" stroke=\"black\"/></svg>"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn film_is_a_clean_height_field() {
        let m = wrinkled_film(20);
        assert_eq!(m.triangles.len(), 800);
        let (lo, hi) = m.bbox().unwrap();
        assert!(lo.z > 0.0 && hi.z < 8.0, "{lo:?} {hi:?}");
        assert_eq!(wrinkled_film(20), m, "reproducible");
        assert!(to_obj(&m).lines().count() == 441 + 800);
    }

    /// W2 and W3 have the sizes issue 5 names (W2 about 1,853 points at
    /// d = 0.603, W3 about 100,000), wherever they land on the film.
    #[test]
    fn paths_have_the_issue_sizes_on_the_film() {
        let surface = crate::surface::Surface::new(wrinkled_film(20)).unwrap();
        for (svg, settings, expected) in [
            (w2_svg(), w2_settings(), 1853.0),
            (w3_svg(), w3_settings(), 100_000.0),
        ] {
            let drawn = crate::pipeline::load_path(svg.as_bytes(), "w.svg").unwrap();
            let sp = crate::pipeline::surface_path(
                &surface,
                &drawn.subpaths,
                &settings.plan.nozzle,
                &settings.plan.placement,
            )
            .unwrap();
            assert_eq!(sp.pieces.len(), 1, "the path stays on the film");
            let n = sp.pieces[0].ta.len() as f64;
            assert!(
                (n / expected - 1.0).abs() < 0.01,
                "{n} points, expected ~{expected}"
            );
        }
    }

    #[test]
    fn serpentine_has_the_requested_passes() {
        let s = serpentine_svg(10);
        assert_eq!(s.matches(" L ").count(), 19);
    }
}
