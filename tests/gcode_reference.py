"""A second G-code reader for the tests, written apart from designopt.gcode (no shared code, another method):
cut and rapid lengths of a program, arcs measured exactly (r |dtheta|, a helix by Pythagoras) instead of sampled.

Reads what the corpus uses: G0-G3 (I/J/K offsets from the start, or R), G17-G19, G20/G21, G90/G91, comments,
words without spaces, M2/M30 (the end). Anything else is ignored, which is why it is only a reference for
programs designopt accepts."""

from __future__ import annotations

import math


def _tokens(line: str):
    """(letter, number) pairs by scanning characters."""
    out, i = [], 0
    s = line.upper()
    while i < len(s):
        c = s[i]
        if c == "(":
            i = s.find(")", i) + 1 or len(s)
            continue
        if c == ";":
            break
        if c.isalpha():
            j = i + 1
            while j < len(s) and (s[j] in "+-.0123456789" or s[j] == " "):
                j += 1
            number = s[i + 1:j].replace(" ", "")
            try:
                out.append((c, float(number)))
            except ValueError:
                pass
            i = j
            continue
        i += 1
    return out


def lengths(text: str) -> tuple[float, float]:
    """(cut length, rapid length) in millimetres."""
    pos = [0.0, 0.0, 0.0]
    motion, plane, inch, absolute = None, 17, False, True
    cut = rapid = 0.0
    axes = {"X": 0, "Y": 1, "Z": 2}
    plane_axes = {17: (0, 1, 2, "I", "J"), 18: (2, 0, 1, "K", "I"), 19: (1, 2, 0, "J", "K")}
    for raw in text.splitlines():
        words = _tokens(raw)
        if not words:
            continue
        unit = 25.4 if inch else 1.0
        new = list(pos)
        has_axis = False
        params = {}
        for letter, value in words:
            if letter == "G":
                g = round(value, 1)
                if g in (0, 1, 2, 3):
                    motion = int(g)
                elif g in (17, 18, 19):
                    plane = int(g)
                elif g == 20:
                    inch = True
                elif g == 21:
                    inch = False
                elif g == 90:
                    absolute = True
                elif g == 91:
                    absolute = False
            elif letter == "M" and value in (2, 30):
                return cut, rapid
            else:
                params[letter] = value
        unit = 25.4 if inch else 1.0
        for letter, k in axes.items():
            if letter in params:
                has_axis = True
                new[k] = params[letter] * unit if absolute else pos[k] + params[letter] * unit
        if motion is None or not (has_axis or (motion in (2, 3) and any(c in params for c in "IJK"))):
            continue
        if motion in (0, 1):
            d = math.dist(pos, new)
            if motion == 0:
                rapid += d
            else:
                cut += d
        else:
            a, b, n, ia, ib = plane_axes[plane]
            if "R" in params:
                r = abs(params["R"] * unit)
                chord = math.hypot(new[a] - pos[a], new[b] - pos[b])
                angle = 2 * math.asin(min(chord / (2 * r), 1.0))
                if params["R"] < 0:
                    angle = 2 * math.pi - angle
            else:
                ca, cb = pos[a] + params.get(ia, 0.0) * unit, pos[b] + params.get(ib, 0.0) * unit
                r = math.hypot(pos[a] - ca, pos[b] - cb)
                t0 = math.atan2(pos[b] - cb, pos[a] - ca)
                t1 = math.atan2(new[b] - cb, new[a] - ca)
                angle = (t0 - t1) if motion == 2 else (t1 - t0)
                angle %= 2 * math.pi
                if angle < 1e-12:
                    angle = 2 * math.pi
            cut += math.hypot(r * angle, new[n] - pos[n])
        pos = new
    return cut, rapid
