"""Adaptive loading rate (case key rate_adapt_max, solver/lib/kernels/loading_rate.hpp):
a ci-size lumped run with rate_adapt_max = 8 raises the rate multiplier phi (/history/rate_multiplier) above 1
while the specimen loads elastically, so the grips move faster than v_app on average; every history interval
follows the rule (a rise x1.25 while elastic and rho = (kinetic energy beyond the loading's motion)/strain < rho_lo, a halving after rho > rho_hi or a
rod deletion); the run keeps its energy balance and its kinetic/strain ratio within the run's bounds (no
warnings), and continues bit for bit after SIGKILLs and --restart. rate_adapt_max = 1 (the default) is today's
run bit for bit: test_reference_outputs."""

import h5py
import numpy as np
import pytest

from conftest import ROOT, run_with_kills
from enamel_results.constants import KINETIC_WARN, LOADING_RATE  # the solver's warning bound and rate rule

CASE = ROOT / "paper_cases" / "theta30_s21.4_e10_cv0.toml"
# at G = 3: at G = 10 this ci run's kinetic/strain ratio reaches 0.075 (measured) past the 0.05 bound, so the
# adaptive rate x8 is not quasi-static there; the rule is tested where it is, and with the intact tip: with the
# default cut tip this run's ratio reaches 0.080 at step 5592, before any crack advance (measured)
SETS = ["stop_da_over_d=2", "threads=1", "Gamma_k_over_sigma0sq=3",
        'crisscross_at_tip="intact"']   # the ci preset stopped early: 0.6-1.5 s (10,409 steps)
RHO_HIGH, RHO_LOW, RAISE, LOWER = (LOADING_RATE[k] for k in ("rho_high", "rho_low", "raise", "lower"))  # loading_rate.hpp


def args_for(out, rate_max, *extra):
    a = ["run", CASE, "--preset", "ci", "--out", out, "--quiet", "--set", f"rate_adapt_max={rate_max}"]
    for s in SETS:
        a += ["--set", s]
    return a + list(extra)


def read(path):
    with h5py.File(path, "r") as f:
        h = {k: f["history"][k][:] for k in f["history"]}
        return {"history": h, "da": f["rcurve/da_over_d"][:], "R": f["rcurve/R_over_Gamma"][:],
                "meta": dict(f["meta"].attrs)}


@pytest.fixture(scope="module")
def adaptive(run, tmp_path_factory):
    out = tmp_path_factory.mktemp("rate8")
    r = run(*args_for(out, 8))
    assert r.returncode == 0, r.stderr
    return read(out / "result.h5")


def test_rate_rises_while_loading_elastically(adaptive):
    h, meta = adaptive["history"], adaptive["meta"]
    phi = h["rate_multiplier"]
    assert np.all((phi >= 1.0) & (phi <= 8.0))
    elastic = (h["da_over_d"] == 0) & (h["broken_rod_elements"] == 0) & (h["failed_interfaces"] == 0)
    # on average faster than v_app: U(t) > 1.5 v_app t at the end (a fixed rate gives U < v_app t)
    speedup = h["applied_displacement"][-1] / (float(meta["v_app"]) * h["time"][-1])
    print(f"phi: max {phi.max():.3g}, while elastic {phi[elastic].max():.3g}; U / (v_app t) = {speedup:.3g}; "
          f"steps {meta['steps']}")
    assert phi[elastic].max() > 1.5, "the rate was not raised during the elastic loading"
    assert speedup > 1.5


def rule_rows(h, rho_high, rho_low):
    """Check every history interval against the rule with these bounds; return (raised, lowered, held above
    the default high bound): phi at row i+1 is the rule's target set at row i (the ramp ends on the next history
    row)."""
    phi = h["rate_multiplier"]
    rho = h["kinetic_energy_beyond_loading"] / np.maximum(h["strain_energy_beams"] + h["strain_energy_interfaces"], 1e-300)
    deleted = np.diff(h["broken_rod_elements"], prepend=0) > 0
    elastic = (h["da_over_d"] == 0) & (h["broken_rod_elements"] == 0) & (h["failed_interfaces"] == 0)
    raised = lowered = held_above_default = 0
    for i in range(1, len(phi) - 2):   # the last row is where the run stopped, off the history interval
        if deleted[i] or rho[i] > rho_high:
            assert phi[i + 1] == max(1.0, LOWER * phi[i]), f"row {i}: not halved"
            lowered += 1
        elif elastic[i] and rho[i] < rho_low:
            assert phi[i + 1] == min(8.0, RAISE * phi[i]), f"row {i}: not raised"
            raised += 1
        elif rho[i] > RHO_HIGH and phi[i] > 1:
            held_above_default += phi[i + 1] >= phi[i]
    return raised, lowered, held_above_default


def test_each_interval_follows_the_rule(adaptive):
    """x1.25 (capped) while elastic and rho < rho_lo, halved (not below 1) after rho > rho_hi or a deletion."""
    raised, lowered, _ = rule_rows(adaptive["history"], RHO_HIGH, RHO_LOW)
    assert raised >= 3 and lowered >= 1, (raised, lowered)


def test_case_key_moves_the_rules_bounds(run, tmp_path):
    """rate_adapt_rho_high = 0.04: halved only above 0.04, raised below 0.01 (a quarter of it), and at least one
    interval with rho above the default's 0.01 at phi > 1 not lowered (the default would have halved it)."""
    assert LOADING_RATE["rho_low_share"] == 0.25 and RHO_LOW == LOADING_RATE["rho_low_share"] * RHO_HIGH
    r = run(*args_for(tmp_path, 8, "--set", "rate_adapt_rho_high=0.04"))
    assert r.returncode == 0, r.stderr
    raised, lowered, held = rule_rows(read(tmp_path / "result.h5")["history"], 0.04, 0.01)
    print(f"rho_high 0.04: raised {raised}, lowered {lowered}, held above 0.01 {held}")
    assert raised >= 3 and held >= 1, (raised, lowered, held)


def test_adaptive_run_stays_quasi_static_and_balanced(adaptive):
    meta = adaptive["meta"]
    assert meta["status"] == "completed"
    # neither the energy balance nor the kinetic ratio warned (the size warning is about the ci specimen's height)
    warned = [w for w in meta["warnings"].splitlines() if w and not w.startswith("inelastic zone reached")]
    assert warned == [], meta["warnings"]
    assert meta["max_kinetic_over_strain_while_growing"] < KINETIC_WARN


def test_restart_of_adaptive_run_is_bit_for_bit(enamel, adaptive, tmp_path):
    """Killed (SIGKILL) twice after a checkpoint while phi moves, continued with --restart: the same history
    (phi included), R-curve and step count as the uninterrupted run."""
    out = tmp_path / "killed"
    # the whole run is 0.6 s on an AMD EPYC: checkpoints every 0.02 s and kills 0.01 s after one, so
    # both kills land in the first half of the run on a machine several times faster
    kills = run_with_kills(enamel, out, lambda extra: args_for(out, 8, *extra), [0.01, 0.01], timeout=600,
                           every=0.02)
    assert kills == 2, f"only {kills} kills landed after a checkpoint (run too short?)"
    a, b = adaptive, read(out / "result.h5")
    assert a["meta"]["steps"] == b["meta"]["steps"]
    assert np.array_equal(a["da"], b["da"]) and np.array_equal(a["R"], b["R"])
    for name in ("rate_multiplier", "applied_displacement", "J_over_Gamma", "kinetic_energy", "broken_rod_elements"):
        assert np.array_equal(a["history"][name], b["history"][name]), f"{name} differs after restarts"
