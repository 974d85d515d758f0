"""Every figure title and summary table says whether its runs are size-converged (enamel_results.results):
only specimens at the size reference (200 x 200 d, the paper's), at h_e 0.3 d or finer, at the default G and tip
reading, are; 80 x 80 d (the converged preset) is not shown to give its R-curve."""
import types

from enamel_results.results import CONVERGED_G, CONVERGED_TIP, convergence_label, size_converged


def run(w, h, h_e=0.3, G=CONVERGED_G, tip=CONVERGED_TIP):
    params = {"w_s_over_d": w, "h_s_over_d": h, "h_e_over_d": h_e, "Gamma_k_over_sigma0sq": G}
    return types.SimpleNamespace(params=params if tip is None else dict(params, crisscross_at_tip=tip))


def test_only_large_square_fine_enough_runs_at_the_shown_G_are_converged():
    assert size_converged(run(200, 200)) and size_converged(run(200, 200, 0.15))
    assert not size_converged(run(80, 80)) and not size_converged(run(100, 100))   # 12 and 10 % below 200 d
    assert not size_converged(run(40, 20))          # the reduced preset: shorter than the inelastic zone
    assert not size_converged(run(200, 40))         # wide but not tall
    assert not size_converged(run(80, 80, h_e=0.6))
    assert not size_converged(run(200, 200, G=3))   # a G other than the default's
    assert not size_converged(run(200, 200, tip="intact"))   # the other tip reading
    assert not size_converged(run(200, 200, tip=None))       # a run without the key: its tip was intact


def test_the_label_names_the_sizes_and_G_when_any_run_is_not_converged():
    assert convergence_label([run(200, 200), run(200, 200, 0.15)]) == "size-converged"
    assert convergence_label([run(80, 80)]).startswith("NOT size-converged (80 x 80 d")
    text = convergence_label([run(16, 8), run(200, 200)])
    assert text.startswith("NOT size-converged") and "16 x 8 d" in text and f"G = {CONVERGED_G:g}" in text
    assert "G = 3" in convergence_label([run(200, 200, G=3)])
