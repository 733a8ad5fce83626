//! The core's tests that matter, compiled to wasm32 and run in Node
//! (`wasm-pack test --node -- --test wasm_core`): importers, registration,
//! projection, planners, quality and G-code must give in the browser what
//! they give natively. The demo's G-code is compared with the native golden
//! file byte for byte, both through `pcpp::job` and through the page's
//! `pcpp::wasm::Session` adapter.
#![cfg(target_arch = "wasm32")]

use pcpp::demo::{self, antennas, parts::DemoPart, test_part};
use pcpp::gcode::MachineProfile;
use pcpp::job::{self, FiducialSource, JobSettings, RegistrationSettings};
use pcpp::mesh::{import_mesh, ImportOptions, MeshFormat, ScanUnits};
use pcpp::planners::PlannerKind;
use pcpp::quality::Defect;
use pcpp::registration::{parse_points, register, RegistrationMethod};
use pcpp::DVec3;
use wasm_bindgen::JsValue;
use wasm_bindgen_test::wasm_bindgen_test;

const GOLDEN_MARLIN: &str = include_str!("golden/demo-marlin.gcode");
const GOLDEN_GRBL: &str = include_str!("golden/demo-grbl.gcode");

/// A 4 x 4 grid of quads in cm with a bump, as OBJ text.
fn small_obj() -> String {
    let mut s = String::from("# a small bumpy sheet\n");
    for j in 0..5 {
        for i in 0..5 {
            let z = if (i, j) == (2, 2) { 0.1 } else { 0.0 };
            s.push_str(&format!("v {} {} {z}\n", i as f64 * 0.5, j as f64 * 0.5));
        }
    }
    for j in 0..4 {
        for i in 0..4 {
            let a = j * 5 + i + 1;
            s.push_str(&format!("f {} {} {} {}\n", a, a + 1, a + 6, a + 5));
        }
    }
    s
}

#[wasm_bindgen_test]
fn obj_imports_with_units() {
    let cm = ImportOptions {
        units: Some(ScanUnits::Cm),
        up_axis: None,
        max_edge_mm: None,
    };
    let m = import_mesh(small_obj().as_bytes(), "sheet.obj", &cm).unwrap();
    assert_eq!(m.format, MeshFormat::Obj);
    assert_eq!(m.mesh.triangle_count(), 32);
    let (lo, hi) = m.mesh.bbox().unwrap();
    assert_eq!(lo, DVec3::ZERO);
    assert_eq!(hi, DVec3::new(20.0, 20.0, 1.0));
}

#[wasm_bindgen_test]
fn demo_ply_round_trips_through_the_importer() {
    let bytes = demo::demo_scan_bytes();
    let m = import_mesh(&bytes, demo::DEMO_SCAN_NAME, &ImportOptions::DEFAULT).unwrap();
    assert_eq!(m.format, MeshFormat::Ply);
    let part = test_part::test_part();
    // Zero-area triangles may be dropped by the importer, nothing else.
    let (n, k) = (m.mesh.triangle_count(), part.triangle_count());
    assert!(n <= k && n + 100 > k, "{n} of {k} triangles");
    assert!(m.mesh.bbox() == part.bbox());
}

#[wasm_bindgen_test]
fn hostile_scans_are_errors_not_panics() {
    let inputs: [&[u8]; 6] = [
        b"",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nend_header\n",
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n",
        b"v 1 2 3\nf 1 2 99\n",
        b"glTF\x02\x00\x00\x00\xff\xff\xff\xff",
        &[0xff; 300],
    ];
    let names = ["a.obj", "b.ply", "c.stl", "d.obj", "e.glb", "f.stl"];
    for (bytes, name) in inputs.iter().zip(names) {
        let e = import_mesh(bytes, name, &ImportOptions::DEFAULT);
        assert!(e.is_err(), "{name} imported");
    }
}

#[wasm_bindgen_test]
fn paper_table_s1_registers() {
    // Table S1's points, typed as the page and the CLI take them.
    let sr = parse_points(
        "-58.4037,86.5977,-39.1942; -88.5714,153.855,-53.3039; -57.0373,153.469,-124.727",
    )
    .unwrap();
    let p = parse_points(
        "88.1799,14.0904,-50.7744\n13.4989,11.1944,-50.7974\n10.1549,89.0994,-50.7314",
    )
    .unwrap();
    let lsq = register(&sr, &p, RegistrationMethod::Lsq).unwrap();
    let paper = register(&sr, &p, RegistrationMethod::Paper).unwrap();
    assert!((0.05..=0.35).contains(&lsq.rms_mm), "{}", lsq.rms_mm);
    assert!(lsq.rms_mm <= paper.rms_mm);
    assert!(paper.residuals_mm[1] < 1e-12);
    assert!(parse_points("1, 2").is_err());
}

fn golden_settings() -> JobSettings {
    let mut s = JobSettings::default();
    s.plan.placement = test_part::placement();
    s
}

/// The demo scan prepared with `settings`' scan and registration options.
fn demo_prepared(scan: &[u8], settings: &JobSettings) -> job::PreparedScan {
    job::prepare_scan(
        scan,
        demo::DEMO_SCAN_NAME,
        &settings.scan,
        &settings.registration,
    )
    .unwrap()
}

#[wasm_bindgen_test]
fn demo_gcode_equals_the_native_golden_files() {
    let scan = demo::demo_scan_bytes();
    let svg = test_part::test_part_svg();
    let settings = golden_settings();
    let prepared = demo_prepared(&scan, &settings);
    for (dialect, golden) in [("marlin", GOLDEN_MARLIN), ("grbl", GOLDEN_GRBL)] {
        let profile = MachineProfile::builtin(dialect).unwrap();
        let out = job::run_on(
            &prepared,
            svg.as_bytes(),
            demo::DEMO_PATH_NAME,
            &settings.plan,
            &profile,
            false,
        )
        .unwrap();
        let (golden, gcode) = (golden, out.gcode.as_str());
        if gcode != golden {
            let diffs: Vec<String> = golden
                .lines()
                .zip(gcode.lines())
                .enumerate()
                .filter(|(_, (a, b))| a != b)
                .map(|(i, (a, b))| format!("line {}: golden {a:?} wasm {b:?}", i + 1))
                .collect();
            panic!(
                "{dialect}: wasm G-code differs from tests/golden in {} line(s):\n{}",
                diffs.len(),
                diffs
                    .iter()
                    .take(12)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        }
    }
}

#[wasm_bindgen_test]
fn planners_compare_and_the_guarded_one_never_touches() {
    let scan = demo::demo_scan_bytes();
    let svg = test_part::test_part_svg();
    let settings = golden_settings();
    let prepared = demo_prepared(&scan, &settings);
    let marlin = MachineProfile::builtin("marlin").unwrap();
    let rows = job::compare_on(
        &prepared,
        svg.as_bytes(),
        "lines.svg",
        &settings.plan,
        &marlin,
    )
    .unwrap()
    .rows;
    let kinds: Vec<PlannerKind> = rows.iter().map(|r| r.planner).collect();
    assert_eq!(kinds, PlannerKind::ALL.to_vec());
    for guarded in &rows[3..] {
        assert_eq!(guarded.quality.contact_pct, 0.0);
        assert_eq!(guarded.motion.touching_moves, 0);
    }
    // The constant stand-off runs into the part's steps (the paper's point).
    assert!(rows[0].quality.contact_pct > 0.0);
    assert!(rows[0].motion.touching_moves > 0);

    // Projection: every Ta point of the first line lies on the part.
    let out = job::run_on(
        &prepared,
        svg.as_bytes(),
        "lines.svg",
        &settings.plan,
        &MachineProfile::builtin("marlin").unwrap(),
        false,
    )
    .unwrap();
    // Walls are vertical, so points right at a wall may take either side's
    // height: require nearly all, not all, to sit on the analytic surface.
    let ta: Vec<&[f64; 3]> = out.report.surface_path.iter().flatten().collect();
    let on = ta
        .iter()
        .filter(|p| (p[2] - test_part::height(p[0], p[1])).abs() < 1e-3)
        .count();
    assert!(on * 100 >= ta.len() * 95, "{on} of {}", ta.len());
    assert!(out
        .report
        .defects
        .iter()
        .flatten()
        .all(|d| *d != Defect::Contact));
}

#[wasm_bindgen_test]
fn auto_fiducials_register_the_demo() {
    let scan = demo::demo_scan_bytes();
    let reg = RegistrationSettings {
        fiducials: FiducialSource::Auto,
        printer_points: test_part::FIDUCIALS_MM.to_vec(),
        method: RegistrationMethod::Lsq,
        ..Default::default()
    };
    let prepared =
        job::prepare_scan(&scan, demo::DEMO_SCAN_NAME, &ImportOptions::DEFAULT, &reg).unwrap();
    assert!(prepared.registration.rms_mm < 0.05);
}

#[wasm_bindgen_test]
fn antennas_plan_on_the_demo_part() {
    let svg = antennas::hilbert_loop_svg(3, 20.0).unwrap();
    let drawn = pcpp::pipeline::load_path(svg.as_bytes(), "hilbert.svg").unwrap();
    assert!(!drawn.subpaths.is_empty());
    assert!(antennas::hilbert_loop_svg(0, 20.0).is_err());
    assert!(antennas::archimedean_spiral_svg(f64::NAN, 1.0, 1.0).is_err());
}

// ---- the page's adapter (src/wasm.rs), as the worker calls it ----

fn js<T: serde::Serialize>(v: &T) -> JsValue {
    serde_wasm_bindgen::to_value(v).unwrap()
}

/// A session on the scan `bytes` (named `name`) prepared with the scan
/// and registration settings of `settings`, in one call.
fn session_on(bytes: &[u8], name: &str, settings: &JobSettings) -> pcpp::wasm::Session {
    pcpp::wasm::Session::new(bytes, name, js(&settings.scan), js(&settings.registration))
        .unwrap_or_else(|e| panic!("{e:?}"))
}

/// The demo's drawing planned on `session` with `plan` for Marlin, the risk
/// not accepted; `with_report` as [`pcpp::wasm::Session::plan`] takes it.
fn plan_demo_drawing(
    session: &mut pcpp::wasm::Session,
    plan: &pcpp::pipeline::PlanSettings,
    with_report: Option<bool>,
) -> Result<JsValue, JsValue> {
    session.plan(
        test_part::test_part_svg().as_bytes(),
        demo::DEMO_PATH_NAME,
        js(plan),
        "marlin",
        false,
        None,
        with_report,
    )
}

#[wasm_bindgen_test]
fn session_plans_the_golden_gcode_and_the_cli_report() {
    let settings = golden_settings();
    let mut session = session_on(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    let out =
        plan_demo_drawing(&mut session, &settings.plan, None).unwrap_or_else(|e| panic!("{e:?}"));
    let gcode = js_sys::Reflect::get(&out, &"gcode".into()).unwrap();
    assert_eq!(gcode.as_string().unwrap(), GOLDEN_MARLIN);
    let report = js_sys::Reflect::get(&out, &"report_json".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(report.ends_with("}\n"));
    let parsed: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(parsed["planner"], "even");

    // A placement change re-plans on the same session (no re-import).
    let mut moved = settings.plan;
    moved.placement.offset_mm.x += 1.0;
    let again = plan_demo_drawing(&mut session, &moved, None).unwrap_or_else(|e| panic!("{e:?}"));
    let g2 = js_sys::Reflect::get(&again, &"gcode".into()).unwrap();
    assert_ne!(g2.as_string().unwrap(), GOLDEN_MARLIN);
}

/// A plan that leaves its report for later: the same bytes when asked for,
/// and only while no later such plan replaced it.
#[wasm_bindgen_test]
fn a_report_left_for_later_is_the_same_bytes_and_kept_until_the_next_plan() {
    let settings = golden_settings();
    let mut session = session_on(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    let plan = |session: &mut pcpp::wasm::Session,
                with_report: Option<bool>,
                settings: &pcpp::pipeline::PlanSettings| {
        plan_demo_drawing(session, settings, with_report).unwrap_or_else(|e| panic!("{e:?}"))
    };
    let whole = plan(&mut session, Some(true), &settings.plan);
    let expected = get(&whole, "report_json").as_string().unwrap();
    let absent = |v: JsValue| v.is_null() || v.is_undefined();
    assert!(absent(get(&whole, "report_id")));
    let later = plan(&mut session, Some(false), &settings.plan);
    assert!(absent(get(&later, "report_json")));
    assert_eq!(get(&later, "gcode").as_string().unwrap(), GOLDEN_MARLIN);
    let id = get(&later, "report_id").as_f64().unwrap() as u32;
    let mut moved = settings.plan;
    moved.placement.offset_mm.x += 1.0;
    let next = plan(&mut session, Some(false), &moved);
    let next_id = get(&next, "report_id").as_f64().unwrap() as u32;
    assert_ne!(id, next_id);
    // The first is gone, the second is the moved plan's.
    let err = session
        .report_json(id)
        .expect_err("replaced by the next plan");
    assert!(message_and_kind(&err).0.contains("no longer kept"));
    let moved_report = String::from_utf8(session.report_json(next_id).unwrap()).unwrap();
    assert_ne!(moved_report, expected);
    // Asked again for the first settings: the bytes of the report written
    // at once.
    let again = plan(&mut session, Some(false), &settings.plan);
    let again_id = get(&again, "report_id").as_f64().unwrap() as u32;
    let bytes = session.report_json(again_id).unwrap();
    assert_eq!(String::from_utf8(bytes).unwrap(), expected);
}

#[wasm_bindgen_test]
fn session_errors_name_the_cause_and_the_stage() {
    let none = JobSettings::default();
    let err = pcpp::wasm::Session::new(
        b"v 1 2 3\nf 1 2 99\n",
        "broken.obj",
        js(&none.scan),
        js(&none.registration),
    )
    .err()
    .expect("a broken OBJ must not import");
    let message = js_sys::Reflect::get(&err, &"message".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(message.contains("broken.obj"), "{message}");
    let kind = js_sys::Reflect::get(&err, &"kind".into()).unwrap();
    assert_eq!(kind.as_string().as_deref(), Some("mesh"));

    // A readable scan with too few printer points: a registration error.
    let reg = RegistrationSettings {
        fiducials: FiducialSource::Auto,
        printer_points: vec![DVec3::ZERO],
        method: RegistrationMethod::Lsq,
        ..Default::default()
    };
    let err = pcpp::wasm::Session::new(
        small_obj().as_bytes(),
        "sheet.obj",
        js(&none.scan),
        js(&reg),
    )
    .err()
    .expect("one printer point cannot register");
    let kind = js_sys::Reflect::get(&err, &"kind".into()).unwrap();
    assert_eq!(kind.as_string().as_deref(), Some("registration"));

    // Unknown dialect and bad settings objects are errors, not panics.
    let mut ok = session_on(small_obj().as_bytes(), "sheet.obj", &none);
    let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" viewBox="0 0 10 10"><path d="M1 5 L9 5"/></svg>"#;
    assert!(ok
        .plan(
            svg,
            "l.svg",
            js(&none.plan),
            "no-such-dialect",
            false,
            None,
            None
        )
        .is_err());
    assert!(ok
        .plan(
            svg,
            "l.svg",
            JsValue::from_str("nonsense"),
            "marlin",
            false,
            None,
            None
        )
        .is_err());
}

#[wasm_bindgen_test]
fn session_plans_with_a_custom_profile_and_names_its_bad_field() {
    let settings = golden_settings();
    let mut session = session_on(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    let svg = test_part::test_part_svg();
    let svg = svg.as_bytes();
    let mut profile: serde_json::Value =
        serde_json::from_str(include_str!("../src/gcode/profiles/marlin.json")).unwrap();
    profile["name"] = "my-printer".into();
    profile["start"] = serde_json::json!(["G21", "G90", "M117 custom start"]);
    let text = profile.to_string();
    assert_eq!(
        pcpp::wasm::check_profile(&text, "my-printer.json").ok(),
        Some("my-printer".to_string())
    );
    let out = session
        .plan(
            svg,
            demo::DEMO_PATH_NAME,
            js(&settings.plan),
            &text,
            false,
            Some("my-printer.json".into()),
            None,
        )
        .unwrap_or_else(|e| panic!("{e:?}"));
    let gcode = js_sys::Reflect::get(&out, &"gcode".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(gcode.contains("M117 custom start"), "{gcode}");

    profile["decimals"] = "three".into();
    let bad = profile.to_string();
    let err = session
        .plan(
            svg,
            demo::DEMO_PATH_NAME,
            js(&settings.plan),
            &bad,
            false,
            Some("bad.json".into()),
            None,
        )
        .expect_err("a profile with a bad field must not plan");
    let message = js_sys::Reflect::get(&err, &"message".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(
        message.contains("bad.json") && message.contains("decimals"),
        "{message}"
    );
}

#[wasm_bindgen_test]
fn session_pick_finds_the_surface_under_a_vertical_ray() {
    let none = JobSettings::default();
    let session = session_on(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &none);
    // The demo part's flat margin is at 5 mm.
    let hit = session
        .pick(&[2.0, 40.0, 100.0], &[0.0, 0.0, -1.0])
        .unwrap_or_else(|e| panic!("{e:?}"));
    let scan: [f64; 3] =
        serde_wasm_bindgen::from_value(js_sys::Reflect::get(&hit, &"scan".into()).unwrap())
            .unwrap();
    assert!((scan[2] - 5.0).abs() < 1e-9, "{scan:?}");
    assert!((scan[0] - 2.0).abs() < 1e-9 && (scan[1] - 40.0).abs() < 1e-9);
    // A ray that misses is null; a bad direction is an error.
    let miss = session
        .pick(&[-50.0, -50.0, 100.0], &[0.0, 0.0, -1.0])
        .unwrap_or_else(|e| panic!("{e:?}"));
    assert!(miss.is_null());
    assert!(session.pick(&[0.0, 0.0, 1.0], &[0.0, 0.0, 0.0]).is_err());
    assert!(session.pick(&[0.0, 0.0], &[0.0, 0.0, -1.0]).is_err());
}

// ---- live re-planning and the page's limits (src/wasm.rs) ----

fn get(v: &JsValue, key: &str) -> JsValue {
    js_sys::Reflect::get(v, &key.into()).unwrap()
}

fn message_and_kind(err: &JsValue) -> (String, String) {
    (
        get(err, "message").as_string().unwrap_or_default(),
        get(err, "kind").as_string().unwrap_or_default(),
    )
}

fn bytes_text(v: &JsValue) -> String {
    String::from_utf8(js_sys::Uint8Array::new(v).to_vec()).unwrap()
}

/// A session built the way the worker builds it: the file written into a
/// ScanBuffer in chunks, then imported, registered and indexed.
fn staged_session(bytes: &[u8], name: &str, settings: &JobSettings) -> pcpp::wasm::Session {
    staged_session_hashed(bytes, name, settings, None)
}

fn staged_session_hashed(
    bytes: &[u8],
    name: &str,
    settings: &JobSettings,
    hashed: Option<bool>,
) -> pcpp::wasm::Session {
    let mut buf = pcpp::wasm::ScanBuffer::new(name, bytes.len() as f64, hashed)
        .unwrap_or_else(|e| panic!("{e:?}"));
    for chunk in bytes.chunks(100_000) {
        buf.write(chunk).unwrap_or_else(|e| panic!("{e:?}"));
    }
    assert_eq!(buf.received(), bytes.len());
    let mut imp = buf
        .import_scan(js(&settings.scan))
        .unwrap_or_else(|e| panic!("{e:?}"));
    imp.register(js(&settings.registration))
        .unwrap_or_else(|e| panic!("{e:?}"));
    imp.index().unwrap_or_else(|e| panic!("{e:?}"))
}

fn demo_page_settings() -> JobSettings {
    let mut s = golden_settings();
    s.registration = RegistrationSettings {
        fiducials: FiducialSource::Auto,
        printer_points: test_part::FIDUCIALS_MM.to_vec(),
        method: RegistrationMethod::Lsq,
        ..Default::default()
    };
    s
}

/// The page hashes the scan in a second worker, beside the import: a
/// session whose ScanBuffer did not hash neither plans nor checks until
/// it is given the digest, then writes the bytes of one that did.
#[wasm_bindgen_test]
fn a_scan_hashed_beside_its_import_plans_once_its_digest_is_given() {
    let scan = demo::demo_scan_bytes();
    let settings = golden_settings();
    let mut hashed = staged_session(&scan, demo::DEMO_SCAN_NAME, &settings);
    let mut session = staged_session_hashed(&scan, demo::DEMO_SCAN_NAME, &settings, Some(false));
    let plan = |s: &mut pcpp::wasm::Session| plan_demo_drawing(s, &settings.plan, None);
    let err = plan(&mut session).expect_err("no digest yet");
    let (message, _) = message_and_kind(&err);
    assert!(
        message.starts_with(&format!("{}: its SHA-256", demo::DEMO_SCAN_NAME)),
        "{message}"
    );
    let program = get(&plan(&mut hashed).unwrap(), "gcode")
        .as_string()
        .unwrap();
    let checked = session.check_gcode(
        program.as_bytes(),
        "demo.gcode",
        js(&settings.plan.nozzle),
        settings.plan.process.tolerance_mm,
        None,
    );
    assert!(
        checked.is_err(),
        "a check compares the header with the digest"
    );
    assert!(session.set_scan_sha256(&[0u8; 31]).is_err());
    // The digest as the second worker finds it, in chunks.
    let mut stream = pcpp::wasm::Sha256Stream::new();
    for chunk in scan.chunks(70_000) {
        stream.update(chunk);
    }
    session
        .set_scan_sha256(&stream.finish())
        .unwrap_or_else(|e| panic!("{e:?}"));
    let out = plan(&mut session).unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(get(&out, "gcode").as_string().unwrap(), program);
    assert_eq!(
        get(&out, "report_json").as_string().unwrap(),
        get(&plan(&mut hashed).unwrap(), "report_json")
            .as_string()
            .unwrap()
    );
}

#[wasm_bindgen_test]
fn live_plan_writes_the_bytes_of_job_run_on_in_one_call() {
    let scan = demo::demo_scan_bytes();
    let svg = test_part::test_part_svg();
    // The golden settings (no fiducials) and the page's demo (auto
    // fiducials): the staged session must prepare the scan as
    // job::prepare_scan does.
    for settings in [golden_settings(), demo_page_settings()] {
        let prepared = demo_prepared(&scan, &settings);
        let mut session = staged_session(&scan, demo::DEMO_SCAN_NAME, &settings);
        session
            .set_path(svg.as_bytes(), demo::DEMO_PATH_NAME)
            .unwrap_or_else(|e| panic!("{e:?}"));
        let mut plan = settings.plan;
        // A drag: the placement moves, then a planner and a nozzle change
        // (the surface path is reused, then projected again).
        for step in 0..4 {
            if step == 1 {
                plan.placement.offset_mm.x += 1.25;
            } else if step == 2 {
                plan.planner = PlannerKind::Slope;
            } else if step == 3 {
                plan.nozzle.inner_diameter_mm = 0.413;
                plan.nozzle.outer_diameter_mm = 0.718;
            }
            // The paper's planners touch the part: their G-code needs the
            // risk accepted, in the page as in the CLI.
            let accept = !plan.planner.is_guarded();
            let want = job::run_on(
                &prepared,
                svg.as_bytes(),
                demo::DEMO_PATH_NAME,
                &plan,
                &MachineProfile::builtin("grbl").unwrap(),
                accept,
            )
            .unwrap();
            let out = session
                .plan_live(js(&plan), "grbl", accept, None, step == 0, None)
                .unwrap_or_else(|e| panic!("{e:?}"));
            // Compared without printing: a G-code file fills the screen.
            assert!(
                bytes_text(&get(&out, "gcode")) == want.gcode,
                "step {step}: the live plan's G-code differs from job::run_on's"
            );
            let mut report = serde_json::to_string_pretty(&want.report).unwrap();
            report.push('\n');
            assert!(
                bytes_text(&get(&out, "report")) == report,
                "step {step}: the live plan's report differs from job::run_on's"
            );
            // The per-point arrays are the report's, as f32 and codes.
            let view = get(&out, "view");
            let pieces = js_sys::Uint32Array::new(&get(&view, "pieces")).to_vec();
            let tool = js_sys::Float32Array::new(&get(&view, "tool")).to_vec();
            let defects = js_sys::Uint8Array::new(&get(&view, "defects")).to_vec();
            let toolpath: Vec<&[f64; 3]> = want.report.toolpath.iter().flatten().collect();
            assert_eq!(
                pieces,
                want.report
                    .toolpath
                    .iter()
                    .map(|p| p.len() as u32)
                    .collect::<Vec<_>>()
            );
            assert_eq!(tool.len(), 3 * toolpath.len());
            assert_eq!(tool[3], toolpath[1][0] as f32);
            let want_codes: Vec<u8> = want
                .report
                .defects
                .iter()
                .flatten()
                .map(|d| match d {
                    Defect::Good => 0,
                    Defect::Contact => 1,
                    Defect::Flattening => 2,
                    Defect::Floating => 3,
                })
                .collect();
            assert_eq!(defects, want_codes);
            let summary = get(&out, "summary");
            assert_eq!(
                get(&summary, "planner").as_string().unwrap(),
                plan.planner.name()
            );
            // The report's safe-motion part and its G-code header line.
            let motion: job::MotionReport =
                serde_wasm_bindgen::from_value(get(&summary, "motion")).unwrap();
            assert_eq!(motion, want.report.motion);
            assert_eq!(
                get(&summary, "motion_line").as_string().unwrap(),
                want.report.motion.summary_line()
            );
            // The comparison comes in the same call, on the same surface path,
            // with every planner's per-point errors for the plot.
            let comparison = get(&out, "comparison");
            let series = get(&out, "series");
            if step == 0 {
                let series = js_sys::Array::from(&series);
                assert_eq!(series.length() as usize, PlannerKind::ALL.len());
                let errors = js_sys::Float32Array::new(&get(&view, "error")).to_vec();
                for (sr, k) in series.iter().zip(PlannerKind::ALL) {
                    assert_eq!(get(&sr, "planner").as_string().unwrap(), k.name());
                    let e = js_sys::Float32Array::new(&get(&sr, "error")).to_vec();
                    let d = js_sys::Uint8Array::new(&get(&sr, "defects")).to_vec();
                    assert_eq!((e.len(), d.len()), (errors.len(), errors.len()));
                    if k == plan.planner {
                        assert_eq!(d, defects);
                        assert!(e
                            .iter()
                            .zip(&errors)
                            .all(|(a, b)| a.to_bits() == b.to_bits()));
                    }
                }
                let rows: Vec<serde_json::Value> =
                    serde_wasm_bindgen::from_value(comparison).unwrap();
                let grbl = MachineProfile::builtin("grbl").unwrap();
                let want_rows = job::compare_on(
                    &prepared,
                    svg.as_bytes(),
                    demo::DEMO_PATH_NAME,
                    &plan,
                    &grbl,
                )
                .unwrap()
                .rows;
                assert_eq!(rows.len(), PlannerKind::ALL.len());
                for (row, want) in rows.iter().zip(&want_rows) {
                    assert_eq!(row["planner"], want.planner.name());
                    assert_eq!(
                        row["quality"]["mean_abs_error_mm"],
                        want.quality.mean_abs_error_mm
                    );
                    assert_eq!(
                        row["motion"]["backward_moves"],
                        want.motion.backward_moves as u64
                    );
                }
            } else {
                assert!(comparison.is_null());
                assert!(series.is_null());
            }
        }
    }
}

#[wasm_bindgen_test]
fn a_failed_registration_keeps_the_import_and_bad_paths_keep_the_drawing() {
    let scan = demo::demo_scan_bytes();
    let settings = demo_page_settings();
    let mut buf = pcpp::wasm::ScanBuffer::demo();
    assert_eq!(buf.received(), scan.len());
    assert!(
        buf.write(b"x").is_err(),
        "a full buffer takes no more bytes"
    );
    let mut imp = buf.import_scan(js(&settings.scan)).unwrap();
    let bad = RegistrationSettings {
        printer_points: vec![DVec3::ZERO],
        ..settings.registration.clone()
    };
    let err = imp
        .register(js(&bad))
        .expect_err("one point cannot register");
    assert_eq!(message_and_kind(&err).1, "registration");
    imp.register(js(&settings.registration)).unwrap();
    let mut session = imp.index().unwrap_or_else(|e| panic!("{e:?}"));

    // No drawing yet: an error, not a panic.
    assert!(session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .is_err());
    let svg = test_part::test_part_svg();
    session
        .set_path(svg.as_bytes(), demo::DEMO_PATH_NAME)
        .unwrap();
    let first = session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .unwrap();
    // A broken SVG names the file (kind svg) and the previous drawing stays.
    let err = session
        .set_path(b"<svg><path d='M 0 0 L", "broken.svg")
        .expect_err("a broken SVG must not load");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "svg");
    assert!(message.contains("broken.svg"), "{message}");
    let again = session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .unwrap();
    assert_eq!(
        bytes_text(&get(&again, "gcode")),
        bytes_text(&get(&first, "gcode"))
    );
}

/// QA round 20 F6: a scan 1 m across in the metres it was read in, seen
/// edge-on, is refused on the page with the units advice of the build
/// volume's refusal, as on the command line.
#[wasm_bindgen_test]
fn a_scan_too_large_in_its_units_is_told_them_whatever_refuses_it() {
    let square = b"v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";
    let mut settings = JobSettings::default();
    settings.scan.units = Some(ScanUnits::M);
    let mut session = staged_session(square, "square.obj", &settings);
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" viewBox="0 0 10 10"><path d="M 2 5 L 8 5" stroke="black"/></svg>"#;
    session.set_path(svg.as_bytes(), "line.svg").unwrap();
    let err = session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .expect_err("a scan seen edge-on is refused");
    let advised = |err: &JsValue| {
        let (message, _) = message_and_kind(err);
        assert!(
            message.contains("seen edge-on from above")
                && message.contains(
                    "the scan is larger than the build volume of profile marlin (x 1000.0 mm, \
                     the volume 220.0 mm), read in metres: in centimetres it would be 10.0 x \
                     0.0 x 10.0 mm (--scan-units cm)"
                ),
            "{message}"
        );
    };
    advised(&err);
    // The comparison's refusal says the same (marlin when no profile is
    // named).
    let err = session
        .compare(svg.as_bytes(), "line.svg", js(&settings.plan), None, None)
        .expect_err("a scan seen edge-on is refused");
    advised(&err);
    // A stray vertex is named before any planner runs, as by `pcpp
    // compare` (review: the page's Session.compare planned on).
    let axis: Vec<f64> = (0..11).map(|i| 10.0 + 4.0 * i as f64).collect();
    let plate = pcpp::mesh::TriMesh::height_field(&axis, &axis, |x, y| {
        if (x, y) == (30.0, 30.0) {
            1e300
        } else {
            1.0
        }
    });
    let mut settings = JobSettings::default();
    settings.scan.units = Some(ScanUnits::Mm);
    let obj = demo::workloads::to_obj(&plate);
    let session = staged_session(obj.as_bytes(), "spike.obj", &settings);
    let err = session
        .compare(svg.as_bytes(), "line.svg", js(&settings.plan), None, None)
        .expect_err("a stray vertex is refused");
    let (message, _) = message_and_kind(&err);
    assert!(
        message.contains("because 1 vertex(es) lie far from the rest")
            && !message.contains("edge-on"),
        "{message}"
    );
}

#[wasm_bindgen_test]
fn the_page_refuses_scans_past_its_size_limit_before_reading() {
    let limit = pcpp::wasm::PAGE_MAX_SCAN_BYTES as f64;
    assert!(pcpp::wasm::check_scan_size("ok.stl", limit).is_ok());
    let err = pcpp::wasm::check_scan_size("huge-scan.stl", limit + 1.0).unwrap_err();
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "limit");
    assert!(
        message.contains("huge-scan.stl") && message.contains("512 MiB"),
        "{message}"
    );
    let err = pcpp::wasm::ScanBuffer::new("huge-scan.stl", limit + 1.0, None)
        .err()
        .expect("no buffer past the limit");
    assert_eq!(message_and_kind(&err).1, "limit");
    for bad in [f64::NAN, -1.0, f64::INFINITY] {
        assert!(pcpp::wasm::check_scan_size("x.stl", bad).is_err());
    }
    let err = pcpp::wasm::check_svg_size("huge.svg", 65.0 * 1048576.0).unwrap_err();
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "limit");
    assert!(message.contains("huge.svg") && message.contains("64 MiB"));

    // A buffer that was not filled does not import.
    let mut buf = pcpp::wasm::ScanBuffer::new("short.ply", 10.0, None).unwrap();
    buf.write(b"ply\n").unwrap();
    assert!(buf.write(&[0; 7]).is_err(), "more than the declared size");
    let err = buf
        .import_scan(js(&ImportOptions::DEFAULT))
        .err()
        .expect("a short read must not import");
    assert!(message_and_kind(&err).0.contains("short.ply"));
}

#[wasm_bindgen_test]
fn too_long_paths_are_refused_with_the_page_and_the_core_messages() {
    let settings = golden_settings();
    let mut session = staged_session(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    session
        .set_path(test_part::test_part_svg().as_bytes(), demo::DEMO_PATH_NAME)
        .unwrap();
    // The demo's 408 mm of lines scaled 1000 times: ~1.35 million samples,
    // past the page's limit but within the core's per subpath.
    let mut plan = settings.plan;
    plan.placement.scale = 1000.0;
    let err = session
        .plan_live(js(&plan), "marlin", false, None, false, None)
        .expect_err("past the page's sample limit");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "limit", "{message}");
    assert!(
        message.contains(demo::DEMO_PATH_NAME)
            && message.contains("1 million")
            && message.contains("(pcpp plan allows 10 million)"),
        "{message}"
    );
    // Scaled 50 000 times one line needs more samples than the core allows
    // per subpath: the core's own message (sampling.rs), as the CLI prints it.
    plan.placement.scale = 50_000.0;
    let err = session
        .plan_live(js(&plan), "marlin", false, None, false, None)
        .expect_err("past the core's sample limit");
    let (message, _) = message_and_kind(&err);
    assert!(
        message.contains("samples needed") && message.contains("10000000"),
        "{message}"
    );
}

// ---- safe motion, the G-code check and the demo parts in the page ----

/// A demo part's session as the worker makes it (ScanBuffer.demoPart, then
/// the staged import), with the part's drawing set, and its page settings.
fn demo_part_session(name: &str) -> (pcpp::wasm::Session, JobSettings) {
    let part = pcpp::wasm::demo_part(name).unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let settings: JobSettings = serde_wasm_bindgen::from_value(get(&part, "settings")).unwrap();
    let buf = pcpp::wasm::ScanBuffer::demo_part(name)
        .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let mut imp = buf
        .import_scan(js(&settings.scan))
        .unwrap_or_else(|e| panic!("{e:?}"));
    imp.register(js(&settings.registration))
        .unwrap_or_else(|e| panic!("{e:?}"));
    let mut session = imp.index().unwrap_or_else(|e| panic!("{e:?}"));
    let svg = get(&part, "svg").as_string().unwrap();
    let path_name = get(&part, "path_name").as_string().unwrap();
    session
        .set_path(svg.as_bytes(), &path_name)
        .unwrap_or_else(|e| panic!("{e:?}"));
    (session, settings)
}

#[wasm_bindgen_test]
fn demo_parts_load_as_the_cli_makes_them() {
    let list: Vec<serde_json::Value> =
        serde_wasm_bindgen::from_value(pcpp::wasm::demo_parts().unwrap()).unwrap();
    let names: Vec<&str> = list.iter().map(|p| p["name"].as_str().unwrap()).collect();
    let want: Vec<&str> = DemoPart::ALL.iter().map(|p| p.name()).collect();
    assert_eq!(names, want);
    for part in DemoPart::ALL {
        let view =
            pcpp::wasm::demo_part(part.name()).unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
        assert_eq!(get(&view, "svg").as_string().unwrap(), part.svg());
        assert_eq!(
            get(&view, "scan_name").as_string().unwrap(),
            part.scan_name()
        );
        let settings: JobSettings = serde_wasm_bindgen::from_value(get(&view, "settings")).unwrap();
        assert_eq!(settings.plan.placement, part.placement());
        assert_eq!(settings.plan.planner, PlannerKind::Even);
        let auto = settings.registration.fiducials == FiducialSource::Auto;
        assert_eq!(auto, part == DemoPart::TestPart, "{part}");
        let bytes = pcpp::wasm::demo_part_scan(part.name())
            .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
        assert_eq!(bytes, demo::to_binary_ply(&part.mesh()));
        let buf = pcpp::wasm::ScanBuffer::demo_part(part.name())
            .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
        assert_eq!(buf.received(), bytes.len());
    }
    assert_eq!(
        pcpp::wasm::ScanBuffer::demo().received(),
        demo::demo_scan_bytes().len()
    );
    let err = JsValue::from(pcpp::wasm::demo_part("teapot").err().unwrap());
    let (message, _) = message_and_kind(&err);
    assert!(
        message.contains("unknown demo part 'teapot'") && message.contains("stepped-block"),
        "{message}"
    );
    assert_eq!(
        pcpp::wasm::planners(),
        PlannerKind::ALL
            .iter()
            .map(|k| k.name().to_string())
            .collect::<Vec<_>>()
    );
}

/// QA round 19 F4: the page took a profile that passed validation and
/// then could not write the job, dropping the one in use; it tells them
/// apart by the error's `profile` (its file and field), which only the
/// profile's own faults carry.
#[wasm_bindgen_test]
fn a_profile_that_cannot_write_the_job_is_named_by_its_error() {
    let (mut session, settings) = demo_part_session("stepped-block");
    let mut homes = MachineProfile::builtin("marlin").unwrap();
    homes.end = vec!["M107".into(), "G28".into()];
    let text = homes.to_json().unwrap();
    let err = session
        .plan_live(
            js(&settings.plan),
            &text,
            false,
            Some("end_G28.json".into()),
            false,
            None,
        )
        .expect_err("an end block that homes");
    let profile = get(&err, "profile");
    assert_eq!(
        get(&profile, "file").as_string().as_deref(),
        Some("end_G28.json")
    );
    assert_eq!(
        get(&profile, "field").as_string().as_deref(),
        Some("end[1]")
    );
    // A refusal that is not the profile's carries none.
    let mut plan = settings.plan;
    plan.planner = PlannerKind::Slope;
    let err = session
        .plan_live(js(&plan), "marlin", false, None, false, None)
        .expect_err("slope runs into the steps' walls");
    assert!(get(&err, "profile").is_undefined());
}

#[wasm_bindgen_test]
fn live_plans_that_touch_are_refused_by_line_unless_the_risk_is_accepted() {
    let (mut session, settings) = demo_part_session("stepped-block");
    let mut plan = settings.plan;
    plan.planner = PlannerKind::Slope;
    let err = session
        .plan_live(js(&plan), "marlin", false, None, true, None)
        .expect_err("slope runs into the steps' walls");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "touching");
    assert!(
        message.contains("of planner slope") && message.contains("line "),
        "{message}"
    );
    let touching: pcpp::motion::MotionSummary =
        serde_wasm_bindgen::from_value(get(&err, "touching")).unwrap();
    assert!(touching.touching_moves > 0);
    let first = &touching.touching[0];
    assert!(
        message.contains(&format!("line {}: the move", first.line.unwrap())),
        "{message}"
    );
    // The planners were compared on the settings that failed.
    let rows: Vec<job::ComparisonRow> =
        serde_wasm_bindgen::from_value(get(&err, "comparison")).unwrap();
    assert_eq!(rows.len(), PlannerKind::ALL.len());
    let slope = rows
        .iter()
        .find(|r| r.planner == PlannerKind::Slope)
        .unwrap();
    assert!(slope.motion.touching_moves > 0);
    for r in rows.iter().filter(|r| r.planner.is_guarded()) {
        assert_eq!(r.motion.touching_moves, 0, "{:?}", r.planner);
    }
    // The refused tool path and where it was planned, for the view (QA
    // round 7 F3): slope's own points, as a plan's view gives them.
    let view = get(&err, "view");
    let tool = js_sys::Float32Array::from(get(&view, "tool")).to_vec();
    assert!(!tool.is_empty() && tool.len() % 3 == 0, "{}", tool.len());
    let pieces = js_sys::Uint32Array::from(get(&view, "pieces")).to_vec();
    assert_eq!(pieces.iter().sum::<u32>() as usize * 3, tool.len());
    let placed: pcpp::svg::Placement =
        serde_wasm_bindgen::from_value(get(&err, "placement")).unwrap();
    assert_eq!(placed, plan.placement);
    // Without the comparison, none is attached.
    let err = session
        .plan_live(js(&plan), "marlin", false, None, false, None)
        .err()
        .unwrap();
    assert!(get(&err, "comparison").is_undefined());

    // Accepted: written, and said so in the summary and the G-code header.
    let out = session
        .plan_live(js(&plan), "marlin", true, None, false, None)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let summary = get(&out, "summary");
    let motion: job::MotionReport =
        serde_wasm_bindgen::from_value(get(&summary, "motion")).unwrap();
    assert!(motion.risk_accepted);
    assert_eq!(motion.program.touching_moves, touching.touching_moves);
    let line = get(&summary, "motion_line").as_string().unwrap();
    assert!(line.starts_with("WARNING: "), "{line}");
    assert!(bytes_text(&get(&out, "gcode")).contains(&format!("; safe motion: {line}\n")));

    // The default planner clears the steps.
    let out = session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let motion: job::MotionReport =
        serde_wasm_bindgen::from_value(get(&get(&out, "summary"), "motion")).unwrap();
    assert!(!motion.risk_accepted);
    assert_eq!(motion.program.touching_moves, 0);
}

#[wasm_bindgen_test]
fn gcode_files_are_checked_against_the_scan_and_bad_ones_name_the_line() {
    let settings = golden_settings();
    let session = staged_session(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    let nozzle = js(&settings.plan.nozzle);
    let tol = settings.plan.process.tolerance_mm;
    let check = |text: &[u8], name: &str| {
        session.check_gcode(text, name, js(&settings.plan.nozzle), tol, None)
    };
    // The demo's own G-code clears the part.
    let ok = check(GOLDEN_MARLIN.as_bytes(), "demo-even.gcode").unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(get(&ok, "clear"), JsValue::TRUE);
    let c: job::GcodeCheck = serde_wasm_bindgen::from_value(ok).unwrap();
    assert!(c.is_clear() && c.summary.moves > 1000);
    assert!(c.summary.min_clearance_mm.unwrap() >= tol);

    // Down beside a 2 mm wall, then up across its corner: line 4.
    let cut =
        "G21 G90\nG0 X15.4 Y16 Z30\nG1 X15.4 Y16 Z5.603 F300\nG1 X16.230 Y16 Z7.603\nG0 Z30\n";
    let bad = check(cut.as_bytes(), "cut.gcode").unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(get(&bad, "clear"), JsValue::FALSE);
    // For the view: the moves placed in the frame (the first travel's
    // start is unknown), feed, too close, rapid.
    let kinds = js_sys::Uint8Array::new(&get(&bad, "kinds")).to_vec();
    assert_eq!(kinds, [0, 2, 1]);
    let moves = js_sys::Float32Array::new(&get(&bad, "moves")).to_vec();
    assert_eq!(moves[6..12], [15.4, 16.0, 5.603, 16.23, 16.0, 7.603]);
    let c: job::GcodeCheck = serde_wasm_bindgen::from_value(bad).unwrap();
    assert_eq!(c.summary.touching_moves, 1);
    assert_eq!(c.summary.touching[0].line, Some(4));
    assert!(c.summary.touching[0].rise_mm > 1.0);

    // The dialect chosen in the page: grbl reads X/Y beside M3 as Grbl
    // does, a move whose end is known (QA round 3).
    let laser = b"G21 G90\nG0 X40 Y40 Z30\nG1 Z29 F300\nX41 Y40 M3 S100\nX42 Y40 M3 S0\n";
    let as_any: job::GcodeCheck =
        serde_wasm_bindgen::from_value(check(laser, "laser.nc").unwrap()).unwrap();
    let as_grbl: job::GcodeCheck = serde_wasm_bindgen::from_value(
        session
            .check_gcode(
                laser,
                "laser.nc",
                js(&settings.plan.nozzle),
                tol,
                Some("grbl".into()),
            )
            .unwrap(),
    )
    .unwrap();
    assert_eq!(as_grbl.summary.moves, as_any.summary.moves + 1);
    assert!(
        as_grbl.notes.iter().any(|n| n.contains("as Grbl makes it")),
        "{:?}",
        as_grbl.notes
    );

    // What the reader cannot follow is an error naming the file and line.
    let err = check(b"G21 G90\nG0 X10 Y10 Z30\nG2 X20 Y10 I5 J0\n", "arc.nc").unwrap_err();
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "gcode");
    assert!(message.starts_with("arc.nc, line 3: arcs"), "{message}");
    let err = check(b"G1 X1\n; \xff\n", "latin1.gcode").unwrap_err();
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "gcode");
    assert!(
        message.contains("latin1.gcode: not UTF-8 text (byte 8)"),
        "{message}"
    );
    // A nozzle the core refuses, and a settings object that is not one.
    let mut thin = settings.plan.nozzle;
    thin.outer_diameter_mm = 0.1;
    let err = session
        .check_gcode(cut.as_bytes(), "cut.gcode", js(&thin), tol, None)
        .unwrap_err();
    assert!(message_and_kind(&err).0.contains("outer"), "{err:?}");
    assert!(session
        .check_gcode(
            cut.as_bytes(),
            "cut.gcode",
            JsValue::from_str("x"),
            tol,
            None
        )
        .is_err());
    assert!(session
        .check_gcode(cut.as_bytes(), "cut.gcode", nozzle, -1.0, None)
        .is_err());
}

// ---- the print preview (src/preview.rs through the bindings) ----

#[wasm_bindgen_test]
fn gcode_previews_as_timed_moves_with_their_clearance() {
    let settings = golden_settings();
    let session = staged_session(&demo::demo_scan_bytes(), demo::DEMO_SCAN_NAME, &settings);
    let tol = settings.plan.process.tolerance_mm;
    let nozzle = || js(&settings.plan.nozzle);
    let speed = settings.plan.process.speed_mm_s;
    let p = session
        .preview_gcode(
            GOLDEN_MARLIN.as_bytes(),
            "demo.gcode",
            nozzle(),
            tol,
            "marlin",
            None,
            speed,
        )
        .unwrap_or_else(|e| panic!("{e:?}"));
    let lines = js_sys::Uint32Array::new(&get(&p, "lines")).to_vec();
    let classes = js_sys::Uint8Array::new(&get(&p, "classes")).to_vec();
    let starts = js_sys::Float64Array::new(&get(&p, "starts")).to_vec();
    let durations = js_sys::Float64Array::new(&get(&p, "durations")).to_vec();
    let moves = js_sys::Float64Array::new(&get(&p, "moves")).to_vec();
    let rapid = js_sys::Uint8Array::new(&get(&p, "rapid")).to_vec();
    // The moves the G-code check follows, none closer than tol.
    let program = pcpp::gcode::read_gcode(GOLDEN_MARLIN, "demo.gcode").unwrap();
    assert_eq!(lines.len(), program.moves.len());
    assert!(classes.iter().all(|&c| c < 2) && classes.contains(&1));
    let total = get(&p, "total_s").as_f64().unwrap();
    assert!((starts[starts.len() - 1] + durations[durations.len() - 1] - total).abs() < 1e-9);
    // The page's timeline at a print move's middle: its line and position.
    let t = pcpp::wasm::PreviewTimeline::new(&moves, &starts, &durations, &lines, &rapid)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let i = rapid.iter().position(|&r| r == 0).unwrap() + 1;
    let c = json(t.at(starts[i] + 0.5 * durations[i]).unwrap());
    assert_eq!(c["line"], lines[i]);
    let mid: Vec<f64> = (0..3)
        .map(|k| 0.5 * (moves[6 * i + k] + moves[6 * i + 3 + k]))
        .collect();
    for k in 0..3 {
        assert!((c["position"][k].as_f64().unwrap() - mid[k]).abs() < 1e-9);
    }
    // Mismatched arrays and unreadable files are errors, not panics.
    assert!(
        pcpp::wasm::PreviewTimeline::new(&moves, &starts, &durations, &lines[1..], &rapid).is_err()
    );
    let err = session
        .preview_gcode(
            b"G2 X1 Y1 I1 J0\n",
            "arc.nc",
            nozzle(),
            tol,
            "marlin",
            None,
            speed,
        )
        .unwrap_err();
    assert_eq!(message_and_kind(&err).1, "gcode");
}

// ---- a scan in its scanner frame, placed on the bed (issue 13) ----

fn json(v: JsValue) -> serde_json::Value {
    serde_wasm_bindgen::from_value(v).unwrap()
}

/// JSON as the page sends it: plain objects, not `Map`s.
fn obj(v: &serde_json::Value) -> JsValue {
    use serde::Serialize;
    v.serialize(&serde_wasm_bindgen::Serializer::new().serialize_maps_as_objects(true))
        .unwrap()
}

#[wasm_bindgen_test]
fn a_scan_in_its_scanner_frame_is_placed_on_the_bed_by_the_page() {
    // The test part as a scanner gives it: turned and 800 mm down.
    let mut mesh = test_part::test_part();
    let g = pcpp::DMat4::from_translation(DVec3::new(-300.0, 150.0, -800.0))
        * pcpp::DMat4::from_rotation_z(0.5);
    mesh.transform(&g);
    let bytes = demo::to_binary_ply(&mesh);
    let mut settings = JobSettings::default();
    let as_scanned = staged_session(&bytes, "face.ply", &settings);
    let info = json(as_scanned.info().unwrap());
    let reg = &info["registration"];
    assert_eq!(reg["status"]["kind"], "as-scanned");
    assert!(reg["status_text"]
        .as_str()
        .unwrap()
        .starts_with("unregistered, taken as it is"));
    assert_eq!(info["bbox_mm"], info["scan_bbox_mm"]);
    let b: Vec<f64> = info["bbox_mm"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|p| p.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
        .collect();
    let fit = json(pcpp::wasm::volume_fit(&b, "marlin", None, None).unwrap());
    assert_eq!(fit["inside"], false);
    let message = fit["message"].as_str().unwrap();
    assert!(
        message.contains("outside the build volume of profile marlin")
            && message.contains("(--place-scan bed)"),
        "{message}"
    );
    assert!(pcpp::wasm::volume_fit(&b[..5], "marlin", None, None).is_err());
    // Read in metres, a 2 m cube is told the units it fits in (QA round
    // 16 F10); units the page never sends are an error.
    let cube = [0.0, 0.0, 0.0, 2000.0, 2000.0, 2000.0];
    let fit = json(pcpp::wasm::volume_fit(&cube, "marlin", None, Some("m".into())).unwrap());
    let message = fit["message"].as_str().unwrap();
    assert!(
        message.contains("read in metres: in centimetres it would be 20.0 x 20.0 x 20.0 mm"),
        "{message}"
    );
    assert!(pcpp::wasm::volume_fit(&cube, "marlin", None, Some("furlong".into())).is_err());

    // Placed on the bed of the profile: lowest point at z 0, the scan's
    // own frame unchanged, the status says so.
    let bed = pcpp::wasm::bed_of("marlin", None).unwrap();
    let placement = serde_json::json!({
        "mode": "on-bed", "bed": json(bed), "rotation_deg": 0.0, "offset_mm": [0.0, 0.0, 0.0]
    });
    settings.registration.scan_placement = serde_json::from_value(placement.clone()).unwrap();
    let mut placed = staged_session(&bytes, "face.ply", &settings);
    let pinfo = json(placed.info().unwrap());
    assert_eq!(
        pinfo["registration"]["status_text"],
        "unregistered, placed on the bed"
    );
    assert_eq!(pinfo["scan_bbox_mm"], info["scan_bbox_mm"]);
    assert!(pinfo["bbox_mm"][0][2].as_f64().unwrap().abs() < 1e-9);

    // The drawing carried with the scan, and a new drawing centred on it.
    let drawing = serde_json::json!({"offset_mm": [b[0] + 10.0, b[1] + 10.0], "rotation_deg": 0.0, "scale": 1.0});
    let carried = json(
        pcpp::wasm::carry_drawing(
            obj(&drawing),
            &b,
            obj(&serde_json::json!({"mode": "as-scanned"})),
            obj(&placement),
        )
        .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e))),
    );
    assert_eq!(carried["scale"], 1.0);
    // Placed without a turn, the scan moved by a shift: the drawing too.
    for k in 0..2 {
        let shift = pinfo["bbox_mm"][0][k].as_f64().unwrap() - b[k];
        let moved =
            carried["offset_mm"][k].as_f64().unwrap() - drawing["offset_mm"][k].as_f64().unwrap();
        assert!((moved - shift).abs() < 1e-9, "{moved} vs {shift}");
    }
    let spiral = antennas::paper_spiral_svg();
    placed
        .set_path(spiral.as_bytes(), "spiral.svg")
        .unwrap_or_else(|e| panic!("{e:?}"));
    let centred = json(
        placed
            .centre_drawing(js(&settings.plan.placement), None)
            .unwrap_or_else(|e| panic!("{e:?}")),
    );
    assert!(centred["note"].is_null(), "{centred}");
    // Far larger than the scan: scaled down to fit, unless the scale is to
    // be kept (a Scale the user typed, `--place centre,ROT,SCALE`).
    let mut huge = settings.plan.placement;
    huge.scale = 50.0;
    let fitted = json(
        placed
            .centre_drawing(js(&huge), None)
            .unwrap_or_else(|e| panic!("{e:?}")),
    );
    assert!(
        fitted["placement"]["scale"].as_f64().unwrap() < 50.0,
        "{fitted}"
    );
    assert!(fitted["note"].is_string(), "{fitted}");
    let kept = json(
        placed
            .centre_drawing(js(&huge), Some(false))
            .unwrap_or_else(|e| panic!("{e:?}")),
    );
    assert_eq!(kept["placement"]["scale"], 50.0, "{kept}");
    let note = kept["note"].as_str().unwrap_or_default();
    assert!(note.contains("kept at its scale"), "{kept}");
    settings.plan.placement = serde_json::from_value(centred["placement"].clone()).unwrap();
    let out = placed
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let gcode = bytes_text(&get(&out, "gcode"));
    assert!(
        gcode.contains("; registration: unregistered, placed on the bed;"),
        "{}",
        &gcode[..800]
    );
}

/// A point cloud of a whole object (a pebble, top and underside, as a
/// turntable scanner gives it): the page gets the refusal of its G-code
/// with a kind of its own, naming the file, and the G-code once the user
/// accepts the risk.
#[wasm_bindgen_test]
fn a_whole_objects_cloud_is_refused_with_its_own_kind() {
    let text = demo::workloads::to_xyz(&demo::pebble_cloud(0.25));
    // On the bed, where its centre goes to the bed's centre.
    let mut settings = JobSettings::default();
    let marlin = MachineProfile::builtin("marlin").unwrap();
    settings.registration.scan_placement = pcpp::placement::ScanPlacement::on_bed(&marlin);
    let centre = pcpp::placement::Bed::of_profile(&marlin).centre_mm;
    settings.plan.placement.offset_mm = centre - pcpp::DVec2::new(6.0, 1.0);
    let mut session = session_on(text.as_bytes(), "pebble.xyz", &settings);
    let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="12mm" height="2mm" viewBox="0 0 12 2"><path d="M0 1 H12" fill="none" stroke="black"/></svg>"#;
    let err = session
        .plan(
            svg,
            "line.svg",
            js(&settings.plan),
            "marlin",
            false,
            None,
            None,
        )
        .expect_err("G-code written for a whole object's cloud");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "whole-object", "{message}");
    assert!(
        message.contains("pebble.xyz") && message.contains("as a mesh"),
        "{message}"
    );
    session
        .plan(
            svg,
            "line.svg",
            js(&settings.plan),
            "marlin",
            true,
            None,
            None,
        )
        .unwrap_or_else(|e| panic!("{e:?}"));
}

/// A file written into a ScanBuffer in chunks, as the worker reads it.
fn written(name: &str, bytes: &[u8]) -> pcpp::wasm::ScanBuffer {
    let mut buf = pcpp::wasm::ScanBuffer::new(name, bytes.len() as f64, None)
        .unwrap_or_else(|e| panic!("{e:?}"));
    for chunk in bytes.chunks(100_000) {
        buf.write(chunk).unwrap_or_else(|e| panic!("{e:?}"));
    }
    buf
}

/// The page's import of a `.gltf` with its buffer in a separate file: the
/// scan lists the file it needs (decoded, with the name to select), takes
/// it as a ScanBuffer of its own, and plans the G-code and report the CLI
/// writes for the same files (the core's `prepare_scan_owned_with`); the
/// scan's info names the `.bin` and its hash. Without it the import fails
/// (kind `mesh`) naming the buffer and the file; a remote URI is refused
/// when listed.
#[wasm_bindgen_test]
fn a_gltf_with_a_separate_bin_imports_with_it_and_names_it_without() {
    let part = DemoPart::SteppedBlock;
    let (gltf, bin) = demo::to_gltf_separate(&part.mesh(), "block%20scan.bin");
    let mut settings = JobSettings::default();
    settings.plan.placement = part.placement();

    let mut scan = written("block.gltf", &gltf);
    let needed: serde_json::Value =
        serde_wasm_bindgen::from_value(scan.external_files().unwrap_or_else(|e| panic!("{e:?}")))
            .unwrap();
    assert_eq!(
        needed,
        serde_json::json!([{"buffer": 0, "uri": "block%20scan.bin", "path": "block scan.bin",
            "file_name": "block scan.bin"}])
    );
    scan.add_external_file(written("block scan.bin", &bin))
        .unwrap_or_else(|e| panic!("{e:?}"));
    // The page's staged steps (web/worker.js).
    let mut import = scan
        .import_scan(js(&settings.scan))
        .unwrap_or_else(|e| panic!("{e:?}"));
    import
        .register(js(&settings.registration))
        .unwrap_or_else(|e| panic!("{e:?}"));
    let mut session = import.index().unwrap_or_else(|e| panic!("{e:?}"));
    let info = json(session.info().unwrap());
    let want = job::InputFile::new("block scan.bin", &bin);
    assert_eq!(info["external_files"][0]["name"], "block scan.bin");
    assert_eq!(info["external_files"][0]["sha256"], want.sha256.as_str());
    session
        .set_path(part.svg().as_bytes(), "block.svg")
        .unwrap_or_else(|e| panic!("{e:?}"));
    let out = session
        .plan_live(js(&settings.plan), "marlin", false, None, false, None)
        .unwrap_or_else(|e| panic!("{e:?}"));
    let files = pcpp::mesh::ExternalFiles::new().with("block scan.bin", bin.clone());
    let native = job::prepare_scan_owned_with(
        gltf.clone(),
        "block.gltf",
        files,
        &settings.scan,
        &settings.registration,
        job::Candidates::Listed,
    )
    .unwrap();
    let profile = MachineProfile::builtin("marlin").unwrap();
    let want_gcode = job::run_on(
        &native,
        part.svg().as_bytes(),
        "block.svg",
        &settings.plan,
        &profile,
        false,
    )
    .unwrap()
    .gcode;
    let gcode = bytes_text(&get(&out, "gcode"));
    assert!(
        gcode.contains("; scan external file: block scan.bin ("),
        "{}",
        &gcode[..600]
    );
    assert_eq!(gcode, want_gcode);

    // Without the .bin: the page's error names it.
    let err = written("block.gltf", &gltf)
        .import_scan(js(&settings.scan))
        .err()
        .expect("no import without the .bin");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "mesh");
    assert!(
        message.starts_with("block.gltf: buffer 0 ")
            && message.contains("'block scan.bin'")
            && message.contains("select both files together"),
        "{message}"
    );
    // A buffer on the web, refused when listed.
    let remote = String::from_utf8(gltf)
        .unwrap()
        .replace("block%20scan.bin", "https://example.com/scan.bin");
    let err = written("block.gltf", remote.as_bytes())
        .external_files()
        .expect_err("a remote buffer is refused");
    let (message, kind) = message_and_kind(&err);
    assert_eq!(kind, "mesh");
    assert!(
        message.contains("buffer 0 refers to 'https://example.com/scan.bin', a remote URI"),
        "{message}"
    );
}

/// A Draco-compressed glTF (Google's encoder, EdgeBreaker; see
/// tests/data/realworld/SOURCES.md) decodes in wasm32 to the uncompressed
/// bunny: the same triangles, each vertex within a quantization step of its
/// own; and the page's staged import takes it.
#[wasm_bindgen_test]
fn a_draco_compressed_gltf_decodes_to_the_uncompressed_scan() {
    decodes_to_the_bunny(
        "bunny-draco.glb",
        include_bytes!("data/realworld/mesh/bunny-draco.glb"),
    );
}

/// meshopt-compressed glTFs (gltfpack: 16-bit positions, and float
/// positions through the exponential filter) decode in wasm32 to the
/// uncompressed bunny, and the page's staged import takes them.
#[wasm_bindgen_test]
fn a_meshopt_compressed_gltf_decodes_to_the_uncompressed_scan() {
    decodes_to_the_bunny(
        "bunny-meshopt.glb",
        include_bytes!("data/realworld/mesh/bunny-meshopt.glb"),
    );
    decodes_to_the_bunny(
        "bunny-meshopt-vpf.glb",
        include_bytes!("data/realworld/mesh/bunny-meshopt-vpf.glb"),
    );
}

/// The compressed bunny `name` imports as the uncompressed one: the same
/// triangles, each vertex within a quantization step (14 bits) of its own;
/// and the page's staged import (web/worker.js) takes it.
fn decodes_to_the_bunny(name: &str, compressed: &[u8]) {
    let plain = include_bytes!("data/realworld/mesh/bunny.glb");
    let original = import_mesh(plain, "bunny.glb", &ImportOptions::DEFAULT).unwrap();
    let decoded = import_mesh(compressed, name, &ImportOptions::DEFAULT).unwrap();
    let (lo, hi) = original.mesh.bbox().unwrap();
    let step = (hi - lo).max_element() / 16383.0;
    assert_eq!(
        decoded.mesh.triangle_count(),
        original.mesh.triangle_count()
    );
    let nearest: Vec<u32> = decoded
        .mesh
        .vertices
        .iter()
        .map(|v| {
            let (k, d) = original
                .mesh
                .vertices
                .iter()
                .enumerate()
                .map(|(k, o)| (k, o.distance(*v)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(d <= step, "{name}: {v} is {d} mm from the nearest vertex");
            k as u32
        })
        .collect();
    let sorted = |mut t: [u32; 3]| {
        t.sort_unstable();
        t
    };
    let want: std::collections::BTreeSet<[u32; 3]> =
        original.mesh.triangles.iter().map(|&t| sorted(t)).collect();
    let got: std::collections::BTreeSet<[u32; 3]> = decoded
        .mesh
        .triangles
        .iter()
        .map(|t| sorted(t.map(|v| nearest[v as usize])))
        .collect();
    assert_eq!(got, want, "{name}");
    // The page's staged steps (web/worker.js).
    let settings = JobSettings::default();
    let mut import = written(name, compressed)
        .import_scan(js(&settings.scan))
        .unwrap_or_else(|e| panic!("{e:?}"));
    import
        .register(js(&RegistrationSettings::default()))
        .unwrap_or_else(|e| panic!("{e:?}"));
    import.index().unwrap_or_else(|e| panic!("{e:?}"));
}
