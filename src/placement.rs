//! Placement: where an unregistered scan and the drawing go in the printer
//! frame (spec section 1 for the scan, section 4's decision "the user places
//! the SVG in printer XY" for the drawing).
//!
//! A scan straight from a scanner is in the scanner's frame, often far from
//! the stage's build volume (a structured-light head puts it hundreds of mm
//! away). Until the user registers it by its fiducials, the planner can put
//! it on the bed: lowest point on the bed, footprint centred on it,
//! orientation kept (the up axis is the import's choice), then moved and
//! turned by hand. [`volume_fit`] says where a scan lies against a build
//! volume, so the page and the CLI can offer that before anything fails.
//!
//! A new drawing, or a drawing on a new scan, is centred on the scan's
//! footprint and scaled down (with a note) when it does not fit:
//! [`centre_drawing`], or on the surface near that middle when it lies
//! over a gap ([`centre_on_surface`]); when the scan is moved on the bed
//! by hand, the drawing goes with it: [`carry_drawing`].

use glam::{DMat4, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::gcode::{BuildVolume, MachineProfile};
use crate::mesh::ScanUnits;
use crate::surface::Surface;
use crate::svg::{Placement, Subpath2};

/// The bed of a machine: the middle of its build volume in XY, at z = 0
/// where the volume holds it (the work zero a user touches off on the
/// bed; QA round 19 F13: on Grbl's volume, z -100 to 100, the scan went
/// to z -100 and the nozzle 89 mm into a bed touched off at 0), else at
/// its lowest z.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bed {
    pub centre_mm: DVec2,
    pub z_mm: f64,
}

impl Bed {
    pub fn of(volume: &BuildVolume) -> Bed {
        Bed {
            centre_mm: 0.5 * (volume.min_mm + volume.max_mm).truncate(),
            z_mm: if (volume.min_mm.z..=volume.max_mm.z).contains(&0.0) {
                0.0
            } else {
                volume.min_mm.z
            },
        }
    }

    pub fn of_profile(profile: &MachineProfile) -> Bed {
        Bed::of(&profile.build_volume)
    }
}

/// How an unregistered scan is put in the printer frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "mode")]
pub enum ScanPlacement {
    /// As the file gives it: the scan is taken to be in the printer frame.
    #[default]
    AsScanned,
    /// Lowest point on the bed, the footprint's middle on the bed's
    /// middle, then turned by `rotation_deg` (counter-clockwise about z,
    /// around the footprint's middle) and moved by `offset_mm`.
    OnBed {
        bed: Bed,
        #[serde(default)]
        rotation_deg: f64,
        #[serde(default)]
        offset_mm: DVec3,
    },
}

impl ScanPlacement {
    /// On the bed of `profile`, not turned or moved.
    pub fn on_bed(profile: &MachineProfile) -> ScanPlacement {
        ScanPlacement::OnBed {
            bed: Bed::of_profile(profile),
            rotation_deg: 0.0,
            offset_mm: DVec3::ZERO,
        }
    }

    /// Checks the numbers (finite, within a kilometre).
    pub fn validate(&self) -> crate::Result<()> {
        if let ScanPlacement::OnBed {
            bed,
            rotation_deg,
            offset_mm,
        } = self
        {
            let ok = bed.centre_mm.is_finite()
                && bed.z_mm.is_finite()
                && rotation_deg.is_finite()
                && offset_mm.is_finite()
                && offset_mm.abs().max_element() <= 1e6;
            if !ok {
                return Err(crate::Error::Parameter {
                    name: "scan placement",
                    value: format!("{self:?}"),
                    reason: "the bed, rotation and offset must be finite numbers".into(),
                });
            }
        }
        Ok(())
    }

    /// The rigid transform scanner -> printer for a scan whose bounds (in
    /// the scanner frame, after import) are `bbox`; `None` for
    /// [`ScanPlacement::AsScanned`].
    pub fn transform(&self, bbox: (DVec3, DVec3)) -> Option<DMat4> {
        let ScanPlacement::OnBed {
            bed,
            rotation_deg,
            offset_mm,
        } = self
        else {
            return None;
        };
        let (lo, hi) = bbox;
        let middle = 0.5 * (lo + hi).truncate();
        let to_origin = DMat4::from_translation(DVec3::new(-middle.x, -middle.y, -lo.z));
        let turn = DMat4::from_rotation_z(rotation_deg.to_radians());
        let to_bed = DMat4::from_translation(bed.centre_mm.extend(bed.z_mm) + *offset_mm);
        Some(to_bed * turn * to_origin)
    }
}

/// How a scan was put in the printer frame, for the report, the G-code
/// header and the page.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum RegistrationStatus {
    /// Not registered: taken as it is.
    #[default]
    AsScanned,
    /// Not registered: placed on the bed.
    PlacedOnBed { rotation_deg: f64, offset_mm: DVec3 },
    /// Registered by its fiducials.
    Registered {
        method: crate::registration::RegistrationMethod,
        fiducials: usize,
        rms_mm: f64,
    },
}

impl std::fmt::Display for RegistrationStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RegistrationStatus::AsScanned => {
                f.write_str("unregistered, taken as it is (the scan's frame is the printer's)")
            }
            RegistrationStatus::PlacedOnBed {
                rotation_deg,
                offset_mm,
            } => {
                write!(f, "unregistered, placed on the bed")?;
                if *rotation_deg != 0.0 || *offset_mm != DVec3::ZERO {
                    write!(
                        f,
                        " (turned {rotation_deg} deg, moved ({}, {}, {}) mm)",
                        offset_mm.x, offset_mm.y, offset_mm.z
                    )?;
                }
                Ok(())
            }
            RegistrationStatus::Registered {
                method,
                fiducials,
                rms_mm,
            } => write!(
                f,
                "registered ({}, {fiducials} fiducials, RMS residual {rms_mm:.3} mm)",
                method.name()
            ),
        }
    }
}

/// Where a scan lies against a build volume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VolumeFit {
    /// Whether the whole scan lies inside the volume.
    pub inside: bool,
    /// How far it sticks out beyond the volume on each axis (mm, 0 where it
    /// does not).
    pub outside_by_mm: DVec3,
    /// Whether it would fit after placing it on the bed (its size fits).
    pub fits_on_bed: bool,
    /// One sentence for the user.
    pub message: String,
    /// The sentence for a scan already placed on the bed (whose offset, not
    /// a placement, moved it out).
    pub placed_message: String,
}

/// Where a scan with bounds `bbox` (printer frame), read in `read_in`,
/// lies against `volume` of profile `profile`.
pub fn volume_fit(
    bbox: (DVec3, DVec3),
    volume: &BuildVolume,
    profile: &str,
    read_in: ScanUnits,
) -> VolumeFit {
    let (lo, hi) = bbox;
    let outside = (volume.min_mm - lo)
        .max(hi - volume.max_mm)
        .max(DVec3::ZERO);
    // A hair out is on the face (a registration's rounding).
    let inside = outside.max_element() <= crate::gcode::VOLUME_HAIR_MM;
    let size = hi - lo;
    let fits_on_bed = size.cmple(room(volume)).all();
    let mut placed_message = String::new();
    let message = if inside {
        format!("the scan lies inside the build volume of profile {profile}")
    } else {
        let spans = format!(
            "the scan lies outside the build volume of profile {profile} ({volume}): it spans \
             x {:.1}..{:.1}, y {:.1}..{:.1}, z {:.1}..{:.1} mm, out by up to {:.1} mm",
            lo.x,
            hi.x,
            lo.y,
            hi.y,
            lo.z,
            hi.z,
            outside.max_element(),
        );
        if fits_on_bed {
            placed_message =
                format!("{spans}; move it back inside (--place-scan bed,DX,DY,DZ[,ROT])");
            format!(
                "{spans}; if it is still in the scanner's frame, place it on the bed \
                 (--place-scan bed) or register it by its fiducials"
            )
        } else {
            // Placing it cannot help, on the bed or elsewhere (QA: a scan
            // read in metres, placed on the bed, was told to be moved back
            // inside): name the axis it is too large on.
            let over = Oversize::of(size, room(volume), read_in);
            let larger = format!("{spans}; it is larger than the volume {}", over.axis);
            if read_in == ScanUnits::Mm {
                format!(
                    "{larger}: check the scan's units and up axis, or use a profile whose build \
                     volume holds it (pcpp does not scale a scan: one too large even read in mm, \
                     the smallest unit it reads, must be scaled down in the program that exported \
                     it)"
                )
            } else if over.tiny {
                format!(
                    "{larger}, read in {}; in smaller units it would fit only as a part under \
                     {} mm across: check the scan's up axis, or use a profile whose build volume \
                     holds it",
                    read_in.words(),
                    crate::mesh::SMALL_SCAN_MM
                )
            } else if over.smaller.is_empty() {
                format!(
                    "{larger}, read in {}, and in any smaller units too: check the scan's up \
                     axis, or use a profile whose build volume holds it (pcpp does not scale a \
                     scan: one too large even read in mm must be scaled down in the program that \
                     exported it)",
                    read_in.words()
                )
            } else {
                format!("{larger}{}", over.units_advice(read_in))
            }
        }
    };
    if placed_message.is_empty() {
        placed_message.clone_from(&message);
    }
    VolumeFit {
        inside,
        outside_by_mm: outside,
        fits_on_bed,
        message,
        placed_message,
    }
}

/// The room a part has in `volume`: its extent, up from the bed, where a
/// part stands (QA round 20 F3: a 125 mm scan on Grbl's -100..100 mm was
/// told to move back inside, and the only way, down, sank it into the
/// bed).
fn room(volume: &BuildVolume) -> DVec3 {
    (volume.max_mm - volume.min_mm).with_z(volume.max_mm.z - Bed::of(volume).z_mm)
}

/// How a scan too large for a build volume's room exceeds it, and the
/// smaller units it would fit in ([`volume_fit`], [`units_hint`]).
struct Oversize {
    /// The axis it exceeds most, with its size and the room's:
    /// "(x 1000.0 mm, the volume 220.0 mm)".
    axis: String,
    /// The units smaller than the ones it was read in that it fits in, as
    /// parts a nozzle prints on, with its size in each: "in centimetres it
    /// would be 10.0 x 10.0 x 10.0 mm (--scan-units cm)".
    smaller: Vec<String>,
    /// It fits in some smaller units, but only as a speck in each.
    tiny: bool,
}

impl Oversize {
    /// A scan `size` (mm, read in `read_in`) against a volume's `room`
    /// (its extent, z from its bed).
    fn of(size: DVec3, room: DVec3, read_in: ScanUnits) -> Oversize {
        let over = size - room;
        let (axis, k) = [("x", 0), ("y", 1), ("z", 2)]
            .into_iter()
            .fold(("x", 0), |m, a| if over[a.1] > over[m.1] { a } else { m });
        let axis = format!(
            "({axis} {:.1} mm, the volume {:.1} mm{})",
            size[k],
            room[k],
            if k == 2 { " above its bed" } else { "" }
        );
        // Read in larger units than mm: the smaller ones it fits in
        // (QA round 16 F10: a 2-unit glTF cube read in its metres was
        // told it was too large "even read in mm").
        let fitting: Vec<(ScanUnits, DVec3)> = [ScanUnits::Cm, ScanUnits::In, ScanUnits::Mm]
            .into_iter()
            .filter(|u| u.to_mm() < read_in.to_mm())
            .map(|u| (u, size * (u.to_mm() / read_in.to_mm())))
            .filter(|(_, s)| s.cmple(room).all())
            .collect();
        // Only units in which it is a part to print on (QA round 17
        // F8: a 155 mm bunny given in metres, too tall for a 100 mm
        // volume, was offered 1.6 mm in cm and 0.2 mm in mm, each of
        // which the units check itself calls too small).
        let tiny = !fitting.is_empty()
            && fitting
                .iter()
                .all(|(_, s)| s.max_element() < crate::mesh::SMALL_SCAN_MM);
        let smaller = fitting
            .into_iter()
            .filter(|(_, s)| s.max_element() >= crate::mesh::SMALL_SCAN_MM)
            .map(|(u, s)| {
                format!(
                    "in {} it would be {:.1} x {:.1} x {:.1} mm (--scan-units {u})",
                    u.words(),
                    s.x,
                    s.y,
                    s.z
                )
            })
            .collect();
        Oversize {
            axis,
            smaller,
            tiny,
        }
    }

    /// What follows "larger than the volume (x 1000.0 mm, the volume 220.0
    /// mm)" for a scan the smaller units of [`Oversize::smaller`] mend.
    fn units_advice(&self, read_in: ScanUnits) -> String {
        format!(
            ", read in {}: {}; check the scan's units and up axis, or use a profile whose build \
             volume holds it",
            read_in.words(),
            self.smaller.join(", ")
        )
    }
}

/// The units advice for a scan with bounds `bbox` (printer frame), read in
/// `read_in`, whose size is implausible in those units: it cannot stand
/// on the bed of `volume` (profile `profile`), and in some smaller units
/// it would, as a part a nozzle prints on. The same sentence, on the same
/// test, as [`volume_fit`]'s for such a scan outside the volume; `None`
/// for any other scan. QA round 20 F6: glTF's metres made 1 m parts of
/// 1 mm ones, and only a refusal for the build volume said to check the
/// units; one seen edge-on, or missed by the drawing, did not.
pub fn units_hint(
    bbox: (DVec3, DVec3),
    volume: &BuildVolume,
    profile: &str,
    read_in: ScanUnits,
) -> Option<String> {
    let size = bbox.1 - bbox.0;
    let space = room(volume);
    if read_in == ScanUnits::Mm || size.cmple(space).all() || !size.is_finite() {
        return None;
    }
    let over = Oversize::of(size, space, read_in);
    (!over.smaller.is_empty()).then(|| {
        format!(
            "the scan is larger than the build volume of profile {profile} {}{}",
            over.axis,
            over.units_advice(read_in)
        )
    })
}

/// How much of the footprint a drawing may fill when it is scaled to fit.
pub const FIT_SHARE: f64 = 0.9;

/// A footprint side this small beside the other is not fitted to
/// ([`centre_drawing`]).
pub const FLAT_SIDE_SHARE: f64 = 1e-3;

/// The placement that puts the middle of the drawing's bounding box (as
/// `current` turns and scales it) on the middle of a scan's footprint
/// `footprint` (printer XY). With `fit`, a drawing larger than
/// [`FIT_SHARE`] of the footprint is scaled down to fit, and the note says
/// so; without, its scale is kept (an antenna's size sets its resonance)
/// and the note says when it overhangs the footprint. `None` for a drawing
/// without points.
pub fn centre_drawing(
    drawn: &[Subpath2],
    footprint: (DVec2, DVec2),
    current: &Placement,
    fit: bool,
) -> Option<(Placement, Option<String>)> {
    let turned = Placement {
        offset_mm: DVec2::ZERO,
        ..*current
    };
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in drawn.iter().flat_map(|s| &s.points) {
        let q = turned.apply(*p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let (flo, fhi) = footprint;
    let room = (fhi - flo) * FIT_SHARE;
    let size = hi - lo;
    let mut scale = 1.0;
    for k in 0..2 {
        // A side of the footprint that is nothing beside the other (a scan
        // seen edge-on: a film or plate in a file with another up axis) is
        // not fitted to: the drawing would shrink to a line; planning then
        // says the scan is edge-on.
        let flat = room[k] <= FLAT_SIDE_SHARE * room.max_element();
        if size[k] > room[k] && room[k] > 0.0 && !flat {
            scale = f64::min(scale, room[k] / size[k]);
        }
    }
    let mut placement = turned;
    let mut note = None;
    if scale < 1.0 && fit {
        placement.scale *= scale;
        note = Some(format!(
            "the drawing ({:.1} x {:.1} mm) is larger than {:.0}% of the scan's footprint \
             ({:.1} x {:.1} mm): it was scaled by {} to fit; to choose the scale yourself, give \
             it with the placement (--place centre,ROT,SCALE), which is kept as given",
            size.x,
            size.y,
            FIT_SHARE * 100.0,
            fhi.x - flo.x,
            fhi.y - flo.y,
            crate::error::significant(scale, 3, 3)
        ));
        lo *= scale;
        hi *= scale;
    } else if size.x > fhi.x - flo.x || size.y > fhi.y - flo.y {
        note = Some(format!(
            "the drawing at scale {} ({:.1} x {:.1} mm) is larger than the scan's footprint \
             ({:.1} x {:.1} mm): centred, kept at its scale; what lies off the scan is not \
             printed",
            current.scale,
            size.x,
            size.y,
            fhi.x - flo.x,
            fhi.y - flo.y,
        ));
    }
    placement.offset_mm = 0.5 * (flo + fhi) - 0.5 * (lo + hi);
    Some((placement, note))
}

/// [`centre_drawing`] on a scan's surface: on the middle of its footprint,
/// or, where that middle lies over no surface (a ring-shaped cloud, a
/// C-shaped part) and the drawing centred there lies partly over the gap,
/// where more of its line lies over the surface, with a note saying so
/// (QA round 2 F9: `--place centre` put the drawing in the gap of a
/// ring-shaped cloud, 68 mm from its nearest point, and planning refused
/// it).
///
/// The places tried: a 9 x 9 grid over the footprint, and the surface
/// nearest the middle and on from it, away from the middle, by up to the
/// drawing's size (a narrow band). Each is scored by how many of
/// [`COVER_SAMPLES`] points spread evenly along the drawing's lines lie
/// over the surface; the best wins, the one nearest the middle among
/// equals, and the middle itself unless another covers more (QA round 7
/// F1: scored by the drawing's corners and never kept centred, a 50 mm
/// square was put off a ring it fitted on).
pub fn centre_on_surface(
    drawn: &[Subpath2],
    surface: &Surface,
    current: &Placement,
    fit: bool,
) -> Option<(Placement, Option<String>)> {
    let (placement, note) = centre_on_surface_exact(drawn, surface, current, fit)?;
    Some((as_shown(placement, current.scale), note))
}

/// A placement as the page's fields show it, and so as the CLI plans it
/// (QA round 13 F3: `--place centre` planned at an offset of
/// -0.852996826171875 mm, the page at the -0.853 its field shows, and 63
/// moves differed in the third decimal): the offset to 0.1 um, a fitted
/// scale (one that is not `sent`) to six significant digits. Rounded as
/// JavaScript's `Math.round` and `toPrecision(6)` would.
pub fn as_shown(p: Placement, sent: f64) -> Placement {
    let mm = |v: f64| {
        let x = v * 1e4;
        let mut r = x.round();
        // Math.round takes halves up, Rust's round away from zero.
        if r - x == -0.5 {
            r += 1.0;
        }
        r / 1e4 + 0.0
    };
    let scale = if p.scale.to_bits() == sent.to_bits() {
        p.scale
    } else {
        format!("{:.5e}", p.scale).parse().unwrap_or(p.scale)
    };
    Placement {
        offset_mm: DVec2::new(mm(p.offset_mm.x), mm(p.offset_mm.y)),
        scale,
        ..p
    }
}

fn centre_on_surface_exact(
    drawn: &[Subpath2],
    surface: &Surface,
    current: &Placement,
    fit: bool,
) -> Option<(Placement, Option<String>)> {
    let (lo, hi) = surface.bbox();
    let (flo, fhi) = (lo.truncate(), hi.truncate());
    // Not fitted to a scan seen edge-on, nor said to be larger than its
    // footprint: planning refuses it as such (QA round 20 F6: "scaled by
    // 0.576 to fit" a 20 x 0.0 mm footprint, then the refusal).
    let edge_on = crate::pipeline::edge_on(fhi - flo, hi.z - lo.z);
    let (placement, note) = centre_drawing(drawn, (flo, fhi), current, fit && !edge_on)?;
    let note = note.filter(|_| !edge_on);
    let middle = 0.5 * (flo + fhi);
    if surface.highest_hit(middle).is_some() {
        return Some((placement, note));
    }
    let samples = along_lines(drawn, COVER_SAMPLES);
    let over = |shift: DVec2| {
        let mut at = placement;
        at.offset_mm += shift;
        (samples.iter())
            .filter(|p| surface.highest_hit(at.apply(**p)).is_some())
            .count()
    };
    let (dlo, dhi) = (samples.iter().map(|p| placement.apply(*p)))
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let size = (dhi - dlo).max_element();
    let shifts = tried_middles(surface, size).into_iter().map(|c| c - middle);
    let centred = over(DVec2::ZERO);
    let (mut best, mut best_over) = (DVec2::ZERO, centred);
    for shift in shifts {
        let n = over(shift);
        if n > best_over || (n == best_over && n > centred && shift.length() < best.length()) {
            (best, best_over) = (shift, n);
        }
    }
    if best == DVec2::ZERO {
        return Some((placement, note));
    }
    let centre = middle + best;
    let share = |n: usize| 100.0 * n as f64 / samples.len().max(1) as f64;
    let moved = format!(
        "the middle of the scan's footprint ({:.3}, {:.3}) lies over a gap in the scan: the \
         drawing is centred at ({:.3}, {:.3}) instead, {:.3} mm away, where {:.0}% of its line \
         lies over the scan ({:.0}% centred on the middle); move it where you want it on the \
         scan",
        middle.x,
        middle.y,
        centre.x,
        centre.y,
        best.length(),
        share(best_over),
        share(centred)
    );
    let mut placed = placement;
    placed.offset_mm += best;
    let note = Some(match note {
        Some(n) => format!("{n}; {moved}"),
        None => moved,
    });
    Some((placed, note))
}

/// Where [`centre_on_surface`] tries the middle of a drawing `size` mm
/// across when the middle of the scan's footprint is a gap: at 9 x 9
/// points over the footprint, then (the middle being a gap) from the
/// surface nearest the footprint's middle outwards, a quarter of `size` at
/// a time.
fn tried_middles(surface: &Surface, size: f64) -> Vec<DVec2> {
    let (lo, hi) = surface.bbox();
    let (flo, fhi) = (lo.truncate(), hi.truncate());
    let middle = 0.5 * (flo + fhi);
    let mut at: Vec<DVec2> = (0..9)
        .flat_map(|i| (0..9).map(move |j| DVec2::new(i as f64, j as f64) / 8.0))
        .map(|f| flo + f * (fhi - flo))
        .collect();
    // (A walk of every triangle: only where the middle is a gap.)
    if surface.highest_hit(middle).is_some() {
        return at;
    }
    if let Some(nearest) = surface.nearest_in_xy(middle) {
        let away = (nearest - middle).normalize_or_zero();
        at.extend((0..=4).map(|k| nearest + away * (0.25 * k as f64 * size)));
    }
    at
}

/// The largest share (0 to 1) of the points along the drawing's lines,
/// placed by `placement`, that lie over the scan's surface, where it is
/// and with its middle at each place [`centre_on_surface`] tries
/// ([`tried_middles`]), at the same size and turn. Under a half, no move
/// of the drawing is likely to print half of it: the scanned surface is
/// smaller than the drawing (QA round 15 F3: a drawing refused as mostly
/// beside a scan was told to use `--place centre`, which it had).
pub fn best_cover(drawn: &[Subpath2], surface: &Surface, placement: &Placement) -> f64 {
    // At most COVER_SAMPLES of them (`along_lines` adds every subpath's
    // start: a drawing of text has tens of thousands).
    let along = along_lines(drawn, COVER_SAMPLES);
    let stride = along.len().div_ceil(COVER_SAMPLES).max(1);
    let samples: Vec<DVec2> = (along.into_iter().step_by(stride))
        .map(|p| placement.apply(p))
        .collect();
    if samples.is_empty() {
        return 0.0;
    }
    let (dlo, dhi) = (samples.iter())
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let middle = 0.5 * (dlo + dhi);
    let over = |shift: DVec2| {
        (samples.iter())
            .filter(|p| surface.highest_hit(**p + shift).is_some())
            .count()
    };
    let best = (tried_middles(surface, (dhi - dlo).max_element()).into_iter())
        .map(|c| over(c - middle))
        .fold(over(DVec2::ZERO), usize::max);
    best as f64 / samples.len() as f64
}

/// How many points along the drawing's lines [`centre_on_surface`] scores
/// a place by.
pub const COVER_SAMPLES: usize = 256;

/// About `n` points spread evenly along the lines of `drawn` (drawing
/// coordinates): every subpath's start, then one each `length / n` of
/// line.
fn along_lines(drawn: &[Subpath2], n: usize) -> Vec<DVec2> {
    let length: f64 = (drawn.iter())
        .flat_map(|s| s.points.windows(2))
        .map(|w| w[0].distance(w[1]))
        .sum();
    let step = length / n.max(1) as f64;
    let mut out = Vec::with_capacity(n + drawn.len());
    for s in drawn {
        let Some(&first) = s.points.first() else {
            continue;
        };
        out.push(first);
        // How far along the next point lies from the last one taken.
        let mut next = step;
        for w in s.points.windows(2) {
            let l = w[0].distance(w[1]);
            while step > 0.0 && next <= l {
                out.push(w[0].lerp(w[1], next / l));
                next += step;
            }
            next -= l;
        }
    }
    out
}

/// The drawing's placement after its scan moves from `from` to `to` (both
/// for a scan whose bounds in the scanner frame are `bbox`): the drawing
/// moves and turns with the scan, so it stays on the same part of it (the
/// page moves the scan by hand; re-centring would undo the user's own
/// placement of the drawing). Both placements are turns about z and moves,
/// so the result is again a [`Placement`]; its scale is kept.
pub fn carry_drawing(
    drawing: &Placement,
    bbox: (DVec3, DVec3),
    from: &ScanPlacement,
    to: &ScanPlacement,
) -> Placement {
    let g = |p: &ScanPlacement| p.transform(bbox).unwrap_or(DMat4::IDENTITY);
    let m = g(to) * g(from).inverse();
    let turn = |p: &ScanPlacement| match p {
        ScanPlacement::OnBed { rotation_deg, .. } => *rotation_deg,
        ScanPlacement::AsScanned => 0.0,
    };
    // The turn in degrees as typed, not read back from the matrix: a
    // quarter turn stays 90, not 89.99999999999999.
    Placement {
        offset_mm: m.transform_point3(drawing.offset_mm.extend(0.0)).truncate(),
        rotation_deg: drawing.rotation_deg + turn(to) - turn(from),
        scale: drawing.scale,
    }
}

/// The drawing's placement after the registration of its scan (scanner
/// frame to printer frame, row-major as the report gives it) changes from
/// `from` to `to`: the printer points of the fiducials were typed again, or
/// the holes paired with them another way, so the scan now stands elsewhere
/// on the printer, and the drawing goes with it to stay on the same part of
/// it, as in [`carry_drawing`]. `z_mm` is the height the drawing lies at
/// before the change (the scan's middle): a change that tilts the scan
/// moves a point at that height, and only the change's turn about z turns
/// the drawing, which stays flat. The drawing as it was when `from` cannot
/// be undone (a singular matrix).
pub fn carry_drawing_by(
    drawing: &Placement,
    z_mm: f64,
    from: &[[f64; 4]; 4],
    to: &[[f64; 4]; 4],
) -> Placement {
    let g = |m: &[[f64; 4]; 4]| DMat4::from_cols_array_2d(m).transpose();
    let (from, to) = (g(from), g(to));
    let det = from.determinant();
    if !det.is_finite() || det.abs() < 1e-12 || from == to {
        return *drawing;
    }
    let m = to * from.inverse();
    if !m.is_finite() {
        return *drawing;
    }
    // The turn read back from the matrix, to a billionth of a degree: a
    // fit's rounding (1e-17 of a turn on a pure move) is not shown as a
    // rotation of 0.0000000000000006 degrees.
    let turn = libm::atan2(m.x_axis.y, m.x_axis.x).to_degrees();
    let turn = (turn * 1e9).round() / 1e9;
    Placement {
        offset_mm: m
            .transform_point3(drawing.offset_mm.extend(z_mm))
            .truncate(),
        rotation_deg: drawing.rotation_deg + turn,
        scale: drawing.scale,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row_major(m: DMat4) -> [[f64; 4]; 4] {
        m.transpose().to_cols_array_2d()
    }

    /// A registration moved and turned the scan: every point of the
    /// drawing lands where the change takes the point of the part it lay
    /// on, and a pure move leaves the rotation as typed.
    #[test]
    fn a_drawing_goes_with_its_scan_when_the_registration_changes() {
        let drawing = Placement {
            offset_mm: DVec2::new(10.0, 20.0),
            rotation_deg: 5.0,
            scale: 1.5,
        };
        let from = DMat4::from_translation(DVec3::new(-3.0, 7.0, 1.0))
            * DMat4::from_rotation_z(12f64.to_radians());
        let change = DMat4::from_translation(DVec3::new(60.0, 45.0, 2.0))
            * DMat4::from_rotation_z(30f64.to_radians());
        let to = change * from;
        let carried = carry_drawing_by(&drawing, 4.0, &row_major(from), &row_major(to));
        assert!((carried.rotation_deg - 35.0).abs() < 1e-9, "{carried:?}");
        assert_eq!(carried.scale, 1.5);
        for p in [DVec2::ZERO, DVec2::new(40.0, -3.0), DVec2::new(-8.0, 25.0)] {
            let want = change
                .transform_point3(drawing.apply(p).extend(4.0))
                .truncate();
            let got = carried.apply(p);
            assert!(got.distance(want) < 1e-9, "{p}: {got} vs {want}");
        }
        // A pure move: the rotation stays 5 exactly.
        let moved = DMat4::from_translation(DVec3::new(60.0, 45.0, 0.0)) * from;
        let carried = carry_drawing_by(&drawing, 4.0, &row_major(from), &row_major(moved));
        assert_eq!(carried.rotation_deg, 5.0);
        assert!(carried.offset_mm.distance(DVec2::new(70.0, 65.0)) < 1e-9);
        // The same registration, or one that cannot be undone: unchanged.
        let same = carry_drawing_by(&drawing, 4.0, &row_major(from), &row_major(from));
        assert_eq!(same, drawing);
        let flat = row_major(DMat4::from_scale(DVec3::new(1.0, 1.0, 0.0)));
        assert_eq!(
            carry_drawing_by(&drawing, 4.0, &flat, &row_major(to)),
            drawing
        );
    }

    fn volume() -> BuildVolume {
        BuildVolume {
            min_mm: DVec3::ZERO,
            max_mm: DVec3::new(220.0, 220.0, 250.0),
        }
    }

    /// The demo part registered on its fiducials spans x from -1e-13:
    /// "outside the build volume ... out by up to 0.0 mm".
    /// A scan placed on the bed and still taller than the volume was told
    /// to "place it on the bed".
    #[test]
    fn a_scan_larger_than_the_volume_is_told_which_axis_not_to_place_it() {
        let bbox = (DVec3::new(30.0, 30.0, 0.0), DVec3::new(90.0, 90.0, 260.4));
        let fit = volume_fit(bbox, &volume(), "marlin", ScanUnits::Mm);
        assert!(!fit.inside && !fit.fits_on_bed);
        assert!(
            fit.message
                .contains("it is larger than the volume (z 260.4 mm, the volume 250.0 mm above its bed)")
                && !fit.message.contains("place it on the bed")
                // (QA round 9 L2: a 1.1 m model in every unit offered.)
                && fit.message.ends_with(
                    "pcpp does not scale a scan: one too large even read in mm, the smallest \
                     unit it reads, must be scaled down in the program that exported it)"
                ),
            "{}",
            fit.message
        );
        // Placed on the bed, the same: moving it cannot help (QA: a scan
        // read in metres, placed on the bed, was told to move back inside).
        assert_eq!(fit.placed_message, fit.message);
        // Read in metres, a 2 m cube (a glTF's 2 units): the smaller units
        // it fits in, not "even read in mm" (QA round 16 F10).
        let cube = (DVec3::ZERO, DVec3::splat(2000.0));
        let fit = volume_fit(cube, &volume(), "marlin", ScanUnits::M);
        assert!(
            fit.message.contains(
                "the volume 220.0 mm), read in metres: in centimetres it would be 20.0 x 20.0 x \
                 20.0 mm (--scan-units cm), in inches it would be 50.8 x 50.8 x 50.8 mm \
                 (--scan-units in); check the scan's units"
            ) && !fit.message.contains("even read in mm"),
            "{}",
            fit.message
        );
        // QA round 17 F8: a 155 mm bunny in metres, too tall for a 100 mm
        // volume: no units in which it would be a speck.
        let tall = DVec3::new(300.0, 300.0, 100.0);
        let bunny = (DVec3::ZERO, DVec3::new(155.7, 120.7, 154.3));
        let fit = volume_fit(
            bunny,
            &BuildVolume {
                min_mm: DVec3::ZERO,
                max_mm: tall,
            },
            "lab",
            ScanUnits::M,
        );
        assert!(
            fit.message.contains(
                "(z 154.3 mm, the volume 100.0 mm above its bed), read in metres; in smaller units it would \
                 fit only as a part under 5 mm across: check the scan's up axis, or use a \
                 profile whose build volume holds it"
            ) && !fit.message.contains("--scan-units"),
            "{}",
            fit.message
        );
        // In centimetres, 5 m: too large in millimetres too.
        let fit = volume_fit(
            (DVec3::ZERO, DVec3::splat(5000.0)),
            &volume(),
            "marlin",
            ScanUnits::Cm,
        );
        assert!(
            fit.message
                .contains("read in centimetres, and in any smaller units too"),
            "{}",
            fit.message
        );
        let fit = volume_fit(
            (DVec3::new(0.0, 0.0, 0.0), DVec3::new(30.0, 30.0, 10.0)),
            &volume(),
            "marlin",
            ScanUnits::Mm,
        );
        assert!(fit.inside);
        let fit = volume_fit(
            (DVec3::new(-10.0, 0.0, 0.0), DVec3::new(30.0, 30.0, 10.0)),
            &volume(),
            "marlin",
            ScanUnits::Mm,
        );
        assert!(
            fit.placed_message
                .ends_with("move it back inside (--place-scan bed,DX,DY,DZ[,ROT])"),
            "{}",
            fit.placed_message
        );
    }

    /// QA round 20 F6: the units advice for a scan that cannot stand on the
    /// printer in its units, and would in smaller ones, is the build
    /// volume's refusal's, wherever it lies (a refusal for something else
    /// says it too); a scan that fits, one read in mm, or one a speck in
    /// every smaller unit gets none.
    #[test]
    fn the_units_hint_is_the_volume_refusals() {
        let metre = (
            DVec3::new(-500.0, -500.0, 0.0),
            DVec3::new(500.0, 500.0, 1.0),
        );
        let hint = units_hint(metre, &volume(), "marlin", ScanUnits::M).unwrap();
        assert_eq!(
            hint,
            "the scan is larger than the build volume of profile marlin (x 1000.0 mm, the volume \
             220.0 mm), read in metres: in centimetres it would be 10.0 x 10.0 x 0.0 mm \
             (--scan-units cm), in inches it would be 25.4 x 25.4 x 0.0 mm (--scan-units in); \
             check the scan's units and up axis, or use a profile whose build volume holds it"
        );
        let fit = volume_fit(metre, &volume(), "marlin", ScanUnits::M);
        let tail = hint.replace(
            "the scan is larger than the build volume of profile marlin",
            "it is larger than the volume",
        );
        assert!(fit.message.ends_with(&tail), "{}", fit.message);
        // Inside the volume or not, the same hint.
        let moved = (metre.0 + 600.0, metre.1 + 600.0);
        assert_eq!(
            units_hint(moved, &volume(), "marlin", ScanUnits::M),
            Some(hint)
        );
        assert_eq!(units_hint(metre, &volume(), "marlin", ScanUnits::Mm), None);
        let part = (DVec3::ZERO, DVec3::new(0.15, 0.1, 0.01));
        assert_eq!(units_hint(part, &volume(), "marlin", ScanUnits::M), None);
        // QA round 17 F8's bunny, too tall for a 100 mm volume in metres.
        let low = BuildVolume {
            min_mm: DVec3::ZERO,
            max_mm: DVec3::new(300.0, 300.0, 100.0),
        };
        let bunny = (DVec3::ZERO, DVec3::new(155.7, 120.7, 154.3));
        assert_eq!(units_hint(bunny, &low, "lab", ScanUnits::M), None);
    }

    #[test]
    fn a_scan_a_hair_past_a_face_is_inside() {
        let hi = DVec3::new(80.0, 80.0, 8.0);
        let fit = volume_fit(
            (DVec3::new(-1e-13, 0.0, 3.5), hi),
            &volume(),
            "marlin",
            ScanUnits::Mm,
        );
        assert!(fit.inside, "{}", fit.message);
        let fit = volume_fit(
            (DVec3::new(-0.01, 0.0, 3.5), hi),
            &volume(),
            "marlin",
            ScanUnits::Mm,
        );
        assert!(!fit.inside);
    }

    /// QA round 20 F3: a 125 mm tall scan on Grbl's -100..100 mm volume
    /// (bed at z = 0) was told to move back inside, and the only way,
    /// down, sank it into the bed: the room is what lies above the bed.
    #[test]
    fn a_scan_taller_than_the_room_above_the_bed_does_not_fit_on_it() {
        let grbl = BuildVolume {
            min_mm: DVec3::splat(-100.0),
            max_mm: DVec3::splat(100.0),
        };
        let tall = (DVec3::new(-60.0, -90.0, 0.0), DVec3::new(60.0, 90.0, 125.4));
        let fit = volume_fit(tall, &grbl, "grbl", ScanUnits::Mm);
        assert!(!fit.inside && !fit.fits_on_bed);
        assert!(
            fit.message.contains(
                "it is larger than the volume (z 125.4 mm, the volume 100.0 mm above its bed)"
            ) && !fit.message.contains("move it back inside"),
            "{}",
            fit.message
        );
        // One that fits above the bed is still offered a place there.
        let short = (
            DVec3::new(-60.0, -90.0, 150.0),
            DVec3::new(60.0, 90.0, 249.0),
        );
        let fit = volume_fit(short, &grbl, "grbl", ScanUnits::Mm);
        assert!(!fit.inside && fit.fits_on_bed, "{}", fit.message);
    }

    #[test]
    fn a_drawing_is_not_fitted_to_a_scan_seen_edge_on() {
        // A 20 mm square plate standing on its edge (a glTF read +Z up).
        let wall = crate::mesh::TriMesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(20.0, 0.0, 0.0),
                DVec3::new(20.0, 0.0, 20.0),
                DVec3::new(0.0, 0.0, 20.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let surface = Surface::new(wall).unwrap();
        let drawn = vec![Subpath2 {
            points: vec![DVec2::ZERO, DVec2::new(31.3, 31.5)],
            corner: vec![true, true],
            closed: false,
            source: "line".into(),
        }];
        let (placed, note) =
            centre_on_surface(&drawn, &surface, &Placement::default(), true).unwrap();
        assert_eq!((placed.scale, note), (1.0, None));
    }

    #[test]
    fn a_scan_in_the_scanner_frame_is_placed_on_the_bed() {
        let bbox = (
            DVec3::new(-60.0, 30.0, -820.0),
            DVec3::new(40.0, 90.0, -790.0),
        );
        let fit = volume_fit(bbox, &volume(), "marlin", ScanUnits::Mm);
        assert!(!fit.inside && fit.fits_on_bed);
        assert!(fit.message.contains("--place-scan bed"), "{}", fit.message);
        let p = ScanPlacement::OnBed {
            bed: Bed::of(&volume()),
            rotation_deg: 0.0,
            offset_mm: DVec3::ZERO,
        };
        let g = p.transform(bbox).unwrap();
        let (lo, hi) = (g.transform_point3(bbox.0), g.transform_point3(bbox.1));
        assert!((lo.z - 0.0).abs() < 1e-9 && (hi.z - 30.0).abs() < 1e-9);
        let mid = 0.5 * (lo + hi);
        assert!((mid.truncate() - DVec2::new(110.0, 110.0)).length() < 1e-9);
        assert!(volume_fit((lo.min(hi), lo.max(hi)), &volume(), "marlin", ScanUnits::Mm).inside);
        // Turned a quarter and raised: the footprint turns about its
        // middle, the lowest point stays on the bed plus the offset.
        let p = ScanPlacement::OnBed {
            bed: Bed::of(&volume()),
            rotation_deg: 90.0,
            offset_mm: DVec3::new(5.0, 0.0, 1.0),
        };
        let g = p.transform(bbox).unwrap();
        let c = g.transform_point3(DVec3::new(-10.0, 60.0, -820.0));
        assert!((c - DVec3::new(115.0, 110.0, 1.0)).length() < 1e-9, "{c}");
        let x_end = g.transform_point3(DVec3::new(40.0, 60.0, -820.0));
        assert!(
            (x_end - DVec3::new(115.0, 160.0, 1.0)).length() < 1e-9,
            "{x_end}"
        );
        assert!(ScanPlacement::AsScanned.transform(bbox).is_none());
        // QA round 19 F13: the built-in Grbl and Aerotech volumes reach
        // below z = 0 (work coordinates); their bed is z = 0, where a
        // user touches off the nozzle, not the volume's floor.
        for name in ["grbl", "aerotech"] {
            let profile = MachineProfile::builtin(name).unwrap();
            assert!(profile.build_volume.min_mm.z < 0.0, "{name}");
            assert_eq!(Bed::of_profile(&profile).z_mm, 0.0, "{name}");
        }
        let above = BuildVolume {
            min_mm: DVec3::new(0.0, 0.0, 10.0),
            max_mm: DVec3::new(100.0, 100.0, 50.0),
        };
        assert_eq!(Bed::of(&above).z_mm, 10.0);
    }

    #[test]
    fn status_says_how_the_scan_got_there() {
        assert!(RegistrationStatus::AsScanned
            .to_string()
            .starts_with("unregistered"));
        let s = RegistrationStatus::PlacedOnBed {
            rotation_deg: 0.0,
            offset_mm: DVec3::ZERO,
        };
        assert_eq!(s.to_string(), "unregistered, placed on the bed");
        let s = RegistrationStatus::Registered {
            method: crate::registration::RegistrationMethod::Lsq,
            fiducials: 3,
            rms_mm: 0.165,
        };
        assert_eq!(
            s.to_string(),
            "registered (lsq, 3 fiducials, RMS residual 0.165 mm)"
        );
    }

    #[test]
    fn a_drawing_moves_and_turns_with_its_scan() {
        let bbox = (
            DVec3::new(-60.0, 30.0, -820.0),
            DVec3::new(40.0, 90.0, -790.0),
        );
        let drawing = Placement {
            offset_mm: DVec2::new(-10.0, 60.0),
            rotation_deg: 10.0,
            scale: 0.5,
        };
        let bed = ScanPlacement::OnBed {
            bed: Bed::of(&volume()),
            rotation_deg: 0.0,
            offset_mm: DVec3::ZERO,
        };
        // Placed on the bed: the footprint's middle (-10, 60) goes to the
        // bed's (110, 110), and the drawing with it.
        let on_bed = carry_drawing(&drawing, bbox, &ScanPlacement::AsScanned, &bed);
        assert!((on_bed.offset_mm - DVec2::new(110.0, 110.0)).length() < 1e-9);
        assert_eq!((on_bed.rotation_deg, on_bed.scale), (10.0, 0.5));
        // Turned a quarter and moved: a point of the drawing lands where
        // the scan's point under it went.
        let turned = ScanPlacement::OnBed {
            bed: Bed::of(&volume()),
            rotation_deg: 90.0,
            offset_mm: DVec3::new(5.0, -3.0, 1.0),
        };
        let after = carry_drawing(&on_bed, bbox, &bed, &turned);
        assert_eq!(after.rotation_deg, 100.0);
        let q = DVec2::new(4.0, 2.0);
        let scan_point = drawing.apply(q).extend(-800.0);
        let g = turned.transform(bbox).unwrap();
        let want = g.transform_point3(scan_point).truncate();
        assert!(
            (after.apply(q) - want).length() < 1e-9,
            "{}",
            after.apply(q)
        );
        // And back to the scanner's frame.
        let back = carry_drawing(&after, bbox, &turned, &ScanPlacement::AsScanned);
        assert!((back.offset_mm - drawing.offset_mm).length() < 1e-9);
        assert_eq!(back.rotation_deg, 10.0);
    }

    /// The XY box of a subpath's points.
    fn extent(s: &Subpath2) -> (DVec2, DVec2) {
        s.points
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    }

    /// A flat ring at z = 1 about (100, 100), from radius `inner` to
    /// `outer`, in `sectors` quads.
    fn ring(inner: f64, outer: f64, sectors: u32) -> Surface {
        let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
        for k in 0..sectors {
            let a = DVec2::from_angle(k as f64 * std::f64::consts::TAU / sectors as f64);
            for r in [inner, outer] {
                vertices.push((DVec2::splat(100.0) + r * a).extend(1.0));
            }
            let (i, j) = (2 * k, 2 * ((k + 1) % sectors));
            triangles.extend([[i, i + 1, j + 1], [i, j + 1, j]]);
        }
        Surface::new(crate::mesh::TriMesh {
            vertices,
            triangles,
        })
        .unwrap()
    }

    /// QA round 13 F3: the CLI's `--place centre` planned at the offset
    /// as computed (-0.852996826171875 mm from a scan's single-precision
    /// box), the page at what its field shows (-0.853): 63 moves of the
    /// same drawing differed in the third decimal. Both now plan the
    /// centred placement as the page shows it.
    #[test]
    fn a_centred_placement_is_the_one_the_page_shows() {
        // A plate whose corners are not round numbers in binary.
        let (x0, y0, x1, y1) = (
            -58.7f32 as f64,
            0.1f32 as f64,
            57.0f32 as f64,
            115.8f32 as f64,
        );
        let plate = Surface::new(crate::mesh::TriMesh {
            vertices: vec![
                DVec3::new(x0, y0, 1.0),
                DVec3::new(x1, y0, 1.0),
                DVec3::new(x1, y1, 1.0),
                DVec3::new(x0, y1, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        })
        .unwrap();
        let line = Subpath2 {
            points: vec![DVec2::new(0.0, 0.0), DVec2::new(300.0, 7.0)],
            corner: vec![true; 2],
            closed: false,
            source: "line".into(),
        };
        let drawn = std::slice::from_ref(&line);
        let exact = centre_on_surface_exact(drawn, &plate, &Placement::IDENTITY, true)
            .unwrap()
            .0;
        let (shown, note) = centre_on_surface(drawn, &plate, &Placement::IDENTITY, true).unwrap();
        assert!(note.is_some(), "scaled to fit");
        // The page's rounding (web/worker.js, shownPlacement).
        let js_round4 = |v: f64| (v * 1e4 + 0.5).floor() / 1e4 + 0.0;
        assert_eq!(shown.offset_mm.x, js_round4(exact.offset_mm.x));
        assert_eq!(shown.offset_mm.y, js_round4(exact.offset_mm.y));
        assert_ne!(shown.offset_mm, exact.offset_mm);
        assert_eq!(
            shown.scale,
            format!("{:.5e}", exact.scale).parse::<f64>().unwrap()
        );
        assert_ne!(shown.scale, exact.scale);
        // Idempotent, as the page's own rounding is of it.
        assert_eq!(as_shown(shown, 1.0), shown);
        // Halves: up, as Math.round; a kept scale is not touched.
        let half = Placement {
            offset_mm: DVec2::new(-0.00025, 0.00025),
            rotation_deg: 0.0,
            scale: 1.0 / 3.0,
        };
        let r = as_shown(half, 1.0 / 3.0);
        assert_eq!(
            (r.offset_mm.x, r.offset_mm.y),
            (js_round4(-0.00025), js_round4(0.00025))
        );
        assert_eq!(r.scale, 1.0 / 3.0);
    }

    /// QA round 2 F9: a ring-shaped scan's footprint has a gap in its
    /// middle; `--place centre` put the drawing there and planning refused
    /// it. It goes onto the ring, most of it over the surface, with a note;
    /// on a scan whose middle is covered it is `centre_drawing`'s placement.
    #[test]
    fn a_drawing_centred_over_a_gap_goes_onto_the_surface_near_it() {
        let narrow = ring(20.0, 40.0, 64);
        // A 10 mm circle (closed: its last point repeats the first).
        let circle = Subpath2 {
            points: (0..=48)
                .map(|k| 5.0 * DVec2::from_angle(k as f64 * std::f64::consts::TAU / 48.0))
                .collect(),
            corner: vec![false; 49],
            closed: true,
            source: "c".into(),
        };
        let drawn = std::slice::from_ref(&circle);
        let (lo, hi) = narrow.bbox();
        let (gap, _) = centre_drawing(
            drawn,
            (lo.truncate(), hi.truncate()),
            &Placement::IDENTITY,
            true,
        )
        .unwrap();
        let on = |p: &Placement| {
            (circle.points.iter())
                .filter(|q| narrow.highest_hit(p.apply(**q)).is_some())
                .count()
        };
        assert_eq!(on(&gap), 0);
        let (p, note) = centre_on_surface(drawn, &narrow, &Placement::IDENTITY, true).unwrap();
        assert_eq!(on(&p), 49, "{p:?}");
        assert_eq!((p.rotation_deg, p.scale), (0.0, 1.0));
        let note = note.expect("a note");
        assert!(
            note.starts_with(
                "the middle of the scan's footprint (100.000, 100.000) lies over a gap in the \
                 scan: the drawing is centred at ("
            ) && note
                .contains("where 100% of its line lies over the scan (0% centred on the middle)"),
            "{note}"
        );
        // QA round 7 F1: a 50 mm square on a ring 50 to 80 mm across lies
        // on the band centred (its sides' middles on the inner edge, its
        // corners 35 mm out): it stays centred; it was put off the ring.
        let square = Subpath2 {
            points: [
                (-25.0, -25.0),
                (25.0, -25.0),
                (25.0, 25.0),
                (-25.0, 25.0),
                (-25.0, -25.0),
            ]
            .map(|(x, y)| DVec2::new(x, y))
            .to_vec(),
            corner: vec![true; 5],
            closed: true,
            source: "square".into(),
        };
        let wide = ring(25.0, 40.0, 256);
        let samples = along_lines(std::slice::from_ref(&square), 400);
        let covered = |p: &Placement| {
            (samples.iter())
                .filter(|q| wide.highest_hit(p.apply(**q)).is_some())
                .count() as f64
                / samples.len() as f64
        };
        let (lo, hi) = wide.bbox();
        let (centred, _) = centre_drawing(
            std::slice::from_ref(&square),
            (lo.truncate(), hi.truncate()),
            &Placement::IDENTITY,
            false,
        )
        .unwrap();
        let (p, _) = centre_on_surface(
            std::slice::from_ref(&square),
            &wide,
            &Placement::IDENTITY,
            false,
        )
        .unwrap();
        assert_eq!(covered(&centred), 1.0);
        assert_eq!(p, centred);
        // A disk: its middle is covered, and the drawing stays there.
        let disk = Surface::new(crate::mesh::TriMesh {
            vertices: vec![
                DVec3::new(60.0, 60.0, 1.0),
                DVec3::new(140.0, 60.0, 1.0),
                DVec3::new(140.0, 140.0, 1.0),
                DVec3::new(60.0, 140.0, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        })
        .unwrap();
        let (lo, hi) = disk.bbox();
        assert_eq!(
            centre_on_surface(drawn, &disk, &Placement::IDENTITY, true),
            centre_drawing(
                drawn,
                (lo.truncate(), hi.truncate()),
                &Placement::IDENTITY,
                true
            )
        );
    }

    #[test]
    fn drawings_are_centred_and_scaled_to_fit() {
        let square = Subpath2 {
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(100.0, 0.0),
                DVec2::new(100.0, 50.0),
            ],
            corner: vec![true; 3],
            closed: false,
            source: "s".into(),
        };
        let footprint = (DVec2::new(10.0, 20.0), DVec2::new(50.0, 60.0));
        let (p, note) = centre_drawing(
            std::slice::from_ref(&square),
            footprint,
            &Placement::IDENTITY,
            true,
        )
        .unwrap();
        assert!(note.unwrap().contains("scaled by 0.360"));
        assert!((p.scale - 0.36).abs() < 1e-12);
        let (lo, hi) = extent(&p.apply_subpath(&square));
        assert!((0.5 * (lo + hi) - DVec2::new(30.0, 40.0)).length() < 1e-9);
        assert!(lo.cmpge(footprint.0).all() && hi.cmple(footprint.1).all());
        // A small drawing keeps its scale and rotation.
        let current = Placement {
            rotation_deg: 30.0,
            scale: 0.1,
            ..Placement::IDENTITY
        };
        let (p, note) =
            centre_drawing(std::slice::from_ref(&square), footprint, &current, true).unwrap();
        assert!(note.is_none());
        assert_eq!((p.rotation_deg, p.scale), (30.0, 0.1));
        assert!(centre_drawing(&[], footprint, &current, true).is_none());
        // Not fitted: the scale given is kept, centred, and the note says
        // that it overhangs.
        let (p, note) = centre_drawing(
            std::slice::from_ref(&square),
            footprint,
            &Placement::IDENTITY,
            false,
        )
        .unwrap();
        assert_eq!(p.scale, 1.0);
        assert!(note.unwrap().contains("kept at its scale"));
        let (lo, hi) = extent(&p.apply_subpath(&square));
        assert!((0.5 * (lo + hi) - DVec2::new(30.0, 40.0)).length() < 1e-9);
        let (_, note) =
            centre_drawing(std::slice::from_ref(&square), footprint, &current, false).unwrap();
        assert!(note.is_none());
        // A scan seen edge-on (a vertical plane, 1000 x 0 mm from above):
        // the drawing is not shrunk to its zero side ("scaled by 0.000"),
        // only to the other.
        let edge = (DVec2::new(-500.0, 0.0), DVec2::new(500.0, 0.0));
        let (p, _) = centre_drawing(&[square], edge, &Placement::IDENTITY, true).unwrap();
        assert_eq!(p.scale, 1.0);
    }

    /// A factor below 1 with three significant digits (0.953, 0.000272): a
    /// drawing scaled down ten thousand times was "scaled by 0.000".
    #[test]
    fn scale_factors_keep_three_significant_digits() {
        let three_digits = |x| crate::error::significant(x, 3, 3);
        assert_eq!(three_digits(0.953), "0.953");
        assert_eq!(three_digits(0.0542), "0.0542");
        assert_eq!(three_digits(0.000272), "0.000272");
        assert_eq!(three_digits(0.5), "0.500");
    }
}
