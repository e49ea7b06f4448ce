//! Progress of a long render: a bar on a terminal; plain lines when stderr
//! is a file or a pipe (a render farm's log), at most one every few
//! seconds, with the percentage, the samples per second and the time left.

use crate::preflight::Forecast;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Seconds between plain progress lines; `AIRLIGHT_PROGRESS_SECONDS`
/// changes it.
const DEFAULT_INTERVAL: f64 = 5.0;

/// A run's progress: how it is shown, and the forecast that warns (once)
/// when the run looks endless.
pub struct Progress {
    display: Display,
    forecast: Option<Forecast>,
}

enum Display {
    Hidden,
    Bar(ProgressBar),
    Lines(Lines),
}

pub struct Lines {
    total: u64,
    done: AtomicU64,
    start: Instant,
    interval: Duration,
    /// When the last line was printed, and the message it carries.
    state: Mutex<(Instant, String)>,
}

impl Progress {
    /// Progress over `total` units (pixel samples). Nothing with `quiet`.
    pub fn new(total: u64, quiet: bool) -> Progress {
        Progress { display: Display::new(total, quiet), forecast: None }
    }

    /// The same, also warning when `forecast` projects an endless run.
    pub fn with_forecast(mut self, forecast: Forecast) -> Progress {
        self.forecast = Some(forecast);
        self
    }

    /// `n` more units done (from any thread).
    pub fn inc(&self, n: u64) {
        self.display.inc(n);
        if let Some(warning) = self.forecast.as_ref().and_then(|f| f.advance(n)) {
            self.println(&warning);
        }
    }

    pub fn set_message(&self, message: String) {
        self.display.set_message(message)
    }

    /// Prints a line of its own, above a bar.
    pub fn println(&self, line: &str) {
        match &self.display {
            Display::Bar(bar) => bar.suspend(|| eprintln!("{line}")),
            _ => eprintln!("{line}"),
        }
    }

    pub fn finish(&self) {
        if let Display::Bar(bar) = &self.display {
            bar.finish_and_clear();
        }
    }
}

impl Display {
    fn new(total: u64, quiet: bool) -> Display {
        if quiet {
            return Display::Hidden;
        }
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            if let Ok(style) =
                ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% {elapsed} (eta {eta})")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            return Display::Bar(bar);
        }
        let seconds = std::env::var("AIRLIGHT_PROGRESS_SECONDS")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(DEFAULT_INTERVAL);
        let start = Instant::now();
        Display::Lines(Lines {
            total: total.max(1),
            done: AtomicU64::new(0),
            start,
            interval: Duration::from_secs_f64(seconds),
            state: Mutex::new((start, String::new())),
        })
    }

    fn inc(&self, n: u64) {
        match self {
            Display::Hidden => {}
            Display::Bar(bar) => bar.inc(n),
            Display::Lines(lines) => {
                let done = lines.done.fetch_add(n, Ordering::Relaxed) + n;
                // Another thread printing: this one skips its line.
                if let Ok(mut state) = lines.state.try_lock()
                    && state.0.elapsed() >= lines.interval
                {
                    state.0 = Instant::now();
                    lines.print(done, &state.1);
                }
            }
        }
    }

    fn set_message(&self, message: String) {
        match self {
            Display::Hidden => {}
            Display::Bar(bar) => bar.set_message(message),
            Display::Lines(lines) => {
                if let Ok(mut state) = lines.state.lock() {
                    state.1 = message;
                }
            }
        }
    }
}

impl Lines {
    fn print(&self, done: u64, message: &str) {
        let elapsed = self.start.elapsed().as_secs_f64();
        let rate = done as f64 / elapsed.max(1e-9);
        let left = if rate > 0.0 { (self.total.saturating_sub(done)) as f64 / rate } else { f64::INFINITY };
        eprintln!(
            "airlight: {:5.1}% {message}, {} samples/s, {} left",
            100.0 * done as f64 / self.total as f64,
            si(rate),
            duration(left)
        );
    }
}

/// A rate with an SI prefix: 950, 1.2 k, 3.4 M.
fn si(x: f64) -> String {
    match x {
        x if x >= 1e9 => format!("{:.2} G", x / 1e9),
        x if x >= 1e6 => format!("{:.2} M", x / 1e6),
        x if x >= 1e3 => format!("{:.1} k", x / 1e3),
        x => format!("{x:.0}"),
    }
}

/// Seconds as `1h 02m`, `3m 20s` or `12s`.
fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "unknown time".into();
    }
    let s = seconds.round() as u64;
    match s {
        s if s >= 3600 => format!("{}h {:02}m", s / 3600, s % 3600 / 60),
        s if s >= 60 => format!("{}m {:02}s", s / 60, s % 60),
        s => format!("{s}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_and_times_read_plainly() {
        assert_eq!(si(950.0), "950");
        assert_eq!(si(1234.0), "1.2 k");
        assert_eq!(si(3.456e6), "3.46 M");
        assert_eq!(duration(12.4), "12s");
        assert_eq!(duration(200.0), "3m 20s");
        assert_eq!(duration(3720.0), "1h 02m");
        assert_eq!(duration(f64::INFINITY), "unknown time");
    }
}
