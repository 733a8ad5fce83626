//! The command line as clap (derive) types: one struct per command, the flag
//! groups they share flattened in, and the names a flag takes, parsed by the
//! library's own `FromStr` (and its messages); the other values' parsers are
//! in `values.rs`.
//!
//! Everything a flag can get wrong on its own is a value parser here, so clap
//! reports it as a usage error naming the flag (exit 2) before any file is
//! read; what needs two flags together is checked in `settings.rs`.

use std::ffi::OsStr;
use std::marker::PhantomData;
use std::path::PathBuf;
use std::str::FromStr;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueHint};
use clap_complete::Shell;

use pcpp::demo::parts::DemoPart;
use pcpp::fiducials::DEFAULT_DOT_DIAMETER_MM;
use pcpp::gcode::MachineProfile;
use pcpp::job::FiducialSource;
use pcpp::mesh::{ScanUnits, UpAxis};
use pcpp::params::{Nozzle, Process};
use pcpp::planners::PlannerKind;
use pcpp::registration::RegistrationMethod;

use crate::values::{
    dot_diameter, fiducials, max_edge, number, place, place_scan, printer_points, scan_points,
    PlaceArg, PlaceScanArg, Points,
};

const EXIT_STATUS: &str = "\
Exit status: 0 success, 1 bad input (the message names the file and where), \
2 usage error (the message names the flag).";

/// Conformal tool-path planning (PCPP) for microextrusion printing on scanned
/// surfaces
#[derive(Debug, Parser)]
#[command(
    name = "pcpp",
    version,
    after_help = EXIT_STATUS,
    override_usage = "pcpp [OPTIONS] <COMMAND>"
)]
pub struct Cli {
    /// No progress on stderr, only results, warnings and errors
    ///
    /// Progress (a spinner for steps over a second, the results of finished
    /// steps) is drawn only when stderr is a terminal anyway.
    #[arg(short, long, global = true)]
    pub quiet: bool,

    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Plan a drawn path (SVG) on a scan and write G-code
    #[command(after_help = PLAN_AFTER_HELP)]
    Plan(PlanArgs),
    /// Compare the planners' predicted print quality and motion
    #[command(long_about = COMPARE_ABOUT, after_help = JOB_AFTER_HELP)]
    Compare(CompareArgs),
    /// Check any G-code file's moves against a scan
    #[command(long_about = CHECK_ABOUT)]
    Check(CheckArgs),
    /// List the holes of a scan that could be fiducials (JSON)
    #[command(long_about = FIDUCIALS_ABOUT)]
    Fiducials(FiducialsArgs),
    /// The rigid transform scanner -> printer from fiducial points
    #[command(long_about = REGISTER_ABOUT)]
    Register(RegisterArgs),
    /// Write a built-in demo part, its drawing, G-code and antenna SVGs
    #[command(long_about = DEMO_ABOUT)]
    Demo(DemoArgs),
    /// Print a shell completion script to stdout
    #[command(long_about = "Print a shell completion script to stdout, e.g. \
                      `pcpp completions bash > ~/.local/share/bash-completion/completions/pcpp`")]
    Completions {
        /// The shell to complete in
        shell: Shell,
    },
}

// ---------------------------------------------------------------------------
// Commands

/// The note after the flags of `compare`, and of `plan` after its own (a
/// macro, not a `const`, so that `concat!` can join it).
macro_rules! job_after_help {
    () => {
        "\
Without --fiducials and --printer-points, or --place-scan, the scan is taken as
already in the printer frame. --place centre[,ROT[,SCALE]] centres the drawing on
the scan's footprint (and scales it down to fit, with a warning)."
    };
}

const JOB_AFTER_HELP: &str = job_after_help!();

const PLAN_AFTER_HELP: &str = concat!(
    "The summary goes to stdout, warnings to stderr.\n\n",
    job_after_help!()
);

#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The G-code to write (not created on failure; - for standard output)
    #[arg(short, long, value_name = "FILE", value_hint = ValueHint::FilePath)]
    pub output: PathBuf,

    /// Also write the JSON report (quality, stats, paths; - for standard output)
    #[arg(long, value_name = "FILE.json", value_hint = ValueHint::FilePath)]
    pub report: Option<PathBuf>,

    /// The planner
    ///
    /// even (the default) keeps the filament's predicted thickness closest
    /// to d with no contact: it places the tip's centre d/2 ahead of each
    /// drawn point along the path (do/2 on descents), its back edge over
    /// the point, as the spec's section 7 measures the filament there; on a
    /// flat plate its XY runs d/2 ahead of the drawing and swings outside
    /// sharp corners by as much. pcpp-guarded is the paper's planner with
    /// its moves kept clear; pcpp, slope and constant are the paper's three
    /// as it plans them (they may touch the part). pcpp, pcpp-guarded and
    /// constant put the tip's centre over the drawn point; slope shifts it
    /// along the path too.
    #[arg(
        long,
        value_name = "P",
        default_value_t = PlannerKind::default(),
        value_parser = Named::<PlannerKind>::new(planner_values),
    )]
    pub planner: PlannerKind,

    /// Write G-code even where a move comes closer to the surface than tol
    /// (its header then says so); without it such a plan fails, naming the
    /// first moves
    #[arg(long)]
    pub accept_risk: bool,

    // The flattened groups last: each sets the help heading of what follows.
    #[command(flatten)]
    pub job: JobArgs,

    #[command(flatten)]
    pub machine: MachineArgs,
}

const COMPARE_ABOUT: &str = "\
The planners side by side (the paper's Figure 3e-f)

Prints for each planner (constant, slope, pcpp, pcpp-guarded, even): mean |e|,
mean negative and positive e (mm); the contact, flattening and floating shares
of the points and their sum; the points that move backwards along the drawn
path; the smallest clearance along the print moves (below tol the nozzle comes
too close: the tip's height over the surface where the nearest surface is under
it, else tol plus how far it could sink before coming within tol); and the
waypoints the guarded planners added.";

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Also write the comparison as JSON (- for standard output)
    #[arg(long, value_name = "FILE.json", value_hint = ValueHint::FilePath)]
    pub report: Option<PathBuf>,

    #[command(flatten)]
    pub job: JobArgs,

    #[command(flatten)]
    pub machine: MachineArgs,
}

const CHECK_ABOUT: &str = "\
Check every move of a G-code file against a scan

Follows every G0/G1 move in straight lines (G90/G91, G20/G21 and G70/G71, G92,
N line numbers, *checksums, ; and ( ) comments) and tests the nozzle, its tip
disk and the body above it, along each whole move. Arcs (G2/G3), other work
offsets and program flow are refused with the line named. Exit status 0 when
no move comes closer than tol (prints the smallest clearance), 1 listing the
first moves that do (line, position, how much higher the nozzle would have to
be) and their count, 2 on a usage error.";

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The program to check: ours or another tool's (- for standard input)
    #[arg(long, value_name = "FILE", value_hint = ValueHint::FilePath)]
    pub gcode: PathBuf,

    /// Also write the result as JSON (- for standard output)
    #[arg(long, value_name = "FILE.json", value_hint = ValueHint::FilePath)]
    pub report: Option<PathBuf>,

    #[command(flatten)]
    pub scan: ScanArgs,

    #[command(flatten)]
    pub nozzle: CheckNozzleArgs,

    #[command(flatten)]
    pub registration: RegistrationArgs,

    #[command(flatten)]
    pub machine: MachineArgs,
}

/// The nozzle `check` checks with: each value given, else the one a pcpp
/// program's header gives, else the default (QA round 6 F1: a program
/// planned for another nozzle was checked with the defaults, with no
/// word).
#[derive(Debug, Args)]
#[command(next_help_heading = "Nozzle and process")]
pub struct CheckNozzleArgs {
    /// Nozzle inner diameter d [default: the program header's, else 0.603]
    #[arg(long, value_name = "MM", value_parser = number, allow_hyphen_values = true)]
    pub nozzle_id: Option<f64>,

    /// Nozzle outer diameter do [default: the program header's, else 0.908]
    #[arg(long, value_name = "MM", value_parser = number, allow_hyphen_values = true)]
    pub nozzle_od: Option<f64>,

    /// The distance the nozzle must keep from the surface, tol [default: the
    /// program header's, else 0.1]
    #[arg(long, value_name = "MM", value_parser = number, allow_hyphen_values = true)]
    pub tol: Option<f64>,
}

impl CheckNozzleArgs {
    /// The values given, each other one from `planned` (the program
    /// header's nozzle and tol, where it gives them) or the default.
    pub fn or(&self, planned: (Option<Nozzle>, Option<f64>)) -> NozzleArgs {
        let (nozzle, tol) = planned;
        NozzleArgs {
            nozzle_id: self.nozzle_id.unwrap_or(
                nozzle.map_or(Nozzle::DEFAULT.inner_diameter_mm, |n| n.inner_diameter_mm),
            ),
            nozzle_od: self.nozzle_od.unwrap_or(
                nozzle.map_or(Nozzle::DEFAULT.outer_diameter_mm, |n| n.outer_diameter_mm),
            ),
            tol: self
                .tol
                .unwrap_or(tol.unwrap_or(Process::DEFAULT.tolerance_mm)),
        }
    }
}

const FIDUCIALS_ABOUT: &str = "\
Holes of a scan that could be fiducials, as JSON on stdout

Each candidate has its centroid (mm, scan frame after units and up axis),
equivalent diameter, loop size (vertices), area, perimeter, roundness (1 for a
circle) and its score as a dot of --dot-diameter, best candidates first.";

#[derive(Debug, Args)]
pub struct FiducialsArgs {
    /// The fiducial dots' diameter in mm: holes are ranked by how well they
    /// match it
    #[arg(
        long,
        value_name = "MM",
        default_value_t = DEFAULT_DOT_DIAMETER_MM,
        value_parser = dot_diameter,
        allow_hyphen_values = true,
    )]
    pub dot_diameter: f64,

    #[command(flatten)]
    pub scan: ScanArgs,
}

const REGISTER_ABOUT: &str = "\
The rigid transform from scanner to printer frame

Points are in mm, in the same order in both frames (at least 3). Prints the
4x4 matrix (row-major), the residual of each fiducial and their RMS; --json
prints them as JSON.";

#[derive(Debug, Args)]
pub struct RegisterArgs {
    /// The fiducials in the scanner's frame
    #[arg(
        long,
        value_name = "x,y,z;...",
        value_parser = scan_points,
        allow_hyphen_values = true
    )]
    pub scan_points: Points,

    /// The same fiducials in the printer frame
    #[arg(
        long,
        value_name = "x,y,z;...",
        value_parser = printer_points,
        allow_hyphen_values = true
    )]
    pub printer_points: Points,

    /// Least-squares fit, or the paper's 3-point construction
    #[arg(
        long,
        value_name = "METHOD",
        default_value_t = RegistrationMethod::default(),
        value_parser = Named::<RegistrationMethod>::new(registration_values),
    )]
    pub registration: RegistrationMethod,

    /// Print the result as JSON
    #[arg(long)]
    pub json: bool,
}

const DEMO_ABOUT: &str = "\
The built-in demo, no input needed

Writes to DIR: the part's scan (binary PLY), its drawing (SVG), one G-code per
planner (demo-<planner>.gcode; the paper's three planners, constant, slope and
pcpp, are written even where the nozzle would touch the part, for comparison,
and their headers say so), the comparison and the default planner's report
(JSON). For the test part also the registration of the scan on its fiducial
holes (JSON) and three antenna SVGs (the paper's spiral, a Hilbert loop, a
triangular monopole). Prints the comparison table. Files of parts other than
the test part are named demo-<part>-....";

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The folder to write to [default: pcpp-demo]
    #[arg(short, long, value_name = "DIR", value_hint = ValueHint::DirPath)]
    pub out: Option<PathBuf>,

    /// The folder to write to, given without -o (`pcpp demo out`, as a
    /// user types it; QA round 3 L4)
    #[arg(value_name = "DIR", value_hint = ValueHint::DirPath, conflicts_with = "out")]
    pub dir: Option<PathBuf>,

    /// The G-code dialect
    #[arg(long, value_name = "D", default_value = "marlin", value_parser = dialects())]
    pub dialect: String,

    /// The demo part
    #[arg(
        long,
        value_name = "NAME",
        default_value_t = DemoPart::default(),
        value_parser = Named::<DemoPart>::new(part_values),
    )]
    pub part: DemoPart,
}

impl DemoArgs {
    /// The folder to write to: `-o DIR`, or DIR alone, or pcpp-demo.
    pub fn folder(&self) -> PathBuf {
        self.out
            .clone()
            .or_else(|| self.dir.clone())
            .unwrap_or_else(|| PathBuf::from("pcpp-demo"))
    }
}

// ---------------------------------------------------------------------------
// Flag groups

/// The scan, the drawing and the settings of a job: `plan` and `compare`.
#[derive(Debug, Args)]
pub struct JobArgs {
    #[command(flatten)]
    pub scan: ScanArgs,

    /// The drawn path (- for standard input)
    #[arg(
        long,
        value_name = "FILE.svg",
        value_hint = ValueHint::FilePath,
        help_heading = "Drawing"
    )]
    pub path: PathBuf,

    /// Put the SVG's origin at (X, Y) mm of the printer frame, turned ROT
    /// degrees counter-clockwise and scaled; or `centre`: centred on the
    /// scan's footprint (scaled down to fit, with a warning) [default: 0,0,0,1]
    #[arg(
        long,
        value_name = "X,Y[,ROT[,SCALE]]",
        value_parser = place,
        allow_hyphen_values = true,
        help_heading = "Drawing"
    )]
    pub place: Option<PlaceArg>,

    #[command(flatten)]
    pub nozzle: NozzleArgs,

    #[command(flatten)]
    pub process: ProcessArgs,

    #[command(flatten)]
    pub registration: RegistrationArgs,
}

/// `--scan` and how to read it.
#[derive(Debug, Args)]
#[command(next_help_heading = "Scan")]
pub struct ScanArgs {
    /// The scanned surface: a mesh (OBJ, PLY, STL, glTF, GLB) or a point
    /// cloud (XYZ/CSV/TXT, vertex-only PLY or OBJ, PCD); - for standard input
    #[arg(long, value_name = "FILE", value_hint = ValueHint::FilePath)]
    pub scan: PathBuf,

    /// The scan's units [default: the format's: mm; glTF m]
    #[arg(
        long,
        value_name = "U",
        value_parser = Named::<ScanUnits>::new(unit_values)
    )]
    pub scan_units: Option<ScanUnits>,

    /// The scan's up axis [default: the format's: z; glTF y]
    #[arg(
        long,
        value_name = "A",
        value_parser = Named::<UpAxis>::new(axis_values),
        allow_hyphen_values = true
    )]
    pub up_axis: Option<UpAxis>,

    /// Point clouds: the longest edge (in XY) of a triangle of the meshed
    /// cloud; longer gaps stay holes [default: 3 x the median point spacing;
    /// points spread unevenly: 1.5 x the longest edge of 99% of the triangles]
    #[arg(long, value_name = "MM", value_parser = max_edge, allow_hyphen_values = true)]
    pub max_edge: Option<f64>,
}

/// The nozzle and the distance it must keep.
#[derive(Debug, Args)]
#[command(next_help_heading = "Nozzle and process")]
pub struct NozzleArgs {
    /// Nozzle inner diameter d
    #[arg(
        long,
        value_name = "MM",
        default_value_t = Nozzle::DEFAULT.inner_diameter_mm,
        value_parser = number,
        allow_hyphen_values = true
    )]
    pub nozzle_id: f64,

    /// Nozzle outer diameter do
    #[arg(
        long,
        value_name = "MM",
        default_value_t = Nozzle::DEFAULT.outer_diameter_mm,
        value_parser = number,
        allow_hyphen_values = true
    )]
    pub nozzle_od: f64,

    /// The distance the nozzle must keep from the surface, tol
    #[arg(
        long,
        value_name = "MM",
        default_value_t = Process::DEFAULT.tolerance_mm,
        value_parser = number,
        allow_hyphen_values = true
    )]
    pub tol: f64,
}

/// How the path is printed.
#[derive(Debug, Args)]
#[command(next_help_heading = "Nozzle and process")]
pub struct ProcessArgs {
    /// Print speed
    #[arg(
        long,
        value_name = "MM_S",
        default_value_t = Process::DEFAULT.speed_mm_s,
        value_parser = number,
        allow_hyphen_values = true
    )]
    pub speed: f64,

    /// Dwell after dispense on and before dispense off
    #[arg(
        long,
        value_name = "S",
        default_value_t = Process::DEFAULT.dwell_s,
        value_parser = number,
        allow_hyphen_values = true
    )]
    pub dwell: f64,
}

/// Putting the scan in the printer frame.
#[derive(Debug, Args)]
#[command(next_help_heading = "Registration")]
pub struct RegistrationArgs {
    /// The fiducials in the scan's frame, or auto: the scan's holes that best
    /// match --dot-diameter
    #[arg(
        long,
        value_name = "auto|x,y,z;...",
        value_parser = fiducials,
        allow_hyphen_values = true,
        requires = "printer_points"
    )]
    pub fiducials: Option<FiducialSource>,

    /// The same fiducials in the printer frame
    #[arg(
        long,
        value_name = "x,y,z;...",
        value_parser = printer_points,
        allow_hyphen_values = true,
        requires = "fiducials"
    )]
    pub printer_points: Option<Points>,

    /// Least-squares fit, or the paper's 3-point construction
    #[arg(
        long,
        value_name = "METHOD",
        default_value_t = RegistrationMethod::default(),
        value_parser = Named::<RegistrationMethod>::new(registration_values),
    )]
    pub registration: RegistrationMethod,

    /// The fiducial dots' diameter in mm: holes are ranked by how well they
    /// match it
    #[arg(
        long,
        value_name = "MM",
        default_value_t = DEFAULT_DOT_DIAMETER_MM,
        value_parser = dot_diameter,
        allow_hyphen_values = true
    )]
    pub dot_diameter: f64,

    /// An unregistered scan (still in the scanner's frame): lowest point on
    /// the bed, the middle of its footprint's box on the bed's middle, turned
    /// ROT degrees counter-clockwise about z around that middle, then moved by
    /// DX,DY,DZ mm; the bed is the --dialect/--profile build volume's
    #[arg(
        long,
        value_name = "bed[,DX,DY,DZ[,ROT]]",
        value_parser = place_scan,
        allow_hyphen_values = true
    )]
    pub place_scan: Option<PlaceScanArg>,
}

/// The machine the G-code is for.
#[derive(Debug, Args)]
#[command(next_help_heading = "Machine")]
pub struct MachineArgs {
    /// A built-in G-code dialect
    #[arg(
        long,
        value_name = "D",
        default_value = "marlin",
        value_parser = dialects(),
        conflicts_with = "profile"
    )]
    pub dialect: String,

    /// A machine profile instead of a built-in dialect
    #[arg(long, value_name = "FILE.json", value_hint = ValueHint::FilePath)]
    pub profile: Option<PathBuf>,
}

// ---------------------------------------------------------------------------
// Names a flag takes (for --help and the completions)

fn dialects() -> PossibleValuesParser {
    PossibleValuesParser::new(MachineProfile::builtin_names())
}

fn planner_values() -> Vec<PossibleValue> {
    PlannerKind::ALL
        .iter()
        .rev()
        .map(|k| PossibleValue::new(k.name()))
        .collect()
}

fn part_values() -> Vec<PossibleValue> {
    DemoPart::ALL
        .iter()
        .map(|p| PossibleValue::new(p.name()).help(p.description()))
        .collect()
}

fn unit_values() -> Vec<PossibleValue> {
    ["mm", "cm", "m", "in", "ft"].map(PossibleValue::new).into()
}

fn axis_values() -> Vec<PossibleValue> {
    vec![
        PossibleValue::new("z"),
        PossibleValue::new("y").help("glTF's convention, Blender's OBJ and STL"),
        PossibleValue::new("-z").help("a depth camera's frame: z the distance from the camera"),
    ]
}

fn registration_values() -> Vec<PossibleValue> {
    vec![
        PossibleValue::new("lsq").help("least-squares fit (Horn)"),
        PossibleValue::new("paper").help("the paper's 3-point construction"),
    ]
}

/// A value the library parses with its own `FromStr` (and its own message),
/// with the names it takes listed for `--help` and the shell completions.
#[derive(Clone)]
pub struct Named<T> {
    values: fn() -> Vec<PossibleValue>,
    _type: PhantomData<fn() -> T>,
}

impl<T> Named<T> {
    fn new(values: fn() -> Vec<PossibleValue>) -> Self {
        Named {
            values,
            _type: PhantomData,
        }
    }
}

fn from_str<T: FromStr>(text: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    text.parse().map_err(|e: T::Err| e.to_string())
}

impl<T> TypedValueParser for Named<T>
where
    T: FromStr + Clone + Send + Sync + 'static,
    T::Err: std::fmt::Display,
{
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        // clap's own function parser words the error ("invalid value 'x'
        // for '--flag <V>': <the library's message>").
        let parse: fn(&str) -> Result<T, String> = from_str::<T>;
        parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new((self.values)().into_iter()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }
}
