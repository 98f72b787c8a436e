#!/usr/bin/env python3
"""The same pack computation as sunbeam-pack (window model, Chebyshev, Z = 2,
Kaiser-Bessel deapodisation, phase centring, crop), in numpy/scipy with
scipy.fft.rfft2(workers=2). Usage: bench_numpy.py M N OUT.npy; prints one JSON line.
Writes the stacked crop (complex64) so the output size matches the KTX2 pack."""
import json, math, sys, time
import numpy as np
import scipy.fft

M, N, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
dx = 30e-9
lam_min, taps = 380e-9, 6
tau = 2 * math.pi

c = np.arange(M)
X, Y = np.meshgrid(c * dx, c * dx)
h = 200e-9 * np.sin(tau * X / 1.1e-6) * (0.5 + 0.5 * np.cos(tau * Y / 3.7e-6)) + 80e-9 * np.sin(tau * (X + 0.6 * Y) / 0.83e-6)
del X, Y
t0 = time.perf_counter()
h = h[::-1]  # rows up the image (y up), as the Rust code indexes them
lo, hi = h.min(), h.max()
hc, H = (lo + hi) / 2, (hi - lo) / 2
s = (h - hc) / H
del h
L = M * dx
Z = 2
Nx = Z * M
beta = math.pi * math.sqrt(taps * taps / 4 * 2.25 - 0.8)
K = math.ceil(2 / lam_min * Z * L) + taps // 2
sigma = min(65e-6 / 4, L / 6)
cx = (M - 1) / 2
g = np.exp(-((c - cx) * dx) ** 2 / (2 * sigma ** 2))
nu = (c - cx) / Nx
z = beta ** 2 - (math.pi * taps * nu) ** 2
phihat = beta * np.sinh(np.sqrt(z)) / (math.sinh(beta) * np.sqrt(z))
w1 = g / phihat
wgt = np.outer(w1, w1) / (g.sum() ** 2)
k = np.arange(-K, K + 1)
ph = np.exp(2j * math.pi * k * cx / Nx)
phase = np.outer(ph, ph)
crop = np.empty((N, 2 * K + 1, 2 * K + 1), np.complex64)
prev = np.ones_like(s)
cur = s.copy()
for n in range(N):
    if n == 0:
        b = np.ones_like(s)
    elif n == 1:
        b = s
    else:
        b = 2 * s * cur - prev
        prev, cur = cur, b
    F = scipy.fft.rfft2(b * wgt, s=(Nx, Nx), workers=2)
    ky = k % Nx
    pos = F[np.ix_(ky, np.arange(0, K + 1) % Nx)]  # kx >= 0
    full = np.empty((2 * K + 1, 2 * K + 1), np.complex128)
    full[:, K:] = pos
    full[:, :K] = np.conj(pos[::-1, :0:-1])  # Hermitian: D[-kx,-ky] = conj D[kx,ky]
    crop[n] = full * phase
    del F
np.save(out, crop)
t1 = time.perf_counter()
print(json.dumps({"impl": "numpy", "M": M, "N": N, "crop": 2 * K + 1, "total_s": round(t1 - t0, 3)}))
