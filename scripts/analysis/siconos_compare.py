#!/usr/bin/env python3
"""Errors, wall-time ratios and trajectory agreement from nscd_siconos_compare's CSVs.

usage: siconos_compare.py OUT_DIR   (reads OUT_DIR/runs.csv, OUT_DIR/samples.csv;
                                     writes OUT_DIR/summary.md and OUT_DIR/work_precision.png)
Errors:
  ball      max over the 1 ms samples of |z - z_exact| (exact piecewise-parabolic
            solution of the bouncing ball with restitution e), and the apex heights
            against e^(2k) h0;
  pendulum  max over the 1 ms samples of |theta - theta_ref|, theta_ref from
            nscd_sim at h = 1e-3/512 with tolerance 1e-12 and the combined projection
            (the Siconos run with the same settings is reported as a cross-check).
Ratios: Siconos time / nscd_sim time (wall, and CPU time of the thread), at the same h, and at equal error
(Siconos's time at nscd_sim's error, log-log interpolated between Siconos's runs;
'>' marks a lower bound where nscd_sim's error is below every Siconos error).
"""
import csv
import math
import os
import sys
from collections import defaultdict

import numpy as np

BALL = dict(r=0.05, g=9.81, h0=1.0, e=0.8)


def ball_exact(t):
    g, h0, e = BALL["g"], BALL["h0"], BALL["e"]
    t1 = math.sqrt(2 * h0 / g)
    z = np.empty_like(t)
    for i, ti in enumerate(t):
        if ti <= t1:
            z[i] = h0 - 0.5 * g * ti * ti
            continue
        tk, vk = t1, e * g * t1
        while vk > 1e-12 and ti > tk + 2 * vk / g:
            tk += 2 * vk / g
            vk *= e
        s = ti - tk
        z[i] = max(0.0, vk * s - 0.5 * g * s * s)
    return z


def read(out):
    runs = list(csv.DictReader(open(os.path.join(out, "runs.csv"))))
    samples = defaultdict(lambda: ([], [], []))
    with open(os.path.join(out, "samples.csv")) as f:
        for row in csv.DictReader(f):
            key = (row["scene"], row["scheme"], row["engine"], float(row["h"]))
            s = samples[key]
            s[0].append(float(row["t"]))
            s[1].append(float(row["a"]))
            s[2].append(float(row["b"]))
    samples = {k: tuple(np.array(x) for x in v) for k, v in samples.items()}
    for r in runs:
        r["h"] = float(r["h"])
        r["wall_s"] = float(r["wall_s"])
        r["us_per_step"] = float(r["us_per_step"])
        r["cpu_s"] = float(r.get("cpu_s") or r["wall_s"])
        r["max_pen"] = float(r["max_pen"])
    return runs, samples


def interp_time(err, pts):
    """Time at `err` on the (error, time) curve pts, log-log; (time, flag)."""
    pts = sorted(p for p in pts if p[0] > 0 and p[1] > 0)
    if not pts:
        return None, ""
    le = [math.log(p[0]) for p in pts]
    lt = [math.log(p[1]) for p in pts]
    x = math.log(err)
    if x < le[0]:
        return pts[0][1], ">"  # needs a finer h than any run: lower bound
    if x > le[-1]:
        return pts[-1][1], "<"
    for i in range(len(pts) - 1):
        if le[i] <= x <= le[i + 1]:
            w = 0 if le[i + 1] == le[i] else (x - le[i]) / (le[i + 1] - le[i])
            return math.exp(lt[i] + w * (lt[i + 1] - lt[i])), ""
    return None, ""


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    runs, samples = read(out)
    lines = []
    P = lines.append
    def errors_against(ref_engine):
        errs = {}
        ref_key = next((k for k in samples if k[0] == "pendulum" and k[2] == ref_engine), None)
        for r in runs:
            key = (r["scene"], r["scheme"], r["engine"], r["h"])
            if r["error"] or key not in samples or r["engine"].endswith("_ref"):
                continue
            t, a, b = samples[key]
            if r["scene"] == "ball":
                errs[key] = float(np.max(np.abs(a - ball_exact(t))))
            elif ref_key is not None:
                tr, ar, _ = samples[ref_key]
                n = min(len(t), len(tr))
                errs[key] = float(np.max(np.abs(a[:n] - ar[:n])))
        return errs

    errors = errors_against("nscd_ref")
    errors_sref = errors_against("siconos_ref")
    variants = {"siconos": "Siconos (Newton loop to convergence, default)",
                "siconos_lin": "Siconos SICONOS_TS_LINEAR (one Newton iteration)"}

    def equal_error_ratio(errs, scene, scheme, variant, r, field="wall_s"):
        en = errs.get((scene, scheme, "nscd", r["h"]))
        pts = [(errs.get((scene, scheme, variant, x["h"])), x[field]) for x in runs
               if x["scene"] == scene and x["scheme"] == scheme and x["engine"] == variant
               and errs.get((scene, scheme, variant, x["h"]))]
        if not en:
            return "n/a"
        eq, flag = interp_time(en, pts)
        return f"{flag}{eq / r[field]:.1f}" if eq else "n/a"

    for scene in ("ball", "pendulum"):
        for scheme in ("mj", "cp"):
            rows = [r for r in runs if r["scene"] == scene and r["scheme"] == scheme]
            if not rows:
                continue
            name = {"mj": "Moreau-Jean", "cp": "combined projection"}[scheme]
            P(f"\n### {scene}, {name}\n")
            extra = " (errors vs Siconos ref)" if scene == "pendulum" else ""
            P("| h (s) | Siconos variant | nscd µs/step | Siconos µs/step | time ratio, same h | nscd error "
              "| Siconos error | time ratio, equal error | time ratio, equal error" + (extra or " (same)") +
              " | CPU-time ratio, same h | CPU-time ratio, equal error"
              " | max traj. difference | nscd max pen. (m) | Siconos max pen. (m) |")
            P("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
            for r in sorted((r for r in rows if r["engine"] == "nscd"), key=lambda r: -r["h"]):
                h = r["h"]
                for variant in ("siconos", "siconos_lin"):
                    s_ = next((x for x in rows if x["engine"] == variant and x["h"] == h), None)
                    if s_ is None:
                        continue
                    kn, ks = (scene, scheme, "nscd", h), (scene, scheme, variant, h)
                    diff = float("nan")
                    if kn in samples and ks in samples:
                        n = min(len(samples[kn][1]), len(samples[ks][1]))
                        diff = float(np.max(np.abs(samples[kn][1][:n] - samples[ks][1][:n])))
                    en, es = errors.get(kn, float("nan")), errors.get(ks, float("nan"))
                    P(f"| {h:.4g} | {variant} | {r['us_per_step']:.3g} | {s_['us_per_step']:.3g} | "
                      f"{s_['wall_s'] / r['wall_s']:.1f} | {en:.3g} | {es:.3g} | "
                      f"{equal_error_ratio(errors, scene, scheme, variant, r)} | "
                      f"{equal_error_ratio(errors_sref, scene, scheme, variant, r)} | "
                      f"{s_['cpu_s'] / r['cpu_s']:.1f} | {equal_error_ratio(errors, scene, scheme, variant, r, 'cpu_s')} | "
                      f"{diff:.3g} | "
                      f"{r['max_pen']:.2g} | {s_['max_pen']:.2g} |")
            for eng in ("nscd", "siconos", "siconos_lin"):
                pts = [(k[3], e) for k, e in errors.items()
                       if k[0] == scene and k[1] == scheme and k[2] == eng and e > 0]
                if len(pts) >= 2:
                    x = np.log([p[0] for p in pts])
                    y = np.log([p[1] for p in pts])
                    P(f"\nobserved order ({eng}): {np.polyfit(x, y, 1)[0]:.2f}")

    # Apex heights (ball) at the finest h of each engine/scheme.
    P("\n### ball apex heights (m), exact e^(2k) h0\n")
    P("| run | apex 1 | apex 2 | apex 3 | apex 4 |")
    P("|---|---|---|---|---|")
    exact = [BALL["h0"] * BALL["e"] ** (2 * k) for k in range(1, 5)]
    P("| exact | " + " | ".join(f"{x:.5f}" for x in exact) + " |")
    for r in runs:
        if r["scene"] == "ball" and r["apex"]:
            ap = [float(x) for x in r["apex"].split(";")][:4]
            P(f"| {r['engine']} {r['scheme']} h={r['h']:.4g} | " + " | ".join(f"{x:.5f}" for x in ap) + " |")

    # Reference cross-check (pendulum)
    keys = [k for k in samples if k[0] == "pendulum" and k[2] in ("nscd_ref", "siconos_ref")]
    if len(keys) == 2:
        a1, a2 = samples[keys[0]][1], samples[keys[1]][1]
        n = min(len(a1), len(a2))
        d = np.abs(a1[:n] - a2[:n])
        ecc = {k[2]: samples[k][2] for k in keys}
        rr = {r["engine"]: r for r in runs if r["engine"].endswith("_ref")}
        P("\n### pendulum references (h = {:.4g} s, tolerance 1e-12, combined projection)\n".format(keys[0][3]))
        P(f"max |theta_nscd - theta_siconos| = {d.max():.3g} rad, at t = {samples[keys[0]][0][int(d.argmax())]:.3f} s; "
          f"theta range [{a1.min():.3f}, {a1.max():.3f}] rad")
        for eng, rr_ in sorted(rr.items()):
            P(f"\n{eng}: {rr_['us_per_step']:.3g} µs/step, wall {rr_['wall_s']:.3g} s, max penetration {rr_['max_pen']:.2g} m, "
              f"eccentricity/cr at t = 1 s: {ecc[eng][-1]:.6f}")

    text = "\n".join(lines) + "\n"
    open(os.path.join(out, "summary.md"), "w").write(text)
    print(text)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for ax, scene in zip(axes, ("ball", "pendulum")):
            for scheme, ls in (("mj", "-"), ("cp", "--")):
                for eng, mk in (("nscd", "o"), ("siconos", "s"), ("siconos_lin", "^")):
                    pts = sorted((errors[k], r["cpu_s"]) for r in runs
                                 for k in [(r["scene"], r["scheme"], r["engine"], r["h"])]
                                 if k in errors and k[0] == scene and k[1] == scheme and k[2] == eng)
                    if pts:
                        ax.loglog([p[1] for p in pts], [p[0] for p in pts], ls, marker=mk,
                                  label=f"{eng} {scheme}")
            ax.set_xlabel("CPU time of the stepping loop (s)")
            ax.set_ylabel("max error (m)" if scene == "ball" else "max angle error (rad)")
            ax.set_title(scene)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "work_precision.png"), dpi=110)
    except Exception as ex:  # plotting is optional
        print("no plot:", ex)


if __name__ == "__main__":
    main()
