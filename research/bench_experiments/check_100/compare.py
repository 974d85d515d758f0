"""The check at 100 x 100 d: `make bench-paper`'s variant (lumped, dt_factor 0.22,
damping_cap 0.5, static_start 0.95) against the same scheme from rest (the unaccelerated lumped run), theta_D = 30
(21.4, 10), to Delta_a = 30 d.

    python3 -m bench.experiments.check_100.compare --rest RUN_DIR --static RUN_DIR   # from two runs: records
    python3 -m bench.experiments.check_100.compare                                  # the report from the records

The runs (commands in README.md here) are not kept; each leaves a record (record_<name>.json: metrics and the
whole R-curve to 10 digits) from which README.md's table and rcurves.png are made, so the report regenerates
without them.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import numpy as np

from enamel_results import metrics, paths
from bench import records as run_records
from bench.records import R_at

HERE = pathlib.Path(__file__).resolve().parent
NAMES = ("rest", "static")


def result_file(run_dir: pathlib.Path) -> pathlib.Path:
    """result.h5, or result.partial.h5 of a run stopped by Ctrl-C (its status then says interrupted), or
    result.failed.h5 of a run that stopped itself (status failed)."""
    return paths.run_result(run_dir) or pathlib.Path(run_dir) / paths.RESULT_NAMES["completed"]


def record_of(run_dir: pathlib.Path, name: str) -> dict:
    return run_records.record_of(result_file(run_dir), name)


def report(records: dict) -> str:
    a, b = records["rest"], records["static"]
    l2 = metrics.rcurve_rel_l2(np.array(a["da"]), np.array(a["R"]), np.array(b["da"]), np.array(b["R"]))
    lines = ["| run | status | steps | wall s (stepping) | R_init/Gamma | R_ss/Gamma | R_m/Gamma | Delta_a max/d | broken rods | KE/SE max | balance |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for rec in (a, b):
        m = rec["meta"]
        lines.append(f"| {rec['name']} | {m.get('status')} | {m.get('steps')} | {m.get('wall_time_s', math.nan):.0f} | "
                     f"{rec['R_init']:.4f} | {rec['R_ss']:.4f} | {rec['R_m']:.4f} | {rec['da_max']:.2f} | {rec['broken_rods']} | "
                     f"{m.get('max_kinetic_over_strain_while_growing', math.nan):.3g} | {m.get('balance_end', math.nan):.2g} |")
    # over the common range, as the bench does: R at a few Delta_a, and R_ss over its last 20%
    common = min(a["da_max"], b["da_max"])
    at = [d for d in (0.5, 1, 2, 5, 10, 15, 20, 25, 30) if d <= common]
    def R_ss_common(rec):
        da, R = np.array(rec["da"]), np.array(rec["R"])
        sel = (da >= 0.8 * common) & (da <= common)
        return float(R[sel].mean()) if sel.any() else math.nan
    lines += ["", f"Common range Delta_a <= {common:.2f} d; R/Gamma at the first R-curve point at or past each Delta_a:", "",
              "| run | " + " | ".join(f"{d:g} d" for d in at) + " | R_ss of the common range |",
              "|---|" + "---|" * (len(at) + 1)]
    for rec in (a, b):
        lines.append(f"| {rec['name']} | " + " | ".join(f"{R_at(rec, d):.4f}" for d in at) + f" | {R_ss_common(rec):.4f} |")
    # steps to the same crack advance: the last Delta_a both reached
    sa, sb = dict(a["steps_at_da"]), dict(b["steps_at_da"])
    last = max(d for d in sa if d in sb)
    steps = sa[last] / sb[last]
    lines += ["", f"R-curve relative L2 (static start against from rest, common Delta_a range): **{l2:.3g}** "
              f"(bound 0.02: {'within' if l2 <= 0.02 else 'OUTSIDE'}); R_init {b['R_init'] / a['R_init'] - 1:+.2e}, "
              f"R_ss of the common range {R_ss_common(b) / R_ss_common(a) - 1:+.2e}, broken rods {b['broken_rods'] - a['broken_rods']:+d}; "
              f"steps to Delta_a = {last:g} d from rest / with the static start: {sa[last]} / {sb[last]} = {steps:.3f}."]
    lines += ["", "How far the inelastic zone reaches from the crack plane (`/history/inelastic_reach_over_d`, first history "
              "row at or past each Delta_a; half-height 50 d):", ""]
    cols = max((a, b), key=lambda rec: len(rec["reach_at_da"]))["reach_at_da"]
    lines += ["| Delta_a/d | " + " | ".join(f"{d:g}" for d, _ in cols) + " |", "|---|" + "---|" * len(cols)]
    for rec in (a, b):
        cells = [f"{r:.1f}" for _, r in rec["reach_at_da"]] + ["-"] * (len(cols) - len(rec["reach_at_da"]))
        lines.append(f"| reach/d, {rec['name']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def extra_report(rest: dict, extras: dict) -> str:
    """Further variants (e.g. a faster loading rate) against the run from rest: R-curve L2, R_init, the steps to
    the last Delta_a both reached, broken rods, the largest KE/SE."""
    if not extras:
        return ""
    lines = ["", "", "Further variants against the run from rest:", "",
             "| variant | Delta_a max/d | R-curve L2 | R_init | R/Gamma at 5, 10, 20 d | broken rods | steps (rest / variant) | KE/SE max |",
             "|---|---|---|---|---|---|---|---|"]
    for name, rec in extras.items():
        l2 = metrics.rcurve_rel_l2(np.array(rest["da"]), np.array(rest["R"]), np.array(rec["da"]), np.array(rec["R"]))
        sa, sv = dict(rest["steps_at_da"]), dict(rec["steps_at_da"])
        last = max(d for d in sv if d in sa)
        lines.append(f"| {name} | {rec['da_max']:.2f} | {l2:.3g} ({'within' if l2 <= 0.02 else 'outside'} 2%) | "
                     f"{rec['R_init'] / rest['R_init'] - 1:+.2%} | " + ", ".join(f"{R_at(rec, d):.2f}" for d in (5, 10, 20)) +
                     f" (rest {', '.join(f'{R_at(rest, d):.2f}' for d in (5, 10, 20))}) | {rec['broken_rods']} ({rest['broken_rods']}) | "
                     f"{sa[last]} / {sv[last]} = {sa[last] / sv[last]:.2f} to {last:g} d | "
                     f"{rec['meta'].get('max_kinetic_over_strain_while_growing', math.nan):.3g} |")
    return "\n".join(lines)


def plot(records: dict, out: pathlib.Path, extras: dict | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    for name, style in (("rest", "-"), ("static", "--")):
        rec = records[name]
        ax.plot(rec["da"], rec["R"], style, label={"rest": "lumped from rest", "static": "static start 0.95 (bench-paper's)"}[name])
    for name, rec in (extras or {}).items():
        ax.plot(rec["da"], rec["R"], ":", lw=1, label=f"{name} (static start)")
    ax.set_xlabel(r"$\Delta a / d$")
    ax.set_ylabel(r"$R / \Gamma_i$")
    ax.set_title(r"100 x 100 d, $\theta_D$ = 30 (21.4, 10)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rest", type=pathlib.Path, help="run folder of the run from rest (writes record_rest.json)")
    ap.add_argument("--static", type=pathlib.Path, help="run folder of the static-start run (writes record_static.json)")
    ap.add_argument("--extra", action="append", default=[], metavar="NAME=RUN_DIR",
                    help="a further variant's run (writes record_NAME.json; the report compares it with the run from rest)")
    ap.add_argument("--out", type=pathlib.Path, default=HERE, help="folder of the records and the report")
    args = ap.parse_args(argv)
    for name in NAMES:
        run = getattr(args, name)
        if run is not None:
            (args.out / f"record_{name}.json").write_text(json.dumps(record_of(run, name), indent=1) + "\n")
    for item in args.extra:
        name, _, run = item.partition("=")
        (args.out / f"record_{name}.json").write_text(json.dumps(record_of(pathlib.Path(run), name), indent=1) + "\n")
    try:
        records = {n: json.loads((args.out / f"record_{n}.json").read_text()) for n in NAMES}
    except FileNotFoundError as e:
        print(f"compare: missing record {e.filename}: run with --rest and --static first", file=sys.stderr)
        return 3
    extras = {p.stem[len("record_"):]: json.loads(p.read_text()) for p in sorted(args.out.glob("record_*.json"))
              if p.stem[len("record_"):] not in NAMES}
    text = report(records) + extra_report(records["rest"], extras)
    plot(records, args.out / "rcurves.png", extras)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
