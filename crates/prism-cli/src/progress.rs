//! Progress bars: drawn on a terminal with an ETA, silent when piped or `--quiet`.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

/// Seconds left at the average rate since the start: `elapsed x left / done`. Steadier
/// than a recent-rate estimate early in a render, whose first tiles are often the cheap
/// ones (background, sky), so it promises less too soon.
fn eta_seconds(elapsed: f64, done: u64, total: u64) -> Option<f64> {
    (done > 0 && total >= done).then(|| elapsed * (total - done) as f64 / done as f64)
}

/// `1h02m`, `3m07s` or `12s`.
fn clock(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m{:02}s", s / 60, s % 60),
        _ => format!("{}h{:02}m", s / 3600, s % 3600 / 60),
    }
}

fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template)
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ")
        .with_key("eta", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let left = eta_seconds(s.elapsed().as_secs_f64(), s.pos(), s.len().unwrap_or(0));
            let _ = match left {
                Some(t) => write!(w, "{}", clock(t)),
                None => write!(w, "-"),
            };
        })
}

/// A bar over `len` steps labelled `what`; hidden unless stderr is a terminal.
pub fn bar(len: u64, what: &str, quiet: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if quiet || !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        pb.set_draw_target(ProgressDrawTarget::hidden());
    }
    pb.set_style(style("{msg} [{bar:30}] {pos}/{len} ETA {eta}"));
    pb.set_message(what.to_string());
    pb
}

/// A bar over `len` samples showing samples per second and an ETA; hidden unless stderr is
/// a terminal. With adaptive sampling `len` is the most the render may take, so the bar
/// may end early.
pub fn samples_bar(len: u64, quiet: bool) -> ProgressBar {
    let pb = bar(len, "render", quiet);
    pb.set_style(
        style("{msg} [{bar:30}] {percent}% {per_sec} ETA {eta}").with_key(
            "per_sec",
            |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let rate = s.pos() as f64 / s.elapsed().as_secs_f64().max(1e-9);
                let _ = write!(w, "{:.2} Msamples/s", rate / 1e6);
            },
        ),
    );
    pb
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: at a steady rate the estimate is exact; nothing is promised before the
    /// first step.
    #[test]
    fn eta_is_the_average_rate_since_the_start() {
        assert_eq!(eta_seconds(4.0, 34, 100), Some(4.0 * 66.0 / 34.0));
        assert_eq!(eta_seconds(10.0, 100, 100), Some(0.0));
        assert_eq!(eta_seconds(3.0, 0, 100), None);
        assert_eq!(clock(7.4), "7s");
        assert_eq!(clock(187.0), "3m07s");
        assert_eq!(clock(3720.0), "1h02m");
    }
}
