"""Transcriptions of a DesignProblem into an NLP: TO (direct collocation) and, later, the FK baseline."""

from designopt.transcriptions.base import InitialGuess, RawResult
from designopt.transcriptions.collocation import Collocation

__all__ = ["Collocation", "InitialGuess", "RawResult"]
