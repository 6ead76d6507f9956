"""One writer per folder (`hsgplan.runner.lock`), and the claims that take the lock."""

import os
import subprocess
import sys
import textwrap

import pytest

from hsgplan import training
from hsgplan.domain.errors import InvalidInputError
from hsgplan.runner.lock import LOCK, hold_folder, holds, release
from hsgplan.runner.run_folder import claim


def _hold_in_another_process(folder):
    """A child that holds `folder`'s lock until its stdin closes; its pid."""
    code = textwrap.dedent(
        f"""
        import sys
        from hsgplan.runner.lock import hold_folder
        hold_folder({str(folder)!r})
        print("held", flush=True)
        sys.stdin.read()
        """
    )
    child = subprocess.Popen(
        [sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "held"
    return child


def test_a_folder_held_by_another_process_is_refused_naming_the_holder(tmp_path):
    run = tmp_path / "run"
    child = _hold_in_another_process(run)
    try:
        with pytest.raises(InvalidInputError, match=f"pid {child.pid}") as e:
            claim(run, "eval", {"goals": 1}, "other configuration")
        assert "\n" not in str(e.value)
        assert sorted(p.name for p in run.iterdir()) == [LOCK]  # no config.json written
        with pytest.raises(InvalidInputError, match="another run"):
            training.claim(run, {"lr": 0.1})
    finally:
        child.stdin.close()
        child.wait()
    claim(run, "eval", {"goals": 1}, "other configuration")  # free again once it ended
    assert (run / "config.json").is_file() and holds(run)


def test_the_lock_of_a_dead_process_is_taken_over(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        text=True,
        capture_output=True,
        check=True,
    ).stdout.strip()
    (run / LOCK).write_text(f"pid {dead} since yesterday: hsgplan eval\n")
    claim(run, "eval", {"goals": 1}, "other configuration")
    assert f"pid {os.getpid()}" in (run / LOCK).read_text()


def test_holding_is_reentrant_and_released(tmp_path):
    hold_folder(tmp_path)
    hold_folder(tmp_path)  # a table and its own claim of the same folder
    assert holds(tmp_path)
    release(tmp_path)
    assert not holds(tmp_path)
    assert not (tmp_path / LOCK).exists()  # the lock leaves with its holder


def test_the_lock_leaves_when_its_process_ends(tmp_path):
    run = tmp_path / "run"
    child = _hold_in_another_process(run)
    assert (run / LOCK).is_file()
    child.stdin.close()
    child.wait()
    assert not (run / LOCK).exists()


def test_a_lock_taken_over_is_not_removed_by_its_earlier_holder(tmp_path):
    # the earlier holder's file is gone (another took the folder over after it had been
    # removed): leaving must not remove the file the new holder locks
    hold_folder(tmp_path)
    (tmp_path / LOCK).unlink()
    (tmp_path / LOCK).write_text("pid 1 since now: another run\n")
    release(tmp_path)
    assert (tmp_path / LOCK).read_text() == "pid 1 since now: another run\n"


def test_an_unheld_lock_left_behind_is_not_other_files(tmp_path):
    (tmp_path / LOCK).write_text("pid 1 since yesterday: hsgplan eval\n")
    claim(tmp_path, "eval", {"goals": 1}, "other configuration")  # not "holds other files"
    release(tmp_path)
    other = tmp_path / "ck"
    other.mkdir()
    (other / LOCK).write_text("")
    training.claim(other, {"lr": 0.1})


def test_a_link_planted_as_the_lock_is_never_written_through(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    run = tmp_path / "run"
    run.mkdir()
    (run / LOCK).symlink_to(victim)
    with pytest.raises(OSError):
        hold_folder(run)
    assert victim.read_text() == "keep me\n"


def test_what_a_killed_claim_leaves_is_not_other_files(tmp_path):
    (tmp_path / LOCK).write_text("")
    (tmp_path / ".config.tmp4242.json").write_text('{"kind": "ev')  # killed while writing
    claim(tmp_path, "eval", {"goals": 1}, "other configuration")
    assert (tmp_path / "config.json").is_file()
