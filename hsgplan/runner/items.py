"""Work items run once each, resumably: the loop `eval`, `eval task` and `eval motion` share.

A job is a list of items (small picklable values) and a top-level function that turns one into
a JSON-able result. Results are appended to the run folder's `episodes.jsonl` as they finish,
one line `{"key": ..., "result": ...}` each; a run started again with the same configuration
reads them back and runs only the items whose key is missing, so an interruption loses at most
the items in flight and repeats nothing that was logged. Without a run folder nothing is kept.
`collect` runs its chunks through the same engines and run-folder claim, keeping each chunk as
a file of its own (`hsgplan.collect.motion`).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Hashable, Sequence
from pathlib import Path
from typing import Any, TypeVar

from hsgplan.domain.errors import a
from hsgplan.runner.engines import engine
from hsgplan.runner.run_folder import RESULTS, claim, logged_rows

Item = TypeVar("Item")


def run_items(
    work: Callable[[Item], Any],
    items: Sequence[Item],
    key: Callable[[Item], Hashable],
    *,
    run_dir: Path | None = None,
    kind: str = "",
    config: dict | None = None,
    workers: int = 2,
    ray: str | None = None,
    on_result: Callable[[Any], None] | None = None,
) -> list[Any]:
    """`work(item)` for every item not yet logged in `run_dir`; every result, in item order.

    `kind` (the command) and `config` are what the run folder is claimed with (a folder of
    another kind or made with another configuration is refused in one line); `config` should
    fingerprint whatever produced the results (`hsgplan.checkpoint.fingerprint`), so that a
    resumed run never mixes rows of another checkpoint with new ones. `on_result` sees each
    result once, those read back first.
    """
    keys = [str(key(item)) for item in items]
    done: dict[str, Any] = {}
    if run_dir is not None:
        claim(
            run_dir,
            kind,
            config or {},
            f"'{run_dir}' holds {a(kind)} run with another configuration or other checkpoints; "
            "use another --out",
        )
        for row in logged_rows(run_dir):
            if isinstance(row, dict) and "key" in row and "result" in row:
                done[str(row["key"])] = row["result"]
    for k in keys:
        if k in done and on_result:
            on_result(done[k])
    todo = [(k, item) for k, item in zip(keys, items, strict=True) if k not in done]
    if todo:
        log_file = open(run_dir / RESULTS, "a") if run_dir else contextlib.nullcontext()  # noqa: SIM115
        with log_file as log, engine(workers, ray) as runner:
            pending = {runner.submit(work, item): k for k, item in todo}
            while pending:
                handle, result = runner.next_done(set(pending))
                k = pending.pop(handle)
                if log:
                    log.write(json.dumps({"key": k, "result": result}) + "\n")
                    log.flush()
                done[k] = result
                if on_result:
                    on_result(result)
    return [done[k] for k in keys]
