//! The gallery's index: each picture's [`Entry`], and index.html, which shows them all with
//! their captions.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

/// One picture of the gallery.
pub struct Entry {
    /// Its file, in the gallery folder.
    pub file: String,
    /// What it shows.
    pub caption: String,
}

/// Writes `output`/index.html, every entry in order.
pub fn write_index(output: &Path, entries: &[Entry]) -> Result<()> {
    let mut html = String::from(
        "<!doctype html><meta charset=\"utf-8\"><title>prism gallery</title>\
         <style>body{font-family:sans-serif;background:#eee}figure{display:inline-block;margin:8px;background:#fff;padding:8px}\
         img{max-width:100%}</style><h1>prism gallery</h1>",
    );
    for e in entries {
        let _ = write!(
            html,
            "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
            e.file, e.caption, e.caption
        );
    }
    prism_image::write_atomic(&output.join("index.html"), |w| {
        std::io::Write::write_all(w, html.as_bytes()).map_err(|source| {
            prism_image::ImageError::Io {
                path: output.join("index.html"),
                source,
            }
        })
    })?;
    Ok(())
}
