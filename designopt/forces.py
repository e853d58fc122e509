"""Process forces on the tool: the paper's alpha * tangent and a milling model (Kienzle per tooth, averaged
over a revolution).

The milling model (docs/production.md) follows the mechanistic milling model of Altintas (Manufacturing
Automation, 2nd ed., Cambridge University Press 2012, ch. 2) with Kienzle's power law for the edge force:
a tooth at immersion angle phi cuts a chip of thickness h(phi) = f_z sin(phi) and width b (the axial depth),
and feels

    F_t = k_c1.1 * b * h^(1 - m_c)      tangential (against the cutting speed)
    F_r = r_r * F_t                     radial (pushes the tool away from the cut)
    F_a = r_a * F_t                     axial (along the tool axis, out of the material)

k_c1.1 is the specific cutting force for a chip of 1 mm x 1 mm (N/mm^2), m_c Kienzle's exponent.

Frames: the feed frame has x along the feed direction (the path tangent projected onto W's x-y plane), z
along W's z (out of the workpiece's top face; the tool points along -z) and y = z x x (left of the feed). The
spindle turns clockwise seen from above (M3). The immersion angle phi runs clockwise from +y, so the tooth
at phi sits at (sin phi, cos phi), moves along (cos phi, -sin phi), and the force on the tool is

    F_x = -F_t cos(phi) - F_r sin(phi),    F_y = F_t sin(phi) - F_r cos(phi),    F_z = F_a.

The mean over a revolution with z teeth is (z / 2 pi) times the integral over the engaged angles: a slot
engages [0, pi]; a side cut of width a_e engages [0, phi_e] (up milling) or [pi - phi_e, pi] (down
milling), with cos(phi_e) = 1 - 2 a_e / D. Units in: metres; Kienzle's law in mm and N/mm^2; out: newtons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

COMPONENTS = ("feed", "feed-normal", "axial")


@dataclass(frozen=True)
class Material:
    """Kienzle parameters of a work material and the force ratios of the milling edge."""

    name: str
    kc11: float  # N/mm^2
    mc: float
    radial_ratio: float
    axial_ratio: float
    source: str


# Sources in docs/production.md. Radial and axial ratios are typical of sharp end mills (Altintas 2012, ch. 2:
# K_rc / K_tc ~ 0.3-0.4 for aluminium and steel); they are assumptions, overridable in the config.
MATERIALS: dict[str, Material] = {
    "aluminium": Material("aluminium", kc11=700.0, mc=0.25, radial_ratio=0.35, axial_ratio=0.15,
                          source="Sandvik Coromant, specific cutting force kc1 for ISO N wrought aluminium "
                                 "alloys (order of 700 N/mm^2, mc 0.25)"),
    "steel_c45": Material("steel_c45", kc11=1660.0, mc=0.21, radial_ratio=0.4, axial_ratio=0.2,
                          source="Kienzle table for C45 / Ck45 (k_c1.1 about 1660 N/mm^2, 1 - m_c about 0.79) as "
                                 "tabulated in machining handbooks (Koenig & Klocke, Fertigungsverfahren 1)"),
}


@dataclass(frozen=True)
class MillingProcess:
    """An end-milling operation: tool, engagement and feed (lengths in metres)."""

    material: Material
    diameter: float
    teeth: int
    feed_per_tooth: float
    axial_depth: float
    radial_width: float | None = None  # None: a full slot
    direction: str = "down"  # down (climb) or up (conventional) milling when radial_width < diameter

    def engagement(self) -> tuple[float, float]:
        """(phi_in, phi_out), radians."""
        if self.radial_width is None or self.radial_width >= self.diameter:
            return 0.0, math.pi
        phi_e = math.acos(1.0 - 2.0 * self.radial_width / self.diameter)
        return (math.pi - phi_e, math.pi) if self.direction == "down" else (0.0, phi_e)


def edge_forces(process: MillingProcess, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F_t, F_r, F_a) on one tooth at immersion angles phi, newtons."""
    m = process.material
    h_mm = np.maximum(process.feed_per_tooth * 1e3 * np.sin(phi), 0.0)
    F_t = m.kc11 * process.axial_depth * 1e3 * h_mm ** (1.0 - m.mc)
    return F_t, m.radial_ratio * F_t, m.axial_ratio * F_t


def mean_force(process: MillingProcess, nodes: int = 256) -> np.ndarray:
    """Mean force on the tool over a revolution, (feed, feed-normal, axial) in the feed frame, newtons.

    Gauss-Legendre quadrature: h^(1 - m_c) has an unbounded derivative where a tooth enters or leaves at zero chip
    thickness, so it converges algebraically; 256 nodes give ~1e-9 relative (measured against the closed form).
    """
    a, b = process.engagement()
    x, w = np.polynomial.legendre.leggauss(nodes)
    phi = 0.5 * (b - a) * x + 0.5 * (b + a)
    w = 0.5 * (b - a) * w
    F_t, F_r, F_a = edge_forces(process, phi)
    F_x = -F_t * np.cos(phi) - F_r * np.sin(phi)
    F_y = F_t * np.sin(phi) - F_r * np.cos(phi)
    scale = process.teeth / (2.0 * math.pi)
    return scale * np.array([w @ F_x, w @ F_y, w @ F_a])


def feed_frames(tangents_W: np.ndarray) -> np.ndarray:
    """(N, 3, 3): columns x (feed in W's x-y plane), y = z x x, z = W's z. A vertical move (a plunge) has no
    feed direction in the plane; it borrows the nearest waypoint's (or W's x if the whole path is vertical)."""
    t = np.asarray(tangents_W, dtype=float)
    planar = t[:, :2].copy()
    norm = np.linalg.norm(planar, axis=1)
    ok = norm > 1e-9
    if not ok.any():
        planar[:] = (1.0, 0.0)
    else:
        good = np.flatnonzero(ok)
        nearest = good[np.abs(np.arange(len(t))[:, None] - good[None, :]).argmin(axis=1)]
        planar = planar[nearest] / norm[nearest, None]
    x = np.column_stack([planar, np.zeros(len(t))])
    z = np.tile([0.0, 0.0, 1.0], (len(t), 1))
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=2)


def milling_force_components(process: MillingProcess, tangents_W: np.ndarray) -> np.ndarray:
    """(3, N, 3): the feed, feed-normal and axial force vectors in W at every waypoint (they sum to the force)."""
    frames = feed_frames(tangents_W)
    mean = mean_force(process)
    return np.stack([mean[i] * frames[:, :, i] for i in range(3)])
