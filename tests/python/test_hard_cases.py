"""Hard cases: each runs at the ci preset to its stop criterion and must finish
with status "completed", no NaN/Inf anywhere in /history or /rcurve, and an energy-balance error within
BALANCE_BOUND once the external work is meaningful (> 1% of its final value, as in test_reference_solver).
theta_D = 0 is the shared ci run of paper_cases/theta0_s21.4_e10_cv0.toml (conftest.ci_run, to the
preset's Delta_a = 5 d); the others are the theta_D = 30 base case with their changes, to Delta_a = 4 d."""
import h5py
import numpy as np
import pytest

from conftest import ROOT

# 2%: the runner's own warning level (solver/lib/run/runner.cpp kBalanceWarn); the measured errors are 1e-6..1e-3.
BALANCE_BOUND = 0.02
BASE = ROOT / "paper_cases" / "theta30_s21.4_e10_cv0.toml"
THETA0_CASE = "theta0_s21.4_e10_cv0"  # BASE with theta_D = 0
VERY_WEAK = "very_weak_rods_all"

HARD = {
    # weak rods: rod fracture competes with interface failure, the symmetric crack branch is unstable
    "weak_rods_s7.1": ["sigma_ru_over_sigma0=7.1"],
    "stiff_rods_e20": ["Er_over_kd=20"],
    "scatter_cv0.3": ["sigma_ru_over_sigma0=28.5", "cv=0.3", "seed=3"],
    "theta0": None,  # the shared ci run of THETA0_CASE
    "theta45": ["theta_D=45"],
    # rods so weak that many elements pass their strength in the same step (deletion rule "all") and nodes
    # lose every rod element around them (they keep their lumped mass: docs/model.md departure)
    VERY_WEAK: ["sigma_ru_over_sigma0=0.6", "deletion_rule=\"all\""],
}


@pytest.fixture(scope="module")
def hard_result(run, ci_run, tmp_path_factory):
    """hard_result(name): the open result file of one hard case, each run once per module."""
    made = {}

    def _get(name):
        if name not in made:
            if HARD[name] is None:
                made[name] = h5py.File(ci_run(THETA0_CASE), "r")
            else:
                out = tmp_path_factory.mktemp(name)
                args = ["run", BASE, "--preset", "ci", "--out", out, "--quiet", "--set", "stop_da_over_d=4"]
                for s in HARD[name]:
                    args += ["--set", s]
                r = run(*args, timeout=900)
                assert r.returncode == 0, f"{name}: exit {r.returncode}\n{r.stderr}"
                made[name] = h5py.File(out / "result.h5", "r")
        return made[name]
    return _get


@pytest.fixture(params=sorted(HARD))
def hard_run(request, hard_result):
    return request.param, hard_result(request.param)


def test_hard_case_completes_finite_and_balanced(hard_run):
    name, f = hard_run
    meta = f["meta"].attrs
    assert meta["status"] == "completed", f"{name}: {meta['stop_reason']}"
    assert "stop_da_over_d" in meta["stop_reason"], f"{name}: stopped by {meta['stop_reason']}"
    for group in ("history", "rcurve"):
        for key, ds in f[group].items():
            assert np.all(np.isfinite(ds[:])), f"{name}: non-finite values in /{group}/{key}"
    h = f["history"]
    work = h["external_work"][:]
    meaningful = work > 0.01 * work[-1]
    worst = float(np.max(np.abs(h["energy_balance_error"][:][meaningful])))
    print(f"{name}: R_init {f['rcurve'].attrs['R_init_over_Gamma']:.3f}  R_ss {f['rcurve'].attrs['R_ss_over_Gamma']:.3f}"
          f"  broken rods {int(h['broken_rod_elements'][-1])}  worst balance {worst:.2e}")
    assert worst < BALANCE_BOUND, f"{name}: energy balance error {worst:.3g}"


def test_very_weak_rods_leave_nodes_without_rods(hard_result):
    """Where whole neighbourhoods of rod elements are deleted at once, at least one node ends with no intact
    rod element (it keeps its mass and its interfaces); the test above checks that run completed balanced."""
    f = hard_result(VERY_WEAK)
    beams = f["geometry/beam_nodes"][:]
    final = max(f["frames"].values(), key=lambda g: g.attrs["step"])
    broken = final["beam_broken"][:].astype(bool)
    n = f["geometry/node_position"].shape[0]
    intact, had = np.zeros(n, int), np.zeros(n, int)
    np.add.at(intact, beams[~broken].ravel(), 1)
    np.add.at(had, beams.ravel(), 1)
    orphaned = int(np.sum((had > 0) & (intact == 0)))
    print(f"very weak rods: {int(broken.sum())} rod elements deleted, {orphaned} nodes left without rods")
    assert broken.sum() > 10
    assert orphaned > 0
