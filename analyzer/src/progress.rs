//! Progress bars on the terminal (indicatif): drawn on stderr only when it is a terminal,
//! hidden with `--quiet`.

use std::path::Path;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The container of the bars: hidden when `quiet` (indicatif hides the stderr target by
/// itself when stderr is not a terminal).
#[must_use]
pub fn multi(quiet: bool) -> MultiProgress {
    if quiet {
        MultiProgress::with_draw_target(ProgressDrawTarget::hidden())
    } else {
        MultiProgress::with_draw_target(ProgressDrawTarget::stderr())
    }
}

/// A byte counter for reading `path`.
#[must_use]
pub fn bytes_bar(path: &Path) -> ProgressBar {
    let bar = ProgressBar::no_length();
    let style = ProgressStyle::with_template(
        "{msg:30!} [{bar:40}] {bytes}/{total_bytes} {bytes_per_sec} eta {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    ));
    bar
}

/// A spinner for a named stage (tables, plots, report).
#[must_use]
pub fn stage(multi: &MultiProgress, what: &str) -> ProgressBar {
    let bar = multi.add(ProgressBar::new_spinner());
    bar.set_message(what.to_owned());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}
