"""The `frustum` command: output of `compose`, --version, and one-line errors with exit status 1."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from frustum import __version__, compose, rotate_z, translate
from frustum.cli import parse_step


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "frustum", *arguments], capture_output=True, text=True, timeout=120, check=False
    )


def test_version():
    result = run("--version")
    assert result.returncode == 0
    assert result.stdout.strip() == f"frustum {__version__}"


def test_compose_prints_steps_composite_and_moved_point():
    result = run("compose", "translate=-1,0,0", "rotate_z_deg=90", "translate=1,0,0", "--point", "2,0,0")
    assert result.returncode == 0, result.stderr
    assert "composite M = M3 · M2 · M1" in result.stdout
    # rotating (2, 0, 0) by 90° about the vertical line through (1, 0, 0) gives (1, 1, 0)
    assert "M · (2, 0, 0, 1) = (1, 1, 0, 1)" in result.stdout


def test_parse_step_builds_the_same_matrices_as_the_api():
    np.testing.assert_allclose(parse_step("rotate_z_deg=30").matrix, rotate_z(np.radians(30)))
    np.testing.assert_allclose(parse_step("translate=1,2,3").matrix, translate(1, 2, 3))
    np.testing.assert_allclose(parse_step("scale=2").matrix, np.diag([2.0, 2, 2, 1]))
    np.testing.assert_allclose(parse_step("reflect=xy").matrix, np.diag([1.0, 1, -1, 1]))
    np.testing.assert_allclose(parse_step("shear=z,1,2,3").matrix[:2, 2:], [[1, -3], [2, -6]])
    np.testing.assert_allclose(
        parse_step("rotate_deg=0,0,1,90,1,0,0").matrix,
        compose(translate(-1, 0, 0), rotate_z(np.pi / 2), translate(1, 0, 0)),
        atol=1e-15,
    )
    np.testing.assert_allclose(parse_step("quaternion=0,0,0,1").matrix, np.diag([-1.0, -1, 1, 1]), atol=1e-15)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (("compose", "rotate_deg=0,0,0,90"), "error: rotate: axis = (0.0, 0.0, 0.0) has zero length"),
        (("compose", "spin=1"), "error: step 'spin=1': 'spin' is not a transformation; expected one of"),
        (("compose", "translate=1,2"), "error: step 'translate=1,2': got 2 numbers; expected 3"),
        (("compose", "translate"), "error: step 'translate' has no '='"),
        (("compose", "scale=a,b,c"), "is not a comma-separated list of numbers"),
        (("compose", "scale=1", "--point", "1,2"), "got 2 numbers; expected 3"),
    ],
)
def test_bad_input_prints_one_line_and_exits_1(arguments, message):
    result = run(*arguments)
    assert result.returncode == 1
    assert result.stderr.count("\n") == 1, result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.stderr
