//! Progress on stderr, for a person watching a terminal: an indicatif
//! spinner naming the step under way, drawn once a step has taken
//! [`SHOW_AFTER`] (reading and meshing a big scan, comparing the planners,
//! planning a big raster), and the results of finished steps ("scan:
//! 2,000,000 triangles") as lines above it. Nothing of it when stderr is not
//! a terminal or with `--quiet`: then stderr carries only warnings and the
//! error, which scripts and tests read.

use std::borrow::Cow;
use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Steps quicker than this draw nothing (no flicker on small jobs).
pub const SHOW_AFTER: Duration = Duration::from_secs(1);
const TICK: Duration = Duration::from_millis(100);

/// At most this many warnings of one list are printed.
pub const WARNINGS_SHOWN: usize = 25;

pub struct Progress {
    /// `None` when nobody is watching.
    bar: Option<ProgressBar>,
}

impl Progress {
    pub fn new(quiet: bool) -> Self {
        if quiet || !std::io::stderr().is_terminal() {
            return Progress { bar: None };
        }
        // Hidden until a step has run SHOW_AFTER; a ticker thread shows it
        // then and turns the spinner. It ends with the bar.
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
            bar.set_style(style);
        }
        let weak = bar.downgrade();
        std::thread::spawn(move || loop {
            std::thread::sleep(TICK);
            let Some(bar) = weak.upgrade() else { break };
            if bar.is_finished() {
                break;
            }
            if bar.is_hidden() && bar.elapsed() >= SHOW_AFTER {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.tick();
        });
        Progress { bar: Some(bar) }
    }

    /// A step begins ("reading scan big.ply..."): the spinner's message.
    pub fn step(&self, message: impl Into<Cow<'static, str>>) {
        if let Some(bar) = &self.bar {
            bar.reset_elapsed();
            bar.set_message(message);
        }
    }

    /// What a finished step found, as a line above the spinner.
    pub fn note(&self, line: &str) {
        if let Some(bar) = &self.bar {
            bar.suspend(|| eprintln!("{line}"));
        }
    }

    /// Warnings for the user, printed above the spinner if it shows: the
    /// first [`WARNINGS_SHOWN`] of them when there are more (a large PCB
    /// drawing on a part gave 117 lines), then how many more there are
    /// (the report keeps them all).
    pub fn warn(&self, warnings: &[String]) {
        let print = || {
            for w in warnings.iter().take(WARNINGS_SHOWN) {
                eprintln!("warning: {w}");
            }
            if warnings.len() > WARNINGS_SHOWN {
                eprintln!(
                    "warning: ... and {} more warning(s), not shown; --report FILE.json \
                     writes them all",
                    warnings.len() - WARNINGS_SHOWN
                );
            }
        };
        match &self.bar {
            Some(bar) => bar.suspend(print),
            None => print(),
        }
    }

    /// Clears the spinner before the results are printed.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

/// 2000000 -> "2,000,000".
pub fn thousands(n: usize) -> String {
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
    fn quiet_progress_draws_nothing() {
        let p = Progress::new(true);
        assert!(p.bar.is_none());
        p.step("a step");
        p.note("a note");
        p.finish();
    }
}
