//! Machine profiles as data: one JSON file per controller dialect.
//!
//! Spec section 9: dialects differ in dispense commands, feed units, dwell
//! and comments, so everything that differs lives in a profile a user can
//! copy and edit, and the writer only knows G0/G1 with X Y Z F words, which
//! all supported controllers share. The built-in profiles are the JSON files
//! in `src/gcode/profiles/`, compiled in, so they go through the same loader
//! and checks as a user's file.

use glam::DVec3;
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use serde_json::{Map, Value};

use super::template::{self, TemplateError};
use super::GcodeError;

/// Tokens the start, end and dispense blocks may use.
pub const BLOCK_TOKENS: &[&str] = &["safe_z", "travel_f", "print_f"];
/// Tokens the dwell template may use: the dwell in milliseconds (integer)
/// and in seconds (3 decimals).
pub const DWELL_TOKENS: &[&str] = &["ms", "s"];

/// Digits after the decimal point when a profile does not say.
pub const DEFAULT_DECIMALS: u32 = 3;

/// Slowest and fastest feed a profile or job may ask for, in mm/s: below
/// 0.001 mm/s the feed word rounds to zero, and no microextrusion stage
/// travels at more than a metre a second.
pub(crate) const FEED_RANGE_MM_S: (f64, f64) = (0.001, 1000.0);

/// Largest build-volume coordinate magnitude, mm.
const MAX_VOLUME_MM: f64 = 1.0e6;

const BUILTINS: &[(&str, &str)] = &[
    ("marlin", include_str!("profiles/marlin.json")),
    ("aerotech", include_str!("profiles/aerotech.json")),
    ("grbl", include_str!("profiles/grbl.json")),
];

/// The unit of the `F` word.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedUnits {
    /// RepRap/Marlin, Grbl, LinuxCNC (G94): 5 mm/s is `F300`.
    MmPerMin,
    /// Aerotech A3200 under `G76` (seconds time base): 5 mm/s is `F5`.
    MmPerS,
}

impl FeedUnits {
    /// `speed_mm_s` in this unit.
    pub fn from_mm_s(self, speed_mm_s: f64) -> f64 {
        match self {
            FeedUnits::MmPerMin => speed_mm_s * 60.0,
            FeedUnits::MmPerS => speed_mm_s,
        }
    }

    /// `mm/min` or `mm/s`.
    pub fn label(self) -> &'static str {
        match self {
            FeedUnits::MmPerMin => "mm/min",
            FeedUnits::MmPerS => "mm/s",
        }
    }
}

/// How a comment is written: `prefix text suffix`, e.g. `;` and nothing, `'`
/// and nothing, or `(` and `)`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommentStyle {
    pub prefix: String,
    /// Empty for comments that run to the end of the line.
    #[serde(default)]
    pub suffix: String,
}

/// The axis-aligned box the nozzle may reach, in mm, printer frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildVolume {
    pub min_mm: DVec3,
    pub max_mm: DVec3,
}

/// How far past a face of the build volume a point still counts as on it:
/// the G-code's resolution (coordinates are written to 0.001 mm). A
/// registration's rounding or a spline's overshoot at a drawing's corner
/// on the face puts points a fraction of a micrometre out; the writer
/// writes them on the face ([`BuildVolume::snap`]).
pub const VOLUME_HAIR_MM: f64 = 0.001;

impl BuildVolume {
    /// Inclusive on every face, and [`VOLUME_HAIR_MM`] past it.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min_mm - VOLUME_HAIR_MM).all() && p.cmple(self.max_mm + VOLUME_HAIR_MM).all()
    }

    /// `p` moved onto the volume where it lies past a face by no more
    /// than [`VOLUME_HAIR_MM`] (unchanged inside, and further out).
    pub fn snap(&self, p: DVec3) -> DVec3 {
        if self.contains(p) {
            p.clamp(self.min_mm, self.max_mm)
        } else {
            p
        }
    }
}

impl std::fmt::Display for BuildVolume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (a, b) = (self.min_mm, self.max_mm);
        write!(
            f,
            "x {}..{}, y {}..{}, z {}..{} mm",
            a.x, b.x, a.y, b.y, a.z, b.z
        )
    }
}

/// One controller dialect. Load with [`MachineProfile::from_json`] or
/// [`MachineProfile::builtin`]; both validate. Block templates are lists of
/// lines that may use the [`BLOCK_TOKENS`]; the dwell template may use the
/// [`DWELL_TOKENS`]. Write `{{` and `}}` for literal braces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MachineProfile {
    pub name: String,
    /// Free text for people choosing a profile (wiring, units, caveats).
    pub description: String,
    pub feed_units: FeedUnits,
    /// Lines written after the header, e.g. units and absolute mode.
    pub start: Vec<String>,
    /// Lines written after the last lift.
    pub end: Vec<String>,
    /// Lines that open the dispenser valve.
    pub dispense_on: Vec<String>,
    /// Lines that close it.
    pub dispense_off: Vec<String>,
    /// One line, e.g. `G4 P{ms}`, `DWELL {s}` or `G4 P{s}`.
    pub dwell: String,
    pub comment: CommentStyle,
    /// Travel height above the scan's highest point (and above the highest
    /// tool-path point), so that travel cannot touch the part.
    pub safe_travel_clearance_mm: f64,
    /// Feed of the descent to each path start (and of G0 moves when
    /// `rapid_feed_word` is set).
    pub travel_feed_mm_s: f64,
    /// Write the travel feed on G0 moves: Marlin moves G0 at the modal feed
    /// rate, which would otherwise still be the slow print feed.
    pub rapid_feed_word: bool,
    pub build_volume: BuildVolume,
    /// Digits after the decimal point of coordinates, 3 to 6.
    pub decimals: u32,
    /// Where the profile was read from, naming it in the errors found
    /// when a program is written (QA round 19 F4: a user's file named
    /// "marlin" read as the built-in). Not part of the JSON.
    #[serde(skip)]
    pub source: ProfileSource,
}

/// Where a profile was read from: a file's name, or empty for one made
/// in code. Every source compares equal: two profiles with the same
/// fields are the same profile.
#[derive(Debug, Clone, Default)]
pub struct ProfileSource(pub String);

impl PartialEq for ProfileSource {
    fn eq(&self, _: &ProfileSource) -> bool {
        true
    }
}

impl MachineProfile {
    /// The label of the profile's errors: the file it was read from, or
    /// its name.
    pub fn label(&self) -> String {
        if self.source.0.is_empty() {
            format!("{} (in memory)", self.name)
        } else {
            self.source.0.clone()
        }
    }
}

impl MachineProfile {
    /// Names accepted by [`MachineProfile::builtin`].
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTINS.iter().map(|(name, _)| *name).collect()
    }

    /// A built-in profile by name (`marlin`, `aerotech`, `grbl`).
    pub fn builtin(name: &str) -> Option<MachineProfile> {
        let (_, text) = BUILTINS.iter().find(|(n, _)| *n == name)?;
        // The files are compiled in and a unit test loads each one, so this
        // cannot fail in a released build.
        MachineProfile::from_json(text, &format!("{name} (built in)")).ok()
    }

    /// Reads and validates a profile. `file_name` only labels errors.
    ///
    /// Every field is required except `description` (empty), `suffix` of
    /// `comment` (empty), `rapid_feed_word` (false) and `decimals` (3);
    /// unknown fields are errors so that a misspelt field is not silently
    /// ignored.
    pub fn from_json(text: &str, file_name: &str) -> Result<MachineProfile, GcodeError> {
        // QA round 19 F9: Windows editors save a byte-order mark, which
        // the page's decoder drops and serde_json refuses.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let value: Value = serde_json::from_str(text).map_err(|e| GcodeError::ProfileSyntax {
            file: file_name.into(),
            message: e.to_string(),
        })?;
        // QA round 19: a key written twice was taken at its last value,
        // silently, where a misspelt one is refused.
        if let Some(key) = repeated_key(text) {
            return Err(GcodeError::ProfileField {
                file: file_name.into(),
                field: key,
                message: "appears twice in the file, and only one can be meant: keep one".into(),
            });
        }
        let Value::Object(map) = value else {
            return Err(GcodeError::ProfileSyntax {
                file: file_name.into(),
                message: "expected a JSON object of profile fields".into(),
            });
        };
        // Field by field rather than one derived Deserialize, so that a type
        // error names the field instead of only a line and column.
        let mut fields = Fields {
            map,
            file: file_name,
        };
        let profile = MachineProfile {
            name: fields.required("name")?,
            description: fields.optional("description")?.unwrap_or_default(),
            feed_units: fields.required("feed_units")?,
            start: fields.required("start")?,
            end: fields.required("end")?,
            dispense_on: fields.required("dispense_on")?,
            dispense_off: fields.required("dispense_off")?,
            dwell: fields.required("dwell")?,
            comment: fields.required("comment")?,
            safe_travel_clearance_mm: fields.required("safe_travel_clearance_mm")?,
            travel_feed_mm_s: fields.required("travel_feed_mm_s")?,
            rapid_feed_word: fields.optional("rapid_feed_word")?.unwrap_or(false),
            build_volume: fields.required("build_volume")?,
            decimals: fields.optional("decimals")?.unwrap_or(DEFAULT_DECIMALS),
            source: ProfileSource(file_name.into()),
        };
        fields.finish()?;
        profile.validate(file_name)?;
        Ok(profile)
    }

    /// The profile as pretty JSON that [`MachineProfile::from_json`] reads
    /// back unchanged: the starting point for a user's own profile.
    pub fn to_json(&self) -> Result<String, GcodeError> {
        serde_json::to_string_pretty(self).map_err(|e| GcodeError::ProfileSyntax {
            file: format!("{}.json", self.name),
            message: e.to_string(),
        })
    }

    /// Checks every field; `source` (a file name) labels the errors. The
    /// writer calls this too, because the fields are public.
    pub fn validate(&self, source: &str) -> Result<(), GcodeError> {
        let bad = |field: &str, message: String| GcodeError::ProfileField {
            file: source.into(),
            field: field.into(),
            message,
        };
        if self.name.trim().is_empty() || self.name.chars().any(char::is_control) {
            return Err(bad("name", "must be non-empty text on one line".into()));
        }
        if !(3..=6).contains(&self.decimals) {
            return Err(bad(
                "decimals",
                format!(
                    "must be 3 to 6 (digits after the decimal point), got {}",
                    self.decimals
                ),
            ));
        }
        let clearance = self.safe_travel_clearance_mm;
        if !(clearance.is_finite() && clearance >= 0.0) {
            return Err(bad(
                "safe_travel_clearance_mm",
                format!("must be a finite number >= 0 mm, got {clearance}"),
            ));
        }
        let (lo, hi) = FEED_RANGE_MM_S;
        let travel = self.travel_feed_mm_s;
        if !(travel.is_finite() && (lo..=hi).contains(&travel)) {
            return Err(bad(
                "travel_feed_mm_s",
                format!("must be between {lo} and {hi} mm/s, got {travel}"),
            ));
        }
        let v = &self.build_volume;
        // A kilometre bounds every real stage and keeps every coordinate
        // the volume admits short when written in fixed notation.
        let bounded = |p: DVec3| p.is_finite() && p.abs().max_element() <= MAX_VOLUME_MM;
        if !(bounded(v.min_mm) && bounded(v.max_mm)) {
            return Err(bad(
                "build_volume",
                format!("coordinates must be finite and within ±{MAX_VOLUME_MM} mm"),
            ));
        }
        if !v.min_mm.cmplt(v.max_mm).all() {
            return Err(bad(
                "build_volume",
                format!(
                    "min_mm must be below max_mm on every axis, got {:?} and {:?}",
                    v.min_mm.to_array(),
                    v.max_mm.to_array()
                ),
            ));
        }
        let c = &self.comment;
        if c.prefix.is_empty() {
            return Err(bad("comment.prefix", "must not be empty".into()));
        }
        if c.prefix
            .chars()
            .chain(c.suffix.chars())
            .any(char::is_control)
        {
            return Err(bad(
                "comment",
                "prefix and suffix must not contain line breaks or control characters".into(),
            ));
        }
        // QA round 19 F1, F10: the header's comments must stay comments
        // (a prefix `G1 Z0 ;` made every one a plunge; a space, a letter
        // or a `(` never closed sent the text to the controller).
        for text in COMMENT_PROBES {
            let line = super::format::comment_line(c, text);
            if !super::read::is_comment_only(&line) {
                return Err(bad(
                    "comment",
                    format!(
                        "the comment line `{line}` would be read as a command, not a comment: \
                         use the prefix `;` (Marlin, Grbl), `'` (Aerotech) or `(` with the \
                         suffix `)`"
                    ),
                ));
            }
        }
        if self.dispense_on.is_empty() {
            return Err(bad("dispense_on", "needs at least one line".into()));
        }
        if self.dispense_off.is_empty() {
            return Err(bad("dispense_off", "needs at least one line".into()));
        }
        let blocks = [
            ("start", &self.start),
            ("end", &self.end),
            ("dispense_on", &self.dispense_on),
            ("dispense_off", &self.dispense_off),
        ];
        for (field, lines) in blocks {
            for (i, line) in lines.iter().enumerate() {
                check_template(source, &format!("{field}[{i}]"), line, BLOCK_TOKENS)?;
            }
        }
        self.check_frame(source)?;
        if self.dwell.trim().is_empty() {
            return Err(bad("dwell", "must not be empty".into()));
        }
        check_template(source, "dwell", &self.dwell, DWELL_TOKENS)?;
        // The commands the writer puts between checked moves must not
        // move the head or change where the next move goes (QA round 19
        // F1, F2: axis words on a valve's M-code, a dwell written `G1 Z0
        // P{s}` or `G91 G4 P{s}`).
        for (name, lines) in [
            ("dispense_on", &self.dispense_on),
            ("dispense_off", &self.dispense_off),
        ] {
            for (i, line) in lines.iter().enumerate() {
                check_inert(source, &format!("{name}[{i}]"), line, BLOCK_TOKENS)?;
            }
        }
        check_inert(source, "dwell", &self.dwell, DWELL_TOKENS)
    }
}

/// The first key an object of the JSON `text` repeats, as a path
/// (`comment.prefix`, `start`), which `serde_json` reads as its last value
/// without a word; `None` when there is none (or the text is not JSON,
/// which the parse says).
fn repeated_key(text: &str) -> Option<String> {
    use serde::de::{DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
    struct Walk;
    impl<'de> DeserializeSeed<'de> for Walk {
        type Value = Option<String>;
        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_any(Walk)
        }
    }
    impl<'de> Visitor<'de> for Walk {
        type Value = Option<String>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("JSON")
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut seen = std::collections::HashSet::new();
            let mut found = None;
            while let Some(key) = map.next_key::<String>()? {
                let inner = map.next_value_seed(Walk)?;
                if found.is_none() {
                    found = match inner {
                        Some(path) => Some(format!("{key}.{path}")),
                        None if !seen.insert(key.clone()) => Some(key),
                        None => None,
                    };
                }
            }
            Ok(found)
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut found = None;
            let mut i = 0;
            while let Some(inner) = seq.next_element_seed(Walk)? {
                if found.is_none() {
                    found = inner.map(|path| format!("[{i}].{path}"));
                }
                i += 1;
            }
            Ok(found)
        }
        fn visit_bool<E>(self, _: bool) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_i64<E>(self, _: i64) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_u64<E>(self, _: u64) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_f64<E>(self, _: f64) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_str<E>(self, _: &str) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_unit<E>(self) -> Result<Self::Value, E> {
            Ok(None)
        }
    }
    Walk.deserialize(&mut serde_json::Deserializer::from_str(text))
        .ok()
        .flatten()
}

/// A frame a start may turn on if it turns it off again (G codes times
/// ten): the code that cancels it, and what it does.
fn modal_frame(g: u32) -> Option<(u32, &'static str)> {
    match g {
        410..=429 => Some((400, "offsets the path by the tool's radius")),
        430..=439 => Some((
            490,
            "applies a tool length offset, which shifts every Z after it",
        )),
        510..=519 => Some((500, "scales the coordinates")),
        680..=689 => Some((690, "rotates the coordinates")),
        _ => None,
    }
}

/// Header texts a comment line is tried with: what the writer writes
/// (letters, digits, parentheses, a `;`), so a style that reads any of
/// them as a command is refused.
const COMMENT_PROBES: [&str; 4] = [
    "pcpp 0.1.0",
    "",
    "G1 X10 Y10 Z0 F100",
    "safe motion: min clearance 0.101 mm (tol 0.1 mm); a 'quote'",
];

/// The stage's axis letters: on a line with no motion G-code, Grbl and
/// LinuxCNC move them in the modal motion mode (G1 after a print move).
/// (Other letters are parameters of M-codes the nozzle does not follow:
/// Marlin's `M150 R255 U0 B0` sets a light, `M260 A66 B1` talks to I2C.)
const AXIS_LETTERS: [char; 3] = ['X', 'Y', 'Z'];

/// A command the writer puts between checked moves (a dispense line, the
/// dwell): no axis word, no G-code but the dwell G4, and, followed by
/// the G-code reader (both its readings of M-codes with axis words) from
/// a known position, no move of its own and the next move where it was
/// written to go. Tokens are filled with stand-in values.
fn check_inert(source: &str, field: &str, line: &str, known: &[&str]) -> Result<(), GcodeError> {
    let bad = |message: String| GcodeError::ProfileField {
        file: source.into(),
        field: field.into(),
        message,
    };
    let filled = template::fill(line, |token| {
        known.contains(&token).then(|| "1".to_string())
    })
    .map_err(|e| template_error(source, field, e, known))?;
    let words = super::read::line_words(&filled)
        .map_err(|p| bad(format!("`{}` cannot be read as G-code: {p}", line.trim())))?;
    for (letter, value) in words.iter().flatten() {
        if AXIS_LETTERS.contains(letter) {
            return Err(bad(format!(
                "`{}` has the axis word {letter}: a controller moves that axis (Grbl and \
                 LinuxCNC in the modal motion mode, on a line with no G0/G1), between moves \
                 pcpp checked against the part: remove it",
                line.trim()
            )));
        }
        if *letter == 'G' && value.is_none_or(|v| v != 4.0) {
            return Err(bad(format!(
                "`{}` has a G-code other than the dwell G4 (a move, or a change of units, \
                 mode or frame) between moves pcpp checked against the part: remove it",
                line.trim()
            )));
        }
    }
    let program = format!("G21\nG90\nG0 X1 Y2 Z3\n{filled}\nG0 X4 Y5 Z6\n");
    for read in [super::read_gcode, super::read_gcode_grbl] {
        let followed = read(&program, source).map_err(|e| {
            bad(format!(
                "`{}` cannot be followed by the G-code reader ({e}), so the moves after it \
                 cannot be checked: remove it",
                line.trim()
            ))
        })?;
        let moved_itself = followed.unknown_moves.iter().any(|u| u.line > 3)
            || followed.moves.iter().any(|m| m.line == 4);
        let next: Vec<_> = followed.moves.iter().filter(|m| m.line > 4).collect();
        let next_as_written = matches!(next[..], [m] if m.from == DVec3::new(1.0, 2.0, 3.0)
            && m.to == DVec3::new(4.0, 5.0, 6.0));
        if moved_itself || !next_as_written {
            return Err(bad(format!(
                "`{}` {} between moves pcpp checked against the part: remove it",
                line.trim(),
                if moved_itself {
                    "moves the head"
                } else {
                    "changes where the moves after it go (units, relative moves or offsets)"
                }
            )));
        }
    }
    Ok(())
}

impl MachineProfile {
    /// The writer's moves are millimetres, absolute, in the frame the scan
    /// was placed in (spec section 6f checks them as written): a `start`
    /// that leaves the controller in inches or relative moves, or moves its
    /// frame (G92, a work offset, machine coordinates), and a dispense
    /// command that does any of that or moves an axis, would make the
    /// controller go elsewhere than the moves checked. Refused, naming the
    /// line. (`end` runs after the last move: the writer follows it and
    /// its moves are checked with the program's, `writer::follow_end`.)
    fn check_frame(&self, source: &str) -> Result<(), GcodeError> {
        let bad = |field: String, message: String| GcodeError::ProfileField {
            file: source.into(),
            field,
            message,
        };
        let (mut inches, mut relative) = (None::<(String, u32)>, None::<(String, u32)>);
        let mut feed_mode = None::<(String, u32)>;
        // Offsets, scaling and rotation the start turns on: the G-code
        // that cancels each, the line and the code.
        let mut active: Vec<(u32, String, u32)> = Vec::new();
        let blocks = [
            ("start", &self.start),
            ("dispense_on", &self.dispense_on),
            ("dispense_off", &self.dispense_off),
        ];
        for (name, lines) in blocks {
            for (i, line) in lines.iter().enumerate() {
                let field = format!("{name}[{i}]");
                let words = super::read::line_words(line)
                    .ok()
                    .flatten()
                    .unwrap_or_default();
                let has = |letter: char| words.iter().any(|&(l, _)| l == letter);
                // QA round 19 F3: home offsets move the frame as G92 does.
                if let Some((m, what)) = words.iter().find_map(|&(l, v)| {
                    let m = v.filter(|v| l == 'M' && v.fract() == 0.0 && (0.0..1e5).contains(v))?;
                    Some((m, super::read::m_frame(m as u32)?))
                }) {
                    return Err(bad(
                        field,
                        format!(
                            "M{m} {what}, so the controller would not go where pcpp's moves \
                             (millimetres, absolute, in the frame the scan was placed in) were \
                             checked to go: remove it"
                        ),
                    ));
                }
                // (G codes times ten, as the G-code reader reads them.)
                for g in super::read::g_codes(line) {
                    let what = match g {
                        200 | 700 if name == "start" => {
                            inches = Some((field.clone(), g));
                            continue;
                        }
                        210 | 710 if name == "start" => {
                            inches = None;
                            continue;
                        }
                        910 if name == "start" => {
                            relative = Some((field.clone(), g));
                            continue;
                        }
                        930 | 950 if name == "start" => {
                            feed_mode = Some((field.clone(), g));
                            continue;
                        }
                        940 if name == "start" => {
                            feed_mode = None;
                            continue;
                        }
                        // QA round 19 F3: offsets, scaling and rotation
                        // the G-code reader cannot relate either; those
                        // a later line of the start cancels are fine.
                        100 if has('L') || has('P') => "sets work or tool offsets",
                        520 => "sets a local coordinate offset",
                        _ if name == "start" && modal_frame(g).is_some() => {
                            let cancel = modal_frame(g).map_or(0, |m| m.0);
                            active.retain(|a| a.0 != cancel);
                            active.push((cancel, field.clone(), g));
                            continue;
                        }
                        400 | 490 | 500 | 690 if name == "start" => {
                            active.retain(|a| a.0 != g);
                            continue;
                        }
                        900 if name == "start" => {
                            relative = None;
                            continue;
                        }
                        40 => continue,
                        // Slicers' start blocks reset the extruder with
                        // `G92 E0`, which leaves X, Y and Z as they are.
                        920 if name == "start"
                            && has('E')
                            && !(has('X') || has('Y') || has('Z')) =>
                        {
                            continue
                        }
                        920..=923 => "sets the position to other coordinates",
                        530 => "moves in machine coordinates",
                        540..600 => "switches to another work offset",
                        200 | 700 => "switches to inches",
                        910 => "switches to relative moves",
                        _ if name == "start" => continue,
                        _ => "is a G-code inside the dispense command (a move, or a mode change)",
                    };
                    return Err(bad(
                        field,
                        format!(
                            "{} {what}, so the controller would not go where pcpp's moves \
                             (millimetres, absolute, in the frame the scan was placed in) were \
                             checked to go: remove it",
                            super::read::g_name(g)
                        ),
                    ));
                }
            }
        }
        let left = |state: Option<(String, u32)>, what: &str, back: &str| match state {
            Some((field, g)) => Err(bad(
                field,
                format!(
                    "{} leaves the controller in {what} after the start: remove it, or end \
                     the start with {back}",
                    super::read::g_name(g)
                ),
            )),
            None => Ok(()),
        };
        left(
            inches,
            "inches, but pcpp writes its moves in millimetres",
            "G21",
        )?;
        left(
            relative,
            "relative moves, but pcpp writes its moves absolute",
            "G90",
        )?;
        if let Some((cancel, field, g)) = active.into_iter().next() {
            let what = modal_frame(g).map_or("", |m| m.1);
            return Err(bad(
                field,
                format!(
                    "{} {what}, so the controller would not go where pcpp's moves were checked \
                     to go: remove it, or end the start with {}",
                    super::read::g_name(g),
                    super::read::g_name(cancel)
                ),
            ));
        }
        left(
            feed_mode,
            "another feed mode (inverse time or per revolution), so every F word pcpp writes \
             would be read as another speed",
            "G94",
        )
    }
}

/// One template line: a single line (a line break would split one command
/// into two, behind the writer's back) using only `known` tokens.
fn check_template(source: &str, field: &str, line: &str, known: &[&str]) -> Result<(), GcodeError> {
    if line.contains(['\n', '\r']) {
        return Err(GcodeError::ProfileField {
            file: source.into(),
            field: field.into(),
            message: "must be one line (use one list entry per line)".into(),
        });
    }
    template::check(line, known).map_err(|e| template_error(source, field, e, known))
}

pub(crate) fn template_error(
    source: &str,
    field: &str,
    error: TemplateError,
    known: &[&str],
) -> GcodeError {
    let known_list = || {
        known
            .iter()
            .map(|t| format!("{{{t}}}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    match error {
        TemplateError::UnknownToken(token) => GcodeError::UnknownToken {
            file: source.into(),
            field: field.into(),
            token,
            known: known_list(),
        },
        TemplateError::UnclosedBrace => GcodeError::ProfileField {
            file: source.into(),
            field: field.into(),
            message: "has a `{` without a matching `}` (write `{{` for a literal brace)".into(),
        },
        TemplateError::StrayCloseBrace => GcodeError::ProfileField {
            file: source.into(),
            field: field.into(),
            message: "has a `}` without a matching `{` (write `}}` for a literal brace)".into(),
        },
    }
}

/// The fields of a profile object, taken one by one.
struct Fields<'a> {
    map: Map<String, Value>,
    file: &'a str,
}

impl Fields<'_> {
    fn optional<T: DeserializeOwned>(&mut self, key: &str) -> Result<Option<T>, GcodeError> {
        let Some(value) = self.map.remove(key) else {
            return Ok(None);
        };
        serde_json::from_value(value)
            .map(Some)
            .map_err(|e| GcodeError::ProfileField {
                file: self.file.into(),
                field: key.into(),
                message: e.to_string(),
            })
    }

    fn required<T: DeserializeOwned>(&mut self, key: &str) -> Result<T, GcodeError> {
        self.optional(key)?.ok_or_else(|| GcodeError::ProfileField {
            file: self.file.into(),
            field: key.into(),
            message: "missing".into(),
        })
    }

    fn finish(self) -> Result<(), GcodeError> {
        match self.map.keys().next() {
            Some(key) => Err(GcodeError::ProfileField {
                file: self.file.into(),
                field: key.clone(),
                message: "not a profile field (misspelt?)".into(),
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marlin_json() -> Value {
        serde_json::from_str(include_str!("profiles/marlin.json")).unwrap()
    }

    fn load(value: &Value) -> Result<MachineProfile, GcodeError> {
        MachineProfile::from_json(&value.to_string(), "my.json")
    }

    fn load_err(edit: impl FnOnce(&mut Map<String, Value>)) -> String {
        let mut v = marlin_json();
        edit(v.as_object_mut().unwrap());
        let e = load(&v).unwrap_err().to_string();
        assert!(e.contains("my.json"), "error must name the file: {e}");
        e
    }

    #[test]
    fn every_builtin_loads() {
        assert_eq!(
            MachineProfile::builtin_names(),
            ["marlin", "aerotech", "grbl"]
        );
        for name in MachineProfile::builtin_names() {
            let text = BUILTINS.iter().find(|(n, _)| *n == name).unwrap().1;
            let p = MachineProfile::from_json(text, name).unwrap();
            assert_eq!(p.name, name);
            assert_eq!(MachineProfile::builtin(name), Some(p));
        }
        assert_eq!(MachineProfile::builtin("makerbot"), None);
    }

    #[test]
    fn builtin_dialects_match_their_controllers() {
        let m = MachineProfile::builtin("marlin").unwrap();
        assert_eq!(m.feed_units, FeedUnits::MmPerMin);
        assert_eq!(m.dispense_on, ["M106 S255"]);
        assert_eq!(m.dispense_off, ["M107"]);
        assert_eq!(m.dwell, "G4 P{ms}");
        assert!(m.start.starts_with(&["G21".into(), "G90".into()]));
        let a = MachineProfile::builtin("aerotech").unwrap();
        assert_eq!(a.feed_units, FeedUnits::MmPerS);
        assert_eq!(a.dispense_on, ["$DO[0].X = 1"]);
        assert_eq!(a.dwell, "DWELL {s}");
        assert_eq!(a.comment.prefix, "'");
        assert_eq!(a.end.last().map(String::as_str), Some("M2"));
        let g = MachineProfile::builtin("grbl").unwrap();
        assert_eq!(
            (g.dispense_on[0].as_str(), g.dispense_off[0].as_str()),
            ("M8", "M9")
        );
        assert_eq!(g.dwell, "G4 P{s}");
        assert_eq!(
            (g.comment.prefix.as_str(), g.comment.suffix.as_str()),
            ("(", ")")
        );
    }

    #[test]
    fn json_round_trip_is_lossless() {
        for name in MachineProfile::builtin_names() {
            let p = MachineProfile::builtin(name).unwrap();
            let text = p.to_json().unwrap();
            assert_eq!(MachineProfile::from_json(&text, "copy.json").unwrap(), p);
        }
    }

    #[test]
    fn optional_fields_take_their_defaults() {
        let mut v = marlin_json();
        let map = v.as_object_mut().unwrap();
        for key in ["description", "rapid_feed_word", "decimals"] {
            map.remove(key);
        }
        map.insert("comment".into(), serde_json::json!({ "prefix": ";" }));
        let p = load(&v).unwrap();
        assert_eq!(p.description, "");
        assert!(!p.rapid_feed_word);
        assert_eq!(p.decimals, DEFAULT_DECIMALS);
        assert_eq!(p.comment.suffix, "");
    }

    /// A start that leaves inches or relative moves, a frame moved (G92,
    /// a work offset) or a G-code inside a dispense command would send the
    /// controller elsewhere than the moves checked: refused by line. Set
    /// back within the start, in comments, dwells and the end block, they
    /// are not.
    #[test]
    fn blocks_that_change_units_mode_or_frame_are_refused_by_line() {
        let block = |field: &str, lines: &[&str]| {
            let mut v = marlin_json();
            v.as_object_mut()
                .unwrap()
                .insert(field.into(), serde_json::json!(lines));
            load(&v).map(|_| ()).map_err(|e| e.to_string())
        };
        for (field, lines, named, says) in [
            ("start", &["G20", "G90"][..], "`start[0]`", "inches"),
            (
                "start",
                &["G21", "G91", "G1 Z5"][..],
                "`start[1]`",
                "relative moves",
            ),
            (
                "start",
                &["G21", "G90", "G92 X0 Y0"][..],
                "`start[2]`",
                "other coordinates",
            ),
            ("start", &["G21 G55"][..], "`start[0]`", "work offset"),
            (
                "dispense_on",
                &["G1 Z200", "M106 S255"][..],
                "`dispense_on[0]`",
                "inside the dispense",
            ),
            (
                "dispense_off",
                &["M107", "g91"][..],
                "`dispense_off[1]`",
                "relative",
            ),
        ] {
            let e = block(field, lines).unwrap_err();
            assert!(e.contains(named) && e.contains(says), "{lines:?}: {e}");
        }
        for (field, lines) in [
            (
                "start",
                &["G20", "G91", "G28", "G1 Z5", "G21", "G90", "M107"][..],
            ),
            (
                "start",
                &["G21 ; G91 G92 in a comment", "G90 (not G20)"][..],
            ),
            ("dispense_on", &["M106 S255", "G4 P50"][..]),
            ("end", &["G91", "G1 Z10", "G90", "M84"][..]),
        ] {
            assert_eq!(block(field, lines), Ok(()), "{lines:?}");
        }
        for name in MachineProfile::builtin_names() {
            MachineProfile::builtin(name).unwrap();
        }
    }

    /// QA round 19 F1-F3, F9, F10: what the writer puts between checked
    /// moves (comments, dispense commands, the dwell) cannot move the
    /// head or change where the next move goes, and a start cannot leave
    /// offsets, scaling or another feed mode the checks do not know.
    #[test]
    fn lines_between_checked_moves_cannot_move_the_head() {
        let with = |field: &str, value: Value| {
            let mut v = marlin_json();
            v.as_object_mut().unwrap().insert(field.into(), value);
            load(&v).map(|_| ()).map_err(|e| e.to_string())
        };
        use serde_json::json;
        for (field, value, named, says) in [
            (
                "comment",
                json!({"prefix": "G1 Z0 ;"}),
                "`comment`",
                "`G1 Z0 ; pcpp",
            ),
            (
                "comment",
                json!({"prefix": " "}),
                "`comment`",
                "read as a command",
            ),
            (
                "comment",
                json!({"prefix": "X"}),
                "`comment`",
                "read as a command",
            ),
            ("comment", json!({"prefix": "("}), "`comment`", "suffix `)`"),
            (
                "comment",
                json!({"prefix": "%"}),
                "`comment`",
                "read as a command",
            ),
            (
                "dispense_on",
                json!(["M3 S1000 Z-2"]),
                "`dispense_on[0]`",
                "axis word Z",
            ),
            (
                "dispense_on",
                json!(["M106", "X10 Y10 Z0"]),
                "`dispense_on[1]`",
                "axis word X",
            ),
            (
                "dispense_off",
                json!(["M5 Z0"]),
                "`dispense_off[0]`",
                "axis word Z",
            ),
            (
                "dwell",
                json!("G1 Z0 P{s}"),
                "`dwell`",
                "other than the dwell G4",
            ),
            ("dwell", json!("G4 P{s} Z0"), "`dwell`", "axis word Z"),
            (
                "dwell",
                json!("G91 G4 P{s}"),
                "`dwell`",
                "other than the dwell G4",
            ),
            (
                "dwell",
                json!("G4 P{s} G20"),
                "`dwell`",
                "other than the dwell G4",
            ),
            (
                "dwell",
                json!("G92 Z0 G4 P{s}"),
                "`dwell`",
                "other than the dwell G4",
            ),
            ("dwell", json!("G4 P{s} M206 Z5"), "`dwell`", "axis word Z"),
            (
                "dwell",
                json!("G4 P{s} M428"),
                "`dwell`",
                "cannot be followed",
            ),
            (
                "dispense_on",
                json!(["M106 S255 (open"]),
                "`dispense_on[0]`",
                "cannot be read",
            ),
            (
                "start",
                json!(["G21", "G10 L20 P1 X0 Y0 Z0"]),
                "`start[1]`",
                "offsets",
            ),
            (
                "start",
                json!(["G21", "G10 L2 P1 Z-5"]),
                "`start[1]`",
                "offsets",
            ),
            (
                "start",
                json!(["G21", "G43 H1"]),
                "`start[1]`",
                "tool length offset",
            ),
            (
                "start",
                json!(["G43.1 Z5"]),
                "`start[0]`",
                "tool length offset",
            ),
            (
                "start",
                json!(["G21", "M206 Z-5"]),
                "`start[1]`",
                "home offsets",
            ),
            ("start", json!(["G51 X2"]), "`start[0]`", "scales"),
            ("start", json!(["G68 R30"]), "`start[0]`", "rotates"),
            ("start", json!(["G21", "G93"]), "`start[1]`", "feed mode"),
            (
                "start",
                json!(["G21", "G92 E0 Z0"]),
                "`start[1]`",
                "other coordinates",
            ),
            (
                "start",
                json!(["G21", "G92"]),
                "`start[1]`",
                "other coordinates",
            ),
        ] {
            let e = with(field, value.clone()).unwrap_err();
            assert!(e.contains(named) && e.contains(says), "{value}: {e}");
        }
        // What controllers write and the built-in profiles use stays
        // fine: comments of each form, a valve's M-codes with S and P
        // words, a dwell alone, an output set, a cancelled offset or feed
        // mode, Marlin's firmware retraction.
        for (field, value) in [
            ("comment", json!({"prefix": ";"})),
            ("comment", json!({"prefix": "(", "suffix": ")"})),
            ("comment", json!({"prefix": "'"})),
            ("comment", json!({"prefix": "//"})),
            ("dispense_on", json!(["M42 P4 S255", "G4 P{safe_z}"])),
            ("dispense_on", json!(["$DO[0].X = 1"])),
            ("dispense_on", json!(["SET_PIN PIN=valve VALUE=1"])),
            (
                "dispense_on",
                json!(["M150 R255 U0 B0", "M260 A66 B1 S1", "M106"]),
            ),
            ("dwell", json!("G4 S{s}")),
            ("dwell", json!("DWELL {s}")),
            ("dwell", json!("M400 G4 P{ms} ; wait")),
            ("start", json!(["G21", "G93", "G94", "G90"])),
            ("start", json!(["G21", "G43 H1", "G49", "G10"])),
            ("start", json!(["G21", "G90", "M82", "G92 E0"])),
        ] {
            assert_eq!(with(field, value.clone()), Ok(()), "{value}");
        }
        // A key written twice is named, nested ones by their path.
        let twice = |text: &str| {
            MachineProfile::from_json(text, "dup.json")
                .unwrap_err()
                .to_string()
        };
        let text = marlin_json().to_string();
        let e = twice(&text.replacen("\"decimals\"", "\"decimals\":4,\"decimals\"", 1));
        assert!(
            e.contains("dup.json, field `decimals`: appears twice"),
            "{e}"
        );
        let e = twice(&text.replacen("\"prefix\"", "\"prefix\":\"(\",\"prefix\"", 1));
        assert!(e.contains("field `comment.prefix`: appears twice"), "{e}");
        // A profile saved with a byte-order mark reads as without.
        let text = format!("\u{feff}{}", marlin_json());
        assert_eq!(
            MachineProfile::from_json(&text, "bom.json").unwrap(),
            MachineProfile::from_json(&marlin_json().to_string(), "plain.json").unwrap()
        );
    }

    #[test]
    fn validation_errors_name_file_and_field() {
        let e = load_err(|m| {
            m.insert("decimals".into(), 9.into());
        });
        assert!(e.contains("`decimals`") && e.contains("3 to 6"), "{e}");
        let e = load_err(|m| {
            m.insert("decimals".into(), 2.into());
        });
        assert!(e.contains("`decimals`"), "{e}");
        let e = load_err(|m| {
            m.insert("safe_travel_clearance_mm".into(), (-1.0).into());
        });
        assert!(e.contains("`safe_travel_clearance_mm`"), "{e}");
        let e = load_err(|m| {
            m.insert(
                "build_volume".into(),
                serde_json::json!({ "min_mm": [0, 0, 10], "max_mm": [100, 100, 10] }),
            );
        });
        assert!(e.contains("`build_volume`") && e.contains("below"), "{e}");
        let e = load_err(|m| {
            m.insert(
                "build_volume".into(),
                serde_json::json!({ "min_mm": [0, 0, 0], "max_mm": [1e300, 100, 10] }),
            );
        });
        assert!(e.contains("`build_volume`") && e.contains("within"), "{e}");
        let e = load_err(|m| {
            m.insert("feed_units".into(), "mm_per_hour".into());
        });
        assert!(
            e.contains("`feed_units`") && e.contains("mm_per_hour"),
            "{e}"
        );
        let e = load_err(|m| {
            m.insert("travel_feed_mm_s".into(), 0.0.into());
        });
        assert!(e.contains("`travel_feed_mm_s`"), "{e}");
        let e = load_err(|m| {
            m.insert("dispense_on".into(), serde_json::json!([]));
        });
        assert!(e.contains("`dispense_on`"), "{e}");
        let e = load_err(|m| {
            m.insert("comment".into(), serde_json::json!({ "prefix": "" }));
        });
        assert!(e.contains("`comment.prefix`"), "{e}");
        let e = load_err(|m| {
            m.insert("start".into(), serde_json::json!(["G21\nM3"]));
        });
        assert!(e.contains("`start[0]`") && e.contains("one line"), "{e}");
    }

    #[test]
    fn type_errors_and_unknown_or_missing_fields_name_the_field() {
        let e = load_err(|m| {
            m.insert("decimals".into(), "three".into());
        });
        assert!(
            e.contains("`decimals`") && e.contains("invalid type"),
            "{e}"
        );
        let e = load_err(|m| {
            m.insert("decimals".into(), (-1).into());
        });
        assert!(e.contains("`decimals`"), "{e}");
        let e = load_err(|m| {
            m.insert("safe_clearance".into(), 5.into());
        });
        assert!(
            e.contains("`safe_clearance`") && e.contains("not a profile field"),
            "{e}"
        );
        let e = load_err(|m| {
            m.remove("dwell");
        });
        assert!(e.contains("`dwell`") && e.contains("missing"), "{e}");
        let e = load_err(|m| {
            m.insert(
                "comment".into(),
                serde_json::json!({ "prefix": ";", "sufix": "" }),
            );
        });
        assert!(e.contains("`comment`") && e.contains("sufix"), "{e}");
    }

    #[test]
    fn unknown_template_tokens_fail_at_load_time() {
        let e = load_err(|m| {
            m.insert("dwell".into(), "G4 P{msec}".into());
        });
        assert!(e.contains("{msec}") && e.contains("`dwell`"), "{e}");
        assert!(e.contains("{ms}"), "the error lists the known tokens: {e}");
        // {ms} is a dwell token, not a block token.
        let e = load_err(|m| {
            m.insert(
                "dispense_on".into(),
                serde_json::json!(["M106 S255", "G4 P{ms}"]),
            );
        });
        assert!(e.contains("{ms}") && e.contains("`dispense_on[1]`"), "{e}");
        let e = load_err(|m| {
            m.insert("end".into(), serde_json::json!(["G0 Z{safe_z"]));
        });
        assert!(
            e.contains("`end[0]`") && e.contains("without a matching"),
            "{e}"
        );
        // Known tokens and escaped braces load.
        let mut v = marlin_json();
        let map = v.as_object_mut().unwrap();
        map.insert(
            "end".into(),
            serde_json::json!(["G0 Z{safe_z} F{travel_f}", "M117 {{done}}"]),
        );
        assert!(load(&v).is_ok());
    }

    #[test]
    fn hostile_json_is_an_error_not_a_panic() {
        for text in [
            "",
            "null",
            "[]",
            "{",
            "{\"name\": 1e999}",
            "\u{0}",
            "{\"name\": \"x\", \"name\": \"y\"}",
            &"[".repeat(10_000),
        ] {
            let e = MachineProfile::from_json(text, "evil.json").unwrap_err();
            assert!(e.to_string().contains("evil.json"), "{e}");
        }
    }

    #[test]
    fn volume_contains_its_faces() {
        let v = BuildVolume {
            min_mm: DVec3::ZERO,
            max_mm: DVec3::splat(10.0),
        };
        assert!(v.contains(DVec3::ZERO));
        assert!(v.contains(DVec3::splat(10.0)));
        // A hair past a face is on it (the G-code's resolution), more is out.
        assert!(v.contains(DVec3::new(5.0, 10.0009, 5.0)));
        assert!(v.contains(DVec3::new(-0.0009, 5.0, 5.0)));
        assert!(!v.contains(DVec3::new(5.0, 10.0011, 5.0)));
        assert!(!v.contains(DVec3::new(-0.0011, 5.0, 5.0)));
        assert_eq!(
            v.snap(DVec3::new(-0.0009, 10.0009, 5.0)),
            DVec3::new(0.0, 10.0, 5.0)
        );
        assert_eq!(
            v.snap(DVec3::new(-0.5, 5.0, 5.0)),
            DVec3::new(-0.5, 5.0, 5.0)
        );
        assert!(!v.contains(DVec3::new(f64::NAN, 5.0, 5.0)));
        assert_eq!(v.to_string(), "x 0..10, y 0..10, z 0..10 mm");
    }
}
