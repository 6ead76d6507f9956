"""What an f_p knows by name: the object types of the world it was trained in, whose order
indexes its networks' type channels, and the fixed cameras its images were taken by.

A keypoint network and its colour network learn the looks (name, kind and colour) of their
training world's types (`perception.synthetic` renders the images in it). Everything else f_p
knows of a scene (the types' sizes, the table, the shelves) it is given as the scene's `World`
when it looks, so that it sees in any scene whose objects have looks it learned, seen through
its cameras: a layout of its groceries, moved shelves, resized objects.

A checkpoint folder trained in another world than the kitchen holds that world as a scene file
(`TRAINING_SCENE`); one without it (the shipped f_p) learned the kitchen's
(`kitchen_vocabulary`), read when first asked for, never at import.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene_file import default_world, read_world
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.domain.world import ObjectType, World
from hsgplan.files import write_atomically
from hsgplan.scene_graph.names import TYPE_NAMES
from hsgplan.sim.render import Camera

# the world a checkpoint folder's networks were trained in, where it is not the kitchen
TRAINING_SCENE = "training_scene.toml"


@dataclass(frozen=True)
class Vocabulary:
    """The world an f_p was trained in, read as what it names.

    Attributes:
        world: the training world: its object types in channel order, its cameras.
    """

    world: World

    @property
    def types(self) -> tuple[str, ...]:
        """The type names, in the order of the networks' type channels."""
        return tuple(self.world.object_types)

    @property
    def views(self) -> tuple[Camera, ...]:
        """The fixed cameras, as the renderer takes them."""
        return tuple(Camera(**asdict(view)) for view in self.world.cameras)

    def object_type(self, index: int) -> ObjectType:
        """The type of channel `index`, at its training world's size."""
        return self.world.object_type(self.types[index])

    def same_looks(self, other: Vocabulary) -> bool:
        """Whether two vocabularies name the same looks through the same cameras, channel by
        channel (their types' sizes may differ: a layout resizes its groceries)."""
        return [_look(self.world.object_type(t)) for t in self.types] == [
            _look(other.world.object_type(t)) for t in other.types
        ] and tuple(self.world.cameras) == tuple(other.world.cameras)

    def unseen_looks(self, world: World) -> str | None:
        """Why this f_p cannot see a scene of `world`, or None when it can: every type of
        `world` has a look it learned (name, kind and colour), and the cameras are its own."""
        trained = self.world.object_types
        for t in world.type_list:
            known = trained.get(t.name)
            if known is None or _look(known) != _look(t):
                return f"it has not learned the look of '{t.name}'"
        if tuple(world.cameras) != tuple(self.world.cameras):
            return "its cameras are not the ones f_p was trained with"
        return None


def _look(t: ObjectType) -> tuple:
    return t.name, t.kind, t.color


def kitchen_vocabulary() -> Vocabulary:
    """The shipped f_p's: its images were staged in the kitchen (the default of every
    collection), its type channels are the kitchen's six types (`TYPES`), in that order."""
    return Vocabulary(training_world())


def training_world() -> World:
    """The world the shipped f_p was trained in: the default world, the kitchen."""
    return default_world()


# its type channels, as written into its networks (a test holds them to the kitchen's types)
TYPES: tuple[str, ...] = TYPE_NAMES

# The fixed views (in the kitchen, five at 320 x 240: facing the robot over the table; from
# behind the robot's shoulders on either side, low enough to look into the shelves and over the
# prepush regions past the arm, which hides the middle from straight behind; and from the
# table's far corners as low, which see the sides of the stacks on the open space and the shelf
# tops that the first three see from one side only: a box under a can or another box was often
# seen by one view alone). The keypoint network was first trained on the first three (see
# `perception.synthetic.ORIGINAL_VIEWS`), then fine-tuned on all five. Their poses are the
# scene file's (`kitchen_vocabulary().views`); how many there are, the networks' input.
VIEW_COUNT = 5


def read_vocabulary(folder: Path | str) -> Vocabulary:
    """The vocabulary of a checkpoint folder: its training scene's, else the kitchen's. A
    training scene that does not read is refused in one line."""
    path = Path(folder) / TRAINING_SCENE
    if not path.exists():
        return kitchen_vocabulary()
    world = read_world(path)
    if not world.object_types:
        raise InvalidInputError(f"'{path}' names no object types")
    return Vocabulary(world)


def write_vocabulary(folder: Path | str, vocabulary: Vocabulary) -> None:
    """Keep a vocabulary beside a checkpoint's networks (nothing for the kitchen's, which a
    folder without one reads as)."""
    path = Path(folder) / TRAINING_SCENE
    if vocabulary.world == training_world():
        return
    write_atomically(path, to_toml(scene_data(vocabulary.world)))
