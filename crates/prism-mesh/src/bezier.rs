//! Bezier curves of any degree and bicubic Bezier patches, evaluated by de Casteljau's
//! algorithm (repeated linear interpolation), and the course's `.bzc` and `.bez` files.

use prism_math::Loc;
use std::collections::HashMap;
use std::ops::{Add, Mul};

use prism_math::glam::{DVec2, DVec3};

use crate::{MeshError, PolyMesh};

/// One de Casteljau step: the `n - 1` points `(1 - t) p_i + t p_{i+1}`.
#[must_use]
pub fn de_casteljau_step<P>(points: &[P], t: f64) -> Vec<P>
where
    P: Copy + Add<Output = P> + Mul<f64, Output = P>,
{
    points
        .windows(2)
        .map(|w| w[0] * (1.0 - t) + w[1] * t)
        .collect()
}

/// Every level of de Casteljau's construction at `t`, from the control points (level 0)
/// down to the single point on the curve.
#[must_use]
pub fn de_casteljau_levels<P>(points: &[P], t: f64) -> Vec<Vec<P>>
where
    P: Copy + Add<Output = P> + Mul<f64, Output = P>,
{
    let mut levels = vec![points.to_vec()];
    while levels.last().is_some_and(|l| l.len() > 1) {
        let next = de_casteljau_step(levels.last().expect("non-empty"), t);
        levels.push(next);
    }
    levels
}

/// The point at `t` of the Bezier curve with these control points.
///
/// # Panics
/// If `points` is empty.
#[must_use]
pub fn bezier_point<P>(points: &[P], t: f64) -> P
where
    P: Copy + Add<Output = P> + Mul<f64, Output = P>,
{
    de_casteljau_levels(points, t)
        .last()
        .expect("control points")[0]
}

/// A bicubic Bezier patch with control points `cp[i][j]` (row `i`, column `j`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierPatch {
    /// Control points, row-major.
    pub cp: [[DVec3; 4]; 4],
}

impl BezierPatch {
    /// `P(u, v) = sum_i sum_j B_i(u) B_j(v) cp[i][j]`: each row is evaluated at `v`, then the
    /// four results as a curve at `u` (the tensor product is separable).
    #[must_use]
    pub fn evaluate(&self, u: f64, v: f64) -> DVec3 {
        let rows: Vec<DVec3> = self.cp.iter().map(|row| bezier_point(row, v)).collect();
        bezier_point(&rows, u)
    }
}

fn numbers(text: &str, file: &str) -> Result<Vec<(f64, usize)>, MeshError> {
    let mut out = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        for w in line.split_whitespace() {
            let v = w
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| MeshError::Parse {
                    at: Loc::line(file, (ln + 1) as u32),
                    message: format!("expected a finite number, found {w:?}"),
                })?;
            out.push((v, ln + 1));
        }
    }
    Ok(out)
}

fn count(nums: &[(f64, usize)], file: &str, what: &str) -> Result<usize, MeshError> {
    let &(n, line) = nums.first().ok_or_else(|| MeshError::Parse {
        at: Loc::line(file, 1),
        message: format!("expected the number of {what}, found an empty file"),
    })?;
    if n < 0.0 || n.fract() != 0.0 || n > 1e6 {
        return Err(MeshError::Parse {
            at: Loc::line(file, line as u32),
            message: format!("expected a count of {what}, found {n}"),
        });
    }
    Ok(n as usize)
}

/// Parses a `.bzc` curve: `n`, then `n` points `x y`.
///
/// # Errors
/// [`MeshError::Parse`] with the line of a bad number or a wrong point count.
pub fn parse_bzc(text: &str, file: &str) -> Result<Vec<DVec2>, MeshError> {
    let nums = numbers(text, file)?;
    let n = count(&nums, file, "points")?;
    if nums.len() != 1 + 2 * n || n == 0 {
        return Err(MeshError::Parse {
            at: Loc::line(file, nums.last().map_or(1, |x| x.1) as u32),
            message: format!(
                "expected {n} points (2 numbers each) after the count, found {} numbers",
                nums.len() - 1
            ),
        });
    }
    Ok(nums[1..]
        .chunks_exact(2)
        .map(|c| DVec2::new(c[0].0, c[1].0))
        .collect())
}

/// Parses a `.bez` file: `N`, then `N` x 16 control points of 3 numbers, row-major.
///
/// # Errors
/// [`MeshError::Parse`] with the line of a bad number or a wrong point count.
pub fn parse_bez(text: &str, file: &str) -> Result<Vec<BezierPatch>, MeshError> {
    let nums = numbers(text, file)?;
    let n = count(&nums, file, "patches")?;
    if nums.len() != 1 + 48 * n {
        return Err(MeshError::Parse {
            at: Loc::line(file, nums.last().map_or(1, |x| x.1) as u32),
            message: format!(
                "expected {n} patches of 16 points (48 numbers each), found {} numbers",
                nums.len() - 1
            ),
        });
    }
    Ok(nums[1..]
        .chunks_exact(48)
        .map(|c| {
            let mut cp = [[DVec3::ZERO; 4]; 4];
            for (k, p) in c.chunks_exact(3).enumerate() {
                cp[k / 4][k % 4] = DVec3::new(p[0].0, p[1].0, p[2].0);
            }
            BezierPatch { cp }
        })
        .collect())
}

/// Tessellates patches on a `resolution` x `resolution` grid of (u, v) = (i, j) / resolution
/// per patch, two triangles per cell as the course does, then welds vertices that coincide
/// within 1e-9 and drops triangles that become degenerate (the poles of the teapot).
#[must_use]
pub fn tessellate(patches: &[BezierPatch], resolution: usize) -> PolyMesh {
    let r = resolution.max(1);
    let mut mesh = PolyMesh::default();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut weld = |p: DVec3, mesh: &mut PolyMesh| -> u32 {
        let key = [
            (p.x * 1e9).round() as i64,
            (p.y * 1e9).round() as i64,
            (p.z * 1e9).round() as i64,
        ];
        *index.entry(key).or_insert_with(|| {
            mesh.positions.push(p);
            (mesh.positions.len() - 1) as u32
        })
    };
    for patch in patches {
        let mut grid = vec![0u32; (r + 1) * (r + 1)];
        for i in 0..=r {
            for j in 0..=r {
                let p = patch.evaluate(i as f64 / r as f64, j as f64 / r as f64);
                grid[i * (r + 1) + j] = weld(p, &mut mesh);
            }
        }
        let g = |i: usize, j: usize| grid[i * (r + 1) + j];
        for i in 0..r {
            for j in 0..r {
                for tri in [
                    [g(i + 1, j), g(i + 1, j + 1), g(i, j)],
                    [g(i + 1, j + 1), g(i, j + 1), g(i, j)],
                ] {
                    if tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] {
                        mesh.push_face(&tri);
                    }
                }
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: the Bernstein form of a cubic equals de Casteljau at every t.
    #[test]
    fn matches_bernstein_form() {
        let p = [
            DVec2::new(0.2, 0.35),
            DVec2::new(0.3, 0.6),
            DVec2::new(0.8, 0.75),
            DVec2::new(0.9, 0.45),
        ];
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let u = 1.0 - t;
            let b = p[0] * (u * u * u)
                + p[1] * (3.0 * u * u * t)
                + p[2] * (3.0 * u * t * t)
                + p[3] * (t * t * t);
            assert!((bezier_point(&p, t) - b).length() < 1e-15);
        }
        let levels = de_casteljau_levels(&p, 0.5);
        assert_eq!(
            levels.iter().map(Vec::len).collect::<Vec<_>>(),
            vec![4, 3, 2, 1]
        );
        assert_eq!(levels[1][0], DVec2::new(0.25, 0.475));
    }

    /// Property: a patch whose control points lie on a plane z = ax + by + c evaluates onto
    /// it (affine invariance), and corners interpolate the corner control points.
    #[test]
    fn patch_properties() {
        let mut cp = [[DVec3::ZERO; 4]; 4];
        for (i, row) in cp.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                let (x, y) = (
                    i as f64 + 0.1 * (j as f64).sin(),
                    j as f64 + 0.2 * (i as f64).cos(),
                );
                *p = DVec3::new(x, y, 0.5 * x - 0.25 * y + 1.0);
            }
        }
        let patch = BezierPatch { cp };
        for (u, v) in [(0.1, 0.7), (0.5, 0.5), (0.93, 0.2)] {
            let q = patch.evaluate(u, v);
            assert!((q.z - (0.5 * q.x - 0.25 * q.y + 1.0)).abs() < 1e-12);
        }
        assert_eq!(patch.evaluate(0.0, 0.0), cp[0][0]);
        assert!((patch.evaluate(1.0, 1.0) - cp[3][3]).length() < 1e-15);
    }

    #[test]
    fn staged_files_parse_and_teapot_welds() {
        let dir = prism_testkit::shared_asset("meshedit");
        let c = parse_bzc(
            &std::fs::read_to_string(dir.join("bzc/curve2.bzc")).unwrap(),
            "curve2.bzc",
        )
        .unwrap();
        assert_eq!(c.len(), 5);
        let t = parse_bez(
            &std::fs::read_to_string(dir.join("bez/teapot.bez")).unwrap(),
            "teapot.bez",
        )
        .unwrap();
        assert_eq!(t.len(), 32);
        let w = parse_bez(
            &std::fs::read_to_string(dir.join("bez/wavy_cube.bez")).unwrap(),
            "wavy_cube.bez",
        )
        .unwrap();
        assert_eq!(w.len(), 6);
        let m = tessellate(&t, 16);
        // Welding shares patch borders (and collapses poles): fewer than 32 * 17 * 17
        // vertices, each used by some face.
        assert!(m.vertex_count() < 32 * 17 * 17, "{}", m.vertex_count());
        let mut used = vec![false; m.vertex_count()];
        for f in m.faces() {
            for &v in f {
                used[v as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u));
        assert!(m
            .faces()
            .all(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2]));
    }

    #[test]
    fn bad_files_are_located() {
        let e = parse_bzc("3\n0 0 1 1\n", "a.bzc").unwrap_err();
        assert!(
            e.to_string().starts_with("a.bzc:2: expected 3 points"),
            "{e}"
        );
        let e = parse_bez("1\n0 0 x\n", "a.bez").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.bez:2: expected a finite number, found \"x\""
        );
        assert!(parse_bez("", "a.bez").is_err());
        assert!(parse_bzc("-2", "a.bzc").is_err());
    }
}
