#!/usr/bin/env python3
"""Fig. 8: effect of the coefficient of variation cv of the rod strength (mean sigma_ru/sigma0 = 28.5,
theta_D = 30 deg, Er/kd = 10).

One row per cv (0, 0.1, 0.2, 0.3): process-zone maps of ply 1, interlayer 1-2 and ply 2 of one realisation (the
lowest seed present) at the frame nearest Delta_a/d = 15, and the R-curves R/Gamma_i against Delta_a/d of all
realisations (five per cv > 0) with the paper's merged crack resistance R_m/Gamma_i (paper_values.toml).
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig8_statistics_rcurves.pdf and .png.
"""
import pathlib

from enamel_results import cases, cli, paper_values
from figures import plotting


def main():
    args = cli.argument_parser(__doc__, maps=True).parse_args()
    names = cases.figure_cases("fig8")
    results = cli.load_cases(__file__, args, names, full=True)
    pv = paper_values.paper_values()
    da = args.da if args.da is not None else paper_values.snapshot_da("fig8", pv)
    by_cv = {}
    for c in names:
        if c in results:
            by_cv.setdefault(results[c].param("cv"), []).append(results[c])
    cvs = sorted(by_cv)
    first = by_cv[cvs[0]][0]
    fig, axes = plotting.map_row_layout(len(cvs), first.geometry.attrs)
    for row, cv in zip(axes, cvs):
        group = sorted(by_cv[cv], key=lambda r: r.param("seed"))
        shown = group[0]
        label = f"cv = {cv:g}" + (f" (seed {int(shown.param('seed'))})" if cv > 0 else "")
        plotting.draw_map_row(row, shown, da, label)
        ax = row[3]
        for i, r in enumerate(group):
            plotting.draw_rcurve(ax, r, label=f"seed {int(r.param('seed'))}" + plotting.status_flag(r),
                               color=f"C{i}", markersize=1.5, linewidth=1.0)
        plotting.draw_paper_values(ax, paper_values.values_for_cv(cv, "R_m_pooled_over_Gamma", pv))
        plotting.format_rcurve_axes(ax)
        incomplete = [r for r in group if not r.completed]
        title = f"cv = {cv:g}: {len(group)} realisation" + ("s" if len(group) != 1 else "")
        ax.set_title(title + (f" [{len(incomplete)} NOT COMPLETED]" if incomplete else ""), fontsize=9,
                     color="red" if incomplete else "black")
        ax.legend(fontsize=6.5, loc="best", ncol=2)
    fig.legend(handles=plotting.map_legend_handles(), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=5,
               fontsize=8, frameon=False)
    fig.suptitle("Fig. 8: effect of the rod-strength coefficient of variation ($\\bar\\sigma_{ru}/\\sigma_0$ = 28.5, "
                 f"$\\theta_D$ = 30°, $E_r/kd$ = 10)\n({plotting.preset_text(args.preset, results.values())}; maps at the frame nearest "
                 f"$\\Delta a/d$ = {da:g})", fontsize=11)
    plotting.save(fig, args.preset, pathlib.Path(__file__).stem, args.out)


if __name__ == "__main__":
    main()
