#!/usr/bin/env python3
"""Work-precision plots and orders from nscd_work_precision's CSV.

usage: work_precision.py CSV [--png docs/work_precision.png] [--order-png docs/work_precision_h.png]
                             [--table OUT.md]
Prints the observed orders (least-squares slope of log error vs log h at the
tightest tolerance) and writes the plots (log-log) and a Markdown table.
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            for k in ("h", "tolerance", "wall_s", "us_per_step", "iters_mean", "pos_err_max",
                      "pos_err_rms", "force_err_rel"):
                try:
                    r[k] = float(r[k])
                except ValueError:
                    r[k] = math.nan
            r["reference"] = r["reference"] == "1"
            r["unconverged_steps"] = int(r["unconverged_steps"])
            r["steps"] = int(r["steps"])
            rows.append(r)
    return rows


def slope(h, e):
    pts = [(math.log(a), math.log(b)) for a, b in zip(h, e) if b > 0 and math.isfinite(b)]
    if len(pts) < 2:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--png", default="docs/work_precision.png")
    ap.add_argument("--order-png", default="docs/work_precision_h.png")
    ap.add_argument("--table", default=None, help="write Markdown tables here")
    a = ap.parse_args()

    rows = read(a.csv)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    tols = sorted({r["tolerance"] for r in rows if not r["reference"]}, reverse=True)
    tight = min(tols)
    ncol = min(3, len(scenes))
    nrow = (len(scenes) + ncol - 1) // ncol
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(tols)))

    fig, axes = plt.subplots(nrow, ncol, figsize=(5 * ncol, 4 * nrow), squeeze=False)
    fig2, axes2 = plt.subplots(nrow, ncol, figsize=(5 * ncol, 4 * nrow), squeeze=False)
    orders = []
    for i, s in enumerate(scenes):
        ax, ax2 = axes[i // ncol][i % ncol], axes2[i // ncol][i % ncol]
        tight = min(r["tolerance"] for r in rows if r["scene"] == s and not r["reference"])
        for c, tol in zip(colors, tols):
            rs = sorted((r for r in rows if r["scene"] == s and not r["reference"] and r["tolerance"] == tol
                         and r["status"] == "ok"), key=lambda r: -r["h"])
            if not rs:
                continue
            w = [max(r["wall_s"], 1e-6) for r in rs]
            ax.loglog(w, [r["pos_err_max"] for r in rs], "o-", color=c, ms=4, label="tol %g" % tol)
            ax.loglog(w, [r["force_err_rel"] for r in rs], "x--", color=c, ms=4, alpha=0.6)
            hs = [r["h"] for r in rs]
            ax2.loglog(hs, [r["pos_err_max"] for r in rs], "o-", color=c, ms=4, label="tol %g" % tol)
            if tol == tight:
                p_pos = slope(hs, [r["pos_err_max"] for r in rs])
                p_rms = slope(hs, [r["pos_err_rms"] for r in rs])
                p_f = slope(hs, [r["force_err_rel"] for r in rs])
                ref = next(r for r in rows if r["scene"] == s and r["reference"])
                orders.append((s, tol, p_pos, p_rms, p_f, ref["h"], ref["wall_s"], ref["unconverged_steps"]))
                # Guide line of the fitted slope through the middle point.
                m = len(hs) // 2
                e_m = rs[m]["pos_err_max"]
                if e_m > 0 and math.isfinite(p_pos):
                    g = [e_m * (h / hs[m]) ** p_pos for h in (hs[0], hs[-1])]
                    ax2.loglog([hs[0], hs[-1]], g, "k:", lw=1, label="slope %.2f" % p_pos)
        ax.set_title(s)
        ax.set_xlabel("wall time of the run, s")
        ax.set_ylabel("max position error, m (o) / rel. force error (x)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        ax2.set_title(s)
        ax2.set_xlabel("time step h, s")
        ax2.set_ylabel("max position error, m")
        ax2.grid(True, which="both", alpha=0.3)
        ax2.legend(fontsize=7)
    for j in range(len(scenes), nrow * ncol):
        axes[j // ncol][j % ncol].axis("off")
        axes2[j // ncol][j % ncol].axis("off")
    fig.suptitle("Work-precision: error against a converged reference vs wall time")
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)
    fig2.suptitle("Convergence in h (all tolerances; dotted: fitted order at the tightest)")
    fig2.tight_layout()
    fig2.savefig(a.order_png, dpi=110)

    print("scene,tolerance,order_pos_max,order_pos_rms,order_force,ref_h,ref_wall_s,ref_unconverged")
    for o in orders:
        print("%s,%g,%.2f,%.2f,%.2f,%g,%.2f,%d" % o)
    if a.table:
        with open(a.table, "w") as f:
            f.write("| scene | order (max pos. error) | order (RMS pos. error) | order (key force) "
                    "| reference h | reference wall s | reference unconverged steps |\n")
            f.write("|---|---|---|---|---|---|---|\n")
            for o in orders:
                f.write("| %s | %.2f | %.2f | %.2f | %g | %.1f | %d |\n" % (o[0], o[2], o[3], o[4], o[5], o[6], o[7]))
            f.write("\nOrders fitted over all h of a scene at its tightest tolerance.\n\n")
            for s in scenes:
                stols = sorted({r["tolerance"] for r in rows if r["scene"] == s and not r["reference"]})
                f.write("**%s**\n\n| h | tolerance | wall s | µs/step | mean iters | unconverged steps "
                        "| max pos. err m | RMS pos. err m | rel. force err |\n|---|---|---|---|---|---|---|---|---|\n" % s)
                for r in sorted((r for r in rows if r["scene"] == s and not r["reference"]),
                                key=lambda r: (-r["tolerance"], -r["h"])):
                    if r["tolerance"] not in (stols[0], stols[-1]):
                        continue  # the extreme tolerances only; the CSV has them all
                    f.write("| %g | %g | %.3g | %.3g | %.3g | %d | %.3g | %.3g | %.3g |\n" % (
                        r["h"], r["tolerance"], r["wall_s"], r["us_per_step"], r["iters_mean"],
                        r["unconverged_steps"], r["pos_err_max"], r["pos_err_rms"], r["force_err_rel"]))
                f.write("\n")


if __name__ == "__main__":
    sys.exit(main())
