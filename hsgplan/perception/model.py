"""The DOPE-style keypoint network: belief maps of the 9 cuboid keypoints per object type and
affinity fields that tie each corner to its object's centroid.

DOPE (Tremblay et al. 2018) trains one VGG-based network per object; here one small network,
trained from scratch on the synthetic images, serves every type: its output has a belief map
per (type, keypoint) and, per corner, a 2-vector field pointing from the corner to the
centroid (shared by the types: which type a corner belongs to is its belief map's business), at a
quarter of the image's resolution. Several stages refine the maps, each seeing
the features and the previous stage's maps, as in DOPE and the convolutional pose machines it
follows; every stage is supervised.

The stages work at a quarter of the image's resolution (`stride` 4). Two thin boxes stacked
(2.4 cm each) have centroids 4 to 7 pixels apart in these views: one cell at that stride, one
blob in the maps, so the lower box was never found. With `stride` 2 a light head
(`_Refine`) brings the last stage's maps to half resolution, with the first block's
half-resolution features for where edges are; earlier stages' maps are scaled up to be
supervised there too.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import torch
from torch import nn

from hsgplan.checkpoint import load_trained
from hsgplan.domain.errors import InvalidInputError
from hsgplan.perception.keypoints import KEYPOINTS
from hsgplan.perception.vocabulary import TYPES

STRIDE = 4  # input pixels per output cell, unless a config says 2
STRIDES = (2, 4)
CORNERS = KEYPOINTS - 1


@dataclass(frozen=True)
class PerceptionNetConfig:
    """What builds a keypoint network; saved as `config.json` beside its weights."""

    types: int = len(TYPES)  # type channels: f_p's vocabulary's (`perception.vocabulary`)
    width: int = 32  # channels of the first block; doubled at each of the next two
    stages: int = 2
    stride: int = STRIDE  # input pixels per output cell: 4, or 2 through `_Refine`

    def __post_init__(self) -> None:
        for name in ("types", "width", "stages"):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 1:
                raise InvalidInputError(f"{name} {value!r}: need a positive integer")
        if self.stride not in STRIDES:
            raise InvalidInputError(f"stride {self.stride!r}: need one of {STRIDES}")

    @property
    def beliefs(self) -> int:
        return self.types * KEYPOINTS

    @property
    def fields(self) -> int:
        return CORNERS * 2

    def to_json(self) -> dict:
        return asdict(self)

    @staticmethod
    def from_json(d: dict) -> PerceptionNetConfig:
        return PerceptionNetConfig(**d)


def _block(c_in: int, c_out: int, stride: int) -> nn.Sequential:
    return nn.Sequential(
        nn.Conv2d(c_in, c_out, 3, stride=stride, padding=1, bias=False),
        nn.BatchNorm2d(c_out),
        nn.ReLU(inplace=True),
        nn.Conv2d(c_out, c_out, 3, padding=1, bias=False),
        nn.BatchNorm2d(c_out),
        nn.ReLU(inplace=True),
    )


class _Refine(nn.Module):
    """The last stage's maps at twice their resolution: scaled up, then corrected from the
    half-resolution features.

    Args:
        maps: channels of the maps (beliefs and fields, before the sigmoid).
        features: channels of the half-resolution features.
        width: channels of the correction's hidden layers.

    Shapes:
        maps: [B, maps, h, w]; features: [B, features, 2h, 2w]; output: [B, maps, 2h, 2w].
    """

    def __init__(self, maps: int, features: int, width: int) -> None:
        super().__init__()
        self.correct = nn.Sequential(
            nn.Conv2d(maps + features, width, 1),
            nn.ReLU(inplace=True),
            nn.Conv2d(width, width, 3, padding=1),
            nn.ReLU(inplace=True),
            nn.Conv2d(width, width, 3, padding=1),
            nn.ReLU(inplace=True),
            nn.Conv2d(width, maps, 1),
        )

    def forward(self, maps: torch.Tensor, features: torch.Tensor) -> torch.Tensor:
        up = _doubled(maps)
        return up + self.correct(torch.cat([up, features], dim=1))


def _doubled(maps: torch.Tensor) -> torch.Tensor:
    return nn.functional.interpolate(maps, scale_factor=2, mode="bilinear", align_corners=False)


class KeypointNet(nn.Module):
    """Belief maps and affinity fields from an RGB image.

    Args:
        config: the sizes (`PerceptionNetConfig`).

    Shapes:
        input: [B, 3, H, W] float in 0..1, H and W multiples of 8.
        output: a list over stages (and the refinement, at stride 2) of
            (beliefs [B, types * 9, H / s, W / s] in 0..1, fields [B, 8 * 2, H / s, W / s],
            corner-to-centroid vectors in output cells), s = `config.stride`.
    """

    def __init__(self, config: PerceptionNetConfig) -> None:
        super().__init__()
        w = config.width
        self.stride = config.stride
        self.stem = nn.Sequential(_block(3, w, 2), _block(w, 2 * w, 2))  # 1/4
        self.down = _block(2 * w, 4 * w, 2)  # 1/8: a wider view for telling objects apart
        self.up = nn.ConvTranspose2d(4 * w, 2 * w, 2, stride=2)
        features, out = 4 * w, config.beliefs + config.fields
        self.stages = nn.ModuleList()
        for s in range(config.stages):
            c_in = features + (out if s else 0)
            self.stages.append(
                nn.Sequential(
                    nn.Conv2d(c_in, 2 * w, 3, padding=1),
                    nn.ReLU(inplace=True),
                    nn.Conv2d(2 * w, 2 * w, 3, padding=2, dilation=2),
                    nn.ReLU(inplace=True),
                    nn.Conv2d(2 * w, out, 1),
                )
            )
        self.refine = _Refine(out, w, w) if config.stride == 2 else None
        self.beliefs = config.beliefs

    def forward(self, image: torch.Tensor) -> list[tuple[torch.Tensor, torch.Tensor]]:
        return [self._split(m) for m in self._maps(image)]

    def last(self, image: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The last output of `forward` alone, what a look reads (the earlier ones are there to
        be supervised)."""
        return self._split(self._maps(image)[-1])

    def _split(self, m: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return torch.sigmoid(m[:, : self.beliefs]), m[:, self.beliefs :]

    def _maps(self, image: torch.Tensor) -> list[torch.Tensor]:
        half = self.stem[0](image)
        quarter = self.stem[1](half)
        features = torch.cat([quarter, self.up(self.down(quarter))], dim=1)
        maps, previous = [], None
        for stage in self.stages:
            x = features if previous is None else torch.cat([features, previous], dim=1)
            previous = stage(x)
            maps.append(previous)
        if self.refine is not None:
            maps = [_doubled(m) for m in maps] + [self.refine(previous, half)]
        return maps


def build(config: PerceptionNetConfig) -> KeypointNet:
    return KeypointNet(config)


def load_perception_net(folder: Path) -> tuple[KeypointNet, PerceptionNetConfig]:
    """A trained keypoint network (eval mode) from its checkpoint folder; one line if not."""
    net, config = load_trained(folder, PerceptionNetConfig.from_json, build, "perception network")
    return net, config  # type: ignore[return-value]
