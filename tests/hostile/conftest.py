"""The hostile suite's fixtures: one launcher per test process, one copy of the shipped data."""

from __future__ import annotations

import pytest

from tests.hostile.harness import Launcher, shipped_copy


@pytest.fixture(scope="session")
def launcher():
    server = Launcher()
    yield server
    server.close()


@pytest.fixture(scope="session")
def home(tmp_path_factory):
    return shipped_copy(tmp_path_factory.mktemp("hostile"))
