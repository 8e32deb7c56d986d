"""README.md stays true: it opens with exactly two commands, and its Python tour runs."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

README = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```(\w*)\n(.*?)```", README, flags=re.DOTALL)


def test_readme_opens_with_exactly_two_commands():
    before_first_block = README.split("```", 1)[0]
    assert before_first_block.strip().startswith("# frustum")
    assert before_first_block.strip().count("\n") == 0, "nothing but the title may precede the two commands"
    language, body = BLOCKS[0]
    commands = body.strip().splitlines()
    assert language == "bash" and len(commands) == 2
    assert "pytest" in commands[1] and "pytest" not in commands[0]


def test_readme_main_command_renders_the_example_scene(tmp_path):
    main_call = shlex.split(BLOCKS[0][1].strip().splitlines()[0].split("&&")[-1])
    assert main_call[:3] == [".venv/bin/frustum", "render", "examples/teapot.toml"]
    assert main_call[3:] == ["-o", "example.png"]
    out = tmp_path / "example.png"
    scene_file = Path(__file__).parents[1] / main_call[2]
    result = subprocess.run(
        [sys.executable, "-m", "frustum", "render", str(scene_file), "-o", str(out), "--size", "96x64"],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    image = np.asarray(Image.open(out))
    assert image.shape == (64, 96, 4)
    # the teapot and its control net cover part of the image, the background the rest
    background = np.all(image == image[0, 0], axis=2)
    assert 0.2 < background.mean() < 0.95


@pytest.mark.parametrize("index", [i for i, (language, _) in enumerate(BLOCKS) if language == "python"])
def test_readme_python_tour_runs(index, capsys):
    exec(compile(BLOCKS[index][1], "README.md", "exec"), {})
