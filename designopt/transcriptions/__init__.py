"""Transcriptions of one DesignProblem into an NLP: TO (direct collocation) and the FK baseline.

Every transcription follows the `Transcription` protocol: a frozen description with a ``name`` whose
``build(problem)`` returns a `BuiltNLP` that solves from any number of initial guesses.
"""

from __future__ import annotations

from typing import Protocol

from designopt.problem import DesignProblem
from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.collocation import Collocation
from designopt.transcriptions.forward_kinematics import ForwardKinematics


class BuiltNLP(Protocol):
    """A transcribed problem, built once: IPOPT solves it from any initial guess."""

    n_variables: int
    n_constraints: int
    build_time_s: float

    def solve(self, guess: InitialGuess) -> RawResult: ...


class Transcription(Protocol):
    name: str

    def build(self, problem: DesignProblem) -> BuiltNLP: ...


# The one registry: method name -> (factory, the options it takes).
_FK_OPTIONS = ("max_iter", "compile", "ipopt", "epsilon", "hessian")
TRANSCRIPTIONS = {
    "to": (Collocation, ("kinematics", "tracking", "degree", "max_iter", "hessian", "compile", "ipopt",
                        "hold_degenerate")),
    "fk": (lambda **o: ForwardKinematics(continuous=False, **o), _FK_OPTIONS),
    "fk_continuous": (lambda **o: ForwardKinematics(continuous=True, **o), _FK_OPTIONS),
}

__all__ = ["BuiltNLP", "Collocation", "ForwardKinematics", "InitialGuess", "RawResult", "TRANSCRIPTIONS",
           "Transcription", "transcription_named"]


def transcription_named(method: str, **options) -> Transcription:
    """``to``, ``fk`` or ``fk_continuous``, given the options it takes (others are ignored)."""
    if method not in TRANSCRIPTIONS:
        raise ValueError(f"unknown method {method!r} ({', '.join(TRANSCRIPTIONS)})")
    factory, accepted = TRANSCRIPTIONS[method]
    return factory(**{k: v for k, v in options.items() if k in accepted})
