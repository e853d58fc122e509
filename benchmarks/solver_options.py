"""Solver options from the command line: the benchmarks' ``--option KEY=VALUE`` (e.g. ipopt.perturb_always_cd=no).

A value that reads as an int or a float is that number, any other stays a string: IPOPT's yes / no must stay strings
(YAML would read them as booleans, which IPOPT refuses)."""

from __future__ import annotations


def option_value(text: str) -> int | float | str:
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse_options(items: list[str]) -> tuple[tuple[str, int | float | str], ...]:
    """(key, value) pairs of KEY=VALUE strings, in order."""
    return tuple((key, option_value(value)) for key, value in (item.split("=", 1) for item in items))
