"""Identity colours: a fixed, distinguishable BGR colour per id (the same id keeps its colour)."""

from __future__ import annotations

BGR = tuple[int, int, int]

# Tableau-like palette in BGR, easy to tell apart on grass, water and white.
PALETTE: tuple[BGR, ...] = (
    (180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148),
    (75, 86, 140), (194, 119, 227), (34, 189, 188), (207, 190, 23), (127, 127, 127),
)
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
