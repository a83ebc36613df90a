//! Progress bars: drawn on a terminal with an ETA, silent when piped or `--quiet`.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar over `len` steps labelled `what`; hidden unless stderr is a terminal.
pub fn bar(len: u64, what: &str, quiet: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if quiet || !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        pb.set_draw_target(ProgressDrawTarget::hidden());
    }
    let style = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ETA {eta}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    pb.set_style(style);
    pb.set_message(what.to_string());
    pb
}

/// A bar over `len` samples showing samples per second and an ETA; hidden unless stderr is
/// a terminal. With adaptive sampling `len` is the most the render may take, so the bar
/// may end early.
pub fn samples_bar(len: u64, quiet: bool) -> ProgressBar {
    let pb = bar(len, "render", quiet);
    let style = ProgressStyle::with_template("{msg} [{bar:30}] {percent}% {per_sec} ETA {eta}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    pb.set_style(style.with_key(
        "per_sec",
        |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{:.2} Msamples/s", s.per_sec() / 1e6);
        },
    ));
    pb
}
