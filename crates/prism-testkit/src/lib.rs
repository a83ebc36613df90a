//! Test helpers shared by prism's crates: golden-image comparison that explains itself, a
//! per-pixel Z-test of a render against a reference, and
//! scratch folders that tidy up after passing tests.
//!
//! [`compare_golden`] decodes both PNGs, reports the identical-pixel fraction and the largest
//! channel error, and on failure writes an `expected | diff | actual` triptych under
//! `target/test-diffs/`. With `MAKE_REF=1` in the environment, references the project owns
//! are (re)written instead of compared.
#![warn(missing_docs)]

use std::path::{Path, PathBuf};

use prism_image::{compare_rgb8, read_png, write_png, DiffStats, Image, Rgb8Image};

/// A scratch folder for one test, removed when the test passes (kept, for a look, when it
/// fails). It derefs to its path.
pub struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

/// An empty scratch folder `<temp>/<prefix>-<name>-<process id>`, emptied first if a failed
/// run left it.
///
/// # Panics
/// If the folder cannot be made.
#[must_use]
pub fn scratch(prefix: &str, name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("{prefix}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch folder");
    Scratch(d)
}

/// The workspace root (two levels above this crate's manifest).
#[must_use]
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shared assets folder beside the checkout (`../shared/assets`).
///
/// # Panics
/// If the folder is missing: every test that reads the course's files fails loudly rather
/// than passing without its data.
#[must_use]
pub fn shared_assets() -> PathBuf {
    let dir = workspace_root().join("../shared/assets");
    assert!(
        dir.is_dir(),
        "missing {}: prism's tests read the course's files from the shared folder beside \
         the checkout (../shared/assets); put it there",
        dir.display()
    );
    dir
}

/// The file or folder `rel` under the shared assets.
///
/// # Panics
/// If it is missing, naming it: a test that passes without its data cannot fail.
#[must_use]
pub fn shared_asset(rel: &str) -> PathBuf {
    let path = shared_assets().join(rel);
    assert!(
        path.exists(),
        "missing shared asset {}: this test needs it (see ../shared/assets/SOURCES.md)",
        path.display()
    );
    path
}

/// Where failing comparisons leave their triptychs.
#[must_use]
pub fn diff_dir() -> PathBuf {
    workspace_root().join("target/test-diffs")
}

/// True when references should be regenerated (`MAKE_REF=1`).
#[must_use]
pub fn make_ref() -> bool {
    std::env::var("MAKE_REF").is_ok_and(|v| v == "1")
}

/// An `expected | diff | actual` image; the diff shows differing pixels in red over a
/// dimmed copy of the expected image.
#[must_use]
pub fn triptych(expected: &Rgb8Image, actual: &Rgb8Image) -> Rgb8Image {
    let (w, h) = (
        expected.width().max(actual.width()),
        expected.height().max(actual.height()),
    );
    let get = |im: &Rgb8Image, x: u32, y: u32| {
        if x < im.width() && y < im.height() {
            Some(im.get(x, y))
        } else {
            None
        }
    };
    Image::from_fn(3 * w, h, |x, y| {
        let (panel, px) = (x / w, x % w);
        match panel {
            0 => get(expected, px, y).unwrap_or([255, 0, 255]),
            2 => get(actual, px, y).unwrap_or([255, 0, 255]),
            _ => match (get(expected, px, y), get(actual, px, y)) {
                (Some(e), Some(a)) if e == a => e.map(|c| 128 + c / 2),
                (Some(e), Some(a)) => {
                    let d = (0..3).map(|c| e[c].abs_diff(a[c])).max().unwrap_or(0);
                    [255, 96u8.saturating_sub(d / 3), 0]
                }
                _ => [255, 0, 255],
            },
        }
    })
}

/// Compares `actual` with the PNG at `expected_path`, as [`compare_images`] does. With
/// `MAKE_REF=1` and `owned` true, writes `actual` as the new reference instead and returns
/// perfect statistics.
///
/// # Panics
/// If the reference is missing or unreadable, or as [`compare_images`].
pub fn compare_golden(
    name: &str,
    expected_path: &Path,
    actual: &Rgb8Image,
    owned: bool,
    accept: impl Fn(&DiffStats) -> bool,
) -> DiffStats {
    if owned && make_ref() {
        if let Some(dir) = expected_path.parent() {
            std::fs::create_dir_all(dir).expect("create reference folder");
        }
        write_png(expected_path, actual).expect("write reference");
        return compare_rgb8(actual, actual).expect("same size");
    }
    let expected = read_png(expected_path)
        .unwrap_or_else(|e| panic!("{name}: cannot read reference: {e}"))
        .to_rgb8();
    compare_images(name, &expected, actual, accept)
}

/// Compares two images in memory and returns the statistics; when the sizes differ or
/// `accept` rejects the statistics, writes an `expected | diff | actual` triptych named
/// `name` under [`diff_dir`] and panics with the figures.
///
/// # Panics
/// If the sizes differ or `accept` returns false.
pub fn compare_images(
    name: &str,
    expected: &Rgb8Image,
    actual: &Rgb8Image,
    accept: impl Fn(&DiffStats) -> bool,
) -> DiffStats {
    let stats = compare_rgb8(expected, actual);
    if !stats.as_ref().is_some_and(&accept) {
        let dir = diff_dir();
        std::fs::create_dir_all(&dir).expect("create diff folder");
        let out = dir.join(format!("{name}.png"));
        write_png(&out, &triptych(expected, actual)).expect("write triptych");
        panic!(
            "{name}: image differs from its reference ({stats:?}); triptych at {}",
            out.display()
        );
    }
    stats.expect("checked")
}

/// Pearson's chi-square test of observed counts against expected counts. Cells expected to
/// receive fewer than 5 samples are pooled into one. Returns `(statistic, critical value)`;
/// the hypothesis "the samples follow the expected distribution" is rejected at
/// significance 0.001 when the statistic exceeds the critical value (the chi-square
/// quantile by the Wilson-Hilferty approximation).
#[must_use]
pub fn chi_square(observed: &[f64], expected: &[f64]) -> (f64, f64) {
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            stat += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e.max(1.0);
        cells += 1;
    }
    let k = cells.saturating_sub(1).max(1) as f64;
    let z = 3.090_232; // the standard normal's 0.999 quantile
    let c = 2.0 / (9.0 * k);
    (stat, k * (1.0 - c + z * c.sqrt()).powi(3))
}

/// One pixel's estimate for [`z_test`]: its mean and the variance of that mean (a sample
/// variance over the sample count).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The pixel's mean.
    pub mean: f64,
    /// The variance of the mean.
    pub variance: f64,
}

/// What [`z_test`] found: the smallest p-value over the pixels tested, where, and the
/// threshold it must not fall below (the significance level over the pixels tested:
/// Bonferroni's correction).
#[derive(Clone, Copy, Debug)]
pub struct ZTest {
    /// Pixels tested (those where either estimate has a non-zero variance).
    pub tested: usize,
    /// The smallest two-sided p-value.
    pub worst_p: f64,
    /// The pixel with that p-value.
    pub worst_pixel: usize,
    /// `alpha / tested`.
    pub threshold: f64,
    /// Pixels with no variance on either side whose means differ by more than `tolerance`.
    pub exact_mismatches: usize,
}

impl ZTest {
    /// True if no pixel rejects the hypothesis that both estimates have one mean.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.worst_p >= self.threshold && self.exact_mismatches == 0
    }
}

/// A per-pixel two-sided Z-test of `ours` against `reference` (Mitsuba's `test_renders.py`
/// tests its renders this way): for each pixel, `z = (a - b) / sqrt(var_a + var_b)` and its
/// p-value `erfc(|z| / sqrt 2)`; the test fails if any p-value is below `alpha` over the
/// number of pixels tested. Pixels where neither side varies must agree to `tolerance`.
///
/// # Panics
/// If the slices differ in length.
#[must_use]
pub fn z_test(ours: &[Estimate], reference: &[Estimate], alpha: f64, tolerance: f64) -> ZTest {
    assert_eq!(
        ours.len(),
        reference.len(),
        "one estimate per pixel on both sides"
    );
    let mut out = ZTest {
        tested: 0,
        worst_p: 1.0,
        worst_pixel: 0,
        threshold: alpha,
        exact_mismatches: 0,
    };
    for (i, (a, b)) in ours.iter().zip(reference).enumerate() {
        let var = a.variance + b.variance;
        if var <= 0.0 {
            out.exact_mismatches += usize::from((a.mean - b.mean).abs() > tolerance);
            continue;
        }
        out.tested += 1;
        let z = (a.mean - b.mean).abs() / var.sqrt();
        let p = erfc(z / std::f64::consts::SQRT_2);
        if p < out.worst_p {
            out.worst_p = p;
            out.worst_pixel = i;
        }
    }
    out.threshold = alpha / out.tested.max(1) as f64;
    out
}

/// The complementary error function, to a relative error under 1.2e-7 everywhere (the
/// Chebyshev fit of Numerical Recipes' `erfcc`).
#[must_use]
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Runs `f` on a rayon pool of exactly `threads` threads (for tests that an output does not
/// depend on the thread count).
///
/// # Panics
/// If the pool cannot be made.
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: erfc at tabulated points (Abramowitz and Stegun, table 7.1).
    #[test]
    fn erfc_matches_the_table() {
        for (x, want) in [
            (0.0, 1.0),
            (0.5, 0.479_500_122),
            (1.0, 0.157_299_207),
            (2.0, 0.004_677_735),
            (3.0, 2.209_049_7e-5),
            (-1.0, 1.842_700_793),
        ] {
            let got = erfc(x);
            assert!(
                ((got - want) / want).abs() < 2e-7,
                "erfc({x}) = {got}, want {want}"
            );
        }
    }

    /// Property: the Z-test passes two estimates of one mean (normal draws of known variance,
    /// 10,000 pixels) and fails when one pixel's mean is moved by eight standard errors.
    #[test]
    fn z_test_passes_one_mean_and_catches_a_shifted_pixel() {
        // A 64-bit linear congruential generator's top 53 bits, then Box-Muller.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let mut normal = move || {
            let (u, v) = (uniform(), uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let sd: f64 = 0.1;
        let ours: Vec<Estimate> = (0..10_000)
            .map(|_| Estimate {
                mean: 1.0 + sd * normal(),
                variance: sd * sd,
            })
            .collect();
        let reference = vec![
            Estimate {
                mean: 1.0,
                variance: 0.0,
            };
            10_000
        ];
        let fair = z_test(&ours, &reference, 0.01, 0.0);
        assert!(fair.passed(), "{fair:?}");
        let mut shifted = ours.clone();
        shifted[1234].mean = 1.0 + 8.0 * sd;
        let caught = z_test(&shifted, &reference, 0.01, 0.0);
        assert!(!caught.passed() && caught.worst_pixel == 1234, "{caught:?}");
    }

    /// Property: a scratch folder starts empty (a failed run's leftovers gone) and is
    /// removed, with what was written in it, when it goes out of scope.
    #[test]
    fn scratch_starts_empty_and_is_removed() {
        let path = {
            let d = scratch("prism-testkit", "scratch");
            std::fs::write(d.join("a.txt"), "a").unwrap();
            d.to_path_buf()
        };
        assert!(!path.exists());
        std::fs::create_dir_all(&path).unwrap();
        std::fs::write(path.join("left.txt"), "b").unwrap();
        let d = scratch("prism-testkit", "scratch");
        assert_eq!(std::fs::read_dir(&*d).unwrap().count(), 0);
    }

    #[test]
    fn triptych_marks_differences() {
        let a = Image::new(2, 1, [10u8, 10, 10]);
        let mut b = a.clone();
        b.set(1, 0, [200, 10, 10]);
        let t = triptych(&a, &b);
        assert_eq!((t.width(), t.height()), (6, 1));
        assert_eq!(t.get(2, 0), [133, 133, 133]);
        assert_eq!(t.get(3, 0)[0], 255);
        assert_eq!(t.get(5, 0), [200, 10, 10]);
    }
}
