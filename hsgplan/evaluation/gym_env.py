"""`gymnasium.make("hsgplan/KitchenStorage-v0")`'s entry point: the env in the kitchen unless
a `world` is given. The sim layer takes its world; the default is resolved here, above it."""

from __future__ import annotations

from hsgplan.domain.scene_file import default_world
from hsgplan.sim.env import KitchenStorageEnv


def kitchen_storage_env(**kwargs) -> KitchenStorageEnv:
    return KitchenStorageEnv(**({"world": default_world()} | kwargs))
