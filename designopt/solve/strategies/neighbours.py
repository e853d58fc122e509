"""Neighbour starts: one more start per problem from each neighbouring structure that found a better design.

Two problems of one search are neighbours when they share their case and their structures are one edit apart: one
joint's type differs (R <-> P), or one has a joint the other lacks. A structure whose neighbour found a cheaper
design was stuck in a worse basin, and the neighbour's design is a good guess for it: a structure of the same length
starts from its placement and every link parameter of the same name (`Seeded` with that design, joints by IK, at
most ``SAME_LENGTH_CAP`` iterations); a structure with one joint fewer is this one with a link held as an identity
transform, so its solution, the link inserted, is a start that already tracks the path (`Grown`, solved warm); and a
structure with one joint more inserted first whose first joint stays still along the path is this one placed by that
link's transform, so its solution without the link is an exact start too (`Pruned`, solved warm). The starts are
solved on the full path (stage ``neighbour``) and join each problem's final solves; a second pass (``neighbour2``)
gives starts from the structures whose best the first lowered, so that a design found there reaches the structures
next to it (up to ``PASSES`` passes). A start that is still above ``BOUND_FACTOR`` times its structure's best
objective after ``BOUND_AFTER`` iterations is stopped there (`designopt.solve.observers.AboveBound`), a cold
same-length one already above ``COLD_BOUND_FACTOR`` times it after ``COLD_BOUND_AFTER``. Problems without
neighbours (every search of a single structure) get no task.
"""

from __future__ import annotations

import numpy as np

from designopt.initial_guess import design_from
from designopt.solve.observers import Bound
from designopt.solve.search import Searched, by_job
from designopt.solve.starts import Grown, Pruned, Seeded, pruned_design
from designopt.solve.strategies.steps import numbered_stage, solve_setup
from designopt.solve.tasks import Task

STAGE = "neighbour"
# A neighbour start still above BOUND_FACTOR times its structure's best objective after BOUND_AFTER iterations is
# stopped there: it is not going to beat it. Of the K = I sweep's neighbour starts past 300 iterations (seeds 0 and
# 1, 365 solves), none that went on to beat its structure's best was then above 1.73x it, and 241 of the 279 others
# were above 3x; on an untouched seed 4 of the 119 it stopped would have beaten it, where other starts reached or
# beat those bests (docs/decisions.md).
BOUND_FACTOR, BOUND_AFTER = 3.0, 300
# A longer structure's first joint that moves less than STILL (rad or m) along the path makes its arm the shorter
# structure's (`Pruned`); pruned starts are numbered from PRUNED_FROM (after same-length and grown ones)
STILL = 1e-3
PRUNED_FROM = 50
# Passes of the step: a later pass gives starts only from the neighbours whose best the pass before lowered. A second
# pass on the K = I sweep's seeds 2101-2104: 52-75 more solves (2-8 % of the solver time), 9 structure bests lower by
# more than 1 % (RRR reaching its reference through PRRR's pruned design; PPRPRR 0.45x), none higher
# (docs/benchmarks.md, "Sweep")
PASSES = 2
# A cold same-length start is capped at SAME_LENGTH_CAP iterations (before the bound's BOUND_AFTER, which so holds
# only the grown and pruned starts). Of the 960 such starts of the K = I sweeps 2122-2124 (1,046 s of solver time),
# the 28 that beat their structure's refined best by > 1 % took 35-427 iterations, 25 of them at most 200. Judged on
# fresh seeds 2126 and 2127 (the neighbour and later stages replayed side by side): their solver time 0.70x and
# 0.72x, references within 1.10x 5 + 3 either way, 2 and 0 structure bests higher by > 1 % (RRP 1.14x), none lower
# (docs/decisions.md, "Speed").
SAME_LENGTH_CAP = 200
# A cold same-length start still above COLD_BOUND_FACTOR times its structure's best objective after COLD_BOUND_AFTER
# iterations is stopped there. On the K = I sweeps of seeds 2156 and 2157 (tuning), 130 and 115 of such starts reached
# the cap of 200 above 10x; 3x or 10x from iteration 60 lost RRPR's reference (its start took 194 iterations). Judged
# on fresh seeds 2158 and 2159 (replays from the neighbour stage on): the neighbour and later stages 0.749x and 0.757x
# their solver time (about 0.97x the sweep's), references within 1.10x 6 -> 6 and 8 -> 8, one structure best higher
# by > 1 % (RPRRPP 1.020x), none lower (docs/decisions.md, "Speed").
COLD_BOUND_FACTOR, COLD_BOUND_AFTER = 10.0, 100


def neighbours(structure: str, structures: list[str]) -> list[str]:
    """The structures among ``structures`` that differ from ``structure`` in one joint's type (R <-> P)."""
    return [s for s in structures
            if len(s) == len(structure) and sum(a != b for a, b in zip(s, structure, strict=True)) == 1]


def shorter(structure: str, structures: list[str]) -> list[tuple[str, int]]:
    """(other, where) for every structure among ``structures`` that is ``structure`` without its joint ``where``
    (0-based): ``structure`` is ``other`` with a joint inserted at ``where``. One pair per position, so a structure
    can be one shorter one in several ways (RRPR: RPR without joint 0 or 1)."""
    present = set(structures)
    return [(other, k) for k in range(len(structure)) if (other := structure[:k] + structure[k + 1:]) in present]


def longer(structure: str, structures: list[str]) -> list[str]:
    """The structures among ``structures`` that are ``structure`` with one joint inserted first."""
    return [s for s in structures if len(s) == len(structure) + 1 and s[1:] == structure]


def still_first(solution) -> bool:
    """Whether a solution's first joint moves less than ``STILL`` (rad or m) along the path: its arm is then the
    shorter structure's, placed elsewhere (`starts.Pruned`)."""
    first = np.asarray(solution.raw.Q, float)[:, 0]
    return bool(np.ptp(first) < STILL)


def held(own, factor: float, after: int) -> Bound | None:
    """What a start is held to (`Bound`): ``factor`` times the NLP objective of its structure's best solution ``own``
    from iteration ``after`` on; None (not held) when the structure has no best yet."""
    return Bound(factor * own.raw.objective, after) if own is not None else None


def plan(searched, search):
    """Up to ``PASSES`` passes (stages ``neighbour``, ``neighbour2``, ...): the first gives each structure a start from
    every neighbour that found a cheaper design; each later one only from the neighbours whose best the pass before
    lowered, so that a design found in a pass reaches the structures next to it."""
    jobs = [s.job for s in searched]
    lowered = None  # (case, structure) whose best the last pass lowered; None before the first pass: all
    for i in range(PASSES):
        tasks = _starts(searched, search, numbered_stage(STAGE, i), lowered)
        if not tasks:
            break
        more = by_job(jobs, (yield tasks))
        after = [Searched(s.job, s.explore, s.final + m) for s, m in zip(searched, more, strict=True)]
        lowered = {(a.job.case, a.job.problem.chain.structure) for s, a in zip(searched, after, strict=True)
                   if a.best[1] is not None and a.best[1] is not s.best[1]}
        searched = after
    return searched


def _starts(searched, search, stage: str, lowered) -> list[Task]:
    """One pass's tasks: for every structure, a start from each neighbour (among ``lowered``, when given) that found
    a cheaper design."""
    best = {(s.job.case, s.job.problem.chain.structure): (s.job, s.best[1]) for s in searched}

    def cheaper(case: str, other: str, own) -> tuple | None:
        """(job, best solution) of structure ``other`` when it found a cheaper design than ``own``."""
        other_job, theirs = best[case, other]
        if lowered is not None and (case, other) not in lowered:
            return None
        if theirs is None or (own is not None and theirs.metrics.design_cost >= own.metrics.design_cost):
            return None
        return other_job, theirs

    tasks = []
    for s in searched:
        job, own, structure = s.job, s.best[1], s.job.problem.chain.structure
        same_case = [st for case, st in best if case == job.case]
        same_length, starts = neighbours(structure, same_case), []
        # same-length starts are solved cold (joints by IK), capped and held sooner; grown and pruned ones already track
        # the path: warm. Each kind's (profile, continuation, bound)
        cold = (*solve_setup(job, search, search.profile.capped(SAME_LENGTH_CAP)),
                held(own, COLD_BOUND_FACTOR, COLD_BOUND_AFTER))
        warm = (*solve_setup(job, search, search.profile.warmed()), held(own, BOUND_FACTOR, BOUND_AFTER))
        for j, other in enumerate(same_length):
            if found := cheaper(job.case, other, own):
                design = design_from(job.problem, found[0].problem, found[1].raw.q_d)
                starts.append((cold, Seeded(search.seed, j, search.perturbation, search.init, design)))
        for k, (other, where) in enumerate(shorter(structure, same_case)):
            if found := cheaper(job.case, other, own):
                starts.append((warm, Grown(found[1], found[0].problem, where, search.seed, len(same_length) + k)))
        for k, other in enumerate(longer(structure, same_case)):
            if not (found := cheaper(job.case, other, own)) or not still_first(found[1]):
                continue
            if (design := pruned_design(job.problem, found[0].problem, found[1])) is not None:
                starts.append((warm, Pruned(found[1], design, search.seed, PRUNED_FROM + k)))
        tasks += [Task(job.case, stage, job.problem, job.transcription, profile.observing("above_bound"), start,
                       continuation, bound) for (profile, continuation, bound), start in starts]
    return tasks
