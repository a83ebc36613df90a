//! [`Overlay`], 3D segments drawn over a rendered image through its [`OrbitView`]: depth
//! tested against the scene as that view sees it (ray segments), or drawn on top (BVH
//! boxes), plus point markers; a pixel's ray tree and a BVH's levels and leaves.

use prism_image::RgbImage;
use prism_math::{Aabb, Ray, Rgb, Vec3};

use super::camera::OrbitView;
use super::scene::WhittedScene;
use super::tracer::{DebugRay, RayKind};

/// An image being drawn over, with the depth of the scene at each pixel.
pub struct Overlay {
    /// The picture.
    pub image: RgbImage,
    view: OrbitView,
    /// View-axis depth of the first surface through each pixel centre (infinite on a miss).
    depth: Vec<f32>,
}

impl Overlay {
    /// Starts drawing over `image`, seen through `view`, with depths from `scene`.
    #[must_use]
    pub fn new(image: RgbImage, view: OrbitView, scene: &WhittedScene) -> Overlay {
        let (w, h) = (image.width(), image.height());
        let mut depth = vec![f32::INFINITY; (w * h) as usize];
        for row in 0..h {
            for x in 0..w {
                let ray: Ray = view.ray(x as f32 + 0.5, (h - row) as f32 - 0.5);
                if let Some(hit) = scene.intersect(&ray, f32::INFINITY, false) {
                    depth[(row * w + x) as usize] =
                        view.project(hit.p).map_or(f32::INFINITY, |p| p.2);
                }
            }
        }
        Overlay { image, view, depth }
    }

    /// Draws the segment `a`-`b`, two pixels wide, in `color` (clamped to [0, 1]); with
    /// `depth_test`, only where it is not behind the scene's surface (within 0.5% of the
    /// depth).
    pub fn segment(&mut self, a: Vec3, b: Vec3, color: Rgb, depth_test: bool) {
        // Clip to the part in front of the eye by sampling in world space.
        let (w, h) = (self.image.width(), self.image.height());
        let pa = self.view.project(a);
        let pb = self.view.project(b);
        let screen_len = match (pa, pb) {
            (Some(p), Some(q)) => ((p.0 - q.0).powi(2) + (p.1 - q.1).powi(2)).sqrt(),
            _ => (w + h) as f32,
        };
        let steps = (2.0 * screen_len).ceil().clamp(1.0, 4.0 * (w + h) as f32) as u32;
        let c = Rgb::new(
            color.r.clamp(0.0, 1.0),
            color.g.clamp(0.0, 1.0),
            color.b.clamp(0.0, 1.0),
        );
        for i in 0..=steps {
            let s = i as f32 / steps as f32;
            let p = a + s * (b - a);
            let Some((x, y, z)) = self.view.project(p) else {
                continue;
            };
            if !(x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32) {
                continue;
            }
            let (px, py) = (x as u32, y as u32);
            let d = self.depth[(py * w + px) as usize];
            if depth_test && z > d * 1.005 {
                continue;
            }
            // Two pixels wide, so that lines read at any size.
            for (qx, qy) in [(px, py), (px + 1, py), (px, py + 1), (px + 1, py + 1)] {
                if qx < w && qy < h {
                    self.image.set(qx, qy, c);
                }
            }
        }
    }

    /// Marks point `p` with a 5 x 5 pixel cross in `color`, on top of everything.
    pub fn marker(&mut self, p: Vec3, color: Rgb) {
        let Some((x, y, _)) = self.view.project(p) else {
            return;
        };
        let (w, h) = (self.image.width() as i64, self.image.height() as i64);
        let (cx, cy) = (x.floor() as i64, y.floor() as i64);
        for k in -2..=2i64 {
            for (px, py) in [(cx + k, cy + k), (cx + k, cy - k)] {
                if px >= 0 && py >= 0 && px < w && py < h {
                    self.image.set(px as u32, py as u32, color);
                }
            }
        }
    }

    /// Draws the twelve edges of `b` on top of the picture.
    pub fn aabb(&mut self, b: &Aabb, color: Rgb) {
        let corner = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            )
        };
        for i in 0..8u32 {
            for bit in [1u32, 2, 4] {
                if i & bit == 0 {
                    self.segment(corner(i), corner(i | bit), color, false);
                }
            }
        }
    }

    /// Draws a pixel's ray tree as `prism raytrace --debug-pixel` does: each ray in its
    /// colour, depth-tested except normals (drawn on top), and a red marker where a shadow
    /// ray was blocked.
    pub fn ray_tree(&mut self, rays: &[DebugRay]) {
        for r in rays {
            let on_top = matches!(r.kind, RayKind::Normal | RayKind::InterpolatedNormal);
            self.segment(r.origin, r.end, r.color, !on_top);
        }
        for r in rays {
            if let Some(p) = r.blocked_at {
                self.marker(p, Rgb::new(1.0, 0.0, 0.0));
            }
        }
    }

    /// Draws `scene`'s BVH: the boxes of `level` in palette colours, and leaf `leaf` (its box
    /// in yellow, its triangles in magenta); a level or leaf the BVH lacks draws nothing.
    pub fn bvh(&mut self, scene: &WhittedScene, level: Option<usize>, leaf: Option<usize>) {
        let Some(bvh) = scene.bvh() else {
            return;
        };
        if let Some(level) = level {
            for (i, b) in bvh.level_boxes(level).iter().enumerate() {
                self.aabb(b, palette(i));
            }
        }
        if let Some(view) = leaf.and_then(|k| bvh.leaf_views().into_iter().nth(k)) {
            self.aabb(&view.bounds, Rgb::new(1.0, 1.0, 0.0));
            for &p in &view.prims {
                if (p as usize) < scene.triangle_count() {
                    let t = scene.triangle(p as usize);
                    for e in 0..3 {
                        self.segment(t[e], t[(e + 1) % 3], Rgb::new(1.0, 0.0, 1.0), false);
                    }
                }
            }
        }
    }
}

/// A colour for BVH level or item `i`: evenly spaced hues, full saturation.
#[must_use]
pub fn palette(i: usize) -> Rgb {
    let h = (i as f32 * 0.618_034).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    match h as u32 {
        0 => Rgb::new(1.0, x, 0.0),
        1 => Rgb::new(x, 1.0, 0.0),
        2 => Rgb::new(0.0, 1.0, x),
        3 => Rgb::new(0.0, x, 1.0),
        4 => Rgb::new(x, 0.0, 1.0),
        _ => Rgb::new(1.0, 0.0, x),
    }
}
