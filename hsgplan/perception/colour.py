"""Which type a detection is, from the colour where its centroid is seen.

The keypoint network finds objects and their keypoints well, but tells apart poorly the types
that share a shape: the three cans, and butter and cream cheese (same box). Trained with
belief maps per type, it finds a can at every can-shaped place in every can type's maps with
about the same belief. What does tell them apart is their colour, which the maps' loss never
makes the network weigh against another type's. So a second, small network is trained to do
only that: from the mean chromaticity and brightness of the pixels around the centroid's
projection in a view, the type, as a softmax over every type (a cross-entropy, so the types
compete). The estimator averages its probabilities over the views that saw an object.

A last class is the background: patches wholly outside every object's projected cuboid. A
hidden object is named by a vote of the pixels it keeps in sight (`pixel_vote`), and some of
them are the table's or a shelf's; without it, a pale table's pixels voted butter, and a cream
cheese under another was named butter from its strip of sides and table.

Labels come from the renderer: each in-sight object's type and its centroid projected
through the camera that rendered the image; the background, by the objects' cuboids projected
through it. Saved in the keypoint network's checkpoint folder, in `colour/` (its own
`config.json`, weights and manifest); trained by `perception/train.py` (`train_colour`), which
this module, read at inference, does not import.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from hsgplan.checkpoint import load_trained
from hsgplan.domain.checks import BOUNDS, check_fields, from_settings, setting
from hsgplan.domain.scene_file import MAX_TYPES
from hsgplan.perception.vocabulary import TYPES

PATCH = 3  # pixels each side of the centroid's pixel
FEATURES = 4  # chromaticity r, g, b and brightness
MIN_REGION = 12  # pixels of an object in sight for their colour to name it
MIN_VOTES = 6  # of them named a type of the object's kind, for `pixel_vote` to say
FOLDER = "colour"
TYPE_COUNT = len(TYPES)  # the shipped f_p's object types (the kitchen's)
# the background's class index in a network of the kitchen's types: the last, after its types
BACKGROUND = TYPE_COUNT


@dataclass(frozen=True)
class ColourConfig:
    # the object types (f_p's vocabulary: `perception.vocabulary`), then the background
    types: int = setting(TYPE_COUNT + 1, lo=2, hi=MAX_TYPES + 1)
    hidden: int = setting(32, lo=1, hi=4096)
    steps: int = setting(400, lo=1, hi=1_000_000)
    lr: float = setting(0.01, above=0, hi=10)
    seed: int = setting(0, **BOUNDS["seed"])

    def __post_init__(self) -> None:
        check_fields(self)

    def to_json(self) -> dict:
        return asdict(self)

    @staticmethod
    def from_json(d: dict) -> ColourConfig:
        return from_settings(ColourConfig, d, "colour network setting")


class ColourNet(nn.Module):
    """Type logits from a patch's colour features.

    Args:
        config: the sizes (`ColourConfig`).

    Shapes:
        input: [N, FEATURES]; output: [N, types].
    """

    def __init__(self, config: ColourConfig) -> None:
        super().__init__()
        self.objects = config.types - 1  # classes before the background's
        self.mlp = nn.Sequential(
            nn.Linear(FEATURES, config.hidden), nn.ReLU(), nn.Linear(config.hidden, config.types)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.mlp(x)


def type_probs(colour: ColourNet, rows: np.ndarray) -> torch.Tensor:
    """The colour network's probabilities of the object types, against one another (the
    background left out): [N, FEATURES] features -> [N, types]."""
    with torch.no_grad():
        return torch.softmax(colour(torch.from_numpy(rows))[:, : colour.objects], dim=1)


def features(image: np.ndarray, pixel: np.ndarray) -> np.ndarray | None:
    """Mean chromaticity (r, g, b over their sum) and brightness of the pixels within `PATCH`
    of `pixel` in an [H, W, 3] uint8 image; None when it is not in the image."""
    if not np.isfinite(pixel).all():
        return None
    u, v = int(round(float(pixel[0]))), int(round(float(pixel[1])))
    h, w = image.shape[:2]
    if not (0 <= u < w and 0 <= v < h):
        return None
    patch = image[max(0, v - PATCH) : v + PATCH + 1, max(0, u - PATCH) : u + PATCH + 1]
    return _described(patch.reshape(-1, 3))


def pixel_vote(
    colour: ColourNet, image: np.ndarray, mask: np.ndarray, allowed: torch.Tensor
) -> torch.Tensor | None:
    """The colour network's mean probabilities [types] over the pixels of `mask` [H, W] (bool)
    that it names one of the `allowed` types [types] (bool), each pixel on its own (one it
    names the background is no vote); None when the mask holds fewer than `MIN_REGION` pixels,
    or fewer than `MIN_VOTES` are so named.

    A region painted from estimated poses holds pixels of what hides it too, and a mean of two
    colours can be a third type's: the orange of a soup and the green of a cream cheese under it
    average to a butter's yellow. Each pixel named on its own, those of another kind left out,
    names the cream cheese (3 of 8 such misnamed objects on 100 tuning scenes, seed 2)."""
    if int(mask.sum()) < MIN_REGION:
        return None
    rows = _chromaticity(image[mask].astype(np.float64) / 255.0)
    with torch.no_grad():
        logits = colour(torch.from_numpy(rows))
    named = logits.argmax(dim=1)
    votes = (named < colour.objects) & allowed[named.clamp(max=colour.objects - 1)]
    if int(votes.sum()) < MIN_VOTES:
        return None
    return torch.softmax(logits[votes, : colour.objects], dim=1).mean(dim=0)


def named_pixels(colour: ColourNet, image: np.ndarray) -> np.ndarray:
    """The class the colour network names each pixel of an [H, W, 3] uint8 image, on its own:
    [H, W] int64 (a type's index; the background's is the last)."""
    rows = _chromaticity(image.reshape(-1, 3).astype(np.float64) / 255.0)
    with torch.no_grad():
        named = colour(torch.from_numpy(rows)).argmax(dim=1).numpy()
    return named.reshape(image.shape[:2])


def _described(pixels: np.ndarray) -> np.ndarray:
    """The features of the mean of [N, 3] uint8 pixels: [FEATURES]."""
    return _chromaticity(pixels.astype(np.float64).mean(axis=0, keepdims=True) / 255.0)[0]


def _chromaticity(rgb: np.ndarray) -> np.ndarray:
    """Chromaticity (r, g, b over their sum) and brightness of [N, 3] colours in 0..1:
    [N, FEATURES] float32."""
    total = np.maximum(rgb.sum(axis=1, keepdims=True), 1e-6)
    return np.concatenate([rgb / total, total / 3], axis=1).astype(np.float32)


def load_colour(folder: Path) -> ColourNet:
    model, _ = load_trained(folder, ColourConfig.from_json, ColourNet, "colour network")
    return model  # type: ignore[return-value]
