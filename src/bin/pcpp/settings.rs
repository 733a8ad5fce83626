//! Settings from parsed flags: the library's [`JobSettings`] and machine
//! profile, with the checks that need more than one flag (ranges the
//! library validates, fiducials against a placement on the bed). They are
//! usage errors, found before any file is read.

use pcpp::gcode::MachineProfile;
use pcpp::job::{JobSettings, RegistrationSettings};
use pcpp::mesh::ImportOptions;
use pcpp::placement::{Bed, ScanPlacement};
use pcpp::planners::PlannerKind;

use crate::args::{JobArgs, MachineArgs, NozzleArgs, RegistrationArgs, ScanArgs};
use crate::files::read_text;
use crate::values::PlaceScanArg;
use crate::{usage, CliResult, Failure};

/// How the scan file is read.
pub fn import_options(a: &ScanArgs) -> ImportOptions {
    let mut options = ImportOptions::DEFAULT;
    options.units = a.scan_units;
    options.up_axis = a.up_axis;
    options.max_edge_mm = a.max_edge;
    options
}

/// The machine profile: `--profile FILE.json` or `--dialect` (marlin by
/// default; clap refuses both). A bad profile file is bad input.
pub fn profile(a: &MachineArgs) -> CliResult<MachineProfile> {
    match &a.profile {
        Some(path) => {
            let text = read_text(path, "machine profile", crate::files::MAX_SETTINGS_BYTES)?;
            // The profile's name labels its errors: give the whole path.
            MachineProfile::from_json(&text, &path.display().to_string())
                .map_err(|e| Failure::Input(e.to_string()))
        }
        None => builtin_profile(&a.dialect),
    }
}

/// A built-in profile; clap has already checked the name against
/// [`MachineProfile::builtin_names`].
pub fn builtin_profile(name: &str) -> CliResult<MachineProfile> {
    MachineProfile::builtin(name)
        .ok_or_else(|| Failure::Input(format!("the built-in dialect '{name}' did not load")))
}

/// Registration settings: the fiducials, or the scan placed on the bed of
/// `profile`.
fn registration(
    command: &'static str,
    a: &RegistrationArgs,
    profile: &MachineProfile,
) -> CliResult<RegistrationSettings> {
    let mut r = RegistrationSettings {
        fiducials: a.fiducials.clone().unwrap_or_default(),
        printer_points: a.printer_points.clone().map(|p| p.0).unwrap_or_default(),
        method: a.registration,
        dot_diameter_mm: a.dot_diameter,
        ..Default::default()
    };
    if let Some(PlaceScanArg::OnBed {
        offset_mm,
        rotation_deg,
    }) = a.place_scan
    {
        r.scan_placement = ScanPlacement::OnBed {
            bed: Bed::of_profile(profile),
            rotation_deg,
            offset_mm,
        };
    }
    r.validate().map_err(|e| {
        usage(
            command,
            format!(
                "{}: {e}",
                flag_of(&e, "--place-scan/--fiducials/--dot-diameter")
            ),
        )
    })?;
    Ok(r)
}

/// The flag that sets the parameter an error names (QA: "--tol/--speed/
/// --dwell: invalid parameter tolerance (mm) = 0" named three), else
/// `group`.
fn flag_of<'a>(e: &pcpp::Error, group: &'a str) -> &'a str {
    match e {
        pcpp::Error::Parameter { name, .. } => match *name {
            "nozzle inner diameter (mm)" => "--nozzle-id",
            "nozzle outer diameter (mm)" => "--nozzle-od",
            "tolerance (mm)" => "--tol",
            "speed (mm/s)" => "--speed",
            "dwell (s)" => "--dwell",
            "fiducial dot diameter (mm)" => "--dot-diameter",
            "scan placement" => "--place-scan",
            _ => group,
        },
        _ => group,
    }
}

/// The settings of `check` and the machine profile: scan, registration and
/// nozzle (the process keeps its defaults: only tol matters to a check).
pub fn check_settings(
    command: &'static str,
    scan: &ScanArgs,
    nozzle: &NozzleArgs,
    reg: &RegistrationArgs,
    machine: &MachineArgs,
) -> CliResult<(JobSettings, MachineProfile)> {
    let mut s = JobSettings {
        scan: import_options(scan),
        ..Default::default()
    };
    let p = &mut s.plan;
    p.nozzle.inner_diameter_mm = nozzle.nozzle_id;
    p.nozzle.outer_diameter_mm = nozzle.nozzle_od;
    p.process.tolerance_mm = nozzle.tol;
    // Out-of-range values are usage errors too: checked before reading
    // files (a profile file only after them).
    p.nozzle.validate().map_err(|e| {
        usage(
            command,
            format!("{}: {e}", flag_of(&e, "--nozzle-id/--nozzle-od")),
        )
    })?;
    p.process
        .validate()
        .map_err(|e| usage(command, format!("--tol: {e}")))?;
    let profile = profile(machine)?;
    s.registration = registration(command, reg, &profile)?;
    Ok((s, profile))
}

/// The settings of `plan` and `compare` and the machine profile.
pub fn job_settings(
    command: &'static str,
    a: &JobArgs,
    planner: PlannerKind,
    machine: &MachineArgs,
) -> CliResult<(JobSettings, MachineProfile)> {
    let p = pcpp::Process {
        tolerance_mm: a.nozzle.tol,
        speed_mm_s: a.process.speed,
        dwell_s: a.process.dwell,
    };
    p.validate().map_err(|e| {
        usage(
            command,
            format!("{}: {e}", flag_of(&e, "--tol/--speed/--dwell")),
        )
    })?;
    let (mut s, profile) = check_settings(command, &a.scan, &a.nozzle, &a.registration, machine)?;
    s.plan.process = p;
    s.plan.planner = planner;
    if let Some(place) = a.place {
        s.plan.placement = place.placement;
    }
    Ok((s, profile))
}
