#!/usr/bin/env python3
"""Mitsuba 3's render of a Mitsuba scene file, as the reference prism's render of the same
file is tested against: the mean image over N renders of P samples (seeds 100, 101, ...)
and the per-pixel variance of one sample's luminance, from the spread of those renders.
Needs mitsuba 3.9.1, drjit 1.5.0, OpenEXR and libLLVM 19.

Usage: python3 scripts/mitsuba_xml_reference.py SCENE.xml MEAN.exr VARIANCE.exr [N [P [NAME=VALUE ...]]]
(NAME=VALUE: the scene's $parameters, as Mitsuba's -D)
"""
import os, sys, numpy as np
os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
import OpenEXR
scene_path, mean_path, var_path = sys.argv[1:4]
N = int(sys.argv[4]) if len(sys.argv) > 4 else 256
P = int(sys.argv[5]) if len(sys.argv) > 5 else 64
params = dict(a.split("=", 1) for a in sys.argv[6:])
scene = mi.load_file(scene_path, **params)
w = np.array([0.2126, 0.7152, 0.0722])
acc = None
for i in range(N):
    img = np.array(mi.render(scene, spp=P, seed=100 + i), dtype=np.float64)[..., :3]
    if acc is None:
        acc = np.zeros_like(img); accy = np.zeros(img.shape[:2]); accy2 = np.zeros(img.shape[:2])
    acc += img
    y = img @ w
    accy += y; accy2 += y * y
mean = (acc / N).astype(np.float32)
my = accy / N
sample_var = (np.maximum(accy2 - N * my * my, 0) / (N - 1) * P).astype(np.float32)
header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
OpenEXR.File(header, {c: np.ascontiguousarray(mean[..., i]) for i, c in enumerate("RGB")}).write(mean_path)
OpenEXR.File(header, {"Y": sample_var}).write(var_path)
print("mean", mean.reshape(-1, 3).mean(0), "mean sample variance", sample_var.mean())
