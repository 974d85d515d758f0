#!/usr/bin/env python3
"""Fig. 5: effect of the rod strength sigma_ru/sigma0 (theta_D = 30 deg, Er/kd = 10).

One row per sigma_ru/sigma0 (7.1, 21.4, 28.5): process-zone maps of ply 1, interlayer 1-2 and ply 2 at the frame
nearest Delta_a/d = 15 (the paper's, Fig. 5) and the R-curve R/Gamma_i against Delta_a/d, with the half-rate twin
of sigma_ru/sigma0 = 7.1 where it was run and the paper's stated values (paper_values.toml).
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig5_rod_strength.pdf and .png.
"""
from figures import plotting

if __name__ == "__main__":
    plotting.map_figure(__file__, "fig5", __doc__, ("sigma_ru_over_sigma0",),
                      "Fig. 5: effect of the rod strength ($\\theta_D$ = 30°, $E_r/kd$ = 10)")
