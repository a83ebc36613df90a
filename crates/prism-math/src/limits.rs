//! Resource limits every reader shares: the process's memory budget (and one image's share of
//! it), checked before a size read from an input is allocated, and reading an input only if
//! it is a regular file within a size limit.

use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The memory budget of a process unless raised (`--max-memory`): 2 GiB.
pub const DEFAULT_MEMORY_BUDGET: u64 = 2 << 30;

/// The smallest memory budget that may be set: 64 MiB.
pub const MIN_MEMORY_BUDGET: u64 = 64 << 20;

static MEMORY_BUDGET: AtomicU64 = AtomicU64::new(DEFAULT_MEMORY_BUDGET);

/// Sets the process's memory budget in bytes (at least [`MIN_MEMORY_BUDGET`]); one image's
/// budget is a quarter of it.
pub fn set_memory_budget(bytes: u64) {
    MEMORY_BUDGET.store(bytes.max(MIN_MEMORY_BUDGET), Ordering::Relaxed);
}

/// The most worker threads a call starts: four a core, at least 16 (more only crowd the
/// machine; a hostile `-t` or `threads=` asking for millions is clamped to this).
#[must_use]
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    (4 * cores).max(16)
}

/// The process's memory budget in bytes: what one buffer sized by an input (a film, a frame,
/// a window's pixels) may take.
#[must_use]
pub fn memory_budget() -> u64 {
    MEMORY_BUDGET.load(Ordering::Relaxed)
}

/// One decoded image's budget in bytes: a quarter of the memory budget (512 MiB unless
/// raised, an 8192x4096 RGBA float map), as a scene may hold several textures.
#[must_use]
pub fn image_budget() -> u64 {
    memory_budget() / 4
}

/// A request for memory over a budget: what was asked and what the budget allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverBudget {
    /// Bytes the request needs.
    pub bytes: u64,
    /// The budget it exceeds.
    pub budget: u64,
}

impl std::fmt::Display for OverBudget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "needs {} of memory, over the budget of {} (--max-memory raises it)",
            format_bytes(self.bytes),
            format_bytes(self.budget)
        )
    }
}

impl std::error::Error for OverBudget {}

/// Checks `bytes` against the process's memory budget.
///
/// # Errors
/// [`OverBudget`] if it is larger.
pub fn check_memory(bytes: u64) -> Result<(), OverBudget> {
    check(bytes, memory_budget())
}

/// Checks `bytes` against one image's budget.
///
/// # Errors
/// [`OverBudget`] if it is larger.
pub fn check_image_memory(bytes: u64) -> Result<(), OverBudget> {
    check(bytes, image_budget())
}

fn check(bytes: u64, budget: u64) -> Result<(), OverBudget> {
    if bytes > budget {
        Err(OverBudget { bytes, budget })
    } else {
        Ok(())
    }
}

/// A byte count for people: `512 B`, `3.4 KiB`, `256 MiB`, `8.5 GiB`.
#[must_use]
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    // One decimal, left out when it is 0 or the value is 100 or more.
    let tenths = (value * 10.0).round() / 10.0;
    if tenths.fract() == 0.0 || value >= 100.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else {
        format!("{tenths:.1} {}", UNITS[unit])
    }
}

/// Why an input file was not read, beside the operating system's own errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputRefused {
    /// The path names a folder, a device, a FIFO or a socket.
    NotAFile,
    /// The file is larger than the reader's limit.
    TooLarge {
        /// Its size in bytes.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
}

impl std::fmt::Display for InputRefused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InputRefused::NotAFile => {
                f.write_str("not a regular file (only regular files are read)")
            }
            InputRefused::TooLarge { bytes, limit } => write!(
                f,
                "the file holds {}, over the limit of {} for this kind of file",
                format_bytes(*bytes),
                format_bytes(*limit)
            ),
        }
    }
}

impl std::error::Error for InputRefused {}

/// Reads a whole input file if it is a regular file of at most `limit` bytes; a device, a
/// FIFO, a socket or a folder is refused without being opened (a FIFO would block), and
/// the size is checked before reading and again while reading (a file that grows).
///
/// # Errors
/// The operating system's error, or an [`std::io::ErrorKind::InvalidInput`] error holding
/// an [`InputRefused`].
pub fn read_input(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let refused = |why| std::io::Error::new(std::io::ErrorKind::InvalidInput, why);
    let file = open_input(path)?;
    let meta = file.metadata()?;
    if meta.len() > limit {
        return Err(refused(InputRefused::TooLarge {
            bytes: meta.len(),
            limit,
        }));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(refused(InputRefused::TooLarge {
            bytes: bytes.len() as u64,
            limit,
        }));
    }
    Ok(bytes)
}

/// Opens an input file to read in pieces, if it is a regular file; anything else is refused
/// as [`read_input`] refuses it.
///
/// # Errors
/// The operating system's error, or an [`std::io::ErrorKind::InvalidInput`] error holding
/// [`InputRefused::NotAFile`].
pub fn open_input(path: &Path) -> std::io::Result<std::fs::File> {
    let refused = || std::io::Error::new(std::io::ErrorKind::InvalidInput, InputRefused::NotAFile);
    if !std::fs::metadata(path)?.is_file() {
        return Err(refused());
    }
    let file = std::fs::File::open(path)?;
    if !file.metadata()?.is_file() {
        return Err(refused());
    }
    Ok(file)
}

/// Reads a whole input text file as [`read_input`] does; bytes that are not UTF-8 are an
/// [`std::io::ErrorKind::InvalidData`] error.
///
/// # Errors
/// As [`read_input`], or invalid UTF-8.
pub fn read_input_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_input(path, limit)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal(e: &std::io::Error) -> Option<InputRefused> {
        e.get_ref()?.downcast_ref::<InputRefused>().copied()
    }

    /// Devices, folders and files over the limit are refused before reading; a FIFO is
    /// refused without blocking; a regular file within the limit reads whole.
    #[test]
    fn only_regular_files_within_the_limit_are_read() {
        let dev = read_input(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert_eq!(refusal(&dev), Some(InputRefused::NotAFile));
        let dir = read_input(Path::new("/"), 1 << 20).unwrap_err();
        assert_eq!(refusal(&dir), Some(InputRefused::NotAFile));
        let tmp = std::env::temp_dir().join(format!("prism-limits-{}", std::process::id()));
        std::fs::create_dir_all(&tmp).unwrap();
        let file = tmp.join("ten.txt");
        std::fs::write(&file, b"0123456789").unwrap();
        assert_eq!(read_input(&file, 10).unwrap(), b"0123456789");
        let big = read_input(&file, 9).unwrap_err();
        assert_eq!(
            refusal(&big),
            Some(InputRefused::TooLarge {
                bytes: 10,
                limit: 9
            })
        );
        let fifo = tmp.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = read_input(&fifo, 10).unwrap_err();
            assert_eq!(refusal(&e), Some(InputRefused::NotAFile));
        }
        std::fs::remove_dir_all(&tmp).unwrap();
    }

    /// Closed forms: the image budget is a quarter of the memory budget; sizes print in
    /// binary units.
    #[test]
    fn budgets_and_sizes() {
        assert_eq!(image_budget(), 512 << 20);
        assert!(check(10, 10).is_ok());
        assert_eq!(
            check(11, 10),
            Err(OverBudget {
                bytes: 11,
                budget: 10
            })
        );
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(format_bytes(256 << 20), "256 MiB");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
        assert_eq!(format_bytes((2 << 30) - (1 << 16)), "2 GiB");
        assert_eq!(format_bytes(u64::MAX), "16384 PiB");
    }
}
