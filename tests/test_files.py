"""Files written whole or not at all (`hsgplan.files`)."""

import errno

import pytest

from hsgplan.files import atomic, temporary_name, write_atomically


def test_a_write_replaces_the_whole_file(tmp_path):
    path = tmp_path / "summary.json"
    write_atomically(path, "old\n")
    write_atomically(path, b"new\n")
    assert path.read_bytes() == b"new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_a_full_disk_leaves_the_old_file_and_no_temporary_one(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("old\n")
    with pytest.raises(OSError) as e, atomic(path) as tmp:
        tmp.write_text("half of the new")
        raise OSError(errno.ENOSPC, "No space left on device")  # as a write would
    assert e.value.filename == str(path)  # the error names the file meant, not the temporary
    assert path.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_an_interruption_leaves_no_file_where_there_was_none(tmp_path):
    path = tmp_path / "table1.png"
    with pytest.raises(KeyboardInterrupt), atomic(path) as tmp:
        tmp.write_bytes(b"\x89PNG")
        raise KeyboardInterrupt
    assert not any(tmp_path.iterdir())


def test_the_temporary_name_is_hidden_and_keeps_the_suffix(tmp_path):
    tmp = temporary_name(tmp_path / "chunk-000001.npz")
    assert tmp.parent == tmp_path
    assert tmp.name.startswith(".") and tmp.suffix == ".npz"
