//! usvg's warnings (it reports through the `log` crate what it reads past), caught on the
//! reading thread while it reads a document, to become the document's warnings.

use std::cell::RefCell;
use std::sync::Once;

thread_local! {
    static CAUGHT: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
}

struct Catcher;

static CATCHER: Catcher = Catcher;

impl log::Log for Catcher {
    fn enabled(&self, meta: &log::Metadata) -> bool {
        meta.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            CAUGHT.with(|c| {
                if let Some(v) = c.borrow_mut().as_mut() {
                    let m = record.args().to_string();
                    if !v.contains(&m) {
                        v.push(m);
                    }
                }
            });
        }
    }

    fn flush(&self) {}
}

/// Runs `f`, returning what it returns and the distinct warnings logged on this thread
/// meanwhile (none when the program installed a logger of its own).
pub(crate) fn catching<T>(f: impl FnOnce() -> T) -> (T, Vec<String>) {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        if log::set_logger(&CATCHER).is_ok() {
            log::set_max_level(log::LevelFilter::Warn);
        }
    });
    CAUGHT.with(|c| *c.borrow_mut() = Some(Vec::new()));
    let out = f();
    let caught = CAUGHT.with(|c| c.borrow_mut().take().unwrap_or_default());
    (out, caught)
}
