//! The program: header, start block, one print per subpath, end block.

use glam::DVec3;

use super::format::{comment_line, fixed, push_fixed, trimmed};
use super::profile::{template_error, MachineProfile, BLOCK_TOKENS, DWELL_TOKENS, FEED_RANGE_MM_S};
use super::template;
use super::GcodeError;

/// Longest dwell a job may ask for, as in `Process::validate`.
const MAX_DWELL_S: f64 = 600.0;

/// What to write: the planned tool paths and the process, decoupled from
/// the planner's own types.
#[derive(Debug, Clone, Copy)]
pub struct GcodeJob<'a> {
    /// One array per subpath: the tool-path points T* (x, y, z) in mm,
    /// printer frame. Empty subpaths are skipped; a single point prints a
    /// dot (dispense on, dwell, off).
    pub toolpaths: &'a [Vec<DVec3>],
    /// Print speed, 0.001 to 1000 mm/s (the paper prints at 2.5-5 mm/s).
    pub speed_mm_s: f64,
    /// Dwell after dispense-on and before dispense-off, 0 to 600 s; 0 writes
    /// no dwell.
    pub dwell_s: f64,
    /// Provenance key/value pairs, written as comments in this order.
    pub header: &'a [(String, String)],
    /// Highest point of the registered scan, printer frame: travel happens
    /// at this plus the profile's clearance (spec section 9: "a safe height
    /// above the highest point of Sa").
    pub scan_top_z_mm: f64,
}

/// What kind of motion a written move is (spec section 9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MoveKind {
    /// The first rise to the safe height, from wherever the head is.
    Rise,
    /// Travel at the safe height over a subpath's first point.
    Travel,
    /// The vertical descent onto a subpath's first point.
    Descend,
    /// A print move (the valve open).
    Print,
    /// The lift back to the safe height.
    Lift,
    /// A move of the profile's `end` block (followed by the G-code reader
    /// from where the program left the head).
    End,
}

/// One straight move as written: coordinates exactly as the controller
/// reads them (rounded to the profile's decimals), with the program's
/// 1-based line number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WrittenMove {
    pub line: usize,
    /// `None` for the first rise: where the head starts is not known.
    pub from: Option<DVec3>,
    pub to: DVec3,
    pub kind: MoveKind,
}

/// A written program and the moves it commands.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenProgram {
    pub text: String,
    pub moves: Vec<WrittenMove>,
    /// Where the header's comments end in `text` (bytes) and how many
    /// lines they take: [`WrittenProgram::with_header`] swaps them.
    header: (usize, usize),
}

impl WrittenProgram {
    /// The moves of the profile's `start` block (its `lines` lines after
    /// the header) whose end the G-code reader knows, as it follows the
    /// block from wherever the head stands: (from, where known; to;
    /// program line; index in `start`). `StartBlock::motion` warns that
    /// these run before any checked move; where a move ends is still
    /// known, and a start that drives the nozzle into the part there is
    /// refused (QA round 19 F6). Empty for a block the reader cannot
    /// follow (the warning says so).
    pub fn start_moves(&self, lines: usize) -> Vec<(Option<DVec3>, DVec3, usize, usize)> {
        let text: String = self
            .text
            .lines()
            .skip(self.header.1)
            .take(lines)
            .flat_map(|l| [l, "\n"])
            .collect();
        let Ok(read) = read_start_block(&text, "start") else {
            return Vec::new();
        };
        let at = |line: usize| (self.header.1 + line, line - 1);
        let known = read.moves.iter().map(|m| {
            let (line, i) = at(m.line);
            (Some(m.from), m.to, line, i)
        });
        let ends = read.unknown_moves.iter().filter_map(|u| {
            let [x, y, z] = u.to;
            let (line, i) = at(u.line);
            Some((None, DVec3::new(x?, y?, z?), line, i))
        });
        known.chain(ends).collect()
    }

    /// The text `write_program` writes for `job`, which differs from the
    /// job this program was written for only in its header values, when
    /// the new header takes as many lines (so that `moves` still hold):
    /// the new header and the rest of this text, without writing the moves
    /// again. `None` when the line counts differ.
    pub fn with_header(
        &self,
        job: &GcodeJob,
        profile: &MachineProfile,
    ) -> Result<Option<String>, GcodeError> {
        let safe_z = checked_safe_height(job, profile)?;
        let mut w = Program::new(job, profile, safe_z);
        w.header(job, safe_z);
        if w.lines != self.header.1 {
            return Ok(None);
        }
        w.out.push_str(&self.text[self.header.0..]);
        Ok(Some(w.out))
    }
}

/// Writes the job as one program in the dialect of `profile`.
///
/// Checks first (profile fields, speed, dwell, every point finite and inside
/// the build volume, the safe height too) and writes nothing on error. The
/// output depends only on the inputs, so it can be compared with golden
/// files.
pub fn write_gcode(job: &GcodeJob, profile: &MachineProfile) -> Result<String, GcodeError> {
    write_program(job, profile).map(|p| p.text)
}

/// [`write_gcode`], with every move it commands (what the motion check of
/// spec section 6f follows). The moves of the profile's `end` block are
/// followed from where the program leaves the head (a `G1 Z0` there drove
/// the nozzle into the part after a print checked clear); one that goes
/// where the program does not say (homing Z) below the safe height is
/// refused. The `start` block runs before the first move, from wherever
/// the head stands, as the program's first rise does: not listed.
pub fn write_program(
    job: &GcodeJob,
    profile: &MachineProfile,
) -> Result<WrittenProgram, GcodeError> {
    let source = profile.label();
    profile.validate(&source)?;
    check_job(job)?;
    let safe_z = checked_safe_height(job, profile)?;
    // Points a hair past a face of the volume are written on it (every
    // point is inside once checked; only those out by a hair are copied).
    let volume = profile.build_volume;
    let snapped: Vec<Vec<DVec3>>;
    let snapped_job;
    let job = if job.toolpaths.iter().flatten().any(|&p| volume.snap(p) != p) {
        snapped = job
            .toolpaths
            .iter()
            .map(|ps| ps.iter().map(|&p| volume.snap(p)).collect())
            .collect();
        snapped_job = GcodeJob {
            toolpaths: &snapped,
            ..*job
        };
        &snapped_job
    } else {
        job
    };

    let mut w = Program::new(job, profile, safe_z);
    w.header(job, safe_z);
    let header = (w.out.len(), w.lines);
    w.block("start", &profile.start)?;

    let dwell = w.dwell_line(job.dwell_s)?;
    // The writer does not know where the head is when the program starts,
    // so the first motion is a pure rise; every print ends with a lift, so
    // later travel starts at the safe height.
    let mut at_safe_height = false;
    let paths = job.toolpaths.iter().enumerate();
    for (index, points) in paths.filter(|(_, p)| !p.is_empty()) {
        if !at_safe_height {
            w.rapid_z();
            at_safe_height = true;
        }
        w.print(index, points, dwell.as_deref())?;
    }
    let end_start = (w.out.len(), w.lines);
    w.block("end", &profile.end)?;
    if let Some(at) = w.at {
        let safe = w.read_back(safe_z);
        let end = follow_end(&w.out[end_start.0..], at, end_start.1, safe, &source)?;
        w.moves.extend(end);
    }
    Ok(WrittenProgram {
        text: w.out,
        moves: w.moves,
        header,
    })
}

/// A start block's text as the G-code reader follows it, its lines
/// numbered as in `text`. The block runs in whatever motion mode the
/// machine is in, so a bare coordinate (Grbl's `Z0`) is a straight move
/// there, G0 or G1 alike (Grbl starts in G0; Marlin ignores the line, so
/// taking it as a move is the cautious reading): it is read after a `G0`
/// that moves nothing, where the reader alone refuses it (QA round 19: a
/// start's bare `Z0` into the part was only warned about).
fn read_start_block(text: &str, name: &str) -> Result<super::GcodeProgram, super::GcodeReadError> {
    let mut read = super::read_gcode(&format!("G0\n{text}"), name).map_err(|e| match e {
        super::GcodeReadError::Line {
            file,
            line,
            problem,
        } => super::GcodeReadError::Line {
            file,
            line: line.saturating_sub(1),
            problem,
        },
        e => e,
    })?;
    for m in &mut read.moves {
        m.line -= 1;
    }
    for u in &mut read.unknown_moves {
        u.line -= 1;
    }
    if let Some(n) = &mut read.compensation_line {
        *n -= 1;
    }
    Ok(read)
}

/// The header's note on the program's first move, which no check covers.
const FIRST_RISE_NOTE: &str = "first move: a rise to the safe travel height from wherever the \
     head stands, which pcpp cannot check (start with the nozzle above the part)";

/// A profile's start block as the G-code reader reads it, read once for
/// what it does that the moves' checks cannot see ([`Self::motion`],
/// [`Self::cautions`]). Its tokens are filled with stand-in values (a line
/// moves the head or not whatever they are), and each line of its text
/// keeps the profile line it comes from (a profile line may hold several).
pub struct StartBlock<'p> {
    profile: &'p MachineProfile,
    text: String,
    from: Vec<usize>,
    read: Result<super::GcodeProgram, super::GcodeReadError>,
}

impl<'p> StartBlock<'p> {
    /// `None` for a block with nothing in it.
    pub fn of(profile: &'p MachineProfile) -> Option<StartBlock<'p>> {
        let mut text = String::new();
        let mut from = Vec::new();
        for (i, line) in profile.start.iter().enumerate() {
            let filled = template::fill(line, |token| {
                BLOCK_TOKENS.contains(&token).then(|| "100".to_string())
            })
            .unwrap_or_else(|_| line.clone());
            for part in filled.lines() {
                text.push_str(part);
                text.push('\n');
                from.push(i);
            }
        }
        if text.trim().is_empty() {
            return None;
        }
        let read = read_start_block(&text, &profile.name);
        Some(StartBlock {
            profile,
            text,
            from,
            read,
        })
    }

    /// "start[i] `line`" for the block's text line `n` (from 1).
    fn field(&self, n: usize) -> String {
        let i = self.from.get(n - 1).copied().unwrap_or_default();
        format!("start[{i}] `{}`", self.profile.start[i].trim())
    }

    /// The first line that moves the head (a move, homing, probing), as
    /// written: the block runs before the program's first rise, from
    /// wherever the head stands, so pcpp can no more check those moves
    /// against the scan than that rise (spec 6(f); safety audit, finding
    /// 4). `None` when the block moves nothing. A block the G-code reader
    /// cannot follow is taken to move the head.
    pub fn motion(&self) -> Option<String> {
        let read = match &self.read {
            Ok(read) => read,
            Err(e) => return Some(format!("a line the G-code reader cannot follow ({e})")),
        };
        // A firmware macro (Klipper's PRINT_START, BED_MESH_CALIBRATE) the
        // reader skips may home and move the head as well (review).
        let macro_line = self.text.lines().position(is_macro).map(|k| k + 1);
        let first = read
            .moves
            .iter()
            .map(|m| m.line)
            .chain(read.unknown_moves.iter().map(|u| u.line))
            .chain(macro_line)
            .min()?;
        let what = if Some(first) == macro_line {
            " (a firmware macro, which may home or move the head)"
        } else {
            ""
        };
        Some(format!("{}{what}", self.field(first)))
    }

    /// What the block does beyond moving the head that the moves' checks
    /// cannot see, each naming its line (QA round 21 F4: `G29` and `M420
    /// S1` in a start block were written without a word): probing the bed,
    /// which with the part on it comes down across the part, and
    /// bed-levelling compensation turned on, which moves every move by the
    /// firmware's mesh.
    pub fn cautions(&self) -> Vec<String> {
        let Ok(read) = &self.read else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let probing = read
            .unknown_moves
            .iter()
            .find(|u| u.kind == super::read::UnknownMoveKind::Probing);
        if let Some(u) = probing {
            out.push(format!(
                "{} probes the bed (or levels or calibrates): with the part on the bed the \
                 probe comes down across it, where pcpp cannot check it; probe before the part \
                 is placed, or take the line out",
                self.field(u.line)
            ));
        }
        if let Some(n) = read.compensation_line {
            out.push(format!(
                "{} {}",
                self.field(n),
                super::read::COMPENSATION_NOTE
            ));
        }
        out
    }
}

/// Whether a line calls a firmware macro: its first word a name (letters,
/// digits and underscores, two or more, starting with a letter) that is
/// not a G-code word (a letter and a number: `G28`, `M107`, `T1`).
fn is_macro(line: &str) -> bool {
    let word = line
        .split([';', '(', ' ', '\t'])
        .next()
        .unwrap_or_default()
        .trim();
    let mut chars = word.chars();
    let Some(first) = chars.next() else {
        return false;
    };
    let rest = chars.as_str();
    // A G-code word, or several run together (`G1X10`): a number follows
    // the letter.
    let code_word = rest.starts_with(|c: char| c.is_ascii_digit() || c == '.' || c == '-');
    first.is_ascii_alphabetic()
        && word.len() >= 2
        && word.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !code_word
}

/// The moves of the `end` block's text (filled), the head at `at` when it
/// starts on line `after + 1`: read by the G-code reader (units, modes and
/// G92 as it follows them) from a known position. A move it cannot place
/// that is not wholly at or above `safe_z` (homing Z, probing, machine
/// coordinates) is an error naming the block's line.
fn follow_end(
    text: &str,
    at: DVec3,
    after: usize,
    safe_z: f64,
    source: &str,
) -> Result<Vec<WrittenMove>, GcodeError> {
    if text.is_empty() {
        return Ok(Vec::new());
    }
    const PREFIX_LINES: usize = 3;
    // (Display writes every f64 in full, never in exponent notation, which
    // the reader refuses.)
    let program = format!("G21\nG90\nG0 X{} Y{} Z{}\n{text}", at.x, at.y, at.z);
    let field = |line: usize| format!("end[{}]", line - PREFIX_LINES - 1);
    let read = super::read_gcode(&program, source).map_err(|e| GcodeError::ProfileField {
        file: source.into(),
        field: "end".into(),
        message: format!("cannot be followed: {e}"),
    })?;
    if let Some(u) = read.unknown_moves.iter().find(|u| {
        u.line > PREFIX_LINES
            && ![u.from[2], u.to[2]]
                .iter()
                .all(|z| z.is_some_and(|z| z >= safe_z))
    }) {
        return Err(GcodeError::ProfileField {
            file: source.into(),
            field: field(u.line),
            message: format!(
                "moves the head where the program does not say ({}), which pcpp cannot check \
                 against the part (homing may lower the nozzle onto it, or cross it): park at a \
                 position the line gives instead, e.g. G0 X0 Y200 at the safe height, or \
                 remove it",
                match u.kind {
                    super::read::UnknownMoveKind::Homing => "homing or a stored position",
                    super::read::UnknownMoveKind::Probing => "probing",
                    super::read::UnknownMoveKind::MachineCoordinates => "machine coordinates",
                    super::read::UnknownMoveKind::Statement => {
                        "a controller command or macro that moves it"
                    }
                    _ => "a move from or to an unknown position",
                }
            ),
        });
    }
    Ok(read
        .moves
        .iter()
        .filter(|m| m.line > PREFIX_LINES)
        .map(|m| WrittenMove {
            line: after + m.line - PREFIX_LINES,
            from: Some(m.from),
            to: m.to,
            kind: MoveKind::End,
        })
        .collect())
}

fn check_job(job: &GcodeJob) -> Result<(), GcodeError> {
    let (lo, hi) = FEED_RANGE_MM_S;
    if !(job.speed_mm_s.is_finite() && (lo..=hi).contains(&job.speed_mm_s)) {
        return Err(GcodeError::Parameter {
            name: "print speed (mm/s)",
            value: job.speed_mm_s,
            reason: format!("must be between {lo} and {hi} mm/s"),
        });
    }
    if !(job.dwell_s.is_finite() && (0.0..=MAX_DWELL_S).contains(&job.dwell_s)) {
        return Err(GcodeError::Parameter {
            name: "dwell (s)",
            value: job.dwell_s,
            reason: format!("must be between 0 and {MAX_DWELL_S} s"),
        });
    }
    if !job.scan_top_z_mm.is_finite() {
        return Err(GcodeError::Parameter {
            name: "scan top z (mm)",
            value: job.scan_top_z_mm,
            reason: "must be finite".into(),
        });
    }
    Ok(())
}

/// Checks every point, then returns the travel height: above the scan and
/// above every tool-path point by the clearance, so that travel can touch
/// neither the part nor a path planned above it. The error is what writing
/// the job would fail with (a point not finite, or outside the build
/// volume, or the travel height above it).
pub fn checked_safe_height(job: &GcodeJob, profile: &MachineProfile) -> Result<f64, GcodeError> {
    let volume = profile.build_volume;
    let mut top = job.scan_top_z_mm;
    for (subpath, points) in job.toolpaths.iter().enumerate() {
        for (point, &position) in points.iter().enumerate() {
            if !position.is_finite() {
                return Err(GcodeError::NonFinitePoint {
                    subpath,
                    point,
                    position,
                });
            }
            if !volume.contains(position) {
                return Err(GcodeError::OutOfVolume {
                    subpath,
                    point,
                    position,
                    volume,
                    profile: profile.name.clone(),
                });
            }
            top = top.max(position.z);
        }
    }
    let safe_z = top + profile.safe_travel_clearance_mm;
    if !(volume.min_mm.z..=volume.max_mm.z).contains(&safe_z) {
        return Err(GcodeError::SafeHeightOutOfVolume {
            safe_z_mm: safe_z,
            scan_top_z_mm: job.scan_top_z_mm,
            clearance_mm: profile.safe_travel_clearance_mm,
            volume,
            profile: profile.name.clone(),
        });
    }
    Ok(safe_z)
}

fn feed_word(profile: &MachineProfile, speed_mm_s: f64) -> String {
    trimmed(profile.feed_units.from_mm_s(speed_mm_s), profile.decimals)
}

struct Program<'p> {
    out: String,
    /// Lines written so far.
    lines: usize,
    /// Where the head is, once known (after the first full move).
    at: Option<DVec3>,
    moves: Vec<WrittenMove>,
    profile: &'p MachineProfile,
    /// Labels template errors (which cannot happen after `validate`).
    source: String,
    decimals: u32,
    safe_z: String,
    travel_f: String,
    print_f: String,
}

impl<'p> Program<'p> {
    fn line(&mut self, text: &str) {
        self.out.push_str(text);
        self.out.push('\n');
        self.lines += 1 + text.matches('\n').count();
    }

    /// A coordinate as the controller reads it.
    fn read_back(&self, v: f64) -> f64 {
        super::format::read_back(v, self.decimals)
    }

    /// Records the move the last written line commands, to `to` (rounded
    /// as written); the safe height is `self.safe_z` as written.
    fn moved(&mut self, to: DVec3, kind: MoveKind) {
        let to = DVec3::new(
            self.read_back(to.x),
            self.read_back(to.y),
            self.read_back(to.z),
        );
        self.moved_to(to, kind);
    }

    /// [`Self::moved`] to `to` as the controller reads it already.
    fn moved_to(&mut self, to: DVec3, kind: MoveKind) {
        self.moves.push(WrittenMove {
            line: self.lines,
            from: self.at,
            to,
            kind,
        });
        self.at = Some(to);
    }

    fn comment(&mut self, text: &str) {
        let line = comment_line(&self.profile.comment, text);
        self.line(&line);
    }

    fn new(job: &GcodeJob, profile: &'p MachineProfile, safe_z: f64) -> Program<'p> {
        Program {
            out: String::new(),
            lines: 0,
            at: None,
            moves: Vec::new(),
            profile,
            source: profile.label(),
            decimals: profile.decimals,
            safe_z: fixed(safe_z, profile.decimals),
            travel_f: feed_word(profile, profile.travel_feed_mm_s),
            print_f: feed_word(profile, job.speed_mm_s),
        }
    }

    fn header(&mut self, job: &GcodeJob, safe_z: f64) {
        self.comment(&format!("pcpp {}", env!("CARGO_PKG_VERSION")));
        for (key, value) in job.header {
            self.comment(&format!("{key}: {value}"));
        }
        self.comment(&format!("profile: {}", self.profile.name));
        let units = self.profile.feed_units.label();
        let print = format!(
            "print feed: F{} {units} ({} mm/s)",
            self.print_f, job.speed_mm_s
        );
        self.comment(&print);
        self.comment(&format!("safe travel height: {} mm", fixed(safe_z, 3)));
        // Spec 6(f): safety is a property of every move, and the first one
        // starts where nothing in the program says (safety audit, finding
        // 4): the header names the one move the clearance line leaves out.
        self.comment(FIRST_RISE_NOTE);
    }

    fn fill(&self, field: &str, line: &str, extra: &[(&str, &str)]) -> Result<String, GcodeError> {
        template::fill(line, |token| match token {
            "safe_z" => Some(self.safe_z.clone()),
            "travel_f" => Some(self.travel_f.clone()),
            "print_f" => Some(self.print_f.clone()),
            _ => extra
                .iter()
                .find(|(name, _)| *name == token)
                .map(|(_, value)| value.to_string()),
        })
        .map_err(|e| {
            let known = if field == "dwell" {
                DWELL_TOKENS
            } else {
                BLOCK_TOKENS
            };
            template_error(&self.source, field, e, known)
        })
    }

    fn block(&mut self, field: &str, lines: &[String]) -> Result<(), GcodeError> {
        for (i, line) in lines.iter().enumerate() {
            let text = self.fill(&format!("{field}[{i}]"), line, &[])?;
            self.line(&text);
        }
        Ok(())
    }

    fn dwell_line(&self, dwell_s: f64) -> Result<Option<String>, GcodeError> {
        if dwell_s <= 0.0 {
            return Ok(None);
        }
        let ms = fixed(dwell_s * 1000.0, 0);
        let s = fixed(dwell_s, 3);
        self.fill("dwell", &self.profile.dwell, &[("ms", &ms), ("s", &s)])
            .map(Some)
    }

    fn xyz(&self, p: DVec3) -> String {
        let d = self.decimals;
        format!("X{} Y{} Z{}", fixed(p.x, d), fixed(p.y, d), fixed(p.z, d))
    }

    /// `G0`, with the travel feed where the controller moves G0 at the modal
    /// feed rate (Marlin).
    fn rapid(&mut self, words: &str) {
        let line = if self.profile.rapid_feed_word {
            format!("G0 {words} F{}", self.travel_f)
        } else {
            format!("G0 {words}")
        };
        self.line(&line);
    }

    /// The rise (first) or lift (after a print) to the safe height.
    fn rapid_z(&mut self) {
        let words = format!("Z{}", self.safe_z);
        self.rapid(&words);
        let z: f64 = self.safe_z.parse().unwrap_or(f64::NAN);
        match self.at {
            Some(p) => self.moved(DVec3::new(p.x, p.y, z), MoveKind::Lift),
            None => {
                // Where the head starts is not known: the rise is listed
                // with its height only, and the head's XY becomes known
                // with the first travel.
                self.moves.push(WrittenMove {
                    line: self.lines,
                    from: None,
                    to: DVec3::new(f64::NAN, f64::NAN, z),
                    kind: MoveKind::Rise,
                });
            }
        }
    }

    fn print(
        &mut self,
        index: usize,
        points: &[DVec3],
        dwell: Option<&str>,
    ) -> Result<(), GcodeError> {
        let [first, rest @ ..] = points else {
            return Ok(());
        };
        let count = match points.len() {
            1 => "1 point".to_string(),
            n => format!("{n} points"),
        };
        self.comment(&format!("subpath {index}: {count}"));
        // Travel over the first point at the safe height, then a vertical
        // descent: XY only ever changes at the safe height while the valve
        // is closed.
        let over = format!(
            "X{} Y{} Z{}",
            fixed(first.x, self.decimals),
            fixed(first.y, self.decimals),
            self.safe_z
        );
        self.rapid(&over);
        let safe: f64 = self.safe_z.parse().unwrap_or(f64::NAN);
        let over_at = DVec3::new(first.x, first.y, safe);
        if self.at.is_none() {
            // After the first rise only z is known; travel from there is
            // at the safe height whatever the XY.
            let to = DVec3::new(self.read_back(first.x), self.read_back(first.y), safe);
            self.moves.push(WrittenMove {
                line: self.lines,
                from: None,
                to,
                kind: MoveKind::Travel,
            });
            self.at = Some(to);
        } else {
            self.moved(over_at, MoveKind::Travel);
        }
        let descend = format!("G1 {} F{}", self.xyz(*first), self.travel_f);
        self.line(&descend);
        self.moved(*first, MoveKind::Descend);
        let profile = self.profile;
        self.block("dispense_on", &profile.dispense_on)?;
        if let Some(dwell) = dwell {
            self.line(dwell);
        }
        // Most of a program's lines: written in place, each coordinate
        // read back as it is written (the same text and values as `xyz`
        // and `moved`).
        let d = self.decimals;
        for (i, p) in rest.iter().enumerate() {
            let out = &mut self.out;
            out.push_str("G1 X");
            let x = push_fixed(out, p.x, d);
            out.push_str(" Y");
            let y = push_fixed(out, p.y, d);
            out.push_str(" Z");
            let z = push_fixed(out, p.z, d);
            if i == 0 {
                out.push_str(" F");
                out.push_str(&self.print_f);
            }
            out.push('\n');
            self.lines += 1;
            self.moved_to(DVec3::new(x, y, z), MoveKind::Print);
        }
        if let Some(dwell) = dwell {
            self.line(dwell);
        }
        self.block("dispense_off", &profile.dispense_off)?;
        self.rapid_z();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job<'a>(paths: &'a [Vec<DVec3>], header: &'a [(String, String)]) -> GcodeJob<'a> {
        GcodeJob {
            toolpaths: paths,
            speed_mm_s: 5.0,
            dwell_s: 0.0,
            header,
            scan_top_z_mm: 10.0,
        }
    }

    fn marlin() -> MachineProfile {
        MachineProfile::builtin("marlin").unwrap()
    }

    fn line_path() -> Vec<Vec<DVec3>> {
        vec![vec![
            DVec3::new(10.0, 20.0, 1.0),
            DVec3::new(11.0, 20.0, 1.5),
            DVec3::new(12.0, 20.0, 1.25),
        ]]
    }

    #[test]
    fn a_new_header_on_written_moves_is_the_program_written_afresh() {
        let paths = line_path();
        let pair = |v: &str| [("check".to_string(), v.to_string())];
        let (draft, last) = (pair("pending"), pair("0 touching moves, min 0.102 mm"));
        for name in MachineProfile::builtin_names() {
            let p = MachineProfile::builtin(name).unwrap();
            let first = write_program(&job(&paths, &draft), &p).unwrap();
            let swapped = first.with_header(&job(&paths, &last), &p).unwrap();
            let afresh = write_program(&job(&paths, &last), &p).unwrap();
            assert_ne!(first.text, afresh.text);
            assert_eq!(swapped.as_deref(), Some(afresh.text.as_str()), "{name}");
            // A header of another length would move the lines: refused.
            let longer = [draft[0].clone(), ("more".to_string(), "x".to_string())];
            assert_eq!(first.with_header(&job(&paths, &longer), &p).unwrap(), None);
        }
    }

    #[test]
    fn marlin_program_reads_as_expected() {
        let paths = line_path();
        let header = [("planner".to_string(), "constant offset".to_string())];
        let text = write_gcode(&job(&paths, &header), &marlin()).unwrap();
        let version = env!("CARGO_PKG_VERSION");
        let expected = format!(
            "; pcpp {version}
; planner: constant offset
; profile: marlin
; print feed: F300 mm/min (5 mm/s)
; safe travel height: 15.000 mm
; {FIRST_RISE_NOTE}
G21
G90
M107
G0 Z15.000 F3000
; subpath 0: 3 points
G0 X10.000 Y20.000 Z15.000 F3000
G1 X10.000 Y20.000 Z1.000 F3000
M106 S255
G1 X11.000 Y20.000 Z1.500 F300
G1 X12.000 Y20.000 Z1.250
M107
G0 Z15.000 F3000
M107
M84
"
        );
        assert_eq!(text, expected);
    }

    #[test]
    fn dwell_templates_per_dialect() {
        let paths = line_path();
        for (name, line) in [
            ("marlin", "G4 P250"),
            ("aerotech", "DWELL 0.250"),
            ("grbl", "G4 P0.250"),
        ] {
            let mut j = job(&paths, &[]);
            j.dwell_s = 0.25;
            let text = write_gcode(&j, &MachineProfile::builtin(name).unwrap()).unwrap();
            assert_eq!(
                text.lines().filter(|l| *l == line).count(),
                2,
                "{name}\n{text}"
            );
        }
    }

    /// The end block's moves are followed from the last lift and listed
    /// for the motion check, with their lines; a move it cannot place
    /// below the safe height (homing Z) is refused by its line.
    #[test]
    fn end_block_moves_are_followed_for_the_check() {
        let paths = line_path();
        let mut p = marlin();
        p.end = vec![
            "M107".into(),
            "G91 ; lift".into(),
            "G1 Z10".into(),
            "G90".into(),
            "G0 X0 Y200".into(),
            "G1 Z0".into(),
            "M84".into(),
        ];
        let w = write_program(&job(&paths, &[]), &p).unwrap();
        let end: Vec<&WrittenMove> = w.moves.iter().filter(|m| m.kind == MoveKind::End).collect();
        let lines: Vec<&str> = w.text.lines().collect();
        let at = |m: &WrittenMove| lines[m.line - 1];
        assert_eq!(end.len(), 3, "{end:?}");
        assert_eq!(
            (at(end[0]), end[0].to),
            ("G1 Z10", DVec3::new(12.0, 20.0, 25.0))
        );
        let last_lift = w
            .moves
            .iter()
            .rfind(|m| m.kind == MoveKind::Lift)
            .unwrap()
            .to;
        assert_eq!(end[0].from, Some(last_lift));
        assert_eq!(
            (at(end[1]), end[1].to),
            ("G0 X0 Y200", DVec3::new(0.0, 200.0, 25.0))
        );
        assert_eq!(
            (at(end[2]), end[2].to),
            ("G1 Z0", DVec3::new(0.0, 200.0, 0.0))
        );
        // Homing leaves the head where the file does not say (the reader
        // takes every axis as unknown after it: G28 may pass an
        // intermediate point, or lower Z first).
        for homing in ["G28", "G28 X Y"] {
            p.end = vec!["M107".into(), homing.into(), "M84".into()];
            let e = write_program(&job(&paths, &[]), &p)
                .unwrap_err()
                .to_string();
            assert!(e.contains("`end[1]`") && e.contains("homing"), "{e}");
        }
    }

    #[test]
    fn start_blocks_that_move_the_head_are_named() {
        for name in MachineProfile::builtin_names() {
            let p = MachineProfile::builtin(name).unwrap();
            assert_eq!(StartBlock::of(&p).and_then(|b| b.motion()), None, "{name}");
        }
        let mut p = marlin();
        for (start, named) in [
            (
                vec!["G21", "G90", "G28", "G0 Z{safe_z}"],
                Some("start[2] `G28`"),
            ),
            (
                vec!["G21", "G1 Z{safe_z} F{travel_f}"],
                Some("start[1] `G1 Z{safe_z} F{travel_f}`"),
            ),
            (vec!["G21", "G29 ; level"], Some("start[1] `G29 ; level`")),
            (vec!["G21\nG0 X10", "M107"], Some("start[0] `G21\nG0 X10`")),
            (vec!["G21", "M107", "G4 P100"], None),
            (
                vec!["G21", "PRINT_START BED=60", "G28"],
                Some("start[1] `PRINT_START BED=60` (a firmware macro, which may home or move the head)"),
            ),
            (vec!["G21", "M107 ; fan off", "T0", "M104 S0"], None),
            (vec!["G21", "G1Z5"], Some("start[1] `G1Z5`")),
            // A bare coordinate moves in the machine's motion mode
            // (QA round 19: "a line the reader cannot follow").
            (vec!["G21", "M107", "Z0"], Some("start[2] `Z0`")),
            (vec![], None),
        ] {
            p.start = start.iter().map(|l| l.to_string()).collect();
            let motion = StartBlock::of(&p).and_then(|b| b.motion());
            assert_eq!(motion.as_deref(), named, "{start:?}");
        }
    }

    #[test]
    fn block_tokens_are_filled() {
        let paths = line_path();
        let mut p = marlin();
        p.end = vec!["G0 Z{safe_z} F{travel_f} ; then {print_f} {{x}}".into()];
        let text = write_gcode(&job(&paths, &[]), &p).unwrap();
        assert!(
            text.ends_with("G0 Z15.000 F3000 ; then 300 {x}\n"),
            "{text}"
        );
    }

    #[test]
    fn safe_height_clears_points_above_the_scan() {
        let paths = vec![vec![DVec3::new(10.0, 10.0, 12.0)]];
        let text = write_gcode(&job(&paths, &[]), &marlin()).unwrap();
        assert!(text.contains("G0 Z17.000"), "{text}");
        assert!(!text.contains("Z15.000"), "{text}");
    }

    #[test]
    fn a_single_point_is_a_dot_and_empty_subpaths_are_skipped() {
        let paths = vec![vec![], vec![DVec3::new(10.0, 10.0, 1.0)], vec![]];
        let mut j = job(&paths, &[]);
        j.dwell_s = 0.5;
        let text = write_gcode(&j, &marlin()).unwrap();
        assert!(
            text.contains("G1 X10.000 Y10.000 Z1.000 F3000\nM106 S255\nG4 P500\nG4 P500\nM107\n"),
            "{text}"
        );
        assert_eq!(text.matches("; subpath").count(), 1, "{text}");
    }

    #[test]
    fn no_paths_is_a_program_without_motion() {
        let text = write_gcode(&job(&[], &[]), &marlin()).unwrap();
        assert!(!text.contains("G0") && !text.contains("G1"), "{text}");
        assert!(text.ends_with("M107\nM84\n"));
    }

    #[test]
    fn out_of_volume_names_subpath_point_coordinates_and_volume() {
        let mut paths = line_path();
        paths.push(vec![
            DVec3::new(10.0, 10.0, 1.0),
            DVec3::new(-3.5, 10.0, 1.0),
        ]);
        let e = write_gcode(&job(&paths, &[]), &marlin()).unwrap_err();
        assert!(matches!(
            e,
            GcodeError::OutOfVolume {
                subpath: 1,
                point: 1,
                ..
            }
        ));
        let m = e.to_string();
        assert!(
            m.contains("subpath 1, point 1") && m.contains("(-3.500, 10.000, 1.000)"),
            "{m}"
        );
        assert!(m.contains("x 0..220, y 0..220, z 0..250"), "{m}");
    }

    /// A drawing's corner on the bed's edge: the spline's overshoot put
    /// the point 0.6 micrometres past the face, and the plan was refused
    /// ("point ... at (80.000, -0.001, ...) lies outside the build volume").
    /// A hair out is written on the face; more is still an error.
    #[test]
    fn a_point_a_hair_past_a_face_is_written_on_it() {
        let paths = vec![vec![
            DVec3::new(80.0, 10.0, 5.0),
            DVec3::new(80.0, -0.0006, 5.0),
            DVec3::new(220.0004, 3.0, 5.0),
        ]];
        let p = write_program(&job(&paths, &[]), &marlin()).unwrap();
        assert!(
            p.text.contains("G1 X80.000 Y0.000 Z5.000 F300\n"),
            "{}",
            p.text
        );
        assert!(p.text.contains("G1 X220.000 Y3.000 Z5.000\n"), "{}", p.text);
        assert!(!p.text.contains("-0.001") && !p.text.contains("220.001"));
        let out_of = |m: &&WrittenMove| m.to.y < 0.0 || m.to.x > 220.0;
        assert_eq!(p.moves.iter().find(out_of), None);
        let out = vec![vec![
            DVec3::new(80.0, 10.0, 5.0),
            DVec3::new(80.0, -0.0011, 5.0),
        ]];
        let e = write_gcode(&job(&out, &[]), &marlin()).unwrap_err();
        assert!(matches!(e, GcodeError::OutOfVolume { point: 1, .. }), "{e}");
    }

    #[test]
    fn safe_height_above_the_volume_is_an_error() {
        let paths = line_path();
        let mut j = job(&paths, &[]);
        j.scan_top_z_mm = 248.0;
        let e = write_gcode(&j, &marlin()).unwrap_err();
        assert!(matches!(e, GcodeError::SafeHeightOutOfVolume { .. }), "{e}");
        assert!(e.to_string().contains("253"), "{e}");
        // Written as a person reads them, not 248.33359999999999.
        j.scan_top_z_mm = 248.0 + 0.333_6 + 1e-14;
        let e = write_gcode(&j, &marlin()).unwrap_err().to_string();
        assert!(
            e.starts_with("safe travel height 253.334 mm (highest of scan top 248.334 mm"),
            "{e}"
        );
    }

    #[test]
    fn non_finite_inputs_are_errors() {
        let mut paths = line_path();
        paths[0][2].y = f64::NAN;
        let e = write_gcode(&job(&paths, &[]), &marlin()).unwrap_err();
        assert!(matches!(
            e,
            GcodeError::NonFinitePoint {
                subpath: 0,
                point: 2,
                ..
            }
        ));
        assert!(e.to_string().contains("subpath 0, point 2"), "{e}");
        let paths = line_path();
        for (speed, dwell, top) in [
            (f64::NAN, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (-5.0, 0.0, 0.0),
            (f64::INFINITY, 0.0, 0.0),
            (5.0, -1.0, 0.0),
            (5.0, f64::NAN, 0.0),
            (5.0, 0.0, f64::NEG_INFINITY),
        ] {
            let j = GcodeJob {
                speed_mm_s: speed,
                dwell_s: dwell,
                scan_top_z_mm: top,
                ..job(&paths, &[])
            };
            let e = write_gcode(&j, &marlin()).unwrap_err();
            assert!(matches!(e, GcodeError::Parameter { .. }), "{e}");
        }
    }

    #[test]
    fn header_values_cannot_inject_commands() {
        let paths = line_path();
        let header = [
            ("note\nM3".to_string(), "x\r\nG0 Z-50".to_string()),
            ("paren".to_string(), "a) M3 (b".to_string()),
        ];
        for name in MachineProfile::builtin_names() {
            let p = MachineProfile::builtin(name).unwrap();
            let text = write_gcode(&job(&paths, &header), &p).unwrap();
            for line in text.lines() {
                assert!(
                    !line.starts_with("M3") && !line.starts_with("G0 Z-50"),
                    "{text}"
                );
            }
        }
        let grbl = MachineProfile::builtin("grbl").unwrap();
        let text = write_gcode(&job(&paths, &header), &grbl).unwrap();
        assert!(text.contains("( paren: a] M3 [b )"), "{text}");
    }

    #[test]
    fn hand_built_invalid_profiles_are_rejected() {
        let paths = line_path();
        let mut p = marlin();
        p.dwell = "G4 P{seconds}".into();
        let e = write_gcode(&job(&paths, &[]), &p).unwrap_err();
        assert!(e.to_string().contains("{seconds}"), "{e}");
        let mut p = marlin();
        p.decimals = 12;
        assert!(write_gcode(&job(&paths, &[]), &p).is_err());
    }

    #[test]
    fn negative_zero_and_rounding_noise_do_not_leak() {
        let paths = vec![vec![
            DVec3::new(-0.0, -0.0001, 1.0),
            DVec3::new(1e-12, 2.0, 1.0),
        ]];
        let mut p = MachineProfile::builtin("grbl").unwrap();
        p.decimals = 3;
        let text = write_gcode(&job(&paths, &[]), &p).unwrap();
        assert!(!text.contains("-0.000"), "{text}");
        assert!(text.contains("G1 X0.000 Y0.000 Z1.000"), "{text}");
        assert!(!text.contains("NaN"), "{text}");
    }

    #[test]
    fn output_is_deterministic() {
        let paths = line_path();
        let a = write_gcode(&job(&paths, &[]), &marlin()).unwrap();
        let b = write_gcode(&job(&paths, &[]), &marlin()).unwrap();
        assert_eq!(a, b);
    }
}
