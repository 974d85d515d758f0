"""`enamel-dem info --estimate`'s time of a run (solver/lib/simulation/resources.cpp) against the solver's own numbers: the
time step of its 16 x 8 d block against the one of the model `info` builds at the reduced size, and the steps of
the whole run against real ci runs (/meta steps). The U_end constants were measured on the ci run of
theta30_s21.4_e10_cv0; theta0_s21.4_e10_cv0 (another decussation angle, another c_d and dt) was not used."""
import re

import h5py
import pytest

from conftest import PAPER_CASES

STEPS_FACTOR = 3   # the estimate's steps within this factor of a real run's


def estimate(run, case, preset, *sets):
    args = ["info", PAPER_CASES / f"{case}.toml", "--preset", preset, "--estimate"]
    for s in sets:
        args += ["--set", s]
    r = run(*args)
    assert r.returncode == 0, r.stderr
    return {k: float(v) for k, v in (line.split() for line in r.stdout.splitlines())}


@pytest.mark.parametrize("case", ["theta30_s21.4_e10_cv0", "theta0_s21.4_e10_cv0"])
def test_estimated_steps_of_a_ci_run_are_within_3x_of_the_real_ones(run, ci_run, case):
    est = estimate(run, case, "ci")
    with h5py.File(ci_run(case), "r") as f:
        meta = f["meta"].attrs
        steps, dt, c_d = float(meta["steps"]), float(meta["dt"]), float(meta["c_d_over_cr"])
    assert est["dt"] == pytest.approx(dt, rel=1e-5)      # the ci size is the block's: the same model
    assert est["c_d"] == pytest.approx(c_d, rel=1e-5)
    assert 1 / STEPS_FACTOR < est["steps"] / steps < STEPS_FACTOR, (est, steps)
    # seconds = set-up + steps x seconds per step (rounded up to whole seconds)
    assert est["seconds"] == pytest.approx(est["setup_seconds"] + est["steps"] * est["seconds_per_step"], abs=2)


def test_block_time_step_is_the_full_models_at_the_reduced_size(run):
    """The reduced preset (40 x 20 d, dt_factor 0.22): the 16 x 8 d block's dt within 2% of the built model's
    (0.7% below it, measured)."""
    est = estimate(run, "theta30_s21.4_e10_cv0", "reduced")
    built = run("info", PAPER_CASES / "theta30_s21.4_e10_cv0.toml", "--preset", "reduced")
    assert built.returncode == 0, built.stderr
    dt = float(re.search(r"^time step\s+dt (\S+)", built.stdout, re.M).group(1))
    c_d = float(re.search(r"c_d (\S+) c_r", built.stdout).group(1))
    assert est["dt"] == pytest.approx(dt, rel=0.02)
    assert est["c_d"] == pytest.approx(c_d, rel=1e-3)    # info prints 4 digits


def test_half_rate_twin_takes_about_twice_as_long(run):
    base = estimate(run, "theta30_s21.4_e10_cv0", "reduced")
    twin = estimate(run, "theta30_s21.4_e10_cv0", "reduced", "rate_factor=0.5")
    assert 1.8 < twin["steps"] / base["steps"] <= 2.0
    assert 1.8 < twin["seconds"] / base["seconds"] <= 2.0
