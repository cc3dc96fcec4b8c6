//! Progress bars on stderr (indicatif), shown only when stderr is a terminal.

use std::io::IsTerminal as _;
use std::sync::Mutex;

use indicatif::{ProgressBar, ProgressStyle};
use sfmeval::progress::{Progress, Stage};

/// Shows one bar per stage.
pub struct Bars {
    current: Mutex<Option<ProgressBar>>,
    enabled: bool,
}

impl Bars {
    /// Bars when stderr is a terminal and not quiet.
    pub fn new(quiet: bool) -> Self {
        Bars {
            current: Mutex::new(None),
            enabled: !quiet && std::io::stderr().is_terminal(),
        }
    }
}

impl Progress for Bars {
    fn start(&self, stage: Stage, total: u64) {
        if !self.enabled {
            return;
        }
        let bar = ProgressBar::new(total);
        if let Ok(style) = ProgressStyle::with_template("{msg:28} [{bar:30}] {pos}/{len} ({eta})") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(stage.label());
        if let Ok(mut c) = self.current.lock() {
            *c = Some(bar);
        }
    }

    fn advance(&self, n: u64) {
        if let Some(b) = self.current.lock().ok().as_ref().and_then(|c| c.as_ref()) {
            b.inc(n);
        }
    }

    fn finish(&self) {
        if let Some(b) = self.current.lock().ok().and_then(|mut c| c.take()) {
            b.finish_and_clear();
        }
    }
}
