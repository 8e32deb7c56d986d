"""The work budget: limits set in Python or the environment; errors give the estimate, the budget and the fix."""

import subprocess
import sys

import pytest

import frustum as fr
from frustum.budgets import check_memory, check_operations, format_bytes


def test_defaults_and_set_budget_round_trip():
    previous = fr.set_budget(bytes="2G", operations=1e6)
    try:
        assert fr.get_budget() == fr.Budget(bytes=2 * 2**30, operations=10**6)
    finally:
        fr.set_budget(previous.bytes, previous.operations)
    assert fr.get_budget() == previous


def test_context_manager_restores():
    before = fr.get_budget()
    with fr.budget(bytes=1000):
        assert fr.get_budget().bytes == 1000
        expected = r"uv_sphere: segments = 9 needs about 2\.0 KiB, over the memory budget of 1000 B; .*MAX_BYTES"
        with pytest.raises(fr.GeometryError, match=expected):
            check_memory(2000, where="uv_sphere", cause="segments = 9", error=fr.GeometryError)
    assert fr.get_budget() == before


def test_operations_over_budget():
    with pytest.raises(fr.FrustumError, match=r"mandelbrot: .* 1e\+12 operations, over the work budget"):
        check_operations(1e12, where="mandelbrot", cause="64 x 64 pixels x max_iter = 1e12")
    check_operations(10, where="x", cause="y")


@pytest.mark.parametrize("bad", [0, -1, "lots", float("nan"), True, "G"])
def test_bad_budget_values(bad):
    with pytest.raises(fr.FrustumError, match=r"set_budget: bytes = .* is not a positive number"):
        fr.set_budget(bytes=bad)


def test_environment_variables():
    code = "import frustum as fr; b = fr.get_budget(); print(b.bytes, b.operations)"
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={"FRUSTUM_MAX_BYTES": "512M", "FRUSTUM_MAX_OPERATIONS": "2e3", "PATH": ""},
    )
    assert out.stdout.split() == [str(512 * 2**20), "2000"]


def test_format_bytes():
    assert format_bytes(512) == "512 B"
    assert format_bytes(3 * 2**30) == "3.0 GiB"
