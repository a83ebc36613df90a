//! The wavefront's lane scatter stage: the step for sixteen paths at once at smooth surfaces (diffuse or rough
//! conductor, one kind per group): shading frames, light samples with their MIS weights and
//! shadow rays, the BSDF sample and Russian roulette on sixteen lanes, the random numbers
//! and the BSDFs' evaluation and sampling too. Area, point, directional and hemisphere
//! lights are sampled on the lanes; mesh and environment lights by their own sampling code,
//! lane by lane. The light samples wait on lanes for their shadow rays, and their sum is
//! taken on lanes too ([`GroupTerms::gather`]). Each lane does the scalar code's operations
//! in the same order, so the result is the scalar path's, bit for bit.

// Plain index loops over the lanes are what the vectoriser turns into single instructions.
#![allow(clippy::needless_range_loop)]

use prism_math::lanes::{F16, LANES, M16, V16};
use prism_math::warp::cosine_hemisphere_lanes;
use prism_math::{Frame, Ray, Rgb, Vec2, Vec3};

use super::queues::{PathState, Shadows};
use crate::bsdf::lanes::{SmoothKind, SmoothLanes};
use crate::integrators::PathSettings;
use crate::interaction::Interaction;
use crate::lights::RenderLight;
use crate::sampler::lane_values;

/// The kind of smooth BSDF at a surface this step handles (not under a bump or normal map,
/// which the one-path step handles).
pub(super) fn smooth_kind(hit: &Interaction) -> Option<SmoothKind> {
    match hit.tilt {
        None => SmoothKind::of(&hit.bsdf),
        Some(_) => None,
    }
}

/// What the step reads and writes besides the paths.
pub(super) struct Outputs<'a> {
    /// Scratch: the light samples of a group, kept between groups.
    pub samples: &'a mut Vec<Candidate>,
    /// The light samples of every group, waiting for their shadow rays.
    pub waiting: &'a mut Vec<Waiting>,
    /// Each group's next-event estimate, waiting for its shadow rays.
    pub groups: &'a mut Vec<GroupTerms>,
    pub shadows: &'a mut Shadows,
    pub alive: &'a mut [bool],
}

/// Sixteen light samples: the lanes that keep theirs, and their shadow rays' origins,
/// directions and ends, and the terms they add if unblocked.
pub(super) struct Candidate {
    /// Bit i set where lane i keeps its sample (bits rather than a mask: testing a lane of
    /// a vector mask stores the vector and loads the lane back, lane after lane).
    keep: u32,
    origin: V16,
    dir: V16,
    end: F16,
    term: [F16; 3],
}

/// Sixteen light samples waiting for their shadow rays: the lanes that have one, where the
/// first of those rays is in `Shadows` (the others follow in lane order), and the terms they
/// add if unblocked.
pub(super) struct Waiting {
    keep: u32,
    first: usize,
    term: [F16; 3],
}

/// A group's next-event estimate waiting for its shadow rays: its paths (indices into the
/// pass's paths, `len` of them), their throughputs, and its light samples (a range of
/// [`Waiting`]s, light by light, `count` samples each).
pub(super) struct GroupTerms {
    paths: [u32; LANES],
    len: usize,
    beta: [F16; 3],
    samples: (usize, usize),
}

impl GroupTerms {
    /// Adds the group's estimate to its paths, given which shadow rays are `blocked`: for
    /// each path, the terms of its unblocked samples summed light by light, each light's sum
    /// over its sample count, times the throughput, in the scalar gathering's order.
    #[inline(always)]
    pub(super) fn gather(
        &self,
        opts: &PathSettings,
        lights: &[RenderLight],
        waiting: &[Waiting],
        blocked: &[bool],
        paths: &mut [PathState],
    ) {
        let zero = F16::splat(0.0);
        let mut total = [zero; 3];
        let mut samples = waiting[self.samples.0..self.samples.1].iter();
        for light in lights {
            let count = light.sample_count(opts.light_samples);
            let mut acc = [zero; 3];
            for w in samples.by_ref().take(count as usize) {
                // Adding zero where a lane has no term leaves its sum as skipping it does:
                // a sum from +0 is never -0.
                let mut open = 0;
                let mut bits = w.keep;
                let mut k = w.first;
                while bits != 0 {
                    let lane = bits.trailing_zeros();
                    bits &= bits - 1;
                    open |= u32::from(!blocked[k]) << lane;
                    k += 1;
                }
                let open = M16::from_bits(open);
                for c in 0..3 {
                    acc[c] = acc[c] + F16::select(open, w.term[c], zero);
                }
            }
            let inv = F16::splat(1.0 / count as f32);
            for c in 0..3 {
                total[c] = total[c] + acc[c] * inv;
            }
        }
        let add = [0, 1, 2].map(|c| self.beta[c] * total[c]);
        for i in 0..self.len {
            paths[self.paths[i] as usize].l += Rgb::new(add[0].0[i], add[1].0[i], add[2].0[i]);
        }
    }
}

/// Sets lane `lane` of `v`.
#[inline(always)]
fn put(v: &mut V16, lane: usize, p: Vec3) {
    v.x.0[lane] = p.x;
    v.y.0[lane] = p.y;
    v.z.0[lane] = p.z;
}

/// `v.x v'.x + v.y v'.y + v.z v'.z` against one vector, in glam's order.
#[inline(always)]
fn dot1(v: V16, o: Vec3) -> F16 {
    v.x * o.x + v.y * o.y + v.z * o.z
}

/// The unit direction from `p` to `q`, the distance and its square, in the scalar light
/// samples' order (`d / |d|`, `|d|^2` as `d.d`).
#[inline(always)]
fn toward(p: V16, q: V16) -> (V16, F16, F16) {
    let d = q - p;
    let dist2 = d.dot(d);
    let dist = dist2.sqrt();
    let wi = V16 {
        x: d.x / dist,
        y: d.y / dist,
        z: d.z / dist,
    };
    (wi, dist, dist2)
}

/// A colour on every lane, channel by channel.
#[inline(always)]
fn rgb(c: Rgb) -> [F16; 3] {
    [c.r, c.g, c.b].map(F16::splat)
}

/// Two consecutive draws of sixteen samplers, `j` and `j + 1` dimensions on.
#[inline(always)]
fn pair(key: &[u64; LANES], dim: &[u64; LANES], j: u64) -> (F16, F16) {
    (lane_values(key, dim, j), lane_values(key, dim, j + 1))
}

/// `f32::max` over the three channels, in `Rgb::max_channel`'s order.
#[inline(always)]
fn max_channel(c: &[F16; 3]) -> F16 {
    c[0].max_num(c[1]).max_num(c[2])
}

/// `v` in the frame `(s, t, n)` (`Frame::to_local`), lane by lane. A function, not a
/// closure: a closure is compiled on its own, without the caller's instruction set.
#[inline(always)]
fn local(v: V16, (s, t, n): (V16, V16, V16)) -> V16 {
    V16 {
        x: v.dot(s),
        y: v.dot(t),
        z: v.dot(n),
    }
}

/// The shading frame of `Frame::from_normal`, lane by lane.
#[inline(always)]
fn frame(n: V16) -> (V16, V16) {
    let one = F16::splat(1.0);
    let sign = one.copysign(n.z);
    let a = F16::splat(-1.0) / (sign + n.z);
    let b = n.x * n.y * a;
    let s = V16 {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: -sign * n.x,
    };
    let t = V16 {
        x: b,
        y: sign + n.y * n.y * a,
        z: -n.y,
    };
    (s, t)
}

/// `Interaction::spawn`'s ray origin, lane by lane.
#[inline(always)]
fn spawn(p: V16, ng: V16, dir: V16) -> V16 {
    let m = p.x.abs().max_num(p.y.abs().max_num(p.z.abs()));
    let eps = F16::splat(1e-4) * (F16::splat(1.0) + m);
    let front = F16::splat(0.0).le(dir.dot(ng));
    let side = V16 {
        x: F16::select(front, ng.x, -ng.x),
        y: F16::select(front, ng.y, -ng.y),
        z: F16::select(front, ng.z, -ng.z),
    };
    p + side * eps
}

/// The power heuristic of `super::power`, lane by lane.
#[inline(always)]
fn power(nf: f32, f: F16, g: F16) -> F16 {
    let a = F16::splat(nf) * f;
    let zero = F16::splat(0.0);
    let both = a.eq(zero) & g.eq(zero);
    F16::select(both, zero, a * a / (a * a + g * g))
}

/// A shading point on sixteen lanes, as a light sample's term needs it.
struct At {
    p: V16,
    ng: V16,
    frame: (V16, V16, V16),
    wo_l: V16,
    wo_front: M16,
}

/// Adds to `cand` the light sample toward `wi` at distance `dist` on the lanes `ok`, with
/// incident radiance `li` weighted as `w` says, for the BSDF `bsdf` at `at`.
#[inline(always)]
fn candidate(
    at: &At,
    bsdf: &SmoothLanes,
    cand: &mut Vec<Candidate>,
    (wi, dist, mut ok): (V16, F16, M16),
    li: [F16; 3],
    w: Weight,
) {
    let zero = F16::splat(0.0);
    let At {
        p,
        ng,
        frame,
        wo_l,
        wo_front,
    } = *at;
    ok = ok & !(wo_front ^ zero.lt(wi.dot(ng)));
    let (f, bsdf_pdf) = bsdf.eval_pdf(wo_l, local(wi, frame));
    ok = ok & !max_channel(&f).le(zero);
    // `f li (w / pdf)`, the density with the light's pick; a delta light's weight is 1
    // and its density the pick's alone.
    let w = match w {
        Weight::Delta => F16::splat(1.0),
        Weight::Mis { count, pdf } => power(count as f32, pdf, bsdf_pdf) / pdf,
        Weight::Picked {
            count,
            pmf,
            pdf,
            delta,
        } => {
            let pdf = F16::splat(pmf) * pdf;
            F16::select(delta, F16::splat(1.0), power(count as f32, pdf, bsdf_pdf)) / pdf
        }
    };
    let term = [0, 1, 2].map(|c| f[c] * li[c] * w);
    // Aimed at the light's point from the pushed-off origin and stopping just short
    // of it, as the scalar light term aims it.
    let origin = spawn(p, ng, wi);
    let finite = dist.is_finite();
    let to_light = (p + wi * dist) - origin;
    let length = to_light.dot(to_light).sqrt();
    ok = ok & (!finite | zero.lt(length));
    let dir = V16 {
        x: F16::select(finite, to_light.x / length, wi.x),
        y: F16::select(finite, to_light.y / length, wi.y),
        z: F16::select(finite, to_light.z / length, wi.z),
    };
    let shadow_dist = F16::select(
        finite,
        length * F16::splat(1.0 - 1e-4),
        F16::splat(f32::INFINITY),
    );
    cand.push(Candidate {
        keep: ok.bits(),
        origin,
        dir,
        end: shadow_dist,
        term,
    });
}

/// How a light sample's term is weighted: a delta light's (by 1), an MIS weight against
/// the BSDF for a sample of density `pdf`, one of `count` of its light, or a sample of a
/// light picked with chance `pmf` (density `pdf`, or a delta light where `delta`).
#[derive(Clone, Copy)]
enum Weight {
    Delta,
    Mis {
        count: u32,
        pdf: F16,
    },
    Picked {
        count: u32,
        pmf: f32,
        pdf: F16,
        delta: M16,
    },
}

/// Sixteen samples `u` of `light` seen from points `p`, on the lanes `lanes`: per lane the
/// direction to the light, its distance, the lanes with a sample, the incident radiance and
/// the density (none: a delta light). Area, point, directional and hemisphere lights are
/// sampled on the lanes, the others by their own code, lane by lane.
#[inline(always)]
fn sample_lanes(
    light: &RenderLight,
    p: V16,
    (ux, uy): (F16, F16),
    lanes: M16,
    sky: &Frame,
) -> (V16, F16, M16, [F16; 3], Option<F16>) {
    let zero = F16::splat(0.0);
    match *light {
        RenderLight::Area {
            corner,
            e1,
            e2,
            normal,
            area,
            radiance,
        } => {
            let q = V16::splat(corner) + V16::splat(e1) * ux + V16::splat(e2) * uy;
            let (wi, dist, dist2) = toward(p, q);
            let cos_l = -dot1(wi, normal);
            let ok = zero.lt(dist) & lanes & zero.lt(cos_l);
            let pdf = dist2 / (F16::splat(area) * cos_l);
            (wi, dist, ok, rgb(radiance), Some(pdf))
        }
        RenderLight::Point {
            position,
            intensity,
        } => {
            let (wi, dist, dist2) = toward(p, V16::splat(position));
            let inv = F16::splat(1.0) / dist2;
            let li = rgb(intensity).map(|c| c * inv);
            (wi, dist, zero.lt(dist) & lanes, li, None)
        }
        RenderLight::Directional {
            to_light,
            irradiance,
        } => {
            let dist = F16::splat(f32::INFINITY);
            (V16::splat(to_light), dist, lanes, rgb(irradiance), None)
        }
        RenderLight::Hemisphere { radiance } => {
            // `cosine_hemisphere` about world +Y, in `Frame::to_world`'s order.
            let local = cosine_hemisphere_lanes(ux, uy);
            let wi = V16::splat(sky.s) * local.x
                + V16::splat(sky.t) * local.y
                + V16::splat(sky.n) * local.z;
            let pdf = local.z.max_num(zero) * F16::splat(std::f32::consts::FRAC_1_PI);
            let dist = F16::splat(f32::INFINITY);
            (wi, dist, lanes & zero.lt(local.z), rgb(radiance), Some(pdf))
        }
        RenderLight::Mesh(_)
        | RenderLight::Sphere(_)
        | RenderLight::Spot(_)
        | RenderLight::Environment { .. }
        | RenderLight::EnvironmentMap(_) => {
            // No lane version of the sample: the light's own, lane by lane.
            let (mut wi, mut dist) = (V16::splat(Vec3::Z), F16::splat(1.0));
            let (mut li, mut pdf) = (rgb(Rgb::BLACK), F16::splat(1.0));
            let mut found = 0;
            let mut bits = lanes.bits();
            while bits != 0 {
                let lane = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let at = Vec3::new(p.x.0[lane], p.y.0[lane], p.z.0[lane]);
                let uv = Vec2::new(ux.0[lane], uy.0[lane]);
                if let Some(ls) = light.sample(at, uv) {
                    put(&mut wi, lane, ls.wi);
                    dist.0[lane] = ls.dist;
                    pdf.0[lane] = ls.pdf;
                    for (c, v) in li.iter_mut().zip([ls.li.r, ls.li.g, ls.li.b]) {
                        c.0[lane] = v;
                    }
                    found |= 1 << lane;
                }
            }
            let pdf = (!light.is_delta()).then_some(pdf);
            (wi, dist, M16::from_bits(found), li, pdf)
        }
    }
}

/// One step of up to sixteen paths `group` (indices into `paths`), whose surfaces have
/// smooth BSDFs of kind `kind`, in a scene lit by `lights`, with light sampling kept at
/// this bounce.
#[inline(always)]
pub(super) fn step(
    kind: SmoothKind,
    opts: &PathSettings,
    lights: &[RenderLight],
    (paths, rays): (&mut [PathState], &mut [Ray]),
    surfs: &[Option<Interaction>],
    group: &[usize],
    out: &mut Outputs,
) {
    let m = group.len();
    let lane_in = M16::first(m);
    let (mut p, mut ng, mut n, mut wo): (V16, V16, V16, V16) = Default::default();
    let mut bsdf = SmoothLanes::new(kind);
    let mut beta = [F16::default(); 3];
    let mut key = [0u64; LANES];
    let mut dim = [0u64; LANES];
    // The sixteen records first, then each field in a loop of its own, which the compiler
    // can turn into one gather.
    let no_surface = "scattering paths have a surface";
    let mut hits = [surfs[group[0]].as_ref().expect(no_surface); LANES];
    let mut from = [&paths[group[0]]; LANES];
    let mut dirs = [Vec3::ZERO; LANES];
    for lane in 0..LANES {
        let k = group[lane.min(m - 1)];
        hits[lane] = surfs[k].as_ref().expect(no_surface);
        from[lane] = &paths[k];
        dirs[lane] = rays[k].dir;
    }
    macro_rules! lanes {
        ($dst:expr, $src:ident . $($field:tt).+) => {
            for lane in 0..LANES {
                $dst.0[lane] = $src[lane].$($field).+;
            }
        };
    }
    lanes!(p.x, hits.p.x);
    lanes!(p.y, hits.p.y);
    lanes!(p.z, hits.p.z);
    lanes!(ng.x, hits.ng.x);
    lanes!(ng.y, hits.ng.y);
    lanes!(ng.z, hits.ng.z);
    lanes!(n.x, hits.ns.x);
    lanes!(n.y, hits.ns.y);
    lanes!(n.z, hits.ns.z);
    lanes!(wo.x, dirs.x);
    lanes!(wo.y, dirs.y);
    lanes!(wo.z, dirs.z);
    wo = -wo;
    lanes!(beta[0], from.beta.r);
    lanes!(beta[1], from.beta.g);
    lanes!(beta[2], from.beta.b);
    for lane in 0..LANES {
        (key[lane], dim[lane]) = from[lane].sampler.state();
        bsdf.put(lane, &hits[lane].bsdf);
    }
    let (s, t) = frame(n);
    let wo_l = local(wo, (s, t, n));
    let wo_front = F16::splat(0.0).lt(wo.dot(ng));
    let zero = F16::splat(0.0);

    // Light samples: per light, `count` samples (one for a delta light), each a possible
    // shadow ray.
    let cand = &mut *out.samples;
    cand.clear();
    cand.reserve(if opts.one_light {
        opts.light_samples.max(1) as usize
    } else {
        lights
            .iter()
            .map(|l| l.sample_count(opts.light_samples) as usize)
            .sum()
    });
    let sky = Frame::from_normal(Vec3::Y);
    let mut draw = 0;
    let at = At {
        p,
        ng,
        frame: (s, t, n),
        wo_l,
        wo_front,
    };
    if opts.one_light && !lights.is_empty() {
        // Each sample picks one light per lane, then samples it with the numbers left.
        let count = opts.light_samples.max(1);
        for _ in 0..count {
            let (ux, uy) = pair(&key, &dim, draw);
            draw += 2;
            let mut which = [0usize; LANES];
            let mut rest = ux;
            let mut pmf = 1.0;
            for lane in 0..LANES {
                (which[lane], rest.0[lane], pmf) =
                    PathSettings::pick_light(ux.0[lane], lights.len());
            }
            let (mut wi, mut dist) = (V16::splat(Vec3::Z), F16::splat(1.0));
            let (mut ok, mut delta) = (M16::splat(false), M16::splat(false));
            let (mut li, mut pdf) = (rgb(Rgb::BLACK), F16::splat(1.0));
            for (i, light) in lights.iter().enumerate() {
                let mut bits = 0u32;
                for lane in 0..m {
                    bits |= u32::from(which[lane] == i) << lane;
                }
                if bits == 0 {
                    continue;
                }
                let sel = M16::from_bits(bits);
                let (wi_i, dist_i, ok_i, li_i, pdf_i) =
                    sample_lanes(light, p, (rest, uy), sel, &sky);
                wi = V16 {
                    x: F16::select(sel, wi_i.x, wi.x),
                    y: F16::select(sel, wi_i.y, wi.y),
                    z: F16::select(sel, wi_i.z, wi.z),
                };
                dist = F16::select(sel, dist_i, dist);
                ok = ok | (ok_i & sel);
                for c in 0..3 {
                    li[c] = F16::select(sel, li_i[c], li[c]);
                }
                match pdf_i {
                    Some(d) => pdf = F16::select(sel, d, pdf),
                    None => delta = delta | sel,
                }
            }
            let w = Weight::Picked {
                count,
                pmf,
                pdf,
                delta,
            };
            candidate(&at, &bsdf, cand, (wi, dist, ok), li, w);
        }
    } else if !opts.one_light {
        // Per light, `count` samples (one for a delta light), each a possible shadow ray.
        for light in lights {
            let count = light.sample_count(opts.light_samples);
            for _ in 0..count {
                // The sample's two numbers, drawn only where used (a delta light needs none).
                let u = draw;
                draw += 2;
                let uv = if light.is_delta() {
                    (zero, zero)
                } else {
                    pair(&key, &dim, u)
                };
                let (wi, dist, ok, li, pdf) = sample_lanes(light, p, uv, lane_in, &sky);
                let w = pdf.map_or(Weight::Delta, |pdf| Weight::Mis { count, pdf });
                candidate(&at, &bsdf, cand, (wi, dist, ok), li, w);
            }
        }
    }
    let first = out.waiting.len();
    for c in out.samples.iter() {
        let start = out.shadows.len();
        let mut bits = c.keep;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let at = |v: &V16| Vec3::new(v.x.0[i], v.y.0[i], v.z.0[i]);
            out.shadows
                .push_ray(Ray::new(at(&c.origin), at(&c.dir)), c.end.0[i]);
        }
        out.waiting.push(Waiting {
            keep: c.keep,
            first: start,
            term: c.term,
        });
    }
    let mut group_paths = [0; LANES];
    for (lane, &k) in group_paths.iter_mut().zip(group) {
        *lane = k as u32;
    }
    out.groups.push(GroupTerms {
        paths: group_paths,
        len: m,
        beta,
        samples: (first, out.waiting.len()),
    });

    // The BSDF sample.
    let bounce = paths[group[0]].bounce + 1;
    let roulette = bounce >= opts.rr_bounces;
    // The lobe choice (unused by a smooth BSDF), the direction, then the roulette's.
    let (u2x, u2y) = (
        lane_values(&key, &dim, draw + 1),
        lane_values(&key, &dim, draw + 2),
    );
    let rr = lane_values(&key, &dim, draw + 3);
    let drawn = draw + 3 + u64::from(roulette);
    for &k in group {
        paths[k].sampler.advance(drawn);
    }
    let sample = bsdf.sample(wo_l, u2x, u2y);
    let mut ok = lane_in & sample.ok;
    let pdf = sample.pdf;
    let wi = s * sample.wi.x + t * sample.wi.y + n * sample.wi.z;
    ok = ok & !(wo_front ^ zero.lt(wi.dot(ng)));
    let mut b = [
        beta[0] * sample.weight[0],
        beta[1] * sample.weight[1],
        beta[2] * sample.weight[2],
    ];
    let bmax = max_channel(&b);
    ok = ok & !bmax.le(zero);
    // Paths of one pass advance together: the group's paths are at the same bounce.
    debug_assert!(group.iter().all(|&k| paths[k].bounce + 1 == bounce));
    if roulette {
        let q = bmax.min_num(F16::splat(0.95));
        // The path ends where `u >= q` (false for NaN, as in the scalar test).
        ok = ok & !q.le(rr);
        let inv = F16::splat(1.0) / q;
        b = b.map(|c| c * inv);
    }
    let origin = spawn(p, ng, wi);
    let ok = ok.bits();
    for i in 0..m {
        let k = group[i];
        let alive = ok >> i & 1 != 0;
        out.alive[k] = alive;
        if alive {
            let path = &mut paths[k];
            path.beta = Rgb::new(b[0].0[i], b[1].0[i], b[2].0[i]);
            rays[k] = Ray::new(
                Vec3::new(origin.x.0[i], origin.y.0[i], origin.z.0[i]),
                Vec3::new(wi.x.0[i], wi.y.0[i], wi.z.0[i]),
            );
            path.bounce = bounce;
            path.pdf = pdf.0[i];
            path.mis = true;
        }
    }
}

/// [`step`] compiled for AVX-512 (DQ for the samplers' 64-bit products).
///
/// # Safety
/// The processor must support AVX-512F and AVX-512DQ.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq")]
pub(super) unsafe fn step_avx512(
    kind: SmoothKind,
    opts: &PathSettings,
    lights: &[RenderLight],
    (paths, rays): (&mut [PathState], &mut [Ray]),
    surfs: &[Option<Interaction>],
    group: &[usize],
    out: &mut Outputs,
) {
    step(kind, opts, lights, (paths, rays), surfs, group, out);
}

/// [`step`] compiled for AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn step_avx2(
    kind: SmoothKind,
    opts: &PathSettings,
    lights: &[RenderLight],
    (paths, rays): (&mut [PathState], &mut [Ray]),
    surfs: &[Option<Interaction>],
    group: &[usize],
    out: &mut Outputs,
) {
    step(kind, opts, lights, (paths, rays), surfs, group, out);
}

/// [`step`] on the best instructions the processor has.
pub(super) fn step_dispatch(
    kind: SmoothKind,
    opts: &PathSettings,
    lights: &[RenderLight],
    (paths, rays): (&mut [PathState], &mut [Ray]),
    surfs: &[Option<Interaction>],
    group: &[usize],
    out: &mut Outputs,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if prism_math::Isa::avx512() {
            // SAFETY: the processor has AVX-512F and AVX-512DQ.
            return unsafe { step_avx512(kind, opts, lights, (paths, rays), surfs, group, out) };
        }
        if prism_math::Isa::avx2() {
            // SAFETY: the processor has AVX2.
            return unsafe { step_avx2(kind, opts, lights, (paths, rays), surfs, group, out) };
        }
    }
    step(kind, opts, lights, (paths, rays), surfs, group, out);
}
