"""Runs `hsgplan` command lines as separate processes, without paying the imports each time.

Started as `python launcher.py`, it imports the whole package and its heavy dependencies once
(torch, PyG, PyBullet: two to four seconds a process), then reads one JSON request a line on
stdin and, for each, forks a child that becomes the command: its own process group (setsid),
its own folder, environment, memory and file-size limits, stdin closed, stdout and stderr to
files, `sys.argv` set, then `hsgplan.cli.main()`. The child ends as the real
program would (`_exit_as_python_does`): the exit code of `sys.exit`, an exception reaching the
top printed by `sys.excepthook` with code 1, then the threads joined, the atexit handlers run
and the output flushed; only the teardown of the modules is skipped (a second a process, and
nothing a command does depends on it). The server never runs torch code itself, so forking it
is as safe as starting afresh (no thread pool is copied). What a fork cannot give: every
command shares the server's hash seed (random per server), and what a module reads from the
environment when it is imported is the server's; no command of the package does either.

The server waits for the child up to the request's timeout, kills the child's process group
if it is still running (a hang), and answers one JSON line: the exit code (None for a hang),
the seconds taken and whether processes of the group outlived it.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import pkgutil
import resource
import signal
import sys
import time
import traceback


def preload() -> None:
    import hsgplan

    for module in pkgutil.walk_packages(hsgplan.__path__, "hsgplan."):
        if not module.name.endswith("__main__"):
            importlib.import_module(module.name)


def _become_command(request: dict) -> None:
    """In the child: set up the process as a shell would have, then run the command."""
    os.setsid()
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    memory = int(request["mem_bytes"])
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    if request.get("file_bytes") is not None:
        size = int(request["file_bytes"])
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))
    signal.signal(signal.SIGINT, signal.default_int_handler)
    out = os.open(request["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    err = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    os.dup2(out, 1)
    os.dup2(err, 2)
    os.close(out)
    os.close(err)
    os.close(0)  # stdin closed, as `0<&-` would
    sys.stdin = None
    sys.argv = ["hsgplan", *request["args"]]
    from hsgplan.cli import main

    try:
        main()
        code = 0
    except SystemExit as e:
        code = _exit_code(e.code)
    except BaseException as e:
        sys.excepthook(*sys.exc_info())
        code = 130 if isinstance(e, KeyboardInterrupt) else 1  # as the interpreter exits
    _exit_as_python_does(code)


def _exit_code(value) -> int:
    if value is None:
        return 0
    if isinstance(value, int):
        return value
    print(value, file=sys.stderr)  # `sys.exit("message")`
    return 1


def _exit_as_python_does(code: int) -> None:
    import atexit
    import threading

    threading._shutdown()  # non-daemon threads (a process pool's manager) are waited for
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            code = code or 120  # as the interpreter does when it cannot flush stdout
    os._exit(code)


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except (ProcessLookupError, PermissionError):
        return False
    return True


def _kill_group(pgid: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, signal.SIGKILL)


def serve(request: dict) -> dict:
    """Fork the command and wait for it."""
    sys.stdout.flush()
    sys.stderr.flush()
    start = time.monotonic()
    pid = os.fork()
    if pid == 0:
        try:
            _become_command(request)
        except BaseException:
            # onto the command's stderr, so that the case's record says what broke
            with contextlib.suppress(BaseException):
                traceback.print_exc()
                sys.stderr.flush()
        finally:
            os._exit(70)  # never back into the server's loop, whatever happened
    deadline = start + float(request["timeout"])
    status = None
    while status is None:
        done, raw = os.waitpid(pid, os.WNOHANG)
        if done:
            status = raw
        elif time.monotonic() > deadline:
            _kill_group(pid)
            os.waitpid(pid, 0)
            break
        else:
            time.sleep(0.01)
    seconds = time.monotonic() - start
    lingering = False
    if status is not None:
        end = time.monotonic() + 2.0  # workers shutting down are given a moment
        while _group_alive(pid) and time.monotonic() < end:
            time.sleep(0.05)
        lingering = _group_alive(pid)
        if lingering:
            _kill_group(pid)
    code = None if status is None else os.waitstatus_to_exitcode(status)
    return {"code": code, "seconds": seconds, "lingering": lingering}


def main() -> None:
    preload()
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        print(json.dumps(serve(json.loads(line))), flush=True)


if __name__ == "__main__":
    main()
