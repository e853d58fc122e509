"""The milling force model against hand computations (closed-form integrals of the Kienzle edge force)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designopt.config import parse_config
from designopt.forces import MATERIALS, Material, MillingProcess, mean_force, milling_force_components
from designopt.problem import problem_from_config

LINEAR = Material("linear", kc11=1000.0, mc=0.0, radial_ratio=0.3, axial_ratio=0.2, source="test")


def _process(material, width=None, direction="down"):
    return MillingProcess(material, diameter=0.01, teeth=3, feed_per_tooth=1e-4, axial_depth=2e-3,
                          radial_width=width, direction=direction)


def test_slot_with_a_linear_edge_law():
    # m_c = 0: F_t = K b f sin(phi). Over a slot, int sin cos = 0, int sin^2 = pi/2, int sin = 2, so with
    # z teeth the mean is F_x = -z K b f r / 4, F_y = z K b f / 4, F_z = z a K b f / pi.
    K, b, f, z = 1000.0, 2.0, 0.1, 3  # N/mm^2, mm, mm
    expected = [-z * K * b * f * 0.3 / 4, z * K * b * f / 4, z * 0.2 * K * b * f / math.pi]
    np.testing.assert_allclose(mean_force(_process(LINEAR)), expected, rtol=1e-12)


def test_slot_with_kienzle_exponent():
    # F_t = K b (f sin phi)^p, p = 1 - m_c: int_0^pi sin^(p+1) = sqrt(pi) G((p+2)/2) / G((p+3)/2), and the cos
    # terms vanish by symmetry about pi/2.
    m = MATERIALS["steel_c45"]
    p, K, b, f, z = 1 - m.mc, m.kc11, 2.0, 0.1, 3
    I_p1 = math.sqrt(math.pi) * math.gamma((p + 2) / 2) / math.gamma((p + 3) / 2)
    I_p = math.sqrt(math.pi) * math.gamma((p + 1) / 2) / math.gamma((p + 2) / 2)
    scale = z / (2 * math.pi) * K * b * f**p
    expected = [-scale * m.radial_ratio * I_p1, scale * I_p1, scale * m.axial_ratio * I_p]
    # the quadrature converges algebraically on sin^p (p < 1): 256 nodes give ~1e-9
    np.testing.assert_allclose(mean_force(_process(m)), expected, rtol=1e-8)


@pytest.mark.parametrize("direction", ["down", "up"])
def test_half_immersion_side_cut(direction):
    # a_e = D / 2: phi_e = pi / 2; down milling engages [pi/2, pi], up milling [0, pi/2].
    a, c = (math.pi / 2, math.pi) if direction == "down" else (0.0, math.pi / 2)
    sin_cos = (math.sin(c) ** 2 - math.sin(a) ** 2) / 2
    sin2 = (c - a) / 2 - (math.sin(2 * c) - math.sin(2 * a)) / 4
    sin1 = math.cos(a) - math.cos(c)
    K, b, f, z, r, ax = 1000.0, 2.0, 0.1, 3, 0.3, 0.2
    s = z / (2 * math.pi) * K * b * f
    expected = [-s * (sin_cos + r * sin2), s * (sin2 - r * sin_cos), s * ax * sin1]
    np.testing.assert_allclose(mean_force(_process(LINEAR, 0.005, direction)), expected, rtol=1e-12, atol=1e-12)


def test_components_follow_the_feed_frame_in_W():
    tangents = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, -1.0]])  # +x, +y, then a plunge (borrows +y)
    comp = milling_force_components(_process(LINEAR), tangents)
    F = mean_force(_process(LINEAR))
    np.testing.assert_allclose(comp[0, 0], [F[0], 0, 0], atol=1e-12)  # feed component along +x
    np.testing.assert_allclose(comp[1, 0], [0, F[1], 0], atol=1e-12)  # feed-normal: left of the feed (+y)
    np.testing.assert_allclose(comp[1, 1], [-F[1], 0, 0], atol=1e-12)  # feeding +y, left is -x
    np.testing.assert_allclose(comp[2, 2], [0, 0, F[2]], atol=1e-12)
    np.testing.assert_allclose(comp[:, 2], comp[:, 1], atol=1e-12)


def test_config_milling_model_loads_only_cutting_waypoints():
    """Every key of the config's force block reaches the process whose mean force loads the path (the mean
    force itself is checked against closed forms above)."""
    cfg = parse_config({"toolpath": {"kind": "line", "waypoints": 5,
                                     "force": {"material": "steel_c45", "teeth": 4, "feed_per_tooth": 1e-4,
                                               "axial_depth": 2e-3}}})
    tp = problem_from_config(cfg).toolpath
    assert tp.force_model == "milling"
    process = MillingProcess(MATERIALS["steel_c45"], 0.010, 4, 1e-4, 2e-3)  # a full slot: any diameter
    np.testing.assert_allclose(tp.force_W, np.tile(mean_force(process), (5, 1)), rtol=1e-12)
