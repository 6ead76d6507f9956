"""The simulated kitchen-storage world (PyBullet, DIRECT mode), built from parts."""

import os
import sys


def _import_pybullet_quietly() -> None:
    """PyBullet's C code prints its build time on stderr when imported: every command that
    touched the world began its one-line refusal with a line of noise. It is imported here,
    once, with stderr (the file descriptor, which C writes to) pointed at /dev/null."""
    if "pybullet" in sys.modules:
        return
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
            import pybullet  # noqa: F401
    finally:
        os.dup2(saved, 2)
        os.close(saved)


_import_pybullet_quietly()
