"""A run folder's timing adds up over its sittings, and older folders still read."""

import json
import os

import pytest

from hsgplan.runner.run_folder import TIMING, add_wall_seconds, read_timing, sittings


def test_sittings_add_up(tmp_path):
    assert read_timing(tmp_path) == {"wall_seconds": 0.0, "sittings": []}
    add_wall_seconds(tmp_path, 1.5, workers=2)
    add_wall_seconds(tmp_path, 2.25, workers=1)
    timing = read_timing(tmp_path)
    assert timing["wall_seconds"] == 3.75
    assert [(s["seconds"], s["workers"]) for s in timing["sittings"]] == [(1.5, 2), (2.25, 1)]
    assert all(s["cores"] == os.cpu_count() for s in timing["sittings"])


def test_folder_written_with_the_older_key_still_reads(tmp_path):
    old = {"wall_seconds": 90.0, "sessions": [{"seconds": 90.0, "workers": 2, "cores": 2}]}
    (tmp_path / TIMING).write_text(json.dumps(old))
    add_wall_seconds(tmp_path, 10.0, workers=2)
    timing = read_timing(tmp_path)
    assert timing["wall_seconds"] == 100.0
    assert [s["seconds"] for s in timing["sittings"]] == [90.0, 10.0]
    assert "sessions" not in json.loads((tmp_path / TIMING).read_text())


def test_unreadable_timing_counts_as_none(tmp_path):
    (tmp_path / TIMING).write_text("{not json")
    assert read_timing(tmp_path) == {"wall_seconds": 0.0, "sittings": []}


def test_a_summary_written_with_the_older_key_lists_its_sittings():
    method = {"agent": "regression+gnn", "wall_seconds": 9.0, "sessions": [{"workers": 2}]}
    assert sittings(method) == [{"workers": 2}]
    assert sittings({"sittings": [], "sessions": [{"workers": 1}]}) == []
    with pytest.raises(KeyError, match="sittings"):  # named as the page refusing it says
        sittings({"wall_seconds": 1.0})
