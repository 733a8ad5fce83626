//! The input layout of the `pipeline` fuzz target, shared by the target,
//! the seed writer and the `decode_pipeline` example that turns a crash
//! file back into a scan, a drawing and settings.
//!
//! Layout (all of it optional; missing bytes read as 0):
//!
//! | bytes | meaning |
//! |-------|---------|
//! | 0 | scan format: `% 5` picks obj, ply, stl, gltf, glb (the file extension) |
//! | 1 | bits 0-1 and 5: planner index mod 5 (constant, slope, pcpp, pcpp-guarded, even); bit 2 fiducials `auto` against the demo part's three printer points; bit 3 registration method `paper`; bit 4 accept risk |
//! | 2 | inner diameter d = 0.1 + 1.9 * b / 255 mm |
//! | 3 | outer diameter do = d * (1.01 + 2 * b / 255) |
//! | 4 | tolerance = 0.01 + 0.5 * b / 255 mm |
//! | 5, 6 | placement offset x, y = b - 128 mm |
//! | 7 | placement rotation = b * 360 / 256 deg |
//! | 8 | placement scale = 2^((b - 128) / 32) |
//! | 9..13 | scan length n, u32 little endian (clamped to what follows) |
//! | 13..13+n | the scan's bytes |
//! | rest | the SVG's bytes |

use pcpp::gcode::MachineProfile;
use pcpp::job::{prepare_scan, run_on, FiducialSource, RegistrationSettings};
use pcpp::mesh::ImportOptions;
use pcpp::pipeline::PlanSettings;
use pcpp::planners::PlannerKind;
use pcpp::registration::RegistrationMethod;
use pcpp::svg::Placement;
use pcpp::{DVec2, Nozzle, Process};

/// Header bytes before the scan.
pub const HEADER_LEN: usize = 13;

/// The scan file names, by the format byte.
pub const SCAN_NAMES: [&str; 5] = ["fuzz.obj", "fuzz.ply", "fuzz.stl", "fuzz.gltf", "fuzz.glb"];

/// One decoded pipeline input.
#[derive(Debug, Clone)]
pub struct PipelineCase<'a> {
    pub scan_name: &'static str,
    pub scan: &'a [u8],
    pub svg: &'a [u8],
    pub registration: RegistrationSettings,
    pub settings: PlanSettings,
    pub accept_risk: bool,
}

/// Splits fuzz bytes into a case (never fails: short inputs read as zeros).
pub fn decode(data: &[u8]) -> PipelineCase<'_> {
    let b = |i: usize| f64::from(data.get(i).copied().unwrap_or(0));
    let flags = data.get(1).copied().unwrap_or(0);
    let d = 0.1 + 1.9 * b(2) / 255.0;
    let nozzle = Nozzle {
        inner_diameter_mm: d,
        outer_diameter_mm: d * (1.01 + 2.0 * b(3) / 255.0),
    };
    let process = Process {
        tolerance_mm: 0.01 + 0.5 * b(4) / 255.0,
        ..Process::DEFAULT
    };
    let placement = Placement {
        offset_mm: DVec2::new(b(5) - 128.0, b(6) - 128.0),
        rotation_deg: b(7) * 360.0 / 256.0,
        scale: 2f64.powf((b(8) - 128.0) / 32.0),
    };
    let index = usize::from(flags & 3) | (usize::from((flags >> 5) & 1) << 2);
    let planner = PlannerKind::ALL[index % PlannerKind::ALL.len()];
    let registration = RegistrationSettings {
        fiducials: if flags & 4 != 0 {
            FiducialSource::Auto
        } else {
            FiducialSource::None
        },
        printer_points: if flags & 4 != 0 {
            pcpp::demo::test_part::FIDUCIALS_MM.to_vec()
        } else {
            Vec::new()
        },
        method: if flags & 8 != 0 {
            RegistrationMethod::Paper
        } else {
            RegistrationMethod::Lsq
        },
        ..Default::default()
    };
    let rest = data.get(HEADER_LEN..).unwrap_or(&[]);
    let n = data
        .get(9..13)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize)
        .unwrap_or(0)
        .min(rest.len());
    let (scan, svg) = rest.split_at(n);
    PipelineCase {
        scan_name: SCAN_NAMES[usize::from(data.first().copied().unwrap_or(0) % 5)],
        scan,
        svg,
        registration,
        settings: PlanSettings {
            nozzle,
            process,
            planner,
            placement,
        },
        accept_risk: flags & 16 != 0,
    }
}

/// Runs a case as the CLI's `plan` does, marlin dialect; returns the G-code.
pub fn run(case: &PipelineCase) -> pcpp::Result<String> {
    let scan = prepare_scan(
        case.scan,
        case.scan_name,
        &ImportOptions::DEFAULT,
        &case.registration,
    )?;
    let Some(profile) = MachineProfile::builtin("marlin") else {
        return Err(pcpp::Error::Plan("no marlin profile".into()));
    };
    let out = run_on(
        &scan,
        case.svg,
        "fuzz.svg",
        &case.settings,
        &profile,
        case.accept_risk,
    )?;
    Ok(out.gcode)
}
