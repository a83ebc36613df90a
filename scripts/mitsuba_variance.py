#!/usr/bin/env python3
"""The per-pixel variance of one sample's luminance in Mitsuba 3's render of the course's
CBspheres_lambertian.dae (512x384, max_depth 8, through ../shared/bench/pathtrace's
converter), from the spread of 256 renders of 16 samples (seeds 100 to 355): the variance
image prism-render's per-pixel Z-test reads (tests/golden/mitsuba/). Needs mitsuba 3.9.1,
drjit 1.5.0, OpenEXR and libLLVM 19.

Usage: python3 scripts/mitsuba_variance.py VARIANCE.exr MEAN.exr   (from the workspace root)
"""
import os, sys, numpy as np
os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "../shared/bench/pathtrace"))
import dae_to_mitsuba as d
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
import drjit as dr
import OpenEXR
W, H, P, N = 512, 384, 16, 256
scene = mi.load_dict(d.to_mitsuba_dict(d.parse_dae(os.path.join(ROOT, "../shared/assets/pathtracer/dae/sky/CBspheres_lambertian.dae")), W, H, 8, P))
acc = np.zeros((H, W)); acc2 = np.zeros((H, W))
w = np.array([0.2126, 0.7152, 0.0722])
for i in range(N):
    img = np.array(mi.render(scene, spp=P, seed=100 + i), dtype=np.float64)
    y = img[..., :3] @ w
    acc += y; acc2 += y * y
    if i % 32 == 0: print(i, flush=True)
mean = acc / N
var_pass = np.maximum(acc2 - N * mean * mean, 0) / (N - 1)
sample_var = (var_pass * P).astype(np.float32)
OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, {"Y": sample_var}).write(sys.argv[1])
OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, {"Y": mean.astype(np.float32)}).write(sys.argv[2])
print("mean luminance", mean.mean(), "mean sample variance", sample_var.mean())
