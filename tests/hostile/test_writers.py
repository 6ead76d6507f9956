"""Two writers of one folder, and a disk that fills up while a command writes: one run goes on
and the other is refused; the old file or none is left, never a truncated one."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from tests.hostile.case import TINY_MOTION, tiny_config
from tests.hostile.harness import child_env, launch

pytestmark = pytest.mark.slow
EVAL = [
    "eval",
    "world",
    "--agent",
    "oracle",
    "--sizes",
    "2-3",
    "--goals",
    "2",
    "--workers",
    "1",
    "--out",
    "run",
]


def _temporary_files(folder):
    return list(folder.rglob(".*tmp*"))


def test_a_second_run_into_a_folder_being_written_is_refused(launcher, home, tmp_path):
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    at = EVAL.index("--goals") + 1
    args = [*EVAL[:at], "3", *EVAL[at + 1 :]]  # long enough to be caught running
    first = subprocess.Popen(
        [sys.executable, "-m", "hsgplan.cli", *args],
        cwd=cwd,
        env=child_env(home),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while not (cwd / "run" / "oracle" / "config.json").exists():
            assert first.poll() is None, first.stderr.read()
            assert time.monotonic() < deadline, "the first run never started its episodes"
            time.sleep(0.05)
        second = launch(launcher, args, cwd, home)
        assert first.poll() is None, "the first run ended before the second was tried"
    finally:
        code = first.wait(timeout=300)
    assert code == 0, first.stderr.read()
    assert second.code == 2
    assert len(second.error_lines) == 1
    assert f"pid {first.pid}" in second.error_lines[0]
    assert "another run" in second.error_lines[0]
    rows = (cwd / "run" / "oracle" / "episodes.jsonl").read_text().splitlines()
    assert len(rows) == 6  # 3 goals of each size, each run once


def test_a_full_disk_leaves_the_last_summary_whole(launcher, home, tmp_path):
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    assert launch(launcher, EVAL, cwd, home).code == 0
    summary = (cwd / "run" / "summary.json").read_bytes()
    assert len(summary) > 1024
    full = launch(launcher, EVAL, cwd, home, file_bytes=1024)  # summary.json no longer fits
    assert full.code == 2
    assert full.error_lines == ["error: 'run/summary.json': File too large"]
    assert (cwd / "run" / "summary.json").read_bytes() == summary
    assert _temporary_files(cwd) == []


def test_a_full_disk_while_training_leaves_no_network(launcher, home, tmp_path):
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    (cwd / "tiny.json").write_text(tiny_config(TINY_MOTION))
    args = ["train", "motion", "--config", "tiny.json", "--out", "ck"]
    full = launch(launcher, args, cwd, home, file_bytes=4096)  # the weights do not fit
    assert full.code == 2
    assert len(full.error_lines) == 1 and "model.safetensors" in full.error_lines[0]
    assert not (cwd / "ck" / "model.safetensors").exists()
    assert not (cwd / "ck" / "manifest.json").exists()
    assert _temporary_files(cwd) == []
    again = launch(launcher, args, cwd, home)  # room again: the same command finishes the job
    assert again.code == 0, again.stderr
    assert (cwd / "ck" / "manifest.json").is_file()
