#!/usr/bin/env python3
"""Fig. 6: effect of the stiffness contrast Er/kd (theta_D = 30 deg, sigma_ru/sigma0 = 21.4).

One row per Er/kd (5, 10, 20): process-zone maps of ply 1, interlayer 1-2 and ply 2 at the frame nearest
Delta_a/d = 15 and the R-curve R/Gamma_i against Delta_a/d with the paper's stated values (paper_values.toml).
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig6_stiffness_contrast.pdf and .png.
"""
from figures import plotting

if __name__ == "__main__":
    plotting.map_figure(__file__, "fig6", __doc__, ("Er_over_kd",),
                      "Fig. 6: effect of the stiffness contrast ($\\theta_D$ = 30°, $\\sigma_{ru}/\\sigma_0$ = 21.4)")
