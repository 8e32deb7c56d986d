"""``render_many``: many views on one process, a local process pool, or a Ray cluster, with the same bytes.

Each executor sends every distinct scene to a worker **once** (the pool's initializer; Ray's object store)
and then only jobs (a camera, options and paths: a few hundred bytes). Workers are long-lived, so the compiled
kernels load once per worker; each worker runs ``frustum.set_threads(threads)`` (the threads of the parallel
kernels) with $workers × threads ≤ cores$, so the pool does not oversubscribe the machine. A view's bytes do
not depend on the thread count (each piece of a kernel owns its pixels), so every executor and worker count
writes the same files.

Ctrl-C: workers ignore SIGINT; the caller stops handing out jobs, lets the views in flight finish (so no file
is left half written) and re-raises KeyboardInterrupt.

Ray clusters whose nodes share no disk: where the files go is the ``collect`` mode. ``"workers"``: each actor
writes its views' files itself (a URL every node reaches, or a folder on a one-node cluster). ``"driver"``: each
actor renders and *encodes* its views and returns the files' bytes to the driver, cut into pieces small enough
for Ray to send inside the task's reply (``RAY_INLINE_BYTES``; the driver then maps no page of the object store);
the driver writes them (atomically, as a worker would) before it counts the view, so a view in the run log is a
view on the driver's disk. The driver keeps at most ``RAY_BYTES_IN_FLIGHT`` bytes of views handed out and not yet
written, and a task carries at most ``RAY_TASK_BYTES``, so its memory stays flat whatever the number of views.
The default picks ``"driver"`` for a local folder on a cluster of more than one node (and for ``memory://``,
which lives in one process), ``"workers"`` otherwise. A worker or a node lost mid-run (its actor dies) hands its
batches to the actors left, up to ``RAY_TASK_RETRIES`` times each.

A killed caller (SIGKILL, an out-of-memory kill) leaves no orphans: each pool worker checks every
``PARENT_CHECK_SECONDS`` whether its parent is still the process that started it and exits when it is not,
at once when idle, after the view it is drawing otherwise (that view's files are completed, never cut short).
The multiprocessing resource tracker exits with the last of them (its pipe closes).
"""

from __future__ import annotations

import contextlib
import functools
import os
import pickle
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from frustum._arrays import describe
from frustum.batch.jobs import RenderJob, ViewResult, check_job, encode_view, render_view, write_view
from frustum.batch.progress import ViewProgress
from frustum.batch.storage import is_url
from frustum.errors import FrustumError

__all__ = [
    "COLLECT",
    "EXECUTORS",
    "RAY_BATCH",
    "RAY_BYTES_IN_FLIGHT",
    "RAY_INLINE_BYTES",
    "RAY_TASK_BYTES",
    "RAY_TASK_RETRIES",
    "render_many",
]

EXECUTORS = ("serial", "process", "ray")
"""Executors ``render_many`` accepts."""

RAY_BATCH = 16
"""Most views per Ray task: one task per view would make the driver's loop the limit on a large cluster."""
COLLECT = ("driver", "workers")
"""Where a Ray run's files are written: by the driver (bytes sent back with the tasks) or by the workers."""
RAY_BYTES_IN_FLIGHT = 256 * 2**20
"""collect="driver": most bytes of encoded views handed out and not yet written (an upper bound per view:
4 + 4 + 12 + 2 + 1 bytes per pixel for color, depth, normals, ids, mask)."""
RAY_TASK_BYTES = 2**20
"""collect="driver": most bytes of encoded views per Ray task (same bound; at least one view per task): a task's
reply stays far below Ray's 10 MiB limit of values sent inline with it (``task_rpc_inlined_bytes_limit``), and the
driver's heap holds little of it at a time (2,000 views at 256²: +7 and +11 MiB of RSS after the first 100 views
with one view a task, +2 to +32 MiB with three)."""
RAY_INLINE_BYTES = 96 * 1024
"""collect="driver": a task returns its views' files cut into pieces of at most this size, each a value of its
own, below Ray's 100 KiB limit (``max_direct_call_object_size``) for values sent to the driver inside the task's
reply instead of through the object store; the driver writes a file piece by piece. So the driver never maps
the object store's shared memory (read there, every page of the head node's store it touched counted in its RSS
for the rest of the run: +21 to +83 MiB over 2,000 views at 256² with 16 views a task in one value) and never
holds a large buffer (freed, one would raise glibc's mmap threshold and leave a fragmented heap: +19 to +24 MiB
with the pieces joined per task). Pieces beyond the values planned (a file larger than its bound) still arrive,
in one list through the object store."""
RAY_TASK_RETRIES = 3
"""How often a batch whose actor was lost (a dead worker or node) is handed to another actor."""
RAY_NO_WORKER_SECONDS = 120.0
"""How long a run whose every actor was lost waits for a free CPU on the cluster before it gives up."""
_ENCODED_BYTES_PER_PIXEL = {"color": 4, "depth": 4, "normals": 12, "object_id": 2, "mask": 1}

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
        """Render and write a batch of views here; their ViewResults."""
        results = []
        for job in jobs:
            scene, options = self.scenes[job.scene]
            results.append(render_view(scene, job, options))
        return results

    def encode(self, jobs: list[RenderJob], parts: int) -> list[Any]:
        """Render and encode a batch of views for the driver to write: `parts` values (the task's returns). The
        first is ``[(ViewResult, [(kind, pieces), ...]), ...]``; then each file cut into pieces of at most
        ``RAY_INLINE_BYTES``, one value each (None once all are out); the last value is the list of any pieces
        beyond the values planned (a file larger than ``_encoded_bytes`` says)."""
        step = RAY_INLINE_BYTES
        views, pieces = [], []
        for job in jobs:
            scene, options = self.scenes[job.scene]
            result, encoded = encode_view(scene, job, options)
            counts = []
            for kind, data in encoded.items():
                cut = [data[at : at + step] for at in range(0, len(data), step)]
                counts.append((kind, len(cut)))
                pieces.extend(cut)
            views.append((result, counts))
        slots = parts - 2
        return [views, *pieces[:slots], *[None] * (slots - len(pieces)), pieces[slots:]]


def _parts(batch: list[RenderJob]) -> int:
    """How many values an ``encode`` task of this batch returns: its metadata, the pieces of its files, the rest."""
    return 2 + sum(_encoded_bytes(job) // RAY_INLINE_BYTES + len(job.outputs) for job in batch)


def _pieced(values: list[Any]) -> list[tuple[ViewResult, dict[str, list[bytes]]]]:
    """(ViewResult, {kind: [pieces of the file]}) pairs of the values an ``encode`` task returned."""
    views, *pieces, rest = values
    pieces = [piece for piece in pieces if piece is not None] + rest
    pairs, at = [], 0
    for result, counts in views:
        encoded = {}
        for kind, count in counts:
            encoded[kind] = pieces[at : at + count]
            at += count
        pairs.append((result, encoded))
    return pairs


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


def _encoded_bytes(job: RenderJob) -> int:
    """An upper bound of a view's encoded files (raw pixels; PNG and .npy headers are small)."""
    pixels = job.camera.width * job.camera.height
    return 1024 + pixels * sum(_ENCODED_BYTES_PER_PIXEL.get(kind, 4) for kind in job.outputs)


def _collect_mode(ray: Any, collect: str | None, jobs: Sequence[RenderJob]) -> str:
    """The collect mode, "driver" or "workers", for this cluster and outputs; refuses workers that cannot write."""
    outputs = [path for job in jobs for path in job.outputs.values()]
    local = next((path for path in outputs if not is_url(path)), None)
    memory = next((path for path in outputs if str(path).startswith("memory://")), None)
    nodes = [node for node in ray.nodes() if node.get("Alive")]
    try:
        client = bool(ray.util.client.ray.is_connected())
    except AttributeError:  # pragma: no cover - a Ray without the client
        client = False
    apart = len(nodes) > 1 or client  # workers may run where the driver's disk is not
    if collect is None:
        return "driver" if (local is not None and apart) or memory is not None else "workers"
    if collect == "workers" and local is not None and apart:
        where = "a Ray Client connection" if client else f"a Ray cluster of {len(nodes)} nodes"
        raise FrustumError(
            f"render_many: collect = 'workers' with the local path {str(local)!r} on {where}: each node would "
            "write to its own disk and the driver would miss their files; use collect='driver' (--collect driver, "
            "the default here) or a URL every node reaches (s3://, gs://, file:// on a shared file system)"
        )
    if collect == "workers" and memory is not None:
        raise FrustumError(
            f"render_many: collect = 'workers' with {str(memory)!r}: memory:// lives in one process, so the "
            "workers' files would never reach this one; use collect='driver'"
        )
    return collect


def _ray(
    scenes: list, jobs: list[RenderJob], workers: int | None, on_result: Callable, address: Any,
    collect: str | None = None,
) -> None:  # fmt: skip
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
        _RayRun(ray, scenes, jobs, workers, on_result, _collect_mode(ray, collect, jobs)).run()
    finally:
        if started:
            ray.shutdown()


class _RayRun:
    """One ``render_many`` on Ray: actors, batches handed out and collected, lost actors replaced."""

    def __init__(self, ray: Any, scenes: list, jobs: list[RenderJob], workers: int | None, on_result: Callable,
                 collect: str) -> None:  # fmt: skip
        from collections import deque

        self.ray, self.on_result, self.to_driver = ray, on_result, collect == "driver"
        self.jobs = {job.key: job for job in jobs}
        # one CPU per actor: more actors than free CPUs would wait for ever, holding their views
        free = max(1, int(ray.available_resources().get("CPU", 1)))
        self.wanted = free if workers is None else min(workers, free)
        size = _batch_size(len(jobs), self.wanted)
        self.view_limit = len(jobs)
        if self.to_driver:  # a bounded number of views handed out and not yet written
            per_view = _encoded_bytes(jobs[0])
            size = max(1, min(size, RAY_TASK_BYTES // per_view))
            self.view_limit = max(size, RAY_BYTES_IN_FLIGHT // per_view)
        self.wanted = max(1, min(self.wanted, -(-len(jobs) // size), -(-self.view_limit // size)))
        self.pending = deque(jobs[i : i + size] for i in range(0, len(jobs), size))
        self.tries: dict[str, int] = {}
        self.actor_type = ray.remote(num_cpus=1, max_restarts=0)(_RayRenderer)
        self.scenes_ref = ray.put(scenes)  # once into the object store; each actor fetches it once
        self.actors: list = []
        self.load: dict = {}
        self.in_flight: dict = {}  # first ref -> (actor, batch, every ref of the task)
        self.views_in_flight = 0

    def _add_actors(self, count: int) -> None:
        for _ in range(count):
            actor = self.actor_type.remote(self.scenes_ref, 1)
            self.actors.append(actor)
            self.load[actor] = 0

    def _drop(self, actor: Any) -> None:
        if actor in self.load:
            self.actors.remove(actor)
            del self.load[actor]
            with contextlib.suppress(Exception):
                self.ray.kill(actor, no_restart=True)

    def _submit(self) -> None:
        """Hand out batches: at most two per actor (the next is ready when one ends) and `view_limit` views."""
        while self.pending and self.actors:
            actor = min(self.actors, key=self.load.__getitem__)
            batch = self.pending[0]
            over = self.views_in_flight + len(batch) > self.view_limit and self.in_flight
            if self.load[actor] >= 2 or over:
                return
            self.pending.popleft()
            if self.to_driver:
                refs = actor.encode.options(num_returns=_parts(batch)).remote(batch, _parts(batch))
            else:
                refs = [actor.render.remote(batch)]
            self.in_flight[refs[0]] = (actor, batch, refs)
            self.load[actor] += 1
            self.views_in_flight += len(batch)

    def _finish(self, ref: Any) -> None:
        """Collect one batch: write (driver mode) and count its views, or hand it on when its actor was lost."""
        ray = self.ray
        actor, batch, refs = self.in_flight.pop(ref)
        self.views_in_flight -= len(batch)
        if actor in self.load:
            self.load[actor] -= 1
        try:
            values = ray.get(refs)
        except ray.exceptions.RayTaskError as error:  # the batch itself raised (not a view: those are caught)
            message = " ".join(str(error).split())[:500]
            for job in batch:
                self.on_result(ViewResult(job.key, {}, f"{type(error).__name__}: {message}"))
            return
        except ray.exceptions.RayError as error:  # the actor (its process or its node) was lost
            self._drop(actor)
            tries = self.tries[batch[0].key] = self.tries.get(batch[0].key, 0) + 1
            if tries > RAY_TASK_RETRIES:
                for job in batch:
                    self.on_result(ViewResult(job.key, {}, f"{type(error).__name__}: lost {tries} workers"))
            else:
                self.pending.appendleft(batch)
            return
        del refs  # the task's values are freed as soon as they are read
        if not self.to_driver:
            for result in values[0]:
                self.on_result(result)
            return
        for result, encoded in _pieced(values):
            self.on_result(write_view(self.jobs[result.key], result, encoded))

    def _replace_lost(self) -> None:
        """Every actor was lost: start new ones on the CPUs free now, or wait for one a while.

        Only then: while some actors live they take the lost batches, and a CPU the cluster still lists just
        after its node died (the head notices a dead node after a few seconds) would hold an actor for ever.
        """
        ray = self.ray
        deadline = time.monotonic() + RAY_NO_WORKER_SECONDS
        while True:
            free = int(ray.available_resources().get("CPU", 0))
            missing = min(free, self.wanted, len(self.pending))
            if missing > 0:
                self._add_actors(missing)
            if self.actors or not self.pending:
                return
            if time.monotonic() > deadline:
                raise FrustumError(
                    f"render_many: every Ray worker was lost and no CPU came free in {RAY_NO_WORKER_SECONDS:.0f} s; "
                    f"{sum(len(b) for b in self.pending)} views were not rendered (rerun to resume a dataset)"
                )
            time.sleep(1.0)

    def run(self) -> None:
        ray = self.ray
        self._add_actors(self.wanted)
        try:
            while self.pending or self.in_flight:
                if not self.actors and self.pending:
                    self._replace_lost()
                self._submit()
                ready, _ = ray.wait(list(self.in_flight), num_returns=1)
                for ref in ready:
                    self._finish(ref)
        except KeyboardInterrupt:
            self.pending.clear()
            ready, _ = ray.wait(list(self.in_flight), num_returns=len(self.in_flight))
            for ref in ready:
                self._finish(ref)
            raise
        finally:
            for actor in list(self.actors):
                self._drop(actor)


_RUNNERS = {"serial": _serial, "process": _process, "ray": _ray}


def render_many(
    jobs: Iterable[RenderJob],
    *,
    executor: str = "process",
    workers: int | None = None,
    progress: bool | ViewProgress = True,
    address: str | None = None,
    collect: str | None = None,
) -> list[ViewResult]:
    """Render many views; workers (or this process, ``collect="driver"``) write the files; metadata in job order.

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
        a local one started (and stopped) here unless Ray is already initialized; a lost actor or node hands
        its views to the actors left.
    workers : int or None
        Processes or actors; None: the number of cores (the cluster's free CPUs for Ray, which also caps it).
    progress : bool or ViewProgress
        Show a Rich progress bar on stderr (True), nothing (False), or count on the given bar.
    address : str or None
        ``ray.init(address=...)`` for an existing cluster (e.g. ``"auto"``).
    collect : {"driver", "workers"} or None
        Ray only: who writes the files (module docstring). ``"driver"``: the workers return the encoded bytes
        (in pieces inside the tasks' replies) and this process writes them, at most ``RAY_BYTES_IN_FLIGHT``
        bytes of views outstanding. ``"workers"``: each worker writes its own (refused for a local path on a
        cluster of more than one node, whose nodes do not see each other's disks). None: ``"driver"`` for local
        paths on more than one node and for ``memory://``, else ``"workers"``. The serial and process executors
        write in this machine either way.

    Returns
    -------
    list of ViewResult

    Raises
    ------
    FrustumError
        Unknown executor or collect mode, workers < 1, a bad job, Ray missing (``pip install 'frustum[ray]'``),
        collect = "workers" where the workers cannot reach the outputs, every Ray worker lost for good.
    KeyboardInterrupt
        After the views in flight have finished writing.
    """
    where = "render_many"
    if executor not in _RUNNERS:
        raise FrustumError(f"{where}: executor = {executor!r} is unknown; expected one of {', '.join(EXECUTORS)}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise FrustumError(f"{where}: workers = {describe(workers)} must be a positive integer or None")
    if collect is not None and collect not in COLLECT:
        raise FrustumError(f"{where}: collect = {collect!r} is unknown; expected one of {', '.join(COLLECT)} or None")
    job_list = list(jobs)
    scenes, plain = _prepare(job_list, where)
    if executor == "process":
        memory = next((p for job in plain for p in job.outputs.values() if str(p).startswith("memory://")), None)
        if memory is not None:
            raise FrustumError(f"{where}: {str(memory)!r} with executor = 'process': memory:// lives in one process, "
                               "so the pool's files would never reach this one; use 'serial' or 'ray'")  # fmt: skip
    count = workers
    if executor == "process":
        count = min(workers or _cpu_count(), max(1, len(plain)))
    results: dict[str, ViewResult] = {}
    bar = progress if isinstance(progress, ViewProgress) else ViewProgress(len(plain), enabled=bool(progress))

    def on_result(result: ViewResult) -> None:
        results[result.key] = result
        bar.advance(result)

    runner = _RUNNERS[executor]
    if executor == "ray":
        runner = functools.partial(_ray, collect=collect)
    if plain:
        if isinstance(progress, ViewProgress):
            runner(scenes, plain, count, on_result, address)
        else:
            with bar:
                runner(scenes, plain, count, on_result, address)
    return [results[job.key] for job in plain]
