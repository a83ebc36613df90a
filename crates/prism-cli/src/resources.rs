//! The resources a command may take: `--max-memory` (the memory budget every reader and
//! film checks) and the worker thread pool (`-t`, clamped to a sane maximum).

use anyhow::{Context, Result};

use crate::error::UserError;

/// Parses a byte count: a whole number with an optional unit, `K`, `M`, `G` or `T` (binary
/// multiples, with or without `iB`/`B`), as `--max-memory 4G` or `--max-memory 512MiB`.
pub fn parse_bytes(s: &str) -> std::result::Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (digits, unit) = t.split_at(split);
    let shift = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => u32::MAX,
    };
    let value = digits.parse::<u64>().ok();
    match value.and_then(|v| v.checked_mul(1u64.checked_shl(shift)?)) {
        Some(bytes) if bytes >= prism_math::limits::MIN_MEMORY_BUDGET => Ok(bytes),
        _ => Err(format!(
            "expected a size of at least 64M, such as 4G, 512M or 8GiB; found `{s}`"
        )),
    }
}

/// Checks `bytes`, what a film or frame of `width x height` will hold, against the memory
/// budget before it is allocated; `flag` names the option that set the size.
pub fn check_frame(flag: &str, width: u32, height: u32, bytes: u64) -> Result<()> {
    prism_math::limits::check_memory(bytes)
        .map_err(|e| UserError::Refused(format!("{flag} {width} {height}: the image {e}")).into())
}

/// A worker pool of `threads` threads (default: one per core), at least 1 and at most
/// four a core (at least 16), with a warning when clamped.
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    builder(threads).build().context("starting worker threads")
}

/// A pool builder of `threads` threads as [`pool`] counts them, warning when clamped.
fn builder(threads: Option<usize>) -> rayon::ThreadPoolBuilder {
    let b = rayon::ThreadPoolBuilder::new();
    let Some(t) = threads else { return b };
    let most = prism_math::limits::max_threads();
    if t > most {
        eprintln!("prism: warning: --threads {t}: more than four a core; using {most} threads");
    }
    b.num_threads(t.clamp(1, most))
}

/// Sets the global worker pool to `threads` threads as [`pool`] counts them, for a command
/// whose work must start on the main thread (the window's event loop).
pub fn global_pool(threads: Option<usize>) -> Result<()> {
    if threads.is_none() {
        return Ok(());
    }
    builder(threads)
        .build_global()
        .context("starting worker threads")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: units are binary multiples; sizes under 64 MiB and unknown units are
    /// refused.
    #[test]
    fn sizes_parse() {
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("512MiB"), Ok(512 << 20));
        assert_eq!(parse_bytes("1t"), Ok(1 << 40));
        assert_eq!(parse_bytes("67108864"), Ok(64 << 20));
        for bad in ["", "12", "4X", "G", "-1G", "99999999999T"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }
}
