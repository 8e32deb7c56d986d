"""Benchmark: Mandelbrot 4096² (Numba, parallel over rows) and a 2049² diamond-square fBm terrain.

    python benchmarks/bench_fractals.py [--repeat 5] [--size 4096] [--level 11] [--max-iter 256]

Prints the first call (Numba compilation or loading its on-disk cache, plus one run) separately from the steady
state: the median of `repeat` runs after that warm-up, with the thread count Numba uses. The Mandelbrot window is
the whole set, (-2, 1) × (-1.5, 1.5), with smooth colouring and escape radius 256; the terrain is H = 0.8, seed 0.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np

from frustum.geometry.escape_time import mandelbrot
from frustum.geometry.fractals import fbm_terrain


def _time(fn, repeat: int) -> tuple[float, float, object]:
    start = time.perf_counter()
    result = fn()
    first = time.perf_counter() - start
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        runs.append(time.perf_counter() - start)
    return first, statistics.median(runs), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--level", type=int, default=11)
    parser.add_argument("--max-iter", type=int, default=256)
    args = parser.parse_args()
    print(f"numba threads: {numba.get_num_threads()}")

    first, median, image = _time(
        lambda: mandelbrot((-2.0, 1.0, -1.5, 1.5), args.size, args.size, max_iter=args.max_iter), args.repeat
    )
    inside = float(np.isinf(image).mean())
    print(
        f"mandelbrot {args.size}x{args.size}, max_iter {args.max_iter}: first call {first:.3f} s, "
        f"median {median:.3f} s ({args.size * args.size / median / 1e6:.1f} Mpixel/s; {inside:.1%} inside)"
    )
    side = 2**args.level + 1
    first, median, _ = _time(lambda: fbm_terrain(args.level, 0.8, seed=0), args.repeat)
    print(f"diamond-square {side}x{side}: first call {first:.3f} s, median {median:.3f} s")
    first, median, _ = _time(lambda: fbm_terrain(args.level, 0.8, seed=0, method="midpoint"), args.repeat)
    print(f"midpoint displacement {side}x{side}: first call {first:.3f} s, median {median:.3f} s")


if __name__ == "__main__":
    main()
