"""`hsgplan collect images`: synthetic training images for f_p, rendered in resumable chunks
(format: `perception/images.py`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

from hsgplan.domain.checks import BOUNDS, MAX_SAMPLES, bounded, check_fields, setting
from hsgplan.domain.scene_file import read_world
from hsgplan.domain.world import World
from hsgplan.perception.images import CHUNK, FORMAT, render_chunk, write_format
from hsgplan.perception.synthetic import P_ELSEWHERE, first_views
from hsgplan.perception.vocabulary import VIEW_COUNT, Vocabulary, training_world
from hsgplan.runner.items import run_items
from hsgplan.sim.render import Camera

KIND = "collect-images"


@dataclass(frozen=True)
class ImagesConfig:
    # samples wanted (unstaged draws are skipped, so the last chunk may hold fewer)
    samples: int = field(metadata=bounded(**BOUNDS["samples"]))
    seed: int = setting(0, **BOUNDS["seed"])
    chunk: int = setting(CHUNK, lo=1, hi=MAX_SAMPLES)
    p_elsewhere: float = setting(P_ELSEWHERE, lo=0.0, hi=1.0)  # see `synthetic.P_ELSEWHERE`
    views: int = VIEW_COUNT  # the first this many fixed views (3: shoulders and front)
    # a scene file whose world the scenes are staged in (None: the kitchen, the shipped f_p's);
    # an f_p trained on the images learns its groceries' looks through its cameras
    scene: str | None = None

    def __post_init__(self) -> None:
        check_fields(self)
        self.cameras()

    def world(self) -> World:
        """The world the scenes are staged in."""
        return training_world() if self.scene is None else read_world(self.scene)

    def cameras(self) -> tuple[Camera, ...]:
        """The fixed views rendered: the first `views` of the world's."""
        return first_views(self.views, Vocabulary(self.world()).views)

    @property
    def chunks(self) -> int:
        return -(-self.samples // self.chunk)


def collect_images(
    config: ImagesConfig,
    run_dir: Path,
    workers: int = 2,
    ray: str | None = None,
    on_chunk=None,
) -> list[dict]:
    """Render every chunk not yet logged in `run_dir`; the log rows of all chunks."""
    # The views are recorded as cameras (a collection from before the count was a setting
    # holds the first three), not as the count; the samples wanted under the key collections
    # have always recorded them by ("count"), so that every collection resumes.
    # a collection of the training world records no scene, as before scenes could be given
    dropped = ("views", "samples") + (("scene",) if config.scene is None else ())
    settings = {k: v for k, v in asdict(config).items() if k not in dropped} | {
        "count": config.samples,
        "format": FORMAT,
        "views": [[*c.eye, *c.target, c.fov, c.width, c.height] for c in config.cameras()],
    }
    items = [(str(run_dir), c, config) for c in range(config.chunks)]
    rows = run_items(
        _render,
        items,
        key=lambda item: item[1],
        run_dir=run_dir,
        kind=KIND,
        config=settings,
        workers=workers,
        ray=ray,
        on_result=on_chunk,
    )
    write_format(run_dir, Vocabulary(config.world()))
    return rows


def _render(item: tuple[str, int, ImagesConfig]) -> dict:
    run_dir, chunk, c = item
    world = c.world()
    return render_chunk(run_dir, c.seed, chunk, c.chunk, c.samples, world, c.p_elsewhere, c.views)
