"""The reduced far field (case keys far_field_slices, full_half_height_over_d; docs/solver.md, "Reduced far field") through
the command line: a band wider than the specimen gives the full model's run bit for bit; a run whose inelastic
zone comes within 2 d of the band's edge stops with a message saying so and keeps what it wrote; a far field
without its band is refused before anything is written. The elastic response against the full model is the C++
test FarField.ElasticResponseMatchesTheFullModel."""
import h5py
import numpy as np

from conftest import PAPER_CASES, run_with_kills
from enamel_results.constants import EXIT

CASE = "theta30_s21.4_e10_cv0"


def run_ci(run, out, *sets):
    args = ["run", PAPER_CASES / f"{CASE}.toml", "--preset", "ci", "--out", out, "--quiet"]
    for s in sets:
        args += ["--set", s]
    return run(*args, timeout=900)


def test_wide_band_is_the_full_run(run, ci_run, tmp_path):
    r = run_ci(run, tmp_path / "wide", "far_field_slices=4", "full_half_height_over_d=100")
    assert r.returncode == 0, r.stderr
    with h5py.File(ci_run(CASE), "r") as full, h5py.File(tmp_path / "wide" / "result.h5", "r") as wide:
        for name in ("rcurve/R_over_Gamma", "rcurve/da_over_d", "history/applied_displacement"):
            assert np.array_equal(full[name][:], wide[name][:]), name
        assert np.all(wide["geometry/beam_span"][:] == 1)


def test_theta0_with_a_far_field_gives_four_thirds_and_restarts_bit_for_bit(run, enamel, tmp_path):
    """theta_D = 0 at ci (its crack stays within a rod of the plane) with a node every 4 slices beyond 2.5 d of the
    plane (3/8 of the height full): R_init and R_ss within 3% of the theory's 4/3, as the full model; and the run
    killed twice (SIGKILL between checkpoints) and restarted ends equal to the uninterrupted one, bit for bit."""
    # at G = 3 (4/3 holds at any G): the ci specimen's inelastic zone stays within 0.5 d of the plane, so a band
    # of 2.5 d leaves room for its 2 d guard; at the default G = 10 it reaches 1.25 d and the guard stops the run
    sets = ["far_field_slices=4", "full_half_height_over_d=2.5", "Gamma_k_over_sigma0sq=3"]
    case = PAPER_CASES / "theta0_s21.4_e10_cv0.toml"
    r = run("run", case, "--preset", "ci", "--out", tmp_path / "a", "--quiet", *sum((["--set", s] for s in sets), []))
    assert r.returncode == 0, r.stderr
    args = lambda extra: ["run", case, "--preset", "ci", "--out", tmp_path / "b", "--quiet",
                          *sum((["--set", s] for s in sets), []), *extra]
    assert run_with_kills(enamel, tmp_path / "b", args, [0.3, 0.3]) == 2
    with h5py.File(tmp_path / "a" / "result.h5", "r") as a, h5py.File(tmp_path / "b" / "result.h5", "r") as b:
        assert a["geometry/beam_span"][:].max() == 4
        rc = a["rcurve"].attrs
        for key in ("R_init_over_Gamma", "R_ss_over_Gamma"):
            assert abs(rc[key] / (4 / 3) - 1) < 0.03, (key, rc[key])
        for name in ("rcurve/R_over_Gamma", "history/applied_displacement", "history/external_work"):
            assert np.array_equal(a[name][:], b[name][:]), name


def test_inelastic_zone_at_the_band_edge_stops_the_run(run, tmp_path):
    out = tmp_path / "edge"
    r = run_ci(run, out, "far_field_slices=2", "full_half_height_over_d=2.5")
    assert r.returncode == EXIT["run_unstable"], r.stderr
    assert "edge of the full band" in r.stderr and "full_half_height_over_d = 2.5" in r.stderr
    with h5py.File(out / "result.failed.h5", "r") as f:
        assert f["meta"].attrs["status"] == "failed"
        assert "edge of the full band" in f["meta"].attrs["stop_reason"]
        assert f["history/inelastic_reach_over_d"][-1] > 2.5 - 2
        assert f["geometry/beam_span"][:].max() == 2
        assert f["geometry"].attrs["far_field_slices"] == 2


def test_far_field_rod_breaks_allowed_are_recorded_and_interfaces_still_stop(run, tmp_path):
    """far_field_rod_breaks = allow: a rod element broken near the band's edge (weak rods: mean strength 8 sigma0,
    cv 0.5) is a warning in /meta instead of the stop, and the run goes on until the interfaces past delta0 come
    near the edge, which still stops it; the default (stop) stops at the rod break."""
    sets = ["sigma_ru_over_sigma0=8", "cv=0.5", "far_field_slices=2", "full_half_height_over_d=3.5"]
    stop, allow = tmp_path / "stop", tmp_path / "allow"
    r = run_ci(run, stop, *sets)
    assert r.returncode == EXIT["run_unstable"] and "inelastic zone reached" in r.stderr, r.stderr
    r = run_ci(run, allow, *sets, 'far_field_rod_breaks="allow"')
    assert r.returncode == EXIT["run_unstable"] and "interfaces past delta0 reached" in r.stderr, r.stderr
    with h5py.File(stop / "result.failed.h5", "r") as fs, h5py.File(allow / "result.failed.h5", "r") as fa:
        assert "a rod element broke" not in fs["meta"].attrs["warnings"]
        assert "a rod element broke" in fa["meta"].attrs["warnings"] and "far_field_rod_breaks = allow" in fa["meta"].attrs["warnings"]
        assert fa["meta"].attrs["steps"] > fs["meta"].attrs["steps"]
        assert fa["history/broken_rod_elements"][-1] > fs["history/broken_rod_elements"][-1] > 0
        reach = fa["history/inelastic_reach_over_d"][:]  # rods included: past the limit rows before the stop
        assert (reach > 3.5 - 2).any() and np.argmax(reach > 3.5 - 2) < len(reach) - 1


def test_far_field_without_its_band_is_refused(run, tmp_path):
    out = tmp_path / "bad"
    r = run_ci(run, out, "far_field_slices=4")
    assert r.returncode == EXIT["out_of_range"]
    assert "'full_half_height_over_d' = 0" in r.stderr and "[1, 1000]" in r.stderr
    assert not out.exists()
