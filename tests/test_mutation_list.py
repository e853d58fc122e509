"""The mutation check's list (`tests/mutate.py`) stays current: each mutation's line is in its file exactly once,
so `make mutate` mutates what it names instead of reporting it NOT APPLIED an hour into its run."""

from pathlib import Path

import pytest
from mutate import MUTATIONS, ROOT


@pytest.mark.parametrize("mutation", MUTATIONS, ids=lambda m: m.name[:60])
def test_each_mutation_applies_to_exactly_one_place(mutation):
    text = (ROOT / mutation.file).read_text()
    assert text.count(mutation.old) == 1, f"{mutation.file}: the line is there {text.count(mutation.old)} times"
    assert mutation.new != mutation.old
    assert all((ROOT / t.split("::")[0]).exists() for t in mutation.tests or ()), "a test file that does not exist"


def test_mutation_names_are_distinct():
    names = [m.name for m in MUTATIONS]
    assert len(names) == len(set(names))
    assert Path(__file__).resolve().parent == (ROOT / "tests").resolve()  # the list read is this checkout's
