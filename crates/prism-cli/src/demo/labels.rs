//! Labels on the gallery's grids: each panel's name in its top-left corner, on a dark band
//! so that it reads over any picture.

use prism_image::Rgb8Image;

/// Writes `labels[i]` on panel `i` of a montage of `cols` columns of `panel_w x panel_h`
/// panels, in the viewer's 8x8 font.
pub fn label_panels(img: &mut Rgb8Image, panel_w: u32, panel_h: u32, cols: usize, labels: &[&str]) {
    let fits = ((panel_w.saturating_sub(6)) / prism_view::GLYPH).max(1) as usize;
    for (i, text) in labels.iter().enumerate() {
        let (x0, y0) = ((i % cols) as u32 * panel_w, (i / cols) as u32 * panel_h);
        // A label wider than its panel goes on as many rows as it needs.
        let chars: Vec<char> = text.chars().collect();
        let rows: Vec<String> = chars.chunks(fits).map(|c| c.iter().collect()).collect();
        let longest = rows.iter().map(|r| r.chars().count()).max().unwrap_or(0) as u32;
        let (width, height) = (
            longest * prism_view::GLYPH + 6,
            rows.len() as u32 * (prism_view::GLYPH + 2) + 4,
        );
        for y in y0..(y0 + height).min(img.height()) {
            for x in x0..(x0 + width).min(img.width()) {
                let p = img.get(x, y);
                img.set(x, y, p.map(|c| c / 3));
            }
        }
        for (r, row) in rows.iter().enumerate() {
            let y = i64::from(y0) + 3 + r as i64 * i64::from(prism_view::GLYPH + 2);
            prism_view::draw_text(img, i64::from(x0) + 3, y, row, 1, [255, 255, 255]);
        }
    }
}
