"""Transcriptions of one DesignProblem into an NLP: TO (direct collocation) and the FK baseline."""

from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.collocation import Collocation
from designopt.transcriptions.forward_kinematics import ForwardKinematics

__all__ = ["Collocation", "ForwardKinematics", "InitialGuess", "RawResult", "transcription_named"]


def transcription_named(method: str, **options):
    """``to``, ``fk`` or ``fk_continuous`` with the options each accepts."""
    if method == "to":
        return Collocation(**options)
    if method in ("fk", "fk_continuous"):
        keep = {k: v for k, v in options.items() if k in ("max_iter", "compile", "ipopt", "epsilon")}
        return ForwardKinematics(continuous=method == "fk_continuous", **keep)
    raise ValueError(f"unknown method {method!r} (to, fk, fk_continuous)")
