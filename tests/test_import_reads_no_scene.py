"""No library module reads a scene file as it is imported: with every file under `scenes/`
unreadable, every module but the commands' imports. The kitchen's own module, which the
commands and tests import, reads at import: the same check must catch it."""

import pkgutil
import subprocess
import sys

import hsgplan

# Runs in a child process: opening any file under scenes/ raises, then the modules are imported
# one by one and those that failed are printed, one a line.
GUARD = """
import builtins, importlib, io, sys
from pathlib import Path
scenes = (Path(sys.argv[1]) / "scenes").resolve()
real = io.open
def guarded(file, *args, **kwargs):
    if isinstance(file, (str, Path)) and Path(file).resolve().is_relative_to(scenes):
        raise PermissionError(f"{file} is unreadable")
    return real(file, *args, **kwargs)
io.open = builtins.open = guarded
for name in sys.argv[2:]:
    try:
        importlib.import_module(name)
    except Exception as e:
        print(f"{name}: {type(e).__name__}: {e}")
"""


def _failing_imports(modules: list[str]) -> list[str]:
    home = hsgplan.__path__[0].rsplit("/hsgplan", 1)[0]
    done = subprocess.run(
        [sys.executable, "-c", GUARD, home, *modules],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    return done.stdout.splitlines()


def _library_modules() -> list[str]:
    out = []
    for m in pkgutil.walk_packages(hsgplan.__path__, "hsgplan."):
        if m.name.startswith("hsgplan.cli") or m.name == "hsgplan.domain.kitchen":
            continue
        out.append(m.name)
    return out


def test_no_library_module_reads_a_scene_file_at_import():
    modules = _library_modules()
    assert len(modules) > 150  # the whole package, not a corner of it
    assert _failing_imports(modules) == []


def test_a_module_that_reads_a_scene_at_import_is_caught():
    (failed,) = _failing_imports(["hsgplan.domain.kitchen"])
    assert failed.startswith("hsgplan.domain.kitchen:") and "kitchen.toml" in failed
