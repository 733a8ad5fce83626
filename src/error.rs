//! The crate's error: one variant per pipeline stage, each wrapping that
//! stage's own typed error (which carries the file, line or point at fault).

use crate::{
    gcode::{GcodeError, GcodeReadError},
    mesh::MeshError,
    registration::RegistrationError,
    sampling::SamplingError,
    svg::SvgError,
};

/// Any fatal error of the planning core. Recoverable oddities are not errors:
/// they become warnings in the plan's report.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scan could not be read.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The fiducials do not define a rigid transform.
    #[error(transparent)]
    Registration(#[from] RegistrationError),
    /// The drawn path could not be read.
    #[error(transparent)]
    Svg(#[from] SvgError),
    /// The drawn path could not be sampled.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// The G-code could not be written (names the subpath and point).
    #[error(transparent)]
    Gcode(#[from] GcodeError),
    /// A G-code program could not be read (names the file, line and word).
    #[error(transparent)]
    GcodeRead(#[from] GcodeReadError),
    /// A G-code program could not be read for the machine profile it was
    /// read for, and its header says it was written for another (QA round
    /// 9 L1): the reading's error, then the header's profile.
    #[error("{source}; {note}")]
    GcodeReadForOtherProfile {
        source: Box<GcodeReadError>,
        note: String,
    },
    /// A parameter is out of its valid range (names the parameter and value).
    #[error("invalid parameter {name} = {value}: {reason}")]
    Parameter {
        name: &'static str,
        value: String,
        reason: String,
    },
    /// The tool path leaves the machine's build volume and the scan lies
    /// outside it: says where the scan lies and how to place it.
    #[error("{}", outside_volume(source, fit))]
    OutsideVolume {
        source: Box<GcodeError>,
        fit: String,
    },
    /// The G-code's moves would bring the nozzle too close to the surface
    /// (names the first moves, with their lines).
    #[error(transparent)]
    Touching(#[from] Box<crate::motion::TouchingMoves>),
    /// Planning could not produce a tool path (names the path and point).
    #[error("{0}")]
    Plan(String),
    /// The drawing has no path to print: about the drawing alone, so no
    /// advice on the scan goes with it ([`crate::job::with_units_hint`]).
    #[error("the drawing has no path to print")]
    NoPath,
    /// G-code refused for a point cloud of a whole object (points under
    /// its top were left out): its surface between the points on steep
    /// sides is a guess, so the motion check does not hold for the part.
    #[error(
        "{file}: {hidden} of its {points} points lie under the surface seen from above: \
         a scan of a whole object, or a camera's view in perspective (at the edges of what \
         a depth camera sees, its rays reach under them), not of a surface seen straight \
         from above. Meshed from above, its surface between the points on steep sides \
         and thin features is a guess, so the clearance checked along the moves does not \
         hold for the real part; no G-code written. Export the scan as a mesh (PLY, OBJ, STL \
         or glTF, if the scanner's software makes one), or scan the part straight from \
         above, and plan on that, or accept the risk"
    )]
    WholeObjectCloud {
        file: String,
        hidden: usize,
        points: usize,
    },
    /// G-code refused for a scan so small or so large that its units are
    /// likely wrong ([`crate::mesh::UnitsDoubt`]), none given.
    #[error("{message}. No G-code written: {}", units_advice(*units, size, *stray))]
    UnitsDoubt {
        message: String,
        /// The units it was read in.
        units: crate::mesh::ScanUnits,
        /// "small" or "large".
        size: &'static str,
        /// A few stray vertices make it large ([`crate::mesh::StrayVertices`]):
        /// no units would mend it.
        stray: bool,
    },
    /// G-code refused for a scan placed on the bed and then moved down
    /// (Move Z below 0): if the part stands on the bed, every move is that
    /// much too low, and the clearance checked against the scan does not
    /// hold for the part.
    #[error(
        "the scan is placed on the bed and then moved {depth_mm:.3} mm down (the DZ of \
         --place-scan bed,DX,DY,DZ), so its lowest {depth_mm:.3} mm lie below the bed: if the \
         part stands on the bed, every move is {depth_mm:.3} mm too low and the nozzle would \
         hit it; no G-code written. Give a DZ of 0 or more; if that much of the scan is not \
         on the printer (a scanned base or table), accept the risk"
    )]
    BelowBed { depth_mm: f64 },
    /// G-code refused for a scan placed on the bed that is larger than the
    /// build volume: the part cannot be on the printer as read (most often
    /// a scan read in the wrong units: QA round 7 F8, a 1.2 m scan placed
    /// on a 220 mm bed was planned; not placed, it was refused). The
    /// message is the volume fit's.
    #[error(
        "{0}; no G-code written: a part this large cannot stand on the printer; if it really \
         does, accept the risk"
    )]
    LargerThanVolume(String),
    /// G-code refused for a tool path that dispenses far above the surface
    /// ([`crate::pipeline::REFUSED_HEIGHT_PER_D`]).
    #[error(
        "the tool path would dispense {height_mm:.3} mm above the surface right under the tip, \
         at ({:.3}, {:.3}, {:.3}) (more than {limit_mm:.3} mm, {per_d} d): the nozzle is lifted \
         there to pass a feature it is wider than, or the drawing crosses a wall, and the \
         filament would fall that far; no G-code written. Move the drawing off that feature, \
         or accept the risk", .at[0], .at[1], .at[2], per_d = crate::pipeline::REFUSED_HEIGHT_PER_D
    )]
    FarAbove {
        height_mm: f64,
        at: [f64; 3],
        limit_mm: f64,
    },
    /// A refusal that accepting the risk lifts, with the other risks that
    /// the same acceptance would take (each would be refused on its own),
    /// and why accepting it would still write no G-code, where it would not
    /// (QA round 11 L1: the tool path outside the build volume, which no
    /// acceptance lifts, and `--accept-risk` was offered as writing it).
    #[error("{first}{}{}", also_accepts(others), blocked_anyway(blocked))]
    AlsoRisks {
        first: Box<Error>,
        others: Vec<String>,
        blocked: Option<String>,
    },
    /// G-code refused for a drawing most of which lies beside the scan or
    /// over its holes ([`crate::pipeline::MIN_PRINTED_SHARE`]).
    #[error(
        "only {printed_mm:.1} of the drawing's {drawn_mm:.1} mm ({percent:.0} %) lie over the \
         scan; the rest lies beside it or over its holes and would not be printed; no G-code \
         written. The drawing as placed spans x {:.3}..{:.3}, y {:.3}..{:.3} mm and the scan x \
         {:.3}..{:.3}, y {:.3}..{:.3} mm (printer frame): {}, or accept the risk to print only \
         the part over the scan",
        .drawing_xy[0], .drawing_xy[2], .drawing_xy[1], .drawing_xy[3],
        .scan_xy[0], .scan_xy[2], .scan_xy[1], .scan_xy[3], off_scan_advice(*.best_percent)
    )]
    MostlyOffScan {
        printed_mm: f64,
        drawn_mm: f64,
        percent: f64,
        /// lo x, lo y, hi x, hi y (mm, printer frame).
        drawing_xy: [f64; 4],
        scan_xy: [f64; 4],
        /// The largest share in percent over the scan of the places tried
        /// for the drawing at this size, when under a half: no move helps.
        best_percent: Option<f64>,
    },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What [`Error::MostlyOffScan`] advises: the placement, or where no
/// place tried puts half of the drawing over the scan (`best_percent`), a
/// smaller drawing.
fn off_scan_advice(best_percent: Option<f64>) -> String {
    match best_percent {
        // (Rounded down: 49.6 % is not "half".)
        Some(p) => format!(
            "no place of the drawing at this size and turn puts half of it over the scan (the \
             best of those tried, {} %): the scanned surface is smaller than the drawing, or has \
             gaps or holes under it; scale the drawing down or turn it (a smaller SCALE or \
             another ROT in --place centre,ROT,SCALE)",
            p.floor()
        ),
        None => {
            "check the placement (--place centre puts the drawing on the scan's footprint)".into()
        }
    }
}

/// [`Error::AlsoRisks`]' other risks.
fn also_accepts(others: &[String]) -> String {
    if others.is_empty() {
        String::new()
    } else {
        format!(
            "; accepting the risk would also accept: {}",
            others.join("; ")
        )
    }
}

/// [`Error::AlsoRisks`]' reason no acceptance writes G-code.
fn blocked_anyway(blocked: &Option<String>) -> String {
    blocked.as_ref().map_or(String::new(), |b| {
        format!("; but accepting the risk would write no G-code either: {b}")
    })
}

/// [`Error::OutsideVolume`]'s text: the point out of the volume, then what
/// `fit` says of the scan and how to place it, in place of the point's own
/// generic advice (check the registration or the profile). Where `fit`
/// names the volume (a scan outside it), the point does not name it a
/// second time (QA round 2: "... lies outside the build volume of profile
/// marlin (...): check the registration ...; the scan lies outside the
/// build volume of profile marlin (...)"). `fit` is kept whole: the page
/// finds its banner's sentence in the message.
fn outside_volume(source: &GcodeError, fit: &str) -> String {
    let GcodeError::OutOfVolume {
        subpath,
        point,
        position: p,
        volume,
        profile,
    } = source
    else {
        return format!("{source}; {fit}");
    };
    let at = crate::gcode::point_at(*subpath, *point, *p);
    if fit.starts_with(&format!(
        "the scan lies outside the build volume of profile {profile} "
    )) {
        format!("{at} lies outside the build volume, and {fit}")
    } else {
        format!("{at} lies outside the build volume of profile {profile} ({volume}); {fit}")
    }
}

/// A length (mm) in an error's text: `digits` decimals, or three
/// significant ones in scientific notation from 1e7 mm on (a fuzzed file's
/// 1e299 mm written out in 300 digits said nothing more; QA round 14: a
/// scan "1000000000000000052504760255204420248704...000 mm tall").
pub fn mm_text(v: f64, digits: usize) -> String {
    if v.abs() < 1e7 {
        format!("{v:.digits$}")
    } else {
        format!("{v:.3e}")
    }
}

/// `x` (positive) in a message with `digits` significant digits and at
/// least `min_decimals` decimals, at most 12 (0.92, 0.056 and 0.00012 with
/// 2 and 0; 0.953 and 0.000272 with 3 and 3); `min_decimals` for zero or
/// less.
pub fn significant(x: f64, digits: i32, min_decimals: usize) -> String {
    let decimals = if x > 0.0 {
        ((digits - 1) as f64 - x.log10().floor()).clamp(min_decimals as f64, 12.0) as usize
    } else {
        min_decimals
    };
    format!("{x:.decimals$}")
}

/// What [`Error::UnitsDoubt`] asks of the user.
fn units_advice(units: crate::mesh::ScanUnits, size: &str, stray: bool) -> String {
    if stray {
        "no choice of units mends a stray vertex; mend the file first".into()
    } else {
        format!("give the scan's units (--scan-units {units} if it really is this {size})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::BuildVolume;
    use glam::DVec3;

    fn out_of_volume() -> GcodeError {
        GcodeError::OutOfVolume {
            subpath: 0,
            point: 3,
            position: DVec3::new(110.0, 109.5, 254.7),
            volume: BuildVolume {
                min_mm: DVec3::ZERO,
                max_mm: DVec3::new(220.0, 220.0, 250.0),
            },
            profile: "marlin".into(),
        }
    }

    /// The volume is named once, the point's generic advice left to the
    /// scan's own, and the fit's sentence kept whole.
    #[test]
    fn outside_volume_names_the_volume_once() {
        let volume = "x 0..220, y 0..220, z 0..250 mm";
        let fit = format!(
            "the scan lies outside the build volume of profile marlin ({volume}): it spans x \
             -388.5..608.5, y 0.0..10.0, z 0.0..314.7 mm, out by up to 388.5 mm; check the \
             scan's units"
        );
        let e = Error::OutsideVolume {
            source: Box::new(out_of_volume()),
            fit: fit.clone(),
        }
        .to_string();
        assert_eq!(
            e,
            format!("subpath 0, point 3 at (110.000, 109.500, 254.700) mm lies outside the build volume, and {fit}")
        );
        assert_eq!(e.matches(volume).count(), 1, "{e}");
        assert!(!e.contains("check the registration"), "{e}");
        // A scan inside, the tool path beside it: the point names the volume.
        let fit = "the scan lies inside the build volume, but beside it the tool path passes";
        let e = Error::OutsideVolume {
            source: Box::new(out_of_volume()),
            fit: fit.into(),
        }
        .to_string();
        assert_eq!(
            e,
            format!(
                "subpath 0, point 3 at (110.000, 109.500, 254.700) mm lies outside the build \
                 volume of profile marlin ({volume}); {fit}"
            )
        );
    }
}
