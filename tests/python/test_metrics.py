"""The measure of "the same R-curve" (enamel_results.metrics.same_rcurve): the level over the crack advance decides,
not where the teeth of a sawtooth fall."""
import numpy as np
import pytest

from enamel_results import metrics

DA = np.arange(0.15, 30.16, 0.3)      # one point per slice of h_e = 0.3 d, as the solver's /rcurve
PERIOD = 2.0                          # d / sin(30 deg): the paper's sawtooth period at theta_D = 30


def sawtooth(shift=0.0, level=7.0, amp=2.0, da=DA):
    """Initiation at R_init = 5, then a rising-then-dropping tooth every PERIOD (a rod break at each drop), mean
    `level`, the teeth shifted along Delta_a by `shift`."""
    phase = np.mod(da - shift, PERIOD) / PERIOD
    R = level + amp * (phase - 0.5)
    R[0] = 5.0
    return metrics.RCurve.of(da, R, rod_da=np.arange(PERIOD + shift, 30, PERIOD))


def test_advance_mean_is_the_integral_over_the_advance():
    da = np.linspace(0, 30, 7)                    # R = Delta_a: mean over (0, 30] is 15, over (10, 20] is 15
    c = metrics.RCurve.of(da, da)
    assert metrics.advance_mean(c, 0, 30) == pytest.approx(15)
    assert metrics.advance_mean(c, 10, 20) == pytest.approx(15)
    assert metrics.advance_mean(c, 0, 5) == pytest.approx(2.5)      # a window inside one segment
    uneven = metrics.RCurve.of([0, 1, 1, 4], [1, 1, 5, 5])        # a jump at Delta_a = 1 weighs nothing
    assert metrics.advance_mean(uneven, 0, 4) == pytest.approx((1 * 1 + 3 * 5) / 4)
    assert np.isnan(metrics.advance_mean(c, 31, 40))


@pytest.mark.parametrize("tol", [metrics.TOL_MESH_SIZE, metrics.TOL_RATE_SPEED])
def test_a_sawtooth_shifted_by_a_quarter_tooth_is_the_same(tol):
    a, b = sawtooth(), sawtooth(shift=PERIOD / 4)
    c = metrics.same_rcurve(a, b, tol)
    assert c.same, c
    assert c.l2 > 0.05          # while the pointwise L2 calls it different
    assert len(c.windows) == 3


def test_a_level_shifted_by_12_percent_differs_at_the_mesh_and_size_tolerance():
    a = sawtooth()
    b = metrics.RCurve.of(a.da, a.R * 1.12, a.rod_da)
    assert not metrics.same_rcurve(a, b, metrics.TOL_MESH_SIZE).same
    assert metrics.same_rcurve(a, metrics.RCurve.of(a.da, a.R * 1.08, a.rod_da), metrics.TOL_MESH_SIZE).same


def test_a_level_shifted_by_3_percent_differs_at_the_rate_tolerance():
    a = sawtooth()
    b = metrics.RCurve.of(a.da, a.R * 1.03, a.rod_da)
    c = metrics.same_rcurve(a, b, metrics.TOL_RATE_SPEED)
    assert not c.same and c.mean_rel == pytest.approx(0.03)


def test_R_init_decides_too():
    a = sawtooth()
    R = a.R.copy()
    R[0] *= 1.2
    assert not metrics.same_rcurve(a, metrics.RCurve.of(a.da, R, a.rod_da), metrics.TOL_MESH_SIZE).same


def test_broken_rods_within_20_percent_or_two():
    a = sawtooth()                                    # 14 breaks by 30 d
    n = len(a.rod_da)
    assert metrics.same_rcurve(a, metrics.RCurve.of(a.da, a.R, a.rod_da[:n - 2]), 0.1).same
    few = metrics.RCurve.of(a.da, a.R, a.rod_da[:n - 4])            # 4 of 14 fewer: beyond 20% and 2
    c = metrics.same_rcurve(a, few, 0.1)
    assert not c.rods_ok and not c.same
    only_total = metrics.RCurve.of(a.da, a.R, broken_rods=n)         # a record with the total only
    assert metrics.same_rcurve(a, only_total, 0.1).same


def test_a_run_that_stopped_early_is_compared_over_the_common_range_or_not_at_all():
    a = sawtooth()
    short = sawtooth(da=DA[DA <= 15])
    c = metrics.same_rcurve(a, short, 0.1)
    assert c.comparable and c.hi == pytest.approx(short.da[-1]) and c.same
    tiny = sawtooth(da=DA[DA <= 6])
    c = metrics.same_rcurve(a, tiny, 0.1)
    assert not c.comparable and not c.same


# --- Between two settings: paired over the phases (metrics.paired_phase_comparison) -----------------------------

def phases_of(n=4):
    """One configuration per phase: the teeth shifted by k/n of a period, the level moving with the phase."""
    return [sawtooth(shift=k * PERIOD / n, level=7.0 + 0.3 * k) for k in range(n)]


def scaled(curves, factors):
    return [metrics.RCurve.of(c.da, c.R * f, c.rod_da) for c, f in zip(curves, factors)]


def test_paired_identical_settings_are_the_same():
    a = phases_of()
    p = metrics.paired_phase_comparison(a, phases_of(), metrics.TOL_RATE_SPEED)
    assert p.same and p.comparable
    assert p.level.mean == 0 and p.level.se == 0 and p.init.mean == 0
    assert p.mean_a == pytest.approx(np.mean([metrics.advance_mean(c, 0, 30) for c in a]))
    assert p.hi == pytest.approx([30.0] * 4)


def test_paired_constant_5_percent_shift_differs():
    a = phases_of()
    p = metrics.paired_phase_comparison(a, scaled(a, [1.05] * 4), metrics.TOL_RATE_SPEED)
    assert not p.same and not p.level.same and not p.init.same
    assert p.level.each == pytest.approx([0.05] * 4) and p.level.mean == pytest.approx(0.05)
    assert p.mean_b == pytest.approx(1.05 * p.mean_a)


def test_paired_1_percent_shift_within_a_large_scatter_is_not_shown_the_same():
    """Phases whose own differences scatter by +-4 %: d = +1 % with 2 SE ~ 3.8 % is not pinned within 2 %, so not
    shown the same, while one of the single configurations alone would say the same."""
    a = phases_of()
    each = [0.05, -0.03, 0.035, -0.015]
    p = metrics.paired_phase_comparison(a, scaled(a, [1 + e for e in each]), metrics.TOL_RATE_SPEED)
    assert p.level.mean == pytest.approx(0.01) and p.level.se == pytest.approx(np.std(each, ddof=1) / 2)
    assert (p.level.low, p.level.high) == pytest.approx((-0.03, 0.05))
    assert abs(p.level.mean) <= p.tol < abs(p.level.mean) + 2 * p.level.se
    assert not p.level.same and not p.same
    assert [s.same for s in p.singles] == [False, False, False, True]


def test_paired_1_percent_shift_with_tiny_scatter_is_the_same():
    """d = +1 % on which the phases agree to 0.1 %: the difference with twice its standard error is within 2 %, so the
    same, though significant; a consistent 1.9 % shift is not (its 2 SE takes it past 2 %)."""
    a = phases_of()
    each = [0.011, 0.009, 0.0105, 0.0095]
    p = metrics.paired_phase_comparison(a, scaled(a, [1 + e for e in each]), metrics.TOL_RATE_SPEED)
    assert abs(p.level.mean) > 2 * p.level.se and abs(p.level.mean) + 2 * p.level.se <= p.tol
    assert p.level.same and p.same
    assert all(s.same for s in p.singles)
    near = [0.022, 0.017, 0.021, 0.018]
    q = metrics.paired_phase_comparison(a, scaled(a, [1 + e for e in near]), metrics.TOL_RATE_SPEED)
    assert abs(q.level.mean) <= q.tol and not q.level.same


def test_paired_needs_two_pairs_of_equal_lists_and_comparable_ranges():
    a = phases_of()
    with pytest.raises(ValueError, match="as many"):
        metrics.paired_phase_comparison(a, a[:3], 0.1)
    with pytest.raises(ValueError, match="at least 2"):
        metrics.paired_phase_comparison(a[:1], a[:1], 0.1)
    short = [a[0], sawtooth(da=DA[DA <= 6]), a[2], a[3]]
    p = metrics.paired_phase_comparison(a, short, 0.1)
    assert not p.comparable and not p.same
