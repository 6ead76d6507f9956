"""Video frames for people: camera views side by side under a caption band (Pillow)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from PIL import Image, ImageDraw, ImageFont

BAND = 84  # pixels of caption above the views
LABEL = 22  # pixels of a view's name under it


@lru_cache(maxsize=4)
def _font(size: int) -> ImageFont.ImageFont:
    return ImageFont.load_default(size=size)


def compose(
    views: list[np.ndarray], names: list[str], caption: list[str], scale: float = 1.0
) -> np.ndarray:
    """One frame: the views (each height x width x 3, uint8, all the same size) side by side,
    each named beneath, under up to three lines of caption (the first one larger); `scale`
    sizes the text and its margins (views rendered at half size take `scale=0.5`).

    Shapes:
        views: each [H, W, 3]; returns [round(scale * (BAND + LABEL)) + H, W * len(views), 3].
    """

    def px(v: float) -> int:
        return max(1, round(v * scale))

    h, w, _ = views[0].shape
    band = px(BAND)
    frame = Image.new("RGB", (w * len(views), band + h + px(LABEL)), (250, 250, 250))
    draw = ImageDraw.Draw(frame)
    for k, (view, name) in enumerate(zip(views, names, strict=True)):
        frame.paste(Image.fromarray(view), (k * w, band))
        draw.text((k * w + px(8), band + h + px(3)), name, fill=(90, 90, 90), font=_font(px(15)))
    for k, line in enumerate(caption[:3]):
        size = px(22 if k == 0 else 16)
        xy = (px(10), px(6 + 27 * k - 4 * (k > 1)))
        draw.text(xy, line, fill=(20, 20, 20), font=_font(size))
    return np.asarray(frame)
