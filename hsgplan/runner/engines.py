"""Where work items run: a local process pool or a Ray cluster, behind one small interface
(`submit`, `next_done`, `close`). Every long job (eval, eval task, eval motion, collect) runs
through one of them."""

from __future__ import annotations

import itertools
import multiprocessing
import os
import queue
import socket
import sys
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager

from hsgplan.domain.errors import InvalidInputError


def one_core() -> None:
    """A worker's first act, before anything imports torch (or any process that runs
    episodes itself: the demo, the report): one thread for its math. Two
    processes each spinning two OpenMP threads on two cores were measured to turn 20 ms
    planner calls into 1.5 s ones."""
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    if "torch" in sys.modules:  # imported with the parent's main module
        sys.modules["torch"].set_num_threads(1)


def worker_start(parent: int) -> None:
    """A pool worker's first act: one core (`one_core`), and on Linux an end with its parent:
    a job killed however it was (SIGTERM, SIGKILL) takes its workers with it, where they would
    otherwise go on running the items queued to them."""
    one_core()
    if not sys.platform.startswith("linux"):
        return
    import ctypes
    import signal

    pr_set_pdeathsig = 1
    ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGTERM)
    if os.getppid() != parent:  # the parent died before the signal was asked for
        os._exit(1)


# Times a work item is run again after the process running it died (killed, out of memory)
# before the job gives up on it: an item that kills its worker every time is not retried
# forever.
RETRIES = 3


class WorkerLostError(InvalidInputError):
    """A work item's worker died more often than RETRIES allows, or Ray lost the node or the
    cluster: one line, and the run resumes where it stopped when started again."""


def _lost(what: str) -> WorkerLostError:
    return WorkerLostError(
        f"{what}; every result finished before is kept: run the same command again to go on"
    )


def call(fn: Callable, *args):
    """`fn(*args)` in a worker, on one core (Ray's workers run no pool initializer)."""
    one_core()
    return fn(*args)


class LocalEngine:
    """A process pool (spawned: children forked from a process with torch loaded hang), one
    core per worker. A worker that dies (killed, out of memory) breaks the pool: a new pool
    runs every unfinished item again, each at most RETRIES times more."""

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self.pool = self._new_pool()
        # finished futures in the order they finished: waiting on thousands of pending ones
        # at every step would cost time quadratic in the job's size
        self.finished: queue.SimpleQueue[Future] = queue.SimpleQueue()
        self.jobs: dict[int, tuple[Callable, tuple]] = {}  # handle: its work, until done
        self.futures: dict[Future, int] = {}
        self.retries: dict[int, int] = {}
        self.count = itertools.count()

    def _new_pool(self) -> ProcessPoolExecutor:
        context = multiprocessing.get_context("spawn")
        return ProcessPoolExecutor(
            self.workers, mp_context=context, initializer=worker_start, initargs=(os.getpid(),)
        )

    def submit(self, fn: Callable, *args) -> int:
        handle = next(self.count)
        self.jobs[handle] = (fn, args)
        self._start(handle)
        return handle

    def _start(self, handle: int) -> None:
        fn, args = self.jobs[handle]
        future = self.pool.submit(fn, *args)
        self.futures[future] = handle
        future.add_done_callback(self.finished.put)

    def next_done(self, handles: set) -> tuple[object, object]:
        while True:
            future = self.finished.get()
            handle = self.futures.pop(future, None)  # None: a future of a pool given up
            if handle not in handles:
                continue
            try:
                result = future.result()
            except BrokenProcessPool:
                self._restart(handle)
                continue
            del self.jobs[handle]
            return handle, result

    def _restart(self, broken: int) -> None:
        """A worker died, which breaks the pool: every unfinished item runs again in a new
        one, in the order submitted (the pool's order). Those that were running, the first
        `workers` of them, are counted as retried."""
        self.pool.shutdown(wait=False, cancel_futures=True)
        self.pool = self._new_pool()
        kept = {f: h for f, h in self.futures.items() if _succeeded(f)}
        lost = sorted({broken, *self.futures.values()} - set(kept.values()))
        self.futures = kept
        for h in lost[: self.workers]:
            self.retries[h] = self.retries.get(h, 0) + 1
            if self.retries[h] > RETRIES:
                raise _lost(f"a worker died each of the {RETRIES + 1} times it ran one item")
        for h in lost:
            self._start(h)

    def close(self) -> None:
        # Waiting costs nothing: the interpreter's exit joins the pool's manager thread anyway,
        # and one still closing its wake-up pipe when the exit wakes it raises EBADF there.
        self.pool.shutdown(wait=True, cancel_futures=True)


def _succeeded(future: Future) -> bool:
    return future.done() and not future.cancelled() and future.exception() is None


RAY_CONNECT_SECONDS = 3.0


def check_ray_address(address: str | None) -> None:
    """Refuse in one line, within seconds, a `--ray` address that cannot work: empty, or a
    HOST:PORT where nothing answers (Ray itself would retry it for minutes)."""
    if address is None or address in ("local", "auto"):
        return
    if not address.strip():
        raise InvalidInputError(
            "--ray '': give an address (HOST:PORT, ray://HOST:PORT or auto) or 'local'"
        )
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InvalidInputError(
            f"--ray '{address}': expected HOST:PORT, ray://HOST:PORT, auto or local"
        )
    try:
        socket.create_connection((host.strip("[]"), int(port)), RAY_CONNECT_SECONDS).close()
    except OSError as e:
        raise InvalidInputError(
            f"--ray '{address}': nothing answers there ({e.strerror or type(e).__name__})"
        ) from None


# Left out of the checkout a cluster's workers are sent: history, environments, run folders.
CLUSTER_EXCLUDES = [".git", ".venv", "venv", "**/__pycache__", "runs", "*.egg-info"]


def cluster_env() -> dict:
    """What the workers of a cluster joined with `--ray ADDRESS` are given: this checkout
    (the package, `checkpoints/` and `data/`, less CLUSTER_EXCLUDES) as their working folder,
    which Ray uploads once and unpacks on every node, so no node needs a checkout of its own;
    their dependencies (torch, pybullet, ...) must be installed on each. Run from an installed
    package rather than a checkout, nothing is sent: each node needs the package installed."""
    from hsgplan.paths import home

    env = {"env_vars": {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}}
    root = home()
    if (root / "hsgplan" / "__init__.py").is_file():
        env |= {"working_dir": str(root), "excludes": CLUSTER_EXCLUDES}
    return env


class RayEngine:
    """The same work on a Ray cluster: `address` as `ray.init` takes it ("auto", "ray://...",
    or "local" to start a private instance on this machine)."""

    def __init__(self, address: str, workers: int) -> None:
        check_ray_address(address)
        try:
            import ray
        except ImportError:
            raise InvalidInputError(
                "--ray needs Ray: pip install 'hsgplan[ray]' (or pip install ray)"
            ) from None
        self.ray = ray
        try:
            if address == "local":
                # "local" starts an instance of our own: without it Ray would join one another
                # process started on this machine, and refuse the CPU count it was given
                ray.init(
                    address="local",
                    num_cpus=workers,
                    include_dashboard=False,
                    log_to_driver=False,
                )
            else:
                ray.init(address=address, log_to_driver=False, runtime_env=cluster_env())
        except Exception as e:  # no cluster there, a bad address: one line, not a traceback
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise InvalidInputError(
                f"--ray '{address}': could not start or join Ray ({first})"
            ) from None
        self.task = ray.remote(max_retries=RETRIES)(call)

    def submit(self, fn: Callable, *args):
        # One remote function for every job: `fn` travels as its argument (a plain function
        # or a functools.partial alike, which ray.remote itself refuses).
        return self.task.remote(fn, *args)

    def next_done(self, handles: set) -> tuple[object, object]:
        ready, _ = self.ray.wait(list(handles), num_returns=1)
        try:
            return ready[0], self.ray.get(ready[0])
        except self.ray.exceptions.RayTaskError as e:  # the work's own error, as raised
            raise e.as_instanceof_cause() from None
        except self.ray.exceptions.RayError as e:  # a worker, a node or the cluster lost
            raise _lost(f"Ray lost a worker or a node ({type(e).__name__})") from None

    def close(self) -> None:
        self.ray.shutdown()


@contextmanager
def engine(workers: int, ray_address: str | None = None) -> Iterator[LocalEngine | RayEngine]:
    """A local pool of `workers` processes, or Ray at `ray_address` when one is given."""
    if workers < 1:
        raise InvalidInputError(f"--workers {workers}: need at least one")
    runner = RayEngine(ray_address, workers) if ray_address else LocalEngine(workers)
    try:
        yield runner
    finally:
        runner.close()
