//! The print preview (the page's time slider over a G-code program): the
//! program's straight moves on a timeline at its own feed rates, where the
//! nozzle is at any moment and which move and G-code line it is on, the
//! move nearest a clicked point, and the colour class of every move: by its
//! clearance (the motion check's [`Clearance::gap`], spec section 6f) or by
//! the predicted defect of the planned point it prints (spec section 7).
//!
//! Length: about 800 lines, a third of them tests.
//!
//! It also holds what the page draws of a plan ([`PlanArrays`]): the
//! per-point arrays, built here so that the wasm bindings only convert them.
//!
//! Times are the motion a controller is told to make: every move at its
//! feed (`F`, modal, in the profile's units; `G0` at the profile's travel
//! feed, since a controller's own rapid rate is in no file) plus the
//! profile's dwell lines; acceleration is not modelled, so a real run takes
//! a little longer on short moves.

use glam::DVec3;

use crate::gcode::{numbered_lines, FeedUnits, GcodeMove, MachineProfile};
use crate::motion::Clearance;
use crate::pipeline::Plan;
use crate::quality::Defect;
use crate::surface::Surface;

/// Clearances are found up to tol plus this (mm): far enough to show how
/// high a print move runs above the surface (about d), near enough that the
/// check visits few triangles for travel at the safe height.
pub const PREVIEW_CLEARANCE_CAP_ABOVE_TOL_MM: f64 = 1.0;

/// A move is "near" when its clearance is below tol plus this (mm): within
/// one default tol of touching.
pub const DEFAULT_NEAR_MM: f64 = 0.1;

/// Gaps this close below tol count as tol, as in the motion check.
const TIE_MM: f64 = 1e-9;

/// How long moves take when the text alone does not say.
#[derive(Debug, Clone, PartialEq)]
pub struct FeedRules {
    /// Speed of `G1` moves before the program sets a feed: the job's print
    /// speed.
    pub print_speed_mm_s: f64,
    /// Speed of `G0` moves: the profile's travel feed.
    pub travel_speed_mm_s: f64,
    /// The unit of `F` words.
    pub feed_units: FeedUnits,
    /// The profile's dwell line, read back.
    pub dwell: Option<DwellWord>,
}

impl FeedRules {
    /// The rules of `profile` (its feed units, travel feed and dwell line)
    /// with `print_speed_mm_s` until the program sets a feed.
    pub fn of_profile(profile: &MachineProfile, print_speed_mm_s: f64) -> FeedRules {
        FeedRules {
            print_speed_mm_s,
            travel_speed_mm_s: profile.travel_feed_mm_s,
            feed_units: profile.feed_units,
            dwell: DwellWord::of_template(&profile.dwell),
        }
    }

    fn feed_mm_s(&self, f: f64) -> f64 {
        match self.feed_units {
            FeedUnits::MmPerMin => f / 60.0,
            FeedUnits::MmPerS => f,
        }
    }
}

/// A profile's dwell line (`G4 P{ms}`, `DWELL {s}`, `G4 P{s}`) as a prefix
/// and the seconds one unit of its number stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct DwellWord {
    /// The text before the token, upper case, without spaces.
    prefix: String,
    seconds_per_unit: f64,
}

impl DwellWord {
    /// The dwell line of a profile's template, or `None` when its first
    /// token is neither `{ms}` nor `{s}`.
    pub fn of_template(template: &str) -> Option<DwellWord> {
        let (prefix, rest) = template.split_once('{')?;
        let seconds_per_unit = if rest.starts_with("ms}") {
            1e-3
        } else if rest.starts_with("s}") {
            1.0
        } else {
            return None;
        };
        let prefix = squeeze(prefix);
        (!prefix.is_empty()).then_some(DwellWord {
            prefix,
            seconds_per_unit,
        })
    }

    /// The seconds a line dwells, if it is this dwell line.
    pub fn seconds(&self, line: &str) -> Option<f64> {
        let code = squeeze(strip_comment(line));
        let number = code.strip_prefix(&self.prefix)?;
        let end = number
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
            .unwrap_or(number.len());
        let v: f64 = number[..end].parse().ok()?;
        (v.is_finite() && v >= 0.0).then_some(v * self.seconds_per_unit)
    }
}

/// Upper case without white space.
fn squeeze(s: &str) -> String {
    s.chars()
        .filter(|c| !c.is_whitespace())
        .flat_map(char::to_uppercase)
        .collect()
}

/// A line without its comments: `;` or `'` to the end, `( )` inside.
fn strip_comment(line: &str) -> &str {
    let end = line.find([';', '\'', '(']).unwrap_or(line.len());
    &line[..end]
}

/// One move on the timeline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedMove {
    /// The G-code line (1-based) that commands it.
    pub line: usize,
    pub from: DVec3,
    pub to: DVec3,
    /// `G0` rather than `G1`.
    pub rapid: bool,
    /// When it starts (after any dwell before it), s from the program's start.
    pub start_s: f64,
    /// How long it takes, s.
    pub duration_s: f64,
}

impl TimedMove {
    fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

/// Times the `moves` of a program (from [`crate::gcode::read_gcode`] of
/// `text`, in file order): each at its modal feed (the reader's
/// [`GcodeMove::feed`], the print speed before the program sets one),
/// `G0` at the travel feed, after the dwells written since the previous
/// move.
pub fn time_moves(text: &str, moves: &[GcodeMove], rules: &FeedRules) -> Vec<TimedMove> {
    let mut out = Vec::with_capacity(moves.len());
    let mut lines = numbered_lines(text).peekable();
    let travel = positive(rules.travel_speed_mm_s);
    let mut clock = 0.0;
    for m in moves {
        // Dwells on every line up to and including the move's own.
        while let Some(&(n, line)) = lines.peek() {
            if n > m.line {
                break;
            }
            lines.next();
            if let Some(s) = rules.dwell.as_ref().and_then(|d| d.seconds(line)) {
                clock += s;
            }
        }
        let speed = if m.rapid {
            travel
        } else {
            positive(
                m.feed
                    .map_or(rules.print_speed_mm_s, |f| rules.feed_mm_s(f)),
            )
        };
        let length = (m.to - m.from).length();
        let duration_s = match speed {
            Some(v) if length.is_finite() => length / v,
            _ => 0.0,
        };
        out.push(TimedMove {
            line: m.line,
            from: m.from,
            to: m.to,
            rapid: m.rapid,
            start_s: clock,
            duration_s,
        });
        clock += duration_s;
    }
    out
}

fn positive(v: f64) -> Option<f64> {
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Where the nozzle is at a moment of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cursor {
    /// The move (index into the timeline's moves) and its G-code line.
    pub index: usize,
    pub line: usize,
    /// How far along that move, 0 to 1.
    pub fraction: f64,
    /// The tip's position.
    pub position: DVec3,
}

/// A point of the path picked by a ray (a click in the view).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pick {
    pub index: usize,
    pub fraction: f64,
    /// The moment the nozzle passes there.
    pub time_s: f64,
    /// The ray's distance from the path there, mm.
    pub distance_mm: f64,
}

/// A program's moves against time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timeline {
    moves: Vec<TimedMove>,
    total_s: f64,
}

impl Timeline {
    /// The timeline of `moves` as timed (start times nondecreasing, as
    /// [`time_moves`] makes them; negative or non-finite durations count
    /// as 0).
    pub fn new(mut moves: Vec<TimedMove>) -> Timeline {
        let mut clock: f64 = 0.0;
        for m in &mut moves {
            if !(m.duration_s.is_finite() && m.duration_s >= 0.0) {
                m.duration_s = 0.0;
            }
            m.start_s = if m.start_s.is_finite() {
                m.start_s.max(clock)
            } else {
                clock
            };
            clock = m.end_s();
        }
        Timeline {
            moves,
            total_s: clock,
        }
    }

    pub fn moves(&self) -> &[TimedMove] {
        &self.moves
    }

    /// The program's time, s (its last move's end).
    pub fn total_s(&self) -> f64 {
        self.total_s
    }

    /// Where the nozzle is at `t_s` (clamped to the program): on the move
    /// under way, or at the end of the last one during a dwell. `None` for
    /// a program without moves.
    pub fn at(&self, t_s: f64) -> Option<Cursor> {
        let t = if t_s.is_nan() {
            0.0
        } else {
            t_s.clamp(0.0, self.total_s)
        };
        // The last move started by t (the first if none).
        let index = self
            .moves
            .partition_point(|m| m.start_s <= t)
            .saturating_sub(1);
        let m = self.moves.get(index)?;
        // At or past its end the move's end exactly (no rounding off it).
        let (fraction, position) = if m.duration_s > 0.0 && t < m.end_s() {
            let f = ((t - m.start_s) / m.duration_s).clamp(0.0, 1.0);
            (f, m.from.lerp(m.to, f))
        } else {
            (1.0, m.to)
        };
        Some(Cursor {
            index,
            line: m.line,
            fraction,
            position,
        })
    }

    /// The moment the nozzle is `fraction` along move `index`.
    pub fn time_of(&self, index: usize, fraction: f64) -> Option<f64> {
        let m = self.moves.get(index)?;
        Some(m.start_s + fraction.clamp(0.0, 1.0) * m.duration_s)
    }

    /// The point of the path nearest the ray from `origin` along
    /// `direction` (as the view's ray through a clicked pixel), judged by
    /// the angle under which the ray misses it (so a near move and a far
    /// one are judged as on screen); `None` when every move is missed by
    /// more than `max_angle_rad` or lies behind the origin.
    pub fn nearest_to_ray(
        &self,
        origin: DVec3,
        direction: DVec3,
        max_angle_rad: f64,
    ) -> Option<Pick> {
        let d = direction.normalize_or_zero();
        if d == DVec3::ZERO || !origin.is_finite() {
            return None;
        }
        let mut best: Option<(f64, Pick)> = None;
        for (index, m) in self.moves.iter().enumerate() {
            let (s, p) = closest_on_segment_to_line(m.from, m.to, origin, d);
            let along = (p - origin).dot(d);
            if along.is_nan() || along <= 0.0 {
                continue;
            }
            let distance_mm = (p - origin - along * d).length();
            let angle = (distance_mm / along).atan();
            if angle > max_angle_rad || best.as_ref().is_some_and(|(a, _)| *a <= angle) {
                continue;
            }
            best = Some((
                angle,
                Pick {
                    index,
                    fraction: s,
                    time_s: m.start_s + s * m.duration_s,
                    distance_mm,
                },
            ));
        }
        best.map(|(_, p)| p)
    }
}

/// The point of the segment `a`-`b` nearest the line through `o` along the
/// unit vector `d`: its parameter on the segment (0 to 1) and the point.
fn closest_on_segment_to_line(a: DVec3, b: DVec3, o: DVec3, d: DVec3) -> (f64, DVec3) {
    let u = b - a;
    let w = a - o;
    // Minimise |w + s u - t d|^2 over t, then s: the part of u across d.
    let uu = u.dot(u);
    let ud = u.dot(d);
    let denom = uu - ud * ud;
    let s = if uu <= 0.0 {
        0.0
    } else if denom <= 1e-12 * uu {
        // Parallel: any point; take the one nearest the origin's foot.
        (-(w.dot(u)) / uu).clamp(0.0, 1.0)
    } else {
        ((w.dot(d) * ud - w.dot(u)) / denom).clamp(0.0, 1.0)
    };
    (s, a + s * u)
}

/// How close a move comes to the surface, as the preview colours it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClearanceClass {
    /// At least tol + near all along.
    Clear,
    /// Between tol and tol + near somewhere.
    Near,
    /// Closer than tol: the motion check refuses it.
    Touching,
}

impl ClearanceClass {
    /// The class of a clearance (`None`: at least the cap it was found to,
    /// which is at least tol + `near_mm`).
    pub fn of(gap_mm: Option<f64>, tol_mm: f64, near_mm: f64) -> ClearanceClass {
        match gap_mm {
            Some(g) if g < tol_mm - TIE_MM => ClearanceClass::Touching,
            Some(g) if g < tol_mm + near_mm => ClearanceClass::Near,
            _ => ClearanceClass::Clear,
        }
    }

    /// The page's code: 0 clear, 1 near, 2 touching.
    pub fn code(self) -> u8 {
        match self {
            ClearanceClass::Clear => 0,
            ClearanceClass::Near => 1,
            ClearanceClass::Touching => 2,
        }
    }
}

/// The clearance of every move along its length ([`Clearance::gap`], the
/// motion check's own test), found up to `cap_mm` (`None` above it).
pub fn move_clearances(
    surface: &Surface,
    moves: &[TimedMove],
    clearance: &Clearance,
    cap_mm: f64,
) -> Vec<Option<f64>> {
    moves
        .iter()
        .map(|m| {
            clearance
                .gap(surface, m.from, m.to, cap_mm)
                .map(|g| g.gap_mm)
        })
        .collect()
}

/// The predicted defect each move prints: for a `G1` move, that of the
/// planned point nearest its middle within `radius_mm` (a print move runs
/// between planned points or waypoints beside them); `None` for rapids and
/// for moves far from every planned point (descents, lifts). `points` and
/// `defects` are the plan's tool-path points and their defects, in any
/// order.
pub fn move_defects(
    moves: &[TimedMove],
    points: &[DVec3],
    defects: &[Defect],
    radius_mm: f64,
) -> Vec<Option<Defect>> {
    let cell = if radius_mm.is_finite() && radius_mm > 0.0 {
        radius_mm
    } else {
        return vec![None; moves.len()];
    };
    let key = |p: DVec3| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (i, p) in points.iter().enumerate().take(defects.len()) {
        if p.is_finite() {
            grid.entry(key(*p)).or_default().push(i);
        }
    }
    moves
        .iter()
        .map(|m| {
            if m.rapid {
                return None;
            }
            let mid = m.from.lerp(m.to, 0.5);
            if !mid.is_finite() {
                return None;
            }
            let (cx, cy) = key(mid);
            let mut best: Option<(f64, usize)> = None;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for &i in grid.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                        let d = points[i].distance(mid);
                        if d <= radius_mm && best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, i));
                        }
                    }
                }
            }
            best.map(|(_, i)| defects[i])
        })
        .collect()
}

/// The page's code for a defect (the view's and the plot's colour index).
pub fn defect_code(d: Defect) -> u8 {
    match d {
        Defect::Good => 0,
        Defect::Contact => 1,
        Defect::Flattening => 2,
        Defect::Floating => 3,
    }
}

/// The defect of a code of [`defect_code`] (unknown codes are good).
pub fn defect_of_code(code: u8) -> Defect {
    match code {
        1 => Defect::Contact,
        2 => Defect::Flattening,
        3 => Defect::Floating,
        _ => Defect::Good,
    }
}

/// A plan's per-point arrays for the view and the plot, without the JSON
/// report: points per piece, Ta and T* (xyz, printer frame), the defect
/// code ([`defect_code`]), slope (deg), profile curvature kappa (1/mm) and
/// error (mm, NaN where no filament estimate exists) of every point.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlanArrays {
    pub pieces: Vec<u32>,
    pub ta: Vec<f32>,
    pub tool: Vec<f32>,
    pub defects: Vec<u8>,
    pub slope_deg: Vec<f32>,
    pub kappa: Vec<f32>,
    pub error_mm: Vec<f32>,
}

fn xyz32(v: &DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

impl PlanArrays {
    pub fn of(plan: &Plan) -> PlanArrays {
        let n: usize = plan.pieces.iter().map(|p| p.toolpath.len()).sum();
        let mut a = PlanArrays {
            pieces: Vec::with_capacity(plan.pieces.len()),
            ta: Vec::with_capacity(3 * n),
            tool: Vec::with_capacity(3 * n),
            defects: Vec::with_capacity(n),
            slope_deg: Vec::with_capacity(n),
            kappa: Vec::with_capacity(n),
            error_mm: Vec::with_capacity(n),
        };
        for p in &plan.pieces {
            a.pieces.push(p.toolpath.len() as u32);
            a.ta.extend(p.surface_path.iter().flat_map(xyz32));
            a.tool.extend(p.toolpath.iter().flat_map(xyz32));
            for (g, q) in p.geometry.iter().zip(&p.quality) {
                a.defects.push(defect_code(q.defect));
                a.slope_deg.push(g.slope_rad.to_degrees() as f32);
                a.kappa.push(g.kappa as f32);
                a.error_mm.push(q.error_mm.map_or(f32::NAN, |e| e as f32));
            }
        }
        a
    }
}

/// One planner's per-point errors and defect codes, in the order of
/// [`PlanArrays`] (the planners share the surface path, so its slope and
/// curvature hold for every planner): the plot draws them side by side.
pub fn plan_errors(plan: &Plan) -> (Vec<f32>, Vec<u8>) {
    plan.pieces
        .iter()
        .flat_map(|p| &p.quality)
        .map(|q| {
            (
                q.error_mm.map_or(f32::NAN, |e| e as f32),
                defect_code(q.defect),
            )
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::read_gcode;
    use crate::motion::tests::step;
    use crate::params::Nozzle;

    fn marlin_rules() -> FeedRules {
        let p = MachineProfile::builtin("marlin").unwrap();
        FeedRules::of_profile(&p, 5.0)
    }

    fn timeline(text: &str, rules: &FeedRules) -> Timeline {
        let program = read_gcode(text, "t.gcode").unwrap();
        Timeline::new(time_moves(text, &program.moves, rules))
    }

    const PROGRAM: &str = "G21 G90\nG0 X0 Y0 Z5 F6000\nG1 Z0 F600\n; print\nM106 S255\n\
                           G4 P500\nG1 X10 F300\nG1 X10 Y5\nG4 P250\nG0 Z5 F6000\n";

    #[test]
    fn moves_take_their_feed_and_dwells_pause() {
        let t = timeline(PROGRAM, &marlin_rules());
        let m = t.moves();
        // The first G0 has no known start: the reader leaves it out.
        assert_eq!(
            m.iter().map(|m| m.line).collect::<Vec<_>>(),
            vec![3, 7, 8, 10]
        );
        // Z5 -> Z0 at F600 (10 mm/s): 0.5 s.
        assert!((m[0].duration_s - 0.5).abs() < 1e-12);
        // Dwell 0.5 s, then 10 mm at F300 (5 mm/s): 2 s, then 5 mm: 1 s.
        assert!((m[1].start_s - 1.0).abs() < 1e-12);
        assert!((m[1].duration_s - 2.0).abs() < 1e-12);
        assert!((m[2].duration_s - 1.0).abs() < 1e-12);
        // Dwell 0.25 s; G0 at the profile's travel feed, not the file's F.
        let travel = MachineProfile::builtin("marlin").unwrap().travel_feed_mm_s;
        assert!((m[3].start_s - 4.25).abs() < 1e-12);
        assert!((m[3].duration_s - 5.0 / travel).abs() < 1e-12);
        assert!((t.total_s() - (4.25 + 5.0 / travel)).abs() < 1e-12);
    }

    #[test]
    fn the_cursor_interpolates_and_names_the_line() {
        let t = timeline(PROGRAM, &marlin_rules());
        // Half-way along the first print move (1 s to 3 s).
        let c = t.at(2.0).unwrap();
        assert_eq!((c.index, c.line), (1, 7));
        assert!((c.fraction - 0.5).abs() < 1e-12);
        assert!(c.position.distance(DVec3::new(5.0, 0.0, 0.0)) < 1e-12);
        // During the first dwell the nozzle waits at the end of the descent.
        let c = t.at(0.75).unwrap();
        assert_eq!(c.line, 3);
        assert_eq!(c.position, DVec3::ZERO);
        // Clamped at both ends; NaN is the start.
        assert_eq!(t.at(-1.0).unwrap().position, DVec3::new(0.0, 0.0, 5.0));
        assert_eq!(t.at(f64::NAN).unwrap().index, 0);
        let end = t.at(1e9).unwrap();
        assert_eq!((end.line, end.position), (10, DVec3::new(10.0, 5.0, 5.0)));
        assert_eq!(t.time_of(1, 0.5), Some(2.0));
        assert!(Timeline::default().at(0.0).is_none());
    }

    #[test]
    fn feeds_in_mm_per_s_and_dwell_in_seconds() {
        let p = MachineProfile::builtin("aerotech").unwrap();
        let rules = FeedRules::of_profile(&p, 1.0);
        let text = "G71 G76 G90\nG0 X0 Y0 Z1\nG1 X4 F2 ' two mm/s\nDWELL 1.5\nG1 X8\n";
        let t = timeline(text, &rules);
        let m = t.moves();
        assert_eq!(m.len(), 2);
        assert!((m[0].duration_s - 2.0).abs() < 1e-12);
        assert!((m[1].start_s - 3.5).abs() < 1e-12);
    }

    #[test]
    fn dwell_lines_are_read_past_comments_and_case() {
        let ms = DwellWord::of_template("G4 P{ms}").unwrap();
        assert_eq!(ms.seconds("G4 P250"), Some(0.25));
        assert_eq!(ms.seconds("g4 p1000 ; wait"), Some(1.0));
        assert_eq!(ms.seconds("G1 X1"), None);
        assert_eq!(DwellWord::of_template("{ms}"), None);
        assert_eq!(DwellWord::of_template("G4 P{x}"), None);
    }

    /// An `F` under `G20` is inches a minute: one inch at 60 in/min takes
    /// a second (read as mm it took 25.4).
    #[test]
    fn feeds_under_g20_are_inches() {
        let t = timeline("G20 G90\nG0 X0 Y0 Z0\nG1 X1 F60\n", &marlin_rules());
        // (The G0 starts nowhere known: the G1 is the one move.)
        let m = t.moves();
        assert_eq!(m.len(), 1);
        assert!((m[0].duration_s - 1.0).abs() < 1e-9, "{:?}", m[0]);
    }

    #[test]
    fn a_click_picks_the_move_under_the_ray() {
        let t = timeline(PROGRAM, &marlin_rules());
        // Looking straight down at (7, 0): the print move along x, at 7/10.
        let p = t
            .nearest_to_ray(DVec3::new(7.0, 0.05, 50.0), -DVec3::Z, 0.01)
            .unwrap();
        assert_eq!(p.index, 1);
        assert!((p.fraction - 0.7).abs() < 1e-9);
        assert!((p.time_s - 2.4).abs() < 1e-9);
        assert!((p.distance_mm - 0.05).abs() < 1e-9);
        // Far off, or looking away: nothing.
        assert!(t
            .nearest_to_ray(DVec3::new(40.0, 40.0, 50.0), -DVec3::Z, 0.01)
            .is_none());
        assert!(t
            .nearest_to_ray(DVec3::new(7.0, 0.0, 50.0), DVec3::Z, 0.5)
            .is_none());
        assert!(t.nearest_to_ray(DVec3::ZERO, DVec3::ZERO, 1.0).is_none());
    }

    #[test]
    fn moves_are_classed_by_the_motion_checks_clearance() {
        let s = step();
        let c = Clearance::new(&Nozzle::DEFAULT, 0.1);
        let mv = |a: DVec3, b: DVec3| TimedMove {
            line: 1,
            from: a,
            to: b,
            rapid: false,
            start_s: 0.0,
            duration_s: 1.0,
        };
        let moves = [
            // High above: clear past the cap.
            mv(DVec3::new(1.0, 5.0, 5.0), DVec3::new(9.0, 5.0, 5.0)),
            // 0.15 mm over the low floor: near.
            mv(DVec3::new(1.0, 5.0, 0.15), DVec3::new(2.0, 5.0, 0.15)),
            // Into the wall: touching.
            mv(DVec3::new(3.0, 5.0, 0.5), DVec3::new(7.0, 5.0, 0.5)),
        ];
        let cap = 0.1 + PREVIEW_CLEARANCE_CAP_ABOVE_TOL_MM;
        let gaps = move_clearances(&s, &moves, &c, cap);
        assert_eq!(gaps[0], None);
        assert!((gaps[1].unwrap() - 0.15).abs() < 1e-9, "{gaps:?}");
        assert!(gaps[2].unwrap() < 0.0);
        let classes: Vec<_> = gaps
            .iter()
            .map(|&g| ClearanceClass::of(g, 0.1, DEFAULT_NEAR_MM))
            .collect();
        assert_eq!(
            classes,
            [
                ClearanceClass::Clear,
                ClearanceClass::Near,
                ClearanceClass::Touching
            ]
        );
        // The same moves as the motion check sees them.
        for (m, g) in moves.iter().zip(&gaps) {
            assert_eq!(
                c.is_clear(&s, m.from, m.to),
                !matches!(g, Some(g) if *g < 0.1)
            );
        }
        assert_eq!(ClearanceClass::of(Some(0.1), 0.1, 0.1).code(), 1);
        assert_eq!(ClearanceClass::of(Some(0.2), 0.1, 0.1).code(), 0);
    }

    #[test]
    fn print_moves_take_the_defect_of_the_planned_point_beside_them() {
        let mv = |a: DVec3, b: DVec3, rapid| TimedMove {
            line: 1,
            from: a,
            to: b,
            rapid,
            start_s: 0.0,
            duration_s: 1.0,
        };
        let points: Vec<DVec3> = (0..5).map(|i| DVec3::new(i as f64, 0.0, 1.0)).collect();
        let defects = [
            Defect::Good,
            Defect::Good,
            Defect::Floating,
            Defect::Flattening,
            Defect::Good,
        ];
        let moves = [
            // The descent onto the first point, from 10 mm up.
            mv(DVec3::new(0.0, 0.0, 11.0), DVec3::new(0.0, 0.0, 1.0), false),
            mv(points[1], points[2], false),
            mv(points[2], points[3], false),
            // A waypoint move beside point 3.
            mv(points[3], DVec3::new(3.1, 0.0, 1.2), false),
            mv(DVec3::new(0.0, 0.0, 11.0), DVec3::new(4.0, 0.0, 11.0), true),
        ];
        let got = move_defects(&moves, &points, &defects, 0.908);
        assert_eq!(
            got,
            vec![
                None,
                // The middle is as near points 1 and 2: the first found.
                got[1],
                got[2],
                Some(Defect::Flattening),
                None
            ]
        );
        assert!(matches!(got[1], Some(Defect::Good | Defect::Floating)));
        assert!(matches!(
            got[2],
            Some(Defect::Floating | Defect::Flattening)
        ));
        assert_eq!(move_defects(&moves, &points, &defects, 0.0), vec![None; 5]);
        for d in [
            Defect::Good,
            Defect::Contact,
            Defect::Flattening,
            Defect::Floating,
        ] {
            assert_eq!(defect_of_code(defect_code(d)), d);
        }
    }
}
