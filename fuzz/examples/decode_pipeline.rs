//! Turns a `pipeline` fuzz input back into files and settings:
//! `cargo run --example decode_pipeline -- INPUT OUTDIR` writes OUTDIR/scan.EXT
//! and OUTDIR/path.svg, prints the settings and runs the case.

use std::{env, fs, path::Path, process::ExitCode};

fn main() -> ExitCode {
    let args: Vec<String> = env::args().skip(1).collect();
    let [input, out] = args.as_slice() else {
        eprintln!("usage: decode_pipeline INPUT OUTDIR");
        return ExitCode::from(2);
    };
    let data = match fs::read(input) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{input}: {e}");
            return ExitCode::from(2);
        }
    };
    let case = pcpp_fuzz::decode(&data);
    let out = Path::new(out);
    let ext = case.scan_name.rsplit('.').next().unwrap_or("bin");
    let written = fs::create_dir_all(out)
        .and_then(|()| fs::write(out.join(format!("scan.{ext}")), case.scan))
        .and_then(|()| fs::write(out.join("path.svg"), case.svg));
    if let Err(e) = written {
        eprintln!("{}: {e}", out.display());
        return ExitCode::from(2);
    }
    println!("scan: {} ({} bytes)", case.scan_name, case.scan.len());
    println!("svg: {} bytes", case.svg.len());
    println!("registration: {:?}", case.registration);
    println!("settings: {:?}", case.settings);
    println!("accept_risk: {}", case.accept_risk);
    match pcpp_fuzz::run(&case) {
        Ok(g) => println!("ok: {} bytes of G-code", g.len()),
        Err(e) => println!("error: {e}"),
    }
    ExitCode::SUCCESS
}
