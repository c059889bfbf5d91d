#!/usr/bin/env python3
"""Markdown tables from nscd_fclib's CSV (scripts/fclib_compare.sh).

usage: fclib_table.py fclib.csv [--made-by COMMAND --started EPOCH_S --load-start L] > fclib.md
With --made-by, a first line says which command made the CSV, at which commit, when,
at which load (1-minute average at the start and now) and how long it took.
Per problem and tolerance, one cell per solver: iterations / error (Siconos's
measure) / time ms, with 'FAIL' when the solver did not reach the tolerance.
Then per tolerance: solved count, total time and the geometric mean of
(solver time / nscd time) over the problems both solved; then the cells where
ours is not the fastest converged solver.
"""
import argparse
import csv
import datetime
import math
import os
import subprocess
import time
from collections import OrderedDict, defaultdict


def made_by(command, started, load_start):
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    try:
        commit = subprocess.check_output(["git", "-C", repo, "rev-parse", "--short", "HEAD"], text=True).strip()
        if subprocess.check_output(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no",
                                    "--", ".", ":!docs"], text=True).strip():
            commit += " with uncommitted changes"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    load_end = open("/proc/loadavg").read().split()[0]
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return ("`%s`, run at commit `%s`, finished %s on %d cores (load %s at the start, %s at the end), "
            "in %d s.\n" % (command, commit, when, os.cpu_count(), load_start, load_end, time.time() - started))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--made-by")
    ap.add_argument("--started", type=float)
    ap.add_argument("--load-start")
    a = ap.parse_args()
    if a.made_by:
        print(made_by(a.made_by, a.started or time.time(), a.load_start or "?"))
    rows = list(csv.DictReader(open(a.csv)))
    solvers = list(OrderedDict.fromkeys(r["solver"].split("/")[0] for r in rows))
    table = defaultdict(dict)
    nc = {}
    for r in rows:
        key = (r["problem"], float(r["tol"]))
        table[key][r["solver"].split("/")[0]] = r
        nc[r["problem"]] = r["contacts"]
    print("| problem | contacts | tol | " + " | ".join(solvers) + " |")
    print("|---|---|---|" + "---|" * len(solvers))
    for (prob, tol), cells in table.items():
        out = []
        for s in solvers:
            r = cells.get(s)
            if r is None:
                out.append("")
                continue
            err = float(r["error_siconos"])
            cell = f"{r['iterations']} / {err:.1e} / {float(r['time_ms']):.3g}"
            if "/" in r["solver"]:
                cell += " (" + r["solver"].split("/")[1] + ")"
            if r["converged"] != "1":
                cell = "**FAIL** " + cell
            out.append(cell)
        print(f"| {prob.replace('.hdf5', '')} | {nc[prob]} | {tol:.0e} | " + " | ".join(out) + " |")
    print("\nCells: iterations / error (Siconos measure: natural-map residual / |q|) / wall ms "
          "(fastest of repeated cold-started solves); (sp)/(de): sparse or dense W, the faster "
          "for that Siconos solver.\n")
    print("| tol | solver | solved | total ms | geo. mean time / nscd time |")
    print("|---|---|---|---|---|")
    for tol in sorted({k[1] for k in table}, reverse=True):
        for s in solvers:
            solved, total, logs = 0, 0.0, []
            for (prob, t), cells in table.items():
                if t != tol or s not in cells:
                    continue
                r = cells[s]
                total += float(r["time_ms"])
                if r["converged"] == "1":
                    solved += 1
                    ours = cells.get("nscd")
                    if ours and ours["converged"] == "1" and float(ours["time_ms"]) > 0:
                        logs.append(math.log(float(r["time_ms"]) / float(ours["time_ms"])))
            n = sum(1 for (p, t), c in table.items() if t == tol and s in c)
            gm = f"{math.exp(sum(logs) / len(logs)):.2f}" if logs else "n/a"
            print(f"| {tol:.0e} | {s} | {solved}/{n} | {total:.4g} | {gm} |")
    fastest_elsewhere = []
    for (prob, tol), cells in table.items():
        done = {s: float(r["time_ms"]) for s, r in cells.items() if r["converged"] == "1"}
        if done and min(done, key=done.get) != "nscd":
            best = min(done, key=done.get)
            ours = "%.3g ms" % done["nscd"] if "nscd" in done else "unsolved"
            fastest_elsewhere.append(f"{prob.replace('.hdf5', '')} at {tol:.0e}: {best} {done[best]:.3g} ms, ours {ours}")
    print(f"\nOurs is the fastest converged solver in {len(table) - len(fastest_elsewhere)} of {len(table)} "
          "problem/tolerance cells" + (": not in " + "; ".join(fastest_elsewhere) + "." if fastest_elsewhere else "."))


if __name__ == "__main__":
    main()
