//! G-code writer (spec section 9), with machine profiles as data.
//!
//! [`write_gcode`] turns the planned tool paths into one program for the
//! controller a [`MachineProfile`] describes. Per subpath: rise to the safe
//! height, travel over the first point, descend, dispense on (+ dwell),
//! linear moves through every point at the print speed, dispense off
//! (+ dwell), lift. Everything is checked before the first line is written,
//! so a bad job yields an error and no partial program.
//!
//! Built-in dialects ([`MachineProfile::builtin_names`]):
//! - `marlin`: RepRap/Marlin, mm/min, valve on the fan output (`M106 S255` /
//!   `M107`), `G4 P<ms>`, `;` comments.
//! - `aerotech`: Aerotech A3200 (the paper's controller), `G71 G76 G90`,
//!   mm/s, `$DO[0].X = 1` / `$DO[0].X = 0`, `DWELL <s>`, `'` comments.
//! - `grbl`: Grbl and LinuxCNC, mm/min, `M8`/`M9` (or `M3`/`M5` with a user
//!   profile), `G4 P<s>`, `( )` comments.
//!
//! [`read_gcode`] reads any program back, ours or another tool's, as the
//! straight moves a controller would make (absolute mm, with their lines),
//! so that `pcpp check` can test them against the scan.
//!
//! ```
//! use pcpp::gcode::{write_gcode, GcodeJob, MachineProfile};
//! use pcpp::DVec3;
//!
//! let paths = vec![vec![DVec3::new(10.0, 10.0, 2.0), DVec3::new(20.0, 10.0, 3.0)]];
//! let job = GcodeJob {
//!     toolpaths: &paths,
//!     speed_mm_s: 5.0,
//!     dwell_s: 0.0,
//!     header: &[("planner".into(), "tip-collision-free".into())],
//!     scan_top_z_mm: 4.0,
//! };
//! let marlin = MachineProfile::builtin("marlin").unwrap();
//! let program = write_gcode(&job, &marlin).unwrap();
//! assert!(program.contains("G1 X20.000 Y10.000 Z3.000 F300"));
//! ```

pub(crate) mod format;
mod profile;
mod read;
mod template;
mod writer;

use glam::DVec3;

pub use profile::{
    BuildVolume, CommentStyle, FeedUnits, MachineProfile, ProfileSource, BLOCK_TOKENS,
    DEFAULT_DECIMALS, DWELL_TOKENS, VOLUME_HAIR_MM,
};
pub(crate) use read::numbered_lines;
pub use read::{
    read_gcode, read_gcode_grbl, GcodeLineProblem, GcodeMove, GcodeProgram, GcodeReadError,
    UnknownMove, UnknownMoveKind, MAX_COORDINATE_MM, MAX_GCODE_BYTES, MAX_GCODE_LINES,
};
pub use writer::{
    checked_safe_height, write_gcode, write_program, GcodeJob, MoveKind, StartBlock, WrittenMove,
    WrittenProgram,
};

/// Why a profile cannot be loaded or a job cannot be written. Each variant
/// names the file and field, or the subpath and point, at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GcodeError {
    /// The profile is not valid JSON (or not an object).
    #[error("machine profile {file}: {message}")]
    ProfileSyntax { file: String, message: String },
    /// A profile field is missing, has the wrong type or an invalid value.
    #[error("machine profile {file}, field `{field}`: {message}")]
    ProfileField {
        file: String,
        field: String,
        message: String,
    },
    /// A template uses a `{token}` that field does not provide.
    #[error(
        "machine profile {file}, field `{field}`: unknown template token {{{token}}} \
         (known here: {known}; write {{{{ and }}}} for literal braces)"
    )]
    UnknownToken {
        file: String,
        field: String,
        token: String,
        known: String,
    },
    /// A job parameter is out of range (names the parameter and value).
    #[error("invalid {name} = {}: {reason}", crate::params::shown(*.value))]
    Parameter {
        name: &'static str,
        value: f64,
        reason: String,
    },
    /// A tool-path point is NaN or infinite (the planner's output is broken).
    #[error(
        "subpath {subpath}, point {point}: coordinate ({x}, {y}, {z}) is not finite",
        x = .position.x, y = .position.y, z = .position.z
    )]
    NonFinitePoint {
        /// 0-based index into `GcodeJob::toolpaths`.
        subpath: usize,
        /// 0-based index into that subpath.
        point: usize,
        position: DVec3,
    },
    /// A tool-path point lies outside the machine's build volume: move the
    /// part (registration) or fix the profile's `build_volume`.
    #[error(
        "{} lies outside the build volume of profile {profile} ({volume}): check the \
         registration or the profile's build_volume",
        point_at(*.subpath, *.point, *.position)
    )]
    OutOfVolume {
        subpath: usize,
        point: usize,
        position: DVec3,
        volume: BuildVolume,
        profile: String,
    },
    /// The travel height (scan top or highest point, plus the clearance)
    /// is above the build volume: lower the clearance or the part.
    #[error(
        "safe travel height {safe_z_mm:.3} mm (highest of scan top {scan_top_z_mm:.3} mm and \
         highest tool-path point, plus clearance {clearance_mm} mm) lies outside the build \
         volume of profile {profile} ({volume})"
    )]
    SafeHeightOutOfVolume {
        safe_z_mm: f64,
        scan_top_z_mm: f64,
        clearance_mm: f64,
        volume: BuildVolume,
        profile: String,
    },
}

/// A tool-path point as the errors name it: "subpath S, point P at (x, y,
/// z) mm".
pub(crate) fn point_at(subpath: usize, point: usize, p: DVec3) -> String {
    format!(
        "subpath {subpath}, point {point} at ({:.3}, {:.3}, {:.3}) mm",
        p.x, p.y, p.z
    )
}
