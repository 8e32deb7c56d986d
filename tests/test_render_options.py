"""``frustum.render.options``: ``render``'s keyword arguments checked once into one frozen ``RenderOptions``, by the
same code whether they come from a call or from a scene file's ``[render]`` table."""

import dataclasses
import inspect
import math

import numpy as np
import pytest

from frustum import Camera, FrustumError, Scene, render
from frustum.render.options import DEFAULTS, RenderOptions


def _camera():
    return Camera.look_at((0, 0, 3), (0, 0, 0), (0, 1, 0), width=8, height=6)


def test_defaults_are_renders_signature():
    parameters = inspect.signature(render).parameters
    keywords = {name: p.default for name, p in parameters.items() if p.kind is inspect.Parameter.KEYWORD_ONLY}
    assert keywords == DEFAULTS


def test_options_are_frozen_and_built_from_keywords():
    options = RenderOptions.from_keywords(Scene(), _camera(), mode="surface+edges", samples=4, filter="tent")
    assert (options.mode, options.factor, options.filter, options.edges) == ("surface+edges", 2, "tent", "feature")
    assert options.crease_angle == math.radians(30.0)
    np.testing.assert_array_equal(options.edge_color, [255.0, 255.0, 255.0, 255.0])  # white on the black default
    assert options.supersampled().line_width == 2.0 and options.line_width == 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.mode = "wireframe"  # type: ignore[misc]


@pytest.mark.parametrize(
    "keywords",
    [{"shading": "glossy"}, {"samples": 3}, {"mode": "surface", "line_width": 0.5}, {"transparency": "depth-peel"},
     {"method": "painter"}, {"filter": "gauss"}, {"buffers": "normals"}],
)  # fmt: skip
def test_a_bad_option_gets_renders_message(keywords):
    with pytest.raises(FrustumError) as from_render:
        render(Scene(), _camera(), **keywords)
    with pytest.raises(FrustumError) as from_table:
        RenderOptions.from_keywords(Scene(), _camera(), **keywords)
    assert str(from_table.value) == str(from_render.value)


def test_an_unknown_keyword_is_named():
    with pytest.raises(FrustumError, match=r"render: unknown option 'shadow'; expected one of shading, "):
        RenderOptions.from_keywords(Scene(), _camera(), shadow=True)
