#!/usr/bin/env python3
"""Summary table of every case of every figure (each case once), with the paper's stated values beside ours.

Writes figures/out/PRESET/summary.csv (full precision) and summary.md (rounded, plus the pooled Fig. 9 values
per cv and a check of every trend the paper states, paper_values.toml [[trend]]). Columns:
case, figures, theta_D, sigma_ru_over_sigma0, Er_over_kd, cv, seed, loading (preset / half rate), status,
da_max_over_d, R_init_over_Gamma, R_ss_over_Gamma, R_m_over_Gamma, dR_m_over_Gamma,
da_first_rod_fracture_over_d, broken_rod_elements (last /history row), wall_time_s, and paper_<quantity> for
each quantity the paper states for that case (several values joined by ';', a lower bound written '>=X').
Half-rate twins (a figure table's `slow`) get their own rows where their result file exists.
Reads runs/PRESET/<case>/result.h5, or where a run's result file is not there its record
records/PRESET/<case>.json (enamel_results.records; summary.md names both roots).
"""
import csv
import math
import sys

from enamel_results import cases, cli, metrics, paper_values, paths
from enamel_results.results import convergence_label

PARAMS = ("theta_D", "sigma_ru_over_sigma0", "Er_over_kd", "cv", "seed")
OURS = (("da_max_over_d", "da_max"), ("R_init_over_Gamma", "R_init"), ("R_ss_over_Gamma", "R_ss"),
        ("R_m_over_Gamma", "R_m"), ("dR_m_over_Gamma", "dR_m"),
        ("da_first_rod_fracture_over_d", "da_first_rod_fracture"), ("broken_rod_elements", "broken_rods"),
        ("wall_time_s", "wall_time_s"))
PAPER = ("R_init_over_Gamma", "R_ss_over_Gamma", "R_m_pooled_over_Gamma", "dR_m_pooled_over_Gamma",
         "da_first_rod_fracture_over_d", "da_R_plateau_end_over_d")
COLUMNS = (["case", "figures", *PARAMS, "loading", "status"] + [c for c, _ in OURS] +
           [f"paper_{q}" for q in PAPER])
FIG_ORDER = ("fig4", "fig5", "fig6", "fig7", "fig8", "fig9")
CONSTANT_RTOL = 0.10  # 'constant' trend: (max - min) / mean within 10% (the paper says 'plateau', no number)


def num(x, fmt="%.10g"):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    return fmt % x if isinstance(x, float) else str(x)


def paper_cell(values, quantity):
    out = []
    for v in values:
        if v["quantity"] == quantity:
            out.append((">=" if v.get("relation") == ">=" else "") + "%g" % float(v["value"]))
    return ";".join(out)


def collect(args):
    figs = cases.figure_list()
    order, used_by = [], {}
    for fig in FIG_ORDER + tuple(k for k in figs if k not in FIG_ORDER):
        for c in figs.get(fig, {}).get("cases", []):
            if c not in used_by:
                order.append(c)
                used_by[c] = []
            used_by[c].append(fig)
    results = cli.load_cases(__file__, args, order)
    slow = [c for fig in figs.values() for c in fig.get("slow", [])]
    slows = cli.load_cases(__file__, args, list(dict.fromkeys(slow)), slow=True)
    return order, used_by, results, slows


def make_rows(order, used_by, results, slows, pv):
    slow_of = {f: set(e.get("slow", [])) for f, e in cases.figure_list().items()}
    rows = []
    entries = [(c, False) for c in order] + [(c, True) for c in order if c in slows]
    for c, is_slow in entries:
        r = (slows if is_slow else results).get(c)
        figs = [f for f in used_by[c] if not is_slow or c in slow_of[f]]
        row = dict(case=c + ("_slow" if is_slow else ""), figures=" ".join(figs),
                   loading="half rate" if is_slow else "preset")
        params = r.params if r else cases.params_from_name(c)
        for k in PARAMS:
            row[k] = num(params.get(k), "%g") if isinstance(params.get(k), float) else num(params.get(k))
        row["status"] = r.status if r else "missing"
        for col, attr in OURS:
            row[col] = num(getattr(r, attr)) if r else ""
        if not is_slow:
            vals = paper_values.values_for_case(c, pv=pv)
            if {"fig8", "fig9"} & set(used_by[c]):  # the pooled Fig. 9 values belong to the realisations
                vals += paper_values.values_for_cv(float(params.get("cv", 0.0)), pv=pv)
            for q in PAPER:
                row[f"paper_{q}"] = paper_cell(vals, q)
        rows.append(row)
    return rows


def series_verdict(direction, ys):
    if len(ys) < 2 or any(math.isnan(y) for y in ys):
        return "not enough data"
    d = [b - a for a, b in zip(ys, ys[1:])]
    if direction == "increasing":
        ok = all(x > 0 for x in d)
    elif direction == "decreasing":
        ok = all(x < 0 for x in d)
    elif direction == "constant":
        mean = sum(ys) / len(ys)
        ok = (max(ys) - min(ys)) <= CONSTANT_RTOL * abs(mean)
    elif direction == "maximum_at_first":
        ok = all(ys[0] > y for y in ys[1:])
    else:
        return f"unknown direction '{direction}'"
    return "holds" if ok else "does NOT hold"


def check_trends(results, pv):
    """[(trend, [(series label, [(x, y)], verdict)])] for every [[trend]] of paper_values.toml."""
    out = []
    rs = [r for r in results.values()]
    for t in pv["trend"]:
        where, against, q = t.get("where", {}), t["against"], t["quantity"]

        def match(r):
            for k, v in where.items():
                vs = v if isinstance(v, list) else [v]
                if not any(math.isclose(float(r.params.get(k, math.nan)), float(x)) for x in vs):
                    return False
            return True

        sel = [r for r in rs if match(r)]
        series = []
        if q in ("R_m_pooled_over_Gamma", "dR_m_pooled_over_Gamma"):
            by_cv = {}
            for r in sel:
                by_cv.setdefault(r.param("cv"), []).append(r)
            pts = []
            for cv in sorted(by_cv):
                m, s, _ = metrics.pooled_rm(by_cv[cv])
                pts.append((cv, m if q.startswith("R_m") else s))
            series.append(("pooled per cv", pts, series_verdict(t["direction"], [p[1] for p in pts])))
        else:
            attr = {"R_init_over_Gamma": "R_init", "R_ss_over_Gamma": "R_ss"}[q]
            free = [k for k in ("theta_D", "sigma_ru_over_sigma0", "Er_over_kd", "cv")
                    if k != against and not (k in where and not isinstance(where[k], list))]
            groups = {}
            for r in sel:
                groups.setdefault(tuple(r.param(k) for k in free), []).append(r)
            for key in sorted(groups):
                g = sorted(groups[key], key=lambda r: r.param(against))
                pts = [(r.param(against), getattr(r, attr)) for r in g]
                label = ", ".join(f"{k} = {v:g}" for k, v in zip(free, key)) or "-"
                series.append((label, pts, series_verdict(t["direction"], [p[1] for p in pts])))
        out.append((t, series))
    return out


def overrides_line(results) -> str:
    """Where the runs are and which --set overrides they ran with beyond their preset and case file (from each
    run's /meta case_toml; `threads` changes nothing and the half-rate twins' `rate_factor` is their column)."""
    sets = set()
    for r in results.values():
        for line in str(r.meta.get("case_toml", "")).splitlines():
            item = line[len("# --set "):].strip() if line.startswith("# --set ") else ""
            if item and not item.replace(" ", "").startswith(("threads=", "rate_factor=")):
                sets.add(item)
    runs = sorted({str(paths.source_root(r.path)) for r in results.values() if not paths.is_record(r.path)})
    records = sorted({str(paths.source_root(r.path)) for r in results.values() if paths.is_record(r.path)})
    where = " ".join([f"Runs: {', '.join(runs)}."] * bool(runs) + [f"Records: {', '.join(records)}."] * bool(records))
    where = where or "No runs found."
    if not sets:
        return where + " Every run at its preset and case file (no --set overrides beyond threads)."
    return (where + " **Every value below is for runs with --set " + " ".join(sorted(sets)) +
            "** beyond their preset and case file: not the default model.")


def write_markdown(path, preset, rows, results, pv, trends):
    short = ["case", "figures", "status", "da_max_over_d", "R_init_over_Gamma", "R_ss_over_Gamma",
             "R_m_over_Gamma", "dR_m_over_Gamma", "da_first_rod_fracture_over_d", "broken_rod_elements",
             "wall_time_s", "paper_R_init_over_Gamma", "paper_R_ss_over_Gamma", "paper_R_m_pooled_over_Gamma",
             "paper_da_first_rod_fracture_over_d"]
    head = ["case", "figs", "status", "Δa_max/d", "R_init/Γ", "R_ss/Γ", "R_m/Γ", "ΔR_m/Γ", "Δa/d 1st rod",
            "broken rods", "wall s", "paper R_init", "paper R_ss", "paper R̄_m (pooled)", "paper Δa/d 1st rod"]

    def fmt(col, v):
        if v == "" or col in ("case", "figures", "status", "broken_rod_elements") or col.startswith("paper"):
            return v
        return "%.4g" % float(v) if col != "wall_time_s" else "%.0f" % float(v)

    lines = [f"# Summary of the {preset} preset runs", "", overrides_line(results), "",
             f"Size convergence: {convergence_label(results.values())} (docs/results.md).", "",
             "R normalised by Gamma_i, crack advance by d. R_init: first R with Delta_a > 0; R_ss: mean R over "
             "the last 20% of the advance reached (the paper: R at Delta_a/d ~ 30); R_m, Delta R_m: mean and "
             "standard deviation of R over 0 < Delta_a/d < 30 of this run. `paper` columns: the values the paper "
             "states (figures/paper_values.toml); Fig. 9 values are pooled over the realisations of one cv.", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        st = row["status"]
        row = dict(row, status=st if st == "completed" else f"**{st}**")
        lines.append("| " + " | ".join(fmt(c, row.get(c, "")) for c in short) + " |")
    # pooled R_m per cv (Fig. 9)
    fig9 = [c for c in cases.figure_cases("fig9") if c in results]
    by_cv = {}
    for c in fig9:
        by_cv.setdefault(results[c].param("cv"), []).append(results[c])
    if by_cv:
        lines += ["", "## Fig. 9: merged crack resistance pooled per cv (0 < Delta_a/d < 30)", "",
                  "| cv | realisations | R̄_m/Γ | ΔR_m/Γ | points | paper R̄_m/Γ | paper ΔR_m/Γ |",
                  "|---|---|---|---|---|---|---|"]
        for cv in sorted(by_cv):
            m, s, n = metrics.pooled_rm(by_cv[cv])
            pm = paper_cell(paper_values.values_for_cv(cv, pv=pv), "R_m_pooled_over_Gamma")
            ps = paper_cell(paper_values.values_for_cv(cv, pv=pv), "dR_m_pooled_over_Gamma")
            lines.append(f"| {cv:g} | {len(by_cv[cv])} | {m:.4g} | {s:.4g} | {n} | {pm} | {ps} |")
    lines += ["", "## Trends the paper states, checked on these runs", "",
              f"('constant': max - min within {CONSTANT_RTOL:.0%} of the mean; each combination of the parameters "
              "the trend does not fix is its own series.)", ""]
    for t, series in trends:
        held = sum(v == "holds" for _, _, v in series)
        judged = sum(v in ("holds", "does NOT hold") for _, _, v in series)
        lines.append(f"- **{t['id']}** ({t['quantity']} {t['direction']} with {t['against']}): "
                     f"holds in {held} of {judged} series with data. Paper: \"{t['quote']}\"")
        for label, pts, verdict in series:
            vals = ", ".join(f"{x:g}: {y:.3g}" for x, y in pts)
            lines.append(f"  - {label}: {vals} -> {verdict}")
    path.write_text("\n".join(lines) + "\n")


def main():
    args = cli.argument_parser(__doc__).parse_args()
    pv = paper_values.paper_values()
    order, used_by, results, slows = collect(args)
    rows = make_rows(order, used_by, results, slows, pv)
    d = paths.figure_dir(args.preset, args.out)
    d.mkdir(parents=True, exist_ok=True)
    with open(d / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({c: row.get(c, "") for c in COLUMNS})
    write_markdown(d / "summary.md", args.preset, rows, results, pv, check_trends(results, pv))
    print(d / "summary.csv")
    print(d / "summary.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
