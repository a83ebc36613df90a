//! The rasterizer: a document is prepared into device-space primitives, then rendered in
//! horizontal bands (in parallel, one sample buffer per band) and each band is resolved
//! by a box filter over its samples.
//!
//! Sample `(i, j)` of pixel `(x, y)` at rate `r` (samples = r * r) sits at
//! `(x + (i + 0.5) / r, y + (j + 0.5) / r)`. Samples hold premultiplied RGBA in the
//! document's colour space (stored sRGB values, as SVG composites). Coverage rules:
//! paths and triangles use a top-left rule (a sample on a shared edge belongs to exactly
//! one side); the course's triangles ([`crate::Item::Triangles`], and every triangle in
//! compat mode) count samples on an edge as inside. DDA lines and points are not
//! antialiased: they set every sample of the pixels they touch.
//!
//! Outside compat mode, textures and gradients are shaded once per pixel (at its centre)
//! and the colour is given to every covered sample, as multisampling does; strokes thinner
//! than a pixel are drawn one pixel wide with their opacity scaled by their width.

mod band;
mod edges;
mod offscreen;
mod options;
mod plane;
mod primitives;
mod resolve;

use std::sync::{mpsc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use prism_image::Rgba8Image;
use rayon::prelude::*;

use crate::document::{Document, Item, Mat3};
use band::{Band, Pattern};
pub use options::{
    sample_rate, view_transform, RasterError, RasterOptions, View, MAX_DIMENSION, MAX_SAMPLES,
};
use primitives::prepare;
use primitives::Placed;

/// Wall-clock time spent in each stage of [`render`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RasterStats {
    /// Transforming, flattening and stroking items into device primitives.
    pub prepare: Duration,
    /// Rasterizing samples (band phase, apportioned by thread time).
    pub raster: Duration,
    /// Box-filtering samples into pixels (band phase, apportioned by thread time).
    pub resolve: Duration,
}

/// Renders a document to straight-alpha RGBA8.
///
/// # Errors
/// [`RasterError`] for an output size, sample count or view outside the documented limits.
pub fn render(
    doc: &Document,
    opts: &RasterOptions,
) -> Result<(Rgba8Image, RasterStats), RasterError> {
    check(opts)?;
    let mut pixels = Vec::with_capacity(opts.width as usize * opts.height as usize);
    let stats = render_rows(doc, opts, |rows| {
        pixels.extend_from_slice(rows);
        true
    })?;
    Ok((Rgba8Image::from_vec(opts.width, opts.height, pixels), stats))
}

/// Renders a document to straight-alpha RGBA8 and hands the picture to `sink` on the
/// calling thread, a band of whole rows at a time from the top, while the bands below are
/// still being drawn (so the rows can be written as they come). `sink` returns `false` to
/// stop: the bands not yet drawn are then skipped.
///
/// # Errors
/// [`RasterError`] for an output size, sample count or view outside the documented limits.
pub fn render_rows(
    doc: &Document,
    opts: &RasterOptions,
    sink: impl FnMut(&[[u8; 4]]) -> bool,
) -> Result<RasterStats, RasterError> {
    Ok(Prepared::new(doc, opts)?.render_rows(sink))
}

/// A document turned into device-space primitives for one set of options: everything
/// drawing needs, so the document can be dropped before the picture is drawn.
pub struct Prepared {
    prims: Vec<Placed>,
    opts: RasterOptions,
    rate: usize,
    time: Duration,
}

impl Prepared {
    /// Transforms, flattens and strokes the items of `doc` for `opts`.
    ///
    /// # Errors
    /// [`RasterError`] for an output size, sample count or view outside the documented
    /// limits.
    pub fn new(doc: &Document, opts: &RasterOptions) -> Result<Prepared, RasterError> {
        let rate = check(opts)?;
        let t0 = Instant::now();
        let view = view_transform(doc, opts);
        let prims = prepare(doc, &doc.items, opts, &view, render_premultiplied);
        Ok(Prepared {
            prims,
            opts: opts.clone(),
            rate,
            time: t0.elapsed(),
        })
    }

    /// The options the picture was prepared for.
    #[must_use]
    pub fn options(&self) -> &RasterOptions {
        &self.opts
    }

    /// Draws the picture as [`render_rows`] does, handing rows to `sink` from the top.
    pub fn render_rows(&self, mut sink: impl FnMut(&[[u8; 4]]) -> bool) -> RasterStats {
        let (prims, opts) = (&self.prims, &self.opts);
        let (w, h) = (opts.width, opts.height);
        let t1 = Instant::now();
        let band_rows = band_rows(w);
        let bands = (h as usize).div_ceil(band_rows);
        let pat = Pattern::grid(self.rate);
        let background = background(opts);
        let times = Mutex::new((Duration::ZERO, Duration::ZERO));
        // Planes are reused from band to band.
        let spare: Mutex<Vec<Band>> = Mutex::new(Vec::new());
        let (tx, rx) = mpsc::channel::<(usize, Option<Vec<[u8; 4]>>)>();
        // One job per band. A job that panics still reports (with no rows), so the wait
        // below ends and the scope passes the panic on.
        let draw = |bi: usize, tx: mpsc::Sender<(usize, Option<Vec<[u8; 4]>>)>| {
            let mut report = Report { bi, tx, rows: None };
            let taken = spare.lock().unwrap_or_else(PoisonError::into_inner).pop();
            let mut band = taken.unwrap_or_else(|| Band::new(w as i32, band_rows, pat.clone()));
            let y0 = bi * band_rows;
            let rows_px = band_rows.min(h as usize - y0);
            let ta = Instant::now();
            draw_band(
                &mut band,
                prims,
                opts,
                y0 as i32,
                rows_px as i32,
                background,
            );
            let tb = Instant::now();
            let mut out = vec![[0u8; 4]; rows_px * w as usize];
            band.resolve(&mut out, opts.compat);
            let tc = Instant::now();
            spare
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push(band);
            let mut t = times.lock().unwrap_or_else(PoisonError::into_inner);
            (t.0, t.1) = (t.0 + (tb - ta), t.1 + (tc - tb));
            report.rows = Some(out);
        };
        // Bands are started at most `window` ahead of the next one due, in order, so they
        // finish nearly in order and few wait for the sink, however slow it is.
        let window = 2 * rayon::current_num_threads() + 2;
        rayon::in_place_scope(|s| {
            let mut held: Vec<Option<Vec<[u8; 4]>>> = vec![None; bands];
            let (mut started, mut due) = (0, 0);
            while due < bands {
                while started < bands && started < due + window {
                    let tx = tx.clone();
                    s.spawn(move |_| draw(started, tx));
                    started += 1;
                }
                let Some((bi, Some(rows))) = receive(&rx) else {
                    break;
                };
                held[bi] = Some(rows);
                let mut stop = false;
                while let Some(rows) = held.get_mut(due).and_then(Option::take) {
                    due += 1;
                    if !sink(&rows) {
                        stop = true;
                        break;
                    }
                }
                if stop {
                    break;
                }
            }
        });
        let wall = t1.elapsed();
        let (rt, st) = *times.lock().unwrap_or_else(PoisonError::into_inner);
        let total = (rt + st).as_secs_f64().max(1e-12);
        RasterStats {
            prepare: self.time,
            raster: wall.mul_f64(rt.as_secs_f64() / total),
            resolve: wall.mul_f64(st.as_secs_f64() / total),
        }
    }
}

/// A band's rows on their way to the sink, sent when the job ends, even by a panic
/// (then without rows).
struct Report {
    bi: usize,
    tx: mpsc::Sender<(usize, Option<Vec<[u8; 4]>>)>,
    rows: Option<Vec<[u8; 4]>>,
}

impl Drop for Report {
    fn drop(&mut self) {
        // The receiver is gone only when the sink has stopped: nothing is waiting.
        let _ = self.tx.send((self.bi, self.rows.take()));
    }
}

/// Checks the output size, sample count and view against the documented limits; returns
/// the sample rate (samples per pixel side).
fn check(opts: &RasterOptions) -> Result<usize, RasterError> {
    let (w, h) = (opts.width, opts.height);
    if w == 0 || h == 0 || w > MAX_DIMENSION || h > MAX_DIMENSION {
        return Err(RasterError::BadSize(w, h));
    }
    let r = sample_rate(opts.samples).ok_or(RasterError::BadSamples(opts.samples))? as usize;
    if let View::Region { cx, cy, span } = opts.view {
        if !(cx.is_finite() && cy.is_finite() && span.is_finite() && span > 0.0) {
            return Err(RasterError::BadView(cx, cy, span));
        }
    }
    Ok(r)
}

/// The next message, waiting for it; on a pool thread, running the pool's other work
/// while waiting (so a one-thread pool cannot wait on itself). `None` once every sender
/// has gone.
fn receive<T>(rx: &mpsc::Receiver<T>) -> Option<T> {
    loop {
        match rx.try_recv() {
            Ok(m) => return Some(m),
            Err(mpsc::TryRecvError::Disconnected) => return None,
            Err(mpsc::TryRecvError::Empty) => match rayon::yield_now() {
                None => return rx.recv().ok(),
                Some(rayon::Yield::Executed) => {}
                Some(rayon::Yield::Idle) => match rx.recv_timeout(Duration::from_micros(100)) {
                    Ok(m) => return Some(m),
                    Err(mpsc::RecvTimeoutError::Disconnected) => return None,
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                },
            },
        }
    }
}

/// Pixel rows per band: about 32 KiB of pixel colours per band and per layer (2 rows at
/// 960 pixels), so that a band's split pixels (up to 256 bytes each at 16 samples) stay
/// small beside the rest of the process.
fn band_rows(width: u32) -> usize {
    ((32usize << 10) / (width as usize * 16)).clamp(1, 64)
}

/// The colour every sample starts with.
fn background(opts: &RasterOptions) -> [f32; 4] {
    if opts.compat {
        [1.0, 1.0, 1.0, 1.0]
    } else {
        [0.0; 4]
    }
}

/// Draws the primitives touching pixel rows `[y0, y0 + rows_px)` into `band`.
fn draw_band(
    band: &mut Band,
    prims: &[Placed],
    opts: &RasterOptions,
    y0: i32,
    rows_px: i32,
    background: [f32; 4],
) {
    band.start(y0, rows_px, background);
    for p in prims {
        if p.y1 > y0 && p.y0 < y0 + rows_px {
            band.draw(p, opts.compat);
        }
    }
}

/// Renders `items` of `doc` through `view` into premultiplied pixels of an
/// `opts.width` x `opts.height` image on a transparent background (offscreen layers:
/// pattern tiles and filtered groups).
fn render_premultiplied(
    doc: &Document,
    items: &[Item],
    opts: &RasterOptions,
    view: &Mat3,
) -> Vec<[f32; 4]> {
    let r = sample_rate(opts.samples).unwrap_or(1) as usize;
    let prims = prepare(doc, items, opts, view, render_premultiplied);
    let mut pixels = vec![[0f32; 4]; opts.width as usize * opts.height as usize];
    draw_bands(&prims, opts, r, &mut pixels, |band, out| {
        band.resolve_premultiplied(out);
    });
    pixels
}

/// Draws `prims` band by band in parallel and resolves each band into its rows of `pixels`
/// with `resolve`.
fn draw_bands<T: Send>(
    prims: &[Placed],
    opts: &RasterOptions,
    r: usize,
    pixels: &mut [T],
    resolve: impl Fn(&mut Band, &mut [T]) + Sync,
) {
    let w = opts.width;
    // Regular r x r grid: it agreed better with analytic coverage (resvg) on the test suites
    // than n-rooks patterns did.
    let pat = Pattern::grid(r);
    let band_rows = band_rows(w);
    let background = background(opts);
    pixels
        .par_chunks_mut(band_rows * w as usize)
        .enumerate()
        .for_each_init(
            // Planes are reused from band to band on each thread.
            || Band::new(w as i32, band_rows, pat.clone()),
            |band, (bi, out)| {
                let y0 = (bi * band_rows) as i32;
                let rows_px = (out.len() / w as usize) as i32;
                draw_band(band, prims, opts, y0, rows_px, background);
                resolve(band, out);
            },
        );
}

#[cfg(test)]
mod tests {
    use super::primitives::{dda, radial_t};
    use super::*;
    use crate::document::{FillRule, Item, Mat3, Paint};
    use prism_math::{DVec2, Rgb};

    /// Closed forms: the course's worked example (800x600 canvas shown at 800x600 maps
    /// (x, y) to (0.625 x + 150, 0.625 y + 112.5)) and a zoom region.
    #[test]
    fn view_transforms_closed_form() {
        let doc = Document {
            width: 800.0,
            height: 600.0,
            ..Document::default()
        };
        let course = RasterOptions {
            width: 800,
            height: 600,
            compat: true,
            ..RasterOptions::default()
        };
        let m = view_transform(&doc, &course);
        let p = m.apply(DVec2::new(100.0, 40.0));
        assert!((p - DVec2::new(0.625 * 100.0 + 150.0, 0.625 * 40.0 + 112.5)).length() < 1e-9);
        let zoom = RasterOptions {
            width: 100,
            height: 100,
            view: View::Region {
                cx: 50.0,
                cy: 50.0,
                span: 25.0,
            },
            ..RasterOptions::default()
        };
        let doc = Document {
            width: 100.0,
            height: 100.0,
            ..Document::default()
        };
        let m = view_transform(&doc, &zoom);
        assert!((m.apply(DVec2::new(25.0, 25.0)) - DVec2::ZERO).length() < 1e-9);
        assert!((m.apply(DVec2::new(75.0, 75.0)) - DVec2::splat(100.0)).length() < 1e-9);
        let fit = RasterOptions {
            width: 200,
            height: 50,
            ..RasterOptions::default()
        };
        let m = view_transform(&doc, &fit);
        assert!((m.apply(DVec2::new(100.0, 100.0)) - DVec2::new(200.0, 50.0)).length() < 1e-9);
    }

    #[test]
    fn sample_rates() {
        assert_eq!(sample_rate(1), Some(1));
        assert_eq!(sample_rate(16), Some(4));
        assert_eq!(sample_rate(25), Some(5));
        assert_eq!(sample_rate(8), None);
        assert_eq!(sample_rate(0), None);
        assert_eq!(sample_rate(1024), None);
    }

    /// Course behaviour: a vertical line draws floor(|dy|) + 1 pixels; identical endpoints
    /// draw one pixel.
    #[test]
    fn dda_closed_forms() {
        let mut px = Vec::new();
        let d = DVec2::new;
        dda(d(3.5, 1.2), d(3.5, 6.7), 10, 10, &mut px);
        assert_eq!(px, (1..=6).map(|y| (3, y)).collect::<Vec<_>>());
        px.clear();
        dda(d(2.0, 2.0), d(2.0, 2.0), 10, 10, &mut px);
        assert_eq!(px, vec![(2, 2)]);
        px.clear();
        dda(d(0.0, 0.0), d(4.0, 2.0), 10, 10, &mut px);
        assert_eq!(px, vec![(0, 0), (1, 0), (2, 1), (3, 1), (4, 2)]);
        // Far outside: clipped, bounded work, only in-image pixels kept.
        px.clear();
        dda(d(-1e12, 5.0), d(1e12, 5.0), 10, 10, &mut px);
        assert_eq!(px, (0..10).map(|x| (x, 5)).collect::<Vec<_>>());
        px.clear();
        dda(d(-1e12, -1e12), d(-1e11, 3.0), 10, 10, &mut px);
        assert!(px.is_empty());
    }

    /// A deterministic pseudo-random stream for tests (SplitMix64).
    fn rng(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Property: a mesh of triangles tiling the image (jittered convex quads), with random
    /// diagonals and windings, covers every sample exactly once, both through the triangle rasterizer
    /// (top-left rule) and the path filler. Each triangle is drawn at 50% opacity in its
    /// own layer, so a doubly covered sample would show 75% and a crack 0%.
    #[test]
    fn shared_edges_are_watertight() {
        use crate::path::Path;
        for seed0 in 0..8u64 {
            let mut seed = seed0;
            let n = 7;
            let pts: Vec<Vec<DVec2>> = (0..=n)
                .map(|j| {
                    (0..=n)
                        .map(|i| {
                            let edge = |k: usize| k == 0 || k == n;
                            let jx = if edge(i) { 0.0 } else { rng(&mut seed) - 0.5 };
                            let jy = if edge(j) { 0.0 } else { rng(&mut seed) - 0.5 };
                            // Snapped to 1/8: samples then fall exactly on edges and
                            // vertices, so the tie-breaking rule is what is tested.
                            let snap = |v: f64| (v * 8.0).round() / 8.0;
                            DVec2::new(
                                snap(-4.0 + (i as f64 + jx * 0.4) * 48.0 / n as f64),
                                snap(-4.0 + (j as f64 + jy * 0.4) * 48.0 / n as f64),
                            )
                        })
                        .collect()
                })
                .collect();
            let mut tris = Vec::new();
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (pts[j][i], pts[j][i + 1], pts[j + 1][i + 1], pts[j + 1][i]);
                    let pair = if rng(&mut seed) < 0.5 {
                        [[a, b, c], [a, c, d]]
                    } else {
                        [[a, b, d], [b, c, d]]
                    };
                    for mut t in pair {
                        if rng(&mut seed) < 0.5 {
                            t.swap(1, 2);
                        }
                        tris.push(t);
                    }
                }
            }
            for as_path in [false, true] {
                let mut doc = Document {
                    width: 40.0,
                    height: 40.0,
                    ..Document::default()
                };
                for t in &tris {
                    doc.items.push(Item::BeginLayer);
                    doc.items.push(if as_path {
                        Item::Fill {
                            path: Path::polygon(t, true),
                            transform: Mat3::IDENTITY,
                            rule: FillRule::NonZero,
                            paint: Paint::Solid(Rgb::new(1.0, 0.0, 0.0)),
                            opacity: 1.0,
                        }
                    } else {
                        Item::ColorTri {
                            points: *t,
                            colors: [Rgb::new(1.0, 0.0, 0.0); 3],
                            transform: Mat3::IDENTITY,
                        }
                    });
                    doc.items.push(Item::EndLayer {
                        opacity: 0.5,
                        blend: crate::BlendMode::Normal,
                    });
                }
                for samples in [1, 16] {
                    let opts = RasterOptions {
                        width: 40,
                        height: 40,
                        samples,
                        ..RasterOptions::default()
                    };
                    let (img, _) = render(&doc, &opts).unwrap();
                    for (k, p) in img.pixels().iter().enumerate() {
                        assert_eq!(
                            p[3], 128,
                            "seed {seed0} path {as_path} spp {samples} pixel {k}: {p:?}"
                        );
                    }
                }
            }
        }
    }

    /// Regression (found by fuzzing): coordinates near the f64 range render without panics.
    #[test]
    fn huge_coordinates_do_not_panic() {
        use crate::{parse_svg, Dialect, Source};
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">
            <rect width="1e38" height="1e38" fill="red"/>
            <polygon points="0,0 1e38,5 5,1e38" fill="blue" stroke="green"/>
            <line x1="-1e38" y1="0" x2="1e38" y2="9" stroke="black"/>
            <colortri points="0 0 1e38 0 0 1e38" colors="1 0 0 1 0 1 0 1 0 0 1 1"/>
            <path d="M0 0 C1e38 0 0 1e38 5 5 Z" stroke="red" stroke-width="1e38"/></svg>"#;
        for dialect in [Dialect::Svg, Dialect::Cs184] {
            let doc = parse_svg(svg, dialect, &Source::default()).unwrap();
            let opts = RasterOptions {
                width: 16,
                height: 16,
                samples: 4,
                compat: dialect == Dialect::Cs184,
                ..RasterOptions::default()
            };
            render(&doc, &opts).unwrap();
        }
    }

    /// A drawing with layers, translucency, a gradient and an image-free mix of shapes.
    fn busy_drawing() -> Document {
        use crate::{parse_svg, Dialect, Source};
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="120" height="90">
            <defs><linearGradient id="g"><stop offset="0" stop-color="#f60"/>
            <stop offset="1" stop-color="#06f" stop-opacity="0.5"/></linearGradient></defs>
            <rect width="120" height="90" fill="#fff"/>
            <circle cx="40" cy="40" r="33" fill="url(#g)" stroke="#222" stroke-width="3"/>
            <g opacity="0.6"><path d="M10 80 L110 5 L100 85 Z" fill="#3a3"/>
            <ellipse cx="80" cy="50" rx="30" ry="12" fill="#c0c" stroke="#000"/></g>
            </svg>"##;
        parse_svg(svg, Dialect::Svg, &Source::default()).unwrap()
    }

    /// `render_rows` hands on every row once, top to bottom, the same pixels as `render`;
    /// a sink that stops is given no more rows.
    #[test]
    fn rows_come_in_order_and_stop_when_asked() {
        let doc = busy_drawing();
        let opts = RasterOptions {
            width: 120,
            height: 90,
            samples: 16,
            ..RasterOptions::default()
        };
        let (img, _) = render(&doc, &opts).unwrap();
        let mut rows: Vec<[u8; 4]> = Vec::new();
        let mut calls = 0;
        render_rows(&doc, &opts, |band| {
            assert_eq!(band.len() % 120, 0, "whole rows");
            rows.extend_from_slice(band);
            calls += 1;
            true
        })
        .unwrap();
        assert_eq!(rows, img.pixels());
        assert!(calls > 1, "the picture comes in several bands");
        let mut given = 0;
        render_rows(&doc, &opts, |band| {
            given += band.len();
            false
        })
        .unwrap();
        assert_eq!(
            given,
            band_rows(120).min(90) * 120,
            "one band, then nothing"
        );
    }

    /// A prepared picture needs nothing of its document: drawn after the document is
    /// dropped, and drawn twice, it gives `render`'s pixels.
    #[test]
    fn a_prepared_picture_outlives_its_document() {
        let opts = RasterOptions {
            width: 120,
            height: 90,
            samples: 4,
            ..RasterOptions::default()
        };
        let (img, _) = render(&busy_drawing(), &opts).unwrap();
        let doc = busy_drawing();
        let prepared = Prepared::new(&doc, &opts).unwrap();
        drop(doc);
        for _ in 0..2 {
            let mut rows: Vec<[u8; 4]> = Vec::new();
            prepared.render_rows(|band| {
                rows.extend_from_slice(band);
                true
            });
            assert_eq!(rows, img.pixels());
        }
    }

    /// Same bytes whatever the thread count (one, two or three workers).
    #[test]
    fn same_pixels_on_one_two_and_three_threads() {
        let doc = busy_drawing();
        let opts = RasterOptions {
            width: 120,
            height: 90,
            samples: 9,
            ..RasterOptions::default()
        };
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&doc, &opts).unwrap().0)
        };
        let one = on(1);
        assert_eq!(one, on(2));
        assert_eq!(one, on(3));
    }

    /// A size over the limit is refused before anything is allocated for it.
    #[test]
    fn an_oversized_picture_is_refused_before_allocation() {
        let opts = RasterOptions {
            width: 1_000_000,
            height: 1_000_000,
            ..RasterOptions::default()
        };
        let doc = Document::default();
        assert!(matches!(render(&doc, &opts), Err(RasterError::BadSize(..))));
        assert!(matches!(
            render_rows(&doc, &opts, |_| true),
            Err(RasterError::BadSize(..))
        ));
    }

    #[test]
    fn radial_t_is_distance_ratio_for_centred_focus() {
        let c = DVec2::new(5.0, 5.0);
        assert!((radial_t(DVec2::new(8.0, 5.0), c, 6.0, c) - 0.5).abs() < 1e-12);
        assert!((radial_t(c, c, 6.0, c)).abs() < 1e-12);
    }
}
