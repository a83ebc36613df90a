//! [`Materials`], a scene's materials as a hit needs them: each one's BSDF, the texture its
//! albedo is multiplied by, its emission and sides, and the choice a blend or a mask makes at
//! every hit.

use std::collections::HashMap;
use std::sync::Arc;

use prism_image::{PixelSampling, Texture};
use prism_math::{Ray, Rgb, Vec2};
use prism_scene::{Material, MaterialTexture, ScalarTexture, Scene};

use crate::bsdf::Bsdf;

/// A prepared texture (shared by the materials that use its image), its lookup and its
/// `to_uv`.
type Lookup = (Arc<Texture>, PixelSampling, [f32; 6]);

/// A number over the surface, prepared.
enum Scalar {
    Constant(f32),
    Image(Lookup),
}

/// What a blend or a mask chooses between.
enum Choice {
    /// `materials[1]` with probability `weight`, else `materials[0]`.
    Blend {
        weight: Scalar,
        materials: [usize; 2],
    },
    /// `material` with probability `opacity`, else nothing.
    Mask { opacity: Scalar, material: usize },
}

/// What a hit scatters with once blends and masks have chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Chosen {
    /// This material; `one_sided` if it is black from behind (every material on the way to
    /// it is one-sided: a `twosided` around a blend makes both its choices two-sided).
    Material { index: usize, one_sided: bool },
    /// No surface: a mask let the ray through.
    Through,
}

/// The materials of a scene, prepared for hits.
pub(crate) struct Materials {
    bsdfs: Vec<Bsdf>,
    textures: Vec<Option<Lookup>>,
    /// Per material, the choice it defers to.
    choices: Vec<Option<Choice>>,
    /// Emitted radiance.
    pub(crate) emission: Vec<Option<Rgb>>,
    one_sided: Vec<bool>,
    /// True if its BSDF is anisotropic, so hits carry a tangent.
    pub(crate) anisotropic: Vec<bool>,
    /// True if it emits from its front side only (where the winding's normal points), as a
    /// Mitsuba area emitter does.
    pub(crate) front_only: Vec<bool>,
}

impl Materials {
    /// Prepares `scene`'s materials; materials that share an image share its texture.
    pub(crate) fn new(scene: &Scene) -> Materials {
        let mut built = HashMap::new();
        let mut prepare = |t: &MaterialTexture| -> Lookup {
            let texture = built
                .entry((Arc::as_ptr(&t.image), t.wrap))
                .or_insert_with(|| {
                    Arc::new(Texture::new((*t.image).clone()).with_wrap(t.wrap, t.wrap))
                });
            (Arc::clone(texture), t.sampling, t.to_uv)
        };
        let count = scene.materials.len();
        // Indices out of range make a choice black rather than panic.
        let valid = |i: usize| i < count;
        let mut textures = Vec::with_capacity(count);
        let mut choices = Vec::with_capacity(count);
        for m in &scene.materials {
            textures.push(match m {
                Material::Diffuse {
                    texture: Some(t), ..
                }
                | Material::Plastic {
                    texture: Some(t), ..
                }
                | Material::RoughPlastic {
                    texture: Some(t), ..
                } => Some(prepare(t)),
                _ => None,
            });
            let mut scalar = |s: &ScalarTexture| match s {
                ScalarTexture::Constant(v) => Scalar::Constant(*v),
                ScalarTexture::Image(t) => Scalar::Image(prepare(t)),
            };
            choices.push(match m {
                Material::Blend { weight, materials } if materials.iter().all(|&i| valid(i)) => {
                    Some(Choice::Blend {
                        weight: scalar(weight),
                        materials: *materials,
                    })
                }
                Material::Mask { opacity, material } if valid(*material) => Some(Choice::Mask {
                    opacity: scalar(opacity),
                    material: *material,
                }),
                _ => None,
            });
        }
        Materials {
            bsdfs: scene.materials.iter().map(Bsdf::from_material).collect(),
            textures,
            choices,
            emission: scene
                .materials
                .iter()
                .map(|m| match m {
                    Material::Emission { radiance }
                    | Material::EmissiveDiffuse { radiance, .. } => Some(*radiance),
                    _ => None,
                })
                .collect(),
            one_sided: (0..count)
                .map(|i| scene.one_sided.get(i).copied().unwrap_or(false))
                .collect(),
            anisotropic: scene
                .materials
                .iter()
                .map(|m| Bsdf::from_material(m).anisotropic())
                .collect(),
            front_only: scene
                .materials
                .iter()
                .map(|m| matches!(m, Material::EmissiveDiffuse { .. }))
                .collect(),
        }
    }

    /// The BSDF of material `index`, before its texture.
    #[inline(always)]
    pub(crate) fn bsdf(&self, index: usize) -> Bsdf {
        self.bsdfs[index]
    }

    /// True if material `index` has a texture its albedo is multiplied by.
    #[inline(always)]
    pub(crate) fn textured(&self, index: usize) -> bool {
        self.textures[index].is_some()
    }

    /// The material a hit on material `index` scatters with. A blend or a mask chooses with
    /// numbers drawn from the bits of `ray` (the same ray chooses alike on any thread, and
    /// different rays independently), its weight or opacity read at `uv` (Mitsuba's surface
    /// coordinates, `v` running down the image) where it is a texture.
    #[inline(always)]
    pub(crate) fn choose(&self, index: usize, ray: &Ray, uv: impl Fn() -> Vec2) -> Chosen {
        let mut index = index;
        let mut one_sided = self.one_sided[index];
        if self.choices[index].is_none() {
            return Chosen::Material { index, one_sided };
        }
        let mut bits = ray_bits(ray);
        // Blends and masks nest (the reader bounds how deep); a scene built with a cycle
        // stops after as many steps as it has materials.
        for _ in 0..self.choices.len() {
            let Some(choice) = &self.choices[index] else {
                return Chosen::Material { index, one_sided };
            };
            bits = mix(bits);
            let u = (bits >> 40) as f32 * (1.0 / (1u64 << 24) as f32);
            let value = |s: &Scalar| match s {
                Scalar::Constant(v) => *v,
                Scalar::Image(lookup) => luminance(self.lookup(lookup, uv())),
            };
            index = match choice {
                Choice::Blend { weight, materials } => {
                    materials[usize::from(u < value(weight).clamp(0.0, 1.0))]
                }
                Choice::Mask { opacity, material } => {
                    if u >= value(opacity).clamp(0.0, 1.0) {
                        return Chosen::Through;
                    }
                    *material
                }
            };
            one_sided &= self.one_sided[index];
        }
        Chosen::Material { index, one_sided }
    }

    /// The texel of material `index`'s texture at surface coordinates `uv` (`v` running
    /// down the image), through its `to_uv`; white without a texture.
    #[inline(always)]
    pub(crate) fn texel(&self, index: usize, uv: Vec2) -> Rgb {
        match &self.textures[index] {
            Some(lookup) => self.lookup(lookup, uv),
            None => Rgb::WHITE,
        }
    }

    fn lookup(&self, (tex, sampling, m): &Lookup, uv: Vec2) -> Rgb {
        let at = Vec2::new(
            m[0] * uv.x + m[1] * uv.y + m[2],
            m[3] * uv.x + m[4] * uv.y + m[5],
        );
        tex.sample_level(at, 0, *sampling)
    }
}

/// Mitsuba's luminance of a linear sRGB colour.
fn luminance(c: Rgb) -> f32 {
    0.212671 * c.r + 0.715160 * c.g + 0.072169 * c.b
}

/// A hash of the ray's origin and direction.
fn ray_bits(ray: &Ray) -> u64 {
    [ray.origin, ray.dir]
        .iter()
        .flat_map(|v| [v.x, v.y, v.z])
        .fold(0x9e37_79b9_7f4a_7c15, |h, x| {
            mix(h ^ u64::from(x.to_bits()))
        })
}

/// SplitMix64's output function: every input bit moves every output bit.
fn mix(x: u64) -> u64 {
    let x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    let x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}
