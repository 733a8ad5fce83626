//! `pcpp`, the command-line tool: a thin adapter over the planning core.
//!
//! It parses arguments (clap, `args.rs`), reads files, calls [`pcpp::job`]
//! (the same entry the browser page calls, so both write identical G-code
//! for the same inputs), writes files and maps errors to exit codes: 0
//! success, 1 bad input (the message names the file and the line, element
//! or point), 2 usage error (the message names the flag). Outputs are
//! written to a temporary file in the same folder and renamed only once
//! everything succeeded, so a failed run leaves no partial file behind.
//!
//! `args.rs` declares the commands and flags, `values.rs` parses the flags'
//! values, `settings.rs` turns them into the library's settings; one module
//! per command (`plan.rs` holds `plan` and `compare`, which share reading
//! the inputs; `fiducials.rs` holds `fiducials` and `register`); `files.rs`
//! reads and writes, `outputs.rs` checks the outputs before anything is
//! read (not an input, not each other, in a folder that exists),
//! `progress.rs` draws progress on a terminal.
//!
//! The CLI is native only: on wasm32 (built there only because the
//! integration tests name the binary) it is an empty `main`, and its
//! dependencies (clap, clap_complete, indicatif) are native-only.

#[cfg(target_os = "linux")]
mod alloc;
#[cfg(not(target_arch = "wasm32"))]
mod args;
#[cfg(not(target_arch = "wasm32"))]
mod check;
#[cfg(not(target_arch = "wasm32"))]
mod demo;
#[cfg(not(target_arch = "wasm32"))]
mod fiducials;
#[cfg(not(target_arch = "wasm32"))]
mod files;
#[cfg(not(target_arch = "wasm32"))]
mod outputs;
#[cfg(not(target_arch = "wasm32"))]
mod plan;
#[cfg(not(target_arch = "wasm32"))]
mod progress;
#[cfg(not(target_arch = "wasm32"))]
mod settings;
#[cfg(not(target_arch = "wasm32"))]
mod values;

#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: alloc::HugePages = alloc::HugePages;

#[cfg(not(target_arch = "wasm32"))]
use native::{usage, CliResult, Failure, VERSION};

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    native::run()
}

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use std::process::ExitCode;

    use clap::error::ErrorKind;
    use clap::{CommandFactory, Parser};

    use crate::args::{Cli, Command};
    use crate::progress::Progress;

    pub const VERSION: &str = env!("CARGO_PKG_VERSION");

    /// Why the tool stops: a usage error (exit 2, clap's message naming the
    /// flag and the command's usage) or bad input (exit 1).
    #[derive(Debug)]
    pub enum Failure {
        Usage(Box<clap::Error>),
        Input(String),
    }

    pub type CliResult<T> = Result<T, Failure>;

    /// A usage error found after parsing (a value out of range, two flags
    /// that exclude each other), worded and shown as clap's own.
    pub fn usage(command: &str, message: impl std::fmt::Display) -> Failure {
        let mut cli = Cli::command();
        cli.build();
        let error = match cli.find_subcommand_mut(command) {
            Some(sub) => sub.error(ErrorKind::ValueValidation, message),
            None => cli.error(ErrorKind::ValueValidation, message),
        };
        Failure::Usage(Box::new(error))
    }

    pub fn run() -> ExitCode {
        // A reader that stops early (`pcpp fiducials ... | head -1`) ends
        // this command as it ends any Unix tool, by SIGPIPE, instead of a
        // panic in println! (Rust ignores SIGPIPE by default). Output files
        // are renamed into place before anything is printed about them.
        #[cfg(target_os = "linux")]
        // SAFETY: sets the default disposition of one signal at the start
        // of main, before any thread is spawned.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
        // Help and version (exit 0, stdout) and usage errors (exit 2,
        // stderr) are clap's.
        let cli = Cli::parse();
        let progress = Progress::new(cli.quiet);
        let result = match &cli.command {
            None => Err(Failure::Usage(Box::new(Cli::command().error(
                ErrorKind::MissingSubcommand,
                "no command given; run 'pcpp help' for the commands",
            )))),
            Some(Command::Plan(a)) => crate::plan::cmd_plan(a, &progress),
            Some(Command::Compare(a)) => crate::plan::cmd_compare(a, &progress),
            Some(Command::Check(a)) => crate::check::cmd_check(a, &progress),
            Some(Command::Fiducials(a)) => crate::fiducials::cmd_fiducials(a, &progress),
            Some(Command::Register(a)) => crate::fiducials::cmd_register(a, &progress),
            Some(Command::Demo(a)) => crate::demo::cmd_demo(a, &progress),
            Some(Command::Completions { shell }) => {
                clap_complete::generate(
                    *shell,
                    &mut Cli::command(),
                    "pcpp",
                    &mut std::io::stdout(),
                );
                Ok(())
            }
        };
        drop(progress);
        match result {
            Ok(()) => ExitCode::SUCCESS,
            Err(Failure::Usage(e)) => {
                let _ = e.print();
                ExitCode::from(2)
            }
            Err(Failure::Input(message)) => {
                eprintln!("error: {message}");
                ExitCode::from(1)
            }
        }
    }
}
