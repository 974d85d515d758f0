"""A run's record for the studies and bench experiments that keep their numbers without their run folders: the
last history row (`history_end`), the whole record of a run (`record_of`: metrics, /meta provenance, the scene and
the R-curve to 10 digits, as JSON-ready data) and R at a crack advance of a record (`R_at`)."""
from __future__ import annotations

import math
import pathlib

import numpy as np

from enamel_results import results

RECORD_META = ("status", "stop_reason", "steps", "dof", "threads", "wall_time_s", "dt",
               "max_kinetic_over_strain_while_growing", "peak_memory_mb", "git_hash", "static_start")


def cpu_model() -> str:
    """The machine's CPU model (/proc/cpuinfo's "model name"), for the provenance of records and benches."""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def history_end(result_h5) -> dict:
    """The last /history row's applied displacement, time and energy-balance error (results.load_result
    reads /meta and the R-curve, not these)."""
    import h5py
    with h5py.File(result_h5, "r") as f:
        h = f["history"]
        return dict(U_end=float(h["applied_displacement"][-1]), t_end=float(h["time"][-1]),
                    balance_end=float(h["energy_balance_error"][-1]))


def record_of(result_h5: pathlib.Path, name: str) -> dict:
    """The record of the run whose result file (result.h5, or the partial or failed one) is `result_h5`: its
    case, /meta provenance (RECORD_META), last history row, R_init, R_ss, R_m, Delta_a reached, broken rods,
    warnings, how far the inelastic zone reached at Delta_a = 0, 1, 2, 5, ..., 30 d (the scene), the step at
    which the crack reached each of them, and the R-curve to 10 significant digits."""
    import h5py
    r = results.load_result(result_h5)  # the case from /meta's case_source
    m = r.meta
    meta = {k: (m[k].item() if hasattr(m.get(k), "item") else m.get(k)) for k in RECORD_META if k in m}
    meta.update(history_end(result_h5))
    with h5py.File(result_h5, "r") as f:
        h = f["history"]
        da_h, reach, step_h = np.asarray(h["da_over_d"]), np.asarray(h["inelastic_reach_over_d"]), np.asarray(h["step"])
    scene = [(float(d), float(reach[np.argmax(da_h >= d)])) for d in (0.0, 1, 2, 5, 10, 15, 20, 25, 30) if (da_h >= d).any()]
    # the step at which the crack first reached each Delta_a (0: its start), for the steps saved at equal advance
    steps_at = [(float(d), int(step_h[np.argmax(da_h >= d)])) for d in (1e-9, 1, 2, 5, 10, 15, 20, 25, 30) if (da_h >= d).any()]
    return dict(name=name, case=r.case, meta=meta,
                R_init=r.R_init, R_ss=r.R_ss, R_m=r.R_m, da_max=r.da_max, broken_rods=r.broken_rods,
                warnings=str(m.get("warnings", "")), reach_at_da=scene, steps_at_da=steps_at,
                da=[float(f"{x:.10g}") for x in r.da], R=[float(f"{x:.10g}") for x in r.R])


def R_at(rec: dict, d: float) -> float:
    """R/Gamma at the first R-curve point at or past Delta_a = d (nan when the crack did not get there)."""
    da, R = np.array(rec["da"]), np.array(rec["R"])
    return float(R[np.argmax(da >= d)]) if (da >= d).any() else math.nan
