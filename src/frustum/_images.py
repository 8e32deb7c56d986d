"""Image files read under the work budget: the size from the header, checked before any pixel is decoded.

Pillow warns (``DecompressionBombWarning``) above 89 Mpx and refuses above twice that, whatever the machine; frustum
instead checks every image it reads — textures, MTL and glTF images, environment maps, scene-file images —
against the one memory budget (``frustum.budgets``), with its own message, and hides Pillow's warning.
"""

from __future__ import annotations

import warnings
from typing import Any

from frustum.budgets import check_memory
from frustum.errors import FrustumError

__all__ = ["BYTES_PER_IMAGE_PIXEL", "open_image"]

BYTES_PER_IMAGE_PIXEL = 24
"""Memory of one decoded pixel on its way to a kernel: RGBA bytes, a converted copy and float32 channels."""


def open_image(source: Any, *, where: str, name: str, error: type[FrustumError] = FrustumError) -> Any:
    """``PIL.Image.open(source)`` (a path or a binary file) after its header's width × height passed the memory
    budget; raises `error` naming `name` and the size otherwise. The pixels are decoded later, on first use."""
    from PIL import Image

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        try:
            image = Image.open(source)
        except Image.DecompressionBombError as bomb:  # past Pillow's hard limit: the budget says it as well
            raise error(f"{where}: {name} is too large to decode ({bomb}); give a smaller image") from None
    width, height = image.size
    try:
        check_memory(float(width) * height * BYTES_PER_IMAGE_PIXEL, where=where,
                     cause=f"{name} ({width} x {height} pixels)", error=error)  # fmt: skip
    except FrustumError:
        image.close()
        raise
    return image


def decode(image: Any) -> Any:
    """``image.load()`` with Pillow's decompression-bomb warning hidden (the budget has checked the size)."""
    from PIL import Image

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        image.load()
    return image
