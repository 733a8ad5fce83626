//! Integration tests: safe motion (spec section 6f). Every claim that the
//! nozzle does not touch the part is checked here by the independent
//! brute-force oracle of `bruteforce.rs`, which follows every move of the
//! written G-code and shares no code with the planner.

use proptest::prelude::*;

use pcpp::demo::parts::DemoPart;
use pcpp::demo::test_part;
use pcpp::gcode::MachineProfile;
use pcpp::job::{prepare_scan, run_on, JobOutput, PreparedScan, RegistrationSettings};
use pcpp::mesh::{ImportOptions, TriMesh};
use pcpp::pipeline::PlanSettings;
use pcpp::planners::PlannerKind;
use pcpp::svg::Placement;
use pcpp::{DVec3, Error, Nozzle, Process};

use crate::bruteforce::{check_gcode, SafetyReport};

const DO: f64 = Nozzle::DEFAULT.outer_diameter_mm;
const TOL: f64 = Process::DEFAULT.tolerance_mm;

fn marlin() -> MachineProfile {
    MachineProfile::builtin("marlin").expect("marlin profile")
}

/// `mesh` (already in the printer frame) prepared as a PLY file.
fn prepared(mesh: &TriMesh) -> Result<PreparedScan, Error> {
    let bytes = pcpp::demo::to_binary_ply(mesh);
    prepare_scan(
        &bytes,
        "part.ply",
        &ImportOptions::DEFAULT,
        &RegistrationSettings::default(),
    )
}

/// Plans `svg` on `mesh` (already in the printer frame) with `planner`.
fn plan(
    mesh: &TriMesh,
    svg: &str,
    placement: Placement,
    planner: PlannerKind,
    accept_risk: bool,
) -> Result<JobOutput, Error> {
    let scan = prepared(mesh)?;
    let settings = PlanSettings {
        placement,
        planner,
        ..PlanSettings::default()
    };
    run_on(
        &scan,
        svg.as_bytes(),
        "path.svg",
        &settings,
        &marlin(),
        accept_risk,
    )
}

fn describe(r: &SafetyReport) -> String {
    format!(
        "{} moves, {} samples, min distance {:.4} mm, {} too close, deepest {:.3} mm, first: {:?}",
        r.moves,
        r.samples,
        r.min_distance_mm,
        r.too_close,
        r.deepest_mm,
        r.first_too_close.first()
    )
}

/// The guarded planners' G-code keeps tol along every move on the test
/// part and every generated substrate, by the oracle; and the core's own
/// check, written in the G-code header and the report, agrees.
#[test]
fn guarded_planners_never_touch_any_demo_part_along_their_moves() {
    for part in DemoPart::ALL {
        let mesh = part.mesh();
        for planner in [PlannerKind::Even, PlannerKind::PcppGuarded] {
            let out = plan(&mesh, &part.svg(), part.placement(), planner, false)
                .unwrap_or_else(|e| panic!("{part} {planner}: {e}"));
            let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
            eprintln!("{part} {planner}: {}", describe(&oracle));
            assert_eq!(
                oracle.too_close,
                0,
                "{part} {planner}: {}",
                describe(&oracle)
            );
            assert!(oracle.min_distance_mm >= TOL, "{part} {planner}");
            assert!(oracle.moves > 100, "{part} {planner}: {}", oracle.moves);
            let m = &out.report.motion;
            assert_eq!(m.program.touching_moves, 0, "{part} {planner}");
            assert!(!m.risk_accepted);
            assert!(
                m.program.min_clearance_mm.unwrap() >= TOL,
                "{part} {planner}"
            );
            let header = out.gcode.lines().find(|l| l.contains("safe motion:"));
            assert!(
                header.is_some_and(|l| l.contains("min clearance") && !l.contains("WARNING")),
                "{part} {planner}: {header:?}"
            );
        }
    }
}

/// Issue 11's example: the guarded planner's demo G-code moved from
/// (15.446, 16, 5.603) to (16.230, 16, 7.603), both ends clear of the
/// region-1 block, the straight line between them through its edge.
#[test]
fn demo_move_through_the_region_1_block_edge_is_caught_and_no_longer_planned() {
    let mesh = test_part::test_part();
    let cut = "G90\nG21\nG0 X15.446 Y16 Z5.603\nG1 X16.230 Y16 Z7.603\n";
    let oracle = check_gcode(cut, &mesh, DO, TOL);
    assert!(oracle.too_close > 0, "{}", describe(&oracle));
    assert!(oracle.deepest_mm > 1.0, "{}", describe(&oracle));
    // The core's check finds it too, by line.
    let surface = pcpp::surface::Surface::new(mesh.clone()).unwrap();
    let c = pcpp::motion::Clearance::new(&Nozzle::DEFAULT, TOL);
    let a = DVec3::new(15.446, 16.0, 5.603);
    let b = DVec3::new(16.230, 16.0, 7.603);
    let sum = pcpp::motion::check_moves(&surface, [(a, b, Some(4))], &c);
    assert_eq!(sum.touching_moves, 1);
    assert_eq!(sum.touching[0].line, Some(4));
    assert!(sum.touching[0].rise_mm > 1.0, "{:?}", sum.touching[0]);
    // Every planner the page offers by default now climbs that step
    // without cutting it.
    for planner in [PlannerKind::Even, PlannerKind::PcppGuarded] {
        let out = plan(
            &mesh,
            &test_part::test_part_svg(),
            test_part::placement(),
            planner,
            false,
        )
        .unwrap();
        let near: String = out
            .gcode
            .lines()
            .filter(|l| l.contains("Y16.000"))
            .collect::<Vec<_>>()
            .join("\n");
        let oracle = check_gcode(&format!("G90\n{near}\n"), &mesh, DO, TOL);
        assert_eq!(oracle.too_close, 0, "{planner}: {}", describe(&oracle));
    }
}

/// QA round 6 F0: a plunge straight down beside a block, into it: the
/// wall's top edge crosses the tip's disk at the bottom of the move, no
/// corner under it. The core's check took the edge at the move's start
/// (the top) and called the program clear; the oracle and the core now
/// both find the move too close, by line.
#[test]
fn regression_a_plunge_beside_a_wall_was_checked_at_its_top() {
    let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // A floor at z = 0 from x = 0 to 5, a block 2 mm high from x = 5 to
    // 10 (its wall at x = 5), 10 mm deep: large triangles, their corners
    // far from the plunge.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(5.0, 0.0, 0.0),
        v(5.0, 10.0, 0.0),
        v(0.0, 10.0, 0.0),
        v(5.0, 0.0, 2.0),
        v(10.0, 0.0, 2.0),
        v(10.0, 10.0, 2.0),
        v(5.0, 10.0, 2.0),
    ];
    let triangles = vec![
        [0, 1, 2],
        [0, 2, 3],
        [4, 5, 6],
        [4, 6, 7],
        // The wall, facing -X.
        [1, 7, 2],
        [1, 4, 7],
    ];
    let mesh = TriMesh {
        vertices,
        triangles,
    };
    // Down at x = 4.7: the wall's top edge 0.3 mm from the axis, inside
    // the 0.454 mm tip; the tip ends 1 mm below the block's top.
    let plunge = "G90\nG21\nG0 X4.7 Y5 Z20\nG1 X4.7 Y5 Z5\nG1 X4.7 Y5 Z1\n";
    let oracle = check_gcode(plunge, &mesh, DO, TOL);
    assert!(oracle.too_close > 0, "{}", describe(&oracle));
    let surface = pcpp::surface::Surface::new(mesh.clone()).unwrap();
    let c = pcpp::motion::Clearance::new(&Nozzle::DEFAULT, TOL);
    let down = [(v(4.7, 5.0, 5.0), v(4.7, 5.0, 1.0), Some(5))];
    let sum = pcpp::motion::check_moves(&surface, down, &c);
    assert_eq!(sum.touching_moves, 1, "{sum:?}");
    assert_eq!(sum.touching[0].line, Some(5));
    // 1 mm into the block, and tol more.
    assert!(
        (sum.touching[0].rise_mm - 1.0 - TOL).abs() < 1e-6,
        "{:?}",
        sum.touching[0]
    );
}

/// `slope` on the stepped block cuts the steps: refused, naming a move
/// with its line and depth; accepted, written with a warning in the header,
/// and the oracle confirms the touching.
#[test]
fn slope_on_the_stepped_block_is_refused_unless_the_risk_is_accepted() {
    let part = DemoPart::SteppedBlock;
    let mesh = part.mesh();
    let e = plan(
        &mesh,
        &part.svg(),
        part.placement(),
        PlannerKind::Slope,
        false,
    )
    .err()
    .expect("slope must be refused");
    let text = e.to_string();
    assert!(matches!(e, Error::Touching(_)), "{text}");
    assert!(text.contains("G-code move(s) of planner slope"), "{text}");
    // The lines are the unwritten program's (a CLI run printed them after
    // the drawing's file name, as if they were its lines).
    assert!(text.contains("; G-code line "), "{text}");
    assert!(text.contains("mm higher there"), "{text}");
    assert!(text.contains("--accept-risk"), "{text}");
    let Error::Touching(t) = &e else {
        unreachable!()
    };
    let first = &t.summary.touching[0];
    let line = first.line.expect("a line number");

    let out = plan(
        &mesh,
        &part.svg(),
        part.placement(),
        PlannerKind::Slope,
        true,
    )
    .unwrap();
    let header = out
        .gcode
        .lines()
        .find(|l| l.contains("safe motion:"))
        .unwrap();
    assert!(
        header.contains("WARNING") && header.contains("risk was accepted"),
        "{header}"
    );
    assert!(out.report.motion.risk_accepted);
    // The named line is the move it says.
    let written = out.gcode.lines().nth(line - 1).unwrap();
    let [x, y, z] = first.to;
    assert!(
        written.contains(&format!("X{x:.3} Y{y:.3} Z{z:.3}")),
        "line {line}: {written} vs {first:?}"
    );
    let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
    assert!(oracle.too_close > 0, "{}", describe(&oracle));
}

/// Where the core's check says the paper planners' moves touch, the
/// oracle finds it too (and the other way round), on every part.
#[test]
fn core_check_and_oracle_agree_on_the_paper_planners() {
    for part in DemoPart::ALL {
        let mesh = part.mesh();
        for planner in [PlannerKind::Constant, PlannerKind::Pcpp] {
            let out = plan(&mesh, &part.svg(), part.placement(), planner, true).unwrap();
            let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
            let core = out.report.motion.program.touching_moves;
            eprintln!(
                "{part} {planner}: core {core} touching moves; oracle {}",
                describe(&oracle)
            );
            assert_eq!(core > 0, oracle.too_close > 0, "{part} {planner}");
        }
    }
}

// ------------------------------------------------------------ properties

/// A random substrate on a 24 x 24 mm plate at z = 5: a step, a dimple or a
/// crease (ridge or valley), with its size drawn at random.
#[derive(Debug, Clone)]
enum Feature {
    /// A step of `height` (up or down) at x = `at`.
    Step { at: f64, height: f64 },
    /// A spherical dimple of radius `radius`, `depth` deep, at `centre`.
    Dimple {
        centre: (f64, f64),
        radius: f64,
        depth: f64,
    },
    /// A crease along y at x = `at`, flanks at `angle_deg`, `height` high
    /// (negative: a valley).
    Crease {
        at: f64,
        angle_deg: f64,
        height: f64,
    },
}

const SIZE: f64 = 24.0;

impl Feature {
    fn height(&self, x: f64, y: f64) -> f64 {
        5.0 + match *self {
            Feature::Step { at, height } => {
                if x >= at {
                    height.max(0.0)
                } else {
                    (-height).max(0.0)
                }
            }
            Feature::Dimple {
                centre,
                radius,
                depth,
            } => {
                let q = (x - centre.0).powi(2) + (y - centre.1).powi(2);
                // A ball of `radius` sunk so its lowest point is `depth`
                // below the plate: 2 mm of plate under it.
                let c = 2.0 - depth + radius;
                if q < radius * radius {
                    let z = c - (radius * radius - q).sqrt();
                    z.min(2.0)
                } else {
                    2.0
                }
            }
            Feature::Crease {
                at,
                angle_deg,
                height,
            } => {
                let run = height.abs() / angle_deg.to_radians().tan();
                let u = (1.0 - (x - at).abs() / run).max(0.0);
                3.0 + height * u
            }
        }
    }

    fn mesh(&self) -> TriMesh {
        // 0.1 mm across the features' direction, with a step's wall
        // coordinate repeated (evaluated either side) for a true wall.
        let mut xs: Vec<f64> = (0..=240).map(|i| i as f64 * 0.1).collect();
        if let Feature::Step { at, .. } = *self {
            xs.retain(|x| (x - at).abs() > 1e-6);
            xs.push(at);
            xs.push(at);
            xs.sort_by(f64::total_cmp);
        }
        let ys: Vec<f64> = (0..=48).map(|i| i as f64 * 0.5).collect();
        let w = xs.len();
        let mut m = TriMesh::default();
        for &y in &ys {
            for (i, &x) in xs.iter().enumerate() {
                let past = i > 0 && xs[i - 1] == x;
                let xe = if past { x + 1e-7 } else { x - 1e-7 };
                m.vertices.push(DVec3::new(x, y, self.height(xe, y)));
            }
        }
        for j in 0..ys.len() - 1 {
            for i in 0..w - 1 {
                let a = (j * w + i) as u32;
                let (b, c, d) = (a + 1, a + 1 + w as u32, a + w as u32);
                for t in [[a, b, c], [a, c, d]] {
                    let [p, q, r] = t.map(|k| m.vertices[k as usize]);
                    if (q - p).cross(r - p).length() > 1e-12 {
                        m.triangles.push(t);
                    }
                }
            }
        }
        m
    }
}

fn feature() -> impl Strategy<Value = Feature> {
    prop_oneof![
        (6.0f64..18.0, prop_oneof![0.5f64..3.0, -3.0f64..-0.5])
            .prop_map(|(at, height)| Feature::Step { at, height }),
        ((8.0f64..16.0, 8.0f64..16.0), 1.0f64..3.0, 0.2f64..1.0).prop_map(|(centre, radius, k)| {
            Feature::Dimple {
                centre,
                radius,
                depth: k * radius,
            }
        }),
        (
            8.0f64..16.0,
            20.0f64..75.0,
            prop_oneof![0.5f64..3.0, -2.5f64..-0.5]
        )
            .prop_map(|(at, angle_deg, height)| Feature::Crease {
                at,
                angle_deg,
                height
            }),
    ]
}

/// A straight line through the plate's middle at `angle`, or an arc of
/// radius `radius` around it, as SVG in mm (y down, the page 24 mm high).
fn path_svg(straight: bool, angle_deg: f64, radius: f64) -> String {
    let a = angle_deg.to_radians();
    let (cx, cy) = (SIZE / 2.0, SIZE / 2.0);
    let d = if straight {
        let (dx, dy) = (9.0 * a.cos(), 9.0 * a.sin());
        format!(
            "M {} {} L {} {}",
            cx - dx,
            SIZE - (cy - dy),
            cx + dx,
            SIZE - (cy + dy)
        )
    } else {
        let (x0, y0) = (cx + radius * a.cos(), cy + radius * a.sin());
        let (x1, y1) = (cx - radius * a.cos(), cy - radius * a.sin());
        format!(
            "M {x0} {} A {radius} {radius} 0 0 1 {x1} {}",
            SIZE - y0,
            SIZE - y1
        )
    };
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{SIZE}mm\" height=\"{SIZE}mm\" \
         viewBox=\"0 0 {SIZE} {SIZE}\"><path d=\"{d}\" stroke=\"black\" fill=\"none\"/></svg>"
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random steps, dimples and creases under random straight and curved
    /// paths: the default planner's G-code never comes within tol of the
    /// surface along any move, by the oracle.
    #[test]
    fn default_planner_never_touches_random_substrates(
        f in feature(),
        straight in any::<bool>(),
        angle in 0.0f64..360.0,
        radius in 3.0f64..9.0,
    ) {
        let mesh = f.mesh();
        let svg = path_svg(straight, angle, radius);
        let placement = Placement { offset_mm: pcpp::DVec2::new(0.0, SIZE), ..Placement::IDENTITY };
        let out = plan(&mesh, &svg, placement, PlannerKind::default(), false)
            .map_err(|e| TestCaseError::fail(format!("{f:?}: {e}")))?;
        let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
        prop_assert_eq!(oracle.too_close, 0, "{:?}: {}", f, describe(&oracle));
        prop_assert_eq!(out.report.motion.program.touching_moves, 0);
    }
}

/// A scan placed on the bed and then moved down (Move Z -50 in the page)
/// wrote G-code 50 mm into a part standing on the bed, "clear" by the
/// check on the moved scan (found by a QA run). It is refused by name, and
/// written only with the risk accepted, which its header then says.
#[test]
fn regression_a_scan_moved_below_the_bed_wrote_gcode_into_the_part() {
    use pcpp::placement::{Bed, ScanPlacement};
    let bytes = pcpp::demo::to_binary_ply(&test_part::test_part());
    let on_bed = |dz: f64| RegistrationSettings {
        scan_placement: ScanPlacement::OnBed {
            bed: Bed::of_profile(&marlin()),
            rotation_deg: 0.0,
            offset_mm: DVec3::new(0.0, 0.0, dz),
        },
        ..RegistrationSettings::default()
    };
    let settings = PlanSettings {
        // The demo drawing on the part, which the bed's middle now holds.
        placement: Placement {
            offset_mm: pcpp::DVec2::new(70.0, 150.0),
            ..test_part::placement()
        },
        ..PlanSettings::default()
    };
    let run = |dz: f64, accept_risk: bool| {
        let scan = prepare_scan(&bytes, "part.ply", &ImportOptions::DEFAULT, &on_bed(dz)).unwrap();
        let svg = test_part::test_part_svg();
        run_on(
            &scan,
            svg.as_bytes(),
            "lines.svg",
            &settings,
            &marlin(),
            accept_risk,
        )
    };
    // On the bed, or raised: planned as before.
    for dz in [0.0, 2.0] {
        let out = run(dz, false).unwrap();
        assert!(out.report.motion.accepted_risks.is_empty());
    }
    let e = run(-0.5, false)
        .err()
        .expect("G-code written below the bed");
    assert!(matches!(e, Error::BelowBed { .. }), "{e}");
    assert!(e.to_string().contains("moved 0.500 mm down"), "{e}");
    let out = run(-0.5, true).unwrap();
    assert!(
        out.gcode
            .contains("the scan's placement on the bed moves it 0.500 mm below the bed"),
        "{}",
        &out.gcode[..1500]
    );
}

/// A needle modelled as triangles of no area (a vertical segment, as
/// three collinear corners, and as a repeated corner) was dropped at
/// import: the nozzle was driven through it with a clearance of 0.603 mm
/// reported. Kept as the segments they are, the moves pass over it, by the
/// oracle, which measures the needle as the triangles the file gives.
#[test]
fn regression_a_needle_of_zero_area_triangles_is_cleared() {
    // Around (50, 50), inside the build volume.
    let corner = |x: f64, y: f64| DVec3::new(50.0 + x, 50.0 + y, 0.0);
    let (a, b, c, d) = (
        corner(-20.0, -20.0),
        corner(20.0, -20.0),
        corner(20.0, 20.0),
        corner(-20.0, 20.0),
    );
    let mut triangles = vec![[a, b, c], [a, c, d]];
    let tip = DVec3::new(50.3, 50.05, 3.0);
    triangles.push([
        DVec3::new(50.3, 50.05, 0.0),
        DVec3::new(50.3, 50.05, 1.5),
        tip,
    ]);
    let post = DVec3::new(46.0, 49.95, 2.0);
    let foot = DVec3::new(46.0, 49.95, 0.0);
    triangles.push([foot, foot, post]);
    let mesh = TriMesh {
        vertices: triangles.iter().flatten().copied().collect(),
        triangles: (0..triangles.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect(),
    };
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="2mm" viewBox="0 0 20 2"><path d="M0,1 H20" stroke="black" fill="none"/></svg>"#;
    let placement = Placement {
        offset_mm: pcpp::DVec2::new(40.0, 51.0),
        ..Placement::default()
    };
    for planner in [PlannerKind::Even, PlannerKind::PcppGuarded] {
        let out = plan(&mesh, svg, placement, planner, false)
            .unwrap_or_else(|e| panic!("{planner}: {e}"));
        let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
        assert_eq!(oracle.too_close, 0, "{planner}: {}", describe(&oracle));
        assert!(
            out.report
                .warnings
                .iter()
                .any(|w| w.contains("2 degenerate triangle(s)")),
            "{:?}",
            out.report.warnings
        );
        // Over the needle: every move that crosses its x does so at its
        // tip's height plus tol at least (its lower end, in a straight
        // line over).
        let points: Vec<(f64, f64)> = out
            .gcode
            .lines()
            .filter(|l| l.starts_with("G1 ") || l.starts_with("G0 "))
            .filter_map(|l| {
                let word = |c: char| {
                    l.split_whitespace()
                        .find_map(|w| w.strip_prefix(c)?.parse::<f64>().ok())
                };
                Some((word('X')?, word('Z')?))
            })
            .collect();
        let crossing: Vec<f64> = points
            .windows(2)
            .filter(|w| w[0].0.min(w[1].0) <= tip.x && tip.x <= w[0].0.max(w[1].0))
            .map(|w| w[0].1.min(w[1].1))
            .collect();
        assert!(
            !crossing.is_empty(),
            "{planner}: no move crosses the needle"
        );
        for z in crossing {
            assert!(
                z >= tip.z + TOL,
                "{planner}: a move crosses the needle at z {z}"
            );
        }
    }
}

/// A profile's blocks were written as they were, and the header claimed the
/// planned moves' clearance: an `end` with `G1 Z0` drove the nozzle into
/// the part after the print, a dispense command with `G1 Z-0.5` at every
/// path start. The end block's moves are checked with the program's; a
/// dispense command that moves is refused.
#[test]
fn regression_profile_blocks_that_move_into_the_part_are_refused() {
    let mesh = test_part::test_part();
    let scan = prepared(&mesh).unwrap();
    let settings = PlanSettings {
        placement: test_part::placement(),
        ..PlanSettings::default()
    };
    let svg = test_part::test_part_svg();
    let run = |profile: &MachineProfile, accept_risk: bool| {
        run_on(
            &scan,
            svg.as_bytes(),
            "lines.svg",
            &settings,
            profile,
            accept_risk,
        )
    };
    // A user's file (QA round 19 F4: named "marlin" inside, it read as
    // the built-in profile, and the refusal blamed the planner).
    let text = marlin().to_json().unwrap();
    let mut end = MachineProfile::from_json(&text, "lab-bench.json").unwrap();
    end.end = vec!["M107".into(), "G1 Z0".into(), "M84".into()];
    let e = run(&end, false)
        .err()
        .expect("an end block into the part written");
    let said = e.to_string();
    assert!(
        matches!(e, Error::Gcode(_))
            && said.contains("machine profile lab-bench.json, field `end`")
            && said.contains("after the print")
            && !said.contains("planner"),
        "{said}"
    );
    let line: usize = said
        .split("G-code line ")
        .nth(1)
        .and_then(|rest| rest.split(':').next())
        .and_then(|n| n.parse().ok())
        .expect("the end block's line");
    let out = run(&end, true).unwrap();
    assert_eq!(out.gcode.lines().nth(line - 1), Some("G1 Z0"));
    let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
    assert!(oracle.too_close > 0, "{}", describe(&oracle));
    // Lifted and parked at the safe height: clear, by the oracle too.
    end.end = vec![
        "M107".into(),
        "G91".into(),
        "G1 Z5".into(),
        "G90".into(),
        "G0 X0 Y0".into(),
    ];
    let out = run(&end, false).unwrap();
    let oracle = check_gcode(&out.gcode, &mesh, DO, TOL);
    assert_eq!(oracle.too_close, 0, "{}", describe(&oracle));
    // A travel clearance no build volume holds is named as the cause
    // (QA round 19 F4: only "lower the scan" was said).
    let mut high = MachineProfile::from_json(&text, "lab-bench.json").unwrap();
    high.safe_travel_clearance_mm = 1e6;
    let said = run(&high, false)
        .err()
        .expect("a travel height outside the volume")
        .to_string();
    assert!(
        said.contains("`safe_travel_clearance_mm` (1000000 mm in lab-bench.json) is smaller"),
        "{said}"
    );
    // A start that ends where the reader knows, inside the part (QA
    // round 19 F6: written with a warning that the block moves the head);
    // one that stays above it is written, with that warning.
    let mut start = MachineProfile::from_json(&text, "lab-bench.json").unwrap();
    start.start = ["G21", "G90", "G0 Z0.5", "G0 X40 Y40 Z0.2"]
        .map(String::from)
        .to_vec();
    let said = run(&start, false)
        .err()
        .expect("a start into the part")
        .to_string();
    assert!(
        said.contains("machine profile lab-bench.json, field `start[3]`: puts the nozzle closer"),
        "{said}"
    );
    // A bare coordinate moves in the machine's motion mode (Grbl's `Z0`):
    // followed there too (QA round 19: only warned about).
    start.start[3] = "G0 X40 Y40 Z30".into();
    start.start.push("Z0.2".into());
    let said = run(&start, false)
        .err()
        .expect("a bare Z into the part")
        .to_string();
    assert!(
        said.contains("machine profile lab-bench.json, field `start[4]`: puts the nozzle closer"),
        "{said}"
    );
    start.start.pop();
    let out = run(&start, false).unwrap();
    assert!(
        out.report
            .warnings
            .iter()
            .any(|w| w.contains("its start block moves the head")),
        "{:?}",
        out.report.warnings
    );
    let outside = |w: &Vec<String>| -> Vec<String> {
        w.iter()
            .filter(|w| w.contains("outside its build volume"))
            .cloned()
            .collect()
    };
    assert_eq!(outside(&out.report.warnings), Vec::<String>::new());
    // A start or end block's move out of the build volume is said, naming
    // the field and where (QA round 19: not flagged); the part is not at
    // risk (the firmware stops at its limits), so the G-code is written.
    let (lo, hi) = (start.build_volume.min_mm, start.build_volume.max_mm);
    start.start[3] = format!("G0 X{} Y40 Z30", hi.x + 5.0);
    let out = run(&start, false).unwrap();
    let said = outside(&out.report.warnings);
    assert!(
        said.len() == 1
            && said[0].starts_with(&format!(
                "profile lab-bench.json: its `start[3]` moves the head to ({:.3}, 40.000, \
                 30.000), outside its build volume (x {}..{}",
                hi.x + 5.0,
                lo.x,
                hi.x
            )),
        "{said:?}"
    );
    let mut park = MachineProfile::from_json(&text, "lab-bench.json").unwrap();
    park.end = vec!["M107".into(), format!("G0 X0 Y{}", lo.y - 1.0)];
    let out = run(&park, false).unwrap();
    let said = outside(&out.report.warnings);
    assert!(
        said.len() == 1 && said[0].contains("its `end` moves the head to (0.000, "),
        "{said:?}"
    );
    let mut dispense = marlin();
    dispense.dispense_on = vec!["G1 Z-0.5".into(), "M106 S255".into()];
    let e = run(&dispense, true)
        .err()
        .expect("a dispense command that moves written");
    assert!(e.to_string().contains("`dispense_on[0]`"), "{e}");
}
