"""Shared by every test: no test keeps a folder's lock (`hsgplan.runner.lock`) past its end."""

import pytest

from hsgplan.runner.lock import release_all


@pytest.fixture(autouse=True)
def _release_folder_locks():
    yield
    release_all()
