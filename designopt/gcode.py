"""G-code programs as toolpaths: cutting moves (G1, G2, G3) are tracked and loaded, rapids (G0) are free.

Lexing is done by `gcodeparser` (PyPI, maintained, pure Python): it splits a line into its command and
parameter words. It is lenient -- it drops words it does not know and lines without a G/M/T word -- so every
line is first checked here word by word (an unknown or unsupported word is an error naming the line), and a
line that only carries coordinates continues the modal motion, as on a CNC. The machine state (plane, units,
distance mode, feed) and the geometry of arcs are interpreted here.

Supported: G0 G1 G2 G3 (arcs by I/J/K centre offsets or by R, helical arcs), G17 G18 G19, G20 G21, G90 G91,
G94 (feed per minute), G4 (dwell: no motion), G40 G49 G80 (cancels: no effect), G54 (the program's zero is
W's origin); M, S, T, N words are accepted and ignored. Coordinates of the program are coordinates in W.

Units out: metres; feed in m/s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from gcodeparser import parse_gcode_lines

from designopt.errors import InputError, read_text

UNITS = {20: 0.0254, 21: 0.001}  # metres per program unit
# (first, second, normal) axes of each arc plane and the centre-offset words along the first two
PLANES = {17: ("XYZ", "IJ"), 18: ("ZXY", "KI"), 19: ("YZX", "JK")}
AXES = "XYZ"
MOTION = (0, 1, 2, 3)
IGNORED_G = {4, 40, 49, 54, 80, 94}
ALLOWED_WORDS = set("GMXYZIJKRFSTNP")
WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
ARC_RADIUS_TOLERANCE = 0.002e-3  # m: LinuxCNC's absolute tolerance for the end point's distance from the centre


@dataclass(frozen=True)
class Move:
    """One motion of the program as a polyline in W (metres): rapid or cutting, with its feed (m/s; None on a
    rapid or when the program gives none) and the program line it comes from (1-based)."""

    rapid: bool
    points: np.ndarray  # (M, 3), first point = the end of the previous move
    feed: float | None
    line: int

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())


def _strip_comments(line: str) -> str:
    line = re.sub(r"\([^)]*\)", " ", line)
    return line.split(";", 1)[0]


def _words(text: str, source, line_no: int) -> list[tuple[str, float]]:
    """The words of one line, checked: every character belongs to a word of a known letter."""
    where = f"line {line_no}"
    rest = WORD.sub(" ", text).strip()
    if rest.replace("%", "").strip():
        raise InputError(source, where, f"cannot read {rest.split()[0]!r} as a G-code word (letter and number)")
    words = [(m.group(1).upper(), float(m.group(2))) for m in WORD.finditer(text)]
    for letter, value in words:
        if letter not in ALLOWED_WORDS:
            what = "rotary and auxiliary axes are not supported" if letter in "ABCUVW" else "unknown word"
            raise InputError(source, where, f"{letter}{value:g}: {what}")
        if letter == "G" and value not in (*MOTION, 17, 18, 19, *UNITS, 90, 91, *IGNORED_G):
            raise InputError(source, where, f"G{value:g} is not supported (supported: G0-G3, G4, G17-G21, G40, "
                                            "G49, G54, G80, G90, G91, G94)")
    return words


def _arc(start, end, words, plane, clockwise, scale, chord_tolerance, source, line_no) -> np.ndarray:
    """Points of an arc (or helix) from start to end in program units converted to metres, sampled so that no
    chord departs from the arc by more than chord_tolerance (m)."""
    where = f"line {line_no}"
    (a, b, n), (oa, ob) = [AXES.index(c) for c in PLANES[plane][0]], PLANES[plane][1]
    u0 = np.array([start[a], start[b]])
    u1 = np.array([end[a], end[b]])
    if "R" in words:
        r = words["R"] * scale
        chord = np.linalg.norm(u1 - u0)
        if chord < 1e-12:
            raise InputError(source, where, "an R arc needs an end point other than its start (use I/J/K for a "
                                            "full circle)")
        if abs(r) < chord / 2 - ARC_RADIUS_TOLERANCE:
            raise InputError(source, where, f"R{words['R']:g} is shorter than half the chord "
                                            f"({chord / 2 / scale:.6g}): no such arc")
        mid, half = 0.5 * (u0 + u1), max(r * r - chord * chord / 4, 0.0)
        normal = np.array([-(u1 - u0)[1], (u1 - u0)[0]]) / chord  # left of the chord
        # the centre lies right of the chord for a short clockwise arc; a negative R asks for the long arc
        side = -1.0 if clockwise else 1.0
        centre = mid + side * np.sign(r) * math.sqrt(half) * normal
    else:
        if oa not in words and ob not in words:
            raise InputError(source, where, f"an arc in plane G{plane} needs {oa}/{ob} centre offsets or R")
        centre = u0 + scale * np.array([words.get(oa, 0.0), words.get(ob, 0.0)])
    r0, r1 = np.linalg.norm(u0 - centre), np.linalg.norm(u1 - centre)
    if abs(r0 - r1) > max(ARC_RADIUS_TOLERANCE, 1e-3 * r0):
        raise InputError(source, where, f"arc radius {r0 / scale:.6g} at the start but {r1 / scale:.6g} at the end "
                                        "(inconsistent centre)")
    if r0 < 1e-12:
        raise InputError(source, where, "arc of zero radius")
    th0 = math.atan2(*(u0 - centre)[::-1])
    th1 = math.atan2(*(u1 - centre)[::-1])
    period = -2 * math.pi if clockwise else 2 * math.pi
    sweep = (th1 - th0) % period
    if abs(sweep) < 1e-12:
        sweep = period  # the end is the start: a full circle
    step = 2 * math.acos(max(1.0 - chord_tolerance / r0, -1.0))
    pieces = max(int(math.ceil(abs(sweep) / step)), 2)
    s = np.linspace(0.0, 1.0, pieces + 1)
    theta = th0 + s * sweep
    radius = r0 + s * (r1 - r0)
    pts = np.tile(np.asarray(start, dtype=float), (len(s), 1))
    pts[:, a] = centre[0] + radius * np.cos(theta)
    pts[:, b] = centre[1] + radius * np.sin(theta)
    pts[:, n] = start[n] + s * (end[n] - start[n])
    pts[-1] = end
    return pts


def parse_program(text: str, source="<program>", chord_tolerance: float = 1e-4) -> list[Move]:
    """The moves of a G-code program (metres, W); `InputError` naming the line for anything it cannot follow."""
    state = {"motion": None, "plane": 17, "scale": UNITS[21], "absolute": True, "feed": None}
    position = np.zeros(3)
    moves: list[Move] = []
    for line_no, raw in enumerate(text.splitlines(), start=1):
        clean = _strip_comments(raw).strip()
        if not clean or clean == "%":
            continue
        words = _words(clean, source, line_no)
        letters = [w for w, _ in words]
        for letter in set(letters):
            if letter != "G" and letter != "M" and letters.count(letter) > 1:
                raise InputError(source, f"line {line_no}", f"word {letter} appears twice")
        g_codes = [int(v) for w, v in words if w == "G"]
        if not any(w == "G" for w in letters) and any(w in AXES for w in letters):
            clean = f"G{state['motion']} {clean}" if state["motion"] is not None else clean
        # the library's lexing of the (checked) line: commands with their parameter words
        params: dict[str, float] = {}
        for parsed in parse_gcode_lines(clean):
            params.update({k.upper(): float(v) for k, v in parsed.params.items()
                           if isinstance(v, int | float) and not isinstance(v, bool)})
        for g in g_codes:
            if g in MOTION:
                state["motion"] = g
            elif g in PLANES:
                state["plane"] = g
            elif g in UNITS:
                state["scale"] = UNITS[g]
            elif g in (90, 91):
                state["absolute"] = g == 90
        if "F" in params:
            if params["F"] <= 0:
                raise InputError(source, f"line {line_no}", f"F{params['F']:g}: a feed must be > 0")
            state["feed"] = params["F"] * state["scale"] / 60.0  # units/min -> m/s
        if not any(w in AXES for w in letters):
            if any(g in (2, 3) for g in g_codes) or ("I" in letters or "J" in letters or "K" in letters):
                raise InputError(source, f"line {line_no}", "an arc needs an end point (X, Y or Z)")
            continue
        if state["motion"] is None:
            raise InputError(source, f"line {line_no}", "coordinates without a motion (G0, G1, G2 or G3)")
        target = position.copy()
        for i, axis in enumerate(AXES):
            if axis in params:
                value = params[axis] * state["scale"]
                target[i] = value if state["absolute"] else position[i] + value
        if np.allclose(target, position, atol=1e-12) and state["motion"] in (0, 1):
            continue
        if state["motion"] in (0, 1):
            pts = np.vstack([position, target])
        else:
            pts = _arc(position, target, params, state["plane"], state["motion"] == 2, state["scale"],
                       chord_tolerance, source, line_no)
        rapid = state["motion"] == 0
        moves.append(Move(rapid, pts, None if rapid else state["feed"], line_no))
        position = target
    return moves


def read_program(path: Path, chord_tolerance: float = 1e-4) -> list[Move]:
    """The moves of the program in ``path``; checked: at least one cutting move, and feeds on every cutting
    move if the program has any."""
    path = Path(path)
    moves = parse_program(read_text(path), path, chord_tolerance)
    cuts = [m for m in moves if not m.rapid]
    if not cuts:
        raise InputError(path, "(file)", "no cutting move (G1, G2 or G3): nothing to track")
    with_feed = [m for m in cuts if m.feed is not None]
    if with_feed and len(with_feed) < len(cuts):
        first = next(m for m in cuts if m.feed is None)
        raise InputError(path, f"line {first.line}", "a cutting move before any F word, while the program "
                                                     "gives feeds elsewhere: set F before the first cut")
    return moves


@dataclass(frozen=True)
class SampledProgram:
    """Waypoints of a program: points (N, 3) in W, times t (N), tangents (N, 3), tracked (N), and the time unit
    (``s`` when the program gives feeds, else ``task``: t in [0, 1] proportional to arc length)."""

    points: np.ndarray
    t: np.ndarray
    tangents: np.ndarray
    tracked: np.ndarray
    time_unit: str


def sample_program(moves: list[Move], spacing: float, rapid_speed: float, origin=(0.0, 0.0, 0.0)) -> SampledProgram:
    """Waypoints spaced by arc length (at most ``spacing`` m apart, each move split evenly) from the start of
    the first cutting move to the end of the last; rapids in between run at ``rapid_speed`` (m/s). ``origin`` is
    where the program's zero lies in W (m): every point is shifted by it.

    A waypoint is tracked when it lies on a cutting move (the ends of a cut included). Its tangent is the
    direction of the move that leaves it (the last waypoint: of the move that arrives).
    """
    cut_index = [i for i, m in enumerate(moves) if not m.rapid]
    moves = moves[cut_index[0]: cut_index[-1] + 1]
    timed = all(m.feed is not None for m in moves if not m.rapid)
    points, times, tangents, tracked = [moves[0].points[0]], [0.0], [], [True]
    clock = 0.0
    for move in moves:
        seg = np.diff(move.points, axis=0)
        seg_len = np.linalg.norm(seg, axis=1)
        keep = seg_len > 1e-12
        seg, seg_len = seg[keep], seg_len[keep]
        if not len(seg):
            continue
        arc = np.concatenate([[0.0], np.cumsum(seg_len)])
        total = arc[-1]
        pieces = max(int(math.ceil(total / spacing - 1e-9)), 1)
        s = np.linspace(0.0, total, pieces + 1)[1:]
        corners = np.vstack([move.points[:1], move.points[1:][keep]])
        pts = np.column_stack([np.interp(s, arc, corners[:, k]) for k in range(3)])
        # tangent leaving each waypoint: the first waypoint of the move takes the move's first segment
        starts = np.concatenate([[0.0], s[:-1]])
        leaving = np.minimum(np.searchsorted(arc, starts + 1e-12, side="right") - 1, len(seg) - 1)
        tangents.extend(seg[leaving] / seg_len[leaving, None])
        speed = (rapid_speed if move.rapid else move.feed) if timed else 1.0
        times.extend(clock + s / speed)
        clock += total / speed
        points.extend(pts)
        tracked.extend([not move.rapid] * len(pts))
        if not move.rapid:
            tracked[-len(pts) - 1] = True  # the cut's first point (the end of the move before it)
    tangents.append(tangents[-1])
    tracked = np.array(tracked, dtype=bool)
    tangents = np.array(tangents)
    # where a cut ends and a rapid leaves, the cut's force follows the cut: take the arriving direction
    ends = np.flatnonzero(tracked[1:-1] & ~tracked[2:]) + 1
    tangents[ends] = tangents[ends - 1]
    points, t = np.array(points) + np.asarray(origin, dtype=float), np.array(times)
    if not timed:
        t = t / t[-1]
    return SampledProgram(points, t, tangents, tracked, "s" if timed else "task")
