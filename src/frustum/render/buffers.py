"""Frame buffers: the work arrays recycled between calls (``Scratch``, and ``take_array`` for the passes' per-pixel
arrays) and the color and depth arrays recycled between frames (``FrameBuffers``), the clear, and the filters that
resolve a supersampled image (box or tent, nearest depth). What one frame draws into is ``render.context``."""

from __future__ import annotations

import math
import sys
import threading
from typing import Any, ClassVar

import numpy as np

_HUGE_PAGE = 1 << 21


class Scratch:
    """Work arrays of one ``render`` call (buffers no Frame returns: face codes, barycentrics, window records,
    tile lists), taken from the arrays the previous call gave back when shape and dtype match.

    A fresh large array costs a first-touch pass (the kernel zeroes every page) on top of its use: reusing the
    last frame's saves that on every frame of an animation or a multi-view render of the same scene. At most one
    call's arrays are kept (``release`` replaces them); concurrent calls each take distinct arrays (a lock
    guards the pool), so renders in threads never share one.
    """

    _pool: ClassVar[dict[tuple, list[np.ndarray]]] = {}
    _lock: ClassVar[threading.Lock] = threading.Lock()

    def __init__(self) -> None:
        self.taken: list[np.ndarray] = []
        self.free: dict[tuple, list[np.ndarray]] = {}

    def empty(self, shape: tuple[int, ...], dtype: Any = np.float64) -> np.ndarray:
        """An uninitialized array like ``np.empty(shape, dtype)``: one this call recycled, or one of the pool."""
        key = (tuple(int(n) for n in shape), np.dtype(dtype).str)
        arrays = self.free.get(key)
        array = arrays.pop() if arrays else None
        if array is None:
            with Scratch._lock:
                arrays = Scratch._pool.get(key)
                array = arrays.pop() if arrays else None
        if array is None:
            array = np.empty(key[0], dtype=dtype)
        self.taken.append(array)
        return array

    def recycle(self, *arrays: np.ndarray) -> None:
        """Arrays this call took and no longer reads: free for its next ``empty`` of the same shape (next item)."""
        for array in arrays:
            self.free.setdefault((array.shape, array.dtype.str), []).append(array)

    def release(self) -> None:
        """Give this call's arrays to the pool, in place of what it held."""
        pool: dict[tuple, list[np.ndarray]] = {}
        for array in {id(a): a for a in self.taken}.values():
            pool.setdefault((array.shape, array.dtype.str), []).append(array)
        with Scratch._lock:
            Scratch._pool = pool
        self.taken, self.free = [], {}

    @classmethod
    def release_pool(cls) -> int:
        """Forget the pooled arrays; return their bytes."""
        with cls._lock:
            released = sum(a.nbytes for arrays in cls._pool.values() for a in arrays)
            cls._pool = {}
        return released


class FrameBuffers:
    """The color and depth arrays a Frame returns, recycled once nobody holds them (double buffering).

    A new large array costs a first-touch pass (the kernel zeroes each page on first write) on top of the clear:
    about 18 ms of a 4096² frame. The buffers of the last few frames stay in a short list; a request takes one of
    them when no array outside the list still refers to it (its reference count says so: every view of a NumPy
    array holds its base), so a program that keeps the previous Frame while rendering the next (an animation
    loop) alternates between two sets, and one that keeps every Frame gets new arrays each time. Buffers start on
    a 2 MiB boundary, so the kernel can back them with huge pages (2 page faults per 4 MiB instead of ~1000).
    ``release_memory()`` empties the list.
    """

    KEEP = 4
    """Buffers kept: color and depth of two frames."""
    _kept: ClassVar[list[np.ndarray]] = []
    _lock: ClassVar[threading.Lock] = threading.Lock()

    @classmethod
    def take(cls, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
        """An uninitialized ``np.empty(shape, dtype)``, 2 MiB-aligned: a kept buffer nobody holds, or a new one."""
        dtype = np.dtype(dtype)
        size = math.prod(shape) * dtype.itemsize
        if size < _HUGE_PAGE:
            return np.empty(shape, dtype=dtype)
        with cls._lock:
            for index in range(len(cls._kept)):
                raw = cls._kept[index]  # free when only the list, this name and getrefcount's argument hold it
                if raw.nbytes == size + _HUGE_PAGE and sys.getrefcount(raw) == 3:
                    del cls._kept[index]
                    break
            else:
                raw = np.empty(size + _HUGE_PAGE, dtype=np.uint8)
            cls._kept.append(raw)  # most recently used last; the oldest go first
            del cls._kept[: -cls.KEEP]
            start = -raw.ctypes.data % _HUGE_PAGE
            return raw[start : start + size].view(dtype).reshape(shape)

    @classmethod
    def release(cls) -> int:
        """Forget the kept buffers; return their bytes (those still held by Frames stay alive with them)."""
        with cls._lock:
            released = sum(raw.nbytes for raw in cls._kept if sys.getrefcount(raw) == 3)
            cls._kept = []
        return released


def clear_buffers(depth: np.ndarray, color: np.ndarray, background: np.ndarray) -> None:
    """Depth 1.0 (far) and the background color bytes (4,) everywhere (NumPy's fills run at memory bandwidth, as
    a compiled loop did, without its compile time). Face codes need no clearing: a pixel is drawn exactly where
    its depth is below 1, and only there are codes and barycentrics read."""
    depth.fill(1.0)
    color.view(np.uint32).fill(background.view(np.uint32)[0])


def resolve_color(big: np.ndarray, factor: int) -> np.ndarray:
    """Box-filter resolve in integers: (H·s, W·s, 4) uint8 → (H, W, 4) uint8, each channel the rounded mean of
    its s×s block, $floor(Σ/s² + 1/2) = (2·Σ + s²) // (2·s²)$ (exactly the rounded mean)."""
    height, width = big.shape[0] // factor, big.shape[1] // factor
    area = factor * factor
    # Σ + ⌊s²/2⌋ ≤ 255·s² + s²/2 fits uint16 up to s = 16; the rounded mean is then (Σ + ⌊s²/2⌋) // s², the same
    # integer as above. Rows first (contiguous planes of whole rows), then the s samples side by side: a few
    # in-place adds instead of a strided two-axis reduction (23 → 1.6 ms for 480 × 360 × 4 samples).
    dtype = np.uint16 if area <= 256 else np.uint32
    rows = big.reshape(height, factor, width * factor * 4)
    across = rows[:, 0].astype(dtype)
    for i in range(1, factor):
        across += rows[:, i]
    columns = across.reshape(height, width, factor, 4)
    total = columns[:, :, 0].copy()
    for j in range(1, factor):
        total += columns[:, :, j]
    total += area // 2
    total //= area
    return total.astype(np.uint8)


def block_min(values: np.ndarray, factor: int) -> np.ndarray:
    """(H·s, W·s) → (H, W): the minimum of each s×s block, as in-place ``np.minimum`` of its row and column
    planes (0.2 ms for 960 × 720 against 11 ms for a strided ``min(axis=(1, 3))``; the same values)."""
    height, width = values.shape[0] // factor, values.shape[1] // factor
    rows = values.reshape(height, factor, width * factor)
    across = rows[:, 0].copy()
    for i in range(1, factor):
        np.minimum(across, rows[:, i], out=across)
    columns = across.reshape(height, width, factor)
    result = columns[:, :, 0].copy()
    for j in range(1, factor):
        np.minimum(result, columns[:, :, j], out=result)
    return result


def downsample(values: np.ndarray, factor: int, kind: str) -> np.ndarray:
    """(H·s, W·s, C) → (H, W, C): the mean of each s×s block ("box"), or a separable tent of width 2s centred
    on each block (weights $s − |offset|$ for the 2s − 1 samples around it, edges clamped)."""
    height, width = values.shape[0] // factor, values.shape[1] // factor
    if kind == "box":
        return values.reshape(height, factor, width, factor, -1).mean(axis=(1, 3))
    offsets = np.arange(-(factor - 1), factor) if factor > 1 else np.array([0])
    weights = (factor - np.abs(offsets)).astype(np.float64)
    weights /= weights.sum()

    def along(array: np.ndarray, axis: int, size: int) -> np.ndarray:
        # output k is centred between samples k·s + (s − 1)/2: use the sample pair around the centre
        total = np.zeros((*array.shape[:axis], size, *array.shape[axis + 1 :]))
        for offset, weight in zip(offsets, weights, strict=True):
            index = np.clip(np.arange(size) * factor + (factor - 1) // 2 + offset, 0, array.shape[axis] - 1)
            if factor % 2 == 0:  # even blocks: average the two centre-adjacent alignments
                index2 = np.clip(index + 1, 0, array.shape[axis] - 1)
                total += 0.5 * weight * (np.take(array, index, axis=axis) + np.take(array, index2, axis=axis))
            else:
                total += weight * np.take(array, index, axis=axis)
        return total

    return along(along(values, 0, height), 1, width)


_POOL: dict[tuple, list[np.ndarray]] = {}
_POOL_LOCK = threading.Lock()


def take_array(shape: tuple[int, ...], dtype: Any) -> np.ndarray:
    """An uninitialized work array, one a previous frame gave back where shape and dtype match (no first-touch
    page faults for the maps and per-pixel arrays of an animation's every frame)."""
    key = (tuple(shape), np.dtype(dtype).str)
    with _POOL_LOCK:
        arrays = _POOL.get(key)
        if arrays:
            return arrays.pop()
    return np.empty(shape, dtype=dtype)


def give_back(*arrays: np.ndarray) -> None:
    """Keep `arrays` for the next frame (only the last frame's: the pool holds one array per shape)."""
    with _POOL_LOCK:
        for array in arrays:
            _POOL[(array.shape, array.dtype.str)] = [array]


def release_work_arrays() -> int:
    """Free the arrays ``take_array`` keeps between frames; return their bytes."""
    with _POOL_LOCK:
        released = sum(a.nbytes for arrays in _POOL.values() for a in arrays)
        _POOL.clear()
    return released


_KEEPERS: list[Any] = []
"""``release`` functions of the passes that keep memory between frames (the shadow pass's maps), added by each
pass's module when it is first imported: ``render.release_memory`` frees what they hold without importing a pass
that never ran."""


def keeps_memory(release: Any) -> Any:
    """Register `release` (() -> bytes freed) with ``release_kept``; returns it (usable as a decorator)."""
    _KEEPERS.append(release)
    return release


def release_kept() -> int:
    """Call every registered pass's release function; return the bytes they freed."""
    return sum(release() for release in _KEEPERS)
