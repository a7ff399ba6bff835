"""Draw the shipped maps: a warehouse, an office and a field, in the ROS map_server format.

Each is 100 × 100 domain units (the paper's area) at 0.5 units per pixel, so a coverage cell of 1 is
2 × 2 pixels. Pixels follow the ROS convention: 0 occupied, 254 free, 205 unknown. Run it again to
rewrite scenarios/maps/*.pgm, *.yaml and docs/maps.png:

    .venv/bin/python scenarios/make_maps.py
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
SIZE = 100.0
RESOLUTION = 0.5
FREE, UNKNOWN, OCCUPIED = 254, 205, 0


def canvas() -> np.ndarray:
    pixels = round(SIZE / RESOLUTION)
    return np.full((pixels, pixels), FREE, dtype=np.uint8)


def box(image: np.ndarray, x0: float, y0: float, x1: float, y1: float, value: int = OCCUPIED) -> None:
    """Fill the world rectangle [x0, x1] × [y0, y1] (y up; image row 0 is the top)."""
    rows = image.shape[0]
    c0, c1 = round(x0 / RESOLUTION), round(x1 / RESOLUTION)
    r0, r1 = rows - round(y1 / RESOLUTION), rows - round(y0 / RESOLUTION)
    image[r0:r1, c0:c1] = value


def outer_walls(image: np.ndarray, thickness: float = 1.0) -> None:
    for x0, y0, x1, y1 in ((0, 0, SIZE, thickness), (0, SIZE - thickness, SIZE, SIZE)):
        box(image, x0, y0, x1, y1)
    for x0, y0, x1, y1 in ((0, 0, thickness, SIZE), (SIZE - thickness, 0, SIZE, SIZE)):
        box(image, x0, y0, x1, y1)


def warehouse() -> np.ndarray:
    """Walls, and six rows of shelves 3 deep with a cross aisle in the middle of each row."""
    image = canvas()
    outer_walls(image)
    for row in range(6):
        y0 = 14.0 + row * 13.0
        box(image, 12.0, y0, 45.0, y0 + 3.0)
        box(image, 55.0, y0, 88.0, y0 + 3.0)
    return image


def office() -> np.ndarray:
    """Walls, a corridor across the middle, four rooms on each side with 4-unit doors, and a closed
    store room (no door) in one corner, which no robot can reach."""
    image = canvas()
    outer_walls(image)
    box(image, 0.0, 40.0, SIZE, 41.0)  # corridor walls
    box(image, 0.0, 59.0, SIZE, 60.0)
    for x in (25.0, 50.0, 75.0):
        box(image, x - 0.5, 0.0, x + 0.5, 40.0)
        box(image, x - 0.5, 60.0, x + 0.5, SIZE)
    for x in (10.0, 35.0, 60.0, 85.0):
        box(image, x, 40.0, x + 4.0, 41.0, FREE)  # doors
        box(image, x, 59.0, x + 4.0, 60.0, FREE)
    box(image, 85.0, 85.0, 86.0, 99.0)  # the store room: walls all round
    box(image, 85.0, 85.0, 99.0, 86.0)
    box(image, 86.0, 86.0, 99.0, 99.0, UNKNOWN)  # never mapped inside
    return image


def field() -> np.ndarray:
    """No walls (the map's edge bounds it): an elliptic pond and a building."""
    image = canvas()
    rows = image.shape[0]
    centre = (round(35.0 / RESOLUTION), rows - round(60.0 / RESOLUTION))
    axes = (round(16.0 / RESOLUTION), round(10.0 / RESOLUTION))
    cv2.ellipse(image, centre, axes, 20.0, 0.0, 360.0, OCCUPIED, thickness=-1)
    box(image, 62.0, 15.0, 82.0, 32.0)
    return image


def write_map(name: str, image: np.ndarray) -> None:
    cv2.imwrite(str(HERE / "maps" / f"{name}.pgm"), image)
    (HERE / "maps" / f"{name}.yaml").write_text(
        f"image: {name}.pgm\n"
        "mode: trinary\n"
        f"resolution: {RESOLUTION}\n"
        "origin: [0.0, 0.0, 0.0]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.25\n",
        encoding="utf-8",
    )


def plot_maps(maps: dict[str, np.ndarray], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(maps), figsize=(4 * len(maps), 4.2))
    for ax, (name, image) in zip(axes, maps.items(), strict=True):
        ax.imshow(image, cmap="gray", vmin=0, vmax=255, extent=(0, SIZE, 0, SIZE))
        ax.set_title(f"scenarios/maps/{name}.yaml")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> None:
    (HERE / "maps").mkdir(exist_ok=True)
    maps = {"warehouse": warehouse(), "office": office(), "field": field()}
    for name, image in maps.items():
        write_map(name, image)
    plot_maps(maps, HERE.parent / "docs" / "maps.png")


if __name__ == "__main__":
    main()
