"""Reference-solver checks that run the binary at the `ci` preset (and one at `reduced`):
theta_D = 0 gives R = 4/3 Gamma_i, half the loading rate gives the same R-curve, theta_D = 30 runs to its
stop criterion with broken rods and R rising above R_init, and result.h5 has the documented layout.
The theta_D = 0 and 30 runs are the shared ci runs (conftest.ci_run)."""
import h5py
import numpy as np
import pytest

from conftest import PAPER_CASES

R_THEORY = 4.0 / 3.0   # paper: corrugated crack faces, 4/3 of a flat crack's area per unit advance
TOL_THEORY = 0.03      # acceptance bound: R_init and R_ss within 3% of 4/3
TOL_RATE = 0.02        # acceptance bound: half the loading rate gives an R-curve within 2%
THETA0, THETA30 = "theta0_s21.4_e10_cv0", "theta30_s21.4_e10_cv0"


def run_case(run, out, case, *sets, preset="ci"):
    args = ["run", PAPER_CASES / f"{case}.toml", "--preset", preset, "--out", out, "--quiet"]
    for s in sets:
        args += ["--set", s]
    r = run(*args, timeout=900)
    assert r.returncode == 0, r.stderr
    return h5py.File(out / "result.h5", "r")


@pytest.fixture(scope="module")
def theta0(ci_run):
    return h5py.File(ci_run(THETA0), "r")


@pytest.fixture(scope="module")
def theta0_half_rate(run, tmp_path_factory, theta0):
    rate = float(theta0["meta"].attrs["v_app"]) / float(theta0["meta"].attrs["c_d_over_cr"])
    return run_case(run, tmp_path_factory.mktemp("theta0_half"), THETA0, f"v_app_over_cd={rate / 2}")


@pytest.fixture(scope="module")
def theta30(ci_run):
    return h5py.File(ci_run(THETA30), "r")


def test_theta0_gives_four_thirds(theta0):
    rc = theta0["rcurve"]
    R_init, R_ss = rc.attrs["R_init_over_Gamma"], rc.attrs["R_ss_over_Gamma"]
    print(f"theta0 ci: R_init/Gamma {R_init:.4f}  R_ss/Gamma {R_ss:.4f}  (4/3 = {R_THEORY:.4f})")
    assert abs(R_init / R_THEORY - 1) < TOL_THEORY, R_init
    assert abs(R_ss / R_THEORY - 1) < TOL_THEORY, R_ss
    assert theta0["meta"].attrs["status"] == "completed"
    assert "stop_da_over_d" in theta0["meta"].attrs["stop_reason"]
    assert int(theta0["history/broken_rod_elements"][-1]) == 0, "no rod breaks at theta_D = 0"


def test_theta0_gives_four_thirds_at_the_reduced_size_in_the_slow_limit(run, tmp_path):
    """The `reduced` specimen (40 x 20 d, Delta_a 12 d) at half and a quarter of the preset's loading rate: R falls
    as the rate falls (the excess over 4/3 is the loading's kinetic share), and the slow limit, extrapolated from
    the two as R(r/2) - (R(r) - R(r/2))/3 (the excess taken as growing with the square of the rate, the stricter
    of the linear and quadratic readings: it leaves the larger limit), is within 3% of 4/3. Measured at G = 10:
    R_ss 1.390 (+4.2%) at half, 1.373 (+3.0%) at a quarter, limit 1.368 (+2.6%); R_init 1.361, 1.347, limit
    1.342. (At G = 3 half the rate alone is within 3%: 1.365 / 1.344.) The static
    elastic start keeps each run to 1-2 min (one thread: two oversubscribed OpenMP threads spin on a busy
    machine)."""
    got = {}
    for rate in (0.5, 0.25):
        with run_case(run, tmp_path / f"rate{rate}", THETA0, f"rate_factor={rate}", "static_start=0.95",
                      "threads=1", preset="reduced") as f:
            assert f["meta"].attrs["status"] == "completed" and f["rcurve"].attrs["da_max_over_d"] >= 12
            got[rate] = (f["rcurve"].attrs["R_init_over_Gamma"], f["rcurve"].attrs["R_ss_over_Gamma"])
    for k, name in enumerate(("R_init", "R_ss")):
        fast, slow = got[0.5][k], got[0.25][k]
        limit = slow - (fast - slow) / 3
        print(f"theta0 reduced {name}: half rate {fast:.4f}, quarter rate {slow:.4f}, slow limit {limit:.4f}")
        assert slow < fast, f"{name} did not fall with the loading rate"
        assert abs(limit / R_THEORY - 1) < TOL_THEORY, (name, limit)


def test_half_rate_gives_same_rcurve(theta0, theta0_half_rate):
    da1, R1 = theta0["rcurve/da_over_d"][:], theta0["rcurve/R_over_Gamma"][:]
    da2, R2 = theta0_half_rate["rcurve/da_over_d"][:], theta0_half_rate["rcurve/R_over_Gamma"][:]
    hi = min(da1[-1], da2[-1])
    grid = np.linspace(max(da1[0], da2[0]), hi, 50)
    a, b = np.interp(grid, da1, R1), np.interp(grid, da2, R2)
    l2 = np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b ** 2))
    print(f"rate vs half rate: relative L2 difference {l2:.4f}")
    assert l2 < TOL_RATE


def test_inelastic_reach_and_the_edge_warning(theta0, theta30):
    """/history/inelastic_reach_over_d (how far from the crack plane an interface passed delta0 or a rod broke)
    never falls (both are irreversible) and stays inside the specimen; at the ci size the theta_D = 30 zone comes
    within 2 d of the loaded edges (h_s/2 = 4 d) and /meta warns; theta_D = 0 warns exactly when its zone does."""
    for f in (theta0, theta30):
        reach = f["history/inelastic_reach_over_d"][:]
        assert reach.min() >= 0 and reach.max() <= f["geometry"].attrs["h_s"] / 2
        assert np.all(np.diff(reach) >= 0), "the inelastic zone's reach fell"
    half = theta30["geometry"].attrs["h_s"] / 2
    assert theta30["history/inelastic_reach_over_d"][-1] > half - 2
    assert "inelastic zone reached" in theta30["meta"].attrs["warnings"]
    # theta_D = 0 breaks no rod, but at G = 10 its interfaces pass delta0 up to ~2.75 d from the plane (a long
    # trapezoid plateau): it warns exactly when its reach comes within 2 d of the loaded edges
    reach0 = theta0["history/inelastic_reach_over_d"][-1]
    assert ("inelastic zone reached" in theta0["meta"].attrs["warnings"]) == (reach0 > half - 2), reach0
    assert int(theta0["history/broken_rod_elements"][-1]) == 0


def test_theta30_runs_to_stop_with_broken_rods_and_a_rising_rcurve(theta30):
    # at the default G rods break at the ci size too (6 rod elements at G = 10; at G = 3 none do):
    # R rises above R_init and falls back at each break, a sawtooth, so the rise is asked of the maximum
    meta = theta30["meta"].attrs
    assert meta["status"] == "completed", meta["stop_reason"]
    broken = int(theta30["history/broken_rod_elements"][-1])
    R = theta30["rcurve/R_over_Gamma"][:]
    rc = theta30["rcurve"].attrs
    # balance error relative to the external work, once that is 1% of its final value (before, the ratio
    # of two tiny numbers says nothing)
    work = theta30["history/external_work"][:]
    err = np.abs(theta30["history/energy_balance_error"][:][work > 0.01 * work[-1]]).max()
    print(f"theta30 ci: R_init {rc['R_init_over_Gamma']:.3f}  R_end {R[-1]:.3f}  R_max {R.max():.3f}  "
          f"broken rods {broken}  max |balance error| {err:.2e}")
    assert broken > 0, "no rod broke"
    assert R.max() > 1.2 * R[0], "R never rose above R_init"
    assert err < 0.02, "energy balance within 2%"


def test_result_file_layout(theta0):
    f = theta0
    for key in ("case_toml", "preset", "solver_version", "git_hash", "integrator", "seed", "wall_time_s",
                "status", "stop_reason", "units"):
        assert key in f["meta"].attrs, key
    assert f["meta"].attrs["preset"] == "ci"
    da, R = f["rcurve/da_over_d"], f["rcurve/R_over_Gamma"]
    assert da.ndim == 1 and da.shape == R.shape and da.shape[0] > 3
    assert np.all(np.diff(da[:]) > 0)
    for name in ("time", "applied_displacement", "J_over_Gamma", "da_over_d", "kinetic_energy",
                 "strain_energy_beams", "strain_energy_interfaces", "damping_dissipation",
                 "fracture_dissipation_interfaces", "external_work", "energy_balance_error",
                 "broken_rod_elements", "failed_interfaces"):
        d = f["history"][name]
        assert d.shape == f["history/time"].shape, name
        assert "unit" in d.attrs or "normalisation" in d.attrs or "units" in d.attrs, name
    for name in ("node_position", "beam_nodes", "iface_nodes", "iface_tag", "iface_area"):
        assert name in f["geometry"], name
    assert len(f["frames"]) >= 1
    frame = f["frames"][sorted(f["frames"].keys())[0]]
    for name in ("beam_broken", "iface_damage", "node_displacement"):
        assert name in frame, name
