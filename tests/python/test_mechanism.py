"""The measures of the fracture mechanism (enamel_results.mechanism) on crafted R-curves and frames whose answers
are known: a rise to a plateau at a given crack advance, a zone of given size, a kink of given length in each
ply."""
import math

import numpy as np
import pytest

from enamel_results import mechanism as m
from enamel_results.metrics import RCurve, advance_mean
from enamel_results.results import TAG_INTER12, TAG_PLY1, TAG_PLY2, Frame, Geometry

H_E = 0.3
THETA = 30.0
SLOPE = math.tan(math.radians(THETA))
S = 1.0 / math.cos(math.radians(THETA))     # the gaps' spacing along y in one slice
YC = 20.0                                   # the crack plane
A0 = 10.0                                   # a0_effective
NSLICES = 120                               # x from 0 to 35.7 d
GAPS = range(-8, 9)                         # gap lines c_j = YC - S/2 + j S - slope x_ref per ply


# ------------------------------------------------------------------------------------------ R-curves
def test_rise_length_of_a_linear_rise_to_a_plateau():
    """R rises linearly from 1 at Delta_a 0 to 10 at 4 d, then stays: the (5, 25] level is 10, and 0.9 x 10 is
    reached where 1 + 9 Delta_a / 4 = 9, at 32/9 d."""
    da = np.linspace(0, 30, 301)
    R = np.minimum(1 + 9 * da / 4, 10)
    c = RCurve.of(da, R)
    assert advance_mean(c, 5, 25) == pytest.approx(10)
    assert m.rise_length(c) == pytest.approx(32 / 9, abs=1e-9)
    assert m.rise_length(c, frac=0.5) == pytest.approx(4 * 4 / 9, abs=1e-9)   # 1 + 9 x / 4 = 5


def test_rise_length_of_a_step_is_the_step():
    """R = 2 up to 6 d, then 8 (two points at 6 d): the level (1 x 2 + 19 x 8) / 20 = 7.7, reached at the step."""
    da = np.concatenate((np.linspace(0.5, 6, 12), np.linspace(6, 30, 49)))
    R = np.where(np.arange(da.size) < 12, 2.0, 8.0)
    c = RCurve.of(da, R)
    assert advance_mean(c, 5, 25) == pytest.approx(7.7)
    assert m.rise_length(c) == pytest.approx(6.0)


def test_rise_length_nan_when_the_curve_is_too_short_or_never_gets_there():
    assert math.isnan(m.rise_length(RCurve.of(np.linspace(0, 20, 41), np.linspace(1, 5, 41))))   # ends at 20 d
    assert math.isnan(m.rise_length(RCurve.of(np.linspace(6, 30, 41), np.full(41, 3.0))))       # starts at 6 d
    assert math.isnan(m.rise_length(RCurve.of(np.linspace(0, 30, 41), np.full(41, 3.0)), frac=1.5))
    falling = RCurve.of(np.linspace(0.2, 30, 41), np.linspace(9, 3, 41))   # already above 0.9 x level at its start
    assert m.rise_length(falling) == pytest.approx(0.2)


def test_interface_advance_is_the_advance_before_the_first_rod():
    c = RCurve.of([0.3, 0.9, 1.5, 2.1, 2.4, 5.0], [1, 2, 3, 4, 3, 5])
    assert m.interface_advance(c, 2.1) == pytest.approx(1.5)
    assert m.interface_advance(c, 0.0) == 0.0                  # a rod broke before the crack advanced
    assert m.interface_advance(c, math.nan) == pytest.approx(5.0)   # no rod broke


# ------------------------------------------------------------------------------------------ a crafted specimen
def ply_interfaces(tag):
    """Every interface of one ply: one per gap line and slice, on y = c_j + slope x (ply 2: the slope negated)."""
    slope = SLOPE if tag == TAG_PLY1 else -SLOPE
    k = np.repeat(np.arange(NSLICES), len(GAPS))
    j = np.tile(np.array(GAPS), NSLICES)
    x = k * H_E
    y = YC - S / 2 + j * S + slope * (x - A0)      # gap j = 0 straddles the plane at the tip's x
    return k, x, y


def specimen(rods=()):
    """A Geometry of ply 1, ply 2 and a row of interlayer interfaces on the crack plane, and its all-elastic Frame
    at Delta_a = 0; `rods`: (x0, y0, x1, y1) of rod elements, all broken."""
    ks, xs, ys, tags = [], [], [], []
    for tag in (TAG_PLY1, TAG_PLY2):
        k, x, y = ply_interfaces(tag)
        ks.append(k), xs.append(x), ys.append(y), tags.append(np.full(k.size, tag))
    k = np.arange(NSLICES)
    ks.append(k), xs.append(k * H_E), ys.append(np.full(k.size, YC + 0.1)), tags.append(np.full(k.size, TAG_INTER12))
    mid = np.zeros((sum(a.size for a in ks), 3))
    mid[:, 0], mid[:, 1] = np.concatenate(xs), np.concatenate(ys)
    X = np.zeros((2 * len(rods), 3))
    if rods:
        X[:, :2] = np.asarray(rods, dtype=float).reshape(-1, 2)
    attrs = dict(a0_effective=A0, y_crack_plane=YC, h_e=H_E, theta_D_deg=THETA, w_s=NSLICES * H_E, h_s=2 * YC)
    g = Geometry(node_position=X, node_ply=np.zeros(X.shape[0], dtype=np.int32),
                 beam_nodes=np.arange(X.shape[0]).reshape(-1, 2), beam_strength=None, iface_nodes=None,
                 iface_tag=np.concatenate(tags), iface_midpoint=mid, iface_zshift=None, iface_area=None,
                 iface_slice=np.concatenate(ks), attrs=attrs)
    f = Frame(index=0, target_da=15.0, da=0.0, step=0, iface_state=np.zeros(mid.shape[0], dtype=np.uint8),
              iface_damage=None, beam_broken=np.ones(len(rods), dtype=np.uint8), node_displacement=None,
              beam_stress=None)
    return g, f


def on_gap(g, tag, j, k_from, k_to):
    """Indices of the interfaces of ply `tag` on gap j in slices k_from..k_to."""
    base = 0 if tag == TAG_PLY1 else NSLICES * len(GAPS)
    return [base + k * len(GAPS) + (j - GAPS[0]) for k in range(k_from, k_to + 1)]


def set_state(f, idx, state):
    f.iface_state[np.asarray(idx)] = state


# ------------------------------------------------------------------------------------------ the inelastic zone
def test_inelastic_zone_of_a_known_rectangle():
    g, f = specimen()
    x, y = g.iface_midpoint[:, 0], g.iface_midpoint[:, 1]
    tip = A0 + 6.0
    inside = (np.abs(y - YC) <= 2.5) & (x >= tip - 3.0) & (x <= tip + 4.0)
    set_state(f, np.flatnonzero(inside), m.INELASTIC)
    f.da = 6.0
    z = m.inelastic_zone(f, g)
    assert z.count == int(inside.sum()) > 0
    assert z.height == pytest.approx(np.abs(y[inside] - YC).max())
    assert 2.0 < z.height <= 2.5
    assert z.ahead == pytest.approx(x[inside].max() - tip)
    assert 3.7 < z.ahead <= 4.0
    assert z.x_min == pytest.approx(x[inside].min())
    edge = np.flatnonzero((x > g.attrs["w_s"] - 1.0) & (np.abs(y - YC) < 1))[0]   # one softened at the right edge
    set_state(f, [edge], m.INELASTIC)
    assert m.inelastic_zone(f, g).ahead == pytest.approx(x[edge] - tip)
    with_margin = m.inelastic_zone(f, g, margin=2.0)
    assert with_margin == z
    only_plies = m.inelastic_zone(f, g, margin=2.0, tags=(TAG_PLY1, TAG_PLY2))
    assert only_plies.count == int((inside & (g.iface_tag != TAG_INTER12)).sum()) < z.count


def test_inelastic_zone_empty_and_behind_the_tip():
    g, f = specimen()
    empty = m.inelastic_zone(f, g)
    assert (empty.count, empty.height, empty.ahead) == (0, 0.0, 0.0) and math.isnan(empty.x_min)
    set_state(f, on_gap(g, TAG_PLY1, 0, 10, 12), m.FAILED)
    z = m.inelastic_zone(f, g, tip_x=20.0)
    assert z.count == 3 and z.ahead == 0.0


# ------------------------------------------------------------------------------------------ kinks
def kinked_frame():
    """A ply-1 kink of 7 failed interfaces along gap 0 (slices 34-40: 2.1 d) with 4 softened ones ahead on its gap
    (1.2 d), a ply-2 kink of 4 (slices 37-40: 1.2 d); distractors: an old ply-1 run 8 d behind, a ply-1 run on a
    gap 7 d off the plane ending at the tip's x, and a ply-2 run ahead of the tip (a daughter crack)."""
    g, f = specimen()
    set_state(f, on_gap(g, TAG_PLY1, 0, 34, 40), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY1, 0, 41, 44), m.INELASTIC)
    set_state(f, on_gap(g, TAG_PLY2, 0, 37, 40), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY1, -1, 5, 10), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY1, 6, 30, 40), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY2, 1, 50, 55), m.FAILED)
    f.da = 40 * H_E - A0
    return g, f


def test_kinks_have_their_known_lengths_in_each_ply():
    g, f = kinked_frame()
    tip = m.crack_tip_x(f, g)
    assert tip == pytest.approx(40 * H_E)
    k = m.kinks(f, g, tip)
    k1, k2 = k[TAG_PLY1], k[TAG_PLY2]
    assert (k1.count, k2.count) == (7, 4)
    assert k1.length == pytest.approx(2.1) and k2.length == pytest.approx(1.2)
    assert k1.x_start == pytest.approx(34 * H_E) and k1.x_end == pytest.approx(tip)
    assert k1.offset_end - k1.offset_start == pytest.approx(6 * H_E * SLOPE)    # ply 1 rises along +theta
    assert k2.offset_end - k2.offset_start == pytest.approx(-3 * H_E * SLOPE)   # ply 2 falls along -theta
    assert k1.softened_ahead == pytest.approx(4 * H_E)
    assert k2.softened_ahead == 0.0
    assert k2.length < 1 / math.sin(math.radians(THETA))    # resolved below one crisscross spacing (2 d)


def test_no_kink_where_the_ply_has_no_failed_run_near_the_tip():
    g, f = specimen()
    set_state(f, on_gap(g, TAG_PLY1, 0, 34, 40), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY2, 0, 30, 36), m.FAILED)     # ends 1.2 d behind the tip
    k = m.kinks(f, g, 40 * H_E)
    assert k[TAG_PLY1].count == 7 and k[TAG_PLY2].count == 7
    k = m.kinks(f, g, 40 * H_E, reach=1.0)
    assert k[TAG_PLY1].count == 7
    assert k[TAG_PLY2].count == 0 and math.isnan(k[TAG_PLY2].length)


def test_gap_runs_split_at_a_missing_slice_and_give_the_period():
    g, f = specimen()
    for start in (10, 17, 24, 31):                          # a sawtooth: a run every 7 slices (2.1 d)
        set_state(f, on_gap(g, TAG_PLY1, start // 7, start, start + 5), m.FAILED)
    set_state(f, on_gap(g, TAG_PLY1, 0, 40, 42) + on_gap(g, TAG_PLY1, 0, 44, 45), m.FAILED)
    runs = m.gap_runs(f, g, TAG_PLY1)
    assert [r.count for r in runs] == [6, 6, 6, 6, 3, 2]
    assert m.run_period(runs[:4], H_E) == pytest.approx(7 * H_E)
    assert math.isnan(m.run_period(runs[:1], H_E))
    f.da = 45 * H_E - A0
    assert m.path_runs_per_d(f, g) == pytest.approx((6 + 0) / 2 / (45 * H_E - A0))


# ------------------------------------------------------------------------------------------ offsets, far rods
def test_crack_offset_tells_a_symmetric_crack_from_a_one_sided_one():
    g, f = specimen()
    set_state(f, on_gap(g, TAG_PLY1, 0, 34, 40) + on_gap(g, TAG_PLY2, 1, 34, 40), m.FAILED)   # mirror images
    sym = m.crack_offset(f, g)
    assert sym.count == 14 and abs(sym.mean) < 1e-9
    set_state(f, on_gap(g, TAG_PLY1, -5, 41, 50) + on_gap(g, TAG_PLY2, -5, 41, 50), m.FAILED)
    one_sided = m.crack_offset(f, g)
    assert one_sided.mean < -2.0 and one_sided.max_abs > 4.0
    g, f = specimen()
    assert m.crack_offset(f, g).count == 0 and math.isnan(m.crack_offset(f, g).mean)


def test_far_rod_breaks_count_the_rods_away_from_the_crack_line():
    rods = [(14.0, 20.2, 14.3, 20.3),      # on the plane, behind the tip
            (15.0, 27.0, 15.3, 27.2),      # 7 d off the plane
            (18.5, 20.0, 18.8, 20.1),      # 2.65 d ahead of the tip at 16 d
            (23.0, 21.0, 23.3, 21.0)]      # 7.15 d ahead
    g, f = specimen(rods)
    assert m.far_rod_breaks(f, g, tip_x=16.0, distance=5.0) == 2
    assert m.far_rod_breaks(f, g, tip_x=16.0, distance=2.0) == 3
    f.beam_broken[:] = 0
    assert m.far_rod_breaks(f, g, tip_x=16.0, distance=2.0) == 0
