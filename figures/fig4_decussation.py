#!/usr/bin/env python3
"""Fig. 4: effect of the decussation angle theta_D (sigma_ru/sigma0 = 21.4, Er/kd = 10).

One row per theta_D (0, 15, 30 deg): process-zone maps of ply 1, interlayer 1-2 and ply 2 at the frame nearest
Delta_a/d = 15 (interfaces coloured by state, deleted rod elements in black) and the R-curve R/Gamma_i against
Delta_a/d, with the half-rate twin where it was run and the paper's stated values (paper_values.toml).
Reads runs/PRESET/<case>/result.h5 (or its record records/PRESET/<case>.json);
writes figures/out/PRESET/fig4_decussation.pdf and .png.
"""
from figures import plotting

if __name__ == "__main__":
    plotting.map_figure(__file__, "fig4", __doc__, ("theta_D",),
                      "Fig. 4: effect of the decussation angle ($\\sigma_{ru}/\\sigma_0$ = 21.4, $E_r/kd$ = 10)")
