"""Identity colours: a fixed BGR colour per id, and the dark outline drawn around every coloured mark."""

from __future__ import annotations

BGR = tuple[int, int, int]

# Saturated BGR colours that stand out on grass, water, sand and white (no pure greens).
PALETTE: tuple[BGR, ...] = (
    (0, 140, 255), (255, 160, 30), (230, 60, 230), (0, 230, 255), (255, 255, 90),
    (190, 150, 255), (180, 105, 255), (255, 255, 255), (90, 190, 255), (160, 80, 255),
)
OUTLINE: BGR = (20, 20, 20)
FALSE_POSITIVE: BGR = (200, 200, 200)


def identity_colour(identity: int) -> BGR:
    """BGR colour of ``identity`` (an agent or track id, >= 0); negative ids (false positives) are grey."""
    if identity < 0:
        return FALSE_POSITIVE
    return PALETTE[int(identity) % len(PALETTE)]


def rgb_hex(colour: BGR) -> str:
    """``#rrggbb`` of a BGR colour (for matplotlib and HTML)."""
    b, g, r = colour
    return f"#{r:02x}{g:02x}{b:02x}"
