//! Generated substrates for tests and demos (spec "The paper's test part and
//! prints"): the kinds of part the paper prints on, with every parameter in
//! the code, so no file needs finding. Each comes with a drawing that
//! crosses its features and the placement that lays it there.
//!
//! - `stepped-block`: a staircase of 2 mm steps up and down with true
//!   vertical walls, and a 2 mm block, 60 x 40 mm.
//! - `dimpled-hemisphere`: a hemisphere of R 27 mm on a plate, with
//!   spherical dimples of R 1 to 3 mm, under the paper's 556 mm spiral.
//! - `folded-film`: a film folded into sharp creases of 80 degrees
//!   (flanks at +-50 degrees, 6 mm high), crease lines turned 20 degrees
//!   from the drawing's axes, under a Hilbert loop.
//! - `wrinkled-film`: a film with smooth wrinkles (several wave trains,
//!   0.3-1 mm high, 3-8 mm long), under the spiral.
//!
//! Every part is a height field in the printer frame with its base at
//! z = 5 mm, its lower-left corner at the origin.

use std::fmt;
use std::str::FromStr;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::{antennas, test_part};
use crate::mesh::TriMesh;
use crate::svg::Placement;

/// Height of every part's base.
pub const BASE_Z_MM: f64 = 5.0;

/// The built-in parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DemoPart {
    /// The paper's 80 x 80 mm test part ([`test_part`]).
    #[default]
    TestPart,
    SteppedBlock,
    DimpledHemisphere,
    FoldedFilm,
    WrinkledFilm,
}

impl DemoPart {
    pub const ALL: [DemoPart; 5] = [
        DemoPart::TestPart,
        DemoPart::SteppedBlock,
        DemoPart::DimpledHemisphere,
        DemoPart::FoldedFilm,
        DemoPart::WrinkledFilm,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DemoPart::TestPart => "test-part",
            DemoPart::SteppedBlock => "stepped-block",
            DemoPart::DimpledHemisphere => "dimpled-hemisphere",
            DemoPart::FoldedFilm => "folded-film",
            DemoPart::WrinkledFilm => "wrinkled-film",
        }
    }

    /// One line for menus and `--help`.
    pub fn description(self) -> &'static str {
        match self {
            DemoPart::TestPart => "the paper's 80 x 80 mm test part with straight lines",
            DemoPart::SteppedBlock => "2 mm steps with vertical walls, lines across them",
            DemoPart::DimpledHemisphere => {
                "R 27 mm hemisphere with R 1-3 mm dimples, the paper's spiral"
            }
            DemoPart::FoldedFilm => "film folded in sharp 80 degree creases, a Hilbert loop",
            DemoPart::WrinkledFilm => "film with smooth wrinkles, the paper's spiral",
        }
    }

    /// The part's surface, printer frame, mm.
    pub fn mesh(self) -> TriMesh {
        match self {
            DemoPart::TestPart => test_part::test_part(),
            DemoPart::SteppedBlock => stepped_block(),
            DemoPart::DimpledHemisphere => dimpled_hemisphere(),
            DemoPart::FoldedFilm => folded_film(),
            DemoPart::WrinkledFilm => wrinkled_film(),
        }
    }

    /// The drawing printed on it, as SVG text.
    pub fn svg(self) -> String {
        match self {
            DemoPart::TestPart => test_part::test_part_svg(),
            DemoPart::SteppedBlock => stepped_block_svg(),
            DemoPart::DimpledHemisphere | DemoPart::WrinkledFilm => antennas::paper_spiral_svg(),
            DemoPart::FoldedFilm => {
                // Order 3 at 32 mm: cells of 4.6 mm, several per fold.
                antennas::hilbert_loop_svg(3, 32.0).unwrap_or_default()
            }
        }
    }

    /// Where the drawing goes in printer XY.
    pub fn placement(self) -> Placement {
        match self {
            DemoPart::TestPart => test_part::placement(),
            // Drawn in part coordinates (y flipped by the page's top edge).
            DemoPart::SteppedBlock => Placement {
                offset_mm: DVec2::new(0.0, STEPPED_SIZE.y),
                ..Placement::IDENTITY
            },
            DemoPart::DimpledHemisphere => centred(&self.svg(), HEMISPHERE_CENTRE),
            DemoPart::FoldedFilm => centred(&self.svg(), FILM_SIZE * 0.5),
            DemoPart::WrinkledFilm => centred(&self.svg(), FILM_SIZE * 0.5),
        }
    }

    /// File names for the scan and the drawing.
    pub fn scan_name(self) -> String {
        match self {
            DemoPart::TestPart => super::DEMO_SCAN_NAME.into(),
            _ => format!("demo-{}.ply", self.name()),
        }
    }

    pub fn path_name(self) -> String {
        match self {
            DemoPart::TestPart => super::DEMO_PATH_NAME.into(),
            _ => format!("demo-{}-path.svg", self.name()),
        }
    }
}

impl fmt::Display for DemoPart {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DemoPart {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        DemoPart::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = DemoPart::ALL.iter().map(|p| p.name()).collect();
                format!("unknown demo part '{s}' (expected {})", names.join(", "))
            })
    }
}

/// The placement that puts the centre of the drawing's bounding box at
/// `centre` (the page's and `--place centre`'s centring, on a footprint of
/// one point: nothing to scale to).
fn centred(svg: &str, centre: DVec2) -> Placement {
    crate::svg::import_svg(svg.as_bytes(), "demo.svg")
        .ok()
        .and_then(|drawn| {
            crate::placement::centre_drawing(&drawn, (centre, centre), &Placement::IDENTITY, true)
        })
        .map_or(Placement::IDENTITY, |(placement, _)| placement)
}

/// A grid over `xs` x `ys` whose x coordinates may repeat at a vertical
/// wall: `xs` holds (coordinate, where to evaluate the height), so the two
/// copies of a wall's x take the heights either side. Copies with equal
/// heights share their vertex, so only real walls get (vertical)
/// triangles and the mesh has no slits.
fn walled_grid(xs: &[(f64, f64)], ys: &[f64], f: impl Fn(f64, f64) -> f64) -> TriMesh {
    let w = xs.len();
    let mut m = TriMesh::default();
    let mut ids = vec![0u32; w * ys.len()];
    for (j, &y) in ys.iter().enumerate() {
        for (i, &(x, xe)) in xs.iter().enumerate() {
            let p = DVec3::new(x, y, f(xe, y));
            let same = i > 0 && xs[i - 1].0 == x && m.vertices[ids[j * w + i - 1] as usize] == p;
            ids[j * w + i] = if same {
                ids[j * w + i - 1]
            } else {
                m.vertices.push(p);
                (m.vertices.len() - 1) as u32
            };
        }
    }
    for j in 0..ys.len() - 1 {
        for i in 0..w - 1 {
            let a = ids[j * w + i];
            let b = ids[j * w + i + 1];
            let c = ids[(j + 1) * w + i + 1];
            let d = ids[(j + 1) * w + i];
            for t in [[a, b, c], [a, c, d]] {
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    m.triangles.push(t);
                }
            }
        }
    }
    m
}

/// Regular coordinates from `from` to `to` at about `step`.
fn axis(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round().max(1.0) as usize;
    (0..=n)
        .map(|i| from + (to - from) * i as f64 / n as f64)
        .collect()
}

const STEPPED_SIZE: DVec2 = DVec2::new(60.0, 40.0);
/// (x of the wall, height change there): up 2 mm three times, down three
/// times, then a 4 mm wide block.
const STEPS: [(f64, f64); 8] = [
    (10.0, 2.0),
    (16.0, 2.0),
    (22.0, 2.0),
    (30.0, -2.0),
    (36.0, -2.0),
    (42.0, -2.0),
    (48.0, 2.0),
    (52.0, -2.0),
];

fn stepped_height(x: f64) -> f64 {
    BASE_Z_MM
        + STEPS
            .iter()
            .filter(|&&(w, _)| x >= w)
            .map(|&(_, h)| h)
            .sum::<f64>()
}

fn stepped_block() -> TriMesh {
    let mut xs: Vec<(f64, f64)> = axis(0.0, STEPPED_SIZE.x, 0.1)
        .into_iter()
        .map(|x| (x, x))
        .collect();
    // Each wall's x twice: evaluated just before and just past it.
    for &(w, _) in &STEPS {
        xs.retain(|&(x, _)| (x - w).abs() > 1e-9);
        xs.push((w, w - 1e-7));
        xs.push((w, w + 1e-7));
    }
    xs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    walled_grid(&xs, &axis(0.0, STEPPED_SIZE.y, 0.5), |x, _| {
        stepped_height(x)
    })
}

/// Lines along x across every step, and one at 30 degrees across them.
fn stepped_block_svg() -> String {
    let (w, h) = (STEPPED_SIZE.x, STEPPED_SIZE.y);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}mm\" height=\"{h}mm\" \
         viewBox=\"0 0 {w} {h}\">\n"
    );
    for (k, y) in [8.0, 14.0, 26.0].into_iter().enumerate() {
        s.push_str(&format!(
            "  <line id=\"line{}\" x1=\"4\" y1=\"{}\" x2=\"56\" y2=\"{}\" stroke=\"black\" \
             stroke-width=\"0.6\"/>\n",
            k + 1,
            h - y,
            h - y
        ));
    }
    // From (6, 18) at 30 degrees to x = 56.
    let (x0, y0, x1) = (6.0, 18.0, 56.0);
    let y1 = y0 + (x1 - x0) * 30f64.to_radians().tan() * 0.25;
    s.push_str(&format!(
        "  <line id=\"diagonal\" x1=\"{x0}\" y1=\"{}\" x2=\"{x1}\" y2=\"{}\" stroke=\"black\" \
         stroke-width=\"0.6\"/>\n",
        h - y0,
        h - y1
    ));
    s.push_str("</svg>\n");
    s
}

const HEMISPHERE_SIZE: f64 = 70.0;
const HEMISPHERE_CENTRE: DVec2 = DVec2::new(35.0, 35.0);
pub const HEMISPHERE_RADIUS_MM: f64 = 27.0;
/// Dimples: (distance of the centre from the axis, azimuth in degrees,
/// dimple radius). The spiral of the drawing passes over them.
const DIMPLES: [(f64, f64, f64); 9] = [
    (4.0, 20.0, 1.0),
    (6.5, 140.0, 1.5),
    (8.0, 260.0, 2.0),
    (10.0, 30.0, 2.5),
    (11.5, 190.0, 3.0),
    (13.0, 100.0, 1.0),
    (14.5, 300.0, 2.0),
    (3.0, 230.0, 1.5),
    (16.0, 60.0, 3.0),
];

fn hemisphere_height(x: f64, y: f64) -> f64 {
    let r0 = HEMISPHERE_RADIUS_MM;
    let p = DVec2::new(x, y) - HEMISPHERE_CENTRE;
    let rr = p.length_squared();
    let mut z = if rr < r0 * r0 {
        (r0 * r0 - rr).sqrt()
    } else {
        0.0
    };
    for &(dist, az, rd) in &DIMPLES {
        // A ball of radius rd whose centre sits 0.4 rd outside the sphere
        // above the point at (dist, az): a dimple 0.6 rd deep.
        let a = az.to_radians();
        let c_xy = DVec2::new(dist * libm::cos(a), dist * libm::sin(a));
        let n = DVec3::new(c_xy.x, c_xy.y, (r0 * r0 - c_xy.length_squared()).sqrt()) / r0;
        let c = n * (r0 + 0.4 * rd);
        let q = (p - c.truncate()).length_squared();
        if q < rd * rd {
            z = z.min(c.z - (rd * rd - q).sqrt());
        }
    }
    BASE_Z_MM + z
}

fn dimpled_hemisphere() -> TriMesh {
    let xs: Vec<(f64, f64)> = axis(0.0, HEMISPHERE_SIZE, 0.2)
        .into_iter()
        .map(|x| (x, x))
        .collect();
    walled_grid(&xs, &axis(0.0, HEMISPHERE_SIZE, 0.2), hemisphere_height)
}

const FILM_SIZE: DVec2 = DVec2::new(40.0, 40.0);
/// The folded film: crease lines at 20 degrees to y, flanks at 50 degrees
/// (80 degree creases), 6 mm high.
const FOLD_TURN_DEG: f64 = 20.0;
const FOLD_FLANK_DEG: f64 = 50.0;
const FOLD_HEIGHT_MM: f64 = 6.0;

fn folded_height(x: f64, y: f64) -> f64 {
    let a = FOLD_TURN_DEG.to_radians();
    let s = x * libm::cos(a) + y * libm::sin(a);
    let run = FOLD_HEIGHT_MM / FOLD_FLANK_DEG.to_radians().tan();
    let period = 2.0 * run;
    let u = (s / period).rem_euclid(1.0) * period;
    let tri = if u < run { u } else { period - u };
    BASE_Z_MM + tri * FOLD_HEIGHT_MM / run
}

fn folded_film() -> TriMesh {
    let xs: Vec<(f64, f64)> = axis(0.0, FILM_SIZE.x, 0.125)
        .into_iter()
        .map(|x| (x, x))
        .collect();
    walled_grid(&xs, &axis(0.0, FILM_SIZE.y, 0.125), folded_height)
}

/// Wave trains of the wrinkled film: (wavelength mm, direction deg,
/// amplitude mm, phase).
const WRINKLES: [(f64, f64, f64, f64); 5] = [
    (7.5, 10.0, 1.0, 0.0),
    (5.0, 75.0, 0.6, 1.3),
    (3.5, 130.0, 0.4, 2.1),
    (4.2, 40.0, 0.3, 0.7),
    (8.0, 160.0, 0.5, 4.0),
];

fn wrinkled_height(x: f64, y: f64) -> f64 {
    // The wave trains' amplitudes add to 2.8 mm: the film stays above the
    // base.
    BASE_Z_MM
        + 3.0
        + WRINKLES
            .iter()
            .map(|&(l, deg, amp, ph)| {
                let a = deg.to_radians();
                let s = x * libm::cos(a) + y * libm::sin(a);
                amp * libm::sin(std::f64::consts::TAU * s / l + ph)
            })
            .sum::<f64>()
}

fn wrinkled_film() -> TriMesh {
    let xs: Vec<(f64, f64)> = axis(0.0, FILM_SIZE.x, 0.125)
        .into_iter()
        .map(|x| (x, x))
        .collect();
    walled_grid(&xs, &axis(0.0, FILM_SIZE.y, 0.125), wrinkled_height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_meshes_are_sound() {
        for p in DemoPart::ALL {
            assert_eq!(p.name().parse::<DemoPart>().unwrap(), p);
            if p == DemoPart::TestPart {
                continue; // tested in test_part.rs
            }
            let m = p.mesh();
            assert!(m.triangles.len() > 10_000, "{p}");
            let (lo, hi) = m.bbox().unwrap();
            assert!(lo.z >= BASE_Z_MM - 1e-9 && hi.z < BASE_Z_MM + 40.0, "{p}");
            // Every triangle has area: no slits, no degenerate walls.
            for t in 0..m.triangles.len() {
                let [a, b, c] = m.triangle(t);
                assert!((b - a).cross(c - a).length() > 1e-12, "{p} triangle {t}");
            }
            // The drawing lands on the part.
            let drawn = crate::svg::import_svg(p.svg().as_bytes(), "p.svg").unwrap();
            let pl = p.placement();
            for s in &drawn {
                for q in &s.points {
                    let r = pl.apply(*q);
                    assert!(
                        r.x > lo.x && r.y > lo.y && r.x < hi.x && r.y < hi.y,
                        "{p}: {r}"
                    );
                }
            }
        }
        assert!("cube".parse::<DemoPart>().is_err());
    }

    #[test]
    fn features_have_the_promised_sizes() {
        // Steps of 2 mm with true vertical walls.
        let m = stepped_block();
        assert!(m.triangles.iter().any(|t| {
            let [p, q, r] = t.map(|k| m.vertices[k as usize]);
            let n = (q - p).cross(r - p);
            n.z.abs() < 1e-12 && (p.z - q.z).abs().max((q.z - r.z).abs()) > 1.9
        }));
        assert_eq!(stepped_height(9.99), BASE_Z_MM);
        assert_eq!(stepped_height(25.0), BASE_Z_MM + 6.0);
        // The hemisphere's top and a dimple's depth.
        let top = hemisphere_height(35.0, 35.0);
        assert!((top - (BASE_Z_MM + 27.0)).abs() < 1e-9);
        let (dist, az, rd) = DIMPLES[4];
        let c = HEMISPHERE_CENTRE + dist * DVec2::new(az.to_radians().cos(), az.to_radians().sin());
        let sphere = BASE_Z_MM + (27.0f64.powi(2) - dist * dist).sqrt();
        let depth = sphere - hemisphere_height(c.x, c.y);
        assert!(depth > 0.5 * rd && depth < 0.7 * rd, "{depth}");
        // Fold flanks at 50 degrees, 6 mm high.
        let a = FOLD_TURN_DEG.to_radians();
        let dir = DVec2::new(a.cos(), a.sin());
        let p = DVec2::new(10.0, 10.0);
        let (lo, hi) = (p + dir * 0.5, p + dir * 0.6);
        let slope = (folded_height(hi.x, hi.y) - folded_height(lo.x, lo.y)).abs() / 0.1;
        assert!((slope.atan().to_degrees() - 50.0).abs() < 1e-6, "{slope}");
        let zs: Vec<f64> = (0..400)
            .map(|i| folded_height(i as f64 * 0.1, 3.0))
            .collect();
        let span = zs.iter().cloned().fold(f64::MIN, f64::max)
            - zs.iter().cloned().fold(f64::MAX, f64::min);
        assert!((span - 6.0).abs() < 0.05, "{span}");
    }
}
