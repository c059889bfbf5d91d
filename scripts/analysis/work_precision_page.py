#!/usr/bin/env python3
"""Writes docs/work_precision.md (fixed against adaptive steps) from the raw results
scripts/work_precision_page.sh leaves in OUT: per scene OUT/wp_SCENE.csv
(nscd_work_precision) and OUT/wp_SCENE.info (its command, load before and after), the
slider-crank study's OUT/crank_study.md, and OUT/ran_STAGE.info and OUT/elapsed.txt
(when and how long). Run by work_precision_page.sh.

    work_precision_page.py OUT --template scripts/templates/work_precision_template.md --page docs/work_precision.md
"""
import argparse
import csv
import math
import os

from machine import cpu

# The work-precision set, in the page's order: (name, what the error is).
SCENES = [
    ("double_pendulum", "max"), ("fourbar", "max"), ("slider_crank", "max"), ("clearance_pendulum", "max"),
    ("fourbar_3clearances", "max"), ("c60_trip", "end"),
]
ERR = {"max": ("pos_err_max", "max over bodies and samples"), "end": ("pos_err_end", "at the end, max over bodies")}


def g(x, d=3):
    return "%.*g" % (d, x) if x == x and x is not None else "—"


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def read(path):
    rows = []
    for r in csv.DictReader(open(path)):
        for k in ("h", "tolerance", "wall_s", "us_per_step", "iters_mean", "pos_err_max", "pos_err_rms",
                  "force_err_rel", "pos_err_end", "step_tol"):
            r[k] = num(r.get(k))
        for k in ("steps", "unconverged_steps", "rejected_steps"):
            r[k] = int(r.get(k) or 0)
        r["adaptive"] = r.get("step_control") == "adaptive"
        r["reference"] = r["reference"] == "1"
        rows.append(r)
    return rows


def front(runs, key):
    """The cheapest-runs front: sorted by wall time, each more accurate than every cheaper one."""
    ok = sorted((r for r in runs if r["status"] == "ok" and r[key] > 0), key=lambda r: r["wall_s"])
    f = []
    for r in ok:
        if not f or r[key] < f[-1][key]:
            f.append(r)
    return f


def refined(runs, key):
    """Each fixed run with its error replaced by the worst of its own and every finer
    dt's: the accuracy a user who picks dt by refining until the answer settles can
    count on. Where the errors do not fall with dt (a contact sequence that changes with
    dt), a coarse run that lands near the reference by a draw is not on this front."""
    ok = [r for r in runs if r["status"] == "ok" and r[key] > 0]
    out = []
    for r in ok:
        worst = max(x[key] for x in ok if x["h"] <= r["h"])
        out.append(dict(r, **{key: worst}))
    return out


def wall_at(f, key, err):
    """Wall time of the front at error err: (wall, how). how '=': log-log between the two
    runs that bracket err; '~': beyond the front's ends, extended along the slope of its
    two end runs (err below every run, or above every run); None if the front has fewer
    than two runs there."""
    if not f:
        return None, None
    for a, b in zip(f, f[1:]):
        if a[key] >= err >= b[key]:
            t = (math.log(err) - math.log(a[key])) / (math.log(b[key]) - math.log(a[key]))
            return math.exp(math.log(a["wall_s"]) + t * (math.log(b["wall_s"]) - math.log(a["wall_s"]))), "="
    if len(f) < 2:
        return None, None
    a, b = (f[-2], f[-1]) if err < f[-1][key] else (f[0], f[1])
    slope = math.log(b["wall_s"] / a["wall_s"]) / math.log(b[key] / a[key])
    if not slope < 0:
        return None, None
    return b["wall_s"] * (err / b[key]) ** slope, "~"


def read_info(path):
    """A file of "KEY VALUE" lines as a dict ({} if there is none): the records
    scripts/work_precision_page.sh writes, wp_SCENE.info (a scene's command, load before
    and after) and ran_STAGE.info (when a stage ran: date, commit)."""
    d = {}
    if os.path.exists(path):
        for line in open(path):
            k, _, v = line.rstrip("\n").partition(" ")
            d[k] = v
    return d


def scene_section(out, name, metric):
    path = os.path.join(out, "wp_%s.csv" % name)
    if not os.path.exists(path):
        return "_(missing: %s)_\n" % path, None
    key, what = ERR[metric]
    rows = read(path)
    ref = next((r for r in rows if r["reference"]), None)
    fixed = [r for r in rows if not r["reference"] and not r["adaptive"]]
    adaptive = [r for r in rows if not r["reference"] and r["adaptive"]]
    ff = front(fixed, key)
    fr = front(refined(fixed, key), key)
    i = read_info(os.path.join(out, "wp_%s.info" % name))
    s = []
    s.append("**%s** — `%s`\n\n" % (name, i.get("command", "?")))
    if ref:
        how = ("adaptive at rtol = atol = %g, solver tolerance %g" % (ref["step_tol"], ref["tolerance"])
               if ref["adaptive"] else "fixed h = %g, solver tolerance %g" % (ref["h"], ref["tolerance"]))
        s.append("Reference: %s, %d steps, %.1f s. Load average %s before, %s after. Error: position of the "
                 "bodies' centres of mass, %s (m).\n\n" % (how, ref["steps"], ref["wall_s"], i.get("load_start", "?"),
                                                            i.get("load_end", "?"), what))
    s.append("| control | dt or rtol = atol | steps (rejected) | unconverged | wall s | error m | end error m "
             "| best fixed dt's wall at this error | adaptive / best fixed | refined fixed dt's wall "
             "| adaptive / refined |\n")
    s.append("|---|---|---|---|---|---|---|---|---|---|---|\n")
    verdict = []
    for r in sorted(fixed, key=lambda r: -r["h"]):
        s.append("| fixed | %g | %d | %d | %s | %s | %s | | | | |\n" % (
            r["h"], r["steps"], r["unconverged_steps"], g(r["wall_s"]), g(r[key]), g(r["pos_err_end"])))
    for r in sorted(adaptive, key=lambda r: -r["step_tol"]):
        cells, ratios = [], []
        for f in (ff, fr):
            w, how = wall_at(f, key, r[key]) if r["status"] == "ok" else (None, None)
            if w is None:
                cells += ["—", "—"]
            else:
                mark = "~ " if how == "~" else ""
                cells += [mark + g(w), mark + g(r["wall_s"] / w, 2)]
            ratios.append((None if w is None else r["wall_s"] / w, how))
        verdict.append((r, ratios))
        status = "" if r["status"] == "ok" else " " + r["status"]
        s.append("| adaptive | %g | %d (%d) | %d | %s | %s | %s | %s |%s\n" % (
            r["step_tol"], r["steps"], r["rejected_steps"], r["unconverged_steps"], g(r["wall_s"]), g(r[key]),
            g(r["pos_err_end"]), " | ".join(cells), status))
    s.append("\n")
    return "".join(s), verdict


def summary_row(name, metric, verdict):
    """The scene's row: for each front (best fixed dt, refined fixed dt) whether
    adaptive is no slower, and every adaptive run's error with its ratios."""
    if verdict is None:
        return "| %s | — | — | — |\n" % name
    key = ERR[metric][0]
    cells, verdicts = [], []
    for k in range(2):
        held = sum(1 for _, q in verdict if q[k][0] is not None and q[k][0] <= 1)
        slower = sum(1 for _, q in verdict if q[k][0] is not None and q[k][0] > 1)
        verdicts.append("yes" if held and not slower else ("no" if slower and not held else ("partly" if held else "—")))
    for r, q in verdict:
        parts = []
        for ratio, how in q:
            mark = "~" if how == "~" else ""
            text = "—" if ratio is None else mark + g(ratio, 2)
            parts.append("**%s**" % text if ratio is not None and ratio > 1 else text)
        cells.append("%s (%s)" % (g(r[key], 2), " / ".join(parts)))
    return "| %s | %s | %s | %s |\n" % (name, verdicts[0], verdicts[1], ", ".join(cells))


def run_section(out):
    """When and at which commit the raw results were made, stage by stage."""
    parts = {}
    for stage in ("scenes", "crank"):
        d = read_info(os.path.join(out, "ran_%s.info" % stage))
        key = (d.get("date", "an unknown date"), d.get("commit", "unknown"))
        parts.setdefault(key, []).append(stage)
    if len(parts) == 1:
        (date, commit), _ = next(iter(parts.items()))
        return "%s, commit `%s`" % (date, commit)
    return "; ".join("the %s stage%s %s, commit `%s`" % (" and ".join(st), "s" if len(st) > 1 else "", date, commit)
                     for (date, commit), st in parts.items())


def crank_section(out):
    """The slider-crank study's tables (scripts/work_precision_page.sh, stage crank)."""
    p = os.path.join(out, "crank_study.md")
    return open(p).read() if os.path.exists(p) else "_(missing: the crank stage of scripts/work_precision_page.sh)_\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--template", required=True)
    ap.add_argument("--page", required=True)
    a = ap.parse_args()
    sections, summary = [], []
    for name, metric in SCENES:
        text, verdict = scene_section(a.out, name, metric)
        sections.append(text)
        summary.append(summary_row(name, metric, verdict))
    page = open(a.template).read()
    page = page.replace("@RUN@", run_section(a.out))
    page = page.replace("@MACHINE@", "%s, %d cores" % (cpu(), os.cpu_count()))
    ep = os.path.join(a.out, "elapsed.txt")
    elapsed = int(open(ep).read()) if os.path.exists(ep) else None
    page = page.replace("@ELAPSED@", "%d min %d s" % divmod(elapsed, 60) if elapsed is not None else "an unknown time")
    page = page.replace("@SUMMARY@", "| scene | adaptive no slower than the best fixed dt | than the refined fixed dt "
                        "| each adaptive run: error m (adaptive wall / best fixed dt's wall at that error / refined "
                        "fixed dt's; ~ extrapolated, **bold** where adaptive is slower) |\n|---|---|---|---|\n"
                        + "".join(summary))
    page = page.replace("@SCENES@", "\n".join(sections))
    page = page.replace("@CRANK@", crank_section(a.out))
    open(a.page, "w").write(page)
    print("wrote %s" % a.page)


if __name__ == "__main__":
    main()
