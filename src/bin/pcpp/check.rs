//! `pcpp check`: every move of a G-code file, ours or another tool's,
//! checked against a scan.

use std::fmt::Write as _;

use pcpp::job;

use crate::args::CheckArgs;
use crate::files::{
    file_name, in_file, input_shown, is_stdout, read_gcode_text, to_json, write_one,
};
use crate::outputs::{Flagged, Outputs};
use crate::plan::load_scan;
use crate::progress::Progress;
use crate::settings::check_settings;
use crate::{CliResult, Failure};

pub fn cmd_check(a: &CheckArgs, progress: &Progress) -> CliResult<()> {
    let read = [
        Some(Flagged::new("--scan", &a.scan.scan)),
        Some(Flagged::new("--gcode", &a.gcode)),
        a.machine
            .profile
            .as_deref()
            .map(|p| Flagged::new("--profile", p)),
    ];
    let report = a.report.as_deref().map(|r| Flagged::new("--report", r));
    let outputs = Outputs::check("check", report, read.into_iter().flatten())?;
    // The nozzle values not given are the program header's (a pcpp
    // program's own nozzle and tol), said when they are not the defaults:
    // the program (small beside the scan) is read before the values are
    // checked, and the scan after.
    let gcode_path = &a.gcode;
    let (text, encoding) = read_gcode_text(gcode_path)?;
    let given = a.nozzle.or((None, None));
    let nozzle = a.nozzle.or(job::planned_nozzle(&text));
    let (settings, profile) =
        check_settings("check", &a.scan, &nozzle, &a.registration, &a.machine)?;
    let from_header: Vec<String> = [
        (nozzle.nozzle_od != given.nozzle_od)
            .then(|| format!("outer diameter {} mm", nozzle.nozzle_od)),
        (nozzle.nozzle_id != given.nozzle_id)
            .then(|| format!("inner diameter {} mm", nozzle.nozzle_id)),
        (nozzle.tol != given.tol).then(|| format!("tol {} mm", nozzle.tol)),
    ]
    .into_iter()
    .flatten()
    .collect();
    let header_nozzle = (!from_header.is_empty()).then(|| {
        format!(
            "checked with the nozzle the program's header names: {} (--nozzle-od, --nozzle-id \
             and --tol check with another)",
            from_header.join(", ")
        )
    });
    let prepared = load_scan(&a.scan, &settings, &outputs, progress)?;
    progress.step("checking every move...");
    let name = file_name(gcode_path);
    // Read as Grbl reads it for the grbl profile (`--dialect grbl`).
    let checked = job::check_gcode_as(
        &prepared,
        &text,
        &name,
        &settings.plan.nozzle,
        settings.plan.process.tolerance_mm,
        &profile.name,
    );
    let mut check = match checked {
        Ok(check) => check,
        Err(e) => {
            // What the import noticed may be why (the scan read in other
            // units than the program was planned with: QA).
            progress.finish();
            progress.warn(&prepared.warnings);
            return Err(Failure::Input(in_file(gcode_path, &name, &e.to_string())));
        }
    };
    check
        .notes
        .splice(0..0, encoding.into_iter().chain(header_nozzle));
    check.notes.extend(check.outside_volume(&profile));
    if let Some(r) = &a.report {
        write_one(r, to_json(&check)?.as_bytes())?;
    }
    progress.finish();
    progress.warn(&prepared.warnings);
    progress.warn(&check.notes);
    let sum = &check.summary;
    let clear =
        sum.min_clearance_mm
            .map_or("no placed move passes near the scan".to_string(), |c| {
                format!(
                    "min clearance {c:.3} mm{}",
                    sum.min_clearance_line
                        .map_or(String::new(), |l| format!(" (line {l})"))
                )
            });
    let head = format!(
        "{}: {} checked against {} (nozzle outer diameter {} mm, tol {} mm): {clear}",
        input_shown(gcode_path),
        match sum.moves {
            1 => "1 move".to_string(),
            n => format!("{n} moves"),
        },
        input_shown(&a.scan.scan),
        check.outer_diameter_mm,
        check.tol_mm
    );
    if let Some(verdict) = check.clear_verdict() {
        let line = format!("{head}; {verdict}");
        // Standard output carries the report written there, alone.
        if a.report.as_deref().is_some_and(is_stdout) {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
        return Ok(());
    }
    if sum.touching_moves == 0
        && check.unchecked_lines.is_empty()
        && check.planned_otherwise.is_empty()
    {
        if let Some(planned) = &check.planned_nozzle {
            return Err(Failure::Input(format!(
                "{head}; no move comes closer than tol with this nozzle, but {planned}; so the \
                 program is not shown to keep tol"
            )));
        }
    }
    if sum.touching_moves == 0 && check.unchecked_lines.is_empty() {
        // Only the header's scan differs (QA: a 44 mm cow checked as a
        // 1.7 mm one passed with exit 0).
        return Err(Failure::Input(format!(
            "{head}; no move comes closer than tol to the scan as this check reads it, but the \
             program was planned on the scan read or placed another way: {}; so the program is \
             not shown to keep tol",
            check.planned_otherwise.join("; ")
        )));
    }
    if sum.touching_moves == 0 {
        let lines = &check.unchecked_lines;
        // ("none of those comes closer" of 0 moves read as a pass.)
        let checked = match sum.moves {
            0 => "",
            1 => "; it does not come closer than tol",
            _ => "; none of those comes closer than tol",
        };
        return Err(Failure::Input(format!(
            "{head}{checked}, but {} move(s) could not be checked ({}): the file does not give where they start or end, and they come lower \
             than tol above the scan's top, so the program is not shown to keep tol; give the \
             position before them (absolute G90 moves from a known point, or G92), or check \
             the program from where it starts printing",
            lines.len(),
            job::line_list(lines)
        )));
    }
    let mut s = format!(
        "{head}; {} move(s) come closer than tol",
        sum.touching_moves
    );
    if sum.touching_from_previous > 0 {
        let _ = write!(
            s,
            ", {} of them closest at their start, where the move before each ended too close",
            sum.touching_from_previous
        );
    }
    if !check.unchecked_lines.is_empty() {
        let _ = write!(
            s,
            " (and {} more could not be checked, see the warnings)",
            check.unchecked_lines.len()
        );
    }
    s.push(':');
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
