#!/usr/bin/env python3
"""Markdown tables from nscd_fclib's CSV (scripts/fclib_compare.sh).

usage: fclib_table.py fclib.csv > fclib.md
Per problem and tolerance, one cell per solver: iterations / error (Siconos's
measure) / time ms, with 'FAIL' when the solver did not reach the tolerance.
Then per tolerance: solved count, total time and the geometric mean of
(solver time / nscd time) over the problems both solved.
"""
import csv
import math
import sys
from collections import OrderedDict, defaultdict


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
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


if __name__ == "__main__":
    main()
