//! `pcpp fiducials` and `pcpp register`: the holes of a scan that could be
//! fiducial dots, and the transform scanner -> printer from points.

use std::fmt::Write as _;

use pcpp::fiducials::find_fiducials_sized;
use pcpp::registration::register;

use crate::args::{FiducialsArgs, RegisterArgs};
use crate::files::{file_name, in_file, read_external, read_scan, to_json};
use crate::outputs::Outputs;
use crate::progress::{thousands, Progress};
use crate::settings::import_options;
use crate::{CliResult, Failure};

pub fn cmd_fiducials(a: &FiducialsArgs, progress: &Progress) -> CliResult<()> {
    let options = import_options(&a.scan);
    let path = &a.scan.scan;
    progress.step(format!("reading scan {}...", path.display()));
    let bytes = read_scan(path, "scan")?;
    let name = file_name(path);
    // A .gltf's buffers in separate files, from its folder. The JSON goes
    // to stdout: no output file to keep them from.
    let (files, missing) = read_external(path, &name, bytes.as_ref(), &Outputs::default())?;
    progress.step(format!("importing {name}..."));
    let imported = pcpp::pipeline::load_scan_with(bytes.as_ref(), &name, &options, &files)
        .map_err(|e| Failure::Input(missing.explain(in_file(path, &name, &e.to_string()), &e)))?;
    if let Some(cloud) = &imported.cloud {
        progress.note(&cloud.to_string());
    }
    progress.note(&format!(
        "scan: {} triangles",
        thousands(imported.mesh.triangle_count())
    ));
    progress.step("looking for holes...");
    let found = find_fiducials_sized(&imported.mesh, a.dot_diameter);
    progress.finish();
    progress.warn(&imported.warnings);
    print!("{}", to_json(&found)?);
    Ok(())
}

pub fn cmd_register(a: &RegisterArgs, progress: &Progress) -> CliResult<()> {
    let method = a.registration;
    let r = register(&a.scan_points.0, &a.printer_points.0, method)
        .map_err(|e| Failure::Input(format!("registration: {e}")))?;
    let rows = r.matrix_row_major();
    if a.json {
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
    progress.warn(&r.notes);
    // `plan` refuses G-code on a registration this far off (more than the
    // nozzle's inner diameter d): said here too, where it is first seen.
    let d = pcpp::Nozzle::DEFAULT.inner_diameter_mm;
    if r.rms_mm > d {
        progress.warn(&[format!(
            "the fiducials lie {:.3} mm RMS from the printer points, more than the default \
             nozzle's inner diameter d = {d} mm: check the points and their order (plan \
             refuses G-code on this registration unless the risk is accepted)",
            r.rms_mm
        )]);
    }
    Ok(())
}
