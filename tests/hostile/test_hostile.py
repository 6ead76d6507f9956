"""Every hostile case (`tests/hostile/`) is refused cleanly: one `error:` line, exit code 2,
nothing written, within the time limit."""

from __future__ import annotations

import pytest

from tests.hostile import all_cases
from tests.hostile.harness import run_case

CASES = all_cases()


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_refused_cleanly(case, launcher, home, tmp_path):
    result = run_case(case, launcher, tmp_path, home)
    detail = "; ".join([result.gist, *result.notes])
    assert result.kind == "refused", f"{result.kind}: {detail}\nstderr: {result.stderr[-2000:]}"
