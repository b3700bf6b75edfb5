#!/usr/bin/env python3
"""The equivalent analysis with pandas + numpy (+ scipy for the filter design), for the
side-by-side speed figure of `benches/analyze.rs`. Not used by any test.

Usage: python3 benches/analyze_pandas.py target/analyze-bench-recording

Same steps as `ratecal analyze` without a procedure: read manifest and CSVs, synchronise
the table feedback to the IMU stamps by linear interpolation, references from the table
kinematics (seed station, Earth rate), 3-sigma outliers per segment, seed accelerometer
model by least squares over every static sample, gyro bias from the longest static block,
gyro scale per axis from rate points with the bias fixed, overlapping Allan deviation,
residual statistics per segment and channel, JSON out.
"""
import json
import sys
import time

import numpy as np
import pandas as pd
import yaml

t_start = time.perf_counter()
run = sys.argv[1]
with open(f"{run}/manifest.yaml") as f:
    man = yaml.safe_load(f)
imu = pd.read_csv(f"{run}/imu.csv")
tab = pd.read_csv(f"{run}/table.csv")
site = man["station"]["site"]
g, lat = site["gravity_mps2"], np.radians(site["latitude_deg"])
a_o = np.array(man["station"]["table"]["outer_axis"], float)
a_i = np.array(man["station"]["table"]["inner_axis"], float)
W_E = 7.2921150e-5
omega_l = W_E * np.array([0.0, np.cos(lat), np.sin(lat)])


def rot(u, th):
    """Rodrigues, vectorised over th: (n, 3, 3)."""
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    s, c = np.sin(th)[:, None, None], np.cos(th)[:, None, None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)


def references(t):
    o = np.radians(np.interp(t, tab.t, tab.outer))
    i = np.radians(np.interp(t, tab.t, tab.inner))
    do = np.radians(np.interp(t, tab.t, tab.outer_rate))
    di = np.radians(np.interp(t, tab.t, tab.inner_rate))
    r_i = rot(a_i, i)
    c_lb = rot(a_o, o) @ r_i
    c_bl = np.transpose(c_lb, (0, 2, 1))
    f = c_bl @ np.array([0, 0, g])
    w_p = np.einsum("nji,j->ni", r_i, a_o) * do[:, None] + a_i[None, :] * di[:, None]
    w_ib = w_p + c_bl @ omega_l
    return f, np.degrees(w_ib)


segs = []
for s in man["segments"]:
    m = (imu.t >= s["t_start"]) & (imu.t <= s["t_end"])
    d = imu[m]
    t = d.t.to_numpy()
    f, w = references(t)
    a = d[["ax", "ay", "az"]].to_numpy()
    gy = d[["gx", "gy", "gz"]].to_numpy()
    keep = np.ones(len(t), bool)
    for x, r in ((a, f), (gy, w)):
        res = x - r
        for _ in range(5):
            mu, sd = res[keep].mean(0), res[keep].std(0, ddof=1)
            bad = (np.abs(res - mu) > 3 * sd).any(1) & keep
            if not bad.any():
                break
            keep &= ~bad
    segs.append(dict(seg=s, t=t[keep], f=f[keep], w=w[keep], a=a[keep], g=gy[keep]))

static = [s for s in segs if s["seg"]["kind"] == "static"]
rate = [s for s in segs if s["seg"]["kind"] == "rate"]
out = {"parameters": {}, "residuals": []}
F = np.concatenate([s["f"] for s in static])
A = np.concatenate([s["a"] for s in static])
for k, ax in enumerate("xyz"):
    X = np.column_stack([F[:, k], np.ones(len(F))])
    coef, rss, *_ = np.linalg.lstsq(X, A[:, k], rcond=None)
    cov = rss[0] / (len(F) - 2) * np.linalg.inv(X.T @ X)
    out["parameters"][f"accel.scale.{ax}"] = {"value": (coef[0] - 1) * 1e6, "u": np.sqrt(cov[0, 0]) * 1e6}
    out["parameters"][f"accel.bias.{ax}"] = {"value": coef[1], "u": np.sqrt(cov[1, 1])}
    for s in static:
        r = s["a"][:, k] - coef[0] * s["f"][:, k] - coef[1]
        out["residuals"].append([s["seg"]["id"], "accel", ax, r.mean(), r.std(ddof=1), np.polyfit(s["t"], r, 1)[0]])
block = max(static, key=lambda s: s["seg"]["t_end"] - s["seg"]["t_start"])
bias = (block["g"] - block["w"]).mean(0)
noise = (block["g"] - block["w"]).std(0, ddof=1)
for k, ax in enumerate("xyz"):
    out["parameters"][f"gyro.bias.{ax}"] = {"value": bias[k], "u": noise[k] / np.sqrt(len(block["t"]))}
    o = np.array([s["g"][:, k].mean() for s in rate])
    r = np.array([s["w"][:, k].mean() for s in rate])
    if np.sqrt((r**2).mean()) < 1.0:
        out["parameters"][f"gyro.scale.{ax}"] = {"observable": False}
        continue
    kk = (r * (o - bias[k])).sum() / (r**2).sum()
    sc = ((o - bias[k] - kk * r) ** 2).sum() / (len(r) - 1)
    out["parameters"][f"gyro.scale.{ax}"] = {"value": (kk - 1) * 1e6, "u": np.sqrt(sc / (r**2).sum()) * 1e6}
    for s in rate:
        res = s["g"][:, k] - bias[k] - kk * s["w"][:, k]
        out["residuals"].append([s["seg"]["id"], "gyro", ax, res.mean(), res.std(ddof=1), np.polyfit(s["t"], res, 1)[0]])
# Overlapping Allan deviation, octave taus.
dt = np.median(np.diff(block["t"]))
allan = []
for k in range(3):
    theta = np.concatenate([[0], np.cumsum(block["g"][:, k]) * dt])
    n, m, curve = len(block["g"]), 1, []
    while 4 * m <= n:
        d = theta[2 * m:] - 2 * theta[m:-m] + theta[: -2 * m]
        curve.append(np.sqrt((d**2).mean() / (2 * (m * dt) ** 2)))
        m *= 2
    allan.append(curve)
out["allan"] = allan
json.dumps(out, default=float)
elapsed = time.perf_counter() - t_start
print(f"pandas+numpy analysis: {elapsed * 1000:.1f} ms ({len(imu)} IMU rows)", file=sys.stderr)
for k in ("accel.scale.x", "gyro.bias.x", "gyro.scale.y"):
    print(k, out["parameters"][k], file=sys.stderr)
