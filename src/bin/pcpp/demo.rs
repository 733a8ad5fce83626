//! `pcpp demo`: a generated part planned by every planner, with its files,
//! the comparison and (for the paper's test part) its registration and the
//! antenna drawings.

use std::fmt::Write as _;

use pcpp::demo::parts::DemoPart;
use pcpp::demo::{self, antennas, test_part};
use pcpp::job::{self, FiducialSource, InputFile, JobSettings};
use pcpp::planners::PlannerKind;
use pcpp::registration::RegistrationMethod;

use crate::args::DemoArgs;
use crate::files::{to_json, Staged};
use crate::plan::{comparison_json, registration_line};
use crate::progress::{thousands, Progress};
use crate::settings::builtin_profile;
use crate::{CliResult, Failure};

/// The start of the demo's file names: `demo` for the test part, else
/// `demo-<part>`.
fn demo_prefix(part: DemoPart) -> String {
    match part {
        DemoPart::TestPart => "demo".into(),
        _ => format!("demo-{part}"),
    }
}

/// The demo's G-code file name for a planner.
fn demo_gcode_name(part: DemoPart, k: PlannerKind) -> String {
    format!("{}-{}.gcode", demo_prefix(part), k.name())
}

pub fn cmd_demo(a: &DemoArgs, progress: &Progress) -> CliResult<()> {
    let out = &a.folder();
    let profile = builtin_profile(&a.dialect)?;
    let part = a.part;
    let fail = |what: &str, e: &dyn std::fmt::Display| Failure::Input(format!("demo {what}: {e}"));

    progress.step(format!("building the demo part {part}..."));
    let scan = demo::to_binary_ply(&part.mesh());
    let svg = part.svg();
    let (scan_name, path_name) = (part.scan_name(), part.path_name());
    let mut settings = JobSettings::default();
    settings.plan.placement = part.placement();
    let prepared = job::prepare_scan(&scan, &scan_name, &settings.scan, &settings.registration)
        .map_err(|e| fail("scan", &e))?;
    progress.note(&format!(
        "scan: {} triangles",
        thousands(prepared.triangle_count())
    ));

    // Registration as a user would run it: the holes found in the scan
    // matched to the printer points. The test part is already in the
    // printer frame, so G is the identity and the residuals are ~0.
    let registration = if part == DemoPart::TestPart {
        progress.step("registering the scan on its fiducial holes...");
        let reg_settings = job::RegistrationSettings {
            fiducials: FiducialSource::Auto,
            printer_points: test_part::FIDUCIALS_MM.to_vec(),
            method: RegistrationMethod::Lsq,
            ..Default::default()
        };
        Some(
            job::registration_for(&prepared.fiducials, &reg_settings)
                .map_err(|e| fail("registration", &e))?,
        )
    } else {
        None
    };

    // One G-code per planner. The guarded planners never touch the part;
    // the paper's three are written even where they do (their headers say
    // so), since they are there to be compared.
    std::fs::create_dir_all(out)
        .map_err(|e| Failure::Input(format!("cannot create {}: {e}", out.display())))?;
    let mut staged = Staged::default();
    let mut rows = Vec::new();
    let mut default_report = None;
    let mut regions = Vec::new();
    let default_planner = PlannerKind::default();
    for (i, k) in PlannerKind::ALL.into_iter().enumerate() {
        progress.step(format!(
            "planning ({k}, {} of {})...",
            i + 1,
            PlannerKind::ALL.len()
        ));
        let mut plan = settings.plan;
        plan.planner = k;
        let o = job::run_on(
            &prepared,
            svg.as_bytes(),
            &path_name,
            &plan,
            &profile,
            !k.is_guarded(),
        )
        .map_err(|e| fail("plan", &e))?;
        rows.push(job::ComparisonRow::of(&o.plan));
        if part == DemoPart::TestPart {
            regions.push((k, test_part::region_summaries(&o.plan)));
        }
        staged.add(&out.join(demo_gcode_name(part, k)), o.gcode.as_bytes())?;
        if k == default_planner {
            default_report = Some(o.report);
        }
    }
    let prefix = demo_prefix(part);
    let mut files: Vec<(String, Vec<u8>)> = vec![
        (scan_name, scan),
        (path_name.clone(), svg.clone().into_bytes()),
        (
            format!("{prefix}-comparison.json"),
            to_json(&comparison_json(
                &[
                    prepared.file.clone(),
                    InputFile::new(&path_name, svg.as_bytes()),
                ],
                &settings.plan,
                &rows,
            ))?
            .into_bytes(),
        ),
        (
            format!("{prefix}-{default_planner}-report.json"),
            to_json(&default_report)?.into_bytes(),
        ),
    ];
    if let Some(registration) = &registration {
        let antenna =
            |r: Result<String, antennas::AntennaError>| r.map_err(|e| fail("antenna", &e));
        files.extend([
            (
                "demo-registration.json".into(),
                to_json(&serde_json::json!({
                    "fiducials": "auto",
                    "printer_points": test_part::FIDUCIALS_MM,
                    "registration": registration,
                }))?
                .into_bytes(),
            ),
            (
                "antenna-spiral.svg".into(),
                antennas::paper_spiral_svg().into_bytes(),
            ),
            (
                "antenna-hilbert.svg".into(),
                antenna(antennas::hilbert_loop_svg(4, 40.0))?.into_bytes(),
            ),
            (
                "antenna-monopole.svg".into(),
                antenna(antennas::triangular_monopole_svg(30.0, 20.0, 5.0))?.into_bytes(),
            ),
        ]);
    }
    for (name, bytes) in &files {
        staged.add(&out.join(name), bytes)?;
    }
    let mut written: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    written.extend(PlannerKind::ALL.iter().map(|&k| demo_gcode_name(part, k)));
    staged.commit()?;
    progress.finish();

    if let Some(r) = &default_report {
        progress.warn(&r.warnings);
    }
    let mut s = format!("wrote {} files to {}:\n", written.len(), out.display());
    for n in &written {
        let _ = writeln!(s, "  {n}");
    }
    if let Some(registration) = &registration {
        let _ = writeln!(
            s,
            "{} (fiducials auto against the part's 3 holes)",
            registration_line(registration, RegistrationMethod::Lsq)
        );
    }
    let _ = writeln!(
        s,
        "G-code dialect {}; planner comparison on the demo part {part} ({}):",
        profile.name,
        part.description()
    );
    s.push_str(&job::comparison_table(&rows));
    if !regions.is_empty() {
        s.push_str(
            "\ndefects per region (contact / flattening / floating, % of the region's points):\n",
        );
        let _ = write!(s, "{:<13}", "planner");
        for (name, _, _) in test_part::REGIONS {
            let _ = write!(s, " {name:>26}");
        }
        s.push('\n');
        for (k, per) in &regions {
            let _ = write!(s, "{:<13}", k.name());
            for (_, q) in per {
                let cell = format!(
                    "{:.1} / {:.1} / {:.1}",
                    q.contact_pct, q.flattening_pct, q.floating_pct
                );
                let _ = write!(s, " {cell:>26}");
            }
            s.push('\n');
        }
    }
    // The drawing is placed as the demo placed it: without `--place`, the
    // SVG's y (which points down) put it off the part.
    let p = settings.plan.placement;
    let _ = writeln!(
        s,
        "plan the drawing yourself: pcpp plan --scan {} --path {} --place {},{},{},{} -o {}.gcode",
        shell_word(&out.join(part.scan_name()).display().to_string()),
        shell_word(&out.join(part.path_name()).display().to_string()),
        job::exact(p.offset_mm.x),
        job::exact(p.offset_mm.y),
        job::exact(p.rotation_deg),
        job::exact(p.scale),
        demo_prefix(part)
    );
    print!("{s}");
    Ok(())
}

/// `word` as a POSIX shell reads it back: as it is when plain, else in
/// single quotes.
fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_./,:=+-@%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.into()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}
