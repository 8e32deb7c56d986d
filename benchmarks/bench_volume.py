"""Benchmark: a 256³ volume ray cast at 1024² (composite and MIP), frustum against VTK's CPU ray caster.

    python benchmarks/bench_volume.py [--size 256] [--image 1024] [--repeat 3] [--no-vtk]

The anchor is VTK's ``vtkFixedPointVolumeRayCastMapper`` through PyVista off-screen (EGL here), measured in
the same run with the same volume, camera (parallel projection, oblique view of the cube), image size, sample
distance (half a voxel; VTK's automatic sample-distance adjustment off), the same near plane and sample placement
(frustum's ``sampling="near"``: every whole multiple of the step from the ray's point on the near plane, which is
where VTK's caster puts its samples — ``ComputeRayInfo`` advances the ray start from the near plane by whole
steps to the first one inside the volume), trilinear interpolation, transfer functions (piecewise linear, opacity
unit distance one voxel) and no shading. The volume is
``frustum.head_phantom(size)`` (values in [0, 1]) smoothed by a Gaussian of σ = 1 voxel. VTK spreads a parallel
camera's window of height 2·ParallelScale over H − 1 pixel pitches (NDC ±1 on the centres of the first and last
pixel rows), frustum over H pixels (NDC ±1 on the image's edges, as OpenGL): the frustum camera's window is
made (H − 1)/H as tall to match. Prints the first call (Numba compilation or its on-disk cache, plus one run)
apart from the `repeat` runs after it (median wall time, and the least CPU time of the process: all threads,
which is what to compare on a busy machine), the ratios frustum / VTK, the share of pixels within ±2 levels of
VTK's (the MIP target; composite for information), the load average, and the peak resident memory.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import time

import numba
import numpy as np

import frustum as f


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _time(fn, repeat: int) -> tuple[float, float, float, object]:
    """(first call wall s, median wall s, least CPU s of the process) over `repeat` runs after the first."""
    start = time.perf_counter()
    result = fn()
    first = time.perf_counter() - start
    runs, cpu = [], []
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        result = fn()
        runs.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return first, statistics.median(runs), min(cpu), result


def _setup(size: int):
    """The phantom on the grid 0 … size − 1 (spacing 1), the view, and the two transfer functions."""
    from scipy.ndimage import gaussian_filter

    # band-limited (σ = 1 voxel, as a scanner's point spread), so neither caster's sample phase decides the image
    data = gaussian_filter(np.asarray(f.head_phantom(size).data), 1.0)
    volume = f.Volume(data)  # spacing 1, origin 0: VTK's image data
    centre = np.full(3, (size - 1) / 2.0)
    direction = np.array([1.0, 0.6, 1.3]) / np.linalg.norm([1.0, 0.6, 1.3])
    eye = centre + 2.5 * size * direction
    half_height = 0.5 * size * 3**0.5 / 2 * 1.05  # the cube's bounding sphere, a little margin
    composite = f.TransferFunction([0.0, 0.15, 0.25, 0.35, 1.0], [(0, 0, 0), (0.6, 0.3, 0.3), (1.0, 0.7, 0.3),
                                   (1.0, 0.9, 0.6), (1, 1, 1)], [0.0, 0.0, 0.02, 0.2, 0.8])  # fmt: skip
    mip = f.TransferFunction([0.0, 1.0], [(0, 0, 0), (1, 1, 1)], [1.0, 1.0])
    return volume, centre, eye, half_height, {"composite": composite, "mip": mip}


def _clipping(eye, centre) -> tuple[float, float]:
    """Near and far plane distances, the same for both renderers (the near plane anchors the samples)."""
    return 1.0, float(np.linalg.norm(eye - centre)) * 2


def _frustum(volume, centre, eye, half_height, image: int, mode: str, tf, step: float):
    scene = f.Scene()
    scene.add_volume(volume, tf, mode=mode, step=step, sampling="near")
    height = 2.0 * half_height * (image - 1) / image  # VTK's window spans H − 1 pixel pitches (module docstring)
    near, far = _clipping(eye, centre)
    projection = f.Orthographic(height=height, near=near, far=far)
    camera = f.Camera.look_at(eye, centre, (0.0, 1.0, 0.0), projection=projection, width=image, height=image)
    return lambda: f.render(scene, camera).color


def _vtk(volume, centre, eye, half_height, image: int, mode: str, tf, step: float):
    import pyvista as pv
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    grid = pv.ImageData(dimensions=volume.shape, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0))
    grid.point_data["v"] = np.asarray(volume.data).ravel(order="F")  # x fastest, as VTK stores points
    plotter = pv.Plotter(off_screen=True, window_size=(image, image))
    plotter.set_background("black")
    actor = plotter.add_volume(grid, scalars="v", mapper="fixed_point", shade=False, show_scalar_bar=False)
    mapper = actor.GetMapper()
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetSampleDistance(step)
    mapper.SetImageSampleDistance(1.0)
    if mode == "mip":
        mapper.SetBlendModeToMaximumIntensity()
    else:
        mapper.SetBlendModeToComposite()
    color, opacity = vtk.vtkColorTransferFunction(), vtk.vtkPiecewiseFunction()
    for value, rgb, alpha in zip(tf.values, tf.colors, tf.opacities, strict=True):
        color.AddRGBPoint(float(value), *(float(c) for c in rgb))
        opacity.AddPoint(float(value), float(alpha))
    prop = actor.GetProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(1.0)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    camera = plotter.renderer.GetActiveCamera()
    camera.SetParallelProjection(1)
    camera.SetPosition(*eye)
    camera.SetFocalPoint(*centre)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetParallelScale(half_height)
    camera.SetClippingRange(*_clipping(eye, centre))
    window = plotter.render_window

    def run():
        window.Render()
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        pixels = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).reshape(image, image, 3)
        return pixels[::-1]  # VTK's rows start at the bottom

    return run, plotter


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--image", type=int, default=1024)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-vtk", action="store_true")
    args = parser.parse_args()
    step = 0.5
    print(f"numba threads: {numba.get_num_threads()}; volume {args.size}^3 float32, image {args.image}^2, step {step}")
    start = time.perf_counter()
    volume, centre, eye, half_height, tfs = _setup(args.size)
    print(f"phantom built in {time.perf_counter() - start:.1f} s; peak RSS {_peak_mib():.0f} MiB")
    images = {}
    rows = []
    for mode in ("composite", "mip"):
        first, median, cpu, images[mode] = _time(_frustum(volume, centre, eye, half_height, args.image, mode,
                                                          tfs[mode], step), args.repeat)  # fmt: skip
        rows.append([mode, first, median, cpu])
        print(f"frustum {mode}: first call {first:.3f} s, median {median:.3f} s, least CPU {cpu:.3f} s; "
              f"peak RSS {_peak_mib():.0f} MiB; load {os.getloadavg()[0]:.1f}")  # fmt: skip
    if args.no_vtk:
        return
    for row in rows:
        mode = row[0]
        run, plotter = _vtk(volume, centre, eye, half_height, args.image, mode, tfs[mode], step)
        first, median, cpu, vtk_image = _time(run, args.repeat)
        plotter.close()
        difference = np.abs(images[mode][..., :3].astype(int) - vtk_image.astype(int))
        close = (difference <= 2).all(axis=2).mean()
        row += [first, median, cpu, close]
        print(f"VTK fixed-point {mode}: first call {first:.3f} s, median {median:.3f} s, least CPU {cpu:.3f} s; "
              f"peak RSS {_peak_mib():.0f} MiB; load {os.getloadavg()[0]:.1f}")  # fmt: skip
        print(f"{mode} agreement: {close:.2%} of pixels within ±2 levels of VTK's (max difference "
              f"{difference.max()})")  # fmt: skip
    print("\n| mode | frustum first call | frustum median (CPU) | VTK first call | VTK median (CPU) | frustum / VTK "
          "wall (CPU) | pixels within ±2 |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for mode, first, median, cpu, vtk_first, vtk_median, vtk_cpu, close in rows:
        print(f"| {mode} | {first:.3f} s | {median:.3f} s ({cpu:.3f} s) | {vtk_first:.3f} s | {vtk_median:.3f} s "
              f"({vtk_cpu:.3f} s) | {median / vtk_median:.2f} ({cpu / vtk_cpu:.2f}) | {close:.2%} |")  # fmt: skip


if __name__ == "__main__":
    main()
