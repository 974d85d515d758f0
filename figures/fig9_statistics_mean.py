#!/usr/bin/env python3
"""Fig. 9: merged crack resistance R_m/Gamma_i against the coefficient of variation cv of the rod strength
(mean sigma_ru/sigma0 = 28.5, theta_D = 30 deg, Er/kd = 10).

Left: R_m/Gamma_i, the mean of all R points with 0 < Delta_a/d < 30 pooled over the realisations of one cv (the
cv = 0 case alone), with the pooled standard deviation Delta R_m/Gamma_i as error bars; small grey dots: each
realisation's own R_m. Right: Delta R_m/Gamma_i against cv. Dashed: the paper's values (paper_values.toml).
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig9_statistics_mean.pdf and .png.
"""
import pathlib

import matplotlib.pyplot as plt

from enamel_results import cases, cli, metrics, paper_values
from figures import plotting


def main():
    args = cli.argument_parser(__doc__).parse_args()
    names = cases.figure_cases("fig9")
    results = cli.load_cases(__file__, args, names)
    pv = paper_values.paper_values()
    by_cv = {}
    for r in results.values():
        by_cv.setdefault(r.param("cv"), []).append(r)
    cvs = sorted(by_cv)
    pooled = {cv: metrics.pooled_rm(by_cv[cv]) for cv in cvs}
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    ax.errorbar(cvs, [pooled[c][0] for c in cvs], yerr=[pooled[c][1] for c in cvs], marker="o", capsize=4,
                color="C0", label=f"{args.preset} preset: pooled $\\bar R_m \\pm \\Delta R_m$")
    for cv in cvs:
        ax.plot([cv] * len(by_cv[cv]), [r.R_m for r in by_cv[cv]], linestyle="", marker=".", color="grey",
                label="single realisation $R_m$" if cv == cvs[0] else None)
        ax.annotate(f"n={len(by_cv[cv])}" + ("" if all(r.completed for r in by_cv[cv]) else " [NOT COMPLETED]"),
                    (cv, pooled[cv][0]), textcoords="offset points", xytext=(6, 6), fontsize=7,
                    color="black" if all(r.completed for r in by_cv[cv]) else "red")
        ax2.plot([cv], [pooled[cv][1]], marker="o", color="C0",
                 label=f"{args.preset} preset: pooled $\\Delta R_m$" if cv == cvs[0] else None)
    for a, q in ((ax, "R_m_pooled_over_Gamma"), (ax2, "dR_m_pooled_over_Gamma")):
        for v in pv["value"]:
            if v["quantity"] != q or "cv" not in v:
                continue
            lo, hi = min(v["cv"]), max(v["cv"])
            pad = 0.02
            lab = f"paper: {paper_values.paper_value_text(v)} (cv = {', '.join(f'{c:g}' for c in v['cv'])})"
            a.plot([lo - pad, hi + pad], [v["value"]] * 2, **plotting.PAPER_STYLE, label=lab)
        a.set_xlabel("coefficient of variation of rod strength $\\Delta\\sigma_{ru}/\\bar\\sigma_{ru}$")
        a.grid(alpha=0.3)
        a.set_ylim(bottom=0)
        a.set_xlim(-0.05, max(cvs + [0.3]) + 0.05)
        a.legend(fontsize=7.5, loc="lower left")
    ax.set_ylabel("merged crack resistance $\\bar R_m/\\Gamma_i$ ($0 < \\Delta a/d < 30$)")
    ax2.set_ylabel("spread $\\Delta R_m/\\Gamma_i$ (standard deviation)")
    fig.suptitle(f"Fig. 9: merged crack resistance against cv ($\\bar\\sigma_{{ru}}/\\sigma_0$ = 28.5, "
                 f"$\\theta_D$ = 30°, $E_r/kd$ = 10)\n({plotting.preset_text(args.preset, results.values())})", fontsize=11)
    plotting.save(fig, args.preset, pathlib.Path(__file__).stem, args.out)


if __name__ == "__main__":
    main()
