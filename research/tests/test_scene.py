"""The scene measurement (research/scene/measure_scene.py) on a
ci run of theta30 (21.4, 10): its bands are measured from the crack plane and path of that run, lie within the
specimen, grow as the crack does, and agree with a direct count from the frame; the nearest-distance helper
against a brute-force check."""
import numpy as np

from enamel_results import results
from research.scene import measure_scene

CASE = "theta30_s21.4_e10_cv0"


def test_bands_of_a_ci_run(ci_run, tmp_path):
    path = ci_run(CASE)
    r = results.load_result(path, full=True)
    rows = [measure_scene.frame_scene(r, f, 0.5) for f in r.frames]
    h_s = r.param("h_s_over_d")
    yc = r.geometry.attrs["y_crack_plane"]
    for row, f in zip(rows, r.frames):
        assert 0 < row["band_iface"] <= h_s / 2 + 1e-9
        assert row["inelastic"] == int((f.iface_state >= 1).sum())
        # the band is the farthest inelastic interface from the plane, counted directly
        y = r.geometry.iface_midpoint[f.iface_state >= 1, 1]
        assert row["band_iface"] == np.abs(y - yc).max()
        assert row["path_iface"] >= 0 and row["ahead"] >= 0
    assert rows[-1]["inelastic"] >= rows[0]["inelastic"]   # the process zone only grows
    csv = tmp_path / "scene.csv"
    assert measure_scene.main([str(path), "--csv", str(csv), "--md", str(tmp_path / "scene.md")]) == 0
    assert csv.read_text().count("\n") >= 2


def test_nearest_distance_against_brute_force():
    rng = np.random.default_rng(1)
    p, t = rng.uniform(0, 10, (300, 2)), rng.uniform(0, 10, (70, 2))
    brute = np.array([np.min(np.hypot(*(t - q).T)) for q in p])
    assert np.allclose(measure_scene.nearest_distance(p, t), brute, rtol=0, atol=1e-12)
    assert np.all(np.isinf(measure_scene.nearest_distance(p, np.empty((0, 2)))))
