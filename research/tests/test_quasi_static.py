"""research/quasi_static: the ratio is the solver's, the README's table regenerates from data/points.csv, and a
ci run's points are matched and averaged."""
import csv

import numpy as np

from research.quasi_static import points


def test_ratio_is_the_solvers_rule():
    """Elastic rows 0; past the elastic start the kinetic energy beyond the loading over the strain energy; once the
    crack has advanced the larger of that and the whole kinetic energy over it (runner.cpp quasiStaticRatio)."""
    h = {"strain_energy_beams": np.array([1.0, 1.0, 1.0, 1.0, 0.0]),
         "strain_energy_interfaces": np.array([1.0, 1.0, 1.0, 1.0, 0.0]),
         "kinetic_energy_beyond_loading": np.array([0.5, 0.2, 0.2, 0.3, 0.3]),
         "kinetic_energy": np.array([0.6, 0.4, 0.4, 0.4, 0.4]),
         "inelastic_interfaces": np.array([0, 3, 3, 3, 3]),
         "broken_rod_elements": np.array([0, 0, 0, 1, 1]),
         "da_over_d": np.array([0.0, 0.0, 0.5, 0.5, 0.5])}
    assert np.allclose(points.row_ratios(h), [0.0, 0.1, 0.2, 0.2, 0.0])
    # each R point reads the first row whose advance reached it
    assert np.allclose(points.point_ratios(h, np.array([0.3, 0.5]), points.row_ratios(h)), [0.2, 0.2])


def test_readme_table_regenerates_from_its_data():
    readme = (points.HERE / "README.md").read_text()
    for line in points.report().splitlines():
        assert line in readme, f"research/quasi_static/README.md lacks the regenerated line: {line}"
    rows = list(csv.DictReader(open(points.CSV)))
    assert len(rows) >= 20 and all(0 <= float(r["advance_warned"]) <= 1 for r in rows)


def test_a_ci_run_is_matched_and_averaged(ci_run, tmp_path):
    h5 = ci_run("theta30_s21.4_e10_cv0")
    row = points.run_row(h5)   # raises when its ratios are not the solver's /meta max_quasi_static_ratio
    assert 0 <= row["warned"] <= row["points"] > 0
    out = tmp_path / "points.csv"
    rows = points.write(h5.parent.parent, out)
    assert [r["run"] for r in rows] == ["theta30_s21.4_e10_cv0"] and "| theta30_s21.4_e10_cv0 |" in points.report(out)
