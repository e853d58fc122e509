"""Joint trajectories: what a transcription's knot values mean between the waypoints.

A transcription owns its trajectory (rockit's ``sample`` delegates to the method the same way): TO's knots are
(q_k, v_k) of a C^1 piecewise cubic (`HermiteCubic`); the FK baseline defines joint values at the waypoints
only, and between them the straight line is all it says (`PiecewiseLinear`). A solution, its metrics and the
search's lifting of a solution to another grid all ask the trajectory, never the knots directly.

Times are the path's (task time in [0, 1], or seconds for a timed G-code program); joint values in rad or m.
The segment formulas work on numpy and CasADi values alike (the NLP uses them symbolically).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def hermite_midpoint(q0, v0, q1, v1, h):
    """Position and velocity of the cubic Hermite segment at its midpoint (numpy or CasADi)."""
    q_mid = 0.5 * (q0 + q1) + h * (v0 - v1) / 8.0
    v_mid = 1.5 * (q1 - q0) / h - 0.25 * (v0 + v1)
    return q_mid, v_mid


def hermite_acceleration_integral(q0, v0, q1, v1, h):
    """Integral of the squared acceleration over one cubic Hermite segment (exact), per joint."""
    a0 = 6.0 * (q1 - q0) / h**2 - (4.0 * v0 + 2.0 * v1) / h
    a1 = -6.0 * (q1 - q0) / h**2 + (2.0 * v0 + 4.0 * v1) / h
    return h / 3.0 * (a0 * a0 + a0 * a1 + a1 * a1)


def _interval(knots: np.ndarray, t):
    """Segment index k, its length h (column) and the local coordinate s in [0, 1] of every time in t."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    k = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2)
    h = (knots[k + 1] - knots[k])[:, None]
    return k, h, (t[:, None] - knots[k][:, None]) / h


@dataclass(frozen=True, eq=False)
class HermiteCubic:
    """The C^1 cubic Hermite spline through (t_k, Q_k) with velocities V_k (TO's trajectory).

    ``t`` (N), ``Q`` and ``V`` (N x n_m). Position and velocity are continuous at the knots; the collocation
    points are the interval midpoints."""

    t: np.ndarray
    Q: np.ndarray
    V: np.ndarray
    kind = "hermite_cubic"

    def sample(self, t) -> np.ndarray:
        """q(t), len(t) x n_m."""
        Q, V = np.asarray(self.Q, float), np.asarray(self.V, float)
        k, h, s = _interval(np.asarray(self.t, float), t)
        return ((2 * s**3 - 3 * s**2 + 1) * Q[k] + (s**3 - 2 * s**2 + s) * h * V[k]
                + (-2 * s**3 + 3 * s**2) * Q[k + 1] + (s**3 - s**2) * h * V[k + 1])

    def velocity(self, t) -> np.ndarray:
        """dq/dt at t (per unit of the path's time), len(t) x n_m."""
        Q, V = np.asarray(self.Q, float), np.asarray(self.V, float)
        k, h, s = _interval(np.asarray(self.t, float), t)
        return ((6 * s**2 - 6 * s) * (Q[k] - Q[k + 1]) / h + (3 * s**2 - 4 * s + 1) * V[k]
                + (3 * s**2 - 2 * s) * V[k + 1])

    def collocation_points(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, joint values) of the points between the knots where the NLP also enforces its bounds."""
        Q, V, t = np.asarray(self.Q, float), np.asarray(self.V, float), np.asarray(self.t, float)
        h = np.diff(t)[:, None]
        q_mid, _ = hermite_midpoint(Q[:-1], V[:-1], Q[1:], V[1:], h)
        return 0.5 * (t[:-1] + t[1:]), q_mid


@dataclass(frozen=True, eq=False)
class PiecewiseLinear:
    """Straight lines between the knots (Q_k at t_k): all the FK baseline defines between its waypoints."""

    t: np.ndarray
    Q: np.ndarray
    V = None
    kind = "linear"

    def sample(self, t) -> np.ndarray:
        Q = np.asarray(self.Q, float)
        k, _, s = _interval(np.asarray(self.t, float), t)
        return Q[k] + s * (Q[k + 1] - Q[k])

    def velocity(self, t) -> np.ndarray:
        Q = np.asarray(self.Q, float)
        k, h, _ = _interval(np.asarray(self.t, float), t)
        return (Q[k + 1] - Q[k]) / h

    def collocation_points(self) -> tuple[np.ndarray, np.ndarray]:
        """No points between the knots: the baseline constrains nothing there."""
        return np.zeros(0), np.zeros((0, np.shape(self.Q)[1]))


TRAJECTORIES = {HermiteCubic.kind: HermiteCubic, PiecewiseLinear.kind: PiecewiseLinear}


def trajectory(t, Q, V=None, kind: str | None = None) -> HermiteCubic | PiecewiseLinear:
    """A trajectory of the named ``kind`` (a solution file states it) through the knots; without a kind, a Hermite
    cubic when the knots carry velocities, else straight lines (files written before the kind was stored). A
    transcription builds its own."""
    t, Q = np.asarray(t, float), np.asarray(Q, float)
    kind = kind or (HermiteCubic.kind if V is not None else PiecewiseLinear.kind)
    if kind not in TRAJECTORIES:
        raise ValueError(f"unknown trajectory kind {kind!r} ({', '.join(TRAJECTORIES)})")
    if kind == HermiteCubic.kind:
        if V is None:
            raise ValueError("a Hermite cubic needs the joint velocities at the knots")
        return HermiteCubic(t, Q, np.asarray(V, float))
    return PiecewiseLinear(t, Q)
