"""``render_many``: many views on one process, a local process pool, or a Ray cluster, with the same bytes.

Each executor sends every distinct scene to a worker **once** (the pool's initializer; Ray's object store)
and then only jobs (a camera, options and paths: a few hundred bytes). Workers are long-lived, so the compiled
kernels load once per worker; each worker runs ``frustum.set_threads(threads)`` (the threads of the parallel
kernels) with ``workers × threads ≤ cores``, so the pool does not oversubscribe the machine. A view's bytes do
not depend on the thread count (each piece of a kernel owns its pixels), so every executor and worker count
writes the same files.

Ctrl-C: workers ignore SIGINT; the caller stops handing out jobs, lets the views in flight finish (so no file
is left half written) and re-raises KeyboardInterrupt.

A killed caller (SIGKILL, an out-of-memory kill) leaves no orphans: each pool worker checks every
``PARENT_CHECK_SECONDS`` whether its parent is still the process that started it and exits when it is not,
at once when idle, after the view it is drawing otherwise (that view's files are completed, never cut short).
The multiprocessing resource tracker exits with the last of them (its pipe closes).
"""

from __future__ import annotations

import os
import pickle
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from frustum._arrays import describe
from frustum.batch.jobs import RenderJob, ViewResult, check_job, render_view
from frustum.batch.progress import ViewProgress
from frustum.errors import FrustumError

__all__ = ["EXECUTORS", "RAY_BATCH", "render_many"]

EXECUTORS = ("serial", "process", "ray")
"""Executors ``render_many`` accepts."""

RAY_BATCH = 16
"""Most views per Ray task: one task per view would make the driver's loop the limit on a large cluster."""

PARENT_CHECK_SECONDS = 0.5
"""How often a pool worker checks that its parent process is alive."""

_WORKER: dict[str, Any] = {"scenes": None, "parent": None, "busy": False, "orphaned": False}
_WORKER_LOCK = threading.Lock()


def _cpu_count() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return os.cpu_count() or 1


def _prepare(jobs: Sequence[RenderJob], where: str) -> tuple[list[tuple[Any, Mapping]], list[RenderJob]]:
    """Distinct (scene, default options) pairs and the jobs with ``scene`` replaced by an index into them.

    Scene files are loaded here, once, so a file that fails to load is one error, not one per view.
    """
    from frustum.scene import Scene

    scenes: list[tuple[Any, Mapping]] = []
    by_identity: dict[Any, int] = {}
    loaded: dict[str, Any] = {}
    plain = []
    keys: set[str] = set()
    for index, job in enumerate(jobs):
        check_job(job, index, where)
        if job.key in keys:
            raise FrustumError(f"{where}: jobs[{index}].key = {job.key!r} is repeated; every view needs its own key")
        keys.add(job.key)
        camera = job.camera
        if isinstance(job.scene, str | os.PathLike):
            from frustum.scenefile import load_scene_file

            path = os.fspath(job.scene)
            if path not in loaded:
                loaded[path] = load_scene_file(path)
            scene_file = loaded[path]
            identity: Any = ("file", path)
            scene, options = scene_file.scene, scene_file.options
            camera = scene_file.cameras[0] if camera is None else camera
        elif isinstance(job.scene, Scene):
            identity, scene, options = ("scene", id(job.scene)), job.scene, {}
        else:
            raise FrustumError(
                f"{where}: jobs[{index}].scene = {describe(job.scene)} is not a Scene or a scene file path"
            )
        from frustum.camera import Camera

        if not isinstance(camera, Camera):
            raise FrustumError(f"{where}: jobs[{index}].camera = {describe(camera)} is not a Camera")
        if identity not in by_identity:
            by_identity[identity] = len(scenes)
            scenes.append((scene, dict(options)))
        plain.append(replace(job, scene=by_identity[identity], camera=camera))
    return scenes, plain


# --- worker side ------------------------------------------------------------------------------------------------


def _init_worker(scenes_blob: bytes, threads: int, parent: int | None = None) -> None:
    """Pool initializer: watch the parent (its pid `parent`, given by the parent itself: a worker that starts
    after its parent died must not take its new parent, init, for it), unpickle the scenes once, set this
    worker's kernel threads, ignore Ctrl-C."""
    import signal

    from frustum.raster._jit import set_threads

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER["parent"] = os.getppid() if parent is None else parent
    if os.getppid() != _WORKER["parent"]:
        os._exit(0)  # the parent died while this worker was starting
    threading.Thread(target=_watch_parent, args=(_WORKER["parent"],), name="frustum-parent-watch", daemon=True).start()
    _WORKER["scenes"] = pickle.loads(scenes_blob)
    set_threads(threads)


def _watch_parent(parent: int) -> None:
    """A worker's watchdog: when the parent that started it is gone (the worker has been re-parented), exit
    now if idle, else mark it so ``_run_in_worker`` exits after the view being drawn."""
    while True:
        time.sleep(PARENT_CHECK_SECONDS)
        if os.getppid() != parent:
            with _WORKER_LOCK:
                _WORKER["orphaned"] = True
                if not _WORKER["busy"]:
                    os._exit(0)


def _run_in_worker(job: RenderJob) -> ViewResult:
    with _WORKER_LOCK:
        if _WORKER["orphaned"] or (_WORKER["parent"] is not None and os.getppid() != _WORKER["parent"]):
            os._exit(0)  # the caller is gone: nobody would receive this view
        _WORKER["busy"] = True
    try:
        scene, options = _WORKER["scenes"][job.scene]
        return render_view(scene, job, options)
    finally:
        with _WORKER_LOCK:
            _WORKER["busy"] = False
            if _WORKER["orphaned"]:
                os._exit(0)  # the view's files are written; its result has no reader


class _RayRenderer:
    """A long-lived Ray actor: the scenes from the object store once, then a batch of views per call."""

    def __init__(self, scenes: list, threads: int) -> None:
        from frustum.raster._jit import set_threads

        self.scenes = scenes
        set_threads(threads)

    def render(self, jobs: list[RenderJob]) -> list[ViewResult]:
        results = []
        for job in jobs:
            scene, options = self.scenes[job.scene]
            results.append(render_view(scene, job, options))
        return results


def _batch_size(views: int, workers: int) -> int:
    """Views per Ray task: up to `RAY_BATCH`, and at least 4 tasks per actor so the work stays balanced."""
    return max(1, min(RAY_BATCH, views // (4 * workers)))


# --- executors ------------------------------------------------------------------------------------------------


def _serial(scenes: list, jobs: list[RenderJob], workers: int, on_result: Callable, address: Any) -> None:
    for job in jobs:
        scene, options = scenes[job.scene]
        on_result(render_view(scene, job, options))


def _process(scenes: list, jobs: list[RenderJob], workers: int, on_result: Callable, address: Any) -> None:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    threads = max(1, _cpu_count() // workers)
    blob = pickle.dumps(scenes, protocol=pickle.HIGHEST_PROTOCOL)
    # spawn, not fork: a forked child of a process whose kernel threads are running can deadlock
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker,
                               initargs=(blob, threads, os.getpid()))  # fmt: skip
    pending = iter(jobs)
    in_flight: set = set()
    try:
        # at most two jobs per worker queued: an interrupt then waits for little more than the views being drawn
        for job in pending:
            in_flight.add(pool.submit(_run_in_worker, job))
            if len(in_flight) >= 2 * workers:
                break
        while in_flight:
            finished, in_flight = wait(in_flight, return_when=FIRST_COMPLETED)
            for future in finished:
                on_result(future.result())
                job = next(pending, None)
                if job is not None:
                    in_flight.add(pool.submit(_run_in_worker, job))
    except KeyboardInterrupt:
        for future in in_flight:
            future.cancel()
        for future in wait(in_flight).done:  # views that were being drawn finish and are counted
            if not future.cancelled() and future.exception() is None:
                on_result(future.result())
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _ray(scenes: list, jobs: list[RenderJob], workers: int | None, on_result: Callable, address: Any) -> None:
    try:
        import ray
    except ImportError:
        raise FrustumError(
            "render_many: executor = 'ray' needs Ray, which is not installed; pip install 'frustum[ray]'"
        ) from None
    started = False
    if not ray.is_initialized():
        # an existing cluster (address="auto" or "ray://host:port") or a new local one
        ray.init(address=address, include_dashboard=False, log_to_driver=False, configure_logging=False)
        started = True
    try:
        # one CPU per actor: more actors than free CPUs would wait for ever, holding their views
        free = max(1, int(ray.available_resources().get("CPU", 1)))
        workers = free if workers is None else min(workers, free)
        actor_type = ray.remote(num_cpus=1)(_RayRenderer)
        scenes_ref = ray.put(scenes)  # once into the object store; each actor fetches it once
        actors = [actor_type.remote(scenes_ref, 1) for _ in range(min(workers, max(1, len(jobs))))]
        size = _batch_size(len(jobs), len(actors))
        batches = iter([jobs[i : i + size] for i in range(0, len(jobs), size)])
        in_flight: dict = {}
        try:
            for actor in actors:  # two batches queued per actor: the next is ready when one finishes
                for _ in range(2):
                    batch = next(batches, None)
                    if batch is not None:
                        in_flight[actor.render.remote(batch)] = actor
            while in_flight:
                ready, _ = ray.wait(list(in_flight), num_returns=1)
                for ref in ready:
                    actor = in_flight.pop(ref)
                    for result in ray.get(ref):
                        on_result(result)
                    batch = next(batches, None)
                    if batch is not None:
                        in_flight[actor.render.remote(batch)] = actor
        except KeyboardInterrupt:
            ready, _ = ray.wait(list(in_flight), num_returns=len(in_flight))
            for results in ray.get(ready):
                for result in results:
                    on_result(result)
            raise
        finally:
            for actor in actors:
                ray.kill(actor)
    finally:
        if started:
            ray.shutdown()


_RUNNERS = {"serial": _serial, "process": _process, "ray": _ray}


def render_many(
    jobs: Iterable[RenderJob],
    *,
    executor: str = "process",
    workers: int | None = None,
    progress: bool | ViewProgress = True,
    address: str | None = None,
) -> list[ViewResult]:
    """Render many views; workers write the files and return metadata, in the order of `jobs`.

    The same call writes the same bytes with every executor and any number of workers. A view that fails is
    reported in its ``ViewResult.error``; the other views go on. Bad jobs (unknown output kinds, a scene file
    that does not load) raise before any view is rendered.

    Parameters
    ----------
    jobs : iterable of RenderJob
        One per view; keys unique.
    executor : {"serial", "process", "ray"}
        ``"serial"``: in this process. ``"process"``: a local pool of spawned processes, each given the scenes
        once through its initializer and ``cores // workers`` kernel threads. ``"ray"``: long-lived Ray actors
        (one CPU each, one kernel thread, up to ``RAY_BATCH`` views per task) on the cluster at `address`, or
        a local one started (and stopped) here unless Ray is already initialized; the files must go to a path
        every node can reach.
    workers : int or None
        Processes or actors; None: the number of cores (the cluster's free CPUs for Ray, which also caps it).
    progress : bool or ViewProgress
        Show a Rich progress bar on stderr (True), nothing (False), or count on the given bar.
    address : str or None
        ``ray.init(address=...)`` for an existing cluster (e.g. ``"auto"``).

    Returns
    -------
    list of ViewResult

    Raises
    ------
    FrustumError
        Unknown executor, workers < 1, a bad job, or Ray missing (``pip install 'frustum[ray]'``).
    KeyboardInterrupt
        After the views in flight have finished writing.
    """
    where = "render_many"
    if executor not in _RUNNERS:
        raise FrustumError(f"{where}: executor = {executor!r} is unknown; expected one of {', '.join(EXECUTORS)}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise FrustumError(f"{where}: workers = {describe(workers)} must be a positive integer or None")
    job_list = list(jobs)
    scenes, plain = _prepare(job_list, where)
    count = workers
    if executor == "process":
        count = min(workers or _cpu_count(), max(1, len(plain)))
    results: dict[str, ViewResult] = {}
    bar = progress if isinstance(progress, ViewProgress) else ViewProgress(len(plain), enabled=bool(progress))

    def on_result(result: ViewResult) -> None:
        results[result.key] = result
        bar.advance(result)

    if plain:
        if isinstance(progress, ViewProgress):
            _RUNNERS[executor](scenes, plain, count, on_result, address)
        else:
            with bar:
                _RUNNERS[executor](scenes, plain, count, on_result, address)
    return [results[job.key] for job in plain]
