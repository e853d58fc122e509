"""G-code programs as toolpaths: cutting moves (G1, G2, G3) are tracked and loaded, rapids (G0) are free.

designopt reads what CAM posts and shops write (RS274/NGC as LinuxCNC documents it, and the Fanuc-style output of
the common posts). Lexing is its own (`words`): comments ``( )`` and ``;``, ``%`` lines, ``N`` line numbers, ``O``
program numbers, block delete ``/``, lower case, CRLF, spaces anywhere (``G1 X -25``, ``X 10.``) and numbers with
leading or trailing dots (``X.5``, ``F100.``). Every word of a line is read or the line is refused: nothing is
silently dropped. The library gcodeparser was used before and dropped words it did not know, read ``X -1`` as no
X word and raised on ``X0.``.

Modal and setup codes a cell does not need are honoured or ignored with a stated reason (`SETUP`); codes whose
geometry a cell cannot follow are refused with a line that says what to do (`REFUSED`). The machine state (plane,
units, distance and arc-centre modes, work offset, feed) and the geometry of arcs (I/J/K centres, incremental or
absolute; R; full circles; helices; turns) are interpreted here. Program coordinates become coordinates in W by
the work offset in force: where the program's zero (G54, or G55 ... G59.3) lies in W (`parse_program`'s
``offsets``, the config's ``toolpath.origin``).

Units out: metres; feed in m/s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designopt.errors import InputError, read_text

UNITS = {20: 0.0254, 21: 0.001}  # metres per program unit
# (first, second, normal) axes of each arc plane and the centre-offset words along the first two
PLANES = {17: ("XYZ", "IJ"), 18: ("ZXY", "KI"), 19: ("YZX", "JK")}
AXES = "XYZ"
MOTION = (0, 1, 2, 3)
WORD = re.compile(r"([A-Z])([+-]?(?:\d+\.?\d*|\.\d+))")
ARC_RADIUS_TOLERANCE = 0.002e-3  # m: LinuxCNC's absolute tolerance for the end point's distance from the centre
WORK_OFFSETS = ("G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3")

# G codes (in tenths: G43.1 is 431) accepted with no effect on the toolpath, and why
SETUP = {
    40: "dwell: no motion",
    400: "cutter compensation off: the program is the tool centre's path",
    430: "tool length offset: the cell's tool_length defines the tool centre point",
    431: "dynamic tool length offset: the cell's tool_length defines the tool centre point",
    432: "tool length offset: the cell's tool_length defines the tool centre point",
    490: "tool length offset off",
    610: "exact path: a path-blending mode of the controller, not geometry",
    611: "exact stop: a path-blending mode of the controller, not geometry",
    640: "path blending: a mode of the controller, not geometry",
    800: "canned cycle off",
    940: "feed per minute (the only feed mode read)",
}
REFUSED = {  # G code (tenths) -> what to do
    **dict.fromkeys((730, 760, 810, 820, 830, 840, 850, 860, 870, 880, 890),
                    "canned cycles are not read: post-process with cycles expanded into G0/G1 moves"),
    **dict.fromkeys((410, 420, 411, 421), "cutter radius compensation is not read: post-process with compensation off "
                                          "(G40), so that the program is the tool centre's path"),
    **dict.fromkeys((280, 281, 300, 301, 530), "moves in machine coordinates cannot be placed in a cell: post-process "
                                               "without G28/G30/G53, or delete those lines"),
    **dict.fromkeys((100, 520, 920, 921, 922, 923), "the program changes its coordinate system: remove that and say "
                                                    "where its zero is with toolpath.origin"),
    930: "inverse-time feed: post-process with feed per minute (G94)",
    950: "feed per revolution: post-process with feed per minute (G94)",
    **dict.fromkeys((150, 160), "polar coordinates: post-process in Cartesian coordinates"),
    **dict.fromkeys((680, 690, 500, 510), "rotated or scaled coordinates: post-process without G68/G51"),
    **dict.fromkeys((330, 331, 761), "threading is not a milling path"),
    **dict.fromkeys((382, 383, 384, 385), "probing moves are not a milling path: delete them"),
}
M_END = (2, 30)  # end of program: nothing after it runs
IGNORED_WORDS = set("SNTHD")  # spindle speed, line number, tool, tool length and radius register numbers


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


def _clean(raw: str, source, where: str) -> str:
    """A line without comments and spaces, upper case (block delete ``/``: the block runs, as with the switch off)."""
    line = raw.rstrip("\r\n").split(";", 1)[0]
    line = re.sub(r"\([^)]*\)", " ", line)
    if "(" in line:
        raise InputError(source, where, "a comment '(' is not closed on its line")
    line = line.strip()
    if line.startswith("/"):
        line = line[1:]
    return re.sub(r"\s+", "", line).upper()


def words(raw: str, source="<program>", line_no: int = 1) -> list[tuple[str, float]]:
    """The words (letter, number) of one program line; InputError naming the line for anything that is not one."""
    where = f"line {line_no}"
    text = _clean(raw, source, where)
    if text in ("", "%"):
        return []
    if "#" in text or "[" in text:
        raise InputError(source, where, "parameters (#) and expressions ([...]) are not read: post-process to plain "
                                        "numbers")
    if "@" in text or "^" in text:
        raise InputError(source, where, "polar coordinates (@, ^) are not read: post-process in Cartesian "
                                        "coordinates")
    program = re.match(r"^O(\d+)", text)
    if program:  # a program number (Fanuc O1234), or a LinuxCNC O-word
        keyword = re.match(r"[A-Z]+", text[program.end():])
        if keyword and keyword.group(0) in ("SUB", "ENDSUB", "CALL", "IF", "ELSE", "ELSEIF", "ENDIF", "WHILE",
                                            "ENDWHILE", "DO", "REPEAT", "ENDREPEAT", "RETURN", "BREAK", "CONTINUE"):
            raise InputError(source, where, f"O-word {keyword.group(0).lower()}: subroutines and control flow are not "
                                            "read: post-process to a flat program")
        text = text[program.end():]
    found, end = [], 0
    for m in WORD.finditer(text):
        if m.start() != end:
            break
        found.append((m.group(1), float(m.group(2))))
        end = m.end()
    if end != len(text):
        rest = text[end:]
        raise InputError(source, where, f"cannot read {rest[:12]!r} as a G-code word (a letter and a number)")
    return found


def _g10(value: float) -> int:
    """A G code in tenths (G43.1 -> 431, G1 -> 10)."""
    return int(round(value * 10))


def _arc(start, end, values, state, zero, chord_tolerance, source, line_no, motion_here) -> np.ndarray:
    """Points (in W, metres) of an arc or helix from start to end, sampled so that no chord departs from the arc by
    more than chord_tolerance (m). The centre is given by I/J/K offsets (from the start, or with G90.1 absolute
    program coordinates) or by R; an end equal to the start (or no end) with I/J/K is a full circle; P is the
    number of turns (LinuxCNC)."""
    where = f"line {line_no}"
    plane, scale, clockwise = state["plane"], state["scale"], state["motion"] == 2
    (a, b, n), (oa, ob) = [AXES.index(c) for c in PLANES[plane][0]], PLANES[plane][1]
    u0 = np.array([start[a], start[b]])
    u1 = np.array([end[a], end[b]])
    closed = np.linalg.norm(u1 - u0) < 1e-12
    if "R" in values:
        r = values["R"] * scale
        chord = np.linalg.norm(u1 - u0)
        if closed:
            raise InputError(source, where, "an R arc needs an end point other than its start (a full circle needs "
                                            "I/J/K)")
        if abs(r) < chord / 2 - ARC_RADIUS_TOLERANCE:
            raise InputError(source, where, f"R{values['R']:g} is shorter than half the chord "
                                            f"({chord / 2 / scale:.6g}): no such arc")
        mid, half = 0.5 * (u0 + u1), max(r * r - chord * chord / 4, 0.0)
        normal = np.array([-(u1 - u0)[1], (u1 - u0)[0]]) / chord  # left of the chord
        # the centre lies right of the chord for a short clockwise arc; a negative R asks for the long arc
        side = -1.0 if clockwise else 1.0
        centre = mid + side * np.sign(r) * math.sqrt(half) * normal
    else:
        if oa not in values and ob not in values:
            raise InputError(source, where, f"an arc in plane G{plane} needs {oa}/{ob} centre offsets or R")
        given = scale * np.array([values.get(oa, 0.0), values.get(ob, 0.0)])
        centre = np.array([zero[a], zero[b]]) + given if state["arc_absolute"] else u0 + given
    r0, r1 = np.linalg.norm(u0 - centre), np.linalg.norm(u1 - centre)
    if abs(r0 - r1) > max(ARC_RADIUS_TOLERANCE, 1e-3 * r0):
        raise InputError(source, where, f"arc radius {r0 / scale:.6g} at the start but {r1 / scale:.6g} at the end "
                                        "(inconsistent centre)")
    if r0 < 1e-12:
        raise InputError(source, where, "arc of zero radius")
    turns = values.get("P", 1.0)
    if turns < 1 or turns != int(turns):
        raise InputError(source, where, f"P{turns:g}: the number of turns of an arc is a whole number >= 1")
    th0 = math.atan2(*(u0 - centre)[::-1])
    th1 = math.atan2(*(u1 - centre)[::-1])
    period = -2 * math.pi if clockwise else 2 * math.pi
    sweep = (th1 - th0) % period
    if abs(sweep) < 1e-12:
        sweep = period  # the end is the start: a full circle
    sweep += (int(turns) - 1) * period
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


def parse_program(text: str, source="<program>", chord_tolerance: float = 1e-4,
                  offsets: dict[str, np.ndarray] | None = None) -> list[Move]:
    """The moves of a G-code program in W (metres); `InputError` naming the line for anything it cannot follow.

    ``offsets``: where the zero of each work offset the program uses lies in W (m; default: G54 at W's origin)."""
    offsets = {k: np.asarray(v, dtype=float) for k, v in (offsets or {}).items()}
    offsets.setdefault("G54", np.zeros(3))
    state = {"motion": None, "plane": 17, "scale": UNITS[21], "absolute": True, "arc_absolute": False,
             "feed": None, "offset": "G54"}
    position = offsets.get("G54", np.zeros(3)).copy()  # in W: a program starts at its zero, as a viewer assumes
    moves: list[Move] = []
    for line_no, raw in enumerate(text.splitlines(), start=1):
        where = f"line {line_no}"
        found = words(raw, source, line_no)
        if not found:
            continue
        letters = [w for w, _ in found]
        for letter in set(letters):
            if letter not in "GM" and letters.count(letter) > 1:
                raise InputError(source, where, f"word {letter} appears twice")
        ended = False
        for m in (v for w, v in found if w == "M"):
            if int(m) in (98, 99) and m == int(m):
                raise InputError(source, where, f"M{m:g}: subprogram calls are not read: post-process to a flat "
                                                "program")
            ended |= m in M_END
        values = {w: v for w, v in found if w not in "GM"}
        motion_here = None
        for g in (v for w, v in found if w == "G"):
            code = _g10(g)
            name = f"G{g:g}"
            if code in (0, 10, 20, 30):
                motion_here = state["motion"] = code // 10
            elif code in (170, 180, 190):
                state["plane"] = code // 10
            elif code in (200, 210):
                state["scale"] = UNITS[code // 10]
            elif code in (900, 910):
                state["absolute"] = code == 900
            elif code in (901, 911):
                state["arc_absolute"] = code == 901
            elif name in WORK_OFFSETS:
                if name not in offsets:
                    raise InputError(source, where, f"{name} selects a work offset whose place in W is not given: "
                                                    f"add it to toolpath.origin, e.g. origin: {{G54: [0, 0, 0], "
                                                    f"{name}: [x, y, z]}} (m)")
                state["offset"] = name
            elif code in REFUSED:
                raise InputError(source, where, f"{name}: {REFUSED[code]}")
            elif code not in SETUP:
                raise InputError(source, where, f"{name} is not read (accepted: G0-G3, G4, G17-G21, G40, G43, G49, "
                                                "G54-G59.3, G61, G64, G80, G90, G90.1, G91, G91.1, G94)")
        for letter, value in values.items():
            if letter in "ABCUVW":
                raise InputError(source, where, f"{letter}{value:g}: rotary and auxiliary axes are not read: "
                                                "post-process for three linear axes")
            if letter == "E":
                raise InputError(source, where, f"E{value:g}: an extruder axis (a 3D printer's program?)")
            if letter not in "XYZIJKRFP" and letter not in IGNORED_WORDS and letter != "O":
                raise InputError(source, where, f"{letter}{value:g}: unknown word")
        if "F" in values:
            if values["F"] <= 0:
                raise InputError(source, where, f"F{values['F']:g}: a feed must be > 0")
            state["feed"] = values["F"] * state["scale"] / 60.0  # units/min -> m/s
        dwell = any(_g10(v) == 40 for w, v in found if w == "G")
        has_axes = any(w in AXES for w in letters)
        has_centre = any(w in "IJK" for w in letters) or "R" in letters
        if dwell or not (has_axes or (has_centre and state["motion"] in (2, 3))):
            if ended:
                break
            if has_centre and state["motion"] not in (2, 3):
                raise InputError(source, where, "I/J/K or R without an arc (G2, G3)")
            continue
        if state["motion"] is None:
            raise InputError(source, where, "coordinates without a motion (G0, G1, G2 or G3)")
        zero, scale = offsets[state["offset"]], state["scale"]
        target = position.copy()
        for i, axis in enumerate(AXES):
            if axis in values:
                target[i] = zero[i] + scale * values[axis] if state["absolute"] else position[i] + scale * values[axis]
        if state["motion"] in (0, 1):
            if np.allclose(target, position, atol=1e-12):
                position = target
                if ended:
                    break
                continue
            pts = np.vstack([position, target])
        else:
            pts = _arc(position, target, values, state, zero, chord_tolerance, source, line_no, motion_here)
        rapid = state["motion"] == 0
        moves.append(Move(rapid, pts, None if rapid else state["feed"], line_no))
        position = target
        if ended:
            break
    return moves


def read_program(path: Path, chord_tolerance: float = 1e-4, offsets: dict[str, np.ndarray] | None = None) -> list[Move]:
    """The moves of the program in ``path``; checked: at least one cutting move, and feeds on every cutting
    move if the program has any."""
    path = Path(path)
    moves = parse_program(read_text(path), path, chord_tolerance, offsets)
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


def sample_program(moves: list[Move], spacing: float, rapid_speed: float) -> SampledProgram:
    """Waypoints spaced by arc length (at most ``spacing`` m apart, each move split evenly) from the start of
    the first cutting move to the end of the last; rapids in between run at ``rapid_speed`` (m/s).

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
    points, t = np.array(points), np.array(times)
    if not timed:
        t = t / t[-1]
    return SampledProgram(points, t, tangents, tracked, "s" if timed else "task")
