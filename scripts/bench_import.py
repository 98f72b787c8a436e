#!/usr/bin/env python3
"""Benchmark: import + plane level + resample of a large Nanoscope scan,
sunbeam-import against the same job in Python (pySPM + numpy/scipy), both
timed in this one run. Not a test: figures go to docs/bench/import.md.

    python3 scripts/bench_import.py [--size 4096] [--repeat 3] [--bin PATH]

Needs: a release build of sunbeam-import (cargo build --release -p sunbeam-import),
pip install pySPM numpy scipy. The generated scan lives in a temporary folder.
"""
import argparse, os, platform, shutil, subprocess, sys, tempfile, time
import numpy as np


def make_nanoscope(path, n, scan_um=10.0):
    """A Nanoscope v5.31-style file (header + int16 Height channel, bottom row first)."""
    rng = np.random.default_rng(1)
    # Band-limited bumps (filtered noise) + tilt + row offsets, in LSB.
    f = np.fft.rfft2(rng.standard_normal((n, n)))
    ky = np.fft.fftfreq(n)[:, None]
    kx = np.fft.rfftfreq(n)[None, :]
    f *= np.exp(-((kx**2 + ky**2) / (2 * 0.01**2)))
    z = np.fft.irfft2(f, s=(n, n))
    z *= 6000 / z.std()
    yy, xx = np.mgrid[0:n, 0:n]
    z += 4.0 * xx - 2.5 * yy + rng.normal(0, 300, n)[:, None]
    raw = np.clip(np.round(z - z.mean()), -32768, 32767).astype("<i2")
    off = 40960
    hdr = [
        "\\*File list", "\\Version: 0x05310001", f"\\Data length: {off}",
        "\\*Equipment list", "\\Description: synthetic benchmark scan",
        "\\*Scanner list", "\\@Sens. Zscan: V 7.000000 nm/V",
        "\\*Ciao scan list", f"\\Scan size: {scan_um*1000:.2f} nm", f"\\Samps/line: {n}",
        "\\*Ciao image list", f"\\Data offset: {off}", f"\\Data length: {n*n*2}", "\\Bytes/pixel: 2",
        f"\\Samps/line: {n}", f"\\Number of lines: {n}", "\\Aspect ratio: 1:1",
        f"\\Scan size: {scan_um} {scan_um} ~m", "\\Line direction: Retrace",
        "\\Valid data start X: 0", "\\Valid data start Y: 0",
        f"\\Valid data len X: {n}", f"\\Valid data len Y: {n}",
        '\\@2:Image Data: S [Height] "Height"',
        "\\@2:Z scale: V [Sens. Zscan] (0.006539403 V/LSB) 41.60368 V",
        "\\@2:Z offset: V [Sens. Zscan] (0.006539403 V/LSB)       0 V",
        "\\*File list end",
    ]
    text = ("\r\n".join(hdr) + "\r\n").encode("latin1")
    assert len(text) < off
    with open(path, "wb") as fh:
        fh.write(text + b"\x1a" + b"\0" * (off - len(text) - 1))
        fh.write(raw[::-1].tobytes())  # bottom row first, as Nanoscope stores it


def plane_level(z):
    n, m = z.shape
    i, j = np.mgrid[0:n, 0:m]
    A = np.stack([np.ones(z.size), j.ravel(), i.ravel()], 1)
    c, bx, by = np.linalg.lstsq(A, z.ravel(), rcond=None)[0]
    return z - bx * (j - m / 2) - by * (i - n / 2)


def write_gsf(path, z, xreal, yreal):
    h = f"Gwyddion Simple Field 1.0\nXRes = {z.shape[1]}\nYRes = {z.shape[0]}\nXReal = {xreal}\nYReal = {yreal}\nXYUnits = m\nZUnits = m\n".encode()
    h += b"\0" * (4 - len(h) % 4)
    with open(path, "wb") as fh:
        fh.write(h + z.astype("<f4").tobytes())


def python_job(src, out, pixel, resampler, reader):
    import scipy.ndimage, scipy.signal
    if reader == "pySPM":
        import pySPM
        s = pySPM.Bruker(src).get_channel("Height")
        z = np.asarray(s.pixels, dtype=float)[::-1] * 1e-9  # pySPM: nm, bottom row first
        lx = s.size["real"]["x"] * (1e-6 if s.size["real"]["unit"] in ("um", "µm", "μm") else 1e-9)
    else:  # numpy: parse the two numbers needed and np.fromfile
        head = open(src, "rb").read(40960).decode("latin1")
        n = int(head.split("\\Samps/line: ")[1].split()[0])
        z = np.fromfile(src, dtype="<i2", offset=40960, count=n * n).reshape(n, n)[::-1].astype(float)
        z *= 41.60368 / 65536 * 7e-9
        lx = 10e-6
    n = z.shape[1]
    z = plane_level(z)
    m = int(round(lx / pixel))
    if resampler == "zoom":  # cubic spline, no anti-aliasing
        r = scipy.ndimage.zoom(z, m / n, order=3)
    else:  # FFT (band-limited, periodic)
        r = scipy.signal.resample(scipy.signal.resample(z, m, axis=0), m, axis=1)
    write_gsf(out, r, m * pixel, m * pixel)
    return r.shape


def timed(fn, repeat):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return min(ts), sorted(ts)[len(ts) // 2]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--pixel", default="5nm")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    tgt = os.environ.get("CARGO_TARGET_DIR", os.path.join(root, "target"))
    ap.add_argument("--bin", default=os.path.join(tgt, "release", "sunbeam-import"))
    a = ap.parse_args()
    pixel = float(a.pixel.rstrip("nm")) * 1e-9
    d = tempfile.mkdtemp(prefix="sunbeam-bench-")
    try:
        src = os.path.join(d, f"bench_{a.size}.003")
        make_nanoscope(src, a.size)
        rows = []
        jobs = [("gsf", ["--level", "plane", "--resample-to", a.pixel], "(kaiser-sinc, anti-aliased)"),
                ("exr", ["--level", "plane", "--resample-to", a.pixel], "(kaiser-sinc, anti-aliased)"),
                ("gsf", [], "(read + write only, for the split)")]
        for ext, extra, label in jobs:
            out = os.path.join(d, f"out.{ext}")
            cmd = [a.bin, src, "-o", out, "-q"] + extra
            subprocess.run(cmd, check=True)  # warm the page cache
            best, med = timed(lambda: subprocess.run(cmd, check=True), a.repeat)
            rows.append((f"sunbeam-import -> .{ext} {label}", best, med))
        for reader in ("pySPM", "numpy"):
            for rs in ("zoom", "fft"):
                out = os.path.join(d, f"py_{reader}_{rs}.gsf")
                best, med = timed(lambda: python_job(src, out, pixel, rs, reader), a.repeat)
                label = {"zoom": "scipy.ndimage.zoom order 3 (no anti-aliasing)",
                         "fft": "scipy.signal.resample (FFT, anti-aliased)"}[rs]
                rows.append((f"Python: {reader} read + numpy plane + {label} -> .gsf", best, med))
        base = rows[0][1]
        m = int(round(10e-6 / pixel))
        print(f"Job: {a.size}x{a.size} int16 Nanoscope (10 um), plane level, resample to {a.pixel} ({m}x{m}), write.")
        import scipy
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        print(f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs (load average {load:.1f} "
              f"at the end), Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}; "
              f"best and median of {a.repeat} runs, wall clock.\n")
        print("| job | best (s) | median (s) | vs sunbeam-import .gsf |")
        print("|---|---|---|---|")
        for name, best, med in rows:
            print(f"| {name} | {best:.2f} | {med:.2f} | {best/base:.1f}x |")
    finally:
        shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
