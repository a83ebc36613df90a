//! [`Materials`], a scene's materials as a hit needs them: each one's BSDF, the texture its
//! albedo is multiplied by, its emission and sides, the choice a blend or a mask makes at
//! every hit, and the frame a bump or normal map tilts the shading normal to.

use std::collections::HashMap;
use std::sync::Arc;

use prism_image::{PixelSampling, Texture};
use prism_math::{Frame, Ray, Rgb, Vec2, Vec3};
use prism_scene::{
    Material, MaterialTexture, PrincipledWeight, ScalarTexture, Scene, TexturedParameter,
    TiltOptions,
};

use crate::bsdf::Bsdf;
use crate::interaction::{frame_along, Tilt};

/// A prepared texture (shared by the materials that use its image), its lookup and its
/// `to_uv`.
pub(crate) type Lookup = (Arc<Texture>, PixelSampling, [f32; 6]);

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
    /// `material` under a tilted normal.
    Tilted { map: TiltMap, material: usize },
    /// `material`, the surface under an area emitter.
    Surface { material: usize },
    /// `material` with parameters read from textures.
    Textured {
        params: Vec<(TexturedParameter, Lookup)>,
        material: usize,
    },
}

/// Parameters of a material and the textures that give them, prepared.
pub(crate) type Textures = [(TexturedParameter, Lookup)];

/// A bump or normal map, prepared.
pub(crate) struct TiltMap {
    kind: TiltKind,
    options: TiltOptions,
}

enum TiltKind {
    /// Normals `2 rgb - 1` in the shading frame.
    Normal(Lookup),
    /// Heights times `scale`; `bilinear` false gives them no gradient (Mitsuba's nearest
    /// lookup).
    Bump {
        lookup: Lookup,
        scale: f32,
        bilinear: bool,
    },
}

/// What a hit scatters with once blends and masks have chosen.
#[derive(Clone, Copy)]
enum Chosen<'a> {
    /// This material; `one_sided` if it is black from behind (every material on the way to
    /// it is one-sided: a `twosided` around a blend makes both its choices two-sided),
    /// under the map that tilts its normal, if any.
    Material {
        index: usize,
        one_sided: bool,
        tilt: Option<&'a TiltMap>,
        /// Parameters textures give it.
        textured: Option<&'a Textures>,
    },
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
                }
                | Material::Principled {
                    texture: Some(t), ..
                }
                | Material::AreaEmitter {
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
                Material::AreaEmitter {
                    surface: Some(material),
                    ..
                } if valid(*material) => Some(Choice::Surface {
                    material: *material,
                }),
                Material::Textured { material, textures } if valid(*material) => {
                    Some(Choice::Textured {
                        params: textures.iter().map(|(p, t)| (*p, prepare(t))).collect(),
                        material: *material,
                    })
                }
                Material::NormalMap {
                    normals,
                    material,
                    tilt,
                } if valid(*material) => Some(Choice::Tilted {
                    map: TiltMap {
                        kind: TiltKind::Normal(prepare(normals)),
                        options: *tilt,
                    },
                    material: *material,
                }),
                Material::BumpMap {
                    height,
                    scale,
                    material,
                    tilt,
                } if valid(*material) => Some(Choice::Tilted {
                    map: TiltMap {
                        kind: TiltKind::Bump {
                            lookup: prepare(height),
                            scale: *scale,
                            bilinear: height.sampling == PixelSampling::Bilinear,
                        },
                        options: *tilt,
                    },
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
                    Material::Emission { radiance } | Material::AreaEmitter { radiance, .. } => {
                        Some(*radiance)
                    }
                    _ => None,
                })
                .collect(),
            one_sided: (0..count)
                .map(|i| scene.one_sided.get(i).copied().unwrap_or(false))
                .collect(),
            anisotropic: {
                let mut a: Vec<bool> = scene
                    .materials
                    .iter()
                    .map(|m| Bsdf::from_material(m).anisotropic())
                    .collect();
                // Alphas a texture gives apart may differ at any hit.
                for m in &scene.materials {
                    if let Material::Textured { material, textures } = m {
                        let alpha = |p| textures.iter().find(|(q, _)| *q == p).map(|(_, t)| t);
                        let apart = match (
                            alpha(TexturedParameter::AlphaU),
                            alpha(TexturedParameter::AlphaV),
                        ) {
                            (None, None) => false,
                            (Some(u), Some(v)) => u != v,
                            _ => true,
                        };
                        // So may a principled material's anisotropy.
                        let apart = apart
                            || alpha(TexturedParameter::Principled(PrincipledWeight::Anisotropic))
                                .is_some();
                        if valid(*material) && apart {
                            a[*material] = true;
                        }
                    }
                }
                a
            },
            front_only: scene
                .materials
                .iter()
                .map(|m| matches!(m, Material::AreaEmitter { .. }))
                .collect(),
        }
    }

    /// True if material `index` has a texture its albedo is multiplied by.
    #[inline(always)]
    fn textured(&self, index: usize) -> bool {
        self.textures[index].is_some()
    }

    /// The material a hit on material `index` scatters with. A blend or a mask chooses with
    /// numbers drawn from the bits of `ray` (the same ray chooses alike on any thread, and
    /// different rays independently), its weight or opacity read at `uv` (Mitsuba's surface
    /// coordinates, `v` running down the image) where it is a texture.
    #[inline(always)]
    fn choose(&self, index: usize, ray: &Ray, uv: impl Fn() -> Vec2) -> Chosen<'_> {
        let mut index = index;
        let mut one_sided = self.one_sided[index];
        let mut tilt = None;
        let mut textured = None;
        if self.choices[index].is_none() {
            return Chosen::Material {
                index,
                one_sided,
                tilt,
                textured,
            };
        }
        // The numbers blends and masks choose by, drawn one after another from the ray's
        // bits (only where a blend or a mask needs one).
        let mut bits = None;
        let mut next_u = || {
            let b = mix(bits.unwrap_or_else(|| ray_bits(ray)));
            bits = Some(b);
            (b >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
        };
        // Blends and masks nest (the reader bounds how deep); a scene built with a cycle
        // stops after as many steps as it has materials.
        for _ in 0..self.choices.len() {
            let Some(choice) = &self.choices[index] else {
                return Chosen::Material {
                    index,
                    one_sided,
                    tilt,
                    textured,
                };
            };
            let value = |s: &Scalar| match s {
                Scalar::Constant(v) => *v,
                Scalar::Image(lookup) => luminance(self.lookup(lookup, uv())),
            };
            index = match choice {
                Choice::Blend { weight, materials } => {
                    let u = next_u();
                    materials[usize::from(u < value(weight).clamp(0.0, 1.0))]
                }
                Choice::Mask { opacity, material } => {
                    if next_u() >= value(opacity).clamp(0.0, 1.0) {
                        return Chosen::Through;
                    }
                    *material
                }
                Choice::Tilted { map, material } => {
                    tilt = Some(map);
                    *material
                }
                Choice::Surface { material } => *material,
                Choice::Textured { params, material } => {
                    textured = Some(params.as_slice());
                    *material
                }
            };
            one_sided &= self.one_sided[index];
        }
        Chosen::Material {
            index,
            one_sided,
            tilt,
            textured,
        }
    }

    /// What a hit on material `index` along `ray` scatters with: the BSDF (black from
    /// behind where it is one-sided, [`Bsdf::Null`] where a mask lets the ray through, its
    /// textures applied), the material chosen, and the frame a map tilts the shading frame
    /// to. `(ns, ng)` are the shading and geometric normals, `uv` gives the surface
    /// coordinates (Mitsuba's), `derivatives` gives `dp/du` and `dp/dv`; an albedo texture
    /// applies only with `albedo_texture` (a mesh without uvs has none).
    #[inline(always)]
    pub(crate) fn scatterer(
        &self,
        index: usize,
        ray: &Ray,
        (ns, ng): (Vec3, Vec3),
        uv: &impl Fn() -> Vec2,
        derivatives: impl FnOnce() -> (Vec3, Vec3),
        albedo_texture: bool,
    ) -> (Bsdf, Option<usize>, Option<Tilt>) {
        let Chosen::Material {
            index,
            one_sided,
            tilt: map,
            textured,
        } = self.choose(index, ray, uv)
        else {
            return (Bsdf::Null, None, None);
        };
        let tilt = map.and_then(|map| {
            let (dpdu, dpdv) = derivatives();
            let shading = frame_along(ns, Some(dpdu));
            let wo_l = shading.to_local(-ray.dir);
            self.tilt(map, uv(), &shading, (dpdu, dpdv), ng, wo_l)
        });
        let front = tilt.map_or(ns, |t| t.frame.n);
        if one_sided && ray.dir.dot(front) >= 0.0 {
            return (Bsdf::Black, Some(index), tilt);
        }
        let mut bsdf = self.bsdfs[index];
        if let Some(textures) = textured {
            self.apply(&mut bsdf, textures, uv());
        }
        if let (true, true, Some(albedo)) =
            (albedo_texture, self.textured(index), bsdf.albedo_mut())
        {
            *albedo = *albedo * self.texel(index, uv());
        }
        (bsdf, Some(index), tilt)
    }

    /// `bsdf` with the parameters `textures` give at surface coordinates `uv`: colours as
    /// the texel, alphas as its luminance (at least 1e-4, as Mitsuba's microfacets).
    fn apply(&self, bsdf: &mut Bsdf, textures: &Textures, uv: Vec2) {
        for (param, lookup) in textures {
            bsdf.set(*param, self.lookup(lookup, uv));
        }
    }

    /// The frame `map` tilts the shading frame `shading` to at a hit seen from `wo_l` (in
    /// `shading`'s coordinates), with Mitsuba's `dp_du`, `dp_dv`, geometric normal `ng`
    /// and surface coordinates `uv`; none where the map gives no direction.
    fn tilt(
        &self,
        map: &TiltMap,
        uv: Vec2,
        shading: &Frame,
        (dpdu, dpdv): (Vec3, Vec3),
        ng: Vec3,
        wo_l: Vec3,
    ) -> Option<Tilt> {
        // A normal below the outgoing direction has its tangential part mirrored.
        let flip = |n: Vec3| {
            if map.options.flip_invalid_normals && wo_l.z * wo_l.dot(n) <= 0.0 {
                Vec3::new(-n.x, -n.y, n.z)
            } else {
                n
            }
        };
        let (n, s) = match &map.kind {
            TiltKind::Normal(lookup) => {
                let c = self.lookup(lookup, uv);
                let n = flip(Vec3::new(c.r, c.g, c.b) * 2.0 - Vec3::ONE).try_normalize()?;
                (n, (Vec3::X - n * n.x).try_normalize()?)
            }
            TiltKind::Bump {
                lookup,
                scale,
                bilinear,
            } => {
                let (gu, gv) = if *bilinear {
                    let (tex, _, m) = lookup;
                    let at = Vec2::new(
                        m[0] * uv.x + m[1] * uv.y + m[2],
                        m[3] * uv.x + m[4] * uv.y + m[5],
                    );
                    let [dx, dy] = tex.bilinear_gradient(at).map(luminance);
                    let (w, h) = tex.size();
                    // Per unit of the surface's coordinates, through `to_uv` transposed,
                    // scaled by the resolution after it, as Mitsuba's bitmap does.
                    (
                        *scale * w as f32 * (m[0] * dx + m[3] * dy),
                        *scale * h as f32 * (m[1] * dx + m[4] * dy),
                    )
                } else {
                    (0.0, 0.0)
                };
                let ns = shading.n;
                let du = dpdu + ns * (gu - ns.dot(dpdu));
                let dv = dpdv + ns * (gv - ns.dot(dpdv));
                let nw = du.cross(dv).try_normalize()?;
                let nw = if ng.dot(nw) < 0.0 { -nw } else { nw };
                let n = flip(shading.to_local(nw));
                // Mitsuba 3.9.1 makes the tilted frame's tangent from the world's dp/du
                // against this local normal; only anisotropic BSDFs see which tangent it is.
                (n, (dpdu - n * n.dot(dpdu)).try_normalize()?)
            }
        };
        let t = n.cross(s);
        let alpha2 = if map.options.shadowing {
            let cos2 = n.z * n.z;
            (0.125 * (1.0 - cos2).max(0.0) / cos2).min(1.0)
        } else {
            0.0
        };
        Some(Tilt {
            frame: Frame {
                s: shading.to_world(s),
                t: shading.to_world(t),
                n: shading.to_world(n),
            },
            alpha2,
        })
    }

    /// The texel of material `index`'s texture at surface coordinates `uv` (`v` running
    /// down the image), through its `to_uv`; white without a texture.
    #[inline(always)]
    fn texel(&self, index: usize, uv: Vec2) -> Rgb {
        match &self.textures[index] {
            Some(lookup) => self.lookup(lookup, uv),
            None => Rgb::WHITE,
        }
    }

    fn lookup(&self, lookup: &Lookup, uv: Vec2) -> Rgb {
        look_up(lookup, uv)
    }

    /// The radiance material `index` emits at surface coordinates `uv` (Mitsuba's), if it
    /// emits: its radiance, times its texture's texel where it has one.
    #[inline(always)]
    pub(crate) fn emission_at(&self, index: usize, uv: impl Fn() -> Vec2) -> Option<Rgb> {
        let radiance = self.emission[index]?;
        Some(match &self.textures[index] {
            Some(lookup) => radiance * look_up(lookup, uv()),
            None => radiance,
        })
    }

    /// The texture an emitting material `index` multiplies its radiance by, if any.
    pub(crate) fn emission_texture(&self, index: usize) -> Option<&Lookup> {
        self.emission[index].and(self.textures[index].as_ref())
    }
}

/// A texture's texel at surface coordinates `uv`, through its `to_uv` transform.
pub(crate) fn look_up((tex, sampling, m): &Lookup, uv: Vec2) -> Rgb {
    let at = Vec2::new(
        m[0] * uv.x + m[1] * uv.y + m[2],
        m[3] * uv.x + m[4] * uv.y + m[5],
    );
    tex.sample_level(at, 0, *sampling)
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
