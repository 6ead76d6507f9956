"""The launcher runs a command as a real process would: the same exit code and output as
`hsgplan` started afresh, for a refusal at the door, one deep in a command, and a run."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.hostile.harness import child_env, launch

pytestmark = pytest.mark.slow

COMMANDS = [
    ["eval", "world", "--sizes", "13"],  # refused by the parser's checks
    ["train", "motion", "--config", "missing.json", "--out", "ck"],  # refused after imports
    ["goals", "--objects", "3", "--goals", "2", "--seed", "4"],  # runs, prints goals
]


@pytest.mark.parametrize("args", COMMANDS, ids=[" ".join(a[:2]) for a in COMMANDS])
def test_a_forked_command_ends_as_a_fresh_process_does(args, launcher, home, tmp_path):
    real_cwd, forked_cwd = tmp_path / "real", tmp_path / "forked"
    real_cwd.mkdir()
    forked_cwd.mkdir()
    real = subprocess.run(
        [sys.executable, "-m", "hsgplan.cli", *args],
        cwd=real_cwd,
        env=child_env(home),
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=120,
    )
    forked = launch(launcher, args, forked_cwd, home)
    assert forked.code == real.returncode
    assert forked.stdout == real.stdout
    assert forked.error_lines == [line for line in real.stderr.splitlines() if line.strip()]
