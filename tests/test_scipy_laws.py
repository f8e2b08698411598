"""The time laws, sampled pieces and joint splines evaluated by scipy (BPoly, CubicSpline) agree with the
hand-evaluated formulas they replaced (kept here, as written before, as the independent route) to 1e-12,
and the closed-form peaks stay the exact extrema."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import BPoly

from scara_pin.motion.paths import JointSpline
from scara_pin.motion.trajectory import QuinticLaw, Samples, _SampledPiece


def old_quintic(T: float, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x = np.clip(np.asarray(tau, dtype=float) / T, 0.0, 1.0)
    x2 = x * x
    s = x2 * x * (10.0 + x * (-15.0 + 6.0 * x))
    sd = 30.0 * x2 * (1.0 + x * (-2.0 + x)) / T
    sdd = 60.0 * x * (1.0 + x * (-3.0 + 2.0 * x)) / (T * T)
    return s, sd, sdd


def old_hermite(S: Samples, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, S.t[-1])
    i = np.clip(np.searchsorted(S.t, tau, side="right") - 1, 0, len(S.t) - 2)
    h = (S.t[i + 1] - S.t[i])[:, None]
    x = ((tau - S.t[i]) / (S.t[i + 1] - S.t[i]))[:, None]
    p0, v0, a0 = S.q[i], S.qd[i] * h, S.qdd[i] * h * h
    p1, v1, a1 = S.q[i + 1], S.qd[i + 1] * h, S.qdd[i + 1] * h * h
    dp = p1 - p0
    c3 = 10 * dp - 6 * v0 - 4 * v1 - (3 * a0 - a1) / 2
    c4 = -15 * dp + 8 * v0 + 7 * v1 + (3 * a0 - 2 * a1) / 2
    c5 = 6 * dp - 3 * (v0 + v1) - (a0 - a1) / 2
    c2 = a0 / 2
    q = p0 + x * (v0 + x * (c2 + x * (c3 + x * (c4 + x * c5))))
    qd = (v0 + x * (2 * c2 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))) / h
    qdd = (2 * c2 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))) / (h * h)
    return q, qd, qdd


@pytest.mark.parametrize("T", [1e-3, 0.37, 1.0, 12.5])
def test_quintic_law_matches_the_closed_form(T: float) -> None:
    law = QuinticLaw(T)
    tau = np.concatenate([np.linspace(-0.1 * T, 1.1 * T, 2001), [0.0, T, T / 2]])
    for k, (new, old) in enumerate(zip(law.evaluate(tau), old_quintic(T, tau))):
        assert np.abs(new - old).max() <= 1e-12 / T**k, k
    assert law.evaluate(np.array([0.0, T]))[0].tolist() == [0.0, 1.0]


@pytest.mark.parametrize("T", [1e-3, 0.37, 12.5])
def test_quintic_peaks_are_the_exact_extrema(T: float) -> None:
    law = QuinticLaw(T)
    v_peak, a_peak = law.peaks()
    # at the stationary points (sd' = 0 at T/2; sdd' = 0 at T (1/2 -/+ sqrt(3)/6)), written here
    _, sd, _ = law.evaluate(np.array([T / 2]))
    _, _, sdd = law.evaluate(T * np.array([0.5 - math.sqrt(3) / 6, 0.5 + math.sqrt(3) / 6]))
    assert abs(sd[0] - v_peak) <= 1e-12 * v_peak
    assert np.abs(np.abs(sdd) - a_peak).max() <= 1e-12 * a_peak
    # and nothing higher on a dense grid, nor through the scaled law
    _, sd, sdd = law.evaluate(np.linspace(0.0, T, 100_001))
    assert sd.max() <= v_peak * (1 + 1e-12) and np.abs(sdd).max() <= a_peak * (1 + 1e-12)
    v2, a2 = law.scaled(3.0).peaks()
    assert v2 == pytest.approx(v_peak / 3, rel=1e-15) and a2 == pytest.approx(a_peak / 9, rel=1e-15)


def test_sampled_piece_matches_the_hand_hermite_and_scipy() -> None:
    rng = np.random.default_rng(7)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-3, 0.5, 40))])
    S = Samples(t, rng.normal(size=(41, 4)), rng.normal(size=(41, 4)), rng.normal(size=(41, 4)))
    piece = _SampledPiece(S)
    tau = np.concatenate([np.linspace(-0.1, t[-1] + 0.1, 5001), t])
    ref = BPoly.from_derivatives(t, np.stack([S.q, S.qd, S.qdd], axis=1))  # scipy's own construction
    clipped = np.clip(tau, 0.0, t[-1])
    h_min = float(np.diff(t).min())
    for k, (new, old) in enumerate(zip(piece.evaluate(tau), old_hermite(S, tau))):
        scale = max(1.0, float(np.abs(old).max())) / h_min**k  # the k-th derivative scales with 1 / h^k
        assert np.abs(new - old).max() <= 1e-12 * scale, k
        assert np.abs(new - ref(clipped, k)).max() <= 1e-12 * scale, k
    q, qd, qdd = piece.evaluate(t)  # the samples themselves, bit for bit
    assert (q == S.q).all() and (qd == S.qd).all() and (qdd == S.qdd).all()


def test_joint_spline_matches_its_hand_evaluated_coefficients() -> None:
    rng = np.random.default_rng(11)
    W = np.cumsum(rng.normal(size=(7, 4)), axis=0)
    path = JointSpline(W)
    s = np.concatenate([np.linspace(0.0, 1.0, 3001), path.knots()])
    spline = path._spline
    x, c = spline.x, spline.c
    i = np.clip(np.searchsorted(x, s, side="right") - 1, 0, len(x) - 2)
    d = (s - x[i])[:, None]
    c0, c1, c2, c3 = c[0, i], c[1, i], c[2, i], c[3, i]
    old = [((c0 * d + c1) * d + c2) * d + c3, (3.0 * c0 * d + 2.0 * c1) * d + c2, 6.0 * c0 * d + 2.0 * c1]
    for k, (new, ref) in enumerate(zip(path.evaluate(s), old)):
        assert np.abs(new - ref).max() <= 1e-12 * max(1.0, float(np.abs(ref).max())), k
    np.testing.assert_allclose(path.evaluate(path.knots())[0], W, atol=1e-12)  # through the waypoints
