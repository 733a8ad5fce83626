//! Whether a scan read with its format's default up axis looks like it was
//! saved with the other one (spec section 2: the scan is placed in the
//! printer's frame with +Z up).
//!
//! OBJ, PLY and STL carry no up axis; we read them +Z up (scanners'
//! convention), but Blender's and many scanner apps' OBJ and STL exports are
//! +Y up, and such a scan is shown, placed on the bed and planned lying on
//! its side, with nothing said (found by QA: the Stanford bunny and a cow,
//! both +Y up, shown on their backs). An object rests on the side it was
//! scanned standing on: the side whose outermost points spread widest
//! (the bunny's base, the cow's four hooves; a film's lowest points, spread
//! over its whole footprint). When, as read, that is clearly the -Y side
//! (+Y when read +Y up: then +Z was up), or its top, +Z (a depth camera's
//! frame, z the distance from the camera: -Z was up), the scan gets a note
//! naming the up axis to try. It is only a note: the reading stays the one
//! asked for.

use glam::{DVec2, DVec3};

#[cfg(test)]
use super::TriMesh;
use super::UpAxis;

/// The most vertices looked at (evenly spread): the sides' spread does not
/// need every vertex of a 2 M triangle scan.
const SAMPLES: usize = 100_000;

/// How far in from a side its outermost points may lie, as a share of the
/// scan's largest extent.
const SLAB: f64 = 0.01;

/// How much wider the side it rests on must spread than any other side.
const MARGIN: f64 = 2.0;

/// The least spread, as a share of the largest extent squared, that says
/// anything (a cube or a sliver spreads alike, or not at all, everywhere).
const LEAST: f64 = 0.02;

/// A note when the scan's `vertices` (a mesh's or a cloud's), read with
/// `up` (the format's default, not the user's choice), rest clearly on a
/// side that says the other axis was up.
pub(crate) fn note(
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    up: UpAxis,
    file: &str,
) -> Option<String> {
    let stride = vertices.len().div_ceil(SAMPLES).max(1);
    let sample: Vec<DVec3> = vertices.iter().step_by(stride).copied().collect();
    resting_note(&sample, vertices, triangles, up, file).or_else(|| edge_note(&sample, up, file))
}

/// The note for a scan resting clearly on a side that says the other axis
/// was up.
fn resting_note(
    sample: &[DVec3],
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    up: UpAxis,
    file: &str,
) -> Option<String> {
    let spread = side_spreads(sample)?;
    // [-X, +X, -Y, +Y, -Z, +Z], the side it rests on: the widest, by the
    // margin.
    let side = (0..6).max_by(|&a, &b| spread[a].total_cmp(&spread[b]))?;
    let next = (0..6)
        .filter(|&i| i != side)
        .map(|i| spread[i])
        .fold(0.0, f64::max);
    if spread[side] < LEAST || spread[side] < MARGIN * next {
        return None;
    }
    // Read +Z up, a +Y-up scan rests on -Y and a depth camera's (-Z up) on
    // +Z; read +Y up, a +Z-up one rests on +Y, its -Z turned to +Y: named
    // in the file's own axes, as its up axis is (QA round 18 F12: "read
    // +Y up, it rests on its +Y side").
    let (name, other, flag, shown) = match (up, side) {
        (UpAxis::Z, 2) => ("-Y", "+Y", "y", "lying on its side"),
        // Only a mesh whose surface faces down as read: a depth camera sees
        // the faces turned to it, at -Z. A scan seen from above with a flat
        // top over a tilted base spreads widest at its top too (review).
        (UpAxis::Z, 5) if faces_down(vertices, triangles) => ("+Z", "-Z", "-z", "upside down"),
        (UpAxis::Y, 3) => ("-Z (in the file's axes)", "+Z", "z", "lying on its side"),
        _ => return None,
    };
    // Turned onto that side, a part much taller than as read stands on an
    // end (QA round 18 F12: a VR controller lying flat, 82 mm high, would
    // stand 181 mm tall): a substrate lies on the bed, so no note.
    if side == 2 || side == 3 {
        let (lo, hi) = bounds(sample);
        let size = hi - lo;
        if size.y > TALLER * size.z {
            return None;
        }
    }
    let read = match up {
        UpAxis::Z => "+Z up",
        UpAxis::Y => "+Y up (glTF's convention)",
        UpAxis::NegZ => "-Z up",
    };
    Some(format!(
        "{file}: read {read}, it rests on its {name} side (its outermost points spread far \
         wider there than on any other side): it was likely saved with {other} up; if the \
         part is {shown} as read, read it {other} up (--up-axis {flag})"
    ))
}

/// How much taller than as read a part turned onto the side it rests on
/// may be for the note to suggest it.
const TALLER: f64 = 1.5;

/// How much thinner along Y than along X and Z a scan standing on an edge
/// is.
const EDGE: f64 = 0.3;

/// The note for a plate standing on an edge as read: thin along Y, wide
/// along X and tall along Z (QA round 16: a flange ring, a wing and a case
/// lid, each saved +Y up and read +Z up, were planned on their 10 mm rims
/// with no word, their two broad faces spreading alike so that neither is
/// the side they rest on). A substrate lies on the bed; standing on an
/// edge it offers the nozzle its rim only.
fn edge_note(sample: &[DVec3], up: UpAxis, file: &str) -> Option<String> {
    let (other, flag, read) = match up {
        UpAxis::Z => ("+Y", "y", "+Z up"),
        UpAxis::Y => ("+Z", "z", "+Y up (glTF's convention)"),
        UpAxis::NegZ => return None,
    };
    let (lo, hi) = bounds(sample);
    let size = hi - lo;
    let broad = size.x.min(size.z);
    if !(size.is_finite() && broad > 0.0 && size.y <= EDGE * broad) {
        return None;
    }
    Some(format!(
        "{file}: read {read}, it stands on an edge, {} x {} x {} mm and thinnest along Y: \
         it was likely saved with {other} up; if the part lies flat, read it {other} up \
         (--up-axis {flag})",
        crate::error::mm_text(size.x, 1),
        crate::error::mm_text(size.y, 1),
        crate::error::mm_text(size.z, 1),
    ))
}

/// Whether most of the surface's area faces -Z (triangles wound
/// counter-clockwise seen from outside): their area-weighted normals sum
/// to at least half their area, pointing down.
fn faces_down(vertices: &[DVec3], triangles: &[[u32; 3]]) -> bool {
    let (mut sum, mut area) = (DVec3::ZERO, 0.0);
    for t in triangles {
        let [Some(&a), Some(&b), Some(&c)] = t.map(|i| vertices.get(i as usize)) else {
            continue;
        };
        let n = (b - a).cross(c - a);
        sum += n;
        area += n.length();
    }
    area > 0.0 && sum.z < -0.5 * area
}

/// The box of `points` (infinite, inside out, for none).
fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// For each side of the box of `points` (-X, +X, -Y, +Y, -Z, +Z): the area
/// of the convex hull of the points within `SLAB` of it, seen along its
/// axis, over the largest extent squared. `None` for a degenerate box.
fn side_spreads(points: &[DVec3]) -> Option<[f64; 6]> {
    let (lo, hi) = bounds(points);
    let size = (hi - lo).max_element();
    if !(size.is_finite() && size > 0.0) {
        return None;
    }
    let eps = SLAB * size;
    let mut out = [0.0; 6];
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (k, at_low) in [(0, true), (1, false)] {
            let slab: Vec<DVec2> = points
                .iter()
                .filter(|p| {
                    if at_low {
                        p[axis] <= lo[axis] + eps
                    } else {
                        p[axis] >= hi[axis] - eps
                    }
                })
                .map(|p| DVec2::new(p[u], p[v]))
                .collect();
            out[2 * axis + k] = hull_area(slab) / (size * size);
        }
    }
    Some(out)
}

/// The area of the convex hull of `points` (Andrew's monotone chain).
fn hull_area(mut points: Vec<DVec2>) -> f64 {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return 0.0;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * points.len());
    for pass in [false, true] {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &DVec2>> = if pass {
            Box::new(points.iter().rev())
        } else {
            Box::new(points.iter())
        };
        for &p in ordered {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        // The chain's last point starts the other one.
        hull.pop();
    }
    let n = hull.len();
    0.5 * (0..n)
        .map(|i| hull[i].perp_dot(hull[(i + 1) % n]))
        .sum::<f64>()
        .abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An animal: a body on four thin legs 40 x 20 mm apart, standing on
    /// -Z, turned by `turn`.
    fn stand(turn: impl Fn(DVec3) -> DVec3) -> TriMesh {
        // The body, rounded: its outermost points on each side but the
        // bottom are single points, inside the legs' footprint.
        let mut vertices = vec![
            DVec3::new(20.0, 10.0, 10.0),
            DVec3::new(20.0, 10.0, 25.0),
            DVec3::new(2.0, 10.0, 17.5),
            DVec3::new(38.0, 10.0, 17.5),
            DVec3::new(20.0, 2.0, 17.5),
            DVec3::new(20.0, 18.0, 17.5),
        ];
        // Four legs down to 0 at its corners, 1 mm wide.
        for &(x, y) in &[(0.0, 0.0), (39.0, 0.0), (0.0, 19.0), (39.0, 19.0)] {
            for &(dx, dy) in &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                vertices.push(DVec3::new(x + dx, y + dy, 0.0));
            }
        }
        let n = vertices.len() as u32;
        TriMesh {
            vertices: vertices.into_iter().map(turn).collect(),
            triangles: (0..n - 2).map(|i| [i, i + 1, i + 2]).collect(),
        }
    }

    #[test]
    fn a_scan_standing_on_minus_y_read_z_up_gets_the_y_note() {
        // Saved +Y up: the file's (x, y, z) is the standing part's (x, z, -y).
        let yup = stand(|p| DVec3::new(p.x, p.z, -p.y));
        let note = note(&yup.vertices, &yup.triangles, UpAxis::Z, "cow.stl").expect("a note");
        assert!(
            note.starts_with("cow.stl: read +Z up, it rests on its -Y side"),
            "{note}"
        );
        assert!(note.ends_with("read it +Y up (--up-axis y)"), "{note}");
        // Standing on -Z as read: nothing to say.
        assert_eq!(
            super::note(&stand(|p| p).vertices, &[], UpAxis::Z, "cow.stl"),
            None
        );
    }

    /// A dome on a table, seen from above (its faces up), `turn`ed.
    fn dome(turn: impl Fn(DVec3) -> DVec3) -> TriMesh {
        let axis: Vec<f64> = (0..=40).map(f64::from).collect();
        let mut m = TriMesh::height_field(&axis, &axis, |x, y| {
            (12.0 - ((x - 20.0).powi(2) + (y - 20.0).powi(2)) / 12.0).max(0.0)
        });
        m.vertices.iter_mut().for_each(|v| *v = turn(*v));
        m
    }

    #[test]
    fn a_depth_cameras_scan_read_z_up_gets_the_minus_z_note() {
        // z the distance from a camera above: half a turn about X.
        let camera = dome(|p| DVec3::new(p.x, -p.y, 400.0 - p.z));
        let n = note(&camera.vertices, &camera.triangles, UpAxis::Z, "depth.ply").expect("a note");
        assert!(n.contains("rests on its +Z side"), "{n}");
        assert!(n.ends_with("read it -Z up (--up-axis -z)"), "{n}");
        // Seen from above, a flat top over a tilted base spreads widest at
        // its top as well: its faces are up, no note (review). Nor for a
        // cloud's points, which have no faces.
        let axis: Vec<f64> = (0..=50).map(f64::from).collect();
        let mesa = TriMesh::height_field(&axis, &axis, |x, y| {
            if (10.0..=40.0).contains(&x) && (10.0..=40.0).contains(&y) {
                10.0
            } else {
                0.1 * x
            }
        });
        assert_eq!(
            note(&mesa.vertices, &mesa.triangles, UpAxis::Z, "m.ply"),
            None
        );
        assert_eq!(note(&camera.vertices, &[], UpAxis::Z, "depth.xyz"), None);
        // The dome upright: none.
        let up = dome(|p| p);
        assert_eq!(note(&up.vertices, &up.triangles, UpAxis::Z, "d.ply"), None);
    }

    #[test]
    fn a_z_up_scan_read_y_up_gets_the_z_note() {
        // glTF read +Y up turns (x, y, z) to (x, -z, y): a part standing on
        // -Z in the file rests on +Y.
        let turned = stand(|p| DVec3::new(p.x, -p.z, p.y));
        let note = note(&turned.vertices, &turned.triangles, UpAxis::Y, "cad.glb").expect("a note");
        assert!(
            note.contains(
                "read +Y up (glTF's convention), it rests on its -Z (in the file's axes) side"
            ),
            "{note}"
        );
        assert!(note.ends_with("read it +Z up (--up-axis z)"), "{note}");
        // Lying flat as read (40 x 75 mm on the bed, 20 mm high, as QA's VR
        // controller lay, 124 x 181 x 82 mm) though it spreads widest on
        // that side: turned, it would stand on an end, 75 mm tall; no note
        // (QA round 18 F12).
        let flat = stand(|p| DVec3::new(p.x, -p.z * 3.0, p.y));
        assert_eq!(
            super::note(&flat.vertices, &flat.triangles, UpAxis::Y, "c.glb"),
            None
        );
    }

    #[test]
    fn a_cube_a_flat_film_and_a_sliver_get_no_note() {
        let cube = TriMesh {
            vertices: (0..8)
                .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
                .collect(),
            triangles: vec![[0, 1, 2], [4, 5, 6]],
        };
        assert_eq!(note(&cube.vertices, &cube.triangles, UpAxis::Z, "c"), None);
        // A film 0.2 mm thick lying flat: it rests on -Z (and +Z alike).
        let film = TriMesh {
            vertices: (0..400)
                .map(|i| {
                    let (x, y) = ((i % 20) as f64, (i / 20) as f64);
                    DVec3::new(x, y, 0.1 * (x * 0.7).sin() * (y * 0.5).cos())
                })
                .collect(),
            triangles: vec![[0, 1, 20]],
        };
        assert_eq!(note(&film.vertices, &film.triangles, UpAxis::Z, "f"), None);
        let sliver = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)],
            triangles: vec![[0, 1, 2]],
        };
        assert_eq!(
            note(&sliver.vertices, &sliver.triangles, UpAxis::Z, "s"),
            None
        );
    }

    /// A ring 120 mm across and 10 mm thick, its faces at y = 0 and 10:
    /// standing on its rim as read.
    fn ring() -> Vec<DVec3> {
        (0..72)
            .flat_map(|i| {
                let a = f64::from(i) * 5f64.to_radians();
                [40.0, 60.0].into_iter().flat_map(move |r| {
                    [0.0, 10.0].map(|y| DVec3::new(60.0 + r * a.cos(), y, 60.0 + r * a.sin()))
                })
            })
            .collect()
    }

    #[test]
    fn a_plate_standing_on_an_edge_gets_the_other_axis_note() {
        let n = note(&ring(), &[], UpAxis::Z, "ring.ply").unwrap();
        assert_eq!(
            n,
            "ring.ply: read +Z up, it stands on an edge, 120.0 x 10.0 x 120.0 mm and thinnest \
             along Y: it was likely saved with +Y up; if the part lies flat, read it +Y up \
             (--up-axis y)"
        );
        let n = note(&ring(), &[], UpAxis::Y, "ring.glb").unwrap();
        assert!(n.ends_with("read it +Z up (--up-axis z)"), "{n}");
        assert_eq!(note(&ring(), &[], UpAxis::NegZ, "ring.xyz"), None);
        // Lying flat, or thicker than the rule: no note.
        let flat: Vec<DVec3> = ring().iter().map(|p| DVec3::new(p.x, p.z, p.y)).collect();
        assert_eq!(note(&flat, &[], UpAxis::Z, "flat.ply"), None);
        let thick: Vec<DVec3> = ring()
            .iter()
            .map(|p| DVec3::new(p.x, 4.0 * p.y, p.z))
            .collect();
        assert_eq!(note(&thick, &[], UpAxis::Z, "thick.ply"), None);
    }

    #[test]
    fn hull_area_of_a_square_with_inner_and_repeated_points() {
        let pts = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 2.0),
            (0.0, 2.0),
            (1.0, 1.0),
            (2.0, 0.0),
            (1.0, 0.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
        assert!((hull_area(pts) - 4.0).abs() < 1e-12);
    }
}
