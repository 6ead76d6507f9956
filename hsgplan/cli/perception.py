"""Commands of f_p, the pose estimator: `train perception`, `eval perception`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    bounded_option,
    dash,
    err,
    input_path,
    out,
    out_folder,
    print_table,
    read_config,
    refuses_bad_input,
    shown,
)
from hsgplan.cli.seeding import PerceptionRulesOption, SplitOption, rule_settings
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.seeds import marked, seed_words
from hsgplan.paths import PERCEPTION_CHECKPOINT, RUNS


@refuses_bad_input
def train_perception(
    config: Annotated[
        Path | None, typer.Option(help="Training configuration (JSON).", parser=input_path)
    ] = None,
    images: Annotated[
        list[Path] | None,
        typer.Option(
            help="Image collection folder, repeated for several (overrides the config).",
            parser=input_path,
        ),
    ] = None,
    out_dir: Annotated[
        Path,
        typer.Option("--out", help="Checkpoint folder (resumed if it exists).", parser=out_folder),
    ] = RUNS / "train-perception",
    scene: Annotated[
        Path | None,
        typer.Option(
            help="Learn this scene file's looks: its images rendered into OUT-images first "
            "(resumed), then trained on (docs/own-scene.md).",
            parser=input_path,
        ),
    ] = None,
    samples: Annotated[
        int, bounded_option("samples", "With --scene, images to render (scenes x views).")
    ] = 600,
    image_seed: Annotated[
        int, bounded_option("seed", "With --scene, the seed of the rendered scenes.")
    ] = 30,
    workers: Annotated[int, bounded_option("workers", "With --scene, rendering processes.")] = 2,
) -> None:
    """Train the DOPE-style keypoint network on a synthetic image collection, or on images of
    a scene file rendered first (--scene)."""
    from hsgplan.perception.train import PerceptionTrainConfig
    from hsgplan.perception.train import train_perception as run

    settings = read_config(config)
    if scene is not None and images:
        raise InvalidInputError("--scene renders its own images: give it or --images")
    if scene is not None:
        settings["images"] = str(_render_scene(scene, samples, image_seed, workers, out_dir))
    if images:
        settings["images"] = ",".join(str(p) for p in images)
    cfg = PerceptionTrainConfig.from_json(settings)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("keypoint network", total=cfg.epochs)
        batches = progress.add_task("epoch", total=None)

        def on_epoch(epoch: int, loss: float) -> None:
            progress.update(bar, completed=epoch, description=f"keypoint network loss {loss:.4f}")
            err.print(f"epoch {epoch}: loss {loss:.4f}", highlight=False)

        def on_batch(done: int, total: int) -> None:
            progress.update(batches, completed=done, total=total)

        run(cfg, out_dir, on_epoch, on_batch)
    out.print(f"trained the keypoint and colour networks into {shown(out_dir)}")


def _render_scene(scene: Path, samples: int, seed: int, workers: int, out_dir: Path) -> Path:
    """The scene's training images, rendered (or resumed) beside the checkpoint folder."""
    from hsgplan.collect.images import ImagesConfig, collect_images

    folder = out_dir.with_name(out_dir.name + "-images")
    config = ImagesConfig(samples, seed, scene=str(scene))
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task(f"images of {scene.name}", total=config.chunks)
        collect_images(config, folder, workers, None, lambda _: progress.advance(bar))
    err.print(f"images of {scene} in {shown(folder)}", highlight=False)
    return folder


@refuses_bad_input
def eval_perception(
    perception_checkpoint: Annotated[
        Path,
        typer.Option(
            help="f_p's checkpoint (default: the shipped one).",
            parser=input_path,
            show_default=False,
        ),
    ] = PERCEPTION_CHECKPOINT,
    scenes: Annotated[int, bounded_option("scenes", "Fresh scenes.")] = 100,
    seed: Annotated[
        int | None,
        bounded_option(
            "seed", "Seed of the scenes (default: 6, or the split's first; docs/perception.md)."
        ),
    ] = None,
    split: SplitOption = None,
    perception_rules: PerceptionRulesOption = "",
    raw: Annotated[
        bool,
        typer.Option(
            "--raw", metavar="", help="The fused PnP poses, not made to rest on their supports."
        ),
    ] = False,
    unpruned: Annotated[
        bool,
        typer.Option(
            "--no-pruned",
            metavar="",
            help="Keep what a lone view found that the other views contradict (dropped unless "
            "told: perception/phantoms.py).",
        ),
    ] = False,
    keypoint_yaw: Annotated[
        bool,
        typer.Option(
            "--no-silhouette",
            metavar="",
            help="Keep each box's yaw as its keypoints say, unchecked by its silhouette "
            "(perception/silhouette.py).",
        ),
    ] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the summary as JSON.", metavar="")
    ] = False,
    markdown: Annotated[
        bool, typer.Option("--markdown", help="Print Markdown tables.", metavar="")
    ] = False,
    views: Annotated[
        int | None,
        typer.Option(
            help="See from the first this many fixed views (3: the shoulder and front views).",
            min=1,
        ),
    ] = None,
    scene: Annotated[
        Path | None,
        typer.Option(
            "--scene",
            help="Stage the scenes in this scene file's world, or round a folder of them (scene "
            "k in its k-th file); default: the kitchen. f_p sees only the groceries and cameras "
            "it learned (docs/scenes.md).",
            parser=input_path,
        ),
    ] = None,
    loop: Annotated[
        bool,
        typer.Option(
            "--loop",
            metavar="",
            help="Scenes from inside the loop (the oracle part way through a random goal, the "
            "scene's own look) instead of synthetic ones.",
        ),
    ] = False,
) -> None:
    """f_p on fresh synthetic scenes: pose errors per object type, symbolic scene graph match."""
    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.domain.kitchen import KITCHEN
    from hsgplan.domain.scene_file import read_worlds
    from hsgplan.evaluation.config import unseeable
    from hsgplan.evaluation.perception_eval import evaluate, evaluate_loop, summary
    from hsgplan.evaluation.splits import check_seed, split_named
    from hsgplan.paths import shipped
    from hsgplan.perception.estimator import PoseEstimator
    from hsgplan.perception.rules import PerceptionRules
    from hsgplan.perception.synthetic import first_views
    from hsgplan.perception.vocabulary import read_vocabulary
    from hsgplan.sim.outcome import BELIEF_OFF, BELIEF_TURNED

    cameras = read_vocabulary(shipped(perception_checkpoint)).views
    shown = len(first_views(views, cameras)) if views is not None else len(cameras)
    worlds = (KITCHEN,) if scene is None else tuple(read_worlds(scene).values())
    if why := unseeable(worlds, scene, perception_checkpoint):
        raise InvalidInputError(why)
    if split is not None:
        seed = split_named(split.value).seeds.start if seed is None else seed
        check_seed(split_named(split.value), seed)
    seed = 6 if seed is None else seed
    settings = rule_settings(perception_rules)
    estimator = PoseEstimator.load(
        perception_checkpoint,
        settled=not raw,
        pruned=not unpruned,
        silhouette=not keypoint_yaw,
        rules=PerceptionRules.parse(settings),
    )
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("scenes", total=scenes)
        run = evaluate_loop if loop else evaluate
        found = run(
            estimator,
            scenes,
            seed,
            on_scene=lambda: progress.advance(task),
            views=shown,
            worlds=worlds,
        )
        report = summary(found) | {"seed": seed, "split": split and split.value}
        report["perception_rules"] = list(settings)
    if as_json:
        print(json.dumps(report, indent=2))
        return

    rows = [
        (
            t,
            str(m["objects"]),
            dash(m["translation_cm_median"], ".2f"),
            dash(m["rotation_deg_median"], ".1f"),
            dash(m.get("off_targets"), ".3f"),
        )
        for t, m in report["by_type"].items()
    ]
    rows.append(
        (
            "all",
            str(report["objects"]),
            dash(report["translation_cm_median"], ".2f"),
            dash(report["rotation_deg_median"], ".1f"),
            dash(report.get("off_targets"), ".3f"),
        )
    )
    title = (
        f"f_p on {report['scenes']} {'scenes from inside the loop' if loop else 'fresh scenes'}, "
        f"{seed_words(seed, split and split.value)}"
        f"{', rules ' + ', '.join(settings) if settings else ''}"
        f"{f', in {scene}' if scene is not None else ''}"
        f"{f' (the first {views} views)' if views else ''}: objects found (recall) "
        f"{report['found_rate']:.3f}, detections matching an object (precision) "
        f"{report['precision']:.3f} ({report['unmatched_detections']} matched none), "
        f"symbolic scene graph equal {report['symbolic_match_rate']:.3f}"
    )
    if report["misreads"]:
        misreads = ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in report["misreads"].items())
        title += f"; scenes misread by: {misreads}"
    title = marked(title, seed, perception=True, split=split and split.value)
    print_table(
        title,
        (
            "type",
            "objects",
            "translation cm (median)",
            "rotation deg (median)",
            f"off > {100 * BELIEF_OFF:.0f} cm or {BELIEF_TURNED:.0f}°",
        ),
        rows,
        markdown,
    )
