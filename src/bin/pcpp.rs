//! `pcpp`, the command-line tool: a thin adapter over the planning core.
//!
//! It parses arguments, reads files, calls [`pcpp::job`] (the same entry the
//! browser page calls, so both write identical G-code for the same inputs),
//! writes files and maps errors to exit codes: 0 success, 1 bad input (the
//! message names the file and the line, element or point), 2 usage error
//! (the message names the flag). Outputs are written to a temporary file in
//! the same folder and renamed only once everything succeeded, so a failed
//! run leaves no partial file behind.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::{IsTerminal, Write as _};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use pcpp::demo::parts::DemoPart;
use pcpp::demo::{self, antennas, test_part};
use pcpp::fiducials::{find_fiducials_sized, DEFAULT_DOT_DIAMETER_MM};
use pcpp::gcode::MachineProfile;
use pcpp::job::{self, FiducialSource, InputFile, JobSettings, PreparedScan};
use pcpp::mesh::{ScanUnits, UpAxis};
use pcpp::placement::ScanPlacement;
use pcpp::planners::PlannerKind;
use pcpp::registration::{parse_points, register, Registration, RegistrationMethod};
use pcpp::svg::Placement;
use pcpp::{DVec2, DVec3, Error};

const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Why the tool stops: a usage error (exit 2) or bad input (exit 1).
#[derive(Debug)]
enum Failure {
    Usage {
        command: &'static str,
        message: String,
    },
    Input(String),
}

type CliResult<T> = Result<T, Failure>;

fn usage(command: &'static str, message: impl Into<String>) -> Failure {
    Failure::Usage {
        command,
        message: message.into(),
    }
}

fn main() -> ExitCode {
    let mut args = Vec::new();
    for a in std::env::args_os().skip(1) {
        match a.into_string() {
            Ok(s) => args.push(s),
            Err(a) => {
                eprintln!("error: argument {a:?} is not valid UTF-8");
                return ExitCode::from(2);
            }
        }
    }
    match dispatch(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Usage { command, message }) => {
            eprintln!("error: {message}");
            if command.is_empty() {
                eprintln!("run 'pcpp --help' for usage");
            } else {
                eprintln!("run 'pcpp {command} --help' for usage");
            }
            ExitCode::from(2)
        }
        Err(Failure::Input(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
    }
}

fn dispatch(args: &[String]) -> CliResult<()> {
    let Some(first) = args.first() else {
        eprint!("{MAIN_HELP}");
        return Err(usage("", "no command given"));
    };
    let rest = &args[1..];
    match first.as_str() {
        "-h" | "--help" => {
            print!("{MAIN_HELP}");
            Ok(())
        }
        "-V" | "--version" => {
            println!("pcpp {VERSION}");
            Ok(())
        }
        "help" => match rest.first() {
            None => {
                print!("{MAIN_HELP}");
                Ok(())
            }
            Some(c) => match COMMANDS.iter().find(|cmd| cmd.name == c) {
                Some(cmd) => {
                    print!("{}", cmd.full_help());
                    Ok(())
                }
                None => Err(usage("", format!("unknown command '{c}'"))),
            },
        },
        name => {
            let Some(cmd) = COMMANDS.iter().find(|cmd| cmd.name == name) else {
                return Err(usage("", format!("unknown command '{name}'")));
            };
            if rest.iter().any(|a| a == "-h" || a == "--help") {
                print!("{}", cmd.full_help());
                return Ok(());
            }
            let parsed = Args::parse(cmd, rest)?;
            (cmd.run)(&parsed)
        }
    }
}

// ---------------------------------------------------------------------------
// Commands and their flags

/// A flag: its canonical name (without dashes), its aliases, and whether it
/// takes a value.
struct Flag {
    name: &'static str,
    aliases: &'static [&'static str],
    value: bool,
}

const fn valued(name: &'static str) -> Flag {
    Flag {
        name,
        aliases: &[],
        value: true,
    }
}

const fn switch(name: &'static str) -> Flag {
    Flag {
        name,
        aliases: &[],
        value: false,
    }
}

struct Command {
    name: &'static str,
    help: &'static str,
    /// Whether the help goes on with [`JOB_FLAGS_HELP`].
    job_help: bool,
    flags: &'static [Flag],
    run: fn(&Args) -> CliResult<()>,
}

impl Command {
    fn full_help(&self) -> String {
        if self.job_help {
            format!("{}{JOB_FLAGS_HELP}", self.help)
        } else {
            self.help.to_string()
        }
    }
}

/// The flags that build a [`JobSettings`], shared by `plan` and `compare`.
macro_rules! job_flags {
    ($($extra:expr),* $(,)?) => {
        &[
            valued("scan"),
            valued("path"),
            valued("report"),
            valued("nozzle-id"),
            valued("nozzle-od"),
            valued("tol"),
            valued("speed"),
            valued("dwell"),
            valued("scan-units"),
            valued("up-axis"),
            valued("max-edge"),
            valued("place"),
            valued("fiducials"),
            valued("printer-points"),
            valued("registration"),
            valued("place-scan"),
            valued("dot-diameter"),
            $($extra),*
        ]
    };
}

const COMMANDS: &[Command] = &[
    Command {
        name: "plan",
        job_help: true,
        help: PLAN_HELP,
        flags: job_flags![
            Flag {
                name: "output",
                aliases: &["-o"],
                value: true,
            },
            valued("planner"),
            valued("dialect"),
            valued("profile"),
            switch("accept-risk"),
        ],
        run: cmd_plan,
    },
    Command {
        name: "compare",
        job_help: true,
        help: COMPARE_HELP,
        flags: job_flags![valued("dialect"), valued("profile")],
        run: cmd_compare,
    },
    Command {
        name: "fiducials",
        job_help: false,
        help: FIDUCIALS_HELP,
        flags: &[
            valued("scan"),
            valued("scan-units"),
            valued("up-axis"),
            valued("max-edge"),
            valued("dot-diameter"),
        ],
        run: cmd_fiducials,
    },
    Command {
        name: "register",
        job_help: false,
        help: REGISTER_HELP,
        flags: &[
            valued("scan-points"),
            valued("printer-points"),
            valued("registration"),
            switch("json"),
        ],
        run: cmd_register,
    },
    Command {
        name: "check",
        job_help: false,
        help: CHECK_HELP,
        flags: &[
            valued("scan"),
            valued("gcode"),
            valued("report"),
            valued("nozzle-id"),
            valued("nozzle-od"),
            valued("tol"),
            valued("scan-units"),
            valued("up-axis"),
            valued("max-edge"),
            valued("fiducials"),
            valued("printer-points"),
            valued("registration"),
            valued("place-scan"),
            valued("dot-diameter"),
            valued("dialect"),
            valued("profile"),
        ],
        run: cmd_check,
    },
    Command {
        name: "demo",
        job_help: false,
        help: DEMO_HELP,
        flags: &[
            Flag {
                name: "out",
                aliases: &["-o"],
                value: true,
            },
            valued("dialect"),
            valued("part"),
        ],
        run: cmd_demo,
    },
];

/// Parsed flags of one command. `--flag value` and `--flag=value` both work;
/// a value may start with `-` (negative coordinates).
struct Args {
    command: &'static str,
    values: HashMap<&'static str, String>,
    switches: Vec<&'static str>,
}

impl Args {
    fn parse(cmd: &Command, raw: &[String]) -> CliResult<Args> {
        let mut out = Args {
            command: cmd.name,
            values: HashMap::new(),
            switches: Vec::new(),
        };
        let mut i = 0;
        while i < raw.len() {
            let arg = &raw[i];
            i += 1;
            let (key, inline) = match arg.split_once('=') {
                Some((k, v)) if k.starts_with("--") => (k, Some(v.to_string())),
                _ => (arg.as_str(), None),
            };
            let flag = cmd
                .flags
                .iter()
                .find(|f| key.strip_prefix("--") == Some(f.name) || f.aliases.contains(&key));
            let Some(flag) = flag else {
                return Err(usage(
                    cmd.name,
                    if key.starts_with('-') {
                        format!("unknown flag '{key}' for 'pcpp {}'", cmd.name)
                    } else {
                        format!("unexpected argument '{arg}' (every input is given by a flag)")
                    },
                ));
            };
            if !flag.value {
                if inline.is_some() {
                    return Err(usage(cmd.name, format!("--{} takes no value", flag.name)));
                }
                if !out.switches.contains(&flag.name) {
                    out.switches.push(flag.name);
                }
                continue;
            }
            let value = match inline {
                Some(v) => v,
                None => {
                    let Some(v) = raw.get(i) else {
                        return Err(usage(cmd.name, format!("--{} needs a value", flag.name)));
                    };
                    i += 1;
                    v.clone()
                }
            };
            if out.values.insert(flag.name, value).is_some() {
                return Err(usage(cmd.name, format!("--{} given twice", flag.name)));
            }
        }
        Ok(out)
    }

    fn get(&self, name: &str) -> Option<&str> {
        self.values.get(name).map(String::as_str)
    }

    fn has(&self, name: &str) -> bool {
        self.switches.contains(&name)
    }

    fn required(&self, name: &str) -> CliResult<&str> {
        self.get(name)
            .ok_or_else(|| usage(self.command, format!("missing required flag --{name}")))
    }

    fn number(&self, name: &str) -> CliResult<Option<f64>> {
        let Some(text) = self.get(name) else {
            return Ok(None);
        };
        parse_number(text)
            .map(Some)
            .ok_or_else(|| usage(self.command, format!("--{name}: '{text}' is not a number")))
    }

    /// A flag parsed by the library's own `FromStr`.
    fn parsed<T: std::str::FromStr>(&self, name: &str) -> CliResult<Option<T>>
    where
        T::Err: std::fmt::Display,
    {
        match self.get(name) {
            None => Ok(None),
            Some(text) => text
                .parse()
                .map(Some)
                .map_err(|e| usage(self.command, format!("--{name}: {e}"))),
        }
    }

    fn points(&self, name: &str) -> CliResult<Option<Vec<DVec3>>> {
        match self.get(name) {
            None => Ok(None),
            Some(text) => parse_points(text)
                .map(Some)
                .map_err(|e| usage(self.command, format!("--{name}: {e}"))),
        }
    }
}

fn parse_number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

// ---------------------------------------------------------------------------
// Settings from flags

/// `--place X,Y[,ROT_DEG[,SCALE]]`, or `--place centre[,ROT_DEG[,SCALE]]`
/// (the offset is found once the scan is read: [`centre_on_scan`]).
fn placement(a: &Args) -> CliResult<Placement> {
    let Some(text) = a.get("place") else {
        return Ok(Placement::IDENTITY);
    };
    if let Some(rest) = centre_word(text) {
        let mut v = [0.0, 1.0];
        let parts: Vec<&str> = rest
            .split(',')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .collect();
        if parts.len() > 2 {
            return Err(usage(
                a.command,
                "--place centre takes at most a rotation and a scale: centre[,ROT_DEG[,SCALE]]",
            ));
        }
        for (slot, p) in v.iter_mut().zip(&parts) {
            *slot = parse_number(p)
                .ok_or_else(|| usage(a.command, format!("--place: '{p}' is not a number")))?;
        }
        let place = Placement {
            offset_mm: DVec2::ZERO,
            rotation_deg: v[0],
            scale: v[1],
        };
        place
            .validate()
            .map_err(|e| usage(a.command, format!("--place: {e}")))?;
        return Ok(place);
    }
    let bad = |why: String| {
        usage(
            a.command,
            format!("--place: {why}; write X,Y,ROT_DEG,SCALE"),
        )
    };
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if !(2..=4).contains(&parts.len()) {
        return Err(bad(format!("expected 2 to 4 numbers, got {}", parts.len())));
    }
    let mut v = [0.0, 0.0, 0.0, 1.0];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = parse_number(p).ok_or_else(|| bad(format!("'{p}' is not a number")))?;
    }
    let place = Placement {
        offset_mm: DVec2::new(v[0], v[1]),
        rotation_deg: v[2],
        scale: v[3],
    };
    place
        .validate()
        .map_err(|e| usage(a.command, format!("--place: {e}")))?;
    Ok(place)
}

/// `centre` or `center`, and what follows it.
fn centre_word(text: &str) -> Option<&str> {
    let t = text.trim();
    ["centre", "center"].iter().find_map(|w| {
        t.get(..w.len())
            .filter(|h| h.eq_ignore_ascii_case(w))
            .map(|_| t[w.len()..].trim_start_matches(','))
    })
}

/// With `--place centre`, the drawing centred on the scan's footprint
/// (scaled down to fit, with a warning, when it is larger).
fn centre_on_scan(
    a: &Args,
    inputs: &Inputs,
    plan: &mut pcpp::pipeline::PlanSettings,
) -> CliResult<()> {
    if a.get("place").is_none_or(|t| centre_word(t).is_none()) {
        return Ok(());
    }
    let drawn = pcpp::pipeline::load_path(&inputs.svg, &inputs.svg_name)
        .map_err(|e| Failure::Input(in_file(&inputs.svg_path, &inputs.svg_name, &e.to_string())))?;
    let (lo, hi) = inputs.prepared.surface.bbox();
    let Some((place, note)) = pcpp::placement::centre_drawing(
        &drawn.subpaths,
        (lo.truncate(), hi.truncate()),
        &plan.placement,
    ) else {
        return Ok(());
    };
    if let Some(n) = note {
        warn_all(&[n]);
    }
    plan.placement = place;
    Ok(())
}

fn job_settings(a: &Args) -> CliResult<JobSettings> {
    let mut s = JobSettings::default();
    s.scan.units = a.parsed::<ScanUnits>("scan-units")?;
    s.scan.up_axis = a.parsed::<UpAxis>("up-axis")?;
    s.scan.max_edge_mm = a.number("max-edge")?;
    if let Some(v) = a.number("dot-diameter")? {
        s.registration.dot_diameter_mm = v;
    }
    if let Some(text) = a.get("place-scan") {
        s.registration.scan_placement = scan_placement(a, text)?;
    }

    let fiducials = match a.get("fiducials") {
        None => FiducialSource::None,
        Some(t) if t.trim().eq_ignore_ascii_case("auto") => FiducialSource::Auto,
        Some(_) => FiducialSource::Points(a.points("fiducials")?.unwrap_or_default()),
    };
    let printer = a.points("printer-points")?;
    match (&fiducials, &printer) {
        (FiducialSource::None, Some(_)) => {
            return Err(usage(
                a.command,
                "--printer-points needs --fiducials (auto, or the same points in the scan's frame)",
            ))
        }
        (FiducialSource::Auto | FiducialSource::Points(_), None) => {
            return Err(usage(
                a.command,
                "--fiducials needs --printer-points (the fiducials in the printer frame)",
            ))
        }
        _ => {}
    }
    s.registration.fiducials = fiducials;
    s.registration.printer_points = printer.unwrap_or_default();
    if let Some(m) = a.parsed::<RegistrationMethod>("registration")? {
        s.registration.method = m;
    }
    s.registration.validate().map_err(|e| {
        usage(
            a.command,
            format!("--place-scan/--fiducials/--dot-diameter: {e}"),
        )
    })?;

    let p = &mut s.plan;
    if a.values.contains_key("planner") {
        p.planner = a.parsed::<PlannerKind>("planner")?.unwrap_or_default();
    }
    if let Some(v) = a.number("nozzle-id")? {
        p.nozzle.inner_diameter_mm = v;
    }
    if let Some(v) = a.number("nozzle-od")? {
        p.nozzle.outer_diameter_mm = v;
    }
    if let Some(v) = a.number("tol")? {
        p.process.tolerance_mm = v;
    }
    if let Some(v) = a.number("speed")? {
        p.process.speed_mm_s = v;
    }
    if let Some(v) = a.number("dwell")? {
        p.process.dwell_s = v;
    }
    p.placement = placement(a)?;
    // Out-of-range values are usage errors too: check before reading files.
    p.nozzle
        .validate()
        .map_err(|e| usage(a.command, format!("--nozzle-id/--nozzle-od: {e}")))?;
    p.process
        .validate()
        .map_err(|e| usage(a.command, format!("--tol/--speed/--dwell: {e}")))?;
    Ok(s)
}

/// `--place-scan bed[,DX,DY,DZ[,ROT_DEG]]`: on the bed of the profile
/// (`--dialect`/`--profile`), then moved and turned; `--place-scan as-is`.
fn scan_placement(a: &Args, text: &str) -> CliResult<ScanPlacement> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts[0].to_ascii_lowercase().as_str() {
        "as-is" | "asis" | "none" if parts.len() == 1 => Ok(ScanPlacement::AsScanned),
        "bed" => {
            let bad = |why: String| {
                usage(
                    a.command,
                    format!("--place-scan: {why}; write bed or bed,DX,DY,DZ[,ROT_DEG]"),
                )
            };
            if !(parts.len() == 1 || parts.len() == 4 || parts.len() == 5) {
                return Err(bad(format!("expected 1, 4 or 5 fields, got {}", parts.len())));
            }
            let mut v = [0.0; 4];
            for (slot, p) in v.iter_mut().zip(&parts[1..]) {
                *slot = parse_number(p).ok_or_else(|| bad(format!("'{p}' is not a number")))?;
            }
            let mut place = ScanPlacement::on_bed(&profile(a)?);
            if let ScanPlacement::OnBed {
                rotation_deg,
                offset_mm,
                ..
            } = &mut place
            {
                *offset_mm = DVec3::new(v[0], v[1], v[2]);
                *rotation_deg = v[3];
            }
            Ok(place)
        }
        other => Err(usage(
            a.command,
            format!("--place-scan: '{other}' is not a placement; write bed, bed,DX,DY,DZ[,ROT_DEG] or as-is"),
        )),
    }
}

fn builtin_profile(command: &'static str, name: &str) -> CliResult<MachineProfile> {
    MachineProfile::builtin(name.trim()).ok_or_else(|| {
        usage(
            command,
            format!(
                "--dialect: unknown dialect '{name}' (expected {})",
                MachineProfile::builtin_names().join(", ")
            ),
        )
    })
}

fn profile(a: &Args) -> CliResult<MachineProfile> {
    match (a.get("profile"), a.get("dialect")) {
        (Some(_), Some(_)) => Err(usage(
            a.command,
            "--profile and --dialect exclude each other (a profile file is a dialect)",
        )),
        (Some(path), None) => {
            let path = Path::new(path);
            let text = read_text(path, "machine profile")?;
            // The profile's name labels its errors: give the whole path.
            MachineProfile::from_json(&text, &path.display().to_string())
                .map_err(|e| Failure::Input(e.to_string()))
        }
        (None, d) => builtin_profile(a.command, d.unwrap_or("marlin")),
    }
}

// ---------------------------------------------------------------------------
// Files

fn read_bytes(path: &Path, what: &str) -> CliResult<Vec<u8>> {
    std::fs::read(path)
        .map_err(|e| Failure::Input(format!("cannot read {what} {}: {e}", path.display())))
}

fn read_text(path: &Path, what: &str) -> CliResult<String> {
    let bytes = read_bytes(path, what)?;
    String::from_utf8(bytes).map_err(|e| {
        Failure::Input(format!(
            "{}: {what} is not UTF-8 text (byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}

/// The name the library sees: the file name alone, so that reports and
/// G-code headers do not depend on where the file was read from.
fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Puts the path in front of a library message. The library names files by
/// the name it was given; where a message starts with that name, the path
/// replaces it, and the library's `name:12: ...` line form reads
/// "dir/scan.obj, line 12: ...".
fn in_file(path: &Path, name: &str, message: &str) -> String {
    let Some(rest) = message.strip_prefix(name).and_then(|r| r.strip_prefix(':')) else {
        return format!("{}: {message}", path.display());
    };
    let line = rest
        .split_once(':')
        .filter(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    match line {
        Some((n, tail)) => format!("{}, line {n}:{tail}", path.display()),
        None => format!("{}:{rest}", path.display()),
    }
}

/// Outputs staged as temporary files beside their targets, renamed into
/// place only when all of them were written.
#[derive(Default)]
struct Staged {
    files: Vec<(PathBuf, PathBuf)>,
}

impl Staged {
    fn add(&mut self, target: &Path, bytes: &[u8]) -> CliResult<()> {
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = dir.join(format!(
            ".{}.pcpp-tmp-{}",
            file_name(target),
            std::process::id()
        ));
        let result = std::fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(Failure::Input(format!(
                "cannot write {}: {e}",
                target.display()
            )));
        }
        self.files.push((tmp, target.to_path_buf()));
        Ok(())
    }

    fn commit(mut self) -> CliResult<()> {
        let files = std::mem::take(&mut self.files);
        let mut failed = None;
        for (tmp, target) in &files {
            if failed.is_some() {
                let _ = std::fs::remove_file(tmp);
            } else if let Err(e) = std::fs::rename(tmp, target) {
                let _ = std::fs::remove_file(tmp);
                failed = Some(format!("cannot write {}: {e}", target.display()));
            }
        }
        failed.map_or(Ok(()), |m| Err(Failure::Input(m)))
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in &self.files {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

fn to_json<T: serde::Serialize>(value: &T) -> CliResult<String> {
    serde_json::to_string_pretty(value)
        .map(|mut s| {
            s.push('\n');
            s
        })
        .map_err(|e| Failure::Input(format!("cannot write JSON: {e}")))
}

// ---------------------------------------------------------------------------
// Progress and summaries

/// Stage messages on stderr, only when a person is watching it.
struct Progress {
    on: bool,
}

impl Progress {
    fn new() -> Self {
        Progress {
            on: std::io::stderr().is_terminal(),
        }
    }

    fn say(&self, message: &str) {
        if self.on {
            eprintln!("{message}");
        }
    }
}

/// 2000000 -> "2,000,000".
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn registration_line(r: &Registration, method: RegistrationMethod) -> String {
    let res: Vec<String> = r.residuals_mm.iter().map(|v| format!("{v:.4}")).collect();
    format!(
        "registration ({}): rotation {:.3} deg, residuals [{}] mm, rms {:.4} mm",
        method.name(),
        r.rotation_deg(),
        res.join(", "),
        r.rms_mm
    )
}

fn warn_all(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

// ---------------------------------------------------------------------------
// plan and compare

/// The two inputs of a job, read and with the scan prepared.
struct Inputs {
    scan_path: PathBuf,
    svg_path: PathBuf,
    svg_name: String,
    svg: Vec<u8>,
    prepared: PreparedScan,
}

fn load_inputs(a: &Args, settings: &JobSettings, progress: &Progress) -> CliResult<Inputs> {
    let svg_path = PathBuf::from(a.required("path")?);
    let (scan_path, prepared) = load_scan(a, settings, progress)?;
    let svg = read_bytes(&svg_path, "path")?;
    Ok(Inputs {
        svg_name: file_name(&svg_path),
        scan_path,
        svg_path,
        svg,
        prepared,
    })
}

/// Reads, registers and indexes `--scan`.
fn load_scan(
    a: &Args,
    settings: &JobSettings,
    progress: &Progress,
) -> CliResult<(PathBuf, PreparedScan)> {
    let scan_path = PathBuf::from(a.required("scan")?);
    progress.say(&format!("reading scan {}...", scan_path.display()));
    let scan = read_bytes(&scan_path, "scan")?;
    let scan_name = file_name(&scan_path);
    let prepared = job::prepare_scan(&scan, &scan_name, &settings.scan, &settings.registration)
        .map_err(|e| match e {
            Error::Registration(r) => {
                Failure::Input(format!("registration of {}: {r}", scan_path.display()))
            }
            other => Failure::Input(in_file(&scan_path, &scan_name, &other.to_string())),
        })?;
    progress.say(&format!(
        "scan: {} triangles",
        thousands(prepared.triangle_count())
    ));
    if let Some(cloud) = &prepared.cloud {
        progress.say(&cloud.to_string());
    }
    if settings.registration.fiducials != FiducialSource::None {
        progress.say(&registration_line(&prepared.registration, prepared.method));
    }
    Ok((scan_path, prepared))
}

/// Errors of planning on a prepared scan: the drawn path's file is named.
fn plan_failure(inputs: &Inputs, e: Error) -> Failure {
    match e {
        Error::Gcode(g) => Failure::Input(format!("writing G-code: {g}")),
        e @ Error::OutsideVolume { .. } => Failure::Input(format!(
            "writing G-code for {}: {e}",
            inputs.scan_path.display()
        )),
        Error::Touching(t) => Failure::Input(format!("{}: {t}", inputs.svg_path.display())),
        Error::Plan(m) if m.contains("no G-code written") => Failure::Input(format!(
            "{}: {m} (--accept-risk writes it anyway)",
            inputs.svg_path.display()
        )),
        Error::Plan(m) if m.contains("misses the scan") => Failure::Input(format!(
            "{} on {}: {m}",
            inputs.svg_path.display(),
            inputs.scan_path.display()
        )),
        other => Failure::Input(in_file(
            &inputs.svg_path,
            &inputs.svg_name,
            &other.to_string(),
        )),
    }
}

fn cmd_plan(a: &Args) -> CliResult<()> {
    let mut settings = job_settings(a)?;
    let profile = profile(a)?;
    let out = PathBuf::from(a.required("output")?);
    let report_path = a.get("report").map(PathBuf::from);
    let progress = Progress::new();
    let inputs = load_inputs(a, &settings, &progress)?;
    centre_on_scan(a, &inputs, &mut settings.plan)?;
    progress.say(&format!("planning ({})...", settings.plan.planner));
    let output = job::run_on(
        &inputs.prepared,
        &inputs.svg,
        &inputs.svg_name,
        &settings.plan,
        &profile,
        a.has("accept-risk"),
    )
    .map_err(|e| plan_failure(&inputs, e))?;

    let mut staged = Staged::default();
    staged.add(&out, output.gcode.as_bytes())?;
    if let Some(r) = &report_path {
        staged.add(r, to_json(&output.report)?.as_bytes())?;
    }
    staged.commit()?;

    warn_all(&output.report.warnings);
    let st = &output.report.stats;
    let mut s = format!(
        "wrote {} ({}, {}): {} piece(s), {} points, {:.3} mm, print time {:.1} s\n",
        out.display(),
        output.report.planner,
        profile.name,
        st.subpaths,
        st.points,
        st.length_mm,
        st.print_time_s
    );
    let _ = writeln!(
        s,
        "path: height change {:.3} mm, max inclination {:.1} deg, min radius {:.3} mm",
        st.height_change_mm, st.max_inclination_deg, st.min_radius_mm
    );
    if settings.registration.fiducials != FiducialSource::None {
        let _ = writeln!(
            s,
            "{}",
            registration_line(&inputs.prepared.registration, inputs.prepared.method)
        );
    }
    let _ = writeln!(s, "scan: {}", output.report.registration.status);
    let _ = writeln!(s, "predicted quality: {}", output.report.quality);
    let _ = writeln!(s, "safe motion: {}", output.report.motion.summary_line());
    if let Some(r) = &report_path {
        let _ = writeln!(s, "report: {}", r.display());
    }
    print!("{s}");
    Ok(())
}

/// The comparison as JSON (the `--report` of `compare`, the demo's file).
fn comparison_json(
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
    })
}

fn cmd_compare(a: &Args) -> CliResult<()> {
    let mut settings = job_settings(a)?;
    let report_path = a.get("report").map(PathBuf::from);
    let progress = Progress::new();
    let inputs = load_inputs(a, &settings, &progress)?;
    centre_on_scan(a, &inputs, &mut settings.plan)?;
    progress.say("planning with all four planners...");
    let comparison = job::compare_on(
        &inputs.prepared,
        &inputs.svg,
        &inputs.svg_name,
        &settings.plan,
    )
    .map_err(|e| plan_failure(&inputs, e))?;
    let rows = comparison.rows;
    if let Some(r) = &report_path {
        let files = [
            inputs.prepared.file.clone(),
            InputFile::new(&inputs.svg_name, &inputs.svg),
        ];
        let mut staged = Staged::default();
        staged.add(
            r,
            to_json(&comparison_json(&files, &settings.plan, &rows))?.as_bytes(),
        )?;
        staged.commit()?;
    }
    warn_all(&inputs.prepared.warnings);
    warn_all(&inputs.prepared.registration.notes);
    warn_all(&comparison.warnings);
    print!("{}", job::comparison_table(&rows));
    Ok(())
}

// ---------------------------------------------------------------------------
// check

fn cmd_check(a: &Args) -> CliResult<()> {
    let settings = job_settings(a)?;
    let gcode_path = PathBuf::from(a.required("gcode")?);
    let report_path = a.get("report").map(PathBuf::from);
    let progress = Progress::new();
    let text = read_text(&gcode_path, "gcode")?;
    let (scan_path, prepared) = load_scan(a, &settings, &progress)?;
    progress.say("checking every move...");
    let name = file_name(&gcode_path);
    let check = job::check_gcode(
        &prepared,
        &text,
        &name,
        &settings.plan.nozzle,
        settings.plan.process.tolerance_mm,
    )
    .map_err(|e| Failure::Input(in_file(&gcode_path, &name, &e.to_string())))?;
    if let Some(r) = &report_path {
        let mut staged = Staged::default();
        staged.add(r, to_json(&check)?.as_bytes())?;
        staged.commit()?;
    }
    warn_all(&prepared.warnings);
    warn_all(&check.notes);
    let sum = &check.summary;
    let clear = sum
        .min_clearance_mm
        .map_or("no move passes near the scan".to_string(), |c| {
            format!(
                "min clearance {c:.3} mm{}",
                sum.min_clearance_line
                    .map_or(String::new(), |l| format!(" (line {l})"))
            )
        });
    let head = format!(
        "{}: {} moves checked against {} (nozzle outer diameter {} mm, tol {} mm): {clear}",
        gcode_path.display(),
        sum.moves,
        scan_path.display(),
        check.outer_diameter_mm,
        check.tol_mm
    );
    if check.is_clear() {
        println!("{head}; no move comes closer than tol");
        if !check.unchecked_lines.is_empty() {
            println!(
                "{} move(s) not checked: their position is not in the file (see the warning)",
                check.unchecked_lines.len()
            );
        }
        return Ok(());
    }
    let mut s = format!(
        "{head}; {} move(s) come closer than tol:",
        sum.touching_moves
    );
    for t in &sum.touching {
        let _ = write!(s, "\n  {t}");
    }
    if sum.touching_moves > sum.touching.len() {
        let _ = write!(
            s,
            "\n  ... and {} more",
            sum.touching_moves - sum.touching.len()
        );
    }
    Err(Failure::Input(s))
}

// ---------------------------------------------------------------------------
// fiducials and register

fn cmd_fiducials(a: &Args) -> CliResult<()> {
    let mut options = pcpp::mesh::ImportOptions::DEFAULT;
    options.units = a.parsed::<ScanUnits>("scan-units")?;
    options.up_axis = a.parsed::<UpAxis>("up-axis")?;
    options.max_edge_mm = a.number("max-edge")?;
    let path = PathBuf::from(a.required("scan")?);
    let progress = Progress::new();
    progress.say(&format!("reading scan {}...", path.display()));
    let bytes = read_bytes(&path, "scan")?;
    let name = file_name(&path);
    let imported = pcpp::pipeline::load_scan(&bytes, &name, &options)
        .map_err(|e| Failure::Input(in_file(&path, &name, &e.to_string())))?;
    if let Some(cloud) = &imported.cloud {
        progress.say(&cloud.to_string());
    }
    progress.say(&format!(
        "scan: {} triangles; looking for holes...",
        thousands(imported.mesh.triangle_count())
    ));
    warn_all(&imported.warnings);
    let dot = a.number("dot-diameter")?.unwrap_or(DEFAULT_DOT_DIAMETER_MM);
    if !(dot > 0.0 && dot <= 100.0) {
        return Err(usage(
            a.command,
            "--dot-diameter: must be above 0 and at most 100 mm",
        ));
    }
    let found = find_fiducials_sized(&imported.mesh, dot);
    print!("{}", to_json(&found)?);
    Ok(())
}

fn cmd_register(a: &Args) -> CliResult<()> {
    let scan = a.points("scan-points")?;
    let printer = a.points("printer-points")?;
    let (Some(scan), Some(printer)) = (scan, printer) else {
        let missing = if a.get("scan-points").is_none() {
            "scan-points"
        } else {
            "printer-points"
        };
        return Err(usage(
            a.command,
            format!("missing required flag --{missing}"),
        ));
    };
    let method = a
        .parsed::<RegistrationMethod>("registration")?
        .unwrap_or_default();
    let r = register(&scan, &printer, method)
        .map_err(|e| Failure::Input(format!("registration: {e}")))?;
    let rows = r.matrix_row_major();
    if a.has("json") {
        let v = serde_json::json!({
            "method": method,
            "matrix": rows,
            "residuals_mm": r.residuals_mm,
            "rms_mm": r.rms_mm,
            "rotation_deg": r.rotation_deg(),
            "notes": r.notes,
        });
        print!("{}", to_json(&v)?);
        return Ok(());
    }
    let mut s = format!(
        "registration ({}), scanner -> printer, 4x4 row-major:\n",
        method.name()
    );
    for row in &rows {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:>12.6}")).collect();
        let _ = writeln!(s, "  {}", cells.join(" "));
    }
    let _ = writeln!(s, "rotation: {:.4} deg", r.rotation_deg());
    let _ = writeln!(s, "residuals:");
    for (i, v) in r.residuals_mm.iter().enumerate() {
        let _ = writeln!(s, "  fiducial {}: {v:.4} mm", i + 1);
    }
    let _ = writeln!(s, "rms: {:.4} mm", r.rms_mm);
    print!("{s}");
    warn_all(&r.notes);
    Ok(())
}

// ---------------------------------------------------------------------------
// demo

/// The demo's G-code file name for a planner.
/// The start of the demo's file names: `demo` for the test part, else
/// `demo-<part>`.
fn demo_prefix(part: DemoPart) -> String {
    match part {
        DemoPart::TestPart => "demo".into(),
        _ => format!("demo-{part}"),
    }
}

fn demo_gcode_name(part: DemoPart, k: PlannerKind) -> String {
    format!("{}-{}.gcode", demo_prefix(part), k.name())
}

fn cmd_demo(a: &Args) -> CliResult<()> {
    let out = PathBuf::from(a.get("out").unwrap_or("pcpp-demo"));
    let profile = builtin_profile(a.command, a.get("dialect").unwrap_or("marlin"))?;
    let part = a.parsed::<DemoPart>("part")?.unwrap_or_default();
    let progress = Progress::new();
    let fail = |what: &str, e: &dyn std::fmt::Display| Failure::Input(format!("demo {what}: {e}"));

    progress.say(&format!("building the demo part {part}..."));
    let scan = demo::to_binary_ply(&part.mesh());
    let svg = part.svg();
    let (scan_name, path_name) = (part.scan_name(), part.path_name());
    let mut settings = JobSettings::default();
    settings.plan.placement = part.placement();
    let prepared = job::prepare_scan(&scan, &scan_name, &settings.scan, &settings.registration)
        .map_err(|e| fail("scan", &e))?;
    progress.say(&format!(
        "scan: {} triangles",
        thousands(prepared.triangle_count())
    ));

    // Registration as a user would run it: the holes found in the scan
    // matched to the printer points. The test part is already in the
    // printer frame, so G is the identity and the residuals are ~0.
    let registration = if part == DemoPart::TestPart {
        progress.say("registering the scan on its fiducial holes...");
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
    std::fs::create_dir_all(&out)
        .map_err(|e| Failure::Input(format!("cannot create {}: {e}", out.display())))?;
    let mut staged = Staged::default();
    let mut rows = Vec::new();
    let mut default_report = None;
    let mut regions = Vec::new();
    let default_planner = PlannerKind::default();
    for k in PlannerKind::ALL {
        progress.say(&format!("planning ({k})..."));
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
        (scan_name.clone(), scan.clone()),
        (path_name.clone(), svg.clone().into_bytes()),
        (
            format!("{prefix}-comparison.json"),
            to_json(&comparison_json(
                &[
                    InputFile::new(&scan_name, &scan),
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

    if let Some(r) = &default_report {
        warn_all(&r.warnings);
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
    print!("{s}");
    Ok(())
}

// ---------------------------------------------------------------------------
// Help

const MAIN_HELP: &str = "\
pcpp: conformal tool-path planning (PCPP) for microextrusion printing on scanned surfaces

usage: pcpp <command> [flags]

commands:
  plan        plan a drawn path (SVG) on a scan and write G-code
  compare     compare the planners' predicted print quality and motion
  check       check any G-code file's moves against a scan
  fiducials   list the holes of a scan that could be fiducials (JSON)
  register    the rigid transform scanner -> printer from fiducial points
  demo        write the built-in test part, its paths, G-code and antenna SVGs
  help [cmd]  this help, or a command's

  pcpp <command> --help   flags of a command
  pcpp --version          the version

exit status: 0 success, 1 bad input (the message names the file and where),
2 usage error (the message names the flag)
";

const JOB_FLAGS_HELP: &str =
    "  --scan FILE              the scanned surface: a mesh (OBJ, PLY, STL, glTF, GLB)
                           or a point cloud (XYZ/CSV/TXT, vertex-only PLY, PCD)
                           (required)
  --path FILE.svg          the drawn path (required)
  --nozzle-id MM           nozzle inner diameter d (default 0.603)
  --nozzle-od MM           nozzle outer diameter do (default 0.908)
  --tol MM                 tolerance (default 0.1)
  --speed MM_S             print speed (default 5)
  --dwell S                dwell after dispense on / before off (default 0)
  --scan-units U           mm, cm, m or in (default: the format's, mm; glTF m)
  --up-axis A              z or y (default: the format's, z; glTF y)
  --max-edge MM            point clouds: the longest edge (in XY) of a triangle
                           of the meshed cloud; longer gaps stay holes (default
                           3 x the median point spacing)
  --place X,Y[,ROT[,SCALE]]
                           put the SVG's origin at (X, Y) mm of the printer frame,
                           turned ROT degrees counter-clockwise and scaled
                           (default 0,0,0,1)
  --fiducials auto|\"x,y,z;x,y,z;x,y,z\"
                           the fiducials in the scan's frame, or auto (its holes)
  --printer-points \"x,y,z;x,y,z;x,y,z\"
                           the same fiducials in the printer frame
  --registration lsq|paper least-squares fit (default) or the paper's 3-point
                           construction
  --dot-diameter MM        the fiducial dots' diameter: holes are ranked by how
                           well they match it (default 1)
  --place-scan bed[,DX,DY,DZ[,ROT]]
                           an unregistered scan (still in the scanner's frame):
                           lowest point on the bed, footprint centred on it, then
                           moved by DX,DY,DZ mm and turned ROT degrees about z;
                           the bed is the --dialect/--profile build volume's
Without --fiducials and --printer-points, or --place-scan, the scan is taken as
already in the printer frame. --place centre[,ROT[,SCALE]] centres the drawing on
the scan's footprint (and scales it down to fit, with a warning).
";

const PLAN_HELP: &str = "\
pcpp plan: plan a drawn path on a scan and write G-code

usage: pcpp plan --scan FILE --path FILE.svg -o OUT.gcode [flags]

  -o, --output FILE        the G-code to write (required; not created on failure)
  --report FILE.json       also write the JSON report (quality, stats, paths)
  --planner P              even (default), pcpp-guarded, pcpp, slope or constant
  --dialect D              marlin (default), aerotech or grbl
  --profile FILE.json      a machine profile instead of a built-in dialect
  --accept-risk            write G-code even where a move comes closer to the
                           surface than tol (its header then says so); without
                           it such a plan fails, naming the first moves

The summary goes to stdout, warnings to stderr.

inputs:
";

const COMPARE_HELP: &str = "\
pcpp compare: the planners side by side (the paper's Figure 3e-f)

usage: pcpp compare --scan FILE --path FILE.svg [flags]

  --report FILE.json       also write the comparison as JSON

Prints for each planner (constant, slope, pcpp, pcpp-guarded, even): mean |e|,
mean negative and positive e (mm); the contact, flattening and floating shares
of the points and their sum; the points that move backwards along the drawn
path; the smallest clearance along the print moves (below tol the nozzle comes
too close: the tip's height over the surface where the nearest surface is under
it, else tol plus how far it could sink before coming within tol); and the
waypoints the guarded planners added.

inputs:
";

const FIDUCIALS_HELP: &str = "\
pcpp fiducials: holes of a scan that could be fiducials, as JSON on stdout

usage: pcpp fiducials --scan FILE [--scan-units U] [--up-axis A] [--max-edge MM]

Each candidate has its centroid (mm, scan frame after units and up axis),
equivalent diameter, loop size (vertices), area, perimeter and roundness
(1 for a circle), best candidates first.
";

const REGISTER_HELP: &str = "\
pcpp register: the rigid transform from scanner to printer frame

usage: pcpp register --scan-points \"x,y,z;...\" --printer-points \"x,y,z;...\"
                     [--registration lsq|paper] [--json]

Points are in mm, in the same order in both frames (at least 3). Prints the
4x4 matrix (row-major), the residual of each fiducial and their RMS; --json
prints them as JSON.
";

const CHECK_HELP: &str = "\
pcpp check: check every move of a G-code file against a scan

usage: pcpp check --scan FILE --gcode FILE [flags]

  --scan FILE              the scanned surface (OBJ, PLY, STL, glTF or GLB)
  --gcode FILE             the program to check: ours or another tool's
  --report FILE.json       also write the result as JSON
  --nozzle-od MM           nozzle outer diameter do (default 0.908)
  --tol MM                 the distance the nozzle must keep (default 0.1)
  --scan-units, --up-axis, --fiducials, --printer-points, --registration
                           as for plan: put the scan in the printer frame

Follows every G0/G1 move in straight lines (G90/G91, G20/G21 and G70/G71, G92,
N line numbers, *checksums, ; and ( ) comments) and tests the nozzle, its tip
disk and the body above it, along each whole move. Arcs (G2/G3), other work
offsets and program flow are refused with the line named. Exit status 0 when
no move comes closer than tol (prints the smallest clearance), 1 listing the
first moves that do (line, position, how much higher the nozzle would have to
be) and their count, 2 on a usage error.
";

const DEMO_HELP: &str = "\
pcpp demo: the built-in demo, no input needed

usage: pcpp demo [--part NAME] [--out DIR] [--dialect marlin|aerotech|grbl]

Writes to DIR (default ./pcpp-demo): the part's scan (binary PLY), its drawing
(SVG), one G-code per planner (demo-<planner>.gcode; the paper's three planners,
constant, slope and pcpp, are written even where the nozzle would touch the
part, for comparison, and their headers say so), the comparison and the default
planner's report (JSON). For the test part also the registration of the scan
on its fiducial holes (JSON) and three antenna SVGs (the paper's spiral, a
Hilbert loop, a triangular monopole). Prints the comparison table.

Parts (--part, default test-part):
  test-part            the paper's 80 x 80 mm test part with straight lines
  stepped-block        2 mm steps with vertical walls, lines across them
  dimpled-hemisphere   R 27 mm hemisphere with R 1-3 mm dimples, the paper's spiral
  folded-film          film folded in sharp 80 degree creases, a Hilbert loop
  wrinkled-film        film with smooth wrinkles, the paper's spiral
Files of parts other than the test part are named demo-<part>-....
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_groups_digits() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(2_000_000), "2,000,000");
        assert_eq!(thousands(12_345), "12,345");
    }

    #[test]
    fn paths_replace_the_library_file_name() {
        let p = Path::new("dir/scan.obj");
        assert_eq!(
            in_file(p, "scan.obj", "scan.obj:12: bad vertex"),
            "dir/scan.obj, line 12: bad vertex"
        );
        assert_eq!(
            in_file(p, "scan.obj", "scan.obj: truncated"),
            "dir/scan.obj: truncated"
        );
        assert_eq!(
            in_file(p, "scan.obj", "the path misses"),
            "dir/scan.obj: the path misses"
        );
    }
}
