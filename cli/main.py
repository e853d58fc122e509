"""designopt command line: parses arguments, calls the library, prints. No logic lives here."""

from __future__ import annotations

import functools
import sys
import time
import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from designopt.config import load_config
from designopt.errors import InputError, InputWarning
from designopt.verify import SolutionFileError

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Design a robot and its cell in one trajectory optimization.")
out = Console(soft_wrap=True)
err = Console(stderr=True, soft_wrap=True)
# Errors that are the user's input: one line, exit 2. Anything else is a bug and keeps its traceback.
USER_ERRORS = (InputError, SolutionFileError)


def _warn(message, category, filename, lineno, file=None, line=None) -> None:
    if issubclass(category, InputWarning):
        err.print(f"[yellow]warning:[/yellow] {message}", highlight=False)
    else:
        _show_warning(message, category, filename, lineno, file, line)


_show_warning = warnings.showwarning


@app.callback()
def _group() -> None:
    """Design a robot and its cell in one trajectory optimization."""
    warnings.showwarning = _warn
    # joblib's process pool (loky) replaces a worker whose memory grew by 300 MB (the NLPs it keeps built) and
    # says so as "a memory leak"; the worker's tasks are not lost and the results are the same.
    warnings.filterwarnings("ignore", message="A worker stopped while some jobs were given to the executor",
                            category=UserWarning)


def fail(message: str) -> None:
    """A user error: one line on stderr, exit code 2, no traceback."""
    err.print(f"[red]error:[/red] {message}", highlight=False)
    raise typer.Exit(code=2)


def user_errors(command):
    """Turn bad input found anywhere below a command into one line and exit code 2."""

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        try:
            return command(*args, **kwargs)
        except USER_ERRORS as exc:
            fail(str(exc))

    return wrapper


def show(renderable) -> None:
    """Print a table; piped or redirected output gets its full width (no ellipses in CI logs or files)."""
    console = out if out.is_terminal else Console(file=sys.stdout, width=1000, soft_wrap=True)
    console.print(renderable, crop=False)


def load(path: Path):
    return load_config(path)


def solutions_table(solutions, title: str, stages: list[str] | None = None) -> Table:
    """One row per solve, best first; a stage column when the solves come from more than one stage (a seed refined
    from two barriers is then two rows: refine and refine2)."""
    staged = stages is not None and len(set(stages)) > 1
    stage_of = {id(s): st for s, st in zip(solutions, stages, strict=True)} if staged else {}
    table = Table(title=title)
    columns = ("seed", "stage", "status", "iter", "time [s]", "design cost", "pos err [m]", "axis err", "max step",
               "tracks")
    for col in columns if staged else tuple(c for c in columns if c != "stage"):
        table.add_column(col, justify="left" if col == "stage" else "right")
    for s in sorted(solutions, key=lambda s: (not s.metrics.tracks, s.metrics.design_cost)):
        m, r = s.metrics, s.raw
        stage = (stage_of[id(s)],) if staged else ()
        table.add_row(str(r.seed), *stage, r.status, str(r.iterations), f"{r.solve_time_s:.2f}",
                      f"{m.design_cost:.6g}", f"{m.max_position_error:.3e}", f"{m.max_axis_error:.3e}",
                      f"{m.max_joint_step:.4f}", "yes" if m.tracks else "no")
    return table


@app.command()
@user_errors
def run(
    config: Annotated[Path, typer.Argument(help="YAML config (see configs/ and the README).")],
    out_dir: Annotated[Path, typer.Option("--out", help="Root of the results tree.")] = Path("results"),
    name: Annotated[str | None, typer.Option("--name", help="Run name (default: a timestamp).")] = None,
    no_figures: Annotated[bool, typer.Option("--no-figures", help="Skip the figures.")] = False,
    urdf: Annotated[bool, typer.Option("--urdf", help="Also export the best design as URDF (see export).")] = False,
    resume: Annotated[bool, typer.Option("--resume", help="Finish the run --name: keep its finished solves, "
                                                          "solve the rest.")] = False,
    jobs: Annotated[int, typer.Option("--jobs", help="Worker processes (-1: every core).")] = -1,
):
    """Search one design problem (config's search: README "Search") and write results/<experiment>/<run>/.

    Exit code 0 when a design tracks the path, 3 when none does, 2 for bad input."""
    from designopt.experiments.run import run_experiment
    from designopt.tables import is_coarse

    cfg = load(config)
    with Bar(f"{cfg.name}: solving") as bar:
        result = run_experiment(cfg, out_dir, name, bar, figures=not no_figures, resume=resume, jobs=jobs)
    problem = result.problem
    if result.explored:
        # every coarse stage (explore on the coarsest path, screen on a finer one) with how many of its solves track
        coarse = result.summary[result.summary["stage"].map(is_coarse)]
        stages = [(stage, len(rows), int(rows["tracks"].astype(str).str.lower().eq("true").sum()))
                  for stage, rows in coarse.groupby("stage", sort=False)]
        parts = [f"{stage} {solves} solves ({tracking} track)" for stage, solves, tracking in stages]
        out.print(f"explored: {', '.join(parts)}; {len(result.solution_set)} distinct optima; "
                  f"{len({s.raw.seed for s in result.solutions})} refined on the full path ({problem.toolpath.n} "
                  f"waypoints, {len(result.solutions)} solves)"
                  + ("" if result.solutions or not stages or stages[-1][2] else
                     f" -- nothing tracked in the {stages[-1][0]} stage, so nothing was refined: try more starts "
                     "(search.starts), another start placement or search.preset paper (starts on the full path)"))
    show(solutions_table(result.solutions, f"{cfg.name}: {problem.chain.structure}, "
                                           f"stiffness {problem.stiffness.describe()}", result.stages))
    if len(result.solution_set):
        show(_frame_table(result.solution_set.head(8), f"distinct optima reached ({len(result.solution_set)} among "
                                                       f"{len(result.explored or result.solutions)} solves; "
                                                       "solution_set.csv)"))
    if result.best is None:
        statuses = ", ".join(sorted({s.raw.status for s in result.solutions})) or "none"
        err.print(f"[red]no design tracks the path[/red] within {problem.position_tol:g} m and axis "
                  f"{problem.axis_tol:g} (full-path statuses: {statuses}); see {result.directory.path / 'summary.csv'}",
                  highlight=False)
    else:
        b = result.best
        placement = b.chain.placement_values([0.0] * b.chain.n_moving, [])
        out.print(f"best: seed {b.raw.seed} ({b.raw.status}, {b.raw.iterations} iterations), design cost "
                  f"[bold]{b.metrics.design_cost:.6g}[/bold], placement xyz = ({placement[0]:.3f}, {placement[1]:.3f}, "
                  f"{placement[2]:.3f}) m")
        if len(result.draw_bests) > 1:
            ratios = [cost / b.metrics.design_cost for cost in result.draw_bests]
            out.print(f"{len(ratios)} draws, each one's best / the answer: "
                      f"{', '.join(f'{r:.3f}x' for r in ratios)} ({sum(r <= 1.01 for r in ratios)} of "
                      f"{len(ratios)} within 1 %)")
        if urdf:
            from designopt.export import export as export_cell
            from designopt.solution import to_dict

            for p in export_cell(to_dict(b), result.directory.path / "export", stem="best"):
                out.print(f"wrote {p}")
    out.print(f"results: {result.directory.path}")
    if result.best is None:
        raise typer.Exit(code=3)


@app.command()
@user_errors
def check(config: Annotated[Path, typer.Argument(help="YAML config (see configs/ and the README).")],
          build: Annotated[bool, typer.Option("--build", help="Also build the NLP (and time it).")] = False):
    """Validate a config and its toolpath, and say what a solve would be (the NLP's size is counted, not built)."""
    from designopt.experiments.check import check_config

    cfg = load(config)
    s = check_config(cfg, build)
    joints = Table(title=f"{s.name}: {s.structure}, {len(s.design)} design joints, {len(s.moving)} moving, "
                         f"{s.n_fixed} fixed")
    for col in ("joint", "role", "start", "lower", "upper", "unit"):
        joints.add_column(col, justify="left" if col in ("joint", "role") else "right")
    for role, group in (("design", s.design), ("moving", s.moving)):
        for j in group:
            start = f"{j.value:.6g}" if role == "design" else "(trajectory)"
            joints.add_row(j.name, role, start, f"{j.lower:.6g}", f"{j.upper:.6g}",
                           "m" if j.kind == "length" else "rad")
    show(joints)
    force = "along the tangent (the paper's model)" if s.force_model == "paper" else "(milling model)"
    rapids = f" ({s.waypoints - s.tracked} on rapids, untracked)" if s.tracked < s.waypoints else ""
    duration = f", {s.duration:.4g} s" if s.time_unit == "s" else ""
    ex, ey, ez = (v * 1e3 for v in s.extent_m)
    out.print(f"toolpath: {s.toolpath_kind}, {s.waypoints} waypoints{rapids}{duration}; {s.path_length_m:.6g} m long: "
              f"cutting {s.cut_length_m:.6g} m, rapids {s.rapid_length_m:.6g} m; extent {ex:.4g} x {ey:.4g} x "
              f"{ez:.4g} mm, cuts at z = {s.z_range_m[0] * 1e3:.4g} .. {s.z_range_m[1] * 1e3:.4g} mm in W; force "
              f"{s.force_range_n[0]:.6g} .. {s.force_range_n[1]:.6g} N {force}")
    if s.cell:
        out.print(f"cell: {s.cell}")
    out.print(f"stiffness: {s.stiffness.describe()}; deflection: {s.deflection}")
    built = f"built in {s.build_time_s:.2f} s" if s.build_time_s is not None else "counted (--build builds it)"
    out.print(f"NLP (TO, {s.tracking} tracking, {s.kinematics} kinematics): {s.n_variables} variables, "
              f"{s.n_constraints} constraints; {built}")
    out.print(f"a run searches it by {s.search}; nothing was solved")


# Seconds between two plain progress lines when stderr is not a terminal (a log file, CI): rich draws no bar there.
PLAIN_PROGRESS_EVERY_S = 60.0


class Bar:
    """A rich progress bar that is an experiment's `Progress`: solves planned, solves done, how many track. When
    stderr is not a terminal, a plain line every `PLAIN_PROGRESS_EVERY_S` seconds instead."""

    def __init__(self, label: str):
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self.label, self.failed = label, 0
        self.bar = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                            TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(), console=err, transient=True)
        self.task = self.bar.add_task(label, total=0)
        self.plain, self.last_line = not err.is_terminal, time.monotonic()

    def __enter__(self):
        self.bar.__enter__()
        return self

    def __exit__(self, *exc):
        return self.bar.__exit__(*exc)

    def planned(self, solves: int, finished: int = 0) -> None:
        total = self.bar.tasks[0].total or 0
        self.bar.update(self.task, total=total + solves, advance=finished)

    def solved(self, task, solution) -> None:
        self.failed += not solution.metrics.tracks
        where = " ".join(x for x in (task.case, task.stage, task.problem.chain.structure) if x)
        self.bar.update(self.task, advance=1, description=f"{self.label} {where}: {self.failed} not tracking")
        if self.plain and time.monotonic() - self.last_line >= PLAIN_PROGRESS_EVERY_S:
            self.last_line = time.monotonic()
            t = self.bar.tasks[0]
            err.print(f"{self.label}: {t.completed:.0f} of {t.total:.0f} solves planned so far, {self.failed} not "
                      f"tracking, {t.elapsed:.0f} s", highlight=False)


def _frame_table(frame, title: str) -> Table:
    table = Table(title=title)
    for col in frame.columns:
        table.add_column(str(col), justify="right")
    for _, row in frame.iterrows():
        table.add_row(*[f"{v:.6g}" if isinstance(v, float) else str(v) for v in row])
    return table


ConfigArg = Annotated[Path, typer.Argument(help="YAML config.")]
OutOpt = Annotated[Path, typer.Option("--out", help="Root of the results tree.")]
NameOpt = Annotated[str | None, typer.Option("--name", help="Run name (default: a timestamp).")]
ResumeOpt = Annotated[bool, typer.Option("--resume", help="Finish the run --name: keep its finished solves, "
                                                          "solve the rest.")]
JobsOpt = Annotated[int, typer.Option("--jobs", help="Worker processes (-1: every core).")]


def _names(text: str, allowed, option: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in allowed]
    if unknown or not names:
        fail(f"{option}: {unknown[0] if unknown else '(empty)'!r} is not one of {', '.join(allowed)}")
    return names


@app.command()
@user_errors
def continuous(
    config: ConfigArg = Path("configs/continuous.yaml"),
    out_dir: OutOpt = Path("results"),
    name: NameOpt = None,
    resume: ResumeOpt = False,
    jobs: JobsOpt = -1,
    cases: Annotated[str, typer.Option("--cases", help="Comma-separated: placement_only, design_only, combined.")]
    = "placement_only,design_only,combined",
    methods: Annotated[str, typer.Option("--methods", help="Comma-separated: to, fk, fk_continuous.")]
    = "to,fk,fk_continuous",
):
    """Continuous design problem: placement only, design only, combined x TO, FK, FK with bounded steps."""
    from designopt.experiments.adapters import CASES
    from designopt.experiments.continuous import METHODS, run_continuous

    case_names, method_names = _names(cases, CASES, "--cases"), _names(methods, METHODS, "--methods")
    cfg = load(config)
    with Bar("continuous") as bar:
        result = run_continuous(cfg, out_dir, name, bar, resume=resume, jobs=jobs, cases=case_names,
                                methods=method_names)
    cols = ["case", "method", "n_design_joints", "design_cost", "max_joint_step", "tracking_starts", "starts",
            "median_solve_time_s"]
    show(_frame_table(result.table[cols], "best tracking start per case and method"))
    out.print(f"results: {result.directory.path}")


@app.command()
@user_errors
def waypoints(
    config: ConfigArg = Path("configs/continuous.yaml"),
    out_dir: OutOpt = Path("results"),
    name: NameOpt = None,
    resume: ResumeOpt = False,
    jobs: JobsOpt = -1,
    counts: Annotated[str, typer.Option("--waypoints", help="Comma-separated waypoint counts (3..2000).")]
    = "20,40,80,160,320",
):
    """Waypoint study: design cost, tracking between waypoints and solve time against N (TO, combined)."""
    from designopt.experiments.waypoints import run_waypoint_study

    try:
        ns = tuple(int(n) for n in counts.split(","))
    except ValueError:
        fail(f"--waypoints: expected comma-separated integers, got {counts!r}")
    if not ns or any(not 3 <= n <= 2000 for n in ns):
        fail(f"--waypoints: every count must lie in 3..2000, got {counts!r}")
    cfg = load(config)
    with Bar("waypoint study") as bar:
        result = run_waypoint_study(cfg, out_dir, name, bar, resume=resume, jobs=jobs, waypoints=ns)
    show(_frame_table(result.table, "waypoint study (TO, design + placement)"))
    out.print(f"results: {result.directory.path}")


@app.command("sweep-structures")
@user_errors
def sweep_structures(
    config: Annotated[Path, typer.Option("--config", help="Base config (task, costs, solver).")]
    = Path("configs/structures.yaml"),
    min_dof: Annotated[int, typer.Option("--min-dof", min=1, max=12, help="Fewest joints.")] = 1,
    max_dof: Annotated[int, typer.Option("--max-dof", min=1, max=12, help="Most joints.")] = 6,
    jobs: Annotated[int, typer.Option("--jobs", help="Worker processes (-1: all cores).")] = -1,
    out_dir: OutOpt = Path("results"),
    name: Annotated[str, typer.Option("--name", help="Run name (reuse it with --resume).")] = "sweep",
    resume: Annotated[bool, typer.Option("--resume", help="Skip finished solves of this run, do the rest.")] = False,
    backend: Annotated[str, typer.Option("--backend", help="loky (local processes) or dask.")] = "loky",
    scheduler: Annotated[str | None, typer.Option("--scheduler", help="dask scheduler address, e.g. tcp://host:8786 "
                                                                       "(none: a LocalCluster).")] = None,
):
    """Search every kinematic structure over {R, P} with min..max joints (the config's search, plus starts from
    neighbouring structures' better designs), in parallel."""
    from designopt.experiments.sweep import run_sweep

    if backend not in ("loky", "dask"):
        fail(f"--backend: expected loky or dask, got {backend!r}")
    cfg = load(config)
    with Bar("structures") as bar:
        result = run_sweep(cfg, out_dir, name, min_dof, max_dof, jobs, resume, backend, scheduler, bar)
    tracking = int(result.table["design_cost"].notna().sum())
    out.print(f"{result.structures} structures solved ({result.solved_now} solves now, {result.already_done} "
              f"already done), {tracking} track the path; best per number of joints:")
    show(_frame_table(result.best_per_dof[["dof", "structure", "n_prismatic", "design_cost", "tracking_starts",
                                           "starts"]], "best structure per DOF"))
    out.print(f"results: {result.directory.path}")


@app.command()
@user_errors
def modular(
    config: ConfigArg = Path("configs/modular.yaml"),
    out_dir: OutOpt = Path("results"),
    name: NameOpt = None,
    resume: ResumeOpt = False,
    jobs: JobsOpt = -1,
    weight: Annotated[float, typer.Option("--weight", min=0.0, help="Weight of L_mod in the objective.")] = 1.0e-3,
    budget: Annotated[int, typer.Option("--budget", min=0, help="Robots the neighbourhood search may screen (one "
                                                                "assignment each: assignments that differ by a lift "
                                                                "along base z, which the placement z takes up, are one "
                                                                "robot; 0: no neighbourhood search).")] = 300,
    refine: Annotated[int, typer.Option("--refine", min=1, help="Best distinct screening optima the neighbourhood "
                                                                "search searches on the full path.")] = 8,
    swaps: Annotated[bool, typer.Option("--swaps/--no-swaps", help="A step of the neighbourhood search also "
                                        "exchanges two neighbouring links' modules.")] = True,
    refine_starts: Annotated[int, typer.Option("--refine-starts", min=1, help="Coarse starts of the full-path search "
                                               "of each refined optimum (fewer: a cheaper, less thorough "
                                               "search).")] = 160,
):
    """Modular design: continuous TO with L_mod, round links to modules, re-solve placement, search neighbouring
    assignments (+ FK, plain TO)."""
    from designopt.experiments.modular import run_modular

    cfg = load(config)
    with Bar("modular") as bar:
        result = run_modular(cfg, out_dir, name, bar, resume=resume, jobs=jobs, weight=weight,
                             neighbourhood_budget=budget, neighbourhood_refine=refine, neighbourhood_swaps=swaps,
                             neighbourhood_refine_starts=refine_starts)
    show(_frame_table(result.table, "modular design: best tracking start per stage"))
    out.print(f"results: {result.directory.path}")


@app.command("modular-study")
@user_errors
def modular_study(
    config: ConfigArg = Path("configs/modular.yaml"),
    out_dir: OutOpt = Path("results"),
    name: NameOpt = None,
    resume: ResumeOpt = False,
    jobs: JobsOpt = -1,
):
    """Beyond the paper: the L_mod weight study, and every module assignment of a small catalogue."""
    from designopt.experiments.modular import run_modular_study

    cfg = load(config)
    with Bar("modular study") as bar:
        result = run_modular_study(cfg, out_dir, name, bar, resume=resume, jobs=jobs)
    enum = result.enumeration
    show(_frame_table(result.weights, "L_mod weight study"))
    show(_frame_table(enum.head(10), "best module assignments (small catalogue)"))
    picked = enum[enum["rounding_picked"]]
    if len(picked):
        out.print(f"rounding picked rank {int(picked['rank'].iloc[0])} of {len(enum)}")
    out.print(f"results: {result.directory.path}")


@app.command()
@user_errors
def export(
    solution: Annotated[Path, typer.Argument(help="A solution file (designopt.solution/1).")],
    out_dir: Annotated[Path | None, typer.Option("--out", help="Directory (default: next to the solution).")] = None,
):
    """Write the designed cell as URDF (robot + placed workpiece + toolpath) and the joint trajectory."""
    from designopt.export import export as export_cell
    from designopt.solution import Solution, to_dict

    sol = Solution.from_file(solution)
    paths = export_cell(to_dict(sol), out_dir or solution.parent / "export", stem=solution.stem)
    for p in paths:
        out.print(f"wrote {p}")


@app.command()
@user_errors
def render(
    solution: Annotated[Path, typer.Argument(help="A solution file (designopt.solution/1).")],
    out_dir: Annotated[Path | None, typer.Option("--out", help="Directory (default: next to the solution).")] = None,
    frames: Annotated[int, typer.Option(min=1, max=50, help="Robot poses drawn along the path.")] = 6,
    animate: Annotated[bool, typer.Option("--animate", help="Also write an animation (GIF, or MP4 with ffmpeg).")]
    = False,
):
    """Draw the robot following its path (PNG + PDF), optionally animated."""
    from designopt.plots import render_animation, render_figure, save
    from designopt.solution import Solution

    sol = Solution.from_file(solution)
    target = out_dir or solution.parent
    for p in save(render_figure(sol, frames), target, f"{solution.stem}_render"):
        out.print(f"wrote {p}")
    if animate:
        out.print(f"wrote {render_animation(sol, target / f'{solution.stem}_render.gif')}")


@app.command()
@user_errors
def view(
    solution: Annotated[Path, typer.Argument(help="A solution file (designopt.solution/1).")],
    out_file: Annotated[Path | None, typer.Option("--out", help="HTML file (default: <solution>_view.html next "
                                                                "to it).")] = None,
    frames: Annotated[int, typer.Option(min=2, max=400, help="Robot poses in the animation.")] = 60,
):
    """Write an interactive 3D view of the cell: one self-contained HTML file (opens offline in any browser)."""
    from designopt.solution import Solution
    from designopt.view import write_view

    sol = Solution.from_file(solution)
    path = write_view(sol, out_file or solution.with_name(f"{solution.stem}_view.html"), frames)
    out.print(f"wrote {path} (open it in a browser: no network needed)")


@app.command()
@user_errors
def cache(
    clear: Annotated[bool, typer.Option("--clear", help="Delete every file of the cache (compiled again when "
                                                        "next needed).")] = False,
    clear_other: Annotated[bool, typer.Option("--clear-other", help="Delete only the files of no current kind "
                                                                    "(an older designopt's, a dead build's).")]
    = False,
):
    """Show the compile cache of the per-waypoint blocks (its place, libraries by level, blocks counting towards
    their -O1 build), or clear it."""
    from designopt.transcriptions.compiled import cache_report, clear_cache, tier_up_after

    if clear or clear_other:
        files, freed = clear_cache(only_other=clear_other and not clear)
        out.print(f"removed {files} files ({freed / 1e6:.1f} MB) from {cache_report().path}")
        return
    r = cache_report()
    after = tier_up_after()
    table = Table(title=f"compile cache {r.path} ({r.bytes / 1e6:.1f} MB)")
    table.add_column("what")
    table.add_column("count", justify="right")
    table.add_row("libraries at -O0", str(r.libraries["O0"]))
    table.add_row("libraries at -O1 (tiered up)", f"{r.libraries['O1']} ({r.tiered_up})")
    table.add_row("libraries at -O2", str(r.libraries["O2"]))
    most = f"; most {r.counting[0][1]:.1f} s" if r.counting else ""
    threshold = "never" if after is None else f"{after:g} s of solving"
    table.add_row(f"blocks counting towards -O1 (at {threshold}){most}", str(len(r.counting)))
    table.add_row("-O1 builds under way", str(r.building))
    table.add_row("files of no current kind (--clear-other)", str(r.other))
    show(table)


def main() -> None:
    try:
        app()
    except KeyboardInterrupt:
        err.print("interrupted: finished results are in the run directory")
        sys.exit(130)


if __name__ == "__main__":
    main()
