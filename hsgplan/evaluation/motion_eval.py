"""`hsgplan eval motion`: single-shot success of each motion model on fresh scenes.

Scenes come from the same generator as the training data but from another stream
(`EVAL_STREAM + seed`), so no evaluation scene is a training scene. With scene files, each
world gets the same task indices; a model whose networks know the kitchen's names is left out
of a world that names others (the GNN is then refused). In every staged scene each
model proposes its best bin pair once, and that primitive is executed from the same saved
state: the models are compared on identical scenes.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.agents.registry import check_reads
from hsgplan.checkpoint import fingerprint
from hsgplan.data.motion_tasks import draw_task
from hsgplan.data.motion_trials import stage_task, try_params
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world, read_worlds
from hsgplan.evaluation.config import world_of_file
from hsgplan.evaluation.intervals import training_goal_interval
from hsgplan.paths import shipped
from hsgplan.runner.items import run_items
from hsgplan.sim.scene import Scene
from hsgplan.trainings import seed_folders

MODELS = ("gnn", "gnn_paper", "mlp", "mlp_paper", "mlp_bce", "random")
# Where their checkpoints exist, shown beside ours so that differences are measured, not
# claimed: the GNN with the paper's MLP head (ours has the bin-query head), the MLP as the
# paper trains it (its head, ce on the successes) and with our loss alone (bce, every trial).
# `mlp` is the fair baseline: the GNN's examples, loss, bin inputs and parameter count. Only the
# GNN is required: a folder of one GNN (a point of a learning curve) is measured against Random.
OPTIONAL = ("gnn_paper", "mlp", "mlp_paper", "mlp_bce")
FOLDERS = {
    "gnn": "gnn",
    "gnn_paper": "gnn-paper",
    "mlp": "mlp",
    "mlp_paper": "mlp-paper",
    "mlp_bce": "mlp-bce",
}
# a model's name in the tables: a column headed "(paper)" anywhere holds the paper's numbers,
# so networks trained by the paper's recipe are named for the recipe
LABELS = {
    "gnn": "GNN",
    "gnn_paper": "GNN, paper's recipe",
    "mlp": "MLP",
    "mlp_paper": "MLP, paper's recipe",
    "mlp_bce": "MLP, BCE",
    "random": "Random",
}
EVAL_STREAM = 1_000_000  # collection streams use small seeds; evaluation never meets them
CHUNK = 8
CROWDED = 2  # a shelf top with this many of its 4 cells taken counts as crowded


def _learned(
    kind: MotionPrimitive, checkpoints: Path, world: World, scene: str | None = None
) -> dict:
    """The trained models for a primitive, loaded once (optional ones where they exist and
    read `world`'s names)."""
    from hsgplan.motion.generator import LearnedMotion

    out = {}
    checkpoints = shipped(checkpoints)
    for name, folder in FOLDERS.items():
        path = checkpoints / f"{kind.value}-{folder}"
        if name in OPTIONAL and not path.exists():
            continue
        try:
            check_reads([path], world, scene)
        except InvalidInputError:
            if name in OPTIONAL:
                continue
            raise
        out[name] = LearnedMotion(name, {kind: path})
    return out


def run_eval_chunk(
    primitive: str, seed: int, start: int, checkpoints: str, scene: str | None = None
) -> list[dict]:
    """Every model once in each staged scene of tasks start..start+CHUNK-1, in the world of the
    scene file `scene` (None: the kitchen); a worker's job."""
    import torch

    torch.set_num_threads(1)  # one process per core already
    kind = MotionPrimitive(primitive)
    rows = []
    from hsgplan.motion.generator import RandomMotion

    world = world_of_file(scene) if scene else default_world()
    learned = _learned(kind, Path(checkpoints), world, scene)
    for index in range(start, start + CHUNK):
        task = draw_task(kind, EVAL_STREAM + seed, index, world)
        # Random draws from its own seed per task, so chunking cannot change its choices.
        generators = learned | {"random": RandomMotion(seed * 1_000_003 + index)}
        for name in generators:
            # A fresh scene per model: a restored physics state still carries the solver's
            # contact caches, so one model's trial would nudge the next one's outcome.
            with Scene((), seed=seed, visuals=False, world=world) as sim:
                staged = stage_task(sim, task)
                if staged is None:
                    break
                params = generators[name].ranked(staged.before, task.subgoal)[0]
                outcome = try_params(sim, staged, params)
            rows.append(
                {
                    "task": index,
                    "model": name,
                    "crowding": task.crowding,
                    "shelf_top": task.target in world.shelves and kind is MotionPrimitive.PLACE,
                    "ok": outcome.ok,
                    "status": outcome.status.value,
                }
            )
    return rows


def rate(rows: list[dict]) -> dict:
    """The success rate, and its 95% interval over trainings and scenes
    (`evaluation.intervals`)."""
    cells: dict[tuple, list[float]] = defaultdict(list)
    for r in rows:
        cells[(r.get("training"), (r.get("scene"), r["task"]))].append(float(r["ok"]))
    ci = training_goal_interval(cells)
    return {
        "success_rate": sum(r["ok"] for r in rows) / len(rows),
        "trials": len({scene for _, scene in cells}),
        **({"success_ci": list(ci)} if ci is not None else {}),
    }


def summarize(rows: list[dict]) -> dict:
    """Per model: overall, per crowding level, and (place) on crowded shelf tops."""
    out = {}
    for name in MODELS:
        mine = [r for r in rows if r["model"] == name]
        if not mine:
            continue
        by_level = defaultdict(list)
        for r in mine:
            by_level[str(r["crowding"])].append(r)
        entry = rate(mine) | {"by_crowding": {k: rate(v) for k, v in sorted(by_level.items())}}
        by_training = defaultdict(list)
        for r in mine:
            by_training[r.get("training")].append(r["ok"])
        if len(by_training) > 1:  # how far one training's rate lies from another's
            entry["success_by_training"] = {
                str(s): sum(oks) / len(oks) for s, oks in sorted(by_training.items())
            }
        crowded = [r for r in mine if r["shelf_top"] and r["crowding"] >= CROWDED]
        if crowded:
            entry["crowded_shelf_tops"] = rate(crowded)
        out[name] = entry
    return out


@dataclass(frozen=True)
class MotionChunk:
    """CHUNK consecutive evaluation scenes of one primitive: a unit of `eval motion` work."""

    primitive: str
    seed: int
    start: int
    checkpoints: str
    scene: str | None = None  # the scene file it runs in (None: the kitchen)

    @property
    def key(self) -> str:
        where = f"{Path(self.scene).stem}/" if self.scene else ""
        return f"{where}{self.primitive}/{self.start}"


def run_motion_chunk(chunk: MotionChunk) -> list[dict]:
    return run_eval_chunk(chunk.primitive, chunk.seed, chunk.start, chunk.checkpoints, chunk.scene)


def evaluate_motion(
    primitives: list[str],
    trials: int,
    seed: int,
    checkpoints: Path,
    workers: int,
    progress: Callable[[], None] | None = None,
    run_dir: Path | None = None,
    ray: str | None = None,
    scene: Path | None = None,
) -> dict:
    """`{primitive: {model: {"success_rate", "trials", "by_crowding", ...}}}` over the first
    `trials` tasks of the evaluation stream (scenes that could not be staged are skipped), in
    the scene file `scene` or in each of a folder's (default: the kitchen), pooled. With
    `run_dir`, finished chunks are kept there and a run started again skips them."""
    if trials < 1:
        raise InvalidInputError(f"--trials {trials}: need at least one")
    if not primitives:
        raise InvalidInputError("--primitives names none: place, push or place,push")
    kinds = []
    for p in primitives:
        if p not in ("place", "push"):
            raise InvalidInputError(f"primitive '{p}': place or push")
        kinds.append(MotionPrimitive(p))
    trainings = seed_folders(checkpoints) or {None: Path(checkpoints)}
    rows: dict[str, list[dict]] = {k.value: [] for k in kinds}
    for seed_of, folder in trainings.items():
        into = run_dir if run_dir is None or seed_of is None else run_dir / f"seed-{seed_of}"
        for kind, got in _rows(kinds, trials, seed, folder, workers, progress, into, ray, scene):
            rows[kind] += [r | {"training": seed_of} for r in got]
    report = {}
    first = next(iter(trainings.values()))  # the shipped seed's networks: what each learnt from
    for kind in kinds:
        report[kind.value] = summarize(rows[kind.value])
        for name, record in _trained_on(kind, first).items():
            if name in report[kind.value]:  # left out where it cannot read the scene's names
                report[kind.value][name] |= asdict(record)
    return report


def _rows(
    kinds: list[MotionPrimitive],
    trials: int,
    seed: int,
    checkpoints: Path,
    workers: int,
    progress: Callable[[], None] | None,
    run_dir: Path | None,
    ray: str | None,
    scene: Path | None,
) -> list[tuple[str, list[dict]]]:
    """Every trial of one set of networks, by primitive, in the order of the tasks."""
    worlds = {None: default_world()} if scene is None else read_worlds(scene)
    for kind in kinds:  # missing checkpoints, or a GNN that cannot read a scene: before work
        _learned(kind, checkpoints, default_world())
        gnn = shipped(checkpoints) / f"{kind.value}-{FOLDERS['gnn']}"
        for path, world in worlds.items():
            check_reads([gnn], world, path and str(path))
            if kind is MotionPrimitive.PUSH and world.goal_interior is None:
                raise InvalidInputError(
                    f"'{path}' has no shelf interior to push into: --primitives place"
                )
    chunks = [
        MotionChunk(kind.value, seed, start, str(checkpoints), path and str(path))
        for path in worlds
        for kind in kinds
        for start in range(0, trials, CHUNK)
    ]

    def on_chunk(rows: list[dict]) -> None:
        if progress:
            for _ in range(len({r["task"] for r in rows if r["task"] < trials})):
                progress()

    results = run_items(
        run_motion_chunk,
        chunks,
        key=lambda c: c.key,
        run_dir=run_dir,
        kind="eval-motion",
        config={
            "primitives": [k.value for k in kinds],
            "seed": seed,
            "checkpoints": str(checkpoints),
            "fingerprint": fingerprint(
                [shipped(checkpoints) / f"{k.value}-{f}" for k in kinds for f in FOLDERS.values()]
                + [p for p in worlds if p is not None]
            ),
            **({"scene": str(scene)} if scene else {}),
        },
        workers=workers,
        ray=ray,
        on_result=on_chunk,
    )
    by_kind = []
    for kind in kinds:
        got = [
            r | {"scene": chunk.scene}  # a task's index is a scene's own in each scene file
            for chunk, part in zip(chunks, results, strict=True)
            if chunk.primitive == kind.value
            for r in part
            if r["task"] < trials
        ]
        got.sort(key=lambda r: (r["task"], MODELS.index(r["model"])))
        by_kind.append((kind.value, got))
    return by_kind


def _trained_on(kind: MotionPrimitive, checkpoints: Path) -> dict:
    """Each learned model's parameter count, training examples and the epoch it kept."""
    from hsgplan.motion.train import TrainingRecord

    folders = shipped(checkpoints)
    return {
        name: TrainingRecord.of(folders / f"{kind.value}-{FOLDERS[name]}", gen.nets[kind])
        for name, gen in _learned(kind, checkpoints, default_world()).items()
    }
