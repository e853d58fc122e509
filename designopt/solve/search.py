"""The search: how a set of problems is solved, from which starts, on which paths, and when to stop.

Local optima are everywhere in design problems: the same task from different seeded starts ends anywhere between
the best design known and thousands of times its cost. A `Search` names a strategy (one module each under
`designopt.solve.strategies`) and its budget; `PRESETS` are the named searches a config picks
(``search: {preset: ...}``). What a search is given is a list of `Job`s (the problems an experiment describes);
what it returns is one `Searched` per job. `designopt.solve.strategies.run_search` drives it.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace

from designopt.initial_guess import STARTS_PER_SEED, start_index
from designopt.problem import DesignProblem
from designopt.solution import Solution
from designopt.solve.observers import StalledViolation
from designopt.solve.optima import best_solution
from designopt.solve.profile import SolverProfile
from designopt.solve.tasks import Task
from designopt.transcriptions import Collocation

DRAW_STRIDE = 1_000_000
"""Seeds apart of a search's independent draws (`Search.draw_seeds`): far enough that their start numbers (seed x 1000
+ index, `designopt.initial_guess.start_number`) never meet, however many indices a draw uses."""

SMALL_ARM = 5
"""Moving joints below which an arm cannot track the path's 5 degrees of freedom (the tool's position and its axis's
direction; its spin is free) on a general design: its designs are structural, often far from a generic start."""


def small_arm(moving_joints: int) -> bool:
    """Whether an arm of ``moving_joints`` moving joints is small: fewer than `SMALL_ARM`."""
    return moving_joints < SMALL_ARM


@dataclass(frozen=True)
class Search:
    """A strategy and its budget. Counts are per problem; iteration caps per solve.

    ``multistart``: ``starts`` seeded cold starts on the full path. ``coarse_to_fine``, stage by stage (each
    field's comment says what it sets; the stage names are those of a run's ``summary.csv``):

    1. ``explore``: ``starts`` seeded starts on ``explore_waypoints`` of the path's waypoints, then a second round
       on new joint branches from the best distinct coarse optima (the leaders), explored alike;
    2. ``prescreen``: the next-best distinct coarse optima solved warm on ``prescreen_waypoints``, the best kept;
    3. ``screen``: the best distinct coarse optima (and the kept prescreened ones) re-ranked on
       ``screen_waypoints``, once per pass (`screen_passes`);
    4. ``refine``: the best distinct screened optima solved on the full path, once per barrier of
       ``refine_mu_init``, the best ones once more through relaxed velocity limits (``relax``);
    5. after the strategy, for either: a start from each neighbouring structure's better design, restarts around
       the best (``hop``), reflections across length bounds (``reflect``).

    Designs within ``distinct`` (m or rad) in every design joint are one optimum (`optima.cluster_designs`); a form
    is the pattern of an arm's joint axes (`optima.distinct_best`). Settings that were measured and not adopted by
    any preset (docs/decisions.md says what each did) are kept as options: a variant is judged by setting them.
    """

    # -- the starts ---------------------------------------------------------------------------------------------
    #: ``coarse_to_fine`` (`strategies.coarse_to_fine`) or ``multistart`` (`strategies.multistart`).
    strategy: str = "coarse_to_fine"
    #: Seeded starts of the exploration (``multistart``: on the full path).
    starts: int = 80
    #: The seed the starts are numbered and drawn from (`initial_guess.start_number`).
    seed: int = 0
    #: How far a perturbed start's design moves from the configured one: x 0.5 m for lengths, x pi for angles.
    perturbation: float = 0.3
    #: How seeded starts spread their designs: ``perturb`` (by ``perturbation``), ``box`` (drawn from the task's
    #: box, `initial_guess.box_design`) or ``mixed`` (odd starts from the box).
    spread: str = "perturb"
    #: How a start's joints reach the path: ``ik``, ``home`` (the IK walk pulled towards the first waypoint's
    #: configuration), ``reach`` or ``constant`` (`designopt.initial_guess`).
    init: str = "ik"

    # -- the exploration ----------------------------------------------------------------------------------------
    #: Waypoints of the exploration's coarse path.
    explore_waypoints: int = 10
    #: Iteration cap of each exploration solve (both rounds).
    explore_max_iter: int = 250
    #: The exploration's linear solver instead of the profile's (None: the profile's; `SolverProfile.linear_solver`).
    explore_linear_solver: str | None = None
    #: Factor the exploration's solves scale the objective by while they iterate (`SolverProfile.objective_scale`;
    #: 1: none).
    explore_objective_scale: float = 1.0

    # -- the second round on new joint branches (`strategies.coarse_to_fine`, `starts.Rebranched`) ---------------
    #: Leaders: the best distinct coarse optima restarted on new joint branches (the optimum's design, first joints
    #: drawn over the whole circle), ``starts // rebranch`` times each (`rebranch_starts`; at least once); 0: none.
    rebranch: int = 8
    #: At most this many leaders of one form before other forms (None: by cost alone).
    rebranch_per_form: int | None = None
    #: Also the cheapest optimum of each of up to this many forms not among the leaders.
    rebranch_new_forms: int = 0
    #: The leader of rank k restarted as many times as its k-th entry, where there is one (`leader_starts`).
    rebranch_shares: tuple[int, ...] | None = None
    #: Rounds on new joint branches, each from the best of every round before it, sharing ``starts // rebranch``
    #: per leader.
    rebranch_rounds: int = 1
    #: > 1: a leader's starts taken from this many times as many drawn, spread over the branches where their walks
    #: reach the path's first waypoint (`starts.spread_branches`).
    rebranch_pool: int = 1
    #: Starts more per leader, spread over the branches its drawn ones miss, out of ``rebranch_extra_pool`` drawn
    #: in a block of their own (`more_start`).
    rebranch_extra: int = 0
    rebranch_extra_pool: int = 40
    #: > 0: the extras' designs moved around the leader's by this scale (as ``perturbation``).
    rebranch_extra_perturbation: float = 0.0
    #: The extras from the leader's design with its arm's angles (twists) at the nearest multiple of pi/2, the
    #: idealised arm of its form (`optima.snapped_design`), before any move.
    rebranch_extra_snap: bool = False
    #: Starts more again per leader, their designs moved around the leader's by ``rebranch_moved_perturbation``,
    #: spread over the branches all its other starts miss, out of ``rebranch_moved_pool`` drawn (`more_blocks`).
    rebranch_moved: int = 0
    rebranch_moved_pool: int = 20
    rebranch_moved_perturbation: float = 0.1

    # -- the screen and its prescreen (`strategies.coarse_to_fine.best_prescreened`) ----------------------------
    #: Waypoints the candidates are re-ranked on (skipped when the path has no more than this).
    screen_waypoints: int = 40
    #: Candidates: the best distinct optima of both rounds.
    screen: int = 12
    #: At most this many candidates of one form before other forms (None: by cost alone).
    screen_per_form: int | None = None
    #: Also the cheapest distinct optimum of each of up to this many second-round leaders whose starts have none
    #: among the candidates (`leader_of`).
    screen_new_leaders: int = 0
    #: Iteration cap of each screen solve.
    screen_max_iter: int = 300
    #: > 0: the next this-many distinct coarse optima solved warm on ``prescreen_waypoints`` as the screen's first
    #: pass solves (stage ``prescreen``; skipped when the screen's waypoints are no more), the best
    #: ``prescreen_keep`` of them screened too.
    prescreen: int = 0
    prescreen_keep: int = 8
    prescreen_waypoints: int = 20
    #: How a prescreened candidate is screened: from its ``coarse`` optimum, from its ``prescreened`` optimum
    #: (10, 20, then 40 waypoints), or ``both`` (screen passes of their own; the candidate's best pass kept).
    screen_prescreened: str = "coarse"
    #: The screen's linear solvers: each candidate screened once by each (None: the profile's; `screen_passes`).
    screen_linear_solver: tuple[str | None, ...] = (None,)
    #: The screen's barriers (IPOPT's ``mu_init``; None: the warm start's): each candidate screened once from
    #: each (stages ``screen``, ``screen2``, ...), ranked for the refine by its better pass.
    screen_mu_init: tuple[float | None, ...] = (None,)

    # -- the refine on the full path (solver profile ``profile``) ------------------------------------------------
    #: Distinct screened optima refined on the full path.
    refine: int = 4
    #: The refine's barriers (None: the warm start's own, 1e-4, `designopt.solve.backends.ipopt`), each candidate
    #: refined once per value (stages ``refine``, ``refine2``, ...; the answer is the best of all): from a small one
    #: a refine stays in its screened start's basin, from the warm start's it sometimes walks into a better one and
    #: more often into a worse one.
    refine_mu_init: tuple[float | None, ...] = (None,)
    #: Each refined candidate refined once more from its coarse optimum lifted straight to the full path, warm from
    #: the warm start's barrier (the stage after the barriers' passes): a screened solution fits the screen's
    #: waypoints and may leave the path between them faster than the velocity limits allow.
    refine_from_coarse: bool = False
    #: Each of this many best refined candidates (0: none) whose lifted start steps further than the velocity limits
    #: allow (by r, the largest step over v_max h) refined once more through relaxed limits: warm with every limit
    #: times 1.05 r (stage ``relax``), times sqrt(1.05 r) from barrier 1e-6 (``relax2``), then at the limits from
    #: 1e-6 (the stage after the other refines); the relaxed solves are not answers.
    refine_relaxed: int = 0
    #: The refine's candidates distinct arms whichever way their joint axes point: with ``same_arm_cost``, a
    #: candidate whose arm is a cheaper one's written otherwise (`optima.arm_invariants`: lengths by size, twists as
    #: angles between lines; a DH arm's reflections, its twists turned by pi about zero offsets) at a screen cost
    #: within that fraction is that candidate, and the next distinct arm takes its place.
    refine_distinct_arms: bool = False
    #: The full-path solves' solver profile (the exploration's and the screen's derive from it).
    profile: SolverProfile = field(default_factory=SolverProfile)

    # -- what makes two optima one ------------------------------------------------------------------------------
    #: Designs within this (m or rad) in every design joint are one optimum.
    distinct: float = 0.02
    #: Two designs whose arms (every design joint but the placement's) lie within ``distinct`` and whose design
    #: costs within this fraction of the cheaper's are one optimum too: the same arm placed elsewhere (a path's
    #: symmetry turns a placement about a circle's axis; a flat valley slides it). None: off.
    same_arm_cost: float | None = None

    # -- after the strategy -------------------------------------------------------------------------------------
    #: A solve stalled on a degenerate design is finished with the design held there (`strategies.continuation`).
    hold_degenerate: bool = True
    #: One more start per problem from each neighbouring structure's better design (structures that differ in one
    #: joint's type, or by one joint, are neighbours; `strategies.neighbours`).
    structure_neighbours: bool = True
    #: Restarts around each of the ``hop_incumbents`` best distinct full-path optima, on a new joint branch with the
    #: design moved by ``hop_perturbation`` (as ``perturbation``), solved on the screen's waypoints (stage ``hop``),
    #: the ``hop_refine`` best distinct of them refined on the full path (stage ``hop_full``; `strategies.hop`);
    #: 0: none.
    hop: int = 0
    hop_incumbents: int = 2
    hop_perturbation: float = 0.1
    hop_refine: int = 6
    #: Rounds (stages ``reflect``, ``reflect2``, ...) in which each problem's best full-path solution is reflected
    #: across the length bounds it lies at (the same arm with that length's sign flipped) and solved warm
    #: (`strategies.reflect`); 0: none.
    reflect: int = 0
    #: The first round reflects every distinct full-path optimum within this factor of the problem's best (None: the
    #: best alone).
    reflect_within: float | None = None

    # -- a search of several problems (a sweep's structures) ----------------------------------------------------
    #: Small arms (fewer than `SMALL_ARM` moving joints, `small_arm`): screened by the first pass only
    #: (`passes_for`; a small arm's passes end in one basin).
    small_arm_screens_once: bool = False
    #: Small arms' ``perturbation`` (None: ``perturbation``; `perturbation_for`).
    small_arm_perturbation: float | None = None
    #: Small arms' exploration starts times this, after ``small_problem_starts``' share (`starts_for`); their screen
    #: as that share gives it. A small arm's best family can be the coarse optimum of about one start in a hundred,
    #: and when reached ranks first on the coarse path.
    small_arm_starts: float = 1.0
    #: A problem with fewer unknowns than the largest gets as many exploration starts as cost about what the
    #: largest one's ``starts`` cost, at most this many times ``starts`` (its share, `shares`), and screens as many
    #: times more candidates on as many more waypoints as keep its screen the largest one's size (`screening`;
    #: both in `strategies.coarse_to_fine`); 1: every problem ``starts``, ``screen`` and ``screen_waypoints``.
    small_problem_starts: float = 1.0

    #: Independent draws of the whole search (`draw_seeds`), the answer the best of them.
    draws: int = 1

    def __post_init__(self):
        if self.screen_prescreened not in SCREEN_PRESCREENED:
            raise ValueError(f"screen_prescreened must be one of {', '.join(SCREEN_PRESCREENED)}, "
                             f"got {self.screen_prescreened!r}")
        if self.draws < 1:
            raise ValueError(f"draws must be at least 1, got {self.draws}")

    @property
    def draw_seeds(self) -> list[int]:
        """The seeds of the ``draws`` independent draws: ``seed``, then ``seed`` + k x `DRAW_STRIDE`."""
        return [self.seed + k * DRAW_STRIDE for k in range(self.draws)]

    @property
    def explore_profile(self) -> SolverProfile:
        """How the exploration's solves (both rounds) are solved: the profile capped at ``explore_max_iter``, by
        ``explore_linear_solver``, the objective scaled by ``explore_objective_scale``."""
        return (self.profile.capped(self.explore_max_iter).solved_by(self.explore_linear_solver)
                .scaled(self.explore_objective_scale))

    def drawn(self) -> list[Search]:
        """The ``draws`` independent draws, each this search of one draw with its seed (`draw_seeds`)."""
        return [replace(self, seed=seed, draws=1) for seed in self.draw_seeds]

    def draw_of(self, number):
        """Which draw (0-based, `draw_seeds`) the start numbered ``number`` (an int or an array of them) belongs to;
        a lifted or continued solve keeps its start's number, so every solve of a draw is told by it."""
        return start_index(number, self.seed) // (DRAW_STRIDE * STARTS_PER_SEED)

    def index_in_draw(self, number):
        """The index of the start numbered ``number`` (an int or an array of them) among its own draw's starts
        (`initial_guess.start_index` for the draw's seed; the same as for ``seed`` in a search of one draw)."""
        return start_index(number, self.seed) % (DRAW_STRIDE * STARTS_PER_SEED)

    @property
    def rebranch_starts(self) -> int:
        """Starts on new joint branches per rebranched optimum: the rounds on new joint branches together as large as
        the first (``rebranch_rounds`` of them, each from the best distinct optima of every round before it)."""
        return max(1, self.starts // (self.rebranch * self.rebranch_rounds)) if self.rebranch else 0

    def leader_starts(self, rank: int) -> int:
        """A round's starts on new joint branches from its leader of ``rank`` (0: the cheapest):
        ``rebranch_shares[rank]`` where set and long enough, else ``rebranch_starts`` (a new form's leader, after the
        ``rebranch`` leaders, too)."""
        if self.rebranch_shares is not None and rank < len(self.rebranch_shares):
            return self.rebranch_shares[rank]
        return self.rebranch_starts

    @property
    def most_starts(self) -> int:
        """The most exploration starts one problem gets (`exploration_starts`): the second round's start indices
        follow them."""
        return math.ceil(self.starts * max(self.small_problem_starts, 1.0) * max(self.small_arm_starts, 1.0))

    @property
    def leaders(self) -> int:
        """The most leaders a round on new joint branches has: ``rebranch`` and ``rebranch_new_forms``."""
        return self.rebranch + self.rebranch_new_forms

    @property
    def more_blocks(self) -> tuple[tuple[int, int, float, bool], ...]:
        """The blocks of starts more per leader of a round on new joint branches, beside its drawn ones, in the
        order they join them and are numbered (`more_start`): (how many, out of how many drawn, the scale the
        design is moved by, whether the leader's arm angles are snapped first: `starts.Rebranched`) for the extras
        (``rebranch_extra``), then the moved starts (``rebranch_moved``)."""
        return ((self.rebranch_extra, self.rebranch_extra_pool, self.rebranch_extra_perturbation,
                 self.rebranch_extra_snap),
                (self.rebranch_moved, self.rebranch_moved_pool, self.rebranch_moved_perturbation, False))

    @property
    def leader_drawn(self) -> int:
        """The start indices a leader's drawn starts take in one round on new joint branches: the most starts any
        leader has (`leader_starts`), drawn ``rebranch_pool`` times over."""
        return self.rebranch_pool * max([self.rebranch_starts, *(self.rebranch_shares or ())])

    @property
    def leader_width(self) -> int:
        """The start indices one leader takes in one round on new joint branches: its drawn starts
        (`leader_drawn`), then the pool of every block of `more_blocks` that adds any start."""
        return self.leader_drawn + sum(size for count, size, *_ in self.more_blocks if count > 0)

    def leader_start(self, r: int, rank: int) -> int:
        """The first start index of round ``r``'s leader of ``rank`` (0: the cheapest) on new joint branches, the
        first of its drawn starts: ``most_starts``, then one block of `leader_width` per leader and round, by rank
        first, so that a leader's starts keep their numbers whatever the count of leaders after it (e.g. more new
        forms, ``rebranch_new_forms``)."""
        return self.most_starts + (rank * self.rebranch_rounds + r) * self.leader_width

    def more_start(self, block: int, r: int, rank: int) -> int:
        """The first start index of the pool drawn for block ``block`` of `more_blocks` for round ``r``'s leader
        of ``rank``: in that leader's block (`leader_start`), after its drawn starts and the pools of the earlier
        blocks that add any start."""
        earlier = sum(size for count, size, *_ in self.more_blocks[:block] if count > 0)
        return self.leader_start(r, rank) + self.leader_drawn + earlier

    def hop_start(self, rank: int) -> int:
        """The first start index of the hops around the full-path optimum of ``rank`` (`strategies.hop`): after
        every index the exploration can use (`last_exploration_start`), ``hop`` per optimum."""
        return self.last_exploration_start + rank * self.hop

    @property
    def last_start(self) -> int:
        """One past the largest start index the exploration and the hop step can use (`hop_start`)."""
        return self.hop_start(self.hop_incumbents if self.hop else 0)

    @property
    def last_exploration_start(self) -> int:
        """One past the largest start index the exploration can use: every leader's block in every round on new
        joint branches (`leader_start`)."""
        if not self.rebranch:
            return self.most_starts
        return self.leader_start(0, self.leaders)

    def leader_of(self, number) -> int | None:
        """The rank of the second-round leader whose block (`leader_start`) holds the exploration start numbered
        ``number``; None for a start of the first round or past the exploration's numbers. In any draw."""
        index = self.index_in_draw(number)
        if not self.most_starts <= index < self.last_exploration_start:  # empty without leaders
            return None
        return (index - self.most_starts) // (self.rebranch_rounds * self.leader_width)

    def second_round(self, number):
        """Whether the exploration start numbered ``number`` (an int or an array of them) is of the second round,
        on a new joint branch: its index in its draw (`index_in_draw`) from ``most_starts`` on
        (`rebranched_tasks`)."""
        return self.index_in_draw(number) >= self.most_starts

    @property
    def screen_passes(self) -> list[tuple[float | None, str | None]]:
        """The screen's passes, (barrier, linear solver) each: every barrier of ``screen_mu_init`` by every linear
        solver of ``screen_linear_solver``, barriers outer; pass i is stage `numbered_stage("screen", i)`."""
        return [(mu, solver) for mu in self.screen_mu_init for solver in self.screen_linear_solver]

    def perturbation_for(self, moving_joints: int) -> float:
        """The seeded starts' perturbation for an arm of ``moving_joints`` moving joints: ``small_arm_perturbation``
        for a small arm (`small_arm`), when set, else ``perturbation``."""
        if self.small_arm_perturbation is not None and small_arm(moving_joints):
            return self.small_arm_perturbation
        return self.perturbation

    def starts_for(self, moving_joints: int, share: int) -> int:
        """The exploration starts of an arm of ``moving_joints`` moving joints whose share of the batch is ``share``
        (`strategies.coarse_to_fine.exploration_starts`): ``small_arm_starts`` times it for a small arm
        (`small_arm`), else the share."""
        return round(share * self.small_arm_starts) if small_arm(moving_joints) else share

    def passes_for(self, moving_joints: int) -> list[tuple[float | None, str | None]]:
        """The screen's passes for an arm of ``moving_joints`` moving joints: every one of `screen_passes`, or only
        the first for a small arm (`small_arm`) when ``small_arm_screens_once``."""
        passes = self.screen_passes
        return passes[:1] if self.small_arm_screens_once and small_arm(moving_joints) else passes

    def describe(self) -> str:
        """The search in words."""
        if self.draws > 1:
            return (f"{self.draws} independent draws (seeds {', '.join(str(s) for s in self.draw_seeds)}), the best of "
                    f"them, each {replace(self, draws=1).describe()}")
        held = "; a solve stalled on a degenerate design is finished held" if self.hold_degenerate else ""
        options = ", ".join(f"{k.removeprefix('ipopt.')} {v}" for k, v in self.profile.options)
        solver = f"; IPOPT options {options}" if options else ""  # what the profile sets beyond the backend's own
        if self.profile.linear_solver != "mumps":
            solver += f"; KKT systems by {self.profile.linear_solver}"
        cap = f"<= {self.profile.max_iter} iterations"
        drawn = {"perturb": "", "box": " drawn from the task's box",
                 "mixed": " (every other one drawn from the task's box)"}[self.spread]
        if self.small_arm_perturbation is not None:
            drawn += f" (an arm of fewer than {SMALL_ARM} joints perturbed by {self.small_arm_perturbation:g})"
        if self.small_arm_starts != 1.0:
            drawn += f" ({self.small_arm_starts:g}x as many for an arm of fewer than {SMALL_ARM} joints)"
        if self.init == "home":
            drawn += " (their IK walks pulled towards the first waypoint's configuration)"
        which = ("the best" if self.reflect_within is None else
                 f"every distinct optimum within {self.reflect_within:g}x of the best (later rounds the best)")
        reflect = (f", then {which} reflected across its length bounds (up to {self.reflect} rounds)" if self.reflect
                   else "")
        if self.hop:
            reflect = (f", then {self.hop} restarts around each of the best {self.hop_incumbents} distinct optima with "
                       f"the design moved by {self.hop_perturbation:g}, on the screen's waypoints, the best "
                       f"{self.hop_refine} of them refined{reflect}")
        if self.strategy == "multistart":
            stall = f"; a TO start no closer to the path for {StalledViolation.PATIENCE} iterations is stopped"
            return (f"multistart: {self.starts} seeded starts{drawn} on the full path ({cap}){stall}{reflect}{held}"
                    f"{solver}")
        capped = f" (at most {self.screen_per_form} of one form)" if self.screen_per_form is not None else ""
        if self.screen_new_leaders:
            capped += f" and the best of up to {self.screen_new_leaders} second-round leaders' starts not among them"
        if self.small_problem_starts > 1:
            capped += " (a smaller problem's more, on more waypoints, in proportion)"
        if self.prescreen:
            capped += (f" and the best {self.prescreen_keep} of the next {self.prescreen} re-ranked on "
                       f"{self.prescreen_waypoints} waypoints (as the screen's first pass"
                       f"{SCREENED_FROM[self.screen_prescreened]}),")
        screen = (f", the best {self.screen} distinct{capped} re-ranked on {self.screen_waypoints} waypoints "
                  f"(<= {self.screen_max_iter} iterations{_barriers(self.screen_mu_init)}"
                  f"{self._kkt(self.screen_linear_solver)}{self._repeated()}, if the path has more)"
                  if self.screen_waypoints else "")
        per_form = (f" (at most {self.rebranch_per_form} of one form)" if self.rebranch_per_form is not None
                    else "")
        if self.rebranch_new_forms:
            per_form += f" and the best of up to {self.rebranch_new_forms} forms not among them"
        times = (f"{self.rebranch_starts} times each" if self.rebranch_shares is None else
                 f"{', '.join(str(n) for n in self.rebranch_shares)} times by rank")
        if self.rebranch_rounds > 1:
            times += f", in {self.rebranch_rounds} rounds, each from the best of every round before it,"
        if self.rebranch_pool > 1:
            times += (f" (spread over the branches of {self.rebranch_pool}x as many drawn, by their first "
                      f"waypoint's configuration)")
        if self.rebranch_extra:
            times += (f" and {self.rebranch_extra} more spread over the branches those miss (of "
                      f"{self.rebranch_extra_pool} drawn)")
            if self.rebranch_extra_snap:
                times += " from the leader's design with its arm's angles at the nearest multiple of pi/2"
            if self.rebranch_extra_perturbation:
                times += f" with the design perturbed by {self.rebranch_extra_perturbation:g}"
        if self.rebranch_moved:
            times += (f" and {self.rebranch_moved} more with the design moved by {self.rebranch_moved_perturbation:g}"
                      f", spread over the branches all those miss (of {self.rebranch_moved_pool} drawn)")
        again = (f", the best {self.rebranch} distinct{per_form} restarted {times} on a new joint branch"
                 if self.rebranch else "")
        kkt = self._kkt((self.explore_linear_solver,))
        if self.explore_objective_scale != 1.0:
            kkt += f", the objective scaled by {self.explore_objective_scale:g}"
        barrier = _barriers(self.refine_mu_init)
        if self.refine_from_coarse and self.screen:
            barrier += ", and once from its coarse optimum"
        if self.refine_relaxed:
            which = "each" if self.refine_relaxed >= self.refine else f"the best {self.refine_relaxed}"
            barrier += f", and {which} once through velocity limits relaxed to fit its lifted start"
        if self.small_problem_starts > 1:
            drawn += (f" (a problem smaller than the largest up to {self.small_problem_starts:g}x as many, "
                      f"about its cost)")
        same = (f"; the same arm within {self.same_arm_cost:.1%} of a cheaper one's cost one optimum"
                if self.same_arm_cost is not None else "")
        if self.same_arm_cost is not None and self.refine_distinct_arms:
            same += " (the refine's whichever way its joint axes point)"
        return (f"coarse to fine: {self.starts} starts{drawn} on {self.explore_waypoints} waypoints (<= "
                f"{self.explore_max_iter} iterations{kkt}){again}{screen}, the best {self.refine} distinct optima "
                f"refined on the full path ({cap}{barrier}){reflect}{same}{held}{solver}")

    def _repeated(self) -> str:
        """Which arms the screen's passes after the first are for, in words (`passes_for`)."""
        if len(self.screen_passes) < 2 or not self.small_arm_screens_once:
            return ""
        return f"; an arm of fewer than {SMALL_ARM} joints the first pass only"

    def _kkt(self, linear_solvers: tuple[str | None, ...]) -> str:
        """A stage's linear solvers in words (None: the profile's): one, only where it is not the profile's; several,
        each candidate solved once by each."""
        names = [solver or self.profile.linear_solver for solver in linear_solvers]
        if len(names) > 1:
            return f", each candidate once with KKT systems by {' and once by '.join(names)}"
        return f", KKT systems by {names[0]}" if names[0] != self.profile.linear_solver else ""


def _barriers(mu_init: tuple[float | None, ...]) -> str:
    """A stage's barriers in words (`Search.screen_mu_init`, `Search.refine_mu_init`); nothing for the warm start's."""
    if mu_init == (None,):
        return ""
    return ", each from barrier " + " and ".join(f"{mu:g}" if mu is not None else "the warm start's" for mu in mu_init)


# IPOPT options for design spaces whose tracking Jacobian goes rank-deficient on the way: a structure with fewer
# than six joints tracks a path only on a degenerate design, and prismatic joints line up. There IPOPT's multipliers
# blow up (dual infeasibility 1e5-1e12) and a solve creeps to its cap. These regularise the constraint block of
# every KKT system (delta_c = 1e-8 mu^0.25, what IPOPT does anyway once it has found the Jacobian degenerate) and
# step the multipliers to reduce the dual infeasibility. On the K = I sweep (seed 0): 1,473 instead of 2,113 of the
# 5,040 exploration solves at the cap, 0.71x the solver CPU, 61 of 123 structure bests lower and 23 higher. On the
# main job (six revolute joints, default search) they made the answer worse (docs/decisions.md, 2026-11-24).
REGULARISED_CONSTRAINTS = (("ipopt.perturb_always_cd", "yes"),)
DEGENERATE_JACOBIAN = (*REGULARISED_CONSTRAINTS, ("ipopt.alpha_for_y", "min-dual-infeas"))

# how the prescreened candidates are screened (`Search.screen_prescreened`), as `describe` says it
SCREENED_FROM = {"coarse": "", "prescreened": ", screened from there", "both": ", screened from there and from 10"}
SCREEN_PRESCREENED = tuple(SCREENED_FROM)

# the paper's comparisons: every method gets the same seeded cold starts on the full path, start for start
PAPER = Search(strategy="multistart", starts=8, profile=SolverProfile(max_iter=1500, time_limit=120.0))

# `designopt run`: 160 starts on 10 waypoints walked home, explored with the LDLᵀ; a second round on new joint branches
# from the 8 best distinct coarse optima and the best of up to 4 forms not among them (20 drawn starts each, 30 more
# over the branches those miss, 10 more with the design moved by 0.1); the 24 best distinct coarse optima and the best
# 8 of the next 48 (prescreened on 20 waypoints) screened on 40 waypoints from two barriers, those 8 from their
# 20-waypoint optima too; the best 4 distinct arms (whichever way their axes point) refined on the full path from two
# barriers, the best of them once more through relaxed velocity limits where its lifted start steps beyond them; every
# refined optimum within 1.05x of the best reflected across its length bounds, then the best (3 rounds at most); the
# same arm placed elsewhere at a cost within 0.2 % one optimum. Each setting was judged on evaluation seeds never tuned
# on, against the preset before it (seeds better / worse, solve time): docs/benchmarks.md "Search", docs/decisions.md.
DEFAULT = Search(starts=160, screen=24, init="home", explore_linear_solver="ldl", screen_mu_init=(None, 1e-6),
                 refine_mu_init=(None, 1e-6), rebranch_new_forms=4, reflect=3, reflect_within=1.05, rebranch_extra=30,
                 rebranch_extra_pool=50, same_arm_cost=0.002, rebranch_moved=10, prescreen=48, refine_relaxed=1,
                 screen_prescreened="both", refine_distinct_arms=True)

PRESETS: dict[str, Search] = {
    # A structure sweep's search per structure (`designopt sweep-structures`): a quarter of the default's starts,
    # tighter caps and no second round on new joint branches; IPOPT set for degenerate Jacobians (most of a sweep's
    # structures have fewer than six joints or prismatic ones); the exploration and the screen (20 waypoints) by the
    # LDLᵀ, each candidate screened a second time by MUMPS where the arm has 5 or more joints and ranked by its
    # better pass; the best 4 refined; each structure's best reflected across its length bounds. An arm of fewer
    # joints gets more starts and screens (`small_problem_starts`, `screening`); below 5 joints perturbed by 0.6 and
    # twice its share of the starts (`small_arm_starts`). Each setting was judged on fresh seeds against the preset
    # before it (whole sweeps; the small arms' doubled starts on 20 seeds of each small reference structure searched
    # alone): docs/benchmarks.md "Sweep", docs/decisions.md. Its blocks compiled at -O1 where first needed, in parts
    # (`designopt.transcriptions.compiled.split_statements`), not tiered: a structure is solved for about 20 s, too
    # short to tier up, and its solves at -O1 take 0.85x the CPU of -O0's for about 1.3 s more gcc a structure
    # (the 5-joint structures 0.954x the wall, every solve the same; docs/decisions.md, Speed, 2026-12-07).
    "quick": Search(starts=40, rebranch=0, screen=12, screen_waypoints=20, refine=4, reflect=3, small_problem_starts=4,
                    explore_linear_solver="ldl", screen_linear_solver=("ldl", "mumps"), small_arm_screens_once=True,
                    small_arm_perturbation=0.6, small_arm_starts=2,
                    profile=SolverProfile(max_iter=600, time_limit=60.0, options=DEGENERATE_JACOBIAN, compile="O1")),
    "default": DEFAULT,
    # a best design worth three times the wait: the default made three times independently, the best of the three
    # (`Search.draws`); what it reaches is estimated from the default's evaluation runs taken three at a time
    # (docs/benchmarks.md "Search", "`thorough`: three draws")
    "thorough": replace(DEFAULT, draws=3),
    "paper": PAPER,
    # an existing arm whose starts cross singular configurations: few basins, so 4 cold starts on the full program,
    # and IPOPT's constraint block regularised from the first iteration (at a singular configuration the position
    # rows go dependent; their multipliers grew to 1e13 on configs/gcode_pocket.yaml, 4 starts 39 -> 13 s). A per-job
    # choice: on the Button program the PUMA took 1.8x as long for a 0.70x design and the Kinova did worse on every
    # count; in the default search it moved the answers both ways (docs/decisions.md, 2026-11-25)
    "production": replace(PAPER, starts=4, profile=replace(PAPER.profile, options=REGULARISED_CONSTRAINTS)),
}


def search_to_dict(search: Search) -> dict:
    """Every field of ``search``, its profile's too, as plain values (tuples stay tuples; JSON writes them as
    lists): what a run writes to its search.json, so that a run says the search it made after a preset changes."""
    return asdict(search)


def search_from_dict(data: dict) -> Search:
    """The search a `search_to_dict` dict (or its JSON, lists for tuples) describes. Raises ValueError for a field
    `Search` or `SolverProfile` does not have (a file of another version)."""
    def tuples(value):
        return tuple(tuples(v) for v in value) if isinstance(value, list | tuple) else value

    for cls, given in ((Search, data), (SolverProfile, data.get("profile", {}))):
        unknown = set(given) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f"{cls.__name__} has no field {', '.join(sorted(unknown))}")
    values = {k: tuples(v) for k, v in data.items() if k != "profile"}
    profile = SolverProfile(**{k: tuples(v) for k, v in data.get("profile", {}).items()})
    return Search(**values, profile=profile)


def preset(name: str, **overrides) -> Search:
    """A named search with some fields replaced (e.g. ``seed``, ``starts``)."""
    if name not in PRESETS:
        raise ValueError(f"unknown search preset {name!r} ({', '.join(PRESETS)})")
    return replace(PRESETS[name], **overrides)


@dataclass(frozen=True, eq=False)
class Job:
    """One problem to search: what an experiment describes. ``case`` names it in the run's files (jobs of one
    search differ in case, method or structure); ``transcription`` is how it becomes an NLP (TO by default)."""

    case: str
    problem: DesignProblem
    transcription: object = field(default_factory=Collocation)

    @property
    def tracks_exactly(self) -> bool:
        """Whether the transcription holds the tool on the path at every waypoint (TO): its constraint violation is
        then the distance to the path, and a design can degenerate the way hard equalities do."""
        return getattr(self.transcription, "exact_tracking", False)

    @property
    def identity(self) -> tuple[str, str, str]:
        return self.case, self.transcription.name, self.problem.chain.structure


@dataclass(frozen=True, eq=False)
class Searched:
    """What a search of one job solved: ``explore`` (solves on coarser paths, empty for ``multistart``) and
    ``final`` (full-path solves, the ones an answer is chosen from), each as (task, solution) in start order."""

    job: Job
    explore: list[tuple[Task, Solution]]
    final: list[tuple[Task, Solution]]

    @property
    def best(self) -> tuple[Task | None, Solution | None]:
        """(task, solution) of the best tracking full-path solve, or (None, None)."""
        best = best_solution([sol for _, sol in self.final])
        return next(((t, s) for t, s in self.final if s is best), (None, None))


def by_job(jobs: list[Job], done: list[tuple[Task, Solution]]) -> list[list[tuple[Task, Solution]]]:
    """Split (task, solution) pairs by the job they belong to, each list in start order."""
    where = {job.identity: k for k, job in enumerate(jobs)}
    out = [[] for _ in jobs]
    for task, sol in done:
        out[where[task.case, task.method, task.problem.chain.structure]].append((task, sol))
    return [sorted(d, key=lambda d: d[0].seed) for d in out]
