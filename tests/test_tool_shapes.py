"""Tool shapes: profiles checked against values worked out by hand."""

import math

import numpy as np
import pytest

from gcodekit.errors import ConfigError
from gcodekit.tool_shapes import ToolShape


def test_endmill_is_flat_and_full_radius():
    tool = ToolShape("endmill", diameter=6.0)
    assert np.all(tool.height_at([0.0, 1.5, 3.0]) == 0.0)
    assert np.isnan(tool.height_at(3.1))
    assert tool.radius_at(0.0) == 3.0 and tool.radius_at(-0.1) == 0.0


def test_ballend_is_a_hemisphere():
    tool = ToolShape("ballend", diameter=10.0)
    # at r = 3 on a 5 mm sphere: 5 - sqrt(25 - 9) = 1
    assert tool.height_at(3.0) == pytest.approx(1.0)
    assert tool.radius_at(1.0) == pytest.approx(3.0)
    assert tool.tip_height == pytest.approx(5.0)
    assert tool.radius_at(20.0) == pytest.approx(5.0)


def test_bullnose_flat_then_corner():
    tool = ToolShape("bullnose", diameter=10.0, corner_radius=2.0)
    assert tool.height_at(3.0) == 0.0  # inside the 3 mm flat
    # 1 mm into the 2 mm corner: 2 - sqrt(4 - 1)
    assert tool.height_at(4.0) == pytest.approx(2 - math.sqrt(3))
    assert tool.tip_height == pytest.approx(2.0)


def test_vbit_and_drill_cones():
    vbit = ToolShape("vbit", diameter=10.0, angle=60.0)
    assert vbit.height_at(5.0) == pytest.approx(5.0 / math.tan(math.radians(30)))
    drill = ToolShape("drill", diameter=8.0)
    assert drill.angle == 118.0
    assert drill.tip_height == pytest.approx(4.0 / math.tan(math.radians(59)))


def test_chamfer_has_a_flat_tip():
    tool = ToolShape("chamfer", diameter=12.0, angle=90.0, tip_diameter=2.0)
    assert tool.height_at(1.0) == 0.0
    assert tool.height_at(6.0) == pytest.approx(5.0)
    assert tool.radius_at(2.0) == pytest.approx(3.0)


def test_profile_closes_the_body():
    prof = ToolShape("ballend", diameter=6.0, length=20.0).profile(8)
    assert tuple(prof[0]) == (0.0, 0.0) and tuple(prof[-1]) == (3.0, 20.0)
    assert np.all(np.diff(prof[:, 1]) >= 0)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"kind": "endmil", "diameter": 6}, "did you mean 'endmill'"),
        ({"kind": "endmill", "diameter": 0}, "positive"),
        ({"kind": "endmill", "diameter": -3}, "positive"),
        ({"kind": "bullnose", "diameter": 6, "corner_radius": 4}, "corner_radius"),
        ({"kind": "vbit", "diameter": 6, "angle": 190}, "angle"),
    ],
)
def test_bad_shapes_are_config_errors(kwargs, words):
    with pytest.raises(ConfigError, match=words):
        ToolShape(**kwargs)
