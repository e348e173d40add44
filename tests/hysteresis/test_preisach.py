"""Preisach model: grid reproduction, interpolation (Eqs. 4-5), memory properties, inverse (Eqs. 6-7)."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_budget import examples

from clutchlab.errors import DataError, ParameterError
from clutchlab.hysteresis import Preisach, PreisachState, forc_table_from_masses

GRID = np.linspace(0.0, 4.5, 10)


def random_table(seed, grid=GRID, offset=0.0):
    rng = np.random.default_rng(seed)
    n = grid.size - 1
    return forc_table_from_masses(grid, rng.random((n, n)) * 20.0, rng.random(n) * 30.0, offset)


def model(seed=1, grid=GRID):
    return Preisach(grid, random_table(seed, grid))


def brute_force_P(grid, cell, line, i, j):
    """Relay mass of the triangle b <= beta <= alpha <= a by direct summation."""
    s = 0.0
    for p in range(j, i):
        s += line[p]
        for q in range(j, p):
            s += cell[p, q]
    return s


def test_table_from_masses_matches_direct_sum():
    rng = np.random.default_rng(3)
    n = GRID.size - 1
    cell, line = rng.random((n, n)), rng.random(n)
    F = forc_table_from_masses(GRID, cell, line, offset=2.0)
    for i in range(GRID.size):
        for j in range(i + 1):
            expect = 2.0 + brute_force_P(GRID, cell, line, i, 0) - brute_force_P(GRID, cell, line, i, j)
            assert F[i, j] == pytest.approx(expect, abs=1e-12)


@pytest.mark.parametrize("grid", [GRID, np.array([0.0, 0.3, 1.0, 1.2, 2.5, 4.5])])
@pytest.mark.parametrize("remanence", [False, True])
def test_grid_points_reproduced_exactly(grid, remanence):
    """F(alpha, beta) is the output after rising to alpha and falling to beta (any grid, with remanence)."""
    F = random_table(5, grid)
    if remanence:  # a measured table may keep force at the lowest current after a reversal
        F = F + np.tril(np.outer(np.linspace(0, 7.0, grid.size), np.ones(grid.size)))
    m = Preisach(grid, F)
    for i in range(grid.size):
        for j in range(i + 1):
            u = np.concatenate([np.linspace(grid[0], grid[i], 5), np.linspace(grid[i], grid[j], 4)[1:]])
            assert m.simulate(u)[-1] == pytest.approx(F[i, j], abs=1e-10)


def test_from_forc_table_long_format_roundtrip():
    F = random_table(2)
    i, j = np.tril_indices(GRID.size)
    m = Preisach.from_forc_table(GRID[i], GRID[j], F[i, j])
    np.testing.assert_allclose(m.tables[0], F, atol=0)


def test_interpolation_square_cell_bilinear_eq4():
    F = random_table(4)
    m = Preisach(GRID, F)
    a, b = 3.2, 1.3  # alpha in cell 5 [2.5, 3.0]? no: [3.0, 3.5] -> i = 6; beta in [1.0, 1.5] -> j = 2
    i, j = 6, 2
    s = (a - GRID[i]) / 0.5
    t = (b - GRID[j]) / 0.5
    expect = (F[i, j] * (1 - s) * (1 - t) + F[i + 1, j] * s * (1 - t) + F[i, j + 1] * (1 - s) * t
              + F[i + 1, j + 1] * s * t)
    out = m.simulate([0.0, a, b])
    assert out[-1] == pytest.approx(expect, rel=1e-12)
    # the same value from C0 + C1 a + C2 b + C3 a b fitted to the four vertices (Eq. 4)
    A = np.array([[1, x, y, x * y] for x, y in [(GRID[i], GRID[j]), (GRID[i + 1], GRID[j]),
                                                 (GRID[i], GRID[j + 1]), (GRID[i + 1], GRID[j + 1])]])
    c = np.linalg.solve(A, [F[i, j], F[i + 1, j], F[i, j + 1], F[i + 1, j + 1]])
    assert out[-1] == pytest.approx(c @ [1, a, b, a * b], rel=1e-12)


def test_interpolation_triangular_cell_linear_eq5():
    F = random_table(6)
    m = Preisach(GRID, F)
    a, b = 2.4, 2.15  # both in cell [2.0, 2.5], b <= a
    k = 4
    verts = [(GRID[k], GRID[k]), (GRID[k + 1], GRID[k + 1]), (GRID[k + 1], GRID[k])]
    A = np.array([[1, x, y] for x, y in verts])
    c = np.linalg.solve(A, [F[k, k], F[k + 1, k + 1], F[k + 1, k]])
    assert m.simulate([0.0, a, b])[-1] == pytest.approx(c @ [1, a, b], rel=1e-12)
    assert m.simulate([0.0, a])[-1] == pytest.approx(c @ [1, a, a], rel=1e-12)


# ------------------------------------------------------------------ hypothesis properties
inputs = st.lists(st.floats(0.0, 4.5, allow_nan=False), min_size=1, max_size=25)


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 50), history=inputs, top=st.floats(0.0, 4.5), tail=inputs)
def test_wiping_out(seed, history, top, tail):
    """An input above every past value erases the memory: the history no longer matters."""
    top = max(top, max(history))
    m = model(seed)
    a = m.simulate(history + [top] + tail)[-len(tail):]
    b = m.simulate([top] + tail)[-len(tail):]
    np.testing.assert_allclose(a, b, atol=1e-9)


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 50), history=inputs, excursion=inputs, tail=inputs)
def test_return_point_memory(seed, history, excursion, tail):
    """A closed excursion from the last reversal point leaves no trace (return-point memory).

    The excursion starts at the present input x, moves against the direction
    of arrival without passing the last stored extremum and returns to x.
    """
    m = model(seed)
    x = history[-1]
    m.simulate(history)
    ext = m.state.extrema
    if ext.size % 2 == 0:  # arrived rising: excursion between the last minimum and x
        lo, hi = (ext[-1] if ext.size else 0.0), x
    else:  # arrived falling: excursion between x and the last maximum
        lo, hi = x, ext[-1]
    exc = list(np.clip(excursion, lo, hi)) + [x]
    a = m.simulate(history + exc + tail)
    b = m.simulate(history + tail)
    assert a[len(history) + len(exc) - 1] == pytest.approx(b[len(history) - 1], abs=1e-9)
    np.testing.assert_allclose(a[-len(tail):], b[-len(tail):], atol=1e-9)


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 50), h1=inputs, h2=inputs, ua=st.floats(0.0, 4.0), width=st.floats(0.05, 2.0),
       n=st.integers(2, 12))
def test_congruency_of_minor_loops(seed, h1, h2, ua, width, n):
    """Minor loops between the same input extrema have the same shape whatever the history."""
    ub = min(ua + width, 4.5)
    m = model(seed)
    loop = list(np.linspace(ua, ub, n)) + list(np.linspace(ub, ua, n))[1:]
    out = []
    for h in (h1, h2):
        top = max(max(h), ub) + 0.0
        seq = h + [top, ua] + loop
        y = m.simulate(seq)[-len(loop) - 1:]
        out.append(y - y[0])
    np.testing.assert_allclose(out[0], out[1], atol=1e-9)


@settings(max_examples=examples(60), deadline=None)
@given(seed=st.integers(0, 50), u=st.lists(st.floats(0.0, 4.5), min_size=1, max_size=60))
def test_output_within_major_loop(seed, u):
    m = model(seed)
    y = m.simulate(u)
    low = m.forc(u, u)  # limiting ascending branch
    high = m.forc(np.full(len(u), 4.5), u)  # limiting descending branch
    assert np.all(y >= low - 1e-9)
    assert np.all(y <= high + 1e-9)


@settings(max_examples=examples(40), deadline=None)
@given(seed=st.integers(0, 50), u=st.lists(st.floats(0.0, 4.5), min_size=1, max_size=60))
def test_invert_simulate_identity(seed, u):
    m = model(seed)
    target = m.simulate(u)
    inv = m.invert(target)
    assert inv.all_feasible
    np.testing.assert_allclose(inv.output, target, atol=1e-8)
    np.testing.assert_allclose(m.simulate(inv.input), target, atol=1e-8)


def test_invert_recovers_input_for_strictly_increasing_model():
    m = model(7)
    u = np.clip(np.cumsum(np.random.default_rng(1).normal(0, 0.3, 300)), 0, 4.5)
    inv = m.invert(m.simulate(u))
    np.testing.assert_allclose(inv.input, u, atol=1e-9)


def test_invert_reports_infeasible_targets():
    m = model(8)
    top = m.forc(4.5, 4.5)
    inv = m.invert([0.5 * top, 1.2 * top, 0.4 * top, -5.0])
    np.testing.assert_array_equal(inv.feasible, [True, False, True, False])
    assert inv.input[1] == 4.5 and inv.output[1] == pytest.approx(top)
    assert inv.input[3] == 0.0
    assert inv.reachable_high[1] == pytest.approx(top)
    rep = inv.report()
    assert "2 of 4" in rep and "sample 1" in rep and "sample 3" in rep


# ------------------------------------------------------------------ state
def test_step_continues_and_state_restores():
    m = model(9)
    u = np.random.default_rng(2).uniform(0, 4.5, 200)
    full = m.simulate(u)
    m.simulate(u[:120])
    st_mid = m.state
    np.testing.assert_allclose(m.step(u[120:]), full[120:], atol=1e-12)
    m.reset()
    m.state = st_mid
    assert m.step(float(u[120])) == pytest.approx(full[120], abs=1e-12)
    with pytest.raises(ParameterError, match="alternating"):
        m.state = PreisachState(np.array([1.0, 2.0]), 1.5)


def test_long_decaying_oscillation_grows_memory():
    m = model(10)
    k = np.arange(4000)
    u = 2.25 + 2.25 * np.cos(np.pi * k) * np.exp(-k / 2000)
    y = m.simulate(u)
    assert m.state.extrema.size > 100  # the stack grew beyond its initial capacity
    assert np.all(np.isfinite(y))


# ------------------------------------------------------------------ airgap family
def test_airgap_quadratic_interpolation_exact_for_quadratic_tables():
    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0]) * 1e-3
    A, B, C = random_table(1), random_table(2), random_table(3)
    tabs = [A + B * (g * 1e3) + C * (g * 1e3) ** 2 for g in gaps]
    fam = Preisach(GRID, np.array(tabs), gaps)
    u = np.random.default_rng(4).uniform(0, 4.5, 50)
    for g in (0.2e-3, 0.33e-3, 0.57e-3, 0.91e-3, 1.0e-3):
        expect = sum(Preisach(GRID, T).simulate(u) * c for T, c in ((A, 1.0), (B, g * 1e3), (C, (g * 1e3) ** 2)))
        np.testing.assert_allclose(fam.simulate(u, airgap=g), expect, rtol=1e-9, atol=1e-9)


def _lagrange(x, g):
    """Quadratic Lagrange weights through the three airgaps ``x`` at ``g`` (written out, for the tests)."""
    return [np.prod([(g - x[m]) / (x[k] - x[m]) for m in range(3) if m != k]) for k in range(3)]


def test_airgap_blends_the_two_quadratics_of_its_interval():
    """In [0.4, 0.6] mm of four calibration airgaps: (1 - s) times the quadratic through 0.2, 0.4, 0.6 plus s times
    the one through 0.4, 0.6, 0.8 (s the position in the interval); in the first and the last interval the one
    quadratic that exists ([1], Sec. 2.1 "second-order polynomial interpolation", read C1: docs/emtc.md)."""
    gaps = np.array([0.2, 0.4, 0.6, 0.8]) * 1e-3
    tabs = [random_table(s) for s in range(4)]
    fam = Preisach(GRID, np.array(tabs), gaps)
    u = [0.0, 3.0, 1.0]
    vals = np.array([Preisach(GRID, T).simulate(u)[-1] for T in tabs])
    for g in (0.45e-3, 0.5e-3, 0.55e-3, 0.599e-3):
        s = (g - gaps[1]) / (gaps[2] - gaps[1])
        expect = (1 - s) * np.dot(_lagrange(gaps[:3], g), vals[:3]) + s * np.dot(_lagrange(gaps[1:], g), vals[1:])
        assert fam.simulate(u, airgap=g)[-1] == pytest.approx(float(expect), rel=1e-12)
    for g, three in ((0.25e-3, slice(0, 3)), (0.75e-3, slice(1, 4))):
        expect = np.dot(_lagrange(gaps[three], g), vals[three])
        assert fam.simulate(u, airgap=g)[-1] == pytest.approx(float(expect), rel=1e-12)


def test_airgap_interpolation_is_continuous_with_its_slope():
    """Across every calibration airgap and every interval's middle (where the quadratic through the nearest three,
    the reading until the twenty-fifth session, jumped: an armature parked there had no force balance) the output
    is continuous and so is its slope in the airgap: one-sided differences agree to their truncation error."""
    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4]) * 1e-3
    tabs = [random_table(s) * (1.0 + 0.3 * k) for k, s in enumerate(range(7))]
    fam = Preisach(GRID, np.array(tabs), gaps)
    u = [0.0, 4.0, 1.5, 3.0]

    def out(g):
        return fam.simulate(u, airgap=g)[-1]

    h = 1e-9  # m
    scale = max(abs(out(g)) for g in gaps)
    points = np.concatenate([gaps[1:-1], 0.5 * (gaps[:-1] + gaps[1:])])
    for g in points:
        left, mid, right = out(g - h), out(g), out(g + h)
        assert abs(right - left) < 1e-4 * scale, g      # no jump (a 0.4 % jump would be 4e-3 of the scale)
        slope_l, slope_r = (mid - left) / h, (right - mid) / h
        assert abs(slope_r - slope_l) < 1e-3 * max(abs(slope_l), scale / 1e-3), (g, slope_l, slope_r)
    # the nearest three do jump at 1.1 mm (the parked armature's airgap): what this test rules out
    g = 1.1e-3
    below = np.dot(_lagrange(gaps[3:6], g), [Preisach(GRID, T).simulate(u)[-1] for T in tabs[3:6]])
    above = np.dot(_lagrange(gaps[4:7], g), [Preisach(GRID, T).simulate(u)[-1] for T in tabs[4:7]])
    assert abs(above - below) > 1e-3 * scale


def test_airgap_weights_refuse_arrays_too_short_for_four_tables():
    """A caller sized for the three tables of the reading before the twenty-fifth session (a benchmark did) gets
    NaN weights, and nothing is written past its arrays (compiled code does not check bounds: the writes past
    their end had corrupted memory).  Arrays of GAP_TABLES get finite weights that sum to one."""
    from clutchlab.hysteresis import kernels as K

    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4]) * 1e-3
    guard = np.full(8, 7.0)
    iguard = np.full(8, 7, dtype=np.int64)
    idx, w = iguard[:3], guard[:3]
    K.gap_weights(gaps, 0.7e-3, idx, w)
    assert np.all(np.isnan(w)) and np.all(idx == 0)
    assert np.all(guard[3:] == 7.0) and np.all(iguard[3:] == 7)
    # the readers take no weight past the arrays' end either (there a table index would be garbage): NaN out
    iguard[3:] = 10**9
    guard[3:] = 1.0
    fam = Preisach(GRID, np.array([random_table(s) for s in range(7)]), gaps)
    fam.simulate([0.0, 3.0, 1.0], airgap=0.7e-3)
    assert np.isnan(K.weighted_output(fam.kernel_tables, fam.grid, fam._stack, fam._length, fam._pref, fam._u,
                                      idx, w))
    assert np.isnan(K.peek(fam.kernel_tables, fam.grid, fam._stack, fam._pref, fam._length, fam._u, 2.0, idx, w))
    comb = np.zeros((1,) + fam.kernel_tables.shape[1:])
    K.combine_tables(fam.kernel_tables, idx, w, comb)
    assert np.all(np.isnan(comb[0][np.tril_indices(comb.shape[1])]))
    idx, w = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    K.gap_weights(gaps, 0.7e-3, idx, w)
    assert np.all(np.isfinite(w)) and w.sum() == pytest.approx(1.0, rel=1e-14)


def test_family_inverse_at_off_grid_airgap():
    gaps = np.array([0.2, 0.6, 1.0, 1.4]) * 1e-3
    fam = Preisach(GRID, np.array([random_table(s) * (1.5 - 0.3 * k) for k, s in enumerate(range(4))]), gaps)
    u = np.random.default_rng(5).uniform(0, 4.5, 100)
    target = fam.simulate(u, airgap=0.7e-3)
    inv = fam.invert(target, airgap=0.7e-3)
    assert inv.all_feasible
    np.testing.assert_allclose(fam.simulate(inv.input, airgap=0.7e-3), target, atol=1e-8)


# ------------------------------------------------------------------ errors and files
def test_bad_input_raises_clear_errors():
    F = random_table(1)
    i, j = np.tril_indices(GRID.size)
    with pytest.raises(DataError, match="missing F"):
        Preisach.from_forc_table(GRID[i][:-1], GRID[j][:-1], F[i, j][:-1])
    with pytest.raises(DataError, match="beta = .* > alpha"):
        Preisach.from_forc_table([1.0, 0.0, 1.0], [1.0, 0.0, 2.0], [1, 2, 3])
    vals = F[i, j].copy()
    vals[3] = np.nan
    with pytest.raises(DataError, match=r"value\[3\]"):
        Preisach.from_forc_table(GRID[i], GRID[j], vals)
    with pytest.raises(DataError, match="given twice"):
        Preisach.from_forc_table(np.r_[GRID[i], 4.5], np.r_[GRID[j], 0.0], np.r_[F[i, j], 1.0])
    m = Preisach(GRID, F)
    with pytest.raises(DataError, match=r"u\[2\] = 5.0 A outside the Preisach grid"):
        m.simulate([0.0, 1.0, 5.0])
    with pytest.raises(DataError, match="not finite"):
        m.simulate([0.0, np.nan])
    with pytest.raises(ParameterError, match="airgap given"):
        m.simulate([1.0], airgap=1e-3)
    fam = Preisach(GRID, np.array([F, F * 0.5]), [0.2e-3, 0.4e-3])
    with pytest.raises(ParameterError, match="pass airgap"):
        fam.simulate([1.0])
    with pytest.raises(DataError, match="outside the calibration range"):
        fam.simulate([1.0], airgap=0.5e-3)
    with pytest.raises(DataError, match="not strictly increasing"):
        Preisach([0.0, 1.0, 1.0], np.zeros((3, 3)))


def test_json_roundtrip(tmp_path):
    gaps = np.array([0.2e-3, 0.4e-3, 0.6e-3])
    fam = Preisach(GRID, np.array([random_table(s) for s in range(3)]), gaps)
    p = fam.to_json(tmp_path / "m.json")
    with pytest.raises(FileExistsError):
        fam.to_json(p)
    back = Preisach.from_json(p)
    np.testing.assert_allclose(back.tables, fam.tables)
    np.testing.assert_allclose(back.airgaps, gaps)
    (tmp_path / "bad.json").write_text(json.dumps({"kind": "other"}))
    with pytest.raises(DataError, match="not a clutchlab Preisach model"):
        Preisach.from_json(tmp_path / "bad.json")


@settings(max_examples=examples(60), deadline=None)
@given(history=st.lists(st.floats(0.0, 4.5), min_size=1, max_size=30), v=st.floats(0.0, 4.5),
       gap=st.floats(0.2e-3, 1.0e-3))
def test_peek_with_combined_airgap_table_equals_weighted_peek(history, v, gap):
    """The compiled bench evaluates the family through one airgap-combined table (linearity of Eqs. 2-5)."""
    from clutchlab.hysteresis import kernels as K

    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0]) * 1e-3
    fam = Preisach(GRID, np.array([random_table(s) * (1 + s) for s in range(5)]), gaps)
    fam.simulate(history, airgap=gap)
    idx, w = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    K.gap_weights(fam.airgaps, gap, idx, w)
    comb = np.zeros((1,) + fam.kernel_tables.shape[1:])
    K.combine_tables(fam.kernel_tables, idx, w, comb)
    args = (fam._stack, fam._pref, fam._length, fam._u, v, idx, w)
    a = K.peek(fam.kernel_tables, fam.grid, *args)
    b = K.peek_combined(comb, fam.grid, *args)
    assert b == pytest.approx(a, rel=1e-12, abs=1e-9)
    # and peek equals committing the step
    assert a == pytest.approx(fam.step(v, airgap=gap), rel=1e-12, abs=1e-9)


@settings(max_examples=examples(200), deadline=None)
@given(history=st.lists(st.floats(0.0, 4.5), min_size=0, max_size=30), v=st.floats(0.0, 4.5),
       gap=st.floats(0.2e-3, 1.0e-3), inside=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=5))
def test_peek_segment_is_the_combined_peek_on_its_whole_stretch(history, v, gap, inside):
    """:func:`peek_segment` (the drum bench's stage evaluations while the armature rests on a stop): the
    quadratic it returns for the stretch around ``v`` equals the combined-table peek at ``v`` and at any input
    strictly inside that stretch, for any memory."""
    from clutchlab.hysteresis import kernels as K

    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0]) * 1e-3
    fam = Preisach(GRID, np.array([random_table(s) * (1 + s) for s in range(5)]), gaps)
    if history:
        fam.simulate(history, airgap=gap)
    idx, w = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    K.gap_weights(fam.airgaps, gap, idx, w)
    comb = np.zeros((1,) + fam.kernel_tables.shape[1:])
    K.combine_tables(fam.kernel_tables, idx, w, comb)
    args = (fam._stack, fam._pref, fam._length, fam._u)
    seg = np.zeros(6)
    scale = np.max(np.abs(fam.kernel_tables)) + 1.0
    f = K.peek_segment(comb, fam.grid, *args, v, idx, w, seg)
    assert f == pytest.approx(K.peek_combined(comb, fam.grid, *args, v, idx, w), rel=1e-12, abs=1e-12 * scale)
    lo, hi, a0, a1, a2, kind = seg
    if v == fam._u:
        assert lo == hi == v
        return
    assert lo <= v <= hi and (lo < v or v < hi or lo == hi)
    stack, length, u = fam._stack, fam._length, fam._u
    # the last inputs the same memory may have: rising from the last minimum below the last maximum (even
    # length), or falling from the last maximum above the last minimum (odd)
    if length == 0:
        lo_u, hi_u = fam.grid[0], fam.grid[-1]
    elif length % 2 == 0:
        lo_u, hi_u = stack[length - 1], stack[length - 2]
    else:
        lo_u, hi_u = (stack[length - 2] if length >= 3 else fam.grid[0]), stack[length - 1]
    for s in inside:
        x = lo + s * (hi - lo)
        if not lo < x < hi:
            continue
        ref = K.peek_combined(comb, fam.grid, *args, x, idx, w)
        assert a0 + x * (a1 + x * a2) == pytest.approx(ref, rel=1e-12, abs=1e-12 * scale)
        seg2 = np.zeros(6)
        K.peek_segment(comb, fam.grid, *args, x, idx, w, seg2)
        np.testing.assert_array_equal(seg2, seg)  # one polynomial for the whole stretch
        # kind +1 / -1: the same polynomial for another last input below / above x with the same memory
        for uo in (lo_u + s * (hi_u - lo_u), lo_u, hi_u):
            if (kind == 1.0 and uo < x) or (kind == -1.0 and uo > x):
                ref = K.peek_combined(comb, fam.grid, stack, fam._pref, length, uo, x, idx, w)
                assert a0 + x * (a1 + x * a2) == pytest.approx(ref, rel=1e-12, abs=1e-12 * scale)
                K.peek_segment(comb, fam.grid, stack, fam._pref, length, uo, x, idx, w, seg2)
                np.testing.assert_array_equal(seg2[2:], seg[2:])


@settings(max_examples=examples(100), deadline=None)
@given(history=st.lists(st.floats(0.0, 4.5), min_size=0, max_size=12),
       targets=st.lists(st.floats(-0.2, 1.2), min_size=1, max_size=25), gap=st.floats(0.2e-3, 1.0e-3),
       rising=st.booleans())
def test_invert_combined_is_invert_one_along_a_command_sequence(history, targets, gap, rising):
    """:func:`invert_combined` (the drum bench's controller, one combined table, its rising stretch kept between
    samples) gives the inverse of :func:`invert_one` at every sample of a sequence of targets committed one
    after the other (mostly rising ones with ``rising``: the stretch is reused), to rounding."""
    from clutchlab.hysteresis import kernels as K

    gaps = np.array([0.2, 0.4, 0.6, 0.8, 1.0]) * 1e-3
    fam = Preisach(GRID, np.array([np.maximum.accumulate(np.maximum.accumulate(random_table(s), 0), 1) * (1 + s)
                                   for s in range(5)]), gaps)
    idx, w = np.zeros(K.GAP_TABLES, dtype=np.int64), np.zeros(K.GAP_TABLES)
    K.gap_weights(fam.airgaps, gap, idx, w)
    comb = np.zeros((1,) + fam.kernel_tables.shape[1:])
    K.combine_tables(fam.kernel_tables, idx, w, comb)
    one, ow = np.zeros(K.GAP_TABLES, dtype=np.int64), np.eye(K.GAP_TABLES)[0]
    cap = 64
    stack, pref = np.zeros(cap), np.zeros((1, cap // 2 + 2))
    length, u = 0, float(fam.grid[0])
    for v in history:
        length = K.commit(comb, fam.grid, stack, pref, length, u, v)
        u = v
    lo = K.peek(comb, fam.grid, stack, pref, length, u, fam.grid[0], one, ow)
    hi = K.peek(comb, fam.grid, stack, pref, length, u, fam.grid[-1], one, ow)
    seg = np.full(8, np.nan)
    version = 0
    ts = np.sort(targets) if rising else np.asarray(targets)
    for q in ts:
        if length + 2 > cap:
            break
        target = lo + q * (hi - lo)
        v1, ok1 = K.invert_one(comb, fam.grid, stack, pref, length, u, target, one, ow, 1e-9)
        v2, ok2 = K.invert_combined(comb, fam.grid, stack, pref, length, u, target, one, ow, 1e-9, seg, version)
        if np.isnan(v2):  # not on the kept stretch: the caller's invert_one
            assert not ok2
            v2, ok2 = K.invert_one(comb, fam.grid, stack, pref, length, u, target, one, ow, 1e-9)
        assert ok1 == ok2
        assert v2 == pytest.approx(v1, rel=1e-11, abs=1e-11)
        new = K.commit(comb, fam.grid, stack, pref, length, u, v2)
        version += new != length
        length, u = new, v2
