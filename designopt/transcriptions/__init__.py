"""Transcriptions of one DesignProblem into an NLP: TO (direct collocation) and the FK baseline.

A transcription is a frozen description with a ``name``: ``build(problem)`` returns a `BuiltNLP` (the
backend-neutral `NLP`, and how a guess and an answer map onto its decision vector) and ``trajectory(t, Q, V)``
is the joint trajectory its knots define. How an NLP is solved -- backend, options, caps -- is
`designopt.solve`'s business, never a transcription's.
"""

from __future__ import annotations

from functools import partial
from typing import Protocol

import numpy as np

from designopt.problem import DesignProblem
from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.collocation import Collocation
from designopt.transcriptions.forward_kinematics import ForwardKinematics
from designopt.transcriptions.nlp import NLP


class BuiltNLP(Protocol):
    """A transcribed problem, built once; any backend solves ``nlp`` from any guess."""

    nlp: NLP
    build_time_s: float

    def pack(self, guess: InitialGuess) -> np.ndarray: ...

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, object, float]:
        """(design joints, joint trajectory, kinematic drift)."""


class Transcription(Protocol):
    name: str
    exact_tracking: bool  # tracking rows are equalities in (q, q_d) at every waypoint

    def build(self, problem: DesignProblem) -> BuiltNLP: ...

    def trajectory(self, t, Q, V): ...


# The one registry: the methods a user or an experiment names.
TRANSCRIPTIONS = {
    "to": Collocation,
    "fk": partial(ForwardKinematics, continuous=False),
    "fk_continuous": partial(ForwardKinematics, continuous=True),
}

__all__ = ["BuiltNLP", "Collocation", "ForwardKinematics", "InitialGuess", "NLP", "RawResult", "TRANSCRIPTIONS",
           "Transcription", "transcription_named"]


def transcription_named(method: str, **options) -> Transcription:
    """``to``, ``fk`` or ``fk_continuous``, with options of its own (e.g. ``hessian``)."""
    if method not in TRANSCRIPTIONS:
        raise ValueError(f"unknown method {method!r} ({', '.join(TRANSCRIPTIONS)})")
    return TRANSCRIPTIONS[method](**options)
