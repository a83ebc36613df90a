//! The font database text is set with: the system's fonts and any directories given, with
//! the generic families mapped as asked; built once per set of options and shared.

use std::sync::{Arc, Mutex};

use usvg::fontdb::Database;

use super::common::SvgError;
use super::context::Fonts;

/// The database for `fonts`, built on first use and reused while the options stay the same.
///
/// # Errors
/// [`SvgError::FontDir`] for a font directory that cannot be read.
pub(crate) fn font_database(fonts: &Fonts) -> Result<Arc<Database>, SvgError> {
    static CACHE: Mutex<Option<(Fonts, Arc<Database>)>> = Mutex::new(None);
    let mut cache = CACHE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((key, db)) = cache.as_ref() {
        if key == fonts {
            return Ok(db.clone());
        }
    }
    let mut db = Database::new();
    if !fonts.skip_system {
        db.load_system_fonts();
    }
    for dir in &fonts.dirs {
        if let Err(e) = std::fs::read_dir(dir) {
            return Err(SvgError::FontDir {
                dir: dir.display().to_string(),
                source: Arc::new(e),
            });
        }
        db.load_fonts_dir(dir);
    }
    if let Some(f) = &fonts.serif {
        db.set_serif_family(f.clone());
    }
    if let Some(f) = &fonts.sans_serif {
        db.set_sans_serif_family(f.clone());
    }
    if let Some(f) = &fonts.monospace {
        db.set_monospace_family(f.clone());
    }
    if let Some(f) = &fonts.cursive {
        db.set_cursive_family(f.clone());
    }
    if let Some(f) = &fonts.fantasy {
        db.set_fantasy_family(f.clone());
    }
    let db = Arc::new(db);
    *cache = Some((fonts.clone(), db.clone()));
    Ok(db)
}
