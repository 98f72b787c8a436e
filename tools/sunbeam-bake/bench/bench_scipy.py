"""scipy side of the bake benchmark (docs/bench/bake.md).

Reads OUT_DIR/{uv.f64, samples.csv, rust_linear.f64, rust_natural.f64} written by
`cargo run --release -p sunbeam-mesh --example bench_interp -- OUT_DIR`, runs the
same axial interpolation (doubled-angle vector, then halved) with scipy's
LinearNDInterpolator (= griddata(method="linear")) and CloughTocher2DInterpolator
(= griddata(method="cubic")), single-threaded, and prints timings and the
agreement with the Rust results as JSON.
"""
import json, sys, time
import numpy as np
import scipy
from scipy.interpolate import LinearNDInterpolator, CloughTocher2DInterpolator

out = sys.argv[1]
uv = np.fromfile(f"{out}/uv.f64", dtype="<f8").reshape(-1, 2)
s = np.loadtxt(f"{out}/samples.csv", delimiter=",", skiprows=1)
pts, ang = s[:, :2], np.radians(s[:, 2])
vals = np.stack([np.cos(2 * ang), np.sin(2 * ang)], axis=1)

def field(u, v):
    return 0.8 * np.sin(2.5 * u) + 0.6 * np.cos(6.0 * v + 0.3) * u

def axial(a, b):
    d = np.mod(a - b, np.pi)
    return np.minimum(d, np.pi - d)

rep = {"scipy": scipy.__version__, "numpy": np.__version__, "vertices": len(uv), "samples": len(pts)}
truth = field(uv[:, 0], uv[:, 1])
for name, cls in [("linear", LinearNDInterpolator), ("cubic", CloughTocher2DInterpolator)]:
    best_b, best_e = 1e9, 1e9
    for _ in range(3):
        t0 = time.perf_counter()
        f = cls(pts, vals)
        t1 = time.perf_counter()
        r = f(uv)
        t2 = time.perf_counter()
        best_b, best_e = min(best_b, t1 - t0), min(best_e, t2 - t1)
    a = 0.5 * np.arctan2(r[:, 1], r[:, 0])
    ok = np.isfinite(a)
    e = axial(a[ok], truth[ok])
    entry = {"build_s": best_b, "eval_s": best_e, "inside_hull": int(ok.sum()),
             "rms_err_rad": float(np.sqrt(np.mean(e * e))), "p99_err_rad": float(np.quantile(e, 0.99)), "max_err_rad": float(e.max())}
    if name == "linear":
        rl = np.fromfile(f"{out}/rust_linear.f64", dtype="<f8")
        both = ok & np.isfinite(rl)
        entry["max_diff_vs_rust_linear_rad"] = float(axial(a[both], rl[both]).max())
        entry["hull_mismatch_vertices"] = int((ok != np.isfinite(rl)).sum())
    rep[name] = entry
print(json.dumps(rep, indent=2))
