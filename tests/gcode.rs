//! Integration tests: gcode. A small G-code reader reads each dialect's
//! program back and checks what a machine would do with it: where the
//! nozzle goes, at which feed, and whether the valve is open.

use pcpp::gcode::{write_gcode, FeedUnits, GcodeError, GcodeJob, MachineProfile};
use pcpp::DVec3;

/// Half a unit in the last written digit at 3 decimals, plus float noise.
const PRECISION_MM: f64 = 0.0005 + 1e-9;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Motion {
    Rapid,
    Linear,
}

/// Axes the program has not set yet are `None`.
type Position = [Option<f64>; 3];

#[derive(Debug, Clone)]
struct Move {
    motion: Motion,
    from: Position,
    to: Position,
    /// The explicit F word of this line, if any.
    feed_word: Option<f64>,
    /// The modal feed in force for this move.
    feed: Option<f64>,
    line: usize,
}

#[derive(Debug, Clone)]
enum Event {
    Move(Move),
    DispenseOn,
    DispenseOff,
}

#[derive(Debug, Default)]
struct Readback {
    events: Vec<Event>,
    comments: Vec<String>,
    /// Lines that are neither motion, dispense blocks nor comments.
    other: Vec<String>,
}

impl Readback {
    /// The points of each print: the position at dispense-on, then the end
    /// of every move made while dispensing.
    fn prints(&self) -> Vec<Vec<DVec3>> {
        let mut prints = Vec::new();
        let mut current: Option<Vec<DVec3>> = None;
        let mut position: Position = [None; 3];
        for event in &self.events {
            match event {
                Event::DispenseOn => current = Some(vec![known(position)]),
                Event::DispenseOff => prints.extend(current.take()),
                Event::Move(m) => {
                    position = m.to;
                    if let Some(points) = current.as_mut() {
                        points.push(known(position));
                    }
                }
            }
        }
        assert!(current.is_none(), "program ends with the valve open");
        prints
    }

    /// Moves made with the valve open.
    fn print_moves(&self) -> Vec<&Move> {
        let mut on = false;
        let mut moves = Vec::new();
        for event in &self.events {
            match event {
                Event::DispenseOn => on = true,
                Event::DispenseOff => on = false,
                Event::Move(m) if on => moves.push(m),
                Event::Move(_) => {}
            }
        }
        moves
    }
}

fn known(p: Position) -> DVec3 {
    match p {
        [Some(x), Some(y), Some(z)] => DVec3::new(x, y, z),
        _ => panic!("dispensing at an unknown position {p:?}"),
    }
}

/// A G-code number as the writer must produce it: optional minus, digits,
/// optional fraction; no exponent, no NaN or infinity.
fn number(text: &str) -> Result<f64, String> {
    let digits = text.strip_prefix('-').unwrap_or(text);
    let plain = !digits.is_empty()
        && digits.bytes().all(|b| b.is_ascii_digit() || b == b'.')
        && digits.bytes().filter(|&b| b == b'.').count() <= 1
        && !digits.starts_with('.')
        && !digits.ends_with('.');
    if !plain {
        return Err(format!("not a plain decimal number: {text:?}"));
    }
    text.parse().map_err(|e| format!("{text:?}: {e}"))
}

/// Reads a program: G0/G1 with X Y Z F words and modal state, the profile's
/// dispense blocks (matched line for line) and its comments.
fn read(text: &str, profile: &MachineProfile) -> Result<Readback, String> {
    let lines: Vec<&str> = text.lines().collect();
    let on: Vec<&str> = profile.dispense_on.iter().map(String::as_str).collect();
    let off: Vec<&str> = profile.dispense_off.iter().map(String::as_str).collect();
    let (prefix, suffix) = (&profile.comment.prefix, &profile.comment.suffix);
    let mut out = Readback::default();
    let mut position: Position = [None; 3];
    let mut motion: Option<Motion> = None;
    let mut feed: Option<f64> = None;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if lines[i..].starts_with(&on) {
            out.events.push(Event::DispenseOn);
            i += on.len();
            continue;
        }
        if lines[i..].starts_with(&off) {
            out.events.push(Event::DispenseOff);
            i += off.len();
            continue;
        }
        if let Some(body) = line.strip_prefix(prefix.as_str()) {
            let body = body
                .strip_suffix(suffix.as_str())
                .ok_or_else(|| format!("line {i}: unclosed comment {line:?}"))?;
            if !suffix.is_empty()
                && (body.contains(prefix.as_str()) || body.contains(suffix.as_str()))
            {
                return Err(format!("line {i}: nested comment {line:?}"));
            }
            out.comments.push(body.trim().to_string());
            i += 1;
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let is_motion_line = words
            .iter()
            .any(|w| matches!(*w, "G0" | "G1" | "G00" | "G01") || w.starts_with(['X', 'Y', 'Z']));
        if !is_motion_line {
            out.other.push(line.to_string());
            i += 1;
            continue;
        }
        let mut to = position;
        let mut feed_word = None;
        for word in words {
            let (letter, value) = word.split_at(1);
            match letter {
                "G" => match value {
                    "0" | "00" => motion = Some(Motion::Rapid),
                    "1" | "01" => motion = Some(Motion::Linear),
                    _ => return Err(format!("line {i}: G{value} mixed with motion")),
                },
                "X" => to[0] = Some(number(value)?),
                "Y" => to[1] = Some(number(value)?),
                "Z" => to[2] = Some(number(value)?),
                "F" => feed_word = Some(number(value)?),
                _ => return Err(format!("line {i}: unexpected word {word:?}")),
            }
        }
        feed = feed_word.or(feed);
        let motion = motion.ok_or_else(|| format!("line {i}: axis words before G0/G1"))?;
        out.events.push(Event::Move(Move {
            motion,
            from: position,
            to,
            feed_word,
            feed,
            line: i,
        }));
        position = to;
        i += 1;
    }
    Ok(out)
}

/// Three subpaths over hills, a dot and an empty subpath.
fn hills() -> Vec<Vec<DVec3>> {
    let hill = |x: f64, y: f64| {
        2.0 + 3.0 * (-((x - 30.0).powi(2) + (y - 25.0).powi(2)) / 60.0).exp()
            + 0.4 * (x * 0.7).sin()
    };
    let line = |y: f64, n: usize| -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let x = 10.0 + 40.0 * i as f64 / (n - 1) as f64 + 1e-4 / 3.0;
                DVec3::new(x, y, hill(x, y))
            })
            .collect()
    };
    let mut back = line(25.123_456, 37);
    back.reverse();
    vec![
        line(20.0, 41),
        back,
        vec![],
        vec![DVec3::new(45.0, 40.0, hill(45.0, 40.0))],
        line(31.000_49, 9),
    ]
}

fn job<'a>(paths: &'a [Vec<DVec3>], header: &'a [(String, String)], dwell_s: f64) -> GcodeJob<'a> {
    GcodeJob {
        toolpaths: paths,
        speed_mm_s: 5.0,
        dwell_s,
        header,
        scan_top_z_mm: 6.0,
    }
}

fn header() -> Vec<(String, String)> {
    vec![
        ("planner".into(), "tip-collision-free".into()),
        ("nozzle".into(), "d = 0.603 mm, do = 0.908 mm".into()),
        ("registration residual (mm)".into(), "0.012".into()),
    ]
}

/// Everything the task asks of a program, for one profile.
fn check_program(profile: &MachineProfile, dwell_s: f64) {
    let paths = hills();
    let header = header();
    let job = job(&paths, &header, dwell_s);
    let text = write_gcode(&job, profile).unwrap();
    let name = &profile.name;
    let lower = text.to_ascii_lowercase();
    assert!(
        !lower.contains("nan") && !lower.contains("inf"),
        "{name}: NaN text\n{text}"
    );
    let back = read(&text, profile).unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));

    // Provenance header: program and version, the job's pairs in order, the
    // profile name.
    let version = format!("pcpp {}", env!("CARGO_PKG_VERSION"));
    assert_eq!(back.comments[0], version, "{name}");
    let pairs: Vec<String> = header.iter().map(|(k, v)| format!("{k}: {v}")).collect();
    let pairs: Vec<String> = match profile.comment.suffix.as_str() {
        "" => pairs,
        // Parenthesized comments do not nest and keep no commas.
        _ => pairs
            .iter()
            .map(|p| p.replace(',', " ").replace('(', "[").replace(')', "]"))
            .collect(),
    };
    assert_eq!(back.comments[1..4], pairs[..], "{name}");
    assert_eq!(back.comments[4], format!("profile: {name}"), "{name}");

    // The tool path is recovered to the written precision.
    let expected: Vec<&Vec<DVec3>> = paths.iter().filter(|p| !p.is_empty()).collect();
    let prints = back.prints();
    assert_eq!(
        prints.len(),
        expected.len(),
        "{name}: one print per subpath"
    );
    for (k, (got, want)) in prints.iter().zip(&expected).enumerate() {
        assert_eq!(got.len(), want.len(), "{name}: print {k} point count");
        for (j, (g, w)) in got.iter().zip(want.iter()).enumerate() {
            let err = (*g - *w).abs().max_element();
            assert!(
                err <= PRECISION_MM,
                "{name}: print {k} point {j}: {g} vs {w}"
            );
        }
    }

    // Print moves are linear at the print speed in the profile's units, and
    // the first of each print carries the F word.
    let print_feed = match profile.feed_units {
        FeedUnits::MmPerMin => 300.0,
        FeedUnits::MmPerS => 5.0,
    };
    let print_moves = back.print_moves();
    assert_eq!(
        print_moves.len(),
        expected.iter().map(|p| p.len() - 1).sum::<usize>(),
        "{name}"
    );
    for m in &print_moves {
        assert_eq!(m.motion, Motion::Linear, "{name}: line {}", m.line);
        assert_eq!(m.feed, Some(print_feed), "{name}: line {}", m.line);
    }
    let mut on = false;
    let mut first = false;
    for event in &back.events {
        match event {
            Event::DispenseOn => (on, first) = (true, true),
            Event::DispenseOff => on = false,
            Event::Move(m) if on => {
                if first {
                    assert_eq!(m.feed_word, Some(print_feed), "{name}: line {}", m.line);
                }
                first = false;
            }
            Event::Move(_) => {}
        }
    }

    // Travel (valve closed): XY only changes at the safe height; the only
    // moves below it are the descent straight into a print and the lift.
    let top = paths
        .iter()
        .flatten()
        .map(|p| p.z)
        .fold(job.scan_top_z_mm, f64::max);
    let safe = top + profile.safe_travel_clearance_mm;
    let at_safe = |z: Option<f64>| z.is_some_and(|z| z >= safe - PRECISION_MM);
    let mut on = false;
    let mut travel_moves = 0;
    for (k, event) in back.events.iter().enumerate() {
        match event {
            Event::DispenseOn => on = true,
            Event::DispenseOff => on = false,
            Event::Move(m) if !on => {
                travel_moves += 1;
                let xy_changes = m.from[0] != m.to[0] || m.from[1] != m.to[1];
                if xy_changes {
                    assert!(
                        at_safe(m.from[2]) && at_safe(m.to[2]),
                        "{name}: line {}: XY travel below the safe height {safe}: {m:?}",
                        m.line
                    );
                }
                if !at_safe(m.to[2]) {
                    assert!(
                        matches!(back.events.get(k + 1), Some(Event::DispenseOn)),
                        "{name}: line {}: travel ends below the safe height",
                        m.line
                    );
                }
            }
            Event::Move(_) => {}
        }
    }
    assert!(travel_moves >= 3 * expected.len(), "{name}");
    let last = back.events.iter().rev().find_map(|e| match e {
        Event::Move(m) => Some(m),
        _ => None,
    });
    assert!(
        last.is_some_and(|m| at_safe(m.to[2])),
        "{name}: ends at the safe height"
    );

    // Dwells: after each dispense-on and before each dispense-off.
    let dwells = back
        .other
        .iter()
        .filter(|l| l.starts_with("G4") || l.starts_with("DWELL"))
        .count();
    let expected_dwells = if dwell_s > 0.0 { 2 * expected.len() } else { 0 };
    assert_eq!(dwells, expected_dwells, "{name}\n{text}");
}

#[test]
fn every_builtin_dialect_reads_back_without_dwell() {
    for name in MachineProfile::builtin_names() {
        check_program(&MachineProfile::builtin(name).unwrap(), 0.0);
    }
}

#[test]
fn every_builtin_dialect_reads_back_with_dwell() {
    for name in MachineProfile::builtin_names() {
        check_program(&MachineProfile::builtin(name).unwrap(), 0.2);
    }
}

#[test]
fn feed_units_differ_by_dialect() {
    let paths = hills();
    let job = job(&paths, &[], 0.0);
    let first_print_line = |name: &str| {
        let profile = MachineProfile::builtin(name).unwrap();
        let text = write_gcode(&job, &profile).unwrap();
        let on = &profile.dispense_on[0];
        let after_on = text.split(on.as_str()).nth(1).unwrap().to_string();
        after_on.lines().nth(1).unwrap().to_string()
    };
    assert!(first_print_line("marlin").ends_with(" F300"));
    assert!(first_print_line("grbl").ends_with(" F300"));
    assert!(first_print_line("aerotech").ends_with(" F5"));
}

#[test]
fn a_user_profile_with_spindle_valve_and_more_decimals_reads_back() {
    // The documented alternative for Grbl: a valve on the spindle enable.
    let mut json: serde_json::Value =
        serde_json::from_str(&MachineProfile::builtin("grbl").unwrap().to_json().unwrap()).unwrap();
    json["name"] = "grbl-spindle".into();
    json["dispense_on"] = serde_json::json!(["M3 S1000", "G4 P0.05"]);
    json["dispense_off"] = serde_json::json!(["M5"]);
    json["comment"] = serde_json::json!({ "prefix": ";" });
    json["decimals"] = 6.into();
    let profile = MachineProfile::from_json(&json.to_string(), "grbl-spindle.json").unwrap();
    check_program(&profile, 0.0);
    check_program(&profile, 1.5);
}

#[test]
fn out_of_volume_names_the_point_and_writes_nothing() {
    for name in MachineProfile::builtin_names() {
        let profile = MachineProfile::builtin(name).unwrap();
        let mut paths = hills();
        paths[4][3].x = profile.build_volume.max_mm.x + 1.0;
        let result = write_gcode(&job(&paths, &header(), 0.0), &profile);
        let Err(e) = result else {
            panic!("{name}: an out-of-volume job was written");
        };
        assert!(
            matches!(
                e,
                GcodeError::OutOfVolume {
                    subpath: 4,
                    point: 3,
                    ..
                }
            ),
            "{name}: {e:?}"
        );
        let message = e.to_string();
        assert!(message.contains("subpath 4, point 3"), "{message}");
        assert!(
            message.contains(&profile.build_volume.to_string()),
            "{message}"
        );
        assert!(message.contains(&format!("{}", paths[4][3].x)), "{message}");
    }
}

#[test]
fn nan_and_infinite_points_name_the_point_and_write_nothing() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for name in MachineProfile::builtin_names() {
            let profile = MachineProfile::builtin(name).unwrap();
            let mut paths = hills();
            paths[1][17].z = bad;
            let Err(e) = write_gcode(&job(&paths, &[], 0.0), &profile) else {
                panic!("{name}: a job with {bad} was written");
            };
            assert!(
                matches!(
                    e,
                    GcodeError::NonFinitePoint {
                        subpath: 1,
                        point: 17,
                        ..
                    }
                ),
                "{name}: {e:?}"
            );
            assert!(e.to_string().contains("subpath 1, point 17"), "{e}");
        }
    }
}

#[test]
fn the_reader_catches_what_it_is_meant_to_catch() {
    // Guard against a reader that accepts anything.
    let profile = MachineProfile::builtin("marlin").unwrap();
    assert!(read("G1 X1e3 Y0 Z0", &profile).is_err());
    assert!(read("G1 XNaN Y0 Z0", &profile).is_err());
    assert!(read("X1 Y2", &profile).is_err());
    let grbl = MachineProfile::builtin("grbl").unwrap();
    assert!(read("( a ( b )", &grbl).is_err());
    let back = read(
        "G0 Z10\nG0 X5 Y5\nG1 Z1 F600\nM106 S255\nG1 X6 F300\nM107\nG0 Z10",
        &profile,
    )
    .unwrap();
    assert_eq!(
        back.prints(),
        [vec![DVec3::new(5.0, 5.0, 1.0), DVec3::new(6.0, 5.0, 1.0)]]
    );
    assert_eq!(back.print_moves()[0].feed, Some(300.0));
}

/// A pcpp program checked against a scan other than the one it was planned
/// on, or against its scan in another frame (placed on the bed when it
/// was planned as scanned): the check found only collisions and did not
/// say why, though the program's header names the scan's SHA-256 and the
/// registration it was planned with. Now the notes say so; the program
/// checked as it was planned gets neither note.
#[test]
fn regression_check_did_not_compare_the_programs_header_with_its_scan() {
    use pcpp::demo;
    use pcpp::job::{check_gcode, prepare_scan, FiducialSource, RegistrationSettings};
    use pcpp::mesh::ImportOptions;

    let golden = include_str!("golden/demo-marlin.gcode");
    let nozzle = pcpp::Nozzle::DEFAULT;
    let prepare = |bytes: &[u8], name: &str, registration: &RegistrationSettings| {
        prepare_scan(bytes, name, &ImportOptions::DEFAULT, registration).unwrap()
    };
    let notes = |scan| {
        check_gcode(scan, golden, "demo.gcode", &nozzle, 0.1)
            .unwrap()
            .notes
    };
    let ply = demo::demo_scan_bytes();
    let as_planned = prepare(&ply, demo::DEMO_SCAN_NAME, &RegistrationSettings::default());
    let n = notes(&as_planned);
    assert!(
        !n.iter()
            .any(|n| n.contains("another frame") || n.contains("another scan")),
        "{n:?}"
    );

    // The same scan registered 2 mm and 3 mm over from where it was.
    let fiducials = demo::test_part::FIDUCIALS_MM.to_vec();
    let shifted = RegistrationSettings {
        fiducials: FiducialSource::Points(fiducials.clone()),
        printer_points: fiducials
            .iter()
            .map(|p| *p + DVec3::new(2.0, 3.0, 0.0))
            .collect(),
        ..Default::default()
    };
    let moved = prepare(&ply, demo::DEMO_SCAN_NAME, &shifted);
    let n = notes(&moved);
    assert!(
        n.iter().any(|n| n.contains("another frame")
            && n.contains("taken as it is")
            && n.contains("up to 3.000")
            && n.contains("place or register the scan")),
        "{n:?}"
    );

    let obj = demo::workloads::to_obj(&demo::test_part::test_part());
    let other = prepare(obj.as_bytes(), "part.obj", &RegistrationSettings::default());
    let n = notes(&other);
    assert!(
        n.iter().any(|n| n.contains("another scan file")
            && n.contains(demo::DEMO_SCAN_NAME)
            && n.contains("part.obj")),
        "{n:?}"
    );
}

/// The demo part as `pcpp check` reads it: as scanned, unregistered.
fn demo_scan() -> pcpp::job::PreparedScan {
    pcpp::job::prepare_scan(
        &pcpp::demo::demo_scan_bytes(),
        pcpp::demo::DEMO_SCAN_NAME,
        &pcpp::mesh::ImportOptions::DEFAULT,
        &pcpp::job::RegistrationSettings::default(),
    )
    .unwrap()
}

/// QA round 6 F3: inside the scan's box, over a hole in it, nothing is
/// known of the part either, and a print move ending over a scan's
/// dropout was not named. A plate with a 10 mm hole in its middle: a move
/// across the hole, one ending over it and the rise out of it, are named;
/// moves over the
/// plate around it, one high over the hole, and one descending from high
/// over the hole to low over the plate (QA round 8 F3), are not.
#[test]
fn regression_moves_over_a_hole_in_the_scan_are_named() {
    use pcpp::job::check_gcode;

    let axis: Vec<f64> = (0..=40).map(f64::from).collect();
    // (A block at x 32-40 stands 4 mm above the plate, so the moves over
    // the plate are lower than tol above the scan's top.)
    let mut plate =
        pcpp::mesh::TriMesh::height_field(&axis, &axis, |x, _| if x >= 32.0 { 6.0 } else { 2.0 });
    let vertices = plate.vertices.clone();
    plate.triangles.retain(|t| {
        let c = t.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / 3.0;
        !((15.0..25.0).contains(&c.x) && (15.0..25.0).contains(&c.y))
    });
    let scan = pcpp::job::prepare_scan(
        &pcpp::demo::to_binary_ply(&plate),
        "holed.ply",
        &pcpp::mesh::ImportOptions::DEFAULT,
        &pcpp::job::RegistrationSettings::default(),
    )
    .unwrap();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let program = "G21\nG90\nG0 X5 Y5 Z10\nG1 Z2.5\nG1 X28 Y5\nG1 X28 Y20\nG1 X5 Y20\n\
                   G1 X5 Y35\nG1 X19 Y35\nG1 X19 Y20\nG0 Z10\nG0 X20 Y20 Z10\nG1 X5 Y20 Z2.5\n";
    let check = check_gcode(&scan, program, "holed.gcode", &nozzle, 0.1).unwrap();
    assert!(check.is_clear(), "{:?}", check.summary);
    let notes = check.notes.join("\n");
    assert!(
        notes.contains(
            "3 move(s) pass beside the scan or over a hole in it lower than tol above its top \
             (lines 7, 10, 11; the lowest at z 2.500 mm, line 7,"
        ),
        "{notes}"
    );
    // Counted for the verdict (QA round 8 F4).
    assert_eq!(check.off_scan_moves, 3);
}

/// A file without a move (empty, comments only, a point cloud's numbers)
/// was checked as "clear: none of the 0 moves comes closer than tol"; it
/// shows nothing, and now says so.
#[test]
fn regression_a_program_without_moves_was_clear() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    for text in ["", "; only a comment\n(and another)\n", "G21\nG90\nM82\n"] {
        let e = check_gcode(&scan, text, "empty.gcode", &nozzle, 0.1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("empty.gcode has no moves") && e.contains("nothing to check"),
            "{text:?}: {e}"
        );
    }
    // A scan given as the program is named as one (QA round 3).
    for (text, kind) in [
        (
            "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n",
            "a PLY scan",
        ),
        ("solid part\nendsolid part\n", "an ASCII STL scan"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "an OBJ scan"),
    ] {
        let e = check_gcode(&scan, text, "scan.txt", &nozzle, 0.1)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!(
                "scan.txt is {kind}, not a G-code program: give it as the scan"
            )),
            "{text:?}: {e}"
        );
    }
    // One move is checked as before.
    let one = check_gcode(&scan, "G90\nG0 X10 Y10 Z60\n", "one.gcode", &nozzle, 0.1).unwrap();
    assert!(one.is_clear());
}

/// `X40 Y41 Z2 M3 S100` under a modal G1 (how some laser and spindle
/// programs turn the tool on) was read as M3's parameters, so `check`
/// passed a program whose move on that line dives 2.7 mm into the demo
/// part. The move is checked now, and the line after it, whose start is
/// not known for sure, is listed as unchecked.
#[test]
fn regression_check_passed_a_dive_written_beside_m3() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let text = "G21\nG90\nG0 X40 Y40 Z20\nG1 Z10 F300\nX40 Y41 Z2 M3 S100\nG1 X41 Y41 Z10\n";
    let check = check_gcode(&scan, text, "laser.nc", &nozzle, 0.1).unwrap();
    assert!(!check.is_clear());
    assert_eq!(check.summary.touching_moves, 1, "{:?}", check.summary);
    assert_eq!(check.summary.min_clearance_line, Some(5));
    assert_eq!(check.unchecked_lines, [6]);
    // Each line is explained once: line 3 as the program's first rise, line
    // 6 as unchecked; not again in a list of "moves before every axis had a
    // known position".
    let notes = check.notes.join("\n");
    assert!(!notes.contains("lines 3, 6"), "{notes}");
    assert!(
        notes.contains("could not be checked") && notes.contains("(line 6)"),
        "{notes}"
    );
}

/// QA round 3: a program printing beyond a cropped scan's edge, below its
/// surface's height, was "clear" with no word: those moves are named.
#[test]
fn regression_moves_beside_the_scan_are_named() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let (lo, hi) = scan.surface.bbox();
    let x = hi.x + 40.0;
    let text = format!(
        "G21\nG90\nG0 X40 Y40 Z{top}\nG0 X{x} Y40 Z{top}\nG1 Z{low}\nG1 X{far} Y40\nG0 Z{top}\n",
        top = hi.z + 20.0,
        low = lo.z - 1.0,
        far = x + 10.0,
    );
    let check = check_gcode(&scan, &text, "beside.gcode", &nozzle, 0.1).unwrap();
    assert!(check.is_clear(), "{:?}", check.summary);
    let notes = check.notes.join("\n");
    assert!(
        notes.contains(&format!(
            "3 move(s) pass beside the scan or over a hole in it lower than tol above its top \
             (lines 5, 6, 7; the lowest at z {:.3} mm, line 5,",
            lo.z - 1.0
        )) && notes.contains("nothing is known of the part there"),
        "{notes}"
    );
    assert_eq!(check.off_scan_moves, 3);
    // Over the scan, or high above it: no such note.
    let over = format!(
        "G21\nG90\nG0 X40 Y40 Z{top}\nG0 X{x} Y40 Z{top}\n",
        top = hi.z + 20.0
    );
    let check = check_gcode(&scan, &over, "over.gcode", &nozzle, 0.1).unwrap();
    assert!(
        !check.notes.join("\n").contains("beside the scan"),
        "{:?}",
        check.notes
    );
    assert_eq!(check.off_scan_moves, 0);
}

/// Two moves 5 mm above the scan's top: clear of it wherever they are.
fn moves_above(scan: &pcpp::job::PreparedScan) -> String {
    let (_, hi) = scan.surface.bbox();
    format!(
        "G21\nG90\nG0 X40 Y40 Z{z}\nG1 X50 Y40 Z{z}\n",
        z = hi.z + 5.0
    )
}

/// QA round 2: a program planned on a 44 mm cow (the scan read in inches,
/// +Y up), checked with the scan read in mm, was "clear" (exit 0) against
/// a 1.7 mm cow, the header's mismatch said only in a note. A program whose
/// header says the scan was read or placed another way is not shown clear.
#[test]
fn regression_a_program_planned_on_the_scan_read_otherwise_is_not_clear() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let moves = moves_above(&scan);
    let plain = check_gcode(&scan, &moves, "a.gcode", &nozzle, 0.1).unwrap();
    assert!(plain.is_clear() && plain.planned_otherwise.is_empty());
    let text = format!("; pcpp 0.1.0\n; scan read in: in, +Y up\n{moves}");
    let check = check_gcode(&scan, &text, "a.gcode", &nozzle, 0.1).unwrap();
    assert_eq!(check.summary.touching_moves, 0);
    assert!(!check.is_clear());
    assert_eq!(
        check.planned_otherwise.len(),
        1,
        "{:?}",
        check.planned_otherwise
    );
    assert!(
        check.planned_otherwise[0].starts_with(
            "the program was planned with the scan read in in, +Y up, this check reads it in mm"
        ),
        "{:?}",
        check.planned_otherwise
    );
    // Another tool's comment that reads alike is not pcpp's header.
    let foreign = format!("; scan read in: in, +Y up\n{moves}");
    let check = check_gcode(&scan, &foreign, "a.gcode", &nozzle, 0.1).unwrap();
    assert!(check.is_clear(), "{:?}", check.notes);
}

/// QA round 13 F1: a program planned on a GLB (read in m, +Y up), checked
/// against the STL it was made from (read in mm, +Z up), was advised
/// `--scan-units m --up-axis y`, which read the STL 1000 times too large.
/// Another file's format may rightly read otherwise: the note says so and
/// gives no flags, and the check is not refused for it; the same file read
/// otherwise still is.
#[test]
fn another_scan_file_read_otherwise_is_not_advised_the_programs_reading() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let moves = moves_above(&scan);
    let header = |sha: &str| {
        format!(
            "; pcpp 0.1.0\n; scan file: part.glb (1000 bytes, sha256 {sha})\n; scan read in: m, \
             +Y up\n{moves}"
        )
    };
    let other = header(&"ab".repeat(32));
    let check = check_gcode(&scan, &other, "a.gcode", &nozzle, 0.1).unwrap();
    assert!(
        check.planned_otherwise.is_empty(),
        "{:?}",
        check.planned_otherwise
    );
    assert!(check.is_clear(), "{:?}", check.notes);
    assert!(
        check.notes.iter().any(|n| n.starts_with(
            "the program's scan was read in m, +Y up, this check reads demo-test-part.ply in mm, \
             +Z up; as they are different files, check this file's own units and up axis"
        )),
        "{:?}",
        check.notes
    );
    assert!(
        !check.notes.iter().any(|n| n.contains("--scan-units")),
        "{:?}",
        check.notes
    );
    // The same file read otherwise: advised and not shown clear.
    let same = header(&scan.file.sha256);
    let check = check_gcode(&scan, &same, "a.gcode", &nozzle, 0.1).unwrap();
    assert!(!check.is_clear());
    assert!(
        check.planned_otherwise[0].ends_with("read it as it was then (--scan-units m --up-axis y)"),
        "{:?}",
        check.planned_otherwise
    );
}

/// QA round 3: a pen plotter's program (X and Y only, svg2gcode) was told
/// to give the position before its moves; it is said to never give Z.
#[test]
fn a_program_that_never_gives_z_is_said_to() {
    use pcpp::job::check_gcode;

    let scan = demo_scan();
    let nozzle = pcpp::Nozzle::DEFAULT;
    let text = "G21\nG90\nG0 X10 Y10\nG1 X20 Y10 F300\nG1 X20 Y20\n";
    let check = check_gcode(&scan, text, "plot.gcode", &nozzle, 0.1).unwrap();
    assert!(!check.is_clear());
    assert!(
        check.notes[0].starts_with("the file never gives Z: a program for two axes"),
        "{:?}",
        check.notes
    );
    // One Z anywhere: not said.
    let text = "G21\nG90\nG0 Z30\nG0 X10 Y10\nG1 X20 Y10 F300\n";
    let check = check_gcode(&scan, text, "z.gcode", &nozzle, 0.1).unwrap();
    assert!(
        !check.notes.iter().any(|n| n.contains("never gives Z")),
        "{:?}",
        check.notes
    );
}
