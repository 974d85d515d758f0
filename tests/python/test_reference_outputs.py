"""Reference outputs: re-run the reference cases at the ci preset and compare
R-curves and failure counts with tests/reference/<case>.json within the tolerances stored there
(tests/reference/make_reference.py states why each is what it is; `make reference` regenerates them).
The runs are the shared ci runs (conftest.ci_run), made as make_reference.run_case makes them."""
import json

import pytest

from enamel_results.metrics import rcurve_rel_l2
from tests.reference import make_reference


def rcurve_difference(ref, new):
    """Relative L2 difference of two R-curves over their common Delta_a range (50 points)."""
    return rcurve_rel_l2(ref["da_over_d"], ref["R_over_Gamma"], new["da_over_d"], new["R_over_Gamma"])


def compare(ref, new):
    """The quantities outside their tolerance, as messages (empty: all within)."""
    tol = ref["tolerances"]
    bad = []
    l2 = rcurve_difference(ref, new)
    if l2 > tol["rcurve_rel_l2"]:
        bad.append(f"R-curve moved: relative L2 {l2:.4f} > {tol['rcurve_rel_l2']}")
    for key, t in (("R_init_over_Gamma", "R_init_rtol"), ("R_ss_over_Gamma", "R_ss_rtol")):
        if abs(new[key] / ref[key] - 1) > tol[t]:
            bad.append(f"{key} {new[key]:.4f} vs reference {ref[key]:.4f} (rtol {tol[t]})")
    if abs(new["da_max_over_d"] - ref["da_max_over_d"]) > tol["da_max_atol"]:
        bad.append(f"da_max {new['da_max_over_d']:.3f} vs {ref['da_max_over_d']:.3f}")
    if abs(new["broken_rod_elements"] - ref["broken_rod_elements"]) > tol["broken_rods_atol"]:
        bad.append(f"broken rods {new['broken_rod_elements']} vs {ref['broken_rod_elements']}")
    if abs(new["failed_interfaces"] / max(ref["failed_interfaces"], 1) - 1) > tol["failed_interfaces_rtol"]:
        bad.append(f"failed interfaces {new['failed_interfaces']} vs {ref['failed_interfaces']}")
    return bad


@pytest.mark.parametrize("case", make_reference.CASES)
def test_reference_rcurve_within_tolerance(case, ci_run):
    ref = json.loads((make_reference.HERE / f"{case}.json").read_text())
    new = make_reference.summarise(ci_run(case))
    print(f"{case}: R_init {new['R_init_over_Gamma']:.4f} (ref {ref['R_init_over_Gamma']:.4f}), "
          f"R_ss {new['R_ss_over_Gamma']:.4f} (ref {ref['R_ss_over_Gamma']:.4f}), "
          f"broken {new['broken_rod_elements']} (ref {ref['broken_rod_elements']}), "
          f"L2 {rcurve_difference(ref, new):.2e}")
    assert new["status"] == "completed"
    assert compare(ref, new) == []


def test_comparison_catches_a_moved_rcurve():
    """The comparison itself: a reference R-curve raised by 5% (beyond the 2% tolerance) is caught."""
    ref = json.loads((make_reference.HERE / f"{make_reference.CASES[1]}.json").read_text())
    moved = dict(ref, R_over_Gamma=[r * 1.05 for r in ref["R_over_Gamma"]])
    assert any("R-curve moved" in m for m in compare(ref, moved))
    assert compare(ref, ref) == []
