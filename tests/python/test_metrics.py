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
