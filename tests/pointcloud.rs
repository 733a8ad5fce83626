//! Raw point clouds (issue 14): the demo part sampled as a scanner would
//! (heights on a 0.2 mm grid, none in the fiducial holes, 0.02 mm of
//! noise), written in every point-cloud format, meshed by the importer,
//! and compared with the mesh: the same fiducials and the same tool path.

use pcpp::demo::test_part;
use pcpp::fiducials::find_fiducials;
use pcpp::mesh::{import_mesh, ImportOptions, ImportedMesh, MeshFormat};
use pcpp::pipeline::{self, Plan, PlanSettings};
use pcpp::surface::Surface;
use pcpp::{DVec2, DVec3};

use crate::bruteforce::Rng;

/// Spacing of the sampled grid, mm.
const STEP: f64 = 0.2;
/// Noise added to each height, mm (uniform in +-NOISE).
const NOISE: f64 = 0.02;

/// The demo part as a profilometer sees it: the highest surface point on
/// each vertical line of a STEP grid, none where the line misses (the
/// fiducial holes), with noise on the height.
fn sampled_cloud() -> Vec<DVec3> {
    let surface = Surface::new(test_part::test_part()).unwrap();
    let n = (test_part::SIZE_MM / STEP).round() as usize;
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut pts = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let xy = DVec2::new(i as f64 * STEP, j as f64 * STEP);
            if let Some(z) = surface.highest_hit(xy) {
                pts.push(xy.extend(z + NOISE * (2.0 * rng.unit() - 1.0)));
            }
        }
    }
    pts
}

fn lzf_literal(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() + data.len() / 32 + 1);
    for chunk in data.chunks(32) {
        out.push((chunk.len() - 1) as u8);
        out.extend_from_slice(chunk);
    }
    out
}

/// The cloud in each format, with a file name that names it.
fn files(pts: &[DVec3]) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut xyz = String::new();
    let mut csv = String::from("x,y,z,nx,ny,nz\n");
    for p in pts {
        xyz += &format!("{:.4} {:.4} {:.4}\n", p.x, p.y, p.z);
        csv += &format!("{:.4},{:.4},{:.4},0,0,1\n", p.x, p.y, p.z);
    }
    out.push(("part.xyz".to_string(), xyz.clone().into_bytes()));
    out.push(("part.csv".to_string(), csv.into_bytes()));
    let n = pts.len();
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\ncomment points only\nelement vertex {n}\n\
         property float x\nproperty float y\nproperty float z\nproperty uchar red\nend_header\n"
    )
    .into_bytes();
    for p in pts {
        for v in p.to_array() {
            ply.extend_from_slice(&(v as f32).to_le_bytes());
        }
        ply.push(200);
    }
    out.push(("part-binary.ply".to_string(), ply));
    let mut ply_ascii = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty double x\nproperty double y\n\
         property double z\nend_header\n"
    );
    ply_ascii += &xyz;
    out.push(("part-ascii.ply".to_string(), ply_ascii.into_bytes()));
    let head = |data: &str| {
        format!(
            "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n\
             TYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n\
             DATA {data}\n"
        )
    };
    out.push((
        "part-ascii.pcd".to_string(),
        (head("ascii") + &xyz).into_bytes(),
    ));
    let mut bin = head("binary").into_bytes();
    let mut columns = Vec::with_capacity(12 * n);
    for p in pts {
        for v in p.to_array() {
            bin.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    for k in 0..3 {
        for p in pts {
            columns.extend_from_slice(&(p[k] as f32).to_le_bytes());
        }
    }
    out.push(("part-binary.pcd".to_string(), bin));
    let packed = lzf_literal(&columns);
    let mut comp = head("binary_compressed").into_bytes();
    comp.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    comp.extend_from_slice(&(columns.len() as u32).to_le_bytes());
    comp.extend_from_slice(&packed);
    out.push(("part-compressed.pcd".to_string(), comp));
    out
}

fn import(bytes: &[u8], name: &str) -> ImportedMesh {
    import_mesh(bytes, name, &ImportOptions::DEFAULT).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn plan(mesh: pcpp::mesh::TriMesh) -> Plan {
    let surface = Surface::new(mesh).unwrap();
    let drawn = pipeline::load_path(test_part::test_part_svg().as_bytes(), "demo.svg").unwrap();
    let settings = PlanSettings {
        placement: test_part::placement(),
        ..Default::default()
    };
    pipeline::plan(&surface, &drawn.subpaths, &settings).unwrap()
}

/// Distance from `p` to the polyline `line` (3-D).
fn to_polyline(p: DVec3, line: &[DVec3]) -> f64 {
    line.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let ab = b - a;
            let t = if ab.length_squared() > 0.0 {
                ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + ab * t).distance(p)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The mesh's three best fiducial candidates (`mesh_fids`) are among the
/// three best of `meshed`, each within `tol` mm.
fn assert_dots_found(
    mesh_fids: &[pcpp::fiducials::Fiducial],
    meshed: &pcpp::mesh::TriMesh,
    tol: f64,
    name: &str,
) {
    let fids = find_fiducials(meshed);
    for (k, f) in mesh_fids.iter().take(3).enumerate() {
        let nearest = fids
            .iter()
            .take(3)
            .map(|g| g.centroid.truncate().distance(f.centroid.truncate()))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < tol,
            "{name}: fiducial {k} at {} is {nearest:.3} mm from the cloud's best three",
            f.centroid
        );
    }
}

#[test]
fn the_demo_part_as_a_point_cloud_in_every_format_gives_the_meshs_fiducials_and_path() {
    let pts = sampled_cloud();
    let mesh = test_part::test_part();
    let mesh_fids = find_fiducials(&mesh);
    let mesh_plan = plan(mesh);
    for (name, bytes) in files(&pts) {
        let imported = import(&bytes, &name);
        let want = if name.ends_with(".pcd") {
            MeshFormat::Pcd
        } else if name.ends_with(".ply") {
            MeshFormat::Ply
        } else {
            MeshFormat::Xyz
        };
        assert_eq!(imported.format, want, "{name}");
        let info = imported
            .cloud
            .unwrap_or_else(|| panic!("{name}: not read as a cloud"));
        assert_eq!(info.points, pts.len(), "{name}");
        assert!((info.spacing_mm - STEP).abs() < 1e-3, "{name}: {info:?}");
        assert!((info.max_edge_mm - 3.0 * info.spacing_mm).abs() < 1e-12);
        // The three dots are the three best candidates, each within 0.1 mm.
        assert_dots_found(&mesh_fids, &imported.mesh, 0.1, &name);
        // The tool path: the plan on the meshed cloud against the mesh's.
        // Text and binary forms of one format mesh the same points, so the
        // path is planned for one file of each format.
        if !(name == "part.xyz" || name == "part-binary.ply" || name == "part-compressed.pcd") {
            continue;
        }
        let cloud_plan = plan(imported.mesh);
        let mut devs = Vec::new();
        for (a, b) in cloud_plan.pieces.iter().zip(&mesh_plan.pieces) {
            for p in &a.toolpath {
                devs.push(to_polyline(*p, &b.toolpath));
            }
        }
        assert_eq!(cloud_plan.pieces.len(), mesh_plan.pieces.len(), "{name}");
        devs.sort_by(f64::total_cmp);
        let pct = |q: f64| devs[((devs.len() - 1) as f64 * q).round() as usize];
        eprintln!(
            "{name}: tool path vs the mesh's: median {:.4}, 95% {:.4}, 99% {:.4}, max {:.4} mm \
             over {} points",
            pct(0.5),
            pct(0.95),
            pct(0.99),
            pct(1.0),
            devs.len()
        );
        assert!(
            pct(0.95) <= 0.05,
            "{name}: 95% of the path within {:.4}",
            pct(0.95)
        );
    }
}

#[test]
fn hostile_point_clouds_get_clear_errors() {
    let mut cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "ragged.xyz",
            b"1 2 3\n4 5\n".to_vec(),
            "ragged.xyz:2: 2 value(s)",
        ),
        (
            "text.csv",
            b"1,2,3\n4,five,6\n".to_vec(),
            "text.csv:2: 'five'",
        ),
        ("one.xyz", b"1 2 3\n".to_vec(), "at least 3 points"),
        (
            "line.xyz",
            (0..50)
                .map(|i| format!("{i} {i} 0\n"))
                .collect::<String>()
                .into_bytes(),
            "one line",
        ),
        (
            "nan.xyz",
            b"1 2 3\n4 5 nan\n".to_vec(),
            "nan.xyz:2: z is NaN",
        ),
        (
            "noface.ply",
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
              property float z\nend_header\n0 0 0\n1 1 1\n"
                .to_vec(),
            "at least 3 points",
        ),
    ];
    // A binary PCD point at infinity: the import's check names the point.
    let mut inf = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 3\nDATA binary\n".to_vec();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, f32::INFINITY, 0.0],
    ] {
        for v in p {
            inf.extend_from_slice(&v.to_le_bytes());
        }
    }
    cases.push(("inf.pcd", inf, "vertex 2 has a non-finite coordinate (inf)"));
    for (name, bytes, want) in cases {
        let e = import_mesh(&bytes, name, &ImportOptions::DEFAULT)
            .err()
            .unwrap_or_else(|| panic!("{name} was accepted"))
            .to_string();
        assert!(e.contains(want), "{name}: {e}");
    }
}

/// 10^6 identical points (the issue asks 10^7 of the importer; a million
/// keeps the debug test quick and takes the same path): one error, no
/// panic, no triangulation of a million copies.
#[test]
fn a_million_identical_points_are_one_place() {
    let bytes = "1.5 2.5 3.5\n".repeat(1_000_000).into_bytes();
    let e = import_mesh(&bytes, "same.xyz", &ImportOptions::DEFAULT)
        .expect_err("accepted")
        .to_string();
    assert!(e.contains("only 1 place"), "{e}");
}

#[test]
fn a_larger_edge_limit_closes_the_fiducial_holes() {
    let pts = sampled_cloud();
    let text: String = pts
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    let options = ImportOptions {
        max_edge_mm: Some(2.0),
        ..ImportOptions::DEFAULT
    };
    let m = import_mesh(text.as_bytes(), "part.xyz", &options).unwrap();
    assert!(
        !m.warnings.iter().any(|w| w.contains("--max-edge")),
        "{:?}",
        m.warnings
    );
    // Given for a mesh, the limit is said not to be used (a QA run found
    // it dropped silently).
    let ply = pcpp::demo::demo_scan_bytes();
    let mesh = import_mesh(&ply, "part.ply", &options).unwrap();
    let said: Vec<&String> = mesh
        .warnings
        .iter()
        .filter(|w| w.contains("--max-edge"))
        .collect();
    assert!(
        said.len() == 1
            && said[0].starts_with("part.ply: ")
            && said[0].contains("2 mm, is not used"),
        "{:?}",
        mesh.warnings
    );
    let info = m.cloud.unwrap();
    assert!(info.max_edge_given && info.max_edge_mm == 2.0);
    let fids = find_fiducials(&m.mesh);
    for f in test_part::FIDUCIALS_MM {
        assert!(
            fids.iter()
                .all(|g| g.centroid.truncate().distance(f.truncate()) > 0.3),
            "the hole at {f} stayed open with a 2 mm limit"
        );
    }
}

/// A pebble as a turntable scanner gives it: points on the whole surface
/// of an ellipsoid of semi-axes (10, 10, 4) mm resting on z = 0, about
/// 0.25 mm apart, top and underside; and the ellipsoid as a fine mesh.
fn pebble() -> (String, pcpp::mesh::TriMesh) {
    let text = pcpp::demo::workloads::to_xyz(&pcpp::demo::pebble_cloud(0.25));
    let at = pcpp::demo::pebble_point;
    // The true surface, finer than the cloud: 200 x 400 quads.
    let (n, m) = (200usize, 400usize);
    let mut mesh = pcpp::mesh::TriMesh::default();
    for i in 0..=n {
        for j in 0..m {
            let phi = std::f64::consts::PI * i as f64 / n as f64;
            mesh.vertices
                .push(at(phi, std::f64::consts::TAU * j as f64 / m as f64));
        }
    }
    for i in 0..n {
        for j in 0..m {
            let v = |i: usize, j: usize| (i * m + j % m) as u32;
            mesh.triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            mesh.triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    (text, mesh)
}

/// A whole object's cloud (issue: a scanned bunny's cloud was meshed
/// across its top and underside, printed 19 of 414 mm, or with a larger
/// edge limit came 0.037 mm from the real top): the underside is left
/// out, the part rests on its lowest point when placed on the bed, the
/// import says so, and G-code is written only with the risk accepted,
/// since between the points the real surface may be higher. Over the
/// pebble's top the G-code written then keeps tol from the true surface,
/// by the independent brute-force check.
#[test]
fn a_whole_objects_cloud_is_meshed_from_above_and_its_gcode_needs_the_risk_accepted() {
    use pcpp::gcode::MachineProfile;
    use pcpp::job::{prepare_scan, run_on, RegistrationSettings};
    use pcpp::placement::ScanPlacement;
    use pcpp::svg::Placement;

    let (text, truth) = pebble();
    let profile = MachineProfile::builtin("marlin").unwrap();
    let registration = RegistrationSettings {
        scan_placement: ScanPlacement::on_bed(&profile),
        ..Default::default()
    };
    let scan = prepare_scan(
        text.as_bytes(),
        "pebble.xyz",
        &ImportOptions::DEFAULT,
        &registration,
    )
    .unwrap();
    let info = scan.cloud.unwrap();
    assert!(info.hidden > 1000, "{info:?}");
    assert!(
        scan.warnings
            .iter()
            .any(|w| w.contains("pebble.xyz") && w.contains("under the surface seen from above")),
        "{:?}",
        scan.warnings
    );
    // Resting on its lowest point (a hidden one): that point is on the bed.
    let m = scan.registration.matrix;
    let bottom = m.transform_point3(DVec3::ZERO);
    assert!(bottom.z.abs() < 1e-9, "the pebble's bottom is at {bottom}");
    let (lo, _) = scan.surface.bbox();
    assert!(lo.z > 0.5, "the meshed top reaches down to {lo}");

    // A 12 mm line across the top, through its middle.
    let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="12mm" height="2mm" viewBox="0 0 12 2"><path d="M0 1 H12" fill="none" stroke="black"/></svg>"#;
    let centre = m.transform_point3(DVec3::new(0.0, 0.0, 0.0)).truncate();
    let settings = PlanSettings {
        placement: Placement {
            offset_mm: centre - DVec2::new(6.0, 1.0),
            ..Placement::IDENTITY
        },
        ..Default::default()
    };
    let e = run_on(&scan, svg, "line.svg", &settings, &profile, false)
        .err()
        .expect("G-code written for a whole object's cloud");
    assert!(matches!(e, pcpp::Error::WholeObjectCloud { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("pebble.xyz")
            && msg.contains("as a mesh")
            // (QA round 11 L3: a depth camera's single frame was told
            // only of a whole object and its scanner's mesh export.)
            && msg.contains("or a camera's view in perspective")
            && msg.contains("or scan the part straight from above"),
        "{msg}"
    );

    let out = run_on(&scan, svg, "line.svg", &settings, &profile, true).unwrap();
    // The acceptance is said where the operator reads it: the program's
    // header and the report (they had said nothing: the header's safe
    // motion line read as a clean plan's, `risk_accepted` was false).
    assert!(out.report.motion.risk_accepted);
    assert!(
        out.report.motion.accepted_risks[0].contains("whole object's point cloud"),
        "{:?}",
        out.report.motion.accepted_risks
    );
    let header: Vec<&str> = out
        .gcode
        .lines()
        .take_while(|l| l.starts_with(';'))
        .collect();
    assert!(
        header.iter().any(|l| l.contains("safe motion")
            && l.contains("WARNING: written only because the risk was accepted")
            && l.contains("whole object's point cloud")),
        "{header:#?}"
    );
    let mut truth = truth;
    for v in &mut truth.vertices {
        *v = m.transform_point3(*v);
    }
    let nozzle = settings.nozzle;
    let oracle = crate::bruteforce::check_gcode(
        &out.gcode,
        &truth,
        nozzle.outer_diameter_mm,
        settings.process.tolerance_mm,
    );
    assert_eq!(oracle.too_close, 0, "{oracle:?}");
    assert!(
        oracle.min_distance_mm.is_finite(),
        "nothing was near: {oracle:?}"
    );
}

/// The demo part sampled at random places (a photogrammetric or lidar
/// cloud's points are spread so, not on a grid), as densely as the 0.2 mm
/// grid, none in the fiducial holes. The default edge limit, 3 x the
/// median nearest-neighbour spacing, left out more than a third of the
/// triangles between such points: the part was meshed full of holes and
/// the drawing planned in many pieces. Now the limit keeps 99.9 % of the
/// triangulation, and the part's own holes stay: its three dots are found
/// where the mesh has them, and the drawing plans in the mesh's pieces.
#[test]
fn regression_a_randomly_spread_cloud_was_meshed_full_of_holes() {
    let surface = Surface::new(test_part::test_part()).unwrap();
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let n = ((test_part::SIZE_MM / STEP) as usize + 1).pow(2);
    let mut text = String::new();
    for _ in 0..n {
        let xy = DVec2::new(rng.unit(), rng.unit()) * test_part::SIZE_MM;
        if let Some(z) = surface.highest_hit(xy) {
            let z = z + NOISE * (2.0 * rng.unit() - 1.0);
            text += &format!("{:.4} {:.4} {:.4}\n", xy.x, xy.y, z);
        }
    }
    let imported = import(text.as_bytes(), "random.xyz");
    let info = imported.cloud.unwrap();
    assert!(info.uneven && !info.max_edge_given, "{info:?}");
    assert!(info.max_edge_mm > 3.0 * info.spacing_mm, "{info:?}");
    assert!(info.to_string().contains("spread unevenly"), "{info}");
    let mesh = test_part::test_part();
    let mesh_fids = find_fiducials(&mesh);
    assert_dots_found(&mesh_fids, &imported.mesh, 0.2, "random.xyz");
    let mesh_plan = plan(mesh);
    let cloud_plan = plan(imported.mesh);
    assert_eq!(cloud_plan.pieces.len(), mesh_plan.pieces.len());
}

/// QA round 11 L4: a cloud of 397 points 4 mm apart (the Stanford bunny's
/// `bun0.pcd`) was planned with no word that between its points, wider
/// apart than the nozzle, the surface is the meshing's flat guess. A
/// gently curved plate sampled every 2 mm is warned of, in the report and
/// the G-code's header; sampled every 0.5 mm it is not.
#[test]
fn a_cloud_sparser_than_the_nozzle_is_warned_of() {
    use pcpp::gcode::MachineProfile;
    use pcpp::job::{prepare_scan, run_on, RegistrationSettings};
    use pcpp::svg::Placement;

    let profile = MachineProfile::builtin("marlin").unwrap();
    let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="2mm" viewBox="0 0 20 2"><path d="M0 1 H20" fill="none" stroke="black"/></svg>"#;
    let settings = PlanSettings {
        placement: Placement {
            offset_mm: DVec2::new(10.0, 21.0),
            ..Placement::IDENTITY
        },
        ..Default::default()
    };
    let warned = |step: f64| {
        let n = (40.0 / step) as usize;
        let points: Vec<DVec3> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i as f64 * step, j as f64 * step)))
            .map(|(x, y)| DVec3::new(x, y, 5.0 + 0.5 * (x / 7.0).sin()))
            .collect();
        let text = pcpp::demo::workloads::to_xyz(&points);
        let scan = prepare_scan(
            text.as_bytes(),
            "plate.xyz",
            &ImportOptions::DEFAULT,
            &RegistrationSettings::default(),
        )
        .unwrap();
        let out = run_on(&scan, svg, "line.svg", &settings, &profile, false).unwrap();
        let says = |w: &str| {
            w.contains("plate.xyz: the point cloud's points lie a median")
                && w.contains("more than the nozzle's outer diameter (0.908 mm)")
        };
        let in_report = out.report.warnings.iter().any(|w| says(w));
        assert_eq!(
            in_report,
            out.gcode.lines().any(|l| l.starts_with(';') && says(l)),
            "{step}"
        );
        in_report
    };
    assert!(warned(2.0));
    assert!(!warned(0.5));
}
