//! `pcpp plan` and `pcpp compare`: a drawing planned on a scan, written as
//! G-code, or planned by every planner and compared.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use pcpp::job::{self, FiducialSource, InputFile, JobSettings, PreparedScan};
use pcpp::registration::{Registration, RegistrationError, RegistrationMethod};
use pcpp::Error;

use crate::args::{CompareArgs, JobArgs, MachineArgs, PlanArgs, ScanArgs};
use crate::files::{
    file_name, in_file, input_shown, is_stdout, read_bytes, read_external, read_scan, to_json,
    write_one, Staged,
};
use crate::outputs::{Flagged, Outputs};
use crate::progress::{thousands, Progress};
use crate::settings::job_settings;
use crate::{CliResult, Failure, VERSION};

/// The two inputs of a job, read and with the scan prepared.
pub struct Inputs {
    pub scan_path: PathBuf,
    pub svg_path: PathBuf,
    pub svg_name: String,
    pub svg: Vec<u8>,
    pub prepared: PreparedScan,
}

/// The files `plan` and `compare` read, for [`Outputs::check`].
fn job_inputs<'a>(a: &'a JobArgs, machine: &'a MachineArgs) -> impl Iterator<Item = Flagged<'a>> {
    [
        Some(Flagged::new("--scan", &a.scan.scan)),
        Some(Flagged::new("--path", &a.path)),
        machine
            .profile
            .as_deref()
            .map(|p| Flagged::new("--profile", p)),
    ]
    .into_iter()
    .flatten()
}

fn load_inputs(
    a: &JobArgs,
    settings: &JobSettings,
    outputs: &Outputs,
    progress: &Progress,
) -> CliResult<Inputs> {
    let prepared = load_scan(&a.scan, settings, outputs, progress)?;
    let svg = read_bytes(&a.path, "path", crate::files::MAX_SVG_BYTES)?;
    Ok(Inputs {
        svg_name: file_name(&a.path),
        scan_path: a.scan.scan.clone(),
        svg_path: a.path.clone(),
        svg,
        prepared,
    })
}

/// Reads, registers and indexes `--scan` (its external files refused
/// where one is also an output).
pub fn load_scan(
    a: &ScanArgs,
    settings: &JobSettings,
    outputs: &Outputs,
    progress: &Progress,
) -> CliResult<PreparedScan> {
    let scan_path = &a.scan;
    progress.step(format!("reading scan {}...", input_shown(scan_path)));
    let scan = read_scan(scan_path, "scan")?;
    let scan_name = file_name(scan_path);
    // A .gltf's buffers in separate files, from its folder.
    let (files, missing) = read_external(scan_path, &scan_name, scan.as_ref(), outputs)?;
    progress.step(format!("importing and indexing {scan_name}..."));
    let prepared = job::prepare_scan_owned_with(
        scan,
        &scan_name,
        files,
        &settings.scan,
        &settings.registration,
        // Neither `plan` nor `check` lists the holes.
        job::Candidates::ForRegistration,
    )
    .map_err(|e| match e {
        Error::Registration(r) => {
            Failure::Input(format!("registration of {}: {r}", input_shown(scan_path)))
        }
        other => Failure::Input(
            missing.explain(in_file(scan_path, &scan_name, &other.to_string()), &other),
        ),
    })?;
    progress.note(&format!(
        "scan: {} triangles",
        thousands(prepared.triangle_count())
    ));
    if let Some(cloud) = &prepared.cloud {
        progress.note(&cloud.to_string());
    }
    if settings.registration.fiducials != FiducialSource::None {
        progress.note(&registration_line(&prepared.registration, prepared.method));
    }
    Ok(prepared)
}

pub fn registration_line(r: &Registration, method: RegistrationMethod) -> String {
    let res: Vec<String> = r.residuals_mm.iter().map(|v| format!("{v:.4}")).collect();
    format!(
        "registration ({}): rotation {:.3} deg, residuals [{}] mm, rms {:.4} mm",
        method.name(),
        r.rotation_deg(),
        res.join(", "),
        r.rms_mm
    )
}

/// The drawing as read once for the command line's own steps before the
/// plan (centring it, telling how large it is); an error is said by the
/// step that needs it, or by the plan.
type Drawn = Result<pcpp::pipeline::DrawnPath, pcpp::Error>;

/// With `--place centre`, the drawing centred on the scan's footprint, or
/// on the surface nearest its middle when that is a gap (scaled down to
/// fit, with a warning, when it is larger, unless a scale was given: that
/// one is kept).
fn centre_on_scan(
    a: &JobArgs,
    inputs: &Inputs,
    drawn: &Drawn,
    plan: &mut pcpp::pipeline::PlanSettings,
    progress: &Progress,
) -> CliResult<()> {
    let Some(place) = a.place.filter(|p| p.centre) else {
        return Ok(());
    };
    let drawn = drawn
        .as_ref()
        .map_err(|e| Failure::Input(in_file(&inputs.svg_path, &inputs.svg_name, &e.to_string())))?;
    let Some((place, note)) = pcpp::placement::centre_on_surface(
        &drawn.subpaths,
        &inputs.prepared.surface,
        &plan.placement,
        !place.scale_given,
    ) else {
        return Ok(());
    };
    if let Some(n) = note {
        progress.warn(&[n]);
    }
    plan.placement = place;
    Ok(())
}

/// Before a large drawing is planned, how large it is (QA round 19 F11: a
/// week of print took 7.6 min and 5.3 GB to plan, with no word until it
/// was done). A drawing that cannot be read or is too large is left to
/// the plan's own error.
fn warn_large_drawing(
    inputs: &Inputs,
    drawn: &Drawn,
    plan: &pcpp::pipeline::PlanSettings,
    progress: &Progress,
) {
    let Ok(drawn) = drawn else {
        return;
    };
    let size = pcpp::pipeline::drawing_size(&drawn.subpaths, &plan.nozzle, &plan.placement);
    if let Some(note) = size
        .ok()
        .filter(|s| s.check().is_ok())
        .and_then(|s| s.large_note(plan.process.speed_mm_s))
    {
        progress.warn(&[format!("{}: {note}", input_shown(&inputs.svg_path))]);
    }
}

/// Errors of planning on a prepared scan: the drawn path's file is named.
/// What the scan's import and registration noticed is said first: it may
/// be the cause (a scan read in the wrong units leaves nothing to print).
/// `noted`: the drawing's and the plan's warnings when the plan was made
/// and then refused (said after the scan's, before the refusal).
fn plan_failure(inputs: &Inputs, e: Error, noted: &[String], progress: &Progress) -> Failure {
    // The other risks the flag would accept, said after the refusal (the
    // plan's warnings that one of them says are left out: filtered here).
    let kept = matches!(e, Error::AlsoRisks { .. }).then(|| job::refused_plan_warnings(&e, noted));
    if let Error::AlsoRisks {
        first,
        others,
        blocked,
    } = e
    {
        let noted = kept.unwrap_or_default();
        return match plan_failure(inputs, *first, &noted, progress) {
            Failure::Input(mut m) => {
                if !others.is_empty() {
                    m = format!(
                        "{m}; --accept-risk would also accept: {}",
                        others.join("; ")
                    );
                }
                // (QA round 11 L1: offered as writing it, then refused.)
                if let Some(b) = blocked {
                    m = format!("{m}; but --accept-risk would write no G-code either: {b}");
                }
                Failure::Input(m)
            }
            usage => usage,
        };
    }
    // A warning the error repeats is said once, by the error.
    let repeated = |w: &String| matches!(&e, Error::UnitsDoubt { message, .. } if message.starts_with(w.as_str()));
    let warnings: Vec<String> = inputs
        .prepared
        .warnings
        .iter()
        .filter(|w| !repeated(w))
        .cloned()
        .collect();
    progress.warn(&warnings);
    progress.warn(&inputs.prepared.registration.notes);
    progress.warn(&job::refused_plan_warnings(&e, noted));
    match e {
        Error::Gcode(g) => Failure::Input(format!("writing G-code: {g}")),
        e @ Error::OutsideVolume { .. } => Failure::Input(format!(
            "writing G-code for {}: {e}",
            input_shown(&inputs.scan_path)
        )),
        // Its lines are the unwritten G-code's, not the drawing's.
        Error::Touching(t) => Failure::Input(format!(
            "{} on {}: {t}",
            input_shown(&inputs.svg_path),
            input_shown(&inputs.scan_path)
        )),
        Error::Registration(
            r @ (RegistrationError::TooFarOff { .. } | RegistrationError::UpsideDown { .. }),
        ) => Failure::Input(format!(
            "{}: {r} (--accept-risk writes it anyway)",
            input_shown(&inputs.scan_path)
        )),
        e @ Error::WholeObjectCloud { .. } => {
            Failure::Input(format!("{e} (--accept-risk writes it anyway)"))
        }
        e @ Error::UnitsDoubt { .. } => Failure::Input(e.to_string()),
        e @ (Error::FarAbove { .. } | Error::MostlyOffScan { .. }) => Failure::Input(format!(
            "{} on {}: {e} (--accept-risk)",
            input_shown(&inputs.svg_path),
            input_shown(&inputs.scan_path)
        )),
        e @ (Error::BelowBed { .. } | Error::LargerThanVolume(_)) => Failure::Input(format!(
            "{}: {e} (--accept-risk)",
            input_shown(&inputs.scan_path)
        )),
        Error::Plan(m) if m.contains("no G-code written") => Failure::Input(format!(
            "{}: {m} (--accept-risk writes it anyway)",
            input_shown(&inputs.svg_path)
        )),
        Error::Plan(m) if m.contains("seen edge-on") => {
            Failure::Input(format!("{}: {m}", input_shown(&inputs.scan_path)))
        }
        Error::Plan(m) if m.contains("misses the scan") => Failure::Input(format!(
            "{} on {}: {m}",
            input_shown(&inputs.svg_path),
            input_shown(&inputs.scan_path)
        )),
        other => Failure::Input(in_file(
            &inputs.svg_path,
            &inputs.svg_name,
            &other.to_string(),
        )),
    }
}

pub fn cmd_plan(a: &PlanArgs, progress: &Progress) -> CliResult<()> {
    let out: &Path = &a.output;
    let written = [
        Some(Flagged::new("-o", out)),
        a.report.as_deref().map(|r| Flagged::new("--report", r)),
    ];
    let outputs = Outputs::check(
        "plan",
        written.into_iter().flatten(),
        job_inputs(&a.job, &a.machine),
    )?;
    let (mut settings, profile) = job_settings("plan", &a.job, a.planner, &a.machine)?;
    let inputs = load_inputs(&a.job, &settings, &outputs, progress)?;
    // Before the drawing is centred and scaled on a scan whose size is in
    // doubt (its warning about scaling came first, and misled).
    job::refuse_unit_doubt(&inputs.prepared, a.accept_risk)
        .and_then(|()| job::refuse_blocking_strays(&inputs.prepared, &profile))
        .and_then(|()| {
            let nozzle = &settings.plan.nozzle;
            job::refuse_bad_registration(&inputs.prepared.registration, nozzle, a.accept_risk)
        })
        .map_err(|e| plan_failure(&inputs, e, &[], progress))?;
    let drawn = pcpp::pipeline::load_path(&inputs.svg, &inputs.svg_name);
    centre_on_scan(&a.job, &inputs, &drawn, &mut settings.plan, progress)?;
    warn_large_drawing(&inputs, &drawn, &settings.plan, progress);
    progress.step(format!("planning ({})...", settings.plan.planner));
    let mut noted = Vec::new();
    let output = job::run_on_noting(
        &inputs.prepared,
        &inputs.svg,
        &inputs.svg_name,
        &settings.plan,
        &profile,
        a.accept_risk,
        &mut noted,
    )
    .map_err(|e| plan_failure(&inputs, e, &noted, progress))?;

    progress.step("writing...");
    let mut staged = Staged::default();
    staged.add(out, output.gcode.as_bytes())?;
    if let Some(r) = &a.report {
        staged.add(r, to_json(&output.report)?.as_bytes())?;
    }
    staged.commit()?;
    progress.finish();

    progress.warn(&output.report.warnings);
    let st = &output.report.stats;
    let mut s = format!(
        "wrote {} ({}, {}): {} piece(s), {} points, {:.3} mm, print time {:.1} s\n",
        shown(out),
        output.report.planner,
        profile.name,
        st.subpaths,
        st.points,
        st.length_mm,
        st.print_time_s
    );
    let _ = writeln!(
        s,
        "path: height change {:.3} mm, max inclination {:.1} deg, min radius {}",
        st.height_change_mm,
        st.max_inclination_deg,
        st.min_radius_text()
    );
    if settings.registration.fiducials != FiducialSource::None {
        let _ = writeln!(
            s,
            "{}",
            registration_line(&inputs.prepared.registration, inputs.prepared.method)
        );
    }
    let _ = writeln!(s, "scan: {}", output.report.registration.status);
    let _ = writeln!(s, "predicted quality: {}", output.report.quality_line());
    let _ = writeln!(s, "safe motion: {}", output.report.motion.summary_line());
    if let Some(r) = &a.report {
        let _ = writeln!(s, "report: {}", shown(r));
    }
    // Standard output carries the file written there, alone.
    if is_stdout(out) || a.report.as_deref().is_some_and(is_stdout) {
        eprint!("{s}");
    } else {
        print!("{s}");
    }
    Ok(())
}

/// An output as the summary names it.
fn shown(path: &Path) -> String {
    if is_stdout(path) {
        "standard output".into()
    } else {
        path.display().to_string()
    }
}

/// The comparison as JSON (the `--report` of `compare`, the demo's file).
pub fn comparison_json(
    inputs: &[InputFile],
    settings: &pcpp::pipeline::PlanSettings,
    rows: &[job::ComparisonRow],
) -> serde_json::Value {
    serde_json::json!({
        "program": "pcpp",
        "version": VERSION,
        "inputs": inputs,
        "settings": settings,
        "planners": rows,
        "notes": job::comparison_notes(rows),
    })
}

pub fn cmd_compare(a: &CompareArgs, progress: &Progress) -> CliResult<()> {
    let report = a.report.as_deref().map(|r| Flagged::new("--report", r));
    let outputs = Outputs::check("compare", report, job_inputs(&a.job, &a.machine))?;
    // The planner flag is plan's; compare plans with all of them.
    let (mut settings, profile) = job_settings("compare", &a.job, Default::default(), &a.machine)?;
    let inputs = load_inputs(&a.job, &settings, &outputs, progress)?;
    // As plan's: a spike of stray vertices out of the volume fails every
    // planner for reasons that hide it ("seen edge-on from above").
    job::refuse_blocking_strays(&inputs.prepared, &profile)
        .map_err(|e| plan_failure(&inputs, e, &[], progress))?;
    let drawn = pcpp::pipeline::load_path(&inputs.svg, &inputs.svg_name);
    centre_on_scan(&a.job, &inputs, &drawn, &mut settings.plan, progress)?;
    warn_large_drawing(&inputs, &drawn, &settings.plan, progress);
    progress.step("planning with all five planners...");
    let comparison = job::compare_on(
        &inputs.prepared,
        &inputs.svg,
        &inputs.svg_name,
        &settings.plan,
        &profile,
    )
    .map_err(|e| plan_failure(&inputs, e, &[], progress))?;
    let rows = comparison.rows;
    if let Some(r) = &a.report {
        let files = [
            inputs.prepared.file.clone(),
            InputFile::new(&inputs.svg_name, &inputs.svg),
        ];
        write_one(
            r,
            to_json(&comparison_json(&files, &settings.plan, &rows))?.as_bytes(),
        )?;
    }
    progress.finish();
    progress.warn(&inputs.prepared.warnings);
    progress.warn(&inputs.prepared.registration.notes);
    progress.warn(&comparison.warnings);
    let table = job::comparison_table(&rows);
    if a.report.as_deref().is_some_and(is_stdout) {
        eprint!("{table}");
    } else {
        print!("{table}");
    }
    Ok(())
}
