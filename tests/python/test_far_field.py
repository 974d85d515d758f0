"""The reduced far field (case keys far_field_slices, full_half_height_over_d; README "Reduced far field") through
the command line: a band wider than the specimen gives the full model's run bit for bit; a run whose inelastic
zone comes within 2 d of the band's edge stops with a message saying so and keeps what it wrote; a far field
without its band is refused before anything is written. The elastic response against the full model is the C++
test FarField.ElasticResponseMatchesTheFullModel."""
import h5py
import numpy as np

from conftest import PAPER_CASES

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


def test_inelastic_zone_at_the_band_edge_stops_the_run(run, tmp_path):
    out = tmp_path / "edge"
    r = run_ci(run, out, "far_field_slices=2", "full_half_height_over_d=2.5")
    assert r.returncode == 10, r.stderr
    assert "edge of the full band" in r.stderr and "full_half_height_over_d = 2.5" in r.stderr
    with h5py.File(out / "result.failed.h5", "r") as f:
        assert f["meta"].attrs["status"] == "failed"
        assert "edge of the full band" in f["meta"].attrs["stop_reason"]
        assert f["history/inelastic_reach_over_d"][-1] > 2.5 - 2
        assert f["geometry/beam_span"][:].max() == 2
        assert f["geometry"].attrs["far_field_slices"] == 2


def test_far_field_without_its_band_is_refused(run, tmp_path):
    out = tmp_path / "bad"
    r = run_ci(run, out, "far_field_slices=4")
    assert r.returncode == 7
    assert "'full_half_height_over_d' = 0" in r.stderr and "[1, 1000]" in r.stderr
    assert not out.exists()
