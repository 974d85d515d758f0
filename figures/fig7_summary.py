#!/usr/bin/env python3
"""Fig. 7: initiation toughness R_init/Gamma_i and steady-state crack resistance R_ss/Gamma_i against the
decussation angle theta_D, the rod strength sigma_ru/sigma0 and the stiffness contrast Er/kd (the 36 cases of
figures/fig7_summary.toml).

Rows: R_init, R_ss; columns: Er/kd = 5, 10, 20; horizontal axis sigma_ru/sigma0; one line per theta_D. The
parameters come from each result's /meta case_toml. R_init is the first R with Delta_a > 0; R_ss is our
/rcurve attribute (mean R over the last 20% of the advance reached; the paper takes R at Delta_a/d ~ 30).
Stars: the paper's stated values (paper_values.toml). Red rings: runs that did not complete.
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig7_summary.pdf and .png.
"""
import pathlib

import matplotlib.pyplot as plt
from matplotlib.lines import Line2D

from enamel_results import cases, cli, paper_values
from figures import plotting

QUANTITIES = (("R_init", "R_init_over_Gamma", "initiation toughness $R_{init}/\\Gamma_i$"),
              ("R_ss", "R_ss_over_Gamma", "steady-state resistance $R_{ss}/\\Gamma_i$"))


def main():
    args = cli.argument_parser(__doc__).parse_args()
    names = cases.figure_cases("fig7")
    results = cli.load_cases(__file__, args, names)
    pv = paper_values.paper_values()
    rs = list(results.values())
    E_values = sorted({r.param("Er_over_kd") for r in rs})
    thetas = sorted({r.param("theta_D") for r in rs})
    fig, axes = plt.subplots(2, len(E_values), figsize=(4.2 * len(E_values), 7.5), squeeze=False,
                             sharex=True, sharey="row", layout="constrained")
    for col, E in enumerate(E_values):
        for row, (attr, quantity, ylabel) in enumerate(QUANTITIES):
            ax = axes[row, col]
            for i, th in enumerate(thetas):
                pts = sorted((r.param("sigma_ru_over_sigma0"), getattr(r, attr), r) for r in rs
                             if r.param("theta_D") == th and r.param("Er_over_kd") == E)
                if not pts:
                    continue
                x = [p[0] for p in pts]
                y = [p[1] for p in pts]
                ax.plot(x, y, marker="o", color=f"C{i}", label=f"$\\theta_D$ = {th:g}°")
                bad = [(p[0], p[1]) for p in pts if not p[2].completed]
                if bad:
                    ax.plot(*zip(*bad), linestyle="", marker="o", markersize=11, markerfacecolor="none",
                            markeredgecolor="red", markeredgewidth=1.5)
                for p in pts:
                    for v in paper_values.values_for_case(p[2].case, "fig7", pv):
                        if v["quantity"] == quantity:
                            ax.plot([p[0] + 0.6 * (i - 1)], [float(v["value"])], linestyle="", marker="*",
                                    markersize=12, color=f"C{i}", markeredgecolor="black")
            ax.set_title(f"$E_r/kd$ = {E:g}", fontsize=10)
            ax.grid(alpha=0.3)
            if col == 0:
                ax.set_ylabel(ylabel)
            if row == 1:
                ax.set_xlabel("rod strength $\\sigma_{ru}/\\sigma_0$")
    for ax in axes[:, 0]:  # after all panels are drawn: shared y-axes autoscale over the whole row
        ax.set_ylim(bottom=0)
    handles = [Line2D([], [], color=f"C{i}", marker="o", label=f"$\\theta_D$ = {th:g}°")
               for i, th in enumerate(thetas)]
    handles.append(Line2D([], [], linestyle="", marker="*", markersize=12, color="grey", markeredgecolor="black",
                          label="paper (stated value; colour = $\\theta_D$, shifted sideways)"))
    if any(not r.completed for r in rs):
        handles.append(Line2D([], [], linestyle="", marker="o", markersize=11, markerfacecolor="none",
                              markeredgecolor="red", label="run not completed"))
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=len(handles), fontsize=9,
               frameon=False)
    missing = len(names) - len(results)
    fig.suptitle(f"Fig. 7: $R_{{init}}$ and $R_{{ss}}$ against $\\theta_D$, $\\sigma_{{ru}}/\\sigma_0$ and $E_r/kd$ "
                 f"({plotting.preset_text(args.preset, results.values())}, {len(results)} runs" + (f", {missing} missing" if missing else "") + ")",
                 fontsize=11)
    plotting.save(fig, args.preset, pathlib.Path(__file__).stem, args.out)


if __name__ == "__main__":
    main()
