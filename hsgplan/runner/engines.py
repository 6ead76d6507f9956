"""Where work items run: a local process pool or a Ray cluster, behind one small interface
(`submit`, `next_done`, `close`). Every long job (eval, eval task, eval motion, collect) runs
through one of them."""

from __future__ import annotations

import multiprocessing
import os
import queue
import socket
import sys
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
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


class LocalEngine:
    """A process pool (spawned: children forked from a process with torch loaded hang), one
    core per worker."""

    def __init__(self, workers: int) -> None:
        context = multiprocessing.get_context("spawn")
        self.pool = ProcessPoolExecutor(workers, mp_context=context, initializer=one_core)
        # finished futures in the order they finished: waiting on thousands of pending ones
        # at every step would cost time quadratic in the job's size
        self.finished: queue.SimpleQueue[Future] = queue.SimpleQueue()

    def submit(self, fn: Callable, *args) -> Future:
        future = self.pool.submit(fn, *args)
        future.add_done_callback(self.finished.put)
        return future

    def next_done(self, handles: set) -> tuple[object, object]:
        while True:
            handle = self.finished.get()
            if handle in handles:
                return handle, handle.result()

    def close(self) -> None:
        self.pool.shutdown(wait=False, cancel_futures=True)


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
                ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
            else:
                ray.init(address=address, log_to_driver=False)
        except Exception as e:  # no cluster there, a bad address: one line, not a traceback
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise InvalidInputError(
                f"--ray '{address}': could not start or join Ray ({first})"
            ) from None
        self.remote = {}

    def submit(self, fn: Callable, *args):
        if fn not in self.remote:
            self.remote[fn] = self.ray.remote(fn)
        return self.remote[fn].remote(*args)

    def next_done(self, handles: set) -> tuple[object, object]:
        ready, _ = self.ray.wait(list(handles), num_returns=1)
        return ready[0], self.ray.get(ready[0])

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
