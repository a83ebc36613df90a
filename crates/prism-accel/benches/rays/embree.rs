//! Embree 4 loaded at run time (`dlopen`), for the rays bench's side-by-side mode: a scene of
//! the bench's triangles, built with Embree's defaults (as `embree_rays.py` builds it), and
//! its one-ray closest-hit call, `rtcIntersect1`.

use std::ffi::{c_char, c_void, CString};

use prism_math::{Ray, Vec3};

/// `RTCRayHit`: a ray, then its hit (with room past the one instance level declared, for
/// libraries built with more).
#[repr(C, align(16))]
struct RayHit {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 9],
}

type NewDevice = unsafe extern "C" fn(*const c_char) -> *mut c_void;
type NewScene = unsafe extern "C" fn(*mut c_void) -> *mut c_void;
type NewGeometry = unsafe extern "C" fn(*mut c_void, u32) -> *mut c_void;
type SetNewBuffer = unsafe extern "C" fn(*mut c_void, u32, u32, u32, usize, usize) -> *mut c_void;
type Unary = unsafe extern "C" fn(*mut c_void);
type Attach = unsafe extern "C" fn(*mut c_void, *mut c_void) -> u32;
type Intersect1 = unsafe extern "C" fn(*mut c_void, *mut RayHit, *mut c_void);

const INVALID: u32 = u32::MAX;

/// An Embree scene of triangles, ready to trace.
pub struct Embree {
    scene: *mut c_void,
    intersect1: Intersect1,
}

// SAFETY: a committed Embree scene may be traced from any number of threads at once.
unsafe impl Sync for Embree {}

impl Embree {
    /// Loads the library at `lib` and builds a scene of `tris`; `None` (with a message on
    /// standard error) if the library or one of its functions cannot be loaded.
    pub fn new(lib: &str, tris: &[[Vec3; 3]]) -> Option<Embree> {
        let path = CString::new(lib).ok()?;
        // SAFETY: `dlopen` and `dlsym` are given NUL-terminated strings; each symbol is
        // cast to the signature Embree 4's headers declare for it.
        unsafe {
            let h = libc::dlopen(path.as_ptr(), libc::RTLD_NOW);
            if h.is_null() {
                eprintln!("PRISM_EMBREE: cannot load {lib}");
                return None;
            }
            let sym = |name: &str| {
                let c = CString::new(name).expect("no NUL");
                let p = libc::dlsym(h, c.as_ptr());
                if p.is_null() {
                    eprintln!("PRISM_EMBREE: {lib} has no {name}");
                }
                (!p.is_null()).then_some(p)
            };
            let new_device: NewDevice = std::mem::transmute(sym("rtcNewDevice")?);
            let new_scene: NewScene = std::mem::transmute(sym("rtcNewScene")?);
            let new_geometry: NewGeometry = std::mem::transmute(sym("rtcNewGeometry")?);
            let set_buffer: SetNewBuffer = std::mem::transmute(sym("rtcSetNewGeometryBuffer")?);
            let commit_geometry: Unary = std::mem::transmute(sym("rtcCommitGeometry")?);
            let attach: Attach = std::mem::transmute(sym("rtcAttachGeometry")?);
            let release_geometry: Unary = std::mem::transmute(sym("rtcReleaseGeometry")?);
            let commit_scene: Unary = std::mem::transmute(sym("rtcCommitScene")?);
            let intersect1: Intersect1 = std::mem::transmute(sym("rtcIntersect1")?);
            let device = new_device(std::ptr::null());
            let scene = new_scene(device);
            // RTC_GEOMETRY_TYPE_TRIANGLE; RTC_BUFFER_TYPE_VERTEX / INDEX; FLOAT3 / UINT3.
            let geom = new_geometry(device, 0);
            let n = tris.len();
            let v = set_buffer(geom, 1, 0, 0x9003, 12, 3 * n).cast::<f32>();
            let ix = set_buffer(geom, 0, 0, 0x5003, 12, n).cast::<u32>();
            for (i, t) in tris.iter().enumerate() {
                for (k, p) in t.iter().enumerate() {
                    for a in 0..3 {
                        *v.add(9 * i + 3 * k + a) = p[a];
                    }
                    *ix.add(3 * i + k) = (3 * i + k) as u32;
                }
            }
            commit_geometry(geom);
            attach(scene, geom);
            release_geometry(geom);
            commit_scene(scene);
            Some(Embree { scene, intersect1 })
        }
    }

    /// The closest hit's distance along `ray` with `0 <= t`, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let mut rh = RayHit {
            org: ray.origin.to_array(),
            tnear: 0.0,
            dir: ray.dir.to_array(),
            time: 0.0,
            tfar: f32::INFINITY,
            mask: u32::MAX,
            id: 0,
            flags: 0,
            ng: [0.0; 3],
            u: 0.0,
            v: 0.0,
            prim_id: INVALID,
            geom_id: INVALID,
            inst_id: [INVALID; 9],
        };
        // SAFETY: the scene is committed and `rh` is a 16-byte aligned `RTCRayHit`.
        unsafe { (self.intersect1)(self.scene, &mut rh, std::ptr::null_mut()) };
        (rh.geom_id != INVALID).then_some(rh.tfar)
    }
}
