"""The Solve layer: how a design problem is solved, between the transcriptions (what the NLP is) and the
experiments (what to solve).

* `profile`: a solver profile -- backend and options (caps, warm or cold, observers);
* `backends`: what turns a transcribed NLP and a profile into a solver (IPOPT today);
* `observers`: watch a solve's iterates, may stop it;
* `local`: one problem, one guess, one profile -> a Solution (NLPs built and prepared once per worker);
* `starts`, `tasks`: typed tasks (case, stage, problem, transcription, profile, start, continuation), fanned out;
* `search`, `strategies`: which tasks a search solves, stage by stage (multistart, coarse to fine; the
  degenerate-design continuation and the structure-neighbour starts serve both); named presets;
* `optima`: distinct local optima and the best solution.
"""

from designopt.solve.local import solve_guess
from designopt.solve.optima import best_solution, cluster_designs, design_distance, distinct_best
from designopt.solve.profile import SolverProfile
from designopt.solve.search import PRESETS, Job, Search, Searched, preset
from designopt.solve.starts import Lifted, Seeded, lifted_guess
from designopt.solve.strategies import run_search
from designopt.solve.tasks import Task, fan_out, run_task

__all__ = ["PRESETS", "Job", "Lifted", "Search", "Searched", "Seeded", "SolverProfile", "Task", "best_solution",
           "cluster_designs", "design_distance", "distinct_best", "fan_out", "lifted_guess", "preset", "run_search",
           "run_task", "solve_guess", "solve_one"]


def solve_one(problem, start: Seeded | Lifted | None = None, transcription=None, profile: SolverProfile | None = None,
              hold_degenerate: bool = True):
    """Solve one problem from one start (default: start 0 of seed 0, TO, the default profile; a solve stalled on a
    degenerate design finished held) -- the library's shortest way to an answer; a search (`run_search`) is the
    way to a good one."""
    from designopt.solve.strategies.steps import solve_setup
    from designopt.transcriptions import Collocation

    job = Job("", problem, transcription or Collocation())
    profile, continuation = solve_setup(job, Search(hold_degenerate=hold_degenerate), profile or SolverProfile())
    return run_task(Task("", "start", problem, job.transcription, profile, start or Seeded(0, 0), continuation))
