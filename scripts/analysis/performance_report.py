#!/usr/bin/env python3
"""Writes docs/performance.md (and docs/stress.png, docs/soak_memory.png) from the
raw results scripts/performance.sh leaves in build/perf. Run by performance.sh."""
import argparse
import csv
import json
import math
import os
import platform
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PEN_TOL = 0.01
GAIN_TOL = 1e-9


def jline(path):
    """The last JSON line of a text file (the tools print one summary line)."""
    if not os.path.exists(path):
        return None
    for line in reversed(open(path).read().splitlines()):
        line = line.strip()
        if line.startswith("{"):
            return json.loads(line)
    return None


def cpu():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def git_rev(repo):
    try:
        return subprocess.check_output(["git", "-C", repo, "rev-parse", "--short", "HEAD"], text=True).strip()
    except Exception:
        return "unknown"


def stress_section(out, docs):
    path = os.path.join(out, "stress.csv")
    summ = jline(os.path.join(out, "stress_summary.json"))
    txt = open(os.path.join(out, "stress.txt")).read() if os.path.exists(os.path.join(out, "stress.txt")) else ""
    if not os.path.exists(path) or summ is None:
        return "_(stress results missing: run scripts/stress.sh)_\n"
    rows = list(csv.DictReader(open(path)))
    for r in rows:
        for k in ("radial", "mu", "e", "dt", "mass_ratio", "pen_rel", "energy_gain_rel", "unconverged_residual_max",
                  "iters_mean"):
            r[k] = float(r[k])
        r["unconverged_steps"] = int(r["unconverged_steps"])
        r["steps"] = int(r["steps"])
    ok = [r for r in rows if r["status"] == "ok"]
    steps_per_run = summ["steps_per_run"]

    def group(name, pred):
        g = [r for r in ok if pred(r)]
        if not g:
            return "| %s | 0 | | | | | |\n" % name
        return "| %s | %d | %d | %.3g | %d | %.3g | %d (%.2f%% of steps) |\n" % (
            name, len(g), sum(r["pen_rel"] > PEN_TOL for r in g), max(r["pen_rel"] for r in g),
            sum(r["energy_gain_rel"] > GAIN_TOL for r in g), max(r["energy_gain_rel"] for r in g),
            sum(r["unconverged_steps"] > 0 for r in g),
            100.0 * sum(r["unconverged_steps"] for r in g) / max(1, sum(r["steps"] for r in g)))

    s = []
    s.append("| | value |\n|---|---|\n")
    s.append("| runs (seed %d, %d steps each) | %d |\n" % (summ["seed"], steps_per_run, summ["runs"]))
    s.append("| total steps / wall time | %d / %.1f s |\n" % (summ["total_steps"], summ["wall_s"]))
    s.append("| **NaN / crash / exception** | **%d** |\n" % summ["failed"])
    s.append("| max penetration / clearance (projection on) | %.3g (runs over 1%%: **%d**) |\n"
             % (summ["pen_rel_max"], summ["pen_rel_over_1pct"]))
    s.append("| max energy gain / energy scale | %.3g (runs over %.0e: **%d**) |\n"
             % (summ["energy_gain_rel_max"], GAIN_TOL, summ["energy_gain_over_tol"]))
    s.append("| runs with unconverged solver steps | %d (%d steps, %.2f%% of all; worst residual %.3g) |\n"
             % (summ["unconverged_runs"], summ["unconverged_steps"],
                100.0 * summ["unconverged_steps"] / max(1, summ["total_steps"]), summ["unconverged_residual_max"]))
    if "halved_steps" in summ:
        s.append("| steps taken again in halves (most substeps in one step) | %d (%d) |\n"
                 % (summ["halved_steps"], summ["substeps_max"]))
    if "longer_solve_steps" in summ:
        s.append("| steps whose smallest step solved once more with 10 times the budget (answer kept) | %d |\n"
                 % summ["longer_solve_steps"])
    if "plastic_retry_steps" in summ:
        s.append("| plastic retries (restitution unsolved, solved with e = 0) / frictionless fallbacks | %d / %d |\n"
                 % (summ["plastic_retry_steps"], summ["frictionless_fallback_steps"]))
    rerun = [l for l in txt.splitlines() if l.startswith("rerun")]
    s.append("| rerun on 1 thread, CSV compared byte for byte | %s |\n\n" % (rerun[0].split(": ", 1)[1] if rerun else "not run"))
    s.append("By kind and time step (runs over the thresholds):\n\n")
    s.append("| group | runs | pen > 1% | max pen/c | gain > tol | max gain | runs with unconverged steps |\n")
    s.append("|---|---|---|---|---|---|---|\n")
    s.append(group("planar, 1 link", lambda r: r["planar"] == "1" and r["links"] == "1"))
    s.append(group("planar, 2 links", lambda r: r["planar"] == "1" and r["links"] == "2"))
    s.append(group("3D, 1 link", lambda r: r["planar"] == "0" and r["links"] == "1"))
    s.append(group("3D, 2 links", lambda r: r["planar"] == "0" and r["links"] == "2"))
    for lo in (1e-6, 1e-5, 1e-4):
        s.append(group("h in [%g, %g)" % (lo, lo * 10), lambda r, lo=lo: lo <= r["dt"] < lo * 10))
    s.append(group("clearance < 10 µm", lambda r: r["radial"] < 1e-5))
    s.append(group("clearance >= 10 µm", lambda r: r["radial"] >= 1e-5))
    s.append(group("mass ratio > 10 or < 0.1", lambda r: r["mass_ratio"] > 10 or r["mass_ratio"] < 0.1))
    s.append("\nWorst runs (replay any with `nscd_stress --seed %d --case K --write case.urdf`, which prints the "
             "`nscd_run` command):\n\n" % summ["seed"])
    s.append("| case | kind | clearance | mu | e | h | mass ratio | pen/c | gain | unconverged steps | worst residual |\n")
    s.append("|---|---|---|---|---|---|---|---|---|---|---|\n")
    worst = sorted(ok, key=lambda r: -r["pen_rel"])[:5] + sorted(ok, key=lambda r: -r["energy_gain_rel"])[:3]
    seen = set()
    for r in worst:
        if r["case"] in seen:
            continue
        seen.add(r["case"])
        s.append("| %s | %s, %s link%s | %.3g | %.2f | %.2f | %.3g | %.3g | %.3g | %.3g | %d | %.3g |\n" % (
            r["case"], "planar" if r["planar"] == "1" else "3D", r["links"], "s" if r["links"] == "2" else "",
            r["radial"], r["mu"], r["e"], r["dt"], r["mass_ratio"], r["pen_rel"], r["energy_gain_rel"],
            r["unconverged_steps"], r["unconverged_residual_max"]))

    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for planar, col, lab in (("1", "tab:blue", "planar"), ("0", "tab:red", "3D")):
        g = [r for r in ok if r["planar"] == planar]
        ax[0].loglog([r["dt"] for r in g], [max(r["pen_rel"], 1e-12) for r in g], ".", color=col, ms=3, label=lab)
        ax[1].loglog([r["dt"] for r in g], [max(r["energy_gain_rel"], 1e-18) for r in g], ".", color=col, ms=3, label=lab)
        ax[2].loglog([r["radial"] for r in g], [max(r["unconverged_steps"], 0.5) for r in g], ".", color=col, ms=3, label=lab)
    ax[0].axhline(PEN_TOL, color="k", ls=":")
    ax[1].axhline(GAIN_TOL, color="k", ls=":")
    ax[0].set(xlabel="h, s", ylabel="max penetration / clearance", title="penetration (floor 1e-12)")
    ax[1].set(xlabel="h, s", ylabel="max (E(t) - E(0)) / energy scale", title="energy gain (floor 1e-18)")
    ax[2].set(xlabel="radial clearance, m", ylabel="unconverged steps (0 shown at 0.5)",
              title="solver non-convergence (of %d steps)" % steps_per_run)
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(docs, "stress.png"), dpi=100)
    s.append("\n![stress](stress.png)\n")
    return "".join(s)


def soak_section(out, docs):
    soak = massif = None
    if os.path.exists(os.path.join(out, "soak.txt")):
        for line in open(os.path.join(out, "soak.txt")):
            if line.startswith('{"massif'):
                massif = json.loads(line)
            elif line.startswith('{"soak_steps'):
                soak = json.loads(line)
    if soak is None:
        return "_(soak results missing: run scripts/soak.sh)_\n"
    s = ["| | value |\n|---|---|\n"]
    s.append("| scene / h | `%s` / %g s |\n" % (os.path.relpath(soak["scene"], os.path.dirname(docs)), soak["dt"]))
    s.append("| steps | %d (%.3g s simulated) |\n" % (soak["soak_steps"], soak["soak_steps"] * soak["dt"]))
    s.append("| wall time | %.1f s (%.2f µs/step) |\n" % (soak["wall_s"], soak["us_per_step"]))
    s.append("| resident memory after warm-up (10 %% of the steps) / at the end | %d KiB / %d KiB |\n" % (soak["rss_kib_after_warmup"], soak["rss_kib_end"]))
    s.append("| resident memory min / max after warm-up | %d / %d KiB |\n" % (soak["rss_kib_min"], soak["rss_kib_max"]))
    s.append("| heap allocations inside `step()` after warm-up (counting `operator new`) | %d (%.3g per step) |\n"
             % (soak["allocations_after_warmup"], soak["allocations_per_step"]))
    s.append("| non-finite / unconverged steps | %d / %d |\n" % (soak["nonfinite"], soak["unconverged_steps"]))
    s.append("| max penetration | %.3g m |\n" % soak["max_penetration"])
    if massif:
        s.append("| valgrind massif (shorter soak): heap at peak / half-way / last snapshot | %d / %d / %d B (%d snapshots) |\n"
                 % (massif["heap_B_peak"], massif["heap_B_at_half"], massif["heap_B_last"], massif["massif_snapshots"]))
    mem = os.path.join(out, "soak_memory.csv")
    if os.path.exists(mem):
        rows = list(csv.DictReader(open(mem)))
        fig, ax = plt.subplots(figsize=(7, 3.2))
        ax.plot([int(r["step"]) for r in rows], [int(r["rss_kib"]) for r in rows], "-")
        ax.set(xlabel="step", ylabel="resident memory, KiB", title="soak: resident memory")
        ax.set_ylim(0, 1.2 * max(int(r["rss_kib"]) for r in rows))
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(docs, "soak_memory.png"), dpi=100)
        s.append("\n![soak memory](soak_memory.png)\n")
    return "".join(s)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--docs", required=True)
    ap.add_argument("--elapsed", type=int, default=0)
    a = ap.parse_args()
    repo = os.path.dirname(os.path.abspath(a.docs))
    wp = open(os.path.join(a.out, "work_precision.md")).read() if os.path.exists(os.path.join(a.out, "work_precision.md")) else "_(missing)_\n"
    sweep = jline(os.path.join(a.out, "sweep.json")) or {}
    tmpl = open(os.path.join(repo, "scripts", "templates", "performance_template.md")).read()
    text = (tmpl.replace("@MACHINE@", "%s, %d cores, %s" % (cpu(), os.cpu_count(), platform.platform()))
            .replace("@COMMIT@", git_rev(repo))
            .replace("@ELAPSED@", "%d min %d s" % divmod(a.elapsed, 60) + (
                " (stages skipped, earlier results reused: %s)" % os.environ["PERF_SKIP"]
                if os.environ.get("PERF_SKIP") else ""))
            .replace("@WORK_PRECISION@", wp)
            .replace("@STRESS@", stress_section(a.out, a.docs))
            .replace("@SOAK@", soak_section(a.out, a.docs))
            .replace("@SWEEP@", "| | value |\n|---|---|\n" + "".join(
                "| %s | %s |\n" % (k, v) for k, v in sweep.items())))
    open(os.path.join(a.docs, "performance.md"), "w").write(text)


if __name__ == "__main__":
    main()
